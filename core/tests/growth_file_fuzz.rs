//! Damaged tree files: every number of a saved tree (species, skeleton, buds, attraction points)
//! replaced in turn by absurd values. Loading either refuses the file with an error naming it,
//! or gives a tree that grows, meshes and saves with finite values, never a panic.

use std::panic::{AssertUnwindSafe, catch_unwind};

use glam::Vec3;
use sylva_core::Tree;
use sylva_core::geometry::{MeshParams, build_meshes};
use sylva_core::species::Species;
use sylva_core::tree::NodeId;

/// Values that stand in for one number of the file.
const BAD_VALUES: [&str; 8] = [
    "-1",
    "0",
    "1e30",
    "-1e30",
    "3e38",
    "1e-30",
    "4294967295",
    "-7.5",
];

/// A small tree that uses every kind of field: width constraint, bud tropism, brush points.
fn sample_tree() -> Tree {
    let mut tree = Tree::new(Species::by_name("birch").expect("birch preset"), 3);
    tree.grow(2, None);
    let tip = tree.skeleton.len() - 1;
    tree.skeleton.internodes[tip / 2].width_constraint = Some(0.02);
    if let Some(bud) = tree.skeleton.internodes[tip].terminal_bud.as_mut() {
        bud.tropism_override = Some(Vec3::X);
    }
    tree.environment
        .attraction
        .add_persistent(Vec3::new(0.3, 1.5, 0.1));
    tree.growth_mask = Some(NodeId(1));
    tree
}

/// Byte ranges of the numbers of a JSON text (outside strings).
fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let bytes = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'"' => {
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' {
                    i += if bytes[i] == b'\\' { 2 } else { 1 };
                }
                i += 1;
            }
            b'-' | b'0'..=b'9' => {
                let start = i;
                i += 1;
                while i < bytes.len()
                    && matches!(bytes[i], b'0'..=b'9' | b'.' | b'e' | b'E' | b'+' | b'-')
                {
                    i += 1;
                }
                spans.push((start, i));
            }
            _ => i += 1,
        }
    }
    spans
}

/// What a damaged file that loads must still allow: growth, widths, meshing and saving, with
/// finite results.
fn use_loaded(mut tree: Tree) -> Result<(), String> {
    tree.grow(2, None);
    tree.sanity_check()
        .map_err(|e| format!("after growth: {e}"))?;
    let m = tree.metrics();
    if !(m.height_m.is_finite() && m.crown_width_m.is_finite() && m.trunk_diameter_m.is_finite()) {
        return Err(format!("non-finite metrics {m:?}"));
    }
    let meshes = build_meshes(&tree.skeleton, &MeshParams::default(), &|p| {
        tree.ambient_at(p)
    });
    let finite = |mesh: &sylva_core::geometry::TreeMesh| {
        mesh.positions.iter().flatten().all(|x| x.is_finite())
            && mesh.normals.iter().flatten().all(|x| x.is_finite())
    };
    let levels = meshes.lods.iter().map(|lod| &lod.branches);
    if !levels.chain([&meshes.leaves, &meshes.fruit]).all(finite) {
        return Err("non-finite vertex".into());
    }
    tree.to_json_bytes().map_err(|e| e.to_string())?;
    Ok(())
}

#[test]
fn every_number_of_a_tree_file_replaced_by_an_absurd_value_loads_cleanly_or_is_refused() {
    let text = String::from_utf8(sample_tree().to_json_bytes().expect("encode")).expect("utf8");
    let spans = number_spans(&text);
    assert!(spans.len() > 500, "{} numbers", spans.len());
    let (mut refused, mut loaded) = (0, 0);
    let mut failures = Vec::new();
    for (k, &(start, end)) in spans.iter().enumerate() {
        for bad in BAD_VALUES {
            let damaged = format!("{}{bad}{}", &text[..start], &text[end..]);
            let context = &text[start.saturating_sub(40)..start];
            let outcome = catch_unwind(AssertUnwindSafe(|| {
                match Tree::from_json_bytes_named(damaged.as_bytes(), "damaged.json") {
                    Err(e) => {
                        let message = e.to_string();
                        if message.contains("damaged.json") {
                            Ok(false)
                        } else {
                            Err(format!("error does not name the file: {message}"))
                        }
                    }
                    Ok(tree) => use_loaded(tree).map(|()| true),
                }
            }));
            match outcome {
                Ok(Ok(true)) => loaded += 1,
                Ok(Ok(false)) => refused += 1,
                Ok(Err(why)) => failures.push(format!("number {k} …{context} → {bad}: {why}")),
                Err(_) => failures.push(format!("number {k} …{context} → {bad}: panicked")),
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {} damaged files failed (loaded {loaded}, refused {refused}); first: {:#?}",
        failures.len(),
        spans.len() * BAD_VALUES.len(),
        &failures[..failures.len().min(12)]
    );
    assert!(
        loaded > 0 && refused > 0,
        "loaded {loaded}, refused {refused}"
    );
    println!(
        "{} damaged files: {loaded} loaded and grew, {refused} refused",
        spans.len() * BAD_VALUES.len()
    );
}
