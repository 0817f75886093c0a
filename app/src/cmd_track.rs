//! `sylva track SEQUENCE [--report report.json] [--plot trajectory.png] [--readout-ms MS]`:
//! runs the monocular tracker over a recorded TUM-layout sequence, prints per-stage timings and
//! ends with one `key=value` line (error fields only when the sequence has ground truth).

#[cfg(not(any(target_os = "android", target_os = "ios")))]
use anyhow::Context;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct TrackArgs {
    /// A TUM-layout sequence folder (rgb.txt, camera.txt, optional groundtruth.txt, ...).
    pub sequence: PathBuf,
    /// Writes the full report (metrics, timings, per-frame trajectory) as JSON.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Draws the aligned estimated trajectory over the true one (top view) as a PNG.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Height the camera is held at above the ground, metres (sets the metric scale).
    #[arg(long, default_value_t = 1.5)]
    pub holding_height_m: f64,
    /// Rolling-shutter readout time of the camera, first row to last, milliseconds (0 for a
    /// global shutter); estimated from the footage when not given.
    #[arg(long, value_parser = parse_readout_ms)]
    pub readout_ms: Option<f64>,
}

/// A readout time in milliseconds: finite, 0 to 200.
fn parse_readout_ms(text: &str) -> Result<f64, String> {
    let ms: f64 = text
        .parse()
        .map_err(|_| format!("`{text}` is not a number of milliseconds"))?;
    if ms.is_finite() && (0.0..=200.0).contains(&ms) {
        Ok(ms)
    } else {
        Err(format!("readout {ms} ms is outside 0 to 200 ms"))
    }
}

#[cfg(any(target_os = "android", target_os = "ios"))]
pub fn track(_args: TrackArgs) -> anyhow::Result<()> {
    anyhow::bail!("`sylva track` needs the OpenCV tracker, which phone builds leave out")
}

#[cfg(not(any(target_os = "android", target_os = "ios")))]
pub fn track(args: TrackArgs) -> anyhow::Result<()> {
    use indicatif::{ProgressBar, ProgressStyle};
    use sylva_tracking::report::run_sequence;

    let config = sylva_tracking::TrackerConfig {
        holding_height_m: args.holding_height_m,
        rolling_shutter_readout_s: args.readout_ms.map(|ms| ms / 1000.0),
        ..Default::default()
    };
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames {elapsed_precise} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let report = run_sequence(
        &args.sequence,
        config,
        |done, total| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        },
        |skip| {
            bar.println(format!(
                "warning: skipped frame {}: {}",
                skip.path.display(),
                skip.reason
            ))
        },
    )
    .with_context(|| format!("tracking {}", args.sequence.display()))?;
    bar.finish_and_clear();
    println!(
        "stage decode: median {:.2} ms/frame (excluded from ms_per_frame)",
        report.median_decode_ms
    );
    println!(
        "stage track: median {:.2} ms/frame (features, pose, local map, keyframes, bundle adjustment)",
        report.ms_per_frame
    );
    println!(
        "map: {} keyframes, {} points; scale from {}; rolling-shutter readout {:.0} ms; {} frames skipped",
        report.num_keyframes,
        report.num_map_points,
        report.scale_source.map_or_else(
            || "nothing (no ground plane found)".to_owned(),
            |s| s.to_string()
        ),
        report.rolling_shutter_readout_ms,
        report.skipped.len()
    );
    if let Some(path) = &args.report {
        let json = serde_json::to_string_pretty(&report).context("encoding the report")?;
        std::fs::write(path, json).with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(path) = &args.plot {
        crate::track_plot::draw(&report, path)
            .with_context(|| format!("drawing {}", path.display()))?;
    }
    println!("{}", report.summary_line());
    Ok(())
}
