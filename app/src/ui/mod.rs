//! The egui UI, touch first (mouse acts as touch): a side bar with the tools (brush, lasso
//! crown, width, bend, prune: [`tools_ui`]), brush radius, grow/ungrow and undo; a top bar with
//! tabs (the tree: species, age and plain-language crown controls; the research parameters under
//! "Advanced"; export); the coaching overlay until the ground is found; the frame-budget
//! overlay; play/pause/seek. The panels overlay the AR view (the camera image keeps its place);
//! on a portrait screen (a phone held upright) the side bar docks at the bottom with the
//! playback controls, so that no panel covers the middle of the view where the tree stands.
//!
//! UI functions never change the design directly: they emit [`InputEvent`]s, which the caller
//! applies and records, so sessions capture every edit.

pub mod garden_ui;
pub mod orbit;
pub mod plain;
pub mod recreate_ui;
pub mod scale_ui;
pub mod tools_ui;
pub mod touch;
pub mod widgets;

use egui::{Align2, Color32, RichText, Ui};
use sylva_core::geometry::Season;

use crate::state::{DesignState, InputEvent};

/// Top-bar tabs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tab {
    /// Species, age in years and the plain-language controls ([`plain::tree_ui`]).
    Tree,
    /// The research parameters with their symbols ([`plain::advanced_ui`]).
    Advanced,
    /// The metric scale: camera height, known length and the measure tool ([`scale_ui::scale_ui`]).
    Scale,
    /// Several trees: plant another, pick the one edited, delete ([`garden_ui::garden_ui`]).
    Garden,
    Export,
    /// Recreating a real tree: marks, "Grow to fit", the measures ([`recreate_ui::recreate_ui`]).
    Recreate,
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
    /// The tree is planted (until then a hint asks for a tap on the ground).
    pub planted: bool,
    pub budget: FrameBudget,
    pub show_debug: bool,
    /// The tree alone, outside AR, in a view that orbits, pans and zooms.
    pub orbit_view: bool,
    pub export_requested: bool,
    pub species_names: Vec<String>,
    /// The length the "Known length" tool marks, metres.
    pub known_length_m: f64,
    /// The rectangles of the panels drawn over the AR view in the last frame, points.
    pub panel_rects: Vec<egui::Rect>,
    /// A seek catching up: (frame shown, frame sought).
    pub seek_progress: Option<(usize, usize)>,
    /// A phone's bottom bar shows the brush sliders and playback (folded away by default).
    pub more_controls: bool,
    /// The species "Plant another tree" plants.
    pub garden_species: String,
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
            planted: false,
            budget: FrameBudget::default(),
            show_debug: false,
            orbit_view: false,
            export_requested: false,
            species_names: crate::state::species_names(),
            known_length_m: 1.0,
            panel_rects: Vec::new(),
            more_controls: false,
            seek_progress: None,
            garden_species: crate::state::DEFAULT_SPECIES.to_owned(),
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
    let portrait = is_portrait(ui.max_rect().size());
    state.panel_rects.clear();
    let top = egui::Panel::top("sylva top bar").show(ui, |ui| {
        ui.horizontal(|ui| {
            for (tab, name) in [
                (Tab::Tree, "Tree"),
                (Tab::Advanced, "Advanced"),
                (Tab::Scale, "Scale"),
                (Tab::Garden, "Garden"),
                (Tab::Export, "Export"),
                (Tab::Recreate, "Recreate a tree"),
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
            Tab::Tree => plain::tree_ui(ui, &mut params, &state.species_names),
            Tab::Advanced => plain::advanced_ui(ui, &mut params),
            Tab::Scale => scale_ui::scale_ui(ui, &mut state.known_length_m, design, events),
            Tab::Recreate => recreate_ui::recreate_ui(ui, design, &state.species_names, events),
            Tab::Garden => garden_ui::garden_ui(
                ui,
                &mut state.garden_species,
                &state.species_names,
                design,
                events,
            ),
            Tab::Export => {
                if ui.button("Export tree (.glb, .json)").clicked() {
                    state.export_requested = true;
                }
            }
        }
    });
    state.panel_rects.push(top.response.rect);
    if portrait {
        // Docked at the bottom, the secondary controls folded away until asked for.
        let bottom = egui::Panel::bottom("sylva phone bar").show(ui, |ui| {
            tools_ui::tool_selector_ui(ui, design, false, events);
            ui.horizontal_wrapped(|ui| {
                grow_buttons_ui(ui, design, events);
                play_button_ui(ui, state);
                let more = if state.more_controls { "Less" } else { "More" };
                if ui.add(egui::Button::new(more).min_size(FINGER)).clicked() {
                    state.more_controls = !state.more_controls;
                }
            });
            if state.more_controls {
                ui.horizontal_wrapped(|ui| brush_sliders_ui(ui, &mut params, false));
                playback_ui(ui, state, false);
            }
        });
        state.panel_rects.push(bottom.response.rect);
    } else {
        let side = egui::Panel::right("sylva side bar")
            .exact_size(SIDE_BAR_WIDTH_PT)
            .show(ui, |ui| {
                ui.vertical_centered(|ui| {
                    ui.label("Tools");
                    tools_ui::tool_selector_ui(ui, design, true, events);
                    ui.separator();
                    brush_sliders_ui(ui, &mut params, true);
                    grow_buttons_ui(ui, design, events);
                });
            });
        state.panel_rects.push(side.response.rect);
        let bottom =
            egui::Panel::bottom("sylva playback").show(ui, |ui| playback_ui(ui, state, true));
        state.panel_rects.push(bottom.response.rect);
    }
    if params != design.params {
        events.push(InputEvent::Parameters { parameters: params });
    }
    let view = ui.available_rect_before_wrap();
    tools_ui::tool_overlays_ui(ui, design, view);
    garden_ui::garden_overlay_ui(ui, design, view);
    overlays_ui(ui, state, view);
    scale_ui::overlay_ui(ui, design, view);
    scale_ui::status_line_ui(ui, design, view);
    recreate_ui::recreate_overlay_ui(ui, design, view);
    view
}

/// The season beside the years slider: one button per season (winter shows deciduous trees
/// leafless).
pub(crate) fn season_ui(ui: &mut Ui, season: &mut Season) {
    ui.horizontal(|ui| {
        ui.label("Season:");
        for s in Season::ALL {
            ui.selectable_value(season, s, s.name());
        }
    });
}

/// Width of the side bar on landscape screens, points.
pub const SIDE_BAR_WIDTH_PT: f32 = 120.0;

/// Whether a screen of `size` points is held upright (or too narrow for a side bar): the
/// controls then dock at the bottom.
pub fn is_portrait(size: egui::Vec2) -> bool {
    size.x < size.y || size.x < 5.0 * SIDE_BAR_WIDTH_PT
}

/// A fingertip-tall button.
const FINGER: egui::Vec2 = egui::vec2(0.0, 0.75 * tools_ui::TOOL_BUTTON_SIZE_PT);

/// Brush radius and grow speed: `vertical` sliders in the side bar, horizontal ones in a
/// phone's bottom bar.
fn brush_sliders_ui(ui: &mut Ui, params: &mut crate::state::Parameters, vertical: bool) {
    fn slider(slider: egui::Slider<'_>, vertical: bool) -> egui::Slider<'_> {
        if vertical { slider.vertical() } else { slider }
    }
    if vertical {
        ui.spacing_mut().slider_width = 80.0;
        ui.label("Brush size");
    }
    ui.add(slider(
        egui::Slider::new(&mut params.brush_radius, 0.02..=0.5).text("Brush radius"),
        vertical,
    ));
    if vertical {
        ui.separator();
        ui.label("Grow (up) / ungrow (down)");
    }
    ui.add(slider(
        egui::Slider::new(&mut params.grow_speed, -20.0..=20.0).text("Grow speed"),
        vertical,
    ));
}

/// Grow, ungrow and undo.
fn grow_buttons_ui(ui: &mut Ui, design: &DesignState, events: &mut Vec<InputEvent>) {
    if ui.add(egui::Button::new("Grow").min_size(FINGER)).clicked() {
        events.push(InputEvent::Grow { iterations: 1 });
    }
    if ui
        .add(egui::Button::new("Ungrow").min_size(FINGER))
        .clicked()
    {
        events.push(InputEvent::Grow { iterations: -1 });
    }
    let undo = ui.add_enabled(
        design.undo_depth() > 0,
        egui::Button::new(RichText::new("Undo").size(18.0)).min_size(FINGER),
    );
    if undo.clicked() {
        events.push(InputEvent::Undo);
    }
}

fn play_button_ui(ui: &mut Ui, state: &mut UiState) {
    let label = if state.playing { "Pause" } else { "Play" };
    if ui.add(egui::Button::new(label).min_size(FINGER)).clicked() {
        state.playing = !state.playing;
    }
}

/// Play/pause (unless `with_play` is false: a phone's bar has it already), the frame slider and
/// the view switches.
fn playback_ui(ui: &mut Ui, state: &mut UiState, with_play: bool) {
    ui.horizontal_wrapped(|ui| {
        if with_play {
            play_button_ui(ui, state);
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
    let seeking = state
        .seek_progress
        .map(|(shown, sought)| format!("Seeking to frame {sought}: tracking frame {shown}..."));
    let hint = if let Some(seeking) = seeking.as_deref() {
        Some(seeking)
    } else if !state.ground_found {
        Some("Move the phone slowly to find the ground...")
    } else if !state.planted {
        Some("Tap the ground where the tree should stand")
    } else {
        None
    };
    if let Some(hint) = hint {
        painter.rect_filled(
            egui::Rect::from_center_size(view.center(), egui::vec2(360.0, 60.0)),
            8.0,
            Color32::from_black_alpha(160),
        );
        painter.text(
            view.center(),
            Align2::CENTER_CENTER,
            hint,
            egui::FontId::proportional(18.0),
            Color32::WHITE,
        );
    }
    let b = state.budget;
    let text = format!(
        "tracking {:.1} ms · growth {:.1} ms · meshing {:.1} ms · render {:.1} ms",
        b.tracking_ms, b.growth_ms, b.meshing_ms, b.render_ms
    );
    // Light text on a dark plate: readable over paving and lawn alike.
    let galley = painter.layout_no_wrap(text, egui::FontId::monospace(13.0), Color32::WHITE);
    let plate = Align2::LEFT_BOTTOM.anchor_size(
        view.left_bottom() + egui::vec2(6.0, -6.0),
        galley.size() + egui::vec2(8.0, 4.0),
    );
    painter.rect_filled(plate, 4.0, Color32::from_black_alpha(170));
    painter.galley(plate.min + egui::vec2(4.0, 2.0), galley, Color32::WHITE);
}
