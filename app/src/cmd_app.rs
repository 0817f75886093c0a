//! `sylva` (the demo), `sylva view`, `sylva replay`.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use crate::footage::Footage;
use crate::session::replay;

/// The bundled demo sequence, relative to the workspace root.
pub const DEMO_SEQUENCE: &str = "test-data/demo_garden";

#[derive(clap::Args, Debug)]
pub struct ReplayArgs {
    /// Session file (JSON) to replay.
    pub session: PathBuf,
    /// Folder for composited PNG frames and the final tree.
    #[arg(long)]
    pub out: PathBuf,
}

#[derive(clap::Args, Debug)]
pub struct ViewArgs {
    /// Recorded sequence (TUM layout folder).
    pub sequence: Option<PathBuf>,
    /// Live camera index instead of a recorded sequence.
    #[arg(long)]
    pub camera: Option<u32>,
    /// Start at this frame.
    #[arg(long, default_value_t = 0)]
    pub frame: usize,
    /// Start paused.
    #[arg(long)]
    pub paused: bool,
    /// Start in the 3D view outside AR (orbit, pan, zoom) instead of the camera view.
    #[arg(long)]
    pub orbit: bool,
}

/// Finds the demo sequence from the current folder or the workspace the binary was built in.
pub fn demo_sequence() -> anyhow::Result<PathBuf> {
    let candidates = [
        PathBuf::from(DEMO_SEQUENCE),
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("..")
            .join(DEMO_SEQUENCE),
    ];
    candidates
        .into_iter()
        .find(|p| p.join("rgb.txt").exists())
        .with_context(|| {
            format!("the demo sequence {DEMO_SEQUENCE} is missing (run from the repository root)")
        })
}

fn has_display() -> bool {
    std::env::var_os("DISPLAY").is_some_and(|d| !d.is_empty())
        || std::env::var_os("WAYLAND_DISPLAY").is_some_and(|d| !d.is_empty())
}

/// `sylva` with no arguments: a window on the demo, or frames in a folder without a display.
pub fn demo() -> anyhow::Result<()> {
    let sequence = demo_sequence()?;
    if has_display() {
        match open_window(&sequence, WindowStart::default()) {
            Ok(()) => return Ok(()),
            Err(e) => eprintln!("no window ({e:#}); rendering frames instead"),
        }
    } else {
        eprintln!("no display (DISPLAY and WAYLAND_DISPLAY unset); rendering frames instead");
    }
    let out = PathBuf::from("out/demo");
    let footage = Footage::open(&sequence)?;
    let session = crate::demo_script::demo_session(&footage, sequence.clone())?;
    std::fs::create_dir_all(&out).with_context(|| format!("cannot create {}", out.display()))?;
    let session_path = out.join("demo-session.json");
    let mut absolute = session.clone();
    absolute.footage = std::fs::canonicalize(&sequence).unwrap_or(sequence);
    absolute.save(&session_path)?;
    let report = replay(&session_path, Some(&out), true, |_, _| {})?;
    println!(
        "rendered {} frames of the demo to {}/frame_0000.png … (tree in {}/tree.json and tree.glb)",
        report.num_frames,
        out.display(),
        out.display()
    );
    println!("{}", report.summary_line());
    Ok(())
}

/// How the window starts.
#[derive(Clone, Copy, Debug, Default)]
struct WindowStart {
    frame: usize,
    paused: bool,
    orbit: bool,
}

fn open_window(sequence: &Path, start: WindowStart) -> anyhow::Result<()> {
    let footage = Footage::open(sequence)?;
    std::fs::create_dir_all("out").context("cannot create out/")?;
    let session_path = PathBuf::from("out/last-session.json");
    let footage_ref = std::fs::canonicalize(sequence).unwrap_or_else(|_| sequence.to_owned());
    crate::desktop::run_window(
        footage,
        footage_ref,
        session_path,
        start.frame,
        start.paused,
        start.orbit,
    )
}

/// `sylva view SEQUENCE` / `sylva view --camera N`.
pub fn view(args: ViewArgs) -> anyhow::Result<()> {
    if let Some(index) = args.camera {
        bail!(
            "live camera {index}: capture from a live camera is not wired into this build yet; record a sequence and use `sylva view FOLDER`"
        );
    }
    let sequence = match args.sequence {
        Some(s) => s,
        None => demo_sequence()?,
    };
    open_window(
        &sequence,
        WindowStart {
            frame: args.frame,
            paused: args.paused,
            orbit: args.orbit,
        },
    )
}

/// `sylva replay SESSION --out DIR`.
pub fn replay_command(args: ReplayArgs) -> anyhow::Result<()> {
    let report = replay(&args.session, Some(&args.out), true, |_, _| {})?;
    println!("{}", report.summary_line());
    Ok(())
}
