//! The compact tree file: the same tree as the JSON file, smaller, and refused with a clear
//! error when cut short, damaged or written by a newer build.

use sylva_core::Tree;
use sylva_core::growth::{TREE_FORMAT_VERSION, TreeFileError, TreeFileFormat};
use sylva_core::species::Species;

fn grown_tree() -> Tree {
    let mut tree = Tree::new(Species::by_name("oak").expect("oak preset"), 3);
    tree.grow(8, None);
    tree
}

#[test]
fn a_compact_file_loads_the_same_tree_as_its_json_file_and_is_smaller() {
    let tree = grown_tree();
    let dir = tempfile::tempdir().expect("temp dir");
    let (json, compact) = (dir.path().join("t.json"), dir.path().join("t.tree"));
    tree.save(&json).expect("json saved");
    tree.save_as(&compact, TreeFileFormat::Compact)
        .expect("compact saved");
    let from_json = Tree::load(&json).expect("json loads");
    let from_compact = Tree::load(&compact).expect("compact loads");
    assert!(from_compact == tree && from_compact == from_json);
    assert_eq!(
        from_compact.to_json_bytes().expect("json"),
        from_json.to_json_bytes().expect("json")
    );
    let (json_len, compact_len) = (
        std::fs::metadata(&json).expect("json").len(),
        std::fs::metadata(&compact).expect("compact").len(),
    );
    assert!(
        compact_len * 10 < json_len * 7,
        "{compact_len} bytes compact, {json_len} JSON"
    );
    // Saving twice gives the same bytes.
    assert_eq!(
        tree.to_compact_bytes().expect("bytes"),
        std::fs::read(&compact).expect("read")
    );
}

fn load_error(bytes: &[u8]) -> String {
    match Tree::from_compact_bytes_named(bytes, "damaged.tree") {
        Ok(_) => panic!("a damaged file loaded"),
        Err(e) => {
            let text = e.to_string();
            assert!(text.contains("damaged.tree"), "{text}");
            text
        }
    }
}

#[test]
fn a_truncated_or_damaged_compact_file_is_a_clear_error() {
    let bytes = grown_tree().to_compact_bytes().expect("bytes");
    for len in [9, 20, 27, 28, bytes.len() / 2, bytes.len() - 1] {
        let text = load_error(&bytes[..len]);
        assert!(text.contains("truncated"), "{len} bytes: {text}");
    }
    let mut longer = bytes.clone();
    longer.push(0);
    assert!(load_error(&longer).contains("after its end"));
    for at in [30, bytes.len() / 3, bytes.len() - 9] {
        let mut damaged = bytes.clone();
        damaged[at] ^= 0x10;
        let text = load_error(&damaged);
        assert!(text.contains("checksum"), "byte {at}: {text}");
    }
}

#[test]
fn a_compact_file_from_a_newer_build_is_refused_by_version() {
    let mut bytes = grown_tree().to_compact_bytes().expect("bytes");
    bytes[8..12].copy_from_slice(&(TREE_FORMAT_VERSION + 1).to_le_bytes());
    match Tree::from_compact_bytes_named(&bytes, "new.tree") {
        Err(TreeFileError::NewerVersion {
            found, supported, ..
        }) => assert_eq!(
            (found, supported),
            (TREE_FORMAT_VERSION + 1, TREE_FORMAT_VERSION)
        ),
        other => panic!("expected a version error, got {:?}", other.map(|_| ())),
    }
}
