//! The gallery's cases, in one table. Each names a built-in scene, the method
//! and knob under test, a failing and a cured `Setting`, and how the truth
//! image is made. To add a case, add an entry to `cases()`.

use crate::render::{RenderSettings, ShadowMode};
use crate::scene::Scene;

/// One way of rendering a case: a renderer, the knobs changed from the
/// scene's defaults (as a command-line-like description), and the functions
/// that apply them.
#[derive(Clone, Copy)]
pub struct Setting {
    /// A renderer name as `--renderer` takes it.
    pub renderer: &'static str,
    /// What is changed, e.g. "--shadows map --shadow-bias 0".
    pub description: &'static str,
    /// Another built-in scene to render instead of the case's own (a truth
    /// made from an exact model of the same scene); `None`: the case's.
    pub scene: Option<&'static str>,
    /// Applies the knobs to the settings made for the scene (`RenderSettings::for_scene`).
    pub apply: fn(&mut RenderSettings),
    /// Changes the scene before it is prepared, when the knob lives there.
    pub transform: Option<fn(&mut Scene)>,
}

impl Setting {
    /// A setting that changes only render settings.
    pub const fn new(renderer: &'static str, description: &'static str, apply: fn(&mut RenderSettings)) -> Setting {
        Setting { renderer, description, scene: None, apply, transform: None }
    }
}

/// One stress case.
#[derive(Clone, Copy)]
pub struct GalleryCase {
    pub name: &'static str,
    /// A built-in scene (`scene::builtin`).
    pub scene: &'static str,
    /// The method under test, e.g. "shadow map".
    pub method: &'static str,
    /// The knob whose value makes the difference.
    pub knob: &'static str,
    /// One line: what goes wrong and why.
    pub explanation: &'static str,
    pub failing: Setting,
    pub cured: Setting,
    /// How the truth is rendered.
    pub truth: Setting,
    /// A setting fails when more pixels than this are wrong, and passes otherwise.
    pub threshold: usize,
}

fn map(s: &mut RenderSettings) {
    s.shadows = ShadowMode::Map;
}

fn nothing(_: &mut RenderSettings) {}

/// The truth of shadow-map cases: the same image with ray-cast shadows.
const RAY_CAST_SHADOWS: Setting = Setting::new("raytrace:brute", "raytrace:brute, ray-cast shadows", nothing);

/// Every case, in the order the gallery shows them.
pub fn cases() -> Vec<GalleryCase> {
    vec![
        GalleryCase {
            name: "shadow-acne",
            scene: "stress-shadow",
            method: "shadow map",
            knob: "shadow-bias",
            explanation: "with no depth bias a lit surface compares its depth against the map's own, rounded to texels, and shadows itself in stripes",
            failing: Setting::new("rasterize", "--shadows map --shadow-bias 0", |s| {
                map(s);
                s.shadow_map_bias = 0.0;
            }),
            cured: Setting::new("rasterize", "--shadows map --shadow-bias 1 (default)", map),
            truth: RAY_CAST_SHADOWS,
            threshold: 40,
        },
        GalleryCase {
            name: "peter-panning",
            scene: "stress-shadow",
            method: "shadow map",
            knob: "shadow-bias",
            explanation: "a huge depth bias pushes shadows away from their casters: the contact shadows under the box and the ball come loose",
            failing: Setting::new("rasterize", "--shadows map --shadow-bias 256", |s| {
                map(s);
                s.shadow_map_bias = 256.0;
            }),
            cured: Setting::new("rasterize", "--shadows map --shadow-bias 1 (default)", map),
            truth: RAY_CAST_SHADOWS,
            threshold: 40,
        },
    ]
}

/// The case called `name`.
pub fn case_by_name(name: &str) -> Result<GalleryCase, String> {
    let all = cases();
    all.iter().find(|c| c.name == name).copied().ok_or_else(|| {
        format!("no gallery case \"{name}\" (choose from {})", all.iter().map(|c| c.name).collect::<Vec<_>>().join(", "))
    })
}
