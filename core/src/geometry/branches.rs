//! Branch meshes: generalized cylinders along the chains of the thickest-path topology.
//!
//! Ring frames (centre, tangent, transported reference, radius, texture coordinates, ambient)
//! are computed once per tree; each level of detail then emits them with its own side counts.

use std::f32::consts::{PI, TAU};

use glam::{Vec3, Vec3A};

use super::lanes::V4;
use super::parent_tube::{ParentTube, onto_parent, onto_parent4};
use super::rings::{Ring, carry_references, push_chain_rings};
use super::topology::{BranchTopology, NONE};
use super::{AmbientFn, BranchStart, MeshParams, NodeGeom, TreeMesh};
use crate::tree::NodeId;

/// The rings of one chain.
#[derive(Clone, Copy, Debug)]
struct ChainRings {
    first_ring: u32,
    /// Fewer than 2 means the chain has no visible geometry (it lies inside its parent).
    num_rings: u32,
    /// Sides C at the finest level (eq. C.2).
    sides: u32,
    /// Diameter of the chain's first internode.
    base_diameter: f32,
    /// Bark tiles around the circumference.
    tiles_around: f32,
}

/// cos/sin of `k·2π/C` for k in 0..=C, and the indices of the 2C triangles joining two rings
/// (relative to the first vertex of the lower ring), for every side count C up to a maximum.
#[derive(Default)]
struct SideTables {
    max_sides: u32,
    /// Mid-radius of a polygonal contour of C sides relative to its circumradius, per C.
    shrink: Vec<f32>,
    offsets: Vec<usize>,
    cos_sin: Vec<(f32, f32)>,
    pattern_offsets: Vec<usize>,
    patterns: Vec<u32>,
}

impl SideTables {
    fn new(max_sides: u32) -> Self {
        let mut offsets = vec![0; max_sides as usize + 1];
        let mut pattern_offsets = vec![0; max_sides as usize + 1];
        let mut cos_sin = Vec::new();
        let mut patterns = Vec::new();
        for sides in 3..=max_sides {
            offsets[sides as usize] = cos_sin.len();
            pattern_offsets[sides as usize] = patterns.len();
            for k in 0..=sides {
                let angle = TAU * k as f32 / sides as f32;
                cos_sin.push((angle.cos(), angle.sin()));
            }
            // Counter-clockwise seen from outside: (a0, a1, b1), (a0, b1, b0).
            for k in 0..sides {
                let (a0, a1, b0, b1) = (k, k + 1, sides + 1 + k, sides + 2 + k);
                patterns.extend_from_slice(&[a0, a1, b1, a0, b1, b0]);
            }
        }
        SideTables {
            max_sides,
            shrink: (0..=max_sides).map(contour_shrink).collect(),
            offsets,
            cos_sin,
            pattern_offsets,
            patterns,
        }
    }

    fn shrink(&self, sides: u32) -> f32 {
        match self.shrink.get(sides as usize) {
            Some(&shrink) => shrink,
            None => contour_shrink(sides),
        }
    }

    fn index_pattern(&self, sides: u32) -> &[u32] {
        let start = self.pattern_offsets[sides as usize];
        &self.patterns[start..start + 6 * sides as usize]
    }

    fn get(&self, sides: u32) -> &[(f32, f32)] {
        let start = self.offsets[sides as usize];
        &self.cos_sin[start..start + sides as usize + 1]
    }
}

/// Ring frames of every chain, and the working memory of the level-of-detail budget.
#[derive(Default)]
pub(crate) struct RingFrames {
    rings: Vec<Ring>,
    chains: Vec<ChainRings>,
    /// The parent's surface where each lateral chain starts; `None` for the trunk. Apart from
    /// `chains`, which the level-of-detail passes read whole and look up by parent.
    tubes: Vec<Option<ParentTube>>,
    /// Chains keyed by base diameter, thickest first (parents before children on ties): the
    /// chain index in the low 32 bits. Sorted on demand by the coarser levels.
    by_diameter: Vec<u64>,
    tables: SideTables,
    /// The internodes of every chain in chain order (`BranchTopology::chain_nodes`): the rings
    /// walk chains, which jump around the arena, so they read this gathered copy.
    chain_geometry: Vec<NodeGeom>,
    /// Per internode: whether a chain grows from its end (its ring is never left out).
    anchors: Vec<bool>,
    /// Working memory of [`push_chain_rings`].
    joints: Vec<u32>,
}

/// Mid-radius of the polygonal contour of a parent with `sides` sides, relative to its
/// circumradius (at least 0.96): a child's first ring laid at this radius shows no gap.
fn contour_shrink(sides: u32) -> f32 {
    (0.5 * (1.0 + (PI / sides as f32).cos())).max(0.96)
}

/// Sides C = 3·dⁿ/d_e (eq. C.2) of a branch of base diameter `d`, clamped to [3, max].
fn contour_sides(diameter: f32, thinnest: f32, exponent: f32, max_sides: u32) -> u32 {
    // pow(d, 1) = d exactly: the common exponent skips the costly `powf`.
    let power = if exponent == 1.0 {
        diameter
    } else {
        diameter.powf(exponent)
    };
    let sides = 3.0 * power / thinnest;
    (sides.round() as u32).clamp(3, max_sides.max(3))
}

/// Sides of a chain at a level of detail drawn with `side_scale` of the finest sides.
fn scaled_sides(sides: u32, side_scale: f32) -> u32 {
    if side_scale == 1.0 {
        // The finest level, without a call to `round` (not an instruction on baseline x86-64).
        return sides.max(3);
    }
    ((sides as f32 * side_scale).round() as u32).max(3)
}

impl RingFrames {
    /// The rings of every chain of `topology`, into `self` (buffers reused).
    pub(crate) fn build_into(
        &mut self,
        nodes: &[NodeGeom],
        topology: &BranchTopology,
        params: &MeshParams,
        ambient: AmbientFn,
    ) {
        let thinnest = nodes
            .iter()
            .map(|n| n.diameter)
            .filter(|&d| d > 0.0)
            .fold(f32::INFINITY, f32::min)
            .clamp(1e-4, 1.0);
        let max_sides = params.max_sides.max(3);
        if self.tables.max_sides != max_sides {
            self.tables = SideTables::new(max_sides);
        }
        let (rings, chains) = (&mut self.rings, &mut self.chains);
        let chain_geometry = &mut self.chain_geometry;
        chain_geometry.clear();
        chain_geometry.extend(topology.chain_nodes.iter().map(|&n| nodes[n as usize]));
        let anchors = &mut self.anchors;
        anchors.clear();
        anchors.resize(nodes.len(), false);
        for chain in &topology.chains {
            if let Some(anchor) = anchors.get_mut(chain.parent_node as usize) {
                *anchor = true;
            }
        }
        rings.clear();
        rings.reserve(nodes.len() + topology.chains.len());
        chains.clear();
        chains.reserve(topology.chains.len());
        self.tubes.clear();
        self.tubes.reserve(topology.chains.len());
        for (chain_index, chain) in topology.chains.iter().enumerate() {
            let chain_nodes = topology.nodes_of(chain_index);
            let geometry = &chain_geometry[chain.first as usize..][..chain_nodes.len()];
            let raw_diameter = geometry[0].diameter;
            let base_diameter = raw_diameter.max(1e-5);
            let circumference = PI * base_diameter;
            let tiles_around = (circumference / params.bark_tile_size.max(1e-4))
                .round()
                .max(1.0);
            let first_ring = rings.len() as u32;
            let tube = (chain.parent_node != NONE)
                .then(|| ParentTube::new(nodes, topology, chain.parent_node, params.tip_taper));
            push_chain_rings(
                rings,
                geometry,
                tube.as_ref(),
                chain_nodes,
                &self.anchors,
                params,
                circumference / tiles_around,
                ambient,
                &mut self.joints,
            );
            chains.push(ChainRings {
                first_ring,
                num_rings: rings.len() as u32 - first_ring,
                sides: contour_sides(base_diameter, thinnest, params.side_exponent, max_sides),
                base_diameter: raw_diameter,
                tiles_around,
            });
            self.tubes.push(tube);
        }
        let spans = self.chains.iter().map(|chain| {
            let first = chain.first_ring as usize;
            first..first + chain.num_rings as usize
        });
        carry_references(&mut self.rings, spans);
        self.by_diameter.clear();
    }

    /// Triangles of the branches drawn with `side_scale` of the finest sides, all chains or the
    /// `kept` ones.
    pub(crate) fn num_triangles(&self, side_scale: f32, kept: Option<&[bool]>) -> usize {
        self.chains
            .iter()
            .enumerate()
            .filter(|(index, _)| kept.is_none_or(|k| k[*index]))
            .map(|(_, c)| chain_triangles(c, side_scale))
            .sum()
    }

    /// The thickest chains whose triangles, with `side_scale`, fit in `budget`; a chain is only
    /// kept with its parent, and the trunk always.
    pub(crate) fn chains_within_budget(
        &mut self,
        topology: &BranchTopology,
        side_scale: f32,
        budget: usize,
        kept: &mut Vec<bool>,
    ) {
        if self.by_diameter.len() != self.chains.len() {
            self.by_diameter.clear();
            self.by_diameter
                .extend(self.chains.iter().enumerate().map(|(index, chain)| {
                    // Non-negative floats order as their bits; invert for thickest first.
                    let bits = chain.base_diameter.max(0.0).to_bits();
                    (u64::from(u32::MAX - bits) << 32) | index as u64
                }));
            self.by_diameter.sort_unstable();
        }
        kept.clear();
        kept.resize(self.chains.len(), false);
        let mut used = 0usize;
        for &key in &self.by_diameter {
            let index = key as u32 as usize;
            let parent = topology.chains[index].parent_chain;
            if parent != NONE && !kept[parent as usize] {
                continue;
            }
            let triangles = chain_triangles(&self.chains[index], side_scale);
            if parent == NONE || used + triangles <= budget {
                kept[index] = true;
                used += triangles;
            }
        }
    }

    /// Emits the branch mesh with `side_scale` of the finest sides, all chains or the `kept` ones,
    /// into `mesh` and `starts` (cleared first; their capacity is reused).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn mesh_into(
        &self,
        topology: &BranchTopology,
        side_scale: f32,
        kept: Option<&[bool]>,
        mesh: &mut TreeMesh,
        starts: &mut Vec<BranchStart>,
    ) {
        let is_kept = |index: usize| kept.is_none_or(|k| k[index]);
        let (mut num_vertices, mut num_indices) = (0, 0);
        for (index, chain) in self.chains.iter().enumerate() {
            if is_kept(index) && chain.num_rings >= 2 {
                let sides = scaled_sides(chain.sides, side_scale) as usize;
                num_vertices += (sides + 1) * chain.num_rings as usize;
                num_indices += 6 * sides * (chain.num_rings as usize - 1);
            }
        }
        mesh.clear();
        mesh.reserve(num_vertices, num_indices);
        starts.clear();
        for (index, chain) in self.chains.iter().enumerate() {
            if !is_kept(index) || chain.num_rings < 2 {
                continue;
            }
            let sides = scaled_sides(chain.sides, side_scale);
            let topo = topology.chains[index];
            let parent = (topo.parent_node != NONE).then(|| {
                let parent_sides =
                    scaled_sides(self.chains[topo.parent_chain as usize].sides, side_scale);
                (topo.parent_node, parent_sides)
            });
            starts.push(BranchStart {
                node: NodeId(topology.chain_nodes[topo.first as usize]),
                parent: parent.map(|(p, _)| (NodeId(p), NodeId(topology.visual_child[p as usize]))),
                first_vertex: mesh.positions.len() as u32,
                sides,
            });
            self.emit_chain(
                mesh,
                chain,
                self.tubes[index].as_ref(),
                sides,
                parent.map(|(_, parent_sides)| parent_sides),
            );
        }
        debug_assert_eq!(mesh.positions.len(), num_vertices);
    }

    /// Emits one chain with `sides` sides; `parent_sides` is the side count of the parent at
    /// this level (the first ring is laid onto `tube`, a surface that polygonal).
    fn emit_chain(
        &self,
        mesh: &mut TreeMesh,
        chain: &ChainRings,
        tube: Option<&ParentTube>,
        sides: u32,
        parent_sides: Option<u32>,
    ) {
        // Mid-radius of the parent's polygonal contour, so the joint shows no gap.
        let shrink = parent_sides.map(|c| self.tables.shrink(c));
        let table = self.tables.get(sides);
        let pattern = self.tables.index_pattern(sides);
        let rings =
            &self.rings[chain.first_ring as usize..(chain.first_ring + chain.num_rings) as usize];
        let du = chain.tiles_around / sides as f32;
        let ring_size = table.len();
        let first_vertex = mesh.positions.len();
        // Every attribute is appended from an iterator of known length, written once in place.
        for ring in rings {
            // In SIMD vectors (`Vec3A`): the same operations lane by lane, so the same bits.
            let (reference, binormal) = (Vec3A::from(ring.reference), Vec3A::from(ring.binormal));
            let center = Vec3A::from(ring.center);
            let direction = |&(cos, sin): &(f32, f32)| reference * cos + binormal * sin;
            mesh.positions.extend(
                table
                    .iter()
                    .map(|cs| (center + direction(cs) * ring.radius).to_array()),
            );
            mesh.normals
                .extend(table.iter().map(|cs| direction(cs).to_array()));
            mesh.uvs
                .extend((0..ring_size).map(|k| [k as f32 * du + ring.u_offset, ring.v]));
            mesh.ambient
                .extend(std::iter::repeat_n(ring.ambient, ring_size));
        }
        if let Some((tube, shrink)) = tube.zip(shrink) {
            // The first ring, written round its centre above, is laid onto the parent.
            let positions = &mut mesh.positions[first_vertex..][..ring_size];
            let normals = &mesh.normals[first_vertex..][..ring_size];
            laid_ring(positions, normals, &rings[0], tube, shrink);
        }
        for ring_index in 0..rings.len() - 1 {
            let below = (first_vertex + ring_index * ring_size) as u32;
            mesh.indices
                .extend(pattern.iter().map(|&offset| below + offset));
        }
    }
}

/// Lays a lateral chain's first ring, written round its centre, onto its parent's surface:
/// moves the `positions` of its vertices, whose `normals` are their directions from the centre.
/// Four vertices at a time (a ring has at least four vertices; the last group overlaps the one
/// before when the count is not a multiple of four, and writes the shared vertices again with
/// the same values); a group with a degenerate vertex is laid one vertex at a time.
fn laid_ring(
    positions: &mut [[f32; 3]],
    normals: &[[f32; 3]],
    ring: &Ring,
    tube: &ParentTube,
    shrink: f32,
) {
    let num_vertices = positions.len();
    let mut start = 0;
    while start < num_vertices {
        let first = start.min(num_vertices.saturating_sub(4));
        let Some(group) = normals.get(first..first + 4) else {
            // Fewer than four vertices in all.
            for (position, &direction) in positions.iter_mut().zip(normals) {
                *position = onto_parent(tube, ring, direction.into(), shrink).to_array();
            }
            return;
        };
        let directions: [Vec3; 4] = std::array::from_fn(|i| Vec3::from(group[i]));
        let laid = &mut positions[first..first + 4];
        match onto_parent4(tube, ring, V4::gather(directions), shrink) {
            Some(projected) => {
                for (i, position) in laid.iter_mut().enumerate() {
                    *position = projected.lane(i);
                }
            }
            None => {
                for (position, direction) in laid.iter_mut().zip(directions) {
                    *position = onto_parent(tube, ring, direction, shrink).to_array();
                }
            }
        }
        start = first + 4;
    }
}

fn chain_triangles(chain: &ChainRings, side_scale: f32) -> usize {
    if chain.num_rings < 2 {
        return 0;
    }
    2 * scaled_sides(chain.sides, side_scale) as usize * (chain.num_rings as usize - 1)
}
