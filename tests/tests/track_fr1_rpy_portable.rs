//! Issue 22, item 4: the tracker on its portable vision backend (the one phones run, no OpenCV)
//! on the whole of TUM fr1_rpy, held to the bounds `track_fr1_rpy.rs` holds the OpenCV backend
//! to.

use sylva_tests::shared_data_dir;
use sylva_tracking::report::run_sequence;
use sylva_tracking::{TrackerConfig, VisionBackend};

#[test]
fn fr1_rpy_on_the_portable_backend_meets_the_desktop_bounds() {
    let root = shared_data_dir().join("tum_fr1_rpy");
    let config = TrackerConfig {
        backend: VisionBackend::Portable,
        ..TrackerConfig::default()
    };
    let report = run_sequence(
        &root,
        config,
        |_, _| {},
        |s| panic!("frame {} unreadable", s.path.display()),
    )
    .expect("fr1_rpy tracks without error");
    let line = report.summary_line();
    println!("portable backend: {line}");
    let e = report.errors.expect("fr1_rpy has ground truth");
    assert_eq!(report.frames, 723, "{line}");
    assert!(report.tracked_fraction >= 0.90, "{line}");
    assert!(e.ate_rmse_m <= 0.035, "{line}");
    assert!(e.window_ate_m <= 0.015, "{line}");
    assert!(e.scale_spread <= 1.5, "{line}");
    assert!(e.rot_err_deg <= 2.0, "{line}");
}
