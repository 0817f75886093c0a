//! Step 4 (vigor, extended Borchert–Honda) and step 7 (shedding).
//!
//! Basipetal pass (reverse loop over the topological arena): each internode collects Q_m, the
//! input of its main continuation (main child or terminal bud), and Q_l, the input of its lateral
//! buds and lateral branches. Acropetal pass (forward loop): the base receives v = Q of the whole
//! tree, and at every branching point v_m = v·λQ_m / (λQ_m + (1 − λ)Q_l) goes to the main axis and
//! v_l = v·(1 − λ)Q_l / (λQ_m + (1 − λ)Q_l) to the laterals, shared in proportion to their Q.

use super::buds::TERMINAL;
use super::{Scratch, Tree};
use crate::tree::NodeId;

/// Runs both passes; returns v_max, the largest vigor of an enabled bud (0 if none).
pub(crate) fn distribute(tree: &Tree, scratch: &mut Scratch) -> f32 {
    let nodes = &tree.skeleton.internodes;
    let n = nodes.len();
    let lambda = tree.species.apical_dominance;
    let Scratch {
        buds,
        node_bud_start,
        q_main,
        q_lateral,
        vigor,
        size,
        ..
    } = scratch;
    q_main.clear();
    q_main.resize(n, 0.0);
    q_lateral.clear();
    q_lateral.resize(n, 0.0);
    vigor.clear();
    vigor.resize(n, 0.0);
    size.clear();
    size.resize(n, 1);
    for i in (0..n).rev() {
        let node = &nodes[i];
        let (mut qm, mut ql) = (0.0, 0.0);
        for bud in &buds[node_bud_start[i] as usize..node_bud_start[i + 1] as usize] {
            if bud.slot == TERMINAL {
                qm += bud.q;
            } else {
                ql += bud.q;
            }
        }
        let mut s = 1;
        if let Some(c) = node.main_child {
            qm += q_main[c.index()] + q_lateral[c.index()];
            s += size[c.index()];
        }
        for c in &node.lateral_children {
            ql += q_main[c.index()] + q_lateral[c.index()];
            s += size[c.index()];
        }
        q_main[i] = qm;
        q_lateral[i] = ql;
        size[i] = s;
    }
    if n > 0 {
        vigor[0] = q_main[0] + q_lateral[0];
    }
    let mut v_max = 0.0f32;
    for i in 0..n {
        let node = &nodes[i];
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
        if let Some(c) = node.main_child {
            vigor[c.index()] = vm;
        }
        for c in &node.lateral_children {
            vigor[c.index()] = lateral_share * (q_main[c.index()] + q_lateral[c.index()]);
        }
        for bud in &mut buds[node_bud_start[i] as usize..node_bud_start[i + 1] as usize] {
            bud.vigor = if bud.slot == TERMINAL {
                // The terminal bud shares v_m with nothing: a node with a bud has no main child.
                if node.main_child.is_some() { 0.0 } else { vm }
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
    let mut shed = Vec::new();
    let nodes = &tree.skeleton.internodes;
    for node in nodes {
        for &c in &node.lateral_children {
            let ratio = scratch.vigor[c.index()] * scale / scratch.size[c.index()] as f32;
            if ratio < threshold && scratch.in_mask[c.index()] {
                shed.push(c);
            }
        }
    }
    shed
}
