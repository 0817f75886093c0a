//! glTF and OBJ export: the Khronos validator accepts the .glb, re-importing it gives back the
//! same triangles and bounds, the OBJ has every triangle, and errors name the file.

mod support;

use glam::Vec3;
use sylva_core::export::{ExportError, write_glb, write_obj};
use sylva_core::geometry::synthetic::{branching_skeleton, crown_ambient};
use sylva_core::geometry::{FruitParams, MeshParams, TreeMeshes, build_meshes};

fn synthetic_meshes() -> TreeMeshes {
    let skeleton = branching_skeleton(8_000, 7);
    let params = MeshParams {
        fruit: Some(FruitParams::default()),
        ..MeshParams::default()
    };
    build_meshes(
        &skeleton,
        &params,
        &crown_ambient(Vec3::new(0.0, 1.0, 0.0), 1.2),
    )
}

#[test]
fn a_synthetic_tree_glb_passes_the_khronos_validator_with_no_errors() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("synthetic.glb");
    write_glb(&synthetic_meshes(), &path).expect("glb written");
    let report = support::validate_glb(&path);
    println!(
        "validator: {} errors, {} warnings",
        report.num_errors, report.num_warnings
    );
    assert_eq!(report.num_errors, 0, "validator errors: {}", report.text);
}

#[test]
fn reimporting_the_glb_gives_the_same_triangles_bounds_leaves_and_textures() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("tree.glb");
    let meshes = synthetic_meshes();
    write_glb(&meshes, &path).expect("glb written");
    support::assert_reimport_matches(&path, &meshes);
}

#[test]
fn only_textured_parts_carry_texture_coordinates_and_the_bark_texture_is_rgb() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("tree.glb");
    let meshes = synthetic_meshes();
    assert!(!meshes.fruit.is_empty(), "the synthetic tree bears fruit");
    write_glb(&meshes, &path).expect("glb written");
    let (json, bin) = support::glb_chunks(&path);
    let materials = json["materials"].as_array().expect("materials");
    let mut materials_seen = Vec::new();
    for mesh in json["meshes"].as_array().expect("meshes") {
        for primitive in mesh["primitives"].as_array().expect("primitives") {
            let material = &materials[primitive["material"].as_u64().expect("material") as usize];
            let name = material["name"].as_str().unwrap_or("").to_string();
            let has_uv = primitive["attributes"]["TEXCOORD_0"].is_u64();
            let textured = material["pbrMetallicRoughness"]["baseColorTexture"].is_object();
            assert_eq!(
                has_uv, textured,
                "{name}: TEXCOORD_0 {has_uv}, texture {textured}"
            );
            materials_seen.push(name);
        }
    }
    assert!(
        materials_seen.iter().any(|m| m == "fruit"),
        "{materials_seen:?}"
    );
    let image_of = |texture: &str| {
        let texture = json["textures"]
            .as_array()
            .expect("textures")
            .iter()
            .find(|t| t["name"] == texture)
            .unwrap_or_else(|| panic!("a {texture} texture"));
        let image = &json["images"][texture["source"].as_u64().expect("a source") as usize];
        let view = image["bufferView"].as_u64().expect("an embedded image") as usize;
        image::load_from_memory(support::view_bytes(&json, &bin, view)).expect("a PNG")
    };
    assert_eq!(
        image_of("bark").color(),
        image::ColorType::Rgb8,
        "bark texture"
    );
    assert_eq!(
        image_of("leaf").color(),
        image::ColorType::Rgba8,
        "leaf texture keeps its alpha"
    );
}

#[test]
fn the_obj_holds_every_triangle_of_the_finest_level_and_its_materials() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("tree.obj");
    let meshes = synthetic_meshes();
    write_obj(&meshes, &path).expect("obj written");
    let text = std::fs::read_to_string(&path).expect("obj readable");
    let faces = text.lines().filter(|l| l.starts_with("f ")).count();
    let vertices = text.lines().filter(|l| l.starts_with("v ")).count();
    assert_eq!(faces, meshes.num_triangles(0));
    let lod = &meshes.lods[0];
    let expected_vertices = lod.branches.num_vertices()
        + meshes.leaves.num_vertices_of_prefix(lod.num_leaf_indices)
        + meshes.fruit.num_vertices_of_prefix(lod.num_fruit_indices);
    assert_eq!(vertices, expected_vertices);
    // Every face index refers to an existing vertex.
    let max_index = text
        .lines()
        .filter(|l| l.starts_with("f "))
        .flat_map(|l| {
            l.split_whitespace().skip(1).map(|v| {
                v.split('/')
                    .next()
                    .unwrap_or("0")
                    .parse::<usize>()
                    .expect("index")
            })
        })
        .max()
        .expect("faces");
    assert_eq!(max_index, vertices);
    let mtl = std::fs::read_to_string(dir.path().join("tree.mtl")).expect("mtl written");
    for needle in [
        "newmtl bark",
        "newmtl leaf",
        "map_Kd tree_bark.png",
        "map_Kd tree_leaf.png",
    ] {
        assert!(mtl.contains(needle), "mtl lacks {needle}");
    }
    for png in ["tree_bark.png", "tree_leaf.png"] {
        let image = image::open(dir.path().join(png)).expect("texture readable");
        assert!(image.width() >= 64);
    }
}

#[test]
fn an_unwritable_path_gives_an_error_naming_the_file() {
    let meshes = synthetic_meshes();
    let path = std::path::Path::new("/nonexistent-sylva-dir/tree.glb");
    let error = write_glb(&meshes, path).expect_err("cannot write there");
    assert!(matches!(error, ExportError::Io { .. }));
    assert!(
        error
            .to_string()
            .contains("/nonexistent-sylva-dir/tree.glb"),
        "{error}"
    );
    let error = write_obj(&meshes, &path.with_extension("obj")).expect_err("cannot write there");
    assert!(
        error.to_string().contains("/nonexistent-sylva-dir/"),
        "{error}"
    );
}

#[test]
fn an_empty_tree_is_refused_rather_than_written_as_an_invalid_file() {
    let empty = build_meshes(
        &sylva_core::Skeleton {
            internodes: Vec::new(),
        },
        &MeshParams::default(),
        &|_| 1.0,
    );
    let dir = tempfile::tempdir().expect("temp dir");
    let error = write_glb(&empty, &dir.path().join("empty.glb")).expect_err("nothing to write");
    assert!(matches!(error, ExportError::Empty { .. }), "{error}");
}
