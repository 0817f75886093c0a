//! The app's Recreate mode on `test-data/tree_a`, through a session recorded with the app's own
//! tracker and design state (`app/tests/sessions/recreate_tree_a.session.json`, re-recorded with
//! `SYLVA_BLESS=1`): tap the trunk base and trace the crown in frame 30, walk on and trace it in
//! frame 150 (marks drawn from the true masks as a user would), pick the birch, "Grow to fit",
//! show the overlay outline-only, prune a main limb with the prune tool, +10 years. Replaying it
//! gives the committed `tree_sha256`; the overlay in outline mode over frame 150 (the traced
//! outline and the model over the real tree) is the golden `recreate_overlay_outline.png`. With
//! `SYLVA_DOCS=1` it also writes the README's pictures (`docs/images/recreate-*.png`).

mod expected;
mod recreate_marks;

use std::path::{Path, PathBuf};

use glam::Vec2;
use sylva_app::demo_script::{scripted_session, tap};
use sylva_app::footage::Footage;
use sylva_app::session::{Session, replay};
use sylva_app::state::{DesignState, InputEvent, Parameters, RecreateAction, Tool, TouchPhase};

use recreate_marks::{base_tap, mask, traced_outline};

/// Frame steps of the user's actions (each acts on the frame shown before it).
const FIRST_MARKS_STEP: usize = 31;
const SECOND_MARKS_STEP: usize = 151;
const PRUNE_STEP: usize = 153;
const YEARS_STEP: usize = 160;

fn app_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn footage_dir() -> PathBuf {
    app_dir().join("../test-data/tree_a")
}

fn session_path() -> PathBuf {
    app_dir().join("tests/sessions/recreate_tree_a.session.json")
}

fn recreate(action: RecreateAction) -> InputEvent {
    InputEvent::Recreate { action }
}

fn touch(phase: TouchPhase, p: [f64; 2]) -> InputEvent {
    InputEvent::Touch {
        phase,
        id: 7,
        x: p[0] as f32,
        y: p[1] as f32,
    }
}

/// A finger tracing `outline`: down on its first point, through the others, up on the last.
fn trace(outline: &[[f64; 2]]) -> Vec<InputEvent> {
    let mut events = vec![touch(TouchPhase::Start, outline[0])];
    events.extend(outline[1..].iter().map(|&p| touch(TouchPhase::Move, p)));
    events.push(touch(TouchPhase::End, outline[outline.len() - 1]));
    events
}

/// The largest main limb of the tree (a lateral of the trunk, at most a quarter of the tree):
/// the middle of its first internodes, in the shown camera's pixels.
fn main_limb_pixel(state: &DesignState) -> Option<Vec2> {
    let tree = &state.tree;
    let nodes = &tree.skeleton.internodes;
    let size = |id: sylva_core::NodeId| {
        tree.skeleton
            .subtree_flags(&[id])
            .iter()
            .filter(|&&f| f)
            .count()
    };
    let limb = nodes
        .iter()
        .filter(|n| n.order == 0)
        .flat_map(|n| n.lateral_children.iter().copied())
        .filter(|&id| size(id) * 4 <= nodes.len())
        .max_by_key(|&id| size(id))?;
    let camera = state.camera?;
    let point = nodes[limb.index()].end;
    camera
        .intrinsics
        .pixel_from_camera(camera.camera_from_world().transform_point3(point))
}

fn record() -> Session {
    let footage = Footage::open(&footage_dir()).expect("tree_a footage");
    let base = base_tap(&mask(&footage_dir(), 30));
    let first = traced_outline(&mask(&footage_dir(), 30), 30);
    let second = traced_outline(&mask(&footage_dir(), 150), 150);
    scripted_session(
        &footage,
        PathBuf::from("../../../test-data/tree_a"),
        Parameters::default(),
        |step, state| match step {
            FIRST_MARKS_STEP => {
                let mut events = vec![recreate(RecreateAction::Start)];
                let pixel = Vec2::new(base[0] as f32, base[1] as f32);
                events.extend(tap(pixel));
                events.extend(trace(&first));
                events
            }
            SECOND_MARKS_STEP => {
                let mut events = trace(&second);
                events.push(recreate(RecreateAction::Species {
                    species: Some("birch".into()),
                }));
                events.push(recreate(RecreateAction::GrowToFit));
                events.push(recreate(RecreateAction::Overlay {
                    opacity: 0.6,
                    outline_only: true,
                }));
                events
            }
            PRUNE_STEP => {
                let mut events = vec![InputEvent::Tool { tool: Tool::Prune }];
                if let Some(pixel) = main_limb_pixel(state) {
                    events.extend(tap(pixel));
                }
                events
            }
            YEARS_STEP => vec![InputEvent::Parameters {
                parameters: Parameters {
                    years: state.params.years + 10.0,
                    ..state.params.clone()
                },
            }],
            _ => Vec::new(),
        },
    )
    .expect("scripted session")
}

/// What the replay saw at the steps that matter.
#[derive(Default)]
struct Seen {
    internodes: Vec<usize>,
    outline_overlay: Option<image::RgbaImage>,
    first_view: Option<image::RgbaImage>,
    filled_overlay: Option<image::RgbaImage>,
    ten_years: Option<image::RgbaImage>,
    result_line: Option<String>,
}

fn picture(state: &DesignState, step: usize, outline_only: bool) -> Option<image::RgbaImage> {
    let footage = Footage::open(&footage_dir()).ok()?;
    let mut style = state.recreate.overlay;
    style.outline_only = outline_only;
    let layer = state.recreate_overlay(Some(step), style)?;
    let frame = footage.load_rgba(step).ok()?;
    Some(sylva_app::recreate::overlay::composite(&frame, &layer))
}

#[test]
fn a_recreate_session_on_tree_a_replays_to_its_tree_and_shows_the_outline_overlay() {
    let bless = std::env::var_os("SYLVA_BLESS").is_some();
    let path = session_path();
    if bless {
        record().save(&path).expect("write session");
    }
    let mut seen = Seen::default();
    let report = replay(&path, None, false, |step, state| {
        seen.internodes.push(state.tree.skeleton.len());
        if step == SECOND_MARKS_STEP {
            let result = state.recreate.result.as_ref().expect("grown to fit");
            let m = &result.measurements;
            seen.result_line = Some(format!(
                "height {:.2} m, crown width {:.2} m, crown base {:.2} m, {} of the tree's points; {} {:.0} years; outline IoU {:?}",
                m.height_m * result.metres_per_unit,
                m.crown_width_m * result.metres_per_unit,
                m.crown_base_m * result.metres_per_unit,
                m.tree_points,
                result.growth.species,
                result.growth.age_years,
                result.outline_iou
            ));
            seen.outline_overlay = picture(state, 150, true);
            seen.filled_overlay = picture(state, 150, false);
            seen.first_view = picture(state, 30, true);
        }
        if step + 1 == YEARS_STEP + 5 {
            seen.ten_years = picture(state, step, false);
        }
    })
    .expect("replay");
    println!(
        "recreate session: {}",
        seen.result_line.as_deref().unwrap_or("no result")
    );
    let n = &seen.internodes;
    let (grown, pruned, older) = (n[SECOND_MARKS_STEP], n[PRUNE_STEP], n[YEARS_STEP]);
    println!(
        "internodes: {} before, {grown} grown to fit, {pruned} pruned, {older} at +10 years",
        n[0]
    );
    assert!(grown > 100, "grow to fit made {grown} internodes");
    assert!(
        pruned < grown,
        "the prune tap cut nothing ({grown} -> {pruned})"
    );
    assert!(
        older > pruned,
        "+10 years grew nothing ({pruned} -> {older})"
    );
    expected::assert_replay_matches(
        &report,
        &app_dir().join("tests/sessions/recreate_tree_a.expected.json"),
        bless,
    );
    let overlay = seen
        .outline_overlay
        .expect("the outline overlay of frame 150");
    check_golden(&overlay, "recreate_overlay_outline", bless);
    if std::env::var_os("SYLVA_DOCS").is_some() {
        let docs = app_dir().join("../docs/images");
        for (name, image) in [
            ("recreate-outline", seen.first_view),
            ("recreate-overlay", seen.filled_overlay),
            ("recreate-10-years", seen.ten_years),
        ] {
            let image = image.unwrap_or_else(|| panic!("no picture for {name}"));
            image
                .save(docs.join(format!("{name}.png")))
                .expect("write picture");
        }
    }
}

/// The overlay is drawn on the CPU from the design alone: it must match the golden exactly but
/// for rounding (a channel off by 2 at most, on 0.5% of the pixels at most).
fn check_golden(image: &image::RgbaImage, name: &str, bless: bool) {
    let path = app_dir().join(format!("tests/golden/{name}.png"));
    if bless {
        image.save(&path).expect("write golden");
    }
    let golden = image::open(&path)
        .unwrap_or_else(|e| {
            panic!(
                "golden {} unreadable ({e}); SYLVA_BLESS=1 makes it",
                path.display()
            )
        })
        .to_rgba8();
    assert_eq!(golden.dimensions(), image.dimensions());
    let differing = golden
        .pixels()
        .zip(image.pixels())
        .filter(|(a, b)| a.0.iter().zip(b.0.iter()).any(|(x, y)| x.abs_diff(*y) > 2))
        .count();
    let limit = (golden.len() / 4) / 200;
    if differing > limit {
        let out = Path::new(&std::env::temp_dir()).join(format!("{name}-actual.png"));
        image.save(&out).ok();
        panic!(
            "{differing} pixels differ from {} (actual in {})",
            path.display(),
            out.display()
        );
    }
}
