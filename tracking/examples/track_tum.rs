//! Quick runner: `cargo run --release -p sylva-tracking --example track_tum -- SEQUENCE`.
#[path = "common/cfg.rs"]
mod cfg;

fn main() {
    let Some(root) = std::env::args().nth(1) else {
        eprintln!("usage: track_tum SEQUENCE");
        std::process::exit(2);
    };
    sylva_tracking::cv::configure_single_thread();
    let config = cfg::config_from_env();
    match sylva_tracking::report::run_sequence(
        std::path::Path::new(&root),
        config,
        |_, _| {},
        |s| eprintln!("warning: skipped frame {}: {}", s.path.display(), s.reason),
    ) {
        Ok(report) => {
            eprintln!(
                "keyframes={} points={} readout_ms={}",
                report.num_keyframes, report.num_map_points, report.rolling_shutter_readout_ms
            );
            if std::env::var_os("SYLVA_TRACE").is_some() {
                for row in &report.trajectory {
                    eprintln!("{} {:?} {}", row.index, row.state, row.num_points);
                }
            }
            if std::env::var_os("SYLVA_ROT").is_some() {
                rotation_check(&root, &report);
            }
            if let Some(path) = std::env::var_os("SYLVA_REPORT") {
                let json = serde_json::to_string(&report).expect("report serialises");
                std::fs::write(&path, json).expect("report written");
            }
            println!("{}", report.summary_line());
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}

/// Diagnostic: orientation error relative to the first tracked frame, against ground truth.
fn rotation_check(root: &str, report: &sylva_tracking::report::TrackReport) {
    let steps = rotation_steps(root, report);
    let mut sorted = steps.clone();
    sorted.sort_by(|a, b| b.0.total_cmp(&a.0));
    eprintln!(
        "worst steps (err deg, frame, true step deg): {:?}",
        &sorted[..sorted.len().min(15)]
    );
    let mean: f64 = steps.iter().map(|s| s.0).sum::<f64>() / steps.len().max(1) as f64;
    eprintln!("mean step err {mean:.3} deg over {}", steps.len());
}

fn rotation_steps(
    root: &str,
    report: &sylva_tracking::report::TrackReport,
) -> Vec<(f64, usize, f64)> {
    let seq = sylva_tracking::TumSequence::open(std::path::Path::new(root)).expect("sequence");
    let mut first: Option<(glam::DQuat, glam::DQuat)> = None;
    let mut prev: Option<(glam::DQuat, glam::DQuat)> = None;
    let mut steps = Vec::new();
    for row in &report.trajectory {
        let Some(q) = row.orientation else { continue };
        let Some(gt) = seq.groundtruth_at(row.timestamp_s, 0.02) else {
            continue;
        };
        let est = glam::DQuat::from_array(q);
        let truth = glam::DQuat::from_mat3(&gt.matrix3);
        if let Some((pe, pt)) = prev {
            let step_err = (pe.inverse() * est)
                .angle_between(pt.inverse() * truth)
                .to_degrees();
            steps.push((
                step_err,
                row.index,
                (pt.inverse() * truth)
                    .angle_between(glam::DQuat::IDENTITY)
                    .to_degrees(),
            ));
        }
        prev = Some((est, truth));
        let (e0, t0) = *first.get_or_insert((est, truth));
        let rel_est = e0.inverse() * est;
        let rel_truth = t0.inverse() * truth;
        if row.index % 20 == 0 {
            eprintln!(
                "rot {} err {:.2} deg (truth moved {:.1} deg)",
                row.index,
                rel_est.angle_between(rel_truth).to_degrees(),
                rel_truth.angle_between(glam::DQuat::IDENTITY).to_degrees()
            );
        }
    }
    steps
}
