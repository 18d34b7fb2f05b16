//! Arbitrary output variables (`--aov`): per pixel, raw values of the
//! surface its first eye ray sees, written beside the image as named
//! layers of one EXR. Not display colours: the depth is a distance, the
//! normal a unit vector in world space.
//!
//! Every pixel's layers come from the eye ray of its first sample (sample
//! index 0, at that sample's offset), cast through the BVH and given its
//! ray differentials and normal map as the ray casters give them; so for
//! the ray casters they describe the hit `pinhole pixel` reports for that
//! sample. A rasterizer or OpenGL finds its own hits, which can differ
//! along edges: the gate says so in a notice (`admit::aov_notice`).

use crate::named::named_enum;
use crate::render::accel::bvh::BvhQuery;
use crate::render::inspect::pixel_record::NoRecord;
use crate::render::{FramePart, PassJob, PreparedScene, RayCounts, RenderSettings, SceneQuery};
use rayon::prelude::*;
use std::sync::atomic::AtomicBool;

named_enum! {
    /// One layer `--aov` can ask for.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
    pub enum Aov ("AOV") {
        /// Distance along the eye ray from its origin to the hit (the ray's t;
        /// the eye ray's direction is a unit vector). Channel `depth.Z`.
        Depth = "depth",
        /// The shading normal (interpolated, normal-mapped, facing the
        /// viewer on two-sided surfaces) in world space. `normal.X/Y/Z`.
        Normal = "normal",
        /// The material's diffuse albedo at the hit, textures applied.
        /// `albedo.R/G/B`.
        Albedo = "albedo",
        /// The hit point in world space. `position.X/Y/Z`.
        Position = "position",
        /// The hit's texture coordinates. `uv.U/V`.
        Uv = "uv",
        /// The object's index (`pinhole pixel`'s `object`). `id.Y`.
        Id = "id",
        /// The material's index. `material.Y`.
        Material = "material",
    }
}

impl Aov {
    /// The layer's channels, as the EXR names them after the layer's name.
    pub fn channels(self) -> &'static [&'static str] {
        match self {
            Aov::Depth => &["Z"],
            Aov::Normal | Aov::Position => &["X", "Y", "Z"],
            Aov::Albedo => &["R", "G", "B"],
            Aov::Uv => &["U", "V"],
            Aov::Id | Aov::Material => &["Y"],
        }
    }
}

/// What a pixel's layers hold where its eye ray meets nothing: zeros,
/// except the ids, which are -1 (no object).
const MISS_ID: f32 = -1.0;

/// `--aov LIST`: comma-separated layer names, each once, checked.
pub fn parse_list(list: &str) -> Result<Vec<Aov>, String> {
    let mut out = Vec::new();
    for name in list.split(',').map(str::trim) {
        let aov = Aov::parse(name).map_err(|_| {
            let known: Vec<&str> = Aov::ALL.iter().map(|a| a.name()).collect();
            format!("--aov: \"{name}\" is not one of {}", known.join(", "))
        })?;
        if out.contains(&aov) {
            return Err(format!("--aov: \"{name}\" is asked for twice"));
        }
        out.push(aov);
    }
    Ok(out)
}

/// One named layer: its channels' full names (`normal.X`) and values,
/// row-major over the image.
pub struct AovLayer {
    pub aov: Aov,
    pub channels: Vec<(String, Vec<f32>)>,
}

/// The layers `aovs` of the frame `settings` describe, over `part`'s
/// rectangle (the whole frame when `None`).
pub fn render_aovs(prepared: &PreparedScene, settings: &RenderSettings, aovs: &[Aov], part: Option<&FramePart>) -> Vec<AovLayer> {
    let whole = FramePart::whole(settings);
    let part = part.unwrap_or(&whole);
    let (w, h) = (part.x.len(), part.y.len());
    let view = prepared.scene.camera.view(settings.width, settings.height);
    let cancel = AtomicBool::new(false);
    let query = BvhQuery::new(prepared);
    let spp = settings.spp.max(1);
    // One row of hits at a time, in parallel: the hit of each pixel's first sample.
    let rows: Vec<Vec<Option<crate::scene::SurfaceHit>>> = part
        .y
        .clone()
        .into_par_iter()
        .map(|y| {
            let job = PassJob {
                prepared,
                view: &view,
                settings,
                offset: crate::render::sample_offset(0, spp, settings.gi.seed),
                sample: 0,
                photons: None,
                active: None,
                rows: y..y + 1,
                cancel: &cancel,
                keep_non_finite: false,
            };
            part.x
                .clone()
                .map(|x| {
                    let (ray, t_max) = job.eye_ray(x, y);
                    let mut hit = query.closest(&ray, t_max, false, &mut RayCounts::default(), &mut NoRecord);
                    crate::render::raytrace::with_eye_differentials(&job, job.sample_position(x, y), &ray, &mut hit);
                    hit
                })
                .collect()
        })
        .collect();
    let hits: Vec<&Option<crate::scene::SurfaceHit>> = rows.iter().flatten().collect();
    let scene = &prepared.scene;
    aovs.iter()
        .map(|&aov| {
            let values = |k: usize| -> Vec<f32> {
                hits.iter()
                    .map(|hit| match hit {
                        None => match aov {
                            Aov::Id | Aov::Material => MISS_ID,
                            _ => 0.0,
                        },
                        Some(h) => match aov {
                            Aov::Depth => h.t,
                            Aov::Normal => h.shading_normal[k],
                            Aov::Position => h.position[k],
                            Aov::Uv => h.uv[k],
                            Aov::Albedo => scene.materials[h.material as usize].albedo(h.uv, &h.diff.footprint(), settings.texture_filter)[k],
                            Aov::Id => h.object as f32,
                            Aov::Material => h.material as f32,
                        },
                    })
                    .collect()
            };
            let channels = aov.channels().iter().enumerate().map(|(k, c)| (format!("{}.{c}", aov.name()), values(k))).collect();
            debug_assert_eq!(hits.len(), w * h);
            AovLayer { aov, channels }
        })
        .collect()
}
