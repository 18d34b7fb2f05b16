//! Debug views: per-sample colours that show what the renderer saw instead of
//! shading it (CGPP 15.4.1.2). Every renderer calls the same function, so a
//! view means the same thing in each.

use crate::math::{Radiance, Ray, Vec3};
use crate::named::named_enum;
use crate::scene::{CameraView, SurfaceHit};

named_enum! {
    /// What a frame shows: the shaded image or a debug view. The spellings
    /// after `|` are how saved viewer settings once wrote the hyphenated
    /// names; they still load.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
    pub enum View ("view") {
        /// The shaded image.
        Shaded = "shaded",
        /// Barycentric weights of v0, v1, v2 as red, green, blue (Figure 15.6).
        Barycentric = "barycentric",
        /// Eye-ray direction as (d + 1) / 2 (Figure 15.4).
        Raydir = "raydir",
        /// Distance from the eye along the eye ray, on a log scale from near (black) to far (white).
        Depth = "depth",
        /// What a depth buffer stores: 1/z, mapped so near = 1 (white) and far = 0 (black).
        Zbuffer = "zbuffer",
        /// Shading normal as (n + 1) / 2.
        Normal = "normal",
        /// Geometric (face) normal as (n + 1) / 2: compare with `Normal` to see
        /// what the interpolated vertex normals do.
        GeometricNormal = "geometric-normal" | "geometricnormal",
        /// Object ids as distinct colours.
        Id = "id",
        /// Triangle (or sphere) ids as distinct colours: the tessellation.
        TriangleId = "triangle-id" | "triangleid",
        /// Material ids as distinct colours.
        MaterialId = "material-id" | "materialid",
        /// A checker in texture coordinates.
        Uv = "uv",
        /// Work per pixel as a heat map (`cost_color`, the same scale for all):
        /// ray casters count BVH nodes visited plus primitives tested by the eye
        /// ray; rasterizers count, per pixel and pass, samples tested (one per
        /// primitive whose tested region - whole image, bounding box, span or
        /// block - holds the pixel's sample), plus fragments (covered samples,
        /// each depth-tested; those that fail are the overdraw), plus fragments
        /// shaded (one with early depth, one per depth-test pass when forward).
        /// With MSAA the work of every coverage sample and the shading layer adds up.
        Cost = "cost",
        /// This renderer's shaded image minus the reference `raytrace:brute`'s:
        /// red where brighter, blue where darker (amplified), the rest dimmed.
        Diff = "diff",
        /// The lights' shadow maps (CGPP Figure 15.14): depth from the light in
        /// grey, black near, white far; a point light's six faces in a 3 x 2 grid.
        Shadowmap = "shadowmap",
        /// The shaded image with every triangle edge drawn over it (`wireframe`).
        Wireframe = "wireframe",
        /// The mip level each sample's texture lookup reads (`mip_color`),
        /// dark grey where the surface has no texture.
        Mip = "mip",
        /// The shaded image's log2 luminance (stops) through the viridis
        /// colour map (`display::false_colour`), legend in stops.
        FalseColour = "false-colour",
        /// The shaded image's relative error against a reference image,
        /// |a - b| / b in luminance, on a log scale (`display::error_view`).
        /// The frame is the shaded image; whoever holds the reference maps it.
        Error = "error" | "relative-error",
        /// The absolute error |a - b| in luminance against a reference image.
        AbsoluteError = "absolute-error",
        /// The signed error a - b in luminance against a reference image:
        /// red brighter, green darker, on a symmetric scale.
        SignedError = "signed-error",
        /// The pixels that took a non-finite sample (before the frame
        /// zeroed it) marked over the shaded image, greyed.
        Nan = "nan",
    }
}

impl View {
    /// Which comparison an error view makes (`None` for the other views).
    pub fn error_kind(self) -> Option<crate::display::error_view::ErrorKind> {
        use crate::display::error_view::ErrorKind;
        match self {
            View::Error => Some(ErrorKind::Relative),
            View::AbsoluteError => Some(ErrorKind::Absolute),
            View::SignedError => Some(ErrorKind::Signed),
            _ => None,
        }
    }

    /// Views whose passes render the shaded image, the view being made
    /// from it once the frame is final (or, for the error views, by whoever
    /// holds the reference image).
    pub fn renders_shaded(self) -> bool {
        matches!(self, View::Shaded | View::Diff | View::Wireframe | View::FalseColour | View::Error | View::AbsoluteError | View::SignedError | View::Nan)
    }
}

/// Mip levels the mip view's colour scale spans (0 to this; coarser levels
/// take its last colour).
pub const MIP_SCALE: f32 = 10.0;

/// The mip view's colour for level `level` (fractional with trilinear
/// filtering): blue at 0 through cyan, green, yellow and red to magenta at
/// `MIP_SCALE`.
pub fn mip_color(level: f32) -> Vec3 {
    const STOPS: [Vec3; 6] = [
        Vec3::new(0.1, 0.2, 0.9),
        Vec3::new(0.1, 0.8, 0.9),
        Vec3::new(0.2, 0.85, 0.2),
        Vec3::new(0.95, 0.9, 0.1),
        Vec3::new(0.95, 0.25, 0.1),
        Vec3::new(0.85, 0.2, 0.85),
    ];
    let x = (level / MIP_SCALE).clamp(0.0, 1.0) * (STOPS.len() - 1) as f32;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    STOPS[i].lerp(STOPS[i + 1], x - i as f32)
}

/// The colour a surface without a texture has in the mip view.
pub const MIP_UNTEXTURED: Vec3 = Vec3::splat(0.15);

/// The mip view of one sample: the level its material's texture (else its
/// normal map) is read at with `filter`.
pub fn mip_view(scene: &crate::scene::Scene, filter: crate::scene::texture::TextureFilter, hit: Option<&SurfaceHit>) -> Radiance {
    let Some(h) = hit else { return Vec3::ZERO };
    let material = &scene.materials[h.material as usize];
    match material.texture.as_ref().or(material.normal_map.as_ref()) {
        Some(t) => {
            let (_, f) = material.scaled(h.uv, &h.diff.footprint());
            mip_color(t.level_used(&f, filter))
        }
        None => MIP_UNTEXTURED,
    }
}

/// The cost that maps to the hot end of the cost view's colour scale.
pub const COST_SCALE: f32 = 1024.0;

/// The colour of one sample in a debug view. Values are "radiance" in [0, 1],
/// shown with exposure 1.
pub fn view_color(view: View, camera: &CameraView, ray: &Ray, hit: Option<&SurfaceHit>) -> Radiance {
    if view == View::Raydir {
        return (ray.dir + Vec3::ONE) * 0.5;
    }
    match hit {
        Some(h) => surface_color(view, camera, h),
        None => Vec3::ZERO,
    }
}

/// `view_color` of a sample that sees `h`, for every view but the ray
/// direction's (which `view_color` answers from the ray alone).
pub fn surface_color(view: View, camera: &CameraView, h: &SurfaceHit) -> Radiance {
    match view {
        // Shaded is resolved by shade(); cost by the renderer, which counted the work.
        // Cost is coloured by the renderer, which counted the work; diff is a
        // whole-frame comparison (`diff_image`).
        // The shadow map view is drawn by `shadow_map::view_sample`.
        // The wireframe view is the shaded image with lines drawn after the frame.
        // The mip view needs the scene's textures (`mip_view`).
        View::Shaded | View::Raydir | View::Cost | View::Diff | View::Shadowmap | View::Wireframe | View::Mip | View::FalseColour | View::Error | View::AbsoluteError | View::SignedError | View::Nan => Vec3::ZERO,
        View::Barycentric => h.barycentric,
        View::Depth => Vec3::splat(depth_value(camera, (h.position - camera.eye).length())),
        View::Zbuffer => Vec3::splat(zbuffer_value(camera, camera.view_depth(h.position).max(camera.near))),
        View::Normal => (h.shading_normal + Vec3::ONE) * 0.5,
        View::Id => id_color(h.object),
        View::GeometricNormal => (h.geometric_normal + Vec3::ONE) * 0.5,
        // Spheres after triangles, so a sphere never shares a triangle's colour.
        View::TriangleId => id_color(match h.kind {
            crate::scene::PrimitiveKind::Triangle => h.primitive,
            crate::scene::PrimitiveKind::Sphere => h.primitive.wrapping_add(1 << 20),
            crate::scene::PrimitiveKind::Csg => h.primitive.wrapping_add(1 << 21),
        }),
        View::MaterialId => id_color(h.material),
        View::Uv => {
            let c = ((h.uv.x * 8.0).floor() as i64 + (h.uv.y * 8.0).floor() as i64).rem_euclid(2);
            if c == 0 { Vec3::new(0.9, 0.9, 0.9) } else { Vec3::new(0.1, 0.1, 0.1) }
        }
    }
}

/// What `view_color` shows where the eye ray meets nothing, for the views
/// whose colour there does not depend on the ray: black in the views that
/// colour only what is hit. `None` for the others (the ray direction view,
/// and those `view_color` does not draw).
pub fn miss_color(view: View) -> Option<Radiance> {
    match view {
        View::Barycentric | View::Depth | View::Zbuffer | View::Normal | View::GeometricNormal | View::Id | View::TriangleId | View::MaterialId | View::Uv => Some(Vec3::ZERO),
        View::Shaded | View::Raydir | View::Cost | View::Diff | View::Shadowmap | View::Wireframe | View::Mip | View::FalseColour | View::Error | View::AbsoluteError | View::SignedError | View::Nan => None,
    }
}

/// A distinct, stable colour for an id (golden-ratio hue steps).
pub fn id_color(id: u32) -> Vec3 {
    let h = (id as f32 * 0.618_034).fract();
    let k = |n: f32| {
        let k = (n + h * 6.0) % 6.0;
        1.0 - (k.min(4.0 - k).clamp(0.0, 1.0))
    };
    Vec3::new(k(5.0), k(3.0), k(1.0)) * 0.8 + Vec3::splat(0.1)
}

/// The depth view's grey level for a distance from the eye: log scale, near = 0, far = 1.
pub fn depth_value(camera: &CameraView, distance: f32) -> f32 {
    ((distance.max(camera.near) / camera.near).ln() / (camera.far / camera.near).ln()).clamp(0.0, 1.0)
}

/// The zbuffer view's grey level for view depth `z`: 1/z mapped so near = 1
/// and far = 0, linear in screen space as rasterizers store it.
pub fn zbuffer_value(camera: &CameraView, z: f32) -> f32 {
    let inv = (1.0 / z - 1.0 / camera.far) / (1.0 / camera.near - 1.0 / camera.far);
    inv.clamp(0.0, 1.0)
}

/// Heat-map colour of a cost: black, blue, magenta, orange, yellow, white on a
/// log scale up to `COST_SCALE`.
pub fn cost_color(cost: f32) -> Vec3 {
    let t = t_of_cost(cost);
    const STOPS: [Vec3; 6] = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.05, 0.05, 0.6),
        Vec3::new(0.6, 0.05, 0.6),
        Vec3::new(0.95, 0.4, 0.05),
        Vec3::new(1.0, 0.9, 0.1),
        Vec3::new(1.0, 1.0, 1.0),
    ];
    let x = t * (STOPS.len() - 1) as f32;
    let i = (x.floor() as usize).min(STOPS.len() - 2);
    STOPS[i].lerp(STOPS[i + 1], x - i as f32)
}

// The inverse maps: what value a debug view's colour stands for (legends,
// hover read-out, inspector).

/// The cost whose `cost_color` is nearest `c` (the cost view's heat scale,
/// inverted): exact for 1 spp up to `COST_SCALE`, saturating above it.
pub fn invert_cost(c: Vec3) -> f32 {
    // cost_color is piecewise linear in t between distinct stops: project
    // onto each segment and keep the closest point.
    const N: usize = 5;
    let stop = |i: usize| cost_color(cost_of_t(i as f32 / N as f32));
    let mut best = (f32::INFINITY, 0.0f32);
    for i in 0..N {
        let (a, b) = (stop(i), stop(i + 1));
        let ab = b - a;
        let s = ((c - a).dot(ab) / ab.length_squared().max(1e-12)).clamp(0.0, 1.0);
        let d = (a + ab * s - c).length_squared();
        if d < best.0 {
            best = (d, (i as f32 + s) / N as f32);
        }
    }
    cost_of_t(best.1)
}

/// Inverse of the cost view's log mapping `t = log2(1 + cost) / log2(1 + COST_SCALE)`.
pub fn cost_of_t(t: f32) -> f32 {
    (2f32.powf(t * (1.0 + COST_SCALE).log2()) - 1.0).max(0.0)
}

/// The cost view's log mapping of a cost to [0, 1]: where it lies on `cost_color`'s scale.
pub fn t_of_cost(cost: f32) -> f32 {
    ((1.0 + cost.max(0.0)).log2() / (1.0 + COST_SCALE).log2()).clamp(0.0, 1.0)
}

/// Distance from the eye for a grey level of the depth view (its inverse).
pub fn depth_distance(camera: &CameraView, v: f32) -> f32 {
    camera.near * (camera.far / camera.near).powf(v)
}

/// View depth z for a grey level of the zbuffer view (1/z, near = 1, far = 0).
pub fn zbuffer_depth(camera: &CameraView, v: f32) -> f32 {
    1.0 / (v * (1.0 / camera.near - 1.0 / camera.far) + 1.0 / camera.far)
}

/// The object whose id colour `c` is, if any.
pub fn object_of_id_color(scene: &crate::scene::Scene, c: Vec3) -> Option<usize> {
    (0..scene.objects.len()).find(|&i| (id_color(i as u32) - c).abs().max_element() < 1e-4)
}

/// Whether two radiances differ by more than 1e-4 relative in any channel
/// (the agreement tests' criterion).
pub fn differs(a: Vec3, b: Vec3) -> bool {
    let d = (a - b).abs();
    let m = a.abs().max(b.abs());
    d.x > 1e-4 * m.x + 1e-7 || d.y > 1e-4 * m.y + 1e-7 || d.z > 1e-4 * m.z + 1e-7
}

/// The diff view of `test` against `reference`: where the luminance is higher
/// red, lower blue, amplified so a difference of 10% of the reference's mean
/// is full scale, and never dimmer than a clearly visible 0.5 where the pixels
/// differ at all; equal pixels show the reference dimmed to grey. Returns the
/// image and the number of differing pixels.
pub fn diff_image(test: &[Radiance], reference: &[Radiance]) -> (Vec<Radiance>, u64) {
    let mean = reference.iter().map(|c| crate::math::luminance(*c)).sum::<f32>() / reference.len().max(1) as f32;
    let gain = 10.0 / mean.max(1e-6);
    let mut count = 0;
    let image = test
        .iter()
        .zip(reference)
        .map(|(&a, &b)| {
            if !differs(a, b) {
                return Vec3::splat((crate::math::luminance(b) / mean.max(1e-6) * 0.01).min(0.02));
            }
            count += 1;
            let d = (crate::math::luminance(a) - crate::math::luminance(b)) * gain;
            if d >= 0.0 { Vec3::new(d.clamp(0.5, 1.0), 0.0, 0.0) } else { Vec3::new(0.0, 0.0, (-d).clamp(0.5, 1.0)) }
        })
        .collect();
    (image, count)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cost_colours_invert_to_their_cost() {
        for cost in [0.0f32, 1.0, 3.0, 17.0, 100.0, 512.0, 1000.0] {
            let back = invert_cost(cost_color(cost));
            assert!((back - cost).abs() < 0.01 * cost.max(1.0), "{cost} -> {back}");
            assert!((cost_of_t(t_of_cost(cost)) - cost).abs() < 0.01 * cost.max(1.0));
        }
    }

    /// Where `miss_color` names a view's colour for a miss, `view_color`
    /// gives exactly that colour whatever the ray (rasterizers fill their
    /// empty pixels with it without making the ray); the ray direction view
    /// is not among them.
    #[test]
    fn miss_colours_are_what_a_miss_shows() {
        let cam = crate::scene::Camera::default().view(16, 9);
        let rays = [Ray::new(Vec3::ZERO, Vec3::X), Ray::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, -0.6, 0.8))];
        let mut named = 0;
        for view in View::ALL {
            let Some(c) = miss_color(view) else { continue };
            named += 1;
            for ray in &rays {
                assert_eq!(view_color(view, &cam, ray, None), c, "{view:?}");
            }
        }
        assert_eq!(named, 9, "the views that colour only what is hit");
        assert!(miss_color(View::Raydir).is_none() && miss_color(View::Shaded).is_none());
    }

    #[test]
    fn depth_and_zbuffer_invert() {
        let cam = crate::scene::Camera { near: 0.1, far: 100.0, ..Default::default() }.view(10, 10);
        let d = depth_distance(&cam, depth_value(&cam, 7.5));
        assert!((d - 7.5).abs() < 1e-3, "{d}");
        assert!((zbuffer_depth(&cam, zbuffer_value(&cam, 3.0)) - 3.0).abs() < 1e-3);
        assert_eq!(zbuffer_value(&cam, cam.near), 1.0);
        assert_eq!(zbuffer_value(&cam, cam.far), 0.0);
    }
}
