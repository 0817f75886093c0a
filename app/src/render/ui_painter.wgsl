// The lean UI painter (ui_painter.rs): egui's meshes, egui-wgpu's colour arithmetic, no branches.

struct Locals {
    screen_size_pt: vec2<f32>,
    pad: vec2<f32>,
};
@group(0) @binding(0) var<uniform> locals: Locals;
@group(1) @binding(0) var ui_image: texture_2d<f32>;
@group(1) @binding(1) var ui_sampler: sampler;

struct VertexOutput {
    @builtin(position) position: vec4<f32>,
    @location(0) uv: vec2<f32>,
    // Premultiplied, gamma-encoded 0..1.
    @location(1) color: vec4<f32>,
};

@vertex
fn vs_main(
    @location(0) pos: vec2<f32>,
    @location(1) uv: vec2<f32>,
    @location(2) color: vec4<f32>,
) -> VertexOutput {
    var out: VertexOutput;
    out.position = vec4<f32>(
        2.0 * pos.x / locals.screen_size_pt.x - 1.0,
        1.0 - 2.0 * pos.y / locals.screen_size_pt.y,
        0.0,
        1.0,
    );
    out.uv = uv;
    out.color = color;
    return out;
}

// Interleaved gradient noise (Jimenez 2014) dithering the gamma-space colour to 8 bits, as
// egui-wgpu does by default.
fn dithered(rgb: vec3<f32>, frag: vec2<f32>) -> vec3<f32> {
    let noise = fract(52.9829189 * fract(0.06711056 * frag.x + 0.00583715 * frag.y));
    return rgb + (noise - 0.5) * 0.95 / 255.0;
}

fn gamma_color(in: VertexOutput) -> vec4<f32> {
    let c = in.color * textureSample(ui_image, ui_sampler, in.uv);
    return vec4<f32>(dithered(c.rgb, in.position.xy), c.a);
}

// sRGB target: the hardware encodes, so the shader hands over linear values.
@fragment
fn fs_linear_target(in: VertexOutput) -> @location(0) vec4<f32> {
    let c = gamma_color(in);
    let lower = c.rgb / 12.92;
    let higher = pow((c.rgb + 0.055) / 1.055, vec3<f32>(2.4));
    return vec4<f32>(select(higher, lower, c.rgb < vec3<f32>(0.04045)), c.a);
}

@fragment
fn fs_gamma_target(in: VertexOutput) -> @location(0) vec4<f32> {
    return gamma_color(in);
}
