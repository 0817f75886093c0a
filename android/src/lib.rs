//! # sylva-android
//!
//! Sylva's Android shell: `android_main` (a `NativeActivity` through android-activity and
//! winit's Android backend) runs the platform-neutral app library
//! ([`sylva_app::platform::winit_shell`]) with frames from ARCore ([`arcore`], through ARCore's
//! C API declared in [`arcore_ffi`]), recording sessions and autosaves into the app's internal
//! storage. The Gradle project around it is `android/app` (see the README, "On a phone").
//!
//! Spaces: ARCore's world (metres, Y up against gravity); its OpenGL-style camera poses become
//! Sylva's camera axes (X right, Y down, looking along +Z) in [`mapping`].
//!
//! Without ARCore the app says so and stops: Sylva's own tracker needs OpenCV, which the phone
//! builds leave out (issue #22, item 4).

pub mod mapping;

#[cfg(target_os = "android")]
mod arcore;
#[cfg(target_os = "android")]
mod arcore_ffi;
#[cfg(target_os = "android")]
mod egl;

/// The entry point the NativeActivity calls (through android-activity) on its own thread.
#[cfg(target_os = "android")]
#[unsafe(no_mangle)]
fn android_main(app: winit::platform::android::activity::AndroidApp) {
    if let Err(error) = run(app) {
        eprintln!("sylva: {error:#}");
    }
}

#[cfg(target_os = "android")]
fn run(app: winit::platform::android::activity::AndroidApp) -> anyhow::Result<()> {
    use anyhow::Context;
    use winit::platform::android::EventLoopBuilderExtAndroid;

    let storage = sylva_app::platform::StorageLocation::new(
        app.internal_data_path()
            .context("the app has no internal storage folder")?,
    );
    if !arcore::arcore_available(&app)? {
        anyhow::bail!(
            "this phone has no ARCore, and Sylva's own tracker needs OpenCV, which this build leaves out"
        );
    }
    let event_loop = winit::event_loop::EventLoop::builder()
        .with_android_app(app.clone())
        .build()
        .context("cannot start the app's event loop")?;
    let provider = Box::new(arcore::ArCoreProvider::new(app));
    if let Some(session) =
        sylva_app::platform::winit_shell::run(event_loop, provider, storage, "ARCore camera")?
    {
        eprintln!("sylva: session recorded to {}", session.display());
    }
    Ok(())
}
