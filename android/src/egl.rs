//! ARCore updates its camera texture through OpenGL ES: `ArSession_update` needs a current GL
//! context and a texture name set with `ArSession_setCameraTextureName`, even when the app only
//! reads the CPU image (Sylva draws with wgpu on Vulkan). This is the smallest such context: a
//! 1 × 1 pbuffer on the thread that updates the session, with one external-OES texture.

use std::ffi::c_void;

type EglDisplay = *mut c_void;
type EglConfig = *mut c_void;
type EglContext = *mut c_void;
type EglSurface = *mut c_void;

const EGL_NONE: i32 = 0x3038;
const EGL_RENDERABLE_TYPE: i32 = 0x3040;
const EGL_OPENGL_ES2_BIT: i32 = 0x0004;
const EGL_SURFACE_TYPE: i32 = 0x3033;
const EGL_PBUFFER_BIT: i32 = 0x0001;
const EGL_WIDTH: i32 = 0x3057;
const EGL_HEIGHT: i32 = 0x3056;
const EGL_CONTEXT_CLIENT_VERSION: i32 = 0x3098;
const GL_TEXTURE_EXTERNAL_OES: u32 = 0x8D65;

#[link(name = "EGL")]
unsafe extern "C" {
    fn eglGetDisplay(display_id: *mut c_void) -> EglDisplay;
    fn eglInitialize(display: EglDisplay, major: *mut i32, minor: *mut i32) -> u32;
    fn eglChooseConfig(
        display: EglDisplay,
        attrib_list: *const i32,
        configs: *mut EglConfig,
        config_size: i32,
        num_config: *mut i32,
    ) -> u32;
    fn eglCreateContext(
        display: EglDisplay,
        config: EglConfig,
        share_context: EglContext,
        attrib_list: *const i32,
    ) -> EglContext;
    fn eglCreatePbufferSurface(
        display: EglDisplay,
        config: EglConfig,
        attrib_list: *const i32,
    ) -> EglSurface;
    fn eglMakeCurrent(
        display: EglDisplay,
        draw: EglSurface,
        read: EglSurface,
        context: EglContext,
    ) -> u32;
    fn eglDestroySurface(display: EglDisplay, surface: EglSurface) -> u32;
    fn eglDestroyContext(display: EglDisplay, context: EglContext) -> u32;
}

#[link(name = "GLESv2")]
unsafe extern "C" {
    fn glGenTextures(n: i32, textures: *mut u32);
    fn glBindTexture(target: u32, texture: u32);
    fn glDeleteTextures(n: i32, textures: *const u32);
}

/// A current GL ES 2 context with the camera texture ARCore writes into.
pub struct CameraTextureContext {
    display: EglDisplay,
    context: EglContext,
    surface: EglSurface,
    pub texture: u32,
}

impl CameraTextureContext {
    /// Creates the context, makes it current on this thread and creates the texture.
    pub fn new() -> anyhow::Result<CameraTextureContext> {
        // SAFETY: plain EGL calls with valid attribute lists; every handle is checked before use.
        unsafe {
            let display = eglGetDisplay(std::ptr::null_mut());
            if display.is_null()
                || eglInitialize(display, std::ptr::null_mut(), std::ptr::null_mut()) == 0
            {
                anyhow::bail!("no EGL display for ARCore's camera texture");
            }
            let attributes = [
                EGL_RENDERABLE_TYPE,
                EGL_OPENGL_ES2_BIT,
                EGL_SURFACE_TYPE,
                EGL_PBUFFER_BIT,
                EGL_NONE,
            ];
            let mut config: EglConfig = std::ptr::null_mut();
            let mut num_configs = 0;
            if eglChooseConfig(
                display,
                attributes.as_ptr(),
                &mut config,
                1,
                &mut num_configs,
            ) == 0
                || num_configs < 1
            {
                anyhow::bail!("no EGL configuration for ARCore's camera texture");
            }
            let context_attributes = [EGL_CONTEXT_CLIENT_VERSION, 2, EGL_NONE];
            let context = eglCreateContext(
                display,
                config,
                std::ptr::null_mut(),
                context_attributes.as_ptr(),
            );
            let surface_attributes = [EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE];
            let surface = eglCreatePbufferSurface(display, config, surface_attributes.as_ptr());
            if context.is_null()
                || surface.is_null()
                || eglMakeCurrent(display, surface, surface, context) == 0
            {
                anyhow::bail!("cannot make a GL context current for ARCore's camera texture");
            }
            let mut texture = 0;
            glGenTextures(1, &mut texture);
            glBindTexture(GL_TEXTURE_EXTERNAL_OES, texture);
            Ok(CameraTextureContext {
                display,
                context,
                surface,
                texture,
            })
        }
    }
}

impl Drop for CameraTextureContext {
    fn drop(&mut self) {
        // SAFETY: the handles were created by `new` and are released once.
        unsafe {
            glDeleteTextures(1, &self.texture);
            eglMakeCurrent(
                self.display,
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                std::ptr::null_mut(),
            );
            eglDestroySurface(self.display, self.surface);
            eglDestroyContext(self.display, self.context);
        }
    }
}
