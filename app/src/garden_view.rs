//! Drawing a garden: the trees besides the selected one, each meshed in its own space only when
//! it changes (cached by its id and revision), placed into the space the frame is drawn in (the
//! selected tree's) and uploaded into the renderer's garden slots 1.. (slot 0 is the selected
//! tree, drawn as a single tree is).

use std::collections::HashMap;

use glam::{Affine3A, Vec3};
use sylva_core::geometry::Season;

use crate::render::{CardInstance, Gpu, LitMesh, Renderer, TreeMesh};
use crate::state::DesignState;
use crate::tree_model::TreeMesher;

/// Where each tree of a design's garden stands, written next to its garden file.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GardenPlacement {
    /// Column-major `world_from_tree` of each tree, in the garden's order.
    pub world_from_tree: Vec<[f32; 12]>,
    /// The tree selected when it was written.
    pub selected: usize,
}

/// Writes the design's garden to `garden_path` (the core's versioned garden file, the selected
/// tree as it is now) and where each tree stands to `garden_path` with the extension
/// `placement.json`; false (nothing written) for a design of one tree, whose tree file says it
/// all.
pub fn write_garden(design: &DesignState, garden_path: &std::path::Path) -> anyhow::Result<bool> {
    let Some((garden, placed)) = design.garden_now() else {
        return Ok(false);
    };
    crate::outputs::write_file(garden_path, &garden.to_json_bytes())?;
    let placement = GardenPlacement {
        world_from_tree: placed.iter().map(Affine3A::to_cols_array).collect(),
        selected: design.selected_tree(),
    };
    crate::outputs::write_file(
        &garden_path.with_extension("placement.json"),
        serde_json::to_string_pretty(&placement)?.as_bytes(),
    )?;
    Ok(true)
}

/// `mesh` (built in a tree's own space) moved by `draw_from_tree` (a rigid motion).
pub fn placed_mesh(mesh: &TreeMesh, draw_from_tree: &Affine3A) -> TreeMesh {
    let point = |p: [f32; 3]| draw_from_tree.transform_point3(Vec3::from(p)).to_array();
    let vector = |v: [f32; 3]| draw_from_tree.transform_vector3(Vec3::from(v)).to_array();
    let lit = |m: &LitMesh| LitMesh {
        vertices: m
            .vertices
            .iter()
            .map(|v| crate::render::LitVertex {
                position: point(v.position),
                normal: vector(v.normal),
                ..*v
            })
            .collect(),
        indices: m.indices.clone(),
    };
    TreeMesh {
        levels: mesh
            .levels
            .iter()
            .map(|level| crate::render::TreeLevel {
                branches: lit(&level.branches),
                cards: level
                    .cards
                    .iter()
                    .map(|c| CardInstance {
                        origin: point(c.origin),
                        across: vector(c.across),
                        along: vector(c.along),
                        normal: vector(c.normal),
                        ambient: c.ambient,
                    })
                    .collect(),
                fruit: lit(&level.fruit),
            })
            .collect(),
        look: mesh.look.clone(),
    }
}

/// What the renderer's garden slots hold: for each other tree its id and revision, and the
/// space they were placed into, with the season.
type Uploaded = (Vec<(u64, u64, [f32; 12])>, Season);

/// Meshes the garden's other trees and keeps the renderer's garden slots up to date.
#[derive(Default)]
pub struct GardenMesher {
    mesher: TreeMesher,
    /// Each tree's mesh in its own space, by id: (revision, season, mesh).
    meshes: HashMap<u64, (u64, Season, TreeMesh)>,
    uploaded: Option<Uploaded>,
}

impl GardenMesher {
    /// Uploads the trees of `design` other than the selected one (none when it holds one tree,
    /// or `show` is false: before planting) into slots 1.., placed in the selected tree's
    /// space; only what changed is meshed, and nothing is uploaded when nothing did.
    pub fn upload(&mut self, gpu: &Gpu, renderer: &mut Renderer, design: &DesignState, show: bool) {
        let others = if show {
            design.other_trees()
        } else {
            Vec::new()
        };
        let tree_from_world = design.tree_from_world();
        let season = design.params.season;
        let key: Uploaded = (
            others
                .iter()
                .map(|o| {
                    let draw_from_tree = tree_from_world * o.world_from_tree;
                    (o.id, o.revision, draw_from_tree.to_cols_array())
                })
                .collect(),
            season,
        );
        if self.uploaded.as_ref() == Some(&key) {
            return;
        }
        self.meshes
            .retain(|id, _| others.iter().any(|o| o.id == *id));
        for (slot, o) in others.iter().enumerate() {
            let fresh = self
                .meshes
                .get(&o.id)
                .is_some_and(|(r, s, _)| *r == o.revision && *s == season);
            if !fresh {
                let mesh = self.mesher.mesh_in(o.tree, season).clone();
                self.meshes.insert(o.id, (o.revision, season, mesh));
            }
            if let Some((_, _, mesh)) = self.meshes.get(&o.id) {
                let draw_from_tree = tree_from_world * o.world_from_tree;
                renderer.set_garden_tree(gpu, slot + 1, &placed_mesh(mesh, &draw_from_tree));
            }
        }
        renderer.keep_garden_trees(others.len() + 1);
        self.uploaded = Some(key);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_placed_mesh_moves_points_and_turns_normals_and_cards() {
        let mut mesh = crate::tree_model::golden_tree_mesh();
        mesh.levels.truncate(1);
        let m = Affine3A::from_rotation_translation(
            glam::Quat::from_rotation_y(0.5),
            Vec3::new(3.0, 0.0, -1.0),
        );
        let placed = placed_mesh(&mesh, &m);
        let (a, b) = (&mesh.levels[0], &placed.levels[0]);
        let v = (a.branches.vertices[5], b.branches.vertices[5]);
        let p = m.transform_point3(Vec3::from(v.0.position));
        assert!(p.distance(Vec3::from(v.1.position)) < 1e-5);
        let n = Vec3::from(v.1.normal);
        assert!((n.length() - Vec3::from(v.0.normal).length()).abs() < 1e-5);
        let card = (a.cards[0], b.cards[0]);
        let corner = m.transform_point3(card.0.corners()[3]);
        assert!(corner.distance(card.1.corners()[3]) < 1e-5);
        assert_eq!(a.branches.indices, b.branches.indices);
    }
}
