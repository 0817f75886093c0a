//! Plain-language controls: what a landscaper asks of a tree, each mapped onto the model's
//! parameters ([`Parameters`], whose recorded fields stay as they are), and the "Advanced" panel
//! that keeps the research parameters with their symbols, angles in degrees.
//!
//! | control | model parameter |
//! |---|---|
//! | crown shape, upright −1 ↔ spreading 0 ↔ weeping 1 | θ, the gravitropic set-point, 0° → 90° → 180° |
//! | density, sparse 0 ↔ dense 1 | Th, the shedding threshold, [`SPARSE_SHEDDING_THRESHOLD`] → 0 |
//! | branch angle, degrees | ψ, the branching angle |
//! | vigour, 0 ↔ 1 | n_max, the longest shoot, 1 → [`MAX_SHOOT_INTERNODES`] internodes |
//! | straightness, 0 ↔ 1 | α, the weight of the current heading (β and γ share the rest) |
//! | flat crown, depth limit (m) | the depth constraint (appendix B), facing the view |

use egui::Ui;

use super::widgets;
use crate::state::Parameters;

/// The shedding threshold of the sparsest crown the density control offers.
pub const SPARSE_SHEDDING_THRESHOLD: f32 = 0.1;
/// The longest shoot (internodes per year) the vigour control offers.
pub const MAX_SHOOT_INTERNODES: f32 = 20.0;

/// Crown shape from −1 (upright) through 0 (spreading) to 1 (weeping).
pub fn crown_shape(params: &Parameters) -> f32 {
    (params.tropism_angle.to_degrees() / 90.0 - 1.0).clamp(-1.0, 1.0)
}

/// Sets the crown shape: the branches' set-point angle θ from vertical, 0° (upright) through
/// 90° (spreading) to 180° (weeping).
pub fn set_crown_shape(params: &mut Parameters, shape: f32) {
    params.tropism_angle = ((shape.clamp(-1.0, 1.0) + 1.0) * 90.0).to_radians();
}

/// Density from 0 (sparse: weak branches are shed) to 1 (dense: none is).
pub fn density(params: &Parameters) -> f32 {
    (1.0 - params.shedding_threshold / SPARSE_SHEDDING_THRESHOLD).clamp(0.0, 1.0)
}

pub fn set_density(params: &mut Parameters, density: f32) {
    params.shedding_threshold = SPARSE_SHEDDING_THRESHOLD * (1.0 - density.clamp(0.0, 1.0));
}

/// Vigour from 0 (one internode a year at most) to 1 ([`MAX_SHOOT_INTERNODES`]).
pub fn vigour(params: &Parameters) -> f32 {
    ((params.max_shoot_length - 1.0) / (MAX_SHOOT_INTERNODES - 1.0)).clamp(0.0, 1.0)
}

pub fn set_vigour(params: &mut Parameters, vigour: f32) {
    params.max_shoot_length = 1.0 + (MAX_SHOOT_INTERNODES - 1.0) * vigour.clamp(0.0, 1.0);
}

/// Straightness from 0 to 1: the weight α of a shoot's current heading.
pub fn straightness(params: &Parameters) -> f32 {
    params.direction_weights[0].clamp(0.0, 1.0)
}

/// Sets α; the environment and tropism weights β, γ keep their ratio and share the rest, so
/// α + β + γ stays 1.
pub fn set_straightness(params: &mut Parameters, straightness: f32) {
    let alpha = straightness.clamp(0.0, 1.0);
    let [_, beta, gamma] = params.direction_weights;
    let rest = beta + gamma;
    let (beta_share, gamma_share) = if rest > 0.0 {
        (beta / rest, gamma / rest)
    } else {
        (0.5, 0.5)
    };
    params.direction_weights = [
        alpha,
        (1.0 - alpha) * beta_share,
        (1.0 - alpha) * gamma_share,
    ];
}

/// A value shown in degrees and kept in radians.
fn degrees_slider_ui(ui: &mut Ui, radians: &mut f32, max_deg: f32, text: &str) {
    let mut degrees = radians.to_degrees();
    if ui
        .add(egui::Slider::new(&mut degrees, 0.0..=max_deg).text(text))
        .changed()
    {
        *radians = degrees.to_radians();
    }
}

/// A plain control over a mapped value: `set` runs only when the slider moves, so merely
/// showing the panel never rewrites a parameter.
fn mapped_slider_ui(
    ui: &mut Ui,
    params: &mut Parameters,
    text: &str,
    range: std::ops::RangeInclusive<f32>,
    get: fn(&Parameters) -> f32,
    set: fn(&mut Parameters, f32),
) {
    let mut value = get(params);
    if ui
        .add(egui::Slider::new(&mut value, range).text(text))
        .changed()
    {
        set(params, value);
    }
}

/// The primary panel: species, age in years and the plain-language crown controls.
pub fn tree_ui(ui: &mut Ui, params: &mut Parameters, species_names: &[String]) {
    ui.horizontal_wrapped(|ui| {
        egui::ComboBox::from_label("Species")
            .selected_text(params.species.clone())
            .show_ui(ui, |ui| {
                for name in species_names {
                    ui.selectable_value(&mut params.species, name.clone(), name);
                }
            });
        ui.add(egui::Slider::new(&mut params.years, 1.0..=40.0).text("Age (years)"));
        super::season_ui(ui, &mut params.season);
    });
    ui.horizontal_wrapped(|ui| {
        ui.label("Crown shape");
        let shape = crown_shape(params);
        for (value, name) in [(-1.0, "Upright"), (0.0, "Spreading"), (1.0, "Weeping")] {
            if ui
                .selectable_label((shape - value).abs() < 0.05, name)
                .clicked()
            {
                set_crown_shape(params, value);
            }
        }
        mapped_slider_ui(
            ui,
            params,
            "Crown: upright to weeping",
            -1.0..=1.0,
            crown_shape,
            set_crown_shape,
        );
    });
    ui.horizontal_wrapped(|ui| {
        mapped_slider_ui(ui, params, "Density", 0.0..=1.0, density, set_density);
        degrees_slider_ui(ui, &mut params.branching_angle, 90.0, "Branch angle (°)");
        mapped_slider_ui(ui, params, "Vigour", 0.0..=1.0, vigour, set_vigour);
        mapped_slider_ui(
            ui,
            params,
            "Straightness",
            0.0..=1.0,
            straightness,
            set_straightness,
        );
    });
    ui.horizontal_wrapped(|ui| {
        ui.label("Scene:");
        for choice in crate::planting::SceneChoice::ALL {
            ui.selectable_value(&mut params.scene_mode, choice, choice.label());
        }
    });
    depth_tool_ui(ui, params);
}

/// Default half-depth when the depth limit is switched on, metres.
const DEFAULT_DEPTH_LIMIT_M: f32 = 0.3;

/// The depth tool: a flat crown, within a depth of the plane through the base facing the view.
fn depth_tool_ui(ui: &mut Ui, params: &mut Parameters) {
    ui.horizontal_wrapped(|ui| {
        let mut flat = params.depth_constraint_m.is_some();
        if ui
            .checkbox(&mut flat, "Flat crown (depth limit facing the view)")
            .changed()
        {
            params.depth_constraint_m = flat.then_some(DEFAULT_DEPTH_LIMIT_M);
        }
        if let Some(depth) = params.depth_constraint_m.as_mut() {
            ui.add(egui::Slider::new(depth, 0.05..=3.0).text("Depth limit (m)"));
        }
    });
}

/// The research parameters (Longay 2014 ch. 4), with their symbols; angles in degrees.
pub fn advanced_ui(ui: &mut Ui, params: &mut Parameters) {
    ui.horizontal(|ui| {
        ui.vertical(|ui| {
            ui.label("α β γ");
            widgets::weights_triangle_ui(ui, &mut params.direction_weights);
        });
        ui.vertical(|ui| {
            ui.label(format!(
                "θ tropism {:.0}°",
                params.tropism_angle.to_degrees()
            ));
            widgets::tropism_arrow_ui(ui, &mut params.tropism_angle);
        });
        ui.vertical(|ui| {
            ui.label("Gravimorphism");
            widgets::gravimorphism_ellipse_ui(ui, &mut params.gravimorphism);
        });
        ui.vertical(|ui| {
            degrees_slider_ui(
                ui,
                &mut params.branching_angle,
                90.0,
                "ψ branching angle (°)",
            );
            degrees_slider_ui(
                ui,
                &mut params.deflection_angle,
                45.0,
                "δ deflection angle (°)",
            );
            ui.add(
                egui::Slider::new(&mut params.apical_dominance, 0.0..=1.0)
                    .text("λ apical dominance"),
            );
            ui.add(
                egui::Slider::new(&mut params.light_sensitivity, 0.0..=2.0)
                    .text("κ light sensitivity"),
            );
            ui.add(
                egui::Slider::new(&mut params.shedding_threshold, 0.0..=1.0)
                    .text("Th shedding threshold"),
            );
            ui.add(
                egui::Slider::new(&mut params.max_shoot_length, 1.0..=MAX_SHOOT_INTERNODES)
                    .text("n_max shoot length"),
            );
            ui.checkbox(
                &mut params.sketch_tropism,
                "Tropism from the stroke direction",
            );
        });
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_plain_control_reads_back_what_it_set() {
        let mut params = Parameters::default();
        for value in [0.0, 0.3, 1.0] {
            set_density(&mut params, value);
            assert!((density(&params) - value).abs() < 1e-5);
            set_vigour(&mut params, value);
            assert!((vigour(&params) - value).abs() < 1e-5);
            set_straightness(&mut params, value);
            assert!((straightness(&params) - value).abs() < 1e-5);
            set_crown_shape(&mut params, 2.0 * value - 1.0);
            assert!((crown_shape(&params) - (2.0 * value - 1.0)).abs() < 1e-5);
        }
        params.check().expect("the controls make valid parameters");
    }

    #[test]
    fn straightness_keeps_the_direction_weights_summing_to_one_in_their_ratio() {
        let mut params = Parameters::default();
        let [_, beta, gamma] = params.direction_weights;
        set_straightness(&mut params, 0.8);
        let [a, b, g] = params.direction_weights;
        assert!((a + b + g - 1.0).abs() < 1e-5);
        assert!((b / g - beta / gamma).abs() < 1e-4);
        assert!((crown_shape(&params) - crown_shape(&Parameters::default())).abs() < 1e-6);
    }
}
