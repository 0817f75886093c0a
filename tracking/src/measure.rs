//! Points picked in a frame and the distance between them: the measure tool, and the known
//! length that sets the metric scale.
//!
//! A picked pixel is a raw (distorted) image pixel, as stored and as tapped. Its 3D point is the
//! ray through it meeting the ground plane, unless the depth mesh of the frame's tracked points
//! ([`crate::depth_mesh`]) holds a surface nearer than the ground there (a wall, a box, a
//! fence): then it is that surface's point. A pixel with neither (the sky, a wall with no
//! tracked points) is an error naming the frame and the pixel.
//!
//! **Uncertainty.** A pick is taken as uncertain by [`PICK_SIGMA_PX`] in each image axis; the
//! point moves with the pixel through the ray–plane intersection or the mesh's depth (finite
//! differences on the same surface), and the distance's standard deviation follows to first
//! order. The map's own errors (the plane's, the points') are not in it.
//!
//! **Spaces.** Everything is in the world of the frame's pose and plane (the tracker's world:
//! Y up, origin on the ground); a distance is in its unit, metres once the scale is metric.

use crate::camera::Camera;
use crate::depth_mesh::{DepthMesh, DepthMeshConfig, DepthSample, Observation, PinholeIntrinsics};
use crate::frame::{Plane, TrackedPoint};
use glam::{DAffine3, DVec2, DVec3, Vec2};
use std::str::FromStr;

/// Standard deviation of a picked pixel in each image axis, pixels.
pub const PICK_SIGMA_PX: f64 = 1.0;

/// A surface seen nearer than the ground by more than this fraction of the ground's depth is
/// taken for an object standing on it.
pub const GROUND_DEPTH_TOLERANCE: f64 = 0.05;

/// Why a pick or a measurement could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MeasureError {
    #[error("`{text}`: {reason} (expected {expected})")]
    Parse {
        text: String,
        reason: String,
        expected: &'static str,
    },
    #[error("frame {frame}: the footage has no such frame ({num_frames} frames)")]
    NoFrame { frame: usize, num_frames: usize },
    #[error("frame {frame} has no camera pose (it was not tracked); pick in a tracked frame")]
    NotTracked { frame: usize },
    #[error("frame {frame}: no ground plane was found yet")]
    NoPlane { frame: usize },
    #[error("frame {frame}: pixel ({u}, {v}) is outside the {width}x{height} image")]
    PixelOutside {
        frame: usize,
        u: f64,
        v: f64,
        width: u32,
        height: u32,
    },
    #[error(
        "frame {frame}: pixel ({u}, {v}) sees neither the ground nor tracked points ({reason})"
    )]
    NoSurface {
        frame: usize,
        u: f64,
        v: f64,
        reason: String,
    },
    #[error("frame {frame}: the two picked points coincide")]
    SamePoint { frame: usize },
}

/// Two pixels picked in one frame: `FRAME:U1,V1:U2,V2`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PixelPair {
    /// Index of the frame in the footage (counting unreadable frames).
    pub frame: usize,
    /// Raw (distorted) image pixels.
    pub a: DVec2,
    pub b: DVec2,
}

const PAIR_FORMAT: &str = "FRAME:U1,V1:U2,V2";
const KNOWN_LENGTH_FORMAT: &str = "FRAME:U1,V1:U2,V2:METRES";

fn parse_error(text: &str, reason: impl Into<String>, expected: &'static str) -> MeasureError {
    MeasureError::Parse {
        text: text.to_owned(),
        reason: reason.into(),
        expected,
    }
}

fn parse_pixel(text: &str, field: &str, expected: &'static str) -> Result<DVec2, MeasureError> {
    let (u, v) = field
        .split_once(',')
        .ok_or_else(|| parse_error(text, format!("`{field}` is not a pixel U,V"), expected))?;
    let number = |s: &str| {
        s.trim()
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| parse_error(text, format!("`{s}` is not a finite number"), expected))
    };
    Ok(DVec2::new(number(u)?, number(v)?))
}

fn parse_pair(
    text: &str,
    fields: &[&str],
    expected: &'static str,
) -> Result<PixelPair, MeasureError> {
    let frame = fields[0].trim().parse::<usize>().map_err(|_| {
        parse_error(
            text,
            format!("`{}` is not a frame index", fields[0]),
            expected,
        )
    })?;
    Ok(PixelPair {
        frame,
        a: parse_pixel(text, fields[1], expected)?,
        b: parse_pixel(text, fields[2], expected)?,
    })
}

impl FromStr for PixelPair {
    type Err = MeasureError;

    fn from_str(text: &str) -> Result<Self, MeasureError> {
        let fields: Vec<&str> = text.split(':').collect();
        if fields.len() != 3 {
            return Err(parse_error(text, "wrong number of fields", PAIR_FORMAT));
        }
        parse_pair(text, &fields, PAIR_FORMAT)
    }
}

/// Two pixels picked on the ends of something `length_m` long: `FRAME:U1,V1:U2,V2:METRES`.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct KnownLength {
    pub pixels: PixelPair,
    pub length_m: f64,
}

impl FromStr for KnownLength {
    type Err = MeasureError;

    fn from_str(text: &str) -> Result<Self, MeasureError> {
        let fields: Vec<&str> = text.split(':').collect();
        if fields.len() != 4 {
            return Err(parse_error(
                text,
                "wrong number of fields",
                KNOWN_LENGTH_FORMAT,
            ));
        }
        let length_m = fields[3]
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|l| l.is_finite() && *l >= 0.01)
            .ok_or_else(|| {
                parse_error(
                    text,
                    format!("`{}` is not a length of at least 0.01 m", fields[3]),
                    KNOWN_LENGTH_FORMAT,
                )
            })?;
        Ok(Self {
            pixels: parse_pair(text, &fields, KNOWN_LENGTH_FORMAT)?,
            length_m,
        })
    }
}

/// What a pick landed on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Surface {
    /// The ground plane.
    Ground,
    /// The depth mesh of the frame's tracked points.
    TrackedPoints,
}

impl Surface {
    pub fn key(self) -> &'static str {
        match self {
            Self::Ground => "ground",
            Self::TrackedPoints => "tracked_points",
        }
    }
}

/// A picked pixel's point in the world.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct PickedPoint {
    pub pixel: DVec2,
    pub world: DVec3,
    pub surface: Surface,
    /// How the point moves per pixel along the image's u and v axes, world units.
    pub world_per_px: [DVec3; 2],
}

/// The distance between two picked points, in world units.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Distance {
    pub frame: usize,
    pub a: PickedPoint,
    pub b: PickedPoint,
    pub distance: f64,
    /// One standard deviation from the picks' [`PICK_SIGMA_PX`].
    pub sigma: f64,
}

/// One tracked frame, as needed to place picks: the camera, its pose, the ground plane and the
/// tracked points (their depth mesh is built on demand).
#[derive(Clone, Copy)]
pub struct FrameView<'a> {
    pub frame: usize,
    pub camera: &'a Camera,
    pub world_from_camera: DAffine3,
    pub plane: Option<Plane>,
    pub points: &'a [TrackedPoint],
}

/// Where a pick found its point, before the finite differences.
enum Hit {
    Ground,
    Mesh,
}

impl FrameView<'_> {
    /// The depth mesh of the tracked points, at their ideal pixels through this frame's pose.
    fn depth_mesh(&self) -> DepthMesh {
        let intrinsics = PinholeIntrinsics::from(self.camera);
        let camera_from_world = self.world_from_camera.inverse();
        let observations: Vec<Observation> = self
            .points
            .iter()
            .filter_map(|p| {
                let c = camera_from_world.transform_point3(p.world.as_dvec3());
                (c.z > 1e-6 && c.is_finite()).then(|| Observation {
                    id: p.id,
                    pixel: Vec2::new(
                        (self.camera.fx * c.x / c.z + self.camera.cx) as f32,
                        (self.camera.fy * c.y / c.z + self.camera.cy) as f32,
                    ),
                    depth_m: c.z as f32,
                })
            })
            .collect();
        // The default depth limits are metres; the tracker's world is in metres of its first
        // guess, maybe far off, so every point in front of the camera is taken.
        let far = observations
            .iter()
            .map(|o| o.depth_m)
            .fold(0.0f32, f32::max);
        let config = DepthMeshConfig {
            min_depth_m: 1e-6,
            max_depth_m: (far * 2.0).max(1.0),
            ..DepthMeshConfig::default()
        };
        let mut mesh = DepthMesh::new(intrinsics, config);
        mesh.update(&observations);
        mesh
    }

    /// The camera-space ray (Z = 1) through a raw pixel.
    fn ray_in_camera(&self, pixel: DVec2) -> DVec3 {
        self.camera.normalized_from_pixel(pixel).extend(1.0)
    }

    /// Camera-Z depth where the ray through `pixel` meets the ground, if in front.
    fn ground_depth(&self, pixel: DVec2) -> Option<f64> {
        let plane = self.plane?;
        let origin = self.world_from_camera.translation;
        let direction = self
            .world_from_camera
            .transform_vector3(self.ray_in_camera(pixel));
        let denominator = plane.normal.dot(direction);
        if denominator.abs() < 1e-12 {
            return None;
        }
        let t = (plane.offset - plane.normal.dot(origin)) / denominator;
        (t.is_finite() && t > 0.0).then_some(t)
    }

    fn mesh_depth(&self, mesh: &DepthMesh, pixel: DVec2) -> DepthSample {
        let n = self.camera.normalized_from_pixel(pixel);
        let ideal = DVec2::new(
            self.camera.fx * n.x + self.camera.cx,
            self.camera.fy * n.y + self.camera.cy,
        );
        mesh.depth_at(ideal.as_vec2())
    }

    fn point_at_depth(&self, pixel: DVec2, depth: f64) -> DVec3 {
        self.world_from_camera
            .transform_point3(self.ray_in_camera(pixel) * depth)
    }

    fn depth_on(&self, hit: &Hit, mesh: &DepthMesh, pixel: DVec2) -> Option<f64> {
        match hit {
            Hit::Ground => self.ground_depth(pixel),
            Hit::Mesh => self.mesh_depth(mesh, pixel).depth_m().map(f64::from),
        }
    }

    /// The world point of one raw pixel (see the module doc for the choice of surface).
    pub fn pick(&self, pixel: DVec2) -> Result<PickedPoint, MeasureError> {
        self.pick_with(&self.depth_mesh(), pixel)
    }

    fn pick_with(&self, mesh: &DepthMesh, pixel: DVec2) -> Result<PickedPoint, MeasureError> {
        let (u, v) = (pixel.x, pixel.y);
        if !(pixel.is_finite() && self.camera.contains(pixel, 0.0)) {
            return Err(MeasureError::PixelOutside {
                frame: self.frame,
                u,
                v,
                width: self.camera.width,
                height: self.camera.height,
            });
        }
        let ground = self.ground_depth(pixel);
        let sample = self.mesh_depth(mesh, pixel);
        let (hit, depth) = match (ground, sample) {
            (Some(g), DepthSample::Known { depth_m })
                if (depth_m as f64) < g * (1.0 - GROUND_DEPTH_TOLERANCE) =>
            {
                (Hit::Mesh, depth_m as f64)
            }
            (None, DepthSample::Known { depth_m }) => (Hit::Mesh, depth_m as f64),
            (Some(g), _) => (Hit::Ground, g),
            (None, DepthSample::Unknown(reason)) => {
                let plane = if self.plane.is_some() {
                    "the ray misses the ground plane"
                } else {
                    "no ground plane yet"
                };
                return Err(MeasureError::NoSurface {
                    frame: self.frame,
                    u,
                    v,
                    reason: format!("{plane}; depth mesh: {reason:?}"),
                });
            }
        };
        let world = self.point_at_depth(pixel, depth);
        // Central differences on the same surface, one-sided where one side has no depth.
        let derivative = |step: DVec2| {
            let side = |sign: f64| {
                let p = pixel + step * sign;
                self.depth_on(&hit, mesh, p)
                    .map(|d| self.point_at_depth(p, d))
            };
            match (side(1.0), side(-1.0)) {
                (Some(plus), Some(minus)) => (plus - minus) / 2.0,
                (Some(plus), None) => plus - world,
                (None, Some(minus)) => world - minus,
                (None, None) => DVec3::ZERO,
            }
        };
        Ok(PickedPoint {
            pixel,
            world,
            surface: match hit {
                Hit::Ground => Surface::Ground,
                Hit::Mesh => Surface::TrackedPoints,
            },
            world_per_px: [derivative(DVec2::X), derivative(DVec2::Y)],
        })
    }

    /// The distance between the points of two raw pixels of this frame.
    pub fn measure(&self, a: DVec2, b: DVec2) -> Result<Distance, MeasureError> {
        let mesh = self.depth_mesh();
        let (a, b) = (self.pick_with(&mesh, a)?, self.pick_with(&mesh, b)?);
        let offset = a.world - b.world;
        let distance = offset.length();
        let Some(direction) = offset.try_normalize() else {
            return Err(MeasureError::SamePoint { frame: self.frame });
        };
        let variance: f64 = a
            .world_per_px
            .iter()
            .chain(&b.world_per_px)
            .map(|d| (direction.dot(*d) * PICK_SIGMA_PX).powi(2))
            .sum();
        Ok(Distance {
            frame: self.frame,
            a,
            b,
            distance,
            sigma: variance.sqrt(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{DMat3, DQuat, Vec3};

    /// A camera 1.5 m above a floor at y = 0, looking towards −Z, `pitch_deg` below the horizon.
    fn looking(pitch_deg: f64) -> DAffine3 {
        let pitch = pitch_deg.to_radians();
        let forward = DVec3::new(0.0, -pitch.sin(), -pitch.cos());
        let right = forward.cross(DVec3::Y).normalize();
        let down = forward.cross(right);
        DAffine3::from_rotation_translation(
            DQuat::from_mat3(&DMat3::from_cols(right, down, forward)),
            DVec3::new(0.0, 1.5, 0.0),
        )
    }

    fn pose() -> DAffine3 {
        looking(34.0)
    }

    fn camera() -> Camera {
        Camera::pinhole(640, 480, 525.0, 525.0, 319.5, 239.5)
    }

    const FLOOR: Plane = Plane {
        normal: DVec3::Y,
        offset: 0.0,
    };

    fn pixel_of(camera: &Camera, pose: &DAffine3, world: DVec3) -> DVec2 {
        camera
            .pixel_from_camera(pose.inverse().transform_point3(world))
            .expect("in front")
    }

    /// Points on a wall at z = −2.5 (x in −1..1, y in 0..1.2), as a tracker would see them.
    fn wall_points() -> Vec<TrackedPoint> {
        let mut points = Vec::new();
        for i in 0..=10 {
            for j in 0..=6 {
                points.push(TrackedPoint {
                    id: (i * 10 + j) as u64,
                    pixel: Vec2::ZERO,
                    world: Vec3::new(-1.0 + 0.2 * i as f32, 0.2 * j as f32, -2.5),
                });
            }
        }
        points
    }

    #[test]
    fn two_ground_pixels_one_metre_apart_measure_one_metre() {
        let (camera, pose) = (camera(), pose());
        let view = FrameView {
            frame: 3,
            camera: &camera,
            world_from_camera: pose,
            plane: Some(FLOOR),
            points: &[],
        };
        let a = pixel_of(&camera, &pose, DVec3::new(-0.5, 0.0, -2.0));
        let b = pixel_of(&camera, &pose, DVec3::new(0.5, 0.0, -2.0));
        let d = view.measure(a, b).expect("measured");
        assert!((d.distance - 1.0).abs() < 1e-9, "{}", d.distance);
        assert_eq!(d.a.surface, Surface::Ground);
        // One pixel at ~2.5 m is ~5 mm; two ends, along the line: ~7 mm.
        assert!(d.sigma > 0.003 && d.sigma < 0.012, "sigma {}", d.sigma);
    }

    #[test]
    fn pixels_on_a_wall_take_its_tracked_points_not_the_ground_behind() {
        let (camera, pose) = (camera(), pose());
        let points = wall_points();
        let view = FrameView {
            frame: 0,
            camera: &camera,
            world_from_camera: pose,
            plane: Some(FLOOR),
            points: &points,
        };
        let a = pixel_of(&camera, &pose, DVec3::new(-0.7, 0.5, -2.5));
        let b = pixel_of(&camera, &pose, DVec3::new(0.7, 0.5, -2.5));
        let d = view.measure(a, b).expect("measured");
        assert_eq!(
            (d.a.surface, d.b.surface),
            (Surface::TrackedPoints, Surface::TrackedPoints)
        );
        assert!((d.distance - 1.4).abs() < 1e-3, "{}", d.distance);
        // In front of the wall the floor is the ground.
        let floor = view
            .pick(pixel_of(&camera, &pose, DVec3::new(0.0, 0.0, -1.5)))
            .expect("floor");
        assert_eq!(floor.surface, Surface::Ground);
    }

    #[test]
    fn a_pixel_in_the_sky_or_off_the_image_is_an_error_naming_the_frame() {
        let camera = camera();
        let view = FrameView {
            frame: 9,
            camera: &camera,
            world_from_camera: pose(),
            plane: Some(FLOOR),
            points: &[],
        };
        // Looking 40° up, the whole image (24.6° half-height) is above the horizon.
        let sky = FrameView {
            world_from_camera: looking(-40.0),
            ..view
        };
        let error = sky.pick(DVec2::new(320.0, 10.0)).expect_err("sky");
        assert!(error.to_string().contains("frame 9"), "{error}");
        let error = view.pick(DVec2::new(700.0, 10.0)).expect_err("outside");
        assert!(
            matches!(error, MeasureError::PixelOutside { frame: 9, .. }),
            "{error}"
        );
    }

    #[test]
    fn picks_parse_from_the_command_line_form_and_refuse_malformed_ones() {
        let k: KnownLength = "120:100.5,200:300,210.25:1.8".parse().expect("parses");
        assert_eq!(k.pixels.frame, 120);
        assert_eq!(k.pixels.a, DVec2::new(100.5, 200.0));
        assert_eq!(k.length_m, 1.8);
        let p: PixelPair = "7:1,2:3,4".parse().expect("parses");
        assert_eq!(p.b, DVec2::new(3.0, 4.0));
        for bad in [
            "7:1,2:3,4",
            "x:1,2:3,4:1",
            "7:1;2:3,4:1",
            "7:1,2:3,4:-1",
            "7:1,2:3,nan:1",
            "7:1,2:3,4:0",
        ] {
            let error = bad.parse::<KnownLength>().expect_err(bad);
            assert!(error.to_string().contains(bad), "{error}");
        }
        assert!("7:1,2".parse::<PixelPair>().is_err());
    }
}
