//! Solids from synthetic walks round a box with known corners.

use super::*;

const CAMERA: PinholeIntrinsics = PinholeIntrinsics {
    width: 640,
    height: 480,
    fx: 525.0,
    fy: 525.0,
    cx: 319.5,
    cy: 239.5,
};

const BOX_MIN: Vec3 = Vec3::new(0.85, 0.0, -0.4);
const BOX_MAX: Vec3 = Vec3::new(1.35, 0.5, 0.1);

/// Whether the segment from `eye` to `point` passes through the box (slabs), short of 1 cm
/// before the point (the box's own points stay visible).
fn behind_the_box(eye: Vec3, point: Vec3) -> bool {
    let d = point - eye;
    let length = d.length();
    let (mut t0, mut t1) = (0.0f32, (length - 0.01) / length);
    for k in 0..3 {
        if d[k].abs() < 1e-9 {
            if eye[k] < BOX_MIN[k] || eye[k] > BOX_MAX[k] {
                return false;
            }
            continue;
        }
        let (a, b) = ((BOX_MIN[k] - eye[k]) / d[k], (BOX_MAX[k] - eye[k]) / d[k]);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
    }
    t0 < t1
}

/// Observations of world points from a camera at `eye` looking at `target` (Y up world,
/// OpenCV camera axes); points hidden by the box are not seen.
fn seen_from(eye: Vec3, target: Vec3, points: &[(u64, Vec3)]) -> (Vec<Observation>, Affine3A) {
    let forward = (target - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let down = forward.cross(right);
    let world_from_camera =
        Affine3A::from_mat3_translation(glam::Mat3::from_cols(right, down, forward), eye);
    let camera_from_world = world_from_camera.inverse();
    let observations = points
        .iter()
        .filter(|(_, p)| !behind_the_box(eye, *p))
        .filter_map(|&(id, p)| {
            let c = camera_from_world.transform_point3(p);
            Some(Observation {
                id,
                pixel: CAMERA.pixel_from_camera(c)?,
                depth_m: c.z,
            })
        })
        .collect();
    (observations, world_from_camera)
}

/// What `seen_from` gives, observed by `solids` on the ground through the origin, Y up.
fn seen_by(
    solids: &mut GroundSolids,
    eye: Vec3,
    target: Vec3,
    points: &[(u64, Vec3)],
) -> (Vec<Observation>, Affine3A) {
    let (observations, world_from_camera) = seen_from(eye, target, points);
    solids.observe(
        &observations,
        &CAMERA,
        &world_from_camera,
        Vec3::ZERO,
        Vec3::Y,
    );
    (observations, world_from_camera)
}

/// A box's corners and edge midpoints, ground points around it, and one stray point.
fn scene() -> Vec<(u64, Vec3)> {
    let mut points = Vec::new();
    let (min, max) = (BOX_MIN, BOX_MAX);
    for (i, (x, z)) in [
        (0.0, 0.0),
        (0.5, 0.0),
        (1.0, 0.0),
        (1.0, 0.5),
        (1.0, 1.0),
        (0.5, 1.0),
        (0.0, 1.0),
        (0.0, 0.5),
    ]
    .into_iter()
    .enumerate()
    {
        let p = Vec3::new(
            min.x + x * (max.x - min.x),
            max.y,
            min.z + z * (max.z - min.z),
        );
        points.push((i as u64, p));
        points.push((100 + i as u64, p.with_y(0.25)));
    }
    for i in 0..40u64 {
        let (x, z) = ((i % 8) as f32 * 0.6 - 2.0, (i / 8) as f32 * 0.6 - 1.5);
        points.push((200 + i, Vec3::new(x, 0.01 * ((i % 3) as f32 - 1.0), z)));
    }
    points.push((999, Vec3::new(-1.0, 0.7, 0.5)));
    points
}

/// The solids after a walk from `num_steps` bearings 10° apart, from 25° left of the
/// box, 3 m from the origin.
fn solids_after_walk(points: &[(u64, Vec3)], num_steps: usize) -> Vec<GroundSolid> {
    let mut solids = GroundSolids::new(GroundSolidsConfig::default());
    for k in 0..num_steps {
        let bearing = (k as f32 * 10.0 - 25.0).to_radians();
        let eye = Vec3::new(3.0 * bearing.sin(), 1.5, 3.0 * bearing.cos());
        seen_by(&mut solids, eye, Vec3::ZERO, points);
    }
    solids.solids().to_vec()
}

#[test]
fn the_points_of_a_box_make_one_prism_with_the_box_footprint_and_height() {
    let solids = solids_after_walk(&scene(), 6);
    assert_eq!(
        solids.len(),
        1,
        "one solid, the stray point and the ground make none: {solids:?}"
    );
    let solid = &solids[0];
    assert!(
        (solid.height_m - 0.5).abs() < 1e-3,
        "height {}",
        solid.height_m
    );
    // The box's outline: every corner on it (edge midpoints may stay, within round-off of
    // collinear), and its area.
    for p in &solid.footprint {
        assert!(p.y.abs() < 1e-4, "footprint {p} on the ground");
        assert!(
            ((p.x - 0.85).abs() < 1e-3 || (p.x - 1.35).abs() < 1e-3)
                || ((p.z + 0.4).abs() < 1e-3 || (p.z - 0.1).abs() < 1e-3),
            "corner {p} off the box's outline"
        );
    }
    let f = &solid.footprint;
    let area: f32 = (0..f.len())
        .map(|i| {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            0.5 * (a.z * b.x - a.x * b.z)
        })
        .sum();
    assert!((area.abs() - 0.25).abs() < 1e-3, "footprint area {area} m²");
}

#[test]
fn the_prism_mesh_has_sides_and_a_top_and_no_vertex_below_the_ground() {
    let mut solids = GroundSolids::new(GroundSolidsConfig::default());
    for k in 0..3 {
        let eye = Vec3::new(0.3 * k as f32, 1.5, 3.0);
        seen_by(&mut solids, eye, Vec3::ZERO, &scene());
    }
    let (mut positions, mut indices) = (Vec::new(), Vec::new());
    solids.append_mesh(Vec3::Y, &mut positions, &mut indices);
    let n = positions.len() / 2;
    assert!(n >= 4, "a footprint of at least the box's corners");
    assert_eq!(
        indices.len(),
        3 * (2 * n + n - 2),
        "a quad per side and a fan over the top"
    );
    assert!(positions.iter().all(|p| p.y > -1e-4 && p.y < 0.5 + 1e-3));
    assert!(indices.iter().all(|&i| (i as usize) < positions.len()));
}

#[test]
fn points_seen_in_too_few_frames_make_no_solid() {
    let mut solids = GroundSolids::new(GroundSolidsConfig::default());
    for _ in 0..2 {
        seen_by(&mut solids, Vec3::new(0.0, 1.5, 3.0), Vec3::ZERO, &scene());
    }
    assert!(solids.solids().is_empty());
}

/// The scene with a track triangulated off the box's silhouette: 15 cm beside its +x face,
/// linked to its points, with ground points behind it that the camera sees past it.
fn scene_with_a_point_off_the_silhouette() -> Vec<(u64, Vec3)> {
    let mut points = scene();
    points.push((500, Vec3::new(1.5, 0.19, 0.03)));
    for i in 0..16u64 {
        let (x, z) = (1.4 + 0.12 * (i % 4) as f32, -0.2 - 0.2 * (i / 4) as f32);
        points.push((600 + i, Vec3::new(x, 0.0, z)));
    }
    points
}

#[test]
fn free_rays_past_a_stray_point_cut_the_solid_back_to_the_box() {
    // Round to 65° right: the ground behind the box's right side comes into view.
    let solids = solids_after_walk(&scene_with_a_point_off_the_silhouette(), 10);
    assert_eq!(solids.len(), 1, "{solids:?}");
    let solid = &solids[0];
    assert!(solid.num_cuts > 0, "the stray point's side is carved");
    for p in &solid.footprint {
        let outside = (p.x - BOX_MAX.x)
            .max(BOX_MIN.x - p.x)
            .max(p.z - BOX_MAX.z)
            .max(BOX_MIN.z - p.z);
        // The stray point stood 15 cm out; the rays leave what none of them crossed.
        assert!(
            outside < 0.04,
            "corner {p} stands {outside} m out of the box"
        );
    }
}

#[test]
fn a_point_seen_now_behind_a_solid_face_is_not_hidden_by_it() {
    let mut solids = GroundSolids::new(GroundSolidsConfig::default());
    let walk = |solids: &mut GroundSolids, points: &[(u64, Vec3)]| {
        for k in 0..3 {
            let eye = Vec3::new(0.3 * k as f32, 1.5, 3.0);
            seen_by(solids, eye, Vec3::ZERO, points);
        }
    };
    walk(&mut solids, &scene_with_a_point_off_the_silhouette());
    // The camera steps right for three frames (the points newly in view become tracks);
    // no point seen in the last is hidden by a solid.
    let (mut last, mut tracked) = (None, None);
    for k in 0..3 {
        let eye = Vec3::new(1.1 + 0.05 * k as f32, 1.5, 3.0);
        let (observations, world_from_camera) = seen_by(
            &mut solids,
            eye,
            Vec3::ZERO,
            &scene_with_a_point_off_the_silhouette(),
        );
        let ids: std::collections::BTreeSet<u64> = observations.iter().map(|o| o.id).collect();
        tracked.get_or_insert(ids);
        last = Some((eye, observations, world_from_camera));
    }
    let tracked = tracked.expect("three frames");
    let (eye, observations, world_from_camera) = last.expect("three frames");
    let (mut positions, mut indices) = (Vec::new(), Vec::new());
    solids.append_mesh(Vec3::Y, &mut positions, &mut indices);
    for o in observations.iter().filter(|o| tracked.contains(&o.id)) {
        let ray =
            world_from_camera.transform_point3(CAMERA.camera_from_pixel(o.pixel, o.depth_m)) - eye;
        let reach = ray.length() - 0.1;
        let dir = ray / ray.length();
        let hit = indices.chunks_exact(3).any(|t| {
            let [a, b, c] = [0, 1, 2].map(|k| positions[t[k] as usize]);
            let (e1, e2) = (b - a, c - a);
            let p = dir.cross(e2);
            let det = e1.dot(p);
            if det.abs() < 1e-9 {
                return false;
            }
            let s = eye - a;
            let (u, q) = (s.dot(p) / det, s.cross(e1));
            let v = dir.dot(q) / det;
            let t = e2.dot(q) / det;
            u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0 && t < reach
        });
        assert!(
            !hit,
            "point {} seen now is hidden by a solid: {:?}",
            o.id,
            solids.solids()
        );
    }
}

#[test]
fn two_objects_farther_apart_than_the_link_distance_stay_two_solids() {
    let plan = [
        Vec2::new(0.0, 0.0),
        Vec2::new(0.3, 0.0),
        Vec2::new(0.6, 0.1),
        Vec2::new(2.0, 0.0),
        Vec2::new(2.2, 0.3),
    ];
    let groups = link_groups(&plan, 0.4);
    assert_eq!(groups, vec![vec![0, 1, 2], vec![3, 4]]);
}
