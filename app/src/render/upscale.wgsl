// The scene drawn at a reduced resolution, stretched over the drawn region of the window with a
// bilinear filter (see upscale.rs).

@group(0) @binding(0) var scene: texture_2d<f32>;
@group(0) @binding(1) var scene_sampler: sampler;

struct UpscaleOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

// One triangle covering the viewport (the drawn region), with the scene texture's coordinates.
@vertex
fn vs_upscale(@builtin(vertex_index) i: u32) -> UpscaleOut {
    let t = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    var out: UpscaleOut;
    out.clip = vec4<f32>(t * 2.0 - 1.0, 0.0, 1.0);
    out.uv = vec2<f32>(t.x, 1.0 - t.y);
    return out;
}

@fragment
fn fs_upscale(s: UpscaleOut) -> @location(0) vec4<f32> {
    return vec4<f32>(textureSampleLevel(scene, scene_sampler, s.uv, 0.0).rgb, 1.0);
}
