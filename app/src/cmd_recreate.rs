//! `sylva recreate FOOTAGE --marks MARKS.json [--species S] [--holding-height-m H] --out tree.json
//! [--glb tree.glb] [--report report.json] [--silhouettes DIR] [--crown-masks DIR]`: tracks the footage with Sylva's
//! own tracker, measures the real tree from the marks ([`crate::recreate`]), grows a species into
//! it, and ends with one line
//! `height_m= crown_width_m= crown_base_m= tree_points= internodes= outline_iou=`
//! (`outline_iou`: the model's silhouette against the traced outline, mean over the marked views).

use std::path::PathBuf;

use anyhow::Context;
use glam::DAffine3;
use serde::Serialize;

use crate::recreate::footage::track_footage;
use crate::recreate::grow::GrowthReport;
use crate::recreate::marks::Marks;
use crate::recreate::measure::Measurements;
use crate::recreate::silhouette::{Silhouette, WorldTriangles};

#[derive(clap::Args, Debug)]
pub struct RecreateArgs {
    /// A TUM-layout footage folder (rgb.txt, camera.txt, ...).
    pub footage: PathBuf,
    /// The marks: `{"base": {"frame": I, "pixel": [u, v]}, "crown": [{"frame": J, "outline":
    /// [[u, v], ...]}, ...]}` (frames 0-based in rgb.txt order, pixels as stored).
    #[arg(long)]
    pub marks: PathBuf,
    /// A preset name or species file; by default the preset closest to the measured proportions.
    #[arg(long)]
    pub species: Option<String>,
    /// Height the camera is held at above the ground, metres (sets the metric scale).
    #[arg(long, default_value_t = sylva_tracking::scale::DEFAULT_HOLDING_HEIGHT_M,
          value_parser = parse_holding_height_m)]
    pub holding_height_m: f64,
    /// Where to save the grown tree (versioned JSON, in its own space: trunk base at the origin).
    #[arg(long)]
    pub out: PathBuf,
    /// Also export the tree's meshes as binary glTF 2.0, in the footage's world frame.
    #[arg(long)]
    pub glb: Option<PathBuf>,
    /// Writes measurements, methods, species, trunk base, cameras and intrinsics as JSON.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Writes the model's silhouette in every tracked frame as `DIR/NNNNN.png` (frame index).
    #[arg(long)]
    pub silhouettes: Option<PathBuf>,
    /// Writes the crown as segmented in the footage's frames as `DIR/NNNNN.png` (frame index).
    #[arg(long)]
    pub crown_masks: Option<PathBuf>,
    /// Seed of the tree's random generator.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Most years of growth spent filling the hull.
    #[arg(long, default_value_t = 40.0)]
    pub max_years: f32,
}

fn parse_holding_height_m(text: &str) -> Result<f64, String> {
    let metres: f64 = text
        .parse()
        .map_err(|_| format!("`{text}` is not a height in metres"))?;
    sylva_tracking::scale::validate_holding_height_m(metres).map_err(|e| e.to_string())
}

/// One tracked frame in the report.
#[derive(Serialize)]
struct FramePose {
    frame: usize,
    /// Row-major 3 × 4 `[R | t]` of `world_from_camera` (camera axes X right, Y down, Z forward).
    world_from_camera: [[f64; 4]; 3],
}

#[derive(Serialize)]
struct Intrinsics {
    width: u32,
    height: u32,
    fx: f64,
    fy: f64,
    cx: f64,
    cy: f64,
    distortion: [f64; 5],
}

#[derive(Serialize)]
struct Report<'a> {
    footage: String,
    measurements: &'a Measurements,
    growth: &'a GrowthReport,
    /// Intersection over union of the model's silhouette and each traced outline.
    outline_iou: Vec<(usize, f64)>,
    outline_iou_mean: f64,
    internodes: usize,
    /// `world_from_tree`: the tree file's space in the world, row-major 3 × 4.
    world_from_tree: [[f64; 4]; 3],
    metres_per_unit: f64,
    scale_source: &'a str,
    intrinsics: Intrinsics,
    frames: Vec<FramePose>,
    num_frames: usize,
}

fn rows(pose: &DAffine3) -> [[f64; 4]; 3] {
    let m = pose.matrix3;
    let t = pose.translation;
    [
        [m.x_axis.x, m.y_axis.x, m.z_axis.x, t.x],
        [m.x_axis.y, m.y_axis.y, m.z_axis.y, t.y],
        [m.x_axis.z, m.y_axis.z, m.z_axis.z, t.z],
    ]
}

pub fn recreate(args: RecreateArgs) -> anyhow::Result<()> {
    // Marks are read and checked against the footage's size before the (long) tracking.
    let marks = Marks::from_file(&args.marks)?;
    let sequence = sylva_tracking::TumSequence::open(&args.footage)
        .with_context(|| format!("cannot open the footage {}", args.footage.display()))?;
    let (width, height) = (sequence.camera.width, sequence.camera.height);
    marks
        .validate(sequence.frames.len(), width, height)
        .with_context(|| format!("bad marks in {}", args.marks.display()))?;
    let species = args
        .species
        .as_deref()
        .map(crate::cmd_grow::load_species)
        .transpose()?;
    drop(sequence);
    let footage = track_footage(&args.footage, args.holding_height_m)
        .with_context(|| format!("tracking {}", args.footage.display()))?;
    // The frames' images, for segmenting the crown (a frame that does not load is left out).
    let images = crate::footage::Footage::open(&args.footage)?;
    let load = |frame: usize| {
        let rgba = images.load_rgba(frame).ok()?;
        Some(image::DynamicImage::ImageRgba8(rgba).into_rgb8())
    };
    let load: crate::recreate::segment::FrameSource = &load;
    let recreated = crate::recreate::recreate(
        &footage,
        &marks,
        species,
        args.seed,
        args.max_years,
        Some(load),
        // track_footage has scaled the world to metres.
        1.0,
    )
    .with_context(|| format!("bad marks in {}", args.marks.display()))?;
    let (tree, world_from_tree) = (&recreated.tree, recreated.world_from_tree);
    let (m, growth) = (&recreated.recreation.measurements, &recreated.growth);
    tree.save(&args.out)?;
    let meshes = recreated.world_meshes();
    if let Some(path) = &args.glb {
        sylva_core::export::write_glb(&meshes, path)?;
    }
    let model = WorldTriangles::of_meshes(&meshes, &glam::Affine3A::IDENTITY);
    let outline_iou = recreated.outline_iou.clone();
    let iou_mean = recreated.outline_iou_mean();
    if let Some(dir) = &args.silhouettes {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        for (frame, pose) in footage.world_from_camera.iter().enumerate() {
            if pose.is_some() {
                let path = dir.join(format!("{frame:05}.png"));
                Silhouette::render(&footage, frame, &model)
                    .save_png(&path)
                    .with_context(|| format!("writing {}", path.display()))?;
            }
        }
    }
    if let Some(dir) = &args.crown_masks {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        for mask in &recreated.crown_masks {
            let path = dir.join(format!("{:05}.png", mask.frame));
            mask.save_png(&path)
                .with_context(|| format!("writing {}", path.display()))?;
        }
    }
    let internodes = tree.skeleton.len();
    if let Some(path) = &args.report {
        let c = &footage.camera;
        let world_from_tree_d = DAffine3 {
            matrix3: world_from_tree.matrix3.as_dmat3(),
            translation: world_from_tree.translation.as_dvec3(),
        };
        let report = Report {
            footage: args.footage.display().to_string(),
            measurements: m,
            growth,
            outline_iou: outline_iou.clone(),
            outline_iou_mean: iou_mean,
            internodes,
            world_from_tree: rows(&world_from_tree_d),
            metres_per_unit: footage.metres_per_unit,
            scale_source: &footage.scale_source,
            intrinsics: Intrinsics {
                width: c.width,
                height: c.height,
                fx: c.fx,
                fy: c.fy,
                cx: c.cx,
                cy: c.cy,
                distortion: c.distortion,
            },
            frames: footage
                .world_from_camera
                .iter()
                .enumerate()
                .filter_map(|(frame, pose)| {
                    pose.map(|p| FramePose {
                        frame,
                        world_from_camera: rows(&p),
                    })
                })
                .collect(),
            num_frames: footage.world_from_camera.len(),
        };
        let json = serde_json::to_string_pretty(&report).context("encoding the report")?;
        std::fs::write(path, json).with_context(|| format!("writing {}", path.display()))?;
    }
    if let Some(note) = &m.methods.crown_depth {
        println!("note: {note}");
    }
    println!(
        "species={} ({}); grew {:.1} years, hull {:.0}% filled",
        growth.species,
        growth.species_choice,
        growth.age_years,
        growth.hull_filled * 100.0
    );
    if let Some(voxels) = growth.crown_voxels {
        println!(
            "crown: segmented in {} views, {voxels} of the hull's {} voxels kept",
            growth.segmented_views, m.hull_voxels
        );
    }
    if let Some(t) = &growth.trunk {
        println!(
            "trunk: seen in {} views ({} agree), base moved {:.3} m, diameter {:.3} m (model's widths x{:.2})",
            t.views,
            t.agreeing_views,
            t.shift_m,
            t.diameter_m,
            growth.trunk_width_ratio.unwrap_or(1.0)
        );
    }
    if let Some(f) = &growth.foliage {
        println!(
            "foliage: leaves x{:.2}, density x{:.2} (IoU with the crown {:.3} -> {:.3})",
            f.leaf_scale, f.density_scale, f.iou_before, f.iou_after
        );
    }
    println!(
        "height_m={:.3} crown_width_m={:.3} crown_base_m={:.3} tree_points={} internodes={} outline_iou={:.3}",
        m.height_m, m.crown_width_m, m.crown_base_m, m.tree_points, internodes, iou_mean
    );
    Ok(())
}
