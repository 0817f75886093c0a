//! The app's Recreate mode (issue 23): "Recreate a tree". The user taps the real tree's trunk
//! base (its ray meets the ground plane), traces the crown's outline with a finger in the view
//! shown, walks on and traces again, picks a species (or lets the closest preset by proportions
//! be chosen) and asks "Grow to fit": the marks, the poses of the frames seen so far and the
//! tracked points go to the same recreation as `sylva recreate` ([`crate::recreate::recreate`]),
//! and the grown tree replaces the design's tree (undoably). It is an ordinary tree then: every
//! tool, undo and the years slider work on it. The measures, in metres, with how each was
//! obtained, and the model's agreement with each outline are kept for the panel.
//!
//! Marks name frames by their place among the frames the design observed (the session's frame
//! steps); pixels are the camera image's. Every action is an [`InputEvent::Recreate`]
//! (super::InputEvent::Recreate), and touches while the mode is on, so sessions replay it.

use std::collections::BTreeMap;

use glam::{DAffine3, DMat3, DVec2, DVec3, Mat4, Vec2};
use serde::{Deserialize, Serialize};
use sylva_tracking::depth_mesh::Observation;
use sylva_tracking::{Camera, Plane};

use super::{DesignState, TAP_SLOP_PX, TouchPhase, species_named};
use crate::recreate::footage::{MapPoint, TrackedFootage};
use crate::recreate::grow::GrowthReport;
use crate::recreate::marks::{BaseMark, CrownMark, Marks};
use crate::recreate::measure::Measurements;
use crate::recreate::overlay::{OverlayStyle, overlay_layer};
use crate::recreate::silhouette::WorldTriangles;
use crate::render::{GroundPlane, Intrinsics};

/// What the Recreate panel asks for.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "action", rename_all = "snake_case")]
pub enum RecreateAction {
    /// Starts marking a real tree (clears earlier marks): a tap marks the trunk base, a drag
    /// traces the crown's outline in the view shown.
    Start,
    /// The species to grow (`None`: the closest preset by the measured proportions).
    Species { species: Option<String> },
    /// Measures the marked tree and grows the species into it.
    GrowToFit,
    /// Leaves the mode without growing (the marks are kept).
    Leave,
    /// The overlay of the model over the real tree: its opacity (0 to 1) and outline-only mode.
    Overlay { opacity: f32, outline_only: bool },
}

/// What a "Grow to fit" measured and grew.
#[derive(Clone, Debug)]
pub struct RecreateResult {
    /// Measures in the tracker's world units (a metre to the scale's error); `metres_per_unit`
    /// turns them into metres for the screen.
    pub measurements: Measurements,
    pub metres_per_unit: f64,
    pub growth: GrowthReport,
    /// Per marked frame step, the model's agreement with the traced outline.
    pub outline_iou: Vec<(usize, f64)>,
}

/// Outline points closer than this to the previous one are skipped, pixels.
const OUTLINE_SPACING_PX: f64 = 4.0;
/// Most years spent filling the marked crown.
const MAX_YEARS: f32 = 40.0;

/// The mode's state: marks, what was observed for them, and the last result.
pub struct RecreateMode {
    pub active: bool,
    pub base: Option<BaseMark>,
    pub outlines: Vec<CrownMark>,
    /// The outline being traced: its touch and points.
    tracing: Option<(u64, Vec<[f64; 2]>, bool)>,
    pub species: Option<String>,
    pub overlay: OverlayStyle,
    /// Every observed frame's pose (None where tracking was lost), by frame step.
    poses: Vec<Option<DAffine3>>,
    /// The tracked points at their latest positions, by id.
    points: BTreeMap<u64, DVec3>,
    ground: Option<Plane>,
    camera: Option<Camera>,
    pub result: Option<RecreateResult>,
    /// The last refusal (a bad mark, nothing to grow from), in plain words.
    pub message: Option<String>,
}

impl Default for RecreateMode {
    fn default() -> Self {
        RecreateMode {
            active: false,
            base: None,
            outlines: Vec::new(),
            tracing: None,
            species: None,
            overlay: OverlayStyle {
                opacity: 0.6,
                outline_only: false,
            },
            poses: Vec::new(),
            points: BTreeMap::new(),
            ground: None,
            camera: None,
            result: None,
            message: None,
        }
    }
}

fn pose_of(world_from_camera: Mat4) -> DAffine3 {
    let m = world_from_camera.as_dmat4();
    DAffine3 {
        matrix3: DMat3::from_cols(
            m.x_axis.truncate(),
            m.y_axis.truncate(),
            m.z_axis.truncate(),
        ),
        translation: m.w_axis.truncate(),
    }
}

impl RecreateMode {
    /// Records an observed frame: its pose, the ground plane and the tracked points.
    pub fn observe(
        &mut self,
        intrinsics: &Intrinsics,
        world_from_camera: Option<Mat4>,
        ground: Option<GroundPlane>,
        observations: &[Observation],
    ) {
        self.camera
            .get_or_insert_with(|| crate::scale::camera_of(intrinsics));
        if let Some(g) = ground {
            let normal = g.normal.as_dvec3().normalize_or(DVec3::Y);
            self.ground = Some(Plane {
                normal,
                offset: -normal.dot(g.point.as_dvec3()),
            });
        }
        let pose = world_from_camera.map(pose_of);
        self.poses.push(pose);
        if let Some(pose) = pose {
            for o in observations {
                let d = f64::from(o.depth_m);
                let in_camera = DVec3::new(
                    (f64::from(o.pixel.x) - f64::from(intrinsics.cx)) / f64::from(intrinsics.fx)
                        * d,
                    (f64::from(o.pixel.y) - f64::from(intrinsics.cy)) / f64::from(intrinsics.fy)
                        * d,
                    d,
                );
                self.points.insert(o.id, pose.transform_point3(in_camera));
            }
        }
    }

    /// The frame step shown now (the last observed).
    pub fn frame_step(&self) -> Option<usize> {
        self.poses.len().checked_sub(1)
    }

    /// The tracked footage as far as observed, for the recreation.
    pub fn tracked(&self) -> Option<TrackedFootage> {
        Some(TrackedFootage {
            camera: self.camera?,
            world_from_camera: self.poses.clone(),
            ground: self.ground?,
            points: self
                .points
                .iter()
                .map(|(&id, &world)| MapPoint { id, world })
                .collect(),
            metres_per_unit: 1.0,
            scale_source: "the design's world".into(),
        })
    }

    /// The marks so far (a trunk base and at least one outline), else what is missing.
    pub fn marks(&self) -> Result<Marks, String> {
        let base = self
            .base
            .clone()
            .ok_or("tap the bottom of the real tree's trunk first")?;
        if self.outlines.is_empty() {
            return Err("trace the crown's outline with a finger first".into());
        }
        Ok(Marks {
            base,
            crown: self.outlines.clone(),
        })
    }

    /// A touch while the mode is on: a tap marks the trunk base, a drag traces an outline.
    fn touch(&mut self, phase: TouchPhase, id: u64, pixel: Vec2) {
        let Some(frame) = self.frame_step() else {
            return;
        };
        let p = [f64::from(pixel.x), f64::from(pixel.y)];
        match phase {
            TouchPhase::Start => self.tracing = Some((id, vec![p], false)),
            TouchPhase::Move => {
                if let Some((touch, points, moved)) = self.tracing.as_mut()
                    && *touch == id
                {
                    let first = DVec2::from(points[0]);
                    *moved |= DVec2::from(p).distance(first) > f64::from(TAP_SLOP_PX);
                    let last = DVec2::from(*points.last().unwrap_or(&p));
                    if DVec2::from(p).distance(last) >= OUTLINE_SPACING_PX {
                        points.push(p);
                    }
                }
            }
            TouchPhase::End => {
                let Some((touch, points, moved)) = self.tracing.take() else {
                    return;
                };
                if touch != id {
                    self.tracing = Some((touch, points, moved));
                    return;
                }
                if moved {
                    self.outlines.push(CrownMark {
                        frame,
                        outline: points,
                    });
                } else {
                    self.base = Some(BaseMark { frame, pixel: p });
                }
                self.message = None;
            }
        }
    }
}

impl DesignState {
    /// Routes a touch to the Recreate mode while it is on (true: taken).
    pub(super) fn recreate_touch(&mut self, phase: TouchPhase, id: u64, pixel: Vec2) -> bool {
        if !self.recreate.active {
            return false;
        }
        self.recreate.touch(phase, id, pixel);
        true
    }

    pub(super) fn recreate_action(&mut self, action: &RecreateAction) {
        let mode = &mut self.recreate;
        match action {
            RecreateAction::Start => {
                mode.active = true;
                mode.base = None;
                mode.outlines.clear();
                mode.tracing = None;
                mode.message = None;
            }
            RecreateAction::Species { species } => mode.species = species.clone(),
            RecreateAction::Leave => {
                mode.active = false;
                mode.tracing = None;
            }
            RecreateAction::Overlay {
                opacity,
                outline_only,
            } => {
                mode.overlay = OverlayStyle {
                    opacity: opacity.clamp(0.0, 1.0),
                    outline_only: *outline_only,
                }
            }
            RecreateAction::GrowToFit => {
                if let Err(message) = self.grow_to_fit() {
                    self.recreate.message = Some(message);
                }
            }
        }
    }

    /// The comparison overlay of frame step `step` (the one shown when `None`) drawn in `style`:
    /// the design's tree as it is now over the real tree, with the outlines traced in that
    /// frame. `None` before anything was observed or planted.
    pub fn recreate_overlay(
        &self,
        step: Option<usize>,
        style: OverlayStyle,
    ) -> Option<image::RgbaImage> {
        let footage = self.recreate.tracked()?;
        let step = step.or(self.recreate.frame_step())?;
        let world_from_tree = self.world_from_tree?;
        let model = WorldTriangles::of_tree(&self.tree, &world_from_tree);
        Some(overlay_layer(
            &footage,
            step,
            &model,
            &self.recreate.outlines,
            style,
        ))
    }

    /// Measures the marked tree and grows the chosen species into it, replacing the design's
    /// tree (undoable); a refusal says which mark is wrong.
    fn grow_to_fit(&mut self) -> Result<(), String> {
        let mode = &self.recreate;
        let marks = mode.marks()?;
        let footage = mode.tracked().ok_or(
            "the ground has not been found yet: walk a few steps with the camera on the ground",
        )?;
        let (width, height) = (footage.camera.width, footage.camera.height);
        marks
            .validate(footage.world_from_camera.len(), width, height)
            .map_err(|e| e.to_string())?;
        let species = mode.species.as_deref().map(species_named);
        let recreated = crate::recreate::recreate(
            &footage,
            &marks,
            species,
            self.seed,
            MAX_YEARS,
            None,
            self.scale.state.metres_per_unit(),
        )
        .map_err(|e| e.to_string())?;
        let world_from_tree = recreated.world_from_tree.to_cols_array();
        self.recreate.result = Some(RecreateResult {
            measurements: recreated.recreation.measurements.clone(),
            metres_per_unit: self.scale.state.metres_per_unit(),
            growth: recreated.growth.clone(),
            outline_iou: recreated.outline_iou.clone(),
        });
        self.recreate.active = false;
        self.restore_tree(recreated.tree, Some(world_from_tree));
        Ok(())
    }
}
