//! Deterministic branching skeletons for tests, benchmarks and examples: a recursive
//! (breadth-first) branching with a straight trunk, spiral laterals, mild upward tropism and
//! pipe-model diameters. Not a growth model: it only has to look and measure like a tree.

use std::collections::VecDeque;

use glam::Vec3;

use super::any_perpendicular;
use crate::rng::Rng;
use crate::tree::{Bud, Children, Internode, LateralBuds, NodeId, Skeleton};

/// Parameters of [`branching_skeleton_with`]. Lengths in metres, angles in radians.
#[derive(Clone, Debug, PartialEq)]
pub struct SyntheticParams {
    pub internode_length: f32,
    /// Trunk internodes before the first lateral.
    pub clear_trunk: u32,
    /// Probability that an internode bears a lateral shoot.
    pub lateral_probability: f32,
    pub branching_angle: f32,
    /// Diameter of a tip internode.
    pub tip_diameter: f32,
    /// Pipe-model exponent: d^γ = Σ d_child^γ.
    pub pipe_exponent: f32,
}

impl Default for SyntheticParams {
    fn default() -> Self {
        SyntheticParams {
            internode_length: 0.05,
            clear_trunk: 10,
            lateral_probability: 0.45,
            branching_angle: 0.85,
            tip_diameter: 0.004,
            pipe_exponent: 2.5,
        }
    }
}

/// A skeleton of exactly `num_internodes` internodes (at least 1) with default parameters.
pub fn branching_skeleton(num_internodes: usize, seed: u64) -> Skeleton {
    branching_skeleton_with(num_internodes, seed, &SyntheticParams::default())
}

fn new_internode(
    parent: Option<NodeId>,
    start: Vec3,
    heading: Vec3,
    left: Vec3,
    length: f32,
    order: u32,
) -> Internode {
    Internode {
        parent,
        main_child: None,
        lateral_children: Children::new(),
        start,
        end: start + heading * length,
        left,
        diameter: 0.0,
        order,
        born_iteration: 0,
        terminal_bud: None,
        lateral_buds: LateralBuds::new(),
        width_constraint: None,
        light_exposure: 1.0,
    }
}

/// Parallel transport of `left` onto the plane perpendicular to `heading`.
fn transported_left(left: Vec3, heading: Vec3) -> Vec3 {
    (left - heading * left.dot(heading))
        .try_normalize()
        .unwrap_or_else(|| any_perpendicular(heading))
}

/// A skeleton of exactly `num_internodes` internodes (at least 1).
pub fn branching_skeleton_with(
    num_internodes: usize,
    seed: u64,
    params: &SyntheticParams,
) -> Skeleton {
    let target = num_internodes.max(1);
    let mut rng = Rng::new(seed);
    let mut nodes = Vec::with_capacity(target);
    nodes.push(new_internode(
        None,
        Vec3::ZERO,
        Vec3::Y,
        Vec3::X,
        params.internode_length,
        0,
    ));
    let mut tips = VecDeque::from([0usize]);
    let mut spiral = 0.0f32;
    while nodes.len() < target {
        let Some(tip) = tips.pop_front() else { break };
        let (end, heading, left, order) = {
            let n: &Internode = &nodes[tip];
            (n.end, n.heading(), n.left, n.order)
        };
        let on_clear_trunk = order == 0 && tip < params.clear_trunk as usize;
        // Tips of high order stop now and then; the last tip never does.
        let stops = !tips.is_empty() && rng.next_f32() < 0.03 * order as f32;
        if !stops {
            let wobble = if on_clear_trunk { 0.03 } else { 0.22 };
            let main_heading = (heading + rng.unit_vector() * wobble + Vec3::Y * 0.06)
                .try_normalize()
                .unwrap_or(heading);
            let id = NodeId(nodes.len() as u32);
            let child_left = transported_left(left, main_heading);
            nodes.push(new_internode(
                Some(NodeId(tip as u32)),
                end,
                main_heading,
                child_left,
                params.internode_length,
                order,
            ));
            nodes[tip].main_child = Some(id);
            tips.push_back(id.index());
        }
        if !on_clear_trunk && nodes.len() < target && rng.next_f32() < params.lateral_probability {
            spiral += 2.399_963;
            let up = heading.cross(left);
            let radial = left * spiral.cos() + up * spiral.sin();
            let (sin_b, cos_b) = params.branching_angle.sin_cos();
            let lateral_heading = (heading * cos_b + radial * sin_b).normalize_or(heading);
            let id = NodeId(nodes.len() as u32);
            let child_left = transported_left(left, lateral_heading);
            nodes.push(new_internode(
                Some(NodeId(tip as u32)),
                end,
                lateral_heading,
                child_left,
                params.internode_length,
                order + 1,
            ));
            nodes[tip].lateral_children.push(id);
            tips.push_back(id.index());
        }
        if nodes.len() < target && tips.is_empty() {
            tips.push_back(tip);
        }
    }
    finish(&mut nodes, params, &mut rng);
    Skeleton { internodes: nodes }
}

/// Pipe-model diameters (tips to base), buds and light exposure.
fn finish(nodes: &mut [Internode], params: &SyntheticParams, rng: &mut Rng) {
    let gamma = params.pipe_exponent;
    for index in (0..nodes.len()).rev() {
        let sum: f32 = nodes[index]
            .children()
            .map(|c| nodes[c.index()].diameter.powf(gamma))
            .sum();
        let diameter = if sum > 0.0 {
            sum.powf(1.0 / gamma)
        } else {
            params.tip_diameter
        };
        let node = &mut nodes[index];
        node.diameter = diameter;
        let heading = node.heading();
        if node.main_child.is_none() {
            node.terminal_bud = Some(Bud::new(heading));
        }
        let side = (heading + node.left).normalize_or(heading);
        let mut bud = Bud::new(side);
        bud.alive = node.lateral_children.is_empty();
        node.lateral_buds = std::iter::once(bud).collect();
        // Outer, higher, thinner parts of the crown see more light.
        node.light_exposure =
            (0.25 + 0.5 * rng.next_f32() + 0.25 * (1.0 - diameter / 0.05).clamp(0.0, 1.0)).min(1.0);
    }
}

/// A smooth stand-in for the growth shadow grid: light falls off towards the crown's core and
/// the ground. 1 at the outside of a crown of `radius` metres centred at `center`.
pub fn crown_ambient(center: Vec3, radius: f32) -> impl Fn(Vec3) -> f32 {
    move |p: Vec3| {
        let depth = 1.0 - (p - center).length() / radius.max(1e-3);
        (1.0 - 0.7 * depth.clamp(0.0, 1.0)).clamp(0.2, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn synthetic_skeletons_are_valid_sized_and_deterministic() {
        let a = branching_skeleton(5_000, 3);
        let b = branching_skeleton(5_000, 3);
        assert_eq!(a.len(), 5_000);
        a.sanity_check().expect("valid synthetic skeleton");
        assert_eq!(a, b);
        assert_ne!(a, branching_skeleton(5_000, 4));
        for node in &a.internodes {
            for child in node.children() {
                assert!(
                    a.get(child).diameter <= node.diameter + 1e-6,
                    "pipe model widens"
                );
            }
        }
    }
}
