//! `sylva garden`: several trees planted together and grown competing for light and space.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use glam::Vec2;
use sylva_core::garden::{
    Garden, Layout, MAX_GARDEN_YEARS, Planting, PlantingFile, RIPLEY_RADIUS_M, ripley_excess,
};

use sylva_core::export::{SceneTree, write_garden_glb, write_garden_obj};

use crate::cmd_grow::load_species;

/// Arguments of `sylva garden`.
#[derive(clap::Args, Debug)]
pub struct GardenArgs {
    /// A planting file: `{"plantings": [...]}` of trees, rows, groups and stands (see README).
    #[arg(long, conflicts_with_all = ["plot", "trees"])]
    pub planting: Option<PathBuf>,
    /// A stand over a plot of W×D metres centred on the origin, e.g. `30x30`.
    #[arg(long, requires = "trees")]
    pub plot: Option<String>,
    /// Trees of the stand.
    #[arg(long, requires = "plot")]
    pub trees: Option<usize>,
    /// Species of the stand, taken in turn (presets or species files).
    #[arg(long, value_delimiter = ',', default_value = "birch,maple,oak")]
    pub species: Vec<String>,
    /// How the stand's trees are spread: uniformly at random or in clusters.
    #[arg(long, value_enum, default_value_t = LayoutArg::Random)]
    pub layout: LayoutArg,
    /// Years the trees grow together after planting.
    #[arg(long)]
    pub years: f32,
    /// Seed of the stand's layout and trees.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Where to save the garden (versioned JSON).
    #[arg(long)]
    pub out: PathBuf,
    /// Also write the garden as binary glTF: one node per tree, named by its planting entry,
    /// textures and materials shared by the trees of a species.
    #[arg(long)]
    pub glb: Option<PathBuf>,
    /// Also write the garden as Wavefront OBJ + MTL: one group per tree, textures once per
    /// species next to it.
    #[arg(long)]
    pub obj: Option<PathBuf>,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum LayoutArg {
    Random,
    Clustered,
}

/// `W×D` or `WxD` in metres.
fn parse_plot(text: &str) -> anyhow::Result<Vec2> {
    let parts: Vec<&str> = text.split(['x', 'X', '×']).collect();
    let [w, d] = parts.as_slice() else {
        anyhow::bail!("--plot {text:?}: expected W×D in metres, e.g. 30x30");
    };
    let w: f32 = w
        .trim()
        .parse()
        .with_context(|| format!("--plot {text:?}: width"))?;
    let d: f32 = d
        .trim()
        .parse()
        .with_context(|| format!("--plot {text:?}: depth"))?;
    Ok(Vec2::new(w, d))
}

fn planting(args: &GardenArgs) -> anyhow::Result<(PlantingFile, String)> {
    if let Some(path) = &args.planting {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read planting file {}", path.display()))?;
        let file: PlantingFile = serde_json::from_str(&text)
            .with_context(|| format!("planting file {} is malformed", path.display()))?;
        return Ok((file, path.display().to_string()));
    }
    let (Some(plot), Some(count)) = (&args.plot, args.trees) else {
        anyhow::bail!("give --planting PLANTING.json, or --plot W×D and --trees N");
    };
    let plot = parse_plot(plot)?;
    let stand = Planting::Stand {
        species: args.species.clone(),
        width_m: plot.x,
        depth_m: plot.y,
        count,
        layout: match args.layout {
            LayoutArg::Random => Layout::Random,
            LayoutArg::Clustered => Layout::Clustered,
        },
        age_years: 0.0,
        seed: args.seed,
    };
    Ok((
        PlantingFile {
            plantings: vec![stand],
        },
        "the command line".into(),
    ))
}

/// The plot the Ripley excess is measured on: the stand's, or the box of the trunk bases.
fn plot_of(args: &GardenArgs, bases: &[Vec2]) -> (Vec2, Vec2) {
    if let Some(plot) = args.plot.as_deref().and_then(|p| parse_plot(p).ok()) {
        return (-plot * 0.5, plot * 0.5);
    }
    let lo = bases
        .iter()
        .fold(Vec2::splat(f32::INFINITY), |a, &b| a.min(b));
    let hi = bases
        .iter()
        .fold(Vec2::splat(f32::NEG_INFINITY), |a, &b| a.max(b));
    (lo, hi)
}

fn figure(value: Option<f32>) -> String {
    value.map_or_else(|| "none".into(), |v| format!("{v:.2}"))
}

/// Plants, grows, saves and prints the summary line.
pub fn garden(args: GardenArgs) -> anyhow::Result<()> {
    if !(args.years.is_finite() && (0.0..=MAX_GARDEN_YEARS).contains(&args.years)) {
        anyhow::bail!(
            "--years must be a number from 0 to {MAX_GARDEN_YEARS}, got {}",
            args.years
        );
    }
    let inputs: Vec<&std::path::Path> = args
        .planting
        .iter()
        .map(PathBuf::as_path)
        .chain(args.species.iter().map(std::path::Path::new))
        .filter(|p| p.is_file())
        .collect();
    crate::outputs::check_outputs(&inputs, &[&args.out])?;
    let (file, origin) = planting(&args)?;
    let resolve = |name: &str| load_species(name).map_err(|e| format!("{e:#}"));
    let trees = file
        .trees(&resolve)
        .with_context(|| format!("bad planting in {origin}"))?;
    let names: Vec<String> = trees
        .iter()
        .enumerate()
        .map(|(k, t)| format!("tree {k} {} (planting {})", t.species.name, t.entry))
        .collect();
    let started = Instant::now();
    let mut garden = Garden::plant(trees).with_context(|| format!("bad planting in {origin}"))?;
    garden.grow_years(args.years);
    let elapsed_ms = started.elapsed().as_secs_f64() * 1000.0;
    garden.save(&args.out)?;
    if args.glb.is_some() || args.obj.is_some() {
        let meshes = garden.tree_meshes();
        let scene: Vec<SceneTree> = garden
            .trees
            .iter()
            .zip(&meshes)
            .zip(names)
            .map(|((t, meshes), name)| SceneTree {
                name,
                species: t.tree.species.name.clone(),
                translation: t.base(),
                meshes,
            })
            .collect();
        if let Some(path) = &args.glb {
            write_garden_glb(&scene, path)?;
        }
        if let Some(path) = &args.obj {
            write_garden_obj(&scene, path)?;
        }
    }
    let crowns = garden.crowns();
    let bases: Vec<Vec2> = crowns
        .iter()
        .map(|c| Vec2::new(c.base.x, c.base.z))
        .collect();
    let centroids: Vec<Vec2> = crowns
        .iter()
        .map(|c| Vec2::new(c.centroid.x, c.centroid.z))
        .collect();
    let (lo, hi) = plot_of(&args, &bases);
    println!(
        "trees={} internodes={} elapsed_ms={:.1} threads={} crown_offset_m={:.3} ripley_excess_bases={} ripley_excess_crowns={}",
        garden.trees.len(),
        garden.num_internodes(),
        elapsed_ms,
        sylva_core::garden::num_threads(),
        garden.mean_crown_offset_m(),
        figure(ripley_excess(&bases, lo, hi, RIPLEY_RADIUS_M)),
        figure(ripley_excess(&centroids, lo, hi, RIPLEY_RADIUS_M)),
    );
    Ok(())
}
