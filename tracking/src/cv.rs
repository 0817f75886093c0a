//! Everything that touches OpenCV. Types here speak glam and this crate's structs; `Mat` and
//! `Vector` never leave the module.

use crate::camera::Camera;
use crate::frame::{Frame, GrayImage};
use crate::pose::Se3;
use crate::sequence::{FrameSource, SequenceError, SourceEvent};
use glam::{DMat3, DQuat, DVec2, DVec3, Vec2};
use opencv::core::{self, KeyPoint, Mat, Point2f, Point3f, Size, TermCriteria, Vector};
use opencv::prelude::*;
use opencv::{calib3d, features2d, imgproc, video, videoio};

/// An OpenCV call failed.
#[derive(Debug, thiserror::Error)]
#[error("OpenCV: {0}")]
pub struct CvError(String);

impl From<opencv::Error> for CvError {
    fn from(e: opencv::Error) -> Self {
        CvError(e.to_string())
    }
}

type Result<T> = std::result::Result<T, CvError>;

/// OpenCV's Lucas–Kanade runs with the window (pixels) and pyramid levels of the tracker's own
/// ([`crate::lk`]), so the two are compared on the same solves.
const LK_WINDOW: i32 = crate::lk::WINDOW as i32;
const LK_LEVELS: i32 = crate::lk::LEVELS as i32;

/// Runs OpenCV on one thread and quiets its logs. Every [`crate::Tracker`] does this: with
/// OpenCV's worker threads the same footage gave different trajectories from run to run
/// (tum_fr1_rpy ATE 0.056–0.062 m), and sessions must replay identically. It also leaves the
/// other cores to the app.
pub fn configure_single_thread() {
    // Both calls only fail on invalid arguments; failure to configure is harmless.
    let _ = core::set_num_threads(1);
    let _ = core::set_log_level(core::LogLevel::LOG_LEVEL_ERROR);
}

fn mat_from_gray(image: &GrayImage) -> Result<Mat> {
    let borrowed =
        Mat::new_rows_cols_with_data(image.height as i32, image.width as i32, &image.pixels)?;
    Ok(borrowed.try_clone()?)
}

/// An image pyramid for OpenCV's Lucas–Kanade. The tracker uses the project's own
/// [`crate::lk`]; OpenCV's stays as the reference it is checked against (`lk_compare` example,
/// `tests/tests/lk_against_opencv.rs`).
pub struct Pyramid {
    levels: Vector<Mat>,
}

impl Pyramid {
    pub fn build(image: &GrayImage) -> Result<Self> {
        let mat = mat_from_gray(image)?;
        let mut levels = Vector::<Mat>::new();
        video::build_optical_flow_pyramid(
            &mat,
            &mut levels,
            Size::new(LK_WINDOW, LK_WINDOW),
            LK_LEVELS,
            true,
            core::BORDER_REFLECT_101,
            core::BORDER_CONSTANT,
            true,
        )?;
        Ok(Self { levels })
    }
}

fn to_points(points: &[Vec2]) -> Vector<Point2f> {
    points.iter().map(|p| Point2f::new(p.x, p.y)).collect()
}

fn lk(
    prev: &Pyramid,
    next: &Pyramid,
    from: &[Vec2],
    guess: Option<&[Vec2]>,
    levels: i32,
) -> Result<Vec<Option<Vec2>>> {
    if from.is_empty() {
        return Ok(Vec::new());
    }
    let prev_pts = to_points(from);
    let mut next_pts = to_points(guess.unwrap_or(from));
    let mut status = Vector::<u8>::new();
    let mut err = Vector::<f32>::new();
    let flags = if guess.is_some() {
        video::OPTFLOW_USE_INITIAL_FLOW
    } else {
        0
    };
    video::calc_optical_flow_pyr_lk(
        &prev.levels,
        &next.levels,
        &prev_pts,
        &mut next_pts,
        &mut status,
        &mut err,
        Size::new(LK_WINDOW, LK_WINDOW),
        levels.clamp(0, LK_LEVELS),
        TermCriteria::new(core::TermCriteria_COUNT + core::TermCriteria_EPS, 20, 0.03)?,
        flags,
        1e-4,
    )?;
    Ok(next_pts
        .iter()
        .zip(status.iter())
        .map(|(p, ok)| (ok != 0).then_some(Vec2::new(p.x, p.y)))
        .collect())
}

/// OpenCV's pyramidal Lucas–Kanade from `prev` to `next`, optionally with a forward-backward
/// check; `guess` seeds the forward search. The reference for [`crate::lk::track_points`].
pub fn track_points(
    prev: &Pyramid,
    next: &Pyramid,
    from: &[Vec2],
    guess: Option<&[Vec2]>,
    options: crate::lk::LkOptions,
) -> Result<Vec<Option<Vec2>>> {
    if from.is_empty() {
        return Ok(Vec::new());
    }
    let levels = options.levels as i32;
    let forward = lk(prev, next, from, guess, levels)?;
    let Some(max_fb_error_px) = options.max_fb_error_px else {
        return Ok(forward);
    };
    crate::lk::forward_backward(from, forward, max_fb_error_px, |there, back_guess| {
        lk(next, prev, there, Some(back_guess), levels)
    })
}

/// Shi–Tomasi corners at least `min_distance_px` away from each other and from `existing`.
pub fn detect_corners(
    image: &GrayImage,
    max_corners: usize,
    min_distance_px: f32,
    existing: &[Vec2],
) -> Result<Vec<Vec2>> {
    if max_corners == 0 {
        return Ok(Vec::new());
    }
    let mat = mat_from_gray(image)?;
    let mut mask = Mat::new_rows_cols_with_default(
        image.height as i32,
        image.width as i32,
        core::CV_8UC1,
        core::Scalar::all(255.0),
    )?;
    for p in existing {
        imgproc::circle(
            &mut mask,
            core::Point::new(p.x.round() as i32, p.y.round() as i32),
            min_distance_px.round() as i32,
            core::Scalar::all(0.0),
            -1,
            imgproc::LINE_8,
            0,
        )?;
    }
    let mut corners = Vector::<Point2f>::new();
    imgproc::good_features_to_track(
        &mat,
        &mut corners,
        max_corners as i32,
        0.01,
        min_distance_px as f64,
        &mask,
        3,
        false,
        0.04,
    )?;
    Ok(corners.iter().map(|p| Vec2::new(p.x, p.y)).collect())
}

fn ideal_pixels(camera: &Camera, normalized: &[DVec2]) -> Vector<Point2f> {
    normalized
        .iter()
        .map(|n| {
            Point2f::new(
                (camera.fx * n.x + camera.cx) as f32,
                (camera.fy * n.y + camera.cy) as f32,
            )
        })
        .collect()
}

fn camera_matrix(camera: &Camera) -> Result<Mat> {
    let k = [
        [camera.fx, 0.0, camera.cx],
        [0.0, camera.fy, camera.cy],
        [0.0, 0.0, 1.0],
    ];
    Ok(Mat::from_slice_2d(&k)?)
}

fn mat3_from(m: &Mat) -> Result<DMat3> {
    let mut cols = [DVec3::ZERO; 3];
    for (c, col) in cols.iter_mut().enumerate() {
        for r in 0..3 {
            col[r] = *m.at_2d::<f64>(r as i32, c as i32)?;
        }
    }
    Ok(DMat3::from_cols(cols[0], cols[1], cols[2]))
}

/// Relative pose from an essential matrix (RANSAC) and cheirality: `second_from_first` with a
/// unit translation, plus the inlier mask. Inputs are normalised undistorted coordinates.
pub fn relative_pose(
    camera: &Camera,
    first: &[DVec2],
    second: &[DVec2],
    threshold_px: f64,
) -> Result<Option<(Se3, Vec<bool>)>> {
    if first.len() < 8 {
        return Ok(None);
    }
    let (p1, p2) = (ideal_pixels(camera, first), ideal_pixels(camera, second));
    let k = camera_matrix(camera)?;
    let mut mask = Mat::default();
    let e = calib3d::find_essential_mat(
        &p1,
        &p2,
        &k,
        calib3d::RANSAC,
        0.999,
        threshold_px,
        1000,
        &mut mask,
    )?;
    if e.rows() != 3 || e.cols() != 3 {
        return Ok(None);
    }
    let (mut r, mut t) = (Mat::default(), Mat::default());
    calib3d::recover_pose_estimated(&e, &p1, &p2, &k, &mut r, &mut t, &mut mask)?;
    let rotation = DQuat::from_mat3(&mat3_from(&r)?).normalize();
    let translation = DVec3::new(*t.at::<f64>(0)?, *t.at::<f64>(1)?, *t.at::<f64>(2)?);
    let inliers = (0..first.len() as i32)
        .map(|i| mask.at::<u8>(i).map(|&m| m != 0))
        .collect::<std::result::Result<Vec<bool>, _>>()?;
    Ok(Some((Se3::new(rotation, translation), inliers)))
}

/// Number of homography inliers (RANSAC) between two views, for model selection.
pub fn homography_inliers(
    camera: &Camera,
    first: &[DVec2],
    second: &[DVec2],
    threshold_px: f64,
) -> Result<usize> {
    if first.len() < 4 {
        return Ok(0);
    }
    let (p1, p2) = (ideal_pixels(camera, first), ideal_pixels(camera, second));
    let mut mask = Mat::default();
    calib3d::find_homography(&p1, &p2, &mut mask, calib3d::RANSAC, threshold_px)?;
    Ok(mask
        .data_bytes()
        .map(|b| b.iter().filter(|&&m| m != 0).count())
        .unwrap_or(0))
}

pub use crate::vision::PnpMinimal;

/// Camera pose from 2D–3D correspondences inside RANSAC (the inliers refined by EPnP):
/// `camera_from_world` and the inlier indices. Image points are normalised undistorted
/// coordinates.
pub fn pnp_ransac(
    camera: &Camera,
    world: &[DVec3],
    normalized: &[DVec2],
    guess: Option<Se3>,
    threshold_px: f32,
    iterations: i32,
    minimal: PnpMinimal,
) -> Result<Option<(Se3, Vec<usize>)>> {
    if world.len() < 6 {
        return Ok(None);
    }
    let object: Vector<Point3f> = world
        .iter()
        .map(|p| Point3f::new(p.x as f32, p.y as f32, p.z as f32))
        .collect();
    let image = ideal_pixels(camera, normalized);
    let k = camera_matrix(camera)?;
    let (mut rvec, mut tvec) = (Mat::default(), Mat::default());
    if let Some(g) = guess {
        let aa = g.rotation.to_scaled_axis();
        rvec = Mat::from_slice_2d(&[[aa.x], [aa.y], [aa.z]])?;
        tvec = Mat::from_slice_2d(&[[g.translation.x], [g.translation.y], [g.translation.z]])?;
    }
    let mut inliers = Vector::<i32>::new();
    let found = calib3d::solve_pnp_ransac(
        &object,
        &image,
        &k,
        &core::no_array(),
        &mut rvec,
        &mut tvec,
        guess.is_some(),
        iterations,
        threshold_px,
        0.99,
        &mut inliers,
        match minimal {
            PnpMinimal::Epnp => calib3d::SOLVEPNP_EPNP,
            PnpMinimal::Ap3p => calib3d::SOLVEPNP_AP3P,
        },
    )?;
    if !found || inliers.len() < 6 {
        return Ok(None);
    }
    let get = |m: &Mat, i: i32| -> Result<f64> { Ok(*m.at::<f64>(i)?) };
    let aa = DVec3::new(get(&rvec, 0)?, get(&rvec, 1)?, get(&rvec, 2)?);
    let t = DVec3::new(get(&tvec, 0)?, get(&tvec, 1)?, get(&tvec, 2)?);
    let pose = Se3::new(crate::pose::exp_so3(aa), t);
    Ok(Some((pose, inliers.iter().map(|i| i as usize).collect())))
}

/// ORB keypoints and descriptors (for relocalisation).
pub struct OrbFeatures {
    orb: core::Ptr<features2d::ORB>,
}

pub use crate::vision::{Descriptor, NearestTwo, hamming};

impl OrbFeatures {
    pub fn new(max_features: usize) -> Result<Self> {
        let orb = features2d::ORB::create(
            max_features as i32,
            1.2,
            8,
            31,
            0,
            2,
            features2d::ORB_ScoreType::HARRIS_SCORE,
            31,
            20,
        )?;
        Ok(Self { orb })
    }

    /// Descriptors of the given keypoints (ORB drops those too near the border).
    fn run(
        &mut self,
        image: &GrayImage,
        keypoints: &mut Vector<KeyPoint>,
    ) -> Result<Vec<Descriptor>> {
        let mat = mat_from_gray(image)?;
        let mut descriptors = Mat::default();
        self.orb
            .detect_and_compute(&mat, &core::no_array(), keypoints, &mut descriptors, true)?;
        let mut out = Vec::with_capacity(keypoints.len());
        for row in 0..descriptors.rows() {
            let mut d = [0u8; 32];
            for (c, byte) in d.iter_mut().enumerate() {
                *byte = *descriptors.at_2d::<u8>(row, c as i32)?;
            }
            out.push(d);
        }
        Ok(out)
    }

    /// Shi–Tomasi corners (as [`detect_corners`] finds them) with their descriptors: the way
    /// map points are described, so the same corner seen again gives the same descriptor.
    pub fn describe_corners(
        &mut self,
        image: &GrayImage,
        max_corners: usize,
        min_distance_px: f32,
    ) -> Result<Vec<(Vec2, Descriptor)>> {
        let corners = detect_corners(image, max_corners, min_distance_px, &[])?;
        let described = self.describe(image, &corners)?;
        Ok(corners
            .into_iter()
            .zip(described)
            .filter_map(|(p, d)| Some((p, d?)))
            .collect())
    }

    /// Describes given points; points ORB drops (too near the border) come back as None.
    pub fn describe(
        &mut self,
        image: &GrayImage,
        points: &[Vec2],
    ) -> Result<Vec<Option<Descriptor>>> {
        let mut keypoints: Vector<KeyPoint> = Vector::new();
        for (i, p) in points.iter().enumerate() {
            // ORB takes provided keypoints' angles as they are: give each the intensity-centroid
            // orientation detection would have found, or its descriptor would not match the
            // same corner detected in another frame.
            let Some(angle) = crate::vision::orb::intensity_centroid_angle_deg(image, *p) else {
                continue;
            };
            keypoints.push(KeyPoint::new_coords(
                p.x, p.y, 31.0, angle, 0.0, 0, i as i32,
            )?);
        }
        let descriptors = self.run(image, &mut keypoints)?;
        let mut out = vec![None; points.len()];
        for (k, d) in keypoints.iter().zip(descriptors) {
            if let Some(slot) = out.get_mut(k.class_id() as usize) {
                *slot = Some(d);
            }
        }
        Ok(out)
    }
}

/// Frames from a video file, an image-sequence pattern or a live camera (OpenCV videoio).
pub struct VideoSource {
    capture: videoio::VideoCapture,
    camera: Camera,
    what: String,
    index: usize,
    frame_rate_hz: f64,
}

impl VideoSource {
    /// Opens a video file (or a `printf`-style image pattern).
    pub fn open_file(
        path: &std::path::Path,
        camera: Camera,
    ) -> std::result::Result<Self, SequenceError> {
        let what = path.display().to_string();
        let capture =
            videoio::VideoCapture::from_file_def(path).map_err(|e| SequenceError::Video {
                what: what.clone(),
                problem: e.to_string(),
            })?;
        Self::wrap(capture, camera, what)
    }

    /// Opens a live camera by index.
    pub fn open_camera(index: i32, camera: Camera) -> std::result::Result<Self, SequenceError> {
        let what = format!("camera {index}");
        let capture = videoio::VideoCapture::new_def(index).map_err(|e| SequenceError::Video {
            what: what.clone(),
            problem: e.to_string(),
        })?;
        Self::wrap(capture, camera, what)
    }

    fn wrap(
        capture: videoio::VideoCapture,
        camera: Camera,
        what: String,
    ) -> std::result::Result<Self, SequenceError> {
        if !capture.is_opened().unwrap_or(false) {
            return Err(SequenceError::Video {
                what,
                problem: "cannot be opened".into(),
            });
        }
        let fps = capture.get(videoio::CAP_PROP_FPS).unwrap_or(0.0);
        let frame_rate_hz = if fps > 0.0 {
            fps
        } else {
            camera.frame_rate_hz.unwrap_or(30.0)
        };
        Ok(Self {
            capture,
            camera,
            what,
            index: 0,
            frame_rate_hz,
        })
    }

    /// What was opened (`camera N` or the file), for messages.
    pub fn what(&self) -> &str {
        &self.what
    }

    /// Frames per second: the stream's own, else the camera model's, else 30.
    pub fn frame_rate_hz(&self) -> f64 {
        self.frame_rate_hz
    }

    /// The frame size the stream reports, when it reports one.
    pub fn frame_size(&self) -> Option<(u32, u32)> {
        let get = |property| self.capture.get(property).unwrap_or(0.0);
        let (w, h) = (
            get(videoio::CAP_PROP_FRAME_WIDTH),
            get(videoio::CAP_PROP_FRAME_HEIGHT),
        );
        (w >= 1.0 && h >= 1.0).then_some((w as u32, h as u32))
    }

    /// Asks a live camera for frames of this size; the camera may pick another (see
    /// [`Self::frame_size`]).
    pub fn request_frame_size(&mut self, width: u32, height: u32) {
        // A camera that cannot change its size keeps its own: not an error here.
        let _ = self
            .capture
            .set(videoio::CAP_PROP_FRAME_WIDTH, f64::from(width));
        let _ = self
            .capture
            .set(videoio::CAP_PROP_FRAME_HEIGHT, f64::from(height));
    }

    /// Replaces the camera model (intrinsics known only once the stream is open).
    pub fn set_camera(&mut self, camera: Camera) {
        self.camera = camera;
    }

    /// The next frame (grey, for tracking) with its colour image (RGB8, as shown), a skipped
    /// frame, or None at the end of the stream.
    pub fn next_color(&mut self) -> Option<(SourceEvent, Option<image::RgbImage>)> {
        self.read(true)
    }

    fn read(&mut self, color: bool) -> Option<(SourceEvent, Option<image::RgbImage>)> {
        let mut bgr = Mat::default();
        let index = self.index;
        self.index += 1;
        let skipped = |what: &str, reason: String| SourceEvent::Skipped {
            index,
            path: what.into(),
            reason,
        };
        match self.capture.read(&mut bgr) {
            Ok(true) if !bgr.empty() => {}
            Ok(_) => return None,
            Err(e) => return Some((skipped(&self.what, e.to_string()), None)),
        }
        let converted = gray_from_mat(&bgr, &self.camera).and_then(|gray| {
            let rgb = if color {
                Some(rgb_from_mat(&bgr)?)
            } else {
                None
            };
            Ok((gray, rgb))
        });
        Some(match converted {
            Ok((image, rgb)) => (
                SourceEvent::Frame(Frame {
                    index,
                    timestamp_s: index as f64 / self.frame_rate_hz,
                    image,
                }),
                rgb,
            ),
            Err(reason) => (skipped(&self.what, reason), None),
        })
    }
}

impl FrameSource for VideoSource {
    fn camera(&self) -> &Camera {
        &self.camera
    }

    fn next_event(&mut self) -> Option<SourceEvent> {
        self.read(false).map(|(event, _)| event)
    }
}

/// A colour frame (BGR or grey) as RGB8.
fn rgb_from_mat(mat: &Mat) -> std::result::Result<image::RgbImage, String> {
    let mut rgb = Mat::default();
    let code = if mat.channels() == 3 {
        imgproc::COLOR_BGR2RGB
    } else {
        imgproc::COLOR_GRAY2RGB
    };
    imgproc::cvt_color_def(mat, &mut rgb, code).map_err(|e| e.to_string())?;
    let (w, h) = (rgb.cols() as u32, rgb.rows() as u32);
    let bytes = rgb.data_bytes().map_err(|e| e.to_string())?.to_vec();
    image::RgbImage::from_raw(w, h, bytes).ok_or_else(|| "bad colour frame buffer".into())
}

fn gray_from_mat(mat: &Mat, camera: &Camera) -> std::result::Result<GrayImage, String> {
    let mut gray = Mat::default();
    if mat.channels() == 3 {
        imgproc::cvt_color_def(mat, &mut gray, imgproc::COLOR_BGR2GRAY)
            .map_err(|e| e.to_string())?;
    } else {
        gray = mat.try_clone().map_err(|e| e.to_string())?;
    }
    let (w, h) = (gray.cols() as u32, gray.rows() as u32);
    if w != camera.width || h != camera.height {
        return Err(format!(
            "frame is {w} x {h}, the camera says {} x {}",
            camera.width, camera.height
        ));
    }
    let bytes = gray.data_bytes().map_err(|e| e.to_string())?.to_vec();
    GrayImage::from_pixels(w, h, bytes).ok_or_else(|| "bad frame buffer".into())
}
