//! Export of tree meshes for SketchUp, Blender, Lumion, Twinmotion, Unreal: binary glTF 2.0
//! ([`write_glb`]) and Wavefront OBJ + MTL ([`write_obj`]).
//!
//! Both carry branches, leaves and fruit with their materials and the project's own procedural
//! textures ([`crate::geometry::textures`]). Units are metres and Y is up, as glTF specifies and
//! as Sylva's world space already is.
//!
//! glTF: one scene holding one tree, the node of the finest level (`tree_LOD0`, a plain node
//! that every reader draws); its `MSFT_lod` extension (used, not required) lists the nodes of
//! the coarser levels (`tree_LOD1`, `tree_LOD2`), which are in no scene, so three.js, which
//! lacks the extension, shows the finest level once (Blender 3.4 makes an object of every node
//! and would stack them; it refuses the default file anyway, see below). Each level's node draws the
//! bark and fruit with quantized attributes (`KHR_mesh_quantization`, required: positions as
//! normalized shorts in a box the node's translation and uniform scale map back to metres,
//! normals as bytes; bark texture coordinates as normalized shorts that the bark texture's
//! `KHR_texture_transform`, required, maps back), in primitives of 16-bit indices; its
//! children draw the leaf cards as instances of one card mesh per ambient level
//! (`EXT_mesh_gpu_instancing`, required: translation, rotation and scale per card as
//! normalized shorts). PBR metallic-roughness materials with embedded PNG textures; ambient
//! light as `COLOR_0`. Readers that lack these extensions refuse the file rather than show a
//! wrong tree (Blender 3.4: "Extension EXT_mesh_gpu_instancing is not available"); for them
//! [`GlbOptions::compat`] writes the finest level alone with its cards as plain triangles,
//! needing only `KHR_mesh_quantization` and `KHR_texture_transform`, which Blender 3.4 reads
//! (`tools/blender-check`), and the OBJ is the other fallback. OBJ: the finest level only,
//! every leaf card expanded to its quad, textures written next to it.

mod garden;
mod glb;
mod leaf_instances;
mod obj;
mod quantize;

use std::path::{Path, PathBuf};

pub use garden::{SceneTree, garden_glb_bytes, write_garden_glb, write_garden_obj};
pub use glb::{glb_bytes, glb_bytes_with, write_glb, write_glb_with};
pub use obj::{obj_files, write_obj};

/// How a `.glb` is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GlbOptions {
    /// Leaf cards as instances of one card mesh per kind (`EXT_mesh_gpu_instancing`, required:
    /// three.js, glTF Transform, Blender importers after 3.4). `false` writes every card as
    /// plain triangles, for readers without the extension (Blender 3.4 refuses a file requiring
    /// it): a larger file that needs only `KHR_mesh_quantization` and
    /// `KHR_texture_transform`.
    pub instanced_leaves: bool,
    /// The coarser levels of detail as `MSFT_lod` alternatives of the finest level's node.
    /// Blender's importer, which does not read `MSFT_lod`, makes an object of every node, so
    /// it shows the levels stacked: files for it hold the finest level only.
    pub coarse_levels: bool,
}

impl GlbOptions {
    /// A file for readers without `EXT_mesh_gpu_instancing` or `MSFT_lod` (Blender 3.4): the
    /// finest level only, its cards as plain triangles (`sylva grow --glb-compat`).
    pub fn compat() -> Self {
        GlbOptions {
            instanced_leaves: false,
            coarse_levels: false,
        }
    }
}

impl Default for GlbOptions {
    fn default() -> Self {
        GlbOptions {
            instanced_leaves: true,
            coarse_levels: true,
        }
    }
}

/// Side length of the generated bark and leaf textures, pixels.
pub const TEXTURE_SIZE: u32 = 256;

/// What went wrong while exporting, naming the file.
#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("cannot write {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("cannot encode {what} for {path}: {reason}")]
    Encode {
        path: PathBuf,
        what: &'static str,
        reason: String,
    },
    #[error("nothing to export to {path}: the tree has no triangles")]
    Empty { path: PathBuf },
    #[error("cannot export to {path}: {reason}")]
    TooLarge { path: PathBuf, reason: String },
}

impl ExportError {
    pub(crate) fn io(path: &Path) -> impl FnOnce(std::io::Error) -> ExportError + '_ {
        move |source| ExportError::Io {
            path: path.to_path_buf(),
            source,
        }
    }
}

/// Ambient light (0..1) as the vertex colour multiplying the base colour: fully shaded parts keep
/// a little light so they read as dark, not black.
pub(crate) fn ambient_color(ambient: f32) -> f32 {
    0.3 + 0.7 * ambient.clamp(0.0, 1.0)
}
