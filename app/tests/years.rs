//! The years slider grows the design to an age and ungrows it back, as one undoable step.

use sylva_app::state::{DesignState, InputEvent, Parameters};

fn with_years(state: &DesignState, years: f32) -> InputEvent {
    InputEvent::Parameters {
        parameters: Parameters {
            years,
            ..state.params.clone()
        },
    }
}

#[test]
fn the_years_slider_grows_to_an_age_ungrows_back_and_undoes() {
    let mut state = DesignState::new(7, Parameters::default());
    let seedling = state.tree_sha256();
    let planted = state.tree.skeleton.len();

    state.apply(&with_years(&state, 8.0));
    let at_8 = state.tree.skeleton.len();
    assert!(
        (state.tree.age_years() - 8.0).abs() <= state.tree.species.years_per_iteration,
        "age {} after asking for 8 years",
        state.tree.age_years()
    );
    assert!(
        at_8 > planted * 4,
        "8 years grew {planted} -> {at_8} internodes"
    );
    let sha_at_8 = state.tree_sha256();

    state.apply(&with_years(&state, 4.0));
    let at_4 = state.tree.skeleton.len();
    assert!(at_4 < at_8 && at_4 > planted, "4 years: {at_4} internodes");
    assert!((state.tree.age_years() - 4.0).abs() <= state.tree.species.years_per_iteration);

    // Forward again: the same tree as the first time at 8 years (same seed, same steps).
    state.apply(&with_years(&state, 8.0));
    assert_eq!(state.tree_sha256(), sha_at_8);

    // Undo walks back through the slider moves to the seedling.
    for _ in 0..3 {
        state.apply(&InputEvent::Undo);
    }
    assert_eq!(state.tree_sha256(), seedling);
}
