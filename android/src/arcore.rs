//! The ARCore adapter: an ARCore session (world tracking, horizontal planes, ambient light)
//! read once per redraw into the app's [`PlatformFrame`]: the sensor camera's pose, the CPU
//! image's intrinsics and pixels, the point cloud with its ids, the tracked horizontal planes
//! and the light estimate. The session is created at the first resume once the camera
//! permission is granted (the Kotlin `MainActivity` asks for it at run time).

use std::ffi::c_void;
use std::ptr::null_mut;

use anyhow::{Context, bail};
use sylva_app::platform::{
    FrameProvider, PlatformFrame, PlatformTracking, YuvPlanes, rgba_from_yuv420,
};
use winit::platform::android::activity::AndroidApp;

use crate::arcore_ffi::*;
use crate::egl::CameraTextureContext;
use crate::mapping;

/// The start of JNI's invocation interface (`JNIInvokeInterface` in `jni.h`, fixed by the JNI
/// specification): the table a `JavaVM*` points to.
#[repr(C)]
struct JniInvokeInterface {
    reserved: [*mut c_void; 3],
    destroy_java_vm: unsafe extern "system" fn(vm: *mut *const JniInvokeInterface) -> i32,
    attach_current_thread: unsafe extern "system" fn(
        vm: *mut *const JniInvokeInterface,
        env: *mut *mut c_void,
        args: *mut c_void,
    ) -> i32,
}

/// The JNI environment of the calling thread (attached to the app's Java VM).
fn jni_env(app: &AndroidApp) -> anyhow::Result<*mut c_void> {
    let vm = app.vm_as_ptr() as *mut *const JniInvokeInterface;
    if vm.is_null() {
        bail!("no Java VM");
    }
    let mut env: *mut c_void = null_mut();
    // SAFETY: `vm` is the process's JavaVM from android-activity; attaching an attached thread
    // returns its existing environment.
    let status = unsafe { ((**vm).attach_current_thread)(vm, &mut env, null_mut()) };
    if status != 0 || env.is_null() {
        bail!("cannot attach the app thread to the Java VM (status {status})");
    }
    Ok(env)
}

/// Whether ARCore is installed and supported on this phone (asks for installing it when it is
/// supported but missing).
pub fn arcore_available(app: &AndroidApp) -> anyhow::Result<bool> {
    let env = jni_env(app)?;
    let mut availability = AR_AVAILABILITY_UNKNOWN_CHECKING;
    // SAFETY: valid env and activity pointers from android-activity.
    unsafe { ArCoreApk_checkAvailability(env, app.activity_as_ptr(), &mut availability) };
    if availability == AR_AVAILABILITY_SUPPORTED_INSTALLED {
        return Ok(true);
    }
    let mut install_status = 0;
    // SAFETY: as above; ARCore shows its own install prompt.
    let status =
        unsafe { ArCoreApk_requestInstall(env, app.activity_as_ptr(), 1, &mut install_status) };
    Ok(status == AR_SUCCESS && install_status == 0)
}

struct Session {
    session: *mut ArSession,
    frame: *mut ArFrame,
    pose: *mut ArPose,
    intrinsics: *mut ArCameraIntrinsics,
    light: *mut ArLightEstimate,
    planes: *mut ArTrackableList,
    /// Keeps the GL context current for `ArSession_update`.
    _texture: CameraTextureContext,
    first_timestamp_ns: Option<i64>,
}

/// Frames from an ARCore session.
pub struct ArCoreProvider {
    app: AndroidApp,
    session: Option<Session>,
    paused: bool,
}

impl ArCoreProvider {
    pub fn new(app: AndroidApp) -> ArCoreProvider {
        ArCoreProvider {
            app,
            session: None,
            paused: true,
        }
    }

    fn create_session(&self) -> anyhow::Result<Session> {
        let env = jni_env(&self.app)?;
        let texture = CameraTextureContext::new()?;
        let mut session = null_mut();
        // SAFETY: valid env and activity; every out-pointer is checked.
        unsafe {
            let status = ArSession_create(env, self.app.activity_as_ptr(), &mut session);
            if status != AR_SUCCESS || session.is_null() {
                bail!(
                    "cannot create the ARCore session (status {status}; is the camera permission granted?)"
                );
            }
            let mut config = null_mut();
            ArConfig_create(session, &mut config);
            ArConfig_setPlaneFindingMode(session, config, AR_PLANE_FINDING_MODE_HORIZONTAL);
            ArConfig_setLightEstimationMode(
                session,
                config,
                AR_LIGHT_ESTIMATION_MODE_AMBIENT_INTENSITY,
            );
            ArConfig_setUpdateMode(session, config, AR_UPDATE_MODE_LATEST_CAMERA_IMAGE);
            let status = ArSession_configure(session, config);
            ArConfig_destroy(config);
            if status != AR_SUCCESS {
                ArSession_destroy(session);
                bail!("ARCore refused the world-tracking configuration (status {status})");
            }
            ArSession_setCameraTextureName(session, texture.texture);
            let mut frame = null_mut();
            ArFrame_create(session, &mut frame);
            let mut pose = null_mut();
            ArPose_create(session, std::ptr::null(), &mut pose);
            let mut intrinsics = null_mut();
            ArCameraIntrinsics_create(session, &mut intrinsics);
            let mut light = null_mut();
            ArLightEstimate_create(session, &mut light);
            let mut planes = null_mut();
            ArTrackableList_create(session, &mut planes);
            Ok(Session {
                session,
                frame,
                pose,
                intrinsics,
                light,
                planes,
                _texture: texture,
                first_timestamp_ns: None,
            })
        }
    }
}

impl Session {
    /// Reads the frame ARCore has now.
    ///
    /// # Safety
    /// The session's handles are valid (created in `create_session`) and used on its thread.
    unsafe fn read_frame(&mut self) -> anyhow::Result<Option<PlatformFrame>> {
        let s = self.session;
        unsafe {
            if ArSession_update(s, self.frame) != AR_SUCCESS {
                return Ok(None);
            }
            let mut timestamp_ns = 0;
            ArFrame_getTimestamp(s, self.frame, &mut timestamp_ns);
            let first = *self.first_timestamp_ns.get_or_insert(timestamp_ns);
            let time_s = (timestamp_ns - first) as f64 * 1e-9;

            let mut camera = null_mut();
            ArFrame_acquireCamera(s, self.frame, &mut camera);
            let mut tracking_state = -1;
            ArCamera_getTrackingState(s, camera, &mut tracking_state);
            ArCamera_getImageIntrinsics(s, camera, self.intrinsics);
            let (mut focal, mut principal, mut size) = ([0.0f32; 2], [0.0f32; 2], [0i32; 2]);
            ArCameraIntrinsics_getFocalLength(s, self.intrinsics, &mut focal[0], &mut focal[1]);
            ArCameraIntrinsics_getPrincipalPoint(
                s,
                self.intrinsics,
                &mut principal[0],
                &mut principal[1],
            );
            ArCameraIntrinsics_getImageDimensions(s, self.intrinsics, &mut size[0], &mut size[1]);
            let world_from_camera = (tracking_state == AR_TRACKING_STATE_TRACKING).then(|| {
                let mut matrix = [0.0f32; 16];
                ArCamera_getPose(s, camera, self.pose);
                ArPose_getMatrix(s, self.pose, matrix.as_mut_ptr());
                mapping::world_from_camera_of_arcore(&matrix)
            });
            ArCamera_release(camera);
            let intrinsics = mapping::intrinsics_of_arcore(focal, principal, size)
                .context("ARCore reports no camera image size")?;

            let Some(rgba) = self.camera_image()? else {
                return Ok(None);
            };
            if (rgba.width(), rgba.height()) != (intrinsics.width, intrinsics.height) {
                bail!(
                    "ARCore's CPU image is {} x {}, its intrinsics are for {} x {}",
                    rgba.width(),
                    rgba.height(),
                    intrinsics.width,
                    intrinsics.height
                );
            }
            let tracking = PlatformTracking {
                world_from_camera,
                feature_points: self.feature_points(),
                planes: self.horizontal_planes(),
                light: self.light(),
            };
            Ok(Some(PlatformFrame {
                time_s,
                rgba,
                intrinsics,
                tracking: Some(tracking),
                up_in_camera: None,
            }))
        }
    }

    /// The CPU camera image (YUV_420_888) as RGBA; None when ARCore has none yet.
    unsafe fn camera_image(&mut self) -> anyhow::Result<Option<image::RgbaImage>> {
        let s = self.session;
        unsafe {
            let mut image = null_mut();
            if ArFrame_acquireCameraImage(s, self.frame, &mut image) != AR_SUCCESS
                || image.is_null()
            {
                return Ok(None);
            }
            let (mut width, mut height, mut format, mut num_planes) = (0, 0, 0, 0);
            ArImage_getWidth(s, image, &mut width);
            ArImage_getHeight(s, image, &mut height);
            ArImage_getFormat(s, image, &mut format);
            ArImage_getNumberOfPlanes(s, image, &mut num_planes);
            if format != AR_IMAGE_FORMAT_YUV_420_888 || num_planes != 3 {
                ArImage_release(image);
                bail!(
                    "ARCore's camera image has format {format:#x} with {num_planes} planes, not YUV_420_888"
                );
            }
            let plane = |index: i32| {
                let (mut data, mut length, mut row_stride, mut pixel_stride) =
                    (std::ptr::null(), 0, 0, 0);
                ArImage_getPlaneData(s, image, index, &mut data, &mut length);
                ArImage_getPlaneRowStride(s, image, index, &mut row_stride);
                ArImage_getPlanePixelStride(s, image, index, &mut pixel_stride);
                let bytes: &[u8] = if data.is_null() || length <= 0 {
                    &[]
                } else {
                    std::slice::from_raw_parts(data, length as usize)
                };
                (
                    bytes,
                    row_stride.max(0) as usize,
                    pixel_stride.max(0) as usize,
                )
            };
            let (y, y_row_stride, _) = plane(0);
            let (u, uv_row_stride, uv_pixel_stride) = plane(1);
            let (v, _, _) = plane(2);
            let rgba = rgba_from_yuv420(&YuvPlanes {
                width: width.max(0) as u32,
                height: height.max(0) as u32,
                y,
                y_row_stride,
                u,
                v,
                uv_row_stride,
                uv_pixel_stride,
                full_range: true,
            });
            ArImage_release(image);
            rgba.map(Some)
                .context("ARCore's camera image planes are shorter than its size")
        }
    }

    unsafe fn feature_points(&self) -> Vec<sylva_app::platform::FeaturePoint> {
        let s = self.session;
        unsafe {
            let mut cloud = null_mut();
            if ArFrame_acquirePointCloud(s, self.frame, &mut cloud) != AR_SUCCESS || cloud.is_null()
            {
                return Vec::new();
            }
            let mut count = 0;
            ArPointCloud_getNumberOfPoints(s, cloud, &mut count);
            let (mut data, mut ids) = (std::ptr::null(), std::ptr::null());
            ArPointCloud_getData(s, cloud, &mut data);
            ArPointCloud_getPointIds(s, cloud, &mut ids);
            let points = if count > 0 && !data.is_null() && !ids.is_null() {
                let n = count as usize;
                mapping::feature_points_of_arcore(
                    std::slice::from_raw_parts(data, 4 * n),
                    std::slice::from_raw_parts(ids, n),
                )
            } else {
                Vec::new()
            };
            ArPointCloud_release(cloud);
            points
        }
    }

    unsafe fn horizontal_planes(&self) -> Vec<sylva_app::platform::PlatformPlane> {
        let s = self.session;
        let mut planes = Vec::new();
        unsafe {
            ArSession_getAllTrackables(s, AR_TRACKABLE_PLANE, self.planes);
            let mut size = 0;
            ArTrackableList_getSize(s, self.planes, &mut size);
            for i in 0..size {
                let mut plane = null_mut();
                ArTrackableList_acquireItem(s, self.planes, i, &mut plane);
                let (mut state, mut kind) = (-1, -1);
                ArTrackable_getTrackingState(s, plane, &mut state);
                ArPlane_getType(s, plane, &mut kind);
                let mut subsumed_by = null_mut();
                ArPlane_acquireSubsumedBy(s, plane, &mut subsumed_by);
                if !subsumed_by.is_null() {
                    ArTrackable_release(subsumed_by);
                }
                if state == AR_TRACKING_STATE_TRACKING
                    && kind == AR_PLANE_HORIZONTAL_UPWARD_FACING
                    && subsumed_by.is_null()
                {
                    let mut matrix = [0.0f32; 16];
                    let mut extent = [0.0f32; 2];
                    ArPlane_getCenterPose(s, plane, self.pose);
                    ArPose_getMatrix(s, self.pose, matrix.as_mut_ptr());
                    ArPlane_getExtentX(s, plane, &mut extent[0]);
                    ArPlane_getExtentZ(s, plane, &mut extent[1]);
                    // The handle stays the same while ARCore tracks the plane.
                    planes.push(mapping::plane_of_arcore(plane as u64, &matrix, extent));
                }
                ArTrackable_release(plane);
            }
        }
        planes
    }

    unsafe fn light(&self) -> Option<sylva_app::platform::LightEstimate> {
        let s = self.session;
        unsafe {
            ArFrame_getLightEstimate(s, self.frame, self.light);
            let mut state = 0;
            ArLightEstimate_getState(s, self.light, &mut state);
            if state != AR_LIGHT_ESTIMATE_STATE_VALID {
                return None;
            }
            let mut intensity = 0.0;
            let mut correction = [0.0f32; 4];
            ArLightEstimate_getPixelIntensity(s, self.light, &mut intensity);
            ArLightEstimate_getColorCorrection(s, self.light, correction.as_mut_ptr());
            Some(mapping::light_of_arcore(intensity, correction))
        }
    }
}

impl Drop for Session {
    fn drop(&mut self) {
        // SAFETY: handles created in `create_session`, destroyed once, session last.
        unsafe {
            ArTrackableList_destroy(self.planes);
            ArLightEstimate_destroy(self.light);
            ArCameraIntrinsics_destroy(self.intrinsics);
            ArPose_destroy(self.pose);
            ArFrame_destroy(self.frame);
            ArSession_destroy(self.session);
        }
    }
}

impl FrameProvider for ArCoreProvider {
    fn poll_frame(&mut self) -> anyhow::Result<Option<PlatformFrame>> {
        match self.session.as_mut() {
            // SAFETY: the session lives on this (the app's main) thread.
            Some(session) if !self.paused => unsafe { session.read_frame() },
            _ => Ok(None),
        }
    }

    fn pause(&mut self) -> anyhow::Result<()> {
        self.paused = true;
        if let Some(session) = &self.session {
            // SAFETY: a valid session.
            let status = unsafe { ArSession_pause(session.session) };
            if status != AR_SUCCESS {
                bail!("ARCore did not pause (status {status})");
            }
        }
        Ok(())
    }

    fn resume(&mut self) -> anyhow::Result<()> {
        if self.session.is_none() {
            match self.create_session() {
                Ok(session) => self.session = Some(session),
                // Without the camera permission yet: tried again at the next resume (the
                // permission dialog pauses and resumes the activity).
                Err(error) => {
                    eprintln!("warning: {error:#}");
                    return Ok(());
                }
            }
        }
        if let Some(session) = &self.session {
            // SAFETY: a valid session.
            let status = unsafe { ArSession_resume(session.session) };
            if status != AR_SUCCESS {
                bail!("ARCore did not resume (status {status})");
            }
        }
        self.paused = false;
        Ok(())
    }
}
