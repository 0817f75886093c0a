//! Determinism and files: same inputs give byte-identical saves, another seed a different tree,
//! saves round-trip (and growth continues identically after loading), bad files are clear errors.

use sylva_core::Tree;
use sylva_core::growth::{TREE_FORMAT_VERSION, TreeFileError};
use sylva_core::species::Species;

fn grown(name: &str, seed: u64, iterations: u32) -> Tree {
    let mut tree = Tree::new(Species::by_name(name).expect("preset"), seed);
    tree.grow(iterations, None);
    tree
}

#[test]
fn the_same_seed_gives_byte_identical_files_and_another_seed_a_different_tree() {
    for species in Species::presets() {
        let a = grown(&species.name, 42, 8).to_json_bytes().expect("encode");
        let b = grown(&species.name, 42, 8).to_json_bytes().expect("encode");
        let c = grown(&species.name, 43, 8).to_json_bytes().expect("encode");
        assert!(a == b, "{}: same seed, different bytes", species.name);
        assert!(a != c, "{}: another seed gave the same tree", species.name);
    }
}

#[test]
fn a_saved_tree_loads_equal_and_keeps_growing_exactly_as_if_never_saved() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("oak.json");
    let mut tree = grown("oak", 9, 6);
    tree.save(&path).expect("save");
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["oak.json"], "temporary file left behind");
    let mut loaded = Tree::load(&path).expect("load");
    assert!(loaded == tree);
    tree.grow(4, None);
    loaded.grow(4, None);
    assert!(
        loaded.to_json_bytes().expect("encode") == tree.to_json_bytes().expect("encode"),
        "growth after loading diverged from uninterrupted growth"
    );
}

#[test]
fn a_newer_version_is_refused_clearly() {
    let bytes = grown("birch", 1, 2).to_json_bytes().expect("encode");
    let text = String::from_utf8(bytes).expect("utf8");
    let newer = text.replacen(
        &format!("\"version\":{TREE_FORMAT_VERSION}"),
        &format!("\"version\":{}", TREE_FORMAT_VERSION + 1),
        1,
    );
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("future.json");
    std::fs::write(&path, newer).expect("write");
    let err = Tree::load(&path).expect_err("newer file accepted");
    assert!(
        matches!(err, TreeFileError::NewerVersion { found, .. } if found == TREE_FORMAT_VERSION + 1)
    );
    let message = err.to_string();
    assert!(
        message.contains("future.json") && message.contains("newer"),
        "{message}"
    );
}

#[test]
fn malformed_foreign_and_missing_files_are_errors_naming_the_file() {
    let dir = tempfile::tempdir().expect("temp dir");
    let cases = [
        (
            "truncated.json",
            "{\"format\":\"sylva-tree\",\"version\":1,\"tree\":{\"species\":",
        ),
        (
            "foreign.json",
            "{\"format\":\"something-else\",\"version\":1}",
        ),
        (
            "broken.json",
            "{\"format\":\"sylva-tree\",\"version\":1,\"tree\":{\"iteration\":\"x\"}}",
        ),
        ("binary.json", "\u{0}\u{1}garbage"),
    ];
    for (name, content) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, content).expect("write");
        let message = Tree::load(&path).expect_err(name).to_string();
        assert!(
            message.contains(name),
            "error for {name} does not name it: {message}"
        );
    }
    let missing = dir.path().join("missing.json");
    let message = Tree::load(&missing).expect_err("missing").to_string();
    assert!(message.contains("missing.json"), "{message}");
    // A structurally broken arena is caught by the sanity check, not a panic.
    let mut tree = grown("maple", 2, 3);
    tree.skeleton.internodes[1].parent = Some(sylva_core::NodeId(50_000));
    let bytes = tree.to_json_bytes().expect("encode");
    let err = Tree::from_json_bytes(&bytes).expect_err("broken arena accepted");
    assert!(err.to_string().contains("malformed"), "{err}");
}
