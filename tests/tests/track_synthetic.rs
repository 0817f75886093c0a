//! Issue 5, item 2, on the project's synthetic walk (test-data/demo_garden: 4.26 m path, camera
//! 1.5 m above a flat lawn, ground normal +Y, truth in scene.json).

use glam::DVec3;
use sylva_tests::project_data_dir;
use sylva_tracking::TrackerConfig;
use sylva_tracking::report::run_sequence;

const PATH_LENGTH_M: f64 = 4.26;

#[test]
#[ignore = "not met yet on demo_garden; run with --ignored (see the tracking report)"]
fn the_demo_garden_walk_is_tracked_to_one_percent_with_the_plane_and_scale_right() {
    let root = project_data_dir().join("demo_garden");
    let report = run_sequence(
        &root,
        TrackerConfig::default(),
        |_, _| {},
        |s| panic!("{}", s.path.display()),
    )
    .expect("demo_garden tracks");
    let line = report.summary_line();
    let errors = report.errors.expect("ground truth");
    assert!(errors.ate_rmse_m <= 0.01 * PATH_LENGTH_M, "{line}");
    assert!(errors.anchor_px <= 3.0, "{line}");
    // The world is metric from the holding height (1.5 m, the true height): the alignment to
    // the truth needs no rescaling beyond 3 %.
    let scale = errors.alignment.scale;
    assert!(
        (scale - 1.0).abs() <= 0.03,
        "alignment scale {scale:.4}; {line}"
    );
    let plane = report.plane.expect("a ground plane");
    let normal_in_truth = errors.alignment.rotation * plane.normal;
    let tilt = normal_in_truth.angle_between(DVec3::Y).to_degrees();
    assert!(tilt <= 1.0, "plane normal off by {tilt:.2}°; {line}");
}
