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
//! **Fusion.** Every tracked point is kept in the world as a running mean of its positions over
//! the frames that saw it, with their spread (Welford) and a few of the camera centres it was
//! seen from; a frame updates only the points it observes. A point whose positions spread more
//! than [`GroundSolidsConfig::max_relative_spread`] of its distance (a track that slides along a
//! silhouette, a mismatch) does not shape a solid nor carve one; it still links the points it
//! lies between into one group (it is on the object's silhouette, just not where its mean is).
//! On `demo_garden` such tracks stretched the wall's solid up to 60 cm in front of the wall.
//!
//! **Solids.** Points higher than [`GroundSolidsConfig::min_height_m`] above the ground are
//! grouped: two are linked when their footprints on the ground lie within
//! [`GroundSolidsConfig::link_distance_m`]. A group of at least
//! [`GroundSolidsConfig::min_points`] points is a solid: the convex hull of its footprints,
//! shrunk by the noise of their means, raised as a vertical prism from the ground to a level top
//! at the [`GroundSolidsConfig::top_quantile`] of the points' heights (a stray point does not
//! raise it). Garden objects (walls, boxes, planters, hedges, sheds) stand on the ground with
//! near-level tops; a concave object is covered by its hull, and two objects closer than the
//! link distance by one hull.
//!
//! **Carving.** A point seen from a camera centre proves the segment between them free (short of
//! the point by [`GroundSolidsConfig::ray_margin_m`]). Where such a segment of a point outside
//! the group passes through a solid below its top, the solid is cut by a half-plane: along the
//! segment (keeping the side with most of the group's points) or across it where it comes down
//! through the top (keeping the camera's side), whichever removes less area. A cut that would
//! leave more than [`GroundSolidsConfig::max_cut_fraction`] of the group outside is refused: the
//! ray, not the group, is then taken to be wrong. The rays of the current frame always carve (a
//! point behind a solid's face in view is not hidden by it) and those of earlier frames from the
//! camera centres kept, so a solid does not flicker from frame to frame.
//!
//! World: metres, Y up or any `up`; the ground is the plane through `ground_point` normal to
//! `up`.

use std::collections::BTreeMap;

use glam::{Affine3A, DVec3, Vec2, Vec3};

use super::plan::{area, clipped, convex_hull, segment_inside, shrunk, widened};
use super::{Observation, PinholeIntrinsics};

/// Tuning of [`GroundSolids`].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
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
    /// A point whose positions spread (RMS about their mean) more than this fraction of its
    /// mean distance from the camera is not used (depth noise grows with distance; a track
    /// sliding along a silhouette spreads by tens of centimetres).
    pub max_relative_spread: f32,
    /// The top of a solid: this quantile of its points' heights.
    pub top_quantile: f32,
    /// Free segments stop this far (m, plus twice the point's spread) short of their point.
    pub ray_margin_m: f32,
    /// A camera centre is kept for a point once it lies this far (m) from the last one kept.
    pub viewpoint_spacing_m: f32,
    /// Camera centres kept per point (every other one is dropped when full).
    pub max_viewpoints: usize,
    /// A cut may leave at most this fraction of a solid's points outside it.
    pub max_cut_fraction: f32,
}

impl Default for GroundSolidsConfig {
    fn default() -> Self {
        Self {
            min_height_m: 0.08,
            link_distance_m: 0.4,
            min_points: 5,
            min_observations: 3,
            min_width_m: 0.04,
            max_relative_spread: 0.015,
            top_quantile: 0.9,
            ray_margin_m: 0.05,
            viewpoint_spacing_m: 0.1,
            max_viewpoints: 16,
            max_cut_fraction: 0.25,
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
    /// Points that made it (after carving).
    pub num_points: usize,
    /// Cuts made by free segments.
    pub num_cuts: usize,
}

#[derive(Clone, Debug, Default)]
struct FusedPoint {
    mean: DVec3,
    /// Sum of squared distances of the positions from their running mean (Welford), m².
    sum_squares: f64,
    sum_depth_m: f64,
    count: u32,
    /// Classified as part of an object; with hysteresis, so that a point near the height
    /// threshold does not flicker between object and ground as the plane is refitted.
    elevated: bool,
    /// Camera centres it was seen from, each `viewpoint_spacing_m` from the one before.
    viewpoints: Vec<Vec3>,
}

impl FusedPoint {
    fn position(&self) -> Vec3 {
        self.mean.as_vec3()
    }

    /// RMS distance of the positions from their mean (m).
    fn spread_m(&self) -> f32 {
        (self.sum_squares / self.count.max(1) as f64).sqrt() as f32
    }

    fn add(&mut self, point: Vec3, depth_m: f32) {
        let point = point.as_dvec3();
        self.count += 1;
        let delta = point - self.mean;
        self.mean += delta / self.count as f64;
        self.sum_squares += delta.dot(point - self.mean);
        self.sum_depth_m += depth_m as f64;
    }

    fn classify(&mut self, ground_point: Vec3, up: Vec3, min_height: f32) {
        let height = (self.position() - ground_point).dot(up);
        let threshold = if self.elevated {
            0.5 * min_height
        } else {
            min_height
        };
        self.elevated = height >= threshold;
    }
}

/// The tracked points of every frame fused in the world, and the solids they make.
#[derive(Clone, Debug, Default)]
pub struct GroundSolids {
    config: GroundSolidsConfig,
    points: BTreeMap<u64, FusedPoint>,
    /// The ground the points were last classified against.
    ground: Option<(Vec3, Vec3)>,
    solids: Vec<GroundSolid>,
}

/// A segment seen free: from a camera centre to a point, not part of solid `owner`'s group.
#[derive(Clone, Copy)]
struct FreeSegment {
    from: Vec3,
    to: Vec3,
    id: u64,
}

/// An object point of one group, in plan.
struct Member {
    plan: Vec2,
    inside: bool,
}

impl GroundSolids {
    pub fn new(config: GroundSolidsConfig) -> Self {
        Self {
            config,
            ..Self::default()
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
        self.solids.clear();
        self.ground = None;
    }

    /// Adds one frame's observations, seen by `camera` from `world_from_camera`, classifies
    /// the points against the ground through `ground_point` with normal `up` (a point becomes
    /// part of an object at [`GroundSolidsConfig::min_height_m`] above the ground and stays so
    /// down to half that height) and rebuilds the solids. Only the observed points are updated
    /// unless the ground moved. Observations that are not finite or not in front of the camera
    /// are skipped.
    pub fn observe(
        &mut self,
        observations: &[Observation],
        camera: &PinholeIntrinsics,
        world_from_camera: &Affine3A,
        ground_point: Vec3,
        up: Vec3,
    ) {
        let Some(up) = up.try_normalize() else {
            return;
        };
        let eye = Vec3::from(world_from_camera.translation);
        let min_height = self.config.min_height_m;
        let mut seen_now = Vec::with_capacity(observations.len());
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
            fused.add(point, o.depth_m);
            let spacing = self.config.viewpoint_spacing_m;
            if fused
                .viewpoints
                .last()
                .is_none_or(|v| v.distance(eye) >= spacing)
            {
                fused.viewpoints.push(eye);
                if fused.viewpoints.len() > self.config.max_viewpoints.max(2) {
                    let mut k = 0;
                    fused.viewpoints.retain(|_| {
                        k += 1;
                        k % 2 == 1
                    });
                }
            }
            fused.classify(ground_point, up, min_height);
            seen_now.push(o.id);
        }
        let moved = self
            .ground
            .is_none_or(|(p, n)| p.distance(ground_point) > 1e-4 || n.dot(up) < 1.0 - 1e-8);
        if moved {
            for fused in self.points.values_mut() {
                fused.classify(ground_point, up, min_height);
            }
            self.ground = Some((ground_point, up));
        }
        self.solids = self.build(ground_point, up, eye, &seen_now);
    }

    /// The solids after the last [`Self::observe`].
    pub fn solids(&self) -> &[GroundSolid] {
        &self.solids
    }

    fn usable(&self, p: &FusedPoint) -> bool {
        p.count >= self.config.min_observations
            && p.spread_m()
                <= self.config.max_relative_spread * (p.sum_depth_m / p.count as f64) as f32
    }

    /// Groups, hulls and carves the solids standing on the ground through `ground_point`
    /// (unit normal `up`), the current camera at `eye` seeing the points `seen_now`.
    fn build(&self, ground_point: Vec3, up: Vec3, eye: Vec3, seen_now: &[u64]) -> Vec<GroundSolid> {
        let u_axis = up.any_orthonormal_vector();
        let v_axis = up.cross(u_axis);
        let plan_of = |p: Vec3| {
            let offset = p - ground_point;
            Vec2::new(offset.dot(u_axis), offset.dot(v_axis))
        };
        let height_of = |p: Vec3| (p - ground_point).dot(up);
        // Object points: id, footprint (plan coordinates), height, noise of the mean, usable.
        let mut objects: Vec<(u64, Vec2, f32, f32, bool)> = self
            .points
            .iter()
            .filter(|(_, p)| p.elevated && p.count >= self.config.min_observations)
            .map(|(&id, p)| {
                let noise = p.spread_m() / (p.count as f32).sqrt();
                let position = p.position();
                (
                    id,
                    plan_of(position),
                    height_of(position),
                    noise,
                    self.usable(p),
                )
            })
            .collect();
        objects.sort_by(|a, b| a.1.x.total_cmp(&b.1.x));
        let plan: Vec<Vec2> = objects.iter().map(|o| o.1).collect();
        // Every object point links (a track sliding along a silhouette still lies between
        // the object's points), only the usable ones shape the solid: a sliding track's mean
        // stands anywhere between the silhouette and the surface behind it.
        let groups: Vec<Vec<usize>> = link_groups(&plan, self.config.link_distance_m)
            .into_iter()
            .map(|group| {
                group
                    .into_iter()
                    .filter(|&i| objects[i].4)
                    .collect::<Vec<_>>()
            })
            .filter(|group| group.len() >= self.config.min_points)
            .collect();
        if groups.is_empty() {
            return Vec::new();
        }
        let segments = self.free_segments(eye, seen_now);
        let to_world = |q: Vec2| ground_point + u_axis * q.x + v_axis * q.y;
        groups
            .into_iter()
            .filter_map(|group| {
                let mut heights: Vec<f32> = group.iter().map(|&i| objects[i].2).collect();
                heights.sort_by(f32::total_cmp);
                let n = heights.len();
                let rank = (self.config.top_quantile.clamp(0.0, 1.0) * (n - 1) as f32) as usize;
                let height_m = heights[rank.min(n - 2)];
                let hull = widened(
                    convex_hull(group.iter().map(|&i| plan[i]).collect()),
                    self.config.min_width_m,
                )?;
                let mut noise: Vec<f32> = group.iter().map(|&i| objects[i].3).collect();
                noise.sort_by(f32::total_cmp);
                let inner = shrunk(&hull, noise[noise.len() / 2]);
                let mut footprint = if inner.len() >= 3 { inner } else { hull };
                let mut members: Vec<Member> = group
                    .iter()
                    .map(|&i| Member {
                        plan: plan[i],
                        inside: true,
                    })
                    .collect();
                let own: std::collections::BTreeSet<u64> =
                    group.iter().map(|&i| objects[i].0).collect();
                let mut num_cuts = 0;
                for segment in segments.iter().filter(|s| !own.contains(&s.id)) {
                    let (from, to) = (
                        (plan_of(segment.from), height_of(segment.from)),
                        (plan_of(segment.to), height_of(segment.to)),
                    );
                    if let Some(cut) = self.carve(&footprint, height_m, &mut members, from, to) {
                        footprint = cut;
                        num_cuts += 1;
                    }
                }
                let num_points = members.iter().filter(|m| m.inside).count();
                (num_points >= self.config.min_points && footprint.len() >= 3).then(|| {
                    GroundSolid {
                        footprint: footprint.into_iter().map(to_world).collect(),
                        height_m,
                        num_points,
                        num_cuts,
                    }
                })
            })
            .collect()
    }

    /// The free segments: from every kept camera centre of each usable point, and from the
    /// current camera to the points it sees now, each stopped short of its point.
    fn free_segments(&self, eye: Vec3, seen_now: &[u64]) -> Vec<FreeSegment> {
        let margin = |p: &FusedPoint| self.config.ray_margin_m + 2.0 * p.spread_m();
        let short_of = |from: Vec3, p: &FusedPoint| {
            let to = p.position();
            let length = from.distance(to);
            let keep = length - margin(p);
            (keep > 0.0).then(|| from + (to - from) * (keep / length))
        };
        // A point seen now proves its segment free however new its track (its spread is not
        // known yet): what is in view behind a solid's face is not hidden by it.
        let seen_now: std::collections::BTreeSet<u64> = seen_now.iter().copied().collect();
        let mut segments = Vec::new();
        for (&id, p) in self.points.iter().filter(|(_, p)| self.usable(p)) {
            for &from in &p.viewpoints {
                if let Some(to) = short_of(from, p) {
                    segments.push(FreeSegment { from, to, id });
                }
            }
            if seen_now.contains(&id)
                && p.viewpoints.last() != Some(&eye)
                && let Some(to) = short_of(eye, p)
            {
                segments.push(FreeSegment { from: eye, to, id });
            }
        }
        segments
    }

    /// The footprint cut so that the free segment `from` → `to` (plan point, height) does not
    /// pass through the prism below `top_m`; `None` when it does not, or when every cut would
    /// leave too many of the group's points outside. Points left outside are marked so.
    fn carve(
        &self,
        footprint: &[Vec2],
        top_m: f32,
        members: &mut [Member],
        (from, from_h): (Vec2, f32),
        (to, to_h): (Vec2, f32),
    ) -> Option<Vec<Vec2>> {
        // The part of the segment between the ground and the top.
        let (mut t_lo, mut t_hi) = (0.0f32, 1.0f32);
        let rise = to_h - from_h;
        if rise.abs() < 1e-9 {
            if !(0.0..=top_m).contains(&from_h) {
                return None;
            }
        } else {
            let (ta, tb) = ((0.0 - from_h) / rise, (top_m - from_h) / rise);
            t_lo = t_lo.max(ta.min(tb));
            t_hi = t_hi.min(ta.max(tb));
        }
        if t_lo >= t_hi {
            return None;
        }
        let (a, b) = (from.lerp(to, t_lo), from.lerp(to, t_hi));
        let (s0, s1) = segment_inside(footprint, a, b)?;
        let direction = (b - a).try_normalize()?;
        if (s1 - s0) * a.distance(b) < 0.002 {
            return None;
        }
        let entry = a.lerp(b, s0);
        // Across: keep the camera's side of the point where it comes down into the prism.
        let mut candidates = vec![(direction, direction.dot(entry))];
        // Along: keep the side with most of the group's points.
        let normal = direction.perp();
        let side: f32 = members
            .iter()
            .filter(|m| m.inside)
            .map(|m| normal.dot(m.plan - a).signum())
            .sum();
        let keep = if side >= 0.0 { -normal } else { normal };
        candidates.push((keep, keep.dot(a)));
        let num_inside = members.iter().filter(|m| m.inside).count();
        let allowed = (self.config.max_cut_fraction * num_inside as f32).floor() as usize;
        let before = area(footprint);
        let best = candidates
            .into_iter()
            .filter_map(|(n, offset)| {
                let part = clipped(footprint, n, offset);
                let num_out = members
                    .iter()
                    .filter(|m| m.inside && n.dot(m.plan) > offset + 1e-4)
                    .count();
                let kept = area(&part);
                (part.len() >= 3
                    && num_out <= allowed
                    && kept >= (1.0 - self.config.max_cut_fraction) * before)
                    .then_some((before - kept, part, n, offset))
            })
            .min_by(|x, y| x.0.total_cmp(&y.0));
        let best = best?;
        let (_, part, n, offset) = best;
        for m in members.iter_mut() {
            if n.dot(m.plan) > offset + 1e-4 {
                m.inside = false;
            }
        }
        Some(part)
    }

    /// The solids as one closed-on-top triangle mesh (sides and top; the ground closes it),
    /// standing along `up`: positions and a triangle list, appended to `positions` and
    /// `indices`.
    pub fn append_mesh(&self, up: Vec3, positions: &mut Vec<Vec3>, indices: &mut Vec<u32>) {
        let up = up.normalize_or_zero();
        for solid in &self.solids {
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

#[cfg(test)]
mod tests;
