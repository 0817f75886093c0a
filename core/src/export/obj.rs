//! Wavefront OBJ + MTL of the finest level of detail, with the bark and leaf textures written as
//! PNG files next to it (`<stem>_bark.png`, `<stem>_leaf.png`).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use super::{ExportError, TEXTURE_SIZE};
use crate::geometry::leaf_card::card_texture;
use crate::geometry::textures::{bark_texture, png_bytes};
use crate::geometry::{TreeMesh, TreeMeshes};

/// Writes the finest level of `meshes` to `path` (OBJ), `path` with extension `.mtl`, and the
/// textures next to them.
pub fn write_obj(meshes: &TreeMeshes, path: &Path) -> Result<(), ExportError> {
    let lod = meshes.lods.first().ok_or_else(|| ExportError::Empty {
        path: path.to_path_buf(),
    })?;
    if lod.num_triangles() == 0 {
        return Err(ExportError::Empty {
            path: path.to_path_buf(),
        });
    }
    let [mtl_name, bark_name, leaf_name] = companion_names(path);
    let sibling = |name: String| -> PathBuf { path.with_file_name(name) };
    write_png(
        &sibling(bark_name.clone()),
        &bark_texture(meshes.colors.bark_kind, meshes.colors.bark, TEXTURE_SIZE),
        "bark texture",
    )?;
    write_png(
        &sibling(leaf_name.clone()),
        &card_texture(meshes, TEXTURE_SIZE),
        "leaf texture",
    )?;
    write_mtl(&sibling(mtl_name.clone()), meshes, &bark_name, &leaf_name)?;

    let parts: [(&str, &str, &TreeMesh, usize); 3] = [
        (
            "branches",
            "bark",
            &lod.branches,
            lod.branches.indices.len(),
        ),
        ("leaves", "leaf", &meshes.leaves, lod.num_leaf_indices),
        ("fruit", "fruit", &meshes.fruit, lod.num_fruit_indices),
    ];
    let write_all = |out: &mut BufWriter<File>| -> std::io::Result<()> {
        writeln!(out, "# Sylva tree: metres, Y up")?;
        writeln!(out, "mtllib {mtl_name}")?;
        let mut first_vertex = 1usize; // OBJ indices are 1-based and global
        for (name, material, mesh, num_indices) in parts {
            if num_indices == 0 {
                continue;
            }
            let num_vertices = mesh.num_vertices_of_prefix(num_indices);
            writeln!(out, "o {name}")?;
            for p in &mesh.positions[..num_vertices] {
                writeln!(out, "v {} {} {}", p[0], p[1], p[2])?;
            }
            for t in &mesh.uvs[..num_vertices] {
                // OBJ puts v = 0 at the bottom of the image, glTF at the top.
                writeln!(out, "vt {} {}", t[0], 1.0 - t[1])?;
            }
            for n in &mesh.normals[..num_vertices] {
                writeln!(out, "vn {} {} {}", n[0], n[1], n[2])?;
            }
            writeln!(out, "usemtl {material}")?;
            for triangle in mesh.indices[..num_indices].chunks_exact(3) {
                let [a, b, c] = [0, 1, 2].map(|k| triangle[k] as usize + first_vertex);
                writeln!(out, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}")?;
            }
            first_vertex += num_vertices;
        }
        out.flush()
    };
    crate::safe_write::write_file_with(path, write_all).map_err(ExportError::io(path))
}

/// The names of the files [`write_obj`] writes next to `path`: its MTL, bark and leaf PNGs.
fn companion_names(path: &Path) -> [String; 3] {
    let stem = path
        .file_stem()
        .and_then(|s| s.to_str())
        .filter(|s| !s.is_empty())
        .unwrap_or("tree");
    [
        format!("{stem}.mtl"),
        format!("{stem}_bark.png"),
        format!("{stem}_leaf.png"),
    ]
}

/// Every file [`write_obj`] writes for `path`: the OBJ, its MTL and the two textures (for
/// checking a command's outputs before it runs).
pub fn obj_files(path: &Path) -> Vec<PathBuf> {
    let mut files = vec![path.to_path_buf()];
    files.extend(companion_names(path).map(|name| path.with_file_name(name)));
    files
}

fn write_png<P>(
    path: &Path,
    image: &image::ImageBuffer<P, Vec<P::Subpixel>>,
    what: &'static str,
) -> Result<(), ExportError>
where
    P: image::PixelWithColorType,
    [P::Subpixel]: image::EncodableLayout,
{
    let bytes = png_bytes(image).map_err(|e| ExportError::Encode {
        path: path.to_path_buf(),
        what,
        reason: e.to_string(),
    })?;
    crate::safe_write::write_file(path, &bytes).map_err(ExportError::io(path))
}

fn write_mtl(
    path: &Path,
    meshes: &TreeMeshes,
    bark_png: &str,
    leaf_png: &str,
) -> Result<(), ExportError> {
    let [fr, fg, fb] = meshes.colors.fruit;
    let text = format!(
        "# Sylva tree materials\n\
         newmtl bark\nKa 0 0 0\nKd 1 1 1\nKs 0.02 0.02 0.02\nNs 8\nillum 2\nmap_Kd {bark_png}\n\n\
         newmtl leaf\nKa 0 0 0\nKd 1 1 1\nKs 0.05 0.05 0.05\nNs 16\nillum 2\nmap_Kd {leaf_png}\nmap_d -imfchan m {leaf_png}\n\n\
         newmtl fruit\nKa 0 0 0\nKd {fr} {fg} {fb}\nKs 0.3 0.3 0.3\nNs 64\nillum 2\n"
    );
    crate::safe_write::write_file(path, text.as_bytes()).map_err(ExportError::io(path))
}
