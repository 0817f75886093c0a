//! The desktop window (winit + wgpu + egui): plays footage, shows the AR view with the tree and
//! the UI, and records a session of everything the user does.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

use crate::platform::{DrawSurface, ViewDrawer, WindowSurface};
use crate::player::Player;
use crate::render::Gpu;

struct Gfx {
    window: Arc<Window>,
    surface: WindowSurface,
    gpu: Gpu,
    drawer: ViewDrawer,
    egui_state: egui_winit::State,
}

struct DesktopApp {
    player: Player,
    gfx: Option<Gfx>,
    error: Option<anyhow::Error>,
    started: Instant,
    session_path: PathBuf,
    autosaver: crate::autosave::Autosaver,
}

/// Opens a window on `player` (recorded footage or a stream); returns an error when no window
/// can be created.
pub fn run_window(
    mut player: Player,
    session_path: PathBuf,
    first_frame: usize,
    paused: bool,
    orbit_view: bool,
) -> anyhow::Result<()> {
    let event_loop = EventLoop::new().context("cannot connect to a display")?;
    event_loop.set_control_flow(winit::event_loop::ControlFlow::Poll);
    player.frame = first_frame.min(player.footage.len().saturating_sub(1));
    player.ui.orbit_view = orbit_view;
    player.ui.playing = !paused;
    let autosaver = crate::autosave::Autosaver::new(
        &session_path,
        !player.is_live(),
        crate::autosave::AUTOSAVE_INTERVAL,
    );
    println!("autosaving the tree to {}", autosaver.tree_path().display());
    let mut app = DesktopApp {
        player,
        gfx: None,
        error: None,
        started: Instant::now(),
        session_path,
        autosaver,
    };
    event_loop
        .run_app(&mut app)
        .context("window event loop failed")?;
    // Whatever happened, the tree is kept.
    let flushed = app.autosaver.flush(&app.player.design, &app.player.session);
    if let Some(error) = app.error {
        return Err(error);
    }
    flushed?;
    app.player.finish_recording()?;
    if !app.player.session_replayable() {
        println!("live session not saved (pass --record DIR to make it replayable)");
        return Ok(());
    }
    app.player.session.save(&app.session_path)?;
    println!("session recorded to {}", app.session_path.display());
    Ok(())
}

fn create_gfx(event_loop: &ActiveEventLoop) -> anyhow::Result<Gfx> {
    let attributes = Window::default_attributes()
        .with_title("Sylva")
        .with_inner_size(winit::dpi::LogicalSize::new(1120.0, 720.0));
    let window = Arc::new(
        event_loop
            .create_window(attributes)
            .context("cannot create a window")?,
    );
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(
        Box::new(window.clone()),
    ));
    let surface = instance
        .create_surface(window.clone())
        .context("cannot create a drawing surface for the window")?;
    let gpu = Gpu::with_instance(instance, Some(&surface))?;
    let size = window.inner_size();
    let surface = WindowSurface::new(
        &gpu,
        surface,
        (size.width, size.height),
        window.scale_factor() as f32,
    )?;
    let drawer = ViewDrawer::new(&gpu, surface.format());
    let egui_state = egui_winit::State::new(
        drawer.egui_ctx().clone(),
        egui::ViewportId::ROOT,
        &window,
        Some(window.scale_factor() as f32),
        None,
        Some(gpu.device.limits().max_texture_dimension_2d as usize),
    );
    Ok(Gfx {
        window,
        surface,
        gpu,
        drawer,
        egui_state,
    })
}

impl ApplicationHandler for DesktopApp {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() {
            return;
        }
        match create_gfx(event_loop) {
            Ok(gfx) => self.gfx = Some(gfx),
            Err(e) => {
                self.error = Some(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(gfx) = self.gfx.as_mut() else {
            return;
        };
        let _ = gfx.egui_state.on_window_event(&gfx.window, &event);
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                let scale = gfx.window.scale_factor() as f32;
                gfx.surface
                    .resize(&gfx.gpu, (size.width, size.height), scale);
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw() {
                    self.error = Some(e);
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Err(error) =
            self.autosaver
                .poll(Instant::now(), &self.player.design, &self.player.session)
        {
            eprintln!("warning: {error:#}");
        }
        if let Some(gfx) = &self.gfx {
            gfx.window.request_redraw();
        }
    }
}

impl DesktopApp {
    fn redraw(&mut self) -> anyhow::Result<()> {
        let Some(gfx) = self.gfx.as_mut() else {
            return Ok(());
        };
        let elapsed = self.started.elapsed().as_secs_f64();
        self.player.tick(elapsed)?;
        let Some(target) = gfx.surface.begin_frame(&gfx.gpu)? else {
            return Ok(());
        };
        let raw = gfx.egui_state.take_egui_input(&gfx.window);
        let size = gfx.surface.size_px();
        let output = gfx
            .drawer
            .draw(&gfx.gpu, &mut self.player, &target, size, raw);
        gfx.egui_state.handle_platform_output(&gfx.window, output);
        gfx.surface.end_frame(&gfx.gpu)?;
        if self.player.ui.export_requested {
            self.player.ui.export_requested = false;
            let path = crate::player::export_tree(&self.player.design, Path::new("out"))?;
            println!("exported {}", path.display());
        }
        Ok(())
    }
}
