//! The desktop window (winit + wgpu + egui): plays footage, shows the AR view with the tree and
//! the UI, and records a session of everything the user does.
//!
//! Recorded footage is tracked on a worker thread ([`crate::tracking_worker`]): a redraw shows
//! the next frame once the tracker has it and never waits for it. Seeking ahead of what the
//! tracker has seen never freezes the window: frames are tracked once, in order, so a seek past
//! the last tracked frame asks the worker for the frames up to it and fast-forwards as they
//! come, showing the frames on the way (at most [`SEEK_BUDGET`] of them per redraw) with a
//! progress line, and a seek back jumps at once. `--frame-report N` measures the redraws
//! ([`crate::frame_report`]).

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

use crate::frame_report::{FrameSample, FrameTimes};
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
    /// The frame a seek is catching up to (recorded footage).
    seek_target: Option<usize>,
    /// Recorded footage is tracked up to this frame (the highest one shown).
    tracked_until: Option<usize>,
    frame_times: Option<FrameTimes>,
    /// Inner size the window opens at, logical pixels.
    window_size: (u32, u32),
    /// The earlier autosave the window offers back (until restored or dismissed).
    restore_offer: Option<crate::autosave::PreviousAutosave>,
}

/// How long a redraw may spend showing the tracked frames of a seek before it draws (the window
/// shows the progress at least this often).
pub const SEEK_BUDGET: std::time::Duration = std::time::Duration::from_millis(200);

/// How the window opens.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WindowOptions {
    /// Recorded footage: the frame to start at (reached by a seek, the window drawing).
    pub first_frame: usize,
    pub paused: bool,
    /// Start in the 3D view outside AR.
    pub orbit_view: bool,
    /// Inner size, logical pixels.
    pub size: (u32, u32),
    /// Measure this many redraws, print the frame-time report and close.
    pub frame_report: Option<usize>,
    /// Restore the earlier autosave (kept when the window starts) at once.
    pub restore: bool,
}

impl Default for WindowOptions {
    fn default() -> Self {
        WindowOptions {
            first_frame: 0,
            paused: false,
            orbit_view: false,
            size: (1120, 720),
            frame_report: None,
            restore: false,
        }
    }
}

/// Opens a window on `player` (recorded footage or a stream); returns an error when no window
/// can be created.
pub fn run_window(
    mut player: Player,
    session_path: PathBuf,
    options: WindowOptions,
) -> anyhow::Result<()> {
    let event_loop = EventLoop::new().context("cannot connect to a display")?;
    event_loop.set_control_flow(winit::event_loop::ControlFlow::Poll);
    let first_frame = options
        .first_frame
        .min(player.footage.len().saturating_sub(1));
    player.ui.orbit_view = options.orbit_view;
    player.ui.playing = !options.paused;
    let live = player.is_live();
    let mut autosaver = crate::autosave::Autosaver::new(
        &session_path,
        !player.is_live(),
        crate::autosave::AUTOSAVE_INTERVAL,
    );
    let mut restore_offer = autosaver.keep_previous(&player.design)?;
    if let Some(previous) = &restore_offer {
        println!(
            "the earlier design is kept in {}",
            previous.tree_path.display()
        );
    }
    if options.restore {
        let previous = restore_offer.take().with_context(|| {
            format!(
                "--restore: no earlier autosave beside {}",
                session_path.display()
            )
        })?;
        player.input(crate::autosave::restore_event(&previous.tree_path)?);
        println!("restored {}", previous.tree_path.display());
    }
    crate::autosave::exit_on_signals();
    println!("autosaving the tree to {}", autosaver.tree_path().display());
    let mut app = DesktopApp {
        player,
        gfx: None,
        error: None,
        started: Instant::now(),
        session_path,
        autosaver,
        seek_target: (first_frame > 0 && !live).then_some(first_frame),
        tracked_until: None,
        frame_times: options.frame_report.map(FrameTimes::new),
        window_size: options.size,
        restore_offer,
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

fn create_gfx(event_loop: &ActiveEventLoop, size: (u32, u32)) -> anyhow::Result<Gfx> {
    let attributes = Window::default_attributes()
        .with_title("Sylva")
        .with_inner_size(winit::dpi::LogicalSize::new(size.0, size.1));
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
    // On a CPU rasteriser the UI is drawn by the lean painter, and the AR view at the footage's
    // resolution stretched over the window.
    let adapter = gpu.adapter.get_info();
    let mut drawer = ViewDrawer::with_ui_painter(
        &gpu,
        surface.format(),
        crate::render::ui_painter::interactive_ui_painter(&adapter),
    );
    drawer.set_scene_resolution(crate::render::upscale::interactive_scene_resolution(
        &adapter,
    ));
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
        match create_gfx(event_loop, self.window_size) {
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
                let size = self.gfx.as_ref().map_or((0, 0), |g| g.surface.size_px());
                if let Some(times) = self.frame_times.as_ref().filter(|t| t.is_done()) {
                    if let Some(report) = times.report(size) {
                        print!("{report}");
                    }
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if crate::autosave::exit_requested() {
            event_loop.exit(); // a signal closes as the close button does: flushed below
            return;
        }
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
    /// Plays the footage to wall-clock time, or catches a seek up (recorded footage).
    fn update(&mut self) -> anyhow::Result<()> {
        if self.player.is_live() {
            return self.player.tick(self.started.elapsed().as_secs_f64());
        }
        let tracked = self.tracked_until;
        if let Some(target) = self
            .player
            .ui
            .seek_to
            .take_if(|t| tracked.is_none_or(|last| *t > last + 1))
        {
            self.seek_target = Some(target);
        }
        match self.seek_target {
            Some(target) => {
                let started = Instant::now();
                self.player.track_ahead_to(target);
                loop {
                    let next = match self.tracked_until {
                        None => 0,
                        // Frames up to the last tracked one are cached: jump there.
                        Some(last) if self.player.frame < last => last,
                        Some(_) => self.player.frame + 1,
                    }
                    .min(target);
                    if !self.player.frame_ready(next)? {
                        break; // the tracker is still on it: draw meanwhile
                    }
                    self.player.show_frame(next)?;
                    self.note_tracked();
                    if self.player.frame >= target || started.elapsed() >= SEEK_BUDGET {
                        break;
                    }
                }
                if self.player.frame >= target {
                    self.seek_target = None;
                }
            }
            None => {
                self.player.tick(self.started.elapsed().as_secs_f64())?;
                self.note_tracked();
            }
        }
        self.player.ui.seek_progress = self.seek_target.map(|t| (self.player.frame, t));
        Ok(())
    }

    fn note_tracked(&mut self) {
        if self.player.image.is_some() {
            self.tracked_until = self.tracked_until.max(Some(self.player.frame));
        }
    }

    fn redraw(&mut self) -> anyhow::Result<()> {
        let redraw_started = Instant::now();
        let process_cpu_s = self
            .frame_times
            .as_ref()
            .map_or(0.0, |_| crate::frame_report::process_cpu_s());
        let frame_ms = self
            .frame_times
            .as_mut()
            .map_or(0.0, |t| t.start(redraw_started));
        let seeking = self.seek_target.is_some();
        self.update()?;
        let update_ms = redraw_started.elapsed().as_secs_f32() * 1000.0;
        let Some(gfx) = self.gfx.as_mut() else {
            return Ok(());
        };
        let Some(target) = gfx.surface.begin_frame(&gfx.gpu)? else {
            return Ok(());
        };
        let raw = gfx.egui_state.take_egui_input(&gfx.window);
        let size = gfx.surface.size_px();
        let draw_started = Instant::now();
        let restore_offer = &mut self.restore_offer;
        let output = gfx.drawer.draw_with(
            &gfx.gpu,
            &mut self.player,
            &target,
            size,
            raw,
            |ui, events| crate::autosave::restore_prompt_ui(ui, restore_offer, events),
        );
        let draw_ms = draw_started.elapsed().as_secs_f32() * 1000.0;
        gfx.egui_state.handle_platform_output(&gfx.window, output);
        let present_started = Instant::now();
        gfx.surface.end_frame(&gfx.gpu)?;
        if let Some(times) = self.frame_times.as_mut() {
            let render_ms = self.player.ui.budget.render_ms;
            let sample = FrameSample {
                frame_ms,
                update_ms,
                render_ms,
                // The drawer runs the UI and submits after encoding the view.
                ui_ms: (draw_ms - render_ms).max(0.0),
                present_ms: present_started.elapsed().as_secs_f32() * 1000.0,
                seeking,
                scene_reused: gfx.drawer.scene_reused(),
                process_cpu_s,
            };
            times.record(sample, self.player.frame);
        }
        if self.player.ui.export_requested {
            self.player.ui.export_requested = false;
            let path = crate::player::export_tree(&self.player.design, Path::new("out"))?;
            println!("exported {}", path.display());
        }
        Ok(())
    }
}
