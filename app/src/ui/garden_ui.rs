//! The Garden tab: plant another tree of a chosen species, pick the tree the tools edit, delete
//! it; and in the view, a ring at the selected tree's foot and the planting hint. Like every
//! panel it only emits [`InputEvent`]s (`PlantAnother`, `SelectTree`, `DeleteTree`).

use egui::{Align2, Color32, Stroke, Ui};

use crate::state::{DesignState, InputEvent};
use crate::ui::touch::window_from_image;

const SELECTED_RING: Color32 = Color32::from_rgb(255, 210, 40);

/// The Garden tab. `species` is the species the next tree will be (kept by the UI).
pub fn garden_ui(
    ui: &mut Ui,
    species: &mut String,
    species_names: &[String],
    design: &DesignState,
    events: &mut Vec<InputEvent>,
) {
    ui.horizontal_wrapped(|ui| {
        egui::ComboBox::from_label("Next tree")
            .selected_text(species.clone())
            .show_ui(ui, |ui| {
                for name in species_names {
                    ui.selectable_value(species, name.clone(), name);
                }
            });
        let plant = ui.add_enabled(
            design.is_planted() && design.garden.planting.is_none(),
            egui::Button::new("Plant another tree"),
        );
        if plant.clicked() {
            events.push(InputEvent::PlantAnother {
                species: species.clone(),
            });
        }
        let delete = ui.add_enabled(
            design.num_trees() >= 2,
            egui::Button::new("Delete this tree"),
        );
        if delete.clicked() {
            events.push(InputEvent::DeleteTree);
        }
    });
    let names = design.tree_species();
    if names.len() >= 2 {
        ui.horizontal_wrapped(|ui| {
            ui.label("Edit:");
            for (i, name) in names.iter().enumerate() {
                let label = format!("{} {name}", i + 1);
                if ui
                    .selectable_label(i == design.selected_tree(), label)
                    .clicked()
                    && i != design.selected_tree()
                {
                    events.push(InputEvent::SelectTree { index: i });
                }
            }
        });
        ui.label("Tap a tree to edit it; the years slider moves the whole garden.");
    }
}

/// In the view: a ring at the foot of the selected tree of a garden, and, while "Plant another
/// tree" waits for its tap, the hint asking for it.
pub fn garden_overlay_ui(ui: &mut Ui, design: &DesignState, view: egui::Rect) {
    let painter = ui.painter_at(view);
    let ppp = ui.ctx().pixels_per_point();
    let screen = ui.ctx().content_rect().size() * ppp;
    let target = (screen.x.round() as u32, screen.y.round() as u32);
    if design.has_garden()
        && let Some(camera) = design.camera
        && let Some(foot) = camera.pixel_from_world(glam::Vec3::ZERO)
    {
        let at = window_from_image(foot, ppp, target, &camera.intrinsics);
        painter.circle_stroke(at, 14.0, Stroke::new(5.0, Color32::BLACK));
        painter.circle_stroke(at, 14.0, Stroke::new(3.0, SELECTED_RING));
        painter.text(
            at + egui::vec2(0.0, 18.0),
            Align2::CENTER_TOP,
            format!("editing tree {}", design.selected_tree() + 1),
            egui::FontId::proportional(14.0),
            SELECTED_RING,
        );
    }
    if let Some(species) = &design.garden.planting {
        let at = view.center_top() + egui::vec2(0.0, 64.0);
        let galley = painter.layout_no_wrap(
            format!("Tap the ground where the new {species} should stand"),
            egui::FontId::proportional(16.0),
            Color32::WHITE,
        );
        let rect = Align2::CENTER_CENTER.anchor_size(at, galley.size() + egui::vec2(16.0, 8.0));
        painter.rect_filled(rect, 6.0, Color32::from_black_alpha(170));
        painter.galley(rect.min + egui::vec2(8.0, 4.0), galley, Color32::WHITE);
    }
}
