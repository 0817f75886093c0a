//! The committed garden session on `test-data/demo_yard` (issue #24, Done-when 6): a tap on the
//! lawn behind the box plants a birch, made 8 years old; "Plant another tree" and a tap plant a
//! second birch 2 m to its left, then a third 2 m to its right (each grown at once to the
//! garden's age against the trees standing); a tap on the middle one selects it, a brush stroke
//! from its top grows it towards the stroke (the other two stay byte-identical), and the years
//! slider moves the whole garden to 11 years. Replayed headlessly it gives the committed tree,
//! garden and frame hashes (lavapipe); the shown frame is the golden `garden_three.png`, the
//! three birches in the footage with the tracked box hiding part of them. `SYLVA_BLESS=1`
//! re-records the session from the script below and rewrites the hashes and the golden.
//!
//! Run: `XDG_RUNTIME_DIR=/tmp/sylva-xdg WGPU_BACKEND=vulkan cargo test --release -p sylva-app --test garden_session -- --nocapture`

mod expected;
mod golden_compare;

use std::path::PathBuf;

use glam::{Vec2, Vec3};
use sylva_app::demo_script::{YARD_TAP_FRAME, YARD_TAP_PIXEL, scripted_session, tap};
use sylva_app::footage::Footage;
use sylva_app::garden_view::placed_mesh;
use sylva_app::planting::{camera_in_tree, occluder_in_tree};
use sylva_app::render::offscreen::OFFSCREEN_FORMAT;
use sylva_app::render::{FrameView, Gpu, Offscreen, Renderer, TreeMesh};
use sylva_app::session::{Session, frame_occluders, replay};
use sylva_app::state::{DesignState, InputEvent, Parameters, TouchPhase};
use sylva_app::tree_model::mesh_of;

/// The frame the golden shows (the walk has gone round so that the box stands in front).
const SHOWN_FRAME: usize = 120;
const SPACING_M: f32 = 2.0;
const START_YEARS: f32 = 8.0;
const END_YEARS: f32 = 11.0;
const SPECIES: &str = "birch";
/// Frames after the first tree stands: the plantings, the selecting tap, the stroke, the years.
const PLANT_LEFT: usize = 2;
const PLANT_RIGHT: usize = 5;
const SELECT_MIDDLE: usize = 9;
const STROKE_START: usize = 12;
const STROKE_END: usize = 32;
const YEARS_MOVED: usize = 40;

fn sessions_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/sessions")
}

fn touch(phase: TouchPhase, p: Vec2) -> InputEvent {
    InputEvent::Touch {
        phase,
        id: 0,
        x: p.x,
        y: p.y,
    }
}

/// The row of three trunk bases in the world: the first tree's, and `SPACING_M` either side of
/// it across the view, on the ground.
fn row_of(state: &DesignState) -> Option<[Vec3; 3]> {
    let (camera, ground, placed) = (state.world_camera()?, state.ground?, state.world_from_tree?);
    let base = placed.transform_point3(Vec3::ZERO);
    let normal = ground.normal.try_normalize()?;
    let right = camera.world_from_camera.x_axis.truncate();
    let across = (right - normal * normal.dot(right)).try_normalize()?;
    Some([base, base - across * SPACING_M, base + across * SPACING_M])
}

fn garden_session(footage: &Footage) -> Session {
    let species = sylva_core::species::Species::by_name(SPECIES).expect("preset");
    let [sx, sy] = [
        footage.intrinsics.width as f32 / 640.0,
        footage.intrinsics.height as f32 / 480.0,
    ];
    let mut planted_at = None;
    let mut row = None;
    let mut stroke = Vec2::ZERO;
    scripted_session(
        footage,
        PathBuf::from("../../../test-data/demo_yard"),
        Parameters::for_species(&species),
        |step, state| {
            let mut events = Vec::new();
            if step == YARD_TAP_FRAME {
                events.extend(tap(YARD_TAP_PIXEL * Vec2::new(sx, sy)));
                return events;
            }
            let at = match planted_at {
                Some(at) => at,
                None if step > YARD_TAP_FRAME && state.is_planted() => {
                    planted_at = Some(step);
                    row = row_of(state);
                    let mut parameters = state.params.clone();
                    parameters.years = START_YEARS;
                    events.push(InputEvent::Parameters { parameters });
                    return events;
                }
                None => return events,
            };
            let pixel = |p: Vec3| state.world_camera().and_then(|c| c.pixel_from_world(p));
            let [middle, left, right] = row.expect("the row is known once planted");
            match step - at {
                PLANT_LEFT | PLANT_RIGHT => events.push(InputEvent::PlantAnother {
                    species: SPECIES.into(),
                }),
                k if k == PLANT_LEFT + 1 || k == PLANT_RIGHT + 1 => {
                    let base = if k == PLANT_LEFT + 1 { left } else { right };
                    events.extend(tap(pixel(base).expect("the base in view")));
                }
                SELECT_MIDDLE => {
                    // A tap on the middle trunk, a third of the way up.
                    let height = 0.33 * state.tree.metrics().height_m;
                    let trunk = pixel(middle + Vec3::Y * height).expect("in view");
                    events.extend(tap(trunk));
                }
                STROKE_START => {
                    let top = state
                        .tree
                        .skeleton
                        .internodes
                        .iter()
                        .map(|n| n.end)
                        .fold(Vec3::ZERO, |a, b| if b.y > a.y { b } else { a });
                    let camera = state.camera.expect("planted");
                    stroke = camera.pixel_from_world(top).expect("the top in view");
                    events.push(touch(TouchPhase::Start, stroke));
                }
                k if k > STROKE_START && k < STROKE_END => {
                    stroke += Vec2::new(2.0, -3.0);
                    events.push(touch(TouchPhase::Move, stroke));
                }
                STROKE_END => events.push(touch(TouchPhase::End, stroke)),
                YEARS_MOVED => {
                    let mut parameters = state.params.clone();
                    parameters.years = END_YEARS;
                    events.push(InputEvent::Parameters { parameters });
                }
                _ => {}
            }
            events
        },
    )
    .expect("garden script")
}

/// The other trees' files, by their place in the garden.
fn others_files(state: &DesignState) -> Vec<Vec<u8>> {
    state
        .other_trees()
        .iter()
        .map(|o| o.tree.to_json_bytes().expect("saves"))
        .collect()
}

#[test]
fn three_birches_planted_in_the_yard_grow_as_a_group_the_middle_one_edited_and_the_years_moved() {
    let session_path = sessions_dir().join("garden_three.session.json");
    let expected_path = sessions_dir().join("garden_three.expected.json");
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../test-data/demo_yard");
    let footage = Footage::open(&root).expect("the demo sequence is in the repository");
    let bless = std::env::var_os("SYLVA_BLESS").is_some();
    if bless {
        garden_session(&footage)
            .save(&session_path)
            .expect("write session");
    }
    let session = Session::load(&session_path).expect("committed session");

    let out = tempfile::tempdir().expect("temp dir");
    let mut log = Vec::new();
    let mut shown = None;
    let report =
        replay(&session_path, Some(out.path()), true, |step, state| {
            log.push((
                state.num_trees(),
                state.selected_tree(),
                state.tree.skeleton.len(),
                others_files(state),
                state.params.years,
            ));
            if step == SHOWN_FRAME {
                let tree_from_world = state.tree_from_world();
                let mut meshes = vec![mesh_of(&state.tree)];
                meshes.extend(state.other_trees().iter().map(|o| {
                    placed_mesh(&mesh_of(o.tree), &(tree_from_world * o.world_from_tree))
                }));
                shown = Some((meshes, state.world_from_tree, state.garden_now()));
            }
        })
        .expect("replay");

    // Three trees, the middle one (the first planted) selected from the tap on to the end.
    let (num_trees, selected, ..) = log.last().expect("frames");
    assert_eq!(*num_trees, 3, "three trees planted");
    assert_eq!(*selected, 0, "the middle tree selected");
    let first_three = log.iter().position(|l| l.0 == 3).expect("a third tree");
    let selected_from = log
        .iter()
        .skip(first_three)
        .position(|l| l.1 == 0)
        .map(|k| k + first_three)
        .expect("the middle tree selected by its tap");
    // The stroke: the middle tree grows, the two others stay byte-identical.
    let years_from = log
        .iter()
        .position(|l| l.4 == END_YEARS)
        .expect("the years moved");
    let (before, after) = (&log[selected_from], &log[years_from - 1]);
    assert!(
        after.2 > before.2,
        "the stroke grew the middle tree: {} -> {} internodes",
        before.2,
        after.2
    );
    assert_eq!(
        before.3, after.3,
        "the other two trees unchanged by the stroke"
    );
    assert_ne!(
        log[years_from].3, after.3,
        "the years slider grows the other trees too"
    );

    let (meshes, world_from_tree, garden) = shown.expect("the shown frame is replayed");
    let (garden, placed) = garden.expect("a garden at the shown frame");
    let bases: Vec<Vec3> = placed
        .iter()
        .map(|m| m.transform_point3(Vec3::ZERO))
        .collect();
    for b in &bases[1..] {
        let d = b.distance(bases[0]);
        assert!(
            (SPACING_M - 0.3..=SPACING_M + 0.3).contains(&d),
            "a tree {d:.2} m from the middle one, planted {SPACING_M} m away"
        );
    }
    for t in &garden.trees {
        let expected = t.tree.species.iterations_for_years(END_YEARS);
        assert!(
            t.tree.iteration >= expected,
            "every tree at {END_YEARS} years: iteration {} < {expected}",
            t.tree.iteration
        );
    }

    // Drawn as the replay draws it: the garden alone, and behind the occluder of the tracked
    // points; part of the group hidden by the box, most of it shown.
    let world_from_tree = world_from_tree.expect("planted");
    let gpu = Gpu::headless().expect("lavapipe");
    let mut renderer = Renderer::new(&gpu, OFFSCREEN_FORMAT);
    let [width, height] = session.frame_size;
    let target = Offscreen::new(&gpu.device, width, height);
    let tree_from_world = world_from_tree.inverse();
    let mut images = None;
    for (step, camera, occluder) in frame_occluders(&session, &footage) {
        if step > SHOWN_FRAME {
            break;
        }
        if step != SHOWN_FRAME {
            continue;
        }
        let mut view = FrameView::augmented(camera_in_tree(&camera, &tree_from_world), None);
        view.show_camera_image = false;
        renderer.set_occluder(&gpu, &occluder_in_tree(&occluder, &tree_from_world));
        let mut draw = |trees: &[TreeMesh], occlude: bool| {
            for slot in 0..meshes.len() {
                let empty = TreeMesh::default();
                renderer.set_garden_tree(&gpu, slot, trees.get(slot).unwrap_or(&empty));
            }
            view.occlude = occlude;
            target.render(&gpu, &mut renderer, &view).expect("render")
        };
        images = Some([draw(&[], false), draw(&meshes, false), draw(&meshes, true)]);
    }
    let [empty, alone, behind] = images.expect("the shown frame has a pose");
    let differs = |a: &image::Rgba<u8>, b: &image::Rgba<u8>| {
        a.0.iter().zip(b.0).any(|(x, y)| x.abs_diff(y) > 8)
    };
    let (mut num_tree, mut num_hidden) = (0usize, 0usize);
    for ((e, a), b) in empty.pixels().zip(alone.pixels()).zip(behind.pixels()) {
        if differs(a, e) {
            num_tree += 1;
            num_hidden += usize::from(!differs(b, e));
        }
    }
    let hidden = num_hidden as f64 / num_tree.max(1) as f64;
    println!(
        "frame {SHOWN_FRAME}: {} trees, {num_tree} tree pixels, {:.1}% hidden by the tracked occluder",
        meshes.len(),
        100.0 * hidden
    );
    assert!(
        num_hidden >= 20 && hidden <= 0.4,
        "part of the group hidden, most shown: {num_hidden} of {num_tree} pixels hidden"
    );

    // The app's own frame (footage, occlusion, shadows) is the golden.
    let frame = image::open(out.path().join(format!("frame_{SHOWN_FRAME:04}.png")))
        .expect("the replay wrote the shown frame")
        .to_rgba8();
    golden_compare::assert_matches_golden("garden_three", &frame);
    assert!(
        out.path().join("garden.json").exists(),
        "the replay saves the garden"
    );
    expected::assert_replay_matches(&report, &expected_path, bless);
    println!("{}", report.summary_line());
}
