//! The season control beside the years slider: it redraws the design in its season (winter
//! strips a deciduous tree of its leaves, never of its wood), it is part of the parameters a
//! session records, and sessions from before seasons load as summer.

use sylva_app::state::{DesignState, InputEvent, Parameters};
use sylva_app::tree_model::TreeMesher;
use sylva_core::geometry::Season;

fn with(state: &DesignState, years: f32, season: Season) -> InputEvent {
    InputEvent::Parameters {
        parameters: Parameters {
            years,
            season,
            ..state.params.clone()
        },
    }
}

#[test]
fn the_season_control_redraws_the_design_leafless_in_winter_without_touching_the_tree() {
    let mut state = DesignState::new(7, Parameters::default());
    state.apply(&with(&state, 6.0, Season::Summer));
    let grown = state.tree_sha256();
    let mut mesher = TreeMesher::default();
    let summer = mesher.mesh_in(&state.tree, state.params.season).clone();
    assert!(!summer.cards().is_empty(), "a summer maple has leaves");

    let revision = state.revision;
    state.apply(&with(&state, 6.0, Season::Winter));
    assert_eq!(state.params.season, Season::Winter);
    assert!(state.revision > revision, "the design is drawn anew");
    assert_eq!(state.tree_sha256(), grown, "the tree itself is unchanged");
    let winter = mesher.mesh_in(&state.tree, state.params.season).clone();
    assert!(winter.cards().is_empty(), "a winter maple is leafless");
    assert_eq!(winter.branches().len(), summer.branches().len());

    // The drawn colours are the species' in its season: a red-orange autumn maple.
    state.apply(&with(&state, 6.0, Season::Autumn));
    let autumn = mesher.mesh_in(&state.tree, state.params.season).clone();
    let [r, g, b] = autumn.look.leaf_color;
    assert!(
        r > 3.0 * g && r > 3.0 * b,
        "autumn maple leaves {:?}",
        autumn.look.leaf_color
    );
    assert!(
        summer.look.leaf_color[1] > summer.look.leaf_color[0],
        "summer maple leaves are green"
    );
    assert_eq!(autumn.look.bark_color, summer.look.bark_color);
    state.apply(&with(&state, 6.0, Season::Winter));

    // Another species keeps the season.
    state.apply(&InputEvent::Parameters {
        parameters: Parameters {
            species: "norway_spruce".into(),
            ..state.params.clone()
        },
    });
    assert_eq!(state.params.season, Season::Winter);
    state.apply(&with(&state, 6.0, Season::Winter));
    let spruce = mesher.mesh_in(&state.tree, state.params.season);
    assert!(!spruce.cards().is_empty(), "the spruce keeps its needles");
}

#[test]
fn sessions_record_the_season_and_old_sessions_load_as_summer() {
    let summer = Parameters::default();
    let json = serde_json::to_value(&summer).expect("serializes");
    assert!(
        json.get("season").is_none(),
        "summer is written as before: {json}"
    );
    let old: Parameters = serde_json::from_value(json).expect("an old session's parameters");
    assert_eq!(old.season, Season::Summer);
    let autumn = Parameters {
        season: Season::Autumn,
        ..Parameters::default()
    };
    let json = serde_json::to_string(&autumn).expect("serializes");
    assert!(json.contains("\"season\":\"autumn\""), "{json}");
    let back: Parameters = serde_json::from_str(&json).expect("reads back");
    assert_eq!(back, autumn);
    assert!(back.check().is_ok());
}
