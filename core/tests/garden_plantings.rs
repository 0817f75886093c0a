//! Plantings: rows, groups and stands put their trees where they say; bad plantings (trees on the
//! same spot, NaN positions, unknown species, 100 000 trees) are errors naming the entry, before
//! anything large is allocated; damaged garden files are refused with the file's name.

use glam::Vec2;
use sylva_core::garden::{
    Garden, Layout, MAX_GARDEN_TREES, MIN_TREE_SPACING_M, PlantedTree, Planting, PlantingFile,
    ripley_excess, stand_positions,
};
use sylva_core::species::Species;

fn presets(name: &str) -> Result<Species, String> {
    Species::by_name(name).map_err(|e| e.to_string())
}

fn expand(json: &str) -> Result<Vec<PlantedTree>, String> {
    let file: PlantingFile = serde_json::from_str(json).map_err(|e| e.to_string())?;
    file.trees(&presets).map_err(|e| e.to_string())
}

#[test]
fn rows_groups_stands_and_single_trees_put_their_trees_where_they_say() {
    let trees = expand(
        r#"{"plantings": [
            {"kind": "row", "species": "birch", "start": [0, 0], "end": [9, 0], "spacing_m": 3},
            {"kind": "group", "species": "oak", "centre": [0, 10], "radius_m": 2, "count": 3, "seed": 4},
            {"kind": "tree", "x": -5, "z": -5, "species": "maple", "age_years": 4, "seed": 9}
        ]}"#,
    )
    .expect("valid plantings");
    assert_eq!(trees.len(), 8);
    let xs: Vec<f32> = trees[..4].iter().map(|t| t.x_m).collect();
    assert_eq!(xs, [0.0, 3.0, 6.0, 9.0]);
    for t in &trees[4..7] {
        let r = Vec2::new(t.x_m, t.z_m - 10.0).length();
        assert!((r - 2.0).abs() < 1e-4, "group tree at radius {r}");
    }
    assert_eq!(trees[7].age_years, 4.0);
    assert_eq!(trees[7].seed, 9);
    assert_eq!(trees[7].species.name, "maple");
}

#[test]
fn a_stand_spreads_its_trees_over_the_plot_and_a_clustered_one_clumps_them() {
    let plot = Vec2::splat(30.0);
    let (lo, hi) = (-plot * 0.5, plot * 0.5);
    let mut random_sum = 0.0;
    let mut clustered_sum = 0.0;
    for seed in 1..=5 {
        let random = stand_positions(plot, 300, Layout::Random, seed).expect("room");
        let clustered = stand_positions(plot, 300, Layout::Clustered, seed).expect("room");
        for set in [&random, &clustered] {
            assert_eq!(set.len(), 300);
            assert!(set.iter().all(|p| p.abs().max_element() <= 15.0));
            for (i, p) in set.iter().enumerate() {
                assert!(
                    set[..i]
                        .iter()
                        .all(|q| q.distance(*p) >= MIN_TREE_SPACING_M)
                );
            }
        }
        random_sum += ripley_excess(&random, lo, hi, 5.0).expect("estimate");
        clustered_sum += ripley_excess(&clustered, lo, hi, 5.0).expect("estimate");
    }
    println!(
        "mean Ripley excess at 5 m: random {:.1}, clustered {:.1}",
        random_sum / 5.0,
        clustered_sum / 5.0
    );
    assert!((random_sum / 5.0f32).abs() < 10.0);
    assert!(clustered_sum / 5.0 > random_sum / 5.0 + 10.0);
}

#[test]
fn bad_plantings_are_errors_naming_the_entry() {
    let cases = [
        (
            r#"{"plantings": [{"kind": "tree", "x": 1, "z": 1, "species": "oak"},
                              {"kind": "tree", "x": 1.1, "z": 1, "species": "oak"}]}"#,
            "1 (tree), tree 1",
            "from 0 (tree), tree 0",
        ),
        (
            r#"{"plantings": [{"kind": "row", "species": "oak", "start": [0, 0], "end": [1e9, 0], "spacing_m": 1}]}"#,
            "0 (row)",
            "position",
        ),
        (
            r#"{"plantings": [{"kind": "tree", "x": 0, "z": 0, "species": "baobab"}]}"#,
            "0 (tree)",
            "baobab",
        ),
        (
            r#"{"plantings": [{"kind": "row", "species": "oak", "start": [0, 0], "end": [400, 0], "spacing_m": 0.004}]}"#,
            "0 (row)",
            "100000 trees",
        ),
        (
            r#"{"plantings": [{"kind": "stand", "species": ["oak"], "width_m": 300, "depth_m": 300, "count": 100000}]}"#,
            "0 (stand)",
            "100000 trees",
        ),
        (
            r#"{"plantings": [{"kind": "stand", "species": ["oak"], "width_m": 1, "depth_m": 1, "count": 500}]}"#,
            "0 (stand)",
            "cannot place 500 trees",
        ),
        (
            r#"{"plantings": [{"kind": "group", "species": "oak", "centre": [0, 0], "radius_m": 0, "count": 2}]}"#,
            "0 (group), tree 1",
            "stands 0.000 m from",
        ),
        (
            r#"{"plantings": [{"kind": "tree", "x": 0, "z": 0, "species": "oak", "age_years": -3}]}"#,
            "0 (tree), tree 0",
            "age_years",
        ),
    ];
    for (json, entry, what) in cases {
        let error = expand(json).expect_err(json);
        assert!(
            error.contains(entry) && error.contains(what),
            "{json}: {error}"
        );
    }
    // NaN is not JSON: a planting built in code.
    let nan = PlantedTree::new(presets("oak").expect("preset"), f32::NAN, 0.0, 0.0, 1);
    let error = Garden::plant(vec![nan]).expect_err("NaN").to_string();
    assert!(error.contains("tree 0") && error.contains("NaN"), "{error}");
    let too_many: Vec<PlantedTree> = (0..=MAX_GARDEN_TREES)
        .map(|k| PlantedTree::new(presets("oak").expect("preset"), k as f32, 0.0, 0.0, 1))
        .collect();
    let error = Garden::plant(too_many).expect_err("too many").to_string();
    assert!(error.contains("2001 trees"), "{error}");
    let error = serde_json::from_str::<PlantingFile>(r#"{"plantings": [{"kind": "hedge"}]}"#)
        .expect_err("unknown kind")
        .to_string();
    assert!(error.contains("hedge"), "{error}");
    let _ = Planting::Tree {
        x: 0.0,
        z: 0.0,
        species: "oak".into(),
        age_years: 0.0,
        seed: 0,
    };
}

#[test]
fn damaged_garden_files_are_refused_with_their_name_and_the_problem() {
    let trees = vec![
        PlantedTree::new(presets("birch").expect("preset"), 0.0, 0.0, 2.0, 1),
        PlantedTree::new(presets("birch").expect("preset"), 2.0, 0.0, 2.0, 2),
    ];
    let mut garden = Garden::plant(trees).expect("valid");
    garden.grow_years(2.0);
    let text = String::from_utf8(garden.to_json_bytes()).expect("utf-8");
    let moved = text.replacen("\"x_m\":2.0", "\"x_m\":0.1", 1);
    let newer = text.replacen("\"version\":1", "\"version\":99", 1);
    let linked = text.replacen("\"neighbours\":[0]", "\"neighbours\":[7]", 1);
    assert_ne!(linked, text, "the second tree is linked to the first");
    for (bytes, what) in [
        (moved, "stands 0.100 m from tree 0"),
        (newer, "newer Sylva"),
        (linked, "neighbour 7"),
        ("{\"format\":\"sylva-tree\"}".into(), "not a Sylva garden"),
    ] {
        let error = Garden::from_json_bytes_named(bytes.as_bytes(), "garden.json")
            .expect_err(what)
            .to_string();
        assert!(
            error.contains("garden.json") && error.contains(what),
            "{error}"
        );
    }
}
