// Sylva's scene shader: every pipeline of the renderer shares this module and bind group 0.
// World space: metres, Y up. Clip space: wgpu (depth 0..1).

struct Globals {
    clip_from_world: mat4x4<f32>,
    light_clip_from_world: mat4x4<f32>,
    // xyz: unit direction towards the sun; w: sun strength.
    sun_direction: vec4<f32>,
    // rgb: sun colour; w: ambient (sky) strength.
    sun_color: vec4<f32>,
    // xyz: ground centre (under the tree); w: half extent of the ground quad, metres.
    ground_origin: vec4<f32>,
    // xyz: first in-plane axis; w: unused.
    ground_u: vec4<f32>,
    // xyz: second in-plane axis; w: shadow strength on the real ground (0..1).
    ground_v: vec4<f32>,
    // xyz: brush centre; w: radius, metres.
    brush: vec4<f32>,
    // Background image: fx, fy, cx, cy (pixels of the image).
    intrinsics: vec4<f32>,
    // k1, k2, p1, p2.
    distortion: vec4<f32>,
    // k3, image width, image height, 1 when a camera image is shown.
    image: vec4<f32>,
    // Drawn region of the target, pixels: x0, y0, width, height.
    viewport: vec4<f32>,
    // point size (px), shadow map texel size (uv), PCF spacing (texels), unused.
    misc: vec4<f32>,
    // rgb: linear colour of the tree's fruit; w unused.
    fruit_color: vec4<f32>,
    // The ground the shadow catcher draws (where the shadow map can shade it, or the whole
    // ground disc if smaller): centre and half axes, xyz; w unused.
    catcher_centre: vec4<f32>,
    catcher_a: vec4<f32>,
    catcher_b: vec4<f32>,
}

@group(0) @binding(0) var<uniform> g: Globals;
@group(0) @binding(1) var shadow_map: texture_depth_2d;
@group(0) @binding(2) var shadow_sampler: sampler_comparison;
@group(0) @binding(3) var background: texture_2d<f32>;
@group(0) @binding(4) var linear_sampler: sampler;
// The tree's species in its season: the leaf card (alpha outside the leaves) and the bark tile,
// both sRGB with mipmaps, and a repeating trilinear sampler.
@group(1) @binding(0) var card_texture: texture_2d<f32>;
@group(1) @binding(1) var bark_texture: texture_2d<f32>;
@group(1) @binding(2) var tree_sampler: sampler;

const LAWN: vec3<f32> = vec3<f32>(0.22, 0.42, 0.16);
const SKY: vec3<f32> = vec3<f32>(0.72, 0.82, 1.0);
// Share of the sun a leaf blade passes to its shaded face: a thin blade transmits about as much
// green light as it reflects, so the underside of a sunlit leaf glows rather than going black.
const LEAF_TRANSMISSION: f32 = 0.6;
// Least sky light on a leaf, as a share of the open sky's: deep in a crown the light that the
// growth shadow grid takes away still reaches a blade through the leaves around it.
const LEAF_AMBIENT_FLOOR: f32 = 0.35;

// Fraction of the sun visible from a point, percentage-closer filtered over a 5 x 5 footprint
// (each tap is itself a bilinear 2 x 2 comparison): a soft edge.
fn sun_visibility(world: vec3<f32>, normal: vec3<f32>) -> f32 {
    let lc = g.light_clip_from_world * vec4<f32>(world + normal * 0.01, 1.0);
    let ndc = lc.xyz / lc.w;
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    if (uv.x < 0.0 || uv.x > 1.0 || uv.y < 0.0 || uv.y > 1.0 || ndc.z > 1.0) {
        return 1.0;
    }
    let step = g.misc.y * g.misc.z;
    var sum = 0.0;
    for (var i = -2; i <= 2; i++) {
        for (var j = -2; j <= 2; j++) {
            let offset = vec2<f32>(f32(i), f32(j)) * step;
            sum += textureSampleCompareLevel(shadow_map, shadow_sampler, uv + offset, ndc.z - 0.003);
        }
    }
    return sum / 25.0;
}

fn shade(albedo: vec3<f32>, n: vec3<f32>, world: vec3<f32>, ambient: f32) -> vec3<f32> {
    let l = g.sun_direction.xyz;
    let direct = max(dot(n, l), 0.0) * sun_visibility(world, n) * g.sun_direction.w;
    let sky = g.sun_color.w * ambient * (0.6 + 0.4 * max(n.y, 0.0));
    return albedo * (sky * SKY + direct * g.sun_color.rgb);
}

// ---- lit tree surfaces ----

struct LitIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) ambient: f32,
    @location(3) uv: vec2<f32>,
}

struct LitOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) ambient: f32,
    @location(3) uv: vec2<f32>,
}

@vertex
fn vs_lit(v: LitIn) -> LitOut {
    var out: LitOut;
    out.clip = g.clip_from_world * vec4<f32>(v.position, 1.0);
    out.world = v.position;
    out.normal = v.normal;
    out.ambient = v.ambient;
    out.uv = v.uv;
    return out;
}

@fragment
fn fs_branch(v: LitOut) -> @location(0) vec4<f32> {
    let n = normalize(v.normal);
    let bark = textureSample(bark_texture, tree_sampler, v.uv).rgb;
    return vec4<f32>(shade(bark, n, v.world, v.ambient), 1.0);
}

@fragment
fn fs_fruit(v: LitOut) -> @location(0) vec4<f32> {
    return vec4<f32>(shade(g.fruit_color.rgb, normalize(v.normal), v.world, v.ambient), 1.0);
}

// ---- leaf cards: one quad, instanced; two-sided ----

struct CardIn {
    @location(0) origin: vec3<f32>,
    @location(1) across: vec3<f32>,
    @location(2) along: vec3<f32>,
    @location(3) normal: vec3<f32>,
    @location(4) ambient: f32,
}

// Corner of the card quad for vertex `i` of its two triangles: (across, along) in 0..1.
fn card_corner(i: u32) -> vec2<f32> {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 0.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(0.0, 0.0), vec2<f32>(1.0, 1.0), vec2<f32>(0.0, 1.0),
    );
    return corners[i];
}

@vertex
fn vs_card(@builtin(vertex_index) i: u32, c: CardIn) -> LitOut {
    let k = card_corner(i);
    let world = c.origin + c.across * k.x + c.along * k.y;
    var out: LitOut;
    out.clip = g.clip_from_world * vec4<f32>(world, 1.0);
    out.world = world;
    out.normal = c.normal;
    out.ambient = c.ambient;
    // The card texture has the base on its bottom row.
    out.uv = vec2<f32>(k.x, 1.0 - k.y);
    return out;
}

// A leaf lit on both faces: the face seen reflects the sun when it faces it and, when the sun
// is behind the blade, passes on the transmitted share; the shadow map is read from the side
// facing the sun. Sky light reaches both faces.
fn shade_leaf(albedo: vec3<f32>, normal: vec3<f32>, front: bool, world: vec3<f32>, ambient: f32) -> vec3<f32> {
    let l = g.sun_direction.xyz;
    var n = normalize(normal);
    if (!front) {
        n = -n;
    }
    let n_dot_l = dot(n, l);
    let sunward = select(-n, n, n_dot_l >= 0.0);
    let sun = max(n_dot_l, 0.0) + LEAF_TRANSMISSION * max(-n_dot_l, 0.0);
    let direct = sun * sun_visibility(world, sunward) * g.sun_direction.w;
    let sky = g.sun_color.w * mix(LEAF_AMBIENT_FLOOR, 1.0, ambient) * (0.6 + 0.4 * abs(n.y));
    return albedo * (sky * SKY + direct * g.sun_color.rgb);
}

// Alpha sharpened to the texel's screen-space footprint: a crisp blade edge under alpha to
// coverage at any distance (the mipmaps keep the covered share).
fn sharpened_alpha(a: f32) -> f32 {
    return clamp((a - 0.5) / max(fwidth(a), 1e-4) + 0.5, 0.0, 1.0);
}

@fragment
fn fs_card(v: LitOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let texel = textureSample(card_texture, tree_sampler, v.uv);
    let alpha = sharpened_alpha(texel.a);
    return vec4<f32>(shade_leaf(texel.rgb, v.normal, front, v.world, v.ambient), alpha);
}

// One sample a pixel (a CPU rasteriser): the blade's edge by an alpha test on the same sharpened
// alpha, no coverage to blend it.
@fragment
fn fs_card_tested(v: LitOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let texel = textureSample(card_texture, tree_sampler, v.uv);
    if (sharpened_alpha(texel.a) < 0.5) {
        discard;
    }
    return vec4<f32>(shade_leaf(texel.rgb, v.normal, front, v.world, v.ambient), 1.0);
}

// ---- shadow map (depth only, from the sun) ----

struct ShadowOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_shadow(v: LitIn) -> ShadowOut {
    var out: ShadowOut;
    out.clip = g.light_clip_from_world * vec4<f32>(v.position, 1.0);
    out.uv = v.uv;
    return out;
}

@vertex
fn vs_shadow_card(@builtin(vertex_index) i: u32, c: CardIn) -> ShadowOut {
    let k = card_corner(i);
    var out: ShadowOut;
    out.clip = g.light_clip_from_world * vec4<f32>(c.origin + c.across * k.x + c.along * k.y, 1.0);
    out.uv = vec2<f32>(k.x, 1.0 - k.y);
    return out;
}

@fragment
fn fs_shadow_card(v: ShadowOut) {
    if (textureSample(card_texture, tree_sampler, v.uv).a < 0.5) {
        discard;
    }
}

// ---- camera image background (undistorted for display) ----

struct ScreenOut {
    @builtin(position) clip: vec4<f32>,
}

@vertex
fn vs_fullscreen(@builtin(vertex_index) i: u32) -> ScreenOut {
    let xy = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u)) * 2.0 - 1.0;
    var out: ScreenOut;
    out.clip = vec4<f32>(xy, 0.0, 1.0);
    return out;
}

@fragment
fn fs_background(s: ScreenOut) -> @location(0) vec4<f32> {
    let t = (s.clip.xy - g.viewport.xy) / g.viewport.zw;
    if (g.image.w < 0.5) {
        return vec4<f32>(mix(SKY, vec3<f32>(0.93, 0.95, 0.97), t.y), 1.0);
    }
    // The displayed image is the ideal pinhole view with the image's intrinsics: find where each
    // displayed pixel lies in the distorted camera image (OpenCV radial-tangential model).
    let p = t * g.image.yz;
    let x = (p.x - g.intrinsics.z) / g.intrinsics.x;
    let y = (p.y - g.intrinsics.w) / g.intrinsics.y;
    let r2 = x * x + y * y;
    let k = g.distortion;
    let radial = 1.0 + r2 * (k.x + r2 * (k.y + r2 * g.image.x));
    let xd = x * radial + 2.0 * k.z * x * y + k.w * (r2 + 2.0 * x * x);
    let yd = y * radial + k.z * (r2 + 2.0 * y * y) + 2.0 * k.w * x * y;
    let uv = vec2<f32>(g.intrinsics.x * xd + g.intrinsics.z, g.intrinsics.y * yd + g.intrinsics.w)
        / g.image.yz;
    if (uv.x < 0.0 || uv.x > 1.0 || uv.y < 0.0 || uv.y > 1.0) {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    return vec4<f32>(textureSampleLevel(background, linear_sampler, uv, 0.0).rgb, 1.0);
}

// ---- scene occluder (depth only) and debug lines ----

struct PositionOut {
    @builtin(position) clip: vec4<f32>,
}

@vertex
fn vs_position(@location(0) position: vec3<f32>) -> PositionOut {
    var out: PositionOut;
    out.clip = g.clip_from_world * vec4<f32>(position, 1.0);
    return out;
}

@fragment
fn fs_depth_only(s: PositionOut) -> @location(0) vec4<f32> {
    return vec4<f32>(0.0);
}

@fragment
fn fs_wire(s: PositionOut) -> @location(0) vec4<f32> {
    return vec4<f32>(0.1, 0.95, 1.0, 1.0);
}

// ---- ground plane: a shadow catcher over the camera image, or a lawn outside AR ----

// Corner `i` of a quad of two triangles over [-1, 1]².
fn quad_corner(i: u32) -> vec2<f32> {
    var corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, 1.0), vec2<f32>(-1.0, 1.0),
    );
    return corners[i];
}

struct GroundOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) local: vec2<f32>,
}

@vertex
fn vs_ground(@builtin(vertex_index) i: u32) -> GroundOut {
    let c = quad_corner(i);
    let normal = normalize(cross(g.ground_v.xyz, g.ground_u.xyz));
    // Lifted 5 mm so the shadow wins the depth test against the scene's own ground triangles.
    let world = g.ground_origin.xyz + (g.ground_u.xyz * c.x + g.ground_v.xyz * c.y) * g.ground_origin.w
        + normal * 0.005;
    var out: GroundOut;
    out.clip = g.clip_from_world * vec4<f32>(world, 1.0);
    out.world = world;
    out.local = c;
    return out;
}

// The shadow catcher's quad: only the ground the shadow can fall on (see `catcher_centre`), with
// the ground disc's own coordinates for the fade at its rim.
@vertex
fn vs_ground_shadow(@builtin(vertex_index) i: u32) -> GroundOut {
    let c = quad_corner(i);
    let normal = normalize(cross(g.ground_v.xyz, g.ground_u.xyz));
    let on_ground = g.catcher_centre.xyz + g.catcher_a.xyz * c.x + g.catcher_b.xyz * c.y;
    let world = on_ground + normal * 0.005;
    let d = on_ground - g.ground_origin.xyz;
    var out: GroundOut;
    out.clip = g.clip_from_world * vec4<f32>(world, 1.0);
    out.world = world;
    out.local = vec2<f32>(dot(d, g.ground_u.xyz), dot(d, g.ground_v.xyz)) / g.ground_origin.w;
    return out;
}

@fragment
fn fs_ground_shadow(s: GroundOut) -> @location(0) vec4<f32> {
    let normal = normalize(cross(g.ground_v.xyz, g.ground_u.xyz));
    let shadow = 1.0 - sun_visibility(s.world, normal);
    let fade = 1.0 - smoothstep(0.75, 1.0, length(s.local));
    return vec4<f32>(0.0, 0.0, 0.0, g.ground_v.w * shadow * fade);
}

@fragment
fn fs_ground_lawn(s: GroundOut) -> @location(0) vec4<f32> {
    let normal = normalize(cross(g.ground_v.xyz, g.ground_u.xyz));
    let fade = 1.0 - smoothstep(0.8, 1.0, length(s.local));
    return vec4<f32>(shade(LAWN, normal, s.world, 1.0), fade);
}

// ---- debug overlays: feature points and the brush sphere ----

@vertex
fn vs_points(@builtin(vertex_index) i: u32, @location(0) position: vec3<f32>) -> PositionOut {
    var clip = g.clip_from_world * vec4<f32>(position, 1.0);
    let offset = quad_corner(i) * g.misc.x / g.viewport.zw;
    clip = vec4<f32>(clip.xy + offset * clip.w, clip.zw);
    var out: PositionOut;
    out.clip = clip;
    return out;
}

@fragment
fn fs_points(s: PositionOut) -> @location(0) vec4<f32> {
    return vec4<f32>(1.0, 0.85, 0.1, 1.0);
}

const BRUSH_RINGS: u32 = 12u;
const BRUSH_SEGMENTS: u32 = 24u;

struct BrushOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) normal: vec3<f32>,
}

@vertex
fn vs_brush(@builtin(vertex_index) i: u32) -> BrushOut {
    let quad = i / 6u;
    var offsets = array<vec2<u32>, 6>(
        vec2<u32>(0u, 0u), vec2<u32>(1u, 0u), vec2<u32>(1u, 1u),
        vec2<u32>(0u, 0u), vec2<u32>(1u, 1u), vec2<u32>(0u, 1u),
    );
    let o = offsets[i % 6u];
    let ring = quad / BRUSH_SEGMENTS + o.y;
    let segment = quad % BRUSH_SEGMENTS + o.x;
    let theta = 3.14159265 * f32(ring) / f32(BRUSH_RINGS);
    let phi = 6.2831853 * f32(segment) / f32(BRUSH_SEGMENTS);
    let n = vec3<f32>(sin(theta) * cos(phi), cos(theta), sin(theta) * sin(phi));
    var out: BrushOut;
    out.clip = g.clip_from_world * vec4<f32>(g.brush.xyz + n * g.brush.w, 1.0);
    out.normal = n;
    return out;
}

@fragment
fn fs_brush(s: BrushOut) -> @location(0) vec4<f32> {
    let lit = 0.6 + 0.4 * max(dot(normalize(s.normal), g.sun_direction.xyz), 0.0);
    return vec4<f32>(vec3<f32>(0.85, 0.92, 1.0) * lit, 0.35);
}
