//! `sylva species` and `sylva grow` as a landscaper's script calls them: one line per preset,
//! byte-identical files for the same seed, the summary line last, and refusals that say what is
//! wrong.

use std::path::Path;
use std::process::{Command, Output};

fn sylva(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args(args)
        .output()
        .expect("sylva runs")
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

fn grow(species: &str, years: &str, seed: &str, out: &Path) -> Output {
    let out = out.to_str().expect("utf-8 path");
    sylva(&[
        "grow",
        "--species",
        species,
        "--years",
        years,
        "--seed",
        seed,
        "--out",
        out,
    ])
}

#[test]
fn species_lists_one_line_per_preset_starting_with_its_name() {
    let output = sylva(&["species"]);
    assert!(output.status.success(), "{output:?}");
    let text = stdout(&output);
    let names: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .collect();
    for preset in [
        "birch",
        "oak",
        "maple",
        "norway_spruce",
        "weeping_willow",
        "lombardy_poplar",
    ] {
        assert_eq!(
            names.iter().filter(|&&n| n == preset).count(),
            1,
            "{preset} in {text}"
        );
    }
}

#[test]
fn grow_gives_identical_files_for_a_seed_another_tree_for_another_and_ends_with_the_summary() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (a, b, c) = (
        dir.path().join("a.json"),
        dir.path().join("b.json"),
        dir.path().join("c.json"),
    );
    let first = grow("birch", "6", "7", &a);
    assert!(first.status.success(), "{first:?}");
    assert!(grow("birch", "6", "7", &b).status.success());
    assert!(grow("birch", "6", "8", &c).status.success());
    let read = |p: &Path| std::fs::read(p).expect("saved tree");
    assert!(read(&a) == read(&b), "same seed, different files");
    assert!(read(&a) != read(&c), "another seed, the same file");
    let text = stdout(&first);
    let last = text.lines().last().expect("a summary line");
    let keys: Vec<&str> = last
        .split_whitespace()
        .map(|pair| pair.split('=').next().unwrap_or(""))
        .collect();
    assert_eq!(
        keys,
        [
            "internodes",
            "height_m",
            "crown_width_m",
            "trunk_diameter_m",
            "elapsed_ms",
            "cpu_ms",
            "threads"
        ],
        "{last}"
    );
    let loaded = sylva_core::Tree::load(&a).expect("the saved tree loads");
    let internodes = last
        .split_whitespace()
        .next()
        .and_then(|p| p.strip_prefix("internodes="))
        .and_then(|n| n.parse::<usize>().ok());
    assert_eq!(internodes, Some(loaded.skeleton.len()), "{last}");
}

#[test]
fn grow_refuses_absurd_years_and_unknown_species_with_a_reason() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("tree.json");
    for (species, years, expected) in [
        ("oak", "5000", "--years"),
        ("oak", "-1", "--years"),
        ("no_such_tree", "5", "no_such_tree"),
    ] {
        let output = grow(species, years, "1", &out);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{species} {years} accepted");
        assert!(stderr.contains(expected), "{species} {years}: {stderr}");
        assert!(!out.exists(), "{species} {years} wrote a tree");
    }
}
