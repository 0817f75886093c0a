//! The real scene behind the footage, as the app sees it: camera poses and the ground plane from
//! `sylva_tracking`'s monocular tracker, and the occluding surface from its incremental depth
//! mesh of the tracked points.
//!
//! The tracker is causal: frame k is tracked after frames 0..k. Each frame is tracked once, in
//! order, and its result kept, so looping playback, seeking back and replays read the cache and
//! seeking forward tracks the frames in between. Streams (a live camera, a video file:
//! [`crate::live`]) feed the same `FrameTracker` each frame as it arrives, keeping no cache.
//! World: metres, Y up, origin on the ground plane (fixed once the plane is found, so a planted
//! tree never moves).

use std::collections::VecDeque;
use std::path::Path;
use std::sync::Arc;

use glam::{Affine3A, Mat4, Vec3};
use sylva_tracking::depth_mesh::{
    DepthMesh, DepthMeshConfig, GroundSolids, GroundSolidsConfig, Observation, PinholeIntrinsics,
};
use sylva_tracking::occupancy::{OccupancyConfig, OccupancyMap};

use crate::render::{GroundPlane, Intrinsics, OccluderMesh};

/// What the app knows about the scene at one frame.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SceneFrame {
    /// `world_from_camera`; None while tracking is lost or not initialised.
    pub world_from_camera: Option<Mat4>,
    /// The ground plane once found.
    pub ground: Option<GroundPlane>,
    /// The map points tracked in this frame: id, ideal (undistorted) pixel and depth along the
    /// optical axis. Sessions record them; the depth mesh is built from them.
    pub observations: Vec<Observation>,
    /// The depth mesh of the tracked points in the world (empty without a pose).
    pub occluder: OccluderMesh,
    /// Time spent tracking this frame and updating the depth mesh, milliseconds (decoding the
    /// image excluded).
    pub tracking_ms: f32,
}

/// The incremental depth mesh of the tracked points, turned into the renderer's occluder, with
/// the solids standing on the ground that the tracked points of all frames since the ground was
/// found make ([`GroundSolids`]). Live tracking and session replays feed it the same
/// observations in the same order, so they draw the same occluder.
pub struct SceneMesher {
    depth_mesh: DepthMesh,
    solids: GroundSolids,
}

impl SceneMesher {
    pub fn new(intrinsics: &Intrinsics) -> SceneMesher {
        SceneMesher {
            depth_mesh: DepthMesh::new(pinhole_of(intrinsics), DepthMeshConfig::default()),
            solids: GroundSolids::new(GroundSolidsConfig::default()),
        }
    }

    /// Updates the mesh with one frame's observations and returns it in the world, filled down
    /// to the ground contact once the ground is known ([`skirt_to_ground`]), with the solids on
    /// the ground.
    pub fn update(
        &mut self,
        observations: &[Observation],
        world_from_camera: Mat4,
        ground: Option<GroundPlane>,
    ) -> OccluderMesh {
        self.depth_mesh.update(observations);
        let mesh = self
            .depth_mesh
            .export_camera_space()
            .to_world(&Affine3A::from_mat4(world_from_camera));
        let mut occluder = OccluderMesh {
            positions: mesh.positions,
            indices: mesh.indices,
        };
        if let Some(ground) = ground {
            skirt_to_ground(&mut occluder, &ground);
            // The world is fixed once the ground is found (refits of the plane do not move
            // it), so the points of every frame since then are fused in one world.
            self.solids.observe(
                observations,
                self.depth_mesh.camera(),
                &Affine3A::from_mat4(world_from_camera),
                ground.point,
                ground.normal,
            );
            self.solids.append_mesh(
                ground.normal,
                &mut occluder.positions,
                &mut occluder.indices,
            );
        }
        occluder
    }
}

/// Edges of the mesh's open boundary higher than this above the ground get a skirt (m).
const MIN_SKIRT_HEIGHT_M: f32 = 0.03;

/// Fills the occluder down to the ground contact: every open boundary edge of the mesh above
/// the ground gets a quad straight down to the plane. The depth mesh leaves the faces under an
/// object's top and edges open (triangles across a depth discontinuity are unknown, and few
/// points are tracked on a plain face); garden objects (walls, boxes, planters) are solid down to
/// the ground, so what is seen of their top hides everything behind them below it.
pub fn skirt_to_ground(occluder: &mut OccluderMesh, ground: &GroundPlane) {
    let mut edge_count: std::collections::BTreeMap<(u32, u32), u32> = Default::default();
    for triangle in occluder.indices.chunks_exact(3) {
        for k in 0..3 {
            let (a, b) = (triangle[k], triangle[(k + 1) % 3]);
            *edge_count.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    let height = |p: Vec3| (p - ground.point).dot(ground.normal);
    for ((a, b), count) in edge_count {
        if count != 1 {
            continue;
        }
        let (pa, pb) = (
            occluder.positions[a as usize],
            occluder.positions[b as usize],
        );
        let (ha, hb) = (height(pa), height(pb));
        if ha.max(hb) < MIN_SKIRT_HEIGHT_M || ha < 0.0 || hb < 0.0 {
            continue;
        }
        let base = occluder.positions.len() as u32;
        occluder.positions.push(pa - ground.normal * ha);
        occluder.positions.push(pb - ground.normal * hb);
        occluder.indices.extend([a, b, base + 1, a, base + 1, base]);
    }
}

/// The occupancy of the scene (free space carved along the rays, surfaces where the points are)
/// from the depth meshes of keyframes' tracked points: the scene that shapes the tree's growth
/// (Longay 2014 §5.4.3). A frame becomes a keyframe once the ground is found (the world is then
/// fixed) and the camera has moved or turned far enough from the last keyframe.
///
/// A keyframe joins the map [`SCENE_LATENCY_FRAMES`] shown frames after it was taken. The
/// window integrates keyframes on a worker thread ([`SceneOccupancy::with_worker`]), which has
/// that long; replays and scripted sessions integrate them inline at the same frame. Both feed
/// the same recorded observations in the same order, so growth sees the same map at every frame
/// and a session replays to the tree it was designed as.
pub struct SceneOccupancy {
    camera: PinholeIntrinsics,
    last_keyframe: Option<Affine3A>,
    /// Frames observed so far.
    num_frames: usize,
    /// Keyframes taken, not yet in the map, with the frame at which they join it.
    pending: VecDeque<(usize, Keyframe)>,
    integrator: Integrator,
}

/// Shown frames between taking a keyframe and growing against it.
pub const SCENE_LATENCY_FRAMES: usize = 10;
/// A new keyframe once the camera moved this far (m) from the last one ...
const KEYFRAME_BASELINE_M: f32 = 0.12;
/// ... or turned this much (radians).
const KEYFRAME_TURN_RAD: f32 = 0.1;
/// Fewer tracked points than this make no keyframe (too little surface to carve with).
const KEYFRAME_MIN_POINTS: usize = 40;

/// One keyframe's tracked points and pose.
struct Keyframe {
    observations: Vec<Observation>,
    world_from_camera: Affine3A,
}

enum Integrator {
    Inline(OccupancyMap),
    /// The worker owns the map and sends a copy after each keyframe, in order.
    Worker {
        keyframes: std::sync::mpsc::Sender<Keyframe>,
        maps: std::sync::mpsc::Receiver<Arc<OccupancyMap>>,
        current: Arc<OccupancyMap>,
    },
}

fn integrate(map: &mut OccupancyMap, camera: PinholeIntrinsics, keyframe: &Keyframe) {
    let mut mesh = DepthMesh::new(camera, DepthMeshConfig::default());
    mesh.update(&keyframe.observations);
    map.integrate(&mesh, &keyframe.world_from_camera);
}

impl SceneOccupancy {
    /// Integrating keyframes on the calling thread.
    pub fn new(intrinsics: &Intrinsics) -> SceneOccupancy {
        SceneOccupancy {
            camera: pinhole_of(intrinsics),
            last_keyframe: None,
            num_frames: 0,
            pending: VecDeque::new(),
            integrator: Integrator::Inline(OccupancyMap::new(OccupancyConfig::default())),
        }
    }

    /// Integrating keyframes on a worker thread (the window): the same maps at the same frames
    /// as [`Self::new`], the UI thread waiting only if the worker is more than
    /// [`SCENE_LATENCY_FRAMES`] behind.
    pub fn with_worker(intrinsics: &Intrinsics) -> SceneOccupancy {
        let camera = pinhole_of(intrinsics);
        let (keyframes, jobs) = std::sync::mpsc::channel::<Keyframe>();
        let (done, maps) = std::sync::mpsc::channel();
        let spawned = std::thread::Builder::new()
            .name("sylva-occupancy".into())
            .spawn(move || {
                let mut map = OccupancyMap::new(OccupancyConfig::default());
                for keyframe in jobs {
                    integrate(&mut map, camera, &keyframe);
                    if done.send(Arc::new(map.clone())).is_err() {
                        return;
                    }
                }
            });
        let mut occupancy = SceneOccupancy::new(intrinsics);
        match spawned {
            Ok(_) => {
                occupancy.integrator = Integrator::Worker {
                    keyframes,
                    maps,
                    current: Arc::new(OccupancyMap::new(OccupancyConfig::default())),
                }
            }
            Err(e) => eprintln!("warning: no occupancy worker ({e}); integrating inline"),
        }
        occupancy
    }

    /// The map growth uses now.
    pub fn map(&self) -> &OccupancyMap {
        match &self.integrator {
            Integrator::Inline(map) => map,
            Integrator::Worker { current, .. } => current,
        }
    }

    /// Takes the next shown frame's tracked points seen from `world_from_camera` (None while
    /// tracking is lost); keeps it as a keyframe when it is one, and brings the keyframes due
    /// at this frame into the map. Returns whether the frame was a keyframe.
    pub fn observe(
        &mut self,
        observations: &[Observation],
        world_from_camera: Option<Mat4>,
        ground_found: bool,
    ) -> bool {
        self.num_frames += 1;
        let keyframe = world_from_camera
            .map(Affine3A::from_mat4)
            .filter(|pose| ground_found && pose.is_finite() && self.is_new_keyframe(pose))
            .filter(|_| observations.len() >= KEYFRAME_MIN_POINTS);
        if let Some(pose) = keyframe {
            self.last_keyframe = Some(pose);
            let keyframe = Keyframe {
                observations: observations.to_vec(),
                world_from_camera: pose,
            };
            let keyframe = match &self.integrator {
                // The worker starts on it now; only the due frame is remembered.
                Integrator::Worker { keyframes, .. } => match keyframes.send(keyframe) {
                    Ok(()) => Keyframe {
                        observations: Vec::new(),
                        world_from_camera: pose,
                    },
                    Err(std::sync::mpsc::SendError(keyframe)) => keyframe,
                },
                Integrator::Inline(_) => keyframe,
            };
            self.pending
                .push_back((self.num_frames + SCENE_LATENCY_FRAMES, keyframe));
        }
        while self
            .pending
            .front()
            .is_some_and(|(due, _)| *due <= self.num_frames)
        {
            let Some((_, keyframe)) = self.pending.pop_front() else {
                break;
            };
            match &mut self.integrator {
                Integrator::Inline(map) => integrate(map, self.camera, &keyframe),
                Integrator::Worker { maps, current, .. } => match maps.recv() {
                    Ok(map) => *current = map,
                    Err(_) => eprintln!("warning: the occupancy worker stopped"),
                },
            }
        }
        keyframe.is_some()
    }

    fn is_new_keyframe(&self, pose: &Affine3A) -> bool {
        self.last_keyframe.is_none_or(|last| {
            let moved = Vec3::from(last.translation).distance(Vec3::from(pose.translation));
            // trace(R) = 1 + 2 cos θ.
            let relative = last.matrix3.transpose() * pose.matrix3;
            let trace = relative.x_axis.x + relative.y_axis.y + relative.z_axis.z;
            let angle = ((trace - 1.0) * 0.5).clamp(-1.0, 1.0).acos();
            moved >= KEYFRAME_BASELINE_M || angle >= KEYFRAME_TURN_RAD
        })
    }
}

fn pinhole_of(intrinsics: &Intrinsics) -> PinholeIntrinsics {
    PinholeIntrinsics {
        width: intrinsics.width,
        height: intrinsics.height,
        fx: intrinsics.fx,
        fy: intrinsics.fy,
        cx: intrinsics.cx,
        cy: intrinsics.cy,
    }
}

mod desktop {
    use super::*;
    use anyhow::Context;
    use glam::{DMat4, DVec3, Vec3};
    use sylva_tracking::sequence::FileListSource;
    use sylva_tracking::{
        Camera, Frame, FrameSource, SourceEvent, Tracker, TrackerConfig, TumSequence,
    };

    /// Plane `normal · p = offset` of the tracker as the renderer's ground (point, up normal).
    fn ground_from_plane(normal: Vec3, offset: f32) -> GroundPlane {
        GroundPlane {
            point: normal * offset,
            normal,
        }
    }

    /// The tracker with the depth mesher of its points: one frame in, the app's scene out.
    /// Recorded footage ([`SceneTracker`]) and live streams ([`crate::live_capture`]) share it.
    pub struct FrameTracker {
        tracker: Tracker,
        mesher: SceneMesher,
        intrinsics: Intrinsics,
    }

    impl FrameTracker {
        /// A tracker for frames of `camera` (its intrinsics for the renderer: `intrinsics`).
        pub fn new(camera: Camera, intrinsics: Intrinsics) -> anyhow::Result<FrameTracker> {
            // OpenCV's own threads (desktop); the portable backend (phones) uses none.
            #[cfg(not(any(target_os = "android", target_os = "ios")))]
            sylva_tracking::cv::configure_single_thread();
            Ok(FrameTracker {
                tracker: Tracker::new(camera, TrackerConfig::default())?,
                mesher: SceneMesher::new(&intrinsics),
                intrinsics,
            })
        }

        /// Tracks the next frame (frames come in order); `up` is gravity "up" in camera axes
        /// when an accelerometer measured it.
        pub fn track(&mut self, frame: &Frame, up: Option<DVec3>) -> anyhow::Result<SceneFrame> {
            let started = std::time::Instant::now();
            let output = self
                .tracker
                .track(frame, up.map(|u| u * 9.81))
                .with_context(|| format!("tracking frame {}", frame.index))?;
            let mut scene = self.scene_of(&output);
            scene.tracking_ms = started.elapsed().as_secs_f32() * 1000.0;
            Ok(scene)
        }

        /// Pose, plane and depth mesh of one tracker output.
        fn scene_of(&mut self, output: &sylva_tracking::FrameOutput) -> SceneFrame {
            let ground = output
                .plane
                .map(|p| ground_from_plane(p.normal.as_vec3(), p.offset as f32));
            let Some(world_from_camera) = output.world_from_camera else {
                return SceneFrame {
                    ground,
                    ..SceneFrame::default()
                };
            };
            let world_from_camera = DMat4::from(world_from_camera).as_mat4();
            // The same observations a platform tracker's feature points make.
            let points = output.tracked_points.iter().map(|p| (p.id, p.world));
            let observations =
                crate::platform::observations_of(world_from_camera, points, &self.intrinsics);
            crate::platform::posed_scene(&mut self.mesher, world_from_camera, observations, ground)
        }
    }

    /// Tracks footage frame by frame and keeps every frame's result.
    pub struct SceneTracker {
        sequence: TumSequence,
        source: FileListSource,
        tracker: FrameTracker,
        frames: Vec<SceneFrame>,
        num_frames: usize,
    }

    impl SceneTracker {
        /// A tracker over the TUM-layout footage at `root` (its `camera.txt` and `rgb.txt`).
        pub fn open(root: &Path, intrinsics: Intrinsics) -> anyhow::Result<SceneTracker> {
            let sequence = TumSequence::open(root)
                .with_context(|| format!("cannot open {} for tracking", root.display()))?;
            let tracker = FrameTracker::new(sequence.camera, intrinsics)
                .with_context(|| format!("cannot start the tracker on {}", root.display()))?;
            let num_frames = sequence.frames.len();
            Ok(SceneTracker {
                source: sequence.source(),
                sequence,
                tracker,
                frames: Vec::with_capacity(num_frames),
                num_frames,
            })
        }

        /// The scene at footage frame `index` if it has been tracked already.
        pub fn get(&self, index: usize) -> Option<&SceneFrame> {
            self.frames.get(index)
        }

        /// The scene at footage frame `index`, tracking the frames up to it first if needed.
        pub fn frame(&mut self, index: usize) -> anyhow::Result<&SceneFrame> {
            let index = index.min(self.num_frames.saturating_sub(1));
            while self.frames.len() <= index {
                let Some(event) = self.source.next_event() else {
                    // Fewer readable frames than listed: the rest have no pose.
                    self.frames.push(SceneFrame::default());
                    continue;
                };
                match event {
                    SourceEvent::Frame(frame) => {
                        let up = self.sequence.up_in_camera_at(frame.timestamp_s);
                        let scene = self.tracker.track(&frame, up)?;
                        self.push_at(frame.index, scene);
                    }
                    SourceEvent::Skipped {
                        index,
                        path,
                        reason,
                    } => {
                        eprintln!("warning: skipped frame {}: {reason}", path.display());
                        self.push_at(index, SceneFrame::default());
                    }
                }
            }
            Ok(&self.frames[index])
        }

        /// Stores the result for source frame `index` (frames never come out of order).
        fn push_at(&mut self, index: usize, scene: SceneFrame) {
            while self.frames.len() < index {
                self.frames.push(SceneFrame::default());
            }
            if self.frames.len() == index {
                self.frames.push(scene);
            }
        }
    }
}

pub use desktop::{FrameTracker, SceneTracker};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_skirt_drops_every_open_edge_above_the_ground_down_to_it() {
        // A box top seen alone: one triangle 0.5 m above the ground, and one on the ground.
        let mut occluder = OccluderMesh {
            positions: vec![
                Vec3::new(0.0, 0.5, 0.0),
                Vec3::new(1.0, 0.5, 0.0),
                Vec3::new(0.0, 0.5, 1.0),
                Vec3::new(3.0, 0.0, 0.0),
                Vec3::new(4.0, 0.01, 0.0),
                Vec3::new(3.0, 0.0, 1.0),
            ],
            indices: vec![0, 1, 2, 3, 4, 5],
        };
        skirt_to_ground(&mut occluder, &GroundPlane::default());
        assert_eq!(
            occluder.indices.len(),
            6 + 3 * 6,
            "one quad per edge of the top"
        );
        assert_eq!(occluder.positions.len(), 6 + 3 * 2);
        for p in &occluder.positions[6..] {
            assert!(
                p.y.abs() < 1e-6 && p.x < 1.5,
                "skirt foot {p} on the ground below the top"
            );
        }
    }
}
