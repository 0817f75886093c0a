//! Species: every parameter of the growth model, as data.
//!
//! Presets are JSON files in `core/species/`, embedded in the binary with `include_str!`; users
//! add their own with [`Species::from_file`]. Units are in field names (`_m`, `_deg`, `_years`,
//! `_internodes`); each field's doc gives the symbol used by Longay 2014 ch. 4 and
//! Pałubicki et al. 2009.

use std::path::Path;
use std::sync::OnceLock;

use serde::{Deserialize, Serialize};

use crate::environment::MAX_SHADOW_DEPTH_VOXELS;
use crate::geometry::Looks;
use crate::growth::TreeMetrics;

/// Arrangement of lateral buds along an axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phyllotaxis {
    /// One bud per node, alternating sides (180°).
    Distichous,
    /// One bud per node, each turned by the phyllotactic angle φ.
    Spiral,
    /// Two opposite buds per node, pairs turned by 90°.
    Decussate,
    /// k buds per node, evenly spaced, whorls turned by φ.
    Whorled,
}

/// Control ellipse of gravimorphism (Longay 2014 fig. 4.20), in the plane ⟂ the parent axis.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ControlEllipse {
    /// s_v: semi-axis along V (the most vertical direction ⟂ H).
    pub vertical_semi_axis: f32,
    /// s_p: semi-axis along P (parallel to the ground).
    pub parallel_semi_axis: f32,
    /// e_v: offset of the centre along V (> 0 favours upper-side buds).
    pub vertical_offset: f32,
}

/// Expected size of the species, from a cited horticultural reference.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExpectedSize {
    pub height_10y_m: f32,
    pub spread_10y_m: f32,
    pub height_30y_m: f32,
    pub spread_30y_m: f32,
    /// The reference(s) the figures come from, by name.
    pub source: String,
    /// Trunk diameter at breast height of an open-grown tree, with its own source; `None` in
    /// files that state none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub trunk_diameter: Option<ExpectedTrunk>,
}

/// Height above the ground at which trunk diameters are stated (breast height), metres.
pub const BREAST_HEIGHT_M: f32 = 1.3;

/// The range of trunk diameters at breast height ([`BREAST_HEIGHT_M`]) an open-grown tree of the
/// species reaches at 15, 30 and 40 years: `[least, most]`, metres.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExpectedTrunk {
    pub at_15y_m: [f32; 2],
    pub at_30y_m: [f32; 2],
    pub at_40y_m: [f32; 2],
    /// The reference(s) the ranges come from, by name.
    pub source: String,
}

/// Apical control that changes with age: λ moves smoothly (smoothstep) from the species'
/// `apical_dominance` (young) to `mature_apical_dominance` between the two ages. An oak is
/// excurrent when young and decurrent when mature: its leader loses dominance and several limbs
/// co-dominate.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ApicalDominanceWithAge {
    /// λ from `to_age_years` on.
    pub mature_apical_dominance: f32,
    /// Age until which λ keeps its young value, years.
    pub from_age_years: f32,
    /// Age from which λ has its mature value, years.
    pub to_age_years: f32,
    /// Why these values, with the reference(s) by name.
    pub notes: String,
}

impl ExpectedTrunk {
    /// (age in years, [least, most] diameter in metres) of each stated range.
    pub fn ranges(&self) -> [(f32, [f32; 2]); 3] {
        [
            (15.0, self.at_15y_m),
            (30.0, self.at_30y_m),
            (40.0, self.at_40y_m),
        ]
    }

    fn validate(&self) -> Result<(), String> {
        for (age, [least, most]) in self.ranges() {
            if !(least.is_finite()
                && most.is_finite()
                && 0.0 < least
                && least <= most
                && most <= 5.0)
            {
                return Err(format!(
                    "expected.trunk_diameter.at_{age}y_m must be [least, most] metres with \
                     0 < least <= most <= 5, got [{least}, {most}]"
                ));
            }
        }
        Ok(())
    }
}

impl ExpectedSize {
    /// Each stated figure beside the grown tree's: (what, measured, expected), metres.
    pub fn against(
        &self,
        at_10_years: &TreeMetrics,
        at_30_years: &TreeMetrics,
    ) -> [(&'static str, f32, f32); 4] {
        [
            (
                "height at 10 years",
                at_10_years.height_m,
                self.height_10y_m,
            ),
            (
                "spread at 10 years",
                at_10_years.crown_width_m,
                self.spread_10y_m,
            ),
            (
                "height at 30 years",
                at_30_years.height_m,
                self.height_30y_m,
            ),
            (
                "spread at 30 years",
                at_30_years.crown_width_m,
                self.spread_30y_m,
            ),
        ]
    }
}

/// All parameters of one species.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Species {
    /// Short identifier used on the command line (`birch`).
    pub name: String,
    pub common_name: String,
    pub latin_name: String,
    /// What the preset should look like.
    pub description: String,
    pub expected: ExpectedSize,
    /// Years represented by one growth iteration (one season = 1).
    pub years_per_iteration: f32,
    /// l: length of every internode, metres.
    pub internode_length_m: f32,
    /// n_max: internodes in the shoot of the most vigorous bud of an iteration.
    pub max_shoot_internodes: f32,
    /// Age at which n_max has halved (n_max·h/(h + age)); 0 keeps n_max constant.
    pub shoot_length_halving_age_years: f32,
    /// λ: apical dominance, share of vigor biased to the main axis (0.5 = neutral).
    pub apical_dominance: f32,
    /// λ changing with age (see [`Species::apical_dominance_at`]); absent keeps
    /// `apical_dominance` for the tree's whole life.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub apical_dominance_with_age: Option<ApicalDominanceWithAge>,
    /// κ: light sensitivity, Q = b·L^κ (0 = space alone decides).
    pub light_sensitivity: f32,
    /// α: weight of the current heading (straightness).
    pub straightness: f32,
    /// β: weight of the tropism direction T.
    pub tropism_weight: f32,
    /// γ: weight of the environment (optimal growth) direction E.
    pub environment_weight: f32,
    /// θ: gravitropic set-point angle from vertical (0 up, 90 horizontal, > 90 downwards).
    pub gravitropism_angle_deg: f32,
    /// The main axis (order 0) keeps an upward tropism while laterals use θ (conifers).
    pub upward_main_axis: bool,
    /// Axes of branch order below this, the scaffold (the trunk and the main limbs), use the
    /// set-point angle θ_s instead of θ; 0 (the default) gives every axis θ. Different branches
    /// of one tree keep different set-point angles (Longay 2014 §4.4.2, after Hallé et al.):
    /// a weeping tree raises a dome of ascending limbs from which its twigs hang.
    #[serde(default, skip_serializing_if = "crate::is_default")]
    pub scaffold_orders: u32,
    /// θ_s: gravitropic set-point angle of the scaffold axes (see `scaffold_orders`).
    #[serde(default, skip_serializing_if = "crate::is_default")]
    pub scaffold_gravitropism_angle_deg: f32,
    /// ψ: angle between a lateral bud and its supporting axis.
    pub branching_angle_deg: f32,
    pub phyllotaxis: Phyllotaxis,
    /// φ: turn between successive nodes (spiral, whorled).
    pub phyllotactic_angle_deg: f32,
    /// k: buds per whorl (whorled phyllotaxis only).
    pub buds_per_whorl: u32,
    /// Years a lateral bud stays able to break; older dormant buds die (0 = forever). Keeps the
    /// competition for space to the young periphery of the crown, as in real trees.
    #[serde(default)]
    pub bud_lifetime_years: f32,
    /// Lateral buds only on the last internode of each shoot (rhythmic whorls of conifers).
    pub lateral_buds_only_at_shoot_end: bool,
    /// δ: deflection of the supporting axis away from a growing lateral bud.
    pub deflection_angle_deg: f32,
    /// r: radius of a bud's occupancy sphere, internode lengths.
    pub occupancy_radius_internodes: f32,
    /// d: perception distance beyond r, internode lengths (perception radius r + d).
    pub perception_distance_internodes: f32,
    /// ζ: full apex angle of the perception cone.
    pub perception_angle_deg: f32,
    /// Autonomous points a fully lit bud generates per iteration (a shaded one generates 1).
    pub max_points_per_bud: u32,
    /// Edge of a shadow voxel, internode lengths.
    pub shadow_voxel_internodes: f32,
    /// a: shadow a node adds to its own voxel.
    pub shadow_strength: f32,
    /// b: decay base of shadow with depth, Δs = a·b^(−q) (b > 1).
    pub shadow_decay_base: f32,
    /// q_max: depth of the shadow pyramid, voxels.
    pub shadow_depth_voxels: u32,
    /// C: full light exposure.
    pub full_exposure: f32,
    /// Gravimorphism control ellipse (s_v, s_p, e_v).
    pub gravimorphism: ControlEllipse,
    /// Th: a branch whose vigor per internode (vigor in new internodes, v·n_max/v_max, divided by
    /// its size) falls below Th is shed; 0 never sheds.
    pub shedding_threshold: f32,
    /// d_e: diameter of a tip internode, metres.
    pub tip_diameter_m: f32,
    /// n: pipe-model exponent, d^n = Σ d_i^n (re-solved below width constraints).
    pub pipe_exponent: f32,
    /// Leaves, bark and fruit; read it through [`Species::looks`]. `None` in files from before
    /// looks were data: such a species looks like the preset of its name, as it always did, or
    /// else like a generic broadleaf ([`Looks::default`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub looks: Option<Looks>,
}

/// A species file that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum SpeciesError {
    #[error("cannot read species file {path}: {source}")]
    Read {
        path: String,
        source: std::io::Error,
    },
    #[error("species file {path} is not a valid species: {reason}")]
    Parse { path: String, reason: String },
    #[error("species {name} ({path}): {reason}")]
    Invalid {
        path: String,
        name: String,
        reason: String,
    },
    #[error("no species preset named {name:?}; presets: {known}")]
    UnknownPreset { name: String, known: String },
}

const PRESET_FILES: [(&str, &str); 6] = [
    ("birch.json", include_str!("../species/birch.json")),
    ("oak.json", include_str!("../species/oak.json")),
    ("maple.json", include_str!("../species/maple.json")),
    (
        "norway_spruce.json",
        include_str!("../species/norway_spruce.json"),
    ),
    (
        "weeping_willow.json",
        include_str!("../species/weeping_willow.json"),
    ),
    (
        "lombardy_poplar.json",
        include_str!("../species/lombardy_poplar.json"),
    ),
];

/// The most branch orders a scaffold may span (far beyond any tree's main limbs).
pub const MAX_SCAFFOLD_ORDERS: u32 = 16;

/// The smallest internode and shadow voxel a species may have, metres.
pub const MIN_VOXEL_M: f32 = 0.02;

impl Species {
    /// All built-in presets, in a fixed order.
    pub fn presets() -> Vec<Species> {
        PRESET_FILES
            .iter()
            .filter_map(|(file, text)| Self::from_json_str(text, file).ok())
            .collect()
    }

    /// The preset called `name` (case-insensitive; `-` and spaces read as `_`).
    pub fn by_name(name: &str) -> Result<Species, SpeciesError> {
        let wanted = name.trim().to_lowercase().replace(['-', ' '], "_");
        let presets = Self::presets();
        if let Some(s) = presets.iter().find(|s| s.name == wanted) {
            return Ok(s.clone());
        }
        let known = presets
            .iter()
            .map(|s| s.name.as_str())
            .collect::<Vec<_>>()
            .join(", ");
        Err(SpeciesError::UnknownPreset {
            name: name.to_string(),
            known,
        })
    }

    /// Loads and validates a user species file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Species, SpeciesError> {
        let path = path.as_ref();
        let shown = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|source| SpeciesError::Read {
            path: shown.clone(),
            source,
        })?;
        Self::from_json_str(&text, &shown)
    }

    /// Parses and validates species JSON; `origin` names the source in errors.
    pub fn from_json_str(text: &str, origin: &str) -> Result<Species, SpeciesError> {
        let species: Species = serde_json::from_str(text).map_err(|e| SpeciesError::Parse {
            path: origin.to_string(),
            reason: e.to_string(),
        })?;
        species.validate().map_err(|reason| SpeciesError::Invalid {
            path: origin.to_string(),
            name: species.name.clone(),
            reason,
        })?;
        Ok(species)
    }

    /// Checks ranges; the message names the offending parameter.
    pub fn validate(&self) -> Result<(), String> {
        // Positive values, each inside bounds far beyond any tree (a file outside them is
        // damaged: a micron voxel or a million-year season would stall growth); the least
        // positive f32 stands for "more than 0".
        let tiny = f32::MIN_POSITIVE;
        let positive = [
            ("years_per_iteration", self.years_per_iteration, 0.01, 100.0),
            (
                "internode_length_m",
                self.internode_length_m,
                MIN_VOXEL_M,
                10.0,
            ),
            (
                "max_shoot_internodes",
                self.max_shoot_internodes,
                tiny,
                200.0,
            ),
            (
                "occupancy_radius_internodes",
                self.occupancy_radius_internodes,
                tiny,
                100.0,
            ),
            (
                "perception_distance_internodes",
                self.perception_distance_internodes,
                tiny,
                100.0,
            ),
            (
                "shadow_voxel_internodes",
                self.shadow_voxel_internodes,
                tiny,
                100.0,
            ),
            ("shadow_strength", self.shadow_strength, tiny, 1e3),
            ("full_exposure", self.full_exposure, tiny, 1e3),
            ("tip_diameter_m", self.tip_diameter_m, 1e-4, 1.0),
            ("pipe_exponent", self.pipe_exponent, 1.0, 10.0),
            (
                "gravimorphism.vertical_semi_axis",
                self.gravimorphism.vertical_semi_axis,
                tiny,
                100.0,
            ),
            (
                "gravimorphism.parallel_semi_axis",
                self.gravimorphism.parallel_semi_axis,
                tiny,
                100.0,
            ),
        ];
        for (name, v, lo, hi) in positive {
            if !(v.is_finite() && (lo..=hi).contains(&v)) {
                return Err(format!(
                    "{name} must be a positive number from {lo} to {hi}, got {v}"
                ));
            }
        }
        let voxel = self.internode_length_m * self.shadow_voxel_internodes;
        if voxel < MIN_VOXEL_M {
            return Err(format!(
                "internode_length_m × shadow_voxel_internodes (the shadow voxel) must be at \
                 least {MIN_VOXEL_M} m, got {voxel}"
            ));
        }
        let ranges = [
            (
                "shoot_length_halving_age_years",
                self.shoot_length_halving_age_years,
                0.0,
                1e6,
            ),
            ("apical_dominance", self.apical_dominance, 0.0, 1.0),
            ("light_sensitivity", self.light_sensitivity, 0.0, 20.0),
            ("straightness", self.straightness, 0.0, 1.0),
            ("tropism_weight", self.tropism_weight, 0.0, 1.0),
            ("environment_weight", self.environment_weight, 0.0, 1.0),
            (
                "gravitropism_angle_deg",
                self.gravitropism_angle_deg,
                0.0,
                180.0,
            ),
            (
                "scaffold_gravitropism_angle_deg",
                self.scaffold_gravitropism_angle_deg,
                0.0,
                180.0,
            ),
            ("branching_angle_deg", self.branching_angle_deg, 0.0, 180.0),
            (
                "phyllotactic_angle_deg",
                self.phyllotactic_angle_deg,
                -360.0,
                360.0,
            ),
            ("deflection_angle_deg", self.deflection_angle_deg, 0.0, 90.0),
            (
                "perception_angle_deg",
                self.perception_angle_deg,
                1.0,
                360.0,
            ),
            ("shadow_decay_base", self.shadow_decay_base, 1.0001, 1e3),
            ("shedding_threshold", self.shedding_threshold, 0.0, 1e3),
            (
                "gravimorphism.vertical_offset",
                self.gravimorphism.vertical_offset,
                -10.0,
                10.0,
            ),
            (
                "max_shoot_internodes",
                self.max_shoot_internodes,
                0.0,
                200.0,
            ),
        ];
        for (name, v, lo, hi) in ranges {
            if !(v.is_finite() && (lo..=hi).contains(&v)) {
                return Err(format!("{name} must lie in [{lo}, {hi}], got {v}"));
            }
        }
        let sum = self.straightness + self.tropism_weight + self.environment_weight;
        if (sum - 1.0).abs() > 1e-3 {
            return Err(format!(
                "straightness α + tropism_weight β + environment_weight γ must be 1, got {sum}"
            ));
        }
        if self.shadow_depth_voxels > MAX_SHADOW_DEPTH_VOXELS {
            return Err(format!(
                "shadow_depth_voxels must be at most {MAX_SHADOW_DEPTH_VOXELS}, got {}",
                self.shadow_depth_voxels
            ));
        }
        if self.phyllotaxis == Phyllotaxis::Whorled && !(1..=12).contains(&self.buds_per_whorl) {
            return Err(format!(
                "buds_per_whorl must be 1..=12 for whorled phyllotaxis, got {}",
                self.buds_per_whorl
            ));
        }
        if self.scaffold_orders > MAX_SCAFFOLD_ORDERS {
            return Err(format!(
                "scaffold_orders must be at most {MAX_SCAFFOLD_ORDERS}, got {}",
                self.scaffold_orders
            ));
        }
        if !(1..=64).contains(&self.max_points_per_bud) {
            return Err(format!(
                "max_points_per_bud must be 1..=64, got {}",
                self.max_points_per_bud
            ));
        }
        if let Some(trunk) = &self.expected.trunk_diameter {
            trunk.validate()?;
        }
        if let Some(a) = &self.apical_dominance_with_age {
            let name = "apical_dominance_with_age";
            let m = a.mature_apical_dominance;
            if !(m.is_finite() && (0.0..=1.0).contains(&m)) {
                return Err(format!(
                    "{name}.mature_apical_dominance must lie in [0, 1], got {m}"
                ));
            }
            let (from, to) = (a.from_age_years, a.to_age_years);
            if !(from.is_finite() && to.is_finite() && 0.0 <= from && from < to && to <= 1e4) {
                return Err(format!(
                    "{name}: from_age_years and to_age_years must satisfy \
                     0 <= from_age_years < to_age_years <= 10000, got {from} and {to}"
                ));
            }
        }
        match &self.looks {
            Some(looks) => looks.validate(),
            None => Ok(()),
        }
    }

    /// λ at `age_years`: `apical_dominance`, or with `apical_dominance_with_age` a smoothstep
    /// from it to the mature value between the two ages.
    pub fn apical_dominance_at(&self, age_years: f32) -> f32 {
        let young = self.apical_dominance;
        let Some(a) = &self.apical_dominance_with_age else {
            return young;
        };
        let t =
            ((age_years - a.from_age_years) / (a.to_age_years - a.from_age_years)).clamp(0.0, 1.0);
        young + (a.mature_apical_dominance - young) * t * t * (3.0 - 2.0 * t)
    }

    /// How the species looks: its own `looks`, or for a file without them the look of the
    /// preset of its name, or a generic broadleaf.
    pub fn looks(&self) -> &Looks {
        static PRESET_LOOKS: OnceLock<Vec<(String, Looks)>> = OnceLock::new();
        static GENERIC: OnceLock<Looks> = OnceLock::new();
        if let Some(looks) = &self.looks {
            return looks;
        }
        let presets = PRESET_LOOKS.get_or_init(|| {
            Species::presets()
                .into_iter()
                .filter_map(|s| s.looks.map(|looks| (s.name, looks)))
                .collect()
        });
        presets
            .iter()
            .find(|(name, _)| *name == self.name)
            .map(|(_, looks)| looks)
            .unwrap_or_else(|| GENERIC.get_or_init(Looks::default))
    }

    /// Lateral buds per node implied by the phyllotaxis.
    pub fn buds_per_node(&self) -> u32 {
        match self.phyllotaxis {
            Phyllotaxis::Distichous | Phyllotaxis::Spiral => 1,
            Phyllotaxis::Decussate => 2,
            Phyllotaxis::Whorled => self.buds_per_whorl,
        }
    }

    /// Growth iterations covering `years` (rounded to the nearest iteration).
    pub fn iterations_for_years(&self, years: f32) -> u32 {
        (years / self.years_per_iteration).round().max(0.0) as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn all_six_presets_load_and_validate() {
        let names: Vec<String> = Species::presets().into_iter().map(|s| s.name).collect();
        assert_eq!(
            names,
            [
                "birch",
                "oak",
                "maple",
                "norway_spruce",
                "weeping_willow",
                "lombardy_poplar"
            ]
        );
        for (file, text) in PRESET_FILES {
            if let Err(e) = Species::from_json_str(text, file) {
                panic!("{e}");
            }
        }
    }

    #[test]
    fn unknown_preset_and_bad_parameters_are_named_in_errors() {
        let err = Species::by_name("baobab").unwrap_err().to_string();
        assert!(err.contains("baobab") && err.contains("birch"), "{err}");
        let mut birch = Species::by_name("Birch").unwrap();
        birch.straightness = 0.9;
        let text = serde_json::to_string(&birch).unwrap();
        let err = Species::from_json_str(&text, "mine.json")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("mine.json") && err.contains("straightness"),
            "{err}"
        );
        let err = Species::from_json_str("{\"name\": 3}", "x.json")
            .unwrap_err()
            .to_string();
        assert!(err.contains("x.json"), "{err}");
    }

    #[test]
    fn apical_dominance_moves_smoothly_from_young_to_mature_and_is_constant_without_the_field() {
        let mut birch = Species::by_name("birch").unwrap();
        birch.apical_dominance_with_age = None;
        let young = birch.apical_dominance;
        for age in [0.0, 10.0, 40.0, 500.0] {
            assert_eq!(birch.apical_dominance_at(age).to_bits(), young.to_bits());
        }
        birch.apical_dominance = 0.6;
        birch.apical_dominance_with_age = Some(ApicalDominanceWithAge {
            mature_apical_dominance: 0.4,
            from_age_years: 10.0,
            to_age_years: 30.0,
            notes: String::new(),
        });
        assert_eq!(birch.apical_dominance_at(5.0), 0.6);
        assert_eq!(birch.apical_dominance_at(10.0), 0.6);
        assert!((birch.apical_dominance_at(20.0) - 0.5).abs() < 1e-6);
        assert_eq!(birch.apical_dominance_at(30.0), 0.4);
        assert_eq!(birch.apical_dominance_at(80.0), 0.4);
        let lambdas: Vec<f32> = (0..=40)
            .map(|a| birch.apical_dominance_at(a as f32))
            .collect();
        assert!(lambdas.windows(2).all(|w| w[1] <= w[0]), "{lambdas:?}");
        // Smooth: no step larger than the linear ramp's 0.01 a year times smoothstep's 1.5.
        assert!(
            lambdas.windows(2).all(|w| w[0] - w[1] <= 0.0151),
            "{lambdas:?}"
        );
    }

    #[test]
    fn a_bad_apical_dominance_with_age_is_named_in_the_error() {
        let mut oak = Species::by_name("oak").unwrap();
        let good = ApicalDominanceWithAge {
            mature_apical_dominance: 0.5,
            from_age_years: 20.0,
            to_age_years: 35.0,
            notes: String::new(),
        };
        let bad = [
            (1.5, 20.0, 35.0, "mature_apical_dominance"),
            (0.5, 35.0, 20.0, "to_age_years"),
            (0.5, -1.0, 20.0, "from_age_years"),
        ];
        for (m, from, to, named) in bad {
            oak.apical_dominance_with_age = Some(ApicalDominanceWithAge {
                mature_apical_dominance: m,
                from_age_years: from,
                to_age_years: to,
                ..good.clone()
            });
            let text = serde_json::to_string(&oak).unwrap();
            let err = Species::from_json_str(&text, "mine.json")
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("mine.json")
                    && err.contains("apical_dominance_with_age")
                    && err.contains(named),
                "{err}"
            );
        }
        oak.apical_dominance_with_age = Some(good);
        let text = serde_json::to_string(&oak).unwrap();
        assert!(Species::from_json_str(&text, "mine.json").is_ok());
    }
}
