//! # sylva-ios
//!
//! Sylva's iOS shell: a static library (`libsylva_ios.a`) whose `sylva_ios_main`, called from
//! the Xcode project's `main.m`, runs the platform-neutral app library in winit's iOS backend
//! ([`sylva_app::platform::winit_shell`], drawing with wgpu on Metal) with frames from ARKit
//! world tracking ([`arkit`], through objc2-ar-kit), recording sessions and autosaves into the
//! app's Documents folder. The Xcode project is generated from `ios/project.yml` (XcodeGen).
//!
//! Spaces: ARKit's world (metres, Y up against gravity); its OpenGL-style camera transforms
//! become Sylva's camera axes (X right, Y down, looking along +Z) in [`mapping`].

pub mod mapping;

#[cfg(target_os = "ios")]
mod arkit;

/// The app's entry point, called from `main.m`; never returns (winit's iOS event loop takes
/// over the main thread).
#[cfg(target_os = "ios")]
#[unsafe(no_mangle)]
pub extern "C" fn sylva_ios_main() {
    if let Err(error) = run() {
        eprintln!("sylva: {error:#}");
    }
}

#[cfg(target_os = "ios")]
fn run() -> anyhow::Result<()> {
    use anyhow::Context;

    let event_loop = winit::event_loop::EventLoop::new().context("cannot start the event loop")?;
    let storage = sylva_app::platform::StorageLocation::new(documents_dir()?);
    let provider = Box::new(arkit::ArKitProvider::new()?);
    if let Some(session) =
        sylva_app::platform::winit_shell::run(event_loop, provider, storage, "ARKit camera")?
    {
        eprintln!("sylva: session recorded to {}", session.display());
    }
    Ok(())
}

/// The app's Documents folder (shared with the Files app through `UIFileSharingEnabled`).
#[cfg(target_os = "ios")]
fn documents_dir() -> anyhow::Result<std::path::PathBuf> {
    use objc2_foundation::{NSFileManager, NSSearchPathDirectory, NSSearchPathDomainMask};
    let manager = NSFileManager::defaultManager();
    let urls = manager.URLsForDirectory_inDomains(
        NSSearchPathDirectory::DocumentDirectory,
        NSSearchPathDomainMask::UserDomainMask,
    );
    let path = urls
        .firstObject()
        .and_then(|url| url.path())
        .ok_or_else(|| anyhow::anyhow!("the app has no Documents folder"))?;
    Ok(std::path::PathBuf::from(path.to_string()))
}
