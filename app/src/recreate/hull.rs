//! The crown's visual hull (Laurentini 1994): each traced outline with its camera is a cone; the
//! hull is what lies inside every cone, above the ground. It is carved in a voxel grid in metres
//! around the trunk base: a voxel stays when its centre projects inside the outline in every
//! marked view. With one outline the cone is open along the view, so the hull is also cut to a
//! slab of the crown's depth along the view (from the tree's own points, or assumed round).

use glam::{DVec2, DVec3};

use super::footage::TrackedFootage;
use super::marks::polygon_contains;

/// A traced outline rasterised in its frame (raw pixels), with a margin around the image.
pub struct OutlineMask {
    pub frame: usize,
    pub outline: Vec<DVec2>,
    width: i64,
    height: i64,
    inside: Vec<bool>,
}

/// Pixels the mask extends past each image border.
const MASK_MARGIN_PX: i64 = 64;

impl OutlineMask {
    pub fn new(frame: usize, outline: Vec<DVec2>, width: u32, height: u32) -> Self {
        let (w, h) = (
            width as i64 + 2 * MASK_MARGIN_PX,
            height as i64 + 2 * MASK_MARGIN_PX,
        );
        let mut inside = vec![false; (w * h) as usize];
        let (low, high) = outline.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let x0 = (low.x.floor() as i64 + MASK_MARGIN_PX).clamp(0, w);
        let x1 = (high.x.ceil() as i64 + MASK_MARGIN_PX + 1).clamp(0, w);
        let y0 = (low.y.floor() as i64 + MASK_MARGIN_PX).clamp(0, h);
        let y1 = (high.y.ceil() as i64 + MASK_MARGIN_PX + 1).clamp(0, h);
        for y in y0..y1 {
            for x in x0..x1 {
                let centre = DVec2::new((x - MASK_MARGIN_PX) as f64, (y - MASK_MARGIN_PX) as f64);
                inside[(y * w + x) as usize] = polygon_contains(&outline, centre);
            }
        }
        Self {
            frame,
            outline,
            width: w,
            height: h,
            inside,
        }
    }

    /// Whether raw pixel `pixel` lies inside the outline.
    pub fn contains(&self, pixel: DVec2) -> bool {
        let (x, y) = (
            pixel.x.round() as i64 + MASK_MARGIN_PX,
            pixel.y.round() as i64 + MASK_MARGIN_PX,
        );
        (0..self.width).contains(&x)
            && (0..self.height).contains(&y)
            && self.inside[(y * self.width + x) as usize]
    }

    /// Area inside the outline, square pixels (of the rasterised mask).
    pub fn area_px(&self) -> usize {
        self.inside.iter().filter(|&&v| v).count()
    }
}

/// Cut of a one-view hull along the view: keep `|(p − centre)·axis| ≤ half_depth_m`.
#[derive(Clone, Copy, Debug)]
pub struct DepthSlab {
    pub centre: DVec3,
    pub axis: DVec3,
    pub half_depth_m: f64,
}

/// The carved hull: occupied voxels of a grid in the world.
#[derive(Clone, Debug)]
pub struct Hull {
    pub min: DVec3,
    pub voxel_m: f64,
    pub dims: [usize; 3],
    pub occupied: Vec<bool>,
}

impl Hull {
    /// Carves the box `[min, max]` (metres) at about `voxel_m`, keeping voxels above the ground
    /// inside every outline (and the slab, if given).
    pub fn carve(
        footage: &TrackedFootage,
        masks: &[OutlineMask],
        slab: Option<DepthSlab>,
        min: DVec3,
        max: DVec3,
        voxel_m: f64,
    ) -> Hull {
        let size = (max - min).max(DVec3::splat(voxel_m));
        let dims = [0, 1, 2].map(|axis| ((size[axis] / voxel_m).ceil() as usize).clamp(1, 400));
        let mut hull = Hull {
            min,
            voxel_m,
            dims,
            occupied: vec![false; dims[0] * dims[1] * dims[2]],
        };
        let poses: Vec<_> = masks
            .iter()
            .map(|m| footage.world_from_camera[m.frame].map(|p| p.inverse()))
            .collect();
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let p = hull.centre(i, j, k);
                    if footage.height_of(p) < 0.0 {
                        continue;
                    }
                    if let Some(s) = slab
                        && ((p - s.centre).dot(s.axis)).abs() > s.half_depth_m
                    {
                        continue;
                    }
                    let inside_all = masks.iter().zip(&poses).all(|(mask, pose)| {
                        let Some(camera_from_world) = pose else {
                            return false;
                        };
                        let c = camera_from_world.transform_point3(p);
                        c.z > 1e-3
                            && footage
                                .camera
                                .pixel_from_camera(c)
                                .is_some_and(|px| mask.contains(px))
                    });
                    let index = hull.index(i, j, k);
                    hull.occupied[index] = inside_all;
                }
            }
        }
        hull
    }

    fn index(&self, i: usize, j: usize, k: usize) -> usize {
        (k * self.dims[1] + j) * self.dims[0] + i
    }

    /// World position of the centre of voxel (i, j, k).
    pub fn centre(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.min + (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * self.voxel_m
    }

    /// Centres of the occupied voxels.
    pub fn voxels(&self) -> Vec<DVec3> {
        let mut out = Vec::new();
        for k in 0..self.dims[2] {
            for j in 0..self.dims[1] {
                for i in 0..self.dims[0] {
                    if self.occupied[self.index(i, j, k)] {
                        out.push(self.centre(i, j, k));
                    }
                }
            }
        }
        out
    }

    pub fn num_voxels(&self) -> usize {
        self.occupied.iter().filter(|&&v| v).count()
    }

    /// Whether `p` lies in an occupied voxel (or within `dilate` voxels of one).
    pub fn contains(&self, p: DVec3, dilate: usize) -> bool {
        let cell = (p - self.min) / self.voxel_m;
        let d = dilate as i64;
        let (ci, cj, ck) = (
            cell.x.floor() as i64,
            cell.y.floor() as i64,
            cell.z.floor() as i64,
        );
        for k in ck - d..=ck + d {
            for j in cj - d..=cj + d {
                for i in ci - d..=ci + d {
                    let inside = i >= 0
                        && j >= 0
                        && k >= 0
                        && (i as usize) < self.dims[0]
                        && (j as usize) < self.dims[1]
                        && (k as usize) < self.dims[2];
                    if inside && self.occupied[self.index(i as usize, j as usize, k as usize)] {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// Extent of the hull along the unit `axis` (metres, voxel size included).
    pub fn extent_along(&self, axis: DVec3) -> f64 {
        let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in self.voxels() {
            let d = p.dot(axis);
            low = low.min(d);
            high = high.max(d);
        }
        if low > high {
            0.0
        } else {
            high - low + self.voxel_m
        }
    }

    /// The hull shrunk by `margin_m`: voxels whose whole neighbourhood of that radius (a cube)
    /// is in the hull. Growth fills this one, so leaves on the outermost twigs stay inside.
    pub fn eroded(&self, margin_m: f64) -> Hull {
        let r = (margin_m / self.voxel_m).round().max(0.0) as usize;
        let [nx, ny, nz] = self.dims;
        let mut occupied = vec![false; self.occupied.len()];
        for k in r..nz.saturating_sub(r) {
            for j in 0..ny {
                for i in r..nx.saturating_sub(r) {
                    if !self.occupied[self.index(i, j, k)] {
                        continue;
                    }
                    // Not eroded from below: the crown's base is measured, the ground is not a
                    // boundary of the crown's envelope.
                    let j_high = (j + r).min(ny - 1);
                    let kept = (k - r..=k + r).all(|kk| {
                        (j..=j_high).all(|jj| {
                            (i - r..=i + r).all(|ii| self.occupied[self.index(ii, jj, kk)])
                        })
                    });
                    occupied[self.index(i, j, k)] = kept;
                }
            }
        }
        Hull {
            occupied,
            ..self.clone()
        }
    }

    /// Whether the hull touches the sides or top of its box (the box was too small).
    pub fn touches_box(&self) -> bool {
        let [nx, ny, nz] = self.dims;
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let edge = i == 0 || k == 0 || i + 1 == nx || k + 1 == nz || j + 1 == ny;
                    if edge && self.occupied[self.index(i, j, k)] {
                        return true;
                    }
                }
            }
        }
        false
    }
}
