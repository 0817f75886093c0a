//! Branch bending: PriMo (Botsch et al. 2006) on tree skeletons, Longay 2014 appendix A.
//!
//! The internodes on the path from a base internode B to an end internode E are rigid prisms;
//! adjacent prisms meet at a joint face, a bilinear patch spanned by the U and L axes of the
//! HLU frame. Bending moves each prism i by a rigid transform (Rᵢ, tᵢ) so as to minimise
//!
//! E = Σ_joints w_ij E_ij,   E_ij = ∫∫_{\[0,1\]²} ‖f^{i→j}(u,v) − f^{j→i}(u,v)‖² du dv   (A.1)
//!
//! with the flexural stiffness wᵢ = rᵢ⁴ / lᵢ (A.3) (joint weight: the two half-prisms in series,
//! the harmonic mean of wᵢ and wⱼ) under positional constraints on the end points of E and of any
//! internode between B and E. The joint below B is anchored to the unmoved tree.
//!
//! Solver: faces are integrated exactly with 2×2 Gauss points (the integrand is bi-quadratic).
//! A global Levenberg–Marquardt solve over all prisms (block-tridiagonal normal equations, see
//! module `bend_solver`) is followed by iterated local shape matching (A.2): each prism takes
//! Horn's closed-form best rigid motion onto its neighbours' faces. Local matching alone moves
//! information one prism per sweep and does not settle long paths interactively, hence the
//! global step. Every solve starts from the rest pose, so the result depends only on the
//! constraints: moving them back restores the tree (circular editing).
//!
//! After the solve, joints are placed midway between the faces of adjacent prisms (a joint that
//! opened is stretching) or, with stretching disabled, the prisms are chained end to start so
//! that every internode keeps its length. Every other branch keeps its pose relative to the path
//! internode that supports it.

use glam::{DQuat, DVec3, Vec3};

use super::EditError;
use super::bend_solver::{self, Face, Motion, Pin, Problem};
use super::horn::CrossCovariance;
use crate::tree::{Internode, NodeId, Skeleton};

/// Knobs of the bend solver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BendSettings {
    /// Half-width of the joint faces in units of the internode radius. Wider faces make bending
    /// costly relative to opening a joint, so the branch stretches rather than bends.
    pub prism_width_factor: f32,
    /// When false, prisms are chained after the solve so every internode keeps its length.
    pub allow_stretching: bool,
    /// Upper bound on global Levenberg–Marquardt steps.
    pub max_steps: u32,
    /// Local shape-matching sweeps run after the global solve (at most).
    pub polish_sweeps: u32,
    /// The solve stops when no prism moves more than this in a step (metres).
    pub tolerance_m: f32,
}

impl Default for BendSettings {
    fn default() -> Self {
        BendSettings {
            prism_width_factor: 1.0,
            allow_stretching: true,
            max_steps: 60,
            polish_sweeps: 1,
            tolerance_m: 1e-4,
        }
    }
}

/// "The end of internode `node` goes to `end_position`" (world metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PositionalConstraint {
    pub node: NodeId,
    pub end_position: Vec3,
}

/// A branch internode that rides rigidly on a path prism.
#[derive(Clone, Debug)]
struct Follower {
    id: NodeId,
    /// Index of the supporting prism on the path.
    support: usize,
    rest: Internode,
}

/// Solution of a bend: one rigid motion per path prism, and the joints derived from them.
#[derive(Clone, Debug, PartialEq)]
pub struct BendPose {
    motions: Vec<(DQuat, DVec3)>,
    /// n + 1 joint positions: start of B, …, end of E (world metres).
    pub joints: Vec<Vec3>,
    /// Global steps plus local sweeps run (for diagnostics and benches).
    pub sweeps: u32,
}

/// A bend gesture in progress: the path, its rest pose and the branches that follow it.
#[derive(Clone, Debug)]
pub struct Bend {
    path: Vec<NodeId>,
    rest_path: Vec<Internode>,
    /// Face k lies at the start of prism k (face 0 is anchored below B).
    faces: Vec<Face>,
    /// Rest midpoints of the prisms (linearisation centres of the global solver).
    rest_centres: Vec<glam::DVec3>,
    followers: Vec<Follower>,
    settings: BendSettings,
}

impl Bend {
    /// Prepares bending the path from `base` (B) up to `end` (E), capturing the rest pose.
    pub fn new(
        skeleton: &Skeleton,
        base: NodeId,
        end: NodeId,
        settings: BendSettings,
    ) -> Result<Bend, EditError> {
        let count = skeleton.len();
        for id in [base, end] {
            if id.index() >= count {
                return Err(EditError::NoSuchInternode { id: id.0, count });
            }
        }
        if !(settings.prism_width_factor.is_finite() && settings.prism_width_factor > 0.0) {
            return Err(EditError::BadParameter {
                name: "prism_width_factor",
                value: settings.prism_width_factor,
            });
        }
        let mut path = vec![end];
        let mut at = end;
        while at != base {
            match skeleton.get(at).parent {
                Some(p) => {
                    at = p;
                    path.push(p);
                }
                None => {
                    return Err(EditError::NotOnPath {
                        id: end.0,
                        base: base.0,
                    });
                }
            }
        }
        path.reverse();
        let rest_path: Vec<Internode> = path.iter().map(|&id| skeleton.get(id).clone()).collect();
        let parent_radius = skeleton
            .get(base)
            .parent
            .map(|p| skeleton.get(p).diameter * 0.5);
        let faces = build_faces(&rest_path, parent_radius, settings.prism_width_factor);
        let followers = collect_followers(skeleton, &path);
        let rest_centres = rest_path
            .iter()
            .map(|i| ((i.start + i.end) * 0.5).as_dvec3())
            .collect();
        Ok(Bend {
            path,
            rest_path,
            faces,
            rest_centres,
            followers,
            settings,
        })
    }

    /// The internodes B … E.
    pub fn path(&self) -> &[NodeId] {
        &self.path
    }

    pub fn settings(&self) -> BendSettings {
        self.settings
    }

    /// Solves for the pose that satisfies `constraints`, always starting from the rest pose:
    /// Levenberg–Marquardt over the whole path (module `bend_solver`), then local shape-matching
    /// sweeps (Horn) that polish each prism against its neighbours' faces.
    pub fn solve(&self, constraints: &[PositionalConstraint]) -> Result<BendPose, EditError> {
        let pins = self.pins(constraints)?;
        let n = self.path.len();
        let base = self.rest_path[0].start.as_dvec3();
        let mut motions = bend_solver::initial_motions(n, base, &pins);
        let tolerance = f64::from(self.settings.tolerance_m);
        let mut pivots = vec![None; n];
        for pin in &pins {
            pivots[pin.prism] = Some(pin.target);
        }
        let problem = Problem {
            faces: &self.faces,
            rest_centres: &self.rest_centres,
            pivots: &pivots,
        };
        let mut sweeps =
            bend_solver::minimise(&problem, &mut motions, tolerance, self.settings.max_steps);
        for sweep in 0..self.settings.polish_sweeps {
            sweeps += 1;
            if self.sweep(&mut motions, &pins, 1, sweep % 2 == 0) < tolerance {
                break;
            }
        }
        let joints = self.joints(&motions);
        Ok(BendPose {
            motions: motions
                .iter()
                .map(|m| (m.rotation, m.translation))
                .collect(),
            joints,
            sweeps,
        })
    }

    /// Writes `pose` into the path and every branch carried by it.
    pub fn apply(&self, pose: &BendPose, skeleton: &mut Skeleton) {
        let joint = |k: usize| pose.joints[k];
        for (k, (&id, rest)) in self.path.iter().zip(&self.rest_path).enumerate() {
            let rotation = pose.motions[k].0.as_quat();
            let node = &mut skeleton.internodes[id.index()];
            node.start = joint(k);
            node.end = joint(k + 1);
            let heading = node.heading();
            let left = rotation * rest.left;
            node.left = (left - heading * heading.dot(left))
                .try_normalize()
                .unwrap_or_else(|| heading.any_orthonormal_vector());
            rotate_buds(node, rest, rotation);
        }
        for follower in &self.followers {
            let k = follower.support;
            let rotation = pose.motions[k].0.as_quat();
            let pivot = self.rest_path[k].end;
            let moved = |p: Vec3| rotation * (p - pivot) + joint(k + 1);
            let node = &mut skeleton.internodes[follower.id.index()];
            node.start = moved(follower.rest.start);
            node.end = moved(follower.rest.end);
            node.left = rotation * follower.rest.left;
            rotate_buds(node, &follower.rest, rotation);
        }
    }

    /// Writes `pose` into a growing tree and refreshes what depends on node positions (the
    /// shadow grid). Widths do not change under bending.
    pub fn apply_to_tree(&self, pose: &BendPose, tree: &mut crate::growth::Tree) {
        self.apply(pose, &mut tree.skeleton);
        tree.rebuild_shadow();
    }

    /// Puts the path and its branches back exactly as they were when the bend began.
    pub fn restore(&self, skeleton: &mut Skeleton) {
        for (&id, rest) in self.path.iter().zip(&self.rest_path) {
            copy_pose(&mut skeleton.internodes[id.index()], rest);
        }
        for follower in &self.followers {
            copy_pose(
                &mut skeleton.internodes[follower.id.index()],
                &follower.rest,
            );
        }
    }

    /// Pins as (prism index, rest end, target), validated.
    fn pins(&self, constraints: &[PositionalConstraint]) -> Result<Vec<Pin>, EditError> {
        constraints
            .iter()
            .map(|c| {
                let Some(k) = self.path.iter().position(|&id| id == c.node) else {
                    return Err(EditError::NotOnPath {
                        id: c.node.0,
                        base: self.path[0].0,
                    });
                };
                if !c.end_position.is_finite() {
                    return Err(EditError::NonFinite {
                        what: "bend constraint position",
                    });
                }
                Ok(Pin {
                    prism: k,
                    rest: self.rest_path[k].end.as_dvec3(),
                    target: c.end_position.as_dvec3(),
                })
            })
            .collect()
    }

    /// One Gauss–Seidel sweep over clusters of `size` prisms; returns the largest point motion.
    fn sweep(&self, motions: &mut [Motion], pins: &[Pin], size: usize, forward: bool) -> f64 {
        let n = self.path.len();
        let clusters = n.div_ceil(size);
        let mut moved = 0.0f64;
        for c in 0..clusters {
            let c = if forward { c } else { clusters - 1 - c };
            let (a, b) = (c * size, ((c + 1) * size).min(n));
            let old = motions[a];
            let new = self.match_cluster(motions, pins, a, b);
            for p in self.faces[a].points {
                moved = moved.max(new.apply(p).distance(old.apply(p)));
            }
            if b < n {
                for p in self.faces[b].points {
                    moved = moved.max(new.apply(p).distance(old.apply(p)));
                }
            }
            motions[a..b].fill(new);
        }
        moved
    }

    /// Horn's best rigid motion of prisms a..b onto the faces of their neighbours and their pins.
    fn match_cluster(&self, motions: &[Motion], pins: &[Pin], a: usize, b: usize) -> Motion {
        let n = self.path.len();
        let below = if a == 0 {
            Motion::IDENTITY
        } else {
            motions[a - 1]
        };
        let mut pairs: [(f64, DVec3, DVec3); 8] = [(0.0, DVec3::ZERO, DVec3::ZERO); 8];
        let mut count = 0;
        for p in self.faces[a].points {
            pairs[count] = (self.faces[a].point_weight, p, below.apply(p));
            count += 1;
        }
        if b < n {
            for p in self.faces[b].points {
                pairs[count] = (self.faces[b].point_weight, p, motions[b].apply(p));
                count += 1;
            }
        }
        let faces = &pairs[..count];
        let inside: Vec<&Pin> = pins.iter().filter(|p| (a..b).contains(&p.prism)).collect();
        let face_weight: f64 = faces.iter().map(|f| f.0).sum();
        // One pin is hard: the cluster rotates about it. Several pins are soft but dominant.
        let (centre_from, centre_to, pin_weight) = match inside.as_slice() {
            [pin] => (pin.rest, pin.target, 0.0),
            _ => {
                let pin_weight = if inside.is_empty() {
                    0.0
                } else {
                    1e8 * face_weight.max(1e-300)
                };
                let mut total = 0.0;
                let (mut from, mut to) = (DVec3::ZERO, DVec3::ZERO);
                for &(w, p, q) in faces {
                    total += w;
                    from += p * w;
                    to += q * w;
                }
                for pin in &inside {
                    total += pin_weight;
                    from += pin.rest * pin_weight;
                    to += pin.target * pin_weight;
                }
                (from / total, to / total, pin_weight)
            }
        };
        let mut covariance = CrossCovariance::default();
        for &(w, p, q) in faces {
            covariance.add(w, p - centre_from, q - centre_to);
        }
        for pin in &inside {
            covariance.add(pin_weight, pin.rest - centre_from, pin.target - centre_to);
        }
        let rotation = covariance.best_rotation(motions[a].rotation);
        Motion {
            rotation,
            translation: centre_to - rotation * centre_from,
        }
    }

    /// Joint positions from the prism motions (see the module doc).
    fn joints(&self, motions: &[Motion]) -> Vec<Vec3> {
        let n = self.path.len();
        let mut joints = Vec::with_capacity(n + 1);
        joints.push(self.rest_path[0].start.as_dvec3());
        for k in 0..n {
            let rest = &self.rest_path[k];
            let (start, end) = (rest.start.as_dvec3(), rest.end.as_dvec3());
            let next = if !self.settings.allow_stretching {
                joints[k] + motions[k].rotation * (end - start)
            } else if k + 1 < n {
                (motions[k].apply(end) + motions[k + 1].apply(end)) * 0.5
            } else {
                motions[k].apply(end)
            };
            joints.push(next);
        }
        joints.iter().map(|j| j.as_vec3()).collect()
    }
}

/// Flexural stiffness w = r⁴ / l (A.3), with the radius floored so a fresh tree without widths
/// still has a well-posed system.
fn stiffness(radius: f64, length: f64, radius_floor: f64) -> f64 {
    radius.max(radius_floor).powi(4) / length.max(1e-9)
}

fn build_faces(path: &[Internode], parent_radius: Option<f32>, width_factor: f32) -> Vec<Face> {
    let radii: Vec<f64> = path.iter().map(|i| f64::from(i.diameter) * 0.5).collect();
    let largest = radii.iter().copied().fold(0.0, f64::max);
    let floor = (largest * 1e-3).max(1e-6);
    let w: Vec<f64> = path
        .iter()
        .zip(&radii)
        .map(|(i, &r)| stiffness(r, f64::from(i.length()), floor))
        .collect();
    let below_radius = parent_radius.map_or(radii[0], f64::from);
    let below_weight = stiffness(below_radius, f64::from(path[0].length()), floor);
    let gauss = 1.0 / 3f64.sqrt();
    (0..path.len())
        .map(|k| {
            let (r_below, w_below) = if k == 0 {
                (below_radius, below_weight)
            } else {
                (radii[k - 1], w[k - 1])
            };
            let joint_weight = 2.0 * w_below * w[k] / (w_below + w[k]).max(1e-300);
            let half_width =
                f64::from(width_factor) * 0.5 * (r_below + radii[k]).max(floor).max(1e-4);
            let node = &path[k];
            let (u, l) = (node.up().as_dvec3(), node.left.as_dvec3());
            let centre = node.start.as_dvec3();
            let d = gauss * half_width;
            Face {
                points: [
                    centre + (u + l) * d,
                    centre + (u - l) * d,
                    centre + (-u + l) * d,
                    centre + (-u - l) * d,
                ],
                point_weight: joint_weight * 0.25,
            }
        })
        .collect()
}

/// Every descendant of B off the path, with the path prism that carries it.
fn collect_followers(skeleton: &Skeleton, path: &[NodeId]) -> Vec<Follower> {
    let base = path[0].index();
    let mut support: Vec<Option<usize>> = vec![None; skeleton.len() - base];
    for (k, id) in path.iter().enumerate() {
        support[id.index() - base] = Some(k);
    }
    let mut followers = Vec::new();
    for i in (base + 1)..skeleton.len() {
        if support[i - base].is_some() {
            continue; // on the path: set before the loop, followers are set only when visited
        }
        let Some(parent) = skeleton.internodes[i].parent else {
            continue;
        };
        if parent.index() < base {
            continue;
        }
        if let Some(k) = support[parent.index() - base] {
            support[i - base] = Some(k);
            followers.push(Follower {
                id: NodeId(i as u32),
                support: k,
                rest: skeleton.internodes[i].clone(),
            });
        }
    }
    followers
}

fn rotate_buds(node: &mut Internode, rest: &Internode, rotation: glam::Quat) {
    if let (Some(bud), Some(rest_bud)) = (node.terminal_bud.as_mut(), rest.terminal_bud.as_ref()) {
        bud.direction = (rotation * rest_bud.direction).normalize_or(rest_bud.direction);
    }
    for (bud, rest_bud) in node.lateral_buds.iter_mut().zip(&rest.lateral_buds) {
        bud.direction = (rotation * rest_bud.direction).normalize_or(rest_bud.direction);
    }
}

fn copy_pose(node: &mut Internode, rest: &Internode) {
    node.start = rest.start;
    node.end = rest.end;
    node.left = rest.left;
    if let (Some(bud), Some(rest_bud)) = (node.terminal_bud.as_mut(), rest.terminal_bud.as_ref()) {
        bud.direction = rest_bud.direction;
    }
    for (bud, rest_bud) in node.lateral_buds.iter_mut().zip(&rest.lateral_buds) {
        bud.direction = rest_bud.direction;
    }
}
