//! The subcommands that only grow trees (`species`, `grow`, `garden`): sylva-core and the
//! command line, nothing of the renderer, the UI or OpenCV. Both binaries run them: the lean
//! `sylva` front (app/src/front) without loading the full app, and `sylva-app`.

use clap::Subcommand;

#[derive(Subcommand, Debug)]
pub enum GrowthCommand {
    /// One line per species preset, starting with its name.
    Species,
    /// Grows a tree autonomously and saves it; ends with a key=value summary line.
    Grow(crate::cmd_grow::GrowArgs),
    /// Plants several trees and grows them together, competing for light and space; ends with a
    /// key=value summary line.
    Garden(crate::cmd_garden::GardenArgs),
}

/// The subcommand names of [`GrowthCommand`], as typed.
pub const GROWTH_COMMANDS: [&str; 3] = ["species", "grow", "garden"];

pub fn run(command: GrowthCommand) -> anyhow::Result<()> {
    match command {
        GrowthCommand::Species => crate::cmd_grow::species(),
        GrowthCommand::Grow(args) => crate::cmd_grow::grow(args),
        GrowthCommand::Garden(args) => crate::cmd_garden::garden(args),
    }
}
