//! Growth gives the same tree on any number of threads: the parallel passes (occupancy,
//! perception, bud light) write per point and per node and never sum across threads.

use glam::Vec3;
use sylva_core::Tree;
use sylva_core::growth::StepOptions;
use sylva_core::rng::Rng;
use sylva_core::species::Species;

/// A dense maple (short internodes, long shoots) grown for `iterations`, then one brush-guided
/// iteration towards points above its crown; the saved bytes of both.
fn grow_and_brush(iterations: u32) -> (Vec<u8>, Vec<u8>, usize) {
    let mut species = Species::by_name("maple").expect("maple preset");
    species.internode_length_m = 0.04;
    species.max_shoot_internodes = 12.0;
    species.shoot_length_halving_age_years = 0.0;
    let mut tree = Tree::new(species, 7);
    tree.grow(iterations, None);
    let grown = tree.to_json_bytes().expect("tree serializes");
    let top = Vec3::new(0.0, tree.metrics().height_m + 0.2, 0.0);
    let mut rng = Rng::new(11);
    for _ in 0..300 {
        tree.environment
            .attraction
            .add_persistent(top + rng.in_unit_ball() * 0.4);
    }
    tree.step(StepOptions {
        autonomous: false,
        scene: None,
    });
    let brushed = tree.to_json_bytes().expect("tree serializes");
    (grown, brushed, tree.skeleton.len())
}

fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(f)
}

#[test]
fn a_tree_grown_and_brushed_on_one_two_or_eight_threads_is_byte_for_byte_the_same() {
    let (grown, brushed, internodes) = on_threads(1, || grow_and_brush(14));
    // Big enough that the passes split into many blocks.
    assert!(internodes > 20_000, "{internodes} internodes");
    for threads in [2, 8] {
        let (g, b, _) = on_threads(threads, || grow_and_brush(14));
        assert!(g == grown, "grown tree differs on {threads} threads");
        assert!(b == brushed, "brushed tree differs on {threads} threads");
    }
}
