//! Renders a synthetic TUM-layout garden sequence.
//!
//! `make_synthetic --out DIR [--preset demo|demo-yard|slope|forced-loss|tree-a|tree-b] [--seed N] [--frames N]
//!  [--size WxH] [--quality Q | --png] [--depth-every N] [--no-blur] [--no-exposure]
//!  [--blank START..END]`
//!
//! The committed demo is `make_synthetic --out test-data/demo_garden` (preset demo).

use std::path::PathBuf;
use std::process::ExitCode;

use sylva_tests::synthetic::{FrameFormat, SequenceOptions, render_sequence};

const USAGE: &str = "usage: make_synthetic --out DIR [--preset demo|demo-yard|slope|forced-loss|tree-a|tree-b] [--seed N] [--frames N] \
[--size WxH] [--quality Q | --png] [--depth-every N] [--no-blur] [--no-exposure] [--blank START..END]";

fn parse_number<T: std::str::FromStr>(flag: &str, value: Option<String>) -> Result<T, String> {
    let value = value.ok_or_else(|| format!("{flag} needs a value"))?;
    value
        .parse()
        .map_err(|_| format!("{flag}: cannot parse '{value}'"))
}

fn parse_args() -> Result<(SequenceOptions, PathBuf), String> {
    let mut args = std::env::args().skip(1);
    let mut options = SequenceOptions::demo_garden();
    let mut out = None;
    while let Some(flag) = args.next() {
        match flag.as_str() {
            "--out" => out = args.next().map(PathBuf::from),
            "--preset" => {
                let seed_free = match args.next().as_deref() {
                    Some("demo") => SequenceOptions::demo_garden(),
                    Some("demo-yard") => SequenceOptions::demo_yard(),
                    Some("slope") => SequenceOptions::slope(),
                    Some("forced-loss") => SequenceOptions::forced_loss(),
                    Some("tree-a") => SequenceOptions::tree_a(),
                    Some("tree-b") => SequenceOptions::tree_b(),
                    other => {
                        return Err(format!(
                            "unknown preset {other:?} (demo, demo-yard, slope, forced-loss, tree-a, tree-b)"
                        ));
                    }
                };
                options = seed_free;
            }
            "--seed" => options.seed = parse_number(&flag, args.next())?,
            "--frames" => options.num_frames = parse_number(&flag, args.next())?,
            "--quality" => {
                options.frame_format = FrameFormat::Jpeg {
                    quality: parse_number(&flag, args.next())?,
                }
            }
            "--png" => options.frame_format = FrameFormat::Png,
            "--depth-every" => options.depth_every = parse_number(&flag, args.next())?,
            "--no-blur" => options.motion_blur = false,
            "--no-exposure" => options.exposure_changes = false,
            "--size" => {
                let value = args.next().ok_or("--size needs WxH")?;
                let (w, h) = value
                    .split_once('x')
                    .ok_or(format!("--size: expected WxH, got '{value}'"))?;
                options.width = parse_number("--size", Some(w.to_owned()))?;
                options.height = parse_number("--size", Some(h.to_owned()))?;
            }
            "--blank" => {
                let value = args.next().ok_or("--blank needs START..END")?;
                let (a, b) = value
                    .split_once("..")
                    .ok_or(format!("--blank: expected START..END, got '{value}'"))?;
                options.blank_frames = Some(
                    parse_number("--blank", Some(a.to_owned()))?
                        ..parse_number("--blank", Some(b.to_owned()))?,
                );
            }
            "--help" | "-h" => return Err(USAGE.to_owned()),
            other => return Err(format!("unknown argument '{other}'\n{USAGE}")),
        }
    }
    let out = out.ok_or_else(|| format!("--out is required\n{USAGE}"))?;
    Ok((options, out))
}

fn main() -> ExitCode {
    let (options, out) = match parse_args() {
        Ok(parsed) => parsed,
        Err(message) => {
            eprintln!("{message}");
            return ExitCode::from(2);
        }
    };
    match render_sequence(&options, &out) {
        Ok(summary) => {
            println!(
                "wrote {} frames and {} depth maps to {} ({:.1} MB), path length {:.2} m",
                summary.num_frames,
                summary.num_depth_maps,
                out.display(),
                summary.total_bytes as f64 / 1e6,
                summary.path_length_m
            );
            ExitCode::SUCCESS
        }
        Err(error) => {
            eprintln!("make_synthetic: {error}");
            ExitCode::FAILURE
        }
    }
}
