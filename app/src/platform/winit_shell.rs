//! The event loop the phone shells run (winit's Android and iOS backends): a full-screen
//! window whose surface comes and goes with the app's lifecycle, touches passed on, one camera
//! frame polled and one frame drawn per redraw, the tree autosaved. The design, the GPU and the
//! session live across pauses; only the window's surface is recreated.

use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

use super::{
    DisplayTransform, FrameProvider, ShellApp, StorageLocation, TouchInput, TrackerChoice,
    WindowSurface,
};
use crate::render::Gpu;
use crate::state::TouchPhase;

/// Frames per second a phone camera is assumed to deliver.
pub const PHONE_FRAME_RATE_HZ: f64 = 30.0;

struct PhoneShell {
    provider: Box<dyn FrameProvider>,
    storage: StorageLocation,
    describe: String,
    /// Started at the first camera frame (its intrinsics fix the stream's camera).
    app: Option<ShellApp>,
    gpu: Option<Gpu>,
    window: Option<(Arc<Window>, WindowSurface)>,
    error: Option<anyhow::Error>,
}

/// Runs the app on `event_loop` with camera frames from `provider` (described as `describe`
/// in messages and the session), recording into `storage`; returns the session file once the
/// app exits.
pub fn run(
    event_loop: EventLoop<()>,
    provider: Box<dyn FrameProvider>,
    storage: StorageLocation,
    describe: &str,
) -> anyhow::Result<Option<std::path::PathBuf>> {
    event_loop.set_control_flow(winit::event_loop::ControlFlow::Poll);
    let mut shell = PhoneShell {
        provider,
        storage,
        describe: describe.to_owned(),
        app: None,
        gpu: None,
        window: None,
        error: None,
    };
    event_loop
        .run_app(&mut shell)
        .context("the app's event loop failed")?;
    let finished = shell.app.take().map(ShellApp::finish).transpose();
    match shell.error {
        Some(error) => Err(error),
        None => finished,
    }
}

impl PhoneShell {
    fn open_window(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<()> {
        let window = Arc::new(
            event_loop
                .create_window(Window::default_attributes().with_title("Sylva"))
                .context("cannot create the app's window")?,
        );
        let surface = match &self.gpu {
            Some(gpu) => gpu.instance.create_surface(window.clone()),
            None => {
                let instance = wgpu::Instance::new(
                    wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
                        window.clone(),
                    )),
                );
                let surface = instance.create_surface(window.clone());
                if let Ok(surface) = &surface {
                    self.gpu = Some(Gpu::with_instance(instance, Some(surface))?);
                }
                surface
            }
        }
        .context("cannot create a drawing surface for the window")?;
        let gpu = self.gpu.as_ref().context("no GPU")?;
        let size = window.inner_size();
        let surface = WindowSurface::new(
            gpu,
            surface,
            (size.width, size.height),
            window.scale_factor() as f32,
        )?;
        self.window = Some((window, surface));
        Ok(())
    }

    fn redraw(&mut self) -> anyhow::Result<()> {
        if let Some(frame) = self.provider.poll_frame()? {
            if self.app.is_none() {
                let choice = match frame.tracking {
                    Some(_) => TrackerChoice::Platform,
                    None => TrackerChoice::Own,
                };
                self.app = Some(ShellApp::start(
                    &self.storage,
                    frame.intrinsics,
                    PHONE_FRAME_RATE_HZ,
                    choice,
                    &self.describe,
                )?);
            }
            if let Some(app) = self.app.as_mut() {
                app.frame(frame)?;
            }
        }
        let (Some(app), Some(gpu), Some((_, surface))) =
            (self.app.as_mut(), self.gpu.as_ref(), self.window.as_mut())
        else {
            return Ok(());
        };
        if let Err(error) = app.poll_autosave(Instant::now()) {
            eprintln!("warning: {error:#}");
        }
        // The camera as a phone shows it: upright (the turn follows the phone's rotation),
        // filling the screen.
        app.set_display(DisplayTransform::phone(
            self.provider.display_quarter_turns_cw(),
        ));
        app.draw(gpu, surface)?;
        Ok(())
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, error: anyhow::Error) {
        eprintln!("error: {error:#}");
        self.error = Some(error);
        event_loop.exit();
    }
}

impl ApplicationHandler for PhoneShell {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        let resumed = self
            .open_window(event_loop)
            .and_then(|()| self.provider.resume());
        match resumed {
            Ok(()) => {
                if let Some(app) = self.app.as_mut() {
                    app.resume();
                }
            }
            Err(error) => self.fail(event_loop, error),
        }
    }

    fn suspended(&mut self, event_loop: &ActiveEventLoop) {
        // The window (and its surface) is about to go: the design is saved and kept.
        self.window = None;
        let paused = self
            .app
            .as_mut()
            .map_or(Ok(()), ShellApp::pause)
            .and_then(|()| self.provider.pause());
        if let Err(error) = paused {
            self.fail(event_loop, error);
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                // Rotation too: the surface follows, the design is untouched.
                if let (Some(gpu), Some((window, surface))) = (&self.gpu, self.window.as_mut()) {
                    surface.resize(gpu, (size.width, size.height), window.scale_factor() as f32);
                }
            }
            WindowEvent::Touch(touch) => {
                let phase = match touch.phase {
                    winit::event::TouchPhase::Started => TouchPhase::Start,
                    winit::event::TouchPhase::Moved => TouchPhase::Move,
                    winit::event::TouchPhase::Ended | winit::event::TouchPhase::Cancelled => {
                        TouchPhase::End
                    }
                };
                if let Some(app) = self.app.as_mut() {
                    app.touch(TouchInput {
                        phase,
                        id: touch.id,
                        x_px: touch.location.x as f32,
                        y_px: touch.location.y as f32,
                    });
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(error) = self.redraw() {
                    self.fail(event_loop, error);
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some((window, _)) = &self.window {
            window.request_redraw();
        }
    }
}
