//! Report: the project's Lucas–Kanade (`sylva_tracking::lk`) against OpenCV's on consecutive
//! frames of a TUM sequence: agreement of the tracked positions and time per call.
//! `cargo run --release -p sylva-tracking --example lk_compare -- SEQUENCE [STEP]`

use std::time::Instant;
use sylva_tracking::{cv, lk, sequence::decode_gray};

fn main() {
    let root = std::env::args()
        .nth(1)
        .expect("usage: lk_compare SEQUENCE [STEP]");
    let step: usize = std::env::args()
        .nth(2)
        .map(|s| s.parse().expect("step"))
        .unwrap_or(1);
    cv::configure_single_thread();
    let sequence = sylva_tracking::TumSequence::open(std::path::Path::new(&root)).expect("open");
    let (mut ours_ms, mut theirs_ms, mut pyr_ms, mut cv_pyr_ms) = (0.0, 0.0, 0.0, 0.0);
    let (mut both, mut only_ours, mut only_theirs, mut close) = (0, 0, 0, 0);
    let mut errors = Vec::new();
    let pairs: Vec<usize> = (0..sequence.frames.len().saturating_sub(step))
        .step_by(7)
        .collect();
    for &i in &pairs {
        let a = decode_gray(&sequence.frames[i].path, &sequence.camera).expect("frame");
        let b = decode_gray(&sequence.frames[i + step].path, &sequence.camera).expect("frame");
        let corners = cv::detect_corners(&a, 300, 14.0, &[]).expect("corners");
        let t = Instant::now();
        let (pa, pb) = (lk::Pyramid::build(&a), lk::Pyramid::build(&b));
        pyr_ms += t.elapsed().as_secs_f64() * 1e3;
        let t = Instant::now();
        let (ca, cb) = (
            cv::Pyramid::build(&a).expect("pyr"),
            cv::Pyramid::build(&b).expect("pyr"),
        );
        cv_pyr_ms += t.elapsed().as_secs_f64() * 1e3;
        let options = lk::LkOptions {
            levels: 3,
            max_fb_error_px: Some(2.0),
        };
        let t = Instant::now();
        let ours = lk::track_points(&pa, &pb, &corners, None, options);
        ours_ms += t.elapsed().as_secs_f64() * 1e3;
        let t = Instant::now();
        let theirs = cv::track_points(
            &ca,
            &cb,
            &corners,
            None,
            lk::LkOptions {
                levels: 3,
                max_fb_error_px: Some(2.0),
            },
        )
        .expect("lk");
        theirs_ms += t.elapsed().as_secs_f64() * 1e3;
        for (o, t) in ours.iter().zip(&theirs) {
            match (o, t) {
                (Some(o), Some(t)) => {
                    both += 1;
                    let d = o.distance(*t);
                    errors.push(d);
                    if d < 0.1 {
                        close += 1;
                    }
                }
                (Some(_), None) => only_ours += 1,
                (None, Some(_)) => only_theirs += 1,
                _ => {}
            }
        }
    }
    errors.sort_by(f32::total_cmp);
    let n = pairs.len() as f64;
    println!(
        "pairs={} both={both} only_ours={only_ours} only_opencv={only_theirs} within_0.1px={:.3} median_diff_px={:.4} p95_diff_px={:.3}",
        pairs.len(),
        close as f64 / both.max(1) as f64,
        errors.get(errors.len() / 2).copied().unwrap_or(f32::NAN),
        errors
            .get(errors.len() * 95 / 100)
            .copied()
            .unwrap_or(f32::NAN),
    );
    println!(
        "ms per pair: ours lk={:.2} pyramids={:.2} | opencv lk={:.2} pyramids={:.2}",
        ours_ms / n,
        pyr_ms / n,
        theirs_ms / n,
        cv_pyr_ms / n
    );
}
