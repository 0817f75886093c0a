//! `sylva`, the lean front: growing a tree (`species`, `grow`, `garden`) needs sylva-core and
//! the command line only, so this binary links nothing of the renderer, the UI or OpenCV and
//! starts in a few milliseconds. Every other subcommand (and no subcommand: the demo, `--help`)
//! runs the full app, `sylva-app` next to this binary, with the same arguments.

use std::ffi::OsString;
use std::path::PathBuf;

use clap::Parser;

// The growth commands' own sources, shared with the full app's library.
#[path = "../cli_growth.rs"]
mod cli_growth;
#[path = "../cmd_garden.rs"]
mod cmd_garden;
#[path = "../cmd_grow.rs"]
mod cmd_grow;
#[path = "../limits.rs"]
mod limits;
// Writing helpers of the whole app; the growth commands use some of them.
#[allow(dead_code)]
#[path = "../outputs.rs"]
mod outputs;

#[derive(Parser, Debug)]
#[command(name = "sylva", version, about = "Grow trees in augmented reality")]
struct Lean {
    #[command(subcommand)]
    command: cli_growth::GrowthCommand,
}

/// The full app's binary: `sylva-app` in this binary's folder.
fn full_app() -> anyhow::Result<PathBuf> {
    let me = std::env::current_exe()
        .map_err(|e| anyhow::anyhow!("cannot find the sylva binary's own path: {e}"))?;
    Ok(me.with_file_name(format!("sylva-app{}", std::env::consts::EXE_SUFFIX)))
}

/// Runs the full app with `args` in place of this process (Unix) or as a child whose exit
/// status becomes this one's.
fn run_full_app(args: Vec<OsString>) -> anyhow::Result<()> {
    let app = full_app()?;
    let mut command = std::process::Command::new(&app);
    command.args(args);
    #[cfg(unix)]
    {
        use std::os::unix::process::CommandExt;
        let error = command.exec();
        anyhow::bail!(
            "cannot run the full Sylva app {} (it is installed next to sylva): {error}",
            app.display()
        )
    }
    #[cfg(not(unix))]
    {
        let status = command.status().map_err(|error| {
            anyhow::anyhow!(
                "cannot run the full Sylva app {} (it is installed next to sylva): {error}",
                app.display()
            )
        })?;
        std::process::exit(status.code().unwrap_or(1))
    }
}

fn main() -> anyhow::Result<()> {
    let args: Vec<OsString> = std::env::args_os().skip(1).collect();
    let growth = args
        .first()
        .and_then(|a| a.to_str())
        .is_some_and(|a| cli_growth::GROWTH_COMMANDS.contains(&a));
    if !growth {
        return run_full_app(args);
    }
    cli_growth::run(Lean::parse().command)
}
