//! The shadow grid of the shadow-propagation light model (Pałubicki et al. 2009).
//!
//! A voxel grid of shadow values s (J vertical). Every node of the tree (the end of an internode,
//! where its buds and leaves sit) in voxel (I, J, K) adds Δs = a·b^(−q) to the voxels
//! (I ± p, J − q, K ± p), q = 0..q_max, p = 0..q: a pyramid of shade below it. The light exposure
//! of a bud is L = max(C − s + a, 0); the `+ a` cancels the bud's own contribution.
//!
//! Values are fixed-point integers, so adding and removing nodes in any order gives exactly the
//! same grid: incremental updates during growth, a rebuild after loading and an "ungrow" all agree
//! bit for bit. The grid is dense over a box that grows (with slack) as the tree does.

use glam::{IVec3, Vec3};

/// Fixed-point scale of shadow values: 1.0 of shadow = 65 536 units.
const UNITS_PER_SHADOW: f32 = 65_536.0;

#[derive(Clone, Debug, Default)]
pub struct ShadowGrid {
    voxel_size: f32,
    /// Δs per pyramid level q, in fixed-point units.
    level_units: Vec<i32>,
    /// Voxel coordinates of `values[0]`.
    min_voxel: IVec3,
    dims: IVec3,
    values: Vec<i32>,
}

impl ShadowGrid {
    /// An empty grid: voxels of `voxel_size` metres, shadow a·b^(−q) for q = 0..=q_max.
    pub fn new(voxel_size: f32, a: f32, b: f32, q_max: u32) -> Self {
        let level_units = (0..=q_max)
            .map(|q| (a * b.powi(-(q as i32)) * UNITS_PER_SHADOW).round() as i32)
            .collect();
        ShadowGrid {
            voxel_size: voxel_size.max(1e-4),
            level_units,
            min_voxel: IVec3::ZERO,
            dims: IVec3::ZERO,
            values: Vec::new(),
        }
    }

    pub fn voxel_size(&self) -> f32 {
        self.voxel_size
    }

    /// Number of voxels currently allocated.
    pub fn num_voxels(&self) -> usize {
        self.values.len()
    }

    fn voxel_of(&self, point_in_world: Vec3) -> IVec3 {
        (point_in_world / self.voxel_size).floor().as_ivec3()
    }

    /// Shadow value s at a point (0 outside the grid).
    pub fn shadow_at(&self, point_in_world: Vec3) -> f32 {
        if !point_in_world.is_finite() {
            return 0.0;
        }
        let v = self.voxel_of(point_in_world) - self.min_voxel;
        if v.cmplt(IVec3::ZERO).any() || v.cmpge(self.dims).any() {
            return 0.0;
        }
        let i = (v.x + self.dims.x * (v.y + self.dims.y * v.z)) as usize;
        self.values[i] as f32 / UNITS_PER_SHADOW
    }

    /// Adds (`sign` = 1) or removes (`sign` = −1) the shadow pyramid of a node.
    pub fn apply_node(&mut self, node_in_world: Vec3, sign: i32) {
        if self.level_units.is_empty() || !node_in_world.is_finite() {
            return;
        }
        let q_max = (self.level_units.len() - 1) as i32;
        let top = self.voxel_of(node_in_world);
        self.ensure_covers(
            top - IVec3::new(q_max, q_max, q_max),
            top + IVec3::new(q_max, 0, q_max),
        );
        for q in 0..=q_max {
            let delta = sign * self.level_units[q as usize];
            let y = top.y - q - self.min_voxel.y;
            for z in (top.z - q - self.min_voxel.z)..=(top.z + q - self.min_voxel.z) {
                let row = (self.dims.x * (y + self.dims.y * z)) as usize;
                let x0 = (top.x - q - self.min_voxel.x) as usize;
                let x1 = (top.x + q - self.min_voxel.x) as usize;
                for value in &mut self.values[row + x0..=row + x1] {
                    *value += delta;
                }
            }
        }
    }

    /// Grows the dense box (with 50% slack per side) so that `lo..=hi` voxels are inside it.
    fn ensure_covers(&mut self, lo: IVec3, hi: IVec3) {
        let cur_hi = self.min_voxel + self.dims - IVec3::ONE;
        if !self.values.is_empty() && lo.cmpge(self.min_voxel).all() && hi.cmple(cur_hi).all() {
            return;
        }
        let (new_lo, new_hi) = if self.values.is_empty() {
            (lo - IVec3::splat(8), hi + IVec3::splat(8))
        } else {
            let slack = (self.dims / 2).max(IVec3::splat(8));
            let want_lo = lo.min(self.min_voxel);
            let want_hi = hi.max(cur_hi);
            (
                IVec3::select(lo.cmplt(self.min_voxel), want_lo - slack, want_lo),
                IVec3::select(hi.cmpgt(cur_hi), want_hi + slack, want_hi),
            )
        };
        let new_dims = new_hi - new_lo + IVec3::ONE;
        let mut values = vec![0; (new_dims.x * new_dims.y * new_dims.z) as usize];
        for z in 0..self.dims.z {
            for y in 0..self.dims.y {
                let src = (self.dims.x * (y + self.dims.y * z)) as usize;
                let o = self.min_voxel + IVec3::new(0, y, z) - new_lo;
                let dst = (o.x + new_dims.x * (o.y + new_dims.y * o.z)) as usize;
                values[dst..dst + self.dims.x as usize]
                    .copy_from_slice(&self.values[src..src + self.dims.x as usize]);
            }
        }
        self.values = values;
        self.min_voxel = new_lo;
        self.dims = new_dims;
    }

    /// True when every voxel is zero (no node casts shade).
    pub fn is_clear(&self) -> bool {
        self.values.iter().all(|&v| v == 0)
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
}
