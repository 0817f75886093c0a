//! The "Recreate a tree" panel (issue 23): the steps in plain words (tap the trunk's base, trace
//! the crown with a finger, walk on and trace again, pick the species, "Grow to fit"), the
//! measures in metres with how each was obtained, the model's agreement with each traced
//! outline, and the overlay's opacity and outline-only mode. The traced outlines and the trunk
//! base are drawn over the view ([`recreate_overlay_ui`]). Every control sends an
//! [`InputEvent::Recreate`].

use egui::{Color32, Stroke, Ui};

use super::touch::window_from_image;
use crate::state::{DesignState, InputEvent, RecreateAction};

const TRACED: Color32 = Color32::from_rgb(255, 210, 40);

fn send(events: &mut Vec<InputEvent>, action: RecreateAction) {
    events.push(InputEvent::Recreate { action });
}

/// The panel's contents (the Recreate tab).
pub fn recreate_ui(
    ui: &mut Ui,
    design: &DesignState,
    species_names: &[String],
    events: &mut Vec<InputEvent>,
) {
    let mode = &design.recreate;
    ui.horizontal_wrapped(|ui| {
        if ui.button("Start marking").clicked() {
            send(events, RecreateAction::Start);
        }
        if mode.active && ui.button("Stop marking").clicked() {
            send(events, RecreateAction::Leave);
        }
    });
    if mode.active {
        let step = match (&mode.base, mode.outlines.len()) {
            (None, _) => "1. Tap the bottom of the real tree's trunk.".to_owned(),
            (Some(_), 0) => "2. Trace the crown's outline with a finger.".to_owned(),
            (Some(_), n) => format!(
                "{n} outline(s) traced. Walk a few steps around the tree and trace it again, or grow."
            ),
        };
        ui.label(step);
    }
    ui.horizontal_wrapped(|ui| {
        let chosen = mode.species.clone();
        let text = chosen.clone().unwrap_or_else(|| "closest by shape".into());
        egui::ComboBox::from_label("Species to grow")
            .selected_text(text)
            .show_ui(ui, |ui| {
                if ui
                    .selectable_label(chosen.is_none(), "closest by shape")
                    .clicked()
                {
                    send(events, RecreateAction::Species { species: None });
                }
                for name in species_names {
                    let picked = chosen.as_deref() == Some(name.as_str());
                    if ui.selectable_label(picked, name).clicked() {
                        send(
                            events,
                            RecreateAction::Species {
                                species: Some(name.clone()),
                            },
                        );
                    }
                }
            });
        let ready = mode.base.is_some() && !mode.outlines.is_empty();
        if ui
            .add_enabled(ready, egui::Button::new("Grow to fit"))
            .clicked()
        {
            send(events, RecreateAction::GrowToFit);
        }
    });
    if let Some(message) = &mode.message {
        ui.colored_label(Color32::from_rgb(255, 120, 90), message);
    }
    if let Some(result) = &mode.result {
        let m = &result.measurements;
        let s = result.metres_per_unit;
        let line = |ui: &mut Ui, what: &str, metres: f64, how: &str| {
            ui.label(format!("{what}: {:.2} m ({how})", metres * s));
        };
        line(ui, "Height", m.height_m, &m.methods.height);
        line(ui, "Crown width", m.crown_width_m, &m.methods.crown_width);
        ui.label(format!(
            "Crown axes: {:.2} m × {:.2} m ({})",
            m.crown_axes_m[0] * s,
            m.crown_axes_m[1] * s,
            m.methods.crown_axes
        ));
        line(ui, "Crown base", m.crown_base_m, &m.methods.crown_base);
        ui.label(format!("Trunk base: {}", m.methods.trunk_base));
        if let Some(depth) = &m.methods.crown_depth {
            ui.label(depth);
        }
        ui.label(format!(
            "Grown: {} ({}), {:.0} years",
            result.growth.species, result.growth.species_choice, result.growth.age_years
        ));
        for (frame, iou) in &result.outline_iou {
            ui.label(format!(
                "Agreement with the outline of frame {frame}: {:.0}%",
                iou * 100.0
            ));
        }
        let mut style = mode.overlay;
        ui.add(egui::Slider::new(&mut style.opacity, 0.0..=1.0).text("Model opacity"));
        ui.checkbox(&mut style.outline_only, "Outline only");
        if style != mode.overlay {
            send(
                events,
                RecreateAction::Overlay {
                    opacity: style.opacity,
                    outline_only: style.outline_only,
                },
            );
        }
    }
}

/// The overlay's texture, kept while the tree, the frame and the style stay the same.
#[derive(Clone)]
struct OverlayTexture {
    key: (u64, usize, u32, bool),
    texture: egui::TextureHandle,
}

/// After "Grow to fit": the model over the real tree in the frame shown, filled at the chosen
/// opacity or as its outline only ([`DesignState::recreate_overlay`]); re-drawn when the tree,
/// the frame or the style changes.
fn model_overlay_ui(
    ui: &Ui,
    design: &DesignState,
    painter: &egui::Painter,
    corners: [egui::Pos2; 2],
) {
    let mode = &design.recreate;
    let (Some(_), Some(step)) = (&mode.result, mode.frame_step()) else {
        return;
    };
    let style = mode.overlay;
    let key = (
        design.revision,
        step,
        style.opacity.to_bits(),
        style.outline_only,
    );
    let id = egui::Id::unique("recreate overlay texture");
    let cached: Option<OverlayTexture> = ui.ctx().data_mut(|d| d.get_temp(id));
    let texture = match cached {
        Some(c) if c.key == key => c.texture,
        _ => {
            let Some(layer) = design.recreate_overlay(Some(step), style) else {
                return;
            };
            let size = [layer.width() as usize, layer.height() as usize];
            let image = egui::ColorImage::from_rgba_unmultiplied(size, layer.as_raw());
            let texture =
                ui.ctx()
                    .load_texture("recreate overlay", image, egui::TextureOptions::NEAREST);
            let entry = OverlayTexture {
                key,
                texture: texture.clone(),
            };
            ui.ctx().data_mut(|d| d.insert_temp(id, entry));
            texture
        }
    };
    let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
    let rect = egui::Rect::from_min_max(corners[0], corners[1]);
    painter.image(texture.id(), rect, uv, Color32::WHITE);
}

/// The model overlay, the traced outlines of the frame shown and the trunk-base tap, over the
/// view.
pub fn recreate_overlay_ui(ui: &Ui, design: &DesignState, view: egui::Rect) {
    let mode = &design.recreate;
    let (Some(camera), Some(step)) = (design.world_camera(), mode.frame_step()) else {
        return;
    };
    if mode.outlines.is_empty() && mode.base.is_none() {
        return;
    }
    let painter = ui.painter_at(view);
    let ppp = ui.ctx().pixels_per_point();
    let screen = ui.ctx().content_rect().size() * ppp;
    let target = (screen.x.round() as u32, screen.y.round() as u32);
    let to_window = |p: &[f64; 2]| {
        window_from_image(
            glam::Vec2::new(p[0] as f32, p[1] as f32),
            ppp,
            target,
            &camera.intrinsics,
        )
    };
    let k = &camera.intrinsics;
    let corners = [
        to_window(&[0.0, 0.0]),
        to_window(&[f64::from(k.width), f64::from(k.height)]),
    ];
    model_overlay_ui(ui, design, &painter, corners);
    for outline in mode.outlines.iter().filter(|o| o.frame == step) {
        let mut points: Vec<egui::Pos2> = outline.outline.iter().map(to_window).collect();
        if let Some(first) = points.first().copied() {
            points.push(first);
        }
        painter.add(egui::Shape::line(points, Stroke::new(2.0, TRACED)));
    }
    if let Some(base) = mode.base.as_ref().filter(|b| b.frame == step) {
        painter.circle_stroke(to_window(&base.pixel), 8.0, Stroke::new(2.0, TRACED));
    }
}
