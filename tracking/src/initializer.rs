//! Two-view initialisation: corners of a reference frame followed by Lucas–Kanade until the
//! essential-matrix pose triangulates enough points with enough parallax. Pure rotation (all rays
//! parallel) and planar-homography-dominated views without parallax are refused. Frames seen
//! meanwhile get their poses once the map exists (late poses).

use crate::ba::{BaObservation, bundle_adjust, refine_pose, reprojection_error_px};
use crate::features::{Track, normalized, parallax_rad, triangulate};
use crate::frame::{Frame, TrackingState};
use crate::lk::{self, Pyramid};
use crate::map::Observation;
use crate::pose::Se3;
use crate::tracker::{LatePose, Tracker, TrackerError};
use crate::world::WorldFrame;
use glam::{DVec2, DVec3, Vec2};

/// The reference frame and the tracks followed since.
pub(crate) struct Initializer {
    frame_index: usize,
    pyramid: Pyramid,
    reference: Vec<Vec2>,
    /// Per frame since the reference: its index and each reference corner's pixel (if alive).
    history: Vec<(usize, Vec<Option<Vec2>>)>,
    current: Vec<Option<Vec2>>,
    prev_pyramid: Pyramid,
}

const MIN_INIT_TRACKS: usize = 100;

impl Tracker {
    pub(crate) fn start_initializing(
        &mut self,
        frame: &Frame,
        pyramid: Pyramid,
    ) -> Result<(), TrackerError> {
        let corners =
            self.vision
                .detect_corners(&frame.image, 2 * self.config.max_tracks, 10.0, &[])?;
        if corners.len() < MIN_INIT_TRACKS {
            self.state = TrackingState::NotInitialized;
            return Ok(());
        }
        self.init = Some(Initializer {
            frame_index: frame.index,
            pyramid: pyramid.clone(),
            current: corners.iter().copied().map(Some).collect(),
            reference: corners,
            history: Vec::new(),
            prev_pyramid: pyramid,
        });
        self.state = TrackingState::Initializing;
        Ok(())
    }

    /// Follows the reference corners; builds the first map when the views allow it.
    pub(crate) fn continue_initializing(
        &mut self,
        frame: &Frame,
        pyramid: Pyramid,
    ) -> Result<Option<Se3>, TrackerError> {
        let Some(mut init) = self.init.take() else {
            self.start_initializing(frame, pyramid)?;
            return Ok(None);
        };
        let alive: Vec<usize> = (0..init.current.len())
            .filter(|&i| init.current[i].is_some())
            .collect();
        let from: Vec<Vec2> = alive.iter().filter_map(|&i| init.current[i]).collect();
        let moved = lk::track_points(
            &init.prev_pyramid,
            &pyramid,
            &from,
            None,
            lk::LkOptions {
                levels: self.config.lk_levels,
                max_fb_error_px: Some(self.config.max_fb_error_px),
            },
        );
        for (k, &i) in alive.iter().enumerate() {
            init.current[i] = moved[k].filter(|p| self.camera.contains(p.as_dvec2(), 2.0));
        }
        let num_alive = init.current.iter().flatten().count();
        if num_alive < MIN_INIT_TRACKS {
            self.start_initializing(frame, pyramid)?;
            return Ok(None);
        }
        init.history.push((frame.index, init.current.clone()));
        init.prev_pyramid = pyramid;
        match self.try_two_view(&init, frame)? {
            Some(pose) => {
                self.prev_pyramid = Some(init.prev_pyramid);
                self.keyframe_pyramids.insert(0, init.pyramid);
                self.state = TrackingState::Ok;
                self.prev_pose = Some(pose);
                Ok(Some(pose))
            }
            None => {
                self.init = Some(init);
                Ok(None)
            }
        }
    }

    /// Essential matrix, cheirality, triangulation and the parallax test; on success the map
    /// holds two keyframes and their points, and the world frame is set.
    fn try_two_view(
        &mut self,
        init: &Initializer,
        frame: &Frame,
    ) -> Result<Option<Se3>, TrackerError> {
        let pairs: Vec<(usize, DVec2, DVec2)> = (0..init.reference.len())
            .filter_map(|i| {
                let cur = init.current[i]?;
                Some((
                    i,
                    normalized(&self.camera, init.reference[i]),
                    normalized(&self.camera, cur),
                ))
            })
            .collect();
        let displacement = median(
            pairs
                .iter()
                .map(|p| (p.1 - p.2).length() * self.camera.focal())
                .collect(),
        );
        if displacement < 10.0 {
            return Ok(None);
        }
        let first: Vec<DVec2> = pairs.iter().map(|p| p.1).collect();
        let second: Vec<DVec2> = pairs.iter().map(|p| p.2).collect();
        let Some((relative, inliers)) = self.vision.relative_pose(
            &self.camera,
            &first,
            &second,
            1.0,
            self.config.essential_minimal,
        )?
        else {
            return Ok(None);
        };
        let focal = self.camera.focal();
        let reference_pose = Se3::IDENTITY;
        let mut good: Vec<(usize, DVec3)> = Vec::new();
        let mut parallaxes = Vec::new();
        for (k, p) in pairs.iter().enumerate() {
            if !inliers[k] {
                continue;
            }
            let Some(x) = triangulate(&reference_pose, p.1, &relative, p.2) else {
                continue;
            };
            let ok = reprojection_error_px(&reference_pose, x, p.1, focal) < 2.0
                && reprojection_error_px(&relative, x, p.2, focal) < 2.0;
            let parallax = parallax_rad(&reference_pose, p.1, &relative, p.2).to_degrees();
            if ok && parallax >= 0.25 * self.config.min_parallax_deg {
                good.push((k, x));
                parallaxes.push(parallax);
            }
        }
        let num_inliers = inliers.iter().filter(|&&b| b).count();
        let median_parallax = median(parallaxes.clone());
        if good.len() < self.config.init_min_points
            || median_parallax < self.config.init_min_parallax_deg
        {
            return Ok(None);
        }
        // Homography-versus-essential model selection: a homography explaining nearly all
        // essential inliers means rotation or a plane seen without enough depth spread.
        let homography = self
            .vision
            .homography_inliers(&self.camera, &first, &second, 1.0)?;
        if homography as f64 > 0.95 * num_inliers as f64
            && median_parallax < 2.0 * self.config.init_min_parallax_deg
        {
            return Ok(None);
        }
        // Normalise: median depth 1 in the reference camera.
        let scale = 1.0 / median(good.iter().map(|g| g.1.z).collect()).max(1e-9);
        let current_pose = Se3::new(relative.rotation, relative.translation * scale);
        self.map = crate::map::Map::default();
        let kf0 = self.map.add_keyframe(init.frame_index, reference_pose);
        let kf1 = self.map.add_keyframe(frame.index, current_pose);
        self.tracks.clear();
        for &(k, x) in &good {
            let (i, n0, n1) = pairs[k];
            let obs = |keyframe, pixel: Vec2, normalized| Observation {
                keyframe,
                pixel,
                normalized,
            };
            let pixel1 = init.current[i].unwrap_or(init.reference[i]);
            let id = self.map.add_point(
                x * scale,
                vec![obs(kf0, init.reference[i], n0), obs(kf1, pixel1, n1)],
            );
            self.tracks.push(Track {
                pixel: pixel1,
                point: Some(id),
                origin: None,
            });
        }
        let mut pose = self.initial_bundle_adjustment();
        if let Some(kf) = self.map.keyframes.get(kf1) {
            pose = kf.camera_from_world;
        }
        self.frames_since_keyframe = 0;
        self.tracked_at_keyframe = self.tracks.len();
        self.set_world_frame(&pose);
        self.add_late_poses(init, &pairs.iter().map(|p| p.0).collect::<Vec<_>>());
        self.add_candidates(frame, kf1)?;
        self.describe_keyframe_points(kf1, &frame.image);
        Ok(Some(pose))
    }

    /// Bundle adjustment of the two initial keyframes (the first fixed); returns nothing but
    /// updates the map.
    fn initial_bundle_adjustment(&mut self) -> Se3 {
        let ids: Vec<u64> = self.map.points.keys().copied().collect();
        let mut poses: Vec<Se3> = self
            .map
            .keyframes
            .iter()
            .map(|k| k.camera_from_world)
            .collect();
        let mut points: Vec<DVec3> = ids.iter().map(|id| self.map.points[id].position).collect();
        let observations: Vec<BaObservation> = ids
            .iter()
            .enumerate()
            .flat_map(|(p, id)| {
                self.map.points[id]
                    .observations
                    .iter()
                    .map(move |o| BaObservation {
                        camera: o.keyframe,
                        point: p,
                        normalized: o.normalized,
                    })
            })
            .collect();
        bundle_adjust(
            &mut poses,
            &[true, false],
            &mut points,
            &observations,
            &self.ba_config(15),
        );
        // Keep the unit: the baseline stays 1 after adjustment.
        let baseline = poses[1].inverse().translation.length().max(1e-9);
        let unit = poses_baseline_before(&self.map) / baseline;
        poses[1].translation *= unit;
        for (id, x) in ids.iter().zip(&points) {
            if let Some(p) = self.map.points.get_mut(id) {
                p.position = *x * unit;
            }
        }
        for (kf, pose) in self.map.keyframes.iter_mut().zip(&poses) {
            kf.camera_from_world = *pose;
        }
        poses[1]
    }

    fn set_world_frame(&mut self, camera_from_map: &Se3) {
        let points: Vec<DVec3> = self.map.points.values().map(|p| p.position).collect();
        let center = camera_from_map.inverse().translation;
        // Gravity "up" is measured in the current camera; rotate it into the map.
        let up = self
            .gravity_up
            .map(|u| camera_from_map.rotation.inverse() * u);
        self.world = WorldFrame::from_points(&points, center, up, self.config.holding_height_m);
    }

    /// Poses of the frames seen while initialising, by motion-only refinement on the new map.
    fn add_late_poses(&mut self, init: &Initializer, _pair_indices: &[usize]) {
        let by_reference: Vec<Option<DVec3>> = {
            let mut v = vec![None; init.reference.len()];
            for p in self.map.points.values() {
                if let Some(o) = p.observations.iter().find(|o| o.keyframe == 0)
                    && let Some(i) = init.reference.iter().position(|r| *r == o.pixel)
                {
                    v[i] = Some(p.position);
                }
            }
            v
        };
        let mut pose = Se3::IDENTITY;
        let mut late = vec![LatePose {
            index: init.frame_index,
            world_from_camera: self.world_from_camera(&Se3::IDENTITY),
        }];
        for (index, pixels) in init
            .history
            .iter()
            .take(init.history.len().saturating_sub(1))
        {
            let (world, image): (Vec<DVec3>, Vec<DVec2>) = pixels
                .iter()
                .zip(&by_reference)
                .filter_map(|(px, x)| {
                    Some((x.as_ref().copied()?, normalized(&self.camera, (*px)?)))
                })
                .unzip();
            if world.len() < self.config.min_pose_inliers {
                continue;
            }
            pose = refine_pose(pose, &world, &image, &self.ba_config(10));
            late.push(LatePose {
                index: *index,
                world_from_camera: self.world_from_camera(&pose),
            });
        }
        self.late_poses.extend(late);
    }
}

fn poses_baseline_before(map: &crate::map::Map) -> f64 {
    map.keyframes.get(1).map_or(1.0, |k| k.center().length())
}

pub(crate) fn median(mut values: Vec<f64>) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}
