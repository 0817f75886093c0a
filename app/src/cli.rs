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
    /// `species`, `grow` and `garden` (the lean `sylva` front runs them without this binary).
    #[command(flatten)]
    Growth(crate::cli_growth::GrowthCommand),
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
        Some(Command::Growth(command)) => crate::cli_growth::run(command),
        Some(Command::Replay(args)) => crate::cmd_app::replay_command(args),
        Some(Command::View(args)) => crate::cmd_app::view(args),
        Some(Command::Track(args)) => crate::cmd_track::track(args),
        Some(Command::Recreate(args)) => crate::cmd_recreate::recreate(args),
        None => crate::cmd_app::demo(),
    }
}
