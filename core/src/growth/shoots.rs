//! Steps 5 and 6: shoot length n = ⌊v/v_max·n_max⌋ and the direction of every new internode,
//! H' = αH + βT + γE, with the deflection δ of an axis away from its growing laterals.
//!
//! New internodes are appended to the arena, so it stays in topological order; every new node
//! casts its shadow at once and consumes the attraction points in its occupancy sphere, and each
//! further internode of a shoot re-perceives the remaining points (so a thin brush stroke is
//! followed internode by internode). A shoot stops where its next internode would go below the
//! ground (the horizontal plane through the tree's base), as it stops at a scene it grows in
//! front of.

use glam::Vec3;

use super::buds::{self, TERMINAL};
use super::space;
use super::{Scratch, Tree};
use crate::environment::{Scene, SceneMode};
use crate::tree::{Bud, Children, Internode, LateralBuds, NodeId};

/// Upper bound on internodes in one shoot (guards absurd parameter values).
const MAX_SHOOT_LENGTH: f32 = 200.0;

/// n_max at the tree's current age: n_max·h/(h + age) (constant when h = 0).
pub(crate) fn max_shoot_internodes(tree: &Tree) -> f32 {
    let s = &tree.species;
    let h = s.shoot_length_halving_age_years;
    if h > 0.0 {
        s.max_shoot_internodes * h / (h + tree.age_years())
    } else {
        s.max_shoot_internodes
    }
}

fn shoot_length(vigor: f32, v_max: f32, n_max: f32) -> u32 {
    (vigor / v_max * n_max).clamp(0.0, MAX_SHOOT_LENGTH).floor() as u32
}

/// Grows every enabled bud whose shoot length is ≥ 1, skipping branches being shed.
/// Returns (shoots, new internodes).
pub(crate) fn grow_all(
    tree: &mut Tree,
    scratch: &mut Scratch,
    v_max: f32,
    removed: &[bool],
    scene: Option<(&dyn Scene, SceneMode)>,
) -> (usize, usize) {
    if v_max <= 0.0 {
        return (0, 0);
    }
    let n_max = max_shoot_internodes(tree);
    let front = match scene {
        Some((s, SceneMode::GrowInFront)) => Some(s),
        _ => None,
    };
    let num_before = tree.skeleton.len();
    let constants = ShootConstants::of(tree);
    let (mut shoots, mut added) = (0, 0);
    for (i, &gone) in removed.iter().enumerate().take(num_before) {
        if gone {
            continue;
        }
        let range = scratch.node_bud_start[i] as usize..scratch.node_bud_start[i + 1] as usize;
        deflect(tree, scratch, &constants, i, range.clone(), v_max, n_max);
        for bi in range {
            let bud = scratch.buds[bi];
            if !bud.enabled {
                continue;
            }
            let n = shoot_length(bud.vigor, v_max, n_max);
            if n > 0 {
                let grown = grow_shoot(tree, scratch, &constants, bi, n, front);
                shoots += usize::from(grown > 0);
                added += grown;
            }
        }
    }
    (shoots, added)
}

/// δ: a node whose laterals grow turns its terminal bud away from them.
fn deflect(
    tree: &mut Tree,
    scratch: &mut Scratch,
    constants: &ShootConstants,
    node: usize,
    range: std::ops::Range<usize>,
    v_max: f32,
    n_max: f32,
) {
    let Some((sin_delta, cos_delta)) = constants.deflection else {
        return;
    };
    if range.is_empty() || scratch.buds[range.start].slot != TERMINAL {
        return;
    }
    let h = scratch.buds[range.start].direction;
    let mut away = Vec3::ZERO;
    for b in &scratch.buds[range.start + 1..range.end] {
        if b.enabled && shoot_length(b.vigor, v_max, n_max) > 0 {
            away += (b.direction - b.direction.dot(h) * h).normalize_or_zero();
        }
    }
    let Some(away) = away.try_normalize() else {
        return;
    };
    let deflected = (cos_delta * h - sin_delta * away)
        .try_normalize()
        .unwrap_or(h);
    scratch.buds[range.start].direction = deflected;
    if let Some(bud) = &mut tree.skeleton.internodes[node].terminal_bud {
        bud.direction = deflected;
    }
}

/// What every shoot of an iteration grows by, worked out once: the model's radii and the sines
/// and cosines of its angles.
struct ShootConstants {
    /// Occupancy radius r, perception radius r + d (metres) and cos(ζ/2).
    radii: (f32, f32, f32),
    /// sin and cos of the gravitropic set-point angle θ.
    theta: (f32, f32),
    /// sin and cos of the scaffold's set-point angle θ_s.
    scaffold_theta: (f32, f32),
    lateral_buds: buds::LateralBudPlacement,
    /// sin and cos of the deflection angle δ, if it is positive.
    deflection: Option<(f32, f32)>,
}

impl ShootConstants {
    fn of(tree: &Tree) -> Self {
        let s = &tree.species;
        ShootConstants {
            radii: space::radii(tree),
            theta: s.gravitropism_angle_deg.to_radians().sin_cos(),
            scaffold_theta: s.scaffold_gravitropism_angle_deg.to_radians().sin_cos(),
            lateral_buds: buds::LateralBudPlacement::of(s),
            deflection: Some(s.deflection_angle_deg.to_radians())
                .filter(|&delta| delta > 0.0)
                .map(f32::sin_cos),
        }
    }
}

/// T: the per-bud override, else the tropism carried by the points, else gravitropism — global
/// up rotated by θ (θ_s on the scaffold's orders) in the vertical plane holding H (upward for
/// the main axis of conifers).
fn tropism(
    tree: &mut Tree,
    constants: &ShootConstants,
    heading: Vec3,
    order: u32,
    chosen: Option<Vec3>,
) -> Vec3 {
    if let Some(t) = chosen {
        return t;
    }
    let s = &tree.species;
    if s.upward_main_axis && order == 0 {
        return Vec3::Y;
    }
    let (sin_t, cos_t) = if order < s.scaffold_orders {
        constants.scaffold_theta
    } else {
        constants.theta
    };
    let horizontal = Vec3::new(heading.x, 0.0, heading.z)
        .try_normalize()
        .unwrap_or_else(|| {
            let (z, x) = tree.rng.range_f32(0.0, std::f32::consts::TAU).sin_cos();
            Vec3::new(x, 0.0, z)
        });
    cos_t * Vec3::Y + sin_t * horizontal
}

/// Grows one shoot of up to `n` internodes from bud `bi`; returns how many were added.
fn grow_shoot(
    tree: &mut Tree,
    scratch: &mut Scratch,
    constants: &ShootConstants,
    bi: usize,
    n: u32,
    front: Option<&dyn Scene>,
) -> usize {
    let bud = scratch.buds[bi];
    let radii = constants.radii;
    let s = &tree.species;
    let (alpha, beta, gamma) = (s.straightness, s.tropism_weight, s.environment_weight);
    let l = s.internode_length_m;
    let only_at_end = s.lateral_buds_only_at_shoot_end;
    let lateral = bud.slot != TERMINAL;
    let mut parent = bud.node as usize;
    let parent_node = &tree.skeleton.internodes[parent];
    let order = parent_node.order + u32::from(lateral);
    let stored = if lateral {
        parent_node.lateral_buds.get(bud.slot as usize)
    } else {
        parent_node.terminal_bud.as_ref()
    };
    let bud_override = stored.and_then(|b| b.tropism_override);
    let mut previous_azimuth = if lateral {
        None
    } else {
        buds::first_bud_azimuth(parent_node)
    };
    let mut heading = bud.direction;
    let won = scratch.won[bi];
    let mut environment = won.environment_sum.try_normalize().unwrap_or(heading);
    let mut carried = won.tropism_sum.try_normalize();
    // What the tip perceived after the previous internode (none before the first).
    let mut perceived: Option<(Vec3, Option<Vec3>)> = None;
    let ground_y = tree.ground_y();
    for k in 0..n {
        let tip = tree.skeleton.internodes[parent].end;
        if let Some((e, t)) = perceived.take() {
            environment = e;
            carried = t.or(carried);
        }
        let mut t = tropism(tree, constants, heading, order, bud_override.or(carried));
        // A garden's neighbourhood asymmetry (Longay 2014 eq. 6.5: F = S_t + (1 − α)·V).
        let asymmetry = tree.environment.neighbour_tropism;
        if asymmetry != Vec3::ZERO && bud_override.or(carried).is_none() {
            t = (t + asymmetry).try_normalize().unwrap_or(t);
        }
        // A stroke's direction (sketch tropism) weighs at least what the stroke asks for.
        let beta = match (bud_override, carried) {
            (None, Some(_)) => beta.max(tree.environment.attraction.sketch_tropism_weight),
            _ => beta,
        };
        let new_heading = (alpha * heading + beta * t + gamma * environment)
            .try_normalize()
            .unwrap_or(heading);
        let end = tip + new_heading * l;
        // The ground and a scene grown in front of stop the shoot where it would enter them.
        if end.y < ground_y || front.is_some_and(|scene| !scene.is_segment_free(tip, end)) {
            return k as usize;
        }
        let random_azimuth = tree.rng.range_f32(0.0, std::f32::consts::TAU);
        let azimuth = buds::next_azimuth(&tree.species, previous_azimuth, random_azimuth);
        previous_azimuth = Some(azimuth);
        let mut node = Internode {
            parent: Some(NodeId(parent as u32)),
            main_child: None,
            lateral_children: Children::new(),
            start: tip,
            end,
            left: buds::transport_left(tree.skeleton.internodes[parent].left, new_heading),
            diameter: tree.species.tip_diameter_m,
            order,
            born_iteration: tree.iteration,
            terminal_bud: Some(Bud::new(new_heading)),
            lateral_buds: LateralBuds::new(),
            width_constraint: None,
            light_exposure: 0.0,
        };
        constants.lateral_buds.add_to(&mut node, azimuth);
        let id = NodeId(tree.skeleton.len() as u32);
        let parent_mut = &mut tree.skeleton.internodes[parent];
        if k == 0 && lateral {
            parent_mut.lateral_children.push(id);
            if let Some(b) = parent_mut.lateral_buds.get_mut(bud.slot as usize) {
                b.alive = false;
            }
        } else {
            parent_mut.main_child = Some(id);
            parent_mut.terminal_bud = None;
            if k > 0 && only_at_end {
                parent_mut.lateral_buds.clear();
            }
        }
        tree.environment.shadow.apply_node(end, 1);
        node.light_exposure = tree.ambient_at(end) * tree.species.full_exposure;
        tree.skeleton.internodes.push(node);
        if k + 1 < n {
            perceived = space::consume_and_perceive(tree, scratch, end, radii, new_heading);
        } else {
            space::consume(scratch, end, radii.0);
        }
        heading = new_heading;
        parent = id.index();
    }
    n as usize
}
