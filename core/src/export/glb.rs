//! Binary glTF 2.0: the document is built with `gltf-json`, the GLB container by hand (12-byte
//! header, a JSON chunk padded with spaces, a BIN chunk padded with zeros).

use std::path::Path;

use gltf_json as json;
use json::validation::{Checked::Valid, USize64};

use super::leaf_instances::{CardKind, EXT_MESH_GPU_INSTANCING, card_instances, common_scale};
use super::quantize::{self, Quantizer, UvBox};
use super::{ExportError, GlbOptions, TEXTURE_SIZE, ambient_color};
use crate::geometry::billboard_cloud::bake_atlas;
use crate::geometry::leaf_card::card_texture;
use crate::geometry::textures::{bark_texture, png_bytes};
use crate::geometry::{TreeMesh, TreeMeshes};

/// The glTF extension naming a node's coarser levels of detail.
const MSFT_LOD: &str = "MSFT_lod";
/// The glTF extension allowing quantized (integer) positions, normals and instance transforms.
const KHR_MESH_QUANTIZATION: &str = "KHR_mesh_quantization";
/// The glTF extension mapping quantized texture coordinates back to the texture's.
const KHR_TEXTURE_TRANSFORM: &str = "KHR_texture_transform";

pub(super) const GLB_MAGIC: u32 = 0x4654_6C67; // "glTF"
pub(super) const CHUNK_JSON: u32 = 0x4E4F_534A;
pub(super) const CHUNK_BIN: u32 = 0x004E_4942;

/// Writes `meshes` to `path` as binary glTF 2.0.
pub fn write_glb(meshes: &TreeMeshes, path: &Path) -> Result<(), ExportError> {
    write_glb_with(meshes, path, GlbOptions::default())
}

/// [`write_glb`] with `options`.
pub fn write_glb_with(
    meshes: &TreeMeshes,
    path: &Path,
    options: GlbOptions,
) -> Result<(), ExportError> {
    let bytes = build(meshes, path, options)?;
    crate::safe_write::write_file(path, &bytes).map_err(ExportError::io(path))
}

/// `meshes` as the bytes of a binary glTF 2.0 file.
pub fn glb_bytes(meshes: &TreeMeshes) -> Result<Vec<u8>, ExportError> {
    glb_bytes_with(meshes, GlbOptions::default())
}

/// [`glb_bytes`] with `options`.
pub fn glb_bytes_with(meshes: &TreeMeshes, options: GlbOptions) -> Result<Vec<u8>, ExportError> {
    build(meshes, Path::new("<memory>"), options)
}

/// Buffer views of one mesh's quantized vertex attributes, which the primitives drawing parts
/// of it share (every level draws a prefix of the fruit's).
struct VertexViews {
    /// The quantized positions (for the accessors' bounds) and their view.
    positions: Vec<[i16; 4]>,
    position_view: json::Index<json::buffer::View>,
    /// Normals and ambient colours; none for a billboard cloud's quads, which are flat (a reader
    /// computes the same normal) and whose atlas carries the light.
    normals: Option<json::Index<json::buffer::View>>,
    uvs: Option<json::Index<json::buffer::View>>,
    colors: Option<json::Index<json::buffer::View>>,
}

/// A run of triangles whose vertices span fewer than 2¹⁶ − 1 indices: one primitive with
/// 16-bit indices (65,535 is the primitive restart value, never used as an index).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Chunk {
    /// Range of the run's indices.
    first_index: usize,
    end_index: usize,
    /// First and last vertex the run uses.
    first_vertex: u32,
    last_vertex: u32,
}

/// The first `num_indices` of `indices` cut into runs of triangles of 16-bit reach.
fn chunks(indices: &[u32], num_indices: usize) -> Vec<Chunk> {
    let mut out = Vec::new();
    let triangles = indices[..num_indices.min(indices.len())].chunks_exact(3);
    let mut current: Option<Chunk> = None;
    for (t, triangle) in triangles.enumerate() {
        let lo = triangle.iter().copied().min().unwrap_or(0);
        let hi = triangle.iter().copied().max().unwrap_or(0);
        current = Some(match current {
            Some(chunk) => {
                let (first, last) = (chunk.first_vertex.min(lo), chunk.last_vertex.max(hi));
                if last - first >= u32::from(u16::MAX) {
                    out.push(chunk);
                    Chunk {
                        first_index: 3 * t,
                        end_index: 3 * t + 3,
                        first_vertex: lo,
                        last_vertex: hi,
                    }
                } else {
                    Chunk {
                        end_index: 3 * t + 3,
                        first_vertex: first,
                        last_vertex: last,
                        ..chunk
                    }
                }
            }
            None => Chunk {
                first_index: 0,
                end_index: 3,
                first_vertex: lo,
                last_vertex: hi,
            },
        });
    }
    out.extend(current);
    out
}

pub(super) struct Builder<'a> {
    pub(super) root: json::Root,
    bin: Vec<u8>,
    path: &'a Path,
}

impl<'a> Builder<'a> {
    /// A buffer view of `bytes`; vertex attribute views carry their element size as stride, since
    /// the primitives drawing parts of them share them.
    pub(super) fn view(
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
    pub(super) fn accessor(
        &mut self,
        view: json::Index<json::buffer::View>,
        byte_offset: usize,
        count: usize,
        component: json::accessor::ComponentType,
        type_: json::accessor::Type,
        normalized: bool,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
    ) -> json::Index<json::Accessor> {
        let value = |v: Vec<f32>| {
            json::Value::from(
                v.into_iter()
                    .map(|x| json::Value::from(x as f64))
                    .collect::<Vec<_>>(),
            )
        };
        let (min, max) = match bounds {
            Some((lo, hi)) => (Some(value(lo)), Some(value(hi))),
            None => (None, None),
        };
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: (byte_offset > 0).then(|| USize64::from(byte_offset)),
            count: USize64::from(count),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            extensions: None,
            extras: Default::default(),
            type_: Valid(type_),
            min,
            max,
            name: None,
            normalized,
            sparse: None,
        })
    }

    /// The buffer views of the first `num_vertices` vertices of `mesh`, quantized by
    /// `quantizer`; texture coordinates only with a `uvs` box to quantize them in (a part drawn
    /// without a texture gets none, which readers would carry unused); normals and colours only
    /// when `lit`.
    fn vertex_views(
        &mut self,
        mesh: &TreeMesh,
        num_vertices: usize,
        uvs: Option<&UvBox>,
        quantizer: &Quantizer,
        lit: bool,
    ) -> VertexViews {
        use json::buffer::Target::ArrayBuffer;
        let positions: Vec<[i16; 4]> = mesh.positions[..num_vertices]
            .iter()
            .map(|&p| quantizer.position(p))
            .collect();
        let bytes: Vec<u8> = positions
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let position_view = self.view(&bytes, Some(ArrayBuffer), Some(8));
        let normals = lit.then(|| {
            let bytes: Vec<u8> = mesh.normals[..num_vertices]
                .iter()
                .flat_map(|&n| quantize::normal(n).map(|c| c as u8))
                .collect();
            self.view(&bytes, Some(ArrayBuffer), Some(4))
        });
        let uvs = uvs.map(|uv_box| {
            let bytes: Vec<u8> = mesh.uvs[..num_vertices]
                .iter()
                .flat_map(|&uv| uv_box.quantize(uv))
                .flat_map(|c| c.to_le_bytes())
                .collect();
            self.view(&bytes, Some(ArrayBuffer), Some(4))
        });
        let colors = lit.then(|| {
            let bytes: Vec<u8> = mesh.ambient[..num_vertices]
                .iter()
                .flat_map(|&a| {
                    let c = quantize::unorm8(ambient_color(a));
                    [c, c, c, 255]
                })
                .collect();
            self.view(&bytes, Some(ArrayBuffer), Some(4))
        });
        VertexViews {
            positions,
            position_view,
            normals,
            uvs,
            colors,
        }
    }

    /// Triangle primitives drawing the first `num_indices` indices of `mesh` (whose vertices
    /// `views` holds), one per run of 16-bit reach.
    fn primitives(
        &mut self,
        mesh: &TreeMesh,
        views: &VertexViews,
        num_indices: usize,
        material: json::Index<json::Material>,
    ) -> Vec<json::mesh::Primitive> {
        use json::accessor::ComponentType::{I8, I16, U8, U16, U32};
        use json::accessor::Type::{Scalar, Vec2, Vec3, Vec4};
        let runs = chunks(&mesh.indices, num_indices);
        // Each run's indices relative to its first vertex, as 16-bit integers; a run that
        // reaches further (a single triangle spanning 2¹⁶ vertices, which no tree mesh has)
        // as 32-bit ones, aligned to 4 bytes.
        let mut index_bytes = Vec::with_capacity(2 * num_indices);
        let mut index_starts = Vec::with_capacity(runs.len());
        for run in &runs {
            let wide = run.last_vertex - run.first_vertex >= u32::from(u16::MAX);
            if wide {
                while !index_bytes.len().is_multiple_of(4) {
                    index_bytes.push(0);
                }
            }
            index_starts.push((index_bytes.len(), if wide { U32 } else { U16 }));
            for &i in &mesh.indices[run.first_index..run.end_index] {
                let relative = i - run.first_vertex;
                if wide {
                    index_bytes.extend_from_slice(&relative.to_le_bytes());
                } else {
                    index_bytes.extend_from_slice(&(relative as u16).to_le_bytes());
                }
            }
        }
        let index_view = self.view(
            &index_bytes,
            Some(json::buffer::Target::ElementArrayBuffer),
            None,
        );
        let mut out = Vec::with_capacity(runs.len());
        for (run, (index_offset, index_component)) in runs.into_iter().zip(index_starts) {
            let (first, count) = (
                run.first_vertex as usize,
                (run.last_vertex - run.first_vertex) as usize + 1,
            );
            let (lo, hi) = views.positions[first..first + count].iter().fold(
                ([i16::MAX; 3], [i16::MIN; 3]),
                |(lo, hi), q| {
                    (
                        [lo[0].min(q[0]), lo[1].min(q[1]), lo[2].min(q[2])],
                        [hi[0].max(q[0]), hi[1].max(q[1]), hi[2].max(q[2])],
                    )
                },
            );
            let bounds = (lo.map(f32::from).to_vec(), hi.map(f32::from).to_vec());
            let mut attributes = std::collections::BTreeMap::new();
            let position = self.accessor(
                views.position_view,
                8 * first,
                count,
                I16,
                Vec3,
                true,
                Some(bounds),
            );
            attributes.insert(Valid(json::mesh::Semantic::Positions), position);
            if let Some(normals) = views.normals {
                let normal = self.accessor(normals, 4 * first, count, I8, Vec3, true, None);
                attributes.insert(Valid(json::mesh::Semantic::Normals), normal);
            }
            if let Some(uvs) = views.uvs {
                let uv = self.accessor(uvs, 4 * first, count, U16, Vec2, true, None);
                attributes.insert(Valid(json::mesh::Semantic::TexCoords(0)), uv);
            }
            if let Some(colors) = views.colors {
                let color = self.accessor(colors, 4 * first, count, U8, Vec4, true, None);
                attributes.insert(Valid(json::mesh::Semantic::Colors(0)), color);
            }
            let indices = self.accessor(
                index_view,
                index_offset,
                run.end_index - run.first_index,
                index_component,
                Scalar,
                false,
                None,
            );
            out.push(json::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Default::default(),
                indices: Some(indices),
                material: Some(material),
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
            });
        }
        out
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

    /// A material; a texture read through `uv_box` (quantized texture coordinates) says so by
    /// `KHR_texture_transform`.
    #[allow(clippy::field_reassign_with_default)]
    fn material(
        &mut self,
        name: &str,
        texture: Option<json::Index<json::Texture>>,
        uv_box: Option<&UvBox>,
        color: [f32; 4],
        roughness: f32,
        leaf: bool,
    ) -> json::Index<json::Material> {
        let extensions = uv_box.map(|uv_box| {
            let mut others = serde_json::Map::new();
            others.insert(
                KHR_TEXTURE_TRANSFORM.into(),
                serde_json::json!({ "offset": uv_box.offset, "scale": uv_box.scale }),
            );
            let mut info = json::extensions::texture::Info::default();
            info.others = others;
            info
        });
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
                    extensions,
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

/// The leaf cards' texture at the export's size.
fn card_texture_of(meshes: &TreeMeshes) -> image::RgbaImage {
    card_texture(meshes, TEXTURE_SIZE)
}

pub(super) fn f32_bytes<'a>(values: impl Iterator<Item = &'a f32>) -> Vec<u8> {
    values.flat_map(|v| v.to_le_bytes()).collect()
}

fn build(meshes: &TreeMeshes, path: &Path, options: GlbOptions) -> Result<Vec<u8>, ExportError> {
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
    // One box for every level, so that they share the fruit's quantized vertices.
    let quantizer = Quantizer::of(
        (0..meshes.lods.len())
            .filter_map(|level| meshes.bounds(level))
            .reduce(|(a0, a1), (b0, b1)| (a0.min(b0), a1.max(b1)))
            .unwrap_or((glam::Vec3::ZERO, glam::Vec3::ONE)),
    );
    let opaque = |c: [f32; 3]| [c[0], c[1], c[2], 1.0];
    let bark_png = builder.png(
        "bark texture",
        &bark_texture(meshes.colors.bark_kind, meshes.colors.bark, TEXTURE_SIZE),
    )?;
    let bark_texture = builder.texture("bark", &bark_png, json::texture::WrappingMode::Repeat);
    let uv_box = UvBox::of(meshes.lods.iter().flat_map(|lod| &lod.branches.uvs));
    let bark = builder.material(
        "bark",
        Some(bark_texture),
        Some(&uv_box),
        [1.0; 4],
        0.95,
        false,
    );
    let leaf_uv_box = (!options.instanced_leaves).then(|| {
        let merged = meshes
            .lods
            .iter()
            .filter(|lod| lod.billboards.is_none())
            .flat_map(|lod| &lod.merged_leaves.uvs);
        UvBox::of(meshes.leaves.uvs.iter().chain(merged))
    });
    let leaf = if meshes.leaves.is_empty() {
        None
    } else {
        let leaf_png = builder.png("leaf texture", &card_texture_of(meshes))?;
        let texture = builder.texture("leaf", &leaf_png, json::texture::WrappingMode::ClampToEdge);
        // Plain cards carry quantized texture coordinates; the card meshes carry their own.
        let uv_box = leaf_uv_box.as_ref().filter(|_| !options.instanced_leaves);
        Some(builder.material("leaf", Some(texture), uv_box, [1.0; 4], 0.6, true))
    };
    let fruit = if meshes.fruit.is_empty() {
        None
    } else {
        let num_vertices = meshes.fruit.num_vertices();
        let views = builder.vertex_views(&meshes.fruit, num_vertices, None, &quantizer, true);
        Some((
            builder.material(
                "fruit",
                None,
                None,
                opaque(meshes.colors.fruit),
                0.45,
                false,
            ),
            views,
        ))
    };
    let card_size = (meshes.leaf_card.width_m, meshes.leaf_card.length_m);
    let mut card_texture: Option<image::RgbaImage> = None;
    let mut card_meshes: Vec<(CardKind, Option<[u32; 3]>, json::Index<json::Mesh>)> = Vec::new();
    let mut level_nodes = Vec::new();
    let num_levels = if options.coarse_levels {
        meshes.lods.len()
    } else {
        1
    };
    for (level, lod) in meshes.lods.iter().enumerate().take(num_levels) {
        let mut primitives = Vec::new();
        if !lod.branches.is_empty() {
            let branches = &lod.branches;
            let views = builder.vertex_views(
                branches,
                branches.num_vertices(),
                Some(&uv_box),
                &quantizer,
                true,
            );
            primitives.extend(builder.primitives(branches, &views, branches.indices.len(), bark));
        }
        if let Some((material, views)) = fruit.as_ref().filter(|_| lod.num_fruit_indices > 0) {
            primitives.extend(builder.primitives(
                &meshes.fruit,
                views,
                lod.num_fruit_indices,
                *material,
            ));
        }
        let mut children = Vec::new();
        let plain_leaves = leaf_uv_box.as_ref().zip(leaf);
        let atlas = lod
            .billboards
            .as_ref()
            .filter(|_| lod.num_leaf_indices > 0)
            .map(|cloud| {
                let texture = card_texture.get_or_insert_with(|| card_texture_of(meshes));
                (cloud, texture)
            });
        if let Some((cloud, texture)) = atlas {
            // A billboard cloud: plain quads (positions and atlas coordinates only) drawn from
            // the level's own atlas, which carries the leaves' colour and light.
            let quads = &lod.merged_leaves;
            let image = bake_atlas(cloud, quads, &meshes.leaves, texture);
            let png = builder.png("leaf atlas", &image)?;
            let name = format!("leaf atlas LOD{level}");
            let texture = builder.texture(&name, &png, json::texture::WrappingMode::ClampToEdge);
            let material = builder.material(&name, Some(texture), None, [1.0; 4], 0.6, true);
            let num_vertices = quads.num_vertices_of_prefix(lod.num_leaf_indices);
            let views =
                builder.vertex_views(quads, num_vertices, Some(&UvBox::UNIT), &quantizer, false);
            primitives.extend(builder.primitives(quads, &views, lod.num_leaf_indices, material));
        } else if let Some((uv_box, material)) = plain_leaves.filter(|_| lod.num_leaf_indices > 0) {
            let cards = lod.leaves_in(&meshes.leaves);
            let num_vertices = cards.num_vertices_of_prefix(lod.num_leaf_indices);
            let views = builder.vertex_views(cards, num_vertices, Some(uv_box), &quantizer, true);
            primitives.extend(builder.primitives(cards, &views, lod.num_leaf_indices, material));
        } else if let Some(material) = leaf.filter(|_| lod.num_leaf_indices > 0) {
            let cards = lod.leaves_in(&meshes.leaves);
            let groups = card_instances(cards, lod.num_leaf_indices, card_size, &quantizer);
            for (kind, instances) in groups {
                // Cards all of one size (the finest level's) carry no scale of their own.
                let baked = common_scale(&instances);
                let key = baked.map(|s| s.to_array().map(f32::to_bits));
                let mesh = match card_meshes.iter().find(|(k, b, _)| *k == kind && *b == key) {
                    Some(&(_, _, mesh)) => mesh,
                    None => {
                        let mesh = builder.card_mesh(kind, card_size, baked, material);
                        card_meshes.push((kind, key, mesh));
                        mesh
                    }
                };
                let name = format!(
                    "tree_LOD{level}_leaves_ambient{}_{}",
                    kind.ambient_level,
                    if kind.normal_up { "up" } else { "down" }
                );
                children.push(builder.instance_node(name, mesh, &instances, baked.is_none()));
            }
        }
        if primitives.is_empty() && children.is_empty() {
            continue;
        }
        let name = format!("tree_LOD{level}");
        let mesh = (!primitives.is_empty()).then(|| {
            builder.root.push(json::Mesh {
                extensions: None,
                extras: Default::default(),
                name: Some(name.clone()),
                primitives,
                weights: None,
            })
        });
        let c = quantizer.center;
        level_nodes.push(builder.root.push(json::Node {
            mesh,
            name: Some(name),
            translation: Some([c.x, c.y, c.z]),
            scale: Some([quantizer.half_extent; 3]),
            children: (!children.is_empty()).then_some(children),
            ..Default::default()
        }));
    }
    // Quantized bark texture coordinates are read through the bark texture's transform.
    for extension in [KHR_MESH_QUANTIZATION, KHR_TEXTURE_TRANSFORM] {
        builder.root.extensions_used.push(extension.into());
        builder.root.extensions_required.push(extension.into());
    }
    if !card_meshes.is_empty() {
        builder
            .root
            .extensions_used
            .push(EXT_MESH_GPU_INSTANCING.into());
        builder
            .root
            .extensions_required
            .push(EXT_MESH_GPU_INSTANCING.into());
    }
    // One scene with one tree: the finest level is a plain node, which readers without
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
pub(super) fn container(
    mut json_bytes: Vec<u8>,
    bin: Vec<u8>,
    path: &Path,
) -> Result<Vec<u8>, ExportError> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_runs_stay_within_16_bits_and_cover_every_triangle() {
        // Three "chains" of 40,000 vertices each, one quad strip per chain.
        let mut indices = Vec::new();
        for chain in 0..3u32 {
            let base = chain * 40_000;
            for k in 0..19_999 {
                let (a, b) = (base + 2 * k, base + 2 * k + 2);
                indices.extend_from_slice(&[a, a + 1, b + 1, a, b + 1, b]);
            }
        }
        let runs = chunks(&indices, indices.len());
        assert!(runs.len() >= 2, "{runs:?}");
        assert_eq!(runs[0].first_index, 0);
        assert_eq!(runs.last().map(|r| r.end_index), Some(indices.len()));
        for pair in runs.windows(2) {
            assert_eq!(pair[0].end_index, pair[1].first_index);
        }
        for run in &runs {
            assert!(
                run.last_vertex - run.first_vertex < u32::from(u16::MAX),
                "{run:?}"
            );
            let used = &indices[run.first_index..run.end_index];
            assert!(
                used.iter()
                    .all(|&i| (run.first_vertex..=run.last_vertex).contains(&i))
            );
        }
    }
}
