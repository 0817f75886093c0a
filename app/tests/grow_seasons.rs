//! `sylva grow --season`: the exported tree in its season, as a landscaper shows it. Deciduous
//! trees stand leafless in winter and the spruce keeps its needles; autumn leaves take each
//! species' colour (maple red-orange, birch yellow, oak brown).

use std::path::{Path, PathBuf};
use std::process::Command;

/// Grows `species` for 8 years (seed 3) and exports it in `season` as `dir/<species>_<season>`
/// `.glb` and `.obj`; returns the printed lines and the two paths.
fn grow_in(species: &str, season: &str, dir: &Path) -> (String, PathBuf, PathBuf) {
    let stem = dir.join(format!("{species}_{season}"));
    let (json, glb, obj) = (
        stem.with_extension("json"),
        stem.with_extension("glb"),
        stem.with_extension("obj"),
    );
    let output = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args(["grow", "--species", species, "--years", "8", "--seed", "3"])
        .args(["--season", season, "--out"])
        .args([
            &json,
            &PathBuf::from("--glb"),
            &glb,
            &PathBuf::from("--obj"),
            &obj,
        ])
        .output()
        .expect("sylva runs");
    let text = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(output.status.success(), "{species} {season}: {output:?}");
    (text, glb, obj)
}

/// The `leaves=` count of the line starting with `key=`.
fn leaves_on_line(text: &str, key: &str) -> usize {
    let line = text
        .lines()
        .find(|l| l.starts_with(key))
        .unwrap_or_else(|| panic!("no {key} line in {text}"));
    line.split_whitespace()
        .find_map(|f| f.strip_prefix("leaves="))
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no leaves= in {line}"))
}

/// Names of the materials of a binary glTF file (its JSON chunk).
fn glb_materials(path: &Path) -> Vec<String> {
    let bytes = std::fs::read(path).expect("glb written");
    let length = u32::from_le_bytes(bytes[12..16].try_into().expect("chunk header")) as usize;
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + length]).expect("json");
    json["materials"]
        .as_array()
        .map(|m| {
            m.iter()
                .filter_map(|m| m["name"].as_str().map(String::from))
                .collect()
        })
        .unwrap_or_default()
}

/// Faces the OBJ draws with material `material`.
fn obj_faces_with(path: &Path, material: &str) -> usize {
    let text = std::fs::read_to_string(path).expect("obj written");
    let mut current = String::new();
    let mut faces = 0;
    for line in text.lines() {
        if let Some(m) = line.strip_prefix("usemtl ") {
            current = m.trim().to_string();
        } else if line.starts_with("f ") && current == material {
            faces += 1;
        }
    }
    faces
}

#[test]
fn in_winter_deciduous_exports_are_leafless_and_the_spruce_keeps_its_needles() {
    let dir = tempfile::tempdir().expect("temp dir");
    for species in ["birch", "oak", "maple", "weeping_willow", "lombardy_poplar"] {
        let (summer, _, summer_obj) = grow_in(species, "summer", dir.path());
        assert!(
            leaves_on_line(&summer, "glb=") > 100,
            "{species} in summer: {summer}"
        );
        assert!(
            obj_faces_with(&summer_obj, "leaf") > 100,
            "{species} summer obj"
        );
        let (winter, glb, obj) = grow_in(species, "winter", dir.path());
        assert_eq!(
            leaves_on_line(&winter, "glb="),
            0,
            "{species} in winter: {winter}"
        );
        assert_eq!(
            leaves_on_line(&winter, "obj="),
            0,
            "{species} in winter: {winter}"
        );
        let materials = glb_materials(&glb);
        assert!(
            materials.iter().all(|m| m != "leaf") && materials.iter().any(|m| m == "bark"),
            "{species} in winter: materials {materials:?}"
        );
        assert_eq!(obj_faces_with(&obj, "leaf"), 0, "{species} winter obj");
        assert!(
            obj_faces_with(&obj, "bark") > 100,
            "{species} winter obj has its wood"
        );
    }
    let (winter, glb, obj) = grow_in("norway_spruce", "winter", dir.path());
    let (summer, _, _) = grow_in("norway_spruce", "summer", dir.path());
    let needles = leaves_on_line(&winter, "glb=");
    assert!(needles > 1000, "spruce in winter: {winter}");
    assert_eq!(
        needles,
        leaves_on_line(&summer, "glb="),
        "as many needles as in summer"
    );
    assert!(glb_materials(&glb).iter().any(|m| m == "leaf"));
    assert!(obj_faces_with(&obj, "leaf") > 1000);
}

/// Mean sRGB colour of the opaque pixels of the leaf texture written beside `obj`, as hue
/// (degrees), saturation and value.
fn leaf_hsv(obj: &Path) -> (f32, f32, f32) {
    let stem = obj.file_stem().and_then(|s| s.to_str()).expect("stem");
    let png = obj.with_file_name(format!("{stem}_leaf.png"));
    let image = image::open(&png).expect("leaf texture").to_rgba8();
    let (mut sum, mut n) = ([0f64; 3], 0f64);
    for p in image.pixels().filter(|p| p[3] == 255) {
        for (s, c) in sum.iter_mut().zip(p.0) {
            *s += f64::from(c) / 255.0;
        }
        n += 1.0;
    }
    let [r, g, b] = sum.map(|s| (s / n) as f32);
    let (max, min) = (r.max(g).max(b), r.min(g).min(b));
    let delta = max - min;
    let hue = if delta == 0.0 {
        0.0
    } else if max == r {
        60.0 * ((g - b) / delta).rem_euclid(6.0)
    } else if max == g {
        60.0 * ((b - r) / delta + 2.0)
    } else {
        60.0 * ((r - g) / delta + 4.0)
    };
    (hue, delta / max.max(1e-6), max)
}

#[test]
fn autumn_leaves_are_red_orange_on_the_maple_yellow_on_the_birch_and_brown_on_the_oak() {
    let dir = tempfile::tempdir().expect("temp dir");
    let hsv = |species: &str, season: &str| leaf_hsv(&grow_in(species, season, dir.path()).2);
    let (maple, birch, oak) = (
        hsv("maple", "autumn"),
        hsv("birch", "autumn"),
        hsv("oak", "autumn"),
    );
    println!(
        "autumn leaves (hue°, saturation, value): maple {maple:?}, birch {birch:?}, oak {oak:?}"
    );
    let summer_maple = hsv("maple", "summer");
    println!("summer maple {summer_maple:?}");
    assert!(
        summer_maple.0 > 70.0,
        "a summer maple is green: {summer_maple:?}"
    );
    assert!(
        maple.0 < 25.0 && maple.1 > 0.6,
        "maple red-orange: {maple:?}"
    );
    assert!(
        (42.0..70.0).contains(&birch.0) && birch.2 > 0.7,
        "birch yellow: {birch:?}"
    );
    assert!((20.0..45.0).contains(&oak.0), "oak brown: {oak:?}");
    assert!(
        oak.2 < birch.2 - 0.15,
        "oak darker than the birch's yellow: {oak:?}"
    );
    assert!(oak.1 < maple.1, "oak duller than the maple: {oak:?}");
}

#[test]
fn an_unknown_season_is_refused_naming_it_and_the_seasons() {
    let dir = tempfile::tempdir().expect("temp dir");
    let output = Command::new(env!("CARGO_BIN_EXE_sylva"))
        .args([
            "grow",
            "--species",
            "oak",
            "--years",
            "2",
            "--season",
            "monsoon",
            "--out",
        ])
        .arg(dir.path().join("t.json"))
        .output()
        .expect("sylva runs");
    let text = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success());
    assert!(
        text.contains("monsoon") && text.contains("autumn"),
        "{text}"
    );
}
