//! The Scale tab and the status line: where the metric scale comes from and how sure it is, the
//! camera height (entered once, refined from the tracked camera's height), the "Known length"
//! tool (two taps on the ends of something measured) and the "Measure" tool (two taps: the
//! distance in metres, shown on the view).

use egui::{Align2, Color32, RichText, Ui};
use sylva_tracking::scale::HOLDING_HEIGHT_RANGE_M;

use crate::scale::ScaleTool;
use crate::state::{DesignState, InputEvent};

/// The lengths the known-length field offers, metres.
const KNOWN_LENGTH_RANGE_M: std::ops::RangeInclusive<f64> = 0.05..=100.0;

/// The Scale tab: camera height, the two tools and what the last one said.
pub fn scale_ui(
    ui: &mut Ui,
    known_length_m: &mut f64,
    design: &DesignState,
    events: &mut Vec<InputEvent>,
) {
    let scale = &design.scale;
    ui.horizontal(|ui| {
        let mut height_m = scale.state.holding_height_m();
        let name = ui.label("Camera height above the ground (m):");
        let field = ui
            .add(
                egui::DragValue::new(&mut height_m)
                    .range(HOLDING_HEIGHT_RANGE_M)
                    .speed(0.01)
                    .fixed_decimals(2),
            )
            .labelled_by(name.id);
        if field.changed() && height_m != scale.state.holding_height_m() {
            events.push(InputEvent::HoldingHeight {
                holding_height_m: height_m,
            });
        }
        ui.separator();
        let name = ui.label("Length (m):");
        ui.add(
            egui::DragValue::new(known_length_m)
                .range(KNOWN_LENGTH_RANGE_M)
                .speed(0.01)
                .fixed_decimals(2),
        )
        .labelled_by(name.id);
        let marking = matches!(scale.tool, Some(ScaleTool::KnownLength { .. }));
        if ui.selectable_label(marking, "Known length").clicked() {
            let tool = (!marking).then_some(ScaleTool::KnownLength {
                length_m: *known_length_m,
            });
            events.push(InputEvent::ScaleTool { tool });
        }
        let measuring = scale.tool == Some(ScaleTool::Measure);
        if ui.selectable_label(measuring, "Measure").clicked() {
            let tool = (!measuring).then_some(ScaleTool::Measure);
            events.push(InputEvent::ScaleTool { tool });
        }
    });
    if let Some(message) = &scale.message {
        ui.label(RichText::new(message).size(16.0));
    }
}

/// The status line, always shown over the view's top-left corner (taking no room from it): the
/// scale's source and uncertainty.
pub fn status_line_ui(ui: &Ui, design: &DesignState, view: egui::Rect) {
    egui::Area::new(egui::Id::unique("sylva scale status"))
        .fixed_pos(view.left_top() + egui::vec2(8.0, 8.0))
        .interactable(false)
        .show(ui.ctx(), |ui| {
            egui::Frame::new()
                .fill(Color32::from_black_alpha(170))
                .corner_radius(6.0)
                .inner_margin(6.0)
                .show(ui, |ui| {
                    ui.label(
                        RichText::new(design.scale_status())
                            .size(15.0)
                            .color(Color32::WHITE),
                    );
                });
        });
}

/// The last distance measured, large on the view while the measure tool is chosen.
pub fn overlay_ui(ui: &Ui, design: &DesignState, view: egui::Rect) {
    let scale = &design.scale;
    let (Some(ScaleTool::Measure), Some(measured)) = (scale.tool, scale.measured) else {
        return;
    };
    let text = format!("{:.2} m ± {:.2} m", measured.distance_m, measured.sigma_m);
    let at = view.center_top() + egui::vec2(0.0, 16.0);
    let painter = ui.painter_at(view);
    painter.rect_filled(
        egui::Rect::from_center_size(at + egui::vec2(0.0, 18.0), egui::vec2(240.0, 44.0)),
        8.0,
        Color32::from_black_alpha(170),
    );
    painter.text(
        at + egui::vec2(0.0, 18.0),
        Align2::CENTER_CENTER,
        text,
        egui::FontId::proportional(24.0),
        Color32::WHITE,
    );
}
