//! The app renderer's time per frame for a tree planted in the demo footage, at two ages, in
//! one run (issue 25, done-when 5): the committed demo session is replayed to find where its
//! tree stands, then an oak of each age is drawn there in every tracked frame of the footage
//! through the renderer the app uses (camera image, depth-mesh occluder, shadow on the ground),
//! offscreen at the footage's size. A frame's time is the upload of its camera image and
//! occluder, the recorded passes, and the wait for the finished frame to be read back.
//! Decoding the footage and meshing the occluder happen before the clock starts.
//!
//! `cargo run --release -p sylva-app --example render_timing [-- SPECIES YEARS_A YEARS_B ROUNDS STRIDE]`
//! (oak, 15, 40, 2 rounds and every 8th frame by default; the ages alternate round by round
//! so a load on the machine falls on both). Run with `XDG_RUNTIME_DIR=/tmp/sylva-xdg WGPU_BACKEND=vulkan` on
//! lavapipe.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use glam::Affine3A;
use sylva_app::footage::Footage;
use sylva_app::planting::{camera_in_tree, ground_in_tree, occluder_in_tree};
use sylva_app::render::offscreen::OFFSCREEN_FORMAT;
use sylva_app::render::{
    FrameView, Gpu, GroundPlane, OccluderMesh, Offscreen, Renderer, ViewCamera,
};
use sylva_app::session::{Session, frame_occluders, replay};
use sylva_app::state::species_named;
use sylva_app::tree_model::TreeMesher;
use sylva_core::Tree;
use sylva_core::geometry::Season;

/// Seed of the timed trees.
const SEED: u64 = 7;

/// One tracked frame, ready to draw: its image, camera, ground and occluder in tree space.
struct Frame {
    rgba: image::RgbaImage,
    camera: ViewCamera,
    ground: Option<GroundPlane>,
    occluder: OccluderMesh,
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    match values.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => values[n / 2],
        n => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let species = args.next().unwrap_or_else(|| "oak".into());
    let mut number = |default: f32| -> anyhow::Result<f32> {
        match args.next() {
            Some(text) => text
                .parse()
                .with_context(|| format!("{text:?} is not a number")),
            None => Ok(default),
        }
    };
    let ages = [number(15.0)?, number(40.0)?];
    let rounds = number(2.0)?.max(1.0) as usize;
    let stride = number(8.0)?.max(1.0) as usize;

    let session_path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/sessions/demo_garden.session.json");
    let session = Session::load(&session_path)?;
    let base = session_path.parent().unwrap_or(std::path::Path::new("."));
    let footage = Footage::open(&base.join(&session.footage))?;
    let report = replay(&session_path, None, false, |_, _| {})?;
    let world_from_tree = report
        .world_from_tree
        .map(|m| Affine3A::from_cols_array(&m))
        .context("the demo session plants no tree")?;
    let tree_from_world = world_from_tree.inverse();

    let mut frames = Vec::new();
    // The occluder grows from every frame's observations, as in the replay.
    for (step, camera, occluder) in frame_occluders(&session, &footage) {
        if step % stride != 0 {
            continue;
        }
        let record = &session.frames[step];
        frames.push(Frame {
            rgba: footage.load_rgba(record.index)?,
            camera: camera_in_tree(&camera, &tree_from_world),
            ground: record
                .ground_plane()
                .map(|g| ground_in_tree(&g, &tree_from_world)),
            occluder: occluder_in_tree(&occluder, &tree_from_world),
        });
    }
    anyhow::ensure!(!frames.is_empty(), "no tracked frame in the demo session");

    let gpu = Gpu::headless()?;
    let (width, height) = (footage.intrinsics.width, footage.intrinsics.height);
    let target = Offscreen::new(&gpu.device, width, height);
    let mut meshes = Vec::new();
    for years in ages {
        let mut tree = Tree::new(species_named(&species), SEED);
        tree.grow_years(years);
        let started = Instant::now();
        let mesh = TreeMesher::default().mesh_in(&tree, Season::Summer).clone();
        let meshing_ms = started.elapsed().as_secs_f64() * 1000.0;
        meshes.push((years, tree.skeleton.len(), mesh, meshing_ms));
    }
    println!(
        "adapter={} frames={} size={width}x{height} species={species} seed={SEED}",
        gpu.adapter_name(),
        frames.len()
    );
    let mut times_ms: Vec<Vec<f64>> = vec![Vec::new(); ages.len()];
    // Frames drawn at each level of detail, per age.
    let mut levels_drawn = vec![[0usize; 3]; ages.len()];
    for round in 0..rounds {
        for i in 0..ages.len() {
            // Alternate which age goes first, so both see the same machine.
            let i = if round % 2 == 0 {
                i
            } else {
                ages.len() - 1 - i
            };
            let mut renderer = Renderer::new(&gpu, OFFSCREEN_FORMAT);
            renderer.set_tree(&gpu, &meshes[i].2);
            for frame in &frames {
                let started = Instant::now();
                renderer.set_camera_image(&gpu, frame.rgba.as_raw(), footage.intrinsics);
                renderer.set_occluder(&gpu, &frame.occluder);
                let view = FrameView::augmented(frame.camera, frame.ground);
                target.render(&gpu, &mut renderer, &view)?;
                times_ms[i].push(started.elapsed().as_secs_f64() * 1000.0);
                levels_drawn[i][renderer.drawn_level().min(2)] += 1;
            }
        }
    }
    let mut medians = Vec::new();
    for (i, (years, internodes, mesh, meshing_ms)) in meshes.iter().enumerate() {
        let times = &mut times_ms[i];
        let mean = times.iter().sum::<f64>() / times.len() as f64;
        let med = median(times);
        medians.push(med);
        println!(
            "years={years} internodes={internodes} triangles={} meshing_ms={meshing_ms:.1} \
             ms_per_frame_median={med:.2} ms_per_frame_mean={mean:.2} frames_timed={} \
             frames_at_levels={:?} triangles_at_levels={:?}",
            mesh.num_triangles(),
            times.len(),
            levels_drawn[i],
            mesh.levels
                .iter()
                .map(|l| l.num_triangles())
                .collect::<Vec<_>>()
        );
    }
    println!(
        "ratio_median={:.2} (years {} over years {})",
        medians[1] / medians[0],
        ages[1],
        ages[0]
    );
    Ok(())
}
