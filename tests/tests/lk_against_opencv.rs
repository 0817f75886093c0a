//! The tracker's own Lucas–Kanade (`sylva_tracking::lk`) against OpenCV's on real footage:
//! corners of TUM fr1_rpy frames followed three frames ahead (blur, fast rotation), both with
//! the tracker's forward-backward check.

use sylva_tests::shared_data_dir;
use sylva_tracking::sequence::decode_gray;
use sylva_tracking::{TumSequence, cv, lk};

#[test]
fn the_projects_lucas_kanade_tracks_fr1_corners_where_opencvs_does() {
    let root = shared_data_dir().join("tum_fr1_rpy");
    let sequence = TumSequence::open(&root).expect("fr1_rpy opens");
    let (mut both, mut only_ours, mut only_opencv, mut close) = (0usize, 0usize, 0usize, 0usize);
    for i in (0..700).step_by(35) {
        let a = decode_gray(&sequence.frames[i].path, &sequence.camera).expect("frame decodes");
        let b = decode_gray(&sequence.frames[i + 3].path, &sequence.camera).expect("frame decodes");
        let corners = cv::detect_corners(&a, 300, 14.0, &[]).expect("corners");
        let ours = lk::track_points(
            &lk::Pyramid::build(&a),
            &lk::Pyramid::build(&b),
            &corners,
            None,
            lk::LkOptions {
                levels: 3,
                max_fb_error_px: Some(2.0),
            },
        );
        let opencv = cv::track_points(
            &cv::Pyramid::build(&a).expect("pyramid"),
            &cv::Pyramid::build(&b).expect("pyramid"),
            &corners,
            None,
            lk::LkOptions {
                levels: 3,
                max_fb_error_px: Some(2.0),
            },
        )
        .expect("OpenCV tracks");
        for (o, c) in ours.iter().zip(&opencv) {
            match (o, c) {
                (Some(o), Some(c)) => {
                    both += 1;
                    if o.distance(*c) < 0.1 {
                        close += 1;
                    }
                }
                (Some(_), None) => only_ours += 1,
                (None, Some(_)) => only_opencv += 1,
                (None, None) => {}
            }
        }
    }
    let summary = format!(
        "both {both}, only ours {only_ours}, only OpenCV {only_opencv}, within 0.1 px {close}"
    );
    assert!(both > 3000, "{summary}");
    // The same points survive: each side keeps at most 6% that the other loses (measured: 3%
    // and 5% of 3713; the two judge texture and borders a little differently) ...
    assert!(
        only_ours * 100 <= both * 6 && only_opencv * 100 <= both * 6,
        "{summary}"
    );
    // ... and lands on the same place: 95% of the common tracks within a tenth of a pixel
    // (measured: 98%).
    assert!(close * 100 >= both * 95, "{summary}");
}
