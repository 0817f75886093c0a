//! Trunks at age: the diameter at breast height (1.3 m) of every preset at 15, 30 and 40 years,
//! the median of five seeds, lies in the range its species file states with its source; and
//! the shadow-grid ambient light that shades the meshes follows the shadow pyramid.

mod support;

use glam::Vec3;
use support::median;
use sylva_core::Tree;
use sylva_core::environment::ShadowGrid;
use sylva_core::geometry::build_tree_meshes;
use sylva_core::species::{BREAST_HEIGHT_M, Species};

const SEEDS: [u64; 5] = [2014, 1, 2, 3, 4];

#[test]
fn every_preset_trunk_at_breast_height_lies_in_its_stated_range_at_15_30_and_40_years() {
    let mut failures = Vec::new();
    for species in Species::presets() {
        let Some(stated) = species.expected.trunk_diameter.clone() else {
            failures.push(format!(
                "{}: the species file states no trunk diameters",
                species.name
            ));
            continue;
        };
        let ranges = stated.ranges();
        // per age: the diameter of each seed's tree
        let mut diameters = vec![Vec::new(); ranges.len()];
        for seed in SEEDS {
            let mut tree = Tree::new(species.clone(), seed);
            for (k, (age, _)) in ranges.iter().enumerate() {
                tree.grow_years(age - tree.age_years());
                diameters[k].push(tree.trunk_diameter_at(BREAST_HEIGHT_M).unwrap_or(0.0));
            }
        }
        for ((age, [least, most]), seeds) in ranges.into_iter().zip(diameters) {
            let m = median(seeds.clone());
            println!(
                "{:16} {age:>2} years: median {:.1} cm (seeds {:?} cm), stated {:.1}–{:.1} cm",
                species.name,
                m * 100.0,
                seeds
                    .iter()
                    .map(|d| (d * 1000.0).round() / 10.0)
                    .collect::<Vec<_>>(),
                least * 100.0,
                most * 100.0
            );
            if !(least..=most).contains(&m) {
                failures.push(format!(
                    "{}: trunk {:.1} cm at 1.3 m at {age} years, stated {:.1}–{:.1} cm ({})",
                    species.name,
                    m * 100.0,
                    least * 100.0,
                    most * 100.0,
                    stated.source
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn the_trunk_diameter_at_a_height_is_that_of_the_trunk_internode_spanning_it() {
    let mut tree = Tree::new(Species::by_name("oak").expect("preset"), 5);
    assert_eq!(
        tree.trunk_diameter_at(BREAST_HEIGHT_M),
        None,
        "a seedling is shorter"
    );
    tree.grow_years(12.0);
    let base = tree.trunk_diameter_at(0.0).expect("a trunk");
    let breast = tree
        .trunk_diameter_at(BREAST_HEIGHT_M)
        .expect("12 years reach 1.3 m");
    assert_eq!(base, tree.skeleton.internodes[0].diameter);
    assert!(
        breast < base,
        "the trunk tapers: {breast} at 1.3 m, {base} at the base"
    );
    assert_eq!(tree.trunk_diameter_at(1000.0), None);
}

/// A grid like the oak's, shaded by `count` nodes in the voxel of `point`.
fn tree_shaded_at(point: Vec3, count: usize) -> Tree {
    let mut tree = Tree::new(Species::by_name("oak").expect("preset"), 1);
    let s = &tree.species;
    let mut grid = ShadowGrid::new(
        s.internode_length_m * s.shadow_voxel_internodes,
        s.shadow_strength,
        s.shadow_decay_base,
        s.shadow_depth_voxels,
    );
    for _ in 0..count {
        grid.apply_node(point, 1);
    }
    tree.environment.shadow = grid;
    tree
}

#[test]
fn ambient_light_is_full_in_the_open_and_falls_off_below_shading_nodes_by_the_pyramid() {
    let voxel = 0.13; // the oak's internode, one voxel
    let centre = Vec3::new(0.5, 5.0, 0.5) * voxel + Vec3::new(0.0, 5.0, 0.0);
    let tree = tree_shaded_at(centre, 8);
    let (c, a, b) = (1.0f32, 0.25f32, 1.8f32); // the oak's C, a and b
    // L = C − s + a with s = 8·a·b^(−q) at q voxels below, inside the pyramid's square.
    let expected = |q: i32| ((c - 8.0 * a * b.powi(-q) + a) / c).clamp(0.0, 1.0);
    let below = |q: f32, sideways: f32| centre + Vec3::new(sideways * voxel, -q * voxel, 0.0);
    for q in 0..=5 {
        let measured = tree.ambient_at(below(q as f32, 0.0));
        println!(
            "{q} voxels below: ambient {measured:.3}, expected {:.3}",
            expected(q)
        );
        assert!(
            (measured - expected(q)).abs() < 2e-3,
            "{q} voxels below the nodes: ambient {measured}, expected {}",
            expected(q)
        );
    }
    // The pyramid widens by a voxel per level: two levels down, one voxel aside is as dark as
    // the centre, three voxels aside is in full light.
    assert!((tree.ambient_at(below(2.0, 1.0)) - expected(2)).abs() < 2e-3);
    assert_eq!(tree.ambient_at(below(2.0, 3.0)), 1.0);
    assert_eq!(
        tree.ambient_at(centre + Vec3::Y * voxel),
        1.0,
        "above the nodes"
    );
    assert_eq!(tree.ambient_at(centre + Vec3::X * 10.0), 1.0, "far aside");
    // The shade does not depend on where the nodes are, only on the depth below them.
    let moved = tree_shaded_at(centre + Vec3::new(3.0, 1.0, -2.0), 8);
    let q2 = moved.ambient_at(below(2.0, 0.0) + Vec3::new(3.0, 1.0, -2.0));
    assert!((q2 - expected(2)).abs() < 2e-3, "moved: {q2}");
}

#[test]
fn a_grown_crown_shades_its_inner_and_lower_leaves_and_its_meshes_carry_that_shade() {
    let mut tree = Tree::new(Species::by_name("maple").expect("preset"), 3);
    tree.grow_years(15.0);
    let top = tree
        .skeleton
        .internodes
        .iter()
        .map(|n| n.end.y)
        .fold(f32::NEG_INFINITY, f32::max);
    assert_eq!(tree.ambient_at(Vec3::new(0.0, top + 1.0, 0.0)), 1.0);
    // Down the vertical line through the crown's centre, from above it to the ground: full
    // light above, darker into the crown, darkest below most of it.
    let ends: Vec<Vec3> = tree.skeleton.internodes.iter().map(|n| n.end).collect();
    let centre = ends.iter().copied().sum::<Vec3>() / ends.len() as f32;
    let profile: Vec<(f32, f32)> = (0..=((top + 0.5) / 0.1) as i32)
        .map(|k| {
            let y = top + 0.5 - k as f32 * 0.1;
            (y, tree.ambient_at(Vec3::new(centre.x, y, centre.z)))
        })
        .collect();
    let mean_between = |lo: f32, hi: f32| {
        let v: Vec<f32> = profile
            .iter()
            .filter(|(y, _)| (lo..hi).contains(y))
            .map(|p| p.1)
            .collect();
        v.iter().sum::<f32>() / v.len().max(1) as f32
    };
    let (upper, lower) = (
        mean_between(0.8 * top, top),
        mean_between(0.2 * top, 0.5 * top),
    );
    println!(
        "ambient down the crown's axis: upper fifth {upper:.3}, 20–50% of the height {lower:.3}"
    );
    assert_eq!(profile[0].1, 1.0, "above the crown");
    assert!(
        lower < upper - 0.2,
        "the lower crown is shaded: {lower} against {upper}"
    );
    // The leaves' shade is the grid's: it spans dark inner leaves and lit outer ones.
    let meshes = build_tree_meshes(&tree);
    let shades = &meshes.leaves.ambient;
    let (lo, hi) = shades
        .iter()
        .fold((1.0f32, 0.0f32), |(lo, hi), &s| (lo.min(s), hi.max(s)));
    println!(
        "leaf ambient {lo:.3}..{hi:.3} over {} vertices",
        shades.len()
    );
    assert!(hi - lo > 0.4, "leaf shade spans {lo}..{hi}");
}
