//! Local mapping inside the tracker: keyframe decision and insertion, triangulation of candidate
//! tracks, the local map searched in every frame by reprojection + Lucas–Kanade from the
//! keyframe that saw each point, and local bundle adjustment over recent keyframes.

use crate::ba::{BaObservation, bundle_adjust, reprojection_error_px};
use crate::features::{Track, TrackOrigin, parallax_rad, triangulate};
use crate::frame::{Frame, GrayImage};
use crate::lk::{self, Pyramid};
use crate::map::Observation;
use crate::pose::Se3;
use crate::tracker::{Tracker, TrackerError};
use glam::{DVec3, Vec2};
use std::collections::{BTreeMap, HashMap, HashSet};

/// Median depth of the map points a keyframe sees, in its camera (0 when it sees none).
fn median_depth(map: &crate::map::Map, keyframe: usize) -> f64 {
    let Some(kf) = map.keyframes.get(keyframe) else {
        return 0.0;
    };
    crate::initializer::median(
        kf.points
            .iter()
            .filter_map(|id| map.points.get(id))
            .map(|p| kf.camera_from_world.transform_point(p.position).z)
            .filter(|z| *z > 0.0)
            .collect(),
    )
}

/// A map point found by the local-map search must lie this close to its projection, pixels.
const SEARCH_GATE_PX: f32 = 6.0;

/// Keyframe pyramids kept for the local-map search.
const MAX_KEYFRAME_PYRAMIDS: usize = 40;

impl Tracker {
    pub(crate) fn needs_keyframe(&self) -> bool {
        let tracked = self.tracks.iter().filter(|t| t.point.is_some()).count();
        self.frames_since_keyframe >= self.config.max_keyframe_gap
            || (self.frames_since_keyframe >= 2
                && (tracked as f64) < 0.8 * self.tracked_at_keyframe as f64)
            || (self.frames_since_keyframe >= 1 && tracked < 60)
    }

    /// Makes the current frame a keyframe: observations, new points, new corners, bundle
    /// adjustment. The frame's pose may move with the adjustment.
    pub(crate) fn insert_keyframe(&mut self, frame: &Frame, pose: Se3) -> Result<(), TrackerError> {
        if self.config.adopt_map_points {
            self.adopt_map_points(&frame.image, &pose)?;
        }
        let kf = self.map.add_keyframe(frame.index, pose);
        let shutter = self.shutter();
        for track in &self.tracks {
            if let Some(id) = track.point {
                self.map.add_observation(
                    id,
                    Observation {
                        keyframe: kf,
                        pixel: track.pixel,
                        normalized: shutter.normalized(&self.camera, track.pixel),
                    },
                );
            }
        }
        self.triangulate_candidates(kf, &pose);
        self.local_bundle_adjustment(kf);
        self.add_candidates(frame, kf)?;
        self.describe_keyframe_points(kf, &frame.image);
        if let Some(pyramid) = &self.prev_pyramid {
            self.keyframe_pyramids.insert(kf, pyramid.clone());
        }
        if self.keyframe_pyramids.len() > MAX_KEYFRAME_PYRAMIDS {
            let oldest = self.keyframe_pyramids.keys().copied().min();
            if let Some(old) = oldest.and_then(|k| self.keyframe_pyramids.remove(&k)) {
                old.recycle(&mut self.pyramid_scratch);
            }
        }
        if let Some(pose) = self.map.keyframes.get(kf).map(|k| k.camera_from_world) {
            self.prev_pose = Some(pose);
        }
        if let Some(world) = self.world.as_mut() {
            let points: Vec<DVec3> = self.map.points.values().map(|p| p.position).collect();
            world.refine(&points);
        }
        self.frames_since_keyframe = 0;
        self.tracked_at_keyframe = self.tracks.iter().filter(|t| t.point.is_some()).count();
        Ok(())
    }

    /// Adds this frame's evidence (its tracked map points) to the rolling-shutter readout
    /// estimate.
    pub(crate) fn estimate_readout(&mut self, pose: &Se3) {
        let observations: Vec<(DVec3, Vec2)> = self
            .tracks
            .iter()
            .filter_map(|t| Some((self.map.points.get(&t.point?)?.position, t.pixel)))
            .collect();
        let rate = self.shutter().rate;
        let config = self.ba_config(5);
        self.readout
            .observe(&self.camera, pose, rate, &observations, &config);
    }

    /// Candidates with enough parallax since their origin keyframe become map points.
    fn triangulate_candidates(&mut self, kf: usize, pose: &Se3) {
        let focal = self.camera.focal();
        let min_parallax = self.config.min_parallax_deg.to_radians();
        let min_baseline = self.config.min_baseline_ratio;
        let center = pose.inverse().translation;
        // Whether each origin keyframe is far enough from this one, judged on the baseline over
        // its median scene depth: the same test for all its candidates, so the points that get
        // triangulated are not those whose noise happened to inflate their parallax (choosing
        // per point at the first threshold crossing makes every new point too near, and the map
        // shrinks keyframe after keyframe).
        let shutter = self.shutter();
        let mut ready: HashMap<usize, bool> = HashMap::new();
        let mut dropped = Vec::new();
        for (i, track) in self.tracks.iter_mut().enumerate() {
            let Some(origin) = track.origin else { continue };
            let Some(origin_kf) = self.map.keyframes.get(origin.keyframe) else {
                continue;
            };
            let origin_pose = origin_kf.camera_from_world;
            let n = shutter.normalized(&self.camera, track.pixel);
            if min_baseline > 0.0 {
                let is_ready = *ready.entry(origin.keyframe).or_insert_with(|| {
                    let depth = median_depth(&self.map, origin.keyframe);
                    depth > 0.0 && origin_kf.center().distance(center) >= min_baseline * depth
                });
                if !is_ready {
                    continue;
                }
            }
            if parallax_rad(&origin_pose, origin.normalized, pose, n) < min_parallax {
                if min_baseline > 0.0 {
                    dropped.push(i);
                }
                continue;
            }
            let point = triangulate(&origin_pose, origin.normalized, pose, n).filter(|x| {
                reprojection_error_px(&origin_pose, *x, origin.normalized, focal) < 2.0
                    && reprojection_error_px(pose, *x, n, focal) < 2.0
            });
            match point {
                Some(x) => {
                    let observations = vec![
                        Observation {
                            keyframe: origin.keyframe,
                            pixel: origin.pixel,
                            normalized: origin.normalized,
                        },
                        Observation {
                            keyframe: kf,
                            pixel: track.pixel,
                            normalized: n,
                        },
                    ];
                    track.point = Some(self.map.add_point(x, observations));
                    track.origin = None;
                }
                None => dropped.push(i),
            }
        }
        for i in dropped.into_iter().rev() {
            self.tracks.swap_remove(i);
        }
    }

    /// New corners away from the live tracks, born as candidates in keyframe `kf`.
    pub(crate) fn add_candidates(&mut self, frame: &Frame, kf: usize) -> Result<(), TrackerError> {
        let wanted = self.config.max_tracks.saturating_sub(self.tracks.len());
        if wanted < 20 {
            return Ok(());
        }
        let existing: Vec<Vec2> = self.tracks.iter().map(|t| t.pixel).collect();
        let corners = self.vision.detect_corners(
            &frame.image,
            wanted,
            self.config.min_corner_distance_px,
            &existing,
        )?;
        let shutter = self.shutter();
        for pixel in corners {
            self.tracks.push(Track {
                pixel,
                point: None,
                origin: Some(TrackOrigin {
                    keyframe: kf,
                    pixel,
                    normalized: shutter.normalized(&self.camera, pixel),
                }),
            });
        }
        Ok(())
    }

    /// ORB descriptors of the points seen in keyframe `kf`, for relocalisation.
    pub(crate) fn describe_keyframe_points(&mut self, kf: usize, image: &GrayImage) {
        let Some(keyframe) = self.map.keyframes.get(kf) else {
            return;
        };
        let seen: Vec<(u64, Vec2)> = keyframe
            .points
            .iter()
            .filter_map(|id| {
                let p = self.map.points.get(id)?;
                Some((*id, p.observations.iter().find(|o| o.keyframe == kf)?.pixel))
            })
            .collect();
        let pixels: Vec<Vec2> = seen.iter().map(|s| s.1).collect();
        // Descriptors only help relocalisation; failing to compute them is not a tracking error.
        let Ok(descriptors) = self.vision.describe(image, &pixels) else {
            return;
        };
        for ((id, _), d) in seen.iter().zip(descriptors) {
            if let (Some(p), Some(d)) = (self.map.points.get_mut(id), d) {
                p.descriptor = Some(d);
            }
        }
    }

    /// Map points not tracked now but in view are searched by Lucas–Kanade from the latest
    /// keyframe that saw them, seeded at their projection.
    pub(crate) fn search_local_map(
        &mut self,
        pyramid: &Pyramid,
        pose: &Se3,
    ) -> Result<(), TrackerError> {
        let tracked: HashSet<u64> = self.tracks.iter().filter_map(|t| t.point).collect();
        let center = pose.inverse().translation;
        // Centres of the keyframes whose pyramids are kept (None for the others), by id.
        let mut searchable: Vec<Option<DVec3>> = vec![None; self.map.keyframes.len()];
        for &k in self.keyframe_pyramids.keys() {
            if let Some(kf) = self.map.keyframes.get(k) {
                searchable[k] = Some(kf.center());
            }
        }
        let shutter = self.shutter();
        let mut wanted: Vec<(usize, u64, Vec2, Vec2)> = Vec::new();
        // Cheapest tests first: most map points were last seen by keyframes without a pyramid.
        for point in self.map.points.values() {
            if tracked.contains(&point.id) {
                continue;
            }
            let Some((obs, kf_center)) = point
                .observations
                .iter()
                .filter_map(|o| Some((o, searchable.get(o.keyframe).copied().flatten()?)))
                .max_by_key(|(o, _)| o.keyframe)
            else {
                continue;
            };
            // Skip views too different from the keyframe's (LK would not match them).
            let angle = (point.position - kf_center).angle_between(point.position - center);
            if angle.to_degrees() > 20.0 {
                continue;
            }
            let Some(projected) = self.project(&shutter, pose, point.position) else {
                continue;
            };
            wanted.push((obs.keyframe, point.id, obs.pixel, projected));
        }
        wanted.sort_by_key(|w| std::cmp::Reverse(w.0));
        wanted.truncate(self.config.max_local_search);
        // Ordered by keyframe: tracks must come out in the same order on every run.
        let mut by_keyframe: BTreeMap<usize, Vec<(u64, Vec2, Vec2)>> = BTreeMap::new();
        for (kf, id, from, guess) in wanted {
            by_keyframe.entry(kf).or_default().push((id, from, guess));
        }
        for (kf, list) in by_keyframe {
            let Some(kf_pyramid) = self.keyframe_pyramids.get(&kf) else {
                continue;
            };
            let from: Vec<Vec2> = list.iter().map(|l| l.1).collect();
            let guess: Vec<Vec2> = list.iter().map(|l| l.2).collect();
            let found = lk::track_points_near_guess(
                kf_pyramid,
                pyramid,
                &from,
                &guess,
                SEARCH_GATE_PX,
                lk::LkOptions {
                    levels: self.config.search_lk_levels,
                    max_fb_error_px: self
                        .config
                        .search_fb_check
                        .then_some(self.config.max_fb_error_px),
                },
            );
            for ((id, _, _), pixel) in list.into_iter().zip(found) {
                if let Some(pixel) = pixel {
                    self.tracks.push(Track {
                        pixel,
                        point: Some(id),
                        origin: None,
                    });
                }
            }
        }
        Ok(())
    }

    /// Bundle adjustment of the last keyframes and their points; keyframes outside the window
    /// that see those points stay fixed (at least two fixed, so the scale holds).
    fn local_bundle_adjustment(&mut self, newest: usize) {
        let first = (newest + 1).saturating_sub(self.config.local_window);
        let window: Vec<usize> = (first..=newest).collect();
        let ids = self.map.points_of(&window);
        let mut cameras: Vec<usize> = window.clone();
        let mut outside: Vec<usize> = ids
            .iter()
            .flat_map(|id| self.map.points[id].observations.iter().map(|o| o.keyframe))
            .filter(|k| *k < first)
            .collect();
        outside.sort_unstable();
        outside.dedup();
        let outside: Vec<usize> = outside.into_iter().rev().take(10).collect();
        cameras.extend(&outside);
        let slot: HashMap<usize, usize> =
            cameras.iter().enumerate().map(|(i, &k)| (k, i)).collect();
        let mut fixed: Vec<bool> = cameras.iter().map(|k| *k < first || *k == 0).collect();
        let mut need = 2usize.saturating_sub(fixed.iter().filter(|&&f| f).count());
        for f in fixed.iter_mut().take(window.len()) {
            if need == 0 {
                break;
            }
            if !*f {
                *f = true;
                need -= 1;
            }
        }
        let mut poses: Vec<Se3> = cameras
            .iter()
            .map(|&k| self.map.keyframes[k].camera_from_world)
            .collect();
        let mut points: Vec<DVec3> = ids.iter().map(|id| self.map.points[id].position).collect();
        let mut observations = Vec::new();
        for (p, id) in ids.iter().enumerate() {
            for o in &self.map.points[id].observations {
                if let Some(&camera) = slot.get(&o.keyframe) {
                    observations.push(BaObservation {
                        camera,
                        point: p,
                        normalized: o.normalized,
                    });
                }
            }
        }
        bundle_adjust(
            &mut poses,
            &fixed,
            &mut points,
            &observations,
            &self.ba_config(8),
        );
        for (&k, pose) in cameras.iter().zip(&poses) {
            self.map.keyframes[k].camera_from_world = *pose;
        }
        for (id, x) in ids.iter().zip(&points) {
            if let Some(p) = self.map.points.get_mut(id) {
                p.position = *x;
            }
        }
        self.remove_bad_observations(&ids);
    }

    /// Observations the adjusted map no longer explains are dropped (and their tracks).
    fn remove_bad_observations(&mut self, ids: &[u64]) {
        let focal = self.camera.focal();
        let limit = 2.0 * self.config.outlier_px;
        let mut bad: Vec<(u64, usize)> = Vec::new();
        for id in ids {
            let Some(point) = self.map.points.get(id) else {
                continue;
            };
            for o in &point.observations {
                let pose = self.map.keyframes[o.keyframe].camera_from_world;
                if reprojection_error_px(&pose, point.position, o.normalized, focal) > limit {
                    bad.push((*id, o.keyframe));
                }
            }
        }
        for (id, kf) in bad {
            self.map.remove_observation(id, kf);
        }
        let points = &self.map.points;
        self.tracks
            .retain(|t| t.point.is_none_or(|id| points.contains_key(&id)));
    }
}
