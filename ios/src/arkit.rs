//! The ARKit adapter: an `ARSession` with world tracking (horizontal plane detection, light
//! estimation) read once per redraw into the app's [`PlatformFrame`]: the camera transform and
//! intrinsics, the captured image (bi-planar YUV 4:2:0) as RGBA, `rawFeaturePoints` with their
//! identifiers, the horizontal `ARPlaneAnchor`s and the light estimate.
//!
//! The simd-typed properties (`transform`, `intrinsics`, `points`, `center`) are not in the
//! generated bindings (objc2 has no simd types): they are sent with `msg_send!` and returned in
//! `#[repr(C)]` structs of NEON vectors, which arm64 returns in vector registers exactly as it
//! returns `simd_float4x4` (a homogeneous aggregate of four 128-bit vectors).

use std::arch::aarch64::float32x4_t;

use anyhow::bail;
use objc2::encode::{Encode, Encoding, RefEncode};
use objc2::rc::Retained;
use objc2::runtime::AnyObject;
use objc2::{ClassType, msg_send};
use objc2_ar_kit::{
    ARFrame, ARPlaneAnchor, ARPlaneAnchorAlignment, ARPlaneDetection, ARSession, ARTrackingState,
    ARWorldTrackingConfiguration,
};
use objc2_core_video::{
    CVPixelBuffer, CVPixelBufferGetBaseAddressOfPlane, CVPixelBufferGetBytesPerRowOfPlane,
    CVPixelBufferGetHeightOfPlane, CVPixelBufferGetPlaneCount, CVPixelBufferGetWidthOfPlane,
    CVPixelBufferLockBaseAddress, CVPixelBufferLockFlags, CVPixelBufferUnlockBaseAddress,
};
use sylva_app::platform::{
    FrameProvider, PlatformFrame, PlatformTracking, YuvPlanes, rgba_from_yuv420,
};

use crate::mapping;

/// `simd_float3` (16 bytes: three lanes and padding).
#[repr(C)]
#[derive(Clone, Copy)]
struct SimdFloat3(float32x4_t);

/// `simd_float3x3`: three column vectors.
#[repr(C)]
#[derive(Clone, Copy)]
struct SimdFloat3x3([float32x4_t; 3]);

/// `simd_float4x4`: four column vectors.
#[repr(C)]
#[derive(Clone, Copy)]
struct SimdFloat4x4([float32x4_t; 4]);

// The encodings are only compared in debug builds, and objc2's `disable-encoding-assertions`
// turns that off: the runtime describes simd types as opaque.
unsafe impl Encode for SimdFloat3 {
    const ENCODING: Encoding = Encoding::Struct("?", &[]);
}
// `rawFeaturePoints.points` returns a pointer to them.
unsafe impl RefEncode for SimdFloat3 {
    const ENCODING_REF: Encoding = Encoding::Pointer(&Self::ENCODING);
}
unsafe impl Encode for SimdFloat3x3 {
    const ENCODING: Encoding = Encoding::Struct("?", &[]);
}
unsafe impl Encode for SimdFloat4x4 {
    const ENCODING: Encoding = Encoding::Struct("?", &[]);
}

fn lanes(v: float32x4_t) -> [f32; 4] {
    // SAFETY: a float32x4_t is four f32 lanes.
    unsafe { std::mem::transmute::<float32x4_t, [f32; 4]>(v) }
}

fn columns4(m: SimdFloat4x4) -> [[f32; 4]; 4] {
    m.0.map(lanes)
}

/// Frames from an ARKit world-tracking session.
pub struct ArKitProvider {
    session: Retained<ARSession>,
    configuration: Retained<ARWorldTrackingConfiguration>,
    last_timestamp_s: Option<f64>,
    first_timestamp_s: Option<f64>,
    running: bool,
}

impl ArKitProvider {
    /// A session for this device; an error when it has no world tracking.
    pub fn new() -> anyhow::Result<ArKitProvider> {
        // SAFETY: plain ARKit class methods on the main thread.
        unsafe {
            // A class method of the concrete configuration (ARConfiguration's own says no).
            let supported: bool = msg_send![ARWorldTrackingConfiguration::class(), isSupported];
            if !supported {
                bail!("this device has no ARKit world tracking");
            }
            let configuration = ARWorldTrackingConfiguration::new();
            configuration.setPlaneDetection(ARPlaneDetection::Horizontal);
            configuration.setLightEstimationEnabled(true);
            Ok(ArKitProvider {
                session: ARSession::new(),
                configuration,
                last_timestamp_s: None,
                first_timestamp_s: None,
                running: false,
            })
        }
    }

    /// # Safety
    /// `frame` is the session's current frame, read on the main thread.
    unsafe fn read(&mut self, frame: &ARFrame) -> anyhow::Result<Option<PlatformFrame>> {
        unsafe {
            let timestamp_s = frame.timestamp();
            if self.last_timestamp_s == Some(timestamp_s) {
                return Ok(None);
            }
            self.last_timestamp_s = Some(timestamp_s);
            let first = *self.first_timestamp_s.get_or_insert(timestamp_s);
            let camera = frame.camera();
            let camera_object: &AnyObject = &camera;
            let transform: SimdFloat4x4 = msg_send![camera_object, transform];
            let intrinsics: SimdFloat3x3 = msg_send![camera_object, intrinsics];
            let resolution = camera.imageResolution();
            let Some(intrinsics) = mapping::intrinsics_of_arkit(
                intrinsics.0.map(lanes),
                [resolution.width, resolution.height],
            ) else {
                bail!("ARKit reports an empty camera image");
            };
            let world_from_camera = (camera.trackingState() == ARTrackingState::Normal)
                .then(|| mapping::world_from_camera_of_arkit(columns4(transform)));
            let rgba = captured_rgba(&frame.capturedImage())?;
            if (rgba.width(), rgba.height()) != (intrinsics.width, intrinsics.height) {
                bail!(
                    "ARKit's captured image is {} x {}, its intrinsics are for {} x {}",
                    rgba.width(),
                    rgba.height(),
                    intrinsics.width,
                    intrinsics.height
                );
            }
            let feature_points = match frame.rawFeaturePoints() {
                Some(cloud) => {
                    let count = cloud.count();
                    let cloud_object: &AnyObject = &cloud;
                    let points: *const SimdFloat3 = msg_send![cloud_object, points];
                    let ids = cloud.identifiers();
                    if count == 0 || points.is_null() {
                        Vec::new()
                    } else {
                        let points = std::slice::from_raw_parts(points, count);
                        let ids = std::slice::from_raw_parts(ids.as_ptr(), count);
                        let points: Vec<[f32; 4]> = points.iter().map(|p| lanes(p.0)).collect();
                        mapping::feature_points_of_arkit(&points, ids)
                    }
                }
                None => Vec::new(),
            };
            let mut planes = Vec::new();
            for anchor in frame.anchors().iter() {
                let Ok(plane) = anchor.downcast::<ARPlaneAnchor>() else {
                    continue;
                };
                if plane.alignment() != ARPlaneAnchorAlignment::Horizontal {
                    continue;
                }
                let anchor_object: &AnyObject = &plane;
                let transform: SimdFloat4x4 = msg_send![anchor_object, transform];
                let center: SimdFloat3 = msg_send![anchor_object, center];
                let extent = plane.planeExtent();
                // The anchor object is the same while ARKit tracks the plane.
                let id = Retained::as_ptr(&plane) as u64;
                planes.push(mapping::plane_of_arkit(
                    id,
                    columns4(transform),
                    lanes(center.0),
                    [extent.width(), extent.height()],
                ));
            }
            let light = frame.lightEstimate().map(|light| {
                mapping::light_of_arkit(light.ambientIntensity(), light.ambientColorTemperature())
            });
            Ok(Some(PlatformFrame {
                time_s: timestamp_s - first,
                rgba,
                intrinsics,
                tracking: Some(PlatformTracking {
                    world_from_camera,
                    feature_points,
                    planes,
                    light,
                }),
                up_in_camera: None,
            }))
        }
    }
}

/// The captured image (`420f`: a luma plane and an interleaved CbCr plane) as RGBA.
fn captured_rgba(buffer: &CVPixelBuffer) -> anyhow::Result<image::RgbaImage> {
    // SAFETY: the buffer is locked read-only while its planes are read, and unlocked after.
    unsafe {
        if CVPixelBufferGetPlaneCount(buffer) != 2 {
            bail!("ARKit's captured image is not bi-planar YUV");
        }
        if CVPixelBufferLockBaseAddress(buffer, CVPixelBufferLockFlags::ReadOnly) != 0 {
            bail!("cannot lock ARKit's captured image");
        }
        let plane = |index: usize| {
            let base = CVPixelBufferGetBaseAddressOfPlane(buffer, index) as *const u8;
            let row = CVPixelBufferGetBytesPerRowOfPlane(buffer, index);
            let height = CVPixelBufferGetHeightOfPlane(buffer, index);
            let bytes: &[u8] = if base.is_null() {
                &[]
            } else {
                std::slice::from_raw_parts(base, row * height)
            };
            (bytes, row)
        };
        let (y, y_row_stride) = plane(0);
        let (cbcr, uv_row_stride) = plane(1);
        let rgba = rgba_from_yuv420(&YuvPlanes {
            width: CVPixelBufferGetWidthOfPlane(buffer, 0) as u32,
            height: CVPixelBufferGetHeightOfPlane(buffer, 0) as u32,
            y,
            y_row_stride,
            u: cbcr,
            v: cbcr.get(1..).unwrap_or(&[]),
            uv_row_stride,
            uv_pixel_stride: 2,
            full_range: true,
        });
        CVPixelBufferUnlockBaseAddress(buffer, CVPixelBufferLockFlags::ReadOnly);
        match rgba {
            Some(rgba) => Ok(rgba),
            None => bail!("ARKit's captured image planes are shorter than its size"),
        }
    }
}

impl FrameProvider for ArKitProvider {
    fn poll_frame(&mut self) -> anyhow::Result<Option<PlatformFrame>> {
        if !self.running {
            return Ok(None);
        }
        // SAFETY: ARKit on the main thread, where winit runs the app.
        unsafe {
            match self.session.currentFrame() {
                Some(frame) => self.read(&frame),
                None => Ok(None),
            }
        }
    }

    fn pause(&mut self) -> anyhow::Result<()> {
        // SAFETY: as above.
        unsafe { self.session.pause() };
        self.running = false;
        Ok(())
    }

    fn resume(&mut self) -> anyhow::Result<()> {
        // SAFETY: as above; running a running session again keeps its world.
        unsafe { self.session.runWithConfiguration(&self.configuration) };
        self.running = true;
        Ok(())
    }
}
