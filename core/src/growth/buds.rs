//! Buds: gathering the living buds of the tree for an iteration, and placing new lateral buds by
//! phyllotaxis (distichous, spiral with angle φ, decussate, whorled with k buds) at branching
//! angle ψ from the heading, in the internode's HLU frame.

use glam::Vec3;
use rayon::prelude::*;

use super::{Scratch, Tree};
use crate::environment::clear_with_room;
use crate::species::{Phyllotaxis, Species};
use crate::tree::Internode;

/// Nodes per block of the parallel pass over the tree (a block outweighs handing it over).
const PARALLEL_NODES: usize = 4096;

/// [`collect`] keeps the light exposures of nodes in unchanged bricks only when at most one
/// brick in this many changed since the previous iteration.
const KEEP_LIGHT_CHANGED_BRICKS: usize = 4;

/// Slot of a terminal bud in [`BudState::slot`]; lateral buds use their index.
pub(crate) const TERMINAL: u32 = u32::MAX;

/// Working state of one living bud during an iteration.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BudState {
    pub node: u32,
    pub slot: u32,
    pub direction: Vec3,
    /// L: light exposure.
    pub light: f32,
    /// Q: bud input.
    pub q: f32,
    /// v: vigor reaching the bud.
    pub vigor: f32,
    pub enabled: bool,
    /// Takes part in the competition for space this iteration (may grow and is not in full
    /// shade when light matters).
    pub competes: bool,
}

/// The iteration before which lateral buds have outlived the species' bud lifetime (dormant
/// buds that never broke die), if any.
fn bud_cutoff(tree: &Tree) -> Option<u32> {
    let s = &tree.species;
    if s.bud_lifetime_years <= 0.0 {
        return None;
    }
    let lifetime = (s.bud_lifetime_years / s.years_per_iteration).ceil() as u32;
    tree.iteration.checked_sub(lifetime)
}

/// One pass over the tree on all threads by blocks of nodes: kills lateral buds older than the
/// bud lifetime, sets the light exposure L of every node that has buds (step 1,
/// [`super::light`]), lists every living bud, node by node (terminal first), with the mask,
/// and takes the arena's compact links (`scratch.main_child`, `lateral_range`, `lateral`);
/// then the blocks' lists are copied into `scratch.buds` and `scratch.lateral` (a pass over
/// compact lists, not the arena).
pub(crate) fn collect(tree: &mut Tree, scratch: &mut Scratch) {
    let cutoff = bud_cutoff(tree);
    // Nodes born before `expired` had every lateral bud killed by an earlier pass of this tree
    // (nothing revives a bud, and every node added since was born later): their lateral buds
    // need no visit. A tree whose iteration did not simply advance since (a clone, a loaded or
    // rewound tree starts with empty scratch) checks every node.
    let expired = if scratch
        .expired_at
        .is_some_and(|at| at + 1 == tree.iteration)
    {
        scratch.expired_below
    } else {
        0
    };
    scratch.expired_below = expired.max(cutoff.unwrap_or(0));
    scratch.expired_at = Some(tree.iteration);
    let nodes = &mut tree.skeleton.internodes;
    let n = nodes.len();
    // About one living bud per node in a grown crown; a few more cost one copy.
    clear_with_room(&mut scratch.buds, n);
    clear_with_room(&mut scratch.node_bud_start, n + 1);
    clear_with_room(&mut scratch.node_end, n);
    clear_with_room(&mut scratch.in_mask, n);
    clear_with_room(&mut scratch.main_child, n);
    clear_with_room(&mut scratch.lateral_range, n);
    clear_with_room(&mut scratch.lateral, n);
    scratch
        .in_mask
        .resize(nodes.len(), tree.growth_mask.is_none());
    if let Some(mask) = tree.growth_mask
        && mask.index() < nodes.len()
    {
        scratch.in_mask[mask.index()] = true;
        for (i, node) in nodes.iter().enumerate().skip(mask.index() + 1) {
            if let Some(p) = node.parent {
                scratch.in_mask[i] = scratch.in_mask[p.index()];
            }
        }
    }
    let (species, shadow) = (&tree.species, &tree.environment.shadow);
    let light_matters = species.light_sensitivity > 0.0;
    // A node that had living buds at the previous iteration's collection got its exposure
    // then; if the grid is the same one and no change since touched the node's brick, the
    // same formula would give the same value, so it is kept. New nodes (born since, with the
    // exposure their shoot gave them) and every node after anything else (a clone, a loaded
    // tree, another grid, other light parameters) get it computed.
    let light_key = LightKey {
        grid: shadow.id(),
        full_exposure: species.full_exposure.to_bits(),
        shadow_strength: species.shadow_strength.to_bits(),
    };
    // When most bricks changed (autonomous growth, as a rule), asking brick by brick costs
    // more than it saves: every exposure is computed (the same values either way).
    let light_seen = scratch
        .light_seen
        .filter(|seen| seen.key == light_key && seen.iteration + 1 == tree.iteration)
        .filter(|seen| {
            let (changed, bricks) = shadow.bricks_changed_since(seen.version);
            changed.saturating_mul(KEEP_LIGHT_CHANGED_BRICKS) <= bricks
        })
        .map(|seen| (seen.version, seen.iteration));
    scratch.light_seen = Some(LightSeen {
        key: light_key,
        version: shadow.version(),
        iteration: tree.iteration,
    });
    let Scratch {
        buds,
        node_bud_start,
        node_end,
        in_mask,
        main_child,
        lateral_range,
        lateral,
        bud_blocks,
        ..
    } = scratch;
    node_bud_start.resize(n + 1, 0);
    node_end.resize(n, Vec3::ZERO);
    main_child.resize(n, super::NO_NODE);
    lateral_range.resize(n, (0, 0));
    let num_blocks = n.div_ceil(PARALLEL_NODES);
    if bud_blocks.len() < num_blocks {
        bud_blocks.resize_with(num_blocks, BudBlock::default);
    }
    // One pass over the arena, on all threads by blocks of nodes: the expired lateral buds
    // die, a node left with a living bud gets the light exposure of its buds, and each block
    // lists its living buds (node by node, terminal first) and lateral children in its own
    // buffers and writes its nodes' links with offsets into those buffers (each node is its
    // own: any thread count gives the same values).
    nodes
        .par_chunks_mut(PARALLEL_NODES)
        .zip(node_bud_start[..n].par_chunks_mut(PARALLEL_NODES))
        .zip(node_end.par_chunks_mut(PARALLEL_NODES))
        .zip(main_child.par_chunks_mut(PARALLEL_NODES))
        .zip(lateral_range.par_chunks_mut(PARALLEL_NODES))
        .zip(in_mask.par_chunks(PARALLEL_NODES))
        .zip(bud_blocks[..num_blocks].par_iter_mut())
        .enumerate()
        .for_each(
            |(block, ((((((block_nodes, starts), ends), mains), ranges), mask), out))| {
                out.buds.clear();
                out.lateral.clear();
                for (k, node) in block_nodes.iter_mut().enumerate() {
                    let i = block * PARALLEL_NODES + k;
                    let expired_before = node.born_iteration < expired;
                    if !expired_before
                        && cutoff.is_some_and(|c| node.born_iteration < c)
                        && node.lateral_buds.iter().any(|b| b.alive)
                    {
                        for bud in &mut node.lateral_buds {
                            bud.alive = false;
                        }
                    }
                    let terminal = node.terminal_bud.as_ref().is_some_and(|b| b.alive);
                    let laterals = !expired_before && node.lateral_buds.iter().any(|b| b.alive);
                    let current = || {
                        light_seen.is_some_and(|(version, iteration)| {
                            node.born_iteration < iteration
                                && !shadow.changed_since(node.end, version)
                        })
                    };
                    if (terminal || laterals) && !current() {
                        node.light_exposure = super::light::exposure(species, shadow, node.end);
                    }
                    let first = out.buds.len();
                    starts[k] = first as u32;
                    ends[k] = node.end;
                    mains[k] = node.main_child.map_or(super::NO_NODE, |c| c.0);
                    let lateral_start = out.lateral.len() as u32;
                    out.lateral
                        .extend(node.lateral_children.iter().map(|c| c.0));
                    ranges[k] = (lateral_start, out.lateral.len() as u32);
                    if !(terminal || laterals) {
                        continue;
                    }
                    let may_grow = mask[k];
                    // A bud in full shade (L = 0) can never grow when κ > 0 (Q = b·0^κ = 0):
                    // it takes no part in the competition for space ([`super::space`]).
                    let light = node.light_exposure;
                    let competes = may_grow && (!light_matters || light > 0.0);
                    let state = |slot: u32, direction: Vec3| BudState {
                        node: i as u32,
                        slot,
                        direction,
                        light,
                        q: 0.0,
                        vigor: 0.0,
                        enabled: false,
                        competes,
                    };
                    if let Some(bud) = &node.terminal_bud
                        && bud.alive
                    {
                        out.buds.push(state(TERMINAL, bud.direction));
                    }
                    if laterals {
                        for (slot, bud) in node.lateral_buds.iter().enumerate() {
                            if bud.alive {
                                out.buds.push(state(slot as u32, bud.direction));
                            }
                        }
                    }
                }
            },
        );
    // Then, again by blocks on all threads, each block's buds and lateral children go to
    // their place in the whole lists, and its offsets become offsets into those.
    let (total_buds, total_laterals) = bud_blocks[..num_blocks]
        .iter()
        .fold((0usize, 0usize), |(b, l), block| {
            (b + block.buds.len(), l + block.lateral.len())
        });
    buds.resize(total_buds, BudState::UNSET);
    lateral.resize(total_laterals, 0);
    node_bud_start[n] = total_buds as u32;
    let mut parts = Vec::with_capacity(num_blocks);
    let (mut bud_rest, mut lateral_rest) = (&mut buds[..], &mut lateral[..]);
    let (mut bud_base, mut lateral_base) = (0u32, 0u32);
    for block in &bud_blocks[..num_blocks] {
        let (bud_part, bud_tail) = bud_rest.split_at_mut(block.buds.len());
        let (lateral_part, lateral_tail) = lateral_rest.split_at_mut(block.lateral.len());
        parts.push((bud_part, bud_base, lateral_part, lateral_base));
        (bud_rest, lateral_rest) = (bud_tail, lateral_tail);
        bud_base += block.buds.len() as u32;
        lateral_base += block.lateral.len() as u32;
    }
    node_bud_start[..n]
        .par_chunks_mut(PARALLEL_NODES)
        .zip(lateral_range.par_chunks_mut(PARALLEL_NODES))
        .zip(bud_blocks[..num_blocks].par_iter())
        .zip(parts.into_par_iter())
        .for_each(
            |(((starts, ranges), block), (bud_part, bud_base, lateral_part, lateral_base))| {
                bud_part.copy_from_slice(&block.buds);
                lateral_part.copy_from_slice(&block.lateral);
                for s in starts {
                    *s += bud_base;
                }
                for r in ranges {
                    *r = (r.0 + lateral_base, r.1 + lateral_base);
                }
            },
        );
    let num_buds = scratch.buds.len();
    clear_with_room(&mut scratch.won, num_buds);
    scratch.won.resize(num_buds, WonPoints::default());
}

/// What the light exposures of [`collect`] were computed from: the shadow grid and the
/// species' light parameters (bits).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct LightKey {
    grid: u64,
    full_exposure: u32,
    shadow_strength: u32,
}

/// The last [`collect`]: its light key, the grid's version then and the iteration.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LightSeen {
    key: LightKey,
    version: u64,
    iteration: u32,
}

/// One block's part of [`collect`]'s lists, kept between iterations.
#[derive(Debug, Default)]
pub(crate) struct BudBlock {
    buds: Vec<BudState>,
    lateral: Vec<u32>,
}

impl BudState {
    /// A placeholder, overwritten before it is read.
    const UNSET: BudState = BudState {
        node: 0,
        slot: 0,
        direction: Vec3::ZERO,
        light: 0.0,
        q: 0.0,
        vigor: 0.0,
        enabled: false,
        competes: false,
    };
}

/// What a bud won in the competition for space (step 2), kept apart from [`BudState`] so
/// that the passes over every bud read less memory.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct WonPoints {
    /// Σ unit vectors to the attraction points this bud won.
    pub environment_sum: Vec3,
    /// Σ tropism directions carried by those points.
    pub tropism_sum: Vec3,
    pub count: u32,
}

/// Azimuth turn between successive nodes of an axis.
fn azimuth_step(species: &Species) -> f32 {
    match species.phyllotaxis {
        Phyllotaxis::Distichous => std::f32::consts::PI,
        Phyllotaxis::Decussate => std::f32::consts::FRAC_PI_2,
        Phyllotaxis::Spiral | Phyllotaxis::Whorled => species.phyllotactic_angle_deg.to_radians(),
    }
}

/// Azimuth of the first lateral bud of `node` in its HLU frame, if it has one.
pub(crate) fn first_bud_azimuth(node: &Internode) -> Option<f32> {
    let bud = node.lateral_buds.first()?;
    let (h, l) = (node.heading(), node.left);
    let u = h.cross(l);
    Some(bud.direction.dot(u).atan2(bud.direction.dot(l)))
}

/// Azimuth for the next node of an axis whose previous node had `previous` (random if none).
pub(crate) fn next_azimuth(species: &Species, previous: Option<f32>, random: f32) -> f32 {
    previous.map_or(random, |a| a + azimuth_step(species))
}

/// Where a species places the lateral buds of a new internode: k buds at branching angle ψ from
/// the heading (sin ψ and cos ψ worked out once for all the internodes of an iteration).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LateralBudPlacement {
    sin_psi: f32,
    cos_psi: f32,
    buds: u32,
}

impl LateralBudPlacement {
    pub(crate) fn of(species: &Species) -> Self {
        let (sin_psi, cos_psi) = species.branching_angle_deg.to_radians().sin_cos();
        LateralBudPlacement {
            sin_psi,
            cos_psi,
            buds: species.buds_per_node(),
        }
    }

    /// Adds the lateral buds of a new internode, the first at `azimuth` around its heading.
    pub(crate) fn add_to(&self, node: &mut Internode, azimuth: f32) {
        let h = node.heading();
        let l = node.left;
        let u = h.cross(l);
        let k = self.buds;
        node.lateral_buds.clear();
        for j in 0..k {
            let az = azimuth + j as f32 * std::f32::consts::TAU / k as f32;
            let (s, c) = az.sin_cos();
            let dir = (self.cos_psi * h + self.sin_psi * (c * l + s * u))
                .try_normalize()
                .unwrap_or(h);
            node.lateral_buds.push(crate::tree::Bud::new(dir));
        }
    }
}

/// Parallel transport of the L axis onto a new heading: the minimal change keeping L ⟂ H.
pub(crate) fn transport_left(left: Vec3, heading: Vec3) -> Vec3 {
    (left - left.dot(heading) * heading)
        .try_normalize()
        .unwrap_or_else(|| heading.any_orthonormal_vector())
}

#[cfg(test)]
mod tests {
    use crate::Tree;
    use crate::growth::StepOptions;
    use crate::species::Species;

    #[test]
    fn skipping_expired_nodes_grows_the_same_tree_as_checking_every_node() {
        let species = Species::by_name("maple").expect("maple preset");
        let mut kept = Tree::new(species, 3);
        let mut fresh = kept.clone();
        let options = StepOptions {
            autonomous: true,
            scene: None,
        };
        for iteration in 0..9 {
            if iteration == 6 {
                // A shorter bud lifetime moves the cutoff past nodes not yet expired.
                kept.species.bud_lifetime_years = 1.0;
                fresh.species.bud_lifetime_years = 1.0;
            }
            kept.step(options);
            // A clone starts with empty working memory, so it visits every node's buds.
            fresh = fresh.clone();
            fresh.step(options);
            assert_eq!(kept, fresh, "iteration {iteration}");
        }
        let dead = kept
            .skeleton
            .internodes
            .iter()
            .filter(|n| !n.lateral_buds.is_empty() && n.lateral_buds.iter().all(|b| !b.alive))
            .count();
        assert!(dead > 100, "{dead} nodes with only dead buds");
    }
}
