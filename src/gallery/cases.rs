//! The gallery's cases, in one table. Each names a built-in scene, the method
//! and knob under test, a failing and a cured `Setting`, and how the truth
//! image is made. To add a case, add an entry to `cases()`.

use crate::render::raster::depth_format::DepthFormat;
use crate::render::shadow::volume::VolumeMode;
use crate::render::shadow::ShadowFilter;
use crate::render::{RenderSettings, ShadowMode};
use crate::scene::texture::TextureFilter;
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
    /// The size the gallery renders at, when not the scene's own (a big
    /// scene measured small, so the gallery stays quick); the viewer keeps
    /// the scene's size.
    pub size: Option<(u32, u32)>,
    /// For cases whose settings are estimates with noise (sampled lights):
    /// the relative difference from the truth a pixel may have before it
    /// counts as wrong, instead of `measure::REL_TOLERANCE`, so that what is
    /// counted is the method's error and not its noise.
    pub noise_tolerance: Option<f32>,
}

fn map(s: &mut RenderSettings) {
    s.shadows = ShadowMode::Map;
}

fn nothing(_: &mut RenderSettings) {}

/// Ray-cast shadows, as the scene defaults have them (spelled out for the
/// viewer, where the user's own shadow mode would otherwise stay).
fn rays(s: &mut RenderSettings) {
    s.shadows = ShadowMode::Ray;
}

/// The truth of shadow-map cases: the same image with ray-cast shadows.
const RAY_CAST_SHADOWS: Setting = Setting::new("raytrace:brute", "raytrace:brute, ray-cast shadows", nothing);

/// Every case, in the order the gallery shows them.
pub fn cases() -> Vec<GalleryCase> {
    let mut all = vec![
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
            size: None,
            noise_tolerance: None,
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
            size: None,
            noise_tolerance: None,
        },
        GalleryCase {
            name: "grazing-light",
            scene: "stress-grazing",
            method: "shadow map",
            knob: "shadow_map_slope_bias",
            explanation: "light 6 degrees above the ground: one texel spans a long stretch of depth there, so a constant bias that suffices under steep light leaves acne",
            failing: Setting::new("rasterize", "--shadows map, constant bias 1", |s| {
                map(s);
                s.shadow_map_slope_bias = false;
            }),
            cured: Setting::new("rasterize", "--shadows map, slope-scaled bias 1 (default)", map),
            truth: RAY_CAST_SHADOWS,
            threshold: 40,
            size: None,
            noise_tolerance: None,
        },
        GalleryCase {
            name: "shadow-terminator",
            scene: "stress-terminator",
            method: "shadow rays",
            knob: "terminator_lift",
            explanation: "smooth normals face the light where the coarse facets do not: shadow rays leaving those facets hit the neighbouring ones, and the lit side ends in jagged black teeth",
            failing: Setting::new("raytrace", "terminator_lift = false (from the hit point)", |s| {
                rays(s);
                s.terminator_lift = false;
            }),
            cured: Setting::new("raytrace", "terminator_lift = true (default: Hanika 2021)", rays),
            truth: Setting::new("raytrace:brute", "raytrace:brute --shadows none (a convex object alone casts no shadow but its own)", |s| s.shadows = ShadowMode::None),
            threshold: 40,
            size: None,
            noise_tolerance: None,
        },
        GalleryCase {
            name: "self-intersection",
            scene: "bunny",
            method: "shadow rays",
            knob: "bump",
            explanation: "a shadow ray leaving exactly from a rounded hit point finds the surface it leaves about half the time: speckled self-shadowing (CGPP's rayBumpEpsilon cures it)",
            failing: Setting::new("raytrace", "--bump 0", |s| {
                rays(s);
                s.shadow_bump = 0.0;
            }),
            cured: Setting::new("raytrace", "--bump 1e-4 (default)", |s| {
                rays(s);
                s.shadow_bump = 1e-4;
            }),
            truth: Setting::new("raytrace", "raytrace --bump 1e-3", |s| s.shadow_bump = 1e-3),
            threshold: 40,
            size: Some((160, 100)),
            noise_tolerance: None,
        },
        GalleryCase {
            name: "specular-aliasing",
            scene: "stress-specular",
            method: "sampling",
            knob: "spp",
            explanation: "each bump's highlight is smaller than a pixel: one sample per pixel hits it or misses it, and the field sparkles instead of glowing",
            failing: Setting::new("rasterize", "--spp 1", |s| s.spp = 1),
            cured: Setting::new("rasterize", "--spp 256", |s| s.spp = 256),
            truth: Setting::new("raytrace", "raytrace --spp 1024", |s| s.spp = 1024),
            threshold: 400,
            size: None,
            noise_tolerance: None,
        },
        GalleryCase {
            name: "near-plane",
            scene: "stress-near",
            method: "rasterize",
            knob: "near_clip",
            explanation: "the floor and the wall pass beside and behind the eye: without a clipper their triangles must be dropped whole, and they vanish",
            failing: Setting::new("rasterize", "near_clip = false", |s| s.near_clip = false),
            cured: Setting::new("rasterize", "near_clip = true (default)", nothing),
            truth: Setting::new("raytrace:brute", "raytrace:brute", nothing),
            threshold: 40,
            size: None,
            noise_tolerance: None,
        },
        GalleryCase {
            name: "t-junction-cracks",
            scene: "stress-tjunction",
            method: "meshes",
            knob: "shared vertices",
            explanation: "a vertex lying on its neighbour's edge stays on it only in exact arithmetic: rounded (here 100,000 units out) it moves off, and the background shows through",
            failing: Setting::new("raytrace", "T-junctions (stress-tjunction)", rays),
            cured: Setting {
                renderer: "raytrace",
                description: "every edge shared whole (stress-tjunction-shared)",
                scene: Some("stress-tjunction-shared"),
                apply: rays,
                transform: None,
            },
            truth: Setting {
                renderer: "raytrace:brute",
                description: "raytrace:brute on stress-tjunction-shared re-centred at the camera",
                scene: Some("stress-tjunction-shared"),
                apply: nothing,
                transform: Some(crate::scene::recentre::recentre_at_camera),
            },
            threshold: 20,
            size: None,
            noise_tolerance: None,
        },
        GalleryCase {
            name: "far-from-origin",
            scene: "stress-far",
            method: "ray casting",
            knob: "camera-relative",
            explanation: "100,000 units from the origin a float resolves 0.008: hit points land off their surfaces, beyond the 1e-4 bump, and shadow themselves",
            failing: Setting::new("raytrace", "as placed (at 100000, 100000, 100000)", rays),
            cured: Setting {
                renderer: "raytrace",
                description: "re-centred at the camera",
                scene: None,
                apply: rays,
                transform: Some(crate::scene::recentre::recentre_at_camera),
            },
            truth: Setting {
                renderer: "raytrace:brute",
                description: "raytrace:brute on stress-shadow, the same scene at the origin",
                scene: Some("stress-shadow"),
                apply: nothing,
                transform: None,
            },
            threshold: 40,
            size: None,
            noise_tolerance: None,
        },
        GalleryCase {
            name: "zpass-eye-in-shadow",
            scene: "stress-zpass",
            method: "shadow volumes",
            knob: "shadow-volume",
            explanation: "z-pass counts the volume faces in front of each visible point, assuming the eye is in no volume: standing in the roof's shadow, every count is off by one and shadow and light swap",
            failing: Setting::new("rasterize", "--shadows volume --shadow-volume zpass", |s| {
                s.shadows = ShadowMode::Volume;
                s.shadow_volume = VolumeMode::ZPass;
            }),
            cured: Setting::new("rasterize", "--shadows volume --shadow-volume zfail (default)", |s| {
                s.shadows = ShadowMode::Volume;
                s.shadow_volume = VolumeMode::ZFail;
            }),
            truth: RAY_CAST_SHADOWS,
            threshold: 40,
            size: Some((160, 100)),
            noise_tolerance: None,
        },
        GalleryCase {
            name: "painter-cycles",
            scene: "stress-painter",
            method: "visibility",
            knob: "renderer",
            explanation: "three bars overlap in a cycle and two triangles pass through each other: no back-to-front order of whole triangles exists, so the painter must draw some of them wrongly on top",
            failing: Setting::new("rasterize:painter", "--renderer rasterize:painter", nothing),
            cured: Setting::new("rasterize:fixed", "--renderer rasterize:fixed (a depth buffer)", nothing),
            truth: Setting::new("raytrace:brute", "raytrace:brute", nothing),
            threshold: 40,
            size: Some((160, 100)),
            noise_tolerance: None,
        },
        GalleryCase {
            name: "z-fighting",
            scene: "stress-zfight",
            method: "depth buffer",
            knob: "depth-buffer",
            explanation: "a decal 2 cm above the ground, 30-90 m away, near plane 1 cm: 16 fixed-point bits of z/w cannot tell the two surfaces apart there, and the ground wins where they round equal",
            failing: Setting::new("rasterize", "--depth-buffer unorm16", |s| s.depth_buffer = DepthFormat::Unorm16),
            cured: Setting::new("rasterize", "--depth-buffer unorm24", |s| s.depth_buffer = DepthFormat::Unorm24),
            truth: Setting::new("raytrace:brute", "raytrace:brute", nothing),
            threshold: 40,
            size: Some((160, 100)),
            noise_tolerance: None,
        },
        GalleryCase {
            name: "linear-z",
            scene: "stress-linear-z",
            method: "depth buffer",
            knob: "depth-buffer",
            explanation: "z interpolated linearly across the ground's two long triangles lies beyond the ground (z is not affine in image space, 1/z is), so the halves of the balls buried under it show through",
            failing: Setting::new("rasterize", "--depth-buffer linear-z", |s| s.depth_buffer = DepthFormat::LinearZ),
            cured: Setting::new("rasterize", "--depth-buffer f32 (stores 1/z)", |s| s.depth_buffer = DepthFormat::F32),
            truth: Setting::new("raytrace:brute", "raytrace:brute", nothing),
            threshold: 40,
            size: Some((160, 100)),
            noise_tolerance: None,
        },
        GalleryCase {
            name: "z-fighting-near-plane",
            scene: "stress-zfight",
            method: "depth buffer",
            knob: "camera.near",
            explanation: "z/w spends most of its steps just beyond the near plane: moving the near plane from 1 cm to 1 m gives the 16-bit buffer the precision the far decal needs",
            failing: Setting::new("rasterize", "--depth-buffer unorm16, camera.near = 0.01", |s| s.depth_buffer = DepthFormat::Unorm16),
            cured: Setting {
                renderer: "rasterize",
                description: "--depth-buffer unorm16, camera.near = 1",
                scene: None,
                apply: |s| s.depth_buffer = DepthFormat::Unorm16,
                transform: Some(|scene| scene.camera.near = 1.0),
            },
            truth: Setting::new("raytrace:brute", "raytrace:brute", nothing),
            threshold: 40,
            size: Some((160, 100)),
            noise_tolerance: None,
        },
        GalleryCase {
            name: "environment-reflections",
            scene: "textures",
            method: "environment-mapped reflections",
            knob: "reflections",
            explanation: "the mirror ball looks the sky up in the reflected direction with no ray: the checker ground and the globe beside it, which a traced ray finds, are missing from its reflection",
            failing: Setting::new("rasterize", "--reflections env", |s| s.reflections = crate::render::Reflections::Env),
            cured: Setting::new("rasterize", "--reflections ray (default)", |s| s.reflections = crate::render::Reflections::Ray),
            truth: Setting::new("raytrace:brute", "raytrace:brute", nothing),
            threshold: 40,
            size: Some((160, 100)),
            noise_tolerance: None,
        },
        GalleryCase {
            name: "subsample-misses",
            scene: "textures",
            method: "sub-sampling",
            knob: "subsample",
            explanation: "every fourth pixel is traced and the rest interpolated, refined only where the traced corners differ: the normal-mapped bumps (too faint at the corners to trigger refinement) and the checker squares near the horizon (smaller than the grid) are smeared or lost",
            failing: Setting::new("raytrace", "--subsample 4 --subsample-contrast 0.3", |s| {
                s.subsample = crate::render::frame::Subsample { step: 4, contrast: Some(0.3) }
            }),
            cured: Setting::new("raytrace", "--subsample 1 (every pixel traced)", |s| s.subsample = crate::render::frame::Subsample::default()),
            truth: Setting::new("raytrace:brute", "raytrace:brute", nothing),
            threshold: 40,
            size: Some((160, 100)),
            noise_tolerance: None,
        },
        GalleryCase {
            name: "thin-lens",
            scene: "spheres",
            method: "camera",
            knob: "aperture",
            explanation: "a pinhole sees everything sharp; a lens of radius 0.15 focused 2 units away blurs the blue and green spheres at depth 4 over a disk 0.15 (1 - 2/4) = 0.075 units in radius on the plane in focus, 7.5 pixels across, which the pinhole image lacks; the lens needs many samples per pixel to draw its blur without noise",
            failing: Setting::new("raytrace", "aperture = 0 (pinhole) --spp 256", |s| s.spp = 256),
            cured: Setting { transform: Some(thin_lens), ..Setting::new("raytrace", "aperture = 0.15, focus_distance = 2 --spp 256", |s| s.spp = 256) },
            truth: Setting { transform: Some(thin_lens), ..Setting::new("raytrace", "aperture = 0.15, focus_distance = 2 --spp 1024", |s| s.spp = 1024) },
            threshold: 400,
            size: Some((160, 100)),
            noise_tolerance: Some(0.25),
        },
        GalleryCase {
            name: "subpixel-bits",
            scene: "teapot",
            method: "fixed-point rasterization",
            knob: "subpixel-bits",
            explanation: "vertices snapped to whole pixels (0 bits of sub-pixel precision) move by up to half a pixel, and the silhouettes and the spout's thin edges shift with them; 8 bits keep the edges within 1/512 pixel",
            failing: Setting::new("rasterize:fixed", "--subpixel-bits 0", |s| s.subpixel_bits = 0),
            cured: Setting::new("rasterize:fixed", "--subpixel-bits 8", |s| s.subpixel_bits = 8),
            truth: Setting::new("raytrace:brute", "raytrace:brute", nothing),
            threshold: 40,
            size: Some((160, 100)),
            noise_tolerance: None,
        },
        GalleryCase {
            name: "faceted-teapot",
            scene: "teapot",
            method: "shading interpolation",
            knob: "interpolation",
            explanation: "one lighting value per triangle, taken at its centroid (Computer Graphics from Scratch's flat shading): the teapot's facets and the seams between them show, and highlights smaller than a triangle vanish or fill it",
            failing: Setting::new("rasterize", "--interpolation faceted", |s| s.interpolation = crate::render::Interpolation::Faceted),
            cured: Setting::new("rasterize", "--interpolation phong", |s| s.interpolation = crate::render::Interpolation::Phong),
            truth: Setting::new("raytrace:brute", "raytrace:brute", nothing),
            threshold: 40,
            size: Some((160, 100)),
            noise_tolerance: None,
        },
        GalleryCase {
            name: "trilinear-blur",
            scene: "textures",
            method: "texture filtering",
            knob: "texture-filter",
            explanation: "trilinear reads a receding footprint at the level of its length and so blurs the far checkerboard across its width too; taps spread along the length read a finer level and keep the squares",
            failing: Setting { transform: Some(checkerboard_only), ..Setting::new("raytrace", "--texture-filter trilinear (the checkerboard alone)", |s| s.texture_filter = TextureFilter::Trilinear) },
            cured: Setting { transform: Some(checkerboard_only), ..Setting::new("raytrace", "--texture-filter anisotropic:16", |s| s.texture_filter = TextureFilter::Anisotropic16) },
            truth: Setting {
                transform: Some(checkerboard_only),
                ..Setting::new("raytrace", "--texture-filter nearest --spp 256", |s| {
                    s.texture_filter = TextureFilter::Nearest;
                    s.spp = 256;
                })
            },
            // One sample a pixel still aliases at the horizon, where a pixel
            // spans many squares, with any filter: the threshold leaves that.
            threshold: 1000,
            size: Some((160, 100)),
            noise_tolerance: Some(0.1),
        },
    ];
    all.extend(area_light_cases());
    all
}

/// The `textures` scene's checkerboard ground alone (its first object),
/// under a black sky: what the texture filters differ on, without the
/// globe's, the mirror's and the sky's own sampling.
fn checkerboard_only(scene: &mut Scene) {
    scene.triangles.retain(|t| t.object == 0);
    scene.spheres.clear();
    scene.environment = None;
    scene.render.background = crate::math::Vec3::ZERO;
}

/// The thin-lens case's camera: focused on the front of the red sphere.
fn thin_lens(scene: &mut Scene) {
    scene.camera.aperture = 0.15;
    scene.camera.focus_distance = 2.0;
}


/// Area-light cases: enough light samples that the shading itself is
/// quiet, so what differs is visibility (the shadow cases) or the sampling
/// strategy (the MIS case).
fn soft(s: &mut RenderSettings) {
    s.spp = 16;
    s.light_samples = 16;
}

fn soft_map(s: &mut RenderSettings, filter: ShadowFilter) {
    soft(s);
    s.shadows = ShadowMode::Map;
    s.shadow_filter = filter;
}

/// The cure of the area-light shadow cases: shadow rays to points on the panel.
const AREA_RAYS: Setting = Setting::new("rasterize", "--shadows ray", |s| {
    soft(s);
    s.shadows = ShadowMode::Ray;
});

/// The truth of the area-light shadow cases: the panel sampled with rays.
const AREA_TRUTH: Setting = Setting::new("raytrace", "raytrace --spp 64 --light-samples 32", |s| {
    s.spp = 64;
    s.light_samples = 32;
    s.shadows = ShadowMode::Ray;
});

/// The cases of lights with extent: soft shadows, which maps and volumes
/// approximate, and light sampling against BSDF sampling.
fn area_light_cases() -> Vec<GalleryCase> {
    vec![
        GalleryCase {
            name: "area-light-hard-map",
            scene: "soft-shadows",
            method: "shadow map of an area light",
            knob: "shadow-filter",
            explanation: "a plain shadow map is drawn from the panel's centre: every shadow has a hard edge, the floating ball's faint blur becomes a dark disc and the post's widening shadow stays thin",
            failing: Setting::new("rasterize", "--shadows map --shadow-filter none", |s| soft_map(s, ShadowFilter::None)),
            cured: AREA_RAYS,
            truth: AREA_TRUTH,
            threshold: AREA_THRESHOLD,
            size: Some((160, 100)),
            noise_tolerance: Some(AREA_NOISE),
        },
        GalleryCase {
            name: "area-light-volume",
            scene: "soft-shadows",
            method: "shadow volume of an area light",
            knob: "shadows",
            explanation: "a shadow volume is cast from one point, the panel's centre: it cannot be soft, so every penumbra is a hard edge",
            failing: Setting::new("rasterize", "--shadows volume", |s| {
                soft(s);
                s.shadows = ShadowMode::Volume;
            }),
            cured: AREA_RAYS,
            truth: AREA_TRUTH,
            threshold: AREA_THRESHOLD,
            size: Some((160, 100)),
            noise_tolerance: Some(AREA_NOISE),
        },
        GalleryCase {
            name: "pcf-contact-shadow",
            scene: "soft-shadows",
            method: "percentage-closer filtering",
            knob: "shadow-filter",
            explanation: "PCF blurs every edge by the same width: the resting ball's contact shadow, sharp where it touches the floor, is smeared as much as the far edge of its penumbra, and the post's shadow is blurred even at its foot; rays to the panel give each point its own penumbra",
            failing: Setting::new("rasterize", "--shadows map --shadow-filter pcf --pcf-radius 12", |s| {
                soft_map(s, ShadowFilter::Pcf);
                s.pcf_radius = 12.0;
            }),
            cured: AREA_RAYS,
            truth: AREA_TRUTH,
            threshold: AREA_THRESHOLD,
            size: Some((160, 100)),
            noise_tolerance: Some(AREA_NOISE),
        },
        GalleryCase {
            name: "pcss-thin-post",
            scene: "soft-shadows",
            method: "percentage-closer soft shadows",
            knob: "shadows",
            explanation: "PCSS filters the map as wide as the penumbra it estimates: the thin post covers too few texels of that width, so light leaks through its shadow, which rays to the panel keep",
            failing: Setting::new("rasterize", "--shadows map --shadow-filter pcss", |s| soft_map(s, ShadowFilter::Pcss)),
            cured: AREA_RAYS,
            truth: AREA_TRUTH,
            threshold: AREA_THRESHOLD,
            size: Some((160, 100)),
            noise_tolerance: Some(AREA_NOISE),
        },
        GalleryCase {
            name: "light-sampling-alone",
            scene: "stress-glossy-panel",
            method: "light sampling without MIS",
            knob: "mis",
            explanation: "points sampled on the lights rarely fall in the glossy ball's narrow lobe: its reflection of the large panel is speckled; MIS adds BSDF samples, which find that reflection, and weighs each strategy where it is good",
            failing: Setting::new("raytrace", "--spp 64 --light-samples 4 --mis off", |s| {
                s.spp = 64;
                s.light_samples = 4;
                s.mis = false;
            }),
            cured: Setting::new("raytrace", "--spp 64 --light-samples 4", |s| {
                s.spp = 64;
                s.light_samples = 4;
            }),
            truth: Setting::new("raytrace", "raytrace --spp 1024 --light-samples 4", |s| {
                s.spp = 1024;
                s.light_samples = 4;
            }),
            // The floor keeps some noise in both; the speckled highlight is the difference.
            threshold: 1000,
            size: Some((160, 100)),
            noise_tolerance: Some(AREA_NOISE),
        },
    ]
}

/// How far (relative) an area-light case's pixel may stray from the truth
/// by the noise of 256 or more samples before it counts as wrong.
const AREA_NOISE: f32 = 0.1;

/// Wrong pixels (of 16,000) above which an area-light case fails.
const AREA_THRESHOLD: usize = 400;

/// The case called `name`.
pub fn case_by_name(name: &str) -> Result<GalleryCase, String> {
    let all = cases();
    all.iter().find(|c| c.name == name).copied().ok_or_else(|| {
        format!("no gallery case \"{name}\" (choose from {})", all.iter().map(|c| c.name).collect::<Vec<_>>().join(", "))
    })
}
