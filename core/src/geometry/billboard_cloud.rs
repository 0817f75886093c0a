//! The coarsest level of detail's leaves as a billboard cloud (Décoret et al. 2003, "Billboard
//! clouds for extreme model simplification"; the leaf-cluster impostors of SpeedTree's and
//! Xfrog's far levels): the finest level's leaf cards are clustered by facing and position, and
//! each cluster becomes one textured quad whose texture, a rectangle of one atlas per tree,
//! holds the cluster's leaves drawn with their true alpha outlines, as seen along the quad's
//! normal. A coarse level of merged cards ([`super::lod_leaves`]) keeps the leaf area but draws
//! a card's outline where there was a spray of leaves and gaps; a billboard keeps the gaps.
//!
//! - **Facing**: a card belongs to the nearest of [`FACINGS`] (13 axes: the cube's faces, edges
//!   and corners, so no card is more than about 30° off its axis; cards are two-sided, so a
//!   normal and its opposite face the same way).
//! - **Position**: within a facing, the cards' centres are ordered along a Z-order (Morton)
//!   curve in a frame stretched [`FLATTEN`] times along the facing, so octree cells are slabs
//!   thinner along the facing than across it; a cell becomes a cluster once its cards' corners
//!   span at most a depth ε along the facing. ε is the smallest (bisection) that keeps the
//!   clusters within the level's quads (its triangle budget, at most [`MAX_QUADS`]), but not
//!   under [`MIN_DEPTH_PX`] of a pixel of the tree
//!   seen [`SILHOUETTE_HEIGHT_PX`] tall; quads left over split the deepest clusters further.
//!   Parallax (a leaf drawn where its quad's plane is, not where the leaf is) grows with that
//!   depth, so it is what the clusters bound, not their number of cards.
//! - **Quad**: the plane through a cluster's area-weighted centre, normal to its members' mean
//!   facing, "up" as close to world up as the plane allows; the quad is the bounding rectangle
//!   of the members' corners projected onto it, clipped at the ground.
//! - **Atlas**: one texel size for every quad (square texels), chosen so that the rectangles
//!   fit one [`ATLAS_WIDTH`]-wide atlas by shelf packing, with a transparent gutter between
//!   them. The layout is made with the meshes (cheap); the texels are drawn on demand
//!   ([`bake_atlas`]) by the export, the side-view measure and the renderer: each texel's
//!   [`BAKE_SUBSAMPLES`]² samples are tested against the member cards' texture, the texel's
//!   colour is the mean of the covering leaves' colours times their baked ambient light (so
//!   the quads need no vertex colour), and its alpha the covered share, made 0 or 255 by error
//!   diffusion so that an alpha test at ½ keeps each region's covered share.

use glam::{Vec2, Vec3};
use image::{Rgba, RgbaImage};

use super::leaves::push_quad_indices;
use super::lod_leaves::morton3;
use super::silhouette::SILHOUETTE_HEIGHT_PX;
use super::{TreeMesh, TreeMeshes};

/// Width of the atlas, texels; its height is the power of two the packed rectangles need, at
/// most as much.
pub const ATLAS_WIDTH: u32 = 2048;
/// Samples per texel side when baking.
pub const BAKE_SUBSAMPLES: usize = 4;
/// Transparent texels between rectangles, so that filtering does not bleed one into the next.
const GUTTER: u32 = 1;
/// Bits per axis of a card centre's Morton code (octree depth).
const OCTREE_BITS: u32 = 9;
/// How much thinner a cluster's cell is along its facing than across it: parallax (a leaf
/// drawn on its quad where the quad's plane is, not where the leaf is) grows with a cluster's
/// depth along the facing, not with its width.
const FLATTEN: f32 = 8.0;
/// Most quads of a cloud: as many as the pixels of a square around a tree seen
/// [`SILHOUETTE_HEIGHT_PX`] tall, where the coarsest level is drawn; more would not show, and
/// each costs about 60 bytes in a `.glb`.
pub const MAX_QUADS: usize = (SILHOUETTE_HEIGHT_PX * SILHOUETTE_HEIGHT_PX) as usize;
/// Depth a cluster may span unsplit, in screen pixels of a tree [`SILHOUETTE_HEIGHT_PX`] tall.
const MIN_DEPTH_PX: f32 = 0.25;
/// Share of the atlas the rectangles are first assumed to fill when the texel size is chosen.
const FILL: f32 = 0.8;
/// Smallest texel side, metres: finer than any leaf needs.
const MIN_TEXEL_M: f32 = 0.001;
/// The facings cards are grouped by (not unit; normalised where used).
pub const FACINGS: [[f32; 3]; 13] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
    [1.0, 1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 0.0, 1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, 1.0],
    [0.0, 1.0, -1.0],
    [1.0, 1.0, 1.0],
    [1.0, 1.0, -1.0],
    [1.0, -1.0, 1.0],
    [1.0, -1.0, -1.0],
];

/// An internode whose bark the level does not mesh (a thin chain its bark budget drops), drawn
/// into the atlas instead: the cylinder from `start` to `end` of `diameter` (metres) seen along
/// its quad's normal, in `color` (linear RGB, the bark's colour times its baked ambient light).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct CloudWood {
    pub start: [f32; 3],
    pub end: [f32; 3],
    pub diameter: f32,
    pub color: [f32; 3],
}

/// The layout of a billboard cloud: quad k of the level's leaf mesh (vertices 4k … 4k + 3:
/// base-left, base-right, tip-left, tip-right) is drawn from atlas rectangle `rects[k]` and
/// stands for the elements `members[starts[k]..starts[k + 1]]`: the finest level's cards
/// (indices below `num_cards`) and the dropped wood (index `num_cards + 2w` and
/// `num_cards + 2w + 1` are [`Self::wood`]`[w]`, which is drawn into two quads of facings
/// about perpendicular to it and to each other, so that no side view sees it only edge-on).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BillboardCloud {
    /// Per quad: x, y, width, height in atlas texels (y down, as the image's rows).
    pub rects: Vec<[u32; 4]>,
    /// Indices of the elements (cards, then wood), cluster by cluster.
    pub members: Vec<u32>,
    /// Where each quad's members start in [`Self::members`], and their end.
    pub starts: Vec<u32>,
    /// Atlas width and height, texels.
    pub atlas_size: [u32; 2],
    /// Side of a texel, metres.
    pub texel_m: f32,
    /// Cards among the elements: members at or above it are wood.
    pub num_cards: u32,
    /// The wood drawn into the atlas.
    pub wood: Vec<CloudWood>,
}

impl BillboardCloud {
    pub fn clear(&mut self) {
        self.rects.clear();
        self.members.clear();
        self.starts.clear();
        self.atlas_size = [0, 0];
        self.texel_m = 0.0;
        self.num_cards = 0;
        self.wood.clear();
    }

    pub fn num_quads(&self) -> usize {
        self.rects.len()
    }
}

/// One card of the finest level: centre, unit normal facing its axis, area.
#[derive(Clone, Copy, Debug)]
struct Card {
    center: Vec3,
    normal: Vec3,
    area: f32,
}

/// A cluster's quad before packing: its base-left corner, unit axes and extent (metres).
#[derive(Clone, Copy, Debug)]
struct Frame {
    origin: Vec3,
    across: Vec3,
    along: Vec3,
    normal: Vec3,
    size: Vec2,
}

/// What a cloud clusters: the finest level's cards (4 vertices each), then two ribbons per
/// internode of dropped wood (base-left, base-right, tip-left, tip-right, as a card's).
#[derive(Clone, Copy)]
struct Elements<'a> {
    cards: &'a TreeMesh,
    num_cards: usize,
    ribbons: &'a [[Vec3; 4]],
}

impl Elements<'_> {
    fn len(&self) -> usize {
        self.num_cards + self.ribbons.len()
    }

    fn corner(&self, element: usize, k: usize) -> Vec3 {
        if element < self.num_cards {
            Vec3::from(self.cards.positions[4 * element + k])
        } else {
            self.ribbons[element - self.num_cards][k]
        }
    }
}

/// The two ribbons of `wood`: the cylinder's outline seen along the facing most perpendicular
/// to its axis, and along the facing most perpendicular to both the axis and the first.
fn ribbons_of(wood: &CloudWood) -> [[Vec3; 4]; 2] {
    let (start, end) = (Vec3::from(wood.start), Vec3::from(wood.end));
    let axis = (end - start).try_normalize().unwrap_or(Vec3::Y);
    let facing = |k: usize| Vec3::from(FACINGS[k]).normalize();
    let first = (0..FACINGS.len())
        .min_by(|&a, &b| {
            let off = |k: usize| facing(k).dot(axis).abs();
            off(a).total_cmp(&off(b))
        })
        .unwrap_or(0);
    let second = (0..FACINGS.len())
        .filter(|&k| k != first)
        .min_by(|&a, &b| {
            let off = |k: usize| facing(k).dot(axis).abs() + facing(k).dot(facing(first)).abs();
            off(a).total_cmp(&off(b))
        })
        .unwrap_or(first);
    let radius = 0.5 * wood.diameter.max(0.0);
    [first, second].map(|k| {
        let side = facing(k)
            .cross(axis)
            .try_normalize()
            .unwrap_or_else(|| super::any_perpendicular(axis))
            * radius;
        [start - side, start + side, end - side, end + side]
    })
}

/// Working memory of [`build_cloud_into`].
#[derive(Default)]
pub(crate) struct CloudScratch {
    ribbons: Vec<[Vec3; 4]>,
    cards: Vec<Card>,
    /// Facing (4 bits) and Morton code (27 bits) in the high 32 bits, card index in the low.
    keys: Vec<u64>,
    codes: Vec<u32>,
    /// Per sorted card: the least and most depth of its corners along its facing, metres.
    depths: Vec<(f32, f32)>,
    clusters: Vec<(u32, u32)>,
    frames: Vec<Frame>,
    order: Vec<u32>,
}

/// A billboard cloud of at most `max_quads` quads standing for the cards of `cards` (quads of
/// 4 vertices and 6 indices, card k's vertices at 4k) and for the internodes `wood` whose bark
/// the level does not mesh: its quads into `out` (cleared first; uvs in the atlas, ambient 1
/// since the atlas carries the light), its layout into `cloud`. None reaches below
/// y = `ground_y`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn build_cloud_into(
    cards: &TreeMesh,
    wood: &[CloudWood],
    max_quads: usize,
    ground_y: f32,
    scratch: &mut CloudScratch,
    cloud: &mut BillboardCloud,
    out: &mut TreeMesh,
) {
    out.clear();
    cloud.clear();
    let num_cards = (cards.indices.len() / 6).min(cards.positions.len() / 4);
    if num_cards == 0 || max_quads == 0 {
        return;
    }
    let max_quads = max_quads.min(MAX_QUADS);
    let mut ribbons = std::mem::take(&mut scratch.ribbons);
    ribbons.clear();
    ribbons.extend(wood.iter().flat_map(ribbons_of));
    let elements = Elements {
        cards,
        num_cards,
        ribbons: &ribbons,
    };
    cloud.num_cards = num_cards as u32;
    cloud.wood.extend_from_slice(wood);
    build_clusters(elements, max_quads, ground_y, scratch, cloud, out);
    scratch.ribbons = ribbons;
}

/// [`build_cloud_into`] of `elements`, `cloud`'s wood already set.
fn build_clusters(
    elements: Elements,
    max_quads: usize,
    ground_y: f32,
    scratch: &mut CloudScratch,
    cloud: &mut BillboardCloud,
    out: &mut TreeMesh,
) {
    collect_cards(elements, scratch);
    let by_facing = sort_keys(elements, scratch, true);
    let floor_m = min_depth_m(&scratch.cards);
    let mut limit = smallest_limit(&scratch.codes, &scratch.depths, max_quads).max(floor_m);
    if count_clusters(&scratch.codes, &scratch.depths, limit) > max_quads && by_facing {
        // Fewer quads than facings: cluster by position alone.
        sort_keys(elements, scratch, false);
        limit = smallest_limit(&scratch.codes, &scratch.depths, max_quads).max(floor_m);
    }
    scratch.clusters.clear();
    clusters(
        &scratch.codes,
        &scratch.depths,
        limit,
        &mut Some(&mut scratch.clusters),
    );
    fill_budget(
        &scratch.codes,
        &scratch.depths,
        &mut scratch.clusters,
        max_quads,
        floor_m,
    );
    scratch.frames.clear();
    for &(start, end) in &scratch.clusters {
        let members = scratch.keys[start as usize..end as usize]
            .iter()
            .map(|&key| key as u32 as usize);
        let frame = frame_of(elements, &scratch.cards, members, ground_y);
        scratch.frames.push(frame);
    }
    let Some(texel_m) = pack(&scratch.frames, &mut scratch.order, cloud) else {
        return;
    };
    cloud.texel_m = texel_m;
    let [width, height] = cloud.atlas_size.map(|s| s as f32);
    let num_quads = scratch.frames.len();
    out.reserve(4 * num_quads, 6 * num_quads);
    let (positions, normals, uvs, ambient) = out.grow_vertices(4 * num_quads);
    for (k, (frame, rect)) in scratch.frames.iter().zip(&cloud.rects).enumerate() {
        let (w, h) = (rect[2] as f32 * texel_m, rect[3] as f32 * texel_m);
        let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
        for (j, (s, r)) in corners.into_iter().enumerate() {
            let p = frame.origin + frame.across * (w * s) + frame.along * (h * r);
            positions[4 * k + j] = p.to_array();
            // The base (r = 0) on the rectangle's bottom row, as a leaf card's texture.
            uvs[4 * k + j] = [
                (rect[0] as f32 + s * rect[2] as f32) / width,
                (rect[1] as f32 + (1.0 - r) * rect[3] as f32) / height,
            ];
        }
        normals[4 * k..4 * k + 4].fill(frame.normal.to_array());
        ambient[4 * k..4 * k + 4].fill(1.0);
    }
    push_quad_indices(out, 0, num_quads);
    cloud.starts.push(0);
    for &(start, end) in &scratch.clusters {
        let members = &scratch.keys[start as usize..end as usize];
        cloud.members.extend(members.iter().map(|&key| key as u32));
        cloud.starts.push(cloud.members.len() as u32);
    }
}

/// Centre, facing and area of each element.
fn collect_cards(elements: Elements, scratch: &mut CloudScratch) {
    scratch.cards.clear();
    scratch.cards.extend((0..elements.len()).map(|card| {
        let corner = |k: usize| elements.corner(card, k);
        let center = (0..4).map(corner).sum::<Vec3>() * 0.25;
        let cross = (corner(1) - corner(0)).cross(corner(2) - corner(0));
        let fallback = (card < elements.num_cards)
            .then(|| elements.cards.normals.get(4 * card).copied())
            .flatten()
            .and_then(|n| Vec3::from(n).try_normalize());
        let normal = cross.try_normalize().or(fallback).unwrap_or(Vec3::Z);
        Card {
            center,
            normal,
            area: cross.length(),
        }
    }));
}

/// Index of the facing nearest to unit `normal` (either side).
fn facing_of(normal: Vec3) -> usize {
    let mut best = (0, f32::NEG_INFINITY);
    for (k, f) in FACINGS.iter().enumerate() {
        let d = normal.dot(Vec3::from(*f).normalize()).abs();
        if d > best.1 {
            best = (k, d);
        }
    }
    best.0
}

/// Sorts the cards by facing (when `by_facing`) and Morton code into `keys` and `codes`;
/// returns `by_facing`.
fn sort_keys(elements: Elements, scratch: &mut CloudScratch, by_facing: bool) -> bool {
    let (lo, hi) = scratch.cards.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), c| (lo.min(c.center), hi.max(c.center)),
    );
    let middle = 0.5 * (lo + hi);
    let radius = (0.5 * (hi - lo).length()).max(1e-6);
    let flatten = FLATTEN;
    // Cells are cubes in a frame of the facing whose depth axis is stretched by `flatten`:
    // in the world they are `flatten` times thinner along the facing than across it.
    let frames = FACINGS.map(|f| {
        let depth = Vec3::from(f).normalize();
        let first = super::any_perpendicular(depth);
        (first, depth.cross(first), depth)
    });
    let cells = (1u32 << OCTREE_BITS) as f32;
    let scale = cells / (2.0 * radius * flatten);
    scratch.keys.clear();
    scratch
        .keys
        .extend(scratch.cards.iter().enumerate().map(|(index, card)| {
            let facing = if by_facing { facing_of(card.normal) } else { 0 };
            let d = card.center - middle;
            let (e1, e2, depth) = if by_facing {
                frames[facing]
            } else {
                (Vec3::X, Vec3::Y, Vec3::Z)
            };
            let k = if by_facing { flatten } else { 1.0 };
            let local = Vec3::new(d.dot(e1), d.dot(e2), k * d.dot(depth));
            let q = ((local + Vec3::splat(radius * flatten)) * scale)
                .min(Vec3::splat(cells - 1.0))
                .max(Vec3::ZERO);
            let code = ((facing as u32) << (3 * OCTREE_BITS))
                | morton3(q.x as u32, q.y as u32, q.z as u32);
            (u64::from(code) << 32) | index as u64
        }));
    scratch.keys.sort_unstable();
    scratch.codes.clear();
    scratch
        .codes
        .extend(scratch.keys.iter().map(|&key| (key >> 32) as u32));
    scratch.depths.clear();
    scratch.depths.extend(scratch.keys.iter().map(|&key| {
        let card = key as u32 as usize;
        let facing = (key >> (32 + 3 * OCTREE_BITS)) as usize;
        let depth = if by_facing {
            frames[facing].2
        } else {
            scratch.cards[card].normal
        };
        (0..4).fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), k| {
            let d = elements.corner(card, k).dot(depth);
            (lo.min(d), hi.max(d))
        })
    }));
    by_facing
}

/// The depth below which a cluster is not split: a quarter of a screen pixel where the
/// coarsest level is drawn (a tree [`SILHOUETTE_HEIGHT_PX`] tall), parallax no one sees.
fn min_depth_m(cards: &[Card]) -> f32 {
    let (lo, hi) = cards
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), c| {
            (lo.min(c.center.y), hi.max(c.center.y))
        });
    (hi - lo).max(0.0) * MIN_DEPTH_PX / SILHOUETTE_HEIGHT_PX
}

/// The smallest depth a cluster's cards may span along its facing (metres) at which the
/// clusters number at most `max_quads` (bisection; the clusters fall in number as it grows).
fn smallest_limit(codes: &[u32], depths: &[(f32, f32)], max_quads: usize) -> f32 {
    let (lo, hi) = depths
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), d| {
            (lo.min(d.0), hi.max(d.1))
        });
    let (mut lo, mut hi) = (0.0f32, (hi - lo).max(0.0) + 1e-3);
    if count_clusters(codes, depths, lo) <= max_quads {
        return lo;
    }
    for _ in 0..12 {
        let mid = 0.5 * (lo + hi);
        if count_clusters(codes, depths, mid) <= max_quads {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

fn count_clusters(codes: &[u32], depths: &[(f32, f32)], limit: f32) -> usize {
    clusters(codes, depths, limit, &mut None)
}

/// The clusters of sorted `codes` (ranges of them): octree cells whose cards' corners span at
/// most `limit` along the facing (`depths`), or single cards, or cells of the finest level;
/// pushed to `out` when given. Returns their number.
fn clusters(
    codes: &[u32],
    depths: &[(f32, f32)],
    limit: f32,
    out: &mut Option<&mut Vec<(u32, u32)>>,
) -> usize {
    let shift = 3 * OCTREE_BITS;
    let mut count = 0;
    let mut start = 0;
    while start < codes.len() {
        let facing = codes[start] >> shift;
        let end = start + codes[start..].partition_point(|&c| c >> shift == facing);
        count += split(codes, depths, (start, end), shift, limit, out);
        start = end;
    }
    count
}

/// Splits the cell holding `codes[start..end]` (which share every bit from `shift` up) into
/// clusters.
fn split(
    codes: &[u32],
    depths: &[(f32, f32)],
    (start, end): (usize, usize),
    shift: u32,
    limit: f32,
    out: &mut Option<&mut Vec<(u32, u32)>>,
) -> usize {
    let (lo, hi) = depths[start..end]
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), d| {
            (lo.min(d.0), hi.max(d.1))
        });
    if end - start <= 1 || shift == 0 || hi - lo <= limit {
        if let Some(out) = out.as_deref_mut() {
            out.push((start as u32, end as u32));
        }
        return 1;
    }
    let child_shift = shift - 3;
    let mut count = 0;
    let mut first = start;
    while first < end {
        let child = codes[first] >> child_shift;
        let last = first + codes[first..end].partition_point(|&c| c >> child_shift == child);
        count += split(codes, depths, (first, last), child_shift, limit, out);
        first = last;
    }
    count
}

/// Spends the quads `clusters` leave of `max_quads`: the clusters spanning the most depth are
/// split into their octree children while the children fit.
fn fill_budget(
    codes: &[u32],
    depths: &[(f32, f32)],
    clusters: &mut Vec<(u32, u32)>,
    max_quads: usize,
    floor_m: f32,
) {
    use std::collections::BinaryHeap;
    let spread = |(start, end): (u32, u32)| {
        let (lo, hi) = depths[start as usize..end as usize]
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), d| {
                (lo.min(d.0), hi.max(d.1))
            });
        (hi - lo).max(0.0)
    };
    // Non-negative floats order as their bits.
    let mut heap: BinaryHeap<(u32, u32, u32)> = clusters
        .iter()
        .map(|&c| (spread(c).to_bits(), c.0, c.1))
        .collect();
    let mut count = clusters.len();
    let mut done = Vec::with_capacity(clusters.len());
    let mut children = Vec::new();
    while let Some((bits, start, end)) = heap.pop() {
        let (first, last) = (codes[start as usize], codes[end as usize - 1]);
        let differ = first ^ last;
        if differ == 0 || count >= max_quads || f32::from_bits(bits) <= floor_m {
            done.push((start, end));
            if count >= max_quads {
                done.extend(heap.drain().map(|(_, s, e)| (s, e)));
            }
            continue;
        }
        // The highest 3-bit group in which the cluster's codes differ splits it.
        let shift = (31 - differ.leading_zeros()) / 3 * 3;
        children.clear();
        let mut at = start as usize;
        while at < end as usize {
            let child = codes[at] >> shift;
            let next = at + codes[at..end as usize].partition_point(|&c| c >> shift == child);
            children.push((at as u32, next as u32));
            at = next;
        }
        if count + children.len() - 1 > max_quads {
            done.push((start, end));
            continue;
        }
        count += children.len() - 1;
        heap.extend(children.iter().map(|&c| (spread(c).to_bits(), c.0, c.1)));
    }
    done.sort_unstable();
    *clusters = done;
}

/// The quad of a cluster: the plane through its members' area-weighted centre, normal to their
/// mean facing, the bounding rectangle of their corners on it, clipped at the ground.
fn frame_of(
    elements: Elements,
    cards: &[Card],
    members: impl Iterator<Item = usize> + Clone,
    ground_y: f32,
) -> Frame {
    let axis = cards
        .get(members.clone().next().unwrap_or(0))
        .map_or(Vec3::Z, |c| {
            Vec3::from(FACINGS[facing_of(c.normal)]).normalize()
        });
    let (mut sum_center, mut sum_area, mut sum_normal) = (Vec3::ZERO, 0.0f32, Vec3::ZERO);
    for m in members.clone() {
        let card = cards[m];
        let weight = card.area.max(1e-9);
        sum_center += card.center * weight;
        sum_area += weight;
        let n = if card.normal.dot(axis) < 0.0 {
            -card.normal
        } else {
            card.normal
        };
        sum_normal += n * weight;
    }
    let center = sum_center / sum_area.max(1e-12);
    let normal = sum_normal.try_normalize().unwrap_or(axis);
    let up = if normal.y.abs() < 0.999 {
        Vec3::Y
    } else {
        Vec3::Z
    };
    let along = (up - normal * normal.dot(up)).normalize();
    let across = along.cross(normal);
    let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
    for m in members {
        for k in 0..4 {
            let d = elements.corner(m, k) - center;
            let p = Vec2::new(d.dot(across), d.dot(along));
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    // `across` is level: the quad's lowest edge is its base, at height center.y + lo.y·along.y.
    if along.y > 1e-4 {
        let lowest = (ground_y - center.y) / along.y;
        lo.y = lo.y.max(lowest).min(hi.y);
    }
    Frame {
        origin: center + across * lo.x + along * lo.y,
        across,
        along,
        normal,
        size: (hi - lo).max(Vec2::ZERO),
    }
}

/// Packs the quads' rectangles into the atlas at one texel size, the smallest tried (from
/// [`FILL`] of the atlas up, 10% at a time) at which they fit; sets `cloud`'s rectangles and
/// atlas size and returns the texel side. `None` without quads.
fn pack(frames: &[Frame], order: &mut Vec<u32>, cloud: &mut BillboardCloud) -> Option<f32> {
    if frames.is_empty() {
        return None;
    }
    let area: f32 = frames.iter().map(|f| f.size.x * f.size.y).sum();
    let width = ATLAS_WIDTH;
    let mut texel_m = (area / (FILL * (width * width) as f32))
        .sqrt()
        .max(MIN_TEXEL_M);
    let texels = |m: f32, texel_m: f32| ((m / texel_m).ceil() as u32).max(1);
    order.clear();
    order.extend(0..frames.len() as u32);
    order.sort_by(|&a, &b| {
        let (fa, fb) = (frames[a as usize], frames[b as usize]);
        fb.size.y.total_cmp(&fa.size.y).then(a.cmp(&b))
    });
    cloud.rects.clear();
    cloud.rects.resize(frames.len(), [0; 4]);
    loop {
        let (mut x, mut y, mut row) = (0u32, 0u32, 0u32);
        let mut fits = true;
        for &k in order.iter() {
            let size = frames[k as usize].size;
            let (w, h) = (texels(size.x, texel_m), texels(size.y, texel_m));
            if w > width {
                fits = false;
                break;
            }
            if x + w > width {
                y += row + GUTTER;
                x = 0;
                row = 0;
            }
            if y + h > width {
                fits = false;
                break;
            }
            cloud.rects[k as usize] = [x, y, w, h];
            x += w + GUTTER;
            row = row.max(h);
        }
        if fits {
            let used = y + row;
            cloud.atlas_size = [width, used.next_power_of_two().clamp(1, width)];
            return Some(texel_m);
        }
        texel_m *= 1.1;
    }
}

/// The atlas of level `lod` of `meshes`, drawn from the leaf cards' texture `card_texture`
/// (sRGB, alpha-tested at ½); `None` when the level is not a billboard cloud.
pub fn level_atlas(meshes: &TreeMeshes, lod: usize, card_texture: &RgbaImage) -> Option<RgbaImage> {
    let level = meshes.lods.get(lod)?;
    let cloud = level.billboards.as_ref()?;
    Some(bake_atlas(
        cloud,
        &level.merged_leaves,
        &meshes.leaves,
        card_texture,
    ))
}

/// Draws the atlas of `cloud`, whose quads are `quads` (as [`build_cloud_into`] made them, or
/// moved rigidly since), from the finest level's `cards` and their texture `card_texture`.
pub fn bake_atlas(
    cloud: &BillboardCloud,
    quads: &TreeMesh,
    cards: &TreeMesh,
    card_texture: &RgbaImage,
) -> RgbaImage {
    let [width, height] = cloud.atlas_size;
    let mut atlas = RgbaImage::new(width.max(1), height.max(1));
    let (tw, th) = (card_texture.width().max(1), card_texture.height().max(1));
    // The texture's linear colour, and whether it is opaque, per texel.
    let texels: Vec<Option<Vec3>> = card_texture
        .pixels()
        .map(|p| (p[3] >= 128).then(|| Vec3::new(linear(p[0]), linear(p[1]), linear(p[2]))))
        .collect();
    let texel = |uv: Vec2| {
        let x = ((uv.x * tw as f32) as u32).min(tw - 1);
        let y = ((uv.y * th as f32) as u32).min(th - 1);
        texels.get((y * tw + x) as usize).copied().flatten()
    };
    let s = BAKE_SUBSAMPLES;
    let samples = (s * s) as f32;
    // Mean colour of the opaque texture, for transparent texels (what filtering bleeds in).
    let (sum, n) = texels
        .iter()
        .flatten()
        .fold((Vec3::ZERO, 0usize), |(sum, n), c| (sum + *c, n + 1));
    let background = if n > 0 { sum / n as f32 } else { Vec3::ZERO };
    let (mut masks, mut colors, mut error) = (Vec::new(), Vec::new(), Vec::new());
    let num_quads = cloud
        .rects
        .len()
        .min(quads.positions.len() / 4)
        .min(cloud.starts.len().saturating_sub(1));
    for k in 0..num_quads {
        let [rx, ry, rw, rh] = cloud.rects[k];
        let (rw_us, rh_us) = (rw as usize, rh as usize);
        masks.clear();
        masks.resize(rw_us * rh_us, 0u16);
        colors.clear();
        colors.resize(rw_us * rh_us, Vec3::ZERO);
        let corner = |j: usize| Vec3::from(quads.positions[4 * k + j]);
        let origin = corner(0);
        let (ex, ey) = (corner(1) - origin, corner(2) - origin);
        let (ex2, ey2) = (ex.length_squared(), ey.length_squared());
        if ex2 <= 0.0 || ey2 <= 0.0 {
            continue;
        }
        // World point → texel coordinates within the rectangle (y down from its tip row).
        let to_rect = |p: Vec3| {
            let d = p - origin;
            Vec2::new(
                d.dot(ex) / ex2 * rw as f32,
                (1.0 - d.dot(ey) / ey2) * rh as f32,
            )
        };
        let members = &cloud.members[cloud.starts[k] as usize..cloud.starts[k + 1] as usize];
        let num_cards = cloud.num_cards as usize;
        // Metres per texel on this quad (square texels).
        let texel_m = ex2.sqrt() / rw as f32;
        let mut rect = RectSamples {
            width: rw_us,
            height: rh_us,
            masks: &mut masks,
            colors: &mut colors,
        };
        for &m in members {
            let m = m as usize;
            if m >= num_cards {
                if let Some(wood) = cloud.wood.get((m - num_cards) / 2) {
                    let (a, b) = (to_rect(wood.start.into()), to_rect(wood.end.into()));
                    let radius = 0.5 * wood.diameter / texel_m;
                    rect.draw_capsule(a, b, radius, Vec3::from(wood.color));
                }
                continue;
            }
            if 4 * m + 3 >= cards.positions.len() {
                continue;
            }
            let light =
                crate::export::ambient_color(cards.ambient.get(4 * m).copied().unwrap_or(1.0));
            let p = [0, 1, 2, 3].map(|j| to_rect(Vec3::from(cards.positions[4 * m + j])));
            let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
            let det = e1.perp_dot(e2);
            if det.abs() < 1e-9 {
                continue;
            }
            let lo = p.iter().fold(Vec2::splat(f32::INFINITY), |a, &b| a.min(b));
            let hi = p
                .iter()
                .fold(Vec2::splat(f32::NEG_INFINITY), |a, &b| a.max(b));
            let x0 = lo.x.floor().max(0.0) as usize;
            let y0 = lo.y.floor().max(0.0) as usize;
            let x1 = (hi.x.ceil().max(0.0) as usize).min(rw_us);
            let y1 = (hi.y.ceil().max(0.0) as usize).min(rh_us);
            for ty in y0..y1 {
                for tx in x0..x1 {
                    let i = ty * rw_us + tx;
                    for sy in 0..s {
                        for sx in 0..s {
                            let bit = 1u16 << (sy * s + sx);
                            if rect.masks[i] & bit != 0 {
                                continue;
                            }
                            let q = Vec2::new(
                                tx as f32 + (sx as f32 + 0.5) / s as f32,
                                ty as f32 + (sy as f32 + 0.5) / s as f32,
                            ) - p[0];
                            // q = a·e1 + b·e2: a across the card, b along it from the base.
                            let a = q.perp_dot(e2) / det;
                            let b = e1.perp_dot(q) / det;
                            if !(0.0..1.0).contains(&a) || !(0.0..1.0).contains(&b) {
                                continue;
                            }
                            if let Some(color) = texel(Vec2::new(a, 1.0 - b)) {
                                rect.masks[i] |= bit;
                                rect.colors[i] += color * light;
                            }
                        }
                    }
                }
            }
        }
        // One colour per quad, the mean of its leaves' (the leaves' own shading is below a
        // pixel where this level is drawn, and flat rectangles compress well).
        let (sum, n) = colors
            .iter()
            .zip(&masks)
            .fold((Vec3::ZERO, 0u32), |(sum, n), (c, m)| {
                (sum + *c, n + m.count_ones())
            });
        let flat = if n > 0 { sum / n as f32 } else { background };
        // Alpha by error diffusion (Floyd–Steinberg, serpentine): 0 or 255 per texel, keeping
        // each region's covered share under an alpha test at ½; a texel no leaf touches stays
        // clear.
        error.clear();
        error.resize(rw_us * rh_us, 0.0f32);
        for ty in 0..rh_us {
            let forward = ty % 2 == 0;
            for step in 0..rw_us {
                let tx = if forward { step } else { rw_us - 1 - step };
                let i = ty * rw_us + tx;
                let covered = masks[i].count_ones();
                let (px, py) = (rx + tx as u32, ry + ty as u32);
                if covered == 0 {
                    let c = flat.map(srgb8_of);
                    atlas.put_pixel(px, py, Rgba([c.x as u8, c.y as u8, c.z as u8, 0]));
                    continue;
                }
                let value = covered as f32 / samples + error[i];
                let opaque = value >= 0.5;
                let residual = value - if opaque { 1.0 } else { 0.0 };
                let mut spread = |dx: isize, dy: usize, w: f32| {
                    let dx = if forward { dx } else { -dx };
                    let (nx, ny) = (tx as isize + dx, ty + dy);
                    if nx >= 0 && (nx as usize) < rw_us && ny < rh_us {
                        error[ny * rw_us + nx as usize] += residual * w;
                    }
                };
                spread(1, 0, 7.0 / 16.0);
                spread(-1, 1, 3.0 / 16.0);
                spread(0, 1, 5.0 / 16.0);
                spread(1, 1, 1.0 / 16.0);
                let c = flat.map(srgb8_of);
                let alpha = if opaque { 255 } else { 0 };
                atlas.put_pixel(px, py, Rgba([c.x as u8, c.y as u8, c.z as u8, alpha]));
            }
        }
    }
    atlas
}

/// The samples of one quad's rectangle while it is baked: per texel, which of its
/// [`BAKE_SUBSAMPLES`]² samples are covered and the sum of their colours.
struct RectSamples<'a> {
    width: usize,
    height: usize,
    masks: &'a mut [u16],
    colors: &'a mut [Vec3],
}

impl RectSamples<'_> {
    /// Covers the samples within `radius` texels of the segment `a`–`b` (texel coordinates):
    /// a cylinder seen from the side, its ends rounded (they meet the next internode's).
    fn draw_capsule(&mut self, a: Vec2, b: Vec2, radius: f32, color: Vec3) {
        // NaN radii draw nothing too.
        if radius.is_nan() || radius <= 0.0 {
            return;
        }
        let lo = a.min(b) - Vec2::splat(radius);
        let hi = a.max(b) + Vec2::splat(radius);
        let x0 = lo.x.floor().max(0.0) as usize;
        let y0 = lo.y.floor().max(0.0) as usize;
        let x1 = (hi.x.ceil().max(0.0) as usize).min(self.width);
        let y1 = (hi.y.ceil().max(0.0) as usize).min(self.height);
        let axis = b - a;
        let length2 = axis.length_squared();
        let radius2 = radius * radius;
        let s = BAKE_SUBSAMPLES;
        for ty in y0..y1 {
            for tx in x0..x1 {
                let i = ty * self.width + tx;
                for sy in 0..s {
                    for sx in 0..s {
                        let bit = 1u16 << (sy * s + sx);
                        if self.masks[i] & bit != 0 {
                            continue;
                        }
                        let q = Vec2::new(
                            tx as f32 + (sx as f32 + 0.5) / s as f32,
                            ty as f32 + (sy as f32 + 0.5) / s as f32,
                        );
                        let t = if length2 > 0.0 {
                            ((q - a).dot(axis) / length2).clamp(0.0, 1.0)
                        } else {
                            0.0
                        };
                        if (a + axis * t).distance_squared(q) <= radius2 {
                            self.masks[i] |= bit;
                            self.colors[i] += color;
                        }
                    }
                }
            }
        }
    }
}

/// [`bake_atlas`] of the coarsest level of `meshes`, if it is a billboard cloud, with the card
/// texture at `card_texture_size`.
pub fn coarsest_atlas(meshes: &TreeMeshes, card_texture_size: u32) -> Option<RgbaImage> {
    let coarsest = meshes.lods.len().checked_sub(1)?;
    meshes.lods[coarsest].billboards.as_ref()?;
    let texture = super::leaf_card::card_texture(meshes, card_texture_size);
    level_atlas(meshes, coarsest, &texture)
}

/// An sRGB 8-bit channel as linear 0..1.
fn linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear 0..1 as an sRGB 8-bit channel (as f32, 0..255).
fn srgb8_of(c: f32) -> f32 {
    let c = c.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round()
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::geometry::crown::AlphaMask;
    use crate::geometry::synthetic::{branching_skeleton, crown_ambient};
    use crate::geometry::{LeafParams, MeshParams, build_meshes};

    fn cards() -> TreeMesh {
        let params = MeshParams {
            leaves: LeafParams {
                leaves_per_metre: 60.0,
                ..LeafParams::default()
            },
            ..MeshParams::default()
        };
        let skeleton = branching_skeleton(3_000, 5);
        build_meshes(&skeleton, &params, &crown_ambient(Vec3::Y, 1.5)).leaves
    }

    #[test]
    fn every_card_stands_in_one_quad_within_the_budget_and_above_the_ground() {
        let cards = cards();
        let total = cards.indices.len() / 6;
        assert!(total > 1_000, "{total} cards");
        let (mut cloud, mut quads) = (BillboardCloud::default(), TreeMesh::default());
        let ground_y = 0.4;
        let budget = total / 5;
        build_cloud_into(
            &cards,
            &[],
            budget,
            ground_y,
            &mut CloudScratch::default(),
            &mut cloud,
            &mut quads,
        );
        let n = cloud.num_quads();
        assert!(
            n <= budget && n > budget / 2,
            "{n} quads for a budget of {budget}"
        );
        assert_eq!(quads.indices.len(), 6 * n);
        assert_eq!(cloud.starts.len(), n + 1);
        let mut members = cloud.members.clone();
        members.sort_unstable();
        assert_eq!(members, (0..total as u32).collect::<Vec<_>>());
        assert!(quads.positions.iter().all(|p| p[1] >= ground_y - 1e-4));
        // Rectangles lie in the atlas and do not overlap.
        let [w, h] = cloud.atlas_size;
        let mut used = vec![false; (w * h) as usize];
        for &[x, y, rw, rh] in &cloud.rects {
            assert!(x + rw <= w && y + rh <= h);
            for ty in y..y + rh {
                for tx in x..x + rw {
                    let i = (ty * w + tx) as usize;
                    assert!(!used[i], "rectangles overlap at {tx}, {ty}");
                    used[i] = true;
                }
            }
        }
    }

    /// One flat 0.2 × 0.4 m card facing +Z, 1 m above the ground.
    fn one_card_facing_z() -> TreeMesh {
        let mut cards = TreeMesh::default();
        let (p, n, uv, a) = cards.grow_vertices(4);
        p.copy_from_slice(&[
            [0.0, 1.0, 0.0],
            [0.2, 1.0, 0.0],
            [0.0, 1.4, 0.0],
            [0.2, 1.4, 0.0],
        ]);
        n.fill([0.0, 0.0, 1.0]);
        uv.copy_from_slice(&[[0.0, 1.0], [1.0, 1.0], [0.0, 0.0], [1.0, 0.0]]);
        a.fill(1.0);
        push_quad_indices(&mut cards, 0, 1);
        cards
    }

    #[test]
    fn a_quad_per_card_bakes_the_card_texture_coverage() {
        // One flat card facing +Z: its quad is the card and the atlas holds its texture's
        // opaque share.
        let cards = one_card_facing_z();
        // A texture whose left half is opaque.
        let texture = RgbaImage::from_fn(64, 64, |x, _| {
            if x < 32 {
                Rgba([40, 120, 30, 255])
            } else {
                Rgba([0, 0, 0, 0])
            }
        });
        let (mut cloud, mut quads) = (BillboardCloud::default(), TreeMesh::default());
        build_cloud_into(
            &cards,
            &[],
            4,
            0.0,
            &mut CloudScratch::default(),
            &mut cloud,
            &mut quads,
        );
        assert_eq!(cloud.num_quads(), 1);
        let atlas = bake_atlas(&cloud, &quads, &cards, &texture);
        let [x, y, w, h] = cloud.rects[0];
        let rect = image::imageops::crop_imm(&atlas, x, y, w, h).to_image();
        let opaque = AlphaMask::from_texture(&rect).opaque_fraction();
        assert!((opaque - 0.5).abs() < 0.05, "{opaque} of the quad opaque");
        // The left half is the opaque one, seen from the card's front.
        let left = rect.get_pixel(w / 4, h / 2);
        let right = rect.get_pixel(3 * w / 4, h / 2);
        assert_eq!((left[3], right[3]), (255, 0));
        assert!(left[1] > left[0] && left[1] > left[2], "green: {left:?}");
    }

    #[test]
    fn dropped_wood_is_baked_into_two_quads_that_see_it_from_about_perpendicular_sides() {
        // One card, and a vertical internode 2 m off it that the level's bark leaves out.
        let cards = one_card_facing_z();
        let wood = CloudWood {
            start: [2.0, 0.5, 1.0],
            end: [2.0, 2.5, 1.0],
            diameter: 0.1,
            color: [0.3, 0.2, 0.1],
        };
        let texture = RgbaImage::from_pixel(8, 8, Rgba([40, 120, 30, 255]));
        let (mut cloud, mut quads) = (BillboardCloud::default(), TreeMesh::default());
        build_cloud_into(
            &cards,
            &[wood],
            8,
            0.0,
            &mut CloudScratch::default(),
            &mut cloud,
            &mut quads,
        );
        assert_eq!(cloud.num_quads(), 3, "the card's quad and the wood's two");
        let atlas = bake_atlas(&cloud, &quads, &cards, &texture);
        let mut normals = Vec::new();
        for k in 0..cloud.num_quads() {
            let members = &cloud.members[cloud.starts[k] as usize..cloud.starts[k + 1] as usize];
            if members != [1] && members != [2] {
                continue;
            }
            let normal = Vec3::from(quads.normals[4 * k]);
            assert!(
                normal.y.abs() < 1e-3,
                "a vertical stem's quad faces {normal}"
            );
            normals.push(normal);
            // The quad is the stem's outline seen along its normal: 2 m by 10 cm, all of it
            // opaque but the rounded ends.
            let [x, y, w, h] = cloud.rects[k];
            let size = Vec2::new(w as f32, h as f32) * cloud.texel_m;
            assert!(
                (size.y - 2.0).abs() < 0.02 && (size.x - 0.1).abs() < 0.02,
                "{size}"
            );
            let rect = image::imageops::crop_imm(&atlas, x, y, w, h).to_image();
            let opaque = AlphaMask::from_texture(&rect).opaque_fraction();
            assert!(opaque > 0.85, "{opaque} of the stem's quad opaque");
            let middle = rect.get_pixel(w / 2, h / 2);
            assert!(
                middle[0] > middle[1] && middle[1] > middle[2],
                "bark: {middle:?}"
            );
        }
        assert_eq!(normals.len(), 2, "the wood is drawn in two quads");
        assert!(normals[0].dot(normals[1]).abs() < 0.1, "{normals:?}");
    }

    #[test]
    fn clusters_bound_their_depth_and_split_down_to_single_cards() {
        let codes = [0u32, 1, 2, 9, 64, 65];
        let depths = [
            (0.0, 0.1),
            (0.0, 0.1),
            (0.5, 0.6),
            (0.0, 0.1),
            (2.0, 2.1),
            (2.0, 2.1),
        ];
        // Unbounded depth: the whole facing is one cluster.
        assert_eq!(count_clusters(&codes, &depths, 10.0), 1);
        // No depth: single cards.
        assert_eq!(count_clusters(&codes, &depths, 0.0), 6);
        let limit = smallest_limit(&codes, &depths, 3);
        assert!(count_clusters(&codes, &depths, limit) <= 3);
        assert!(count_clusters(&codes, &depths, 0.9 * limit) > 3);
    }
}
