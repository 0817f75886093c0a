//! The egui UI, touch first (mouse acts as touch): a side bar with brush radius, grow/ungrow and
//! undo; a top bar with tabs (architecture, growth, species, years, export); the coaching overlay
//! until the ground is found; the frame-budget overlay; play/pause/seek.
//!
//! UI functions never change the design directly: they emit [`InputEvent`]s, which the caller
//! applies and records, so sessions capture every edit.

pub mod orbit;
pub mod touch;
pub mod widgets;

use egui::{Align2, Color32, RichText, Ui};
use sylva_core::geometry::Season;

use crate::state::{DesignState, InputEvent};

/// Top-bar tabs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tab {
    Architecture,
    Growth,
    Species,
    Years,
    Export,
}

/// Per-frame timings shown in the frame-budget overlay, milliseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameBudget {
    pub tracking_ms: f32,
    pub growth_ms: f32,
    pub meshing_ms: f32,
    pub render_ms: f32,
}

/// UI-only state (not part of the design).
#[derive(Clone, Debug, PartialEq)]
pub struct UiState {
    /// The open top-bar tab (none: only the tab names show, leaving the view free).
    pub tab: Option<Tab>,
    pub playing: bool,
    pub frame: usize,
    pub num_frames: usize,
    /// Set by the seek slider; the caller jumps there.
    pub seek_to: Option<usize>,
    /// A live stream (camera, video): frames come as they come, there is nothing to seek.
    pub live: bool,
    pub ground_found: bool,
    pub budget: FrameBudget,
    pub show_debug: bool,
    /// The tree alone, outside AR, in a view that orbits, pans and zooms.
    pub orbit_view: bool,
    pub export_requested: bool,
    pub species_names: Vec<String>,
}

impl Default for UiState {
    fn default() -> Self {
        UiState {
            tab: None,
            playing: true,
            frame: 0,
            num_frames: 0,
            seek_to: None,
            live: false,
            ground_found: false,
            budget: FrameBudget::default(),
            show_debug: false,
            orbit_view: false,
            export_requested: false,
            species_names: crate::state::species_names(),
        }
    }
}

/// Draws the whole UI around the AR view; returns the central view's rectangle (where touches
/// brush the tree). Edits come out as events in `events`.
pub fn sylva_ui(
    ui: &mut Ui,
    state: &mut UiState,
    design: &DesignState,
    events: &mut Vec<InputEvent>,
) -> egui::Rect {
    let mut params = design.params.clone();
    egui::Panel::top("sylva top bar").show(ui, |ui| {
        ui.horizontal(|ui| {
            for (tab, name) in [
                (Tab::Architecture, "Architecture"),
                (Tab::Growth, "Growth"),
                (Tab::Species, "Species"),
                (Tab::Years, "Years"),
                (Tab::Export, "Export"),
            ] {
                // Tapping the open tab closes it.
                if ui.selectable_label(state.tab == Some(tab), name).clicked() {
                    state.tab = if state.tab == Some(tab) {
                        None
                    } else {
                        Some(tab)
                    };
                }
            }
        });
        let Some(tab) = state.tab else {
            return;
        };
        match tab {
            Tab::Architecture => architecture_ui(ui, &mut params),
            Tab::Growth => growth_ui(ui, &mut params),
            Tab::Species => {
                egui::ComboBox::from_label("Species")
                    .selected_text(params.species.clone())
                    .show_ui(ui, |ui| {
                        for name in &state.species_names {
                            ui.selectable_value(&mut params.species, name.clone(), name);
                        }
                    });
            }
            Tab::Years => {
                ui.add(
                    egui::Slider::new(&mut params.years, 1.0..=40.0)
                        .text("Age (years): grows or ungrows the tree"),
                );
                season_ui(ui, &mut params.season);
            }
            Tab::Export => {
                if ui.button("Export tree (.glb, .json)").clicked() {
                    state.export_requested = true;
                }
            }
        }
    });
    egui::Panel::right("sylva side bar")
        .exact_size(120.0)
        .show(ui, |ui| {
            side_bar_ui(ui, &mut params, design, events);
        });
    egui::Panel::bottom("sylva playback").show(ui, |ui| playback_ui(ui, state));
    if params != design.params {
        events.push(InputEvent::Parameters { parameters: params });
    }
    let view = ui.available_rect_before_wrap();
    overlays_ui(ui, state, view);
    view
}

fn architecture_ui(ui: &mut Ui, params: &mut crate::state::Parameters) {
    ui.horizontal(|ui| {
        ui.vertical(|ui| {
            ui.label("α β γ");
            widgets::weights_triangle_ui(ui, &mut params.direction_weights);
        });
        ui.vertical(|ui| {
            ui.label("Tropism θ");
            widgets::tropism_arrow_ui(ui, &mut params.tropism_angle);
        });
        ui.vertical(|ui| {
            ui.label("Gravimorphism");
            widgets::gravimorphism_ellipse_ui(ui, &mut params.gravimorphism);
        });
        ui.vertical(|ui| {
            ui.add(
                egui::Slider::new(&mut params.branching_angle, 0.0..=1.6).text("Branching angle"),
            );
            ui.add(
                egui::Slider::new(&mut params.deflection_angle, 0.0..=0.8).text("Deflection angle"),
            );
            ui.checkbox(
                &mut params.sketch_tropism,
                "Tropism from the stroke direction",
            );
        });
    });
}

fn growth_ui(ui: &mut Ui, params: &mut crate::state::Parameters) {
    ui.horizontal_wrapped(|ui| {
        ui.add(
            egui::Slider::new(&mut params.apical_dominance, 0.0..=1.0).text("λ apical dominance"),
        );
        ui.add(
            egui::Slider::new(&mut params.light_sensitivity, 0.0..=1.0).text("κ light sensitivity"),
        );
        ui.add(
            egui::Slider::new(&mut params.shedding_threshold, 0.0..=1.0)
                .text("Th shedding threshold"),
        );
        ui.add(
            egui::Slider::new(&mut params.max_shoot_length, 1.0..=20.0).text("n_max shoot length"),
        );
    });
}

/// The season beside the years slider: one button per season (winter shows deciduous trees
/// leafless).
fn season_ui(ui: &mut Ui, season: &mut Season) {
    ui.horizontal(|ui| {
        ui.label("Season:");
        for s in Season::ALL {
            ui.selectable_value(season, s, s.name());
        }
    });
}

fn side_bar_ui(
    ui: &mut Ui,
    params: &mut crate::state::Parameters,
    design: &DesignState,
    events: &mut Vec<InputEvent>,
) {
    ui.vertical_centered(|ui| {
        ui.label("Brush");
        ui.add(
            egui::Slider::new(&mut params.brush_radius, 0.02..=0.5)
                .vertical()
                .text("Brush radius"),
        );
        ui.separator();
        ui.label("Grow (up) / ungrow (down)");
        ui.add(
            egui::Slider::new(&mut params.grow_speed, -20.0..=20.0)
                .vertical()
                .text("Grow speed"),
        );
        if ui.button("Grow").clicked() {
            events.push(InputEvent::Grow { iterations: 1 });
        }
        if ui.button("Ungrow").clicked() {
            events.push(InputEvent::Grow { iterations: -1 });
        }
        ui.separator();
        let undo = ui.add_enabled(
            design.undo_depth() > 0,
            egui::Button::new(RichText::new("Undo").size(18.0)),
        );
        if undo.clicked() {
            events.push(InputEvent::Undo);
        }
    });
}

fn playback_ui(ui: &mut Ui, state: &mut UiState) {
    ui.horizontal(|ui| {
        let label = if state.playing { "Pause" } else { "Play" };
        if ui.button(label).clicked() {
            state.playing = !state.playing;
        }
        if state.live {
            ui.label(format!("Frame {} (live)", state.frame));
        } else {
            let mut frame = state.frame;
            let last = state.num_frames.saturating_sub(1);
            if ui
                .add(egui::Slider::new(&mut frame, 0..=last).text("Frame"))
                .changed()
            {
                state.seek_to = Some(frame);
            }
        }
        ui.checkbox(&mut state.show_debug, "Debug views");
        ui.checkbox(&mut state.orbit_view, "3D view (outside AR)");
    });
}

fn overlays_ui(ui: &mut Ui, state: &UiState, view: egui::Rect) {
    let painter = ui.painter_at(view);
    if !state.ground_found {
        painter.rect_filled(
            egui::Rect::from_center_size(view.center(), egui::vec2(360.0, 60.0)),
            8.0,
            Color32::from_black_alpha(160),
        );
        painter.text(
            view.center(),
            Align2::CENTER_CENTER,
            "Move the phone slowly to find the ground...",
            egui::FontId::proportional(18.0),
            Color32::WHITE,
        );
    }
    let b = state.budget;
    let text = format!(
        "tracking {:.1} ms · growth {:.1} ms · meshing {:.1} ms · render {:.1} ms",
        b.tracking_ms, b.growth_ms, b.meshing_ms, b.render_ms
    );
    painter.text(
        view.left_bottom() + egui::vec2(8.0, -8.0),
        Align2::LEFT_BOTTOM,
        text,
        egui::FontId::monospace(12.0),
        Color32::from_rgb(255, 255, 180),
    );
}
