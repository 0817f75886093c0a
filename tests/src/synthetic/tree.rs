//! A real-looking tree for the synthetic garden, made by a stochastic branching grammar (not
//! Sylva's growth model, so recreating it measures Sylva against something it did not make).
//!
//! The grammar, in L-system terms (Prusinkiewicz & Lindenmayer 1990, ch. 2 and 3):
//!
//! ```text
//! Leader(h)      → Wood(s) [roll 137.5° · Scaffold(ℓ(h))]? Leader(h + s)   while h < H
//!                → Cluster                                                   at the top
//! Scaffold(ℓ, k) → Wood(s) [±Branch(ℓ·q, k + 1)]? Scaffold(ℓ − s, k)          while ℓ > 0
//!                → Cluster
//! ```
//!
//! Every production draws its angles, lengths and whether the bracketed lateral appears from a
//! seeded generator. A scaffold's length follows the crown profile `ℓ(h)` (an ovoid between the
//! crown base and the top), so the crown has a shape a landscaper would recognise. Wood is
//! capsules with a pipe-model taper; foliage is leaf clusters (spheres) at the tips and along the
//! outer part of each branch. World space: metres, Y up, the trunk base at the origin.

use glam::{Vec2, Vec3};
use serde::Serialize;

use super::rng::SplitMix64;
use super::texture;
use super::tree_bvh::{Bvh, Primitive, TreeHit};

/// What shapes a grammar tree.
#[derive(Clone, Debug, Serialize)]
pub struct TreeParams {
    pub seed: u64,
    /// Height of the leader's top (m); the foliage on it reaches a little higher.
    pub leader_height_m: f32,
    /// Height of the lowest scaffold branch (m): the clear trunk below it.
    pub first_branch_m: f32,
    /// Longest scaffold branch (m), at the crown profile's widest point.
    pub max_branch_m: f32,
    /// Where along the crown (0 = lowest branch, 1 = top) the profile is widest.
    pub widest_at: f32,
    /// Scaffold branches' angle from the vertical at their base (degrees).
    pub branch_angle_deg: f32,
    /// Vertical spacing of scaffold branches along the leader (m).
    pub branch_spacing_m: f32,
    pub trunk_radius_m: f32,
    /// Leaf cluster radius range (m).
    pub cluster_radius_m: (f32, f32),
    /// Horizontal squash of the crown along X (1 = round; below 1 narrower along X).
    pub squash_x: f32,
}

impl TreeParams {
    /// Tree A: a broad, rounded deciduous tree about 3 m tall.
    pub fn tree_a() -> Self {
        Self {
            seed: 31,
            leader_height_m: 2.45,
            first_branch_m: 0.95,
            max_branch_m: 1.15,
            widest_at: 0.35,
            branch_angle_deg: 58.0,
            branch_spacing_m: 0.14,
            trunk_radius_m: 0.075,
            cluster_radius_m: (0.14, 0.21),
            squash_x: 0.9,
        }
    }

    /// Tree B: a narrower, ovoid tree about 3.3 m tall.
    pub fn tree_b() -> Self {
        Self {
            seed: 77,
            leader_height_m: 2.75,
            first_branch_m: 1.2,
            max_branch_m: 0.85,
            widest_at: 0.45,
            branch_angle_deg: 48.0,
            branch_spacing_m: 0.13,
            trunk_radius_m: 0.07,
            cluster_radius_m: (0.13, 0.19),
            squash_x: 1.1,
        }
    }
}

/// What a tree primitive is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TreePart {
    Wood,
    Foliage,
}

/// The true measures of a tree, as a surveyor would take them (written to `tree_truth.json`).
#[derive(Clone, Debug, Serialize)]
pub struct TreeTruth {
    pub trunk_base: [f32; 3],
    /// Ground to the highest point of the tree (m).
    pub height_m: f32,
    /// Largest horizontal extent of the crown (m).
    pub crown_width_m: f32,
    /// The crown's horizontal extents along the direction of the largest one and across it (m).
    pub crown_axes_m: [f32; 2],
    /// Direction (degrees from +X towards +Z) of the largest extent.
    pub crown_axis_deg: f32,
    /// Height of the lowest foliage (m).
    pub crown_base_m: f32,
    pub num_wood: usize,
    pub num_clusters: usize,
}

/// A grammar tree: its primitives in a bounding volume hierarchy.
#[derive(Clone, Debug)]
pub struct SynthTree {
    pub params: TreeParams,
    pub bvh: Bvh,
}

struct Grower<'a> {
    params: &'a TreeParams,
    rng: SplitMix64,
    primitives: Vec<Primitive>,
}

const SEGMENT_M: f32 = 0.16;
const GOLDEN_ANGLE_RAD: f32 = 2.399_963;

impl Grower<'_> {
    fn range(&mut self, low: f32, high: f32) -> f32 {
        low + (high - low) * self.rng.next_f32()
    }

    fn wood(&mut self, a: Vec3, b: Vec3, radius_m: f32) {
        self.primitives.push(Primitive::capsule(a, b, radius_m));
    }

    fn cluster(&mut self, centre: Vec3, scale: f32) {
        let (low, high) = self.params.cluster_radius_m;
        let radius = self.range(low, high) * scale;
        self.primitives.push(Primitive::sphere(centre, radius));
    }

    /// Crown profile: scaffold length at relative height `s` (0 = lowest branch, 1 = top).
    fn profile(&self, s: f32) -> f32 {
        let w = self.params.widest_at.clamp(0.05, 0.95);
        let shape = if s < w {
            (1.0 - ((w - s) / w).powi(2)).sqrt()
        } else {
            1.0 - ((s - w) / (1.0 - w)).powf(1.6)
        };
        self.params.max_branch_m * (0.35 + 0.65 * shape.max(0.0))
    }

    fn leader(&mut self) {
        let p = self.params.clone();
        let mut at = Vec3::ZERO;
        let mut heading = Vec3::Y;
        let mut roll = self.range(0.0, std::f32::consts::TAU);
        let mut next_branch_m = p.first_branch_m;
        while at.y < p.leader_height_m {
            let s = (at.y / p.leader_height_m).clamp(0.0, 1.0);
            let radius = p.trunk_radius_m * (1.0 - 0.75 * s);
            let wobble = Vec3::new(self.range(-0.08, 0.08), 0.0, self.range(-0.08, 0.08));
            heading = (heading + wobble + Vec3::Y * 0.3).normalize();
            let end = at + heading * SEGMENT_M;
            self.wood(at, end, radius);
            at = end;
            while at.y >= next_branch_m && next_branch_m < p.leader_height_m - 0.15 {
                roll += GOLDEN_ANGLE_RAD + self.range(-0.3, 0.3);
                let crown_s = (next_branch_m - p.first_branch_m)
                    / (p.leader_height_m - p.first_branch_m).max(0.1);
                let length = self.profile(crown_s) * self.range(0.8, 1.1);
                let tilt = (p.branch_angle_deg + self.range(-8.0, 8.0) - 25.0 * crown_s)
                    .to_radians()
                    .max(0.2);
                let direction =
                    Vec3::new(roll.cos() * tilt.sin(), tilt.cos(), roll.sin() * tilt.sin());
                self.branch(at, direction, length, radius * 0.55, 1);
                next_branch_m += p.branch_spacing_m * self.range(0.8, 1.2);
            }
        }
        self.cluster(at + Vec3::Y * 0.08, 1.15);
    }

    /// A branch of `order` from `start` along `direction`, `length_m` long.
    fn branch(&mut self, start: Vec3, direction: Vec3, length_m: f32, radius_m: f32, order: u32) {
        let mut at = start;
        let mut heading = direction.normalize();
        let mut done_m = 0.0;
        let mut side = if self.rng.next_f32() < 0.5 { 1.0 } else { -1.0 };
        while done_m < length_m {
            let s = done_m / length_m;
            let step = SEGMENT_M.min(length_m - done_m).max(0.03);
            // Upward tropism, stronger on the thin outer parts; a little random bending.
            let bend = Vec3::new(
                self.range(-0.12, 0.12),
                self.range(-0.05, 0.1),
                self.range(-0.12, 0.12),
            );
            heading = (heading + bend + Vec3::Y * 0.06 * (order as f32)).normalize();
            let end = at + heading * step;
            let radius = (radius_m * (1.0 - 0.7 * s)).max(0.006);
            self.wood(at, end, radius);
            at = end;
            done_m += step;
            if order < 3 && s > 0.2 && self.rng.next_f32() < 0.55 {
                let across = heading.cross(Vec3::Y).try_normalize().unwrap_or(Vec3::X);
                let lateral = (heading * 0.6 + across * side * 0.8 + Vec3::Y * 0.25).normalize();
                side = -side;
                let child_length = (length_m - done_m) * self.range(0.45, 0.7) + 0.15;
                self.branch(at, lateral, child_length, radius * 0.6, order + 1);
            }
            if s > 0.3 && self.rng.next_f32() < 0.6 {
                self.cluster(at, 0.9);
            }
        }
        self.cluster(at, 1.0);
    }
}

impl SynthTree {
    /// Grows the grammar tree of `params` (deterministic from its seed).
    pub fn new(params: TreeParams) -> Self {
        let mut grower = Grower {
            params: &params,
            rng: SplitMix64::new(params.seed ^ 0x7ee5),
            primitives: Vec::new(),
        };
        grower.leader();
        let squash = params.squash_x;
        let primitives = grower
            .primitives
            .into_iter()
            .map(|p| p.squashed_x(squash))
            .collect();
        Self {
            params,
            bvh: Bvh::build(primitives),
        }
    }

    /// The true measures, from the primitives themselves.
    pub fn truth(&self) -> TreeTruth {
        let primitives = self.bvh.primitives();
        let height_m = primitives
            .iter()
            .map(|p| p.bounds().1.y)
            .fold(0.0, f32::max);
        let clusters: Vec<&Primitive> = primitives
            .iter()
            .filter(|p| p.part() == TreePart::Foliage)
            .collect();
        let crown_base_m = clusters
            .iter()
            .map(|p| p.bounds().0.y)
            .fold(f32::INFINITY, f32::min);
        // The crown: foliage, and the wood above the crown base.
        let crown: Vec<&Primitive> = primitives
            .iter()
            .filter(|p| p.part() == TreePart::Foliage || p.bounds().0.y >= crown_base_m)
            .collect();
        let extent_along = |angle: f32| {
            let axis = Vec3::new(angle.cos(), 0.0, angle.sin());
            let (mut low, mut high) = (f32::INFINITY, f32::NEG_INFINITY);
            for p in &crown {
                let (centre, reach) = p.extent_along(axis);
                low = low.min(centre - reach);
                high = high.max(centre + reach);
            }
            high - low
        };
        let (mut best_deg, mut crown_width_m) = (0.0, 0.0);
        for step in 0..360 {
            let deg = step as f32 * 0.5;
            let extent = extent_along(deg.to_radians());
            if extent > crown_width_m {
                (best_deg, crown_width_m) = (deg, extent);
            }
        }
        let across = extent_along((best_deg + 90.0_f32).to_radians());
        TreeTruth {
            trunk_base: [0.0; 3],
            height_m,
            crown_width_m,
            crown_axes_m: [crown_width_m, across],
            crown_axis_deg: best_deg,
            crown_base_m,
            num_wood: primitives.len() - clusters.len(),
            num_clusters: clusters.len(),
        }
    }
}

/// Linear albedo of a tree hit: furrowed bark on wood; on foliage, leaves (ellipses in 5 cm
/// cells, each its own green) over dark gaps between them, prefiltered by the pixel footprint
/// like the garden's textures so corners hold still from frame to frame.
pub fn albedo(hit: &TreeHit, footprint_m: f32, seed: u32) -> Vec3 {
    let salt = hit.primitive.wrapping_mul(0x9e37_79b9);
    match hit.part {
        TreePart::Wood => {
            let p = hit.surface_m;
            let furrows = texture::fbm(
                Vec2::new(p.x * 9.0, p.y * 1.2),
                seed ^ 0xba4c,
                6.0,
                5,
                footprint_m,
            );
            let patches = texture::fbm(p, seed ^ salt ^ 0x1b, 3.0, 3, footprint_m);
            let bark = Vec3::new(0.20, 0.15, 0.11).lerp(Vec3::new(0.42, 0.36, 0.30), patches);
            bark * (0.45 + 1.0 * furrows)
        }
        TreePart::Foliage => {
            const CELL_M: f32 = 0.05;
            let q = hit.surface_m / CELL_M;
            let cell = q.floor();
            let (ix, iy) = (cell.x as i32, cell.y as i32);
            let cell_seed = seed ^ salt ^ 0x1eaf;
            let centre = Vec2::new(
                0.3 + 0.4 * texture::hash01(ix, iy, cell_seed),
                0.3 + 0.4 * texture::hash01(ix, iy, cell_seed ^ 0x11),
            );
            let angle = std::f32::consts::PI * texture::hash01(ix, iy, cell_seed ^ 0x22);
            let d = q - cell - centre;
            let (c, s) = (angle.cos(), angle.sin());
            let local = Vec2::new(c * d.x + s * d.y, -s * d.x + c * d.y);
            let distance_m = Vec2::new(local.x / 0.48, local.y / 0.28).length() * CELL_M * 0.5;
            let soft = 0.5 * footprint_m.max(1e-4);
            let leaf =
                1.0 - texture::smoothstep(0.25 * CELL_M - soft, 0.25 * CELL_M + soft, distance_m);
            let tint = texture::hash01(ix, iy, cell_seed ^ 0x33);
            let green = Vec3::new(0.06, 0.22, 0.04).lerp(Vec3::new(0.30, 0.50, 0.10), tint);
            let veins = texture::fbm(q, cell_seed ^ 0x44, 2.0, 3, footprint_m / CELL_M);
            let gap = Vec3::new(0.015, 0.04, 0.012);
            // Far away the leaves blend into their mean: the cell pattern fades with footprint.
            let cover = texture::smoothstep(CELL_M * 0.6, CELL_M * 0.25, footprint_m);
            let near = gap.lerp(green * (0.8 + 0.4 * veins), leaf);
            let far = gap.lerp(Vec3::new(0.18, 0.36, 0.07), 0.45);
            far.lerp(near, cover)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grammar_trees_have_a_clear_trunk_below_a_full_crown() {
        for params in [TreeParams::tree_a(), TreeParams::tree_b()] {
            let truth = SynthTree::new(params.clone()).truth();
            assert!(
                (2.8..4.5).contains(&truth.height_m),
                "height {} m",
                truth.height_m
            );
            assert!(
                (0.6..1.6).contains(&truth.crown_base_m),
                "crown base {} m",
                truth.crown_base_m
            );
            assert!(
                (1.2..3.5).contains(&truth.crown_width_m),
                "crown width {} m",
                truth.crown_width_m
            );
            assert!(truth.num_clusters > 40, "{} clusters", truth.num_clusters);
        }
    }

    #[test]
    fn the_mask_top_row_is_where_the_true_height_projects() {
        use crate::synthetic::render::{MASK_FOLIAGE, Pinhole, render_tree_mask};
        let tree = SynthTree::new(TreeParams::tree_a());
        let truth = tree.truth();
        let camera = Pinhole::tum_default(320, 240);
        // Level camera 8 m away on +Z looking at the tree (camera Y down, Z forward = −Z).
        let rotation = glam::Mat3::from_cols(Vec3::X, Vec3::NEG_Y, Vec3::NEG_Z);
        let pose = glam::Affine3A::from_mat3_translation(rotation, Vec3::new(0.0, 1.6, 8.0));
        let mask = render_tree_mask(&tree, &camera, &pose);
        let top_row = (0..240)
            .find(|&r| (0..320).any(|c| mask[r * 320 + c] == MASK_FOLIAGE))
            .expect("foliage in view");
        // The highest point lies within the crown's half-width of the trunk axis in depth.
        let row_at = |depth_m: f32| camera.cy - camera.fy * (truth.height_m - 1.6) / depth_m;
        let (near, far) = (
            row_at(8.0 - 0.5 * truth.crown_width_m),
            row_at(8.0 + 0.5 * truth.crown_width_m),
        );
        assert!(
            (near - 1.0..=far + 1.0).contains(&(top_row as f32)),
            "top row {top_row}, the true height projects to rows {near:.1}..{far:.1}"
        );
    }

    #[test]
    fn the_same_seed_grows_the_same_tree() {
        let a = SynthTree::new(TreeParams::tree_a()).truth();
        let b = SynthTree::new(TreeParams::tree_a()).truth();
        assert_eq!(a.height_m, b.height_m);
        assert_eq!(a.num_wood, b.num_wood);
    }
}
