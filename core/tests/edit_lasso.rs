//! Done-when item 4 of issue 3: a lasso of a circle grows a crown whose silhouette on the lasso
//! plane stays inside the circle enlarged by one internode length; and the tree's depth
//! constraint (issue 20) holds for lassoed points.

use glam::{Vec2, Vec3};
use sylva_core::edit::Lasso;
use sylva_core::environment::DepthConstraint;
use sylva_core::growth::{StepOptions, Tree};
use sylva_core::species::Species;

#[test]
fn a_circular_lasso_grows_a_crown_inside_the_circle() {
    let species = Species::by_name("maple").expect("maple preset");
    let mut tree = Tree::new(species, 0x1A550);
    let l = tree.species.internode_length_m;
    // A circle on the plane z = 0 that holds the seedling.
    let (centre, radius) = (Vec2::new(0.0, 1.1), 1.2);
    let outline: Vec<Vec2> = (0..72)
        .map(|i| centre + Vec2::from_angle(i as f32 / 72.0 * std::f32::consts::TAU) * radius)
        .collect();
    let lasso = Lasso::new(Vec3::ZERO, Vec3::X, Vec3::Y, outline).expect("valid lasso");
    let envelope = lasso.envelope(96);
    let added = envelope.add_points_to(&mut tree, 1500);
    assert_eq!(added, 1500);
    for _ in 0..30 {
        let stats = tree.step(StepOptions {
            autonomous: false,
            scene: None,
        });
        if stats.num_new_internodes == 0 {
            break;
        }
    }
    tree.sanity_check().expect("sane");
    let inside = tree
        .skeleton
        .internodes
        .iter()
        .filter(|n| Vec2::new(n.end.x, n.end.y).distance(centre) <= radius + l)
        .count();
    let total = tree.skeleton.len();
    let fraction = inside as f32 / total as f32;
    let depth = tree
        .skeleton
        .internodes
        .iter()
        .map(|n| n.end.z.abs())
        .fold(0.0, f32::max);
    println!(
        "lasso: {inside} of {total} internodes ({:.1}%) inside the circle + l; crown depth ±{depth:.2} m",
        fraction * 100.0
    );
    assert!(total >= 150, "only {total} internodes grew into the lasso");
    assert!(
        fraction >= 0.95,
        "only {:.1}% of internodes inside",
        fraction * 100.0
    );
    // Teddy inflation: the crown is round in depth too, not flat.
    assert!(depth > 0.5 * radius, "crown depth only {depth} m");
}

#[test]
fn a_lasso_adds_no_point_outside_the_depth_constraint() {
    let species = Species::by_name("maple").expect("maple preset");
    let outline: Vec<Vec2> = (0..48)
        .map(|i| Vec2::new(0.0, 1.1) + Vec2::from_angle(i as f32 / 48.0 * std::f32::consts::TAU))
        .collect();
    let lasso = Lasso::new(Vec3::ZERO, Vec3::X, Vec3::Y, outline).expect("valid lasso");
    let envelope = lasso.envelope(64);
    let mut free = Tree::new(species.clone(), 7);
    let free_added = envelope.add_points_to(&mut free, 1000);
    let mut flat = Tree::new(species, 7);
    let slab = DepthConstraint::new(Vec3::Z, 0.2).expect("valid constraint");
    flat.environment.set_depth_constraint(Some(slab));
    let flat_added = envelope.add_points_to(&mut flat, 1000);
    let points = &flat.environment.attraction.points;
    println!("lasso: {free_added} points free, {flat_added} within 0.2 m of the plane");
    assert_eq!(free_added, 1000);
    assert_eq!(points.len(), flat_added);
    assert!(points.iter().all(|p| p.position.z.abs() <= 0.2));
    // A ball-like envelope of radius 1 m: about a third of its volume lies within 0.2 m.
    assert!(
        (150..600).contains(&flat_added),
        "{flat_added} of 1000 points within the slab"
    );
}
