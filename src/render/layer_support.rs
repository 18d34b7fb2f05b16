//! What can draw a scene whose copies live in the two-level instance layer
//! (`scene::instanced`). Each renderer says how much of the layer it draws
//! (`Renderer::instance_layer`): a renderer that reads `Scene::triangles`
//! alone refuses such a scene with one sentence instead of drawing it
//! without its copies. Shadow volumes and the wireframe and shadow-map views
//! are built from `Scene::triangles`, so every renderer refuses them here.

use crate::render::inspect::debug::View;
use crate::render::{RenderSettings, Renderer, ShadowMode};
use crate::scene::Scene;

/// How much of the instance layer a renderer draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LayerSupport {
    /// Nothing: it reads `Scene::triangles` alone.
    Nothing,
    /// The copies, with ray or no shadows, but not into shadow maps of its own.
    WithoutShadowMaps,
    /// The copies, with the CPU shadow maps too (each copy culled whole per light face).
    Everything,
}

/// `Ok` when `renderer` with `settings` draws every copy of `scene`.
pub fn check(renderer: &dyn Renderer, scene: &Scene, settings: &RenderSettings) -> Result<(), String> {
    if scene.layer.is_none() {
        return Ok(());
    }
    let why = |what: &str| {
        Err(format!(
            "{what} cannot draw this scene's {} copies held as shared meshes (over {} triangles are not flattened); use raytrace or rasterize with --shadows ray, map or none",
            scene.layer.as_ref().map_or(0, |l| l.instances.len()),
            crate::scene::file::FLATTEN_LIMIT
        ))
    };
    match renderer.instance_layer() {
        LayerSupport::Nothing => return why(renderer.name()),
        LayerSupport::WithoutShadowMaps if settings.shadows == ShadowMode::Map => return why(&format!("{}'s --shadows map", renderer.name())),
        LayerSupport::WithoutShadowMaps | LayerSupport::Everything => {}
    }
    if settings.shadows == ShadowMode::Volume {
        return why("--shadows volume");
    }
    match settings.view {
        View::Wireframe => why("--view wireframe"),
        View::Shadowmap => why("--view shadowmap"),
        _ => Ok(()),
    }
}
