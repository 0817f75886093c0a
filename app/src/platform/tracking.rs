//! A platform tracker's frame as the app's scene: the pose as it is, the ground from the
//! platform's planes (or, without any, fitted to its feature points), and the feature points
//! projected into the image as the depth mesh's observations, exactly as Sylva's own tracker's
//! map points are ([`observations_of`] is shared by both), so the depth mesh, the occupancy and
//! sessions cannot tell the trackers apart.

use glam::{DVec3, Mat4, Vec2, Vec3};
use sylva_tracking::depth_mesh::Observation;
use sylva_tracking::ground_plane::{OrientedPlaneEstimator, RansacConfig, ransac};

use super::{FeaturePoint, PlatformPlane, PlatformTracking};
use crate::render::{GroundPlane, Intrinsics};
use crate::scene_tracking::{SceneFrame, SceneMesher};

/// A plane whose normal is within this angle of the world's up counts as horizontal ground.
pub const GROUND_MAX_TILT_DEG: f32 = 10.0;
/// The ground lies at least this far below the camera (a phone is held above it), metres.
const MIN_GROUND_DEPTH_BELOW_CAMERA_M: f32 = 0.3;
/// Fewest feature points on a ground fitted to points.
const MIN_GROUND_POINTS: usize = 30;

/// Map points seen from `world_from_camera` as depth-mesh observations: the ideal pixel of each
/// point in front of the camera and its depth along the optical axis, rounded to 0.01 px and
/// 1 mm (far below tracking noise) so sessions record them compactly and replays mesh exactly
/// what the app meshed.
pub fn observations_of(
    world_from_camera: Mat4,
    points_in_world: impl IntoIterator<Item = (u64, Vec3)>,
    k: &Intrinsics,
) -> Vec<Observation> {
    let camera_from_world = world_from_camera.inverse();
    let round = |x: f32, step: f32| (x / step).round() * step;
    points_in_world
        .into_iter()
        .filter_map(|(id, point_in_world)| {
            let c = camera_from_world.transform_point3(point_in_world);
            (c.z > 1e-3 && c.is_finite()).then(|| Observation {
                id,
                pixel: Vec2::new(
                    round(k.fx * c.x / c.z + k.cx, 0.01),
                    round(k.fy * c.y / c.z + k.cy, 0.01),
                ),
                depth_m: round(c.z, 0.001),
            })
        })
        .collect()
}

/// The scene of a posed frame: its observations meshed into the occluder (both trackers).
pub(crate) fn posed_scene(
    mesher: &mut SceneMesher,
    world_from_camera: Mat4,
    observations: Vec<Observation>,
    ground: Option<GroundPlane>,
) -> SceneFrame {
    let occluder = mesher.update(&observations, world_from_camera, ground);
    SceneFrame {
        world_from_camera: Some(world_from_camera),
        ground,
        observations,
        occluder,
        tracking_ms: 0.0,
    }
}

/// Turns a platform tracker's frames into scenes: the occluder from the depth mesh of its
/// feature points, the ground from the plane it chose.
pub struct PlatformTracker {
    intrinsics: Intrinsics,
    mesher: SceneMesher,
    /// The platform plane taken as the ground (followed as the platform refines it), or the
    /// plane fitted to the points (kept once found).
    ground: Option<(Option<u64>, GroundPlane)>,
}

impl PlatformTracker {
    pub fn new(intrinsics: Intrinsics) -> PlatformTracker {
        PlatformTracker {
            mesher: SceneMesher::new(&intrinsics),
            intrinsics,
            ground: None,
        }
    }

    /// The scene of one frame's platform tracking.
    pub fn track(&mut self, tracking: &PlatformTracking) -> SceneFrame {
        let started = std::time::Instant::now();
        let pose = tracking.world_from_camera.filter(Mat4::is_finite);
        self.update_ground(tracking, pose);
        let ground = self.ground.map(|(_, g)| g);
        let Some(world_from_camera) = pose else {
            return SceneFrame {
                ground,
                ..SceneFrame::default()
            };
        };
        let points = tracking
            .feature_points
            .iter()
            .filter(|p| p.point_in_world.is_finite())
            .map(|p| (p.id, p.point_in_world));
        let observations = observations_of(world_from_camera, points, &self.intrinsics);
        let mut scene = posed_scene(&mut self.mesher, world_from_camera, observations, ground);
        scene.tracking_ms = started.elapsed().as_secs_f32() * 1000.0;
        scene
    }

    fn update_ground(&mut self, tracking: &PlatformTracking, pose: Option<Mat4>) {
        // The chosen platform plane, as the platform refines it.
        if let Some((Some(id), _)) = self.ground {
            if let Some(plane) = tracking.planes.iter().find(|p| p.id == id)
                && let Some(ground) = ground_of_plane(plane)
            {
                self.ground = Some((Some(id), ground));
            }
            return;
        }
        let Some(camera_height) = pose.map(|m| m.w_axis.y) else {
            return;
        };
        if let Some(plane) = lowest_horizontal_plane(&tracking.planes, camera_height) {
            self.ground = ground_of_plane(plane).map(|g| (Some(plane.id), g));
            return;
        }
        if self.ground.is_none() {
            self.ground =
                ground_from_points(&tracking.feature_points, camera_height).map(|g| (None, g));
        }
    }
}

fn is_horizontal_up(normal: Vec3) -> bool {
    normal
        .try_normalize()
        .is_some_and(|n| n.y >= GROUND_MAX_TILT_DEG.to_radians().cos())
}

fn ground_of_plane(plane: &PlatformPlane) -> Option<GroundPlane> {
    // A unit normal is kept as the platform gave it (renormalising would change its last bits).
    let n = plane.normal_in_world;
    let normal = match n.length() {
        length if (length - 1.0).abs() <= 1e-5 => n,
        _ => n.try_normalize()?,
    };
    (plane.center_in_world.is_finite() && is_horizontal_up(normal)).then_some(GroundPlane {
        point: plane.center_in_world,
        normal,
    })
}

/// The ground among the platform's planes: the lowest upward-facing horizontal plane below the
/// camera (a table or a bench is higher than the lawn); the larger one when two are as low.
fn lowest_horizontal_plane(planes: &[PlatformPlane], camera_height: f32) -> Option<&PlatformPlane> {
    planes
        .iter()
        .filter(|p| is_horizontal_up(p.normal_in_world) && p.center_in_world.is_finite())
        .filter(|p| camera_height - p.center_in_world.y >= MIN_GROUND_DEPTH_BELOW_CAMERA_M)
        .min_by(|a, b| {
            let area = |p: &PlatformPlane| p.extent_m[0] * p.extent_m[1];
            a.center_in_world
                .y
                .total_cmp(&b.center_in_world.y)
                .then(area(b).total_cmp(&area(a)))
        })
}

/// The ground fitted to feature points when the platform reports no plane: the horizontal
/// plane (gravity-aligned world) through most of the points below the camera, by RANSAC.
pub fn ground_from_points(points: &[FeaturePoint], camera_height: f32) -> Option<GroundPlane> {
    let below: Vec<DVec3> = points
        .iter()
        .map(|p| p.point_in_world)
        .filter(|p| p.is_finite() && camera_height - p.y >= MIN_GROUND_DEPTH_BELOW_CAMERA_M)
        .map(|p| p.as_dvec3())
        .collect();
    let config = RansacConfig {
        threshold: 0.03,
        min_inliers: MIN_GROUND_POINTS,
        ..RansacConfig::default()
    };
    // The world is gravity-aligned: the normal is up, RANSAC finds the height with most
    // points, and the inliers' mean refines it.
    let found = ransac(
        &OrientedPlaneEstimator { normal: DVec3::Y },
        &below,
        &config,
    )?;
    if found.inliers.len() < MIN_GROUND_POINTS {
        return None;
    }
    let height_m =
        found.inliers.iter().map(|&i| below[i].y).sum::<f64>() / found.inliers.len() as f64;
    Some(GroundPlane {
        point: Vec3::new(0.0, height_m as f32, 0.0),
        normal: Vec3::Y,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn intrinsics() -> Intrinsics {
        Intrinsics {
            width: 640,
            height: 480,
            fx: 500.0,
            fy: 500.0,
            cx: 320.0,
            cy: 240.0,
            distortion: [0.0; 5],
        }
    }

    fn plane(id: u64, height_m: f32, extent_m: f32) -> PlatformPlane {
        PlatformPlane {
            id,
            center_in_world: Vec3::new(0.0, height_m, -1.0),
            normal_in_world: Vec3::Y,
            extent_m: [extent_m; 2],
        }
    }

    #[test]
    fn points_project_to_their_pixel_and_depth_and_points_behind_are_dropped() {
        let observations = observations_of(
            Mat4::IDENTITY,
            [
                (3, Vec3::new(0.5, -0.25, 2.0)),
                (4, Vec3::new(0.0, 0.0, -1.0)),
            ],
            &intrinsics(),
        );
        assert_eq!(
            observations.len(),
            1,
            "the point behind the camera is dropped"
        );
        assert_eq!(observations[0].id, 3);
        assert_eq!(observations[0].pixel, Vec2::new(445.0, 177.5));
        assert_eq!(observations[0].depth_m, 2.0);
    }

    #[test]
    fn the_ground_is_the_lowest_horizontal_plane_below_the_camera_and_follows_its_refinement() {
        let mut tracker = PlatformTracker::new(intrinsics());
        let camera = Mat4::from_translation(Vec3::new(0.0, 1.4, 0.0));
        let wall = PlatformPlane {
            normal_in_world: Vec3::Z,
            ..plane(9, -0.2, 3.0)
        };
        let mut tracking = PlatformTracking {
            world_from_camera: Some(camera),
            planes: vec![
                plane(1, 0.7, 1.0),
                wall,
                plane(2, 0.02, 2.0),
                plane(5, 1.3, 1.0),
            ],
            ..PlatformTracking::default()
        };
        let ground = tracker.track(&tracking).ground.expect("a ground");
        assert_eq!(
            ground.point.y, 0.02,
            "the lawn, not the table, the wall or a shelf"
        );
        tracking.planes = vec![plane(1, 0.7, 1.0), plane(2, 0.0, 3.0), plane(7, -0.5, 0.2)];
        let ground = tracker.track(&tracking).ground.expect("kept");
        assert_eq!(
            ground.point.y, 0.0,
            "the chosen plane as refined, not a new lower one"
        );
    }

    #[test]
    fn without_planes_the_ground_is_fitted_to_the_points_on_it() {
        let mut points = Vec::new();
        for i in 0..60u64 {
            let (x, z) = ((i % 10) as f32 * 0.2 - 1.0, -((i / 10) as f32) * 0.3 - 0.5);
            let noise = ((i * 7919) % 11) as f32 * 0.001;
            points.push(FeaturePoint {
                id: i,
                point_in_world: Vec3::new(x, -1.5 + noise, z),
            });
        }
        for i in 0..20u64 {
            // A box top 0.4 m above the ground.
            points.push(FeaturePoint {
                id: 100 + i,
                point_in_world: Vec3::new(i as f32 * 0.05, -1.1, -1.0),
            });
        }
        let ground = ground_from_points(&points, 0.0).expect("the ground");
        assert!(
            (ground.point.y + 1.495).abs() < 0.01,
            "ground at {}",
            ground.point.y
        );
        assert_eq!(ground.normal, Vec3::Y);
        assert!(
            ground_from_points(&points[..20], 0.0).is_none(),
            "too few points"
        );
    }

    #[test]
    fn a_frame_without_a_pose_keeps_the_ground_and_has_no_points() {
        let mut tracker = PlatformTracker::new(intrinsics());
        let tracking = PlatformTracking {
            world_from_camera: Some(Mat4::from_translation(Vec3::Y)),
            planes: vec![plane(1, 0.0, 1.0)],
            ..PlatformTracking::default()
        };
        tracker.track(&tracking);
        let lost = tracker.track(&PlatformTracking {
            world_from_camera: None,
            feature_points: vec![FeaturePoint {
                id: 1,
                point_in_world: Vec3::new(0.0, 0.0, 2.0),
            }],
            ..PlatformTracking::default()
        });
        assert!(lost.world_from_camera.is_none() && lost.observations.is_empty());
        assert!(lost.ground.is_some());
    }
}
