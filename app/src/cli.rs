//! The `sylva` command line.

use clap::{Parser, Subcommand};

#[derive(Parser, Debug)]
#[command(name = "sylva", version, about = "Grow trees in augmented reality")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// One line per species preset, starting with its name.
    Species,
    /// Grows a tree autonomously and saves it; ends with a key=value summary line.
    Grow(crate::cmd_grow::GrowArgs),
    /// Plants several trees and grows them together, competing for light and space; ends with a
    /// key=value summary line.
    Garden(crate::cmd_garden::GardenArgs),
    /// Replays a recorded session headlessly: composited PNG frames and the final tree in --out.
    Replay(crate::cmd_app::ReplayArgs),
    /// Opens a window on a recorded sequence, a video file or `--camera N`.
    View(crate::cmd_app::ViewArgs),
    /// Tracks a recorded sequence; prints timings and a key=value accuracy line.
    Track(crate::cmd_track::TrackArgs),
    /// Recreates an existing tree from footage and marks: measures it and grows a model into
    /// it; ends with a key=value summary line.
    Recreate(crate::cmd_recreate::RecreateArgs),
}

pub fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    match cli.command {
        Some(Command::Species) => crate::cmd_grow::species(),
        Some(Command::Grow(args)) => crate::cmd_grow::grow(args),
        Some(Command::Garden(args)) => crate::cmd_garden::garden(args),
        Some(Command::Replay(args)) => crate::cmd_app::replay_command(args),
        Some(Command::View(args)) => crate::cmd_app::view(args),
        Some(Command::Track(args)) => crate::cmd_track::track(args),
        Some(Command::Recreate(args)) => crate::cmd_recreate::recreate(args),
        None => crate::cmd_app::demo(),
    }
}
