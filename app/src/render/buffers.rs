//! Vertex, index and instance buffers of what the renderer draws, and the draw calls on them.

use bytemuck::Pod;
use wgpu::util::DeviceExt;

use crate::render::mesh::LitMesh;

/// An uploaded mesh: vertices (or instances), optional indices, and how many to draw.
pub(super) struct GpuMesh {
    pub vertices: wgpu::Buffer,
    pub indices: Option<wgpu::Buffer>,
    pub count: u32,
}

pub(super) fn draw(
    pass: &mut wgpu::RenderPass<'_>,
    pipeline: &wgpu::RenderPipeline,
    mesh: Option<&GpuMesh>,
) {
    let Some(mesh) = mesh else {
        return;
    };
    pass.set_pipeline(pipeline);
    pass.set_vertex_buffer(0, mesh.vertices.slice(..));
    match &mesh.indices {
        Some(indices) => {
            pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..mesh.count, 0, 0..1);
        }
        None => pass.draw(0..mesh.count, 0..1),
    }
}

/// Draws card instances: one quad (6 vertices) per instance of `cards`.
pub(super) fn draw_cards(
    pass: &mut wgpu::RenderPass<'_>,
    pipeline: &wgpu::RenderPipeline,
    cards: Option<&GpuMesh>,
) {
    let Some(cards) = cards else {
        return;
    };
    pass.set_pipeline(pipeline);
    pass.set_vertex_buffer(0, cards.vertices.slice(..));
    pass.draw(0..6, 0..cards.count);
}

pub(super) fn upload_lit(device: &wgpu::Device, mesh: &LitMesh) -> Option<GpuMesh> {
    upload(device, &mesh.vertices, Some(&mesh.indices))
}

/// `vertices` (and `indices`) in GPU buffers; `None` when there is nothing to draw.
pub(super) fn upload<T: Pod>(
    device: &wgpu::Device,
    vertices: &[T],
    indices: Option<&[u32]>,
) -> Option<GpuMesh> {
    if vertices.is_empty() || indices.is_some_and(|i| i.is_empty()) {
        return None;
    }
    let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: None,
        contents: bytemuck::cast_slice(vertices),
        usage: wgpu::BufferUsages::VERTEX,
    });
    let index_buffer = indices.map(|indices| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytemuck::cast_slice(indices),
            usage: wgpu::BufferUsages::INDEX,
        })
    });
    Some(GpuMesh {
        vertices: vertex_buffer,
        count: indices.map_or(vertices.len(), |i| i.len()) as u32,
        indices: index_buffer,
    })
}
