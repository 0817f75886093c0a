//! The synthetic garden's ground truth (`test-data/demo_garden`), read by tests only: the true
//! camera poses, the true solids, and the Sim(3) that places a session's tracked world in the
//! generator's.

use std::path::PathBuf;

use glam::{DAffine3, DQuat, DVec3, Vec3};
use serde::Deserialize;
use sylva_app::session::Session;
use sylva_tracking::linalg::Similarity;
use sylva_tracking::metrics::{PosePair, align_frames};

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../test-data/demo_garden")
}

/// The generator's `world_from_camera` of every frame, in the footage's order.
pub fn true_poses() -> Vec<DAffine3> {
    let text = std::fs::read_to_string(root().join("groundtruth.txt")).expect("groundtruth.txt");
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l
                .split_whitespace()
                .skip(1)
                .map(|x| x.parse().expect("number"))
                .collect();
            DAffine3::from_rotation_translation(
                DQuat::from_xyzw(v[3], v[4], v[5], v[6]).normalize(),
                DVec3::new(v[0], v[1], v[2]),
            )
        })
        .collect()
}

#[derive(Deserialize)]
struct Block {
    name: String,
    min: [f32; 3],
    max: [f32; 3],
}

#[derive(Deserialize)]
struct SceneFile {
    blocks: Vec<Block>,
}

/// The generator's solids (wall, box): name, min and max corners.
pub fn true_blocks() -> Vec<(String, Vec3, Vec3)> {
    let text = std::fs::read_to_string(root().join("scene.json")).expect("scene.json");
    let scene: SceneFile = serde_json::from_str(&text).expect("scene.json parses");
    scene
        .blocks
        .into_iter()
        .map(|b| (b.name, Vec3::from(b.min), Vec3::from(b.max)))
        .collect()
}

/// The Sim(3) from the session's tracked world to the generator's, aligning the camera frames.
pub fn truth_from_tracked(session: &Session) -> (Similarity, usize) {
    let truth = true_poses();
    let pairs: Vec<PosePair> = session
        .frames
        .iter()
        .filter_map(|f| {
            let m = glam::Mat4::from_cols_array(f.world_from_camera.as_ref()?);
            Some(PosePair {
                index: f.index,
                estimated: DAffine3::from_mat4(m.as_dmat4()),
                truth: truth[f.index],
            })
        })
        .collect();
    (align_frames(&pairs).expect("alignment"), pairs.len())
}
