//! The sparse map: keyframes with their poses and observations, and 3D map points.

use crate::pose::Se3;
use glam::{DVec2, DVec3, Vec2};
use std::collections::BTreeMap;

/// A 256-bit binary descriptor (ORB), used for relocalisation.
pub type Descriptor = [u8; 32];

/// One sighting of a map point in a keyframe.
#[derive(Clone, Copy, Debug)]
pub struct Observation {
    pub keyframe: usize,
    /// Raw image pixel.
    pub pixel: Vec2,
    /// Normalised undistorted coordinates.
    pub normalized: DVec2,
}

/// A triangulated 3D point.
#[derive(Clone, Debug)]
pub struct MapPoint {
    pub id: u64,
    pub position: DVec3,
    pub observations: Vec<Observation>,
    pub descriptor: Option<Descriptor>,
}

impl MapPoint {
    /// The observation in the latest keyframe.
    pub fn latest_observation(&self) -> Option<&Observation> {
        self.observations.iter().max_by_key(|o| o.keyframe)
    }
}

/// A frame kept for mapping: its pose and the map points it sees.
#[derive(Clone, Debug)]
pub struct Keyframe {
    pub id: usize,
    pub frame_index: usize,
    pub camera_from_world: Se3,
    pub points: Vec<u64>,
}

impl Keyframe {
    pub fn center(&self) -> DVec3 {
        self.camera_from_world.inverse().translation
    }
}

/// Keyframes (ids are their index) and map points by id.
#[derive(Clone, Debug, Default)]
pub struct Map {
    pub keyframes: Vec<Keyframe>,
    pub points: BTreeMap<u64, MapPoint>,
    next_point_id: u64,
}

impl Map {
    /// Adds a keyframe and returns its id.
    pub fn add_keyframe(&mut self, frame_index: usize, camera_from_world: Se3) -> usize {
        let id = self.keyframes.len();
        self.keyframes.push(Keyframe {
            id,
            frame_index,
            camera_from_world,
            points: Vec::new(),
        });
        id
    }

    /// Adds a point with its observations (keyframes must exist) and returns its id.
    pub fn add_point(&mut self, position: DVec3, observations: Vec<Observation>) -> u64 {
        let id = self.next_point_id;
        self.next_point_id += 1;
        for o in &observations {
            if let Some(kf) = self.keyframes.get_mut(o.keyframe) {
                kf.points.push(id);
            }
        }
        self.points.insert(
            id,
            MapPoint {
                id,
                position,
                observations,
                descriptor: None,
            },
        );
        id
    }

    /// Records that keyframe `keyframe` sees point `id`.
    pub fn add_observation(&mut self, id: u64, observation: Observation) {
        if let Some(point) = self.points.get_mut(&id)
            && !point
                .observations
                .iter()
                .any(|o| o.keyframe == observation.keyframe)
        {
            point.observations.push(observation);
            if let Some(kf) = self.keyframes.get_mut(observation.keyframe) {
                kf.points.push(id);
            }
        }
    }

    /// Removes a point and its references from keyframes.
    pub fn remove_point(&mut self, id: u64) {
        if let Some(point) = self.points.remove(&id) {
            for o in point.observations {
                if let Some(kf) = self.keyframes.get_mut(o.keyframe) {
                    kf.points.retain(|&p| p != id);
                }
            }
        }
    }

    /// Removes one observation; the point goes when fewer than two remain.
    pub fn remove_observation(&mut self, id: u64, keyframe: usize) {
        let Some(point) = self.points.get_mut(&id) else {
            return;
        };
        point.observations.retain(|o| o.keyframe != keyframe);
        if let Some(kf) = self.keyframes.get_mut(keyframe) {
            kf.points.retain(|&p| p != id);
        }
        if point.observations.len() < 2 {
            self.remove_point(id);
        }
    }

    /// Ids of the points seen by the given keyframes, without repeats.
    pub fn points_of(&self, keyframes: &[usize]) -> Vec<u64> {
        let mut ids: Vec<u64> = keyframes
            .iter()
            .filter_map(|&k| self.keyframes.get(k))
            .flat_map(|kf| kf.points.iter().copied())
            .collect();
        ids.sort_unstable();
        ids.dedup();
        ids
    }
}
