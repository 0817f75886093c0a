//! Lasso (Longay 2014 §5.2.2): a closed 2D silhouette drawn on a plane becomes a 3D envelope
//! filled with attraction points.
//!
//! 1. The outline is rasterised on the plane (even–odd rule).
//! 2. Erosion of the silhouette, computed at once as an exact Euclidean distance transform
//!    (Felzenszwalb–Huttenlocher lower envelopes), gives for each cell the time D at which erosion
//!    reaches it. The chordal axis (Hall 1989) is the ridge of D: cells where erosion fronts from
//!    opposite sides meet, i.e. where D grows by clearly less than one cell per cell step.
//! 3. Inflation as in Teddy (Igarashi et al. 1999): every axis cell a carries a circular cross
//!    section of radius D(a); the envelope is the union of the balls B(a, D(a)), so its
//!    half-thickness above a plane point p is h(p) = max_a √(D(a)² − ‖p − a‖²).
//! 4. Points are sampled uniformly in the envelope's bounding box and kept if inside.

use glam::{Vec2, Vec3};

use super::EditError;
use crate::growth::Tree;
use crate::rng::Rng;

/// A closed outline on a plane through `origin` spanned by the orthonormal `axis_u`, `axis_v`.
#[derive(Clone, Debug, PartialEq)]
pub struct Lasso {
    pub origin: Vec3,
    pub axis_u: Vec3,
    pub axis_v: Vec3,
    /// Outline in plane coordinates (metres along `axis_u`, `axis_v`); closed implicitly.
    pub outline: Vec<Vec2>,
}

/// The inflated envelope of a lasso, as a half-thickness field over a raster of the plane.
#[derive(Clone, Debug)]
pub struct LassoEnvelope {
    origin: Vec3,
    axis_u: Vec3,
    axis_v: Vec3,
    normal: Vec3,
    /// Plane coordinates of the centre of cell (0, 0).
    grid_min: Vec2,
    cell_m: f32,
    width: usize,
    height: usize,
    /// Half-thickness h (metres) of the envelope at each cell; 0 outside the silhouette.
    half_thickness: Vec<f32>,
    /// Chordal axis cells as plane coordinates, with their erosion distance D (metres).
    axis: Vec<(Vec2, f32)>,
    max_half_thickness: f32,
}

impl Lasso {
    /// Validates the plane and the outline.
    pub fn new(
        origin: Vec3,
        axis_u: Vec3,
        axis_v: Vec3,
        outline: Vec<Vec2>,
    ) -> Result<Lasso, EditError> {
        let finite = origin.is_finite()
            && axis_u.is_finite()
            && axis_v.is_finite()
            && outline.iter().all(|p| p.is_finite());
        if !finite {
            return Err(EditError::NonFinite {
                what: "lasso plane or outline",
            });
        }
        let (Some(u), Some(v)) = (axis_u.try_normalize(), axis_v.try_normalize()) else {
            return Err(EditError::BadParameter {
                name: "lasso plane axis length",
                value: axis_u.length().min(axis_v.length()),
            });
        };
        if u.dot(v).abs() > 1e-3 {
            return Err(EditError::BadParameter {
                name: "lasso plane axes dot product",
                value: u.dot(v),
            });
        }
        if polygon_area(&outline).abs() < 1e-8 {
            return Err(EditError::DegenerateLasso {
                points: outline.len(),
            });
        }
        Ok(Lasso {
            origin,
            axis_u: u,
            axis_v: v,
            outline,
        })
    }

    /// Computes the envelope on a raster whose longer side has `resolution` cells (≥ 8).
    pub fn envelope(&self, resolution: usize) -> LassoEnvelope {
        let resolution = resolution.max(8);
        let (lo, hi) = self.outline.iter().fold(
            (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let cell_m = (hi - lo).max_element() / resolution as f32;
        // One empty cell of margin on each side so that the border counts as outside.
        let grid_min = lo - Vec2::splat(cell_m * 0.5);
        let width = ((hi.x - lo.x) / cell_m).ceil() as usize + 2;
        let height = ((hi.y - lo.y) / cell_m).ceil() as usize + 2;
        let inside = rasterise(&self.outline, grid_min, cell_m, width, height);
        let distance = distance_transform(&inside, width, height);
        let axis = chordal_axis(&distance, width, height, grid_min, cell_m);
        let half_thickness = inflate(&axis, width, height, grid_min, cell_m);
        let max_half_thickness = half_thickness.iter().copied().fold(0.0, f32::max);
        LassoEnvelope {
            origin: self.origin,
            axis_u: self.axis_u,
            axis_v: self.axis_v,
            normal: self.axis_u.cross(self.axis_v),
            grid_min,
            cell_m,
            width,
            height,
            half_thickness,
            axis,
            max_half_thickness,
        }
    }
}

impl LassoEnvelope {
    /// World point → (plane coordinates, signed distance along the plane normal).
    pub fn plane_from_world(&self, p: Vec3) -> (Vec2, f32) {
        let d = p - self.origin;
        (
            Vec2::new(d.dot(self.axis_u), d.dot(self.axis_v)),
            d.dot(self.normal),
        )
    }

    pub fn world_from_plane(&self, uv: Vec2, depth: f32) -> Vec3 {
        self.origin + self.axis_u * uv.x + self.axis_v * uv.y + self.normal * depth
    }

    /// Half-thickness of the envelope above plane point `uv` (0 outside the silhouette).
    pub fn half_thickness_at(&self, uv: Vec2) -> f32 {
        let cell = ((uv - self.grid_min) / self.cell_m).round();
        if cell.x < 0.0 || cell.y < 0.0 {
            return 0.0;
        }
        let (i, j) = (cell.x as usize, cell.y as usize);
        if i >= self.width || j >= self.height {
            return 0.0;
        }
        self.half_thickness[j * self.width + i]
    }

    pub fn contains(&self, p: Vec3) -> bool {
        let (uv, depth) = self.plane_from_world(p);
        depth.abs() <= self.half_thickness_at(uv) && self.half_thickness_at(uv) > 0.0
    }

    /// The chordal axis in world space, each point with its cross-section radius (metres).
    pub fn chordal_axis(&self) -> Vec<(Vec3, f32)> {
        self.axis
            .iter()
            .map(|&(uv, r)| (self.world_from_plane(uv, 0.0), r))
            .collect()
    }

    pub fn max_half_thickness(&self) -> f32 {
        self.max_half_thickness
    }

    /// Fills the envelope with `count` persistent attraction points of `tree` (drawn from the
    /// tree's generator), leaving out those the tree's depth constraint refuses
    /// ([`crate::environment::DepthConstraint`]). Returns how many were added.
    pub fn add_points_to(&self, tree: &mut Tree, count: usize) -> usize {
        let points = self.sample_points(count, &mut tree.rng);
        let mut added = 0;
        for p in points {
            if !tree.environment.depth_allows(p) {
                continue;
            }
            tree.environment.attraction.add_persistent(p);
            added += 1;
        }
        added
    }

    /// `count` points uniform in the envelope, by rejection sampling in its bounding box.
    /// Gives up (returning fewer points) only after 200 tries per point, which a non-empty
    /// envelope never needs.
    pub fn sample_points(&self, count: usize, rng: &mut Rng) -> Vec<Vec3> {
        let mut points = Vec::with_capacity(count);
        if self.max_half_thickness <= 0.0 {
            return points;
        }
        let extent = Vec2::new(self.width as f32, self.height as f32) * self.cell_m;
        let low = self.grid_min - Vec2::splat(self.cell_m * 0.5);
        let mut tries = 0usize;
        while points.len() < count && tries < count.saturating_mul(200) {
            tries += 1;
            let uv = low + Vec2::new(rng.next_f32(), rng.next_f32()) * extent;
            let depth = rng.range_f32(-self.max_half_thickness, self.max_half_thickness);
            let h = self.half_thickness_at(uv);
            if h > 0.0 && depth.abs() <= h {
                points.push(self.world_from_plane(uv, depth));
            }
        }
        points
    }
}

fn polygon_area(outline: &[Vec2]) -> f32 {
    if outline.len() < 3 {
        return 0.0;
    }
    let n = outline.len();
    0.5 * (0..n)
        .map(|i| outline[i].perp_dot(outline[(i + 1) % n]))
        .sum::<f32>()
}

/// Cells whose centre is inside the outline (even–odd rule), row by row from edge crossings.
fn rasterise(
    outline: &[Vec2],
    grid_min: Vec2,
    cell_m: f32,
    width: usize,
    height: usize,
) -> Vec<bool> {
    let mut inside = vec![false; width * height];
    let n = outline.len();
    let mut crossings = Vec::new();
    for j in 0..height {
        let y = grid_min.y + j as f32 * cell_m;
        crossings.clear();
        for i in 0..n {
            let (a, b) = (outline[i], outline[(i + 1) % n]);
            if (a.y <= y) != (b.y <= y) {
                crossings.push(a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x));
            }
        }
        crossings.sort_by(f32::total_cmp);
        for pair in crossings.chunks_exact(2) {
            let first = ((pair[0] - grid_min.x) / cell_m).ceil().max(0.0) as usize;
            let last = ((pair[1] - grid_min.x) / cell_m).floor();
            if last < 0.0 {
                continue;
            }
            let last = (last as usize).min(width - 1);
            for cell in inside[j * width..].iter_mut().take(last + 1).skip(first) {
                *cell = true;
            }
        }
    }
    inside
}

/// Euclidean distance (in cells) from each inside cell to the nearest outside cell centre.
fn distance_transform(inside: &[bool], width: usize, height: usize) -> Vec<f32> {
    let far = ((width * width + height * height) as f32) * 4.0;
    let mut squared: Vec<f32> = inside.iter().map(|&i| if i { far } else { 0.0 }).collect();
    let mut line = vec![0.0f32; width.max(height)];
    let mut out = vec![0.0f32; width.max(height)];
    for x in 0..width {
        for y in 0..height {
            line[y] = squared[y * width + x];
        }
        lower_envelope(&line[..height], &mut out[..height]);
        for y in 0..height {
            squared[y * width + x] = out[y];
        }
    }
    for y in 0..height {
        let row = &mut squared[y * width..(y + 1) * width];
        line[..width].copy_from_slice(row);
        lower_envelope(&line[..width], &mut out[..width]);
        row.copy_from_slice(&out[..width]);
    }
    squared.iter().map(|d| d.sqrt()).collect()
}

/// 1D squared distance transform: out[q] = min_p (q − p)² + f[p] (Felzenszwalb–Huttenlocher).
fn lower_envelope(f: &[f32], out: &mut [f32]) {
    let n = f.len();
    let mut vertices = vec![0usize; n];
    let mut bounds = vec![0.0f32; n + 1];
    let mut k = 0usize;
    bounds[0] = f32::NEG_INFINITY;
    bounds[1] = f32::INFINITY;
    let meet = |q: usize, p: usize| {
        let (qf, pf) = (q as f32, p as f32);
        ((f[q] + qf * qf) - (f[p] + pf * pf)) / (2.0 * qf - 2.0 * pf)
    };
    for q in 1..n {
        let mut s = meet(q, vertices[k]);
        while s <= bounds[k] && k > 0 {
            k -= 1;
            s = meet(q, vertices[k]);
        }
        if s <= bounds[k] {
            // k == 0 and the new parabola dominates everywhere.
            vertices[0] = q;
            bounds[1] = f32::INFINITY;
            continue;
        }
        k += 1;
        vertices[k] = q;
        bounds[k] = s;
        bounds[k + 1] = f32::INFINITY;
    }
    k = 0;
    for (q, slot) in out.iter_mut().enumerate() {
        while bounds[k + 1] < q as f32 {
            k += 1;
        }
        let p = vertices[k];
        let d = q as f32 - p as f32;
        *slot = d * d + f[p];
    }
}

/// Ridge cells of the erosion distance: the slope of D towards every neighbour is well below 1.
fn chordal_axis(
    distance: &[f32],
    width: usize,
    height: usize,
    grid_min: Vec2,
    cell_m: f32,
) -> Vec<(Vec2, f32)> {
    const RIDGE_SLOPE: f32 = 0.75;
    let mut axis = Vec::new();
    for y in 1..height.saturating_sub(1) {
        for x in 1..width.saturating_sub(1) {
            let d = distance[y * width + x];
            if d <= 0.0 {
                continue;
            }
            let mut ridge = true;
            for (dx, dy) in [
                (-1i32, -1i32),
                (0, -1),
                (1, -1),
                (-1, 0),
                (1, 0),
                (-1, 1),
                (0, 1),
                (1, 1),
            ] {
                let (nx, ny) = ((x as i32 + dx) as usize, (y as i32 + dy) as usize);
                let step = ((dx * dx + dy * dy) as f32).sqrt();
                if distance[ny * width + nx] - d >= RIDGE_SLOPE * step {
                    ridge = false;
                    break;
                }
            }
            if ridge {
                let uv = grid_min + Vec2::new(x as f32, y as f32) * cell_m;
                // Erosion reaches the outline half a cell before the first outside cell centre.
                axis.push((uv, (d - 0.5).max(0.5) * cell_m));
            }
        }
    }
    axis
}

/// h(p) = max over axis balls of √(r² − ‖p − a‖²) (Teddy-style circular cross sections).
fn inflate(
    axis: &[(Vec2, f32)],
    width: usize,
    height: usize,
    grid_min: Vec2,
    cell_m: f32,
) -> Vec<f32> {
    let mut h = vec![0.0f32; width * height];
    for &(centre, radius) in axis {
        let c = (centre - grid_min) / cell_m;
        let r_cells = radius / cell_m;
        let x0 = (c.x - r_cells).floor().max(0.0) as usize;
        let y0 = (c.y - r_cells).floor().max(0.0) as usize;
        let x1 = ((c.x + r_cells).ceil() as usize).min(width - 1);
        let y1 = ((c.y + r_cells).ceil() as usize).min(height - 1);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let p = grid_min + Vec2::new(x as f32, y as f32) * cell_m;
                let d2 = radius * radius - p.distance_squared(centre);
                if d2 > 0.0 {
                    let cell = &mut h[y * width + x];
                    *cell = cell.max(d2.sqrt());
                }
            }
        }
    }
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle(radius: f32, n: usize) -> Vec<Vec2> {
        (0..n)
            .map(|i| Vec2::from_angle(i as f32 / n as f32 * std::f32::consts::TAU) * radius)
            .collect()
    }

    #[test]
    fn a_circle_inflates_to_a_ball_like_envelope() {
        let lasso = Lasso::new(Vec3::Y, Vec3::X, Vec3::Y, circle(1.0, 64)).expect("valid lasso");
        let envelope = lasso.envelope(96);
        let h = envelope.max_half_thickness();
        assert!(
            (h - 1.0).abs() < 0.08,
            "half-thickness at the centre {h}, wanted about 1"
        );
        assert!(envelope.contains(Vec3::new(0.0, 1.0, 0.6)));
        assert!(!envelope.contains(Vec3::new(0.0, 1.0, 1.2)));
        assert!(!envelope.contains(Vec3::new(1.1, 1.0, 0.0)));
    }

    #[test]
    fn the_chordal_axis_of_a_long_rectangle_runs_along_its_middle() {
        let outline = vec![
            Vec2::new(-2.0, -0.25),
            Vec2::new(2.0, -0.25),
            Vec2::new(2.0, 0.25),
            Vec2::new(-2.0, 0.25),
        ];
        let lasso = Lasso::new(Vec3::ZERO, Vec3::X, Vec3::Y, outline).expect("valid lasso");
        let envelope = lasso.envelope(160);
        let axis = envelope.chordal_axis();
        let central: Vec<_> = axis.iter().filter(|(p, _)| p.x.abs() < 1.5).collect();
        assert!(
            central.len() > 40,
            "only {} axis cells in the middle",
            central.len()
        );
        for (p, r) in central {
            assert!(p.y.abs() < 0.04, "axis point {p} is off the midline");
            assert!(
                (r - 0.25).abs() < 0.04,
                "cross-section radius {r}, wanted 0.25"
            );
        }
    }

    #[test]
    fn sampled_points_lie_inside_the_silhouette_and_fill_it() {
        let lasso = Lasso::new(Vec3::ZERO, Vec3::X, Vec3::Y, circle(0.5, 48)).expect("valid lasso");
        let envelope = lasso.envelope(64);
        let mut rng = Rng::new(3);
        let points = envelope.sample_points(2000, &mut rng);
        assert_eq!(points.len(), 2000);
        let mut far_out = 0;
        for p in &points {
            assert!(envelope.contains(*p));
            if p.truncate().length() > 0.35 {
                far_out += 1;
            }
        }
        assert!(far_out > 100, "only {far_out} points in the outer ring");
    }

    #[test]
    fn degenerate_outlines_are_refused() {
        let line = vec![Vec2::ZERO, Vec2::X, Vec2::X * 2.0];
        assert!(matches!(
            Lasso::new(Vec3::ZERO, Vec3::X, Vec3::Y, line),
            Err(EditError::DegenerateLasso { points: 3 })
        ));
        assert!(Lasso::new(Vec3::ZERO, Vec3::X, Vec3::X, circle(1.0, 8)).is_err());
    }
}
