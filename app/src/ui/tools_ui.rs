//! The tool selector (plain words, finger-sized buttons), the width tool's setting, and what the
//! tools draw over the view: the selected bud and branch, the lasso being drawn, the tool's hint.

use egui::{Align2, Color32, Pos2, Stroke, Ui};

use super::touch::window_from_image;
use crate::state::{DEFAULT_BRANCH_DIAMETER_M, DesignState, InputEvent, Tool};

/// The smallest side of a tool button, points (a fingertip).
pub const TOOL_BUTTON_SIZE_PT: f32 = 44.0;

/// One button per tool, the chosen one selected; `vertical` stacks them (the side bar), else
/// they wrap in rows (a phone's bottom bar). Choosing one sends [`InputEvent::Tool`].
pub fn tool_selector_ui(
    ui: &mut Ui,
    design: &DesignState,
    vertical: bool,
    events: &mut Vec<InputEvent>,
) {
    let chosen = design.tool();
    let diameter_m = match chosen {
        Tool::Width { diameter_m } => diameter_m,
        _ => DEFAULT_BRANCH_DIAMETER_M,
    };
    let buttons = |ui: &mut Ui| {
        for tool in Tool::all(diameter_m) {
            let width = if vertical {
                ui.available_width()
            } else {
                TOOL_BUTTON_SIZE_PT
            };
            let button = egui::Button::selectable(
                chosen.same_kind(tool),
                egui::RichText::new(tool.label()).size(16.0),
            )
            .min_size(egui::vec2(width, TOOL_BUTTON_SIZE_PT));
            if ui.add(button).clicked() && !chosen.same_kind(tool) {
                events.push(InputEvent::Tool { tool });
            }
        }
    };
    if vertical {
        ui.vertical_centered_justified(buttons);
    } else {
        ui.horizontal_wrapped(buttons);
    }
    if let Tool::Width { diameter_m } = chosen {
        let mut cm = diameter_m * 100.0;
        let slider = egui::Slider::new(&mut cm, 0.5..=30.0).text("Branch width (cm)");
        let slider = if vertical { slider.vertical() } else { slider };
        if ui.add(slider).changed() {
            events.push(InputEvent::Tool {
                tool: Tool::Width {
                    diameter_m: cm / 100.0,
                },
            });
        }
    }
}

/// Where an image pixel of the design's camera is drawn in the window, points.
fn window_point(ui: &Ui, design: &DesignState, pixel: glam::Vec2) -> Option<Pos2> {
    let camera = design.camera?;
    let ppp = ui.ctx().pixels_per_point();
    let screen = ui.ctx().content_rect().size() * ppp;
    let target = (screen.x.round() as u32, screen.y.round() as u32);
    Some(window_from_image(pixel, ppp, target, &camera.intrinsics))
}

const HIGHLIGHT: Color32 = Color32::from_rgb(255, 210, 40);

/// The selected internode (thick) with the rest of its branch up to the tip, and a ring on its
/// bud; the lasso outline while it is drawn; the chosen tool's hint at the top of the view.
pub fn tool_overlays_ui(ui: &mut Ui, design: &DesignState, view: egui::Rect) {
    let painter = ui.painter_at(view);
    if let Some(camera) = design.camera {
        let branch = design.selected_branch();
        let skeleton = &design.tree.skeleton;
        for (i, id) in branch.iter().enumerate() {
            let node = skeleton.get(*id);
            let ends = [node.start, node.end].map(|p| {
                camera
                    .pixel_from_world(p)
                    .and_then(|px| window_point(ui, design, px))
            });
            let [Some(a), Some(b)] = ends else {
                continue;
            };
            let width = if i == 0 { 6.0 } else { 3.0 };
            painter.line_segment([a, b], Stroke::new(width + 2.0, Color32::BLACK));
            painter.line_segment([a, b], Stroke::new(width, HIGHLIGHT));
            if i == 0 {
                painter.circle_stroke(b, 9.0, Stroke::new(3.0, HIGHLIGHT));
            }
        }
    }
    let outline: Vec<Pos2> = design
        .lasso_outline()
        .iter()
        .filter_map(|p| window_point(ui, design, *p))
        .collect();
    if outline.len() >= 2 {
        painter.add(egui::Shape::line(
            outline,
            Stroke::new(3.0, Color32::from_rgb(120, 230, 120)),
        ));
    }
    let tool = design.tool();
    if tool != Tool::Brush && design.is_planted() {
        let at = view.center_top() + egui::vec2(0.0, 36.0);
        let galley = painter.layout_no_wrap(
            tool.hint().to_owned(),
            egui::FontId::proportional(16.0),
            Color32::WHITE,
        );
        let rect = Align2::CENTER_CENTER.anchor_size(at, galley.size() + egui::vec2(16.0, 8.0));
        painter.rect_filled(rect, 6.0, Color32::from_black_alpha(170));
        painter.galley(rect.min + egui::vec2(8.0, 4.0), galley, Color32::WHITE);
    }
}
