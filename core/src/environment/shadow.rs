//! The shadow grid of the shadow-propagation light model (Pałubicki et al. 2009).
//!
//! A voxel grid of shadow values s (J vertical). Every node of the tree (the end of an internode,
//! where its buds and leaves sit) in voxel (I, J, K) adds Δs = a·b^(−q) to the voxels
//! (I ± p, J − q, K ± p), q = 0..q_max, p = 0..q: a pyramid of shade below it. The light exposure
//! of a bud is L = max(C − s + a, 0); the `+ a` cancels the bud's own contribution.
//!
//! Values are fixed-point integers, so adding and removing nodes in any order gives exactly the
//! same grid: incremental updates during growth, a rebuild after loading and an "ungrow" all agree
//! bit for bit. Voxels live in 8³ bricks allocated where shade falls (see [`ShadowGrid`]).
//!
//! Within a brick layer every column along z is stored as differences: a voxel's value is the
//! sum of its column's entries from the brick's first row up to its own. A pyramid level then
//! adds Δs on the first row of its square in the brick and takes it off the row after the last
//! (two row updates, whatever the square's depth), and a lookup sums at most eight entries.

use glam::{IVec3, Vec3};

/// Fixed-point scale of shadow values: 1.0 of shadow = 65 536 units.
const UNITS_PER_SHADOW: f32 = 65_536.0;
/// Voxels per brick edge (a power of two); bricks are 8³ voxels, x fastest, then z, then y, so
/// one horizontal layer of a brick (what a pyramid level touches) is one contiguous run.
const BRICK_SHIFT: i32 = 3;
const BRICK: i32 = 1 << BRICK_SHIFT;
const BRICK_VOXELS: usize = (BRICK * BRICK * BRICK) as usize;
/// Nodes whose voxel lies further than this from the origin along some axis (the tree's base)
/// cast no shade: 20 m at the smallest voxel a species may have (2 cm), 41 m at the growth
/// benchmark's 4 cm, 133 m at the presets' 13 cm; no tree reaches that far in its own voxels,
/// and the bound keeps the brick index to at most about 270³ cells whatever a damaged file
/// holds.
pub const MAX_VOXEL_COORD: i32 = 1024;
/// The deepest pyramid a grid casts (q_max; a species' `shadow_depth_voxels` may not ask for
/// more).
pub const MAX_SHADOW_DEPTH_VOXELS: u32 = 64;
/// Marks a brick-index cell that has no brick yet.
const NO_BRICK: u32 = u32::MAX;
/// Distance in voxels from `v` to brick `b`'s voxels along one axis (0 inside it).
fn axis_gap(v: i32, b: i32) -> i32 {
    let first = b << BRICK_SHIFT;
    (first - v).max(v - (first + BRICK - 1)).max(0)
}

/// Asks the CPU to bring the cache line holding `value` closer (a hint: it changes nothing
/// else, and does nothing on targets without the instruction).
#[inline(always)]
fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch only hints at the cache; it never faults and reads or writes nothing
    // that the program sees, and the address comes from a live reference.
    unsafe {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        _mm_prefetch::<_MM_HINT_T0>(std::ptr::from_ref(value).cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}

/// Calls `f(brick, levels)` for every brick the shadow pyramid of a node in voxel `top` (levels
/// q = 0..=`q_max`) reaches, with the levels whose square lies partly in it.
#[inline(always)]
fn for_each_pyramid_brick(
    top: IVec3,
    q_max: i32,
    mut f: impl FnMut(IVec3, std::ops::RangeInclusive<i32>),
) {
    let lo = top - IVec3::splat(q_max);
    let hi = top + IVec3::new(q_max, 0, q_max);
    for by in (lo.y >> BRICK_SHIFT)..=(hi.y >> BRICK_SHIFT) {
        // Levels whose layer y = top.y − q lies in this brick layer.
        let q_lo = top.y - hi.y.min((by << BRICK_SHIFT) + BRICK - 1);
        let q_hi = top.y - lo.y.max(by << BRICK_SHIFT);
        for bz in (lo.z >> BRICK_SHIFT)..=(hi.z >> BRICK_SHIFT) {
            let gap_z = axis_gap(top.z, bz);
            for bx in (lo.x >> BRICK_SHIFT)..=(hi.x >> BRICK_SHIFT) {
                // The smallest level whose square reaches this brick column.
                let q_first = q_lo.max(gap_z).max(axis_gap(top.x, bx));
                if q_first <= q_hi {
                    f(IVec3::new(bx, by, bz), q_first..=q_hi);
                }
            }
        }
    }
}

/// A brick a shadow pyramid reaches, as [`ShadowGrid::apply_node`] plans it: brick index, brick
/// coordinates and the levels q whose square lies partly in the brick.
type PyramidBrick = (usize, IVec3, std::ops::RangeInclusive<i32>);

/// The part of a pyramid level's square (half-width q around the node's column) inside one
/// brick, in the brick's own columns x0..=x1 and rows z0..=z1.
struct Square {
    x0: usize,
    x1: usize,
    z0: usize,
    z1: usize,
}

impl Square {
    #[inline(always)]
    fn of_level(top: IVec3, q: i32, brick: IVec3) -> Square {
        let first = brick << BRICK_SHIFT;
        let last = first + IVec3::splat(BRICK - 1);
        let local = |v: i32| (v & (BRICK - 1)) as usize;
        Square {
            x0: local((top.x - q).max(first.x)),
            x1: local((top.x + q).min(last.x)),
            z0: local((top.z - q).max(first.z)),
            z1: local((top.z + q).min(last.z)),
        }
    }

    /// The row after the square's last (row 0 when the square runs to the brick's end).
    fn end_row(&self) -> usize {
        (self.z1 + 1) & (ROW - 1)
    }
}

/// Voxels in one row of a brick (along x).
const ROW: usize = BRICK as usize;
/// `COLUMN_MASKS[x0][x1]`: all ones in lanes x0..=x1 of a brick row, zero elsewhere.
const COLUMN_MASKS: [[[i32; ROW]; ROW]; ROW] = {
    let mut masks = [[[0; ROW]; ROW]; ROW];
    let mut x0 = 0;
    while x0 < ROW {
        let mut x1 = x0;
        while x1 < ROW {
            let mut x = x0;
            while x <= x1 {
                masks[x0][x1][x] = -1;
                x += 1;
            }
            x1 += 1;
        }
        x0 += 1;
    }
    masks
};
/// One horizontal layer of a brick, 8 rows (z) of 8 entries (x), aligned to cache lines so that
/// a row never straddles two. Entry (z, x) is the shadow of voxel (z, x) minus that of (z − 1, x)
/// (row 0 holds its own values).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Layer([[i32; ROW]; ROW]);
/// Bricks are stored in chunks of this many, so adding one never moves the others.
const BRICKS_PER_CHUNK: usize = 64;

/// Shadow values in bricks of 8³ voxels, allocated on first touch and found through a dense
/// index over brick coordinates. Growing the crown only grows the small index; bricks never move,
/// so the cost of adding a node is its pyramid alone, whatever the size of the tree.
///
/// Every grid (a clone too) has its own [`ShadowGrid::id`], and every change bumps its
/// [`ShadowGrid::version`] and marks the bricks it touched with it, so that a reader can tell
/// whether the shadow at a point may have changed since it last looked
/// ([`ShadowGrid::changed_since`]).
#[derive(Debug)]
pub struct ShadowGrid {
    voxel_size: f32,
    /// Δs per pyramid level q, in fixed-point units.
    level_units: Vec<i32>,
    /// Brick coordinates of `brick_of[0]`.
    min_brick: IVec3,
    brick_dims: IVec3,
    /// Index into `values` (in bricks) of each brick cell, or [`NO_BRICK`].
    brick_of: Vec<u32>,
    /// Brick after brick in chunks of [`BRICKS_PER_CHUNK`], each brick 8³ values with x
    /// fastest, then z, then y.
    chunks: Vec<Box<[Layer]>>,
    num_bricks: usize,
    /// Working memory of [`ShadowGrid::apply_node`]: the bricks a pyramid reaches (index,
    /// brick coordinates, levels in it).
    reached: Vec<PyramidBrick>,
    /// This grid's own number (see [`ShadowGrid::id`]).
    id: u64,
    /// Changes so far, and the change that last touched each brick (by brick index).
    version: u64,
    brick_version: Vec<u64>,
}

/// The next [`ShadowGrid::id`].
static NEXT_GRID_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);

fn fresh_grid_id() -> u64 {
    NEXT_GRID_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

impl Default for ShadowGrid {
    fn default() -> Self {
        ShadowGrid {
            voxel_size: 0.0,
            level_units: Vec::new(),
            min_brick: IVec3::ZERO,
            brick_dims: IVec3::ZERO,
            brick_of: Vec::new(),
            chunks: Vec::new(),
            num_bricks: 0,
            reached: Vec::new(),
            id: fresh_grid_id(),
            version: 0,
            brick_version: Vec::new(),
        }
    }
}

impl Clone for ShadowGrid {
    /// The same values under a new [`ShadowGrid::id`]: the copy's changes are its own.
    fn clone(&self) -> Self {
        ShadowGrid {
            voxel_size: self.voxel_size,
            level_units: self.level_units.clone(),
            min_brick: self.min_brick,
            brick_dims: self.brick_dims,
            brick_of: self.brick_of.clone(),
            chunks: self.chunks.clone(),
            num_bricks: self.num_bricks,
            reached: Vec::new(),
            id: fresh_grid_id(),
            version: self.version,
            brick_version: self.brick_version.clone(),
        }
    }
}

impl ShadowGrid {
    /// An empty grid: voxels of `voxel_size` metres, shadow a·b^(−q) for q = 0..=q_max (at most
    /// [`MAX_SHADOW_DEPTH_VOXELS`]).
    pub fn new(voxel_size: f32, a: f32, b: f32, q_max: u32) -> Self {
        let level_units = (0..=q_max.min(MAX_SHADOW_DEPTH_VOXELS))
            .map(|q| (a * b.powi(-(q as i32)) * UNITS_PER_SHADOW).round() as i32)
            .collect();
        ShadowGrid {
            voxel_size: voxel_size.max(1e-4),
            level_units,
            ..ShadowGrid::default()
        }
    }

    pub fn voxel_size(&self) -> f32 {
        self.voxel_size
    }

    /// Number of voxels currently allocated.
    pub fn num_voxels(&self) -> usize {
        self.num_bricks * BRICK_VOXELS
    }

    /// Layer `local_y` of brick `brick`: 8 rows (z) of 8 values (x).
    fn brick_layer(&self, brick: usize, local_y: usize) -> &[[i32; ROW]; ROW] {
        let layer = (brick % BRICKS_PER_CHUNK) * ROW + (local_y & (ROW - 1));
        &self.chunks[brick / BRICKS_PER_CHUNK][layer].0
    }

    fn voxel_of(&self, point_in_world: Vec3) -> IVec3 {
        super::grid::floor_to_ivec3(point_in_world / self.voxel_size)
    }

    /// Index in `brick_of` of brick coordinates `b`, if inside the index box.
    fn brick_cell(&self, b: IVec3) -> Option<usize> {
        let o = b - self.min_brick;
        if o.cmplt(IVec3::ZERO).any() || o.cmpge(self.brick_dims).any() {
            return None;
        }
        Some((o.x + self.brick_dims.x * (o.y + self.brick_dims.y * o.z)) as usize)
    }

    /// A number no other grid of this process has (a clone gets a new one).
    pub fn id(&self) -> u64 {
        self.id
    }

    /// How many changes (calls of [`ShadowGrid::apply_node`] and
    /// [`ShadowGrid::apply_nodes`]) this grid has seen.
    pub fn version(&self) -> u64 {
        self.version
    }

    /// False when the shadow at `point_in_world` is certainly what it was when the grid was
    /// at `version` ([`ShadowGrid::version`]): no change since touched the brick holding it
    /// (a point in no brick has had no shade since the grid began). True otherwise.
    pub fn changed_since(&self, point_in_world: Vec3, version: u64) -> bool {
        if version >= self.version {
            return false;
        }
        if !point_in_world.is_finite() {
            return false;
        }
        let v = self.voxel_of(point_in_world);
        let Some(cell) = self.brick_cell(v >> BRICK_SHIFT) else {
            return false;
        };
        let brick = self.brick_of[cell];
        brick != NO_BRICK && self.brick_version[brick as usize] > version
    }

    /// How many of the grid's bricks a change since `version` touched, and how many bricks it
    /// has (a reader can tell whether asking [`ShadowGrid::changed_since`] point by point pays).
    pub fn bricks_changed_since(&self, version: u64) -> (usize, usize) {
        let changed = self.brick_version.iter().filter(|&&v| v > version).count();
        (changed, self.num_bricks)
    }

    /// Shadow value s at a point (0 where no node casts shade).
    pub fn shadow_at(&self, point_in_world: Vec3) -> f32 {
        if !point_in_world.is_finite() {
            return 0.0;
        }
        let v = self.voxel_of(point_in_world);
        let Some(cell) = self.brick_cell(v >> BRICK_SHIFT) else {
            return 0.0;
        };
        let brick = self.brick_of[cell];
        if brick == NO_BRICK {
            return 0.0;
        }
        let local = (v & (BRICK - 1)).as_uvec3();
        let layer = self.brick_layer(brick as usize, local.y as usize);
        // The column's differences up to this row (a fixed loop of eight masked adds).
        let (x, z) = (local.x as usize, local.z);
        let mut value = 0i32;
        for (row, r) in layer.iter().zip(0u32..) {
            value = value.wrapping_add(if r <= z { row[x] } else { 0 });
        }
        value as f32 / UNITS_PER_SHADOW
    }

    /// Adds (`sign` = 1) or removes (`sign` = −1) the shadow pyramid of a node (none for a node
    /// beyond [`MAX_VOXEL_COORD`]).
    ///
    /// Brick by brick: each brick the pyramid reaches is looked up once, then the levels q that
    /// lie in it add Δs, masked to their square's columns, on the row where the square starts in
    /// the brick and take it off the row after the one where it ends (if that row is in the
    /// brick): two fixed 8-wide updates per level and brick, no loop over the square's rows.
    /// A first pass over the same rows only asks for their cache lines, so that the second
    /// waits on memory once for all of them rather than once per row.
    pub fn apply_node(&mut self, node_in_world: Vec3, sign: i32) {
        self.version += 1;
        let mut reached = std::mem::take(&mut self.reached);
        if let Some(top) = self.plan_pyramid(node_in_world, &mut reached) {
            self.add_pyramid(top, &reached, sign);
        }
        self.reached = reached;
    }

    /// The first pass of [`ShadowGrid::apply_node`]: the voxel of the node, and in `reached`
    /// the bricks its pyramid reaches (allocated if new) with the levels in each, their rows
    /// asked for; `None` when the node casts no shade.
    fn plan_pyramid(
        &mut self,
        node_in_world: Vec3,
        reached: &mut Vec<PyramidBrick>,
    ) -> Option<IVec3> {
        reached.clear();
        if self.level_units.is_empty() || !node_in_world.is_finite() {
            return None;
        }
        let q_max = (self.level_units.len() - 1) as i32;
        let top = self.voxel_of(node_in_world);
        if top.cmplt(IVec3::splat(-MAX_VOXEL_COORD)).any()
            || top.cmpgt(IVec3::splat(MAX_VOXEL_COORD)).any()
        {
            return None;
        }
        let lo = top - IVec3::splat(q_max);
        let hi = top + IVec3::new(q_max, 0, q_max);
        self.ensure_index_covers(lo >> BRICK_SHIFT, hi >> BRICK_SHIFT);
        for_each_pyramid_brick(top, q_max, |b, levels| {
            let brick = self.brick_at(b);
            let (_, layers) = self.brick_layers_mut(brick);
            for q in levels.clone() {
                let square = Square::of_level(top, q, b);
                let layer = &layers[((top.y - q) & (BRICK - 1)) as usize].0;
                prefetch(&layer[square.z0]);
                prefetch(&layer[square.end_row()]);
            }
            reached.push((brick, b, levels));
        });
        Some(top)
    }

    /// The second pass of [`ShadowGrid::apply_node`]: the row updates of the pyramid of a node
    /// in voxel `top` over the bricks `reached` that [`ShadowGrid::plan_pyramid`] found.
    fn add_pyramid(&mut self, top: IVec3, reached: &[PyramidBrick], sign: i32) {
        for (brick, b, levels) in reached {
            self.brick_version[*brick] = self.version;
            let (units, layers) = self.brick_layers_mut(*brick);
            for q in levels.clone() {
                let square = Square::of_level(top, q, *b);
                let delta = sign * units[q as usize];
                let layer = &mut layers[((top.y - q) & (BRICK - 1)) as usize].0;
                // A square that runs to the brick's last row has no row after it here: the
                // update then lands on row 0 with nothing to take off (no branch).
                let end_delta = if square.z1 + 1 < ROW { delta } else { 0 };
                let columns = &COLUMN_MASKS[square.x0][square.x1];
                for (value, &m) in layer[square.z0].iter_mut().zip(columns) {
                    *value = value.wrapping_add(delta & m);
                }
                for (value, &m) in layer[square.end_row()].iter_mut().zip(columns) {
                    *value = value.wrapping_sub(end_delta & m);
                }
            }
        }
    }

    /// [`ShadowGrid::apply_node`] for many nodes: the same grid as one call each (integer
    /// sums do not depend on the order), made in brick order so that neighbouring pyramids
    /// find their bricks in cache, and each node's rows asked for while the previous node's
    /// are updated.
    pub fn apply_nodes(&mut self, nodes: impl IntoIterator<Item = Vec3>, sign: i32) {
        self.version += 1;
        let mut keyed: Vec<(u64, Vec3)> = nodes
            .into_iter()
            .map(|p| {
                let b = (self.voxel_of(p) >> BRICK_SHIFT).as_uvec3().as_u64vec3();
                // Brick coordinates as (y, z, x), each kept to 21 bits.
                let mask = (1 << 21) - 1;
                ((b.y & mask) << 42 | (b.z & mask) << 21 | (b.x & mask), p)
            })
            .collect();
        keyed.sort_unstable_by_key(|&(key, _)| key);
        let mut current = std::mem::take(&mut self.reached);
        let mut next = Vec::with_capacity(current.capacity());
        let mut pending = None;
        for (_, p) in keyed {
            // Bricks never move once allocated: planning the next pyramid leaves the current
            // one's brick indices valid.
            let planned = self.plan_pyramid(p, &mut next);
            if let Some(top) = pending {
                self.add_pyramid(top, &current, sign);
            }
            std::mem::swap(&mut current, &mut next);
            pending = planned;
        }
        if let Some(top) = pending {
            self.add_pyramid(top, &current, sign);
        }
        self.reached = current;
    }

    /// The layers (y = 0..8) of brick `brick`, with Δs of every level.
    fn brick_layers_mut(&mut self, brick: usize) -> (&[i32], &mut [Layer; ROW]) {
        let first = (brick % BRICKS_PER_CHUNK) * ROW;
        let chunk = &mut self.chunks[brick / BRICKS_PER_CHUNK][first..first + ROW];
        let layers = <&mut [Layer; ROW]>::try_from(chunk).unwrap_or_else(|_| unreachable!());
        (&self.level_units, layers)
    }

    /// The brick at brick coordinates `b` (inside the index box), allocated if missing.
    fn brick_at(&mut self, b: IVec3) -> usize {
        let Some(cell) = self.brick_cell(b) else {
            unreachable!("ensure_index_covers runs before every brick access");
        };
        if self.brick_of[cell] == NO_BRICK {
            if self.num_bricks == self.chunks.len() * BRICKS_PER_CHUNK {
                self.chunks
                    .push(vec![Layer([[0; ROW]; ROW]); BRICKS_PER_CHUNK * ROW].into_boxed_slice());
            }
            self.brick_of[cell] = self.num_bricks as u32;
            self.num_bricks += 1;
            self.brick_version.push(self.version);
        }
        self.brick_of[cell] as usize
    }

    /// Grows the brick index so that bricks `lo..=hi` are inside it, with slack of half the
    /// extent (at least 2 bricks) on every side that overflows.
    fn ensure_index_covers(&mut self, lo: IVec3, hi: IVec3) {
        let cur_hi = self.min_brick + self.brick_dims - IVec3::ONE;
        if !self.brick_of.is_empty() && lo.cmpge(self.min_brick).all() && hi.cmple(cur_hi).all() {
            return;
        }
        let (new_lo, new_hi) = if self.brick_of.is_empty() {
            (lo - IVec3::splat(2), hi + IVec3::splat(2))
        } else {
            let slack = (self.brick_dims / 2).max(IVec3::splat(2));
            (
                IVec3::select(lo.cmplt(self.min_brick), lo - slack, self.min_brick),
                IVec3::select(hi.cmpgt(cur_hi), hi + slack, cur_hi),
            )
        };
        // Never beyond the bricks that nodes within MAX_VOXEL_COORD can shade.
        let limit = IVec3::splat((MAX_VOXEL_COORD + MAX_SHADOW_DEPTH_VOXELS as i32) >> BRICK_SHIFT)
            + IVec3::ONE;
        let (new_lo, new_hi) = (new_lo.max(-limit).min(lo), new_hi.min(limit).max(hi));
        let new_dims = new_hi - new_lo + IVec3::ONE;
        let mut brick_of = vec![NO_BRICK; (new_dims.x * new_dims.y * new_dims.z) as usize];
        for z in 0..self.brick_dims.z {
            for y in 0..self.brick_dims.y {
                let src = (self.brick_dims.x * (y + self.brick_dims.y * z)) as usize;
                let o = self.min_brick + IVec3::new(0, y, z) - new_lo;
                let dst = (o.x + new_dims.x * (o.y + new_dims.y * o.z)) as usize;
                let n = self.brick_dims.x as usize;
                brick_of[dst..dst + n].copy_from_slice(&self.brick_of[src..src + n]);
            }
        }
        self.brick_of = brick_of;
        self.min_brick = new_lo;
        self.brick_dims = new_dims;
    }

    /// True when every voxel is zero (no node casts shade).
    pub fn is_clear(&self) -> bool {
        self.chunks.iter().all(|c| {
            c.iter()
                .all(|layer| layer.0.iter().flatten().all(|&v| v == 0))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_node_shades_a_pyramid_below_it_and_removal_restores_zero() {
        let mut grid = ShadowGrid::new(0.1, 1.0, 2.0, 3);
        let node = Vec3::new(0.05, 1.05, 0.05);
        grid.apply_node(node, 1);
        assert!((grid.shadow_at(node) - 1.0).abs() < 1e-4);
        assert!((grid.shadow_at(node - Vec3::Y * 0.1) - 0.5).abs() < 1e-4);
        assert!((grid.shadow_at(node + Vec3::new(0.1, -0.1, 0.1)) - 0.5).abs() < 1e-4);
        assert_eq!(grid.shadow_at(node + Vec3::new(0.2, -0.1, 0.0)), 0.0);
        assert_eq!(grid.shadow_at(node + Vec3::Y * 0.1), 0.0);
        grid.apply_node(Vec3::new(5.0, 9.0, -3.0), 1);
        grid.apply_node(node, -1);
        grid.apply_node(Vec3::new(5.0, 9.0, -3.0), -1);
        assert!(grid.is_clear());
    }

    #[test]
    fn pyramids_across_brick_borders_and_negative_coordinates_sum_exactly() {
        // Brute force over a dense box: the pyramid formula, summed over nodes.
        let (a, b, q_max, voxel) = (1.0f32, 1.5f32, 5i32, 0.1f32);
        let mut grid = ShadowGrid::new(voxel, a, b, q_max as u32);
        let nodes = [
            Vec3::new(-0.75, 0.35, 0.05),
            Vec3::new(0.05, 1.25, -0.65),
            Vec3::new(0.79, -0.41, 0.81),
            Vec3::new(-0.05, 0.75, -0.05),
        ];
        for n in nodes {
            grid.apply_node(n, 1);
        }
        for x in -16..16 {
            for y in -16..16 {
                for z in -16..16 {
                    let v = IVec3::new(x, y, z);
                    let expected: i32 = nodes
                        .iter()
                        .map(|n| {
                            let top = (*n / voxel).floor().as_ivec3();
                            let q = top.y - y;
                            let p = (x - top.x).abs().max((z - top.z).abs());
                            if (0..=q_max).contains(&q) && p <= q {
                                (a * b.powi(-q) * UNITS_PER_SHADOW).round() as i32
                            } else {
                                0
                            }
                        })
                        .sum();
                    let at = (v.as_vec3() + Vec3::splat(0.5)) * voxel;
                    let got = grid.shadow_at(at);
                    assert_eq!((got * UNITS_PER_SHADOW).round() as i32, expected, "{v}");
                }
            }
        }
    }
}
