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
pub(crate) fn distribute(tree: &Tree, scratch: &mut Scratch) -> f32 {
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
        let (qm, ql) = (q_main[i], q_lateral[i]);
        let denominator = lambda * qm + (1.0 - lambda) * ql;
        let (vm, vl) = if denominator > 0.0 {
            let v = vigor[i];
            (
                v * lambda * qm / denominator,
                v * (1.0 - lambda) * ql / denominator,
            )
        } else {
            (0.0, 0.0)
        };
        // v_l shared among lateral elements in proportion to their Q.
        let lateral_share = if ql > 0.0 { vl / ql } else { 0.0 };
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
