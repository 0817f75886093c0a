//! Step 2: competition for space (space colonization).
//!
//! Every bud has an occupancy sphere of radius r and a perception cone of apex angle ζ and radius
//! r + d (internode lengths). Attraction points inside any occupancy sphere are removed; each
//! remaining point feeds the closest bud whose perception volume holds it; a bud with at least one
//! point is enabled and its optimal direction E is the normalised mean of the unit vectors
//! towards its points. In autonomous growth every bud first generates points in its own
//! perception volume (1 when shaded, up to `max_points_per_bud` in full light).
//!
//! All queries go through uniform grids ([`crate::environment::SpatialGrid`]): the cost is
//! O(points × buds nearby), never O(points × buds).

use glam::Vec3;

use rayon::prelude::*;

use super::buds::BudState;
use super::timing::{Phase, PhaseClock};
use super::{Scratch, StepOptions, Tree, parallel};
use crate::environment::{AttractionPoint, AttractionPoints, SceneMode, clear_with_room};

/// `Scratch::point_winner` of a point that no bud perceives.
const NO_WINNER: (u32, Vec3) = (u32::MAX, Vec3::ZERO);

/// Cell size of the bud grid relative to the perception radius.
const PERCEPTION_CELL_FRACTION: f32 = 0.5;

/// Radii of the model in metres: (occupancy r, perception r + d, cos(ζ/2)).
pub(crate) fn radii(tree: &Tree) -> (f32, f32, f32) {
    let s = &tree.species;
    let l = s.internode_length_m;
    let r = s.occupancy_radius_internodes * l;
    let perception = (s.occupancy_radius_internodes + s.perception_distance_internodes) * l;
    let cos_half = (0.5 * s.perception_angle_deg.to_radians()).cos();
    (r, perception, cos_half)
}

/// Runs step 2; returns the number of attraction points that survived occupancy.
pub(crate) fn colonize(
    tree: &mut Tree,
    scratch: &mut Scratch,
    options: StepOptions,
    clock: &mut PhaseClock,
) -> usize {
    let (r, perception, cos_half) = radii(tree);
    // Only competing buds ([`super::buds::collect`] leaves out those in full shade when κ > 0,
    // which can never grow) generate and take points.
    if options.autonomous {
        generate_points(tree, scratch, r, perception, cos_half);
    }
    clock.lap(Phase::Points);
    // The ground: no point below the plane through the base feeds a bud (brushed points there
    // are dropped too; generated ones never enter the set).
    let ground_y = tree.ground_y();
    if tree
        .environment
        .attraction
        .points
        .iter()
        .any(|p| p.persistent && p.position.y < ground_y)
    {
        tree.environment
            .attraction
            .points
            .retain(|p| p.position.y >= ground_y);
    }
    // The depth constraint: brushed and lassoed points never enter outside it, generated ones
    // (and any from before it was set) leave here.
    if let Some(constraint) = tree.environment.depth_constraint {
        constraint.retain_allowed(&mut tree.environment.attraction);
    }
    if let Some((scene, SceneMode::GrowInFront)) = options.scene {
        tree.environment
            .attraction
            .points
            .retain(|p| scene.is_free(p.position));
    }
    let points = &tree.environment.attraction.points;
    // Only nodes near some point can take it or perceive it: the grids hold the nodes inside
    // the points' bounding box grown by the radius (all of them in autonomous growth, a small
    // part of the tree under a brush).
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for p in points {
        lo = lo.min(p.position);
        hi = hi.max(p.position);
    }
    let near = |p: Vec3, margin: f32| {
        p.cmpge(lo - Vec3::splat(margin)).all() && p.cmple(hi + Vec3::splat(margin)).all()
    };
    // Occupancy: every node (internode end) holds buds or did; its sphere takes points away.
    let room = scratch.node_end.len().max(points.len());
    clear_with_room(&mut scratch.positions, room);
    scratch
        .positions
        .extend(scratch.node_end.iter().copied().filter(|&e| near(e, r)));
    // A garden's neighbours occupy space too (none for a tree growing alone).
    scratch.positions.extend(
        tree.environment
            .neighbour_nodes
            .iter()
            .copied()
            .filter(|&e| near(e, r)),
    );
    scratch.node_grid.rebuild_for_gathers(&scratch.positions, r);
    // The point grid serves the shoots later (perception, consumption); built now, its cell
    // order also orders the queries below so that neighbouring queries share cached cells.
    scratch.positions.clear();
    scratch.positions.extend(points.iter().map(|p| p.position));
    scratch
        .point_grid
        .rebuild_for_gathers(&scratch.positions, perception);
    // Cell by cell of the point grid: the nodes near the cell's points are gathered once, then
    // each point tests that short list (the same distances as a radius query of the node grid).
    // Runs of cells go to the threads; each point's result lands in its slot.
    scratch
        .point_grid
        .cell_runs(parallel::RUN_ENTRIES, &mut scratch.point_runs);
    clear_with_room(&mut scratch.slot_alive, points.len());
    scratch.slot_alive.resize(points.len(), false);
    let node_grid = &scratch.node_grid;
    parallel::for_each_cell(
        &scratch.point_grid,
        &scratch.point_runs,
        &mut scratch.slot_alive,
        &mut scratch.candidates,
        |candidates, _, _, positions, alive| {
            let (mut lo, mut hi) = (positions[0], positions[0]);
            for &p in positions {
                lo = lo.min(p);
                hi = hi.max(p);
            }
            node_grid.gather_near(lo, hi, r, candidates);
            for (alive, &position) in alive.iter_mut().zip(positions) {
                *alive = !candidates.any_within(position, r);
            }
        },
    );
    clear_with_room(&mut scratch.point_alive, points.len());
    scratch.point_alive.resize(points.len(), false);
    for (&pi, &alive) in scratch
        .point_grid
        .entry_indices()
        .iter()
        .zip(&scratch.slot_alive)
    {
        scratch.point_alive[pi as usize] = alive;
    }
    // Perception: each surviving point feeds its closest perceiving bud. The grid holds the
    // nodes with at least one competing bud (a node's buds share its position, so one distance
    // serves them all; they are tried in bud order, as before); cells of half the perception
    // radius keep the scanned volume near the sphere's.
    clear_with_room(&mut scratch.positions, scratch.node_end.len());
    clear_with_room(&mut scratch.competing_start, scratch.node_end.len() + 1);
    clear_with_room(&mut scratch.competing_buds, scratch.buds.len());
    for range in scratch.node_bud_start.windows(2) {
        let range = range[0] as usize..range[1] as usize;
        let buds = &scratch.buds[range.clone()];
        if let Some(first) = buds.iter().find(|b| b.competes)
            && let Some(position) = scratch.node_end.get(first.node as usize).copied()
            && near(position, perception)
        {
            scratch.positions.push(position);
            scratch
                .competing_start
                .push(scratch.competing_buds.len() as u32);
            scratch.competing_buds.extend(
                range
                    .zip(buds)
                    .filter(|(_, b)| b.competes)
                    .map(|(bi, b)| (bi as u32, b.direction)),
            );
        }
    }
    scratch
        .competing_start
        .push(scratch.competing_buds.len() as u32);
    scratch
        .bud_grid
        .rebuild_for_gathers(&scratch.positions, PERCEPTION_CELL_FRACTION * perception);
    // The buds in the grid's cell order, the grid's entries renumbered to match: candidates
    // gathered from neighbouring cells then find their buds next to each other in memory.
    clear_with_room(&mut scratch.sorted_start, scratch.competing_start.len());
    clear_with_room(&mut scratch.sorted_buds, scratch.competing_buds.len());
    for &i in scratch.bud_grid.entry_indices() {
        let i = i as usize;
        let range = scratch.competing_start[i] as usize..scratch.competing_start[i + 1] as usize;
        scratch.sorted_start.push(scratch.sorted_buds.len() as u32);
        scratch
            .sorted_buds
            .extend_from_slice(&scratch.competing_buds[range]);
    }
    scratch.sorted_start.push(scratch.sorted_buds.len() as u32);
    std::mem::swap(&mut scratch.sorted_start, &mut scratch.competing_start);
    std::mem::swap(&mut scratch.sorted_buds, &mut scratch.competing_buds);
    scratch.bud_grid.number_entries_by_slot();
    // Each surviving point's winner (bud, unit vector from it to the point), found in the point
    // grid's cell order, then summed in point order (the order of the sums fixes their rounding).
    let (starts, competing) = (&scratch.competing_start, &scratch.competing_buds);
    clear_with_room(&mut scratch.slot_winner, points.len());
    scratch.slot_winner.resize(points.len(), NO_WINNER);
    let (bud_grid, slot_alive) = (&scratch.bud_grid, &scratch.slot_alive);
    // Cell by cell of the point grid (runs of cells in parallel): the competing nodes near the
    // cell's points are gathered once, then each point scans that short list.
    parallel::for_each_cell(
        &scratch.point_grid,
        &scratch.point_runs,
        &mut scratch.slot_winner,
        &mut scratch.candidates,
        |candidates, first, _, positions, winners| {
            let alive = &slot_alive[first..first + positions.len()];
            let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for (&position, _) in positions.iter().zip(alive).filter(|(_, a)| **a) {
                lo = lo.min(position);
                hi = hi.max(position);
            }
            if lo.x > hi.x {
                return;
            }
            bud_grid.gather_near(lo, hi, perception, candidates);
            for ((&position, _), winner) in positions
                .iter()
                .zip(alive)
                .zip(winners)
                .filter(|((_, a), _)| **a)
            {
                let best = candidates.nearest_accepted(position, perception, |ci, node_pos, d2| {
                    let towards = position - node_pos;
                    let reach = cos_half * d2.sqrt();
                    let buds =
                        &competing[starts[ci as usize] as usize..starts[ci as usize + 1] as usize];
                    buds.iter()
                        .find(|(_, direction)| towards.dot(*direction) >= reach)
                        .map(|&(bi, _)| (bi, node_pos))
                });
                if let Some(((bi, node_pos), d2)) = best {
                    // The unit vector from the bud (at its node) to the point.
                    let towards = (position - node_pos) / d2.sqrt().max(1e-12);
                    *winner = (bi, towards);
                }
            }
        },
    );
    clear_with_room(&mut scratch.point_winner, points.len());
    scratch.point_winner.resize(points.len(), NO_WINNER);
    for (&pi, &winner) in scratch
        .point_grid
        .entry_indices()
        .iter()
        .zip(&scratch.slot_winner)
    {
        scratch.point_winner[pi as usize] = winner;
    }
    // The shoots' scans only ever look at surviving points: the grid keeps only them (same
    // cells, same order).
    let alive = &scratch.point_alive;
    scratch.point_grid.retain(|pi| alive[pi as usize]);
    let mut alive_count = 0;
    for (pi, point) in points.iter().enumerate() {
        if !scratch.point_alive[pi] {
            continue;
        }
        alive_count += 1;
        let (bi, towards) = scratch.point_winner[pi];
        if bi == NO_WINNER.0 {
            continue;
        }
        let won = &mut scratch.won[bi as usize];
        won.environment_sum += towards;
        won.count += 1;
        if let Some(t) = point.tropism {
            won.tropism_sum += t;
        }
    }
    alive_count
}

/// Competing or not, buds per block of the parallel point generation (a block outweighs
/// handing it to a thread).
const POINT_BLOCK_BUDS: usize = 2048;

/// Draws of the generator per autonomous point (polar angle, azimuth, radius).
const DRAWS_PER_POINT: u64 = 3;

/// Autonomous points: each bud adds 1 + round((max − 1)·L/C) points in its perception shell
/// (those that fall below the ground are drawn, then dropped).
///
/// On all threads, by blocks of buds: every point takes [`DRAWS_PER_POINT`] draws whether it
/// is kept or not, so the draws of each block start at a count known from the buds before it,
/// and each block draws from its own copy of the generator advanced there ([`crate::rng::Rng::advance`]).
/// The blocks' points are then appended in bud order and the generator advanced past all of
/// them: the same points, in the same order, and the same generator afterwards as drawing them
/// one by one, on any number of threads.
fn generate_points(tree: &mut Tree, scratch: &mut Scratch, r: f32, perception: f32, cos_half: f32) {
    let s = &tree.species;
    let extra = (s.max_points_per_bud - 1) as f32;
    let full_exposure = s.full_exposure;
    let (r3, p3) = (r * r * r, perception * perception * perception);
    let ground_y = tree.skeleton.ground_y();
    let count = |bud: &BudState| {
        if bud.competes {
            1 + (extra * (bud.light / full_exposure).clamp(0.0, 1.0)).round() as u32
        } else {
            0
        }
    };
    let Scratch {
        buds,
        node_end,
        point_blocks,
        point_block_draws,
        ..
    } = scratch;
    point_block_draws.clear();
    let mut draws = 0u64;
    for block in buds.chunks(POINT_BLOCK_BUDS) {
        point_block_draws.push(draws);
        let points: u64 = block.iter().map(|b| u64::from(count(b))).sum();
        draws += DRAWS_PER_POINT * points;
    }
    let num_blocks = point_block_draws.len();
    if point_blocks.len() < num_blocks {
        point_blocks.resize_with(num_blocks, Vec::new);
    }
    let start_rng = tree.rng.clone();
    point_blocks[..num_blocks]
        .par_iter_mut()
        .zip(buds.par_chunks(POINT_BLOCK_BUDS))
        .zip(point_block_draws.par_iter())
        .for_each(|((out, block), &first_draw)| {
            out.clear();
            let mut rng = start_rng.clone();
            rng.advance(first_draw);
            for bud in block {
                let n = count(bud);
                if n == 0 {
                    continue;
                }
                let position = node_end[bud.node as usize];
                let (b1, b2) = bud.direction.any_orthonormal_pair();
                for _ in 0..n {
                    // Uniform in the cone: cos of the polar angle uniform in [cos(ζ/2), 1];
                    // radius uniform in the volume of the shell r..r + d.
                    let cos_polar = 1.0 - rng.next_f32() * (1.0 - cos_half);
                    let sin_polar = (1.0 - cos_polar * cos_polar).max(0.0).sqrt();
                    let (sa, ca) = rng.range_f32(0.0, std::f32::consts::TAU).sin_cos();
                    let dir = cos_polar * bud.direction + sin_polar * (ca * b1 + sa * b2);
                    let radius = (r3 + rng.next_f32() * (p3 - r3)).cbrt();
                    let point = position + dir * radius;
                    if point.y >= ground_y {
                        out.push(AttractionPoint {
                            position: point,
                            persistent: false,
                            tropism: None,
                        });
                    }
                }
            }
        });
    tree.rng.advance(draws);
    let points: &mut AttractionPoints = &mut tree.environment.attraction;
    let added: usize = point_blocks[..num_blocks].iter().map(Vec::len).sum();
    points.points.reserve(added);
    for block in &point_blocks[..num_blocks] {
        points.points.extend_from_slice(block);
    }
}

/// [`consume`] at a new node's end (`tip`), then the optimal direction E (and carried
/// tropism) that the next internode of its shoot perceives from there, heading along
/// `heading`: in one scan of the perception sphere, the points visited in the order a separate
/// consumption and perception would visit them. `radii` are the model's ([`radii`]).
pub(crate) fn consume_and_perceive(
    tree: &Tree,
    scratch: &mut Scratch,
    tip: Vec3,
    (r, perception, cos_half): (f32, f32, f32),
    heading: Vec3,
) -> Option<(Vec3, Option<Vec3>)> {
    let consume_r2 = r * r;
    let points = &tree.environment.attraction.points;
    let mut sum = Vec3::ZERO;
    let mut tropism = Vec3::ZERO;
    let mut count = 0;
    // Only points in the occupancy sphere or in the perception cone matter: the scan keeps to
    // the cells that overlap their bounding box (same points, same order).
    let (cone_lo, cone_hi) = cone_bounds(heading, cos_half, perception);
    let margin = Vec3::splat(BOX_MARGIN * perception);
    let lo = tip + cone_lo.min(Vec3::splat(-r)) - margin;
    let hi = tip + cone_hi.max(Vec3::splat(r)) + margin;
    // The points of the cells there, then the scan of them within the perception radius.
    let reach = Vec3::splat(perception);
    let (lo, hi) = (lo.max(tip - reach), hi.min(tip + reach));
    scratch
        .point_grid
        .gather_near(lo, hi, 0.0, &mut scratch.candidates);
    let alive = &mut scratch.point_alive;
    scratch
        .candidates
        .for_each_within(tip, perception, |pi, p, d2| {
            if d2 <= consume_r2 {
                alive[pi as usize] = false;
                return;
            }
            if !alive[pi as usize] || d2 <= 0.0 {
                return;
            }
            let d = d2.sqrt();
            if (p - tip).dot(heading) >= cos_half * d {
                sum += (p - tip) / d;
                count += 1;
                if let Some(t) = points[pi as usize].tropism {
                    tropism += t;
                }
            }
        });
    (count > 0).then(|| {
        (
            sum.try_normalize().unwrap_or(heading),
            tropism.try_normalize(),
        )
    })
}

/// Slack of the perception cone's bounding box, relative to its radius: far more than the
/// rounding of the cone test.
const BOX_MARGIN: f32 = 1e-3;

/// Bounding box, relative to its apex, of the cone of unit axis `axis`, half-angle with cosine
/// `cos_half` and radius `radius` (the cone test's volume): along each world axis e, the extreme
/// directions of the cone make the angle between e and the axis minus and plus the half-angle.
fn cone_bounds(axis: Vec3, cos_half: f32, radius: f32) -> (Vec3, Vec3) {
    let cos_half = cos_half.clamp(-1.0, 1.0);
    let sin_half = (1.0 - cos_half * cos_half).max(0.0).sqrt();
    let extent = |c: f32| {
        let c = c.clamp(-1.0, 1.0);
        let s = (1.0 - c * c).max(0.0).sqrt();
        let high = if c >= cos_half {
            1.0
        } else {
            c * cos_half + s * sin_half
        };
        let low = if -c >= cos_half {
            -1.0
        } else {
            c * cos_half - s * sin_half
        };
        (low.min(0.0) * radius, high.max(0.0) * radius)
    };
    let (x, y, z) = (extent(axis.x), extent(axis.y), extent(axis.z));
    (Vec3::new(x.0, y.0, z.0), Vec3::new(x.1, y.1, z.1))
}

/// Marks the points within the occupancy sphere of a new node as consumed.
pub(crate) fn consume(scratch: &mut Scratch, node_end: Vec3, r: f32) {
    scratch
        .point_grid
        .gather_near(node_end, node_end, r, &mut scratch.candidates);
    let alive = &mut scratch.point_alive;
    scratch
        .candidates
        .for_each_within(node_end, r, |pi, _, _| alive[pi as usize] = false);
}

/// End of an iteration: transient points are cleared, consumed persistent points removed.
pub(crate) fn finish_iteration(tree: &mut Tree, scratch: &Scratch) {
    let mut index = 0;
    tree.environment.attraction.points.retain(|p| {
        let keep = p.persistent && scratch.point_alive.get(index).copied().unwrap_or(true);
        index += 1;
        keep
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn the_cone_box_holds_every_point_the_cone_test_accepts_and_is_tight() {
        let mut rng = Rng::new(5);
        for case in 0..400 {
            let axis = if case % 4 == 0 {
                [Vec3::X, Vec3::NEG_Y, Vec3::Z, Vec3::Y][case / 4 % 4]
            } else {
                rng.unit_vector()
            };
            let cos_half = rng.range_f32(-0.5, 1.0);
            let radius = rng.range_f32(0.05, 2.0);
            let (lo, hi) = cone_bounds(axis, cos_half, radius);
            let margin = Vec3::splat(BOX_MARGIN * radius);
            for _ in 0..500 {
                let p = rng.in_unit_ball() * radius;
                let d = p.length();
                if d > 0.0 && p.dot(axis) >= cos_half * d {
                    assert!(
                        p.cmpge(lo - margin).all() && p.cmple(hi + margin).all(),
                        "{p} outside {lo}..{hi} (axis {axis}, cos {cos_half})"
                    );
                }
            }
            // The apex is always inside; the box reaches no further than the cone does.
            assert!(lo.cmple(Vec3::ZERO).all() && hi.cmpge(Vec3::ZERO).all());
            let tip = axis * radius;
            assert!(tip.cmpge(lo - margin).all() && tip.cmple(hi + margin).all());
            if cos_half > 0.9 {
                assert!((hi - lo).max_element() < 1.2 * radius, "{lo} {hi}");
            }
        }
    }
}
