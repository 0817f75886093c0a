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
    /// The earlier autosave the window offers back (until restored or dismissed).
    restore_offer: Option<crate::autosave::PreviousAutosave>,
}

/// Opens a window on `player` (recorded footage or a stream); returns an error when no window
/// can be created.
pub fn run_window(
    mut player: Player,
    session_path: PathBuf,
    first_frame: usize,
    paused: bool,
    orbit_view: bool,
    restore: bool,
) -> anyhow::Result<()> {
    let event_loop = EventLoop::new().context("cannot connect to a display")?;
    event_loop.set_control_flow(winit::event_loop::ControlFlow::Poll);
    player.frame = first_frame.min(player.footage.len().saturating_sub(1));
    player.ui.orbit_view = orbit_view;
    player.ui.playing = !paused;
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
    if restore {
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
        meshed_revision: None,
        tree_mesher: Default::default(),
        orbit: None,
        uploaded_frame: None,
        started: Instant::now(),
        session_path,
        autosaver,
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
    let mut config = surface
        .get_default_config(&gpu.adapter, size.width.max(1), size.height.max(1))
        .context("the window surface is not supported by the adapter")?;
    let caps = surface.get_capabilities(&gpu.adapter);
    if let Some(srgb) = caps.formats.iter().copied().find(|f| f.is_srgb()) {
        config.format = srgb;
    }
    config.present_mode = wgpu::PresentMode::AutoVsync;
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
        match create_gfx(event_loop) {
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
    fn redraw(&mut self) -> anyhow::Result<()> {
        let Some(gfx) = self.gfx.as_mut() else {
            return Ok(());
        };
        let elapsed = self.started.elapsed().as_secs_f64();
        self.player.tick(elapsed)?;
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

        let raw = gfx.egui_state.take_egui_input(&gfx.window);
        let intrinsics = self.player.footage.intrinsics;
        let player = &mut self.player;
        let orbit = &mut self.orbit;
        let restore_offer = &mut self.restore_offer;
        let output = gfx.egui_ctx.run_ui(raw, |ui| {
            let mut events = Vec::new();
            let view = crate::ui::sylva_ui(ui, &mut player.ui, &player.design, &mut events);
            crate::autosave::restore_prompt_ui(ui, restore_offer, &mut events);
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
        if self.player.ui.export_requested {
            self.player.ui.export_requested = false;
            let path = crate::player::export_tree(&self.player.design, Path::new("out"))?;
            println!("exported {}", path.display());
        }
        Ok(())
    }
}
