//! The third renderer (CGPP 15.7): the scene handed to OpenGL. Triangles
//! go through a vertex shader, GL's fixed-function rasterizer and depth test
//! and a fragment shader that computes `shade()` (`shaders`); spheres stay
//! exact (a bounding cube whose fragments intersect the ray with the sphere
//! and write `gl_FragDepth`). Runs in a headless EGL context (`context`),
//! so it works without a window, on Mesa's llvmpipe where there is no GPU.

mod context;
mod pass;
mod scene_data;
mod shaders;
mod shadow_pass;

use crate::math::Radiance;
use crate::render::{debug, gi, Interpolation, PassJob, RayCounts, RenderSettings, Renderer, ShadowMode};
use crate::scene::Scene;

static GL: context::Shared<pass::State> = context::Shared::new();

/// Releases the OpenGL context before the process exits (a no-op when the
/// `opengl` renderer was never used).
pub fn shutdown() {
    GL.shutdown();
}

pub struct OpenGl;

impl Renderer for OpenGl {
    fn name(&self) -> &'static str {
        "opengl"
    }

    fn description(&self) -> &'static str {
        "the scene through OpenGL (CGPP 15.7): vertex and fragment shaders, GL's rasterizer and depth test, headless EGL"
    }

    fn check(&self, scene: &Scene, settings: &RenderSettings) -> Result<(), String> {
        if !scene.csgs.is_empty() {
            return Err("the opengl renderer cannot draw csg objects (its shaders draw triangles and spheres only); use a raytrace or rasterize renderer".into());
        }
        unsupported(scene, settings)?;
        GL.with(|_| ()).map(|_| ())
    }

    fn render_pass(&self, job: &PassJob, out: &mut [Radiance]) -> RayCounts {
        match GL.with(|g| pass::render(g, job, out)) {
            Ok(Ok(counts)) => counts,
            Ok(Err(e)) | Err(e) => {
                // `check` refuses what cannot be drawn before a frame starts;
                // a failure here leaves the rows black rather than stale.
                eprintln!("warning: opengl: {e}");
                out.fill(Radiance::ZERO);
                RayCounts::default()
            }
        }
    }
}

/// What the fragment shaders do not compute yet, as one sentence.
fn unsupported(scene: &Scene, settings: &RenderSettings) -> Result<(), String> {
    let refuse = |what: &str| Err(format!("the opengl renderer {what}"));
    if !matches!(settings.shadows, ShadowMode::None | ShadowMode::Map) {
        return refuse("supports --shadows none|map only (it casts no rays)");
    }
    if !matches!(settings.view, debug::View::Shaded) {
        return refuse("draws the shaded view only");
    }
    if settings.gi.mode != gi::GiMode::None {
        return refuse("supports --gi none only");
    }
    if settings.interpolation == Interpolation::Gouraud {
        return refuse("supports --interpolation phong|flat only");
    }
    if let Some(m) = scene.materials.iter().find(|m| m.texture.is_some()) {
        return refuse(&format!("does not draw textures yet (material \"{}\")", m.name));
    }
    if let Some(m) = scene.materials.iter().find(|m| m.has_secondary()) {
        return refuse(&format!("cannot trace mirror or glass rays (material \"{}\")", m.name));
    }
    Ok(())
}

/// The OpenGL driver in use (`GL_RENDERER`), or why there is none.
pub fn driver() -> Result<String, String> {
    GL.with(|g| g.renderer.clone())
}
