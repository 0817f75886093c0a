//! The incremental two-layer triangulation: insert, remove, move, per-frame update.

use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

use glam::Vec2;
use spade::handles::FixedVertexHandle;
use spade::{DelaunayTriangulation, HasPosition, HierarchyHintGenerator, Point2, Triangulation};

use super::{DepthMeshConfig, DepthMeshError, Observation, PinholeIntrinsics};

/// Map-point ids are already well spread integers: a multiplicative hash (Fibonacci hashing)
/// is enough and several times faster than SipHash on this hot path.
#[derive(Default)]
pub(crate) struct IdHasher(u64);

impl Hasher for IdHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            self.0 = (self.0.rotate_left(8) ^ byte as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        }
    }

    fn write_u64(&mut self, value: u64) {
        self.0 = (self.0 ^ value)
            .wrapping_mul(0x9e37_79b9_7f4a_7c15)
            .rotate_left(29);
    }
}

pub(crate) type IdMap<V> = HashMap<u64, V, BuildHasherDefault<IdHasher>>;
pub(crate) type IdSet = HashSet<u64, BuildHasherDefault<IdHasher>>;

/// A vertex: pixel position, depth and the map point it came from.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MeshVertex {
    pub id: u64,
    pub pixel: Vec2,
    pub depth_m: f32,
}

impl HasPosition for MeshVertex {
    type Scalar = f64;

    fn position(&self) -> Point2<f64> {
        Point2::new(self.pixel.x as f64, self.pixel.y as f64)
    }
}

/// The hierarchy hint generator makes point location O(log n) for queries anywhere.
pub(crate) type Triangles =
    DelaunayTriangulation<MeshVertex, (), (), (), HierarchyHintGenerator<f64>>;

/// One triangulation with its id → handle map (spade moves the last vertex into a removed
/// vertex's slot, so handles are fixed up on every removal).
#[derive(Default)]
pub(crate) struct Layer {
    pub(crate) triangles: Triangles,
    pub(crate) handles: IdMap<FixedVertexHandle>,
}

impl Layer {
    /// Inserts a vertex. Spade would silently overwrite a vertex at the same position, so the
    /// caller checks for duplicates (`check_duplicate`) unless it already did, or the layer is
    /// the surface (a subset of the positions of all points, which are unique).
    fn insert(&mut self, vertex: MeshVertex, check_duplicate: bool) -> Result<(), DepthMeshError> {
        if let Some(existing) = check_duplicate
            .then(|| self.triangles.locate_vertex(vertex.position()))
            .flatten()
        {
            let other = existing.data().id;
            return Err(DepthMeshError::DuplicatePosition {
                id: vertex.id,
                other,
                u: vertex.pixel.x,
                v: vertex.pixel.y,
            });
        }
        let handle = self
            .triangles
            .insert(vertex)
            .map_err(|e| DepthMeshError::Triangulation {
                id: vertex.id,
                reason: format!("{e:?}"),
            })?;
        self.handles.insert(vertex.id, handle);
        Ok(())
    }

    fn remove(&mut self, id: u64) -> Option<MeshVertex> {
        let handle = self.handles.remove(&id)?;
        let removed = self.triangles.remove(handle);
        if handle.index() < self.triangles.num_vertices() {
            let moved_id = self.triangles.vertex(handle).data().id;
            self.handles.insert(moved_id, handle);
        }
        Some(removed)
    }

    pub(crate) fn get(&self, id: u64) -> Option<MeshVertex> {
        self.handles
            .get(&id)
            .map(|&h| *self.triangles.vertex(h).data())
    }

    fn neighbours(&self, id: u64) -> Vec<MeshVertex> {
        let Some(&handle) = self.handles.get(&id) else {
            return Vec::new();
        };
        self.triangles
            .vertex(handle)
            .out_edges()
            .map(|edge| *edge.to().data())
            .collect()
    }

    fn neighbour_ids(&self, id: u64) -> Vec<u64> {
        let Some(&handle) = self.handles.get(&id) else {
            return Vec::new();
        };
        self.triangles
            .vertex(handle)
            .out_edges()
            .map(|edge| edge.to().data().id)
            .collect()
    }
}

/// What one [`DepthMesh::update`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct UpdateStats {
    pub num_inserted: usize,
    pub num_moved: usize,
    pub num_removed: usize,
    /// Observations refused (invalid or duplicate position); see [`DepthMeshError`].
    pub num_rejected: usize,
    /// Vertices currently kept out of the surface as inconsistent.
    pub num_inconsistent: usize,
}

/// The scene depth mesh of one camera (see the module docs).
pub struct DepthMesh {
    pub(crate) camera: PinholeIntrinsics,
    pub(crate) config: DepthMeshConfig,
    pub(crate) all: Layer,
    pub(crate) surface: Layer,
}

impl DepthMesh {
    pub fn new(camera: PinholeIntrinsics, config: DepthMeshConfig) -> Self {
        Self {
            camera,
            config,
            all: Layer::default(),
            surface: Layer::default(),
        }
    }

    pub fn camera(&self) -> &PinholeIntrinsics {
        &self.camera
    }

    pub fn config(&self) -> &DepthMeshConfig {
        &self.config
    }

    /// Number of valid observations held (consistent or not).
    pub fn num_points(&self) -> usize {
        self.all.handles.len()
    }

    /// Number of vertices of the surface that answers queries.
    pub fn num_surface_points(&self) -> usize {
        self.surface.handles.len()
    }

    /// The vertex of map point `id`, if held.
    pub fn vertex(&self, id: u64) -> Option<MeshVertex> {
        self.all.get(id)
    }

    /// Whether map point `id` is part of the surface (consistent with its neighbours).
    pub fn is_consistent(&self, id: u64) -> bool {
        self.surface.handles.contains_key(&id)
    }

    fn validate(&self, observation: &Observation) -> Result<MeshVertex, DepthMeshError> {
        let Observation { id, pixel, depth_m } = *observation;
        if !(pixel.is_finite() && self.camera.contains(pixel)) {
            return Err(DepthMeshError::PixelOutside {
                id,
                u: pixel.x,
                v: pixel.y,
                width: self.camera.width,
                height: self.camera.height,
            });
        }
        if !(depth_m.is_finite()
            && depth_m >= self.config.min_depth_m
            && depth_m <= self.config.max_depth_m)
        {
            return Err(DepthMeshError::InvalidDepth { id, depth_m });
        }
        Ok(MeshVertex { id, pixel, depth_m })
    }

    /// Inserts a point, or moves it if its id is already held.
    pub fn insert(&mut self, observation: Observation) -> Result<(), DepthMeshError> {
        let mut dirty = IdSet::default();
        let result = self.insert_or_move(observation, &mut dirty);
        self.refresh(dirty);
        result.map(|_| ())
    }

    /// Moves a held point (remove + insert: spade has no move).
    pub fn move_point(&mut self, observation: Observation) -> Result<(), DepthMeshError> {
        if !self.all.handles.contains_key(&observation.id) {
            return Err(DepthMeshError::UnknownPoint { id: observation.id });
        }
        self.insert(observation)
    }

    /// Removes a point; unknown ids are an error value.
    pub fn remove(&mut self, id: u64) -> Result<(), DepthMeshError> {
        let mut dirty = IdSet::default();
        if !self.remove_into(id, &mut dirty) {
            return Err(DepthMeshError::UnknownPoint { id });
        }
        self.refresh(dirty);
        Ok(())
    }

    /// Brings the mesh to the current frame: points absent from `observations` are removed,
    /// new ones inserted, moved ones moved. Invalid observations are counted and skipped.
    pub fn update(&mut self, observations: &[Observation]) -> UpdateStats {
        let mut stats = UpdateStats::default();
        let mut dirty = IdSet::default();
        let seen: IdSet = observations.iter().map(|o| o.id).collect();
        let lost: Vec<u64> = self
            .all
            .handles
            .keys()
            .copied()
            .filter(|id| !seen.contains(id))
            .collect();
        for id in lost {
            self.remove_into(id, &mut dirty);
            stats.num_removed += 1;
        }
        for observation in observations {
            match self.insert_or_move(*observation, &mut dirty) {
                Ok(Change::Inserted) => stats.num_inserted += 1,
                Ok(Change::Moved) => stats.num_moved += 1,
                Ok(Change::None) => {}
                Err(_) => stats.num_rejected += 1,
            }
        }
        self.refresh(dirty);
        stats.num_inconsistent = self.num_points() - self.num_surface_points();
        stats
    }

    fn remove_into(&mut self, id: u64, dirty: &mut IdSet) -> bool {
        let neighbours = self.all.neighbour_ids(id);
        if self.all.remove(id).is_none() {
            return false;
        }
        self.surface.remove(id);
        dirty.extend(neighbours);
        dirty.remove(&id);
        true
    }

    fn insert_or_move(
        &mut self,
        observation: Observation,
        dirty: &mut IdSet,
    ) -> Result<Change, DepthMeshError> {
        let vertex = self.validate(&observation)?;
        let change = match self.all.get(vertex.id) {
            None => Change::Inserted,
            Some(old) => {
                let moved = old.pixel.distance(vertex.pixel) > self.config.move_tolerance_px;
                let relative = (old.depth_m - vertex.depth_m).abs() / old.depth_m;
                if !moved && relative <= 1e-3 {
                    return Ok(Change::None);
                }
                if !moved {
                    // Same place, new depth: update the data in both layers, no re-triangulation.
                    for layer in [&mut self.all, &mut self.surface] {
                        if let Some(&h) = layer.handles.get(&vertex.id) {
                            layer.triangles.vertex_data_mut(h).depth_m = vertex.depth_m;
                        }
                    }
                    dirty.insert(vertex.id);
                    dirty.extend(self.all.neighbour_ids(vertex.id));
                    return Ok(Change::Moved);
                }
                Change::Moved
            }
        };
        if let Some(existing) = self.all.triangles.locate_vertex(vertex.position()) {
            let other = existing.data().id;
            if other != vertex.id {
                return Err(DepthMeshError::DuplicatePosition {
                    id: vertex.id,
                    other,
                    u: vertex.pixel.x,
                    v: vertex.pixel.y,
                });
            }
        }
        if change == Change::Moved {
            self.remove_into(vertex.id, dirty);
        }
        self.all.insert(vertex, false)?;
        dirty.insert(vertex.id);
        dirty.extend(self.all.neighbour_ids(vertex.id));
        Ok(change)
    }

    /// Re-evaluates the consistency of `dirty` vertices and mirrors them into the surface.
    ///
    /// Support only counts from trusted neighbours, so outliers cannot vouch for each other:
    /// for a bulk change a lenient first pass (any neighbours) decides whom to trust; otherwise
    /// the trusted are the vertices already in the surface.
    fn refresh(&mut self, dirty: IdSet) {
        let vertices: Vec<MeshVertex> = dirty.iter().filter_map(|&id| self.all.get(id)).collect();
        // The lenient first pass only matters while there is no established surface to trust
        // (a first frame, a relocalisation); in steady state a frame changes few points and
        // the surface's own membership is the trust.
        let bulk = vertices.len() * 4 > self.all.handles.len();
        let first: IdMap<bool> = if bulk {
            vertices
                .iter()
                .map(|v| (v.id, self.is_supported(v, &|_| true, false)))
                .collect()
        } else {
            IdMap::default()
        };
        let trusted = |id: u64| {
            first
                .get(&id)
                .copied()
                .unwrap_or_else(|| self.surface.handles.contains_key(&id))
        };
        let second: Vec<(MeshVertex, bool)> = vertices
            .iter()
            .map(|v| (*v, self.is_supported(v, &trusted, true)))
            .collect();
        for (vertex, consistent) in second {
            let id = vertex.id;
            match (consistent, self.surface.get(id)) {
                (true, None) => {
                    let _ = self.surface.insert(vertex, false);
                }
                (true, Some(old)) if old.pixel != vertex.pixel => {
                    self.surface.remove(id);
                    let _ = self.surface.insert(vertex, false);
                }
                (true, Some(_)) => {}
                (false, Some(_)) => {
                    self.surface.remove(id);
                }
                (false, None) => {}
            }
        }
    }

    /// Whether some triangle of trusted neighbours predicts the vertex's inverse depth
    /// (inverse depth is affine in the image over a plane, so planar surfaces predict
    /// exactly). Tries the 1-ring first, then (if asked) adds the 2-ring.
    fn is_supported(
        &self,
        vertex: &MeshVertex,
        trusted: &dyn Fn(u64) -> bool,
        use_second_ring: bool,
    ) -> bool {
        if self.all.handles.len() < 5 {
            return true;
        }
        let ring = self.all.neighbours(vertex.id);
        let mut candidates: Vec<MeshVertex> = ring
            .iter()
            .filter(|v| trusted(v.id))
            .take(10)
            .copied()
            .collect();
        if ring.len() < 3 {
            return true;
        }
        if self.any_triple_predicts(vertex, &candidates, 0) {
            return true;
        }
        if !use_second_ring {
            return false;
        }
        let num_first = candidates.len();
        for first in &ring {
            for second in self.all.neighbours(first.id) {
                if candidates.len() >= 16 {
                    break;
                }
                if second.id != vertex.id
                    && !ring.iter().any(|r| r.id == second.id)
                    && trusted(second.id)
                    && !candidates.iter().any(|c| c.id == second.id)
                {
                    candidates.push(second);
                }
            }
        }
        candidates.len() > num_first && self.any_triple_predicts(vertex, &candidates, num_first)
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
            !self.bridges_discontinuity(&triple)
                && predict_inverse_depth(vertex.pixel, triple[0], triple[1], triple[2])
                    .is_some_and(|predicted| (predicted - w).abs() <= tolerance)
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

    /// Checks the invariants (spade keeps its own checks test-only, so these are ours): every
    /// id maps to the vertex holding it, the surface is a subset of all points, and both
    /// layers are Delaunay triangulations (see [`super::validity::check_triangulation`]).
    pub fn sanity_check(&self) {
        for layer in [&self.all, &self.surface] {
            assert_eq!(
                layer.handles.len(),
                layer.triangles.num_vertices(),
                "id map size"
            );
            for (&id, &handle) in &layer.handles {
                assert_eq!(
                    layer.triangles.vertex(handle).data().id,
                    id,
                    "stale handle for id {id}"
                );
            }
            super::validity::check_triangulation(&layer.triangles);
        }
        for &id in self.surface.handles.keys() {
            assert!(
                self.all.handles.contains_key(&id),
                "surface point {id} not in all points"
            );
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Change {
    Inserted,
    Moved,
    None,
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
