//! The incremental two-layer triangulation: insert, remove, move, per-frame update.
//!
//! An update touches the triangulations only where points changed: lost points are removed,
//! new ones inserted from a nearby hint, moved ones moved in place when their star allows it
//! (else removed and re-inserted next to a former neighbour). Consistency is re-evaluated for
//! the changed points and their neighbours only, and the surface follows those verdicts. The
//! scratch buffers live in the mesh, so a steady-state update does not allocate.

use std::sync::atomic::AtomicUsize;

use glam::Vec2;
use spade::handles::FixedVertexHandle;
use spade::{HasPosition, Point2, Triangulation};

use super::consistency::{CHANGED, DIRTY, IN_SURFACE, LENIENT, SEEN, Scratch, Support};
use super::layer::Layer;
use super::{DepthMeshConfig, DepthMeshError, Observation, PinholeIntrinsics};

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

/// Scratch state of one edit, kept between updates so that they do not allocate.
#[derive(Default)]
pub(crate) struct Work {
    lost: Vec<u64>,
    /// Indices of the observations that insert or change a point.
    pending: Vec<usize>,
    /// Points inserted, moved or given a new depth: they have no standing in the surface yet.
    pub(crate) changed: Vec<u64>,
    /// Vertices whose consistency must be re-evaluated (their `DIRTY` flag deduplicates).
    pub(crate) dirty: Vec<u64>,
    /// The dirty vertices with their image-order keys.
    ordered: Vec<(u32, FixedVertexHandle)>,
    /// Lenient verdicts (any neighbours vouch) of the changed points.
    pub(crate) lenient: Vec<(u64, bool)>,
    /// Per dirty vertex: the vertex, whether it is consistent, and its flags when tested.
    pub(crate) verdicts: Vec<(MeshVertex, bool, u8)>,
    pub(crate) scratch: Scratch,
    reinsert: Vec<MeshVertex>,
}

impl Work {
    fn clear(&mut self) {
        self.lost.clear();
        self.pending.clear();
        self.changed.clear();
        self.dirty.clear();
        self.ordered.clear();
        self.lenient.clear();
        self.verdicts.clear();
        self.reinsert.clear();
    }
}

/// The scene depth mesh of one camera (see the module docs).
pub struct DepthMesh {
    pub(crate) camera: PinholeIntrinsics,
    pub(crate) config: DepthMeshConfig,
    pub(crate) all: Layer,
    pub(crate) surface: Layer,
    work: Work,
    /// A corner of the face the last query found (index of a surface vertex; a stale one is
    /// only a worse start), where the next query's walk starts when it is near.
    pub(crate) last_query_vertex: AtomicUsize,
}

impl DepthMesh {
    pub fn new(camera: PinholeIntrinsics, config: DepthMeshConfig) -> Self {
        Self {
            camera,
            config,
            all: Layer::new(&camera),
            surface: Layer::new(&camera),
            work: Work::default(),
            last_query_vertex: AtomicUsize::new(usize::MAX),
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
        let mut work = self.begin();
        let result = self.insert_or_move(observation, &mut work);
        self.finish(work);
        result.map(|_| ())
    }

    /// Moves a held point.
    pub fn move_point(&mut self, observation: Observation) -> Result<(), DepthMeshError> {
        if !self.all.handles.contains_key(&observation.id) {
            return Err(DepthMeshError::UnknownPoint { id: observation.id });
        }
        self.insert(observation)
    }

    /// Removes a point; unknown ids are an error value.
    pub fn remove(&mut self, id: u64) -> Result<(), DepthMeshError> {
        let mut work = self.begin();
        let removed = self.remove_into(id, &mut work);
        self.finish(work);
        if removed {
            Ok(())
        } else {
            Err(DepthMeshError::UnknownPoint { id })
        }
    }

    /// Brings the mesh to the current frame: points absent from `observations` are removed,
    /// new ones inserted, moved ones moved. Invalid observations are counted and skipped.
    pub fn update(&mut self, observations: &[Observation]) -> UpdateStats {
        let mut stats = UpdateStats::default();
        let mut work = self.begin();
        // One look-up per observation: mark it seen, and set aside those with work to do.
        for (index, observation) in observations.iter().enumerate() {
            let Some(old) = self.all.mark_seen(observation.id, SEEN) else {
                work.pending.push(index);
                continue;
            };
            if !(self.validate(observation).is_ok() && self.is_unchanged(&old, observation)) {
                work.pending.push(index);
            }
        }
        self.all.drain_unmarked(SEEN, &mut work.lost);
        let lost = std::mem::take(&mut work.lost);
        for &id in &lost {
            self.remove_into(id, &mut work);
        }
        stats.num_removed = lost.len();
        work.lost = lost;
        let mut pending = std::mem::take(&mut work.pending);
        // Edits in image order stay near the previous edit's (cached) neighbourhood.
        pending.sort_unstable_by_key(|&index| image_order(observations[index].pixel));
        for &index in &pending {
            match self.insert_or_move(observations[index], &mut work) {
                Ok(Change::Inserted) => stats.num_inserted += 1,
                Ok(Change::Moved) => stats.num_moved += 1,
                Ok(Change::None) => {}
                Err(_) => stats.num_rejected += 1,
            }
        }
        work.pending = pending;
        self.finish(work);
        stats.num_inconsistent = self.num_points() - self.num_surface_points();
        stats
    }

    /// Takes the scratch buffers out of the mesh, cleared.
    fn begin(&mut self) -> Work {
        let mut work = std::mem::take(&mut self.work);
        work.clear();
        work
    }

    /// Re-evaluates the touched vertices, mirrors them into the surface and puts the scratch
    /// buffers back.
    fn finish(&mut self, mut work: Work) {
        self.refresh(&mut work);
        self.work = work;
    }

    /// Marks `id` and its current neighbours for re-evaluation.
    fn mark_with_neighbours(&mut self, id: u64, work: &mut Work) {
        self.all.flag_around(id, DIRTY, true, &mut work.dirty);
    }

    fn remove_into(&mut self, id: u64, work: &mut Work) -> bool {
        if !self.all.handles.contains_key(&id) {
            return false;
        }
        self.all.flag_around(id, DIRTY, false, &mut work.dirty);
        self.all.remove(id);
        self.surface.remove(id);
        true
    }

    /// Whether an observation of a held point leaves its vertex as it is: it moved at most
    /// the move tolerance and its depth changed by at most 0.1 %.
    fn is_unchanged(&self, old: &MeshVertex, observation: &Observation) -> bool {
        old.pixel.distance(observation.pixel) <= self.config.move_tolerance_px
            && (old.depth_m - observation.depth_m).abs() <= 1e-3 * old.depth_m
    }

    fn insert_or_move(
        &mut self,
        observation: Observation,
        work: &mut Work,
    ) -> Result<Change, DepthMeshError> {
        let vertex = self.validate(&observation)?;
        let Some(old) = self.all.get(vertex.id) else {
            self.all.insert(vertex, None)?;
            work.changed.push(vertex.id);
            self.mark_with_neighbours(vertex.id, work);
            return Ok(Change::Inserted);
        };
        if self.is_unchanged(&old, &observation) {
            return Ok(Change::None);
        }
        let moved = old.pixel.distance(vertex.pixel) > self.config.move_tolerance_px;
        if moved {
            // Neighbours before the move lose or change a neighbour too.
            self.all
                .flag_around(vertex.id, DIRTY, false, &mut work.dirty);
            self.all.move_vertex(vertex)?;
        } else {
            // Same place, new depth: no re-triangulation in either layer.
            self.all.set_depth(vertex.id, vertex.depth_m);
            self.surface.set_depth(vertex.id, vertex.depth_m);
        }
        work.changed.push(vertex.id);
        self.mark_with_neighbours(vertex.id, work);
        Ok(Change::Moved)
    }

    /// Re-evaluates the consistency of the dirty vertices and mirrors them into the surface.
    ///
    /// Support only counts from trusted neighbours, so outliers cannot vouch for each other.
    /// A vertex untouched by this edit is trusted when it is in the surface; a changed one
    /// (new, moved, new depth) has no standing yet, so a lenient first verdict (any neighbours
    /// vouch, 1-ring only) decides whether it is trusted. On a first frame every vertex is new
    /// and this is a lenient pass followed by a strict one over all points.
    fn refresh(&mut self, work: &mut Work) {
        let Work {
            changed,
            dirty,
            lenient,
            verdicts,
            scratch,
            ordered,
            ..
        } = work;
        for &id in changed.iter() {
            if let Some(&handle) = self.all.handles.get(&id) {
                lenient.push((id, self.is_supported(handle, Support::Lenient, scratch)));
            }
        }
        for &(id, verdict) in lenient.iter() {
            self.all.set_mark(id, CHANGED, true);
            self.all.set_mark(id, LENIENT, verdict);
        }
        // In image order, so consecutive tests share most of their neighbourhoods (and the
        // surface edits that follow stay local too): far fewer cache misses on large meshes.
        ordered.clear();
        ordered.extend(dirty.iter().filter_map(|id| {
            let handle = *self.all.handles.get(id)?;
            let pixel = self.all.triangles.vertex(handle).data().pixel;
            Some((image_order(pixel), handle))
        }));
        ordered.sort_unstable_by_key(|&(key, _)| key);
        for &(_, handle) in ordered.iter() {
            self.all.clear_mark(handle, DIRTY);
        }
        for &(_, handle) in ordered.iter() {
            let consistent = self.is_supported(handle, Support::Strict, scratch);
            let vertex = *self.all.triangles.vertex(handle).data();
            verdicts.push((vertex, consistent, self.all.mark(handle)));
        }
        for &(id, _) in lenient.iter() {
            self.all.set_mark(id, CHANGED | LENIENT, false);
        }
        self.apply_verdicts(work);
    }

    /// Brings the surface in line with the verdicts: first every removal and move (so no
    /// stale position remains), then the insertions.
    fn apply_verdicts(&mut self, work: &mut Work) {
        for &(vertex, consistent, mark) in &work.verdicts {
            if mark & IN_SURFACE == 0 {
                if consistent {
                    work.reinsert.push(vertex);
                }
                continue;
            }
            if !consistent {
                self.surface.remove(vertex.id);
                self.all.set_mark(vertex.id, IN_SURFACE, false);
                continue;
            }
            // An unchanged surface member is already where it belongs.
            let Some(old) = (mark & CHANGED != 0)
                .then(|| self.surface.get(vertex.id))
                .flatten()
            else {
                continue;
            };
            if old.pixel != vertex.pixel {
                if self.surface.move_vertex(vertex).is_err() {
                    // Its new position still holds a surface vertex that moves away later in
                    // this loop: insert it after all moves.
                    self.surface.remove(vertex.id);
                    self.all.set_mark(vertex.id, IN_SURFACE, false);
                    work.reinsert.push(vertex);
                }
            } else if old.depth_m != vertex.depth_m {
                self.surface.set_depth(vertex.id, vertex.depth_m);
            }
        }
        for &vertex in &work.reinsert {
            // Every surface vertex is now at its current position, unique among all points.
            if self.surface.insert(vertex, None).is_ok() {
                self.all.set_mark(vertex.id, IN_SURFACE, true);
            }
        }
    }

    /// Checks the invariants (spade keeps its own checks test-only, so these are ours): every
    /// id maps to the vertex holding it, the surface is a subset of all points at the same
    /// positions, and both layers are Delaunay triangulations (checked by
    /// `validity::check_triangulation`).
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
        for (&id, &handle) in &self.all.handles {
            assert_eq!(
                self.all.mark(handle) & !IN_SURFACE,
                0,
                "stray flags on point {id}"
            );
            assert_eq!(
                self.all.mark(handle) & IN_SURFACE != 0,
                self.surface.handles.contains_key(&id),
                "surface flag of point {id}"
            );
        }
        for &id in self.surface.handles.keys() {
            let (surface, all) = (self.surface.get(id), self.all.get(id));
            assert!(all.is_some(), "surface point {id} not in all points");
            assert_eq!(surface, all, "surface point {id} differs from all points");
        }
    }
}

/// Sort key of a pixel: 16-pixel bands top to bottom, left to right within a band.
fn image_order(pixel: Vec2) -> u32 {
    let band = (pixel.y / 16.0).max(0.0) as u32;
    band * 4096 + (pixel.x.max(0.0) as u32).min(4095)
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Change {
    Inserted,
    Moved,
    None,
}
