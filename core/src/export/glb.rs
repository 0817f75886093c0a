//! Binary glTF 2.0: the document is built with `gltf-json`, the GLB container by hand (12-byte
//! header, a JSON chunk padded with spaces, a BIN chunk padded with zeros).

use std::path::Path;

use gltf_json as json;
use json::validation::{Checked::Valid, USize64};

use super::{ExportError, TEXTURE_SIZE, ambient_color};
use crate::geometry::leaf_card::card_texture;
use crate::geometry::textures::{bark_texture, png_bytes};
use crate::geometry::{TreeMesh, TreeMeshes};

/// The glTF extension naming a node's coarser levels of detail.
const MSFT_LOD: &str = "MSFT_lod";

const GLB_MAGIC: u32 = 0x4654_6C67; // "glTF"
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

/// Writes `meshes` to `path` as binary glTF 2.0.
pub fn write_glb(meshes: &TreeMeshes, path: &Path) -> Result<(), ExportError> {
    let bytes = build(meshes, path)?;
    crate::safe_write::write_file(path, &bytes).map_err(ExportError::io(path))
}

/// `meshes` as the bytes of a binary glTF 2.0 file.
pub fn glb_bytes(meshes: &TreeMeshes) -> Result<Vec<u8>, ExportError> {
    build(meshes, Path::new("<memory>"))
}

/// Accessors of one vertex buffer (views shared by every level that draws a prefix of it).
#[derive(Clone, Copy)]
struct VertexViews {
    positions: json::Index<json::buffer::View>,
    normals: json::Index<json::buffer::View>,
    uvs: Option<json::Index<json::buffer::View>>,
    colors: json::Index<json::buffer::View>,
    indices: json::Index<json::buffer::View>,
}

struct Builder<'a> {
    root: json::Root,
    bin: Vec<u8>,
    path: &'a Path,
}

impl<'a> Builder<'a> {
    /// A buffer view of `bytes`; vertex attribute views carry their element size as stride, since
    /// every level of detail drawing a prefix shares them.
    fn view(
        &mut self,
        bytes: &[u8],
        target: Option<json::buffer::Target>,
        stride: Option<usize>,
    ) -> json::Index<json::buffer::View> {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: stride.map(json::buffer::Stride),
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        })
    }

    #[allow(clippy::too_many_arguments)]
    fn accessor(
        &mut self,
        view: json::Index<json::buffer::View>,
        count: usize,
        component: json::accessor::ComponentType,
        type_: json::accessor::Type,
        normalized: bool,
        bounds: Option<([f32; 3], [f32; 3])>,
    ) -> json::Index<json::Accessor> {
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(type_),
            min: bounds.map(|(lo, _)| json::Value::from(lo.to_vec())),
            max: bounds.map(|(_, hi)| json::Value::from(hi.to_vec())),
            name: None,
            normalized,
            sparse: None,
        })
    }

    /// The buffer views of `mesh`'s attributes; texture coordinates only `with_uvs` (a part
    /// drawn without a texture gets none, which readers would carry unused).
    fn vertex_views(&mut self, mesh: &TreeMesh, with_uvs: bool) -> VertexViews {
        use json::buffer::Target::{ArrayBuffer, ElementArrayBuffer};
        let positions = self.view(
            &f32_bytes(mesh.positions.iter().flatten()),
            Some(ArrayBuffer),
            Some(12),
        );
        let normals = self.view(
            &f32_bytes(mesh.normals.iter().flatten()),
            Some(ArrayBuffer),
            Some(12),
        );
        let uvs = with_uvs.then(|| {
            self.view(
                &f32_bytes(mesh.uvs.iter().flatten()),
                Some(ArrayBuffer),
                Some(8),
            )
        });
        let colors: Vec<u8> = mesh
            .ambient
            .iter()
            .flat_map(|&a| {
                let c = (ambient_color(a) * 255.0 + 0.5) as u8;
                [c, c, c, 255]
            })
            .collect();
        let colors = self.view(&colors, Some(ArrayBuffer), Some(4));
        let indices: Vec<u8> = mesh.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let indices = self.view(&indices, Some(ElementArrayBuffer), None);
        VertexViews {
            positions,
            normals,
            uvs,
            colors,
            indices,
        }
    }

    /// A triangle primitive drawing the first `num_indices` indices of `mesh`.
    fn primitive(
        &mut self,
        mesh: &TreeMesh,
        views: &VertexViews,
        num_indices: usize,
        material: json::Index<json::Material>,
    ) -> json::mesh::Primitive {
        use json::accessor::ComponentType::{F32, U8, U32};
        use json::accessor::Type::{Scalar, Vec2, Vec3, Vec4};
        let num_vertices = mesh.num_vertices_of_prefix(num_indices);
        let bounds = mesh.positions[..num_vertices].iter().fold(
            ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
            |(lo, hi), p| {
                (
                    [lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])],
                    [hi[0].max(p[0]), hi[1].max(p[1]), hi[2].max(p[2])],
                )
            },
        );
        let mut attributes = std::collections::BTreeMap::new();
        let position = self.accessor(
            views.positions,
            num_vertices,
            F32,
            Vec3,
            false,
            Some(bounds),
        );
        attributes.insert(Valid(json::mesh::Semantic::Positions), position);
        let normal = self.accessor(views.normals, num_vertices, F32, Vec3, false, None);
        attributes.insert(Valid(json::mesh::Semantic::Normals), normal);
        if let Some(uvs) = views.uvs {
            let uv = self.accessor(uvs, num_vertices, F32, Vec2, false, None);
            attributes.insert(Valid(json::mesh::Semantic::TexCoords(0)), uv);
        }
        let color = self.accessor(views.colors, num_vertices, U8, Vec4, true, None);
        attributes.insert(Valid(json::mesh::Semantic::Colors(0)), color);
        let indices = self.accessor(views.indices, num_indices, U32, Scalar, false, None);
        json::mesh::Primitive {
            attributes,
            extensions: None,
            extras: Default::default(),
            indices: Some(indices),
            material: Some(material),
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
        }
    }

    /// A texture from a PNG stored in the BIN chunk.
    fn texture(
        &mut self,
        name: &str,
        png: &[u8],
        wrap: json::texture::WrappingMode,
    ) -> json::Index<json::Texture> {
        let view = self.view(png, None, None);
        let image = self.root.push(json::Image {
            buffer_view: Some(view),
            mime_type: Some(json::image::MimeType("image/png".into())),
            name: Some(name.into()),
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        let sampler = self.root.push(json::texture::Sampler {
            mag_filter: Some(Valid(json::texture::MagFilter::Linear)),
            min_filter: Some(Valid(json::texture::MinFilter::LinearMipmapLinear)),
            name: None,
            wrap_s: Valid(wrap),
            wrap_t: Valid(wrap),
            extensions: None,
            extras: Default::default(),
        });
        self.root.push(json::Texture {
            name: Some(name.into()),
            sampler: Some(sampler),
            source: image,
            extensions: None,
            extras: Default::default(),
        })
    }

    fn material(
        &mut self,
        name: &str,
        texture: Option<json::Index<json::Texture>>,
        color: [f32; 4],
        roughness: f32,
        leaf: bool,
    ) -> json::Index<json::Material> {
        self.root.push(json::Material {
            alpha_cutoff: leaf.then_some(json::material::AlphaCutoff(0.5)),
            alpha_mode: Valid(if leaf {
                json::material::AlphaMode::Mask
            } else {
                json::material::AlphaMode::Opaque
            }),
            double_sided: leaf,
            name: Some(name.into()),
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor(color),
                base_color_texture: texture.map(|index| json::texture::Info {
                    index,
                    tex_coord: 0,
                    extensions: None,
                    extras: Default::default(),
                }),
                metallic_factor: json::material::StrengthFactor(0.0),
                roughness_factor: json::material::StrengthFactor(roughness),
                ..Default::default()
            },
            ..Default::default()
        })
    }

    fn png<P>(
        &self,
        what: &'static str,
        image: &image::ImageBuffer<P, Vec<P::Subpixel>>,
    ) -> Result<Vec<u8>, ExportError>
    where
        P: image::PixelWithColorType,
        [P::Subpixel]: image::EncodableLayout,
    {
        png_bytes(image).map_err(|e| ExportError::Encode {
            path: self.path.to_path_buf(),
            what,
            reason: e.to_string(),
        })
    }
}

fn f32_bytes<'a>(values: impl Iterator<Item = &'a f32>) -> Vec<u8> {
    values.flat_map(|v| v.to_le_bytes()).collect()
}

fn build(meshes: &TreeMeshes, path: &Path) -> Result<Vec<u8>, ExportError> {
    if meshes.lods.iter().all(|lod| lod.num_triangles() == 0) {
        return Err(ExportError::Empty {
            path: path.to_path_buf(),
        });
    }
    let mut builder = Builder {
        root: json::Root::default(),
        bin: Vec::new(),
        path,
    };
    builder.root.asset.generator = Some(format!("Sylva {}", env!("CARGO_PKG_VERSION")));
    let opaque = |c: [f32; 3]| [c[0], c[1], c[2], 1.0];
    let bark_png = builder.png(
        "bark texture",
        &bark_texture(meshes.colors.bark_kind, meshes.colors.bark, TEXTURE_SIZE),
    )?;
    let bark_texture = builder.texture("bark", &bark_png, json::texture::WrappingMode::Repeat);
    let bark = builder.material("bark", Some(bark_texture), [1.0; 4], 0.95, false);
    let leaf = if meshes.leaves.is_empty() {
        None
    } else {
        let leaf_png = builder.png("leaf texture", &card_texture(meshes, TEXTURE_SIZE))?;
        let texture = builder.texture("leaf", &leaf_png, json::texture::WrappingMode::ClampToEdge);
        let views = builder.vertex_views(&meshes.leaves, true);
        Some((
            builder.material("leaf", Some(texture), [1.0; 4], 0.6, true),
            views,
        ))
    };
    let fruit = if meshes.fruit.is_empty() {
        None
    } else {
        let views = builder.vertex_views(&meshes.fruit, false);
        Some((
            builder.material("fruit", None, opaque(meshes.colors.fruit), 0.45, false),
            views,
        ))
    };
    let mut level_nodes = Vec::new();
    for (level, lod) in meshes.lods.iter().enumerate() {
        let mut primitives = Vec::new();
        if !lod.branches.is_empty() {
            let views = builder.vertex_views(&lod.branches, true);
            primitives.push(builder.primitive(
                &lod.branches,
                &views,
                lod.branches.indices.len(),
                bark,
            ));
        }
        if let Some((material, views)) = leaf.as_ref().filter(|_| lod.num_leaf_indices > 0) {
            let cards = lod.leaves_in(&meshes.leaves);
            // The finest level's cards are shared views; a coarse level's merged cards get
            // their own.
            let views = if lod.level == 0 {
                *views
            } else {
                builder.vertex_views(cards, true)
            };
            primitives.push(builder.primitive(cards, &views, lod.num_leaf_indices, *material));
        }
        if let Some((material, views)) = fruit.as_ref().filter(|_| lod.num_fruit_indices > 0) {
            primitives.push(builder.primitive(
                &meshes.fruit,
                views,
                lod.num_fruit_indices,
                *material,
            ));
        }
        if primitives.is_empty() {
            continue;
        }
        let name = format!("LOD{level}");
        let mesh = builder.root.push(json::Mesh {
            extensions: None,
            extras: Default::default(),
            name: Some(format!("tree_{name}")),
            primitives,
            weights: None,
        });
        level_nodes.push(builder.root.push(json::Node {
            mesh: Some(mesh),
            name: Some(format!("tree_{name}")),
            ..Default::default()
        }));
    }
    // One scene with one tree: the finest level is a plain mesh node, which readers without
    // MSFT_lod draw; its MSFT_lod extension lists the coarser levels' nodes, finest first.
    // The extension is used, not required.
    if let Some((&finest, coarser)) = level_nodes.split_first() {
        if !coarser.is_empty() {
            let ids: Vec<serde_json::Value> = coarser.iter().map(|n| n.value().into()).collect();
            let mut others = serde_json::Map::new();
            others.insert(MSFT_LOD.into(), serde_json::json!({ "ids": ids }));
            builder.root.nodes[finest.value()].extensions =
                Some(json::extensions::scene::Node { others });
            builder.root.extensions_used.push(MSFT_LOD.into());
        }
        builder.root.push(json::Scene {
            extensions: None,
            extras: Default::default(),
            name: Some("tree".into()),
            nodes: vec![finest],
        });
    }
    builder.root.scene = Some(json::Index::new(0));
    while !builder.bin.len().is_multiple_of(4) {
        builder.bin.push(0);
    }
    builder.root.push(json::Buffer {
        byte_length: USize64::from(builder.bin.len()),
        name: None,
        uri: None,
        extensions: None,
        extras: Default::default(),
    });
    let json_bytes = builder.root.to_vec().map_err(|e| ExportError::Encode {
        path: path.to_path_buf(),
        what: "glTF JSON",
        reason: e.to_string(),
    })?;
    container(json_bytes, builder.bin, path)
}

/// The GLB container around a JSON document and its binary buffer.
fn container(mut json_bytes: Vec<u8>, bin: Vec<u8>, path: &Path) -> Result<Vec<u8>, ExportError> {
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    let total = 12 + 8 + json_bytes.len() + 8 + bin.len();
    let total_u32 = u32::try_from(total).map_err(|_| ExportError::TooLarge {
        path: path.to_path_buf(),
        reason: format!("{total} bytes exceed the 4 GiB a GLB file can hold"),
    })?;
    let mut out = Vec::with_capacity(total);
    for word in [GLB_MAGIC, 2, total_u32, json_bytes.len() as u32, CHUNK_JSON] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    out.extend_from_slice(&json_bytes);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(&CHUNK_BIN.to_le_bytes());
    out.extend_from_slice(&bin);
    Ok(out)
}
