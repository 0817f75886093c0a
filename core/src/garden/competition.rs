//! How the trees of a garden reach each other's environment.
//!
//! **Links.** Tree j reaches tree i once j's crown (the horizontal box of its nodes) comes
//! within i's reach: i's own box grown by the furthest a shadow pyramid spreads sideways in i's
//! grid, i's perception radius and the longest shoot one iteration can add. Nothing of a tree
//! outside that reach can shade a bud of i or occupy the space a bud of i perceives, so leaving
//! it out changes nothing. Once linked a pair stays linked (the links are saved with the garden),
//! so a neighbour's shade never flickers in and out.
//!
//! **Shade.** When j is linked to i, every node of j casts its pyramid into i's shadow grid (in
//! i's space); after each round the nodes j grew are added and those it shed are taken away.
//! Integer sums: the grid is exactly i's own shade plus that of its linked neighbours' current
//! nodes, whatever the order.
//!
//! **Space.** Before each round a tree due to grow gets, as occupied space in its own space, the
//! nodes of its linked neighbours close enough to take an attraction point from it.

use std::collections::HashSet;

use glam::{IVec3, Vec2, Vec3};
use rayon::prelude::*;

use super::{Garden, GardenTree};

/// Slack added to every reach, metres: far beyond the rounding of the boxes.
const REACH_SLACK_M: f32 = 0.05;

/// Horizontal box (x, z) of a tree's nodes in garden space.
fn crown_box(t: &GardenTree) -> (Vec2, Vec2) {
    let base = Vec2::new(t.x_m, t.z_m);
    let (mut lo, mut hi) = (base, base);
    for n in &t.tree.skeleton.internodes {
        let p = base + Vec2::new(n.end.x, n.end.z);
        lo = lo.min(p);
        hi = hi.max(p);
    }
    (lo, hi)
}

/// How far beyond its crown box tree `t` can feel a neighbour's node this round, metres.
fn reach_m(t: &GardenTree) -> f32 {
    let s = &t.tree.species;
    let l = s.internode_length_m;
    let shade = t.tree.environment.shadow.voxel_size() * (s.shadow_depth_voxels as f32 + 1.0);
    let perception = (s.occupancy_radius_internodes + s.perception_distance_internodes) * l;
    let shoot = s.max_shoot_internodes.max(1.0) * l;
    shade.max(perception) + shoot + REACH_SLACK_M
}

fn boxes_meet((lo_a, hi_a): (Vec2, Vec2), (lo_b, hi_b): (Vec2, Vec2), margin: f32) -> bool {
    lo_a.x - margin <= hi_b.x
        && lo_b.x <= hi_a.x + margin
        && lo_a.y - margin <= hi_b.y
        && lo_b.y <= hi_a.y + margin
}

/// The node ends of a tree in garden space, in arena order.
pub(super) fn node_ends(t: &GardenTree) -> Vec<Vec3> {
    let base = t.base();
    t.tree
        .skeleton
        .internodes
        .iter()
        .map(|n| base + n.end)
        .collect()
}

/// Links every pair that has come within reach and hands the newly linked neighbour's whole
/// shade to the tree it reaches.
pub(super) fn link_neighbours(garden: &mut Garden) {
    let boxes: Vec<(Vec2, Vec2)> = garden.trees.par_iter().map(crown_box).collect();
    let reaches: Vec<f32> = garden.trees.iter().map(reach_m).collect();
    let new_links: Vec<Vec<u32>> = (0..garden.trees.len())
        .into_par_iter()
        .map(|i| {
            let linked = &garden.trees[i].neighbours;
            (0..boxes.len())
                .filter(|&j| {
                    j != i
                        && boxes_meet(boxes[i], boxes[j], reaches[i])
                        && !linked.contains(&(j as u32))
                })
                .map(|j| j as u32)
                .collect()
        })
        .collect();
    if new_links.iter().all(Vec::is_empty) {
        return;
    }
    let ends: Vec<Option<Vec<Vec3>>> = (0..garden.trees.len())
        .into_par_iter()
        .map(|j| {
            new_links
                .iter()
                .any(|l| l.contains(&(j as u32)))
                .then(|| node_ends(&garden.trees[j]))
        })
        .collect();
    garden
        .trees
        .par_iter_mut()
        .zip(new_links)
        .for_each(|(t, links)| {
            let base = t.base();
            for &j in &links {
                if let Some(ends) = &ends[j as usize] {
                    t.tree
                        .environment
                        .shadow
                        .apply_nodes(ends.iter().map(|&p| p - base), 1);
                }
            }
            t.neighbours.extend(links);
            t.neighbours.sort_unstable();
        });
}

/// Cells of `size` metres holding, or next to one holding, a place where tree `t` (its own
/// space) can take attraction points this iteration: its nodes with a living bud and its
/// persistent points.
fn contact_cells(t: &GardenTree, size: f32) -> HashSet<IVec3> {
    let cell = |p: Vec3| (p / size).floor().as_ivec3();
    let tree = &t.tree;
    let buds = tree.skeleton.internodes.iter().filter(|n| {
        n.terminal_bud.as_ref().is_some_and(|b| b.alive) || n.lateral_buds.iter().any(|b| b.alive)
    });
    let own: HashSet<IVec3> = buds
        .map(|n| cell(n.end))
        .chain(
            tree.environment
                .attraction
                .points
                .iter()
                .map(|p| cell(p.position)),
        )
        .collect();
    // Each cell with the 26 around it, so that a neighbour's node needs one look-up.
    let mut cells = HashSet::with_capacity(own.len() * 4);
    for c in own {
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    cells.insert(c + IVec3::new(dx, dy, dz));
                }
            }
        }
    }
    cells
}

/// Gives every tree that is `due` the nodes of its linked neighbours that can take an
/// attraction point from it, in its own space; the others keep none (they do not grow this
/// round). A point a bud can win lies within the perception radius of it (or is a persistent
/// point), and a neighbour's node takes it only within its occupancy radius r: so only nodes
/// within r + perception of a node with a living bud, or of a persistent point, matter. They
/// are found through cells of that size (the cell of each such node and the 26 around it).
pub(super) fn gather_neighbour_nodes(garden: &mut Garden, due: &[bool]) {
    let gathered: Vec<Vec<Vec3>> = (0..garden.trees.len())
        .into_par_iter()
        .map(|i| {
            if !due[i] {
                return Vec::new();
            }
            let t = &garden.trees[i];
            let s = &t.tree.species;
            let size = (2.0 * s.occupancy_radius_internodes + s.perception_distance_internodes)
                * s.internode_length_m
                + REACH_SLACK_M;
            let cells = contact_cells(t, size);
            let (lo, hi) = cells.iter().fold(
                (IVec3::splat(i32::MAX), IVec3::splat(i32::MIN)),
                |(lo, hi), &c| (lo.min(c), hi.max(c)),
            );
            let base = t.base();
            let mut nodes = Vec::new();
            for &j in &t.neighbours {
                let n = &garden.trees[j as usize];
                let offset = n.base() - base;
                for node in &n.tree.skeleton.internodes {
                    let p = node.end + offset;
                    let c = (p / size).floor().as_ivec3();
                    if c.cmpge(lo).all() && c.cmple(hi).all() && cells.contains(&c) {
                        nodes.push(p);
                    }
                }
            }
            nodes
        })
        .collect();
    for (t, nodes) in garden.trees.iter_mut().zip(gathered) {
        t.tree.environment.neighbour_nodes = nodes;
    }
}

/// Weights α_a (relative crown area) and α_d (nearness) of a neighbour's pressure (eq. 6.3).
const PRESSURE_AREA_WEIGHT: f32 = 0.5;
const PRESSURE_DISTANCE_WEIGHT: f32 = 0.5;

/// Sets every tree's neighbourhood asymmetry tropism (Longay 2014 eq. 6.3–6.5). The pressure of
/// neighbour j on tree i is P_ij = ω_ij (T_i − T_j)/‖T_i − T_j‖ with ω_ij = α_a A_j/A_i +
/// α_d (1 − ‖T_i − T_j‖/r_i), for the trees within r_i of i's base (r_i: the spread the species
/// reaches at 30 years; A: projected crown areas, π R² of the crown radius); V_i is their sum,
/// at most 1 long (this garden has no constraint volume, so eq. 6.4's space factor is 1); the
/// tropism is (1 − α) V_i with α = (h/h_max)^½, h the tree's height and h_max the height its
/// species reaches at 30 years: it fades out as the tree grows.
pub(super) fn set_neighbour_tropisms(garden: &mut Garden) {
    let crowns: Vec<(Vec2, f32, f32)> = garden
        .trees
        .par_iter()
        .map(|t| {
            let crown = super::CrownStats::of(t);
            let area = std::f32::consts::PI * crown.radius_m().max(0.05).powi(2);
            (Vec2::new(t.x_m, t.z_m), area, t.tree.metrics().height_m)
        })
        .collect();
    let tropisms: Vec<glam::Vec3> = (0..garden.trees.len())
        .into_par_iter()
        .map(|i| {
            let t = &garden.trees[i];
            let expected = &t.tree.species.expected;
            let r = expected.spread_30y_m.max(0.5);
            let (base, area, height) = crowns[i];
            let mut v = Vec2::ZERO;
            for (j, &(other, other_area, _)) in crowns.iter().enumerate() {
                let d = base.distance(other);
                if j == i || d >= r || d <= 0.0 {
                    continue;
                }
                let weight = PRESSURE_AREA_WEIGHT * other_area / area
                    + PRESSURE_DISTANCE_WEIGHT * (1.0 - d / r);
                v += weight * (base - other) / d;
            }
            let v = v.clamp_length_max(1.0);
            let alpha = (height / expected.height_30y_m.max(0.5))
                .clamp(0.0, 1.0)
                .sqrt();
            glam::Vec3::new(v.x, 0.0, v.y) * (1.0 - alpha)
        })
        .collect();
    for (t, v) in garden.trees.iter_mut().zip(tropisms) {
        t.tree.environment.neighbour_tropism = v;
    }
}

/// What one iteration did to a tree's nodes, in garden space.
pub(super) struct NodeChanges {
    added: Vec<Vec3>,
    removed: Vec<Vec3>,
}

impl NodeChanges {
    /// The nodes of `t` that are not in `before` (its node ends before the iteration, garden
    /// space) and those of `before` that are gone. Growth never moves a node and keeps the
    /// survivors in arena order, so one walk matches them; should a survivor not match, every
    /// old node counts as removed and every current one as added (the same sums).
    pub(super) fn of(t: &GardenTree, before: &[Vec3]) -> NodeChanges {
        let base = t.base();
        let iteration = t.tree.iteration;
        let nodes = &t.tree.skeleton.internodes;
        let mut added = Vec::new();
        let mut removed = Vec::new();
        let mut old = before.iter();
        let mut matched = true;
        for n in nodes {
            let p = base + n.end;
            if n.born_iteration == iteration {
                added.push(p);
                continue;
            }
            loop {
                match old.next() {
                    Some(&q) if q == p => break,
                    Some(&q) => removed.push(q),
                    None => {
                        matched = false;
                        break;
                    }
                }
            }
            if !matched {
                break;
            }
        }
        if !matched {
            return NodeChanges {
                added: nodes.iter().map(|n| base + n.end).collect(),
                removed: before.to_vec(),
            };
        }
        removed.extend(old.copied());
        NodeChanges { added, removed }
    }
}

/// Adds the nodes each tree grew to, and takes those it shed from, the shadow grids of the
/// trees it is linked to.
pub(super) fn hand_on_shade(garden: &mut Garden, changes: &[Option<NodeChanges>]) {
    garden.trees.par_iter_mut().for_each(|t| {
        let base = t.base();
        for &j in &t.neighbours {
            if let Some(c) = &changes[j as usize] {
                let shadow = &mut t.tree.environment.shadow;
                shadow.apply_nodes(c.added.iter().map(|&p| p - base), 1);
                shadow.apply_nodes(c.removed.iter().map(|&p| p - base), -1);
            }
        }
    });
}

/// Each tree's shadow grid rebuilt from its own nodes and its linked neighbours'.
pub(super) fn rebuild_shade(garden: &mut Garden) {
    let ends: Vec<Vec<Vec3>> = garden.trees.par_iter().map(node_ends).collect();
    let competition = garden.competition;
    garden.trees.par_iter_mut().for_each(|t| {
        t.tree.rebuild_shadow();
        t.tree.environment.neighbour_nodes.clear();
        if !competition {
            return;
        }
        let base = t.base();
        for &j in &t.neighbours {
            if let Some(e) = ends.get(j as usize) {
                t.tree
                    .environment
                    .shadow
                    .apply_nodes(e.iter().map(|&p| p - base), 1);
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boxes_meet_within_the_margin_only() {
        let a = (Vec2::ZERO, Vec2::ONE);
        let b = (Vec2::new(2.0, 0.0), Vec2::new(3.0, 1.0));
        assert!(!boxes_meet(a, b, 0.9));
        assert!(boxes_meet(a, b, 1.0));
        assert!(boxes_meet(b, a, 1.0));
    }
}
