//! The tree on the GPU: every level of detail's bark and leaf-card instances, and the species'
//! textures (drawn again only when the look changes), with the level picked for a view.

use glam::Vec3;

use crate::render::buffers::{GpuMesh, draw, draw_cards, upload, upload_lit};
use crate::render::lod::{level_for_card_px, projected_px_per_m};
use crate::render::mesh::{CardInstance, TreeLook, TreeMesh};
use crate::render::pipelines::Pipelines;
use crate::render::textures::{look_images, upload_mipmapped};
use crate::render::{Gpu, ViewCamera};

/// One level of detail of the tree on the GPU.
struct GpuLevel {
    branches: Option<GpuMesh>,
    /// Leaf card instances.
    cards: Option<GpuMesh>,
    fruit: Option<GpuMesh>,
}

/// The pipelines a pass draws the tree's parts with.
#[derive(Clone, Copy)]
pub(super) struct TreePipelines<'a> {
    pub branches: &'a wgpu::RenderPipeline,
    pub cards: &'a wgpu::RenderPipeline,
    pub fruit: &'a wgpu::RenderPipeline,
}

/// The uploaded tree.
pub(super) struct GpuTree {
    /// Finest first.
    levels: Vec<GpuLevel>,
    /// Mean side of a finest-level leaf card, metres (0 without cards): what picks a level.
    card_side_m: f32,
    bounds: Option<(Vec3, Vec3)>,
    /// The look the textures were drawn for, and the textures' bind group (group 1).
    look: Option<TreeLook>,
    group: wgpu::BindGroup,
    sampler: wgpu::Sampler,
}

impl GpuTree {
    /// No tree yet: 1 × 1 placeholder textures (nothing samples them).
    pub fn new(gpu: &Gpu, pipelines: &Pipelines) -> GpuTree {
        let device = &gpu.device;
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("tree textures"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let placeholder = image::RgbaImage::from_pixel(1, 1, image::Rgba([128, 128, 128, 255]));
        let placeholder = upload_mipmapped(device, &gpu.queue, "no tree", &placeholder, false);
        let group = tree_group(device, pipelines, &placeholder, &placeholder, &sampler);
        GpuTree {
            levels: Vec::new(),
            card_side_m: 0.0,
            bounds: None,
            look: None,
            group,
            sampler,
        }
    }

    /// Uploads `tree` (replacing the last): every level of detail, and the species' leaf card
    /// and bark textures when its look differs from the last tree's.
    pub fn set(&mut self, gpu: &Gpu, pipelines: &Pipelines, tree: &TreeMesh) {
        let device = &gpu.device;
        self.levels = tree
            .levels
            .iter()
            .map(|level| GpuLevel {
                branches: upload_lit(device, &level.branches),
                cards: upload(device, &level.cards, None),
                fruit: upload_lit(device, &level.fruit),
            })
            .collect();
        self.card_side_m = mean_card_side_m(tree.cards());
        self.bounds = tree.bounds();
        if self.look.as_ref() != Some(&tree.look) {
            let (card, bark) = look_images(&tree.look);
            let card = upload_mipmapped(device, &gpu.queue, "leaf card", &card, true);
            let bark = upload_mipmapped(device, &gpu.queue, "bark", &bark, false);
            self.group = tree_group(device, pipelines, &card, &bark, &self.sampler);
            self.look = Some(tree.look.clone());
        }
    }

    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.bounds
    }

    /// Linear RGB of the fruit.
    pub fn fruit_color(&self) -> [f32; 3] {
        self.look.as_ref().map_or([0.0; 3], |l| l.fruit_color)
    }

    /// The textures' bind group (group 1 of every pipeline).
    pub fn group(&self) -> &wgpu::BindGroup {
        &self.group
    }

    /// The level drawn by `camera` with focal length `fy` (pixels, of the drawn region): the
    /// finest whose leaf cards are at least [`crate::render::lod::MIN_CARD_PX`] on screen at
    /// the tree's centre; the finest for a tree without leaves.
    pub fn level_for(&self, camera: &ViewCamera, fy: f32) -> usize {
        let Some((lo, hi)) = self.bounds else {
            return 0;
        };
        let px_per_m = projected_px_per_m(
            fy,
            camera.position(),
            camera.world_from_camera.z_axis.truncate(),
            0.5 * (lo + hi),
        );
        level_for_card_px(self.card_side_m * px_per_m, self.levels.len())
    }

    /// Draws level `level` with `pipelines`: bark, leaf cards and fruit.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, level: usize, pipelines: TreePipelines) {
        if let Some(level) = self.levels.get(level) {
            draw(pass, pipelines.branches, level.branches.as_ref());
            draw_cards(pass, pipelines.cards, level.cards.as_ref());
            draw(pass, pipelines.fruit, level.fruit.as_ref());
        }
    }
}

/// Mean side of the cards (the square root of their mean area), metres; 0 for none.
fn mean_card_side_m(cards: &[CardInstance]) -> f32 {
    if cards.is_empty() {
        return 0.0;
    }
    let area: f32 = cards
        .iter()
        .map(|c| Vec3::from(c.across).cross(Vec3::from(c.along)).length())
        .sum();
    (area / cards.len() as f32).sqrt()
}

fn tree_group(
    device: &wgpu::Device,
    pipelines: &Pipelines,
    card: &wgpu::Texture,
    bark: &wgpu::Texture,
    sampler: &wgpu::Sampler,
) -> wgpu::BindGroup {
    let (card, bark) = (
        card.create_view(&Default::default()),
        bark.create_view(&Default::default()),
    );
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("tree textures"),
        layout: &pipelines.tree_layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&card),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::TextureView(&bark),
            },
            wgpu::BindGroupEntry {
                binding: 2,
                resource: wgpu::BindingResource::Sampler(sampler),
            },
        ],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mean_card_side_is_the_root_of_the_mean_area() {
        let card = |side: f32| CardInstance {
            across: [side, 0.0, 0.0],
            along: [0.0, side, 0.0],
            ..CardInstance::default()
        };
        assert_eq!(mean_card_side_m(&[]), 0.0);
        let mean = mean_card_side_m(&[card(0.1), card(0.2)]);
        assert!((mean - (0.025f32).sqrt()).abs() < 1e-6, "{mean}");
    }
}
