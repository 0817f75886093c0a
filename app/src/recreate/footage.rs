//! The footage tracked by Sylva's own tracker, in metres: every frame's `world_from_camera`
//! (None where tracking was lost or not yet started), the ground plane, and the map points seen.
//! The tracker's world is fixed at its first map in units of its first guess; the metric scale
//! (the median camera height against the holding height, as `sylva track` measures it) is one
//! factor about the world origin, which lies on the ground.

use std::path::Path;

use glam::{DAffine3, DVec2, DVec3};
use sylva_tracking::{Camera, Plane};

/// One map point: its id and latest position (metres), and the frames that saw it.
#[derive(Clone, Debug)]
pub struct MapPoint {
    pub id: u64,
    pub world: DVec3,
}

/// Tracked footage in the metric world.
#[derive(Clone, Debug)]
pub struct TrackedFootage {
    pub camera: Camera,
    /// `world_from_camera` per footage frame (metres, Y up, origin on the ground).
    pub world_from_camera: Vec<Option<DAffine3>>,
    /// The ground plane as last refined (metres).
    pub ground: Plane,
    /// Every map point tracked in some frame, at its last position.
    pub points: Vec<MapPoint>,
    pub metres_per_unit: f64,
    /// Where the scale came from, for the report.
    pub scale_source: String,
}

impl TrackedFootage {
    /// The ray of raw image pixel `pixel` in frame `frame`: (origin, unit direction) in the world.
    pub fn ray(&self, frame: usize, pixel: DVec2) -> Option<(DVec3, DVec3)> {
        let pose = self.world_from_camera.get(frame).copied().flatten()?;
        let n = self.camera.normalized_from_pixel(pixel);
        let direction = pose
            .transform_vector3(DVec3::new(n.x, n.y, 1.0))
            .try_normalize()?;
        Some((pose.translation, direction))
    }

    /// Height of a world point above the ground plane (metres).
    pub fn height_of(&self, point: DVec3) -> f64 {
        self.ground.signed_distance(point)
    }

    /// The raw pixel a world point projects to in `frame` (None behind the camera or untracked).
    pub fn project(&self, frame: usize, point: DVec3) -> Option<DVec2> {
        let pose = self.world_from_camera.get(frame).copied().flatten()?;
        let in_camera = pose.inverse().transform_point3(point);
        (in_camera.z > 1e-6)
            .then(|| self.camera.pixel_from_camera(in_camera))
            .flatten()
    }

    /// The raw pixel and depth (metres) of a world point seen from `camera_from_world`; None
    /// behind the camera or within a millimetre of its plane.
    pub fn pixel_and_depth(
        &self,
        camera_from_world: &DAffine3,
        point: DVec3,
    ) -> Option<(DVec2, f64)> {
        let c = camera_from_world.transform_point3(point);
        (c.z > 1e-3)
            .then(|| self.camera.pixel_from_camera(c))
            .flatten()
            .map(|pixel| (pixel, c.z))
    }

    pub fn num_tracked(&self) -> usize {
        self.world_from_camera.iter().flatten().count()
    }
}

/// Tracks the TUM-layout footage at `root` with the tracker's defaults and `holding_height_m`.
#[cfg(not(any(target_os = "android", target_os = "ios")))]
pub fn track_footage(root: &Path, holding_height_m: f64) -> anyhow::Result<TrackedFootage> {
    use anyhow::Context;
    use std::collections::BTreeMap;
    use sylva_tracking::scale::CameraHeights;
    use sylva_tracking::{FrameSource, SourceEvent, TrackingState, TumSequence};
    use sylva_tracking::{Tracker, TrackerConfig};
    let sequence = TumSequence::open(root)
        .with_context(|| format!("cannot open {} for tracking", root.display()))?;
    sylva_tracking::cv::configure_single_thread();
    let config = TrackerConfig {
        holding_height_m,
        ..TrackerConfig::default()
    };
    let mut tracker = Tracker::new(sequence.camera, config)
        .with_context(|| format!("cannot start the tracker on {}", root.display()))?;
    let num_frames = sequence.frames.len();
    let mut poses: Vec<Option<DAffine3>> = vec![None; num_frames];
    let mut points: BTreeMap<u64, DVec3> = BTreeMap::new();
    let mut heights = CameraHeights::default();
    let mut ground: Option<Plane> = None;
    let mut source = sequence.source();
    while let Some(event) = source.next_event() {
        match event {
            SourceEvent::Frame(frame) => {
                let up = sequence.up_in_camera_at(frame.timestamp_s);
                let output = tracker
                    .track(&frame, up.map(|u| u * 9.81))
                    .with_context(|| format!("tracking frame {}", frame.index))?;
                if output.plane.is_some() {
                    ground = output.plane;
                }
                let Some(pose) = output.world_from_camera else {
                    continue;
                };
                if output.state != TrackingState::Ok || frame.index >= num_frames {
                    continue;
                }
                poses[frame.index] = Some(pose);
                if let Some(plane) = &output.plane {
                    heights.push(plane, pose.translation);
                }
                for p in &output.tracked_points {
                    points.insert(p.id, p.world.as_dvec3());
                }
            }
            SourceEvent::Skipped { path, reason, .. } => {
                eprintln!("warning: skipped frame {}: {reason}", path.display());
            }
        }
    }
    let ground = ground.with_context(|| {
        format!(
            "no ground plane was found in {}: the trunk base cannot be placed",
            root.display()
        )
    })?;
    let (metres_per_unit, scale_source) = match heights.scale(holding_height_m) {
        Some(scale) => (scale.metres_per_unit, scale.source.to_string()),
        None => (
            1.0,
            format!("the tracker's first map (camera held {holding_height_m} m above the ground)"),
        ),
    };
    let s = metres_per_unit;
    let scaled = |pose: DAffine3| DAffine3 {
        matrix3: pose.matrix3,
        translation: pose.translation * s,
    };
    Ok(TrackedFootage {
        camera: sequence.camera,
        world_from_camera: poses.into_iter().map(|p| p.map(scaled)).collect(),
        ground: Plane {
            normal: ground.normal,
            offset: ground.offset * s,
        },
        points: points
            .into_iter()
            .map(|(id, world)| MapPoint {
                id,
                world: world * s,
            })
            .collect(),
        metres_per_unit,
        scale_source,
    })
}

#[cfg(any(target_os = "android", target_os = "ios"))]
pub fn track_footage(root: &Path, _holding_height_m: f64) -> anyhow::Result<TrackedFootage> {
    anyhow::bail!(
        "recreating from footage ({}) needs the OpenCV tracker, which phone builds leave out",
        root.display()
    )
}
