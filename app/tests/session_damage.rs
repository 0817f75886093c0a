//! Damaged sessions: values no control could have recorded (parameters the growth model
//! refuses, a grow of two billion iterations, an infinite pose, a giant frame size) make loading
//! fail with the session's path and what is wrong, before any replay starts.

use std::path::{Path, PathBuf};

use serde_json::{Value, json};
use sylva_app::session::Session;

fn committed_session() -> Value {
    let path =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/sessions/demo_garden.session.json");
    let text = std::fs::read_to_string(path).expect("committed session");
    serde_json::from_str(&text).expect("session JSON")
}

fn load_written(dir: &Path, name: &str, session: &Value) -> anyhow::Result<Session> {
    let path = dir.join(name);
    std::fs::write(&path, serde_json::to_string(session).expect("encode")).expect("write");
    Session::load(&path)
}

#[test]
fn the_committed_session_passes_the_check() {
    let dir = tempfile::tempdir().expect("temp dir");
    let session = load_written(dir.path(), "whole.json", &committed_session()).expect("loads");
    assert!(session.events.len() > 100);
}

/// A file name, what to break in the session, and a word the error must hold.
type Damage = (&'static str, fn(&mut Value), &'static str);

#[test]
fn damaged_sessions_are_refused_naming_the_file_and_the_value() {
    let dir = tempfile::tempdir().expect("temp dir");
    let damages: [Damage; 6] = [
        (
            "apical.json",
            |s| s["parameters"]["apical_dominance"] = json!(7.0),
            "apical_dominance",
        ),
        (
            "species.json",
            |s| s["parameters"]["species"] = json!("baobab"),
            "baobab",
        ),
        (
            "years.json",
            |s| s["parameters"]["years"] = json!(1e9),
            "years",
        ),
        (
            "grow.json",
            |s| {
                let events = s["events"].as_array_mut().expect("events");
                events.push(json!({"frame": 3, "time_s": 1.0,
                    "event": {"kind": "grow", "iterations": 2_000_000_000}}));
            },
            "grows 2000000000 iterations",
        ),
        (
            "pose.json",
            |s| s["frames"][200]["world_from_camera"][3] = json!(1e39),
            "frame 200",
        ),
        (
            "size.json",
            |s| s["frame_size"] = json!([320, 1_000_000]),
            "frame size",
        ),
    ];
    for (name, damage, expected) in damages {
        let mut session = committed_session();
        damage(&mut session);
        let err = load_written(dir.path(), name, &session).expect_err(name);
        let message = format!("{err:#}");
        assert!(
            message.contains(name) && message.contains(expected),
            "{name}: {message}"
        );
    }
}

#[test]
fn a_version_2_session_still_replays_with_the_tree_planted_at_the_origin_from_the_start() {
    // Version 2 had no tap: the demo's events without its planting tap, as a v2 file.
    let mut session = committed_session();
    session["version"] = json!(2);
    let events = session["events"].as_array_mut().expect("events");
    assert_eq!(
        events[0]["event"]["kind"], "touch",
        "the demo starts with its tap"
    );
    events.drain(0..2);
    let frames = session["frames"].as_array_mut().expect("frames");
    frames.truncate(60);
    let footage = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../test-data/demo_garden");
    session["footage"] = json!(footage);
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("v2.json");
    std::fs::write(&path, serde_json::to_string(&session).expect("encode")).expect("write");
    let (mut first, mut sizes) = (None, Vec::new());
    sylva_app::session::replay(&path, None, false, |step, state| {
        if step == 0 {
            first = Some(state.world_from_tree);
        }
        sizes.push(state.tree.skeleton.len());
    })
    .expect("a v2 session replays");
    assert_eq!(
        first,
        Some(Some(glam::Affine3A::IDENTITY)),
        "planted at the origin at once"
    );
    let grown = sizes.iter().max().copied().unwrap_or(0);
    assert!(
        grown > sizes[0],
        "the first stroke grows it: {} -> {grown}",
        sizes[0]
    );
}
