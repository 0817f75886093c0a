//! The rings of the generalized cylinders: one per internode joint of a chain, with its centre,
//! tangent, radius, bark texture coordinates and ambient light, and a reference vector carried
//! along the chain by the double-reflection rotation-minimizing frame (Wang et al. 2008), so
//! rings never twist.

use glam::Vec3;

use super::parent_tube::ParentTube;
use super::{AmbientFn, MeshParams, NodeGeom, any_perpendicular, hash_unit};

/// A ring of a generalized cylinder.
#[derive(Clone, Copy, Debug)]
pub(super) struct Ring {
    pub(super) center: Vec3,
    pub(super) tangent: Vec3,
    /// Unit, perpendicular to `tangent`, carried by parallel transport along the chain.
    pub(super) reference: Vec3,
    /// `tangent × reference`.
    pub(super) binormal: Vec3,
    pub(super) radius: f32,
    /// Bark texture coordinates: v along the path, u offset (the per-segment rotation).
    pub(super) v: f32,
    pub(super) u_offset: f32,
    pub(super) ambient: f32,
}

/// The double-reflection rotation-minimizing frame (Wang et al. 2008) from a ring at `from`
/// with tangent `from_tangent` to the next ring at `to` with tangent `to_tangent`: the two
/// reflections, which depend on the rings' positions and tangents only. Carrying a reference
/// vector through them ([`Reflections::carry`]) is what chains one ring to the next, so the
/// reflections of a whole chain are found first, independently of each other.
#[derive(Clone, Copy, Debug)]
struct Reflections {
    /// The first reflection's plane normal v₁ = to − from and 2/|v₁|², 0 when v₁ vanishes.
    v1: Vec3,
    k1: f32,
    /// The second reflection's v₂ = to_tangent − (from_tangent reflected) and 2/|v₂|², 0 when
    /// v₂ vanishes.
    v2: Vec3,
    k2: f32,
}

impl Reflections {
    fn new(from: Vec3, from_tangent: Vec3, to: Vec3, to_tangent: Vec3) -> Self {
        let v1 = to - from;
        let c1 = v1.length_squared();
        let (k1, reflected_tangent) = if c1 > 1e-14 {
            let k1 = 2.0 / c1;
            (k1, from_tangent - v1 * (k1 * v1.dot(from_tangent)))
        } else {
            (0.0, from_tangent)
        };
        let v2 = to_tangent - reflected_tangent;
        let c2 = v2.length_squared();
        Reflections {
            v1,
            k1,
            v2,
            k2: if c2 > 1e-14 { 2.0 / c2 } else { 0.0 },
        }
    }

    /// `reference` of the ring at `from` carried to the ring at `to`: unit, perpendicular to
    /// `to_tangent`.
    #[inline(always)]
    fn carry(&self, reference: Vec3, to_tangent: Vec3) -> Vec3 {
        // k = 2/c is never 0 when the reflection applies.
        let reflected = if self.k1 != 0.0 {
            reference - self.v1 * (self.k1 * self.v1.dot(reference))
        } else {
            reference
        };
        let out = if self.k2 != 0.0 {
            reflected - self.v2 * (self.k2 * self.v2.dot(reflected))
        } else {
            reflected
        };
        (out - to_tangent * out.dot(to_tangent))
            .try_normalize()
            .unwrap_or_else(|| any_perpendicular(to_tangent))
    }
}

/// Appends the rings of one chain: a ring at the start of every internode and one at the tip.
/// A lateral chain's first ring sits at the branching point (it is laid onto the parent surface
/// when emitted); the following rings that still lie inside the parent tube are dropped. Rings
/// of joints that stand off the straight line between their neighbours by less than
/// [`MeshParams::ring_tolerance`] of the radius (or [`MeshParams::ring_tolerance_m`]) are then
/// left out ([`simplify_chain`]), except where `anchors` (per internode of the arena) says a
/// branch grows from the joint; `joints` is working memory.
///
/// The reference vectors of all but the first ring are left to [`carry_references`].
#[allow(clippy::too_many_arguments)]
pub(super) fn push_chain_rings(
    rings: &mut Vec<Ring>,
    geometry: &[NodeGeom],
    tube: Option<&ParentTube>,
    chain_nodes: &[u32],
    anchors: &[bool],
    params: &MeshParams,
    tile_length: f32,
    ambient: AmbientFn,
    joints: &mut Vec<u32>,
) {
    let first_ring = rings.len();
    joints.clear();
    push_rings(
        rings,
        geometry,
        tube,
        chain_nodes,
        params,
        tile_length,
        ambient,
        joints,
    );
    let tolerances = (params.ring_tolerance, params.ring_tolerance_m);
    if (tolerances.0 > 0.0 || tolerances.1 > 0.0) && rings.len() - first_ring > 3 {
        simplify_chain(rings, first_ring, joints, anchors, tolerances);
    }
}

/// Leaves out the rings of `rings[first..]` (one chain; ring `first + 1 + k` sits at the end
/// of internode `joints[k]`) whose centre lies within `tolerance` × its radius, or within
/// `tolerance_m` metres, of the segment between the rings kept before and after it, greedily
/// from the base; keeps the first two rings, the tip and the rings at `anchors`' joints. The
/// rings kept move down in place.
fn simplify_chain(
    rings: &mut Vec<Ring>,
    first: usize,
    joints: &[u32],
    anchors: &[bool],
    (tolerance, tolerance_m): (f32, f32),
) {
    /// Most rings left out in a row: bounds the work per ring and the length of a segment.
    const MAX_RUN: usize = 8;
    let end = rings.len();
    let is_anchor = |ring: usize| {
        joints
            .get(ring - first - 1)
            .is_none_or(|&node| anchors.get(node as usize).copied().unwrap_or(true))
    };
    // The base (laid onto the parent) and the ring above it stay.
    let mut kept = first + 1;
    let mut write = first + 2;
    for candidate in first + 2..end {
        let last = candidate + 1 == end;
        let skippable = !last && !is_anchor(candidate) && candidate - kept <= MAX_RUN && {
            let (a, b) = (rings[kept].center, rings[candidate + 1].center);
            (kept + 1..=candidate).all(|k| {
                let ring = &rings[k];
                distance_to_segment(ring.center, a, b) <= (tolerance * ring.radius).max(tolerance_m)
            })
        };
        if !skippable {
            // `kept` indexes the original rings (not yet overwritten: write <= candidate).
            kept = candidate;
            rings[write] = rings[candidate];
            write += 1;
        }
    }
    rings.truncate(write);
}

/// Distance from `p` to the segment from `a` to `b`.
fn distance_to_segment(p: Vec3, a: Vec3, b: Vec3) -> f32 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared().max(1e-20)).clamp(0.0, 1.0);
    p.distance(a + ab * t)
}

/// The rings of one chain, unsimplified, with the internode each ring after the first ends.
#[allow(clippy::too_many_arguments)]
fn push_rings(
    rings: &mut Vec<Ring>,
    geometry: &[NodeGeom],
    tube: Option<&ParentTube>,
    chain_nodes: &[u32],
    params: &MeshParams,
    tile_length: f32,
    ambient: AmbientFn,
    joints: &mut Vec<u32>,
) {
    let first = &geometry[0];
    let mut previous = Ring {
        center: first.start,
        tangent: first.heading,
        reference: Vec3::ZERO,
        binormal: Vec3::ZERO,
        radius: 0.5 * first.diameter,
        v: 0.0,
        u_offset: 0.0,
        ambient: ambient(first.start).clamp(0.0, 1.0),
    };
    previous.reference = (first.left - previous.tangent * first.left.dot(previous.tangent))
        .try_normalize()
        .unwrap_or_else(|| any_perpendicular(previous.tangent));
    previous.binormal = previous.tangent.cross(previous.reference);
    if let Some(tube) = tube {
        previous.radius = previous.radius.min(0.85 * tube.joint_radius());
    }
    rings.push(previous);
    let mut inside_parent = tube.is_some();
    let mut arc_length = 0.0;
    for (k, (node, &node_index)) in geometry.iter().zip(chain_nodes).enumerate() {
        let heading = node.heading;
        arc_length += node.length;
        let (tangent, radius) = match geometry.get(k + 1) {
            Some(next) => (
                (heading + next.heading).try_normalize().unwrap_or(heading),
                0.5 * next.diameter,
            ),
            None => (heading, 0.5 * node.diameter * params.tip_taper),
        };
        if let Some(tube) = tube.filter(|_| inside_parent) {
            let (axis, parent_radius) = tube.at(node.end);
            if node.end.distance(axis) < parent_radius {
                continue;
            }
            inside_parent = false;
        }
        let twist = params.bark_twist * (2.0 * hash_unit(u64::from(node_index)) - 1.0);
        let ring = Ring {
            center: node.end,
            tangent,
            reference: Vec3::ZERO,
            binormal: Vec3::ZERO,
            radius,
            v: arc_length / tile_length,
            u_offset: previous.u_offset + twist,
            ambient: ambient(node.end).clamp(0.0, 1.0),
        };
        rings.push(ring);
        joints.push(node_index);
        previous = ring;
    }
    if inside_parent {
        // The whole branch hides inside its parent: no geometry.
        rings.pop();
    }
}

/// Carries the reference vector along every chain (`spans` of `rings`), from its first ring to
/// its tip. Within a chain each ring waits for the one before; four chains are carried side by
/// side so that their waits overlap: each of four lanes walks a chain and takes the next chain
/// when it reaches a tip. The reflections between two rings do not wait on anything, so they
/// are found ahead of the references they carry.
pub(super) fn carry_references(
    rings: &mut [Ring],
    spans: impl Iterator<Item = std::ops::Range<usize>>,
) {
    /// A lane: the next ring to carry to, the end of its chain, the reference of the ring before.
    #[derive(Clone, Copy)]
    struct Lane {
        ring: usize,
        end: usize,
        reference: Vec3,
    }
    let mut queue = spans.filter(|span| span.len() >= 2);
    let mut take = |rings: &[Ring]| {
        queue.next().map(|span| Lane {
            ring: span.start + 1,
            end: span.end,
            reference: rings[span.start].reference,
        })
    };
    let mut lanes: [Option<Lane>; 4] = [None; 4];
    for lane in &mut lanes {
        *lane = take(rings);
    }
    while lanes.iter().any(Option::is_some) {
        for slot in &mut lanes {
            let Some(lane) = slot else { continue };
            let (center, tangent) = (rings[lane.ring - 1].center, rings[lane.ring - 1].tangent);
            let ring = &mut rings[lane.ring];
            let reflections = Reflections::new(center, tangent, ring.center, ring.tangent);
            let reference = reflections.carry(lane.reference, ring.tangent);
            ring.reference = reference;
            ring.binormal = ring.tangent.cross(reference);
            lane.reference = reference;
            lane.ring += 1;
            if lane.ring == lane.end {
                *slot = take(rings);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rings of radius 1 cm at `centers`, the joints numbered 0, 1, … after the first ring.
    fn rings_at(centers: &[Vec3]) -> (Vec<Ring>, Vec<u32>) {
        let rings = centers
            .iter()
            .map(|&center| Ring {
                center,
                tangent: Vec3::Y,
                reference: Vec3::X,
                binormal: Vec3::Z,
                radius: 0.01,
                v: center.y,
                u_offset: 0.0,
                ambient: 1.0,
            })
            .collect();
        (rings, (0..centers.len() as u32 - 1).collect())
    }

    fn kept_heights(rings: &[Ring]) -> Vec<f32> {
        rings.iter().map(|r| (r.center.y * 10.0).round()).collect()
    }

    #[test]
    fn a_straight_chain_keeps_its_base_the_ring_above_and_its_tip_and_a_bend_or_a_branch_stays() {
        let straight: Vec<Vec3> = (0..10)
            .map(|k| Vec3::new(0.0, 0.1 * k as f32, 0.0))
            .collect();
        let (mut rings, joints) = rings_at(&straight);
        simplify_chain(&mut rings, 0, &joints, &[false; 9], (0.25, 0.0));
        assert_eq!(kept_heights(&rings), [0.0, 1.0, 9.0]);

        // A kink of 5 cm at the sixth ring (5 radii off the line) keeps that ring.
        let mut bent = straight.clone();
        for p in &mut bent[5..] {
            p.x += 0.05;
        }
        bent[5].x = 0.05;
        let (mut rings, joints) = rings_at(&bent);
        simplify_chain(&mut rings, 0, &joints, &[false; 9], (0.25, 0.0));
        assert!(kept_heights(&rings).contains(&5.0) || kept_heights(&rings).contains(&4.0));
        assert!(rings.len() < bent.len(), "{} rings", rings.len());

        // A branch growing from the end of internode 3 (ring 4) keeps that ring.
        let (mut rings, joints) = rings_at(&straight);
        let mut anchors = [false; 9];
        anchors[3] = true;
        simplify_chain(&mut rings, 0, &joints, &anchors, (0.25, 0.0));
        assert_eq!(kept_heights(&rings), [0.0, 1.0, 4.0, 9.0]);
    }

    #[test]
    fn a_tolerance_in_metres_lets_a_thin_twig_lose_rings_its_radius_alone_would_keep() {
        // A twig of 1 cm radius wavering by 3 mm: over a quarter of its radius, under 4 mm.
        let wavy: Vec<Vec3> = (0..10)
            .map(|k| Vec3::new(if k % 2 == 0 { 0.0 } else { 0.003 }, 0.1 * k as f32, 0.0))
            .collect();
        let (mut by_radius, joints) = rings_at(&wavy);
        simplify_chain(&mut by_radius, 0, &joints, &[false; 9], (0.25, 0.0));
        let (mut by_metres, _) = rings_at(&wavy);
        simplify_chain(&mut by_metres, 0, &joints, &[false; 9], (0.25, 0.004));
        assert_eq!(by_radius.len(), wavy.len(), "every ring stays by radius");
        assert!(by_metres.len() <= 3, "{} rings", by_metres.len());
    }
}
