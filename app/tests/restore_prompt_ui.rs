//! The "Earlier design" prompt (issue 21): with an earlier autosave offered, "Restore" replaces
//! the design's tree by it (same tree hash, where it stood) and closes the prompt; "Dismiss"
//! closes it and leaves the design as it was.

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use sha2::Digest;
use sylva_app::autosave::{PreviousAutosave, restore_prompt_ui};
use sylva_app::state::{DesignState, Parameters};
use sylva_core::Tree;
use sylva_core::species::Species;

struct App {
    offer: Option<PreviousAutosave>,
    design: DesignState,
}

fn harness(offer: PreviousAutosave) -> Harness<'static, App> {
    let app = App {
        offer: Some(offer),
        design: DesignState::unplanted(2, Parameters::default()),
    };
    let mut harness = Harness::new_ui_state(
        |ui, app: &mut App| {
            let mut events = Vec::new();
            restore_prompt_ui(ui, &mut app.offer, &mut events);
            for e in events {
                app.design.apply(&e);
            }
        },
        app,
    );
    harness.set_size(egui::vec2(900.0, 500.0));
    harness.run();
    harness
}

/// An autosave of a grown maple standing 2 m to the side, as the window leaves it.
fn earlier_autosave(dir: &std::path::Path) -> (PreviousAutosave, String) {
    let mut tree = Tree::new(Species::by_name("maple").expect("preset"), 9);
    tree.grow(6, None);
    let tree_path = dir.join("last-session.1.tree.json");
    tree.save(&tree_path).expect("save");
    std::fs::write(
        dir.join("last-session.1.tree.placement.json"),
        r#"{"world_from_tree":[1,0,0,0,1,0,0,0,1,2,0,0]}"#,
    )
    .expect("placement");
    let hash = format!(
        "{:x}",
        sha2::Sha256::digest(std::fs::read(&tree_path).expect("read"))
    );
    let offer = PreviousAutosave {
        tree_path,
        num_internodes: tree.skeleton.len(),
        age_years: tree.age_years(),
    };
    (offer, hash)
}

#[test]
fn restore_brings_the_earlier_tree_back_where_it_stood_and_closes_the_prompt() {
    let dir = tempfile::tempdir().expect("dir");
    let (offer, hash) = earlier_autosave(dir.path());
    let mut h = harness(offer);
    h.get_by_label("Restore").click();
    h.run();
    let app = h.into_state();
    assert!(app.offer.is_none(), "the prompt closes");
    assert_eq!(app.design.tree_sha256(), hash, "the same tree");
    assert_eq!(app.design.tree.species.name, "maple");
    let base = app
        .design
        .world_from_tree
        .expect("planted where it stood")
        .translation;
    assert!((base.x - 2.0).abs() < 1e-6, "{base}");
}

#[test]
fn dismiss_closes_the_prompt_and_keeps_the_design() {
    let dir = tempfile::tempdir().expect("dir");
    let (offer, hash) = earlier_autosave(dir.path());
    let mut h = harness(offer);
    let before = h.state().design.tree_sha256();
    h.get_by_label("Dismiss").click();
    h.run();
    let app = h.into_state();
    assert!(app.offer.is_none());
    assert_eq!(app.design.tree_sha256(), before);
    assert_ne!(app.design.tree_sha256(), hash);
    assert!(
        dir.path().join("last-session.1.tree.json").exists(),
        "the autosave stays"
    );
}
