//! Times meshing of a synthetic 100k-internode tree with leaves, in wall-clock and in CPU time
//! of this thread (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`), so the one-core cost can be read
//! on a busy machine where criterion's wall-clock figures include waiting for a core.
//!
//! Two builds: the drawn level of detail (level 0) with leaves and fruit, as the app re-meshes
//! after an edit, and all three levels, as the glTF export does; each with fresh buffers and
//! with a [`Mesher`] and output meshes reused from the previous call.
//!
//! `cargo run --release -p sylva-core --example mesh_timing [num_internodes] [repeats] [only]`
//! (`only`: `level0-fresh`, `level0-reused`, `all-fresh` or `all-reused` times that build
//! alone, for a profiler).
//!
//! `... --example mesh_timing digest [skeleton_dir]` prints instead a digest of every mesh
//! array (positions, normals, uvs, ambient, indices, branch starts, level prefixes) for
//! synthetic skeletons of 1 to 100k internodes under four parameter sets at every level choice,
//! through fresh and reused meshers, and for a skeleton of every species preset meshed with its
//! look. Optimisations that must not change the meshes compare these lines before and after.
//! The preset skeletons are grown once and kept as JSON in `skeleton_dir` (when given), so the
//! digests do not depend on the growth code of the build that prints them.

use std::time::Instant;

use glam::Vec3;
use sylva_core::Tree;
use sylva_core::geometry::synthetic::{branching_skeleton, crown_ambient};
use sylva_core::geometry::{
    FruitParams, LeafParams, Levels, MeshParams, Mesher, TreeMesh, TreeMeshes, mesh_params_for,
};
use sylva_core::species::Species;
use sylva_core::tree::Skeleton;

#[path = "../benches/common/thread_cpu.rs"]
mod thread_cpu;
use thread_cpu::thread_cpu_ns;

fn main() {
    let mut args = std::env::args().skip(1).peekable();
    if args.peek().map(String::as_str) == Some("digest") {
        args.next();
        print_digests(args.next().map(std::path::PathBuf::from));
        return;
    }
    let num_internodes: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(100_000);
    let repeats: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(10);
    let only = args.next();
    let skeleton = branching_skeleton(num_internodes, 7);
    let params = MeshParams {
        fruit: Some(FruitParams::default()),
        ..MeshParams::default()
    };
    let ambient = crown_ambient(Vec3::new(0.0, 1.5, 0.0), 2.0);
    for (what, key, levels) in [
        ("level 0", "level0", Levels::One(0)),
        ("all levels", "all", Levels::All),
    ] {
        for reuse in [false, true] {
            let name = format!("{key}-{}", if reuse { "reused" } else { "fresh" });
            if only.as_ref().is_some_and(|o| *o != name) {
                continue;
            }
            let mut mesher = Mesher::new();
            let mut meshes = TreeMeshes::default();
            let mut best_wall = f64::INFINITY;
            let mut best_cpu = f64::INFINITY;
            for _ in 0..repeats {
                if !reuse {
                    (mesher, meshes) = (Mesher::new(), TreeMeshes::default());
                }
                let (wall, cpu) = (Instant::now(), thread_cpu_ns());
                mesher.build_into(&skeleton, &params, &ambient, levels, &mut meshes);
                best_wall = best_wall.min(wall.elapsed().as_secs_f64() * 1e3);
                if let (Some(a), Some(b)) = (cpu, thread_cpu_ns()) {
                    best_cpu = best_cpu.min((b - a) as f64 * 1e-6);
                }
            }
            let triangles: Vec<String> = (0..meshes.lods.len())
                .map(|l| meshes.num_triangles(l).to_string())
                .collect();
            println!(
                "{num_internodes} internodes, {what}, {} buffers: best of {repeats}: \
                 {best_wall:.1} ms wall, {best_cpu:.1} ms CPU; triangles {}, {} leaves",
                if reuse { "reused" } else { "fresh" },
                triangles.join(" / "),
                meshes.leaves.num_triangles() / 2
            );
        }
    }
    if only.is_none() {
        time_species_foliage(&skeleton, &ambient, repeats);
    }
}

/// The drawn level with reused buffers under each preset's look (its leaf cards, density and
/// leaf-bearing width) on the same synthetic skeleton: the cost of the species foliage.
fn time_species_foliage(skeleton: &Skeleton, ambient: &dyn Fn(Vec3) -> f32, repeats: usize) {
    for species in Species::presets() {
        let params = mesh_params_for(&species);
        let mut mesher = Mesher::new();
        let mut meshes = TreeMeshes::default();
        let mut best_cpu = f64::INFINITY;
        for _ in 0..repeats {
            let cpu = thread_cpu_ns();
            mesher.build_into(skeleton, &params, ambient, Levels::One(0), &mut meshes);
            if let (Some(a), Some(b)) = (cpu, thread_cpu_ns()) {
                best_cpu = best_cpu.min((b - a) as f64 * 1e-6);
            }
        }
        println!(
            "{} internodes, level 0, reused buffers, {} foliage: best of {repeats}: \
             {best_cpu:.1} ms CPU; {} triangles, {} cards of {} leaves",
            skeleton.len(),
            species.name,
            meshes.num_triangles(0),
            meshes.leaves.num_triangles() / 2,
            meshes.leaf_card.num_leaves()
        );
    }
}

/// FNV-1a (64 bit) over 32-bit words.
struct Digest(u64);

impl Digest {
    fn word(&mut self, w: u32) {
        self.0 = (self.0 ^ u64::from(w)).wrapping_mul(0x0100_0000_01b3);
    }

    fn floats(&mut self, values: impl IntoIterator<Item = f32>) {
        for v in values {
            self.word(v.to_bits());
        }
    }

    fn len(&mut self, n: usize) {
        self.word(n as u32);
    }

    fn mesh(&mut self, mesh: &TreeMesh) {
        self.len(mesh.positions.len());
        self.floats(mesh.positions.iter().flatten().copied());
        self.len(mesh.normals.len());
        self.floats(mesh.normals.iter().flatten().copied());
        self.len(mesh.uvs.len());
        self.floats(mesh.uvs.iter().flatten().copied());
        self.len(mesh.ambient.len());
        self.floats(mesh.ambient.iter().copied());
        self.len(mesh.indices.len());
        for &i in &mesh.indices {
            self.word(i);
        }
    }

    fn meshes(meshes: &TreeMeshes) -> String {
        let mut d = Digest(0xcbf2_9ce4_8422_2325);
        d.len(meshes.lods.len());
        for lod in &meshes.lods {
            d.len(lod.level);
            d.floats([lod.target_fraction]);
            d.mesh(&lod.branches);
            d.len(lod.branch_starts.len());
            for s in &lod.branch_starts {
                let (p, c) = s.parent.map_or((u32::MAX, u32::MAX), |(p, c)| (p.0, c.0));
                for w in [s.node.0, p, c, s.first_vertex, s.sides] {
                    d.word(w);
                }
            }
            d.len(lod.num_leaf_indices);
            d.len(lod.num_fruit_indices);
            d.mesh(&lod.merged_leaves);
        }
        d.mesh(&meshes.leaves);
        d.mesh(&meshes.fruit);
        let c = &meshes.colors;
        d.floats(c.bark.into_iter().chain(c.leaf).chain(c.fruit));
        format!("{:016x}", d.0)
    }
}

/// The four parameter sets of the digests: defaults with fruit, few sides, thick-branch sides
/// and a tilted light with an odd number of petiole steps, and very few sides with dense
/// leaves on a single petiole step.
fn digest_params() -> [MeshParams; 4] {
    let base = MeshParams {
        fruit: Some(FruitParams::default()),
        ..MeshParams::default()
    };
    [
        base.clone(),
        MeshParams {
            max_sides: 9,
            bark_twist: 0.1,
            fruit: None,
            ..base.clone()
        },
        MeshParams {
            side_exponent: 1.6,
            tip_taper: 0.3,
            leaves: LeafParams {
                petiole_steps: 3,
                light_direction: [0.5, 0.8, 0.2],
                leaves_per_metre: 55.0,
                max_branch_diameter: 0.05,
                ..LeafParams::default()
            },
            ..base.clone()
        },
        MeshParams {
            max_sides: 5,
            leaves: LeafParams {
                petiole_steps: 1,
                leaves_per_metre: 90.0,
                ..LeafParams::default()
            },
            fruit: Some(FruitParams {
                threshold: 0.2,
                ..FruitParams::default()
            }),
            seed: 99,
            ..base
        },
    ]
}

/// The skeleton of every species preset grown for fourteen years, read from `dir` when saved there
/// before (and saved there otherwise).
fn preset_skeletons(dir: Option<&std::path::Path>) -> Vec<(Species, Skeleton)> {
    Species::presets()
        .into_iter()
        .map(|species| {
            let path = dir.map(|d| d.join(format!("{}.json", species.name)));
            if let Some(text) = path.as_ref().and_then(|p| std::fs::read(p).ok()) {
                let skeleton = serde_json::from_slice(&text).expect("saved skeleton reads");
                return (species, skeleton);
            }
            let mut tree = Tree::new(species.clone(), 5);
            tree.grow_years(14.0);
            if let Some(path) = &path {
                let bytes = serde_json::to_vec(&tree.skeleton).expect("skeleton encodes");
                std::fs::write(path, bytes).expect("skeleton saved");
            }
            (species, tree.skeleton)
        })
        .collect()
}

fn print_digests(skeleton_dir: Option<std::path::PathBuf>) {
    let ambient = crown_ambient(Vec3::new(0.0, 1.5, 0.0), 2.0);
    let choices = [Levels::All, Levels::One(0), Levels::One(1), Levels::One(2)];
    let mut reused_mesher = Mesher::new();
    let mut reused = TreeMeshes::default();
    for num_internodes in [1, 2, 57, 3_000, 20_000, 100_000] {
        let skeleton = branching_skeleton(num_internodes, num_internodes as u64 ^ 7);
        for (variant, params) in digest_params().iter().enumerate() {
            for levels in choices {
                let mut fresh = TreeMeshes::default();
                Mesher::new().build_into(&skeleton, params, &ambient, levels, &mut fresh);
                reused_mesher.build_into(&skeleton, params, &ambient, levels, &mut reused);
                let (a, b) = (Digest::meshes(&fresh), Digest::meshes(&reused));
                assert_eq!(a, b, "a reused mesher gives other meshes");
                println!("synthetic {num_internodes} v{variant} {levels:?}: {a}");
            }
        }
    }
    for (species, skeleton) in preset_skeletons(skeleton_dir.as_deref()) {
        let params = mesh_params_for(&species);
        for levels in [Levels::All, Levels::One(0)] {
            reused_mesher.build_into(&skeleton, &params, &ambient, levels, &mut reused);
            println!(
                "preset {} ({} internodes) {levels:?}: {}",
                species.name,
                skeleton.len(),
                Digest::meshes(&reused)
            );
        }
    }
}
