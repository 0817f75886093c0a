//! The part of ARCore's C API (`arcore_c_api.h` of the ARCore SDK for Android NDK) the shell
//! calls, declared by hand: no crate wraps it. Linked against `libarcore_sdk_c.so` from the
//! ARCore AAR (`com.google.ar:core`), which Gradle unpacks (see `app/build.gradle.kts`).
//!
//! Opaque handles are zero-sized `#[repr(C)]` structs used only behind pointers; ARCore's enums
//! are `int32_t`.

#![allow(non_camel_case_types, dead_code)]

use std::ffi::c_void;

macro_rules! opaque {
    ($($name:ident),* $(,)?) => {
        $(
            #[repr(C)]
            pub struct $name {
                _private: [u8; 0],
            }
        )*
    };
}

opaque!(
    ArSession,
    ArConfig,
    ArFrame,
    ArCamera,
    ArCameraIntrinsics,
    ArPose,
    ArPointCloud,
    ArTrackable,
    ArTrackableList,
    ArLightEstimate,
    ArImage,
);

/// `ArPlane` is an `ArTrackable` of type `AR_TRACKABLE_PLANE` (the header's `ArAsPlane` is a
/// cast).
pub type ArPlane = ArTrackable;

pub type ArStatus = i32;
pub type ArTrackingState = i32;
pub type ArTrackableType = i32;
pub type ArPlaneType = i32;
pub type ArPlaneFindingMode = i32;
pub type ArLightEstimationMode = i32;
pub type ArLightEstimateState = i32;
pub type ArUpdateMode = i32;
pub type ArImageFormat = i32;
pub type ArAvailability = i32;
pub type ArInstallStatus = i32;

pub const AR_SUCCESS: ArStatus = 0;
pub const AR_ERROR_NOT_YET_AVAILABLE: ArStatus = -12;
pub const AR_TRACKING_STATE_TRACKING: ArTrackingState = 0;
pub const AR_TRACKABLE_PLANE: ArTrackableType = 0x4152_0101;
pub const AR_PLANE_HORIZONTAL_UPWARD_FACING: ArPlaneType = 0;
pub const AR_PLANE_FINDING_MODE_HORIZONTAL: ArPlaneFindingMode = 1;
pub const AR_LIGHT_ESTIMATION_MODE_AMBIENT_INTENSITY: ArLightEstimationMode = 1;
pub const AR_LIGHT_ESTIMATE_STATE_VALID: ArLightEstimateState = 1;
pub const AR_UPDATE_MODE_LATEST_CAMERA_IMAGE: ArUpdateMode = 1;
pub const AR_IMAGE_FORMAT_YUV_420_888: ArImageFormat = 0x23;
pub const AR_AVAILABILITY_UNKNOWN_CHECKING: ArAvailability = 1;
pub const AR_AVAILABILITY_SUPPORTED_INSTALLED: ArAvailability = 203;

#[link(name = "arcore_sdk_c")]
unsafe extern "C" {
    pub fn ArCoreApk_checkAvailability(
        env: *mut c_void,
        context: *mut c_void,
        out_availability: *mut ArAvailability,
    );
    pub fn ArCoreApk_requestInstall(
        env: *mut c_void,
        application_activity: *mut c_void,
        user_requested_install: i32,
        out_install_status: *mut ArInstallStatus,
    ) -> ArStatus;

    pub fn ArSession_create(
        env: *mut c_void,
        context: *mut c_void,
        out_session_pointer: *mut *mut ArSession,
    ) -> ArStatus;
    pub fn ArSession_destroy(session: *mut ArSession);
    pub fn ArSession_configure(session: *mut ArSession, config: *const ArConfig) -> ArStatus;
    pub fn ArSession_resume(session: *mut ArSession) -> ArStatus;
    pub fn ArSession_pause(session: *mut ArSession) -> ArStatus;
    pub fn ArSession_update(session: *mut ArSession, out_frame: *mut ArFrame) -> ArStatus;
    pub fn ArSession_setCameraTextureName(session: *mut ArSession, texture_id: u32);
    pub fn ArSession_setDisplayGeometry(
        session: *mut ArSession,
        rotation: i32,
        width: i32,
        height: i32,
    );
    pub fn ArSession_getAllTrackables(
        session: *const ArSession,
        filter_type: ArTrackableType,
        out_trackable_list: *mut ArTrackableList,
    );

    pub fn ArConfig_create(session: *const ArSession, out_config: *mut *mut ArConfig);
    pub fn ArConfig_destroy(config: *mut ArConfig);
    pub fn ArConfig_setPlaneFindingMode(
        session: *const ArSession,
        config: *mut ArConfig,
        plane_finding_mode: ArPlaneFindingMode,
    );
    pub fn ArConfig_setLightEstimationMode(
        session: *const ArSession,
        config: *mut ArConfig,
        light_estimation_mode: ArLightEstimationMode,
    );
    pub fn ArConfig_setUpdateMode(
        session: *const ArSession,
        config: *mut ArConfig,
        update_mode: ArUpdateMode,
    );

    pub fn ArFrame_create(session: *const ArSession, out_frame: *mut *mut ArFrame);
    pub fn ArFrame_destroy(frame: *mut ArFrame);
    pub fn ArFrame_getTimestamp(
        session: *const ArSession,
        frame: *const ArFrame,
        out_timestamp_ns: *mut i64,
    );
    pub fn ArFrame_acquireCamera(
        session: *const ArSession,
        frame: *const ArFrame,
        out_camera: *mut *mut ArCamera,
    );
    pub fn ArFrame_acquirePointCloud(
        session: *const ArSession,
        frame: *const ArFrame,
        out_point_cloud: *mut *mut ArPointCloud,
    ) -> ArStatus;
    pub fn ArFrame_acquireCameraImage(
        session: *mut ArSession,
        frame: *mut ArFrame,
        out_image: *mut *mut ArImage,
    ) -> ArStatus;
    pub fn ArFrame_getLightEstimate(
        session: *const ArSession,
        frame: *const ArFrame,
        out_light_estimate: *mut ArLightEstimate,
    );

    pub fn ArCamera_release(camera: *mut ArCamera);
    pub fn ArCamera_getTrackingState(
        session: *const ArSession,
        camera: *const ArCamera,
        out_tracking_state: *mut ArTrackingState,
    );
    pub fn ArCamera_getPose(
        session: *const ArSession,
        camera: *const ArCamera,
        out_pose: *mut ArPose,
    );
    pub fn ArCamera_getImageIntrinsics(
        session: *const ArSession,
        camera: *const ArCamera,
        out_camera_intrinsics: *mut ArCameraIntrinsics,
    );

    pub fn ArCameraIntrinsics_create(
        session: *const ArSession,
        out_camera_intrinsics: *mut *mut ArCameraIntrinsics,
    );
    pub fn ArCameraIntrinsics_destroy(camera_intrinsics: *mut ArCameraIntrinsics);
    pub fn ArCameraIntrinsics_getFocalLength(
        session: *const ArSession,
        intrinsics: *const ArCameraIntrinsics,
        out_fx: *mut f32,
        out_fy: *mut f32,
    );
    pub fn ArCameraIntrinsics_getPrincipalPoint(
        session: *const ArSession,
        intrinsics: *const ArCameraIntrinsics,
        out_cx: *mut f32,
        out_cy: *mut f32,
    );
    pub fn ArCameraIntrinsics_getImageDimensions(
        session: *const ArSession,
        intrinsics: *const ArCameraIntrinsics,
        out_width: *mut i32,
        out_height: *mut i32,
    );

    pub fn ArPose_create(
        session: *const ArSession,
        pose_raw: *const f32,
        out_pose: *mut *mut ArPose,
    );
    pub fn ArPose_destroy(pose: *mut ArPose);
    pub fn ArPose_getMatrix(
        session: *const ArSession,
        pose: *const ArPose,
        out_matrix_col_major_4x4: *mut f32,
    );

    pub fn ArPointCloud_getNumberOfPoints(
        session: *const ArSession,
        point_cloud: *const ArPointCloud,
        out_number_of_points: *mut i32,
    );
    pub fn ArPointCloud_getData(
        session: *const ArSession,
        point_cloud: *const ArPointCloud,
        out_point_cloud_data: *mut *const f32,
    );
    pub fn ArPointCloud_getPointIds(
        session: *const ArSession,
        point_cloud: *const ArPointCloud,
        out_point_ids: *mut *const i32,
    );
    pub fn ArPointCloud_release(point_cloud: *mut ArPointCloud);

    pub fn ArTrackableList_create(
        session: *const ArSession,
        out_trackable_list: *mut *mut ArTrackableList,
    );
    pub fn ArTrackableList_destroy(trackable_list: *mut ArTrackableList);
    pub fn ArTrackableList_getSize(
        session: *const ArSession,
        trackable_list: *const ArTrackableList,
        out_size: *mut i32,
    );
    pub fn ArTrackableList_acquireItem(
        session: *const ArSession,
        trackable_list: *const ArTrackableList,
        index: i32,
        out_trackable: *mut *mut ArTrackable,
    );
    pub fn ArTrackable_release(trackable: *mut ArTrackable);
    pub fn ArTrackable_getTrackingState(
        session: *const ArSession,
        trackable: *const ArTrackable,
        out_tracking_state: *mut ArTrackingState,
    );

    pub fn ArPlane_getType(
        session: *const ArSession,
        plane: *const ArPlane,
        out_plane_type: *mut ArPlaneType,
    );
    pub fn ArPlane_getCenterPose(
        session: *const ArSession,
        plane: *const ArPlane,
        out_pose: *mut ArPose,
    );
    pub fn ArPlane_getExtentX(
        session: *const ArSession,
        plane: *const ArPlane,
        out_extent_x: *mut f32,
    );
    pub fn ArPlane_getExtentZ(
        session: *const ArSession,
        plane: *const ArPlane,
        out_extent_z: *mut f32,
    );
    pub fn ArPlane_acquireSubsumedBy(
        session: *const ArSession,
        plane: *const ArPlane,
        out_subsumed_by: *mut *mut ArPlane,
    );

    pub fn ArLightEstimate_create(
        session: *const ArSession,
        out_light_estimate: *mut *mut ArLightEstimate,
    );
    pub fn ArLightEstimate_destroy(light_estimate: *mut ArLightEstimate);
    pub fn ArLightEstimate_getState(
        session: *const ArSession,
        light_estimate: *const ArLightEstimate,
        out_light_estimate_state: *mut ArLightEstimateState,
    );
    pub fn ArLightEstimate_getPixelIntensity(
        session: *const ArSession,
        light_estimate: *const ArLightEstimate,
        out_pixel_intensity: *mut f32,
    );
    pub fn ArLightEstimate_getColorCorrection(
        session: *const ArSession,
        light_estimate: *const ArLightEstimate,
        out_color_correction_4: *mut f32,
    );

    pub fn ArImage_release(image: *mut ArImage);
    pub fn ArImage_getWidth(session: *const ArSession, image: *const ArImage, out_width: *mut i32);
    pub fn ArImage_getHeight(
        session: *const ArSession,
        image: *const ArImage,
        out_height: *mut i32,
    );
    pub fn ArImage_getFormat(
        session: *const ArSession,
        image: *const ArImage,
        out_format: *mut ArImageFormat,
    );
    pub fn ArImage_getNumberOfPlanes(
        session: *const ArSession,
        image: *const ArImage,
        out_num_planes: *mut i32,
    );
    pub fn ArImage_getPlanePixelStride(
        session: *const ArSession,
        image: *const ArImage,
        plane_index: i32,
        out_pixel_stride: *mut i32,
    );
    pub fn ArImage_getPlaneRowStride(
        session: *const ArSession,
        image: *const ArImage,
        plane_index: i32,
        out_row_stride: *mut i32,
    );
    pub fn ArImage_getPlaneData(
        session: *const ArSession,
        image: *const ArImage,
        plane_index: i32,
        out_data: *mut *const u8,
        out_data_length: *mut i32,
    );
}
