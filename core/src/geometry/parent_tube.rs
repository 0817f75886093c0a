//! The parent surface a lateral branch starts from (Longay 2014, appendix C.3): the parent's
//! tube near the branching point, as the parent's rings draw it, and the projection that lays a
//! lateral's first ring onto it, one vertex at a time or four at once.

use glam::{Vec3, Vec4};

use super::NodeGeom;
use super::lanes::V4;
use super::rings::Ring;
use super::topology::{BranchTopology, NONE};

/// Radius of the parent's tube at the ends of internode `node`, as the rings draw it.
fn end_radius(nodes: &[NodeGeom], topology: &BranchTopology, node: u32, tip_taper: f32) -> f32 {
    let next = topology.visual_child[node as usize];
    if next == NONE {
        0.5 * nodes[node as usize].diameter * tip_taper
    } else {
        0.5 * nodes[next as usize].diameter
    }
}

/// One internode of a parent tube: axis from `a` to `b`, radius from `radius_a` to `radius_b`.
#[derive(Clone, Copy, Debug)]
struct TubeSegment {
    a: Vec3,
    /// b − a.
    ab: Vec3,
    /// 1 / |b − a|², 0 for a degenerate segment.
    inverse_length_squared: f32,
    radius_a: f32,
    /// radius_b − radius_a.
    radius_change: f32,
    radius_b: f32,
}

impl TubeSegment {
    fn new(a: Vec3, b: Vec3, radius_a: f32, radius_b: f32) -> Self {
        let ab = b - a;
        let length_squared = ab.length_squared();
        TubeSegment {
            a,
            ab,
            inverse_length_squared: if length_squared > 1e-12 {
                1.0 / length_squared
            } else {
                0.0
            },
            radius_a,
            radius_change: radius_b - radius_a,
            radius_b,
        }
    }

    /// The axis point closest to `point` and the tube radius there.
    fn closest(&self, point: Vec3) -> (Vec3, f32) {
        let t = ((point - self.a).dot(self.ab) * self.inverse_length_squared).clamp(0.0, 1.0);
        (self.a + self.ab * t, self.radius_a + self.radius_change * t)
    }

    /// [`TubeSegment::closest`] for four points.
    fn closest4(&self, point: V4) -> (V4, Vec4) {
        let (a, ab) = (V4::splat(self.a), V4::splat(self.ab));
        let t = (point.sub(a).dot(ab) * Vec4::splat(self.inverse_length_squared))
            .max(Vec4::ZERO)
            .min(Vec4::ONE);
        (
            a.add(ab.scale(t)),
            Vec4::splat(self.radius_a) + Vec4::splat(self.radius_change) * t,
        )
    }
}

/// The parent surface near a branching point, as the parent's rings draw it: the internode the
/// branch grows from and its continuation along the thickest path.
#[derive(Clone, Copy, Debug)]
pub(super) struct ParentTube {
    below: TubeSegment,
    above: Option<TubeSegment>,
}

impl ParentTube {
    pub(super) fn new(
        nodes: &[NodeGeom],
        topology: &BranchTopology,
        parent: u32,
        tip_taper: f32,
    ) -> Self {
        let segment = |node: u32| {
            let n = &nodes[node as usize];
            let radius_b = end_radius(nodes, topology, node, tip_taper);
            TubeSegment::new(n.start, n.end, 0.5 * n.diameter, radius_b)
        };
        let continuation = topology.visual_child[parent as usize];
        ParentTube {
            below: segment(parent),
            above: (continuation != NONE).then(|| segment(continuation)),
        }
    }

    /// Radius of the tube at the branching point.
    pub(super) fn joint_radius(&self) -> f32 {
        self.below.radius_b
    }

    /// [`ParentTube::at`] for four points.
    fn at4(&self, point: V4) -> (V4, Vec4) {
        let (axis, radius) = self.below.closest4(point);
        match &self.above {
            Some(s) => {
                let (other_axis, other_radius) = s.closest4(point);
                let closer = other_axis
                    .sub(point)
                    .dot(other_axis.sub(point))
                    .cmplt(axis.sub(point).dot(axis.sub(point)));
                (
                    V4::select(closer, other_axis, axis),
                    Vec4::select(closer, other_radius, radius),
                )
            }
            None => (axis, radius),
        }
    }

    /// The axis point closest to `point` and the tube radius there.
    pub(super) fn at(&self, point: Vec3) -> (Vec3, f32) {
        let best = self.below.closest(point);
        match &self.above {
            Some(s) => {
                let candidate = s.closest(point);
                if candidate.0.distance_squared(point) < best.0.distance_squared(point) {
                    candidate
                } else {
                    best
                }
            }
            None => best,
        }
    }
}

/// Lays a vertex of a lateral branch's first ring onto its parent's surface: slides it along
/// the branch tangent until it leaves the parent tube, then projects it radially onto the
/// tube (shrunk to the mid-radius of the parent's polygonal contour, so no gap shows).
pub(super) fn onto_parent(tube: &ParentTube, ring: &Ring, direction: Vec3, shrink: f32) -> Vec3 {
    let start = ring.center + direction * ring.radius;
    // One linearised step along the tangent to where the vertex leaves the tube; the radial
    // projection below then puts it exactly on the surface.
    let (axis, radius) = tube.at(start);
    let offset = start - axis;
    let distance = offset.length();
    let gap = radius * shrink - distance;
    let slide = if gap > 1e-4 * radius && distance > 1e-9 {
        let rate = ring.tangent.dot(offset / distance).max(0.25);
        (gap / rate).min(3.0 * tube.joint_radius())
    } else {
        0.0
    };
    let point = start + ring.tangent * slide;
    let (axis, radius) = tube.at(point);
    let outward = (point - axis)
        .try_normalize()
        .or_else(|| direction.try_normalize())
        .unwrap_or(Vec3::X);
    axis + outward * radius * shrink
}

/// [`onto_parent`] for four vertices of a ring; `None` when one of them needs its fallback.
pub(super) fn onto_parent4(
    tube: &ParentTube,
    ring: &Ring,
    directions: V4,
    shrink: f32,
) -> Option<V4> {
    let start = V4::splat(ring.center).add(directions.scale(Vec4::splat(ring.radius)));
    let (axis, radius) = tube.at4(start);
    let offset = start.sub(axis);
    let distance = offset.length();
    let gap = radius * Vec4::splat(shrink) - distance;
    let tangent = V4::splat(ring.tangent);
    let rate = tangent.dot(offset.div(distance)).max(Vec4::splat(0.25));
    let slide = (gap / rate).min(Vec4::splat(3.0 * tube.joint_radius()));
    let slides = gap.cmpgt(Vec4::splat(1e-4) * radius) & distance.cmpgt(Vec4::splat(1e-9));
    let slide = Vec4::select(slides, slide, Vec4::ZERO);
    let point = start.add(tangent.scale(slide));
    let (axis, radius) = tube.at4(point);
    let outward = point.sub(axis).try_normalize()?;
    Some(axis.add(outward.scale(radius).scale(Vec4::splat(shrink))))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{any_perpendicular, hash_unit};

    fn tube(seed: u64) -> ParentTube {
        let r = |k: u64| hash_unit(seed * 16 + k);
        let a = Vec3::new(r(0), r(1), r(2));
        let b = a + Vec3::new(r(3) - 0.5, 1.0, r(4) - 0.5) * 0.3;
        let c = b + Vec3::new(r(5) - 0.5, 1.0, r(6) - 0.5) * 0.3;
        let (ra, rb, rc) = (0.05 + 0.05 * r(7), 0.04 + 0.01 * r(8), 0.02 + 0.01 * r(9));
        ParentTube {
            below: TubeSegment::new(a, b, ra, rb),
            above: (!seed.is_multiple_of(3)).then(|| TubeSegment::new(b, c, rb, rc)),
        }
    }

    fn ring(tube: &ParentTube, seed: u64) -> Ring {
        let r = |k: u64| hash_unit(seed * 16 + 10 + k);
        let center = tube.below.a + tube.below.ab;
        let tangent = Vec3::new(r(0) - 0.5, r(1), r(2) - 0.5).normalize();
        let reference = any_perpendicular(tangent);
        Ring {
            center,
            tangent,
            reference,
            binormal: tangent.cross(reference),
            radius: 0.6 * tube.joint_radius(),
            v: 0.0,
            u_offset: 0.0,
            ambient: 1.0,
        }
    }

    #[test]
    fn four_vertices_at_once_land_where_one_at_a_time_does() {
        let mut groups = 0;
        for seed in 0..300 {
            let tube = tube(seed);
            let ring = ring(&tube, seed);
            let directions: [Vec3; 4] = std::array::from_fn(|i| {
                let angle = 0.4 + 1.3 * i as f32;
                ring.reference * angle.cos() + ring.binormal * angle.sin()
            });
            let Some(four) = onto_parent4(&tube, &ring, V4::gather(directions), 0.97) else {
                continue;
            };
            groups += 1;
            for (i, &direction) in directions.iter().enumerate() {
                let one = onto_parent(&tube, &ring, direction, 0.97);
                let lane = Vec3::from(four.lane(i));
                assert!(
                    (lane - one).abs().max_element() <= 1e-6,
                    "seed {seed} lane {i}: {lane} vs {one}"
                );
            }
        }
        assert!(groups > 250, "only {groups} groups projected");
    }
}
