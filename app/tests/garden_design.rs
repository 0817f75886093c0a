//! The design's garden driven by its events, without footage: "Plant another tree" and a tap on
//! the ground plant a second tree, a tap on the first selects it again, the years slider grows
//! both, a deletion is undone, and undo walks back through the garden steps to the same garden
//! files.

use glam::{Vec2, Vec3};
use sylva_app::render::{GroundPlane, Intrinsics, ViewCamera};
use sylva_app::state::{DesignState, InputEvent, Parameters, TouchPhase};

fn tap(design: &mut DesignState, pixel: Vec2) {
    for phase in [TouchPhase::Start, TouchPhase::End] {
        design.apply(&InputEvent::Touch {
            phase,
            id: 0,
            x: pixel.x,
            y: pixel.y,
        });
    }
}

fn with_years(design: &DesignState, years: f32) -> InputEvent {
    let mut parameters = design.params.clone();
    parameters.years = years;
    InputEvent::Parameters { parameters }
}

#[test]
fn a_second_tree_is_planted_selected_grown_with_the_first_deleted_and_brought_back_by_undo() {
    let species = sylva_core::species::Species::by_name("birch").expect("preset");
    let mut design = DesignState::new(7, Parameters::for_species(&species));
    design.apply(&with_years(&design, 4.0));
    let camera = ViewCamera::looking_at(
        Intrinsics::from_fov(640, 480, 60f32.to_radians()),
        Vec3::new(1.0, 1.5, 7.0),
        Vec3::new(1.0, 1.0, 0.0),
    );
    design.ground = Some(GroundPlane::default());
    design.advance_frame(Some(camera), 0.0, 1.0 / 30.0);
    let pixel = |p: Vec3| camera.pixel_from_world(p).expect("in view");
    assert_eq!(design.num_trees(), 1);
    let alone = design.tree.to_json_bytes().expect("saves");

    // A tap without "Plant another tree" plants nothing.
    tap(&mut design, pixel(Vec3::new(2.5, 0.0, 0.0)));
    assert_eq!(design.num_trees(), 1);
    design.apply(&InputEvent::PlantAnother {
        species: "birch".into(),
    });
    tap(&mut design, pixel(Vec3::new(2.5, 0.0, 0.0)));
    assert_eq!(design.num_trees(), 2, "the armed tap plants a second tree");
    assert_eq!(design.selected_tree(), 1, "the new tree is selected");
    assert!(design.garden.planting.is_none(), "one tree per arming");
    let base = design
        .world_from_tree
        .expect("placed")
        .transform_point3(Vec3::ZERO);
    assert!(
        base.distance(Vec3::new(2.5, 0.0, 0.0)) < 0.01,
        "planted at {base}"
    );
    let expected_iteration = species.iterations_for_years(4.0);
    assert!(
        design.tree.iteration >= expected_iteration,
        "grown to the garden's age"
    );
    let others = design.other_trees();
    assert_eq!(others.len(), 1);
    assert_eq!(
        others[0].tree.to_json_bytes().expect("saves"),
        alone,
        "planting another leaves the first tree as it was"
    );

    // A tap on the first tree's trunk selects it again.
    tap(&mut design, pixel(Vec3::new(0.0, 0.8, 0.0)));
    assert_eq!(design.selected_tree(), 0, "the tap selects the first tree");
    assert_eq!(design.tree.to_json_bytes().expect("saves"), alone);

    let before_years = design.garden_sha256().expect("a garden");
    design.apply(&with_years(&design, 6.0));
    let six = species.iterations_for_years(6.0);
    assert!(design.tree.iteration >= six, "the selected tree grew");
    assert!(
        design.other_trees()[0].tree.iteration >= six,
        "the other tree grew with it"
    );
    let grown = design.garden_sha256().expect("a garden");

    design.apply(&InputEvent::DeleteTree);
    assert_eq!(design.num_trees(), 1, "deleted");
    design.apply(&InputEvent::Undo);
    assert_eq!(design.num_trees(), 2, "the deletion undone");
    assert_eq!(design.garden_sha256().as_deref(), Some(grown.as_str()));
    design.apply(&InputEvent::Undo);
    assert_eq!(
        design.garden_sha256().as_deref(),
        Some(before_years.as_str()),
        "the years change undone"
    );
    // Back through the selection and the planting to the single tree.
    design.apply(&InputEvent::Undo);
    assert_eq!(design.selected_tree(), 1);
    design.apply(&InputEvent::Undo);
    assert_eq!(design.num_trees(), 1);
    assert!(!design.has_garden());
    assert_eq!(design.tree.to_json_bytes().expect("saves"), alone);

    // Going back with the slider restores the garden kept at that age.
    design.apply(&InputEvent::PlantAnother {
        species: "maple".into(),
    });
    tap(&mut design, pixel(Vec3::new(2.5, 0.0, 0.0)));
    let at_four = design.garden_sha256().expect("a garden");
    design.apply(&with_years(&design, 7.0));
    design.apply(&with_years(&design, 4.0));
    assert_eq!(design.garden_sha256().as_deref(), Some(at_four.as_str()));
}
