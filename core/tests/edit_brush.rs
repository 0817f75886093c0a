//! Done-when items 1–3 of issue 3: brushing and sketching follow the stroke, sketch-based
//! tropism steers headings, selective growth stays in the picked subtree; and the depth
//! constraint.

use glam::Vec3;
use sylva_core::edit::{
    BrushPlane, BrushSettings, BrushStroke, apply_depth_constraint, begin_selective_growth,
    end_selective_growth,
};
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

/// Draws `stroke_points` progressively, a few per iteration, then lets growth finish.
fn brush(
    tree: &mut Tree,
    stroke: &mut BrushStroke,
    stroke_points: &[(Vec3, f32)],
    per_iteration: usize,
    extra: usize,
) {
    let mut time = 0.0;
    for chunk in stroke_points.chunks(per_iteration) {
        for &(p, rho) in chunk {
            stroke.add_point(time, p, rho).expect("stroke point");
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
    let mut stroke = BrushStroke::new(plane(), BrushSettings::default());
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
        .map(|&id| stroke.distance_to(tree.skeleton.get(id).end))
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
    let mut stroke = BrushStroke::new(plane(), BrushSettings::default());
    brush(&mut tree, &mut stroke, &points, 2, 6);
    let new: Vec<_> = tree
        .skeleton
        .internodes
        .iter()
        .filter(|n| n.born_iteration > 0)
        .collect();
    let inside = new
        .iter()
        .filter(|n| stroke.distance_to(n.end) <= rho + l)
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
        let mut stroke = BrushStroke::new(plane(), settings);
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
    let mut stroke = BrushStroke::new(
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
fn the_depth_constraint_keeps_points_near_the_plane_through_the_base() {
    let mut tree = Tree::new(oak(), SEED);
    let settings = BrushSettings {
        depth_limit_m: Some(0.1),
        ..BrushSettings::default()
    };
    let mut stroke = BrushStroke::new(plane(), settings);
    stroke
        .add_point(0.0, Vec3::new(0.0, 1.0, 0.0), 0.6)
        .expect("point");
    stroke
        .add_point(0.1, Vec3::new(0.5, 1.5, 0.0), 0.6)
        .expect("point");
    let added = stroke.emit(&mut tree);
    assert!(added > 10, "only {added} points");
    // A resting brush keeps painting around where it rests.
    let dab = stroke.emit_dab(&mut tree);
    assert!(dab > 0, "a resting brush added no points");
    let rest = Vec3::new(0.5, 1.5, 0.0);
    let last: Vec<_> = tree
        .environment
        .attraction
        .points
        .iter()
        .rev()
        .take(dab)
        .collect();
    assert!(last.iter().all(|p| p.position.distance(rest) <= 0.6 + 1e-5));
    assert!(
        tree.environment
            .attraction
            .points
            .iter()
            .all(|p| p.position.z.abs() <= 0.1)
    );
    for i in 0..50 {
        tree.environment
            .attraction
            .add_persistent(Vec3::new(0.0, 1.0, -1.0 + 0.04 * i as f32));
    }
    let removed = apply_depth_constraint(&mut tree, Vec3::Z, 0.1);
    assert!(removed >= 40, "removed {removed}");
    assert!(
        tree.environment
            .attraction
            .points
            .iter()
            .all(|p| p.position.z.abs() <= 0.1 + 1e-6)
    );
}
