//! Issue 5, item 3: the RANSAC ground plane on real depth. Points back-projected from the
//! tum_fr3_cabinet depth maps with their ground-truth poses (mocap world: z up, floor at z ≈ 0)
//! give the floor within 1° and 1 cm, and the cabinet's points are outliers.

use glam::{DVec2, DVec3};
use sylva_tests::shared_data_dir;
use sylva_tracking::ground_plane::{PlaneEstimator, RansacConfig, fit_plane};
use sylva_tracking::sequence::{TumSequence, decode_depth_m};

/// Every `step`-th pixel of every depth map, in the world.
fn world_points(sequence: &TumSequence, step: usize) -> Vec<DVec3> {
    let camera = sequence.camera;
    let depth_scale = camera.depth_scale.expect("camera.txt gives depth_scale");
    let mut points = Vec::new();
    for file in &sequence.depth {
        let world_from_camera = sequence
            .groundtruth_at(file.timestamp_s, 0.02)
            .unwrap_or_else(|| panic!("no ground truth for {}", file.path.display()));
        let (w, h, metres) = decode_depth_m(&file.path, depth_scale)
            .unwrap_or_else(|e| panic!("{}: {e}", file.path.display()));
        for y in (0..h as usize).step_by(step) {
            for x in (0..w as usize).step_by(step) {
                let z = metres[y * w as usize + x] as f64;
                if z <= 0.0 || z > 4.0 {
                    continue;
                }
                let n = camera.normalized_from_pixel(DVec2::new(x as f64, y as f64));
                points.push(world_from_camera.transform_point3(n.extend(1.0) * z));
            }
        }
    }
    points
}

#[test]
fn the_floor_of_fr3_cabinet_is_found_within_one_degree_and_one_centimetre() {
    let sequence =
        TumSequence::open(&shared_data_dir().join("tum_fr3_cabinet")).expect("fr3_cabinet");
    let points = world_points(&sequence, 8);
    assert!(points.len() > 50_000, "only {} depth points", points.len());
    let config = RansacConfig {
        threshold: 0.02,
        ..RansacConfig::default()
    };
    let found = fit_plane(&PlaneEstimator, &points, &config, DVec3::Z).expect("a plane");
    let plane = found.model;
    let tilt_deg = plane.normal.angle_between(DVec3::Z).to_degrees();
    // Height of the plane at the middle of the inliers (the floor under the cabinet).
    let centroid =
        found.inliers.iter().map(|&i| points[i]).sum::<DVec3>() / found.inliers.len() as f64;
    let height_m = plane.offset - plane.normal.dot(DVec3::new(centroid.x, centroid.y, 0.0));
    assert!(tilt_deg <= 1.0, "floor normal tilted by {tilt_deg:.3}°");
    assert!(height_m.abs() <= 0.01, "floor found at z = {height_m:.4} m");
    // The cabinet (0.56 m high) stands on the floor: its points are outliers.
    let cabinet: Vec<usize> = (0..points.len()).filter(|&i| points[i].z > 0.08).collect();
    assert!(
        cabinet.len() > 5_000,
        "only {} cabinet points",
        cabinet.len()
    );
    let inliers: std::collections::HashSet<usize> = found.inliers.iter().copied().collect();
    let cabinet_inliers = cabinet.iter().filter(|i| inliers.contains(i)).count();
    assert!(
        cabinet_inliers == 0,
        "{cabinet_inliers} of {} cabinet points taken as floor",
        cabinet.len()
    );
}
