//! Species looks as data: every preset's look is in its file, a user's own file overrides any
//! part of it and the meshes and exported textures follow, damaged values are refused naming
//! the file and the field, and files from before looks were data still load as they looked.

mod support;

use serde_json::Value;
use sylva_core::Tree;
use sylva_core::geometry::{BarkKind, LeafShape, Looks, Season, build_tree_meshes_in};
use sylva_core::species::Species;

fn oak_json() -> Value {
    serde_json::to_value(Species::by_name("oak").expect("preset")).expect("serializes")
}

#[test]
fn every_preset_states_its_look_and_its_trunk_diameters_in_its_file() {
    for species in Species::presets() {
        let looks = species
            .looks
            .as_ref()
            .unwrap_or_else(|| panic!("{}: no looks", species.name));
        assert_ne!(
            *looks,
            Looks::default(),
            "{}: the generic look",
            species.name
        );
        assert!(
            species.expected.trunk_diameter.is_some(),
            "{}",
            species.name
        );
    }
    let shapes: Vec<LeafShape> = Species::presets()
        .iter()
        .map(|s| s.looks().leaf_shape)
        .collect();
    assert_eq!(
        shapes,
        [
            LeafShape::OvateSerrate,
            LeafShape::Lobed,
            LeafShape::Palmate,
            LeafShape::Needles,
            LeafShape::Lanceolate,
            LeafShape::Deltoid
        ]
    );
}

#[test]
fn a_species_file_from_before_looks_loads_and_looks_like_its_preset_or_a_generic_broadleaf() {
    let mut old = oak_json();
    old.as_object_mut().expect("object").remove("looks");
    old["expected"]
        .as_object_mut()
        .expect("object")
        .remove("trunk_diameter");
    let species = Species::from_json_str(&old.to_string(), "old_oak.json").expect("loads");
    assert_eq!(species.looks, None);
    assert_eq!(species.looks(), Species::by_name("oak").unwrap().looks());
    old["name"] = Value::from("my_tree");
    let mine = Species::from_json_str(&old.to_string(), "my_tree.json").expect("loads");
    assert_eq!(*mine.looks(), Looks::default());
}

#[test]
fn a_tree_saved_before_looks_loads_with_the_look_it_always_had() {
    let mut tree = Tree::new(Species::by_name("birch").expect("preset"), 4);
    tree.grow_years(4.0);
    let mut file: Value = serde_json::from_slice(&tree.to_json_bytes().unwrap()).unwrap();
    file["tree"]["species"]
        .as_object_mut()
        .expect("species")
        .remove("looks");
    let old = Tree::from_json_bytes(file.to_string().as_bytes()).expect("an old tree loads");
    assert_eq!(old.species.looks(), tree.species.looks());
    assert_eq!(old.skeleton, tree.skeleton);
}

#[test]
fn a_users_species_file_overrides_any_part_of_the_look_and_the_meshes_follow() {
    let mut mine = oak_json();
    mine["name"] = Value::from("red_oak");
    mine["looks"] = serde_json::json!({
        "leaf_shape": "palmate",
        "leaf_length": 0.15,
        "leaf_color": {"autumn": [0.5, 0.05, 0.02]},
        "bark": {"kind": "papery"},
        "fruit": null
    });
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("red_oak.json");
    std::fs::write(&path, mine.to_string()).expect("written");
    let species = Species::from_file(&path).expect("a user's file loads");
    let looks = species.looks();
    assert_eq!(looks.leaf_shape, LeafShape::Palmate);
    assert_eq!(looks.bark.kind, BarkKind::Papery);
    // What the file leaves out is the generic broadleaf's, not the oak's.
    assert_eq!(looks.leaf_width, Looks::default().leaf_width);
    assert_eq!(looks.bark.color, Looks::default().bark.color);
    let mut tree = Tree::new(species, 2);
    tree.grow_years(6.0);
    let meshes = build_tree_meshes_in(&tree, Season::Autumn);
    assert_eq!(meshes.colors.leaf_shape, LeafShape::Palmate);
    assert_eq!(meshes.colors.bark_kind, BarkKind::Papery);
    assert_eq!(meshes.colors.leaf, [0.5, 0.05, 0.02]);
    assert!(
        meshes.fruit.is_empty(),
        "the file takes the oak's acorns away"
    );
    let (lo, hi) = meshes.leaves.bounds().expect("leaves");
    assert!(hi.y > lo.y);
    // The saved tree keeps the user's look.
    let again = Tree::from_json_bytes(&tree.to_json_bytes().unwrap()).expect("reloads");
    assert_eq!(again.species.looks(), tree.species.looks());
}

/// Damages one value of a species file's JSON.
type Damage = fn(&mut Value);

#[test]
fn damaged_look_and_trunk_values_are_refused_naming_the_file_and_the_field() {
    let cases: [(&str, Damage); 6] = [
        ("looks.leaf_width", |v| {
            v["looks"]["leaf_width"] = Value::from(-1.0)
        }),
        ("looks.leafy_diameters", |v| {
            v["looks"]["leafy_diameters"] = Value::from(1e9)
        }),
        ("looks.bark.color", |v| {
            v["looks"]["bark"]["color"] = serde_json::json!([0.2, 7.0, 0.1])
        }),
        ("looks.fruit.radius_m", |v| {
            v["looks"]["fruit"]["radius_m"] = Value::from(0.0)
        }),
        ("leaf_colour", |v| {
            v["looks"]["leaf_colour"] = serde_json::json!({"summer": [0.1, 0.3, 0.1]})
        }),
        ("expected.trunk_diameter.at_30y_m", |v| {
            v["expected"]["trunk_diameter"]["at_30y_m"] = serde_json::json!([0.3, 0.1])
        }),
    ];
    for (field, damage) in cases {
        let mut v = oak_json();
        damage(&mut v);
        let err = Species::from_json_str(&v.to_string(), "garden/oak.json")
            .expect_err(field)
            .to_string();
        assert!(
            err.contains("garden/oak.json") && err.contains(field),
            "{field}: {err}"
        );
    }
    let mut v = oak_json();
    v["looks"]["fruit"]["seasons"] = serde_json::json!(["monsoon"]);
    let err = Species::from_json_str(&v.to_string(), "x.json")
        .unwrap_err()
        .to_string();
    assert!(err.contains("monsoon"), "{err}");
}

#[test]
fn deciduous_presets_are_leafless_in_winter_and_their_leaves_change_colour_with_the_seasons() {
    for species in Species::presets() {
        let evergreen = species.looks().evergreen;
        let mut tree = Tree::new(species, 5);
        tree.grow_years(6.0);
        let summer = build_tree_meshes_in(&tree, Season::Summer);
        let winter = build_tree_meshes_in(&tree, Season::Winter);
        let autumn = build_tree_meshes_in(&tree, Season::Autumn);
        let name = &tree.species.name;
        assert!(!summer.leaves.is_empty(), "{name}");
        assert_eq!(winter.leaves.is_empty(), !evergreen, "{name} in winter");
        let (w, s) = (&winter.lods[0].branches, &summer.lods[0].branches);
        assert!(
            w.positions == s.positions && w.indices == s.indices,
            "{name}: the same wood in winter"
        );
        // A leafless crown lets more light onto its wood; an evergreen's is as dark.
        let lighter = w.ambient.iter().zip(&s.ambient).all(|(w, s)| w >= s);
        let mean = |a: &[f32]| a.iter().sum::<f32>() / a.len() as f32;
        assert!(lighter, "{name}: winter wood darker than summer wood");
        if evergreen {
            assert!(w.ambient == s.ambient, "{name}: an evergreen's shade stays");
        } else {
            assert!(
                mean(&w.ambient) > mean(&s.ambient) + 0.05,
                "{name}: a bare crown as dark as in leaf"
            );
        }
        if !evergreen {
            assert_ne!(
                autumn.colors.leaf, summer.colors.leaf,
                "{name} turns in autumn"
            );
        }
    }
}

#[test]
fn season_exports_pass_the_khronos_validator_with_their_species_textures() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (name, season) in [
        ("birch", Season::Winter),
        ("oak", Season::Autumn),
        ("norway_spruce", Season::Winter),
        ("maple", Season::Spring),
    ] {
        let mut tree = Tree::new(Species::by_name(name).expect("preset"), 8);
        tree.grow_years(7.0);
        let meshes = build_tree_meshes_in(&tree, season);
        let path = dir.path().join(format!("{name}_{season}.glb"));
        sylva_core::export::write_glb(&meshes, &path).expect("exports");
        let report = support::validate_glb(&path);
        assert!(
            report.num_errors == 0 && report.num_warnings == 0,
            "{name} in {season}: {}",
            report.text
        );
    }
}
