//! How the tracker's result depends on where the footage starts (issue 22, item 4): both vision
//! backends on a TUM sequence from several start frames, one table row per run.
//! `cargo run --release -p sylva-tracking --example start_frames -- SEQUENCE [FIRST_FRAME...]`
//! (default start frames 0 2 4 8 16; `SYLVA_BACKEND=portable` or `opencv` runs one backend). The
//! portable backend runs with each of its essential-matrix solvers.

use sylva_tracking::VisionBackend;
use sylva_tracking::report::run_sequence_from;
use sylva_tracking::vision::EssentialMinimal;

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(root) = args.next() else {
        eprintln!("usage: start_frames SEQUENCE [FIRST_FRAME...]");
        std::process::exit(2);
    };
    let mut starts: Vec<usize> = args
        .map(|a| {
            a.parse().unwrap_or_else(|_| {
                eprintln!("start frames are frame numbers, not {a}");
                std::process::exit(2)
            })
        })
        .collect();
    if starts.is_empty() {
        starts = vec![0, 2, 4, 8, 16];
    }
    let mut backends: Vec<VisionBackend> = match std::env::var("SYLVA_BACKEND") {
        Ok(name) => vec![VisionBackend::from_name(&name).unwrap_or_else(|| {
            eprintln!("SYLVA_BACKEND: opencv or portable, not {name}");
            std::process::exit(2)
        })],
        Err(_) => vec![VisionBackend::Portable, VisionBackend::default()],
    };
    backends.dedup();
    #[cfg(feature = "opencv")]
    sylva_tracking::cv::configure_single_thread();
    let runs: Vec<(VisionBackend, EssentialMinimal)> = backends
        .iter()
        .flat_map(|&backend| match backend {
            VisionBackend::Portable => {
                vec![
                    (backend, EssentialMinimal::EightPoint),
                    (backend, EssentialMinimal::FivePoint),
                ]
            }
            VisionBackend::OpenCv => vec![(backend, EssentialMinimal::FivePoint)],
        })
        .collect();
    println!(
        "backend   essential   start  tracked  ate_m   window_m  spread  rot_deg  ms_per_frame"
    );
    for &(backend, essential_minimal) in &runs {
        for &first in &starts {
            let config = sylva_tracking::TrackerConfig {
                backend,
                essential_minimal,
                ..sylva_tracking::TrackerConfig::default()
            };
            let report = match run_sequence_from(
                std::path::Path::new(&root),
                config,
                first,
                |_, _| {},
                |s| eprintln!("warning: skipped frame {}: {}", s.path.display(), s.reason),
            ) {
                Ok(r) => r,
                Err(e) => {
                    eprintln!("error: {root} from frame {first}: {e}");
                    std::process::exit(1);
                }
            };
            match &report.errors {
                Some(e) => println!(
                    "{:<9} {:<10}  {:>5}  {:>7.3}  {:.4}  {:.4}    {:>6.2}  {:>7.2}  {:>12.1}",
                    backend.name(),
                    format!("{essential_minimal:?}"),
                    first,
                    report.tracked_fraction,
                    e.ate_rmse_m,
                    e.window_ate_m,
                    e.scale_spread,
                    e.rot_err_deg,
                    report.ms_per_frame
                ),
                None => println!("{backend:?} from {first}: {}", report.summary_line()),
            }
        }
    }
}
