//! A clustered stand (issue #24, Done when 3; Longay 2014 Fig. 6.24): grown together, the crowns
//! spread more evenly than the trunk bases stand, so the Ripley excess K(5 m) − π·25 of the crown
//! centroids is closer to 0 than that of the bases, seed after seed; grown alone they are not.

use glam::Vec2;
use sylva_core::garden::{Garden, Layout, Planting, PlantingFile, RIPLEY_RADIUS_M, ripley_excess};
use sylva_core::species::Species;

const PLOT_M: f32 = 30.0;

fn clustered_stand(seed: u64, competition: bool) -> Garden {
    let file = PlantingFile {
        plantings: vec![Planting::Stand {
            species: vec!["birch".into(), "maple".into(), "oak".into()],
            width_m: PLOT_M,
            depth_m: PLOT_M,
            count: 60,
            layout: Layout::Clustered,
            age_years: 0.0,
            seed,
        }],
    };
    let by_name = |name: &str| Species::by_name(name).map_err(|e| e.to_string());
    let mut garden = Garden::plant(file.trees(&by_name).expect("valid")).expect("plants");
    garden.competition = competition;
    garden.grow_years(12.0);
    garden
}

/// (bases, crowns) Ripley excess at 5 m on the plot.
fn excesses(garden: &Garden) -> (f32, f32) {
    let crowns = garden.crowns();
    let (lo, hi) = (Vec2::splat(-0.5 * PLOT_M), Vec2::splat(0.5 * PLOT_M));
    let bases: Vec<Vec2> = crowns
        .iter()
        .map(|c| Vec2::new(c.base.x, c.base.z))
        .collect();
    let centres: Vec<Vec2> = crowns
        .iter()
        .map(|c| Vec2::new(c.centroid.x, c.centroid.z))
        .collect();
    (
        ripley_excess(&bases, lo, hi, RIPLEY_RADIUS_M).expect("bases estimate"),
        ripley_excess(&centres, lo, hi, RIPLEY_RADIUS_M).expect("crowns estimate"),
    )
}

#[test]
fn the_crowns_of_a_clustered_stand_spread_more_evenly_than_its_trunks_stand() {
    for seed in 1..=5 {
        let (bases, crowns) = excesses(&clustered_stand(seed, true));
        let (_, crowns_alone) = excesses(&clustered_stand(seed, false));
        println!(
            "seed {seed}: Ripley excess bases {bases:.1}, crowns together {crowns:.1}, crowns alone {crowns_alone:.1}"
        );
        assert!(
            bases > 0.0,
            "seed {seed}: a clustered stand, excess {bases}"
        );
        assert!(
            crowns.abs() < bases.abs(),
            "seed {seed}: crowns {crowns:.1} not closer to 0 than bases {bases:.1}"
        );
    }
}
