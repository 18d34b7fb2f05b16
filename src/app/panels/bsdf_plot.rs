//! A material's BSDF in the plane of incidence, drawn as a polar curve for
//! an incident angle the user chooses, with its directional albedo: what
//! the shading code evaluates (`transport::bsdf::bsdf`), so the curve is
//! the lobe the renderers draw.

use crate::math::Vec3;
use crate::render::transport::bsdf::bsdf;
use crate::scene::Material;
use eframe::egui;
use egui_plot::{Line, Plot, PlotPoints};

/// Outgoing angles drawn, from -90 to 90 degrees (a quarter degree apart,
/// so that a sharp lobe of a few degrees is drawn whole).
const SLICE_STEPS: usize = 720;
/// The directional albedo's grid over the hemisphere: cells of equal solid
/// angle in (cos theta, phi), evaluated at their centres.
const GRID_COS: usize = 384;
const GRID_PHI: usize = 384;

/// The unit direction at polar angle `theta` (radians) in the plane of
/// incidence, on the side of +x for positive angles, about the normal z.
fn in_plane(theta: f32) -> Vec3 {
    Vec3::new(theta.sin(), 0.0, theta.cos())
}

/// The light's direction for incident angle `theta_i` (degrees): on the -x
/// side, so that its mirror direction is at `+theta_i`.
fn light_direction(theta_i_deg: f32) -> Vec3 {
    in_plane(-theta_i_deg.to_radians())
}

/// The slice of `m`'s lobe in the plane of incidence: for each outgoing
/// angle theta_o the mean over RGB of `f(w_i, w_o) cos theta_o` (the light
/// reflected towards w_o per unit irradiance), as a point at that angle and
/// distance from the origin.
pub fn slice(m: &Material, theta_i_deg: f32) -> Vec<[f64; 2]> {
    let w_i = light_direction(theta_i_deg);
    (0..=SLICE_STEPS)
        .map(|k| {
            let theta_o = (-90.0 + 180.0 * k as f32 / SLICE_STEPS as f32).to_radians();
            let w_o = in_plane(theta_o);
            let f = bsdf(m, m.lambertian, Vec3::Z, w_i, w_o);
            let r = ((f.x + f.y + f.z) / 3.0 * w_o.z.max(0.0)) as f64;
            let r = if r.is_finite() { r } else { 0.0 };
            [r * (theta_o as f64).sin(), r * (theta_o as f64).cos()]
        })
        .collect()
}

/// The directional albedo for light arriving at `theta_i_deg`: the integral
/// over the hemisphere of `f(w_i, w_o) cos theta_o`, per channel, by the
/// midpoint rule on a `GRID_COS` x `GRID_PHI` grid in (cos theta_o, phi)
/// (cells of equal solid angle). Lobes much narrower than a cell (a
/// Blinn-Phong exponent in the tens of thousands, a microfacet alpha below
/// about 0.01) are under-resolved.
pub fn directional_albedo(m: &Material, theta_i_deg: f32) -> Vec3 {
    let w_i = light_direction(theta_i_deg);
    let cell = (1.0 / GRID_COS as f64) * (2.0 * std::f64::consts::PI / GRID_PHI as f64);
    let mut sum = [0.0f64; 3];
    for a in 0..GRID_COS {
        let mu = (a as f32 + 0.5) / GRID_COS as f32;
        let sin = (1.0 - mu * mu).max(0.0).sqrt();
        for b in 0..GRID_PHI {
            let phi = (b as f32 + 0.5) / GRID_PHI as f32 * std::f32::consts::TAU;
            let w_o = Vec3::new(sin * phi.cos(), sin * phi.sin(), mu);
            let f = bsdf(m, m.lambertian, Vec3::Z, w_i, w_o) * mu;
            for (s, v) in sum.iter_mut().zip(f.to_array()) {
                if v.is_finite() {
                    *s += v as f64;
                }
            }
        }
    }
    Vec3::new((sum[0] * cell) as f32, (sum[1] * cell) as f32, (sum[2] * cell) as f32)
}

/// The plot section of one material: the incident angle, the albedo and
/// the curve. The albedo is kept in the UI's memory with the material and
/// angle it was computed for, and computed again only when they change.
pub fn show(ui: &mut egui::Ui, m: &Material) {
    egui::CollapsingHeader::new(format!("{} lobe plot", m.name)).default_open(false).show(ui, |ui| {
        let angle_id = ui.make_persistent_id("incident angle");
        let mut theta_i: f32 = ui.data(|d| d.get_temp(angle_id)).unwrap_or(45.0);
        ui.horizontal(|ui| {
            let l = ui.label(format!("{} incident angle", m.name));
            ui.add(egui::Slider::new(&mut theta_i, 0.0..=89.0).suffix("°")).labelled_by(l.id);
        });
        ui.data_mut(|d| d.insert_temp(angle_id, theta_i));

        let albedo_id = ui.make_persistent_id("albedo");
        let cached: Option<(Material, f32, Vec3)> = ui.data(|d| d.get_temp(albedo_id));
        let albedo = match cached {
            Some((material, angle, albedo)) if material == *m && angle == theta_i => albedo,
            _ => {
                let albedo = directional_albedo(m, theta_i);
                ui.data_mut(|d| d.insert_temp(albedo_id, (m.clone(), theta_i, albedo)));
                albedo
            }
        };
        ui.label(format!("{} directional albedo: {:.4} {:.4} {:.4}", m.name, albedo.x, albedo.y, albedo.z));

        let curve = slice(m, theta_i);
        let reach = curve.iter().map(|p| p[0].hypot(p[1])).fold(0.0f64, f64::max).max(1e-6);
        let w_i = light_direction(theta_i);
        let light = vec![[0.0, 0.0], [w_i.x as f64 * reach, w_i.z as f64 * reach]];
        Plot::new(ui.make_persistent_id("lobe"))
            .height(180.0)
            .data_aspect(1.0)
            .allow_scroll(false)
            .legend(egui_plot::Legend::default())
            .show(ui, |p| {
                p.line(Line::new("incident light", PlotPoints::from(light)));
                p.line(Line::new("f cos θo (mean of RGB)", PlotPoints::from(curve)));
            });
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::PI;

    #[test]
    fn a_lambertian_lobe_reflects_its_albedo_at_every_angle_and_is_a_circle() {
        let mut m = Material::black();
        m.lambertian = Vec3::new(0.8, 0.5, 0.2);
        for theta in [0.0, 30.0, 80.0] {
            let a = directional_albedo(&m, theta);
            assert!((a - m.lambertian).abs().max_element() < 1e-4, "{a}");
        }
        // f cos theta_o = k / pi cos theta_o: a circle through the origin
        // of diameter k / pi, whatever the incident angle.
        let k = (0.8 + 0.5 + 0.2) / 3.0 / PI;
        for p in slice(&m, 60.0) {
            let d = (p[0] * p[0] + (p[1] - k as f64 / 2.0).powi(2)).sqrt();
            assert!((d - k as f64 / 2.0).abs() < 1e-6, "{p:?}");
        }
    }

    #[test]
    fn a_glossy_lobe_peaks_at_the_mirror_direction() {
        let mut m = Material::black();
        m.glossy = Vec3::ONE;
        m.glossy_model = crate::scene::material::GlossyModel::Phong;
        m.sharpness = 200.0;
        let curve = slice(&m, 40.0);
        let peak = curve.iter().max_by(|a, b| a[0].hypot(a[1]).total_cmp(&b[0].hypot(b[1]))).unwrap();
        let angle = peak[0].atan2(peak[1]).to_degrees();
        assert!((angle - 40.0).abs() < 0.5, "peak at {angle} degrees");
        // Normalized Phong reflects less than arrives at 40 degrees.
        let a = directional_albedo(&m, 40.0);
        assert!(a.x > 0.5 && a.x <= 1.0, "{a}");
    }
}
