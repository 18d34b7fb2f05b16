//! Measuring a case: render its failing and cured settings and its truth,
//! and count the wrong pixels of each against the truth.
//!
//! A pixel is wrong when some channel differs from the truth by more than
//! `ABS_TOLERANCE` and by more than `REL_TOLERANCE` of the larger of the two
//! values (a non-finite value is always wrong): small enough to catch a
//! shadow that moved or a speckle, large enough to let rounding pass.

use crate::gallery::cases::{GalleryCase, Setting};
use crate::math::Radiance;
use crate::render::{self, PreparedScene, RenderSettings};
use std::sync::atomic::AtomicBool;

/// Differences up to this (linear radiance) never count.
pub const ABS_TOLERANCE: f32 = 1e-3;
/// Differences up to this fraction of the brighter value never count.
pub const REL_TOLERANCE: f32 = 0.02;

/// Pixels of `image` whose difference from `truth` exceeds the tolerances.
pub fn wrong_pixels(image: &[Radiance], truth: &[Radiance], width: u32, height: u32) -> usize {
    let n = (width as usize) * (height as usize);
    assert!(image.len() == n && truth.len() == n, "images must both be {width}x{height}");
    image.iter().zip(truth).filter(|(a, b)| pixel_wrong(**a, **b)).count()
}

/// Whether `a` is wrong against the truth `b` (the rule above).
pub fn pixel_wrong(a: Radiance, b: Radiance) -> bool {
    pixel_wrong_within(a, b, REL_TOLERANCE)
}

/// The rule above with a relative tolerance of `relative`.
pub fn pixel_wrong_within(a: Radiance, b: Radiance, relative: f32) -> bool {
    if !(a.is_finite() && b.is_finite()) {
        return true;
    }
    (0..3).any(|c| {
        let d = (a[c] - b[c]).abs();
        d > ABS_TOLERANCE && d > relative * a[c].abs().max(b[c].abs())
    })
}

/// Renders `setting` of `case`: loads the scene (the case's or the
/// setting's own), transforms it, applies the knobs, at the case's size.
/// Returns the image and its size.
pub fn render_setting(case: &GalleryCase, setting: &Setting) -> Result<(Vec<Radiance>, u32, u32), String> {
    let (scene, mut settings) = scene_and_settings(case, setting)?;
    if let Some((w, h)) = case.size {
        (settings.width, settings.height) = (w, h);
    }
    let renderer = render::renderer_by_name(setting.renderer)?;
    let admitted = render::admit::admit(renderer.as_ref(), &scene, &settings).map_err(|e| format!("gallery case {}: \"{}\": {e}", case.name, setting.description))?;
    // A case shows what its settings draw: a substitute would show something else.
    if let Some(n) = admitted.notices.first() {
        return Err(format!("gallery case {}: \"{}\": {n}", case.name, setting.description));
    }
    renderer.ready(&admitted.settings)?;
    let prepared = PreparedScene::new(scene);
    let frame = render::render_frame(renderer.as_ref(), &prepared, &admitted.settings, &AtomicBool::new(false), None).ok_or("the render was cancelled")?;
    Ok((frame.pixels, settings.width, settings.height))
}

/// The scene and settings `setting` of `case` renders at the scene's size
/// (the viewer opens the same).
pub fn scene_and_settings(case: &GalleryCase, setting: &Setting) -> Result<(crate::scene::Scene, RenderSettings), String> {
    let name = setting.scene.unwrap_or(case.scene);
    let mut scene = crate::scene::builtin::load_builtin(name).ok_or_else(|| format!("gallery case {}: no built-in scene \"{name}\"", case.name))??;
    if let Some(t) = setting.transform {
        t(&mut scene);
    }
    let mut settings = RenderSettings::for_scene(&scene);
    (setting.apply)(&mut settings);
    Ok((scene, settings))
}

/// One setting of a case, measured.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SettingResult {
    pub setting: String,
    pub wrong_pixels: usize,
    #[serde(skip)]
    pub image: Vec<Radiance>,
}

/// A case measured: both settings against the truth.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CaseResult {
    pub case: String,
    pub method: String,
    /// How the truth was made (the sheet shows it; not in the JSON).
    #[serde(skip)]
    pub truth_setting: String,
    pub knob: String,
    pub failing: SettingResult,
    pub cured: SettingResult,
    /// The truth image, for the sheet's map of wrong pixels.
    #[serde(skip)]
    pub truth: Vec<Radiance>,
    #[serde(skip)]
    pub width: u32,
    #[serde(skip)]
    pub height: u32,
    #[serde(skip)]
    pub threshold: usize,
    #[serde(skip)]
    pub exposure: f32,
}

impl CaseResult {
    /// The case shows what it claims: fails at its failing setting, passes at its cure.
    pub fn demonstrated(&self) -> bool {
        self.failing.wrong_pixels > self.threshold && self.cured.wrong_pixels <= self.threshold
    }
}

/// The three images a case is judged by, at one size.
pub struct CaseImages {
    pub truth: Vec<Radiance>,
    pub failing: Vec<Radiance>,
    pub cured: Vec<Radiance>,
    pub width: u32,
    pub height: u32,
}

/// Renders the truth and both settings of `case`.
pub fn render_case(case: &GalleryCase) -> Result<CaseImages, String> {
    let (truth, w, h) = render_setting(case, &case.truth)?;
    let mut rendered = Vec::new();
    for setting in [&case.failing, &case.cured] {
        let (image, sw, sh) = render_setting(case, setting)?;
        if (sw, sh) != (w, h) {
            return Err(format!("gallery case {}: \"{}\" renders {sw}x{sh} but the truth is {w}x{h}", case.name, setting.description));
        }
        rendered.push(image);
    }
    let cured = rendered.pop().expect("two settings");
    let failing = rendered.pop().expect("two settings");
    Ok(CaseImages { truth, failing, cured, width: w, height: h })
}

/// Counts the wrong pixels of both settings of `case` against the truth.
pub fn judge(case: &GalleryCase, images: CaseImages) -> Result<CaseResult, String> {
    let CaseImages { truth, failing, cured, width: w, height: h } = images;
    let n = w as usize * h as usize;
    if [&truth, &failing, &cured].iter().any(|i| i.len() != n) {
        return Err(format!("gallery case {}: its three images are not all {w}x{h}", case.name));
    }
    let count = |image: &[Radiance]| match case.noise_tolerance {
        Some(relative) => image.iter().zip(&truth).filter(|(a, b)| pixel_wrong_within(**a, **b, relative)).count(),
        None => wrong_pixels(image, &truth, w, h),
    };
    let result = |setting: &Setting, image: Vec<Radiance>| SettingResult { setting: format!("{} {}", setting.renderer, setting.description), wrong_pixels: count(&image), image };
    let failing = result(&case.failing, failing);
    let cured = result(&case.cured, cured);
    let exposure = crate::scene::builtin::load_builtin(case.scene).and_then(Result::ok).map_or(1.0, |s| s.render.exposure);
    Ok(CaseResult {
        case: case.name.to_string(),
        truth_setting: case.truth.description.to_string(),
        method: case.method.to_string(),
        knob: case.knob.to_string(),
        failing,
        cured,
        truth,
        width: w,
        height: h,
        threshold: case.threshold,
        exposure,
    })
}

/// Renders the truth and both settings of `case` and counts their wrong pixels.
pub fn measure_case(case: &GalleryCase) -> Result<CaseResult, String> {
    judge(case, render_case(case)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tolerances_count_only_real_differences() {
        let t = vec![Radiance::new(0.5, 0.5, 0.5), Radiance::ZERO, Radiance::splat(1.0), Radiance::splat(0.2)];
        let img = vec![
            Radiance::new(0.505, 0.5, 0.5), // 1% off: rounding
            Radiance::splat(0.0009),        // below the absolute floor
            Radiance::new(1.0, 0.9, 1.0),   // 10% off in green
            Radiance::new(f32::NAN, 0.2, 0.2),
        ];
        assert_eq!(wrong_pixels(&img, &t, 2, 2), 2);
        assert_eq!(wrong_pixels(&t, &t, 2, 2), 0);
    }
}
