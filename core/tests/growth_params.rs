//! Each parameter of the growth model has its documented effect, measured on grown trees against
//! a baseline grown from the same seeds.

mod support;

use glam::Vec3;
use support::mean_rise;
use sylva_core::Tree;
use sylva_core::growth::IterationStats;
use sylva_core::species::Species;

const SEEDS: [u64; 3] = [11, 12, 13];
const ITERATIONS: u32 = 9;

/// A compact test species: maple without age slow-down, short runs.
fn baseline() -> Species {
    let mut s = Species::by_name("maple").expect("maple preset");
    s.internode_length_m = 0.15;
    s.shoot_length_halving_age_years = 0.0;
    s.max_shoot_internodes = 4.0;
    s.shedding_threshold = 0.0;
    s
}

/// The baseline with laterals steered by gravitropism: set-point angle θ, an upward main axis
/// and the direction weights (α, β, γ).
fn gravitropic(theta_deg: f32, (alpha, beta, gamma): (f32, f32, f32)) -> Species {
    let mut s = baseline();
    s.gravitropism_angle_deg = theta_deg;
    s.upward_main_axis = true;
    (s.straightness, s.tropism_weight, s.environment_weight) = (alpha, beta, gamma);
    s
}

fn grow(species: &Species, seed: u64) -> (Tree, IterationStats) {
    let mut tree = Tree::new(species.clone(), seed);
    let stats = tree.grow(ITERATIONS, None);
    (tree, stats)
}

/// Mean of `f` over the seeds.
fn mean_over_seeds(species: &Species, f: impl Fn(&Tree, &IterationStats) -> f64) -> f64 {
    SEEDS
        .iter()
        .map(|&seed| {
            let (tree, stats) = grow(species, seed);
            f(&tree, &stats)
        })
        .sum::<f64>()
        / SEEDS.len() as f64
}

#[test]
fn higher_light_sensitivity_grows_fewer_shoots_per_iteration() {
    let mut low = baseline();
    low.light_sensitivity = 0.3;
    let mut high = baseline();
    high.light_sensitivity = 4.0;
    let shoots =
        |s: &Species| mean_over_seeds(s, |_, st| st.num_shoots as f64 / f64::from(ITERATIONS));
    let (a, b) = (shoots(&low), shoots(&high));
    assert!(
        b < a,
        "κ = 4 grew {b:.1} shoots per iteration, κ = 0.3 grew {a:.1}"
    );
}

/// Internodes on the trunk divided by the mean internodes per first-order lateral axis.
fn main_axis_dominance(tree: &Tree) -> f64 {
    let nodes = &tree.skeleton.internodes;
    let trunk = nodes.iter().filter(|n| n.order == 0).count() as f64;
    let first_order = nodes.iter().filter(|n| n.order == 1).count() as f64;
    let axes = nodes
        .iter()
        .filter(|n| n.order == 0)
        .map(|n| n.lateral_children.len())
        .sum::<usize>()
        .max(1) as f64;
    trunk / (first_order / axes).max(1e-9)
}

#[test]
fn apical_dominance_above_half_makes_the_main_axis_longer_relative_to_laterals() {
    let mut weak = baseline();
    weak.apical_dominance = 0.4;
    let mut strong = baseline();
    strong.apical_dominance = 0.65;
    let (a, b) = (
        mean_over_seeds(&weak, |t, _| main_axis_dominance(t)),
        mean_over_seeds(&strong, |t, _| main_axis_dominance(t)),
    );
    assert!(
        b > a,
        "trunk/lateral length ratio: λ = 0.65 → {b:.2}, λ = 0.4 → {a:.2}"
    );
}

/// Mean |H·Y| of lateral internodes: 0 horizontal, 1 vertical.
fn lateral_verticality(tree: &Tree) -> f64 {
    let laterals: Vec<f64> = tree
        .skeleton
        .internodes
        .iter()
        .filter(|n| n.order >= 1)
        .map(|n| f64::from(n.heading().y.abs()))
        .collect();
    laterals.iter().sum::<f64>() / laterals.len().max(1) as f64
}

#[test]
fn a_gravitropic_angle_of_90_degrees_makes_laterals_nearer_horizontal_than_0_degrees() {
    let mut up = baseline();
    up.gravitropism_angle_deg = 0.0;
    (up.straightness, up.tropism_weight, up.environment_weight) = (0.3, 0.4, 0.3);
    let mut flat = up.clone();
    flat.gravitropism_angle_deg = 90.0;
    let (a, b) = (
        mean_over_seeds(&up, |t, _| lateral_verticality(t)),
        mean_over_seeds(&flat, |t, _| lateral_verticality(t)),
    );
    assert!(
        b < a,
        "mean |H·Y| of laterals: θ = 90° → {b:.3}, θ = 0° → {a:.3}"
    );
}

#[test]
fn an_ascending_scaffold_angle_raises_the_main_limbs_while_the_twigs_still_hang() {
    let weeping = gravitropic(160.0, (0.3, 0.4, 0.3));
    let mut scaffold = weeping.clone();
    scaffold.scaffold_orders = 2;
    scaffold.scaffold_gravitropism_angle_deg = 30.0;
    let limbs = |s: &Species| mean_over_seeds(s, |t, _| f64::from(mean_rise(t, 1..=1)));
    let twigs = |s: &Species| mean_over_seeds(s, |t, _| f64::from(mean_rise(t, 2..=u32::MAX)));
    let (flat_limbs, raised_limbs) = (limbs(&weeping), limbs(&scaffold));
    assert!(
        raised_limbs > flat_limbs + 0.3 && raised_limbs > 0.3,
        "mean H·Y of first-order limbs: scaffold θ_s = 30° → {raised_limbs:.2}, \
         none → {flat_limbs:.2}"
    );
    let hanging = twigs(&scaffold);
    assert!(
        hanging < 0.0,
        "twigs above the scaffold's orders still hang (θ = 160°): mean H·Y {hanging:.2}"
    );
}

/// Internodes per cubic metre of the crown's bounding box.
fn crown_density(tree: &Tree) -> f64 {
    let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
    for n in &tree.skeleton.internodes {
        lo = lo.min(n.end);
        hi = hi.max(n.end);
    }
    let volume = f64::from(((hi - lo).max(Vec3::splat(0.1))).element_product());
    tree.skeleton.len() as f64 / volume
}

#[test]
fn a_larger_occupancy_radius_grows_a_sparser_crown() {
    let mut tight = baseline();
    tight.occupancy_radius_internodes = 1.0;
    let mut wide = baseline();
    wide.occupancy_radius_internodes = 3.0;
    let (a, b) = (
        mean_over_seeds(&tight, |t, _| crown_density(t)),
        mean_over_seeds(&wide, |t, _| crown_density(t)),
    );
    assert!(b < a, "internodes per m³: r = 3 → {b:.1}, r = 1 → {a:.1}");
}

#[test]
fn a_larger_maximum_shoot_length_grows_longer_shoots() {
    let mut short = baseline();
    short.max_shoot_internodes = 2.0;
    let mut long = baseline();
    long.max_shoot_internodes = 7.0;
    let per_shoot = |s: &Species| {
        mean_over_seeds(s, |_, st| {
            st.num_new_internodes as f64 / st.num_shoots.max(1) as f64
        })
    };
    let (a, b) = (per_shoot(&short), per_shoot(&long));
    assert!(
        b > a,
        "internodes per shoot: n_max = 7 → {b:.2}, n_max = 2 → {a:.2}"
    );
}

/// Fraction of grown lateral shoots (on clearly non-vertical parents) that leave from the upper
/// side of their parent axis.
fn upper_side_fraction(tree: &Tree) -> f64 {
    let nodes = &tree.skeleton.internodes;
    let (mut upper, mut total) = (0usize, 0usize);
    for parent in nodes {
        let h = parent.heading();
        if h.y.abs() > 0.8 {
            continue;
        }
        let Some(v) = (Vec3::Y - h.y * h).try_normalize() else {
            continue;
        };
        for c in &parent.lateral_children {
            let d = nodes[c.index()].heading();
            total += 1;
            upper += usize::from(d.dot(v) > 0.0);
        }
    }
    upper as f64 / total.max(1) as f64
}

#[test]
fn shifting_the_gravimorphism_ellipse_up_makes_more_upper_side_laterals_grow() {
    let mut down = gravitropic(90.0, (0.4, 0.3, 0.3));
    down.gravimorphism.vertical_offset = -0.7;
    let mut up = down.clone();
    up.gravimorphism.vertical_offset = 0.7;
    let (a, b) = (
        mean_over_seeds(&down, |t, _| upper_side_fraction(t)),
        mean_over_seeds(&up, |t, _| upper_side_fraction(t)),
    );
    assert!(
        b > a,
        "upper-side laterals: e_v = +0.7 → {b:.2}, e_v = −0.7 → {a:.2}"
    );
}

/// Mean angle (radians) between successive trunk internodes.
fn trunk_turning(tree: &Tree) -> f64 {
    let nodes = &tree.skeleton.internodes;
    let angles: Vec<f64> = nodes
        .iter()
        .filter(|n| n.order == 0)
        .filter_map(|n| n.parent.map(|p| (n.heading(), nodes[p.index()].heading())))
        .map(|(a, b)| f64::from(a.dot(b).clamp(-1.0, 1.0).acos()))
        .collect();
    angles.iter().sum::<f64>() / angles.len().max(1) as f64
}

#[test]
fn a_positive_deflection_angle_makes_the_main_axis_deviate() {
    let mut straight = baseline();
    straight.deflection_angle_deg = 0.0;
    straight.upward_main_axis = false;
    straight.phyllotaxis = sylva_core::species::Phyllotaxis::Spiral;
    straight.buds_per_whorl = 1;
    let mut deflected = straight.clone();
    deflected.deflection_angle_deg = 35.0;
    let (a, b) = (
        mean_over_seeds(&straight, |t, _| trunk_turning(t)),
        mean_over_seeds(&deflected, |t, _| trunk_turning(t)),
    );
    assert!(
        b > a,
        "mean trunk turning: δ = 35° → {b:.3} rad, δ = 0 → {a:.3} rad"
    );
}

#[test]
fn a_larger_shedding_threshold_sheds_more() {
    let mut keep = baseline();
    keep.shedding_threshold = 0.005;
    let mut shed = baseline();
    shed.shedding_threshold = 0.3;
    let shed_count = |s: &Species| mean_over_seeds(s, |_, st| st.num_shed_internodes as f64);
    let (a, b) = (shed_count(&keep), shed_count(&shed));
    assert!(
        b > a,
        "internodes shed: Th = 0.3 → {b:.0}, Th = 0.005 → {a:.0}"
    );
}
