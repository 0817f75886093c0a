//! Re-finding old map points at keyframes. A candidate corner that is in fact an existing map
//! point (the camera came back to a part of the scene it mapped before) is attached to that point
//! instead of being triangulated again: the point gains an observation that ties the new keyframe
//! to the old ones in bundle adjustment, and no duplicate is made at a drifted scale.
//!
//! Matching: map points not tracked now are projected through the keyframe's pose; a candidate
//! takes the point projecting within `TrackerConfig::adopt_radius_px` whose ORB descriptor is nearest, when
//! that distance is small and clearly better than the next nearest (ratio test).

use crate::map::Descriptor;
use crate::pose::Se3;
use crate::tracker::{Tracker, TrackerError};
use glam::Vec2;
use std::collections::{BTreeMap, HashMap, HashSet};

/// Largest Hamming distance (of 256 bits) for a match.
const MAX_HAMMING: u32 = 40;
/// The best match must beat the second best by this ratio.
const RATIO: f64 = 0.8;
/// A map point's id, projection and descriptor.
type Projected = (u64, Vec2, Descriptor);

/// Grid cell for the projected points, pixels.
const CELL_PX: f32 = 16.0;

impl Tracker {
    /// Attaches candidate tracks of the current keyframe image to map points they re-find.
    /// Returns how many were attached.
    pub(crate) fn adopt_map_points(
        &mut self,
        image: &crate::frame::GrayImage,
        pose: &Se3,
    ) -> Result<usize, TrackerError> {
        let candidates: Vec<usize> = (0..self.tracks.len())
            .filter(|&i| self.tracks[i].origin.is_some())
            .collect();
        if candidates.is_empty() {
            return Ok(0);
        }
        let tracked: HashSet<u64> = self.tracks.iter().filter_map(|t| t.point).collect();
        // Projections of the described map points not tracked now, bucketed by grid cell.
        let mut grid: HashMap<(i32, i32), Vec<Projected>> = HashMap::new();
        let shutter = self.shutter();
        for point in self.map.points.values() {
            let Some(descriptor) = point.descriptor else {
                continue;
            };
            if tracked.contains(&point.id) {
                continue;
            }
            if let Some(pixel) = self.project(&shutter, pose, point.position) {
                grid.entry(cell(pixel))
                    .or_default()
                    .push((point.id, pixel, descriptor));
            }
        }
        if grid.is_empty() {
            return Ok(0);
        }
        let pixels: Vec<Vec2> = candidates.iter().map(|&i| self.tracks[i].pixel).collect();
        let described = match self.vision.describe(image, &pixels) {
            Ok(d) => d,
            Err(_) => return Ok(0),
        };
        // Best candidate per map point (ordered, so runs repeat exactly).
        let mut best_for_point: BTreeMap<u64, (u32, usize)> = BTreeMap::new();
        for (&track_index, (pixel, descriptor)) in
            candidates.iter().zip(pixels.iter().zip(described))
        {
            let Some(descriptor) = descriptor else {
                continue;
            };
            let mut nearest = crate::vision::NearestTwo::default();
            let (cx, cy) = cell(*pixel);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let Some(list) = grid.get(&(cx + dx, cy + dy)) else {
                        continue;
                    };
                    for (id, projected, d) in list {
                        if projected.distance(*pixel) <= self.config.adopt_radius_px {
                            nearest.offer(crate::vision::hamming(&descriptor, d), *id);
                        }
                    }
                }
            }
            let Some((id, best)) = nearest.accepted(MAX_HAMMING, RATIO) else {
                continue;
            };
            let entry = best_for_point.entry(id).or_insert((best, track_index));
            if best < entry.0 {
                *entry = (best, track_index);
            }
        }
        for (&id, &(_, track_index)) in &best_for_point {
            let track = &mut self.tracks[track_index];
            track.point = Some(id);
            track.origin = None;
        }
        Ok(best_for_point.len())
    }
}

fn cell(pixel: Vec2) -> (i32, i32) {
    (
        (pixel.x / CELL_PX).floor() as i32,
        (pixel.y / CELL_PX).floor() as i32,
    )
}
