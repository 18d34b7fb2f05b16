//! One headless OpenGL context for the process: an EGL device (Mesa's
//! llvmpipe on a machine without a GPU), a display on it, and a core 4.5
//! context made current without a surface. It has no default framebuffer;
//! the passes draw into their own (`target`).
//!
//! The context is kept not current in a mutex and made current on whichever
//! thread renders, for the length of one call, so the renderer stays `Send`
//! and `Sync` while GL objects never cross threads while in use.

use glutin::api::egl::context::NotCurrentContext;
use glutin::api::egl::device::Device;
use glutin::api::egl::display::Display;
use glutin::config::{Api, ConfigSurfaceTypes, ConfigTemplateBuilder};
use glutin::context::{ContextApi, ContextAttributesBuilder, GlProfile, Version};
use glutin::prelude::*;
use std::ffi::CStr;
use std::sync::Mutex;

/// `glClipControl`, which glow does not wrap: loaded from the driver.
pub type ClipControl = unsafe extern "system" fn(origin: u32, depth: u32);

/// The GL state that lives as long as the context: the function table and
/// whatever the renderer keeps between calls (programs, buffers, targets).
pub struct Gl<T> {
    pub gl: glow::Context,
    pub clip_control: ClipControl,
    /// The driver's `GL_RENDERER` string (e.g. "llvmpipe (LLVM ...)").
    pub renderer: String,
    pub state: Option<T>,
}

struct Headless<T> {
    context: Option<NotCurrentContext>,
    gl: Gl<T>,
}

/// The context, created on first use; `Err` (kept) when there is no usable driver.
pub struct Shared<T> {
    inner: Mutex<Option<Result<Headless<T>, String>>>,
}

impl<T> Shared<T> {
    pub const fn new() -> Shared<T> {
        Shared { inner: Mutex::new(None) }
    }

    /// Destroys the context, if one was made, while the process is still
    /// whole. Left to the C library's exit handlers, the driver would tear
    /// its context down while its own rasterizer threads may still run.
    pub fn shutdown(&self) {
        let mut guard = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(Ok(mut headless)) = guard.take() {
            headless.gl.state = None;
            drop(headless);
        }
    }

    /// `shutdown`, unless another thread is using the context right now
    /// (at exit, waiting for it could hang the process).
    pub fn try_shutdown(&self) {
        let mut guard = match self.inner.try_lock() {
            Ok(g) => g,
            Err(std::sync::TryLockError::Poisoned(e)) => e.into_inner(),
            Err(std::sync::TryLockError::WouldBlock) => return,
        };
        if let Some(Ok(mut headless)) = guard.take() {
            headless.gl.state = None;
            drop(headless);
        }
    }

    /// Runs `f` with the context current on this thread; the error (one
    /// sentence) when no OpenGL driver can be used.
    pub fn with<R>(&self, f: impl FnOnce(&mut Gl<T>) -> R) -> Result<R, String> {
        let mut guard = self.inner.lock().unwrap_or_else(|e| e.into_inner());
        let slot = guard.get_or_insert_with(create);
        let headless = match slot {
            Ok(h) => h,
            Err(e) => return Err(e.clone()),
        };
        let Some(not_current) = headless.context.take() else {
            return Err("the OpenGL context was lost after an earlier failure".into());
        };
        let current = not_current.make_current_surfaceless().map_err(|e| format!("cannot make the OpenGL context current: {e}"))?;
        let result = f(&mut headless.gl);
        match current.make_not_current() {
            Ok(c) => headless.context = Some(c),
            Err(e) => return Err(format!("cannot release the OpenGL context: {e}")),
        }
        Ok(result)
    }
}

fn create<T>() -> Result<Headless<T>, String> {
    let no_driver = |why: String| format!("no usable OpenGL driver for the opengl renderer ({why}); install Mesa (libegl1, libegl-mesa0, libgl1-mesa-dri)");
    let devices: Vec<Device> = Device::query_devices().map_err(|e| no_driver(format!("no EGL devices: {e}")))?.collect();
    let mut last = String::from("no EGL device found");
    for device in &devices {
        match create_on(device) {
            Ok(h) => return Ok(h),
            Err(e) => last = e,
        }
    }
    Err(no_driver(last))
}

fn create_on<T>(device: &Device) -> Result<Headless<T>, String> {
    // SAFETY: no native display handle is passed, so glutin opens the device itself.
    let display = unsafe { Display::with_device(device, None) }.map_err(|e| format!("EGL display: {e}"))?;
    let template = ConfigTemplateBuilder::new().with_surface_type(ConfigSurfaceTypes::empty()).with_api(Api::OPENGL).build();
    // SAFETY: the template holds no native window.
    let config = unsafe { display.find_configs(template) }
        .map_err(|e| format!("EGL configs: {e}"))?
        .next()
        .ok_or_else(|| "no EGL config for OpenGL without a surface".to_string())?;
    let attributes = ContextAttributesBuilder::new()
        .with_context_api(ContextApi::OpenGl(Some(Version::new(4, 5))))
        .with_profile(GlProfile::Core)
        .build(None);
    // SAFETY: the config belongs to this display.
    let context = unsafe { display.create_context(&config, &attributes) }.map_err(|e| format!("an OpenGL 4.5 core context: {e}"))?;
    let current = context.make_current_surfaceless().map_err(|e| format!("a surfaceless context: {e}"))?;
    let load = |name: &CStr| display.get_proc_address(name);
    // SAFETY: the loader returns the current context's entry points.
    let gl = unsafe { glow::Context::from_loader_function_cstr(load) };
    let clip = display.get_proc_address(c"glClipControl");
    if clip.is_null() {
        return Err("the driver has no glClipControl".into());
    }
    // SAFETY: glClipControl has this signature (GL 4.5).
    let clip_control: ClipControl = unsafe { std::mem::transmute::<*const std::ffi::c_void, ClipControl>(clip) };
    // SAFETY: a plain query on the current context.
    let renderer = unsafe { glow::HasContext::get_parameter_string(&gl, glow::RENDERER) };
    let context = current.make_not_current().map_err(|e| format!("releasing the context: {e}"))?;
    Ok(Headless { context: Some(context), gl: Gl { gl, clip_control, renderer, state: None } })
}
