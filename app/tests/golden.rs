//! Golden images rendered on lavapipe (Mesa's CPU Vulkan): a grown tree from fixed views, an AR
//! composite where a wall in front hides the lower trunk, the tree's shadow on the ground, and
//! every species preset at 15 and 40 years in summer and winter (the maple and the birch in
//! autumn too), side views under one framing rule (`species/*.png`, the README's pictures).
//!
//! Tolerance: a pixel differs when any channel differs by more than 12 (of 255); an image matches
//! when at most 0.5 % of its pixels differ. On a mismatch the test writes `NAME-actual.png` and
//! `NAME-difference.png` next to the golden. `SYLVA_BLESS=1` rewrites the goldens.
//!
//! Run: `XDG_RUNTIME_DIR=/tmp/sylva-xdg WGPU_BACKEND=vulkan cargo test --release -p sylva-app --test golden`

mod golden_compare;

use std::path::PathBuf;

use golden_compare::{assert_matches_golden, differs};

use glam::Vec3;
use image::{Rgba, RgbaImage};
use sylva_app::render::offscreen::OFFSCREEN_FORMAT;
use sylva_app::render::{
    FrameView, Gpu, GroundPlane, Intrinsics, OccluderMesh, Offscreen, Renderer, TreeMesh,
    ViewCamera,
};
use sylva_app::tree_model::TreeMesher;
use sylva_core::Tree;
use sylva_core::geometry::Season;
use sylva_core::species::Species;

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;

struct Bench {
    gpu: Gpu,
    renderer: Renderer,
    target: Offscreen,
}

fn bench_with(tree: &TreeMesh) -> Bench {
    let gpu = Gpu::headless().expect("a wgpu adapter (lavapipe: WGPU_BACKEND=vulkan)");
    let mut renderer = Renderer::new(&gpu, OFFSCREEN_FORMAT);
    renderer.set_tree(&gpu, tree);
    let target = Offscreen::new(&gpu.device, WIDTH, HEIGHT);
    Bench {
        gpu,
        renderer,
        target,
    }
}

impl Bench {
    fn render(&mut self, view: &FrameView) -> RgbaImage {
        let image = self
            .target
            .render(&self.gpu, &mut self.renderer, view)
            .expect("offscreen frame");
        if let Some(dir) = std::env::var_os("SYLVA_GOLDEN_DEBUG") {
            let n = std::fs::read_dir(&dir).map_or(0, |d| d.count());
            let _ = image.save(PathBuf::from(dir).join(format!("debug-{n:03}.png")));
        }
        image
    }
}

fn grown_tree() -> TreeMesh {
    sylva_app::tree_model::golden_tree_mesh()
}

fn num_pixels_unlike(image: &RgbaImage, colour: Rgba<u8>) -> usize {
    image.pixels().filter(|p| differs(p, &colour, 20)).count()
}

#[test]
fn a_grown_tree_from_three_fixed_views_matches_its_goldens() {
    let tree = grown_tree();
    let (lo, hi) = tree.bounds().expect("the tree has geometry");
    let centre = 0.5 * (lo + hi);
    let distance = (hi - lo).length() * 1.3;
    let mut bench = bench_with(&tree);
    let k = Intrinsics::from_fov(WIDTH, HEIGHT, 1.0);
    let views = [
        ("tree_front", Vec3::new(0.0, 0.3, 1.0)),
        ("tree_side", Vec3::new(1.0, 0.45, 0.1)),
        ("tree_above", Vec3::new(0.3, 1.0, 0.6)),
    ];
    for (name, direction) in views {
        let eye = centre + direction.normalize() * distance;
        let image = bench.render(&FrameView::tree_only(ViewCamera::looking_at(
            k, eye, centre,
        )));
        // The tree fills a real part of the frame: neither empty nor all bark.
        let sky_corner = *image.get_pixel(2, 2);
        let covered = num_pixels_unlike(&image, sky_corner);
        assert!(
            covered > 2_000,
            "{name}: only {covered} pixels differ from the sky"
        );
        assert_matches_golden(name, &image);
    }
}

/// A synthetic AR frame: lawn below the horizon, sky above, and a 0.4 m high wall (a box) 0.7 m
/// in front of the tree; the camera image is rendered on the CPU from the same camera.
struct WallScene {
    camera: ViewCamera,
    wall: OccluderMesh,
    wall_top: f32,
    image: RgbaImage,
}

const WALL: Rgba<u8> = Rgba([176, 120, 96, 255]);

fn wall_scene() -> WallScene {
    let k = Intrinsics::from_fov(WIDTH, HEIGHT, 1.1);
    let camera = ViewCamera::looking_at(k, Vec3::new(0.0, 0.9, 2.6), Vec3::new(0.0, 0.6, 0.0));
    let wall_top = 0.4;
    let (wall_lo, wall_hi) = (Vec3::new(-0.6, 0.0, 0.65), Vec3::new(0.6, wall_top, 0.75));
    let mut wall = OccluderMesh::default();
    wall.add_box(wall_lo, wall_hi);
    let eye = camera.position();
    let image = RgbaImage::from_fn(WIDTH, HEIGHT, |x, y| {
        let ray_in_camera = k.ray_from_pixel(glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
        let ray = camera.world_from_camera.transform_vector3(ray_in_camera);
        // Front face of the wall (z = wall_hi.z, facing the camera).
        let t_wall = (wall_hi.z - eye.z) / ray.z;
        let at_wall = eye + ray * t_wall;
        if t_wall > 0.0
            && (wall_lo.x..=wall_hi.x).contains(&at_wall.x)
            && (wall_lo.y..=wall_hi.y).contains(&at_wall.y)
        {
            return WALL;
        }
        // Its top face, seen from above.
        let t_top = (wall_hi.y - eye.y) / ray.y;
        let at_top = eye + ray * t_top;
        if t_top > 0.0
            && (wall_lo.x..=wall_hi.x).contains(&at_top.x)
            && (wall_lo.z..=wall_hi.z).contains(&at_top.z)
        {
            return WALL;
        }
        if ray.y < 0.0 {
            let g = eye + ray * (-eye.y / ray.y);
            let stripe = ((g.x * 4.0).floor() as i32 & 1) as u8 * 12;
            Rgba([70 + stripe, 130 + stripe, 60, 255])
        } else {
            Rgba([170, 200, 235, 255])
        }
    });
    WallScene {
        camera,
        wall,
        wall_top,
        image,
    }
}

/// Pixels along the trunk's first internodes, with their heights.
fn trunk_pixels(camera: &ViewCamera, heights: &[f32]) -> Vec<(f32, u32, u32)> {
    heights
        .iter()
        .filter_map(|&h| {
            let p = camera.pixel_from_world(sylva_app::tree_model::golden_trunk_point(h))?;
            Some((h, p.x as u32, p.y as u32))
        })
        .collect()
}

#[test]
fn in_ar_a_wall_in_front_hides_the_lower_trunk_and_not_the_upper() {
    let scene = wall_scene();
    let mut bench = bench_with(&grown_tree());
    bench.renderer.set_occluder(&bench.gpu, &scene.wall);
    bench
        .renderer
        .set_camera_image(&bench.gpu, scene.image.as_raw(), scene.camera.intrinsics);
    let mut view = FrameView::augmented(scene.camera, Some(GroundPlane::default()));
    view.lighting.shadow_strength = 0.0;
    let occluded = bench.render(&view);
    view.occlude = false;
    let unoccluded = bench.render(&view);

    // The wall is nearer than the tree everywhere, so a trunk point is hidden exactly where
    // the camera image shows the wall at its pixel.
    let heights: Vec<f32> = (1..20).map(|i| i as f32 * 0.04).collect();
    let (mut num_hidden, mut num_visible) = (0, 0);
    for (h, x, y) in trunk_pixels(&scene.camera, &heights) {
        let background = *scene.image.get_pixel(x, y);
        let drawn = *occluded.get_pixel(x, y);
        if background == WALL {
            num_hidden += 1;
            assert!(
                h < scene.wall_top,
                "a point above the wall top cannot be hidden"
            );
            assert!(
                !differs(&drawn, &WALL, 3),
                "trunk at {h} m behind the wall was drawn at ({x}, {y}): {drawn:?}"
            );
            assert!(
                differs(unoccluded.get_pixel(x, y), &WALL, 20),
                "without occlusion the trunk at {h} m must show at ({x}, {y})"
            );
        } else {
            num_visible += 1;
            assert!(
                differs(&drawn, &background, 20),
                "visible trunk at {h} m is missing at ({x}, {y})"
            );
        }
    }
    assert!(
        num_hidden >= 3 && num_visible >= 3,
        "hidden {num_hidden}, visible {num_visible}: the scene must test both"
    );
    // Seen from below, the crown shows the undersides of its leaves, which the sun lights
    // through the blade: no leaf is drawn black (with one-sided leaves 21.9 % of this frame was
    // near black, every channel under 40; with two-sided leaves 1.7 %, the trunk's shaded side).
    let num_black = occluded
        .pixels()
        .filter(|p| p.0[..3].iter().all(|&c| c < 40))
        .count();
    let black_share = num_black as f64 / f64::from(WIDTH * HEIGHT);
    println!(
        "near-black pixels in the AR frame: {:.2} %",
        100.0 * black_share
    );
    assert!(
        black_share < 0.04,
        "{:.2} % of the frame is near black",
        100.0 * black_share
    );
    assert_matches_golden("ar_wall_occlusion", &occluded);
}

#[test]
fn the_tree_casts_a_soft_shadow_on_the_ground() {
    let tree = grown_tree();
    let (lo, hi) = tree.bounds().expect("the tree has geometry");
    let crown = 0.5 * (lo + hi);
    let mut bench = bench_with(&tree);
    let plain = RgbaImage::from_pixel(WIDTH, HEIGHT, Rgba([150, 150, 150, 255]));
    let k = Intrinsics::from_fov(WIDTH, HEIGHT, 1.2);
    bench
        .renderer
        .set_camera_image(&bench.gpu, plain.as_raw(), k);
    // From the side the shadow falls towards (the sun is behind the tree): the leaf cards' dense
    // crown would hide a shadow cast away from the camera.
    let eye = crown + Vec3::new(0.0, 2.5, -2.2);
    let mut view = FrameView::augmented(
        ViewCamera::looking_at(k, eye, Vec3::ZERO),
        Some(GroundPlane::default()),
    );
    let sun = view.lighting.sun_direction;
    let image = bench.render(&view);
    // The crown's shadow falls where the ray from the crown centre away from the sun meets y = 0.
    let shadow_centre = crown - sun * (crown.y / sun.y);
    // Beside the tree on the sun's side, towards the camera: lit and not hidden by the tree.
    let size = (hi - lo).length();
    let lit_ground = Vec3::new(0.6 * size * sun.x.signum(), 0.0, -0.3 * size);
    let is_shadow = |p: &Rgba<u8>| p.0[0] == p.0[1] && p.0[1] == p.0[2] && p.0[0] < 140;
    let num_shadowed_near = |centre: Vec3| {
        let c = view
            .camera
            .pixel_from_world(centre)
            .expect("in front of the camera");
        image
            .enumerate_pixels()
            .filter(|(x, y, p)| {
                glam::Vec2::new(*x as f32, *y as f32).distance(c) < 40.0 && is_shadow(p)
            })
            .count()
    };
    let near_shadow = num_shadowed_near(shadow_centre);
    let near_lit = num_shadowed_near(Vec3::new(lit_ground.x, 0.0, lit_ground.z));
    assert!(
        near_shadow > 60,
        "only {near_shadow} shadowed pixels where the crown's shadow falls"
    );
    assert_eq!(near_lit, 0, "shadow where the sun shines");
    // Soft: between full shadow and no shadow there are intermediate tones.
    let num_tones = image
        .pixels()
        .filter(|p| p.0[0] == p.0[1] && p.0[1] == p.0[2] && p.0[0] < 150)
        .map(|p| p.0[0])
        .collect::<std::collections::BTreeSet<_>>()
        .len();
    assert!(num_tones > 20, "only {num_tones} shadow tones: not soft");
    view.lighting.shadow_strength = 0.0;
    let unshadowed = bench.render(&view);
    assert!(
        num_pixels_unlike(&unshadowed, plain.get_pixel(0, 0).to_owned())
            < num_pixels_unlike(&image, *plain.get_pixel(0, 0))
    );
    assert_matches_golden("ground_shadow", &image);
}

/// Size of the species pictures, pixels (portrait).
const SPECIES_WIDTH: u32 = 360;
const SPECIES_HEIGHT: u32 = 480;
/// Seed of the species pictures (the suite's reference tree of each preset).
const SPECIES_SEED: u64 = 2014;

/// Height of the world shown by a species picture of a tree of `years`, metres: the same for
/// every species, so their sizes compare (the tallest preset, the Lombardy poplar, is about
/// 15 m at 15 years and 32 m at 40).
fn frame_height_m(years: u32) -> f32 {
    if years <= 15 { 18.0 } else { 36.0 }
}

/// The framing rule of the species pictures: a side view from far away (near orthographic),
/// looking 6° down at the middle of a frame whose bottom edge is just below the tree's base
/// and whose height is [`frame_height_m`].
fn species_camera(years: u32) -> ViewCamera {
    let height_m = frame_height_m(years);
    let distance_m = 4.0 * height_m;
    let vertical_fov = 2.0 * (0.5 * height_m / distance_m).atan();
    let aspect = SPECIES_WIDTH as f32 / SPECIES_HEIGHT as f32;
    let horizontal_fov = 2.0 * ((0.5 * vertical_fov).tan() * aspect).atan();
    let k = Intrinsics::from_fov(SPECIES_WIDTH, SPECIES_HEIGHT, horizontal_fov);
    let target = Vec3::new(0.0, 0.45 * height_m, 0.0);
    let elevation = 6f32.to_radians();
    let eye = target + Vec3::new(0.0, elevation.sin(), elevation.cos()) * distance_m;
    let mut camera = ViewCamera::looking_at(k, eye, target);
    camera.near = 0.5 * distance_m;
    camera.far = 2.0 * distance_m;
    camera
}

/// The pictures of one species: its ages and seasons.
fn species_pictures(name: &str) -> Vec<(u32, Season)> {
    let mut seasons = vec![Season::Summer, Season::Winter];
    if name == "maple" || name == "birch" {
        seasons.push(Season::Autumn);
    }
    [15, 40]
        .into_iter()
        .flat_map(|years| seasons.iter().map(move |&s| (years, s)))
        .collect()
}

#[test]
fn every_species_at_15_and_40_years_in_its_seasons_matches_its_golden_picture() {
    let gpu = Gpu::headless().expect("a wgpu adapter (lavapipe: WGPU_BACKEND=vulkan)");
    let mut renderer = Renderer::new(&gpu, OFFSCREEN_FORMAT);
    let target = Offscreen::new(&gpu.device, SPECIES_WIDTH, SPECIES_HEIGHT);
    let mut mesher = TreeMesher::default();
    let mut failures = Vec::new();
    for species in Species::presets() {
        let name = species.name.clone();
        let evergreen = species.looks().evergreen;
        let mut grown: Option<(u32, Tree)> = None;
        for (years, season) in species_pictures(&name) {
            if grown.as_ref().is_none_or(|(y, _)| *y != years) {
                let mut tree = Tree::new(species.clone(), SPECIES_SEED);
                tree.grow_years(years as f32);
                grown = Some((years, tree));
            }
            let Some((_, tree)) = grown.as_ref() else {
                continue;
            };
            let mesh = mesher.mesh_in(tree, season);
            let num_cards = mesh.cards().len();
            let num_fruit_triangles = mesh.finest().map_or(0, |l| l.fruit.indices.len() / 3);
            renderer.set_tree(&gpu, mesh);
            let view = FrameView::tree_only(species_camera(years));
            let image = target
                .render(&gpu, &mut renderer, &view)
                .expect("offscreen frame");
            let picture = format!("species/{name}_{years}_{season}");
            println!(
                "{picture}: {} internodes, {num_cards} cards, {num_fruit_triangles} fruit \
                 triangles, level {} drawn",
                tree.skeleton.len(),
                renderer.drawn_level()
            );
            // A deciduous tree stands leafless in winter, an evergreen keeps its needles.
            let leafless = season == Season::Winter && !evergreen;
            assert_eq!(num_cards == 0, leafless, "{picture}: {num_cards} cards");
            let covered = num_pixels_unlike(&image, *image.get_pixel(2, 2));
            assert!(covered > 2_000, "{picture}: only {covered} pixels drawn");
            if let Err(e) = std::panic::catch_unwind(|| assert_matches_golden(&picture, &image)) {
                failures.push(format!("{picture}: {e:?}"));
            }
        }
    }
    assert!(failures.is_empty(), "{} pictures differ", failures.len());
}

#[test]
fn a_distant_tree_draws_a_coarser_level_of_detail_than_a_near_one() {
    let tree = grown_tree();
    let (lo, hi) = tree.bounds().expect("the tree has geometry");
    let (centre, size) = (0.5 * (lo + hi), (hi - lo).length());
    let mut bench = bench_with(&tree);
    let k = Intrinsics::from_fov(WIDTH, HEIGHT, 1.0);
    let mut levels = Vec::new();
    for distance in [1.3, 5.0, 15.0, 60.0].map(|f| f * size) {
        let eye = centre + Vec3::new(0.0, 0.3, 1.0).normalize() * distance;
        let mut camera = ViewCamera::looking_at(k, eye, centre);
        camera.far = 2.0 * distance;
        let image = bench.render(&FrameView::tree_only(camera));
        levels.push(bench.renderer.drawn_level());
        let covered = num_pixels_unlike(&image, *image.get_pixel(2, 2));
        assert!(covered > 0, "the tree at {distance} m is drawn");
    }
    println!("levels drawn from near to far: {levels:?}");
    assert_eq!(levels[0], 0, "near, the finest level");
    assert_eq!(levels[3], 2, "far, the coarsest level");
    assert!(levels.windows(2).all(|w| w[0] <= w[1]), "{levels:?}");
    assert!(
        tree.levels[2].num_triangles() * 4 < tree.levels[0].num_triangles(),
        "the coarsest level draws far fewer triangles"
    );
}
