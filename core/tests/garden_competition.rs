//! Gardens: trees grown together compete for space and light (issue #24, Done when 1 and 2), the
//! same garden grows with any number of threads, a garden of one is the tree grown alone, and a
//! saved garden loads back and grows on as if never saved.

use glam::{Vec2, Vec3};
use sylva_core::Tree;
use sylva_core::garden::{CrownStats, Garden, GardenTree, Layout, PlantedTree, stand_positions};
use sylva_core::species::Species;

fn species(name: &str) -> Species {
    Species::by_name(name).expect("preset")
}

fn row_of_three(name: &str, competition: bool, years: f32) -> Garden {
    let trees = [-3.0, 0.0, 3.0]
        .iter()
        .zip(1u64..)
        .map(|(&x, seed)| PlantedTree::new(species(name), x, 0.0, 0.0, seed))
        .collect();
    let mut garden = Garden::plant(trees).expect("a valid row");
    garden.competition = competition;
    garden.grow_years(years);
    garden
}

/// An internode in garden space: start, end, radius.
type Segment = (Vec3, Vec3, f32);

/// Internodes of `a` whose segment comes closer to one of `b`'s than the sum of their radii
/// (their wood overlaps), garden space: a uniform grid over `b`'s segment midpoints.
fn wood_overlaps(a: &GardenTree, b: &GardenTree) -> usize {
    let cell = 0.5f32;
    let mut grid: std::collections::HashMap<(i32, i32, i32), Vec<Segment>> =
        std::collections::HashMap::new();
    let key = |p: Vec3| {
        let c = (p / cell).floor();
        (c.x as i32, c.y as i32, c.z as i32)
    };
    for n in &b.tree.skeleton.internodes {
        let (s, e) = (b.base() + n.start, b.base() + n.end);
        grid.entry(key((s + e) * 0.5))
            .or_default()
            .push((s, e, 0.5 * n.diameter));
    }
    let mut count = 0;
    for n in &a.tree.skeleton.internodes {
        let (s, e) = (a.base() + n.start, a.base() + n.end);
        let (kx, ky, kz) = key((s + e) * 0.5);
        let mut hit = false;
        'cells: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    for &(bs, be, br) in
                        grid.get(&(kx + dx, ky + dy, kz + dz)).into_iter().flatten()
                    {
                        if segment_distance(s, e, bs, be) < 0.5 * n.diameter + br {
                            hit = true;
                            break 'cells;
                        }
                    }
                }
            }
        }
        count += usize::from(hit);
    }
    count
}

/// Closest distance between segments p0p1 and q0q1 (sampled finely: internodes are short).
fn segment_distance(p0: Vec3, p1: Vec3, q0: Vec3, q1: Vec3) -> f32 {
    let mut best = f32::INFINITY;
    for i in 0..=8 {
        let p = p0.lerp(p1, i as f32 / 8.0);
        let d = q1 - q0;
        let t = ((p - q0).dot(d) / d.length_squared().max(1e-12)).clamp(0.0, 1.0);
        best = best.min(p.distance(q0 + d * t));
    }
    best
}

/// How far each outer tree's crown leans away from the middle one, over its crown radius
/// (positive: away).
fn lean_away(crowns: &[CrownStats]) -> (f32, f32) {
    (
        -crowns[0].offset().x / crowns[0].radius_m(),
        crowns[2].offset().x / crowns[2].radius_m(),
    )
}

#[test]
fn three_trees_in_a_row_lean_apart_do_not_interpenetrate_and_the_middle_one_narrows_along_the_row()
{
    let together = row_of_three("maple", true, 20.0);
    let alone = row_of_three("maple", false, 20.0);
    let report = |g: &Garden| {
        let crowns = g.crowns();
        let (left, right) = lean_away(&crowns);
        let middle = crowns[1].extent();
        let overlaps: usize = (0..3)
            .flat_map(|i| (0..3).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| wood_overlaps(&g.trees[i], &g.trees[j]))
            .sum();
        (left, right, middle, overlaps)
    };
    let (left, right, middle, overlaps) = report(&together);
    let (left_alone, right_alone, middle_alone, overlaps_alone) = report(&alone);
    println!(
        "together: lean away {left:.3} / {right:.3} of the crown radius, middle crown {:.2} m along × {:.2} m across, {overlaps} internodes in another's wood; {} internodes",
        middle.x,
        middle.y,
        together.num_internodes()
    );
    println!(
        "alone: lean away {left_alone:.3} / {right_alone:.3}, middle crown {:.2} × {:.2} m, {overlaps_alone} internodes in another's wood; {} internodes",
        middle_alone.x,
        middle_alone.y,
        alone.num_internodes()
    );
    assert!(
        left >= 0.15 && right >= 0.15,
        "outer trees lean away by {left:.3} and {right:.3} of their crown radius"
    );
    assert_eq!(overlaps, 0, "internodes inside a neighbour's wood");
    assert!(
        middle.x < middle.y,
        "middle crown {:.2} m along the row, {:.2} m across",
        middle.x,
        middle.y
    );
    // Grown alone (then placed side by side) none of it holds.
    assert!(
        left_alone < 0.15 && right_alone < 0.15,
        "alone the outer trees lean away by {left_alone:.3} and {right_alone:.3}"
    );
    assert!(
        overlaps_alone > 0,
        "trees grown alone and placed 3 m apart interpenetrate"
    );
    assert!(
        middle_alone.x / middle_alone.y > middle.x / middle.y,
        "alone the middle crown is {:.2} × {:.2} m, no narrower along the row than together",
        middle_alone.x,
        middle_alone.y
    );
}

#[test]
fn a_tall_tree_shades_its_short_neighbour_on_the_side_facing_it() {
    let tall = PlantedTree::new(species("maple"), 0.0, 0.0, 20.0, 7);
    let short = PlantedTree::new(species("maple"), 2.0, 0.0, 0.0, 8);
    let mut garden = Garden::plant(vec![tall, short.clone()]).expect("valid");
    garden.grow_years(10.0);
    let mut alone = Tree::new(short.species.clone(), short.seed);
    alone.grow_years(10.0);
    let beside = &garden.trees[1].tree;
    // Its own space: the tall tree stands towards −x.
    let facing = beside
        .skeleton
        .internodes
        .iter()
        .filter(|n| n.end.x < 0.0)
        .count();
    let far = beside
        .skeleton
        .internodes
        .iter()
        .filter(|n| n.end.x > 0.0)
        .count();
    println!(
        "short tree beside the tall one: {facing} internodes facing it, {far} on the far side, {} in all; alone {}; tall tree {} internodes, {:.2} m",
        beside.skeleton.len(),
        alone.skeleton.len(),
        garden.trees[0].tree.skeleton.len(),
        garden.trees[0].tree.metrics().height_m
    );
    assert!(facing < far, "{facing} facing, {far} far");
    assert!(beside.skeleton.len() < alone.skeleton.len());
}

fn digest(garden: &Garden) -> u64 {
    garden
        .to_json_bytes()
        .iter()
        .fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        })
}

fn small_stand(seed: u64) -> Garden {
    let names = ["birch", "maple", "oak", "lombardy_poplar"];
    let positions = stand_positions(Vec2::splat(8.0), 10, Layout::Random, seed).expect("room");
    let trees = positions
        .iter()
        .enumerate()
        .map(|(k, p)| PlantedTree::new(species(names[k % 4]), p.x, p.y, 0.0, k as u64))
        .collect();
    Garden::plant(trees).expect("valid stand")
}

#[test]
fn a_garden_grows_the_same_with_one_and_with_two_threads() {
    let grow = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            let mut g = small_stand(5);
            g.grow_years(8.0);
            digest(&g)
        })
    };
    assert_eq!(grow(1), grow(2));
}

#[test]
fn a_garden_of_one_grows_exactly_the_tree_grown_alone() {
    let mut garden =
        Garden::plant(vec![PlantedTree::new(species("birch"), 1.5, -2.0, 3.0, 11)]).expect("ok");
    garden.grow_years(6.0);
    let mut alone = Tree::new(species("birch"), 11);
    alone.grow_years(9.0);
    assert_eq!(
        garden.trees[0].tree.to_json_bytes().expect("saves"),
        alone.to_json_bytes().expect("saves")
    );
}

#[test]
fn a_saved_garden_loads_back_and_grows_on_as_if_never_saved() {
    let mut garden = small_stand(9);
    garden.grow_years(4.0);
    let bytes = garden.to_json_bytes();
    let mut loaded = Garden::from_json_bytes(&bytes).expect("loads");
    assert_eq!(loaded.to_json_bytes(), bytes);
    garden.grow_years(3.0);
    loaded.grow_years(3.0);
    assert_eq!(digest(&garden), digest(&loaded));
}

#[test]
fn editing_one_tree_of_ten_leaves_the_other_nine_byte_identical() {
    let mut garden = small_stand(3);
    garden.grow_years(6.0);
    let files = |g: &Garden| -> Vec<Vec<u8>> {
        g.trees
            .iter()
            .map(|t| t.tree.to_json_bytes().expect("saves"))
            .collect()
    };
    let before = files(&garden);
    let edited = 4;
    // A prune of the first branch, a parameter change and two more years for that tree alone.
    assert!(garden.edit_tree(edited, |tree| {
        let branch = (1..tree.skeleton.len())
            .find(|&i| tree.skeleton.internodes[i].order == 1)
            .map(|i| sylva_core::NodeId(i as u32));
        tree.remove_subtrees(&branch.into_iter().collect::<Vec<_>>());
        tree.species.apical_dominance *= 0.9;
        tree.grow_years(2.0);
    }));
    let after = files(&garden);
    for (i, (b, a)) in before.iter().zip(&after).enumerate() {
        if i == edited {
            assert_ne!(b, a, "the edited tree changed");
        } else {
            assert_eq!(b, a, "tree {i} changed");
        }
    }
    assert!(!garden.edit_tree(10, |_| {}));
    // The others' environments took in the edit: growing on, the garden matches a reloaded one.
    let mut reloaded = Garden::from_json_bytes(&garden.to_json_bytes()).expect("loads");
    garden.grow_years(2.0);
    reloaded.grow_years(2.0);
    assert_eq!(digest(&garden), digest(&reloaded));
}
