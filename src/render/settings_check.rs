//! The ranges of the render settings' numbers, checked in one place for
//! every front end: the command line refuses a value out of range, and the
//! viewer puts a saved value out of range back to its default, both with
//! the same bound. Each problem names the knob as the command line does
//! (`--photons`) and as a saved settings file does (`gi.photons`).

use crate::render::RenderSettings;

/// The most samples per pixel a front end accepts.
pub const MAX_SPP: u32 = 65536;
/// The most photons shot.
pub const MAX_PHOTONS: u32 = 50_000_000;
/// The most AO samples, photon neighbours and final-gather rays.
pub const MAX_GATHER: u32 = 4096;
/// The widest PCF filter, in texels.
pub const MAX_PCF_RADIUS: f32 = 64.0;

/// The deepest mirror and glass recursion (`--max-depth`, the viewer's slider).
pub const MAX_MIRROR_DEPTH: u32 = 16;

/// One setting out of its range.
#[derive(Clone, Debug)]
pub struct SettingProblem {
    /// The command line's name for it.
    pub flag: &'static str,
    /// Its name in a saved settings file.
    pub field: &'static str,
    /// The value and its range, e.g. "0 is not between 1 and 65536".
    pub problem: String,
    /// Puts the setting back to its default value.
    pub reset: fn(&mut RenderSettings),
}

impl SettingProblem {
    /// As the command line says it: "--spp 0 is not between 1 and 65536".
    pub fn for_command_line(&self) -> String {
        format!("{} {}", self.flag, self.problem)
    }

    /// As said of a saved file: "render.spp 0 is not between ...; using the default".
    pub fn for_saved_file(&self) -> String {
        format!("saved setting render.{} {}; using the default", self.field, self.problem)
    }
}

/// The first setting out of range, if any.
pub fn check(s: &RenderSettings) -> Result<(), SettingProblem> {
    macro_rules! refuse {
        ($flag:expr, $field:expr, $reset:expr, $($msg:tt)*) => {
            return Err(SettingProblem { flag: $flag, field: $field, problem: format!($($msg)*), reset: $reset })
        };
    }
    if !(1..=MAX_SPP).contains(&s.spp) {
        refuse!("--spp", "spp", |s| s.spp = RenderSettings::default().spp, "{} is not between 1 and {MAX_SPP}", s.spp);
    }
    for (flag, field, v) in [("--width", "width", s.width), ("--height", "height", s.height)] {
        if !(1..=crate::input::MAX_IMAGE_SIDE).contains(&v) {
            let reset: fn(&mut RenderSettings) = if field == "width" { |s| s.width = RenderSettings::default().width } else { |s| s.height = RenderSettings::default().height };
            refuse!(flag, field, reset, "{v} is not between 1 and {}", crate::input::MAX_IMAGE_SIDE);
        }
    }
    if s.max_depth > MAX_MIRROR_DEPTH {
        refuse!("--max-depth", "max_depth", |s| s.max_depth = RenderSettings::default().max_depth, "{} is not a number from 0 to {MAX_MIRROR_DEPTH}", s.max_depth);
    }
    if s.light_samples > crate::render::MAX_LIGHT_SAMPLES {
        refuse!("--light-samples", "light_samples", |s| s.light_samples = RenderSettings::default().light_samples,
            "{} is above the maximum {} (0 turns light sampling off: BSDF sampling alone)", s.light_samples, crate::render::MAX_LIGHT_SAMPLES);
    }
    if !(s.pcf_radius.is_finite() && (0.0..=MAX_PCF_RADIUS).contains(&s.pcf_radius)) {
        refuse!("--pcf-radius", "pcf_radius", |s| s.pcf_radius = RenderSettings::default().pcf_radius, "{} is not a number from 0 to {MAX_PCF_RADIUS}", s.pcf_radius);
    }
    if !(s.shadow_bump.is_finite() && s.shadow_bump >= 0.0) {
        refuse!("--bump", "shadow_bump", |s| s.shadow_bump = RenderSettings::default().shadow_bump, "{} must be a finite number >= 0", s.shadow_bump);
    }
    if !(1..=crate::render::shadow::map::MAX_SIZE).contains(&s.shadow_map_size) {
        refuse!("--shadow-map-size", "shadow_map_size", |s| s.shadow_map_size = RenderSettings::default().shadow_map_size,
            "{} is not between 1 and {}", s.shadow_map_size, crate::render::shadow::map::MAX_SIZE);
    }
    if !(s.shadow_map_bias.is_finite() && s.shadow_map_bias >= 0.0) {
        refuse!("--shadow-bias", "shadow_map_bias", |s| s.shadow_map_bias = RenderSettings::default().shadow_map_bias, "{} must be a finite number of texels >= 0", s.shadow_map_bias);
    }
    if s.subpixel_bits > crate::render::raster::subpixel::SUBPIXEL_BITS {
        refuse!("--subpixel-bits", "subpixel_bits", |s| s.subpixel_bits = RenderSettings::default().subpixel_bits, "{} is more than {}", s.subpixel_bits, crate::render::raster::subpixel::SUBPIXEL_BITS);
    }
    if !crate::render::raster::msaa::COUNTS.contains(&s.msaa) {
        refuse!("--msaa", "msaa", |s| s.msaa = RenderSettings::default().msaa, "{} is not one of 1, 2, 4, 8", s.msaa);
    }
    if let Some(t) = s.adaptive {
        if !(t > 0.0 && t.is_finite()) {
            refuse!("--adaptive", "adaptive", |s| s.adaptive = RenderSettings::default().adaptive, "{t} must be a relative error > 0 (e.g. 0.05)");
        }
    }
    if !crate::render::frame::subsample::STEPS.contains(&s.subsample.step) {
        refuse!("--subsample", "subsample.step", |s| s.subsample = RenderSettings::default().subsample, "{} is not one of 1, 2, 4, 8, 16", s.subsample.step);
    }
    if let Some(c) = s.subsample.contrast {
        if !(c >= 0.0 && c.is_finite()) {
            refuse!("--subsample-contrast", "subsample.contrast", |s| s.subsample = RenderSettings::default().subsample, "{c} must be a contrast >= 0 (e.g. 0.3)");
        }
    }
    if let Err(problem) = s.display.check() {
        refuse!("--exposure", "display.exposure_ev", |s| s.display.exposure_ev = RenderSettings::default().display.exposure_ev, "{problem}");
    }
    let gi = &s.gi;
    if let Some(b) = gi.bounces {
        if b > crate::render::transport::gi::MAX_BOUNCES {
            refuse!("--bounces", "gi.bounces", |s| s.gi.bounces = RenderSettings::default().gi.bounces, "{b} is neither inf nor a number from 0 to {}", crate::render::transport::gi::MAX_BOUNCES);
        }
    }
    if !(1..=MAX_GATHER).contains(&gi.ao_samples) {
        refuse!("--ao-samples", "gi.ao_samples", |s| s.gi.ao_samples = RenderSettings::default().gi.ao_samples, "{} is not between 1 and {MAX_GATHER}", gi.ao_samples);
    }
    if !(gi.ao_distance > 0.0) {
        refuse!("--ao-distance", "gi.ao_distance", |s| s.gi.ao_distance = RenderSettings::default().gi.ao_distance, "{} must be a number > 0 (inf allowed)", gi.ao_distance);
    }
    if !(1..=MAX_PHOTONS).contains(&gi.photons) {
        refuse!("--photons", "gi.photons", |s| s.gi.photons = RenderSettings::default().gi.photons, "{} is not between 1 and {MAX_PHOTONS}", gi.photons);
    }
    if !(1..=MAX_GATHER).contains(&gi.photon_k) {
        refuse!("--photon-k", "gi.photon_k", |s| s.gi.photon_k = RenderSettings::default().gi.photon_k, "{} is not between 1 and {MAX_GATHER}", gi.photon_k);
    }
    if gi.final_gather > MAX_GATHER {
        refuse!("--final-gather", "gi.final_gather", |s| s.gi.final_gather = RenderSettings::default().gi.final_gather, "{} is more than {MAX_GATHER}", gi.final_gather);
    }
    Ok(())
}

/// `s` with every setting out of range put back to its default, and one
/// sentence for each (a saved file written by hand or by another version).
pub fn repaired(mut s: RenderSettings) -> (RenderSettings, Vec<String>) {
    let mut said = Vec::new();
    // Each pass repairs one setting; there are fewer settings than this.
    for _ in 0..64 {
        match check(&s) {
            Ok(()) => break,
            Err(p) => {
                said.push(p.for_saved_file());
                (p.reset)(&mut s);
            }
        }
    }
    (s, said)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_are_in_range() {
        assert!(check(&RenderSettings::default()).is_ok());
    }

    #[test]
    fn every_out_of_range_value_is_named_and_repaired() {
        let mut s = RenderSettings::default();
        s.gi.ao_distance = f32::NAN;
        s.gi.photons = 60_000_000;
        s.shadow_bump = -1.0;
        s.spp = 0;
        let first = check(&s).unwrap_err();
        assert_eq!(first.for_command_line(), "--spp 0 is not between 1 and 65536");
        let (fixed, said) = repaired(s);
        assert!(check(&fixed).is_ok());
        assert_eq!(fixed, RenderSettings::default());
        assert_eq!(said.len(), 4, "{said:?}");
        assert!(said.iter().any(|m| m.contains("render.gi.ao_distance NaN")), "{said:?}");
        assert!(said.iter().any(|m| m.contains("render.gi.photons 60000000")), "{said:?}");
        assert!(said.iter().any(|m| m.contains("render.shadow_bump -1")), "{said:?}");
    }
}
