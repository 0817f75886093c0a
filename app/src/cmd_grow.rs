//! `sylva species` and `sylva grow`: the growth model from the command line.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use sylva_core::Tree;
use sylva_core::geometry::Season;
use sylva_core::growth::TreeFileFormat;
use sylva_core::species::Species;

use crate::limits::{MAX_DESIGN_YEARS, MAX_ITERATIONS_PER_REQUEST};

/// Arguments of `sylva grow`.
#[derive(clap::Args, Debug)]
pub struct GrowArgs {
    /// A preset name (see `sylva species`) or a species JSON file.
    #[arg(long)]
    pub species: String,
    /// Years of autonomous growth.
    #[arg(long)]
    pub years: f32,
    /// Seed of the tree's random generator.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Where to save the grown tree (versioned JSON, or compact with `--format compact`).
    #[arg(long)]
    pub out: PathBuf,
    /// The tree file's format: readable JSON, or compact (CBOR in a checked frame, about 60% of
    /// the size; `sylva` and the app load either).
    #[arg(long, value_enum, default_value_t = TreeFormat::Json)]
    pub format: TreeFormat,
    /// Also export the tree's meshes (three levels of detail, leaves, textures) as binary glTF 2.0.
    #[arg(long)]
    pub glb: Option<PathBuf>,
    /// Write the `--glb` file for readers without `EXT_mesh_gpu_instancing` and `MSFT_lod`
    /// (Blender 3.4): the finest level only, its leaf cards as plain triangles.
    #[arg(long, requires = "glb")]
    pub glb_compat: bool,
    /// Also export the finest level of detail as Wavefront OBJ + MTL, textures next to it.
    #[arg(long)]
    pub obj: Option<PathBuf>,
    /// The season the exported meshes show: spring, summer, autumn or winter (deciduous trees
    /// leafless, conifers keep their needles).
    #[arg(long, default_value_t = Season::Summer)]
    pub season: Season,
}

/// The formats of `--format`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TreeFormat {
    Json,
    Compact,
}

impl From<TreeFormat> for TreeFileFormat {
    fn from(format: TreeFormat) -> Self {
        match format {
            TreeFormat::Json => TreeFileFormat::Json,
            TreeFormat::Compact => TreeFileFormat::Compact,
        }
    }
}

/// Prints one line per preset, starting with its name.
pub fn species() -> anyhow::Result<()> {
    for s in Species::presets() {
        let e = &s.expected;
        println!(
            "{:16} {} ({}): {:.1} m tall, {:.1} m wide at 10 years; {:.1} m tall, {:.1} m wide at 30 years",
            s.name,
            s.common_name,
            s.latin_name,
            e.height_10y_m,
            e.spread_10y_m,
            e.height_30y_m,
            e.spread_30y_m
        );
    }
    Ok(())
}

/// A preset by name, else a species file.
pub(crate) fn load_species(name_or_file: &str) -> anyhow::Result<Species> {
    match Species::by_name(name_or_file) {
        Ok(s) => Ok(s),
        Err(preset_error) => {
            let path = Path::new(name_or_file);
            if path.exists() {
                Ok(Species::from_file(path)?)
            } else {
                Err(preset_error)
                    .context(format!("{name_or_file:?} is neither a preset nor a file"))
            }
        }
    }
}

/// Grows a tree autonomously, saves it and prints a `key=value` summary line.
pub fn grow(args: GrowArgs) -> anyhow::Result<()> {
    if !(args.years.is_finite() && (0.0..=MAX_DESIGN_YEARS).contains(&args.years)) {
        anyhow::bail!(
            "--years must be a number from 0 to {MAX_DESIGN_YEARS}, got {}",
            args.years
        );
    }
    check_grow_files(&args)?;
    let species = load_species(&args.species)?;
    let iterations = species.iterations_for_years(args.years);
    if iterations > MAX_ITERATIONS_PER_REQUEST {
        anyhow::bail!(
            "--years {} of {} is {iterations} growth iterations ({} years each); at most {MAX_ITERATIONS_PER_REQUEST} are grown at once",
            args.years,
            args.species,
            species.years_per_iteration
        );
    }
    let (started, cpu_started) = (Instant::now(), process_cpu_ms());
    let mut tree = Tree::new(species, args.seed);
    tree.grow_years(args.years);
    let elapsed_ms = started.elapsed().as_secs_f64() * 1000.0;
    let cpu_ms = process_cpu_ms() - cpu_started;
    tree.save_as(&args.out, args.format.into())?;
    let glb_options = if args.glb_compat {
        sylva_core::export::GlbOptions::compat()
    } else {
        sylva_core::export::GlbOptions::default()
    };
    let glb = args.glb.as_deref().map(|path| (path, glb_options));
    export_meshes(&tree, args.season, glb, args.obj.as_deref())?;
    let m = tree.metrics();
    println!(
        "internodes={} height_m={:.3} crown_width_m={:.3} trunk_diameter_m={:.4} elapsed_ms={:.1} cpu_ms={:.1} threads={}",
        m.num_internodes,
        m.height_m,
        m.crown_width_m,
        m.trunk_diameter_m,
        elapsed_ms,
        cpu_ms,
        rayon::current_num_threads()
    );
    Ok(())
}

/// CPU time of this process so far (all threads), milliseconds; NaN where the clock is missing.
fn process_cpu_ms() -> f64 {
    #[cfg(unix)]
    {
        let mut ts = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: `ts` is a valid, writable timespec; the call only writes to it.
        if unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) } == 0 {
            return ts.tv_sec as f64 * 1e3 + ts.tv_nsec as f64 / 1e6;
        }
    }
    f64::NAN
}

/// Refuses, before growing, outputs that are the species file or each other (`--out t.json
/// --glb t.json`), and outputs that are not regular writable files.
fn check_grow_files(args: &GrowArgs) -> anyhow::Result<()> {
    let species_file = Species::by_name(&args.species)
        .is_err()
        .then(|| PathBuf::from(&args.species));
    let mut outputs = vec![args.out.clone()];
    outputs.extend(args.glb.clone());
    outputs.extend(
        args.obj
            .iter()
            .flat_map(|p| sylva_core::export::obj_files(p)),
    );
    let outputs: Vec<&Path> = outputs.iter().map(PathBuf::as_path).collect();
    crate::outputs::check_outputs(
        &species_file
            .iter()
            .map(PathBuf::as_path)
            .collect::<Vec<_>>(),
        &outputs,
    )
}

/// Writes the `--glb` and `--obj` files of the tree in `season`, if asked for, one line each
/// (before the summary line, which stays the last line of the output).
fn export_meshes(
    tree: &Tree,
    season: Season,
    glb: Option<(&Path, sylva_core::export::GlbOptions)>,
    obj: Option<&Path>,
) -> anyhow::Result<()> {
    if glb.is_none() && obj.is_none() {
        return Ok(());
    }
    let meshes = sylva_core::geometry::build_tree_meshes_in(tree, season);
    let triangles = [0, 1, 2].map(|lod| meshes.num_triangles(lod));
    let leaves = meshes.leaves.indices.len() / 6;
    if let Some((path, options)) = glb {
        sylva_core::export::write_glb_with(&meshes, path, options)?;
        println!(
            "glb={} season={season} leaves={leaves} lod_triangles={triangles:?}",
            path.display()
        );
    }
    if let Some(path) = obj {
        sylva_core::export::write_obj(&meshes, path)?;
        println!(
            "obj={} season={season} leaves={leaves} triangles={}",
            path.display(),
            triangles[0]
        );
    }
    Ok(())
}
