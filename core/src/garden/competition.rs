//! How the trees of a garden reach each other's environment.
//!
//! **Links.** Tree j reaches tree i once j's crown (the horizontal box of its nodes) comes
//! within i's reach: i's own box grown by the furthest a shadow pyramid spreads sideways in i's
//! grid, i's perception radius and the longest shoot one iteration can add. Nothing of a tree
//! outside that reach can shade a bud of i or occupy the space a bud of i perceives, so leaving
//! it out changes nothing. Once linked a pair stays linked (the links are saved with the garden),
//! so a neighbour's shade never flickers in and out.
//!
//! **Shade.** When j is linked to i, the nodes of j within i's shade cover (module `shade`: the
//! cells around i's own nodes) cast their pyramids into i's shadow grid (in i's space); after
//! each round the nodes j grew there are added and those it shed taken away, and the cells i's
//! new nodes open take in the neighbours' nodes already standing in them (found through the
//! neighbours' node indexes, module `index`). Integer sums: at every node of i the grid reads
//! exactly i's own shade plus that of all its linked neighbours' current nodes, whatever the
//! order.
//!
//! **Space.** Before each round a tree due to grow gets, as occupied space in its own space, the
//! nodes of its linked neighbours close enough to take an attraction point from it.

use glam::{IVec3, Vec2, Vec3};
use rayon::prelude::*;

use super::cell_hash::CellBits;
use super::index::{CellSet, NodeIndex};
use super::shade::ShadeCover;
use super::{Garden, GardenTree};
use crate::environment::floor_to_ivec3;

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

/// Links every pair that has come within reach and hands the newly linked neighbour's shade
/// to the tree it reaches (the part its cover holds: module `shade`).
pub(super) fn link_neighbours(garden: &mut Garden) {
    garden
        .trees
        .par_iter_mut()
        .filter(|t| !t.shade_cover.is_made())
        .for_each(|t| t.shade_cover = ShadeCover::of(&t.tree));
    let boxes: Vec<(Vec2, Vec2)> = garden
        .trees
        .par_iter_mut()
        .map(|t| {
            t.cache.kept_crown_box().unwrap_or_else(|| {
                let b = crown_box(t);
                t.cache.keep_crown_box(b);
                b
            })
        })
        .collect();
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
            let cover = &t.shade_cover;
            for &j in &links {
                if let Some(ends) = &ends[j as usize] {
                    t.tree.environment.shadow.apply_nodes(
                        ends.iter().map(|&p| p - base).filter(|&p| cover.covers(p)),
                        1,
                    );
                }
            }
            t.neighbours.extend(links);
            t.neighbours.sort_unstable();
        });
}

/// Cells of `size` metres holding, or next to one holding, a place where tree `t` (its own
/// space) can take attraction points this iteration: its nodes with a living bud and its
/// persistent points. Returns the cells that hold such a place (each once) and the set of
/// those cells each with the 26 around it, so that a neighbour's node needs one look-up.
fn contact_cells(t: &GardenTree, size: f32) -> (Vec<IVec3>, CellBits) {
    let cell = |p: Vec3| (p / size).floor().as_ivec3();
    let tree = &t.tree;
    let buds = tree.skeleton.internodes.iter().filter(|n| {
        n.terminal_bud.as_ref().is_some_and(|b| b.alive) || n.lateral_buds.iter().any(|b| b.alive)
    });
    let places: Vec<IVec3> = buds
        .map(|n| cell(n.end))
        .chain(
            tree.environment
                .attraction
                .points
                .iter()
                .map(|p| cell(p.position)),
        )
        .collect();
    let (lo, hi) = places.iter().fold(
        (IVec3::splat(i32::MAX), IVec3::splat(i32::MIN)),
        |(lo, hi), &c| (lo.min(c), hi.max(c)),
    );
    let mut own = CellBits::with_box(lo, hi);
    let mut cells =
        CellBits::with_box(lo.saturating_sub(IVec3::ONE), hi.saturating_add(IVec3::ONE));
    let mut each = Vec::new();
    for c in places {
        if !own.insert(c) {
            continue;
        }
        each.push(c);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    cells.insert(c.saturating_add(IVec3::new(dx, dy, dz)));
                }
            }
        }
    }
    (each, cells)
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
            let (places, cells) = contact_cells(t, size);
            let base = t.base();
            // The index cells the 27 cells around each place touch (a superset of those
            // holding a node in `cells`: each node is tested below).
            let mut asked = CellSet::default();
            for c in places {
                let lo = c.saturating_sub(IVec3::ONE).as_vec3();
                let hi = c.saturating_add(IVec3::splat(2)).as_vec3();
                asked.add_box(base + lo * size, base + hi * size);
            }
            let mut nodes = Vec::new();
            for &j in &t.neighbours {
                let n = &garden.trees[j as usize];
                let offset = n.base() - base;
                n.node_index.for_each_in(&asked, |end| {
                    let p = end + offset;
                    if cells.contains(floor_to_ivec3(p / size)) {
                        nodes.push(p);
                    }
                });
            }
            nodes
        })
        .collect();
    for (t, nodes) in garden.trees.iter_mut().zip(gathered) {
        t.tree.environment.neighbour_nodes = nodes;
    }
}

/// Gives tree `index` (to be edited) every node of its linked neighbours, in its own space, as
/// occupied space: a superset of what [`gather_neighbour_nodes`] gives (growth keeps only the
/// nodes within the occupancy radius of a point, so the extra ones take nothing), kept between
/// edits while the neighbours stand as they were (module `cache`).
pub(super) fn give_all_neighbour_nodes(garden: &mut Garden, index: usize) {
    let t = &garden.trees[index];
    let versions: Vec<(u32, u64)> = t
        .neighbours
        .iter()
        .map(|&j| (j, garden.trees[j as usize].cache.version))
        .collect();
    let fresh = versions.iter().all(|&(_, v)| v != 0)
        && t.cache
            .neighbour_nodes
            .as_ref()
            .is_some_and(|(kept, _)| *kept == versions);
    if !fresh {
        let base = t.base();
        let nodes: Vec<Vec3> = t
            .neighbours
            .iter()
            .flat_map(|&j| node_ends(&garden.trees[j as usize]))
            .map(|p| p - base)
            .collect();
        garden.trees[index].cache.neighbour_nodes = Some((versions, nodes));
    }
    let t = &mut garden.trees[index];
    let nodes = t.cache.neighbour_nodes.as_ref().map(|(_, n)| n.as_slice());
    t.tree.environment.neighbour_nodes.clear();
    t.tree
        .environment
        .neighbour_nodes
        .extend_from_slice(nodes.unwrap_or_default());
}

/// Indexes anew the nodes of the trees marked `changed` and of any tree without an index.
pub(super) fn index_nodes(garden: &mut Garden, changed: &[bool]) {
    garden
        .trees
        .par_iter_mut()
        .zip(changed)
        .filter(|(t, c)| **c || !t.node_index.built)
        .for_each(|(t, _)| {
            t.node_index =
                NodeIndex::of(t.base(), t.tree.skeleton.internodes.iter().map(|n| n.end));
        });
}

/// [`crate::Tree::metrics`]'s `height_m`, the same bits, without its other measures: the
/// highest node end above the first internode's start.
fn tree_height_m(tree: &crate::Tree) -> f32 {
    let nodes = &tree.skeleton.internodes;
    let base_y = nodes.first().map_or(0.0, |n| n.start.y);
    // As glam's `Vec3::max` takes it (a NaN end replaces the highest so far).
    nodes
        .iter()
        .fold(base_y, |hi, n| if hi > n.end.y { hi } else { n.end.y })
        - base_y
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
///
/// Only the trees that are `due` get theirs (the others do not grow before they are due again);
/// only their crowns and those of the trees within their r are measured.
pub(super) fn set_neighbour_tropisms(garden: &mut Garden, due: &[bool]) {
    let bases: Vec<Vec2> = garden
        .trees
        .iter()
        .map(|t| Vec2::new(t.x_m, t.z_m))
        .collect();
    let reach = |t: &GardenTree| t.tree.species.expected.spread_30y_m.max(0.5);
    let needed: Vec<bool> = (0..garden.trees.len())
        .into_par_iter()
        .map(|j| {
            due[j]
                || (0..bases.len())
                    .any(|i| due[i] && bases[i].distance(bases[j]) < reach(&garden.trees[i]))
        })
        .collect();
    let areas: Vec<f32> = garden
        .trees
        .par_iter_mut()
        .zip(&needed)
        .map(|(t, &needed)| {
            if !needed {
                return 0.0;
            }
            t.cache.kept_crown_area_m2().unwrap_or_else(|| {
                let radius = super::CrownStats::radius_only_m(t);
                let area = std::f32::consts::PI * radius.max(0.05).powi(2);
                t.cache.keep_crown_area_m2(area);
                area
            })
        })
        .collect();
    let tropisms: Vec<Option<glam::Vec3>> = (0..garden.trees.len())
        .into_par_iter()
        .map(|i| {
            if !due[i] {
                return None;
            }
            let t = &garden.trees[i];
            let expected = &t.tree.species.expected;
            let r = reach(t);
            let (base, area) = (bases[i], areas[i]);
            let mut v = Vec2::ZERO;
            for (j, (&other, &other_area)) in bases.iter().zip(&areas).enumerate() {
                let d = base.distance(other);
                if j == i || d >= r || d <= 0.0 {
                    continue;
                }
                let weight = PRESSURE_AREA_WEIGHT * other_area / area
                    + PRESSURE_DISTANCE_WEIGHT * (1.0 - d / r);
                v += weight * (base - other) / d;
            }
            let v = v.clamp_length_max(1.0);
            let height = tree_height_m(&t.tree);
            let alpha = (height / expected.height_30y_m.max(0.5))
                .clamp(0.0, 1.0)
                .sqrt();
            Some(glam::Vec3::new(v.x, 0.0, v.y) * (1.0 - alpha))
        })
        .collect();
    for (t, v) in garden.trees.iter_mut().zip(tropisms) {
        if let Some(v) = v {
            t.tree.environment.neighbour_tropism = v;
        }
    }
}

/// What one iteration (or an edit) did to a tree's nodes.
pub(super) struct NodeChanges {
    /// Garden space.
    added: Vec<Vec3>,
    removed: Vec<Vec3>,
    /// The added nodes in the tree's own space (as its grid reads them).
    added_in_tree: Vec<Vec3>,
    /// The boxes of `added` and of `removed` (lo above hi when empty).
    added_box: (Vec3, Vec3),
    removed_box: (Vec3, Vec3),
}

/// The box of the finite `points` (lo above hi when there are none; a point that is not
/// finite casts no shade, so it takes no part).
fn box_of(points: &[Vec3]) -> (Vec3, Vec3) {
    points
        .iter()
        .filter(|p| p.is_finite())
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        })
}

impl NodeChanges {
    /// The nodes of `t` that are not in `before` (its node ends, garden space, when it stood
    /// at iteration `before_iteration`: before a round's iteration or an edit) and those of
    /// `before` that are gone. A node born after `before_iteration` is new; growth never
    /// moves a node and keeps the survivors in arena order, so one walk matches the others;
    /// should one not match (a tree replaced, say by an undo), every old node counts as
    /// removed and every current one as added (the same sums).
    pub(super) fn of(t: &GardenTree, before: &[Vec3], before_iteration: u32) -> NodeChanges {
        let base = t.base();
        let nodes = &t.tree.skeleton.internodes;
        let mut added = Vec::new();
        let mut added_in_tree = Vec::new();
        let mut removed = Vec::new();
        let mut old = before.iter();
        let mut matched = true;
        for n in nodes {
            let p = base + n.end;
            if n.born_iteration > before_iteration {
                added.push(p);
                added_in_tree.push(n.end);
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
            (added, removed, added_in_tree) = (
                nodes.iter().map(|n| base + n.end).collect(),
                before.to_vec(),
                nodes.iter().map(|n| n.end).collect(),
            );
        } else {
            removed.extend(old.copied());
        }
        NodeChanges {
            added_box: box_of(&added),
            removed_box: box_of(&removed),
            added,
            removed,
            added_in_tree,
        }
    }
}

/// Adds the nodes each tree grew to, and takes those it shed from, the shadow grids of the
/// trees it is linked to (where their covers hold neighbours' shade); then each tree whose new
/// nodes opened new cells of its cover takes in the shade its neighbours' nodes cast there.
pub(super) fn hand_on_shade(garden: &mut Garden, changes: &[Option<NodeChanges>]) {
    let opens: Vec<bool> = garden
        .trees
        .par_iter()
        .zip(changes)
        .map(|(t, c)| {
            let cover = &t.shade_cover;
            !cover.everywhere
                && c.as_ref()
                    .is_some_and(|c| c.added_in_tree.iter().any(|&p| cover.opens(p)))
        })
        .collect();
    let indexes: Vec<NodeIndex> = garden
        .trees
        .iter_mut()
        .map(|t| std::mem::take(&mut t.node_index))
        .collect();
    let bases: Vec<Vec3> = garden.trees.iter().map(GardenTree::base).collect();
    garden
        .trees
        .par_iter_mut()
        .zip(changes)
        .zip(opens)
        .for_each(|((t, own), opens)| {
            let base = t.base();
            let (shadow, cover) = (&mut t.tree.environment.shadow, &mut t.shade_cover);
            // Every neighbour's added nodes in one cast and its shed ones in another (integer
            // sums: the same grid as neighbour by neighbour, but sorted into brick order
            // together, so pyramids of different neighbours in the same bricks share them).
            let (mut cast, mut uncast) = (Vec::new(), Vec::new());
            for &j in &t.neighbours {
                if let Some(c) = &changes[j as usize] {
                    let near = |p: &Vec3| cover.covers(*p);
                    let meets = |(lo, hi): (Vec3, Vec3)| cover.may_cover_box(lo - base, hi - base);
                    if meets(c.added_box) {
                        cast.extend(c.added.iter().map(|&p| p - base).filter(near));
                    }
                    if meets(c.removed_box) {
                        uncast.extend(c.removed.iter().map(|&p| p - base).filter(near));
                    }
                }
            }
            shadow.apply_nodes(uncast, -1);
            let new = own
                .as_ref()
                .map(|own| cover.extend(own.added_in_tree.iter().copied()));
            if let Some(new) = new.filter(|new| opens && !new.is_empty()) {
                // The neighbours' nodes already standing in the cells just opened (none of
                // them is in `cast`, which holds only nodes of cells covered before).
                let mut asked = CellSet::default();
                for c in new.iter() {
                    let (lo, hi) = cover.cell_box(c);
                    asked.add_box(base + lo, base + hi);
                }
                for &j in &t.neighbours {
                    let other = bases[j as usize];
                    indexes[j as usize].for_each_in(&asked, |end| {
                        let p = (other + end) - base;
                        if cover.in_cells(&new, p) {
                            cast.push(p);
                        }
                    });
                }
            }
            shadow.apply_nodes(cast, 1);
        });
    for (t, index) in garden.trees.iter_mut().zip(indexes) {
        t.node_index = index;
    }
}

/// Makes the grid of tree `index` hold every linked neighbour's shade, wherever it falls (an
/// edited tree may grow anywhere): the neighbours' nodes outside its cover are cast.
pub(super) fn set_shade_everywhere(garden: &mut Garden, index: usize) {
    let t = &garden.trees[index];
    if t.shade_cover.everywhere {
        return;
    }
    let base = t.base();
    let outside: Vec<Vec3> = t
        .neighbours
        .iter()
        .flat_map(|&j| node_ends(&garden.trees[j as usize]))
        .map(|p| p - base)
        .filter(|&p| !t.shade_cover.covers(p))
        .collect();
    let t = &mut garden.trees[index];
    apply_nodes_by_voxel(&mut t.tree.environment.shadow, outside, 1);
    t.shade_cover.everywhere = true;
}

/// The most nodes of one voxel cast as one pyramid of `sign` times their number: a level's Δs
/// is at most 2^16 times a species' shadow strength (at most 10^3, its decay base above 1),
/// so 32 of them stay within i32.
const MAX_NODES_PER_CAST: usize = 32;

/// [`crate::environment::ShadowGrid::apply_nodes`] of `nodes` (this grid's space) with
/// `sign`, the same grid bit for bit, for a fraction of the pyramids: a node's pyramid is
/// that of its voxel, so the n nodes sharing a voxel cast one pyramid of n times the sign
/// (integer sums). Nodes that are not finite cast nothing, as in the grid.
fn apply_nodes_by_voxel(shadow: &mut crate::environment::ShadowGrid, nodes: Vec<Vec3>, sign: i32) {
    let size = shadow.voxel_size();
    let mut keyed: Vec<(IVec3, Vec3)> = nodes
        .into_iter()
        .filter(|p| p.is_finite())
        .map(|p| (floor_to_ivec3(p / size), p))
        .collect();
    keyed.sort_unstable_by_key(|&(v, _)| (v.x, v.y, v.z));
    // by_count[n - 1]: one node of each voxel holding n of them (n up to the cap).
    let mut by_count: Vec<Vec<Vec3>> = Vec::new();
    for run in keyed.chunk_by(|a, b| a.0 == b.0) {
        for part in run.chunks(MAX_NODES_PER_CAST) {
            if by_count.len() < part.len() {
                by_count.resize_with(part.len(), Vec::new);
            }
            by_count[part.len() - 1].push(part[0].1);
        }
    }
    for (n, points) in (1..).zip(by_count) {
        if !points.is_empty() {
            shadow.apply_nodes(points, sign * n);
        }
    }
}

/// Each tree's shadow grid rebuilt from its own nodes and its linked neighbours' (those its
/// cover, made anew from its nodes, holds).
pub(super) fn rebuild_shade(garden: &mut Garden) {
    let ends: Vec<Vec<Vec3>> = garden.trees.par_iter().map(node_ends).collect();
    let competition = garden.competition;
    garden.trees.par_iter_mut().for_each(|t| {
        t.cache.changed();
        t.tree.rebuild_shadow();
        t.tree.environment.neighbour_nodes.clear();
        t.shade_cover = ShadeCover::of(&t.tree);
        t.node_index = NodeIndex::default();
        if !competition {
            return;
        }
        let base = t.base();
        let cover = &t.shade_cover;
        for &j in &t.neighbours {
            if let Some(e) = ends.get(j as usize) {
                t.tree
                    .environment
                    .shadow
                    .apply_nodes(e.iter().map(|&p| p - base).filter(|&p| cover.covers(p)), 1);
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A brush dab beside the crown and a year: an edit that grows both towards persistent
    /// points and autonomously.
    fn dab_and_grow(tree: &mut crate::Tree) {
        let m = tree.metrics();
        let centre = Vec3::new(0.5 * m.crown_width_m.max(0.5), m.height_m * 0.8, 0.0);
        let mut rng = crate::Rng::new(5);
        for _ in 0..200 {
            tree.environment
                .attraction
                .add_persistent(centre + rng.in_unit_ball() * 0.5);
        }
        for _ in 0..2 {
            tree.step(crate::growth::StepOptions {
                autonomous: false,
                scene: None,
            });
        }
        tree.grow_years(1.0);
    }

    #[test]
    fn an_edit_given_all_the_neighbours_nodes_grows_as_with_only_those_that_can_take_a_point() {
        let species = |name: &str| crate::species::Species::by_name(name).expect("preset");
        let planted = vec![
            crate::garden::PlantedTree::new(species("birch"), 0.0, 0.0, 0.0, 1),
            crate::garden::PlantedTree::new(species("maple"), 1.6, 0.0, 0.0, 2),
            crate::garden::PlantedTree::new(species("oak"), -1.4, 0.8, 0.0, 3),
        ];
        let mut garden = Garden::plant(planted).expect("plants");
        garden.grow_years(6.0);
        for edited in 0..3 {
            let mut exact = garden.clone();
            let mut due = vec![false; 3];
            due[edited] = true;
            link_neighbours(&mut exact);
            gather_neighbour_nodes(&mut exact, &due);
            set_neighbour_tropisms(&mut exact, &due);
            set_shade_everywhere(&mut exact, edited);
            assert!(
                !exact.trees[edited]
                    .tree
                    .environment
                    .neighbour_nodes
                    .is_empty()
            );
            dab_and_grow(&mut exact.trees[edited].tree);
            let mut all = garden.clone();
            all.edit_tree(edited, dab_and_grow);
            assert!(
                all.trees[edited].tree.environment.neighbour_nodes.len()
                    >= exact.trees[edited].tree.environment.neighbour_nodes.len()
            );
            assert_eq!(
                exact.trees[edited].tree.to_json_bytes().expect("saves"),
                all.trees[edited].tree.to_json_bytes().expect("saves"),
                "tree {edited} grew otherwise"
            );
        }
    }

    #[test]
    fn the_lean_crown_measures_are_those_of_the_full_ones() {
        let species = |name: &str| crate::species::Species::by_name(name).expect("preset");
        let planted = vec![
            crate::garden::PlantedTree::new(species("birch"), 0.0, 0.0, 0.0, 1),
            crate::garden::PlantedTree::new(species("norway_spruce"), 1.6, -2.3, 0.0, 2),
            crate::garden::PlantedTree::new(species("oak"), -1.4, 0.8, 0.0, 3),
        ];
        let mut garden = Garden::plant(planted).expect("plants");
        for years in [0.0, 1.0, 4.0] {
            garden.grow_years(years);
            for t in &garden.trees {
                let full = super::super::CrownStats::of(t).radius_m();
                let lean = super::super::CrownStats::radius_only_m(t);
                assert_eq!(full.to_bits(), lean.to_bits());
                let height = t.tree.metrics().height_m;
                assert_eq!(height.to_bits(), tree_height_m(&t.tree).to_bits());
            }
        }
    }

    #[test]
    fn the_changes_of_an_edit_of_several_iterations_are_its_new_and_shed_nodes_only() {
        let species = crate::species::Species::by_name("birch").expect("preset");
        let planted = vec![crate::garden::PlantedTree::new(species, 0.0, 0.0, 3.0, 1)];
        let mut garden = Garden::plant(planted).expect("plants");
        let t = &mut garden.trees[0];
        let (before, k) = (node_ends(t), t.tree.iteration);
        let unchanged = NodeChanges::of(t, &before, k);
        assert!(unchanged.added.is_empty() && unchanged.removed.is_empty());
        t.tree.grow(3, None);
        let grown = NodeChanges::of(t, &before, k);
        let born = t
            .tree
            .skeleton
            .internodes
            .iter()
            .filter(|n| n.born_iteration > k)
            .count();
        assert!(born > 0);
        assert_eq!(grown.added.len(), born);
        assert_eq!(grown.added_in_tree.len(), born);
        // What was shed in those iterations (the survivors all matched).
        assert_eq!(
            before.len() - grown.removed.len() + grown.added.len(),
            t.tree.skeleton.len()
        );
        let mut left: Vec<[u32; 3]> = before
            .iter()
            .filter(|p| !grown.removed.contains(p))
            .chain(&grown.added)
            .map(|p| p.to_array().map(f32::to_bits))
            .collect();
        let mut now: Vec<[u32; 3]> = node_ends(t)
            .iter()
            .map(|p| p.to_array().map(f32::to_bits))
            .collect();
        left.sort_unstable();
        now.sort_unstable();
        assert_eq!(left, now);
    }

    #[test]
    fn casting_by_voxel_makes_the_grid_of_casting_node_by_node() {
        let mut by_node = crate::environment::ShadowGrid::new(0.1, 1.0, 1.5, 6);
        let voxel = by_node.voxel_size();
        let mut rng = crate::Rng::new(3);
        // Many nodes sharing voxels (up to 80 in one, beyond one cast's cap), a few alone, and
        // some that cast nothing (not finite, or beyond the grid's reach).
        let mut nodes = Vec::new();
        for k in 0..40 {
            let centre = rng.in_unit_ball() * 2.0 + Vec3::Y * 3.0;
            for _ in 0..(k * 2 + 1) {
                nodes.push(centre + rng.in_unit_ball() * 0.3 * voxel);
            }
        }
        nodes.extend([Vec3::NAN, Vec3::splat(f32::INFINITY), Vec3::X * 1e6]);
        let mut by_voxel = by_node.clone();
        by_node.apply_nodes(nodes.iter().copied(), 1);
        apply_nodes_by_voxel(&mut by_voxel, nodes.clone(), 1);
        assert_eq!(by_node.num_voxels(), by_voxel.num_voxels());
        let mut sampled = 0;
        for x in -40..40 {
            for y in -10..70 {
                for z in -40..40 {
                    let p = (Vec3::new(x as f32, y as f32, z as f32) + 0.5) * voxel;
                    let (a, b) = (by_node.shadow_at(p), by_voxel.shadow_at(p));
                    assert_eq!(a.to_bits(), b.to_bits(), "at {p}");
                    sampled += usize::from(a != 0.0);
                }
            }
        }
        assert!(sampled > 1000);
        // Taken away the same way, nothing is left.
        apply_nodes_by_voxel(&mut by_voxel, nodes, -1);
        assert!(by_voxel.is_clear());
    }

    #[test]
    fn a_first_edit_grows_as_with_every_neighbour_cast_node_by_node() {
        let species = |name: &str| crate::species::Species::by_name(name).expect("preset");
        let planted = vec![
            crate::garden::PlantedTree::new(species("weeping_willow"), 0.0, 0.0, 0.0, 1),
            crate::garden::PlantedTree::new(species("maple"), 1.6, 0.0, 0.0, 2),
            crate::garden::PlantedTree::new(species("oak"), -1.4, 0.8, 0.0, 3),
        ];
        let mut garden = Garden::plant(planted).expect("plants");
        garden.grow_years(6.0);
        for edited in 0..3 {
            let mut plain = garden.clone();
            link_neighbours(&mut plain);
            let t = &plain.trees[edited];
            let base = t.base();
            let outside: Vec<Vec3> = t
                .neighbours
                .iter()
                .flat_map(|&j| node_ends(&plain.trees[j as usize]))
                .map(|p| p - base)
                .filter(|&p| !t.shade_cover.covers(p))
                .collect();
            assert!(!outside.is_empty());
            let t = &mut plain.trees[edited];
            t.tree.environment.shadow.apply_nodes(outside, 1);
            t.shade_cover.everywhere = true;
            plain.edit_tree(edited, dab_and_grow);
            let mut voxels = garden.clone();
            voxels.edit_tree(edited, dab_and_grow);
            assert_eq!(
                plain.trees[edited].tree.to_json_bytes().expect("saves"),
                voxels.trees[edited].tree.to_json_bytes().expect("saves"),
                "tree {edited} grew otherwise"
            );
        }
    }

    #[test]
    fn boxes_meet_within_the_margin_only() {
        let a = (Vec2::ZERO, Vec2::ONE);
        let b = (Vec2::new(2.0, 0.0), Vec2::new(3.0, 1.0));
        assert!(!boxes_meet(a, b, 0.9));
        assert!(boxes_meet(a, b, 1.0));
        assert!(boxes_meet(b, a, 1.0));
    }
}
