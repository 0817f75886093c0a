//! The renderer's GPU resources and the frame it records.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

use crate::render::buffers::{GpuMesh, draw, upload};
use crate::render::camera::Intrinsics;
use crate::render::mesh::{OccluderMesh, TreeMesh};
use crate::render::pipelines::{DEPTH_FORMAT, Pipelines, SAMPLE_COUNT};
use crate::render::shadow::{GroundPatch, shadow_footprint, sun_clip_from_world};
use crate::render::tree_gpu::{GpuTree, TreePipelines};
use crate::render::upscale::{SceneResolution, Upscaler};
use crate::render::{FrameView, Gpu, GroundStyle};

/// The camera a frame picks each tree's level of detail for, and its focal length in pixels.
#[derive(Clone, Copy)]
struct LevelCamera(crate::render::ViewCamera, f32);

/// Side of the square shadow map, texels.
const SHADOW_MAP_SIZE: u32 = 2048;
const BRUSH_VERTICES: u32 = 12 * 24 * 6;

/// Mirrors `Globals` in scene.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Globals {
    clip_from_world: [[f32; 4]; 4],
    light_clip_from_world: [[f32; 4]; 4],
    sun_direction: [f32; 4],
    sun_color: [f32; 4],
    ground_origin: [f32; 4],
    ground_u: [f32; 4],
    ground_v: [f32; 4],
    brush: [f32; 4],
    intrinsics: [f32; 4],
    distortion: [f32; 4],
    image: [f32; 4],
    viewport: [f32; 4],
    misc: [f32; 4],
    /// rgb: linear colour of the tree's fruit; w unused.
    fruit_color: [f32; 4],
    /// The ground the shadow catcher draws: centre and half axes (xyz; w unused).
    catcher_centre: [f32; 4],
    catcher_a: [f32; 4],
    catcher_b: [f32; 4],
}

/// What the shadow map was drawn for: it is drawn again only when one of these changes (the
/// tree is uploaded anew, the sun moves, or the drawn level of detail changes), not per camera
/// frame.
#[derive(Clone, Debug, PartialEq)]
struct ShadowKey {
    /// Counts uploads of any tree of the garden.
    tree_generation: u64,
    /// The level each tree is drawn at (the tree's first, then the garden's others).
    levels: Vec<usize>,
    light_clip_from_world: Mat4,
}

/// What the reduced-resolution scene texture was drawn for: it is drawn again only when one of
/// these changes (a new footage frame brings a new image, occluder and camera), else the window
/// only stretches it again under the redrawn UI.
#[derive(Clone, Debug, PartialEq)]
struct SceneKey {
    view: FrameView,
    scene_size: (u32, u32),
    /// Counts uploads of trees, camera images, occluders and feature points.
    uploads: u64,
}

struct Background {
    texture: wgpu::Texture,
    intrinsics: Intrinsics,
}

/// Owns pipelines, uploaded meshes and images, and draws frames into any colour target of the
/// format it was made for.
pub struct Renderer {
    pipelines: Pipelines,
    globals: wgpu::Buffer,
    shadow_view: wgpu::TextureView,
    shadow_sampler: wgpu::Sampler,
    linear_sampler: wgpu::Sampler,
    background: Background,
    has_camera_image: bool,
    scene_group: wgpu::BindGroup,
    shadow_group: wgpu::BindGroup,
    tree: GpuTree,
    /// Counts [`Renderer::set_tree`] calls: the tree the shadow map shows.
    tree_generation: u64,
    /// What the shadow map holds (None before the first frame).
    shadow_drawn: Option<ShadowKey>,
    /// Whether the last frame drew the shadow map (rather than reusing it).
    shadow_redrawn: bool,
    /// Counts every upload a frame shows (trees, camera image, occluder, feature points).
    uploads: u64,
    /// What the reduced-resolution scene texture holds (None before it is drawn).
    scene_drawn: Option<SceneKey>,
    /// Whether the last frame stretched the kept scene texture without drawing the scene.
    scene_reused: bool,
    /// The garden's other trees (slots 1..), drawn as the tree is, each at its own level.
    others: Vec<GpuTree>,
    /// The level of detail the last frame drew.
    drawn_level: usize,
    occluder: Option<GpuMesh>,
    wireframe: Option<GpuMesh>,
    points: Option<GpuMesh>,
    /// The scene pass's targets.
    targets: Option<SceneTargets>,
    color_format: wgpu::TextureFormat,
    /// The resolution the scene pass draws at (full in offscreen frames).
    scene_resolution: SceneResolution,
    /// The reduced-resolution scene target and its stretch pass (made when first needed).
    upscaler: Option<Upscaler>,
}

/// The scene pass's own targets for one size: the multisampled colour (resolved into the
/// caller's target; None at one sample, which draws into the caller's target directly) and the
/// depth.
struct SceneTargets {
    size: (u32, u32),
    msaa_color: Option<wgpu::TextureView>,
    depth: wgpu::TextureView,
}

fn texture_2d(
    device: &wgpu::Device,
    label: &str,
    (width, height): (u32, u32),
    format: wgpu::TextureFormat,
    sample_count: u32,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

impl Renderer {
    /// A renderer drawing into targets of `color_format`, [`SAMPLE_COUNT`]× multisampled (the
    /// offscreen frames: screenshots, golden images, session hashes).
    pub fn new(gpu: &Gpu, color_format: wgpu::TextureFormat) -> Renderer {
        Renderer::with_samples(gpu, color_format, SAMPLE_COUNT)
    }

    /// A renderer whose scene pass takes `sample_count` samples a pixel (1: no multisampling,
    /// leaf edges by an alpha test; see [`crate::render::interactive_sample_count`]).
    pub fn with_samples(
        gpu: &Gpu,
        color_format: wgpu::TextureFormat,
        sample_count: u32,
    ) -> Renderer {
        let device = &gpu.device;
        let pipelines = Pipelines::new(device, color_format, sample_count.max(1));
        let globals = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("sylva globals"),
            size: std::mem::size_of::<Globals>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let shadow = texture_2d(
            device,
            "sun shadow map",
            (SHADOW_MAP_SIZE, SHADOW_MAP_SIZE),
            DEPTH_FORMAT,
            1,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let shadow_view = shadow.create_view(&Default::default());
        let shadow_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("shadow comparison"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let linear_sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("camera image"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let tree = GpuTree::new(gpu, &pipelines);
        let background = Background {
            texture: background_texture(device, (1, 1)),
            intrinsics: Intrinsics::from_fov(1, 1, 1.0),
        };
        let shadow_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("shadow globals"),
            layout: &pipelines.shadow_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: globals.as_entire_binding(),
            }],
        });
        let scene_group = scene_group(
            device,
            &pipelines,
            &globals,
            &shadow_view,
            &shadow_sampler,
            &background.texture,
            &linear_sampler,
        );
        Renderer {
            pipelines,
            globals,
            shadow_view,
            shadow_sampler,
            linear_sampler,
            background,
            has_camera_image: false,
            scene_group,
            shadow_group,
            tree,
            tree_generation: 0,
            shadow_drawn: None,
            shadow_redrawn: false,
            uploads: 0,
            scene_drawn: None,
            scene_reused: false,
            others: Vec::new(),
            drawn_level: 0,
            occluder: None,
            wireframe: None,
            points: None,
            targets: None,
            color_format,
            scene_resolution: SceneResolution::Full,
            upscaler: None,
        }
    }

    /// Draws the scene at `resolution` from the next frame on ([`SceneResolution::Full`] by
    /// default; [`SceneResolution::Footage`] for an interactive view on a CPU rasteriser).
    pub fn set_scene_resolution(&mut self, resolution: SceneResolution) {
        self.scene_resolution = resolution;
    }

    pub fn scene_resolution(&self) -> SceneResolution {
        self.scene_resolution
    }

    pub fn color_format(&self) -> wgpu::TextureFormat {
        self.color_format
    }

    /// MSAA samples of the scene pass.
    pub fn sample_count(&self) -> u32 {
        self.pipelines.sample_count
    }

    /// Whether the last frame drew the sun's shadow map (it is kept while the tree, the sun and
    /// the drawn level stay the same).
    pub fn shadow_redrawn(&self) -> bool {
        self.shadow_redrawn
    }

    /// Whether the last frame, drawn at a reduced resolution, stretched the scene it drew before
    /// (the same view of the same uploads) instead of drawing it again.
    pub fn scene_reused(&self) -> bool {
        self.scene_reused
    }

    /// Uploads the tree (replacing the previous one): every level of detail, and the species'
    /// leaf card and bark textures when its look differs from the last tree's.
    pub fn set_tree(&mut self, gpu: &Gpu, tree: &TreeMesh) {
        self.tree.set(gpu, &self.pipelines, tree);
        self.tree_generation += 1;
        self.uploads += 1;
    }

    /// Uploads tree `slot` of a garden (0: the tree [`Self::set_tree`] sets; the others, in
    /// the same space, drawn with it), making the slots up to it.
    pub fn set_garden_tree(&mut self, gpu: &Gpu, slot: usize, tree: &TreeMesh) {
        let Some(other) = slot.checked_sub(1) else {
            return self.set_tree(gpu, tree);
        };
        while self.others.len() <= other {
            self.others.push(GpuTree::new(gpu, &self.pipelines));
        }
        self.others[other].set(gpu, &self.pipelines, tree);
        self.tree_generation += 1;
        self.uploads += 1;
    }

    /// Keeps the first `num_trees` garden slots (at least the tree's), dropping the rest.
    pub fn keep_garden_trees(&mut self, num_trees: usize) {
        let kept = num_trees.saturating_sub(1);
        if kept < self.others.len() {
            self.others.truncate(kept);
            self.tree_generation += 1;
            self.uploads += 1;
        }
    }

    /// The level each tree is drawn at for `camera` (the tree's first, then the others').
    fn drawn_levels(&self, camera: LevelCamera) -> Vec<usize> {
        std::iter::once(self.drawn_level)
            .chain(self.others.iter().map(|o| o.level_for(&camera.0, camera.1)))
            .collect()
    }

    /// Bounds of every tree drawn.
    fn trees_bounds(&self) -> Option<(Vec3, Vec3)> {
        std::iter::once(&self.tree)
            .chain(&self.others)
            .filter_map(GpuTree::bounds)
            .reduce(|(a0, a1), (b0, b1)| (a0.min(b0), a1.max(b1)))
    }

    /// Draws every tree with `parts`, each at its level for the frame's camera.
    fn draw_trees(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        parts: TreePipelines,
        camera: LevelCamera,
    ) {
        pass.set_bind_group(1, self.tree.group(), &[]);
        self.tree.draw(pass, self.drawn_level, parts);
        for other in &self.others {
            pass.set_bind_group(1, other.group(), &[]);
            other.draw(pass, other.level_for(&camera.0, camera.1), parts);
        }
    }

    /// The level of detail the last frame drew (0 = finest).
    pub fn drawn_level(&self) -> usize {
        self.drawn_level
    }

    /// The level of detail drawn for `view`: the finest whose leaf cards are at least
    /// [`crate::render::lod::MIN_CARD_PX`] on screen at the tree's centre (coarser levels
    /// merge the cards into fewer, larger ones); the finest for a tree without leaves.
    pub fn level_for(&self, view: &FrameView, size: (u32, u32)) -> usize {
        let region = letterbox(size, &view.camera.intrinsics);
        let camera = view
            .camera
            .intrinsics
            .scaled_to(region[2].round() as u32, region[3].round() as u32);
        self.tree.level_for(&view.camera, camera.fy)
    }

    /// The camera and focal length (pixels of the drawn region) the levels are picked for.
    fn level_camera(&self, view: &FrameView, size: (u32, u32)) -> LevelCamera {
        let region = letterbox(size, &view.camera.intrinsics);
        let camera = view
            .camera
            .intrinsics
            .scaled_to(region[2].round() as u32, region[3].round() as u32);
        LevelCamera(view.camera, camera.fy)
    }

    /// Uploads the scene's depth mesh (occluder and wireframe).
    pub fn set_occluder(&mut self, gpu: &Gpu, mesh: &OccluderMesh) {
        let positions: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.to_array()).collect();
        self.occluder = upload(&gpu.device, &positions, Some(&mesh.indices));
        self.wireframe = upload(&gpu.device, &mesh.wireframe(), None);
        self.uploads += 1;
    }

    /// Uploads the tracked feature points (world space) for the debug view.
    pub fn set_feature_points(&mut self, gpu: &Gpu, points: &[Vec3]) {
        let positions: Vec<[f32; 3]> = points.iter().map(|p| p.to_array()).collect();
        self.points = upload(&gpu.device, &positions, None);
        self.uploads += 1;
    }

    /// Uploads a camera image (tightly packed RGBA8, sRGB) taken with `intrinsics`. An image
    /// with a side over the device's texture limit is scaled down to fit (the shader samples it
    /// in normalised coordinates, so the intrinsics stay those of the full image); one whose
    /// byte count does not match its intrinsics is not shown.
    pub fn set_camera_image(&mut self, gpu: &Gpu, rgba: &[u8], intrinsics: Intrinsics) {
        self.uploads += 1;
        let full = (intrinsics.width, intrinsics.height);
        let expected_len = u64::from(full.0) * u64::from(full.1) * 4;
        if full.0 == 0 || full.1 == 0 || rgba.len() as u64 != expected_len {
            self.has_camera_image = false;
            return;
        }
        let max_side = gpu.device.limits().max_texture_dimension_2d;
        let size = fit_within(full, max_side);
        let scaled;
        let rgba = if size == full {
            rgba
        } else {
            let Some(image) = image::RgbaImage::from_raw(full.0, full.1, rgba.to_vec()) else {
                self.has_camera_image = false;
                return;
            };
            scaled = image::imageops::resize(
                &image,
                size.0,
                size.1,
                image::imageops::FilterType::Triangle,
            );
            scaled.as_raw().as_slice()
        };
        let current = self.background.texture.size();
        if (current.width, current.height) != size {
            self.background.texture = background_texture(&gpu.device, size);
            self.scene_group = scene_group(
                &gpu.device,
                &self.pipelines,
                &self.globals,
                &self.shadow_view,
                &self.shadow_sampler,
                &self.background.texture,
                &self.linear_sampler,
            );
        }
        gpu.queue.write_texture(
            self.background.texture.as_image_copy(),
            rgba,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(size.0 * 4),
                rows_per_image: Some(size.1),
            },
            self.background.texture.size(),
        );
        self.background.intrinsics = intrinsics;
        self.has_camera_image = true;
    }

    fn ensure_targets(&mut self, device: &wgpu::Device, size: (u32, u32)) {
        if self.targets.as_ref().is_some_and(|t| t.size == size) {
            return;
        }
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let samples = self.pipelines.sample_count;
        let msaa_color = (samples > 1).then(|| {
            texture_2d(
                device,
                "msaa colour",
                size,
                self.color_format,
                samples,
                usage,
            )
            .create_view(&Default::default())
        });
        let depth = texture_2d(device, "scene depth", size, DEPTH_FORMAT, samples, usage);
        self.targets = Some(SceneTargets {
            size,
            msaa_color,
            depth: depth.create_view(&Default::default()),
        });
    }

    /// Records one frame into `target` (of `size` pixels, this renderer's colour format): at
    /// the target's resolution, or at the camera image's and stretched over the drawn region
    /// (see [`Self::set_scene_resolution`]).
    pub fn render(
        &mut self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        size: (u32, u32),
        view: &FrameView,
    ) {
        self.scene_reused = false;
        let Some(scene_size) = self
            .scene_resolution
            .reduced_size(size, &view.camera.intrinsics)
        else {
            self.scene_drawn = None;
            return self.render_direct(gpu, encoder, target, size, view);
        };
        let mut upscaler = self
            .upscaler
            .take()
            .unwrap_or_else(|| Upscaler::new(&gpu.device, self.color_format));
        let scene = upscaler.scene_target(&gpu.device, scene_size, self.color_format);
        let key = SceneKey {
            view: *view,
            scene_size,
            uploads: self.uploads,
        };
        if self.scene_drawn.as_ref() == Some(&key) && upscaler.holds(scene_size) {
            // Nothing the scene shows changed: its texture is stretched again as it is.
            self.scene_reused = true;
            self.shadow_redrawn = false;
        } else {
            self.render_direct(gpu, encoder, &scene, scene_size, view);
            self.scene_drawn = Some(key);
        }
        upscaler.stretch(encoder, target, letterbox(size, &view.camera.intrinsics));
        self.upscaler = Some(upscaler);
    }

    /// Records one frame into `target` of `size` pixels, at that resolution.
    fn render_direct(
        &mut self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        size: (u32, u32),
        view: &FrameView,
    ) {
        self.ensure_targets(&gpu.device, size);
        self.drawn_level = self.level_for(view, size);
        let region = letterbox(size, &view.camera.intrinsics);
        let light_clip_from_world = self.light_clip_from_world(view);
        let globals = self.globals_for(view, region, light_clip_from_world);
        gpu.queue
            .write_buffer(&self.globals, 0, bytemuck::bytes_of(&globals));
        let level_camera = self.level_camera(view, size);
        let shadow = ShadowKey {
            tree_generation: self.tree_generation,
            levels: self.drawn_levels(level_camera),
            light_clip_from_world,
        };
        self.shadow_redrawn = self.shadow_drawn.as_ref() != Some(&shadow);
        if self.shadow_redrawn {
            self.shadow_pass(encoder, level_camera);
            self.shadow_drawn = Some(shadow);
        }
        let Some(targets) = &self.targets else {
            return;
        };
        // Multisampled: drawn into the samples and resolved into `target`; else into `target`.
        let (color, resolve_target, store) = match &targets.msaa_color {
            Some(msaa) => (msaa, Some(target), wgpu::StoreOp::Discard),
            None => (target, None, wgpu::StoreOp::Store),
        };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("scene"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: color,
                depth_slice: None,
                resolve_target,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &targets.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_viewport(region[0], region[1], region[2], region[3], 0.0, 1.0);
        pass.set_bind_group(0, &self.scene_group, &[]);
        pass.set_bind_group(1, self.tree.group(), &[]);
        let p = &self.pipelines;
        pass.set_pipeline(&p.background);
        pass.draw(0..3, 0..1);
        if view.occlude {
            draw(&mut pass, &p.occluder, self.occluder.as_ref());
        }
        if view.ground.is_some() && self.trees_bounds().is_some() {
            pass.set_pipeline(match view.ground_style {
                GroundStyle::ShadowCatcher => &p.ground_shadow,
                GroundStyle::Lawn => &p.ground_lawn,
            });
            pass.draw(0..6, 0..1);
        }
        let parts = TreePipelines {
            branches: &p.branches,
            cards: &p.cards,
            fruit: &p.fruit,
        };
        self.draw_trees(&mut pass, parts, level_camera);
        if view.debug.depth_wireframe {
            draw(&mut pass, &p.wire, self.wireframe.as_ref());
        }
        if view.debug.feature_points
            && let Some(points) = &self.points
        {
            pass.set_pipeline(&p.points);
            pass.set_vertex_buffer(0, points.vertices.slice(..));
            pass.draw(0..6, 0..points.count);
        }
        if view.debug.brush.is_some() {
            pass.set_pipeline(&p.brush);
            pass.draw(0..BRUSH_VERTICES, 0..1);
        }
    }

    fn shadow_pass(&self, encoder: &mut wgpu::CommandEncoder, level_camera: LevelCamera) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("sun shadow map"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.shadow_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &self.shadow_group, &[]);
        pass.set_bind_group(1, self.tree.group(), &[]);
        let p = &self.pipelines;
        let parts = TreePipelines {
            branches: &p.shadow_branches,
            cards: &p.shadow_cards,
            fruit: &p.shadow_branches,
        };
        self.draw_trees(&mut pass, parts, level_camera);
    }

    /// The sun's view of the tree's bounding sphere (the shadow map's projection).
    fn light_clip_from_world(&self, view: &FrameView) -> Mat4 {
        let sun = view
            .lighting
            .sun_direction
            .try_normalize()
            .unwrap_or(Vec3::Y);
        let (centre, radius) = self.tree_sphere();
        sun_clip_from_world(sun, centre, radius)
    }

    /// Centre and radius of the bounding sphere of every tree drawn (a unit sphere at the origin
    /// without a tree).
    fn tree_sphere(&self) -> (Vec3, f32) {
        match self.trees_bounds() {
            Some((lo, hi)) => (0.5 * (lo + hi), (0.5 * (hi - lo)).length().max(0.05)),
            None => (Vec3::ZERO, 1.0),
        }
    }

    fn globals_for(
        &self,
        view: &FrameView,
        region: [f32; 4],
        light_clip_from_world: Mat4,
    ) -> Globals {
        let camera = crate::render::ViewCamera {
            intrinsics: view
                .camera
                .intrinsics
                .scaled_to(region[2].round() as u32, region[3].round() as u32),
            ..view.camera
        };
        let light = &view.lighting;
        let sun = light.sun_direction.try_normalize().unwrap_or(Vec3::Y);
        let (centre, radius) = self.tree_sphere();
        let ground = view.ground.unwrap_or_default();
        let normal = ground.normal.try_normalize().unwrap_or(Vec3::Y);
        let u = normal.any_orthonormal_vector();
        let v = u.cross(normal);
        // The ground quad is centred under the tree and reaches well past its shadow.
        let origin = centre - normal * normal.dot(centre - ground.point);
        let extent = radius * 3.0;
        // The shadow catcher adds nothing where no shadow can fall: it draws the ground the
        // shadow map covers, or the whole ground disc where that is smaller (a low sun).
        let disc = GroundPatch {
            centre: origin,
            half_a: u * extent,
            half_b: v * extent,
        };
        let catcher = shadow_footprint(sun, centre, radius, ground.point, normal)
            .filter(|patch| patch.area_m2() < disc.area_m2())
            .unwrap_or(disc);
        let k = &self.background.intrinsics;
        let (brush, brush_radius) = view.debug.brush.unwrap_or((Vec3::ZERO, 0.0));
        let show_image = view.show_camera_image && self.has_camera_image;
        let texel = 1.0 / SHADOW_MAP_SIZE as f32;
        Globals {
            clip_from_world: camera.clip_from_world().to_cols_array_2d(),
            light_clip_from_world: light_clip_from_world.to_cols_array_2d(),
            sun_direction: sun.extend(light.sun_strength).to_array(),
            sun_color: [1.0, 0.96, 0.88, light.ambient_strength],
            ground_origin: origin.extend(extent).to_array(),
            ground_u: u.extend(0.0).to_array(),
            ground_v: v.extend(light.shadow_strength).to_array(),
            brush: brush.extend(brush_radius).to_array(),
            intrinsics: [k.fx, k.fy, k.cx, k.cy],
            distortion: [
                k.distortion[0],
                k.distortion[1],
                k.distortion[2],
                k.distortion[3],
            ],
            image: [
                k.distortion[4],
                k.width as f32,
                k.height as f32,
                if show_image { 1.0 } else { 0.0 },
            ],
            viewport: region,
            misc: [3.0, texel, 1.5, 0.0],
            fruit_color: Vec3::from(self.tree.fruit_color()).extend(1.0).to_array(),
            catcher_centre: catcher.centre.extend(0.0).to_array(),
            catcher_a: catcher.half_a.extend(0.0).to_array(),
            catcher_b: catcher.half_b.extend(0.0).to_array(),
        }
    }
}

/// `size` scaled down (aspect kept, each side at least 1) so that neither side exceeds
/// `max_side`; unchanged when it fits.
pub fn fit_within(size: (u32, u32), max_side: u32) -> (u32, u32) {
    let longest = size.0.max(size.1);
    if longest <= max_side || max_side == 0 {
        return size;
    }
    let scale = f64::from(max_side) / f64::from(longest);
    let side = |s: u32| ((f64::from(s) * scale).round() as u32).clamp(1, max_side);
    (side(size.0), side(size.1))
}

/// The largest region of the target with the camera image's aspect, centred: x, y, w, h.
pub fn letterbox(size: (u32, u32), k: &Intrinsics) -> [f32; 4] {
    let (tw, th) = (size.0 as f32, size.1 as f32);
    let aspect = k.width as f32 / k.height.max(1) as f32;
    let (w, h) = if tw / th > aspect {
        (th * aspect, th)
    } else {
        (tw, tw / aspect)
    };
    let (w, h) = (w.round().max(1.0), h.round().max(1.0));
    [((tw - w) * 0.5).round(), ((th - h) * 0.5).round(), w, h]
}

fn background_texture(device: &wgpu::Device, size: (u32, u32)) -> wgpu::Texture {
    texture_2d(
        device,
        "camera image",
        size,
        wgpu::TextureFormat::Rgba8UnormSrgb,
        1,
        wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
    )
}

fn scene_group(
    device: &wgpu::Device,
    pipelines: &Pipelines,
    globals: &wgpu::Buffer,
    shadow_view: &wgpu::TextureView,
    shadow_sampler: &wgpu::Sampler,
    background: &wgpu::Texture,
    linear_sampler: &wgpu::Sampler,
) -> wgpu::BindGroup {
    let background_view = background.create_view(&Default::default());
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("scene globals"),
        layout: &pipelines.scene_layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: globals.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(shadow_view),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::Sampler(shadow_sampler),
            },
            wgpu::BindGroupEntry {
                binding: 3,
                resource: wgpu::BindingResource::TextureView(&background_view),
            },
            wgpu::BindGroupEntry {
                binding: 4,
                resource: wgpu::BindingResource::Sampler(linear_sampler),
            },
        ],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn letterbox_keeps_the_image_aspect_and_centres_it() {
        let k = Intrinsics::from_fov(640, 480, 1.0);
        assert_eq!(letterbox((640, 480), &k), [0.0, 0.0, 640.0, 480.0]);
        assert_eq!(letterbox((1000, 480), &k), [180.0, 0.0, 640.0, 480.0]);
    }

    #[test]
    fn an_image_over_the_texture_limit_is_scaled_to_fit_keeping_its_aspect() {
        assert_eq!(fit_within((640, 480), 16384), (640, 480));
        assert_eq!(fit_within((17000, 1000), 16384), (16384, 964));
        assert_eq!(fit_within((3000, 40000), 8192), (614, 8192));
        assert_eq!(fit_within((u32::MAX, 1), 4096), (4096, 1));
    }
}
