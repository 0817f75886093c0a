//! `sylva garden` as a script calls it: a planting file or a stand grows, the garden file loads
//! back, the summary line comes last with every key, the same seed gives the same file, and bad
//! plantings are refused naming the entry.

use std::process::{Command, Output};

use sylva_core::garden::Garden;

fn sylva(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args(args)
        .output()
        .expect("sylva runs")
}

fn last_line(output: &Output) -> String {
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    text.lines().last().unwrap_or_default().to_string()
}

fn value<'a>(line: &'a str, key: &str) -> &'a str {
    line.split_whitespace()
        .find_map(|kv| kv.strip_prefix(key).and_then(|v| v.strip_prefix('=')))
        .unwrap_or_else(|| panic!("no {key}= in {line}"))
}

#[test]
fn a_planting_file_grows_into_a_garden_that_loads_back_with_a_summary_line_last() {
    let dir = tempfile::tempdir().expect("temp dir");
    let planting = dir.path().join("planting.json");
    std::fs::write(
        &planting,
        r#"{"plantings": [
            {"kind": "row", "species": "birch", "start": [-2, 0], "end": [2, 0], "spacing_m": 2, "seed": 3},
            {"kind": "tree", "x": 0, "z": 3, "species": "oak", "age_years": 2, "seed": 4}
        ]}"#,
    )
    .expect("writes");
    let out = dir.path().join("garden.json");
    let glb = dir.path().join("garden.glb");
    let output = sylva(&[
        "garden",
        "--planting",
        planting.to_str().expect("utf-8"),
        "--years",
        "6",
        "--out",
        out.to_str().expect("utf-8"),
        "--glb",
        glb.to_str().expect("utf-8"),
        "--obj",
        dir.path().join("garden.obj").to_str().expect("utf-8"),
    ]);
    assert!(output.status.success(), "{output:?}");
    let line = last_line(&output);
    assert_eq!(value(&line, "trees"), "4", "{line}");
    for key in [
        "internodes",
        "elapsed_ms",
        "threads",
        "crown_offset_m",
        "ripley_excess_bases",
        "ripley_excess_crowns",
    ] {
        value(&line, key);
    }
    let garden = Garden::load(&out).expect("the garden file loads");
    assert_eq!(garden.trees.len(), 4);
    assert_eq!(
        value(&line, "internodes"),
        garden.num_internodes().to_string()
    );
    assert_eq!(garden.trees[3].tree.species.name, "oak");
    assert_eq!(garden.years, 6.0);
    // The .glb: one node per tree in its scene, named by its planting entry, at its place.
    let bytes = std::fs::read(&glb).expect("the glb is written");
    let length = u32::from_le_bytes(bytes[12..16].try_into().expect("header")) as usize;
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + length]).expect("JSON");
    let roots = json["scenes"][0]["nodes"].as_array().expect("scene nodes");
    assert_eq!(roots.len(), 4);
    let node = |k: usize| &json["nodes"][roots[k].as_u64().expect("index") as usize];
    assert_eq!(node(0)["name"], "tree 0 birch (planting 0 (row))");
    assert_eq!(node(3)["name"], "tree 3 oak (planting 1 (tree))");
    assert_eq!(node(3)["translation"], serde_json::json!([0.0, 0.0, 3.0]));
    // The .obj: one group per tree.
    let obj = std::fs::read_to_string(dir.path().join("garden.obj")).expect("the obj is written");
    assert_eq!(obj.lines().filter(|l| l.starts_with("g ")).count(), 4);
    assert!(dir.path().join("garden.mtl").is_file());
}

#[test]
fn a_stand_on_a_plot_gives_the_same_file_for_the_same_seed_and_a_ripley_figure() {
    let dir = tempfile::tempdir().expect("temp dir");
    let run = |name: &str| {
        let out = dir.path().join(name);
        let output = sylva(&[
            "garden",
            "--plot",
            "20x20",
            "--trees",
            "24",
            "--species",
            "birch,maple",
            "--layout",
            "clustered",
            "--years",
            "3",
            "--seed",
            "5",
            "--out",
            out.to_str().expect("utf-8"),
        ]);
        assert!(output.status.success(), "{output:?}");
        (last_line(&output), std::fs::read(out).expect("written"))
    };
    let (line, first) = run("a.json");
    let (_, second) = run("b.json");
    assert_eq!(first, second, "same seed, same garden file");
    assert_eq!(value(&line, "trees"), "24");
    assert!(
        value(&line, "ripley_excess_bases").parse::<f32>().is_ok(),
        "{line}"
    );
}

#[test]
fn bad_plantings_are_refused_naming_the_entry() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("garden.json");
    let cases = [
        (
            r#"{"plantings": [{"kind": "tree", "x": 1, "z": 1, "species": "oak"}, {"kind": "tree", "x": 1, "z": 1.05, "species": "oak"}]}"#,
            "planting 1 (tree), tree 1: stands 0.050 m from",
        ),
        (
            r#"{"plantings": [{"kind": "tree", "x": 1, "z": 1, "species": "baobab"}]}"#,
            "planting 0 (tree)",
        ),
        (
            r#"{"plantings": [{"kind": "stand", "species": ["oak"], "width_m": 300, "depth_m": 300, "count": 100000}]}"#,
            "100000 trees",
        ),
        (r#"{"plantings": [{"kind": "row"}]}"#, "malformed"),
    ];
    for (json, what) in cases {
        let planting = dir.path().join("planting.json");
        std::fs::write(&planting, json).expect("writes");
        let output = sylva(&[
            "garden",
            "--planting",
            planting.to_str().expect("utf-8"),
            "--years",
            "2",
            "--out",
            out.to_str().expect("utf-8"),
        ]);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{json} was accepted");
        assert!(
            stderr.contains(what) && stderr.contains("planting.json"),
            "{json}: {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    assert!(!out.exists(), "nothing is written for a bad planting");
    let output = sylva(&[
        "garden", "--plot", "abc", "--trees", "3", "--years", "2", "--out", "x.json",
    ]);
    assert!(!output.status.success());
    assert!(String::from_utf8_lossy(&output.stderr).contains("--plot"));
}
