//! `sylva` (the demo), `sylva view`, `sylva replay`.

use std::path::{Path, PathBuf};

use anyhow::{Context, bail};

use crate::footage::Footage;
use crate::session::replay;

/// The bundled demo sequence, relative to the workspace root.
pub const DEMO_SEQUENCE: &str = "test-data/demo_yard";

#[derive(clap::Args, Debug)]
pub struct ReplayArgs {
    /// Session file (JSON) to replay.
    pub session: PathBuf,
    /// Folder for composited PNG frames and the final tree (empty, or new).
    #[arg(long)]
    pub out: PathBuf,
    /// Replay into a folder that is not empty, removing the frames, tree and placement an
    /// earlier replay wrote there (other files are left).
    #[arg(long)]
    pub force: bool,
}

#[derive(clap::Args, Debug)]
pub struct ViewArgs {
    /// Recorded sequence (TUM layout folder) or a video file (.mp4, .avi, …).
    pub sequence: Option<PathBuf>,
    /// Live camera index instead of a recorded sequence.
    #[arg(long, conflicts_with = "sequence")]
    pub camera: Option<u32>,
    /// Intrinsics of the camera or video (`camera.txt` format); without it a 60° horizontal
    /// field of view is assumed.
    #[arg(long)]
    pub calibration: Option<PathBuf>,
    /// Record the camera or video frames shown into this folder (TUM layout) with the session
    /// (`session.json`), so `sylva view DIR` and `sylva replay DIR/session.json` open it.
    #[arg(long)]
    pub record: Option<PathBuf>,
    /// Start at this frame (recorded sequences).
    #[arg(long, default_value_t = 0)]
    pub frame: usize,
    /// Start paused.
    #[arg(long)]
    pub paused: bool,
    /// Start in the 3D view outside AR (orbit, pan, zoom) instead of the camera view.
    #[arg(long)]
    pub orbit: bool,
    /// Plant the tree at the world origin as soon as the ground is found (a tap there, recorded
    /// in the session) instead of waiting for the user's tap.
    #[arg(long)]
    pub plant_at_origin: bool,
    /// Restore the earlier autosaved design (`out/last-session.1.tree.json`, kept when the window
    /// starts) instead of starting from a sapling; the window also offers it with a button.
    #[arg(long)]
    pub restore: bool,
    /// Measure this many redraws while the footage plays and the tracker runs, print the
    /// frame-time report (median and 95th percentile, ms per frame) and close the window.
    #[arg(long, value_name = "N")]
    pub frame_report: Option<usize>,
    /// The window's inner size, logical pixels.
    #[arg(long, value_name = "WIDTHxHEIGHT", default_value = "1120x720", value_parser = parse_window_size)]
    pub window_size: (u32, u32),
}

/// `1280x800` → (1280, 800).
fn parse_window_size(text: &str) -> Result<(u32, u32), String> {
    let parsed = text
        .split_once(['x', 'X'])
        .and_then(|(w, h)| Some((w.trim().parse::<u32>().ok()?, h.trim().parse::<u32>().ok()?)));
    match parsed {
        Some((w, h)) if (64..=16384).contains(&w) && (64..=16384).contains(&h) => Ok((w, h)),
        _ => Err(format!(
            "expected WIDTHxHEIGHT in pixels from 64 to 16384, such as 1280x800; got {text:?}"
        )),
    }
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
    let session = crate::demo_script::yard_session(&footage, sequence.clone())?;
    // The demo's own folder: an earlier demo's frames are removed, not left beside the new ones.
    crate::outputs::prepare_replay_folder(&out, true)?;
    let session_path = out.join("demo-session.json");
    let mut absolute = session.clone();
    absolute.footage = std::fs::canonicalize(&sequence).unwrap_or(sequence);
    // The first impression at the footage's own size (recorded sessions keep their smaller one).
    absolute.frame_size = [footage.intrinsics.width, footage.intrinsics.height];
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
    window: crate::desktop::WindowOptions,
    plant_at_origin: bool,
}

fn open_window(sequence: &Path, start: WindowStart) -> anyhow::Result<()> {
    let footage = Footage::open(sequence)?;
    std::fs::create_dir_all("out").context("cannot create out/")?;
    let session_path = PathBuf::from("out/last-session.json");
    let footage_ref = std::fs::canonicalize(sequence).unwrap_or_else(|_| sequence.to_owned());
    let mut player = crate::player::Player::new(footage, footage_ref)?;
    player.plant_at_origin = start.plant_at_origin;
    crate::desktop::run_window(player, session_path, start.window)
}

/// What `sylva view` plays.
#[derive(Clone, Debug, PartialEq)]
pub enum ViewSource {
    /// A TUM-layout folder.
    Recorded(PathBuf),
    /// A live camera by index.
    Camera(u32),
    /// A video file.
    Video(PathBuf),
}

impl ViewArgs {
    /// How the window opens.
    pub fn window_options(&self) -> crate::desktop::WindowOptions {
        crate::desktop::WindowOptions {
            first_frame: self.frame,
            paused: self.paused,
            orbit_view: self.orbit,
            size: self.window_size,
            frame_report: self.frame_report,
            restore: self.restore,
        }
    }

    /// The source these arguments name (the demo without any), checking that the stream-only
    /// options are given with a stream.
    pub fn source(&self) -> anyhow::Result<ViewSource> {
        let source = match (&self.sequence, self.camera) {
            (_, Some(index)) => ViewSource::Camera(index),
            // A file, or an image pattern such as `frames/%04d.png` that videoio reads.
            (Some(path), None) if path.is_file() || path.to_string_lossy().contains('%') => {
                ViewSource::Video(path.clone())
            }
            (Some(path), None) if !path.exists() => bail!(
                "{} does not exist (expected a sequence folder or a video file)",
                path.display()
            ),
            (Some(path), None) => ViewSource::Recorded(path.clone()),
            (None, None) => ViewSource::Recorded(demo_sequence()?),
        };
        if let ViewSource::Recorded(folder) = &source {
            let option = match (&self.calibration, &self.record) {
                (Some(_), _) => Some("--calibration"),
                (None, Some(_)) => Some("--record"),
                (None, None) => None,
            };
            if let Some(option) = option {
                bail!(
                    "{option} applies to a live camera or a video file; {} is a recorded sequence (it has its own camera.txt and is replayable as it is)",
                    folder.display()
                );
            }
        } else if self.frame != 0 {
            bail!(
                "--frame applies to recorded sequences; a camera or video stream starts at its first frame"
            );
        }
        Ok(source)
    }
}

/// `sylva view SEQUENCE` / `sylva view VIDEO` / `sylva view --camera N`.
pub fn view(args: ViewArgs) -> anyhow::Result<()> {
    let sequence = match args.source()? {
        ViewSource::Recorded(folder) => folder,
        ViewSource::Camera(index) => return open_stream(StreamSource::Camera(index), &args),
        ViewSource::Video(path) => return open_stream(StreamSource::File(path), &args),
    };
    open_window(
        &sequence,
        WindowStart {
            window: args.window_options(),
            plant_at_origin: args.plant_at_origin,
        },
    )
}

#[cfg(not(any(target_os = "android", target_os = "ios")))]
use crate::live_capture::StreamInput as StreamSource;

/// Phone builds have no videoio streams.
#[cfg(any(target_os = "android", target_os = "ios"))]
enum StreamSource {
    Camera(u32),
    File(PathBuf),
}

/// Opens a stream for the player with the options of `args` (calibration, recording); with
/// `--record DIR` the session is `DIR/session.json` and references `DIR` as its footage.
#[cfg(not(any(target_os = "android", target_os = "ios")))]
pub fn stream_player(
    input: StreamSource,
    args: &ViewArgs,
) -> anyhow::Result<(crate::player::Player, PathBuf)> {
    let stream = crate::live_capture::VideoStream::open(input, args.calibration.as_deref())?;
    let mut player = crate::player::Player::live(Box::new(stream), args.record.as_deref())?;
    let session_path = match &args.record {
        Some(dir) => {
            // The session lies in its footage folder: the pair can move together.
            player.session.footage = PathBuf::from(".");
            dir.join("session.json")
        }
        None => PathBuf::from("out/last-session.json"),
    };
    Ok((player, session_path))
}

#[cfg(not(any(target_os = "android", target_os = "ios")))]
fn open_stream(input: StreamSource, args: &ViewArgs) -> anyhow::Result<()> {
    let (mut player, session_path) = stream_player(input, args)?;
    player.plant_at_origin = args.plant_at_origin;
    if let Some(dir) = args.record.as_ref() {
        eprintln!("recording the frames shown into {}", dir.display());
    }
    let options = crate::desktop::WindowOptions {
        first_frame: 0,
        ..args.window_options()
    };
    crate::desktop::run_window(player, session_path, options)
}

#[cfg(any(target_os = "android", target_os = "ios"))]
fn open_stream(input: StreamSource, _args: &ViewArgs) -> anyhow::Result<()> {
    let what = match input {
        StreamSource::Camera(index) => format!("camera {index}"),
        StreamSource::File(path) => path.display().to_string(),
    };
    bail!("{what}: streams are read with OpenCV's videoio, which phone builds leave out")
}

/// `sylva replay SESSION --out DIR`.
pub fn replay_command(args: ReplayArgs) -> anyhow::Result<()> {
    let outputs = ["tree.json", "tree.glb", "placement.json"].map(|name| args.out.join(name));
    crate::outputs::check_outputs(&[&args.session], &outputs.each_ref().map(PathBuf::as_path))?;
    crate::outputs::prepare_replay_folder(&args.out, args.force)?;
    let report = replay(&args.session, Some(&args.out), true, |_, _| {})?;
    println!("{}", report.summary_line());
    Ok(())
}
