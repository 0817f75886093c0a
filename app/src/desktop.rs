//! The desktop window (winit + wgpu + egui): plays footage, shows the AR view with the tree and
//! the UI, and records a session of everything the user does.
//!
//! Seeking ahead of what the tracker has seen never freezes the window: recorded footage is
//! tracked once, in order, so a seek past the last tracked frame fast-forwards to it, showing
//! the frames on the way (each tracked once; at most [`SEEK_BUDGET`] of them per redraw) with a
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
use crate::player::Player;
use crate::render::resources::letterbox;
use crate::render::{FrameView, Gpu, Renderer};

struct Gfx {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    gpu: Gpu,
    renderer: Renderer,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
}

struct DesktopApp {
    player: Player,
    gfx: Option<Gfx>,
    error: Option<anyhow::Error>,
    meshed_revision: Option<u64>,
    tree_mesher: crate::tree_model::TreeMesher,
    /// The camera of the 3D view outside AR (framed on the tree when the view opens).
    orbit: Option<crate::ui::orbit::OrbitCamera>,
    /// Footage frame whose image and occluder the renderer holds.
    uploaded_frame: Option<(usize, Option<glam::Affine3A>)>,
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
}

/// How long a redraw may spend catching up a seek before it draws (the window shows the
/// progress at least this often, and few redraws keep the catching up quick where drawing is
/// slow, as on a software renderer).
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
}

impl Default for WindowOptions {
    fn default() -> Self {
        WindowOptions {
            first_frame: 0,
            paused: false,
            orbit_view: false,
            size: (1120, 720),
            frame_report: None,
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
        meshed_revision: None,
        tree_mesher: Default::default(),
        orbit: None,
        uploaded_frame: None,
        started: Instant::now(),
        session_path,
        autosaver,
        seek_target: (first_frame > 0 && !live).then_some(first_frame),
        tracked_until: None,
        frame_times: options.frame_report.map(FrameTimes::new),
        window_size: options.size,
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
    let mut config = surface
        .get_default_config(&gpu.adapter, size.width.max(1), size.height.max(1))
        .context("the window surface is not supported by the adapter")?;
    let caps = surface.get_capabilities(&gpu.adapter);
    if let Some(srgb) = caps.formats.iter().copied().find(|f| f.is_srgb()) {
        config.format = srgb;
    }
    // Mailbox shows the newest frame without tearing and without the UI thread waiting for a
    // vertical blank; FIFO where the surface offers nothing else.
    config.present_mode = if caps.present_modes.contains(&wgpu::PresentMode::Mailbox) {
        wgpu::PresentMode::Mailbox
    } else {
        wgpu::PresentMode::AutoVsync
    };
    surface.configure(&gpu.device, &config);
    let renderer = Renderer::new(&gpu, config.format);
    let egui_ctx = egui::Context::default();
    let egui_state = egui_winit::State::new(
        egui_ctx.clone(),
        egui::ViewportId::ROOT,
        &window,
        Some(window.scale_factor() as f32),
        None,
        Some(gpu.device.limits().max_texture_dimension_2d as usize),
    );
    let egui_renderer = egui_wgpu::Renderer::new(&gpu.device, config.format, Default::default());
    Ok(Gfx {
        window,
        surface,
        config,
        gpu,
        renderer,
        egui_ctx,
        egui_state,
        egui_renderer,
    })
}

impl ApplicationHandler for DesktopApp {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gfx.is_some() {
            return;
        }
        match create_gfx(event_loop, self.window_size) {
            Ok(gfx) => {
                // A new renderer holds nothing yet.
                self.gfx = Some(gfx);
                self.uploaded_frame = None;
                self.meshed_revision = None;
            }
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
                gfx.config.width = size.width.max(1);
                gfx.config.height = size.height.max(1);
                gfx.surface.configure(&gfx.gpu.device, &gfx.config);
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.redraw() {
                    self.error = Some(e);
                    event_loop.exit();
                }
                let size = self
                    .gfx
                    .as_ref()
                    .map_or((0, 0), |g| (g.config.width, g.config.height));
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
                loop {
                    let next = match self.tracked_until {
                        None => 0,
                        // Frames up to the last tracked one are cached: jump there.
                        Some(last) if self.player.frame < last => last,
                        Some(_) => self.player.frame + 1,
                    };
                    self.player.show_frame(next.min(target))?;
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
        let frame = match gfx.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t)
            | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                gfx.surface.configure(&gfx.gpu.device, &gfx.config);
                return Ok(());
            }
            _ => return Ok(()),
        };
        let target = frame.texture.create_view(&Default::default());
        let size = (gfx.config.width, gfx.config.height);
        let render_started = Instant::now();
        let mut encoder = gfx.gpu.device.create_command_encoder(&Default::default());
        if self.player.ui.orbit_view {
            // Outside AR: the tree alone on a lawn, seen by the orbiting camera.
            let tree = &self.player.design.tree;
            if self.meshed_revision != Some(self.player.design.revision) {
                let t = Instant::now();
                gfx.renderer.set_tree(&gfx.gpu, self.tree_mesher.mesh(tree));
                self.player.ui.budget.meshing_ms = t.elapsed().as_secs_f32() * 1000.0;
                self.meshed_revision = Some(self.player.design.revision);
            }
            let drawn = self.tree_mesher.current();
            let orbit = *self.orbit.get_or_insert_with(|| {
                let (min, max) = drawn
                    .bounds()
                    .unwrap_or((glam::Vec3::ZERO, glam::Vec3::ONE));
                crate::ui::orbit::OrbitCamera::framing(min, max)
            });
            let camera = orbit.camera(self.player.footage.intrinsics);
            gfx.renderer.render(
                &gfx.gpu,
                &mut encoder,
                &target,
                size,
                &FrameView::tree_only(camera),
            );
        } else if let Some(camera) = self.player.camera_in_tree() {
            // The frame is drawn in tree space (the tree's mesh is), after planting.
            let revision = Some(self.player.design.revision)
                .filter(|_| self.player.ui.ground_found && self.player.design.is_planted());
            if self.meshed_revision != revision {
                let t = Instant::now();
                match revision {
                    Some(_) => gfx.renderer.set_tree(
                        &gfx.gpu,
                        self.tree_mesher
                            .mesh_in(&self.player.design.tree, self.player.design.params.season),
                    ),
                    None => gfx.renderer.set_tree(&gfx.gpu, &Default::default()),
                }
                self.player.ui.budget.meshing_ms = t.elapsed().as_secs_f32() * 1000.0;
                self.meshed_revision = revision;
            }
            // The footage image and the occluder change with the shown frame, not per redraw.
            let placed = (self.player.frame, self.player.design.world_from_tree);
            if self.uploaded_frame != Some(placed) {
                if let Some(image) = &self.player.image {
                    gfx.renderer.set_camera_image(
                        &gfx.gpu,
                        image.as_raw(),
                        self.player.footage.intrinsics,
                    );
                }
                if let Some(scene) = self.player.scene() {
                    let occluder = crate::planting::occluder_in_tree(
                        &scene.occluder,
                        &self.player.design.tree_from_world(),
                    );
                    gfx.renderer.set_occluder(&gfx.gpu, &occluder);
                }
                self.uploaded_frame = Some(placed);
            }
            let mut view = FrameView::augmented(camera, self.player.ground_in_tree());
            view.debug.depth_wireframe = self.player.ui.show_debug;
            view.debug.brush = self.player.brush_sphere();
            gfx.renderer
                .render(&gfx.gpu, &mut encoder, &target, size, &view);
        }
        self.player.ui.budget.render_ms = render_started.elapsed().as_secs_f32() * 1000.0;
        let ui_started = Instant::now();

        let raw = gfx.egui_state.take_egui_input(&gfx.window);
        let intrinsics = self.player.footage.intrinsics;
        let player = &mut self.player;
        let orbit = &mut self.orbit;
        let output = gfx.egui_ctx.run_ui(raw, |ui| {
            let mut events = Vec::new();
            let view = crate::ui::sylva_ui(ui, &mut player.ui, &player.design, &mut events);
            match orbit.as_mut().filter(|_| player.ui.orbit_view) {
                Some(orbit) => {
                    let focal =
                        letterbox(size, &intrinsics)[2] / intrinsics.width as f32 * intrinsics.fx;
                    crate::ui::orbit::orbit_view_ui(ui, view, orbit, focal);
                }
                None => crate::ui::touch::view_touches_ui(ui, view, size, &intrinsics, &mut events),
            }
            for e in events {
                player.input(e);
            }
        });
        gfx.egui_state
            .handle_platform_output(&gfx.window, output.platform_output);
        let ppp = output.pixels_per_point;
        let jobs = gfx.egui_ctx.tessellate(output.shapes, ppp);
        let ui_ms = ui_started.elapsed().as_secs_f32() * 1000.0;
        let present_started = Instant::now();
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [size.0, size.1],
            pixels_per_point: ppp,
        };
        for (id, delta) in &output.textures_delta.set {
            for d in delta {
                gfx.egui_renderer
                    .update_texture(&gfx.gpu.device, &gfx.gpu.queue, *id, d);
            }
        }
        let callbacks = gfx.egui_renderer.update_buffers(
            &gfx.gpu.device,
            &gfx.gpu.queue,
            &mut encoder,
            &jobs,
            &screen,
        );
        {
            let load = if self.player.ui.orbit_view || self.player.camera().is_some() {
                wgpu::LoadOp::Load
            } else {
                wgpu::LoadOp::Clear(wgpu::Color::BLACK)
            };
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("egui"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load,
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            gfx.egui_renderer
                .render(&mut pass.forget_lifetime(), &jobs, &screen);
        }
        for id in &output.textures_delta.free {
            gfx.egui_renderer.free_texture(id);
        }
        gfx.gpu
            .queue
            .submit(callbacks.into_iter().chain([encoder.finish()]));
        gfx.gpu.queue.present(frame);
        if let Some(times) = self.frame_times.as_mut() {
            let sample = FrameSample {
                frame_ms,
                update_ms,
                render_ms: self.player.ui.budget.render_ms,
                ui_ms,
                present_ms: present_started.elapsed().as_secs_f32() * 1000.0,
                seeking,
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
