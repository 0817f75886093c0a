//! A garden as one binary glTF 2.0 scene: one node per tree (named by the caller, translated to
//! the tree's place), each holding that tree's own scene as [`glb_bytes`] writes it, with the
//! images, samplers, textures and materials of a species stored once and shared by all its
//! trees (so the file grows with the geometry, not with texture copies).
//!
//! The trees' documents are merged as JSON: every index into buffer views, accessors, images,
//! samplers, textures, materials, meshes and nodes is moved to its place in the garden's
//! document, including those inside the extensions the tree writer uses (`MSFT_lod`'s node ids,
//! `EXT_mesh_gpu_instancing`'s accessors). A document using an extension not known here is
//! refused with an error naming it rather than written with indices left pointing elsewhere.

use std::collections::HashMap;
use std::path::Path;

use glam::Vec3;
use serde_json::{Map, Value, json};

use super::glb::{CHUNK_BIN, CHUNK_JSON, GLB_MAGIC, container};
use super::{ExportError, glb_bytes};
use crate::geometry::TreeMeshes;

/// Extensions whose indices the merge moves, or that hold none.
const KNOWN_EXTENSIONS: [&str; 4] = [
    "MSFT_lod",
    "EXT_mesh_gpu_instancing",
    "KHR_mesh_quantization",
    "KHR_texture_transform",
];

/// One tree of a garden scene.
pub struct SceneTree<'a> {
    /// The node's name (e.g. the planting entry the tree came from).
    pub name: String,
    /// Its species' name: trees of one species share their textures and materials.
    pub species: String,
    /// Where its base stands, garden metres.
    pub translation: Vec3,
    /// Its meshes in its own space (base at the origin).
    pub meshes: &'a TreeMeshes,
}

/// Writes the garden scene `trees` to `path` as binary glTF 2.0.
pub fn write_garden_glb(trees: &[SceneTree], path: &Path) -> Result<(), ExportError> {
    let bytes = build(trees, path)?;
    std::fs::write(path, bytes).map_err(ExportError::io(path))
}

/// The garden scene `trees` as the bytes of a binary glTF 2.0 file.
pub fn garden_glb_bytes(trees: &[SceneTree]) -> Result<Vec<u8>, ExportError> {
    build(trees, Path::new("<memory>"))
}

/// The JSON and BIN chunks of a GLB file.
fn chunks<'a>(glb: &'a [u8], path: &Path) -> Result<(Value, &'a [u8]), ExportError> {
    let bad = |reason: &str| ExportError::Encode {
        path: path.to_path_buf(),
        what: "garden glTF",
        reason: format!("a tree's GLB {reason}"),
    };
    let word = |at: usize| -> Option<u32> {
        glb.get(at..at + 4)
            .and_then(|b| b.try_into().ok())
            .map(u32::from_le_bytes)
    };
    if word(0) != Some(GLB_MAGIC) || word(16) != Some(CHUNK_JSON) {
        return Err(bad("has no GLB header"));
    }
    let json_len = word(12).ok_or_else(|| bad("is cut short"))? as usize;
    let json_bytes = glb
        .get(20..20 + json_len)
        .ok_or_else(|| bad("is cut short"))?;
    let json: Value = serde_json::from_slice(json_bytes).map_err(|e| bad(&e.to_string()))?;
    let at = 20 + json_len;
    let bin = match (word(at), word(at + 4)) {
        (Some(len), Some(CHUNK_BIN)) => glb
            .get(at + 8..at + 8 + len as usize)
            .ok_or_else(|| bad("is cut short"))?,
        _ => &[],
    };
    Ok((json, bin))
}

fn array<'a>(doc: &'a Value, key: &str) -> &'a [Value] {
    doc[key].as_array().map_or(&[], Vec::as_slice)
}

/// Moves the index at `value[key]` (if any) through `map`.
fn remap(value: &mut Value, key: &str, map: &[usize]) {
    if let Some(slot) = value.get_mut(key)
        && let Some(i) = slot.as_u64()
        && let Some(&to) = map.get(i as usize)
    {
        *slot = json!(to);
    }
}

/// Moves every index in the object `value[key]` (a map of name to index) through `map`.
fn remap_all(value: &mut Value, key: &str, map: &[usize]) {
    if let Some(Value::Object(m)) = value.get_mut(key) {
        for slot in m.values_mut() {
            if let Some(i) = slot.as_u64()
                && let Some(&to) = map.get(i as usize)
            {
                *slot = json!(to);
            }
        }
    }
}

/// The garden's document as it is built.
struct Merged {
    doc: Map<String, Value>,
    bin: Vec<u8>,
    /// Shared items (images by their bytes, the rest by their JSON) → their index.
    shared: HashMap<(String, Vec<u8>), usize>,
    extensions_used: Vec<String>,
    extensions_required: Vec<String>,
}

impl Merged {
    fn push(&mut self, key: &str, value: Value) -> usize {
        let list = self
            .doc
            .entry(key)
            .or_insert_with(|| Value::Array(Vec::new()));
        let Value::Array(items) = list else {
            unreachable!("garden document lists are arrays")
        };
        items.push(value);
        items.len() - 1
    }

    /// `value` pushed under `key` unless an equal one (by `identity`) is there already.
    fn push_shared(&mut self, key: &str, identity: Vec<u8>, value: Value) -> usize {
        if let Some(&i) = self.shared.get(&(key.to_string(), identity.clone())) {
            return i;
        }
        let i = self.push(key, value);
        self.shared.insert((key.to_string(), identity), i);
        i
    }

    /// A copy of buffer view `view` of a tree (its bytes in `bin`) in the garden's buffer.
    fn copy_view(&mut self, view: &Value, bin: &[u8], path: &Path) -> Result<usize, ExportError> {
        let bytes = view_bytes(view, bin).ok_or_else(|| ExportError::Encode {
            path: path.to_path_buf(),
            what: "garden glTF",
            reason: "a tree's buffer view lies outside its buffer".into(),
        })?;
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut view = view.clone();
        view["byteOffset"] = json!(self.bin.len());
        view["buffer"] = json!(0);
        self.bin.extend_from_slice(bytes);
        Ok(self.push("bufferViews", view))
    }
}

fn view_bytes<'a>(view: &Value, bin: &'a [u8]) -> Option<&'a [u8]> {
    let offset = view["byteOffset"].as_u64().unwrap_or(0) as usize;
    let length = view["byteLength"].as_u64()? as usize;
    bin.get(offset..offset.checked_add(length)?)
}

/// An empty scene is an error naming the file.
fn some_trees(trees: &[SceneTree], path: &Path) -> Result<(), ExportError> {
    match trees {
        [] => Err(ExportError::Empty {
            path: path.to_path_buf(),
        }),
        _ => Ok(()),
    }
}

fn build(trees: &[SceneTree], path: &Path) -> Result<Vec<u8>, ExportError> {
    some_trees(trees, path)?;
    let mut merged = Merged {
        doc: Map::new(),
        bin: Vec::new(),
        shared: HashMap::new(),
        extensions_used: Vec::new(),
        extensions_required: Vec::new(),
    };
    let mut garden_nodes = Vec::new();
    for tree in trees {
        let glb = glb_bytes(tree.meshes)?;
        let (doc, bin) = chunks(&glb, path)?;
        garden_nodes.push(merge_tree(&mut merged, tree, &doc, bin, path)?);
    }
    let scene = merged.push("scenes", json!({ "name": "garden", "nodes": garden_nodes }));
    let mut doc = merged.doc;
    doc.insert("scene".into(), json!(scene));
    doc.insert(
        "asset".into(),
        json!({ "version": "2.0", "generator": format!("Sylva {} garden", env!("CARGO_PKG_VERSION")) }),
    );
    while !merged.bin.len().is_multiple_of(4) {
        merged.bin.push(0);
    }
    doc.insert(
        "buffers".into(),
        json!([{ "byteLength": merged.bin.len() }]),
    );
    if !merged.extensions_used.is_empty() {
        doc.insert("extensionsUsed".into(), json!(merged.extensions_used));
    }
    if !merged.extensions_required.is_empty() {
        doc.insert(
            "extensionsRequired".into(),
            json!(merged.extensions_required),
        );
    }
    let json_bytes = serde_json::to_vec(&Value::Object(doc)).map_err(|e| ExportError::Encode {
        path: path.to_path_buf(),
        what: "garden glTF JSON",
        reason: e.to_string(),
    })?;
    container(json_bytes, merged.bin, path)
}

/// Merges one tree's document into the garden's; returns the index of the tree's node.
fn merge_tree(
    merged: &mut Merged,
    tree: &SceneTree,
    doc: &Value,
    bin: &[u8],
    path: &Path,
) -> Result<usize, ExportError> {
    for (key, list) in [
        ("extensionsUsed", &mut merged.extensions_used),
        ("extensionsRequired", &mut merged.extensions_required),
    ] {
        for name in array(doc, key).iter().filter_map(Value::as_str) {
            if !KNOWN_EXTENSIONS.contains(&name) {
                return Err(ExportError::Encode {
                    path: path.to_path_buf(),
                    what: "garden glTF",
                    reason: format!(
                        "the tree writer uses {name}, which the garden merge does not know"
                    ),
                });
            }
            if !list.iter().any(|n| n == name) {
                list.push(name.to_string());
            }
        }
    }
    let views = array(doc, "bufferViews");
    let species = tree.species.as_bytes().to_vec();
    // Images by their bytes (one copy per species), then what refers to them by their JSON.
    let mut images = Vec::new();
    for image in array(doc, "images") {
        let mut image = image.clone();
        let view = image["bufferView"]
            .as_u64()
            .and_then(|v| views.get(v as usize));
        let bytes = view.and_then(|v| view_bytes(v, bin)).unwrap_or_default();
        let identity = [species.as_slice(), b"\0", bytes].concat();
        if let Some(&i) = merged.shared.get(&("images".to_string(), identity.clone())) {
            images.push(i);
            continue;
        }
        if let Some(view) = view {
            image["bufferView"] = json!(merged.copy_view(view, bin, path)?);
        }
        images.push(merged.push_shared("images", identity, image));
    }
    let shared_list = |merged: &mut Merged, key: &str, items: Vec<Value>| -> Vec<usize> {
        items
            .into_iter()
            .map(|item| {
                let identity = [species.as_slice(), b"\0", item.to_string().as_bytes()].concat();
                merged.push_shared(key, identity, item)
            })
            .collect()
    };
    let samplers = shared_list(merged, "samplers", array(doc, "samplers").to_vec());
    let textures: Vec<Value> = array(doc, "textures")
        .iter()
        .map(|t| {
            let mut t = t.clone();
            remap(&mut t, "source", &images);
            remap(&mut t, "sampler", &samplers);
            t
        })
        .collect();
    let textures = shared_list(merged, "textures", textures);
    let materials: Vec<Value> = array(doc, "materials")
        .iter()
        .map(|m| {
            let mut m = m.clone();
            for info in ["baseColorTexture", "metallicRoughnessTexture"] {
                if let Some(info) = m["pbrMetallicRoughness"].get_mut(info) {
                    remap(info, "index", &textures);
                }
            }
            for info in ["normalTexture", "occlusionTexture", "emissiveTexture"] {
                if let Some(info) = m.get_mut(info) {
                    remap(info, "index", &textures);
                }
            }
            if let Some(name) = m["name"].as_str() {
                m["name"] = json!(format!("{}_{name}", tree.species));
            }
            m
        })
        .collect();
    let materials = shared_list(merged, "materials", materials);
    // Geometry is the tree's own: every view an accessor uses is copied.
    let mut view_map: Vec<Option<usize>> = vec![None; views.len()];
    let mut copied_view = |merged: &mut Merged, v: u64| -> Result<usize, ExportError> {
        let v = v as usize;
        if let Some(i) = view_map.get(v).copied().flatten() {
            return Ok(i);
        }
        let view = views.get(v).ok_or_else(|| ExportError::Encode {
            path: path.to_path_buf(),
            what: "garden glTF",
            reason: format!("a tree's accessor names buffer view {v}, which it lacks"),
        })?;
        let i = merged.copy_view(view, bin, path)?;
        view_map[v] = Some(i);
        Ok(i)
    };
    let mut accessors = Vec::new();
    for accessor in array(doc, "accessors") {
        let mut accessor = accessor.clone();
        if let Some(v) = accessor["bufferView"].as_u64() {
            accessor["bufferView"] = json!(copied_view(merged, v)?);
        }
        if let Some(sparse) = accessor.get_mut("sparse") {
            for part in ["indices", "values"] {
                if let Some(v) = sparse[part]["bufferView"].as_u64() {
                    sparse[part]["bufferView"] = json!(copied_view(merged, v)?);
                }
            }
        }
        accessors.push(merged.push("accessors", accessor));
    }
    let mut meshes = Vec::new();
    for mesh in array(doc, "meshes") {
        let mut mesh = mesh.clone();
        if let Some(Value::Array(primitives)) = mesh.get_mut("primitives") {
            for p in primitives {
                remap_all(p, "attributes", &accessors);
                remap(p, "indices", &accessors);
                remap(p, "material", &materials);
                if let Some(Value::Array(targets)) = p.get_mut("targets") {
                    for t in targets {
                        for slot in t.as_object_mut().into_iter().flat_map(|m| m.values_mut()) {
                            if let Some(i) = slot.as_u64() {
                                *slot = json!(accessors.get(i as usize).copied().unwrap_or(0));
                            }
                        }
                    }
                }
            }
        }
        if let Some(name) = mesh["name"].as_str() {
            mesh["name"] = json!(format!("{} {name}", tree.name));
        }
        meshes.push(merged.push("meshes", mesh));
    }
    // Nodes: their indices are known once all are placed (children, MSFT_lod ids).
    let first_node = merged
        .doc
        .get("nodes")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    let nodes = array(doc, "nodes");
    let node_map: Vec<usize> = (first_node..first_node + nodes.len()).collect();
    for node in nodes {
        let mut node = node.clone();
        remap(&mut node, "mesh", &meshes);
        if let Some(Value::Array(children)) = node.get_mut("children") {
            for c in children {
                if let Some(i) = c.as_u64() {
                    *c = json!(node_map.get(i as usize).copied().unwrap_or(0));
                }
            }
        }
        if let Some(ids) = node
            .get_mut("extensions")
            .and_then(|e| e.get_mut("MSFT_lod"))
            .and_then(|l| l.get_mut("ids"))
            .and_then(Value::as_array_mut)
        {
            for id in ids {
                if let Some(i) = id.as_u64() {
                    *id = json!(node_map.get(i as usize).copied().unwrap_or(0));
                }
            }
        }
        if let Some(instancing) = node
            .get_mut("extensions")
            .and_then(|e| e.get_mut("EXT_mesh_gpu_instancing"))
        {
            remap_all(instancing, "attributes", &accessors);
        }
        if let Some(name) = node["name"].as_str() {
            node["name"] = json!(format!("{} {name}", tree.name));
        }
        merged.push("nodes", node);
    }
    let scene = doc["scene"].as_u64().unwrap_or(0) as usize;
    let roots: Vec<usize> = array(doc, "scenes")
        .get(scene)
        .map(|s| array(s, "nodes"))
        .unwrap_or_default()
        .iter()
        .filter_map(Value::as_u64)
        .filter_map(|i| node_map.get(i as usize).copied())
        .collect();
    let t = tree.translation;
    Ok(merged.push(
        "nodes",
        json!({ "name": tree.name, "translation": [t.x, t.y, t.z], "children": roots }),
    ))
}

/// Writes the garden scene `trees` to `path` as Wavefront OBJ: one group per tree (`g` with
/// its name), its parts as objects, placed at the tree's base; `path` with extension `.mtl`
/// holds each species' materials once (`<species>_bark`, `<species>_leaf`, `<species>_fruit`),
/// and each species' textures are written once next to it (`<stem>_<species>_bark.png`, ...).
/// Each tree is written by [`write_obj`] to a scratch folder next to `path` and merged.
pub fn write_garden_obj(trees: &[SceneTree], path: &Path) -> Result<(), ExportError> {
    some_trees(trees, path)?;
    let stem = match path.file_stem().and_then(|s| s.to_str()) {
        Some(stem) if !stem.is_empty() => stem.to_string(),
        _ => "garden".to_string(),
    };
    let scratch = path.with_file_name(format!(".{stem}.garden-scratch"));
    std::fs::create_dir_all(&scratch).map_err(ExportError::io(&scratch))?;
    let merged = merge_objs(trees, path, &stem, &scratch);
    // The scratch folder goes whatever happened; an error removing it is not the user's.
    let _ = std::fs::remove_dir_all(&scratch);
    let (obj, mtl) = merged?;
    let mtl_path = path.with_extension("mtl");
    std::fs::write(&mtl_path, mtl).map_err(ExportError::io(&mtl_path))?;
    std::fs::write(path, obj).map_err(ExportError::io(path))
}

/// The garden's OBJ and MTL text; textures copied next to `path`.
fn merge_objs(
    trees: &[SceneTree],
    path: &Path,
    stem: &str,
    scratch: &Path,
) -> Result<(String, String), ExportError> {
    use std::fmt::Write;
    let mut obj = format!("# Sylva garden: metres, Y up\nmtllib {stem}.mtl\n");
    let mut mtl = String::from("# Sylva garden materials\n");
    let mut species_done: Vec<String> = Vec::new();
    // Vertices, texture coordinates and normals written so far (OBJ indices are global).
    let mut offsets = [0usize; 3];
    for (k, tree) in trees.iter().enumerate() {
        let tree_path = scratch.join(format!("tree{k}.obj"));
        super::write_obj(tree.meshes, &tree_path)?;
        let species: String = tree
            .species
            .chars()
            .map(|c| if c.is_alphanumeric() { c } else { '_' })
            .collect();
        let species = species.as_str();
        if !species_done.iter().any(|s| s == species) {
            species_done.push(species.to_string());
            let text = std::fs::read_to_string(tree_path.with_extension("mtl"))
                .map_err(ExportError::io(&tree_path))?;
            for line in text.lines().filter(|l| !l.starts_with('#')) {
                let mut words: Vec<String> = line.split_whitespace().map(String::from).collect();
                match words.first().map(String::as_str) {
                    Some("newmtl") if words.len() == 2 => {
                        words[1] = format!("{species}_{}", words[1])
                    }
                    Some(map) if map.starts_with("map_") && words.len() >= 2 => {
                        let texture = words.pop().unwrap_or_default();
                        let suffix = texture
                            .strip_prefix(&format!("tree{k}"))
                            .unwrap_or(&texture);
                        let name = format!("{stem}_{species}{suffix}");
                        let from = scratch.join(&texture);
                        let to = path.with_file_name(&name);
                        std::fs::copy(&from, &to).map_err(ExportError::io(&to))?;
                        words.push(name);
                    }
                    _ => {}
                }
                let _ = writeln!(mtl, "{}", words.join(" "));
            }
        }
        let text = std::fs::read_to_string(&tree_path).map_err(ExportError::io(&tree_path))?;
        let _ = writeln!(obj, "g {}", tree.name.replace(char::is_whitespace, "_"));
        let mut counts = [0usize; 3];
        let t = tree.translation;
        for line in text.lines() {
            let mut words = line.split_whitespace();
            let bad = || ExportError::Encode {
                path: path.to_path_buf(),
                what: "garden OBJ",
                reason: format!("a tree's OBJ line {line:?} does not parse"),
            };
            match words.next() {
                Some("v") => {
                    let p: Vec<f32> = words
                        .map(str::parse)
                        .collect::<Result<_, _>>()
                        .map_err(|_| bad())?;
                    let [x, y, z] = p[..] else { return Err(bad()) };
                    let _ = writeln!(obj, "v {} {} {}", x + t.x, y + t.y, z + t.z);
                    counts[0] += 1;
                }
                Some(kind @ ("vt" | "vn")) => {
                    let _ = writeln!(obj, "{line}");
                    counts[if kind == "vt" { 1 } else { 2 }] += 1;
                }
                Some("f") => {
                    obj.push('f');
                    for corner in words {
                        obj.push(' ');
                        for (slot, index) in corner.split('/').enumerate() {
                            if slot > 0 {
                                obj.push('/');
                            }
                            if !index.is_empty() {
                                let i: usize = index.parse().map_err(|_| bad())?;
                                let _ = write!(obj, "{}", i + offsets[slot.min(2)]);
                            }
                        }
                    }
                    obj.push('\n');
                }
                Some("o") => {
                    let part = words.next().unwrap_or("part");
                    let _ = writeln!(
                        obj,
                        "o {}_{part}",
                        tree.name.replace(char::is_whitespace, "_")
                    );
                }
                Some("usemtl") => {
                    let _ = writeln!(obj, "usemtl {species}_{}", words.next().unwrap_or_default());
                }
                _ => {}
            }
        }
        for (offset, count) in offsets.iter_mut().zip(counts) {
            *offset += count;
        }
    }
    Ok((obj, mtl))
}
