//! TEMPORARY STAND-INS for parts other issues deliver, used only until they land:
//! - [`standin_skeleton`]: a procedurally branched skeleton standing in for `sylva_core`'s growth;
//! - [`standin_tree_mesh`]: simple tubes and leaf quads standing in for `sylva_core::geometry`.
//!
//! Each is replaced by the real module as it lands; nothing here is part of the product.

use glam::{Quat, Vec3};
use sylva_core::{Internode, NodeId, Rng, Skeleton};

use crate::render::{LitMesh, LitVertex, TreeMesh};

/// A branched skeleton of `depth` levels, deterministic in `seed`.
pub fn standin_skeleton(seed: u64, depth: u32) -> Skeleton {
    let mut rng = Rng::new(seed);
    let mut internodes: Vec<Internode> = Vec::new();
    // (parent, start, direction, order, remaining internodes on this axis, level)
    let mut queue = std::collections::VecDeque::new();
    queue.push_back((
        None::<NodeId>,
        Vec3::ZERO,
        Vec3::Y,
        0u32,
        6u32 + depth,
        0u32,
    ));
    while let Some((parent, start, direction, order, remaining, level)) = queue.pop_front() {
        let length = 0.16 / (1.0 + order as f32 * 0.6);
        let bend = Quat::from_axis_angle(rng.unit_vector(), rng.range_f32(0.0, 0.18));
        let heading = (bend * direction + Vec3::Y * 0.08).normalize();
        let id = NodeId(internodes.len() as u32);
        let left = heading.any_orthonormal_vector();
        internodes.push(Internode {
            parent,
            main_child: None,
            lateral_children: Vec::new(),
            start,
            end: start + heading * length,
            left,
            diameter: 0.0,
            order,
            born_iteration: level,
            terminal_bud: None,
            lateral_buds: Vec::new(),
            width_constraint: None,
            light_exposure: 1.0,
        });
        if let Some(p) = parent {
            let parent_node = &mut internodes[p.index()];
            if parent_node.main_child.is_none() && parent_node.order == order {
                parent_node.main_child = Some(id);
            } else {
                parent_node.lateral_children.push(id);
            }
        }
        let end = start + heading * length;
        if remaining > 1 {
            queue.push_back((Some(id), end, heading, order, remaining - 1, level + 1));
        }
        let branches = order < 2 && remaining > 1 && level >= 2 && rng.next_f32() < 0.7;
        if branches {
            let around = Quat::from_axis_angle(heading, rng.range_f32(0.0, std::f32::consts::TAU));
            let side = around * heading.any_orthonormal_vector();
            let lateral = (heading * 0.5 + side).normalize();
            queue.push_back((
                Some(id),
                end,
                lateral,
                order + 1,
                remaining.min(depth + 2),
                level + 1,
            ));
        }
    }
    assign_pipe_widths(&mut internodes);
    Skeleton { internodes }
}

/// Pipe model: a tip is 6 mm thick; a parent's cross-section is the sum of its children's.
fn assign_pipe_widths(internodes: &mut [Internode]) {
    for i in (0..internodes.len()).rev() {
        let area: f32 = internodes[i]
            .children()
            .map(|c| internodes[c.index()].diameter.powi(2))
            .sum();
        internodes[i].diameter = if area > 0.0 { area.sqrt() } else { 0.006 };
    }
}

/// Tubes (8 sides) for every internode and four leaves at every tip.
pub fn standin_tree_mesh(skeleton: &Skeleton) -> TreeMesh {
    let mut mesh = TreeMesh::default();
    let top = skeleton
        .internodes
        .iter()
        .map(|n| n.end.y)
        .fold(0.1f32, f32::max);
    for node in &skeleton.internodes {
        let ambient = 0.45 + 0.55 * (node.end.y / top).clamp(0.0, 1.0);
        let end_diameter = node
            .main_child
            .map_or(node.diameter * 0.7, |c| skeleton.get(c).diameter);
        add_tube(&mut mesh.branches, node, end_diameter, ambient);
        if node.is_tip() {
            for k in 0..4 {
                let angle = k as f32 * std::f32::consts::FRAC_PI_2 + node.order as f32;
                add_leaf(&mut mesh.leaves, node, angle, ambient);
            }
        }
    }
    mesh
}

fn add_tube(mesh: &mut LitMesh, node: &Internode, end_diameter: f32, ambient: f32) {
    const SIDES: u32 = 8;
    let heading = node.heading();
    let left = heading.any_orthonormal_vector();
    let up = heading.cross(left);
    let base = mesh.vertices.len() as u32;
    for s in 0..SIDES {
        let a = s as f32 / SIDES as f32 * std::f32::consts::TAU;
        let normal = left * a.cos() + up * a.sin();
        for (centre, diameter) in [(node.start, node.diameter), (node.end, end_diameter)] {
            mesh.vertices.push(LitVertex {
                position: (centre + normal * diameter * 0.5).to_array(),
                normal: normal.to_array(),
                ambient,
                uv: [0.0, 0.0],
            });
        }
    }
    for s in 0..SIDES {
        let (a0, a1) = (base + 2 * s, base + 2 * s + 1);
        let (b0, b1) = (
            base + 2 * ((s + 1) % SIDES),
            base + 2 * ((s + 1) % SIDES) + 1,
        );
        mesh.indices.extend([a0, b0, b1, a0, b1, a1]);
    }
}

fn add_leaf(mesh: &mut LitMesh, node: &Internode, angle: f32, ambient: f32) {
    let heading = node.heading();
    let side = Quat::from_axis_angle(heading, angle) * heading.any_orthonormal_vector();
    let along = (side + heading * 0.6).normalize();
    let across = along.cross(heading).try_normalize().unwrap_or(Vec3::X);
    let normal = across.cross(along).normalize();
    let (length, width) = (0.09, 0.05);
    let base = mesh.vertices.len() as u32;
    for (x, y) in [(-0.5, 0.0), (0.5, 0.0), (0.5, 1.0), (-0.5, 1.0)] {
        let p = node.end + along * (y * length) + across * (x * width);
        mesh.vertices.push(LitVertex {
            position: p.to_array(),
            normal: normal.to_array(),
            ambient,
            uv: [x, y],
        });
    }
    mesh.indices
        .extend([base, base + 1, base + 2, base, base + 2, base + 3]);
}

/// Stand-in for brush-guided growth (space colonization towards `attractors`): each attractor
/// votes for the nearest internode end within `perception` metres; each node with votes grows one
/// internode of `step` metres towards the mean of its voters; attractors closer than `kill` to a
/// new end are consumed. Returns how many internodes grew.
///
/// `weights` are the barycentric α/β/γ blend of the shoot direction: the parent's heading, the
/// direction to the attractors, and `tropism` (a unit direction).
pub fn standin_grow_towards(
    skeleton: &mut Skeleton,
    attractors: &mut Vec<Vec3>,
    (perception, step): (f32, f32),
    weights: [f32; 3],
    tropism: Vec3,
) -> usize {
    if skeleton.internodes.is_empty() {
        return 0;
    }
    let mut sums: Vec<(Vec3, u32)> = vec![(Vec3::ZERO, 0); skeleton.len()];
    for a in attractors.iter() {
        let nearest = skeleton
            .internodes
            .iter()
            .enumerate()
            .map(|(i, n)| (i, n.end.distance_squared(*a)))
            .filter(|(_, d)| *d < perception * perception)
            .min_by(|x, y| x.1.total_cmp(&y.1).then(x.0.cmp(&y.0)));
        if let Some((i, _)) = nearest {
            sums[i].0 += (*a - skeleton.internodes[i].end).normalize_or_zero();
            sums[i].1 += 1;
        }
    }
    let mut grown = 0;
    for (i, (sum, count)) in sums.into_iter().enumerate() {
        let Some(towards) = (sum / count.max(1) as f32).try_normalize() else {
            continue;
        };
        let parent = &skeleton.internodes[i];
        let blended = parent.heading() * weights[0] + towards * weights[1] + tropism * weights[2];
        let direction = blended.try_normalize().unwrap_or(towards);
        let start = parent.end;
        let end = start + direction * step;
        let id = NodeId(skeleton.internodes.len() as u32);
        let order = if parent.is_tip() {
            parent.order
        } else {
            parent.order + 1
        };
        let born = parent.born_iteration + 1;
        if skeleton.internodes[i].is_tip() {
            skeleton.internodes[i].main_child = Some(id);
        } else {
            skeleton.internodes[i].lateral_children.push(id);
        }
        skeleton.internodes.push(Internode {
            parent: Some(NodeId(i as u32)),
            main_child: None,
            lateral_children: Vec::new(),
            start,
            end,
            left: direction.any_orthonormal_vector(),
            diameter: 0.0,
            order,
            born_iteration: born,
            terminal_bud: None,
            lateral_buds: Vec::new(),
            width_constraint: None,
            light_exposure: 1.0,
        });
        attractors.retain(|a| a.distance(end) > step * 1.5);
        grown += 1;
    }
    assign_pipe_widths(&mut skeleton.internodes);
    grown
}

/// Stand-in for pruning: removes the subtree rooted at `root` (all of the tree when it is the
/// root), keeping the arena in topological order.
pub fn standin_remove_subtree(skeleton: &mut Skeleton, root: NodeId) -> usize {
    let n = skeleton.len();
    if root.index() >= n {
        return 0;
    }
    let mut removed = vec![false; n];
    removed[root.index()] = true;
    for i in root.index() + 1..n {
        if let Some(p) = skeleton.internodes[i].parent {
            removed[i] = removed[p.index()];
        }
    }
    let mut new_index = vec![None; n];
    let mut next = 0u32;
    for i in 0..n {
        if !removed[i] {
            new_index[i] = Some(NodeId(next));
            next += 1;
        }
    }
    let remap = |id: NodeId| new_index[id.index()];
    let old = std::mem::take(&mut skeleton.internodes);
    for (i, mut node) in old.into_iter().enumerate() {
        if removed[i] {
            continue;
        }
        node.parent = node.parent.and_then(remap);
        node.main_child = node.main_child.and_then(remap);
        node.lateral_children = node
            .lateral_children
            .iter()
            .filter_map(|c| remap(*c))
            .collect();
        skeleton.internodes.push(node);
    }
    assign_pipe_widths(&mut skeleton.internodes);
    removed.iter().filter(|r| **r).count()
}

/// Stand-in for bending: rotates the subtree rooted at `root` about its start point.
pub fn standin_bend(skeleton: &mut Skeleton, root: NodeId, rotation: Quat) {
    let Some(pivot) = skeleton.internodes.get(root.index()).map(|n| n.start) else {
        return;
    };
    let mut inside = vec![false; skeleton.len()];
    inside[root.index()] = true;
    for i in root.index() + 1..skeleton.len() {
        if let Some(p) = skeleton.internodes[i].parent {
            inside[i] = inside[p.index()];
        }
    }
    for (node, inside) in skeleton.internodes.iter_mut().zip(inside) {
        if inside {
            node.start = pivot + rotation * (node.start - pivot);
            node.end = pivot + rotation * (node.end - pivot);
            node.left = rotation * node.left;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_standin_skeleton_is_a_valid_arena_and_deterministic() {
        let a = standin_skeleton(3, 4);
        a.sanity_check().expect("valid arena");
        assert_eq!(a, standin_skeleton(3, 4));
        assert!(a.len() > 20);
        let mesh = standin_tree_mesh(&a);
        assert!(!mesh.leaves.is_empty() && !mesh.branches.is_empty());
    }
}
