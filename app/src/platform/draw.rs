//! Drawing one frame of the app into a surface texture: the AR view (camera image, occluder,
//! tree) or the 3D view outside AR, then the UI on top. Every shell draws through this, the
//! desktop window as much as the phones and the host tests.

use std::time::Instant;

use super::DisplayTransform;
use crate::player::Player;
use crate::render::resources::letterbox;
use crate::render::ui_painter::{UiPainter, UiPainterKind};
use crate::render::{FrameView, Gpu, Renderer};

/// What the renderer's camera image and occluder were made for: the footage frame, where the
/// tree stood, how the image was shown and the target's size.
type Uploaded = (usize, Option<glam::Affine3A>, DisplayTransform, (u32, u32));

/// The renderer, the UI's context and renderer, and what they hold of the design.
pub struct ViewDrawer {
    renderer: Renderer,
    egui_ctx: egui::Context,
    egui_renderer: egui_wgpu::Renderer,
    /// The lean painter that draws the UI instead of `egui_renderer` on a CPU rasteriser's
    /// window ([`UiPainterKind::Lean`]).
    lean_ui: Option<UiPainter>,
    tree_mesher: crate::tree_model::TreeMesher,
    /// The garden's other trees (drawn with the selected one).
    garden_mesher: crate::garden_view::GardenMesher,
    meshed_revision: Option<u64>,
    /// The camera of the 3D view outside AR (framed on the tree when the view opens).
    orbit: Option<crate::ui::orbit::OrbitCamera>,
    /// Footage frame whose image and occluder the renderer holds (and how the image was shown).
    uploaded_frame: Option<Uploaded>,
    /// How the camera image is shown (turned upright, filling the view on a phone).
    display: DisplayTransform,
    /// The last frame stretched the AR view drawn before instead of drawing it again.
    scene_reused: bool,
}

impl ViewDrawer {
    /// A drawer for surfaces of `format`, multisampled as suits the adapter for an interactive
    /// view ([`crate::render::interactive_sample_count`]: 4× on a GPU, 1× on a CPU rasteriser).
    pub fn new(gpu: &Gpu, format: wgpu::TextureFormat) -> ViewDrawer {
        ViewDrawer::with_ui_painter(gpu, format, UiPainterKind::EguiWgpu)
    }

    /// [`Self::new`] with the UI drawn by `painter` (the lean one on a CPU rasteriser's window,
    /// [`crate::render::ui_painter::interactive_ui_painter`]).
    pub fn with_ui_painter(
        gpu: &Gpu,
        format: wgpu::TextureFormat,
        painter: UiPainterKind,
    ) -> ViewDrawer {
        let samples = crate::render::interactive_sample_count(&gpu.adapter.get_info());
        ViewDrawer {
            renderer: Renderer::with_samples(gpu, format, samples),
            egui_ctx: egui::Context::default(),
            egui_renderer: egui_wgpu::Renderer::new(&gpu.device, format, Default::default()),
            lean_ui: (painter == UiPainterKind::Lean).then(|| UiPainter::new(&gpu.device, format)),
            tree_mesher: Default::default(),
            garden_mesher: Default::default(),
            meshed_revision: None,
            orbit: None,
            uploaded_frame: None,
            display: DisplayTransform::default(),
            scene_reused: false,
        }
    }

    /// Shows the camera image turned and cropped by `display` (a phone's display transform;
    /// the default shows it whole, as the desktop window does).
    pub fn set_display(&mut self, display: DisplayTransform) {
        self.display = display;
    }

    /// How the camera image is shown.
    pub fn display(&self) -> DisplayTransform {
        self.display
    }

    /// The UI's context (for a shell's input translation).
    pub fn egui_ctx(&self) -> &egui::Context {
        &self.egui_ctx
    }

    /// The surface format this drawer renders for.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.renderer.color_format()
    }

    /// Whether the last frame stretched the AR view it drew before (see
    /// [`Renderer::scene_reused`]).
    pub fn scene_reused(&self) -> bool {
        self.scene_reused
    }

    /// Draws the AR view at `resolution` (see [`crate::render::SceneResolution`]).
    pub fn set_scene_resolution(&mut self, resolution: crate::render::SceneResolution) {
        self.renderer.set_scene_resolution(resolution);
    }

    /// Draws the shown frame and the UI (fed `raw` input; its events go to the player) into
    /// `target` of `size` pixels and submits the work; returns the UI's platform output.
    pub fn draw(
        &mut self,
        gpu: &Gpu,
        player: &mut Player,
        target: &wgpu::TextureView,
        size: (u32, u32),
        raw: egui::RawInput,
    ) -> egui::PlatformOutput {
        self.draw_with(gpu, player, target, size, raw, |_, _| {})
    }

    /// [`Self::draw`] with a shell's own UI (e.g. the desktop's offer of an earlier autosave)
    /// drawn after the app's, its events going to the player too.
    pub fn draw_with(
        &mut self,
        gpu: &Gpu,
        player: &mut Player,
        target: &wgpu::TextureView,
        size: (u32, u32),
        raw: egui::RawInput,
        mut shell_ui: impl FnMut(&mut egui::Ui, &mut Vec<crate::state::InputEvent>),
    ) -> egui::PlatformOutput {
        let render_started = Instant::now();
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        self.draw_view(gpu, player, &mut encoder, target, size);
        player.ui.budget.render_ms = render_started.elapsed().as_secs_f32() * 1000.0;

        let intrinsics = player.footage.intrinsics;
        let display = self.display;
        let shown = display.shown_intrinsics(&intrinsics, size);
        let orbit = &mut self.orbit;
        let output = self.egui_ctx.run_ui(raw, |ui| {
            let mut events = Vec::new();
            let view = crate::ui::sylva_ui(ui, &mut player.ui, &player.design, &mut events);
            shell_ui(ui, &mut events);
            match orbit.as_mut().filter(|_| player.ui.orbit_view) {
                Some(orbit) => {
                    let focal =
                        letterbox(size, &intrinsics)[2] / intrinsics.width as f32 * intrinsics.fx;
                    crate::ui::orbit::orbit_view_ui(ui, view, orbit, focal);
                }
                None => {
                    // Touches land on the shown image; the design works in the sensor's.
                    let mut touches = Vec::new();
                    crate::ui::touch::view_touches_ui(ui, view, size, &shown, &mut touches);
                    let sensor = (intrinsics.width, intrinsics.height);
                    events.extend(touches.into_iter().map(|e| match e {
                        crate::state::InputEvent::Touch { phase, id, x, y } => {
                            let p =
                                display.sensor_from_shown_px(glam::Vec2::new(x, y), sensor, size);
                            crate::state::InputEvent::Touch {
                                phase,
                                id,
                                x: p.x,
                                y: p.y,
                            }
                        }
                        other => other,
                    }));
                }
            }
            for e in events {
                player.input(e);
            }
        });
        let ppp = output.pixels_per_point;
        let jobs = self.egui_ctx.tessellate(output.shapes, ppp);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [size.0, size.1],
            pixels_per_point: ppp,
        };
        let mut callbacks = Vec::new();
        match self.lean_ui.as_mut() {
            Some(painter) => {
                painter.set_textures(&gpu.device, &gpu.queue, &output.textures_delta);
                painter.prepare(&gpu.device, &gpu.queue, &jobs, size, ppp);
            }
            None => {
                for (id, deltas) in &output.textures_delta.set {
                    for delta in deltas {
                        self.egui_renderer
                            .update_texture(&gpu.device, &gpu.queue, *id, delta);
                    }
                }
                callbacks = self.egui_renderer.update_buffers(
                    &gpu.device,
                    &gpu.queue,
                    &mut encoder,
                    &jobs,
                    &screen,
                );
            }
        }
        {
            let load = if player.ui.orbit_view || player.camera().is_some() {
                wgpu::LoadOp::Load
            } else {
                wgpu::LoadOp::Clear(wgpu::Color::BLACK)
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("egui"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
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
            match &self.lean_ui {
                Some(painter) => painter.paint(&mut pass),
                None => self
                    .egui_renderer
                    .render(&mut pass.forget_lifetime(), &jobs, &screen),
            }
        }
        match self.lean_ui.as_mut() {
            Some(painter) => painter.free_textures(&output.textures_delta),
            None => {
                for id in &output.textures_delta.free {
                    self.egui_renderer.free_texture(id);
                }
            }
        }
        gpu.queue
            .submit(callbacks.into_iter().chain([encoder.finish()]));
        output.platform_output
    }

    /// The 3D part of the frame: the AR view after planting, or the tree alone outside AR.
    fn draw_view(
        &mut self,
        gpu: &Gpu,
        player: &mut Player,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        size: (u32, u32),
    ) {
        self.scene_reused = false;
        if player.ui.orbit_view {
            // Outside AR: the tree alone on a lawn, seen by the orbiting camera.
            let tree = &player.design.tree;
            if self.meshed_revision != Some(player.design.revision) {
                let t = Instant::now();
                self.renderer.set_tree(gpu, self.tree_mesher.mesh(tree));
                player.ui.budget.meshing_ms = t.elapsed().as_secs_f32() * 1000.0;
                self.meshed_revision = Some(player.design.revision);
            }
            self.garden_mesher
                .upload(gpu, &mut self.renderer, &player.design, true);
            let drawn = self.tree_mesher.current();
            let orbit = *self.orbit.get_or_insert_with(|| {
                let (min, max) = drawn
                    .bounds()
                    .unwrap_or((glam::Vec3::ZERO, glam::Vec3::ONE));
                crate::ui::orbit::OrbitCamera::framing(min, max)
            });
            let camera = orbit.camera(player.footage.intrinsics);
            self.renderer
                .render(gpu, encoder, target, size, &FrameView::tree_only(camera));
            self.scene_reused = self.renderer.scene_reused();
        } else if let Some(camera) = player.camera_in_tree() {
            let camera = self.display.shown_camera(&camera, size);
            // The frame is drawn in tree space (the tree's mesh is), after planting.
            let revision = Some(player.design.revision)
                .filter(|_| player.ui.ground_found && player.design.is_planted());
            if self.meshed_revision != revision {
                let t = Instant::now();
                match revision {
                    Some(_) => self.renderer.set_tree(
                        gpu,
                        self.tree_mesher
                            .mesh_in(&player.design.tree, player.design.params.season),
                    ),
                    None => self.renderer.set_tree(gpu, &Default::default()),
                }
                player.ui.budget.meshing_ms = t.elapsed().as_secs_f32() * 1000.0;
                self.meshed_revision = revision;
            }
            self.garden_mesher
                .upload(gpu, &mut self.renderer, &player.design, revision.is_some());
            // The footage image and the occluder change with the shown frame, not per redraw.
            let placed = (
                player.frame,
                player.design.world_from_tree,
                self.display,
                size,
            );
            if self.uploaded_frame != Some(placed) {
                if let Some(image) = &player.image {
                    if self.display.is_identity() {
                        self.renderer.set_camera_image(
                            gpu,
                            image.as_raw(),
                            player.footage.intrinsics,
                        );
                    } else {
                        let shown = self.display.shown_image(image, size);
                        self.renderer
                            .set_camera_image(gpu, shown.as_raw(), camera.intrinsics);
                    }
                }
                if let Some(scene) = player.scene() {
                    let occluder = crate::planting::occluder_in_tree(
                        &scene.occluder,
                        &player.design.tree_from_world(),
                    );
                    self.renderer.set_occluder(gpu, &occluder);
                }
                self.uploaded_frame = Some(placed);
            }
            let mut view = FrameView::augmented(camera, player.ground_in_tree());
            view.debug.depth_wireframe = player.ui.show_debug;
            view.debug.brush = player.brush_sphere();
            self.renderer.render(gpu, encoder, target, size, &view);
            self.scene_reused = self.renderer.scene_reused();
        }
    }
}
