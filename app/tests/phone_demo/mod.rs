//! The bundled demo footage as a phone camera hands it over (shared by `platform_shell.rs` and
//! `phone_screenshots.rs`).

use glam::DMat4;
use sylva_app::cmd_app::demo_sequence;
use sylva_app::footage::Footage;
use sylva_app::platform::{
    FeaturePoint, PlatformFrame, PlatformIntrinsics, PlatformPlane, PlatformTracking,
};
use sylva_tracking::{FrameSource, SourceEvent, Tracker, TrackerConfig, TumSequence};

pub fn demo_intrinsics(sequence: &TumSequence) -> PlatformIntrinsics {
    let c = sequence.camera;
    PlatformIntrinsics {
        width: c.width,
        height: c.height,
        fx: c.fx,
        fy: c.fy,
        cx: c.cx,
        cy: c.cy,
    }
}

/// The first `num_frames` of the demo as a phone camera hands them over; with `platform_tracking`, each with the
/// pose, feature points and ground plane of Sylva's own tracker run on the images, as an AR
/// session's tracking.
pub fn demo_frames(
    platform_tracking: bool,
    num_frames: usize,
) -> (PlatformIntrinsics, Vec<PlatformFrame>) {
    let root = demo_sequence().expect("the bundled demo sequence test-data/demo_garden");
    let sequence = TumSequence::open(&root).expect("demo sequence");
    let footage = Footage::open(&root).expect("demo footage");
    let intrinsics = demo_intrinsics(&sequence);
    sylva_tracking::cv::configure_single_thread();
    let mut tracker = Tracker::new(sequence.camera, TrackerConfig::default()).expect("tracker");
    let mut source = sequence.source();
    let mut frames = Vec::new();
    while frames.len() < num_frames {
        let Some(SourceEvent::Frame(frame)) = source.next_event() else {
            panic!("demo frame {} is missing", frames.len());
        };
        let up = sequence.up_in_camera_at(frame.timestamp_s);
        let tracking = platform_tracking.then(|| {
            let output = tracker
                .track(&frame, up.map(|u| u * 9.81))
                .expect("tracking");
            PlatformTracking {
                world_from_camera: output.world_from_camera.map(|m| DMat4::from(m).as_mat4()),
                feature_points: output
                    .tracked_points
                    .iter()
                    .map(|p| FeaturePoint {
                        id: p.id,
                        point_in_world: p.world,
                    })
                    .collect(),
                planes: output
                    .plane
                    .map(|p| PlatformPlane {
                        id: 1,
                        // As Sylva's tracker's ground: point = normal · offset, in f32.
                        center_in_world: p.normal.as_vec3() * p.offset as f32,
                        normal_in_world: p.normal.as_vec3(),
                        extent_m: [4.0, 4.0],
                    })
                    .into_iter()
                    .collect(),
                light: None,
            }
        });
        frames.push(PlatformFrame {
            time_s: frame.timestamp_s - footage.frames[0].time_s,
            rgba: footage.load_rgba(frame.index).expect("demo image"),
            intrinsics,
            tracking,
            up_in_camera: up,
        });
    }
    (intrinsics, frames)
}

/// The pixel of the tree's highest point in the shown frame.
pub fn top_pixel(app: &sylva_app::platform::ShellApp) -> Option<glam::Vec2> {
    let player = app.player();
    let top = player
        .design
        .tree
        .skeleton
        .internodes
        .iter()
        .map(|i| i.end)
        .max_by(|a, b| a.y.total_cmp(&b.y))?;
    player.camera_in_tree()?.pixel_from_world(top)
}
