//! One triangulation layer: spade's Delaunay triangulation, an id → handle map, a coarse grid
//! of hint vertices for point location, and in-place moves of vertices whose neighbourhood
//! stays a valid Delaunay triangulation.
//!
//! Every operation touches only the neighbourhood of the vertex it changes: a point is
//! located from a hint vertex near it (a grid cell's vertex, or a former neighbour of a moved
//! vertex) instead of walking across the mesh, and a tracked point that moved a little keeps
//! its vertex when its star still triangulates its new position (no remove + insert).

use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

use glam::Vec2;
use spade::handles::FixedVertexHandle;
use spade::{
    DelaunayTriangulation, LastUsedVertexHintGenerator, Point2, PositionInTriangulation,
    Triangulation,
};

use super::mesh::MeshVertex;
use super::{DepthMeshError, PinholeIntrinsics};

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

/// Point location starts from the hints this module hands over (grid cells, former
/// neighbours); spade's own generator only remembers the last vertex it found. It keeps no
/// positions of its own, which in-place moves rely on: spade reads a vertex's position from
/// its data only (the hierarchy generator stores copies, so it is not used here).
pub(crate) type Triangles =
    DelaunayTriangulation<MeshVertex, (), (), (), LastUsedVertexHintGenerator>;

/// Side of a hint-grid cell (pixels): a few vertices apart at typical densities, so a walk
/// from the cell's vertex takes a handful of steps.
const HINT_CELL_PX: f32 = 24.0;

/// How many cells away a hint is searched for when a pixel's own cell is empty.
const HINT_SEARCH_CELLS: isize = 3;

/// No vertex recorded in a hint cell.
const EMPTY_CELL: u64 = u64::MAX;

/// A vertex recorded per image cell, as a start for point location. The handle is checked
/// against the id before use (handles move when spade removes a vertex).
struct HintGrid {
    columns: usize,
    rows: usize,
    cells: Vec<(u64, FixedVertexHandle)>,
}

impl HintGrid {
    fn new(camera: &PinholeIntrinsics) -> Self {
        let columns = (camera.width as f32 / HINT_CELL_PX).ceil().max(1.0) as usize;
        let rows = (camera.height as f32 / HINT_CELL_PX).ceil().max(1.0) as usize;
        Self {
            columns,
            rows,
            cells: vec![(EMPTY_CELL, FixedVertexHandle::from_index(0)); columns * rows],
        }
    }

    fn cell(&self, pixel: Vec2) -> usize {
        // Pixels are validated finite and inside the image; clamping keeps queries safe too.
        let column = ((pixel.x / HINT_CELL_PX).max(0.0) as usize).min(self.columns - 1);
        let row = ((pixel.y / HINT_CELL_PX).max(0.0) as usize).min(self.rows - 1);
        row * self.columns + column
    }
}

/// The exact position of a pixel as a set key (spade treats equal positions as one vertex;
/// `+ 0.0` folds −0 into +0, which compare equal).
fn position_key(pixel: Vec2) -> u64 {
    (((pixel.x + 0.0).to_bits() as u64) << 32) | (pixel.y + 0.0).to_bits() as u64
}

/// One triangulation with its id → handle map (spade moves the last vertex into a removed
/// vertex's slot, so handles are fixed up on every removal) and the set of taken positions
/// (spade would silently overwrite a vertex inserted at a taken position).
pub(crate) struct Layer {
    pub(crate) triangles: Triangles,
    pub(crate) handles: IdMap<FixedVertexHandle>,
    positions: IdSet,
    /// Per-vertex flags of the owner, indexed like spade's vertices (kept in step with its
    /// swap-removal), so hot loops read them without hashing.
    marks: Vec<u8>,
    grid: HintGrid,
}

impl Layer {
    pub(crate) fn new(camera: &PinholeIntrinsics) -> Self {
        Self {
            triangles: Triangles::default(),
            handles: IdMap::default(),
            positions: IdSet::default(),
            marks: Vec::new(),
            grid: HintGrid::new(camera),
        }
    }

    pub(crate) fn get(&self, id: u64) -> Option<MeshVertex> {
        self.handles
            .get(&id)
            .map(|&h| *self.triangles.vertex(h).data())
    }

    /// A vertex near `pixel` to start point location from: the vertex of its grid cell, else
    /// of the nearest cell around it that holds one (up to [`HINT_SEARCH_CELLS`] away).
    pub(crate) fn hint(&self, pixel: Vec2) -> Option<FixedVertexHandle> {
        let grid = &self.grid;
        let centre = grid.cell(pixel);
        if let Some(handle) = self.cell_hint(centre) {
            return Some(handle);
        }
        let (row, column) = (
            (centre / grid.columns) as isize,
            (centre % grid.columns) as isize,
        );
        for radius in 1..=HINT_SEARCH_CELLS {
            for dr in -radius..=radius {
                for dc in -radius..=radius {
                    if dr.abs().max(dc.abs()) != radius {
                        continue;
                    }
                    let (r, c) = (row + dr, column + dc);
                    if r < 0 || c < 0 || r >= grid.rows as isize || c >= grid.columns as isize {
                        continue;
                    }
                    if let Some(handle) = self.cell_hint(r as usize * grid.columns + c as usize) {
                        return Some(handle);
                    }
                }
            }
        }
        None
    }

    /// The live vertex recorded in a grid cell, if any.
    fn cell_hint(&self, cell: usize) -> Option<FixedVertexHandle> {
        let (id, handle) = self.grid.cells[cell];
        if id == EMPTY_CELL {
            return None;
        }
        if handle.index() < self.triangles.num_vertices()
            && self.triangles.vertex(handle).data().id == id
        {
            return Some(handle);
        }
        self.handles.get(&id).copied()
    }

    fn note(&mut self, vertex: &MeshVertex, handle: FixedVertexHandle) {
        let cell = self.grid.cell(vertex.pixel);
        self.grid.cells[cell] = (vertex.id, handle);
    }

    /// Where `pixel` lies, located from `hint` or the grid.
    pub(crate) fn locate(
        &self,
        pixel: Vec2,
        hint: Option<FixedVertexHandle>,
    ) -> PositionInTriangulation {
        let point = Point2::new(pixel.x as f64, pixel.y as f64);
        match hint.or_else(|| self.hint(pixel)) {
            Some(hint) => self.triangles.locate_with_hint(point, hint),
            None => self.triangles.locate(point),
        }
    }

    /// The error for a vertex whose position is taken (by the vertex `locate` finds there).
    fn duplicate(&self, vertex: &MeshVertex) -> DepthMeshError {
        let other = match self.locate(vertex.pixel, None) {
            PositionInTriangulation::OnVertex(existing) => {
                self.triangles.vertex(existing).data().id
            }
            _ => vertex.id,
        };
        DepthMeshError::DuplicatePosition {
            id: vertex.id,
            other,
            u: vertex.pixel.x,
            v: vertex.pixel.y,
        }
    }

    /// Inserts a vertex, located from `hint` or the grid; a vertex already at its position is
    /// an error (spade would silently overwrite it).
    pub(crate) fn insert(
        &mut self,
        vertex: MeshVertex,
        hint: Option<FixedVertexHandle>,
    ) -> Result<FixedVertexHandle, DepthMeshError> {
        if self.positions.contains(&position_key(vertex.pixel)) {
            return Err(self.duplicate(&vertex));
        }
        let inserted = match hint.or_else(|| self.hint(vertex.pixel)) {
            Some(hint) => self.triangles.insert_with_hint(vertex, hint),
            None => self.triangles.insert(vertex),
        };
        let handle = inserted.map_err(|e| DepthMeshError::Triangulation {
            id: vertex.id,
            reason: format!("{e:?}"),
        })?;
        self.handles.insert(vertex.id, handle);
        self.positions.insert(position_key(vertex.pixel));
        // Spade appends new vertices (a taken position, which it would overwrite, was refused).
        if handle.index() == self.marks.len() {
            self.marks.push(0);
        } else {
            self.marks[handle.index()] = 0;
        }
        self.note(&vertex, handle);
        Ok(handle)
    }

    /// Removes the vertex of `id`; returns it and a former neighbour (a location hint near it).
    pub(crate) fn remove(&mut self, id: u64) -> Option<(MeshVertex, Option<FixedVertexHandle>)> {
        let handle = self.handles.remove(&id)?;
        let neighbour = self
            .triangles
            .vertex(handle)
            .out_edges()
            .next()
            .map(|edge| edge.to().fix());
        let last = FixedVertexHandle::from_index(self.triangles.num_vertices() - 1);
        let removed = self.triangles.remove(handle);
        self.positions.remove(&position_key(removed.pixel));
        // Spade's removal is a swap-removal of the vertex array: mirror it.
        self.marks.swap_remove(handle.index());
        if handle != last {
            // Spade moved the last vertex into the freed slot.
            let moved_id = self.triangles.vertex(handle).data().id;
            self.handles.insert(moved_id, handle);
        }
        let neighbour = neighbour.map(|n| if n == last { handle } else { n });
        Some((removed, neighbour))
    }

    /// Moves a held vertex to `vertex.pixel` (and its new depth): in place when its star
    /// stays a Delaunay triangulation of the new position, else remove + insert near the old
    /// position. A position taken by another vertex is an error and leaves the vertex where
    /// it was.
    pub(crate) fn move_vertex(&mut self, vertex: MeshVertex) -> Result<(), DepthMeshError> {
        let Some(&handle) = self.handles.get(&vertex.id) else {
            return Err(DepthMeshError::UnknownPoint { id: vertex.id });
        };
        if self.positions.contains(&position_key(vertex.pixel)) {
            return Err(self.duplicate(&vertex));
        }
        if self.can_move_in_place(handle, vertex.pixel) {
            let old = std::mem::replace(self.triangles.vertex_data_mut(handle), vertex);
            self.positions.remove(&position_key(old.pixel));
            self.positions.insert(position_key(vertex.pixel));
            self.note(&vertex, handle);
            return Ok(());
        }
        let mark = self.marks[handle.index()];
        let hint = self.remove(vertex.id).and_then(|(_, neighbour)| neighbour);
        let handle = self.insert(vertex, hint)?;
        self.marks[handle.index()] = mark;
        Ok(())
    }

    /// The flags of a vertex (see [`Layer::marks`]).
    pub(crate) fn mark(&self, handle: FixedVertexHandle) -> u8 {
        self.marks[handle.index()]
    }

    /// Sets the flags `bits` on the vertex of `id` (if `include_self`) and on its neighbours;
    /// appends the ids of those that lacked them to `ids` (a deduplicating work list).
    pub(crate) fn flag_around(
        &mut self,
        id: u64,
        bits: u8,
        include_self: bool,
        ids: &mut Vec<u64>,
    ) {
        let Some(&handle) = self.handles.get(&id) else {
            return;
        };
        if include_self && self.marks[handle.index()] & bits == 0 {
            self.marks[handle.index()] |= bits;
            ids.push(id);
        }
        for edge in self.triangles.vertex(handle).out_edges() {
            let mark = &mut self.marks[edge.to().fix().index()];
            if *mark & bits == 0 {
                *mark |= bits;
                ids.push(edge.to().data().id);
            }
        }
    }

    /// Clears the flags `bits` of a vertex.
    pub(crate) fn clear_mark(&mut self, handle: FixedVertexHandle, bits: u8) {
        self.marks[handle.index()] &= !bits;
    }

    /// Sets the flags `bits` of the vertex of `id` and returns the vertex, if held.
    pub(crate) fn mark_seen(&mut self, id: u64, bits: u8) -> Option<MeshVertex> {
        let handle = *self.handles.get(&id)?;
        self.marks[handle.index()] |= bits;
        Some(*self.triangles.vertex(handle).data())
    }

    /// Appends the ids of the vertices lacking every flag of `bits`, then clears `bits`
    /// everywhere (one pass over the flags, no hashing).
    pub(crate) fn drain_unmarked(&mut self, bits: u8, ids: &mut Vec<u64>) {
        for (index, mark) in self.marks.iter_mut().enumerate() {
            if *mark & bits == 0 {
                let handle = FixedVertexHandle::from_index(index);
                ids.push(self.triangles.vertex(handle).data().id);
            }
            *mark &= !bits;
        }
    }

    /// Sets (`on`) or clears the flags `bits` of the vertex of `id`, if held.
    pub(crate) fn set_mark(&mut self, id: u64, bits: u8, on: bool) {
        if let Some(&handle) = self.handles.get(&id) {
            let mark = &mut self.marks[handle.index()];
            *mark = if on { *mark | bits } else { *mark & !bits };
        }
    }

    /// Sets the depth of a held vertex (its position, hence the triangulation, is unchanged).
    pub(crate) fn set_depth(&mut self, id: u64, depth_m: f32) {
        if let Some(&handle) = self.handles.get(&id) {
            self.triangles.vertex_data_mut(handle).depth_m = depth_m;
        }
    }

    /// Whether the vertex can move to `pixel` without changing the triangulation: it is not on
    /// the convex hull, every face of its star stays counter-clockwise, and every edge of the
    /// star (spokes and link) stays locally Delaunay — which makes the whole triangulation
    /// Delaunay again. The tests are conservative: near-degenerate cases say no.
    fn can_move_in_place(&self, handle: FixedVertexHandle, pixel: Vec2) -> bool {
        let p = Point2::new(pixel.x as f64, pixel.y as f64);
        let vertex = self.triangles.vertex(handle);
        let mut degree = 0;
        for edge in vertex.out_edges() {
            degree += 1;
            let (link, twin) = (edge.next(), edge.rev());
            if edge.face().is_outer() || twin.face().is_outer() {
                return false;
            }
            let (a, b) = (edge.to().position(), link.to().position());
            let c = twin.next().to().position();
            if !is_ccw(p, a, b) || in_circle_or_near(p, a, b, c) {
                return false;
            }
            let across = link.rev();
            if !across.face().is_outer()
                && in_circle_or_near(p, a, b, across.next().to().position())
            {
                return false;
            }
        }
        degree >= 3
    }

    /// The vertices around `handle` (its 1-ring, in angular order) with their handles.
    pub(crate) fn ring(
        &self,
        handle: FixedVertexHandle,
    ) -> impl Iterator<Item = (FixedVertexHandle, MeshVertex)> + '_ {
        self.triangles
            .vertex(handle)
            .out_edges()
            .map(|edge| (edge.to().fix(), *edge.to().data()))
    }
}

/// Relative round-off allowance of the floating-point predicates below: far above their
/// error bounds (about 10 ε of the permanent), so a "yes" is certain; a "no" only costs the
/// fallback (remove + insert with exact predicates).
const PREDICATE_SLACK: f64 = 1e-9;

/// Whether `a`, `b`, `c` turn counter-clockwise, clearly.
fn is_ccw(a: Point2<f64>, b: Point2<f64>, c: Point2<f64>) -> bool {
    let (abx, aby, acx, acy) = (b.x - a.x, b.y - a.y, c.x - a.x, c.y - a.y);
    let (left, right) = (abx * acy, aby * acx);
    left - right > PREDICATE_SLACK * (left.abs() + right.abs())
}

/// Whether `d` lies inside, on or near the circle through the counter-clockwise `a`, `b`, `c`.
fn in_circle_or_near(a: Point2<f64>, b: Point2<f64>, c: Point2<f64>, d: Point2<f64>) -> bool {
    let rows = [a, b, c].map(|p| {
        let (x, y) = (p.x - d.x, p.y - d.y);
        (x, y, x * x + y * y)
    });
    let mut det = 0.0;
    let mut permanent = 0.0;
    for i in 0..3 {
        let (j, k) = ((i + 1) % 3, (i + 2) % 3);
        let (left, right) = (rows[j].0 * rows[k].1, rows[k].0 * rows[j].1);
        det += rows[i].2 * (left - right);
        permanent += rows[i].2 * (left.abs() + right.abs());
    }
    det >= -PREDICATE_SLACK * permanent
}
