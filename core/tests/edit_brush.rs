//! Done-when items 1–3 of issue 3: brushing and sketching follow the stroke, sketch-based
//! tropism steers headings, selective growth stays in the picked subtree; the depth constraint
//! holds for brushed points; and (issue 20, Done-when 4) the brush plane follows the device.

use glam::Vec3;
use sylva_core::edit::{
    BrushPlane, BrushSettings, BrushStroke, StrokeCamera, begin_selective_growth,
    end_selective_growth,
};
use sylva_core::environment::DepthConstraint;
use sylva_core::growth::Tree;
use sylva_core::species::Species;
use sylva_core::tree::NodeId;

const SEED: u64 = 0x5EED_0003;

fn oak() -> Species {
    Species::by_name("oak").expect("oak preset")
}

fn plane() -> BrushPlane {
    BrushPlane::new(Vec3::ZERO, Vec3::Z).expect("plane")
}

/// Camera distance of the strokes drawn on a fixed plane.
const STILL_DEPTH_M: f32 = 4.0;

/// A stroke drawn on `plane` from a still camera facing it.
fn still_stroke(plane: BrushPlane, settings: BrushSettings) -> (StrokeCamera, BrushStroke) {
    (
        StrokeCamera::facing(plane, STILL_DEPTH_M).expect("camera"),
        BrushStroke::new(STILL_DEPTH_M, settings).expect("stroke"),
    )
}

/// Draws `stroke_points` (on the plane `camera` faces) progressively, a few per iteration, then
/// lets growth finish.
fn brush(
    tree: &mut Tree,
    (camera, stroke): &mut (StrokeCamera, BrushStroke),
    stroke_points: &[(Vec3, f32)],
    per_iteration: usize,
    extra: usize,
) {
    let mut time = 0.0;
    for chunk in stroke_points.chunks(per_iteration) {
        for &(p, rho) in chunk {
            let placed = stroke
                .add_point(time, *camera, p, rho)
                .expect("stroke point");
            assert!(placed.distance(p) < 1e-4, "{p} placed at {placed}");
            time += 0.05;
        }
        stroke.iterate(tree);
    }
    for _ in 0..extra {
        stroke.iterate(tree);
    }
    tree.sanity_check().expect("tree stays sane");
}

fn arc(radius: f32, n: usize, base: Vec3) -> Vec<Vec3> {
    (0..=n)
        .map(|i| {
            let s = i as f32 / n as f32 * std::f32::consts::FRAC_PI_2;
            base + Vec3::new(radius * (1.0 - s.cos()), radius * s.sin(), 0.0)
        })
        .collect()
}

#[test]
fn a_thin_brush_sketches_one_axis_along_an_arc() {
    let mut tree = Tree::new(oak(), SEED);
    let l = tree.species.internode_length_m;
    let tip = tree.skeleton.internodes[0].end;
    let points: Vec<(Vec3, f32)> = arc(1.2, 40, tip).into_iter().map(|p| (p, 0.02)).collect();
    let mut stroke = still_stroke(plane(), BrushSettings::default());
    brush(&mut tree, &mut stroke, &points, 4, 6);
    // The axis: follow the main continuation from the seedling.
    let mut axis = vec![NodeId(0)];
    while let Some(next) = tree
        .skeleton
        .get(*axis.last().expect("non-empty"))
        .main_child
    {
        axis.push(next);
    }
    let deviation = axis
        .iter()
        .map(|&id| stroke.1.distance_to(tree.skeleton.get(id).end))
        .fold(0.0, f32::max);
    let reach = tree
        .skeleton
        .get(*axis.last().expect("non-empty"))
        .end
        .distance(points.last().expect("arc").0);
    let new = tree.skeleton.len() - 1;
    let off_axis = new + 1 - axis.len();
    println!(
        "sketch: axis of {} internodes, deviation {deviation:.3} m (limit {:.3}), end {reach:.3} m from the stroke end, {off_axis} of {new} new internodes off the axis",
        axis.len(),
        2.0 * l
    );
    assert!(
        axis.len() >= 12,
        "the axis has only {} internodes",
        axis.len()
    );
    assert!(
        deviation <= 2.0 * l,
        "axis strays {deviation} m from the arc"
    );
    assert!(
        reach <= 2.0 * l,
        "axis ends {reach} m from the end of the stroke"
    );
    assert!(
        off_axis * 5 <= new,
        "{off_axis} of {new} new internodes grew off the axis"
    );
}

#[test]
fn a_wide_brush_grows_a_crown_inside_the_swept_volume() {
    let mut tree = Tree::new(oak(), SEED);
    let l = tree.species.internode_length_m;
    let rho = 0.5;
    let tip = tree.skeleton.internodes[0].end;
    let mut points: Vec<(Vec3, f32)> = (0..=12)
        .map(|i| (tip + Vec3::Y * (0.15 * i as f32), rho))
        .collect();
    points.extend((1..=10).map(|i| {
        (
            tip + Vec3::new(0.12 * i as f32, 1.8 + 0.05 * i as f32, 0.0),
            rho,
        )
    }));
    let mut stroke = still_stroke(plane(), BrushSettings::default());
    brush(&mut tree, &mut stroke, &points, 2, 6);
    let new: Vec<_> = tree
        .skeleton
        .internodes
        .iter()
        .filter(|n| n.born_iteration > 0)
        .collect();
    let inside = new
        .iter()
        .filter(|n| stroke.1.distance_to(n.end) <= rho + l)
        .count();
    let fraction = inside as f32 / new.len() as f32;
    println!(
        "wide brush: {inside} of {} new internodes ({:.1}%) within ρ + l of the stroke",
        new.len(),
        fraction * 100.0
    );
    assert!(new.len() >= 60, "only {} internodes grew", new.len());
    assert!(
        fraction >= 0.95,
        "only {:.1}% inside the swept volume",
        fraction * 100.0
    );
}

fn mean_heading_angle(tree: &Tree, born_after: u32, direction: Vec3) -> (f32, usize) {
    let new: Vec<_> = tree
        .skeleton
        .internodes
        .iter()
        .filter(|n| n.born_iteration > born_after)
        .collect();
    let mean = new
        .iter()
        .map(|n| n.heading())
        .sum::<Vec3>()
        .normalize_or_zero();
    (mean.angle_between(direction).to_degrees(), new.len())
}

#[test]
fn sketch_tropism_turns_new_internodes_towards_the_stroke_direction() {
    // Oak as it comes: little tropism of its own (β = 0.1); the stroke's direction still shows.
    let species = oak();
    let run = |sketch_tropism: bool| {
        let mut tree = Tree::new(species.clone(), SEED);
        tree.grow(4, None);
        let born = tree.iteration;
        let top = tree
            .skeleton
            .internodes
            .iter()
            .map(|n| n.end.y)
            .fold(0.0, f32::max);
        let settings = BrushSettings {
            sketch_tropism,
            ..BrushSettings::default()
        };
        let mut stroke = still_stroke(plane(), settings);
        // Sideways strokes over the crown, drawn left to right.
        let points: Vec<(Vec3, f32)> = (0..=16)
            .map(|i| (Vec3::new(-0.8 + 0.1 * i as f32, top + 0.1, 0.0), 0.45))
            .collect();
        brush(&mut tree, &mut stroke, &points, 2, 4);
        mean_heading_angle(&tree, born, Vec3::X)
    };
    let (on, n_on) = run(true);
    let (off, n_off) = run(false);
    println!(
        "sketch tropism: mean heading {on:.1}° from the stroke with it ({n_on} internodes), {off:.1}° without ({n_off})"
    );
    assert!(
        n_on >= 20 && n_off >= 20,
        "too little growth: {n_on}, {n_off}"
    );
    assert!(
        on <= 20.0,
        "with sketch tropism the mean heading is {on}° from the stroke"
    );
}

#[test]
fn selective_growth_adds_internodes_only_in_the_picked_subtree() {
    let mut tree = Tree::new(oak(), SEED);
    tree.grow(6, None);
    let before = tree.skeleton.len();
    // Pick the tip of the lateral branch that reaches farthest out, and stroke outwards from it.
    let horizontal = |p: Vec3| Vec3::new(p.x, 0.0, p.z).length();
    let picked_branch = (1..before)
        .map(|i| NodeId(i as u32))
        .filter(|&id| tree.skeleton.get(id).order >= 1 && tree.skeleton.get(id).is_tip())
        .max_by(|&a, &b| {
            horizontal(tree.skeleton.get(a).end).total_cmp(&horizontal(tree.skeleton.get(b).end))
        })
        .expect("a lateral tip");
    let pick = tree.skeleton.get(picked_branch).end;
    let outwards = Vec3::new(pick.x, 0.0, pick.z).normalize();
    let mut unselective = tree.clone();
    let root = begin_selective_growth(&mut tree, pick, outwards).expect("a bud");
    let stroke_points: Vec<(Vec3, f32)> = (1..12)
        .map(|i| {
            (
                pick + outwards * (0.1 * i as f32) + Vec3::Y * (0.02 * i as f32),
                0.3,
            )
        })
        .collect();
    let normal = outwards.cross(Vec3::Y);
    let mut stroke = still_stroke(
        BrushPlane::new(pick, normal).expect("plane"),
        BrushSettings::default(),
    );
    let mut stroke_copy = stroke.clone();
    brush(&mut tree, &mut stroke, &stroke_points, 2, 3);
    end_selective_growth(&mut tree);
    let grown: Vec<NodeId> = (before..tree.skeleton.len())
        .map(|i| NodeId(i as u32))
        .collect();
    assert!(
        grown.len() >= 5,
        "selective growth grew only {} internodes",
        grown.len()
    );
    for &id in &grown {
        assert!(
            tree.skeleton.is_in_subtree(id, root),
            "internode {} grew outside the picked subtree",
            id.0
        );
    }
    // Without selection the same stroke feeds other branches too.
    brush(&mut unselective, &mut stroke_copy, &stroke_points, 2, 3);
    let outside = (before..unselective.skeleton.len())
        .filter(|&i| !unselective.skeleton.is_in_subtree(NodeId(i as u32), root))
        .count();
    println!(
        "selective: {} internodes, all in the subtree; unselective: {outside} outside it",
        grown.len()
    );
    assert!(
        outside > 0,
        "the control run grew nothing outside the subtree"
    );
}

#[test]
fn the_brush_adds_no_point_outside_the_depth_constraint() {
    let mut tree = Tree::new(oak(), SEED);
    tree.environment
        .set_depth_constraint(DepthConstraint::new(Vec3::Z, 0.1));
    let two_point_stroke = || {
        let (camera, mut stroke) = still_stroke(plane(), BrushSettings::default());
        for (time, p) in [
            (0.0, Vec3::new(0.0, 1.0, 0.0)),
            (0.1, Vec3::new(0.5, 1.5, 0.0)),
        ] {
            stroke.add_point(time, camera, p, 0.6).expect("point");
        }
        stroke
    };
    let mut stroke = two_point_stroke();
    let added = stroke.emit(&mut tree);
    assert!(added > 10, "only {added} points");
    // A resting brush keeps painting around where it rests.
    let dab = stroke.emit_dab(&mut tree);
    assert!(dab > 0, "a resting brush added no points");
    let rest = Vec3::new(0.5, 1.5, 0.0);
    let points = &tree.environment.attraction.points;
    assert_eq!(points.len(), added + dab);
    assert!(
        points
            .iter()
            .rev()
            .take(dab)
            .all(|p| p.position.distance(rest) <= 0.6 + 1e-5)
    );
    assert!(points.iter().all(|p| p.position.z.abs() <= 0.1));
    // The same stroke without the constraint paints the whole ball, far deeper.
    let mut free = Tree::new(oak(), SEED);
    let free_added = two_point_stroke().emit(&mut free);
    let deep = free
        .environment
        .attraction
        .points
        .iter()
        .filter(|p| p.position.z.abs() > 0.1)
        .count();
    println!("depth 0.1 m: {added} points kept; without it {free_added}, {deep} deeper than 0.1 m");
    assert!(deep * 2 > free_added, "only {deep} of {free_added} deeper");
}

/// Attraction points of a sideways stroke at 2 m, drawn while the camera at z = 3 m looking
/// along −Z moves forward by `forward_m` over the first half of the stroke and then holds.
/// Returns the points emitted during the second half and the stroke's last point.
fn second_half_of_a_sideways_stroke(forward_m: f32) -> (Vec<Vec3>, Vec3) {
    let mut tree = Tree::new(oak(), SEED);
    let view = Vec3::NEG_Z;
    let settings = BrushSettings {
        points_per_internode: 12.0,
        ..BrushSettings::default()
    };
    let mut stroke = BrushStroke::new(2.0, settings).expect("stroke");
    let n = 40;
    let mut second_half = Vec::new();
    for i in 0..=n {
        let progress = i as f32 / n as f32;
        let eye = Vec3::new(0.0, 1.5, 3.0) + view * forward_m * (2.0 * progress).min(1.0);
        let camera = StrokeCamera::new(eye, view).expect("camera");
        // The finger sweeps across the screen: the same ray in the camera's frame.
        let ray_in_camera = Vec3::new(-0.4 + 0.8 * progress, 0.1, -1.0);
        stroke
            .add_point(i as f64 / 30.0, camera, eye + ray_in_camera, 0.1)
            .expect("point");
        let before = tree.environment.attraction.len();
        stroke.emit(&mut tree);
        if i > n / 2 {
            let points = &tree.environment.attraction.points[before..];
            second_half.extend(points.iter().map(|p| p.position));
        }
    }
    let last = stroke.points().last().expect("points").position;
    (second_half, last)
}

#[test]
fn a_stroke_drawn_while_the_camera_moves_forward_half_a_metre_lands_half_a_metre_further() {
    let (still, still_last) = second_half_of_a_sideways_stroke(0.0);
    let (moved, moved_last) = second_half_of_a_sideways_stroke(0.5);
    let mean = |points: &[Vec3]| points.iter().sum::<Vec3>() / points.len() as f32;
    let shift = mean(&moved) - mean(&still);
    let along_view = -shift.z;
    println!(
        "camera forward 0.5 m: attraction points {along_view:.3} m further along the view ({} and {} points), sideways {:.3} m; last stroke point {:.4} m further",
        still.len(),
        moved.len(),
        shift.truncate().length(),
        still_last.z - moved_last.z
    );
    assert!(still.len() >= 60 && moved.len() >= 60, "too few points");
    assert!(
        (along_view - 0.5).abs() < 0.02,
        "the points moved {along_view} m along the view direction, not 0.5"
    );
    assert!(
        shift.truncate().length() < 0.02,
        "the points moved {shift} sideways"
    );
    assert!((moved_last - (still_last + Vec3::NEG_Z * 0.5)).length() < 1e-4);
    // At the stroke's depth from the camera that drew it: 2 m in front of the moved eye.
    assert!((moved_last.z - (3.0 - 0.5 - 2.0)).abs() < 1e-4);
}

#[test]
fn a_stroke_point_behind_the_camera_is_refused() {
    let camera = StrokeCamera::new(Vec3::new(0.0, 1.0, 3.0), Vec3::NEG_Z).expect("camera");
    let mut stroke = BrushStroke::new(2.0, BrushSettings::default()).expect("stroke");
    assert!(
        stroke
            .add_point(0.0, camera, Vec3::new(0.0, 1.0, 4.0), 0.1)
            .is_err()
    );
    assert!(BrushStroke::new(0.0, BrushSettings::default()).is_err());
    assert!(StrokeCamera::new(Vec3::ZERO, Vec3::ZERO).is_err());
    assert!(stroke.points().is_empty());
}
