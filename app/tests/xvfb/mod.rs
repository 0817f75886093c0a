//! A virtual X display for the window tests (Xvfb at 1280×800), and a child process killed
//! when dropped. Needs `Xvfb` (scripts/setup.sh installs it); fails loudly without.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

/// A child process killed (and reaped) when dropped.
pub struct Killed(pub Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Starts Xvfb on the first free display from `base` plus this process's id modulo 100;
/// returns it with the display's name (`:N`) once its socket is there.
pub fn start_xvfb(base: u32) -> (Killed, String) {
    let first = base + std::process::id() % 100;
    let number = (first..first + 100)
        .find(|n| !Path::new(&format!("/tmp/.X{n}-lock")).exists())
        .unwrap_or(first);
    let display = format!(":{number}");
    let child = Command::new("Xvfb")
        .args([
            display.as_str(),
            "-screen",
            "0",
            "1280x800x24",
            "-nolisten",
            "tcp",
        ])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("Xvfb is required for this test (apt-get install xvfb)");
    let socket = format!("/tmp/.X11-unix/X{number}");
    for _ in 0..100 {
        if Path::new(&socket).exists() {
            break;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    (Killed(child), display)
}
