//! Solids standing on the ground, fused from the tracked points of many frames: the part of the
//! occluder that a single frame's depth mesh cannot give.
//!
//! On a plain face (a painted box, a rendered wall) few points are tracked, and those are at its
//! edges and corners. In one frame's image-space triangulation they connect mostly to ground
//! points far behind them, and those triangles span a depth discontinuity: they are (rightly)
//! unknown, so the object's faces become holes, and ground triangles that pass under the object
//! in the image draw the far ground where the object is. Measured on `demo_garden` (the box, 9–13
//! tracked points a frame): from frame 160 on, 60–77% of the box's pixels had no occluder and
//! 14–24% had one farther than the box.
//!
//! Here every tracked point is kept in the world (its position averaged over the frames that
//! saw it), so an object's points accumulate as the camera walks round it. Points higher than
//! [`GroundSolidsConfig::min_height_m`] above the ground are grouped: two are linked when their
//! footprints on the ground lie within [`GroundSolidsConfig::link_distance_m`]. A group of at
//! least [`GroundSolidsConfig::min_points`] points is a solid: the convex hull of its footprints,
//! raised as a vertical prism from the ground to a level top at its second highest point (one
//! stray point does not raise it). Garden objects (walls, boxes, planters, hedges, sheds) stand
//! on the ground with near-level tops; a concave object is covered by its hull, and two objects
//! closer than the link distance by one hull. The solids are in the world, so they stay where
//! they are from frame to frame.
//!
//! World: metres, Y up or any `up`; the ground is the plane through `ground_point` normal to
//! `up`.

use std::collections::BTreeMap;

use glam::{Affine3A, DVec3, Vec2, Vec3};

use super::{Observation, PinholeIntrinsics};

/// Tuning of [`GroundSolids`].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GroundSolidsConfig {
    /// Points at least this high above the ground (m) belong to objects; lower ones are ground.
    pub min_height_m: f32,
    /// Object points whose footprints lie within this distance (m) belong to the same solid.
    pub link_distance_m: f32,
    /// Fewer points than this make no solid (a stray mismatched track).
    pub min_points: usize,
    /// A point counts once it has been seen in this many frames.
    pub min_observations: u32,
    /// A hull narrower than this (m: points in one vertical line, a wall seen end-on) is
    /// widened to it.
    pub min_width_m: f32,
}

impl Default for GroundSolidsConfig {
    fn default() -> Self {
        Self {
            min_height_m: 0.08,
            link_distance_m: 0.4,
            min_points: 5,
            min_observations: 3,
            min_width_m: 0.04,
        }
    }
}

/// One solid: a vertical prism over a convex footprint.
#[derive(Clone, Debug, PartialEq)]
pub struct GroundSolid {
    /// Corners of the footprint on the ground, counter-clockwise seen from above.
    pub footprint: Vec<Vec3>,
    /// Height of the level top above the ground (m).
    pub height_m: f32,
    /// Points that made it.
    pub num_points: usize,
}

#[derive(Clone, Copy, Debug, Default)]
struct FusedPoint {
    sum: DVec3,
    count: u32,
    /// Classified as part of an object; with hysteresis, so that a point near the height
    /// threshold does not flicker between object and ground as the plane is refitted.
    elevated: bool,
}

impl FusedPoint {
    fn position(&self) -> Vec3 {
        (self.sum / self.count.max(1) as f64).as_vec3()
    }
}

/// The tracked points of every frame fused in the world, and the solids they make.
#[derive(Clone, Debug, Default)]
pub struct GroundSolids {
    config: GroundSolidsConfig,
    points: BTreeMap<u64, FusedPoint>,
}

impl GroundSolids {
    pub fn new(config: GroundSolidsConfig) -> Self {
        Self {
            config,
            points: BTreeMap::new(),
        }
    }

    pub fn config(&self) -> &GroundSolidsConfig {
        &self.config
    }

    /// Number of points held (seen at least once).
    pub fn num_points(&self) -> usize {
        self.points.len()
    }

    /// Forgets every point (the world was redefined).
    pub fn clear(&mut self) {
        self.points.clear();
    }

    /// Adds one frame's observations, seen by `camera` from `world_from_camera`, and classifies
    /// every point held against the ground through `ground_point` with normal `up`: a point
    /// becomes part of an object at [`GroundSolidsConfig::min_height_m`] above the ground and
    /// stays so down to half that height. Observations that are not finite or not in front of
    /// the camera are skipped.
    pub fn observe(
        &mut self,
        observations: &[Observation],
        camera: &PinholeIntrinsics,
        world_from_camera: &Affine3A,
        ground_point: Vec3,
        up: Vec3,
    ) {
        for o in observations {
            if !(o.pixel.is_finite() && o.depth_m.is_finite() && o.depth_m > 0.0) {
                continue;
            }
            let point =
                world_from_camera.transform_point3(camera.camera_from_pixel(o.pixel, o.depth_m));
            if !point.is_finite() {
                continue;
            }
            let fused = self.points.entry(o.id).or_default();
            fused.sum += point.as_dvec3();
            fused.count += 1;
        }
        let up = up.normalize_or_zero();
        let min_height = self.config.min_height_m;
        for fused in self.points.values_mut() {
            let height = (fused.position() - ground_point).dot(up);
            let threshold = if fused.elevated {
                0.5 * min_height
            } else {
                min_height
            };
            fused.elevated = height >= threshold;
        }
    }

    /// The solids standing on the ground through `ground_point` with normal `up` (unit).
    pub fn solids(&self, ground_point: Vec3, up: Vec3) -> Vec<GroundSolid> {
        let Some(up) = up.try_normalize() else {
            return Vec::new();
        };
        let u_axis = up.any_orthonormal_vector();
        let v_axis = up.cross(u_axis);
        // Footprint (plan coordinates) and height of each object point.
        let mut objects: Vec<(Vec2, f32)> = self
            .points
            .values()
            .filter(|p| p.count >= self.config.min_observations && p.elevated)
            .map(|p| {
                let offset = p.position() - ground_point;
                (
                    Vec2::new(offset.dot(u_axis), offset.dot(v_axis)),
                    offset.dot(up),
                )
            })
            .collect();
        objects.sort_by(|a, b| a.0.x.total_cmp(&b.0.x));
        let plan: Vec<Vec2> = objects.iter().map(|o| o.0).collect();
        let to_world = |q: Vec2| ground_point + u_axis * q.x + v_axis * q.y;
        link_groups(&plan, self.config.link_distance_m)
            .into_iter()
            .filter(|group| group.len() >= self.config.min_points)
            .filter_map(|group| {
                let mut heights: Vec<f32> = group.iter().map(|&i| objects[i].1).collect();
                heights.sort_by(|a, b| b.total_cmp(a));
                let height_m = heights[1.min(heights.len() - 1)];
                let footprint = widened(
                    convex_hull(group.iter().map(|&i| plan[i]).collect()),
                    self.config.min_width_m,
                )?;
                Some(GroundSolid {
                    footprint: footprint.into_iter().map(to_world).collect(),
                    height_m,
                    num_points: group.len(),
                })
            })
            .collect()
    }

    /// The solids as one closed-on-top triangle mesh (sides and top; the ground closes it):
    /// positions and a triangle list, appended to `positions` and `indices`.
    pub fn append_mesh(
        &self,
        ground_point: Vec3,
        up: Vec3,
        positions: &mut Vec<Vec3>,
        indices: &mut Vec<u32>,
    ) {
        let up = up.normalize_or_zero();
        for solid in self.solids(ground_point, up) {
            let base = positions.len() as u32;
            let n = solid.footprint.len() as u32;
            positions.extend(solid.footprint.iter().copied());
            positions.extend(solid.footprint.iter().map(|&p| p + up * solid.height_m));
            for i in 0..n {
                let j = (i + 1) % n;
                indices.extend([base + i, base + j, base + n + j]);
                indices.extend([base + i, base + n + j, base + n + i]);
            }
            for i in 1..n.saturating_sub(1) {
                indices.extend([base + n, base + n + i, base + n + i + 1]);
            }
        }
    }
}

/// Groups of indices into `plan` (sorted by x) linked by chains of distances within `link`.
fn link_groups(plan: &[Vec2], link: f32) -> Vec<Vec<usize>> {
    let mut parent: Vec<usize> = (0..plan.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for i in 0..plan.len() {
        for j in i + 1..plan.len() {
            if plan[j].x - plan[i].x > link {
                break;
            }
            if plan[i].distance_squared(plan[j]) <= link * link {
                let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut groups: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for i in 0..plan.len() {
        let r = root(&mut parent, i);
        groups.entry(r).or_default().push(i);
    }
    groups.into_values().collect()
}

/// Counter-clockwise convex hull (Andrew's monotone chain); collinear points dropped.
fn convex_hull(mut points: Vec<Vec2>) -> Vec<Vec2> {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup();
    if points.len() < 3 {
        return points;
    }
    let cross = |o: Vec2, a: Vec2, b: Vec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<Vec2> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Vec2>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// The hull, widened to `min_width` across when it is thinner (a segment or a sliver);
/// `None` for a single point.
fn widened(hull: Vec<Vec2>, min_width: f32) -> Option<Vec<Vec2>> {
    let (first, last) = (*hull.first()?, *hull.last()?);
    // The longest chord from the first vertex gives the hull's direction.
    let far = hull
        .iter()
        .copied()
        .max_by(|a, b| {
            a.distance_squared(first)
                .total_cmp(&b.distance_squared(first))
        })
        .unwrap_or(last);
    let along = (far - first).try_normalize()?;
    let across = along.perp();
    let (lo, hi) = hull.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| {
        let d = (*p - first).dot(across);
        (lo.min(d), hi.max(d))
    });
    if hull.len() >= 3 && hi - lo >= min_width {
        return Some(hull);
    }
    let (a_lo, a_hi) = hull.iter().fold((f32::MAX, f32::MIN), |(lo, hi), p| {
        let d = (*p - first).dot(along);
        (lo.min(d), hi.max(d))
    });
    let mid = 0.5 * (lo + hi);
    let half = 0.5 * min_width;
    let corner = |a: f32, c: f32| first + along * a + across * c;
    Some(vec![
        corner(a_lo, mid - half),
        corner(a_hi, mid - half),
        corner(a_hi, mid + half),
        corner(a_lo, mid + half),
    ])
}

#[cfg(test)]
mod tests {
    use super::*;

    const CAMERA: PinholeIntrinsics = PinholeIntrinsics {
        width: 640,
        height: 480,
        fx: 525.0,
        fy: 525.0,
        cx: 319.5,
        cy: 239.5,
    };

    /// Observations of world points from a camera at `eye` looking at `target` (Y up world,
    /// OpenCV camera axes).
    fn seen_from(eye: Vec3, target: Vec3, points: &[(u64, Vec3)]) -> (Vec<Observation>, Affine3A) {
        let forward = (target - eye).normalize();
        let right = forward.cross(Vec3::Y).normalize();
        let down = forward.cross(right);
        let world_from_camera =
            Affine3A::from_mat3_translation(glam::Mat3::from_cols(right, down, forward), eye);
        let camera_from_world = world_from_camera.inverse();
        let observations = points
            .iter()
            .filter_map(|&(id, p)| {
                let c = camera_from_world.transform_point3(p);
                Some(Observation {
                    id,
                    pixel: CAMERA.pixel_from_camera(c)?,
                    depth_m: c.z,
                })
            })
            .collect();
        (observations, world_from_camera)
    }

    /// A box's corners and edge midpoints, ground points around it, and one stray point.
    fn scene() -> Vec<(u64, Vec3)> {
        let mut points = Vec::new();
        let (min, max) = (Vec3::new(0.85, 0.0, -0.4), Vec3::new(1.35, 0.5, 0.1));
        for (i, (x, z)) in [
            (0.0, 0.0),
            (0.5, 0.0),
            (1.0, 0.0),
            (1.0, 0.5),
            (1.0, 1.0),
            (0.5, 1.0),
            (0.0, 1.0),
            (0.0, 0.5),
        ]
        .into_iter()
        .enumerate()
        {
            let p = Vec3::new(
                min.x + x * (max.x - min.x),
                max.y,
                min.z + z * (max.z - min.z),
            );
            points.push((i as u64, p));
            points.push((100 + i as u64, p.with_y(0.25)));
        }
        for i in 0..40u64 {
            let (x, z) = ((i % 8) as f32 * 0.6 - 2.0, (i / 8) as f32 * 0.6 - 1.5);
            points.push((200 + i, Vec3::new(x, 0.01 * ((i % 3) as f32 - 1.0), z)));
        }
        points.push((999, Vec3::new(-1.0, 0.7, 0.5)));
        points
    }

    fn solids_after_walk() -> Vec<GroundSolid> {
        let mut solids = GroundSolids::new(GroundSolidsConfig::default());
        for k in 0..6 {
            let bearing = (k as f32 * 10.0 - 25.0).to_radians();
            let eye = Vec3::new(3.0 * bearing.sin(), 1.5, 3.0 * bearing.cos());
            let (observations, world_from_camera) = seen_from(eye, Vec3::ZERO, &scene());
            solids.observe(
                &observations,
                &CAMERA,
                &world_from_camera,
                Vec3::ZERO,
                Vec3::Y,
            );
        }
        solids.solids(Vec3::ZERO, Vec3::Y)
    }

    #[test]
    fn the_points_of_a_box_make_one_prism_with_the_box_footprint_and_height() {
        let solids = solids_after_walk();
        assert_eq!(
            solids.len(),
            1,
            "one solid, the stray point and the ground make none: {solids:?}"
        );
        let solid = &solids[0];
        assert!(
            (solid.height_m - 0.5).abs() < 1e-3,
            "height {}",
            solid.height_m
        );
        // The box's outline: every corner on it (edge midpoints may stay, within round-off of
        // collinear), and its area.
        for p in &solid.footprint {
            assert!(p.y.abs() < 1e-4, "footprint {p} on the ground");
            assert!(
                ((p.x - 0.85).abs() < 1e-3 || (p.x - 1.35).abs() < 1e-3)
                    || ((p.z + 0.4).abs() < 1e-3 || (p.z - 0.1).abs() < 1e-3),
                "corner {p} off the box's outline"
            );
        }
        let f = &solid.footprint;
        let area: f32 = (0..f.len())
            .map(|i| {
                let (a, b) = (f[i], f[(i + 1) % f.len()]);
                0.5 * (a.z * b.x - a.x * b.z)
            })
            .sum();
        assert!((area.abs() - 0.25).abs() < 1e-3, "footprint area {area} m²");
    }

    #[test]
    fn the_prism_mesh_has_sides_and_a_top_and_no_vertex_below_the_ground() {
        let mut solids = GroundSolids::new(GroundSolidsConfig::default());
        for k in 0..3 {
            let eye = Vec3::new(0.3 * k as f32, 1.5, 3.0);
            let (observations, world_from_camera) = seen_from(eye, Vec3::ZERO, &scene());
            solids.observe(
                &observations,
                &CAMERA,
                &world_from_camera,
                Vec3::ZERO,
                Vec3::Y,
            );
        }
        let (mut positions, mut indices) = (Vec::new(), Vec::new());
        solids.append_mesh(Vec3::ZERO, Vec3::Y, &mut positions, &mut indices);
        let n = positions.len() / 2;
        assert!(n >= 4, "a footprint of at least the box's corners");
        assert_eq!(
            indices.len(),
            3 * (2 * n + n - 2),
            "a quad per side and a fan over the top"
        );
        assert!(positions.iter().all(|p| p.y > -1e-4 && p.y < 0.5 + 1e-3));
        assert!(indices.iter().all(|&i| (i as usize) < positions.len()));
    }

    #[test]
    fn points_seen_in_too_few_frames_make_no_solid() {
        let mut solids = GroundSolids::new(GroundSolidsConfig::default());
        let (observations, world_from_camera) =
            seen_from(Vec3::new(0.0, 1.5, 3.0), Vec3::ZERO, &scene());
        solids.observe(
            &observations,
            &CAMERA,
            &world_from_camera,
            Vec3::ZERO,
            Vec3::Y,
        );
        solids.observe(
            &observations,
            &CAMERA,
            &world_from_camera,
            Vec3::ZERO,
            Vec3::Y,
        );
        assert!(solids.solids(Vec3::ZERO, Vec3::Y).is_empty());
    }

    #[test]
    fn points_in_one_vertical_line_make_a_thin_wall_not_nothing() {
        let hull = widened(
            convex_hull(vec![
                Vec2::new(0.0, 0.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(0.5, 0.0),
            ]),
            0.04,
        )
        .expect("a segment widens");
        assert_eq!(hull.len(), 4);
        let width = hull.iter().map(|p| p.y).fold(f32::MIN, f32::max)
            - hull.iter().map(|p| p.y).fold(f32::MAX, f32::min);
        assert!((width - 0.04).abs() < 1e-6, "width {width}");
    }

    #[test]
    fn two_objects_farther_apart_than_the_link_distance_stay_two_solids() {
        let plan = [
            Vec2::new(0.0, 0.0),
            Vec2::new(0.3, 0.0),
            Vec2::new(0.6, 0.1),
            Vec2::new(2.0, 0.0),
            Vec2::new(2.2, 0.3),
        ];
        let groups = link_groups(&plan, 0.4);
        assert_eq!(groups, vec![vec![0, 1, 2], vec![3, 4]]);
    }
}
