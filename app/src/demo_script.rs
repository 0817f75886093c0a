//! The scripted demo session on the bundled sequence: a tap on the ground that plants the tree,
//! two brush strokes, a prune (double tap) and a bend (three touches), aimed at the tree as it
//! is when each gesture happens. It is both the headless demo and the committed session that CI
//! replays. [`scripted_session`] runs any such script through the tracker and the design state
//! exactly as the app does (the scene sessions of the tests use it too).

use std::path::PathBuf;

use glam::Vec2;

use crate::footage::Footage;
use crate::player::DEFAULT_SEED;
use crate::scene_tracking::SceneTracker;
use crate::session::{Session, frame_camera, frame_dt};
use crate::state::{DesignState, InputEvent, Parameters, TouchPhase};

fn touch(phase: TouchPhase, id: u64, p: Vec2) -> InputEvent {
    InputEvent::Touch {
        phase,
        id,
        x: p.x,
        y: p.y,
    }
}

/// Records a session over every frame of `footage` (referenced as `footage_ref`): before each
/// frame, `script(step, state)` says what the user does, seeing the design as it is then (the
/// camera of the frame shown before); the events are applied and recorded, then the frame is
/// tracked, observed and shown, as the player does.
pub fn scripted_session(
    footage: &Footage,
    footage_ref: PathBuf,
    params: Parameters,
    mut script: impl FnMut(usize, &DesignState) -> Vec<InputEvent>,
) -> anyhow::Result<Session> {
    let mut session = Session::new(footage_ref, DEFAULT_SEED, params.clone());
    let mut state = session.initial_design();
    let mut previous_time = footage.frames.first().map_or(0.0, |f| f.time_s);
    let mut tracker = SceneTracker::open(&footage.root, footage.intrinsics)?;
    for index in 0..footage.len() {
        for e in script(index, &state) {
            state.apply(&e);
            session.record(e);
        }
        let scene = tracker.frame(index)?;
        session.push_frame(footage, index, scene);
        let Some(record) = session.frames.last() else {
            continue;
        };
        let camera = frame_camera(record, footage);
        state.observe_scene(
            &footage.intrinsics,
            camera.map(|c| c.world_from_camera),
            record.ground_plane(),
            &record.observations(),
        );
        state.advance_frame(
            camera,
            record.time_s,
            frame_dt(record.time_s - previous_time),
        );
        previous_time = record.time_s;
    }
    Ok(session)
}

/// A tap (touch 0 down and up at once) at `pixel`.
pub fn tap(pixel: Vec2) -> [InputEvent; 2] {
    [
        touch(TouchPhase::Start, 0, pixel),
        touch(TouchPhase::End, 0, pixel),
    ]
}

/// The app's demo sequence (`test-data/demo_yard`): the frame of the planting tap, and the pixel
/// tapped there, on the lawn just behind the box (in the sequence's 640 × 480 frames).
pub const YARD_TAP_FRAME: usize = 30;
pub const YARD_TAP_PIXEL: Vec2 = Vec2::new(361.0, 243.0);
/// The tree the demo plants, and its age in years.
pub const YARD_SPECIES: &str = "norway_spruce";
pub const YARD_YEARS: f32 = 12.0;

/// The app's first impression on `test-data/demo_yard`: a tap on the lawn behind the box plants
/// a seedling there, which is made a Norway spruce of 12 years at once; the walk then goes round
/// so that the box hides the tree's foot while its crown stands in view.
pub fn yard_session(footage: &Footage, footage_ref: PathBuf) -> anyhow::Result<Session> {
    let species = sylva_core::species::Species::by_name(YARD_SPECIES)?;
    // The tap is made in the sequence's pixels; frames of another size get it scaled.
    let [sx, sy] = [
        footage.intrinsics.width as f32 / 640.0,
        footage.intrinsics.height as f32 / 480.0,
    ];
    let mut planted_at = None;
    scripted_session(
        footage,
        footage_ref,
        Parameters::default(),
        |step, state| {
            let mut events = Vec::new();
            if step == YARD_TAP_FRAME {
                events.extend(tap(YARD_TAP_PIXEL * Vec2::new(sx, sy)));
            } else if planted_at.is_none() && step > YARD_TAP_FRAME && state.is_planted() {
                // The species first (a new species starts a new seedling), then its age.
                planted_at = Some(step);
                events.push(InputEvent::Parameters {
                    parameters: Parameters::for_species(&species),
                });
            } else if planted_at.is_some_and(|at| step == at + 1) {
                let mut parameters = state.params.clone();
                parameters.years = YARD_YEARS;
                events.push(InputEvent::Parameters { parameters });
            }
            events
        },
    )
}

/// Builds the demo session over every frame of `footage` (referenced as `footage_ref`).
pub fn demo_session(footage: &Footage, footage_ref: PathBuf) -> anyhow::Result<Session> {
    let n = footage.len();
    let at = |fraction: f32| (fraction * n as f32) as usize;
    let mut stroke_pixel = Vec2::ZERO;
    let mut bend_pixel = Vec2::ZERO;
    scripted_session(
        footage,
        footage_ref,
        Parameters::default(),
        |step, state| {
            let mut events = Vec::new();
            // Plant: a tap on the ground at the world origin's pixel once the ground is found.
            if !state.is_planted()
                && state.ground.is_some()
                && let Some(camera) = state.world_camera()
                && let Some(p) = camera.pixel_from_world(glam::Vec3::ZERO)
            {
                events.extend(tap(p));
            }
            let top_pixel = state.camera.and_then(|c| {
                let top = state
                    .tree
                    .skeleton
                    .internodes
                    .iter()
                    .map(|i| i.end)
                    .fold(glam::Vec3::ZERO, |a, b| if b.y > a.y { b } else { a });
                c.pixel_from_world(top)
            });
            // Stroke 1: from the top of the seedling, up and to the right.
            if step == at(0.1) {
                if let Some(p) = top_pixel {
                    stroke_pixel = p;
                    events.push(touch(TouchPhase::Start, 0, p));
                }
            } else if step > at(0.1) && step < at(0.3) {
                stroke_pixel += Vec2::new(3.0, -5.0);
                events.push(touch(TouchPhase::Move, 0, stroke_pixel));
            } else if step == at(0.3) {
                events.push(touch(TouchPhase::End, 0, stroke_pixel));
            }
            // Stroke 2: from the top again, first straight up (inside the top bud's perception
            // cone), then curving to the left, with a wider brush half way.
            if step == at(0.35)
                && let Some(p) = top_pixel
            {
                stroke_pixel = p;
                events.push(touch(TouchPhase::Start, 0, p));
            } else if step > at(0.35) && step < at(0.55) {
                let turn = (step - at(0.35)) as f32 / (at(0.55) - at(0.35)) as f32;
                stroke_pixel += Vec2::new(-6.0 * turn, -5.0 * (1.0 - 0.5 * turn));
                events.push(touch(TouchPhase::Move, 0, stroke_pixel));
                if step == at(0.45) {
                    let mut p = state.params.clone();
                    p.brush_radius *= 1.6;
                    events.push(InputEvent::Parameters { parameters: p });
                }
            } else if step == at(0.55) {
                events.push(touch(TouchPhase::End, 0, stroke_pixel));
            }
            // Prune: double tap on the newest branch.
            if (step == at(0.62) || step == at(0.62) + 1)
                && let (Some(camera), Some(newest)) =
                    (state.camera, state.tree.skeleton.internodes.last())
                && let Some(p) = camera.pixel_from_world(0.5 * (newest.start + newest.end))
            {
                events.push(touch(TouchPhase::Start, 0, p));
                events.push(touch(TouchPhase::End, 0, p));
            }
            // Bend: three fingers around a branch half way up, dragged to the right.
            if step == at(0.7)
                && let Some(camera) = state.camera
                && let Some(node) = state
                    .tree
                    .skeleton
                    .internodes
                    .get(state.tree.skeleton.len() / 2)
                && let Some(p) = camera.pixel_from_world(node.end)
            {
                bend_pixel = p;
                for (id, offset) in [
                    (1, Vec2::new(-10.0, 0.0)),
                    (2, Vec2::new(10.0, 0.0)),
                    (3, Vec2::new(0.0, 10.0)),
                ] {
                    events.push(touch(TouchPhase::Start, id, p + offset));
                }
            } else if step > at(0.7) && step < at(0.8) {
                bend_pixel.x += 3.0;
                for (id, offset) in [
                    (1, Vec2::new(-10.0, 0.0)),
                    (2, Vec2::new(10.0, 0.0)),
                    (3, Vec2::new(0.0, 10.0)),
                ] {
                    events.push(touch(TouchPhase::Move, id, bend_pixel + offset));
                }
            } else if step == at(0.8) {
                for id in 1..=3 {
                    events.push(touch(TouchPhase::End, id, bend_pixel));
                }
            }
            events
        },
    )
}
