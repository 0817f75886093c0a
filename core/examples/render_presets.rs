//! Renders every species preset, grown for a number of years, into `docs/images/<name>.png`
//! with a small z-buffered CPU rasterizer: perspective camera, bark and leaf textures (leaves
//! alpha-tested), ambient light from the growth shadow grid times a Lambert sun term, over a
//! disc of lawn at the ground plane (darker where the crown shades it).
//! Stands in for the app's offscreen renderer for the README pictures.
//!
//! `cargo run --release -p sylva-core --example render_presets [years] [out_dir] [season]`
//! (summer by default; the files of another season are named `<name>_<season>.png`), and with
//! `textures` as the years, each species' bark and leaf texture into `out_dir`.

use std::path::PathBuf;

use glam::camera::rh::proj::opengl::perspective;
use glam::camera::rh::view::look_at_mat4;
use glam::{Mat4, Vec2, Vec3, Vec4Swizzles};
use image::{Rgba, RgbaImage};
use sylva_core::Tree;
use sylva_core::geometry::leaf_card::card_texture;
use sylva_core::geometry::textures::{bark_texture, leaf_texture};
use sylva_core::geometry::{Season, TreeMesh, build_tree_meshes_in};
use sylva_core::species::Species;

const WIDTH: u32 = 480;
const HEIGHT: u32 = 600;
const SEED: u64 = 11;

/// Pixels of the image and their depths.
struct Target {
    color: RgbaImage,
    depth: Vec<f32>,
}

/// A triangle's vertex after projection: pixel position, depth, and what is interpolated.
#[derive(Clone, Copy)]
struct ScreenVertex {
    pixel: Vec2,
    depth: f32,
    uv: Vec2,
    shade: f32,
}

fn sky(y: u32) -> Rgba<u8> {
    let t = y as f32 / HEIGHT as f32;
    let mix = |a: f32, b: f32| (a + (b - a) * t) as u8;
    Rgba([mix(170.0, 228.0), mix(200.0, 232.0), mix(235.0, 220.0), 255])
}

/// Rasterises the first `num_indices` indices of `mesh`, sampling `texture` (alpha-tested when
/// `alpha_test`), lit by ambient × (sky + sun).
fn draw(
    target: &mut Target,
    mesh: &TreeMesh,
    num_indices: usize,
    texture: &RgbaImage,
    alpha_test: bool,
    clip_from_world: Mat4,
) {
    let sun = Vec3::new(0.4, 0.8, 0.45).normalize();
    let project = |i: u32| -> Option<ScreenVertex> {
        let i = i as usize;
        let clip = clip_from_world * Vec3::from(mesh.positions[i]).extend(1.0);
        if clip.w <= 1e-4 {
            return None;
        }
        let ndc = clip.xyz() / clip.w;
        let normal = Vec3::from(mesh.normals[i]);
        let lambert = if alpha_test {
            normal.dot(sun).abs()
        } else {
            normal.dot(sun).max(0.0)
        };
        Some(ScreenVertex {
            pixel: Vec2::new(
                (ndc.x * 0.5 + 0.5) * WIDTH as f32,
                (0.5 - ndc.y * 0.5) * HEIGHT as f32,
            ),
            depth: ndc.z,
            uv: Vec2::from(mesh.uvs[i]),
            shade: mesh.ambient[i] * (0.45 + 0.75 * lambert) + 0.12,
        })
    };
    for triangle in mesh.indices[..num_indices].chunks_exact(3) {
        let (Some(a), Some(b), Some(c)) = (
            project(triangle[0]),
            project(triangle[1]),
            project(triangle[2]),
        ) else {
            continue;
        };
        fill(target, [a, b, c], texture, alpha_test);
    }
}

fn fill(target: &mut Target, [a, b, c]: [ScreenVertex; 3], texture: &RgbaImage, alpha_test: bool) {
    let area = (b.pixel - a.pixel).perp_dot(c.pixel - a.pixel);
    if area.abs() < 1e-8 {
        return;
    }
    let lo = a.pixel.min(b.pixel).min(c.pixel).max(Vec2::ZERO).floor();
    let hi = a
        .pixel
        .max(b.pixel)
        .max(c.pixel)
        .min(Vec2::new(WIDTH as f32 - 1.0, HEIGHT as f32 - 1.0))
        .ceil();
    // A triangle wholly off the image has an empty box.
    if lo.x > hi.x || lo.y > hi.y {
        return;
    }
    let (tw, th) = (texture.width() as f32, texture.height() as f32);
    for y in lo.y as u32..=hi.y as u32 {
        for x in lo.x as u32..=hi.x as u32 {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let wa = (b.pixel - p).perp_dot(c.pixel - p) / area;
            let wb = (c.pixel - p).perp_dot(a.pixel - p) / area;
            let wc = 1.0 - wa - wb;
            if wa < 0.0 || wb < 0.0 || wc < 0.0 {
                continue;
            }
            let depth = wa * a.depth + wb * b.depth + wc * c.depth;
            let slot = (y * WIDTH + x) as usize;
            if depth >= target.depth[slot] {
                continue;
            }
            let uv = a.uv * wa + b.uv * wb + c.uv * wc;
            let tx = ((uv.x.rem_euclid(1.0)) * tw) as u32 % texture.width();
            let ty = ((uv.y.rem_euclid(1.0)) * th) as u32 % texture.height();
            let texel = texture.get_pixel(tx, ty);
            if alpha_test && texel[3] < 128 {
                continue;
            }
            let shade = (wa * a.shade + wb * b.shade + wc * c.shade).clamp(0.0, 1.3);
            let lit = |c: u8| (c as f32 * shade).min(255.0) as u8;
            target.depth[slot] = depth;
            target.color.put_pixel(
                x,
                y,
                Rgba([lit(texel[0]), lit(texel[1]), lit(texel[2]), 255]),
            );
        }
    }
}

/// The lawn: a disc of the ground plane (y = 0) around the base, `radius` metres wide, shaded by
/// the growth shadow grid's ambient light (darker under the crown).
fn draw_ground(target: &mut Target, tree: &Tree, radius: f32, clip_from_world: Mat4) {
    const RINGS: u32 = 32;
    const SECTORS: u32 = 128;
    let grass = RgbaImage::from_pixel(1, 1, Rgba([104, 132, 70, 255]));
    let vertex = |ring: u32, sector: u32| -> Option<ScreenVertex> {
        let (sin, cos) = (sector as f32 / SECTORS as f32 * std::f32::consts::TAU).sin_cos();
        let r = radius * ring as f32 / RINGS as f32;
        let world = Vec3::new(r * cos, 0.0, r * sin);
        let clip = clip_from_world * world.extend(1.0);
        if clip.w <= 1e-4 {
            return None;
        }
        let ndc = clip.xyz() / clip.w;
        // Light a little above the ground, where the lowest leaves would be.
        let ambient = tree.ambient_at(world + Vec3::Y * 0.1);
        Some(ScreenVertex {
            pixel: Vec2::new(
                (ndc.x * 0.5 + 0.5) * WIDTH as f32,
                (0.5 - ndc.y * 0.5) * HEIGHT as f32,
            ),
            depth: ndc.z,
            uv: Vec2::ZERO,
            shade: 0.45 + 0.55 * ambient,
        })
    };
    for ring in 0..RINGS {
        for sector in 0..SECTORS {
            let next = (sector + 1) % SECTORS;
            let corners = [
                vertex(ring, sector),
                vertex(ring + 1, sector),
                vertex(ring + 1, next),
                vertex(ring, next),
            ];
            let [Some(a), Some(b), Some(c), Some(d)] = corners else {
                continue;
            };
            fill(target, [a, b, c], &grass, false);
            fill(target, [a, c, d], &grass, false);
        }
    }
}

fn render(
    tree: &Tree,
    season: Season,
    out: &std::path::Path,
) -> Result<(usize, usize), Box<dyn std::error::Error>> {
    let meshes = build_tree_meshes_in(tree, season);
    let (lo, hi) = meshes.bounds(0).ok_or("the tree has no geometry")?;
    let center = (lo + hi) * 0.5;
    let size = (hi - lo).max_element().max(0.5);
    let fov = 35f32.to_radians();
    let distance = 0.62 * size / (fov * 0.5).tan() + 0.5 * size;
    let eye = center + Vec3::new(0.0, 0.18, 1.0).normalize() * distance;
    let world_to_view = look_at_mat4(eye, center, Vec3::Y);
    let clip_from_view = perspective(
        fov,
        WIDTH as f32 / HEIGHT as f32,
        0.05 * distance,
        4.0 * distance,
    );
    let clip_from_world = clip_from_view * world_to_view;
    let mut target = Target {
        color: RgbaImage::from_fn(WIDTH, HEIGHT, |_, y| sky(y)),
        depth: vec![f32::INFINITY; (WIDTH * HEIGHT) as usize],
    };
    let ground_radius = 0.6 * (hi - lo).x.max((hi - lo).z).max(1.0);
    draw_ground(&mut target, tree, ground_radius, clip_from_world);
    let lod = &meshes.lods[0];
    let bark = image::DynamicImage::from(bark_texture(
        meshes.colors.bark_kind,
        meshes.colors.bark,
        128,
    ))
    .to_rgba8();
    let leaf = card_texture(&meshes, 256);
    let fruit = RgbaImage::from_pixel(
        1,
        1,
        Rgba(
            meshes
                .colors
                .fruit
                .map(|c| (c.sqrt() * 255.0) as u8)
                .into_iter()
                .chain([255])
                .collect::<Vec<_>>()
                .try_into()
                .map_err(|_| "colour")?,
        ),
    );
    draw(
        &mut target,
        &lod.branches,
        lod.branches.indices.len(),
        &bark,
        false,
        clip_from_world,
    );
    draw(
        &mut target,
        &meshes.leaves,
        lod.num_leaf_indices,
        &leaf,
        true,
        clip_from_world,
    );
    draw(
        &mut target,
        &meshes.fruit,
        lod.num_fruit_indices,
        &fruit,
        false,
        clip_from_world,
    );
    target.color.save(out)?;
    Ok((tree.skeleton.len(), meshes.num_triangles(0)))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let years_arg = args.next();
    let out_dir = PathBuf::from(args.next().unwrap_or_else(|| "docs/images".into()));
    let season: Season = match args.next() {
        Some(name) => name.parse()?,
        None => Season::Summer,
    };
    std::fs::create_dir_all(&out_dir)?;
    if years_arg.as_deref() == Some("textures") {
        return write_textures(&out_dir);
    }
    let years: f32 = years_arg.and_then(|a| a.parse().ok()).unwrap_or(12.0);
    for species in Species::presets() {
        let name = species.name.clone();
        let mut tree = Tree::new(species, SEED);
        tree.grow_years(years);
        let file = match season {
            Season::Summer => format!("{name}.png"),
            other => format!("{name}_{other}.png"),
        };
        let path = out_dir.join(file);
        let (internodes, triangles) = render(&tree, season, &path)?;
        println!(
            "{}: {internodes} internodes, {triangles} triangles at {years} years",
            path.display()
        );
    }
    Ok(())
}

/// Each species' bark and summer leaf texture, 256 pixels, as `<name>_bark.png` and
/// `<name>_leaf.png` (the leaf over a white card, as it would be seen).
fn write_textures(out_dir: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    for species in Species::presets() {
        let looks = species.looks();
        let bark = bark_texture(looks.bark.kind, looks.bark.color, 256);
        bark.save(out_dir.join(format!("{}_bark.png", species.name)))?;
        let leaf = leaf_texture(looks.leaf_shape, looks.leaf_color.summer, 256);
        let on_white = RgbaImage::from_fn(256, 256, |x, y| {
            let p = leaf.get_pixel(x, y);
            if p[3] == 0 {
                Rgba([255, 255, 255, 255])
            } else {
                *p
            }
        });
        on_white.save(out_dir.join(format!("{}_leaf.png", species.name)))?;
        println!("{}: bark and leaf textures", species.name);
    }
    Ok(())
}
