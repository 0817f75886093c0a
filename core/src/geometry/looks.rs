//! The appearance of a species, as data: leaf shape, size, density and colour in each season,
//! bark colour and texture, fruit. It is the `looks` object of a species file
//! ([`crate::species::Species::looks`]); fields a `looks` object leaves out are those of a
//! generic broadleaf ([`Looks::default`]), and a file from before looks were data looks like
//! the preset of its name, as it always did (or like the generic broadleaf). Growth parameters live in
//! [`crate::species`]; these only affect the meshes and textures.

use std::fmt;
use std::str::FromStr;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::{FruitParams, LeafParams, MeshParams, ShortShoots};
use crate::growth::Tree;
use crate::species::Species;

/// The season a tree is shown in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Season {
    Spring,
    #[default]
    Summer,
    Autumn,
    /// Deciduous trees stand leafless; evergreens keep their leaves.
    Winter,
}

impl Season {
    pub const ALL: [Season; 4] = [
        Season::Spring,
        Season::Summer,
        Season::Autumn,
        Season::Winter,
    ];

    /// The lower-case name used on the command line and in files.
    pub fn name(self) -> &'static str {
        match self {
            Season::Spring => "spring",
            Season::Summer => "summer",
            Season::Autumn => "autumn",
            Season::Winter => "winter",
        }
    }
}

impl fmt::Display for Season {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Season {
    type Err = String;

    /// A season by name, case-insensitive; `fall` reads as autumn.
    fn from_str(text: &str) -> Result<Season, String> {
        let wanted = text.trim().to_lowercase();
        if wanted == "fall" {
            return Ok(Season::Autumn);
        }
        Season::ALL
            .into_iter()
            .find(|s| s.name() == wanted)
            .ok_or_else(|| {
                format!("no season named {text:?}; seasons: spring, summer, autumn, winter")
            })
    }
}

/// The outline of a leaf blade, drawn by [`super::textures::leaf_texture`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LeafShape {
    /// A plain elliptic blade (the generic broadleaf).
    #[default]
    Elliptic,
    /// Rounded lobes in pairs along the blade, widest beyond the middle (oak).
    Lobed,
    /// Five pointed lobes spreading from the base like a hand (maple).
    Palmate,
    /// Small, ovate, pointed, with a toothed edge (birch).
    OvateSerrate,
    /// Long, narrow, tapering to both ends (willow).
    Lanceolate,
    /// A triangle with a broad base and a drawn-out tip (poplar).
    Deltoid,
    /// A shoot set with needles on both sides (spruce, other conifers).
    Needles,
}

/// The pattern of a bark texture, drawn by [`super::textures::bark_texture`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BarkKind {
    /// Vertical ridges between deep dark furrows (oak, willow, poplar).
    #[default]
    Furrowed,
    /// Pale, smooth and papery with dark horizontal lenticels and black diamond scars (birch).
    Papery,
    /// Small rounded plates flaking off (spruce).
    Scaly,
    /// Shallow, finely interlacing ridges (maple).
    FineRidged,
}

/// Linear RGB of the leaves in each season; `winter` is used only by evergreens.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SeasonColors {
    pub spring: [f32; 3],
    pub summer: [f32; 3],
    pub autumn: [f32; 3],
    pub winter: [f32; 3],
}

impl Default for SeasonColors {
    fn default() -> Self {
        SeasonColors {
            spring: [0.24, 0.46, 0.08],
            summer: [0.14, 0.34, 0.06],
            autumn: [0.45, 0.3, 0.05],
            winter: [0.1, 0.25, 0.05],
        }
    }
}

/// The bark: texture pattern, linear RGB, and a darker base of the trunk.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BarkLook {
    pub kind: BarkKind,
    pub color: [f32; 3],
    /// The trunk is darker from the ground up to this many trunk base diameters (an old birch's
    /// black, fissured foot); 0 for none. It is baked into the shade of the trunk's vertices.
    pub dark_base_diameters: f32,
    /// Shade of the trunk at the ground within the dark base (1 = not darker), rising to 1 at
    /// its top.
    pub dark_base_shade: f32,
}

impl Default for BarkLook {
    fn default() -> Self {
        BarkLook {
            kind: BarkKind::Furrowed,
            color: [0.25, 0.2, 0.15],
            dark_base_diameters: 0.0,
            dark_base_shade: 1.0,
        }
    }
}

/// Fruit: linear RGB, radius and the seasons it hangs on the tree.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FruitLook {
    pub color: [f32; 3],
    pub radius_m: f32,
    #[serde(default = "FruitLook::default_seasons")]
    pub seasons: Vec<Season>,
}

impl FruitLook {
    fn default_seasons() -> Vec<Season> {
        vec![Season::Summer, Season::Autumn]
    }
}

/// How a species looks. Every field may be left out of a species file (the generic
/// broadleaf's value is used) or overridden in a user's own file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Looks {
    pub leaf_shape: LeafShape,
    /// Blade length along the petiole, metres.
    pub leaf_length: f32,
    /// Blade width, metres.
    pub leaf_width: f32,
    /// Leaves per metre of leaf-bearing branch.
    pub leaves_per_metre: f32,
    /// Leaves on branches thinner than this many tip diameters (`tip_diameter_m`).
    pub leafy_diameters: f32,
    /// Angle between a leaf-bearing branch and its leaves' petioles (or a spray card's axis),
    /// degrees; `None` for the generic 52° (0.9 rad). Left out of saved files when `None`, so
    /// trees saved before the field keep their bytes (and their hashes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub leaf_insertion_deg: Option<f32>,
    /// Leaves drawn on one card (a spray of small leaves, a needle shoot; see
    /// [`super::leaf_card`]).
    pub leaves_per_card: u32,
    /// The fine shoots that carry the leaves off their branches ([`super::ShortShoots`]):
    /// their length, metres (0, the default, keeps leaves on the branch)...
    #[serde(skip_serializing_if = "crate::is_default")]
    pub short_shoot_length_m: f32,
    /// ... and their set-point angle from vertical, degrees (0 up, 90 level, 180 hanging).
    #[serde(skip_serializing_if = "crate::is_default")]
    pub short_shoot_angle_deg: f32,
    /// Branches up to this many tip diameters (beyond `leafy_diameters`) bear leafy spurs
    /// along them, at `spur_leaves_per_metre`; 0 (the default) for none.
    #[serde(skip_serializing_if = "crate::is_default")]
    pub spur_diameters: f32,
    #[serde(skip_serializing_if = "crate::is_default")]
    pub spur_leaves_per_metre: f32,
    /// Keeps its leaves in winter (conifers); deciduous trees stand leafless.
    pub evergreen: bool,
    pub leaf_color: SeasonColors,
    pub bark: BarkLook,
    /// `None` (or `null`) for a species without visible fruit.
    pub fruit: Option<FruitLook>,
}

impl Default for Looks {
    fn default() -> Self {
        Looks {
            leaf_shape: LeafShape::Elliptic,
            leaf_length: 0.09,
            leaf_width: 0.06,
            leaves_per_metre: 120.0,
            leafy_diameters: 10.0,
            leaf_insertion_deg: None,
            leaves_per_card: 8,
            short_shoot_length_m: 0.0,
            short_shoot_angle_deg: 0.0,
            spur_diameters: 0.0,
            spur_leaves_per_metre: 0.0,
            evergreen: false,
            leaf_color: SeasonColors::default(),
            bark: BarkLook::default(),
            fruit: None,
        }
    }
}

impl Looks {
    /// Checks every value is finite and in range; the message names the field
    /// (`looks.leaf_length`).
    pub fn validate(&self) -> Result<(), String> {
        let mut numbers = vec![
            ("looks.leaf_length", self.leaf_length, 0.001, 2.0),
            ("looks.leaf_width", self.leaf_width, 0.0005, 2.0),
            ("looks.leaves_per_metre", self.leaves_per_metre, 0.0, 2000.0),
            ("looks.leafy_diameters", self.leafy_diameters, 1.0, 1000.0),
            (
                "looks.short_shoot_length_m",
                self.short_shoot_length_m,
                0.0,
                5.0,
            ),
            (
                "looks.short_shoot_angle_deg",
                self.short_shoot_angle_deg,
                0.0,
                180.0,
            ),
            ("looks.spur_diameters", self.spur_diameters, 0.0, 1000.0),
            (
                "looks.spur_leaves_per_metre",
                self.spur_leaves_per_metre,
                0.0,
                2000.0,
            ),
            (
                "looks.bark.dark_base_diameters",
                self.bark.dark_base_diameters,
                0.0,
                100.0,
            ),
            (
                "looks.bark.dark_base_shade",
                self.bark.dark_base_shade,
                0.0,
                1.0,
            ),
        ];
        if let Some(fruit) = &self.fruit {
            numbers.push(("looks.fruit.radius_m", fruit.radius_m, 0.001, 0.5));
        }
        if let Some(angle) = self.leaf_insertion_deg {
            numbers.push(("looks.leaf_insertion_deg", angle, 0.0, 180.0));
        }
        for (name, v, lo, hi) in numbers {
            if !(v.is_finite() && (lo..=hi).contains(&v)) {
                return Err(format!(
                    "{name} must be a number from {lo} to {hi}, got {v}"
                ));
            }
        }
        let max_card = super::leaf_card::MAX_LEAVES_PER_CARD;
        if !(1..=max_card).contains(&self.leaves_per_card) {
            return Err(format!(
                "looks.leaves_per_card must be a whole number from 1 to {max_card}, got {}",
                self.leaves_per_card
            ));
        }
        let c = &self.leaf_color;
        let mut colors = vec![
            ("looks.leaf_color.spring", c.spring),
            ("looks.leaf_color.summer", c.summer),
            ("looks.leaf_color.autumn", c.autumn),
            ("looks.leaf_color.winter", c.winter),
            ("looks.bark.color", self.bark.color),
        ];
        if let Some(fruit) = &self.fruit {
            colors.push(("looks.fruit.color", fruit.color));
        }
        for (name, rgb) in colors {
            if !rgb.iter().all(|v| v.is_finite() && (0.0..=1.0).contains(v)) {
                return Err(format!(
                    "{name} must be linear RGB with each channel from 0 to 1, got {rgb:?}"
                ));
            }
        }
        Ok(())
    }

    /// The leaf colour in `season`; `None` when the tree is leafless then.
    pub fn leaf_color_in(&self, season: Season) -> Option<[f32; 3]> {
        let c = &self.leaf_color;
        match season {
            Season::Spring => Some(c.spring),
            Season::Summer => Some(c.summer),
            Season::Autumn => Some(c.autumn),
            Season::Winter => self.evergreen.then_some(c.winter),
        }
    }

    /// The fruit in `season`, if it hangs on the tree then.
    pub fn fruit_in(&self, season: Season) -> Option<&FruitLook> {
        self.fruit.as_ref().filter(|f| f.seasons.contains(&season))
    }
}

/// Mesh parameters giving `species` its summer look.
pub fn mesh_params_for(species: &Species) -> MeshParams {
    mesh_params_in(species, Season::Summer)
}

/// Mesh parameters giving `species` its look in `season`: its leaves (none on a deciduous tree
/// in winter) in that season's colour, its bark and its fruit of the season.
pub fn mesh_params_in(species: &Species, season: Season) -> MeshParams {
    let look = species.looks();
    let defaults = MeshParams::default();
    let leaf_color = look.leaf_color_in(season);
    let fruit = look.fruit_in(season);
    MeshParams {
        leaves: LeafParams {
            max_branch_diameter: species.tip_diameter_m * look.leafy_diameters,
            leaves_per_metre: if leaf_color.is_some() {
                look.leaves_per_metre
            } else {
                0.0
            },
            length: look.leaf_length,
            width: look.leaf_width,
            leaves_per_card: look.leaves_per_card,
            petiole_length: 0.3 * look.leaf_length,
            insertion_angle: look
                .leaf_insertion_deg
                .map_or(LeafParams::default().insertion_angle, f32::to_radians),
            short_shoots: ShortShoots {
                length: look.short_shoot_length_m,
                angle_from_vertical: look.short_shoot_angle_deg.to_radians(),
                max_spur_branch_diameter: species.tip_diameter_m * look.spur_diameters,
                spur_leaves_per_metre: if leaf_color.is_some() {
                    look.spur_leaves_per_metre
                } else {
                    0.0
                },
            },
            ..LeafParams::default()
        },
        fruit: fruit.map(|f| FruitParams {
            radius: f.radius_m,
            max_branch_diameter: species.tip_diameter_m * 2.5,
            ..FruitParams::default()
        }),
        bark_color: look.bark.color,
        bark_kind: look.bark.kind,
        leaf_color: leaf_color.unwrap_or(look.leaf_color.summer),
        leaf_shape: look.leaf_shape,
        fruit_color: fruit.map_or(defaults.fruit_color, |f| f.color),
        ..defaults
    }
}

/// Share of the shadow grid's shade a leafless crown keeps: bare deciduous crowns pass roughly
/// 50–80% of the light, crowns in leaf 2–10%, so about a third of the shade is the wood's.
pub const LEAFLESS_SHADE_KEPT: f32 = 0.35;

/// The shade a mesh vertex at a world point gets: the ambient light of the tree's shadow grid
/// ([`Tree::ambient_at`]), lighter in a leafless crown ([`LEAFLESS_SHADE_KEPT`]), darkened on
/// the trunk's dark base when the species has one (the points of the trunk's own axis below
/// the base's top, where its rings sample the shade).
pub struct TreeShade<'a> {
    tree: &'a Tree,
    /// Share of the grid's shade kept: 1 in leaf.
    shade_kept: f32,
    /// Trunk axis points within the dark base and their shade, lowest first.
    dark_base: Vec<(Vec3, f32)>,
    top_y: f32,
}

impl<'a> TreeShade<'a> {
    /// The shade of `tree` in leaf.
    pub fn new(tree: &'a Tree) -> Self {
        Self::in_season(tree, Season::Summer)
    }

    /// The shade of `tree` in `season` (lighter when the tree is leafless then).
    pub fn in_season(tree: &'a Tree, season: Season) -> Self {
        let bark = &tree.species.looks().bark;
        let skeleton = &tree.skeleton;
        let mut dark_base = Vec::new();
        let mut top_y = f32::NEG_INFINITY;
        if let (Some(root), true) = (skeleton.internodes.first(), bark.dark_base_diameters > 0.0) {
            let ground_y = root.start.y;
            let height = bark.dark_base_diameters * root.diameter;
            top_y = ground_y + height;
            let shade_at = |y: f32| {
                let t = ((y - ground_y) / height).clamp(0.0, 1.0);
                bark.dark_base_shade + (1.0 - bark.dark_base_shade) * t
            };
            dark_base.push((root.start, shade_at(root.start.y)));
            let mut node = root;
            loop {
                dark_base.push((node.end, shade_at(node.end.y)));
                match node.main_child {
                    Some(child) if node.end.y <= top_y => node = skeleton.get(child),
                    _ => break,
                }
            }
        }
        let leafless = tree.species.looks().leaf_color_in(season).is_none();
        TreeShade {
            tree,
            shade_kept: if leafless { LEAFLESS_SHADE_KEPT } else { 1.0 },
            dark_base,
            top_y,
        }
    }

    /// The shade at `point_in_world`, 0..1.
    pub fn at(&self, point_in_world: Vec3) -> f32 {
        let ambient = 1.0 - (1.0 - self.tree.ambient_at(point_in_world)) * self.shade_kept;
        if point_in_world.y > self.top_y {
            return ambient;
        }
        match self.dark_base.iter().find(|(p, _)| *p == point_in_world) {
            Some(&(_, shade)) => ambient * shade,
            None => ambient,
        }
    }
}

/// Meshes of a grown tree with its species' summer look, shaded by [`TreeShade`].
pub fn build_tree_meshes(tree: &Tree) -> super::TreeMeshes {
    build_tree_meshes_in(tree, Season::Summer)
}

/// Meshes of a grown tree with its species' look in `season`, shaded by [`TreeShade`].
pub fn build_tree_meshes_in(tree: &Tree, season: Season) -> super::TreeMeshes {
    let shade = TreeShade::in_season(tree, season);
    let params = mesh_params_in(&tree.species, season);
    super::build_meshes(&tree.skeleton, &params, &|p| shade.at(p))
}

/// Meshes of a grown tree with its species' summer look at level of detail `level` only (see
/// [`super::build_level`]): what a renderer draws.
pub fn build_tree_level(tree: &Tree, level: usize) -> super::TreeMeshes {
    let params = mesh_params_for(&tree.species);
    let shade = TreeShade::new(tree);
    super::build_level(&tree.skeleton, &params, &|p| shade.at(p), level)
}

/// Meshes of a grown tree with explicit parameters, shaded by [`TreeShade`] (in leaf).
pub fn build_tree_meshes_with(tree: &Tree, params: &MeshParams) -> super::TreeMeshes {
    let shade = TreeShade::new(tree);
    super::build_meshes(&tree.skeleton, params, &|p| shade.at(p))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seasons_read_from_their_names_and_refuse_others_by_name() {
        for season in Season::ALL {
            assert_eq!(season.name().parse::<Season>(), Ok(season));
        }
        assert_eq!(" Autumn ".parse::<Season>(), Ok(Season::Autumn));
        assert_eq!("fall".parse::<Season>(), Ok(Season::Autumn));
        let err = "monsoon".parse::<Season>().unwrap_err();
        assert!(err.contains("monsoon") && err.contains("winter"), "{err}");
    }

    #[test]
    fn deciduous_trees_are_leafless_in_winter_and_evergreens_are_not() {
        let deciduous = Looks::default();
        assert_eq!(deciduous.leaf_color_in(Season::Winter), None);
        let evergreen = Looks {
            evergreen: true,
            ..Looks::default()
        };
        assert_eq!(
            evergreen.leaf_color_in(Season::Winter),
            Some(evergreen.leaf_color.winter)
        );
        for season in [Season::Spring, Season::Summer, Season::Autumn] {
            assert!(deciduous.leaf_color_in(season).is_some(), "{season}");
        }
    }

    #[test]
    fn bad_look_values_are_refused_naming_the_field() {
        type Damage = fn(&mut Looks);
        let cases: [(&str, Damage); 8] = [
            ("looks.leaf_length", |l| l.leaf_length = f32::NAN),
            ("looks.short_shoot_angle_deg", |l| {
                l.short_shoot_angle_deg = 200.0
            }),
            ("looks.spur_leaves_per_metre", |l| {
                l.spur_leaves_per_metre = -5.0
            }),
            ("looks.leaf_insertion_deg", |l| {
                l.leaf_insertion_deg = Some(200.0)
            }),
            ("looks.leaves_per_metre", |l| l.leaves_per_metre = -1.0),
            ("looks.leafy_diameters", |l| l.leafy_diameters = 0.5),
            ("looks.leaf_color.autumn", |l| l.leaf_color.autumn[0] = 3.0),
            ("looks.fruit.radius_m", |l| {
                l.fruit = Some(FruitLook {
                    color: [0.3, 0.2, 0.1],
                    radius_m: f32::INFINITY,
                    seasons: vec![Season::Autumn],
                })
            }),
        ];
        assert_eq!(Looks::default().validate(), Ok(()));
        for (field, damage) in cases {
            let mut looks = Looks::default();
            damage(&mut looks);
            let err = looks.validate().unwrap_err();
            assert!(err.contains(field), "{field}: {err}");
        }
    }

    #[test]
    fn a_partial_looks_object_takes_the_rest_from_the_generic_broadleaf() {
        let looks: Looks =
            serde_json::from_str(r#"{"leaf_shape": "palmate", "bark": {"kind": "scaly"}}"#)
                .expect("parses");
        assert_eq!(looks.leaf_shape, LeafShape::Palmate);
        assert_eq!(looks.bark.kind, BarkKind::Scaly);
        assert_eq!(looks.bark.color, BarkLook::default().color);
        assert_eq!(looks.leaf_length, Looks::default().leaf_length);
        let err = serde_json::from_str::<Looks>(r#"{"leaf_shap": "palmate"}"#).unwrap_err();
        assert!(err.to_string().contains("leaf_shap"), "{err}");
    }

    #[test]
    fn a_stated_leaf_insertion_angle_reaches_the_leaves_and_none_keeps_the_generic_one() {
        let mut species = Species::by_name("oak").expect("a preset");
        let generic = mesh_params_for(&species).leaves.insertion_angle;
        assert_eq!(generic, LeafParams::default().insertion_angle);
        let mut looks = species.looks().clone();
        looks.leaf_insertion_deg = Some(15.0);
        species.looks = Some(looks);
        let stated = mesh_params_for(&species).leaves.insertion_angle;
        assert!((stated - 15f32.to_radians()).abs() < 1e-6, "{stated}");
    }
}
