//! The monocular tracker (the ORB-SLAM split: frame → tracker → map): Lucas–Kanade tracks, two-
//! view initialisation, per-frame pose from the map (motion-only refinement, PnP-RANSAC as a
//! fallback), the local map searched in every frame, keyframes with local bundle adjustment, and
//! relocalisation (module `relocalise`).

use crate::ba::{BaConfig, refine_pose, reprojection_error_px};
use crate::backend::{Vision, VisionBackend};
use crate::camera::Camera;
#[cfg(feature = "opencv")]
use crate::cv::CvError;
use crate::features::{Track, normalized};
use crate::frame::{Frame, FrameOutput, Plane, TrackedPoint, TrackingState};
use crate::initializer::Initializer;
use crate::lk::{self, Pyramid, PyramidScratch};
use crate::map::Map;
use crate::pose::Se3;
use crate::rolling_shutter::{ReadoutEstimate, RollingShutter};
use crate::world::WorldFrame;
use glam::{DAffine3, DVec2, DVec3, Vec2};
use std::collections::{HashMap, HashSet};

/// Tracking failed in a way that is not about the footage (an OpenCV error, or a backend this
/// build lacks).
#[derive(Debug, thiserror::Error)]
pub enum TrackerError {
    #[cfg(feature = "opencv")]
    #[error(transparent)]
    Cv(#[from] CvError),
    #[error("this build has no {} vision backend (it needs the `opencv` feature)", .0.name())]
    BackendUnavailable(VisionBackend),
}

/// Tracker settings; defaults suit 640 × 480 handheld footage at 30 Hz.
#[derive(Clone, Copy, Debug)]
pub struct TrackerConfig {
    /// Corners kept alive at once. Default 300.
    pub max_tracks: usize,
    /// Minimum distance between corners, pixels. Default 14.
    pub min_corner_distance_px: f32,
    /// Forward-backward Lucas–Kanade tolerance, pixels. Default 2.0.
    pub max_fb_error_px: f32,
    /// Pyramid levels above the base for frame-to-frame tracks. Default 3.
    pub lk_levels: usize,
    /// Pyramid levels above the base for the local-map search, seeded at projections through
    /// the frame's pose (a guess within a few pixels). Default 1.
    pub search_lk_levels: usize,
    /// Whether the local-map search checks matches forward-backward; its reprojection gate
    /// rejects wrong matches either way. Default true.
    pub search_fb_check: bool,
    /// Reprojection error beyond which a track is an outlier, pixels. Default 4.0.
    pub outlier_px: f64,
    /// Huber threshold δ for pose refinement and bundle adjustment, pixels. Default 1.5.
    pub huber_px: f64,
    /// Smallest ray angle for triangulating a point once its keyframes pass the baseline test,
    /// degrees: it drops only points too far away to place. Default 0.25.
    pub min_parallax_deg: f64,
    /// Candidates are triangulated once their origin keyframe's centre is this far from the
    /// current keyframe's, as a fraction of the origin's median scene depth (0: per-point
    /// parallax test alone). Default 0.01.
    pub min_baseline_ratio: f64,
    /// Whether keyframes attach candidate corners to old map points they re-find (ORB
    /// descriptors near the points' projections). Default true.
    pub adopt_map_points: bool,
    /// How far from a candidate an old map point may project to be re-found, pixels.
    /// Default 4.
    pub adopt_radius_px: f32,
    /// Median ray angle needed to initialise, degrees. Default 1.0.
    pub init_min_parallax_deg: f64,
    /// Triangulated points needed to initialise. Default 80.
    pub init_min_points: usize,
    /// Fewest inlier map points for a pose. Default 12.
    pub min_pose_inliers: usize,
    /// Keyframes optimised by local bundle adjustment. Default 8.
    pub local_window: usize,
    /// Map points searched by reprojection per frame at most. Default 400.
    pub max_local_search: usize,
    /// A keyframe at least every this many frames. Default 8.
    pub max_keyframe_gap: usize,
    /// Rolling-shutter readout time, first row to last, seconds: `Some(0.0)` for a global
    /// shutter; None (default) estimates it from the footage ([`crate::rolling_shutter`]).
    pub rolling_shutter_readout_s: Option<f64>,
    /// Frames after a failure before `RecentlyLost` becomes `Lost`. Default 30.
    pub lost_after_frames: usize,
    /// Holding height for the metric scale, metres. Default 1.5.
    pub holding_height_m: f64,
    /// Corners, two-view geometry, PnP and ORB: OpenCV or the portable backend. Default
    /// OpenCV where the build has it, else portable.
    pub backend: VisionBackend,
    /// The portable backend's minimal essential-matrix solver for the two-view start (OpenCV's
    /// is always five-point). Default eight-point: see the README's start-frame table.
    pub essential_minimal: crate::vision::EssentialMinimal,
}

impl Default for TrackerConfig {
    fn default() -> Self {
        Self {
            max_tracks: 300,
            min_corner_distance_px: 14.0,
            max_fb_error_px: 2.0,
            lk_levels: 3,
            search_lk_levels: 1,
            search_fb_check: true,
            outlier_px: 4.0,
            huber_px: 1.5,
            min_parallax_deg: 0.25,
            init_min_parallax_deg: 1.0,
            min_baseline_ratio: 0.01,
            adopt_map_points: true,
            adopt_radius_px: 4.0,
            init_min_points: 80,
            min_pose_inliers: 12,
            local_window: 8,
            max_local_search: 400,
            max_keyframe_gap: 8,
            rolling_shutter_readout_s: None,
            lost_after_frames: 30,
            holding_height_m: crate::scale::DEFAULT_HOLDING_HEIGHT_M,
            backend: VisionBackend::default(),
            essential_minimal: crate::vision::EssentialMinimal::default(),
        }
    }
}

/// A pose found late: frames seen while initialising get theirs once the first map exists.
#[derive(Clone, Copy, Debug)]
pub struct LatePose {
    pub index: usize,
    pub world_from_camera: DAffine3,
}

/// The monocular tracker.
pub struct Tracker {
    pub(crate) camera: Camera,
    pub(crate) config: TrackerConfig,
    pub(crate) state: TrackingState,
    pub(crate) map: Map,
    pub(crate) tracks: Vec<Track>,
    pub(crate) prev_pyramid: Option<Pyramid>,
    /// Memory of pyramids no longer used, for the next frame's.
    pub(crate) pyramid_scratch: PyramidScratch,
    /// `camera_from_world` (map frame) of the previous frame, and the motion since the one before.
    pub(crate) prev_pose: Option<Se3>,
    pub(crate) velocity: Se3,
    /// Time the velocity spans, and the time of the last frame with a pose, seconds: a frame
    /// that comes after dropped ones is predicted over the whole gap.
    pub(crate) velocity_dt_s: f64,
    pub(crate) last_pose_time_s: Option<f64>,
    pub(crate) keyframe_pyramids: HashMap<usize, Pyramid>,
    pub(crate) init: Option<Initializer>,
    pub(crate) frames_since_keyframe: usize,
    pub(crate) tracked_at_keyframe: usize,
    pub(crate) frames_failed: usize,
    pub(crate) world: Option<WorldFrame>,
    pub(crate) gravity_up: Option<DVec3>,
    pub(crate) late_poses: Vec<LatePose>,
    pub(crate) vision: Vision,
    pub(crate) readout: ReadoutEstimate,
}

impl Tracker {
    pub fn new(camera: Camera, config: TrackerConfig) -> Result<Self, TrackerError> {
        let vision = Vision::new(config.backend)?;
        Ok(Self {
            camera,
            config,
            state: TrackingState::NotInitialized,
            map: Map::default(),
            tracks: Vec::new(),
            prev_pyramid: None,
            pyramid_scratch: PyramidScratch::default(),
            prev_pose: None,
            velocity: Se3::IDENTITY,
            velocity_dt_s: 0.0,
            last_pose_time_s: None,
            keyframe_pyramids: HashMap::new(),
            init: None,
            frames_since_keyframe: 0,
            tracked_at_keyframe: 0,
            frames_failed: 0,
            world: None,
            gravity_up: None,
            late_poses: Vec::new(),
            vision,
            readout: ReadoutEstimate::default(),
        })
    }

    pub fn state(&self) -> TrackingState {
        self.state
    }

    pub fn map(&self) -> &Map {
        &self.map
    }

    /// The world frame (ground plane, scale) once the map exists.
    pub fn world(&self) -> Option<&WorldFrame> {
        self.world.as_ref()
    }

    /// Poses of earlier frames found since the last call (frames seen while initialising).
    pub fn take_late_poses(&mut self) -> Vec<LatePose> {
        std::mem::take(&mut self.late_poses)
    }

    /// Tracks one frame. `accelerometer` is the specific force in camera axes (X right, Y down,
    /// Z forward), m/s², when the footage has one: at rest it points up.
    pub fn track(
        &mut self,
        frame: &Frame,
        accelerometer: Option<DVec3>,
    ) -> Result<FrameOutput, TrackerError> {
        if let Some(a) = accelerometer.filter(|a| a.length() > 1.0) {
            self.gravity_up = Some(a.normalize());
        }
        let blank = frame.image.contrast() < 4.0;
        let pyramid = Pyramid::build_with(&frame.image, &mut self.pyramid_scratch);
        let pose = match self.state {
            TrackingState::NotInitialized | TrackingState::Initializing if blank => None,
            TrackingState::NotInitialized => {
                self.start_initializing(frame, pyramid)?;
                return Ok(self.output(frame, None));
            }
            TrackingState::Initializing => {
                let pose = self.continue_initializing(frame, pyramid)?;
                if pose.is_some() {
                    self.last_pose_time_s = Some(frame.timestamp_s);
                }
                return Ok(self.output(frame, pose));
            }
            _ if blank => None,
            _ => self.track_with_map(frame, &pyramid)?,
        };
        match pose {
            Some(pose) => {
                self.frames_failed = 0;
                self.state = TrackingState::Ok;
                if let Some(prev) = self.prev_pose {
                    self.velocity = pose.compose(&prev.inverse());
                    self.velocity_dt_s =
                        self.last_pose_time_s.map_or(0.0, |t| frame.timestamp_s - t);
                }
                self.last_pose_time_s = Some(frame.timestamp_s);
                self.prev_pose = Some(pose);
                if let Some(old) = self.prev_pyramid.replace(pyramid) {
                    old.recycle(&mut self.pyramid_scratch);
                }
                self.frames_since_keyframe += 1;
                let keyframe = self.needs_keyframe();
                if self.config.rolling_shutter_readout_s.is_none()
                    && (keyframe || self.readout.is_settling())
                {
                    self.estimate_readout(&pose);
                }
                if keyframe {
                    self.insert_keyframe(frame, pose)?;
                }
                let pose = self.prev_pose.unwrap_or(pose);
                Ok(self.output(frame, Some(pose)))
            }
            None => {
                self.frames_failed += 1;
                self.velocity = Se3::IDENTITY;
                self.tracks.clear();
                if let Some(old) = self.prev_pyramid.take() {
                    old.recycle(&mut self.pyramid_scratch);
                }
                self.state = if self.frames_failed > self.config.lost_after_frames {
                    TrackingState::Lost
                } else {
                    TrackingState::RecentlyLost
                };
                Ok(self.output(frame, None))
            }
        }
    }

    /// Pose of a tracked frame: LK from the previous frame, else relocalisation.
    fn track_with_map(
        &mut self,
        frame: &Frame,
        pyramid: &Pyramid,
    ) -> Result<Option<Se3>, TrackerError> {
        let (Some(prev_pyramid), Some(prev_pose)) = (self.prev_pyramid.as_ref(), self.prev_pose)
        else {
            return self.relocalise(frame, pyramid);
        };
        // Frames dropped since the last pose (a gap of at least one and a half frame intervals):
        // the constant-velocity prediction spans the whole gap.
        let gap = match self.last_pose_time_s {
            Some(t) if self.velocity_dt_s > 1e-6 => (frame.timestamp_s - t) / self.velocity_dt_s,
            _ => 1.0,
        };
        let velocity = if gap >= 1.5 {
            self.velocity.scaled(gap.min(10.0))
        } else {
            self.velocity
        };
        let predicted = velocity.compose(&prev_pose);
        let shutter = self.shutter();
        let guesses: Vec<Vec2> = self
            .tracks
            .iter()
            .map(|t| self.predict_pixel(&shutter, t, &prev_pose, &predicted))
            .collect();
        let from: Vec<Vec2> = self.tracks.iter().map(|t| t.pixel).collect();
        let moved = lk::track_points(
            prev_pyramid,
            pyramid,
            &from,
            Some(&guesses),
            lk::LkOptions {
                levels: self.config.lk_levels,
                max_fb_error_px: Some(self.config.max_fb_error_px),
            },
        );
        let mut kept = Vec::with_capacity(self.tracks.len());
        for (track, next) in self.tracks.iter().zip(moved) {
            if let Some(pixel) = next.filter(|p| self.camera.contains(p.as_dvec2(), 2.0)) {
                kept.push(Track { pixel, ..*track });
            }
        }
        self.tracks = kept;
        let estimated = self.estimate_pose(predicted)?;
        let Some(pose) = estimated else {
            return self.relocalise(frame, pyramid);
        };
        self.search_local_map(pyramid, &pose)?;
        Ok(self.estimate_pose(pose)?.or(Some(pose)))
    }

    /// Where a track should appear under the predicted pose (rotation only for candidates).
    fn predict_pixel(
        &self,
        shutter: &RollingShutter,
        track: &Track,
        prev: &Se3,
        predicted: &Se3,
    ) -> Vec2 {
        let in_prev_camera = match track.point.and_then(|id| self.map.points.get(&id)) {
            Some(point) => {
                return self
                    .project(shutter, predicted, point.position)
                    .unwrap_or(track.pixel);
            }
            None => normalized(&self.camera, track.pixel).extend(1.0),
        };
        let rotation = predicted.rotation * prev.rotation.inverse();
        let rotated = rotation * in_prev_camera;
        self.camera
            .pixel_from_camera(rotated)
            .filter(|p| self.camera.contains(*p, 0.0))
            .map(|p| p.as_vec2())
            .unwrap_or(track.pixel)
    }

    /// Where `point` appears in the frame at `camera_from_world` through `shutter` (from
    /// [`Self::shutter`], taken once per frame by callers that project many points).
    pub(crate) fn project(
        &self,
        shutter: &RollingShutter,
        camera_from_world: &Se3,
        point: DVec3,
    ) -> Option<Vec2> {
        shutter
            .pixel(&self.camera, camera_from_world.transform_point(point))
            .filter(|p| self.camera.contains(*p, 4.0))
            .map(|p| p.as_vec2())
    }

    pub(crate) fn ba_config(&self, iterations: usize) -> BaConfig {
        BaConfig {
            focal: self.camera.focal(),
            huber_px: self.config.huber_px,
            max_iterations: iterations,
        }
    }

    /// The rolling-shutter model of the current frame: the readout given or estimated so far
    /// (0 until the estimate has enough keyframes), the rotation rate of the last motion.
    pub(crate) fn shutter(&self) -> RollingShutter {
        let readout_s = self
            .config
            .rolling_shutter_readout_s
            .or_else(|| self.readout.readout_s())
            .unwrap_or(0.0);
        let rate = if self.velocity_dt_s > 1e-6 {
            self.velocity.rotation.to_scaled_axis() / self.velocity_dt_s
        } else {
            DVec3::ZERO
        };
        RollingShutter { rate, readout_s }
    }

    /// The readout time the tracker uses now, seconds (given, estimated, else 0).
    pub fn rolling_shutter_readout_s(&self) -> f64 {
        self.shutter().readout_s
    }

    /// Pose from the tracks that see map points: robust refinement from `start`, PnP-RANSAC
    /// when that leaves too few inliers. Outlier tracks lose their point.
    fn estimate_pose(&mut self, start: Se3) -> Result<Option<Se3>, TrackerError> {
        let shutter = self.shutter();
        let pairs: Vec<(usize, DVec3, DVec2)> = self
            .tracks
            .iter()
            .enumerate()
            .filter_map(|(i, t)| {
                let p = self.map.points.get(&t.point?)?;
                Some((i, p.position, shutter.normalized(&self.camera, t.pixel)))
            })
            .collect();
        if pairs.len() < self.config.min_pose_inliers {
            return Ok(None);
        }
        let world: Vec<DVec3> = pairs.iter().map(|p| p.1).collect();
        let image: Vec<DVec2> = pairs.iter().map(|p| p.2).collect();
        let mut wide = self.ba_config(10);
        wide.huber_px = 8.0;
        let mut pose = refine_pose(start, &world, &image, &wide);
        pose = refine_pose(pose, &world, &image, &self.ba_config(10));
        let focal = self.camera.focal();
        let count = |pose: &Se3| {
            pairs
                .iter()
                .filter(|p| reprojection_error_px(pose, p.1, p.2, focal) <= self.config.outlier_px)
                .count()
        };
        if count(&pose) * 2 < pairs.len() {
            match self.vision.pnp_ransac(
                &self.camera,
                &world,
                &image,
                Some(start),
                self.config.outlier_px as f32,
                100,
                crate::vision::PnpMinimal::Epnp,
            )? {
                Some((found, _)) => pose = refine_pose(found, &world, &image, &self.ba_config(10)),
                None => return Ok(None),
            }
        }
        let inliers: Vec<usize> = (0..pairs.len())
            .filter(|&k| {
                reprojection_error_px(&pose, pairs[k].1, pairs[k].2, focal)
                    <= self.config.outlier_px
            })
            .collect();
        if inliers.len() < self.config.min_pose_inliers {
            return Ok(None);
        }
        let (w, n): (Vec<DVec3>, Vec<DVec2>) =
            inliers.iter().map(|&k| (pairs[k].1, pairs[k].2)).unzip();
        pose = refine_pose(pose, &w, &n, &self.ba_config(10));
        let inlier_tracks: HashSet<usize> = inliers.iter().map(|&k| pairs[k].0).collect();
        let mut index = 0;
        self.tracks.retain(|t| {
            let keep = t.point.is_none() || inlier_tracks.contains(&index);
            index += 1;
            keep
        });
        Ok(Some(pose))
    }

    /// The per-frame output, in the world frame.
    pub(crate) fn output(&self, frame: &Frame, pose: Option<Se3>) -> FrameOutput {
        let world = self.world.as_ref();
        let to_world = |p: DVec3| world.map_or(p, |w| w.world_from_map.transform_point(p));
        let tracked_points = if pose.is_some() {
            self.tracks
                .iter()
                .filter_map(|t| {
                    let point = self.map.points.get(&t.point?)?;
                    Some(TrackedPoint {
                        id: point.id,
                        pixel: t.pixel,
                        world: to_world(point.position).as_vec3(),
                    })
                })
                .collect()
        } else {
            Vec::new()
        };
        FrameOutput {
            index: frame.index,
            timestamp_s: frame.timestamp_s,
            state: self.state,
            world_from_camera: pose.map(|p| self.world_from_camera(&p)),
            tracked_points,
            plane: world.map(|w| w.plane_in_world()).map(|p: Plane| p),
        }
    }

    /// `world_from_camera` of a map-frame `camera_from_world`.
    pub(crate) fn world_from_camera(&self, camera_from_map: &Se3) -> DAffine3 {
        let map_from_camera = camera_from_map.inverse();
        match self.world.as_ref() {
            Some(w) => w.world_from_camera(&map_from_camera),
            None => map_from_camera.to_affine(),
        }
    }
}
