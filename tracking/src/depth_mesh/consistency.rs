//! Consistency of a vertex with its neighbours: is its inverse depth predicted by a triangle
//! of trusted neighbours? Inconsistent vertices (a wrong triangulation, a mismatched track)
//! stay out of the surface.

use glam::Vec2;
use spade::Triangulation;
use spade::handles::FixedVertexHandle;

use super::DepthMesh;
use super::mesh::MeshVertex;

/// Most 1-ring neighbours tried as triangle corners.
const MAX_RING_CANDIDATES: usize = 10;
/// Most candidates once the 2-ring is added.
const MAX_CANDIDATES: usize = 16;

/// Flag of a vertex of all points (see `Layer::mark`): it is in the surface.
pub(crate) const IN_SURFACE: u8 = 1;
/// Flag: the point changed in this edit, so its standing is its lenient verdict ...
pub(crate) const CHANGED: u8 = 2;
/// ... which is this flag.
pub(crate) const LENIENT: u8 = 4;
/// Flag: observed in the current frame (set and cleared within an update).
pub(crate) const SEEN: u8 = 8;
/// Flag: in the work list of vertices to re-evaluate (set and cleared within an edit).
pub(crate) const DIRTY: u8 = 16;

/// How a consistency test counts support.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Support {
    /// Any 1-ring neighbours vouch (a first verdict for points without standing).
    Lenient,
    /// Only trusted neighbours vouch (surface members untouched by this edit, changed points
    /// with a positive lenient verdict); the 2-ring is tried when the 1-ring fails.
    Strict,
}

/// Reused buffers of the consistency test.
#[derive(Default)]
pub(crate) struct Scratch {
    ring: Vec<(FixedVertexHandle, MeshVertex)>,
    candidates: Vec<MeshVertex>,
}

impl DepthMesh {
    /// Whether some triangle of trusted neighbours predicts the vertex's inverse depth
    /// (inverse depth is affine in the image over a plane, so planar surfaces predict
    /// exactly). `handle` is the vertex in the layer of all points.
    pub(crate) fn is_supported(
        &self,
        handle: FixedVertexHandle,
        support: Support,
        scratch: &mut Scratch,
    ) -> bool {
        let trusted = |neighbour: FixedVertexHandle| {
            let mark = self.all.mark(neighbour);
            match support {
                Support::Lenient => true,
                Support::Strict if mark & CHANGED != 0 => mark & LENIENT != 0,
                Support::Strict => mark & IN_SURFACE != 0,
            }
        };
        if self.all.handles.len() < 5 {
            return true;
        }
        let vertex = *self.all.triangles.vertex(handle).data();
        let vertex = &vertex;
        let Scratch { ring, candidates } = scratch;
        ring.clear();
        ring.extend(self.all.ring(handle));
        if ring.len() < 3 {
            return true;
        }
        candidates.clear();
        candidates.extend(
            ring.iter()
                .filter(|(h, _)| trusted(*h))
                .map(|(_, v)| *v)
                .take(MAX_RING_CANDIDATES),
        );
        if self.any_triple_predicts(vertex, candidates, 0) {
            return true;
        }
        if support == Support::Lenient {
            return false;
        }
        let num_first = candidates.len();
        for &(first, _) in ring.iter() {
            for (second_handle, second) in self.all.ring(first) {
                if candidates.len() >= MAX_CANDIDATES {
                    break;
                }
                if second.id != vertex.id
                    && !ring.iter().any(|(_, r)| r.id == second.id)
                    && !candidates.iter().any(|c| c.id == second.id)
                    && trusted(second_handle)
                {
                    candidates.push(second);
                }
            }
        }
        candidates.len() > num_first && self.any_triple_predicts(vertex, candidates, num_first)
    }

    fn bridges_discontinuity(&self, triple: &[MeshVertex; 3]) -> bool {
        let c = &self.config;
        super::query::classify_triangle(
            triple,
            &self.camera,
            f32::INFINITY,
            c.min_plane_distance_m,
            c.min_discontinuity_ratio,
        )
        .is_err()
    }

    /// Tries triples of `candidates` holding at least one index `>= first_new`.
    fn any_triple_predicts(
        &self,
        vertex: &MeshVertex,
        candidates: &[MeshVertex],
        first_new: usize,
    ) -> bool {
        let w = 1.0 / vertex.depth_m;
        let tolerance = self.config.consistency_tolerance * w;
        let predicts = |i: usize, j: usize, k: usize| {
            let triple = [candidates[i], candidates[j], candidates[k]];
            // A triple bridging a discontinuity predicts every depth in between.
            predict_inverse_depth(vertex.pixel, triple[0], triple[1], triple[2])
                .is_some_and(|predicted| (predicted - w).abs() <= tolerance)
                && !self.bridges_discontinuity(&triple)
        };
        let n = candidates.len();
        // Ring neighbours come in angular order: triples a third of the ring apart surround
        // the vertex (interpolation, not extrapolation) and usually settle it at once.
        if first_new == 0 && n >= 3 {
            let third = n / 3;
            if (0..third.max(1)).any(|i| predicts(i, i + third, (i + 2 * third).min(n - 1))) {
                return true;
            }
        }
        for i in 0..n {
            for j in i + 1..n {
                for k in j.max(first_new.saturating_sub(1)) + 1..n {
                    if predicts(i, j, k) {
                        return true;
                    }
                }
            }
        }
        false
    }
}

/// Inverse depth at `pixel` of the plane through three vertices (in (u, v, 1/z)), if the
/// triangle is not degenerate and `pixel` is not far outside it.
fn predict_inverse_depth(pixel: Vec2, a: MeshVertex, b: MeshVertex, c: MeshVertex) -> Option<f32> {
    let (ab, ac, ap) = (b.pixel - a.pixel, c.pixel - a.pixel, pixel - a.pixel);
    let area2 = ab.perp_dot(ac);
    if area2.abs() < 4.0 {
        return None;
    }
    let beta = ap.perp_dot(ac) / area2;
    let gamma = ab.perp_dot(ap) / area2;
    let alpha = 1.0 - beta - gamma;
    if alpha.min(beta).min(gamma) < -0.5 {
        return None;
    }
    Some(alpha / a.depth_m + beta / b.depth_m + gamma / c.depth_m)
}
