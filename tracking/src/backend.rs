//! The tracker's vision backend: OpenCV ([`crate::cv`], desktop builds with the `opencv`
//! feature) or the portable one written here ([`crate::vision`], every build, the only one on
//! phones). [`crate::TrackerConfig::backend`] picks it; Lucas–Kanade is the tracker's own
//! ([`crate::lk`]) either way.

use crate::camera::Camera;
use crate::frame::GrayImage;
use crate::map::Descriptor;
use crate::pose::Se3;
use crate::tracker::TrackerError;
use crate::vision::{self, PnpMinimal};
use glam::{DVec2, DVec3, Vec2};

#[cfg(feature = "opencv")]
use crate::cv;

/// Which implementation of corners, two-view geometry, PnP and ORB the tracker uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VisionBackend {
    /// OpenCV (needs the `opencv` feature): the default on desktop.
    OpenCv,
    /// Sylva's own ([`crate::vision`]): the default without OpenCV (phones).
    Portable,
}

impl Default for VisionBackend {
    fn default() -> Self {
        if cfg!(feature = "opencv") {
            Self::OpenCv
        } else {
            Self::Portable
        }
    }
}

impl VisionBackend {
    /// Whether this build has the backend.
    pub fn available(self) -> bool {
        match self {
            Self::OpenCv => cfg!(feature = "opencv"),
            Self::Portable => true,
        }
    }

    /// `opencv` or `portable`, as command lines and reports name them.
    pub fn name(self) -> &'static str {
        match self {
            Self::OpenCv => "opencv",
            Self::Portable => "portable",
        }
    }

    /// The backend of a name given by [`Self::name`].
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "opencv" => Some(Self::OpenCv),
            "portable" => Some(Self::Portable),
            _ => None,
        }
    }
}

/// The backend a tracker runs on, with its ORB state.
pub(crate) enum Vision {
    #[cfg(feature = "opencv")]
    OpenCv(cv::OrbFeatures),
    Portable(vision::Orb),
}

/// ORB features OpenCV keeps at most per frame (the tracker describes given points).
#[cfg(feature = "opencv")]
const OPENCV_MAX_FEATURES: usize = 1000;

impl Vision {
    pub(crate) fn new(backend: VisionBackend) -> Result<Self, TrackerError> {
        match backend {
            #[cfg(feature = "opencv")]
            VisionBackend::OpenCv => {
                cv::configure_single_thread();
                Ok(Self::OpenCv(cv::OrbFeatures::new(OPENCV_MAX_FEATURES)?))
            }
            #[cfg(not(feature = "opencv"))]
            VisionBackend::OpenCv => Err(TrackerError::BackendUnavailable(backend)),
            VisionBackend::Portable => Ok(Self::Portable(vision::Orb::new())),
        }
    }

    /// Shi–Tomasi corners at least `min_distance_px` away from each other and from `existing`.
    pub(crate) fn detect_corners(
        &self,
        image: &GrayImage,
        max_corners: usize,
        min_distance_px: f32,
        existing: &[Vec2],
    ) -> Result<Vec<Vec2>, TrackerError> {
        match self {
            #[cfg(feature = "opencv")]
            Self::OpenCv(_) => Ok(cv::detect_corners(
                image,
                max_corners,
                min_distance_px,
                existing,
            )?),
            Self::Portable(_) => Ok(vision::detect_corners(
                image,
                max_corners,
                min_distance_px,
                existing,
            )),
        }
    }

    /// Relative pose (essential matrix RANSAC, cheirality) between normalised coordinates.
    pub(crate) fn relative_pose(
        &self,
        camera: &Camera,
        first: &[DVec2],
        second: &[DVec2],
        threshold_px: f64,
        minimal: vision::EssentialMinimal,
    ) -> Result<Option<(Se3, Vec<bool>)>, TrackerError> {
        match self {
            #[cfg(feature = "opencv")]
            Self::OpenCv(_) => Ok(cv::relative_pose(camera, first, second, threshold_px)?),
            Self::Portable(_) => Ok(vision::relative_pose_with(
                camera,
                first,
                second,
                threshold_px,
                minimal,
            )),
        }
    }

    /// Homography inliers (RANSAC) between normalised coordinates.
    pub(crate) fn homography_inliers(
        &self,
        camera: &Camera,
        first: &[DVec2],
        second: &[DVec2],
        threshold_px: f64,
    ) -> Result<usize, TrackerError> {
        match self {
            #[cfg(feature = "opencv")]
            Self::OpenCv(_) => Ok(cv::homography_inliers(camera, first, second, threshold_px)?),
            Self::Portable(_) => Ok(vision::homography_inliers(
                camera,
                first,
                second,
                threshold_px,
            )),
        }
    }

    /// Camera pose from 2D–3D correspondences inside RANSAC.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn pnp_ransac(
        &self,
        camera: &Camera,
        world: &[DVec3],
        normalized: &[DVec2],
        guess: Option<Se3>,
        threshold_px: f32,
        iterations: i32,
        minimal: PnpMinimal,
    ) -> Result<Option<(Se3, Vec<usize>)>, TrackerError> {
        match self {
            #[cfg(feature = "opencv")]
            Self::OpenCv(_) => Ok(cv::pnp_ransac(
                camera,
                world,
                normalized,
                guess,
                threshold_px,
                iterations,
                minimal,
            )?),
            Self::Portable(_) => Ok(vision::pnp_ransac(
                camera,
                world,
                normalized,
                guess,
                threshold_px,
                iterations,
                minimal,
            )),
        }
    }

    /// ORB descriptors of given points (None where the backend drops a point).
    pub(crate) fn describe(
        &mut self,
        image: &GrayImage,
        points: &[Vec2],
    ) -> Result<Vec<Option<Descriptor>>, TrackerError> {
        match self {
            #[cfg(feature = "opencv")]
            Self::OpenCv(orb) => Ok(orb.describe(image, points)?),
            Self::Portable(orb) => Ok(orb.describe(image, points)),
        }
    }

    /// Shi–Tomasi corners with their ORB descriptors.
    pub(crate) fn describe_corners(
        &mut self,
        image: &GrayImage,
        max_corners: usize,
        min_distance_px: f32,
    ) -> Result<Vec<(Vec2, Descriptor)>, TrackerError> {
        match self {
            #[cfg(feature = "opencv")]
            Self::OpenCv(orb) => Ok(orb.describe_corners(image, max_corners, min_distance_px)?),
            Self::Portable(orb) => Ok(orb.describe_corners(image, max_corners, min_distance_px)),
        }
    }
}
