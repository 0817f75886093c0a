//! The editing tools a landscaper picks from (issue 20): what one finger on the AR view does.
//!
//! | tool | one finger |
//! |---|---|
//! | Brush (default) | paints where the tree grows; double tap prunes, press-and-hold selects a bud, three fingers bend (Longay 2014 §5.1–5.2) |
//! | Lasso crown | draws the crown's outline (closed on release); the outline is inflated into an envelope (§5.2.2, [`Lasso`]) filled with attraction points, and the tree grows into it |
//! | Width | drawn over branches, fixes their diameter to the tool's width (§5.3.2, [`set_width_constraint`]) |
//! | Bend | touch a branch and drag: its tip follows the finger (PriMo, [`Bend`]) |
//! | Prune | a tap cuts the branch under the finger |
//!
//! The choice is an [`InputEvent::Tool`](super::InputEvent::Tool), so sessions replay it; a
//! session without one stays with the brush, as it was made. Tools work in tree space, as the
//! rest of the design state.

use glam::{Vec2, Vec3};
use serde::{Deserialize, Serialize};
use sylva_core::NodeId;
use sylva_core::edit::LassoEnvelope;
use sylva_core::edit::{
    Bend, BendSettings, Lasso, OperationKind, PositionalConstraint, prune_at, set_width_constraint,
};
use sylva_core::environment::{Scene, SceneMode};
use sylva_core::growth::StepOptions;

use super::{DesignState, PICK_RADIUS_PX, TAP_SLOP_PX, TouchPhase};
use crate::planting::growth_scene;
use crate::render::ViewCamera;

/// What one finger on the view does.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "tool", rename_all = "snake_case")]
pub enum Tool {
    /// Brush growth (double tap prunes, hold selects, three fingers bend).
    #[default]
    Brush,
    /// Draw the crown's outline; the tree grows to fill it.
    LassoCrown,
    /// Draw over branches to set their diameter to `diameter_m` metres.
    Width { diameter_m: f32 },
    /// Touch a branch and drag its tip.
    Bend,
    /// Tap a branch to cut it.
    Prune,
}

/// The width tool's diameter when first chosen, metres.
pub const DEFAULT_BRANCH_DIAMETER_M: f32 = 0.03;

/// Attraction points per square metre of lassoed outline (the thesis's lasso test fills a
/// 4.5 m² circle with 1500).
const LASSO_POINTS_PER_M2: f32 = 330.0;
const LASSO_MIN_POINTS: usize = 100;
const LASSO_MAX_POINTS: usize = 5000;
/// Raster cells along the outline's longer side for the envelope.
const LASSO_RESOLUTION: usize = 96;
/// Guided iterations the tree grows into a new envelope at most (it stops once none grows).
pub const LASSO_MAX_ITERATIONS: u32 = 40;
/// Outline points closer than this to the previous one are skipped, pixels.
const LASSO_SPACING_PX: f32 = 2.0;

impl Tool {
    /// The tools in the selector's order, the width tool at `diameter_m`.
    pub fn all(diameter_m: f32) -> [Tool; 5] {
        [
            Tool::Brush,
            Tool::LassoCrown,
            Tool::Width { diameter_m },
            Tool::Bend,
            Tool::Prune,
        ]
    }

    /// The selector's label.
    pub fn label(self) -> &'static str {
        match self {
            Tool::Brush => "Brush",
            Tool::LassoCrown => "Lasso crown",
            Tool::Width { .. } => "Width",
            Tool::Bend => "Bend",
            Tool::Prune => "Prune",
        }
    }

    /// What to do with the tool, for the hint line.
    pub fn hint(self) -> &'static str {
        match self {
            Tool::Brush => "Brush where the tree should grow · double tap prunes · hold selects",
            Tool::LassoCrown => "Draw the crown's outline around the tree",
            Tool::Width { .. } => "Draw over branches to give them this width",
            Tool::Bend => "Touch a branch and drag to bend it",
            Tool::Prune => "Tap a branch to cut it",
        }
    }

    /// Whether both name the same tool (whatever the width).
    pub fn same_kind(self, other: Tool) -> bool {
        std::mem::discriminant(&self) == std::mem::discriminant(&other)
    }

    /// Why a recorded tool cannot be used, if it cannot (a damaged session).
    pub fn check(self) -> Result<(), String> {
        match self {
            Tool::Width { diameter_m } if !sylva_core::growth::is_width_constraint(diameter_m) => {
                Err(format!("a branch width of {diameter_m} m"))
            }
            _ => Ok(()),
        }
    }
}

/// The lassoed envelope as a scene: free inside it (and where the tracked scene, if it shapes
/// growth, is free), so that growing into the lasso in front of it keeps every new shoot inside
/// the outline (Longay 2014 §5.2.2: the lasso bounds the crown).
struct LassoScene<'a> {
    envelope: &'a LassoEnvelope,
    tracked: Option<&'a dyn Scene>,
}

impl Scene for LassoScene<'_> {
    fn is_free(&self, point_in_world: Vec3) -> bool {
        self.envelope.contains(point_in_world)
            && self.tracked.is_none_or(|s| s.is_free(point_in_world))
    }
}

/// A one-finger bend: the branch from `base` up to its tip `end`, whose tip follows the finger
/// on the plane through the tip facing the camera.
struct BendDrag {
    bend: Bend,
    end: NodeId,
    rest_end: Vec3,
    /// Where the finger touched, on that plane.
    grab: Vec3,
    depth_m: f32,
}

/// A gesture of a tool other than the brush, from touch start to end.
enum Gesture {
    Lasso { pixels: Vec<Vec2> },
    Width { recorded: bool },
    Bend(Option<Box<BendDrag>>),
    Prune { start: Vec2, moved: bool },
}

/// The chosen tool and its gesture in progress.
#[derive(Default)]
pub(crate) struct ToolState {
    pub(crate) tool: Tool,
    /// The touch the gesture follows, and the gesture.
    gesture: Option<(u64, Gesture)>,
}

/// The point on the ray through `pixel` at camera depth `depth_m`.
fn point_at_depth(camera: &ViewCamera, pixel: Vec2, depth_m: f32) -> Vec3 {
    camera
        .world_from_camera
        .transform_point3(camera.intrinsics.ray_from_pixel(pixel) * depth_m)
}

impl DesignState {
    /// The chosen tool.
    pub fn tool(&self) -> Tool {
        self.tools.tool
    }

    /// The lasso outline being drawn, image pixels (empty when none is).
    pub fn lasso_outline(&self) -> &[Vec2] {
        match &self.tools.gesture {
            Some((_, Gesture::Lasso { pixels })) => pixels,
            _ => &[],
        }
    }

    pub(crate) fn choose_tool(&mut self, tool: Tool) {
        if tool.check().is_err() {
            return;
        }
        self.end_stroke(false);
        self.tools.gesture = None;
        self.tools.tool = tool;
    }

    /// Gives the touch to the chosen tool; false when the brush (the default gestures) takes it.
    pub(crate) fn tool_touch(&mut self, phase: TouchPhase, id: u64, pixel: Vec2) -> bool {
        if matches!(self.tools.tool, Tool::Brush) || !self.is_planted() {
            return false;
        }
        match phase {
            TouchPhase::Start => {
                if self.tools.gesture.is_some() {
                    return true; // one finger at a time
                }
                let gesture = match self.tools.tool {
                    Tool::LassoCrown => Gesture::Lasso {
                        pixels: vec![pixel],
                    },
                    Tool::Width { .. } => Gesture::Width { recorded: false },
                    Tool::Bend => Gesture::Bend(self.begin_one_finger_bend(pixel).map(Box::new)),
                    Tool::Prune => Gesture::Prune {
                        start: pixel,
                        moved: false,
                    },
                    Tool::Brush => return false,
                };
                self.tools.gesture = Some((id, gesture));
                self.tool_move(pixel);
            }
            TouchPhase::Move => {
                if self.tools.gesture.as_ref().is_some_and(|(g, _)| *g == id) {
                    self.tool_move(pixel);
                }
            }
            TouchPhase::End => {
                if self.tools.gesture.as_ref().is_none_or(|(g, _)| *g != id) {
                    return true;
                }
                self.tool_move(pixel);
                let Some((_, gesture)) = self.tools.gesture.take() else {
                    return true;
                };
                match gesture {
                    Gesture::Lasso { pixels } => self.apply_lasso(&pixels),
                    Gesture::Prune { start, moved } if !moved => self.prune_under(start),
                    Gesture::Bend(Some(_)) => self.timeline.keep(&self.tree),
                    _ => {}
                }
            }
        }
        true
    }

    fn tool_move(&mut self, pixel: Vec2) {
        if let Tool::Width { diameter_m } = self.tools.tool
            && matches!(self.tools.gesture, Some((_, Gesture::Width { .. })))
        {
            self.paint_width(pixel, diameter_m);
            return;
        }
        let Some((_, gesture)) = self.tools.gesture.as_mut() else {
            return;
        };
        match gesture {
            Gesture::Lasso { pixels } => {
                if pixels
                    .last()
                    .is_none_or(|p| p.distance(pixel) >= LASSO_SPACING_PX)
                {
                    pixels.push(pixel);
                }
            }
            Gesture::Prune { start, moved } => *moved |= start.distance(pixel) > TAP_SLOP_PX,
            Gesture::Width { .. } => {}
            Gesture::Bend(drag) => {
                let (Some(drag), Some(camera)) = (drag.as_mut(), self.camera) else {
                    return;
                };
                let finger = point_at_depth(&camera, pixel, drag.depth_m);
                let constraint = PositionalConstraint {
                    node: drag.end,
                    end_position: drag.rest_end + (finger - drag.grab),
                };
                if let Ok(pose) = drag.bend.solve(&[constraint]) {
                    drag.bend.apply_to_tree(&pose, &mut self.tree);
                    self.changed();
                }
            }
        }
    }

    /// The width tool over the internode under the finger: its diameter becomes the tool's.
    fn paint_width(&mut self, pixel: Vec2, diameter_m: f32) {
        let Some(node) = self.pick(pixel) else {
            return;
        };
        if self.tree.skeleton.get(node).width_constraint == Some(diameter_m) {
            return;
        }
        if let Some((_, Gesture::Width { recorded })) = self.tools.gesture.as_mut()
            && !*recorded
        {
            // One undo step per stroke of the width tool.
            *recorded = true;
            self.history
                .record(OperationKind::WidthConstraint, &self.tree);
        }
        if set_width_constraint(&mut self.tree, node, Some(diameter_m)).is_ok() {
            self.timeline.keep(&self.tree);
            self.selected = Some(node);
            self.changed();
        }
    }

    /// The branch under the finger (not the trunk's first internode), from the touched
    /// internode up to the tip of its axis; the drag plane passes through the tip.
    fn begin_one_finger_bend(&mut self, pixel: Vec2) -> Option<BendDrag> {
        let camera = self.camera?;
        let base = self
            .pick_within(pixel, 2.0 * PICK_RADIUS_PX)
            .filter(|id| id.0 != 0)?;
        let skeleton = &self.tree.skeleton;
        let mut end = base;
        while let Some(next) = skeleton.get(end).main_child {
            end = next;
        }
        let bend = Bend::new(skeleton, base, end, BendSettings::default()).ok()?;
        let rest_end = skeleton.get(end).end;
        let depth_m = camera.depth_of(rest_end);
        if depth_m <= camera.near {
            return None;
        }
        self.history.record(OperationKind::Bend, &self.tree);
        self.selected = Some(base);
        Some(BendDrag {
            bend,
            end,
            rest_end,
            grab: point_at_depth(&camera, pixel, depth_m),
            depth_m,
        })
    }

    /// Cuts the branch under `pixel` (`sylva_core::edit::prune_at`): one undo step.
    pub(super) fn prune_under(&mut self, pixel: Vec2) {
        let Some(id) = self.pick(pixel) else {
            return;
        };
        let node = self.tree.skeleton.get(id);
        let point = 0.5 * (node.start + node.end);
        let pruned = self
            .history
            .perform(OperationKind::Prune, &mut self.tree, |tree| {
                prune_at(tree, point)
            });
        if pruned.is_ok() {
            self.timeline.keep(&self.tree);
            self.selected = None;
            self.changed();
        }
    }

    /// The lasso on the plane through the tree's base facing the camera (vertical), in the
    /// plane's right/up coordinates, from an outline drawn in image pixels.
    pub fn lasso_from_pixels(&self, pixels: &[Vec2]) -> Option<Lasso> {
        let camera = self.camera?;
        let origin = self
            .tree
            .skeleton
            .internodes
            .first()
            .map_or(Vec3::ZERO, |n| n.start);
        let view = camera.world_from_camera.transform_vector3(Vec3::Z);
        let normal = -Vec3::new(view.x, 0.0, view.z).try_normalize()?;
        let axis_v = Vec3::Y;
        let axis_u = axis_v.cross(normal);
        let eye = camera.position();
        let outline: Vec<Vec2> = pixels
            .iter()
            .filter_map(|p| {
                let direction = camera
                    .world_from_camera
                    .transform_vector3(camera.intrinsics.ray_from_pixel(*p));
                let along = direction.dot(normal);
                if along.abs() < 1e-6 {
                    return None;
                }
                let t = (origin - eye).dot(normal) / along;
                let d = eye + direction * t - origin;
                (t > 0.0).then(|| Vec2::new(d.dot(axis_u), d.dot(axis_v)))
            })
            .collect();
        Lasso::new(origin, axis_u, axis_v, outline).ok()
    }

    /// Fills the lassoed envelope with attraction points and grows the tree into it, guided
    /// iterations in front of the envelope's outside (and of the tracked scene when the scene
    /// mode uses it) until none grows: one undo step.
    fn apply_lasso(&mut self, pixels: &[Vec2]) {
        let Some(lasso) = self.lasso_from_pixels(pixels) else {
            return;
        };
        let area_m2 = polygon_area_m2(&lasso.outline);
        let count =
            ((area_m2 * LASSO_POINTS_PER_M2) as usize).clamp(LASSO_MIN_POINTS, LASSO_MAX_POINTS);
        let envelope = lasso.envelope(LASSO_RESOLUTION);
        let scene = growth_scene(
            self.params.scene_mode,
            &self.occupancy,
            self.world_from_tree,
        );
        let scene = LassoScene {
            envelope: &envelope,
            tracked: scene.as_ref().map(|(s, _)| s as &dyn Scene),
        };
        let timeline = &mut self.timeline;
        let grown = self
            .history
            .perform(OperationKind::Lasso, &mut self.tree, |tree| {
                let first = tree.environment.attraction.len();
                if envelope.add_points_to(tree, count) == 0 {
                    return Err(sylva_core::edit::EditError::DegenerateLasso {
                        points: lasso.outline.len(),
                    });
                }
                // The fill is one group of points, with its own lifetime.
                let iteration = tree.iteration;
                tree.environment
                    .attraction
                    .group_points_from(first, iteration);
                for _ in 0..LASSO_MAX_ITERATIONS {
                    let stats = sylva_core::edit::brush::step_with_point_lifetime(
                        tree,
                        StepOptions {
                            autonomous: false,
                            scene: Some((&scene, SceneMode::GrowInFront)),
                        },
                    );
                    timeline.keep(tree);
                    if stats.num_new_internodes == 0 {
                        break;
                    }
                }
                Ok(())
            });
        if grown.is_ok() {
            self.brush = None;
            self.selected = None;
            self.changed();
        }
    }

    /// The selected internode and the branch above it to its tip (what the UI highlights).
    pub fn selected_branch(&self) -> Vec<NodeId> {
        let skeleton = &self.tree.skeleton;
        let mut branch = Vec::new();
        let mut next = self.selected.filter(|id| id.index() < skeleton.len());
        while let Some(id) = next {
            branch.push(id);
            next = skeleton.get(id).main_child;
        }
        branch
    }
}

/// Area enclosed by a closed outline (shoelace), square metres.
fn polygon_area_m2(outline: &[Vec2]) -> f32 {
    let n = outline.len();
    (0..n)
        .map(|i| outline[i].perp_dot(outline[(i + 1) % n]))
        .sum::<f32>()
        .abs()
        * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tool_round_trips_through_json_with_its_width() {
        for tool in Tool::all(0.05) {
            let json = serde_json::to_string(&tool).expect("serialises");
            let back: Tool = serde_json::from_str(&json).expect("parses");
            assert_eq!(back, tool, "{json}");
        }
    }

    #[test]
    fn a_width_outside_what_a_constraint_takes_is_refused() {
        assert!(Tool::Width { diameter_m: 0.04 }.check().is_ok());
        for bad in [0.0, -0.1, f32::NAN, 50.0] {
            assert!(Tool::Width { diameter_m: bad }.check().is_err(), "{bad}");
        }
    }

    #[test]
    fn the_unit_square_has_unit_area_whichever_way_it_turns() {
        let square = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
        assert!((polygon_area_m2(&square) - 1.0).abs() < 1e-6);
        let reversed: Vec<Vec2> = square.iter().rev().copied().collect();
        assert!((polygon_area_m2(&reversed) - 1.0).abs() < 1e-6);
    }
}
