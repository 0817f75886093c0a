//! `sylva track SEQUENCE [--report report.json] [--plot trajectory.png] [--readout-ms MS]
//! [--holding-height-m M] [--known-length FRAME:U1,V1:U2,V2:METRES] [--measure FRAME:U1,V1:U2,V2]`:
//! runs the monocular tracker over a recorded TUM-layout sequence, prints per-stage timings, the
//! metric scale with its source and uncertainty, one `measured_m=` line per `--measure`, and
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
    /// Height the camera is held at above the ground, metres (0.3 to 3): with the median of the
    /// tracked camera's height above the ground plane it sets the metric scale.
    #[arg(long, default_value_t = sylva_tracking::scale::DEFAULT_HOLDING_HEIGHT_M,
          value_parser = parse_holding_height_m)]
    pub holding_height_m: f64,
    /// Two pixels of one frame on the ends of something of known length, and that length:
    /// `FRAME:U1,V1:U2,V2:METRES` (raw image pixels, frames counted from 0). Sets the metric
    /// scale instead of the holding height.
    #[arg(long, value_name = "FRAME:U1,V1:U2,V2:METRES")]
    pub known_length: Option<sylva_tracking::measure::KnownLength>,
    /// Measures the distance between the points under two pixels of one frame (on the ground or
    /// on tracked points), in metres: `FRAME:U1,V1:U2,V2`. May be repeated.
    #[arg(long, value_name = "FRAME:U1,V1:U2,V2")]
    pub measure: Vec<sylva_tracking::measure::PixelPair>,
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

/// A holding height in metres: finite, inside the sane range.
fn parse_holding_height_m(text: &str) -> Result<f64, String> {
    let metres: f64 = text
        .parse()
        .map_err(|_| format!("`{text}` is not a height in metres"))?;
    sylva_tracking::scale::validate_holding_height_m(metres).map_err(|e| e.to_string())
}

#[cfg(any(target_os = "android", target_os = "ios"))]
pub fn track(_args: TrackArgs) -> anyhow::Result<()> {
    anyhow::bail!("`sylva track` needs the OpenCV tracker, which phone builds leave out")
}

/// Refuses, before tracking, a `--report` or `--plot` that is one of the sequence's list files
/// or the other output.
#[cfg(not(any(target_os = "android", target_os = "ios")))]
fn check_track_files(args: &TrackArgs) -> anyhow::Result<()> {
    let lists = [
        "rgb.txt",
        "depth.txt",
        "groundtruth.txt",
        "camera.txt",
        "accelerometer.txt",
    ]
    .map(|name| args.sequence.join(name));
    let inputs: Vec<&std::path::Path> = lists.iter().map(PathBuf::as_path).collect();
    let outputs: Vec<&std::path::Path> = args
        .report
        .iter()
        .chain(&args.plot)
        .map(PathBuf::as_path)
        .collect();
    crate::outputs::check_outputs(&inputs, &outputs)
}

#[cfg(not(any(target_os = "android", target_os = "ios")))]
pub fn track(args: TrackArgs) -> anyhow::Result<()> {
    use indicatif::{ProgressBar, ProgressStyle};
    use sylva_tracking::report::run_sequence_scaled;
    use sylva_tracking::run_scale::ScaleOptions;

    check_track_files(&args)?;
    let config = sylva_tracking::TrackerConfig {
        holding_height_m: args.holding_height_m,
        rolling_shutter_readout_s: args.readout_ms.map(|ms| ms / 1000.0),
        ..Default::default()
    };
    let scale_options = ScaleOptions {
        holding_height_m: args.holding_height_m,
        known_length: args.known_length,
        measures: args.measure.clone(),
    };
    let bar = ProgressBar::new(0);
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames {elapsed_precise} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let report = run_sequence_scaled(
        &args.sequence,
        config,
        &scale_options,
        |done, total| {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        },
        // To stderr whatever it is (a terminal, a pipe, a log file): the bar's own println
        // prints nothing when its output is hidden.
        |skip| {
            bar.suspend(|| {
                eprintln!(
                    "warning: skipped frame {}: {}",
                    skip.path.display(),
                    skip.reason
                )
            })
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
        "map: {} keyframes, {} points; rolling-shutter readout {:.0} ms; {} frames skipped",
        report.num_keyframes,
        report.num_map_points,
        report.rolling_shutter_readout_ms,
        report.skipped.len()
    );
    print_scale(&report.scale);
    for line in report.measurement_lines() {
        println!("{line}");
    }
    if let Some(path) = &args.report {
        let json = serde_json::to_string_pretty(&report).context("encoding the report")?;
        crate::outputs::write_file(path, json.as_bytes())?;
    }
    if report.tracked_frames == 0 {
        println!("{}", report.summary_line());
        anyhow::bail!(
            "no frame of {} was tracked ({} frames, {} unreadable): the figures above measure nothing",
            args.sequence.display(),
            report.frames,
            report.skipped.len()
        );
    }
    if let Some(path) = &args.plot {
        crate::track_plot::draw(&report, path)
            .with_context(|| format!("drawing {}", path.display()))?;
    }
    println!("{}", report.summary_line());
    Ok(())
}

#[cfg(not(any(target_os = "android", target_os = "ios")))]
fn print_scale(scale: &sylva_tracking::run_scale::RunScale) {
    match &scale.metric {
        Some(metric) => println!(
            "scale: from {metric}; {:.4} m per unit of the tracker's first guess",
            metric.metres_per_unit
        ),
        None => println!("scale: none (no ground plane found and no known length given)"),
    }
    if let Some(k) = &scale.known_length {
        println!(
            "known length: frame {} from ({:.1}, {:.1}) on {} to ({:.1}, {:.1}) on {}",
            k.frame,
            k.a.pixel.x,
            k.a.pixel.y,
            k.a.surface.key(),
            k.b.pixel.x,
            k.b.pixel.y,
            k.b.surface.key()
        );
    }
    if let Some(h) = &scale.camera_height {
        println!(
            "camera height: median {:.3} m over {} frames (spread {:.3} m)",
            h.median_m, h.num_frames, h.spread_m
        );
    }
}
