//! The synthetic footage generator writes a consistent TUM-layout sequence.

use std::fs;
use std::path::Path;

use glam::{Affine3A, Quat, Vec3};
use sylva_tests::synthetic::{FrameFormat, Garden, Ground, SequenceOptions, render_to_temp_dir};

fn small(options: SequenceOptions) -> SequenceOptions {
    SequenceOptions {
        width: 160,
        height: 120,
        num_frames: 12,
        depth_every: 4,
        frame_format: FrameFormat::Png,
        ..options
    }
}

fn data_lines(path: &Path) -> Vec<Vec<String>> {
    fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| l.split_whitespace().map(str::to_owned).collect())
        .collect()
}

fn pose_from_line(fields: &[String]) -> Affine3A {
    let v: Vec<f32> = fields[1..8]
        .iter()
        .map(|f| f.parse().expect("number"))
        .collect();
    Affine3A::from_rotation_translation(
        Quat::from_xyzw(v[3], v[4], v[5], v[6]),
        Vec3::new(v[0], v[1], v[2]),
    )
}

#[test]
fn a_sequence_has_every_tum_file_and_consistent_lists() {
    let (dir, summary) =
        render_to_temp_dir(&small(SequenceOptions::demo_garden())).expect("render");
    let root = dir.path();
    for name in [
        "rgb.txt",
        "depth.txt",
        "groundtruth.txt",
        "accelerometer.txt",
        "camera.txt",
        "scene.json",
    ] {
        assert!(root.join(name).is_file(), "{name} missing");
    }
    let rgb = data_lines(&root.join("rgb.txt"));
    let depth = data_lines(&root.join("depth.txt"));
    let truth = data_lines(&root.join("groundtruth.txt"));
    assert_eq!((rgb.len(), depth.len(), truth.len()), (12, 3, 12));
    for line in rgb.iter().chain(&depth) {
        assert!(
            root.join(&line[1]).is_file(),
            "{} listed but absent",
            line[1]
        );
    }
    let image = image::open(root.join(&rgb[0][1])).expect("decode frame");
    assert_eq!((image.width(), image.height()), (160, 120));
    let accel = data_lines(&root.join("accelerometer.txt"));
    assert_eq!(accel.len(), 48, "120 Hz over 0.4 s");
    assert!(
        summary.path_length_m > 0.1,
        "path {}",
        summary.path_length_m
    );
}

#[test]
fn the_accelerometer_of_a_standing_camera_averages_to_gravity() {
    let mut options = small(SequenceOptions::demo_garden());
    options.num_frames = 60;
    options.depth_every = 0;
    options.walk.start_bearing_deg = 0.0;
    options.walk.end_bearing_deg = 0.0;
    let (dir, _) = render_to_temp_dir(&options).expect("render");
    let accel = data_lines(&dir.path().join("accelerometer.txt"));
    let mean = accel.iter().fold(Vec3::ZERO, |sum, fields| {
        let v: Vec<f32> = fields[1..4]
            .iter()
            .map(|f| f.parse().expect("number"))
            .collect();
        sum + Vec3::new(v[0], v[1], v[2])
    }) / accel.len() as f32;
    assert!(
        (mean.length() - 9.81).abs() < 0.3,
        "mean specific force {mean}"
    );
    // Kinect axes: y = -camera Y, so a camera pitched down 34 degrees reads +g cos(34) on y.
    assert!(
        (mean.y - 9.81 * 34f32.to_radians().cos()).abs() < 0.5,
        "mean {mean}"
    );
}

#[test]
fn depth_maps_back_project_onto_the_analytic_scene() {
    let options = small(SequenceOptions::slope());
    let (dir, _) = render_to_temp_dir(&options).expect("render");
    let root = dir.path();
    let truth = data_lines(&root.join("groundtruth.txt"));
    let depth = data_lines(&root.join("depth.txt"));
    let garden = Garden::new(Ground::sloped(options.slope_deg), 0);
    let camera = sylva_tests::synthetic::Pinhole::tum_default(160, 120);
    let mut checked = 0;
    for line in &depth {
        let world_from_camera = pose_from_line(
            truth
                .iter()
                .find(|t| t[0] == line[0])
                .expect("pose for depth"),
        );
        let map = image::open(root.join(&line[1]))
            .expect("depth png")
            .into_luma16();
        for (x, y, value) in map.enumerate_pixels().step_by(37) {
            if value.0[0] == 0 {
                continue;
            }
            let z = value.0[0] as f32 / 5000.0;
            let ray = Vec3::new(
                (x as f32 - camera.cx) / camera.fx,
                (y as f32 - camera.cy) / camera.fy,
                1.0,
            );
            let point = world_from_camera.transform_point3(ray * z);
            let origin = Vec3::from(world_from_camera.translation);
            let hit = garden
                .intersect(origin, (point - origin).normalize(), 100.0)
                .expect("scene behind pixel");
            assert!(
                (hit.point - point).length() < 0.01 + 0.002 * z,
                "pixel ({x},{y}) off the scene by {}",
                (hit.point - point).length()
            );
            checked += 1;
        }
    }
    assert!(checked > 100, "only {checked} depth samples");
}

#[test]
fn the_same_seed_gives_identical_files_and_another_seed_differs() {
    let options = SequenceOptions {
        num_frames: 3,
        ..small(SequenceOptions::forced_loss())
    };
    let (a, _) = render_to_temp_dir(&options).expect("render a");
    let (b, _) = render_to_temp_dir(&options).expect("render b");
    let (c, _) = render_to_temp_dir(&SequenceOptions {
        seed: 99,
        ..options.clone()
    })
    .expect("render c");
    let first = |dir: &Path| {
        let line = data_lines(&dir.join("rgb.txt"))[1][1].clone();
        fs::read(dir.join(line)).expect("frame bytes")
    };
    assert_eq!(first(a.path()), first(b.path()));
    assert_ne!(first(a.path()), first(c.path()));
}

#[test]
fn blanked_frames_are_uniform_and_the_others_are_textured() {
    let options = SequenceOptions {
        blank_frames: Some(4..8),
        ..small(SequenceOptions::demo_garden())
    };
    let (dir, _) = render_to_temp_dir(&options).expect("render");
    let rgb = data_lines(&dir.path().join("rgb.txt"));
    let spread = |index: usize| {
        let image = image::open(dir.path().join(&rgb[index][1]))
            .expect("frame")
            .into_luma8();
        let (min, max) = image
            .pixels()
            .fold((255u8, 0u8), |(lo, hi), p| (lo.min(p.0[0]), hi.max(p.0[0])));
        max - min
    };
    assert_eq!(spread(5), 0, "blank frame has content");
    assert!(spread(2) > 100, "rendered frame too flat: {}", spread(2));
}

#[test]
fn invalid_options_are_an_error_not_a_panic() {
    let options = SequenceOptions {
        num_frames: 0,
        ..SequenceOptions::demo_garden()
    };
    assert!(render_to_temp_dir(&options).is_err());
}
