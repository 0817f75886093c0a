//! Step 4 (vigor, extended Borchert–Honda) and step 7 (shedding).
//!
//! Basipetal pass (reverse loop over the topological arena): each internode collects Q_m, the
//! input of its main continuation (main child or terminal bud), and Q_l, the input of its lateral
//! buds and lateral branches. Acropetal pass (forward loop): the base receives v = Q of the whole
//! tree, and at every branching point v_m = v·λQ_m / (λQ_m + (1 − λ)Q_l) goes to the main axis and
//! v_l = v·(1 − λ)Q_l / (λQ_m + (1 − λ)Q_l) to the laterals, shared in proportion to their Q.

use super::buds::TERMINAL;
use super::{NO_NODE, Scratch, Tree};
use crate::tree::NodeId;

/// Runs both passes; returns v_max, the largest vigor of an enabled bud (0 if none). Both read
/// the compact copy of the arena's links (see [`Scratch`]) that [`super::buds::collect`] took,
/// which shedding uses too.
///
/// `every_node`: shedding follows, which reads the vigor and size of every branch. Without it
/// (a brush-guided iteration) and with few enabled buds, both passes visit only the nodes on
/// the paths from the enabled buds to the base ([`distribute_along_paths`]): every other node
/// has Q = 0 below it, so it adds exactly 0 to its parent's sums and receives vigor 0.
pub(crate) fn distribute(tree: &Tree, scratch: &mut Scratch, every_node: bool) -> f32 {
    let few_enabled = || {
        let enabled = scratch.buds.iter().filter(|b| b.enabled).count();
        enabled.saturating_mul(PATH_PASS_BUDS_PER_NODE) <= tree.skeleton.len()
    };
    if !every_node
        && few_enabled()
        && let Some(v_max) = distribute_along_paths(tree, scratch)
    {
        return v_max;
    }
    let n = tree.skeleton.len();
    let lambda = tree.species.apical_dominance_at(tree.age_years());
    let Scratch {
        buds,
        node_bud_start,
        q_main,
        q_lateral,
        vigor,
        size,
        main_child,
        lateral_range,
        lateral,
        ..
    } = scratch;
    // The basipetal pass writes every entry of these before it reads it.
    q_main.resize(n, 0.0);
    q_lateral.resize(n, 0.0);
    size.resize(n, 1);
    vigor.clear();
    vigor.resize(n, 0.0);
    // The links come from bud collection's pass (the arena has not changed since): the
    // reverse pass reads them, not the internodes.
    debug_assert_eq!(main_child.len(), n);
    debug_assert_eq!(lateral_range.len(), n);
    for i in (0..n).rev() {
        let (mut qm, mut ql) = (0.0, 0.0);
        for bud in &buds[node_bud_start[i] as usize..node_bud_start[i + 1] as usize] {
            if bud.slot == TERMINAL {
                qm += bud.q;
            } else {
                ql += bud.q;
            }
        }
        let mut s = 1;
        if main_child[i] != NO_NODE {
            let c = main_child[i] as usize;
            qm += q_main[c] + q_lateral[c];
            s += size[c];
        }
        let (start, end) = lateral_range[i];
        for &c in &lateral[start as usize..end as usize] {
            let c = c as usize;
            ql += q_main[c] + q_lateral[c];
            s += size[c];
        }
        q_main[i] = qm;
        q_lateral[i] = ql;
        size[i] = s;
    }
    if n > 0 {
        vigor[0] = q_main[0] + q_lateral[0];
    }
    let laterals = |i: usize| {
        let (start, end) = lateral_range[i];
        &lateral[start as usize..end as usize]
    };
    let mut v_max = 0.0f32;
    for i in 0..n {
        let (vm, lateral_share) = split_vigor(vigor[i], q_main[i], q_lateral[i], lambda);
        let has_main_child = main_child[i] != NO_NODE;
        if has_main_child {
            vigor[main_child[i] as usize] = vm;
        }
        for &c in laterals(i) {
            let c = c as usize;
            vigor[c] = lateral_share * (q_main[c] + q_lateral[c]);
        }
        for bud in &mut buds[node_bud_start[i] as usize..node_bud_start[i + 1] as usize] {
            bud.vigor = if bud.slot == TERMINAL {
                // The terminal bud shares v_m with nothing: a node with a bud has no main child.
                if has_main_child { 0.0 } else { vm }
            } else {
                lateral_share * bud.q
            };
            if bud.enabled {
                v_max = v_max.max(bud.vigor);
            }
        }
    }
    v_max
}

/// Enabled buds per node above which [`distribute_along_paths`] is not tried: their paths to
/// the base would cover much of the tree.
const PATH_PASS_BUDS_PER_NODE: usize = 64;

/// [`distribute`] over the nodes on the paths from the nodes with enabled buds to the base
/// only, in the same orders (descending, then ascending index) and with the same sums: a node
/// off those paths holds no enabled bud in its subtree, so its Q_m + Q_l is 0 and leaving it
/// out of a sum changes no bit (x + 0 = x for the non-negative sums here), and the vigor it
/// and its buds receive is 0 (as [`super::buds::collect`] left the buds'). Subtree sizes are
/// not computed (only shedding reads them). `None`, having changed no result, when the paths
/// cover too much of the tree for this to pay.
fn distribute_along_paths(tree: &Tree, scratch: &mut Scratch) -> Option<f32> {
    let nodes = &tree.skeleton.internodes;
    let n = nodes.len();
    if n == 0 {
        return None;
    }
    let Scratch {
        buds,
        node_bud_start,
        q_main,
        q_lateral,
        vigor,
        main_child,
        lateral_range,
        lateral,
        on_path,
        path_nodes,
        ..
    } = scratch;
    // Mark the paths: from each node with an enabled bud up to the first node already marked.
    on_path.clear();
    on_path.resize(n, false);
    path_nodes.clear();
    let limit = n / 4;
    for bud in buds.iter().filter(|b| b.enabled) {
        let mut node = Some(bud.node as usize);
        while let Some(i) = node {
            if i >= n || on_path[i] {
                break;
            }
            on_path[i] = true;
            path_nodes.push(i as u32);
            node = nodes[i].parent.map(|p| p.index());
        }
        if path_nodes.len() > limit {
            return None;
        }
    }
    path_nodes.sort_unstable();
    let lambda = tree.species.apical_dominance_at(tree.age_years());
    q_main.resize(n, 0.0);
    q_lateral.resize(n, 0.0);
    vigor.clear();
    vigor.resize(n, 0.0);
    for &i in path_nodes.iter().rev() {
        let i = i as usize;
        let (mut qm, mut ql) = (0.0, 0.0);
        for bud in &buds[node_bud_start[i] as usize..node_bud_start[i + 1] as usize] {
            if bud.slot == TERMINAL {
                qm += bud.q;
            } else {
                ql += bud.q;
            }
        }
        let c = main_child[i];
        if c != NO_NODE && on_path[c as usize] {
            qm += q_main[c as usize] + q_lateral[c as usize];
        }
        let (start, end) = lateral_range[i];
        for &c in &lateral[start as usize..end as usize] {
            let c = c as usize;
            if on_path[c] {
                ql += q_main[c] + q_lateral[c];
            }
        }
        q_main[i] = qm;
        q_lateral[i] = ql;
    }
    // The base is on every path (and there is none without an enabled bud).
    if on_path[0] {
        vigor[0] = q_main[0] + q_lateral[0];
    }
    let mut v_max = 0.0f32;
    for &i in path_nodes.iter() {
        let i = i as usize;
        let (vm, lateral_share) = split_vigor(vigor[i], q_main[i], q_lateral[i], lambda);
        let has_main_child = main_child[i] != NO_NODE;
        if has_main_child && on_path[main_child[i] as usize] {
            vigor[main_child[i] as usize] = vm;
        }
        let (start, end) = lateral_range[i];
        for &c in &lateral[start as usize..end as usize] {
            let c = c as usize;
            if on_path[c] {
                vigor[c] = lateral_share * (q_main[c] + q_lateral[c]);
            }
        }
        for bud in &mut buds[node_bud_start[i] as usize..node_bud_start[i + 1] as usize] {
            bud.vigor = if bud.slot == TERMINAL {
                if has_main_child { 0.0 } else { vm }
            } else {
                lateral_share * bud.q
            };
            if bud.enabled {
                v_max = v_max.max(bud.vigor);
            }
        }
    }
    Some(v_max)
}

/// The Borchert–Honda split of a node's vigor `v` (Pałubicki et al. 2009): the main child's share
/// v_m, and the lateral elements' share per unit of Q (v_l / Q_l, so each lateral element gets
/// that times its own Q).
#[inline]
fn split_vigor(v: f32, qm: f32, ql: f32, lambda: f32) -> (f32, f32) {
    let denominator = lambda * qm + (1.0 - lambda) * ql;
    let (vm, vl) = if denominator > 0.0 {
        (
            v * lambda * qm / denominator,
            v * (1.0 - lambda) * ql / denominator,
        )
    } else {
        (0.0, 0.0)
    };
    (vm, if ql > 0.0 { vl / ql } else { 0.0 })
}

/// Step 7: lateral branches (born before this iteration) whose vigor per internode, with vigor in
/// new internodes (v·n_max/v_max), is below Th.
pub(crate) fn select_shed(tree: &Tree, scratch: &mut Scratch, v_max: f32) -> Vec<NodeId> {
    let threshold = tree.species.shedding_threshold;
    if threshold <= 0.0 || v_max <= 0.0 {
        return Vec::new();
    }
    let scale = super::shoots::max_shoot_internodes(tree) / v_max;
    // Every lateral child of every node, in node order.
    scratch
        .lateral_range
        .iter()
        .flat_map(|&(start, end)| &scratch.lateral[start as usize..end as usize])
        .map(|&c| c as usize)
        .filter(|&c| {
            let ratio = scratch.vigor[c] * scale / scratch.size[c] as f32;
            ratio < threshold && scratch.in_mask[c]
        })
        .map(|c| NodeId(c as u32))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::growth::{StepOptions, buds, light, space, timing};
    use crate::species::Species;

    #[test]
    fn the_pass_along_the_enabled_buds_paths_gives_every_bud_the_vigor_of_the_whole_pass() {
        let species = Species::by_name("maple").expect("maple preset");
        let mut tree = Tree::new(species, 4);
        tree.grow(8, None);
        // A brush dab at the highest tip: a few buds near it win points.
        let perception = space::radii(&tree).1;
        let top = tree
            .skeleton
            .internodes
            .iter()
            .map(|n| n.end)
            .max_by(|a, b| a.y.total_cmp(&b.y))
            .expect("a tree has internodes");
        let mut rng = crate::rng::Rng::new(2);
        for _ in 0..40 {
            tree.environment
                .attraction
                .add_persistent(top + rng.in_unit_ball() * perception);
        }
        tree.iteration += 1;
        let mut scratch = Scratch::default();
        let options = StepOptions {
            autonomous: false,
            scene: None,
        };
        buds::collect(&mut tree, &mut scratch);
        let mut clock = timing::PhaseClock::start();
        space::colonize(&mut tree, &mut scratch, options, &mut clock);
        let enabled = light::bud_input(&tree, &mut scratch);
        assert!(enabled > 0, "no bud enabled");
        let mut along = scratch.buds.clone();
        let v_along = distribute_along_paths(&tree, &mut scratch).expect("the paths pass runs");
        std::mem::swap(&mut along, &mut scratch.buds);
        let v_all = distribute(&tree, &mut scratch, true);
        assert_eq!(v_along.to_bits(), v_all.to_bits());
        assert!(v_all > 0.0);
        for (a, b) in along.iter().zip(&scratch.buds) {
            assert_eq!(
                a.vigor.to_bits(),
                b.vigor.to_bits(),
                "bud of node {}",
                a.node
            );
        }
    }
}
