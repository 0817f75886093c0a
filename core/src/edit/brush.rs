//! Brushing and sketching (Longay 2014 §5.2.1, §5.2.3, §5.2.4, §5.4.2, appendix B).
//!
//! A brush is a sphere of radius ρ that moves along a stroke on a camera-facing brush plane. The
//! stroke keeps one scene depth between the camera and its plane (§5.4.2: "a constant scene
//! depth is maintained between the camera and the plane of the brush"): every stroke point comes
//! with the camera it was drawn from ([`StrokeCamera`]: eye and view direction) and a point on
//! the ray through the finger, and is placed where that ray meets the plane at the stroke's depth
//! in front of *that* camera. Moving the device forward while painting moves the brush forward;
//! a still camera draws on one fixed plane ([`StrokeCamera::facing`] gives the camera that sees
//! a given plane at a given depth).
//!
//! While growth iterations run, the stroke continually adds uniformly random persistent
//! attraction points in the volume swept between consecutive stroke points since the last
//! iteration; ρ may change from one stroke point to the next. As ρ → 0 the points lie on the
//! stroke itself and brushing becomes sketching: the single axis that eats them follows the
//! stroke.
//!
//! Options: sketch-based tropism (each point carries the stroke direction, which becomes the
//! tropism T of the bud it feeds) and selective growth (only the branch from a picked bud may
//! grow). The tree's depth constraint ([`crate::environment::DepthConstraint`], appendix B)
//! holds for brushed points too: the brush adds none outside it.
//!
//! Each stroke's points are one group of the tree's attraction points, which expires when the
//! tree has not grown into it for [`crate::environment::IDLE_LIFETIME_ITERATIONS`] iterations
//! (see [`crate::environment::AttractionPoints`]); [`step_with_point_lifetime`] is the growth
//! iteration that ages the groups, and [`BrushStroke::iterate`] runs it.

use glam::Vec3;

use super::EditError;
use super::prune::distance_to_segment;
use crate::environment::{Scene, SceneMode};
use crate::growth::{IterationStats, StepOptions, Tree};
use crate::tree::NodeId;

/// A plane: a point and a unit normal (world space).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrushPlane {
    pub origin: Vec3,
    pub normal: Vec3,
}

impl BrushPlane {
    /// The plane through `origin` with normal `normal` (normalised; an error if zero).
    pub fn new(origin: Vec3, normal: Vec3) -> Result<BrushPlane, EditError> {
        let normal = normal
            .try_normalize()
            .filter(|_| origin.is_finite())
            .ok_or(EditError::NonFinite {
                what: "brush plane",
            })?;
        Ok(BrushPlane { origin, normal })
    }

    /// Orthogonal projection of a world point onto the plane.
    pub fn project(&self, p: Vec3) -> Vec3 {
        p - self.normal * (p - self.origin).dot(self.normal)
    }
}

/// The camera a stroke point is drawn from: its eye and unit view direction (the optical axis),
/// world space. Depths are measured along the view direction, as camera-space Z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrokeCamera {
    eye: Vec3,
    view_direction: Vec3,
}

impl StrokeCamera {
    /// The camera at `eye` looking along `view_direction` (normalised; an error if zero or not
    /// finite).
    pub fn new(eye: Vec3, view_direction: Vec3) -> Result<StrokeCamera, EditError> {
        let view_direction = view_direction
            .try_normalize()
            .filter(|_| eye.is_finite())
            .ok_or(EditError::NonFinite {
                what: "stroke camera",
            })?;
        Ok(StrokeCamera {
            eye,
            view_direction,
        })
    }

    /// The still camera `depth_m` in front of `plane`, looking at it against its normal: a
    /// stroke of that depth drawn from it lies on the plane (the fixed brush plane).
    pub fn facing(plane: BrushPlane, depth_m: f32) -> Result<StrokeCamera, EditError> {
        StrokeCamera::new(plane.origin + plane.normal * depth_m, -plane.normal)
    }

    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    pub fn view_direction(&self) -> Vec3 {
        self.view_direction
    }

    /// The brush plane `depth_m` in front of the camera (normal towards the camera).
    pub fn plane_at(&self, depth_m: f32) -> BrushPlane {
        BrushPlane {
            origin: self.eye + self.view_direction * depth_m,
            normal: -self.view_direction,
        }
    }

    /// Where the ray from the eye through `through` meets the brush plane `depth_m` in front of
    /// the camera; None when `through` is not in front of the camera.
    pub fn point_at_depth(&self, through: Vec3, depth_m: f32) -> Option<Vec3> {
        let ray = through - self.eye;
        let along = ray.dot(self.view_direction);
        (along > 1e-6 && along.is_finite()).then(|| self.eye + ray * (depth_m / along))
    }
}

/// A sample of the stroke: when, where (on the brush plane of its camera), how wide, and the
/// camera it was drawn from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrokePoint {
    pub time_s: f64,
    pub position: Vec3,
    /// Brush radius ρ (metres); 0 sketches.
    pub radius_m: f32,
    pub camera: StrokeCamera,
}

/// Knobs of a stroke.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BrushSettings {
    /// Points added per internode length of stroke travelled (at least; wide brushes add more).
    pub points_per_internode: f32,
    /// Points per volume of one internode-length cube swept by a wide brush.
    pub points_per_internode_cube: f32,
    /// Sketch-based tropism: points carry the stroke direction as the tropism of their bud.
    pub sketch_tropism: bool,
    /// With sketch tropism, the least weight β of the stroke direction for the buds it feeds
    /// (see [`crate::environment::AttractionPoints::sketch_tropism_weight`]).
    pub sketch_tropism_weight: f32,
}

/// Default least weight of the stroke direction under sketch tropism.
pub const SKETCH_TROPISM_WEIGHT: f32 = 0.8;

impl Default for BrushSettings {
    fn default() -> Self {
        BrushSettings {
            points_per_internode: 3.0,
            points_per_internode_cube: 0.5,
            sketch_tropism: false,
            sketch_tropism_weight: SKETCH_TROPISM_WEIGHT,
        }
    }
}

/// One stroke in progress.
#[derive(Clone, Debug)]
pub struct BrushStroke {
    /// Scene depth of the brush plane in front of each point's camera (metres).
    depth_m: f32,
    settings: BrushSettings,
    points: Vec<StrokePoint>,
    /// Stroke points already turned into attraction points (segments before this index).
    emitted: usize,
    /// The group of the tree's attraction points this stroke adds to (from its first point).
    group: Option<u16>,
}

impl BrushStroke {
    /// A stroke whose brush plane stays `depth_m` in front of the camera (positive, finite).
    pub fn new(depth_m: f32, settings: BrushSettings) -> Result<BrushStroke, EditError> {
        if !(depth_m.is_finite() && depth_m > 0.0) {
            return Err(EditError::BadParameter {
                name: "brush plane depth (m)",
                value: depth_m,
            });
        }
        Ok(BrushStroke {
            depth_m,
            settings,
            points: Vec::new(),
            emitted: 0,
            group: None,
        })
    }

    pub fn points(&self) -> &[StrokePoint] {
        &self.points
    }

    /// Scene depth of the brush plane in front of the camera (metres).
    pub fn depth_m(&self) -> f32 {
        self.depth_m
    }

    /// Adds a stroke sample drawn from `camera`: `through` is any world point on the ray
    /// through the finger, and the sample is placed where that ray meets the plane at the
    /// stroke's depth in front of the camera. Returns the placed point. Times must not go back,
    /// the radius must be finite and non-negative and `through` in front of the camera.
    pub fn add_point(
        &mut self,
        time_s: f64,
        camera: StrokeCamera,
        through: Vec3,
        radius_m: f32,
    ) -> Result<Vec3, EditError> {
        if !(through.is_finite() && time_s.is_finite()) {
            return Err(EditError::NonFinite {
                what: "stroke point",
            });
        }
        if !(radius_m.is_finite() && radius_m >= 0.0) {
            return Err(EditError::BadParameter {
                name: "brush radius",
                value: radius_m,
            });
        }
        if let Some(last) = self.points.last()
            && time_s < last.time_s
        {
            return Err(EditError::BadParameter {
                name: "stroke time going back (s)",
                value: time_s as f32,
            });
        }
        let position =
            camera
                .point_at_depth(through, self.depth_m)
                .ok_or(EditError::BadParameter {
                    name: "stroke point depth in front of the camera (m)",
                    value: (through - camera.eye).dot(camera.view_direction),
                })?;
        self.points.push(StrokePoint {
            time_s,
            position,
            radius_m,
            camera,
        });
        Ok(position)
    }

    /// Turns the part of the stroke drawn since the last call into persistent attraction
    /// points in `tree` (uniform in the swept spheres). Returns how many were added.
    pub fn emit(&mut self, tree: &mut Tree) -> usize {
        let l = tree.species.internode_length_m;
        let mut added = 0;
        if self.points.len() == 1 && self.emitted == 0 {
            // A dab: points in the ball under the brush.
            let p = self.points[0];
            added += self.fill_segment(tree, p, p, l);
            self.emitted = 1;
            return added;
        }
        let start = self.emitted.saturating_sub(1);
        for k in start..self.points.len().saturating_sub(1) {
            let (a, b) = (self.points[k], self.points[k + 1]);
            added += self.fill_segment(tree, a, b, l);
        }
        self.emitted = self.points.len();
        added
    }

    /// Points in the ball under the brush where it rests now (the brush keeps painting while
    /// the finger stays down without moving). Returns how many were added.
    pub fn emit_dab(&mut self, tree: &mut Tree) -> usize {
        match self.points.last() {
            Some(&p) => self.fill_segment(tree, p, p, tree.species.internode_length_m),
            None => 0,
        }
    }

    /// Emits the new part of the stroke and runs one brush-guided growth iteration (ageing the
    /// attraction points' groups, [`step_with_point_lifetime`]).
    pub fn iterate(&mut self, tree: &mut Tree) -> IterationStats {
        self.emit(tree);
        step_with_point_lifetime(
            tree,
            StepOptions {
                autonomous: false,
                scene: None,
            },
        )
    }

    /// The group of the tree's attraction points this stroke adds to, once it added one.
    pub fn group(&self) -> Option<u16> {
        self.group
    }

    fn fill_segment(&mut self, tree: &mut Tree, a: StrokePoint, b: StrokePoint, l: f32) -> usize {
        let length = a.position.distance(b.position);
        let radius = a.radius_m.max(b.radius_m);
        let swept = std::f32::consts::PI * radius * radius * length
            + 4.0 / 3.0 * std::f32::consts::PI * radius.powi(3);
        let by_length = (length / l * self.settings.points_per_internode).ceil();
        let by_volume = (swept / (l * l * l) * self.settings.points_per_internode_cube).ceil();
        let count = by_length.max(by_volume).max(1.0) as usize;
        let direction = (b.position - a.position).try_normalize();
        let iteration = tree.iteration;
        let group = *self
            .group
            .get_or_insert_with(|| tree.environment.attraction.begin_group(iteration));
        let mut added = 0;
        for _ in 0..count {
            let t = tree.rng.next_f32();
            let centre = a.position.lerp(b.position, t);
            let rho = a.radius_m + (b.radius_m - a.radius_m) * t;
            let p = centre + tree.rng.in_unit_ball() * rho;
            if !tree.environment.depth_allows(p) {
                continue;
            }
            let attraction = &mut tree.environment.attraction;
            let tropism = direction.filter(|_| self.settings.sketch_tropism);
            if tropism.is_some() {
                attraction.sketch_tropism_weight = self.settings.sketch_tropism_weight;
            }
            attraction.add_persistent_to(group, p, tropism);
            added += 1;
        }
        if added > 0 {
            // Painting keeps the stroke alive.
            tree.environment.attraction.mark_active(group, iteration);
        }
        added
    }

    /// Distance from `p` to the stroke polyline.
    pub fn distance_to(&self, p: Vec3) -> f32 {
        match self.points.as_slice() {
            [] => f32::INFINITY,
            [only] => p.distance(only.position),
            many => many
                .windows(2)
                .map(|w| distance_to_segment(p, w[0].position, w[1].position))
                .fold(f32::INFINITY, f32::min),
        }
    }
}

/// One growth iteration of `tree` that ages its groups of persistent attraction points: a group
/// that lost no point and gained none for [`crate::environment::IDLE_LIFETIME_ITERATIONS`]
/// iterations expires ([`crate::environment::AttractionPoints::track`] and
/// [`crate::environment::AttractionPoints::age`] around [`Tree::step`]). Every growth iteration
/// of a design (brush, lasso, whole-tree growth) runs through it, so that unreached strokes do
/// not pile up.
pub fn step_with_point_lifetime(tree: &mut Tree, options: StepOptions) -> IterationStats {
    let tracked = tree.environment.attraction.track(tree.iteration);
    let stats = tree.step(options);
    tree.environment.attraction.age(&tracked, tree.iteration);
    stats
}

/// `iterations` autonomous growth iterations, each [`step_with_point_lifetime`] (what
/// [`Tree::grow`] does, with the points' lifetime).
pub fn grow_with_point_lifetime(
    tree: &mut Tree,
    iterations: u32,
    scene: Option<(&dyn Scene, SceneMode)>,
) -> IterationStats {
    let mut total = IterationStats::default();
    for _ in 0..iterations {
        total.accumulate(step_with_point_lifetime(
            tree,
            StepOptions {
                autonomous: true,
                scene,
            },
        ));
    }
    total
}

/// Selective growth (§5.2.4): the living bud nearest `pick` is re-oriented along the stroke's
/// initial direction and only the branch growing from it may grow until
/// [`end_selective_growth`]. All buds still consume points in their occupancy zones.
/// Returns the internode carrying the bud.
pub fn begin_selective_growth(
    tree: &mut Tree,
    pick: Vec3,
    initial_direction: Vec3,
) -> Result<NodeId, EditError> {
    let direction = initial_direction
        .try_normalize()
        .filter(|_| pick.is_finite())
        .ok_or(EditError::NonFinite {
            what: "selective growth pick or direction",
        })?;
    let mut best: Option<(NodeId, Option<usize>, f32)> = None;
    for (i, node) in tree.skeleton.internodes.iter().enumerate() {
        let d = node.end.distance(pick);
        if best.is_some_and(|b| b.2 <= d) {
            continue;
        }
        let bud = if node.terminal_bud.as_ref().is_some_and(|b| b.alive) {
            Some(None)
        } else {
            node.lateral_buds.iter().position(|b| b.alive).map(Some)
        };
        if let Some(which) = bud {
            best = Some((NodeId(i as u32), which, d));
        }
    }
    let (node, which, _) = best.ok_or(EditError::NoLivingBud)?;
    let internode = &mut tree.skeleton.internodes[node.index()];
    let bud = match which {
        None => internode.terminal_bud.as_mut(),
        Some(k) => internode.lateral_buds.get_mut(k),
    };
    if let Some(bud) = bud {
        bud.direction = direction;
    }
    tree.growth_mask = Some(node);
    Ok(node)
}

/// Leaves selective growth: every bud may grow again.
pub fn end_selective_growth(tree: &mut Tree) {
    tree.growth_mask = None;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::environment::IDLE_LIFETIME_ITERATIONS;
    use crate::species::Species;

    fn oak() -> Tree {
        Tree::new(Species::by_name("oak").expect("oak preset"), 0x5EED_0021)
    }

    /// A stroke on the plane z = 0, drawn from a still camera 4 m in front of it.
    fn still_stroke() -> (StrokeCamera, BrushStroke) {
        let plane = BrushPlane::new(Vec3::ZERO, Vec3::Z).expect("plane");
        (
            StrokeCamera::facing(plane, 4.0).expect("camera"),
            BrushStroke::new(4.0, BrushSettings::default()).expect("stroke"),
        )
    }

    #[test]
    fn a_stroke_no_bud_reaches_expires_after_the_lifetime() {
        let mut tree = oak();
        tree.grow(2, None);
        let (camera, mut stroke) = still_stroke();
        stroke
            .add_point(0.0, camera, Vec3::new(6.0, 4.0, 0.0), 0.1)
            .expect("point");
        stroke.iterate(&mut tree);
        let attraction = &tree.environment.attraction;
        let painted = attraction.num_persistent();
        assert!(painted > 0);
        assert_eq!(attraction.groups.len(), 1);
        assert_eq!(Some(attraction.groups[0].id), stroke.group());
        for _ in 2..IDLE_LIFETIME_ITERATIONS {
            stroke.iterate(&mut tree);
        }
        assert_eq!(
            tree.environment.attraction.num_persistent(),
            painted,
            "idle for one iteration less than the lifetime"
        );
        stroke.iterate(&mut tree);
        let attraction = &tree.environment.attraction;
        assert_eq!(attraction.num_persistent(), 0, "expired");
        assert!(attraction.runs.is_empty() && attraction.groups.is_empty());
        tree.sanity_check().expect("sane");
    }

    #[test]
    fn a_stroke_from_a_tip_is_consumed_as_the_tree_grows_along_it() {
        let mut tree = oak();
        let l = tree.species.internode_length_m;
        let tip = tree.skeleton.internodes[0].end;
        let end = tip + Vec3::new(0.3 * 30.0 * l, 30.0 * l, 0.0);
        let (camera, mut stroke) = still_stroke();
        // The whole sketch at once: later points are reached only through the earlier ones.
        for k in 0..=30 {
            let p = tip.lerp(end, k as f32 / 30.0);
            stroke.add_point(0.0, camera, p, 0.0).expect("point");
        }
        stroke.emit(&mut tree);
        let painted = tree.environment.attraction.num_persistent();
        let mut iterations = 0;
        while tree.environment.attraction.num_persistent() > 0 && iterations < 400 {
            stroke.iterate(&mut tree);
            iterations += 1;
        }
        let reach = tree
            .skeleton
            .internodes
            .iter()
            .map(|n| n.end.distance(end))
            .fold(f32::INFINITY, f32::min);
        println!(
            "{painted} points consumed in {iterations} iterations; the tree ends {reach:.3} m from the stroke's end"
        );
        assert!(reach <= 2.0 * l, "the tree stopped {reach} m from the end");
        assert_eq!(tree.environment.attraction.num_persistent(), 0);
        tree.sanity_check().expect("sane");
    }
}
