//! Leaves and fruit (Longay 2014, appendices C.1 and C.2).
//!
//! Leaves sit on every branch thinner than a threshold, at a density and size of their own
//! (C.1.1), in a phyllotactic spiral. Each leaf hangs from a petiole, an inextensible rod whose
//! frame H, L, U turns at the rates (C.1.2)
//! Ω_H = −e_H L·T (twist), Ω_L = e_L H·T (bend), Ω_U = e_U L·(T × (H × T)) (turn),
//! integrated proximal to distal in steps Δs; the blade at its end lies in the H–L plane with
//! normal U. The target T is the light direction and the rates scale with the leaf's ambient
//! light, so sunlit leaves turn their blade to the light and shaded ones keep their phyllotaxis.
//!
//! The leaf buffer is in random order, so a prefix of it is an even thinning of the crown: the
//! levels of detail draw prefixes.

use glam::{Vec3, Vec3A};
use serde::{Deserialize, Serialize};

use super::leaf_card::LeafCard;
use super::petiole::{Attachment, Blade, Petiole};
use super::{AmbientFn, NodeGeom, TreeMesh, any_perpendicular, hash_unit};
use crate::rng::Rng;
use crate::tree::{Internode, Skeleton};

/// The golden angle, radians: the phyllotactic divergence between successive leaves.
const GOLDEN_ANGLE: f32 = 2.399_963;

/// Leaf placement, size and orientation. Lengths in metres, angles in radians.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LeafParams {
    /// Leaves grow on internodes thinner than this diameter.
    pub max_branch_diameter: f32,
    /// Leaves per metre of leaf-bearing branch (density).
    pub leaves_per_metre: f32,
    /// Blade length (along the petiole) and width.
    pub length: f32,
    pub width: f32,
    /// Leaves drawn on one card ([`super::leaf_card`]): a card per `leaves_per_card` leaves.
    #[serde(default = "super::leaf_card::one_leaf_per_card")]
    pub leaves_per_card: u32,
    /// Petiole length S.
    pub petiole_length: f32,
    /// Integration steps along the petiole (Δs = S / steps).
    pub petiole_steps: u32,
    /// Angle between the branch and a petiole as it leaves the branch.
    pub insertion_angle: f32,
    /// Twist rate e_H, bend rate e_L and turn rate e_U, per metre of petiole, in full light.
    pub twist_rate: f32,
    pub bend_rate: f32,
    pub turn_rate: f32,
    /// Tropism target T of the blade normal: towards the light.
    pub light_direction: [f32; 3],
    /// The fine shoots that carry the leaves off their branch (none by default).
    #[serde(default, skip_serializing_if = "crate::is_default")]
    pub short_shoots: ShortShoots,
}

/// Leaf-bearing shoots finer than the skeleton draws (Longay 2014 app. C.1.1 puts leaves on
/// every thin branch; a real crown carries most of them on twigs and spurs below the
/// skeleton's resolution). A silver birch hangs its leaves on long pendulous twigs from the
/// arching limbs; a Lombardy poplar holds them on short upright spurs all along its older
/// branches, not only at the tips of its whips. Each leaf (or spray card) sits at a point of
/// its shoot, a hash of the leaf choosing how far out; the shoot leaves its branch towards
/// the branch's side that the leaf faces and heads at its set-point angle from vertical.
/// Lengths in metres, angles in radians. The default (zero length, no spurs) keeps every
/// leaf on its branch.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ShortShoots {
    /// Shoot length: leaves sit from the branch surface to this far out along the shoot.
    pub length: f32,
    /// Set-point angle of a shoot from vertical (0 up, π/2 level, π hanging).
    pub angle_from_vertical: f32,
    /// Branches from `LeafParams::max_branch_diameter` up to this diameter bear spurs too.
    pub max_spur_branch_diameter: f32,
    /// Leaves per metre of those spur-bearing branches.
    pub spur_leaves_per_metre: f32,
}

impl ShortShoots {
    /// Leaves per metre of a branch of `diameter` (the leafy branches' density `leafy`), or
    /// `None` if it bears none.
    fn leaves_per_metre(&self, diameter: f32, max_leafy_diameter: f32, leafy: f32) -> Option<f32> {
        if diameter < max_leafy_diameter {
            Some(leafy)
        } else if diameter < self.max_spur_branch_diameter && self.spur_leaves_per_metre > 0.0 {
            Some(self.spur_leaves_per_metre)
        } else {
            None
        }
    }

    /// The slot `slot` moved out along its shoot, `reach` (0..1) of the shoot's length: the
    /// shoot leaves on the slot's side of the branch at the set-point angle. The petiole keeps
    /// the frame its branch gives it: leaves along a shoot face as the branch's would (a
    /// spray card turned about a hanging twig would lie flat and show its edge to the side).
    fn carry(&self, slot: &mut Attachment, reach: f32) {
        let horizontal = Vec3::new(slot.radial.x, 0.0, slot.radial.z)
            .try_normalize()
            .unwrap_or_else(|| any_perpendicular(Vec3::Y));
        let (sin, cos) = self.angle_from_vertical.sin_cos();
        let shoot = cos * Vec3::Y + sin * horizontal;
        slot.point += shoot * (self.length * reach);
    }
}

impl Default for LeafParams {
    fn default() -> Self {
        LeafParams {
            max_branch_diameter: 0.02,
            leaves_per_metre: 30.0,
            length: 0.08,
            width: 0.05,
            leaves_per_card: 1,
            petiole_length: 0.03,
            petiole_steps: 4,
            insertion_angle: 0.9,
            twist_rate: 90.0,
            bend_rate: 40.0,
            turn_rate: 10.0,
            light_direction: [0.0, 1.0, 0.0],
            short_shoots: ShortShoots::default(),
        }
    }
}

/// Fruit (or flowers) on the buds of thin branches, by p = r·L² (eq. C.1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FruitParams {
    /// A bud bears fruit when p = r·L² exceeds this threshold (0..1).
    pub threshold: f32,
    /// Only buds of internodes thinner than this diameter, metres.
    pub max_branch_diameter: f32,
    /// Fruit radius, metres.
    pub radius: f32,
    /// Rotation of the bud frame towards the ground (the thesis's Droop), radians.
    pub droop: f32,
}

impl Default for FruitParams {
    fn default() -> Self {
        FruitParams {
            threshold: 0.5,
            max_branch_diameter: 0.015,
            radius: 0.035,
            droop: 1.2,
        }
    }
}

/// All leaf cards of the skeleton as quads (4 vertices, 6 indices each) in random order.
pub fn build_leaves(
    skeleton: &Skeleton,
    params: &LeafParams,
    seed: u64,
    ambient: AmbientFn,
) -> TreeMesh {
    let mut nodes = Vec::new();
    NodeGeom::collect_into(skeleton, &mut nodes);
    let mut mesh = TreeMesh::default();
    let mut scratch = LeafScratch::default();
    let ground_y = skeleton.ground_y();
    build_leaves_into(
        &nodes,
        params,
        seed,
        ambient,
        ground_y,
        &mut scratch,
        &mut mesh,
    );
    mesh
}

/// Working memory of [`build_leaves_into`]: the leaf slots and the spiral.
#[derive(Default)]
pub(crate) struct LeafScratch {
    slots: Vec<Attachment>,
    spiral: Spiral,
    card: LeafCard,
}

/// The phyllotactic spiral: leaf n of a tree (in arena order) turns by n + 1 golden angles, as
/// a running complex product renormalised at each step. The products depend on each other, so
/// they are made once and kept: the same for every tree.
#[derive(Default)]
struct Spiral {
    /// cos and sin of the turn of each leaf.
    turns: Vec<(f32, f32)>,
}

impl Spiral {
    /// Makes sure the turns of the first `num_leaves` leaves are known.
    fn extend_to(&mut self, num_leaves: usize) {
        if self.turns.len() >= num_leaves {
            return;
        }
        let (golden_sin, golden_cos) = GOLDEN_ANGLE.sin_cos();
        let mut turn = self.turns.last().copied().unwrap_or((1.0, 0.0));
        let more = num_leaves.max(2 * self.turns.len()).max(1024) - self.turns.len();
        self.turns.extend((0..more).map(|_| {
            let (c, s) = turn;
            let (c, s) = (
                c * golden_cos - s * golden_sin,
                c * golden_sin + s * golden_cos,
            );
            let norm = (c * c + s * s).sqrt();
            turn = (c / norm, s / norm);
            turn
        }));
    }
}

/// Leaves on one internode at most (an absurdly long internode of a damaged file must not ask
/// for billions).
const MAX_LEAVES_PER_INTERNODE: u32 = 4096;

/// [`build_leaves`] into `mesh` (cleared first, capacity reused), with `scratch` as working
/// memory. No blade reaches below the ground plane y = `ground_y`: one that would (a weeping
/// branch's leaves over the lawn) is lifted to lie on it.
pub(crate) fn build_leaves_into(
    nodes: &[NodeGeom],
    params: &LeafParams,
    seed: u64,
    ambient: AmbientFn,
    ground_y: f32,
    scratch: &mut LeafScratch,
    mesh: &mut TreeMesh,
) {
    let slots = &mut scratch.slots;
    // Slots are made walking the arena in order (its memory and the shadow grid stay in cache),
    // then shuffled in a pass of their own by the inside-out Fisher–Yates shuffle (a tight
    // loop keeps many of its cache misses in flight), then made into leaves in that order.
    slots.clear();
    let mut rng = Rng::new(seed ^ 0x1eaf);
    let spiral = &mut scratch.spiral;
    let card = &mut scratch.card;
    card.set(params);
    let leaves_per_card = card.num_leaves() as f32;
    let shoots = &params.short_shoots;
    for (index, node) in nodes.iter().enumerate() {
        let Some(leaves_per_metre) = shoots.leaves_per_metre(
            node.diameter,
            params.max_branch_diameter,
            params.leaves_per_metre,
        ) else {
            continue;
        };
        let expected = leaves_per_metre / leaves_per_card * node.length;
        let jitter = hash_unit(seed ^ ((index as u64) << 20));
        let count = ((expected + jitter) as u32).min(MAX_LEAVES_PER_INTERNODE);
        if count == 0 {
            continue;
        }
        let heading = node.heading;
        let left = (node.left - heading * node.left.dot(heading))
            .try_normalize()
            .unwrap_or_else(|| any_perpendicular(heading));
        let up = heading.cross(left);
        let first_leaf = slots.len();
        spiral.extend_to(first_leaf + count as usize);
        // In SIMD vectors (`Vec3A`): glam's `Vec3` operations lane by lane, the same bits.
        let (left, up) = (Vec3A::from(left), Vec3A::from(up));
        let (start, end) = (Vec3A::from(node.start), Vec3A::from(node.end));
        for (k, &(cos, sin)) in spiral.turns[first_leaf..][..count as usize]
            .iter()
            .enumerate()
        {
            let radial = left * cos + up * sin;
            let along = (k as f32 + 0.5) / count as f32;
            let attachment = start.lerp(end, along) + radial * (0.5 * node.diameter);
            let slot = Attachment {
                point: attachment.into(),
                heading,
                radial: radial.into(),
                light: 0.0,
            };
            slots.push(slot);
        }
    }
    if shoots.length > 0.0 {
        for (k, slot) in slots.iter_mut().enumerate() {
            shoots.carry(slot, hash_unit(seed ^ 0x5400_7000 ^ ((k as u64) << 24)));
        }
    }
    // The ambient light at every attachment, in a pass of its own: a call through the callback
    // in the middle of the slot loop would save and restore its state.
    for slot in slots.iter_mut() {
        slot.light = ambient(slot.point).clamp(0.0, 1.0);
    }
    for i in 0..slots.len() {
        let j = rng.below(i as u32 + 1) as usize;
        slots.swap(i, j);
    }
    mesh.clear();
    mesh.reserve(slots.len() * 4, slots.len() * 6);
    // The petiole carries the card as it would a blade of the card's size. A card of several
    // leaves is a shoot: its leaves would each turn to the light, which one flat card cannot
    // show, and turning the whole spray flat to the sky would show the crown edge-on from the
    // side; so a shoot card keeps the plane its insertion gives it.
    let shoot = card.num_leaves() > 1;
    let rate_scale = if shoot { 0.0 } else { 1.0 };
    let petiole = Petiole::new(&LeafParams {
        length: card.length_m,
        width: card.width_m,
        twist_rate: params.twist_rate * rate_scale,
        bend_rate: params.bend_rate * rate_scale,
        turn_rate: params.turn_rate * rate_scale,
        ..params.clone()
    });
    for block in slots.chunks(LEAF_BLOCK) {
        push_blades(mesh, &petiole, block, ground_y);
    }
}

/// Leaves written to the mesh per block: the block's vertices and indices are reserved in one
/// step and filled in place.
const LEAF_BLOCK: usize = 64;

/// Appends the blades of the slots `block`, four at a time, none below y = `ground_y`.
fn push_blades(mesh: &mut TreeMesh, petiole: &Petiole, block: &[Attachment], ground_y: f32) {
    let base = mesh.positions.len() as u32;
    let (positions, normals, uvs, ambient) = mesh.grow_vertices(4 * block.len());
    let mut write = |leaf: usize, blade: &Blade, light: f32| {
        let range = 4 * leaf..4 * leaf + 4;
        let lowest = blade.corners.iter().fold(f32::INFINITY, |y, c| y.min(c[1]));
        let lift = (ground_y - lowest).max(0.0);
        let corners = blade.corners.map(|[x, y, z]| [x, y + lift, z]);
        positions[range.clone()].copy_from_slice(&corners);
        normals[range.clone()].fill(blade.normal);
        uvs[range.clone()].copy_from_slice(&[[0.0, 1.0], [1.0, 1.0], [0.0, 0.0], [1.0, 0.0]]);
        ambient[range].fill(light);
    };
    let (groups, remainder) = block.as_chunks::<4>();
    let mut leaf = 0;
    for group in groups {
        match petiole.blades4(group) {
            Some(blades) => {
                for (slot, blade) in group.iter().zip(&blades) {
                    write(leaf, blade, slot.light);
                    leaf += 1;
                }
            }
            None => {
                for slot in group {
                    write(leaf, &petiole.blade(slot), slot.light);
                    leaf += 1;
                }
            }
        }
    }
    for slot in remainder {
        write(leaf, &petiole.blade(slot), slot.light);
        leaf += 1;
    }
    push_quad_indices(mesh, base, block.len());
}

/// Appends the indices of `num_quads` quads whose 4 vertices each (base-left, base-right,
/// tip-left, tip-right) start at vertex `base`: counter-clockwise seen from the normal's side
/// (H × L = U).
pub(crate) fn push_quad_indices(mesh: &mut TreeMesh, base: u32, num_quads: usize) {
    let indices = mesh.grow_indices(6 * num_quads);
    for (quad, corner) in indices.chunks_exact_mut(6).zip((base..).step_by(4)) {
        quad.copy_from_slice(&[
            corner,
            corner + 2,
            corner + 3,
            corner,
            corner + 3,
            corner + 1,
        ]);
    }
}

/// Rotation of `v` about unit `axis` by `angle` (Rodrigues).
fn rotate(v: Vec3, axis: Vec3, angle: f32) -> Vec3 {
    let (sin, cos) = angle.sin_cos();
    v * cos + axis.cross(v) * sin + axis * (axis.dot(v) * (1.0 - cos))
}

/// Fruit on the alive buds of thin internodes with p = r·L² above the threshold (eq. C.1):
/// L is the internode's light exposure, r a hash of the bud position. Each fruit is an
/// icosahedron hanging from its bud, the bud direction rotated down by the droop angle.
pub fn build_fruit(skeleton: &Skeleton, params: &FruitParams, ambient: AmbientFn) -> TreeMesh {
    let mut mesh = TreeMesh::default();
    build_fruit_into(skeleton, params, ambient, &mut mesh);
    mesh
}

/// [`build_fruit`] appended to `mesh`.
pub fn build_fruit_into(
    skeleton: &Skeleton,
    params: &FruitParams,
    ambient: AmbientFn,
    mesh: &mut TreeMesh,
) {
    let mut centers = Vec::new();
    for (index, node) in skeleton.internodes.iter().enumerate() {
        fruit_centers(node, index as u32, params, &mut centers);
    }
    push_fruit(mesh, &centers, params, ambient, skeleton.ground_y());
}

/// Appends the centres of the fruit on the buds of `node` (arena index `index`) to `centers`,
/// in bud order. A pure function of the internode, so the mesher finds the fruit in the same
/// pass over the arena that copies the internodes.
pub(crate) fn fruit_centers(
    node: &Internode,
    index: u32,
    params: &FruitParams,
    centers: &mut Vec<Vec3>,
) {
    if node.diameter >= params.max_branch_diameter {
        return;
    }
    let light = node.light_exposure.clamp(0.0, 1.0);
    // r < 1, so no bud of a node this dim wins: skip it without reading its buds.
    if light * light <= params.threshold {
        return;
    }
    let buds = node.terminal_bud.iter().chain(node.lateral_buds.iter());
    let mut node_hash = None;
    for (k, bud) in buds.enumerate().filter(|(_, b)| b.alive) {
        let node_hash = *node_hash.get_or_insert_with(|| position_hash(node.end));
        let r = hash_unit(node_hash ^ ((k as u64) << 48) ^ u64::from(index));
        if r * light * light <= params.threshold {
            continue;
        }
        let down = droop(bud.direction, params.droop);
        centers.push(node.end + down * (params.radius * 1.2));
    }
}

/// The fruit at `centers` appended to `mesh`, lifted where needed to rest on the ground plane
/// y = `ground_y` rather than sink into it.
pub(crate) fn push_fruit(
    mesh: &mut TreeMesh,
    centers: &[Vec3],
    params: &FruitParams,
    ambient: AmbientFn,
    ground_y: f32,
) {
    for &center in centers {
        let center = center.with_y(center.y.max(ground_y + params.radius));
        push_icosahedron(mesh, center, params.radius, ambient(center).clamp(0.0, 1.0));
    }
}

/// Bud direction rotated towards −Y by `angle` (not past straight down).
fn droop(direction: Vec3, angle: f32) -> Vec3 {
    let direction = direction.try_normalize().unwrap_or(Vec3::Y);
    let to_down = direction.angle_between(Vec3::NEG_Y);
    match direction.cross(Vec3::NEG_Y).try_normalize() {
        Some(axis) => rotate(direction, axis, angle.min(to_down)),
        None => direction,
    }
}

/// Hash of a position quantised to 0.1 mm (the thesis XORs the components into a table index).
fn position_hash(p: Vec3) -> u64 {
    let q = |x: f32| round_to_i64(x * 1.0e4) as u64;
    q(p.x).wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ q(p.y).rotate_left(21) ^ q(p.z).rotate_left(42)
}

/// `x.round() as i64` (halves away from zero, saturating, NaN to 0) without a call to `round`,
/// which is no instruction on baseline x86-64: truncate, then step away from zero when the
/// dropped fraction is at least one half. The fraction is exact: below 2²³ the truncation is
/// exact and so is the difference; from 2²³ on every float is an integer (and beyond the
/// range of i64 the step saturates).
fn round_to_i64(x: f32) -> i64 {
    let truncated = x as i64;
    let fraction = x - truncated as f32;
    if fraction >= 0.5 {
        truncated.saturating_add(1)
    } else if fraction <= -0.5 {
        truncated.saturating_sub(1)
    } else {
        truncated
    }
}

fn push_icosahedron(mesh: &mut TreeMesh, center: Vec3, radius: f32, light: f32) {
    const PHI: f32 = 1.618_034;
    const CORNERS: [[f32; 3]; 12] = [
        [-1.0, PHI, 0.0],
        [1.0, PHI, 0.0],
        [-1.0, -PHI, 0.0],
        [1.0, -PHI, 0.0],
        [0.0, -1.0, PHI],
        [0.0, 1.0, PHI],
        [0.0, -1.0, -PHI],
        [0.0, 1.0, -PHI],
        [PHI, 0.0, -1.0],
        [PHI, 0.0, 1.0],
        [-PHI, 0.0, -1.0],
        [-PHI, 0.0, 1.0],
    ];
    const FACES: [[u32; 3]; 20] = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    static NORMALS: std::sync::OnceLock<[Vec3; 12]> = std::sync::OnceLock::new();
    let normals = NORMALS.get_or_init(|| CORNERS.map(|corner| Vec3::from(corner).normalize()));
    let base = mesh.positions.len() as u32;
    let (positions, normals_out, uvs, ambient) = mesh.grow_vertices(CORNERS.len());
    for (i, &normal) in normals.iter().enumerate() {
        positions[i] = (center + normal * radius).to_array();
        normals_out[i] = normal.to_array();
        uvs[i] = [0.5 + 0.5 * normal.x, 0.5 - 0.5 * normal.y];
    }
    ambient.fill(light);
    let indices = mesh.grow_indices(3 * FACES.len());
    for (triangle, face) in indices.chunks_exact_mut(3).zip(FACES) {
        triangle.copy_from_slice(&face.map(|i| base + i));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::synthetic::{branching_skeleton, crown_ambient};

    fn leaves_with(shoots: ShortShoots) -> (TreeMesh, Vec<NodeGeom>) {
        let skeleton = branching_skeleton(3_000, 5);
        let mut nodes = Vec::new();
        NodeGeom::collect_into(&skeleton, &mut nodes);
        let params = LeafParams {
            leaves_per_metre: 60.0,
            leaves_per_card: 4,
            short_shoots: shoots,
            ..LeafParams::default()
        };
        let ambient = crown_ambient(Vec3::Y, 1.5);
        (build_leaves(&skeleton, &params, 3, &ambient), nodes)
    }

    fn mean_height(mesh: &TreeMesh) -> f32 {
        mesh.positions.iter().map(|p| p[1]).sum::<f32>() / mesh.positions.len() as f32
    }

    #[test]
    fn hanging_short_shoots_lower_the_leaves_by_half_their_length_keeping_their_number() {
        let (on_branches, _) = leaves_with(ShortShoots::default());
        let length = 0.2;
        let (hanging, _) = leaves_with(ShortShoots {
            length,
            angle_from_vertical: std::f32::consts::PI,
            ..ShortShoots::default()
        });
        assert_eq!(hanging.positions.len(), on_branches.positions.len());
        // Reach is uniform along the shoot: the leaves drop half its length on average (a
        // little less where the ground lifts a leaf).
        let drop = mean_height(&on_branches) - mean_height(&hanging);
        assert!(
            (0.8 * 0.5 * length..=0.5 * length * 1.05).contains(&drop),
            "leaves dropped {drop} m on shoots of {length} m"
        );
    }

    #[test]
    fn spurs_leaf_the_branches_up_to_their_diameter_at_their_own_density() {
        let (on_branches, nodes) = leaves_with(ShortShoots::default());
        let leafy = LeafParams::default().max_branch_diameter;
        let max_spur = 3.0 * leafy;
        let spur_leaves_per_metre = 30.0;
        let (spurred, _) = leaves_with(ShortShoots {
            max_spur_branch_diameter: max_spur,
            spur_leaves_per_metre,
            ..ShortShoots::default()
        });
        let spur_metres: f32 = nodes
            .iter()
            .filter(|n| (leafy..max_spur).contains(&n.diameter))
            .map(|n| n.length)
            .sum();
        assert!(
            spur_metres > 1.0,
            "only {spur_metres} m of spur-bearing branch"
        );
        let extra_cards = (spurred.positions.len() - on_branches.positions.len()) / 4;
        let expected = spur_leaves_per_metre / 4.0 * spur_metres;
        assert!(
            (extra_cards as f32 - expected).abs() <= 0.05 * expected + 2.0,
            "{extra_cards} cards on spurs, expected about {expected}"
        );
        let (none_dense, _) = leaves_with(ShortShoots {
            max_spur_branch_diameter: max_spur,
            ..ShortShoots::default()
        });
        assert_eq!(none_dense.positions.len(), on_branches.positions.len());
    }

    #[test]
    fn rounding_without_round_equals_round_for_halves_integers_extremes_and_nan() {
        let mut values = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            -1.5,
            2.5,
            -2.5,
            0.499_999_97,
            -0.499_999_97,
            8_388_607.5,
            -8_388_607.5,
            8_388_608.0,
            16_777_217.0,
            1e12,
            -1e12,
            1e30,
            -1e30,
            f32::MAX,
            f32::MIN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
        ];
        values.extend((0..100_000).map(|k| (hash_unit(k) - 0.5) * 2.0e5));
        values.extend((0..20_000).map(|k| (k as f32 - 10_000.0) * 0.25));
        for x in values {
            assert_eq!(round_to_i64(x), x.round() as i64, "{x}");
        }
    }
}
