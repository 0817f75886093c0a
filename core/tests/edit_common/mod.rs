//! Synthetic skeletons with known geometry for the edit tests.
#![allow(dead_code)]

use glam::Vec3;
use sylva_core::tree::{Bud, Children, Internode, NodeId, Skeleton};

/// A fresh internode from `start` to `end` with a terminal bud and no children.
pub fn internode(parent: Option<NodeId>, start: Vec3, end: Vec3, diameter: f32) -> Internode {
    let heading = (end - start).normalize();
    Internode {
        parent,
        main_child: None,
        lateral_children: Children::new(),
        start,
        end,
        left: heading.any_orthonormal_vector(),
        diameter,
        order: 0,
        born_iteration: 0,
        terminal_bud: Some(Bud::new(heading)),
        lateral_buds: std::iter::once(Bud::new(heading.any_orthonormal_vector())).collect(),
        width_constraint: None,
        light_exposure: 1.0,
    }
}

/// Appends `node` as the main child or a lateral of its parent; returns its id.
pub fn push(skeleton: &mut Skeleton, node: Internode, lateral: bool) -> NodeId {
    let id = NodeId(skeleton.internodes.len() as u32);
    if let Some(p) = node.parent {
        let parent = &mut skeleton.internodes[p.index()];
        if lateral {
            parent.lateral_children.push(id);
        } else {
            parent.main_child = Some(id);
            parent.terminal_bud = None;
        }
    }
    skeleton.internodes.push(node);
    id
}

/// A straight vertical trunk of `n` internodes of `length` m; diameters from `diameter(k)`;
/// every `branch_every`-th internode carries a 3-internode horizontal side branch.
pub fn trunk_with_branches(
    n: usize,
    length: f32,
    diameter: impl Fn(usize) -> f32,
    branch_every: usize,
) -> (Skeleton, Vec<NodeId>) {
    let mut skeleton = Skeleton {
        internodes: Vec::new(),
    };
    let mut trunk = Vec::new();
    let mut parent = None;
    for k in 0..n {
        let start = Vec3::Y * (k as f32 * length);
        let node = internode(parent, start, start + Vec3::Y * length, diameter(k));
        let id = push(&mut skeleton, node, false);
        trunk.push(id);
        parent = Some(id);
    }
    if branch_every > 0 {
        for &k in trunk.iter().step_by(branch_every) {
            let mut at = skeleton.get(k).end;
            let mut p = k;
            let d = skeleton.get(k).diameter * 0.5;
            for j in 0..3 {
                let node = internode(Some(p), at, at + Vec3::X * length, d);
                p = push(&mut skeleton, node, j == 0);
                at += Vec3::X * length;
            }
        }
    }
    (skeleton, trunk)
}

/// Largest distance between corresponding internode end points of two skeletons.
pub fn max_displacement(a: &Skeleton, b: &Skeleton) -> f32 {
    a.internodes
        .iter()
        .zip(&b.internodes)
        .map(|(x, y)| x.start.distance(y.start).max(x.end.distance(y.end)))
        .fold(0.0, f32::max)
}
