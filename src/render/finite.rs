//! Keeping NaN and infinity out of pixels. A degenerate hit or a division
//! by zero in a shading formula can make a sample non-finite; it would then
//! poison its pixel for every later pass. A sample is admitted as itself
//! when finite and as black otherwise.
//!
//! A one-sample frame is rendered straight into the frame's sum, so its
//! values must be checked after they are written. Renderers that write in
//! bands check each band (`admit_all`) as soon as it is finished, while it
//! is still in cache, and say so (`Renderer::admits_its_samples`); for the
//! others the frame scans the whole pass afterwards, a second trip through
//! memory. A value streamed past the cache (`math::streaming`) is admitted
//! before it is stored, and the band's check leaves it out
//! (`admit_rows_except`).

use crate::math::Radiance;
use std::ops::Range;

/// What a sample adds to its pixel: itself when finite, nothing otherwise.
#[inline]
pub fn admitted(sample: Radiance) -> Radiance {
    // x * 0 is a zero exactly when x is finite (NaN for NaN and the
    // infinities): one comparison, no branch per channel, where every pixel
    // of every pass comes through.
    let finite = (sample * 0.0).dot(Radiance::ONE) == 0.0;
    if finite { sample } else { Radiance::ZERO }
}

/// Replaces every non-finite value of `values` by black and returns how
/// many it replaced (a frame's `non_finite` count). A read-only scan in
/// lanes: the values are rewritten only when one of them is not finite
/// (rarely).
pub fn admit_all(values: &mut [Radiance]) -> u64 {
    if crate::math::lanes::all_finite(bytemuck::cast_slice(values)) {
        return 0;
    }
    let mut replaced = 0;
    for v in values.iter_mut() {
        replaced += u64::from(!v.is_finite());
        *v = admitted(*v);
    }
    replaced
}

/// `admit_all` over each range of `rows` (in ascending order, apart) of
/// `values`, except the ranges `skipped` (ascending, each within one row):
/// values a renderer streamed past the cache, admitted before they were
/// stored, which a scan would read back from memory.
pub fn admit_rows_except(values: &mut [Radiance], rows: impl Iterator<Item = Range<usize>>, skipped: &[Range<usize>]) -> u64 {
    let mut skip = skipped.iter().peekable();
    let mut replaced = 0;
    for row in rows {
        let mut from = row.start;
        while let Some(s) = skip.next_if(|s| s.start < row.end) {
            replaced += admit_all(&mut values[from..s.start]);
            from = s.end;
        }
        replaced += admit_all(&mut values[from..row.end]);
    }
    replaced
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rows of ten values out of every twelve, with zero, one or two
    /// ranges skipped in a row (at its start, middle and end): every NaN
    /// outside the skipped ranges becomes black, those inside stay.
    #[test]
    fn rows_are_admitted_except_the_skipped_ranges() {
        let rows = (0..4).map(|r| 12 * r + 1..12 * r + 11);
        let skipped = [13..16, 18..20, 25..35, 42..47];
        let mut values = vec![Radiance::NAN; 48];
        admit_rows_except(&mut values, rows.clone(), &skipped);
        for (i, v) in values.iter().enumerate() {
            let in_row = rows.clone().any(|r| r.contains(&i));
            let kept = skipped.iter().any(|s| s.contains(&i));
            assert_eq!(v.is_nan(), !in_row || kept, "value {i}");
        }
    }

    #[test]
    fn non_finite_values_become_black_and_the_others_stay() {
        assert_eq!(admitted(Radiance::new(1.0, f32::NAN, 0.0)), Radiance::ZERO);
        assert_eq!(admitted(Radiance::new(1.0, 2.0, 3.0)), Radiance::new(1.0, 2.0, 3.0));
        let fine: Vec<Radiance> = (0..37).map(|i| Radiance::new(i as f32, -(i as f32), f32::MAX)).collect();
        for at in 0..fine.len() {
            for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
                let mut v = fine.clone();
                v[at].y = bad;
                admit_all(&mut v);
                assert_eq!(v[at], Radiance::ZERO, "{bad} at {at}");
                assert!(v.iter().enumerate().all(|(i, &x)| i == at || x == fine[i]), "{bad} at {at}");
            }
        }
        let mut same = fine.clone();
        admit_all(&mut same);
        assert_eq!(same, fine);
    }
}

#[cfg(test)]
mod renderer_tests {
    use crate::math::Radiance;
    use crate::render::raytrace::brute_renderer::BruteForce;
    use crate::render::raytrace::bvh_renderer::BvhRayTracer;
    use crate::math::Vec3;
    use crate::render::{raster, PassJob, PreparedScene, RenderSettings, Renderer, ShadowMode};
    use crate::scene::{builtin, Light};
    use std::sync::atomic::AtomicBool;

    /// A renderer that says it admits its samples leaves nothing but finite
    /// values in its output, whatever was there before: here a pass whose
    /// pixels are all inactive (so none is written) over an output full of
    /// NaN. Without the band check the NaN would stay, and a one-sample
    /// frame, which then skips its own scan, would show it.
    #[test]
    fn renderers_that_admit_their_samples_leave_no_nan_in_their_output() {
        let prepared = PreparedScene::new(builtin::load_builtin("spheres").unwrap().unwrap());
        let (w, h) = (40u32, 21u32);
        let view = prepared.scene.camera.view(w, h);
        let settings = RenderSettings::for_scene(&prepared.scene);
        let cancel = AtomicBool::new(false);
        let inactive = vec![false; (w * h) as usize];
        let mut renderers: Vec<Box<dyn Renderer>> = raster::renderers();
        renderers.push(Box::new(BvhRayTracer));
        renderers.push(Box::new(BruteForce));
        for renderer in &renderers {
            assert!(renderer.admits_its_samples(), "{}", renderer.name());
            for active in [Some(&inactive[..]), None] {
                let job = PassJob { prepared: &prepared, view: &view, settings: &settings, offset: glam::Vec2::splat(0.5), sample: 0, photons: None, active, rows: 0..h, cancel: &cancel, keep_non_finite: false };
                let mut out = vec![Radiance::splat(f32::NAN); (w * h) as usize];
                renderer.render_pass(&job, &mut out);
                assert!(out.iter().all(|v| v.is_finite()), "{} (active: {})", renderer.name(), active.is_none());
            }
        }
    }

    /// The same renderers shading with a light of infinite power, which
    /// makes every lit sample infinite or NaN: each one becomes black in
    /// the output (over a hundred pixels that are not black with the
    /// light's own power), and the rest stays finite. The rasterizers
    /// stream the background of rows this wide.
    #[test]
    fn renderers_admit_the_non_finite_samples_they_shade() {
        let finite_power = PreparedScene::new(builtin::load_builtin("teapot").unwrap().unwrap());
        let mut scene = builtin::load_builtin("teapot").unwrap().unwrap();
        for light in &mut scene.lights {
            let (Light::Point { power, .. } | Light::Directional { irradiance: power, .. }) = light;
            *power = Vec3::splat(f32::INFINITY);
        }
        let prepared = PreparedScene::new(scene);
        let (w, h) = (96u32, 40u32);
        let view = prepared.scene.camera.view(w, h);
        let settings = RenderSettings { shadows: ShadowMode::None, ..RenderSettings::for_scene(&prepared.scene) };
        let cancel = AtomicBool::new(false);
        let mut renderers: Vec<Box<dyn Renderer>> = raster::renderers();
        renderers.push(Box::new(BvhRayTracer));
        renderers.push(Box::new(BruteForce));
        for renderer in &renderers {
            let job = PassJob { prepared: &prepared, view: &view, settings: &settings, offset: glam::Vec2::splat(0.5), sample: 0, photons: None, active: None, rows: 0..h, cancel: &cancel, keep_non_finite: false };
            let mut out = vec![Radiance::splat(-1.0); (w * h) as usize];
            renderer.render_pass(&job, &mut out);
            assert!(out.iter().all(|v| v.is_finite()), "{}", renderer.name());
            let mut lit = vec![Radiance::splat(-1.0); (w * h) as usize];
            renderer.render_pass(&PassJob { prepared: &finite_power, ..job }, &mut lit);
            let blackened = out.iter().zip(&lit).filter(|(v, l)| **v == Radiance::ZERO && **l != Radiance::ZERO).count();
            assert!(blackened > 100, "{}: only {blackened} pixels blackened", renderer.name());
        }
    }
}
