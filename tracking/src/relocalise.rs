//! Relocalisation once tracking is lost: ORB descriptors of this frame matched to the map
//! points' descriptors, then PnP-RANSAC. On blurred footage descriptor matches are few and
//! noisy (nearest Hamming distances around 55 of 256 bits on fr1_rpy), so they also vote for
//! the keyframes this view resembles, and the points of the best-voted keyframes whose
//! pyramids are kept are followed into the frame by pyramidal Lucas–Kanade from the
//! keyframe's image: many more correspondences, sub-pixel, where the view is near a keyframe's.

use crate::ba::refine_pose;
use crate::features::{Track, normalized};
use crate::frame::{Frame, TrackingState};
use crate::lk::{self, Pyramid};
use crate::pose::Se3;
use crate::tracker::{Tracker, TrackerError};
use crate::vision;
use glam::{DVec2, DVec3, Vec2};
use std::collections::BTreeMap;

/// Descriptor matches accepted: Hamming distance at most this, and Lowe's ratio.
const MAX_HAMMING: u32 = 50;
const RATIO: f64 = 0.8;
/// Keyframes (with kept pyramids) whose points Lucas–Kanade follows into the lost frame.
const CANDIDATE_KEYFRAMES: usize = 2;
/// Fewest descriptor votes for a keyframe to be a candidate.
const MIN_VOTES: usize = 3;
/// Fewest PnP inliers to accept a relocalised pose.
const MIN_INLIERS: usize = 25;
/// RANSAC reprojection threshold, pixels, and hypotheses.
const THRESHOLD_PX: f32 = 4.0;
const HYPOTHESES: i32 = 1000;

/// 2D–3D correspondences: map point id, position, pixel in this frame.
type Correspondences = Vec<(u64, DVec3, Vec2)>;

impl Tracker {
    /// The pose of `frame` found from the map alone, with the tracks it rests on; None when
    /// no hypothesis gathers enough inliers.
    pub(crate) fn relocalise(
        &mut self,
        frame: &Frame,
        pyramid: &Pyramid,
    ) -> Result<Option<Se3>, TrackerError> {
        let described: Vec<(u64, DVec3, crate::map::Descriptor)> = self
            .map
            .points
            .values()
            .filter_map(|p| Some((p.id, p.position, p.descriptor?)))
            .collect();
        if described.len() < 30 {
            return Ok(None);
        }
        let features = self.vision.describe_corners(&frame.image, 1000, 7.0)?;
        let mut matches: Correspondences = Vec::new();
        for (pixel, descriptor) in &features {
            let mut nearest = vision::NearestTwo::default();
            for (k, (_, _, d)) in described.iter().enumerate() {
                nearest.offer(vision::hamming(descriptor, d), k);
            }
            if let Some((k, _)) = nearest.accepted(MAX_HAMMING, RATIO) {
                matches.push((described[k].0, described[k].1, *pixel));
            }
        }
        // Lucas–Kanade from the keyframes the matches point at, each solved on its own; the
        // descriptor matches themselves are the last resort.
        let mut best: Option<(Se3, Vec<usize>, Correspondences)> = None;
        let mut attempts: Vec<Correspondences> = self
            .candidate_keyframes(&matches)
            .into_iter()
            .map(|kf| self.follow_keyframe_points(kf, pyramid))
            .collect();
        attempts.push(matches);
        for correspondences in attempts {
            if correspondences.len() < MIN_INLIERS {
                continue;
            }
            let Some((pose, inliers)) = self.pnp(&correspondences)? else {
                continue;
            };
            if inliers.len() >= MIN_INLIERS
                && best.as_ref().is_none_or(|b| inliers.len() > b.1.len())
            {
                best = Some((pose, inliers, correspondences));
            }
        }
        let Some((pose, inliers, correspondences)) = best else {
            return Ok(None);
        };
        let (w, n): (Vec<DVec3>, Vec<DVec2>) = inliers
            .iter()
            .map(|&k| {
                let c = &correspondences[k];
                (c.1, normalized(&self.camera, c.2))
            })
            .unzip();
        let pose = refine_pose(pose, &w, &n, &self.ba_config(10));
        self.tracks = inliers
            .iter()
            .map(|&k| Track {
                pixel: correspondences[k].2,
                point: Some(correspondences[k].0),
                origin: None,
            })
            .collect();
        self.prev_pose = None;
        Ok(Some(pose))
    }

    /// Keyframes with kept pyramids that see the most matched points, best first (ties to the
    /// newest).
    fn candidate_keyframes(&self, matches: &Correspondences) -> Vec<usize> {
        let mut votes: BTreeMap<usize, usize> = BTreeMap::new();
        for (id, _, _) in matches {
            let Some(point) = self.map.points.get(id) else {
                continue;
            };
            for o in &point.observations {
                if self.keyframe_pyramids.contains_key(&o.keyframe) {
                    *votes.entry(o.keyframe).or_default() += 1;
                }
            }
        }
        let mut ranked: Vec<(usize, usize)> =
            votes.into_iter().filter(|(_, v)| *v >= MIN_VOTES).collect();
        ranked.sort_by_key(|&(kf, v)| std::cmp::Reverse((v, kf)));
        ranked
            .into_iter()
            .take(CANDIDATE_KEYFRAMES)
            .map(|(kf, _)| kf)
            .collect()
    }

    /// The points keyframe `kf` sees, followed from its image into this frame by Lucas–Kanade
    /// over the full pyramid (seeded where they were, checked forward-backward).
    fn follow_keyframe_points(&self, kf: usize, pyramid: &Pyramid) -> Correspondences {
        let (Some(keyframe), Some(kf_pyramid)) =
            (self.map.keyframes.get(kf), self.keyframe_pyramids.get(&kf))
        else {
            return Vec::new();
        };
        let seen: Vec<(u64, DVec3, Vec2)> = keyframe
            .points
            .iter()
            .filter_map(|id| {
                let point = self.map.points.get(id)?;
                let obs = point.observations.iter().find(|o| o.keyframe == kf)?;
                Some((*id, point.position, obs.pixel))
            })
            .collect();
        let from: Vec<Vec2> = seen.iter().map(|s| s.2).collect();
        let found = lk::track_points(
            kf_pyramid,
            pyramid,
            &from,
            None,
            lk::LkOptions {
                levels: self.config.lk_levels,
                max_fb_error_px: Some(self.config.max_fb_error_px),
            },
        );
        seen.into_iter()
            .zip(found)
            .filter_map(|((id, position, _), pixel)| {
                let pixel = pixel.filter(|p| self.camera.contains(p.as_dvec2(), 2.0))?;
                Some((id, position, pixel))
            })
            .collect()
    }

    /// PnP-RANSAC on correspondences: the pose and the inlier indices.
    fn pnp(
        &self,
        correspondences: &Correspondences,
    ) -> Result<Option<(Se3, Vec<usize>)>, TrackerError> {
        let world: Vec<DVec3> = correspondences.iter().map(|c| c.1).collect();
        let image: Vec<DVec2> = correspondences
            .iter()
            .map(|c| normalized(&self.camera, c.2))
            .collect();
        // Once lost, this runs on every frame until it succeeds: the four-point solver keeps
        // each attempt cheap (and needs fewer hypotheses at a given inlier ratio).
        let minimal = match self.state {
            TrackingState::RecentlyLost | TrackingState::Lost => vision::PnpMinimal::Ap3p,
            _ => vision::PnpMinimal::Epnp,
        };
        self.vision.pnp_ransac(
            &self.camera,
            &world,
            &image,
            None,
            THRESHOLD_PX,
            HYPOTHESES,
            minimal,
        )
    }
}
