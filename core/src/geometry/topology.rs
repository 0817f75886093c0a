//! The visual topology of a skeleton (Longay 2014, appendix C.3): every branch follows the
//! thickest path from its base to a tip, whatever axis (apex) grew each part; everything attached
//! to that path is a child branch. Meshing along these chains leaves no cracks where a lateral
//! dominates its parent axis.

use crate::tree::{Internode, Skeleton};

/// Marks "none" in the `u32` links below.
pub const NONE: u32 = u32::MAX;

/// One branch of the visual topology: a chain of internodes along a thickest path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Chain {
    /// Offset of the chain's first internode in [`BranchTopology::chain_nodes`].
    pub first: u32,
    /// Number of internodes in the chain (at least 1).
    pub len: u32,
    /// The internode whose end this chain starts from; [`NONE`] for the trunk.
    pub parent_node: u32,
    /// The chain holding `parent_node`; [`NONE`] for the trunk.
    pub parent_chain: u32,
}

/// Chains of internodes along thickest paths, parents before children.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BranchTopology {
    pub chains: Vec<Chain>,
    /// Internode indices of all chains, each chain contiguous from base to tip.
    pub chain_nodes: Vec<u32>,
    /// For each internode, its continuation along the thickest path ([`NONE`] at a tip).
    pub visual_child: Vec<u32>,
    /// For each internode, the chain it belongs to.
    pub chain_of_node: Vec<u32>,
}

impl BranchTopology {
    /// Reorganises `skeleton` along thickest paths. The continuation of an internode is its
    /// thickest child, the apex's own continuation winning ties.
    pub fn build(skeleton: &Skeleton) -> Self {
        let mut topology = BranchTopology::default();
        topology.build_into(skeleton);
        topology
    }

    /// [`BranchTopology::build`] into `self`, reusing its buffers.
    pub fn build_into(&mut self, skeleton: &Skeleton) {
        let mut links = Links::default();
        links.clear();
        for node in &skeleton.internodes {
            links.push(node);
        }
        let diameters: Vec<f32> = skeleton.internodes.iter().map(|n| n.diameter).collect();
        self.build_with_links(&links, &diameters);
    }

    /// [`BranchTopology::build_into`] from the links of the skeleton and the internode
    /// diameters in arena order: compact arrays that stay in cache while children and parents
    /// are looked up, where the arena's internodes are large and each is read once already when
    /// the links are made.
    pub(crate) fn build_with_links(&mut self, links: &Links, diameters: &[f32]) {
        let num_nodes = links.parents.len();
        self.visual_child.clear();
        self.visual_child
            .extend(links.child_ranges.windows(2).map(|range| {
                let mut best = NONE;
                let mut best_diameter = f32::NEG_INFINITY;
                for &child in &links.children[range[0] as usize..range[1] as usize] {
                    let diameter = diameters[child as usize];
                    if diameter > best_diameter {
                        best = child;
                        best_diameter = diameter;
                    }
                }
                best
            }));
        let visual_child = &self.visual_child;
        self.chain_of_node.clear();
        self.chain_of_node.resize(num_nodes, NONE);
        self.chain_nodes.clear();
        self.chain_nodes.reserve(num_nodes);
        self.chains.clear();
        for (index, &parent_node) in links.parents.iter().enumerate() {
            let starts_chain =
                parent_node == NONE || visual_child[parent_node as usize] != index as u32;
            if !starts_chain {
                continue;
            }
            let chain_index = self.chains.len() as u32;
            let first = self.chain_nodes.len() as u32;
            let mut current = index as u32;
            while current != NONE {
                self.chain_nodes.push(current);
                self.chain_of_node[current as usize] = chain_index;
                current = visual_child[current as usize];
            }
            let parent_chain = if parent_node == NONE {
                NONE
            } else {
                // The parent is earlier in topological order, so its chain already exists.
                self.chain_of_node[parent_node as usize]
            };
            self.chains.push(Chain {
                first,
                len: self.chain_nodes.len() as u32 - first,
                parent_node,
                parent_chain,
            });
        }
    }

    /// The internodes of chain `chain`, base to tip.
    pub fn nodes_of(&self, chain: usize) -> &[u32] {
        let c = self.chains[chain];
        &self.chain_nodes[c.first as usize..(c.first + c.len) as usize]
    }
}

/// The links of a skeleton's internodes in compact arrays: the parent of each ([`NONE`] for
/// the root) and its children (main child first, then the laterals, as
/// [`Internode::children`] gives them).
#[derive(Clone, Debug, Default)]
pub(crate) struct Links {
    parents: Vec<u32>,
    /// The children of internode i are `children[child_ranges[i]..child_ranges[i + 1]]`.
    child_ranges: Vec<u32>,
    children: Vec<u32>,
}

impl Links {
    /// Empties the links, keeping their capacity.
    pub(crate) fn clear(&mut self) {
        self.parents.clear();
        self.children.clear();
        self.child_ranges.clear();
        self.child_ranges.push(0);
    }

    /// Appends the links of the next internode of the arena.
    pub(crate) fn push(&mut self, node: &Internode) {
        self.parents.push(node.parent.map_or(NONE, |p| p.0));
        self.children.extend(node.children().map(|c| c.0));
        self.child_ranges.push(self.children.len() as u32);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tree::{Children, LateralBuds, NodeId};
    use glam::Vec3;

    fn node(parent: Option<u32>, start: Vec3, end: Vec3, diameter: f32) -> Internode {
        Internode {
            parent: parent.map(NodeId),
            main_child: None,
            lateral_children: Children::new(),
            start,
            end,
            left: Vec3::X,
            diameter,
            order: 0,
            born_iteration: 0,
            terminal_bud: None,
            lateral_buds: LateralBuds::new(),
            width_constraint: None,
            light_exposure: 1.0,
        }
    }

    #[test]
    fn a_dominant_lateral_continues_the_trunk_chain() {
        // 0 → main 1 (thin), lateral 2 (thick) → 3.
        let mut nodes = vec![
            node(None, Vec3::ZERO, Vec3::Y, 0.1),
            node(Some(0), Vec3::Y, Vec3::new(0.0, 2.0, 0.0), 0.02),
            node(Some(0), Vec3::Y, Vec3::new(0.5, 2.0, 0.0), 0.08),
            node(
                Some(2),
                Vec3::new(0.5, 2.0, 0.0),
                Vec3::new(0.7, 3.0, 0.0),
                0.06,
            ),
        ];
        nodes[0].main_child = Some(NodeId(1));
        nodes[0].lateral_children = Children::from_slice(&[NodeId(2)]);
        nodes[2].main_child = Some(NodeId(3));
        let skeleton = Skeleton { internodes: nodes };
        skeleton.sanity_check().expect("valid test skeleton");
        let topology = BranchTopology::build(&skeleton);
        assert_eq!(topology.chains.len(), 2);
        assert_eq!(topology.nodes_of(0), &[0, 2, 3]);
        assert_eq!(topology.nodes_of(1), &[1]);
        assert_eq!(topology.chains[1].parent_node, 0);
        assert_eq!(topology.chains[1].parent_chain, 0);
    }
}
