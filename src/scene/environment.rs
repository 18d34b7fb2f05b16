//! The environment: a latitude-longitude image of radiance arriving from
//! infinitely far away, seen by every ray that hits nothing (instead of the
//! flat `background`), and so by mirrors (Computer Graphics from Scratch ch. 15).
//! It is also a light: `EnvironmentLight` samples directions in proportion
//! to luminance times `sin theta`, a piecewise-constant distribution over
//! the image's texels built once per map.

use crate::scene::texture::{Texture, Wrap};
use crate::math::{Vec2, Vec3};
use std::f32::consts::PI;
use std::sync::Arc;

#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    pub texture: Arc<Texture>,
    /// Scales the image's values into radiance.
    pub intensity: f32,
    /// How directions are sampled when it lights surfaces (`None` where the
    /// image is black: it lights nothing).
    pub light: Option<Arc<EnvironmentLight>>,
}

/// Unit direction of the point `(u, v)` of a latitude-longitude image
/// (`latlong_uv`'s inverse).
#[inline]
pub fn latlong_dir(uv: Vec2) -> Vec3 {
    let phi = (uv.x - 0.5) * 2.0 * PI;
    let lat = (uv.y - 0.5) * PI;
    let c = lat.cos();
    Vec3::new(phi.sin() * c, lat.sin(), -phi.cos() * c)
}

/// Where unit direction `dir` falls in a latitude-longitude image: u is the
/// longitude, 0.5 looking down -z, growing towards +x (0.75) and round to
/// +z at the seam (0 or 1); v the latitude, 1 straight up (the top row),
/// 0 straight down.
#[inline]
pub fn latlong_uv(dir: Vec3) -> Vec2 {
    let u = 0.5 + dir.x.atan2(-dir.z) * (0.5 / PI);
    let v = 0.5 + dir.y.clamp(-1.0, 1.0).asin() / PI;
    Vec2::new(u, v)
}

impl Environment {
    /// The environment of image `texture` scaled by `intensity`, with its
    /// sampling distribution built.
    pub fn new(texture: Arc<Texture>, intensity: f32) -> Environment {
        let light = if intensity > 0.0 { EnvironmentLight::build(&texture).map(Arc::new) } else { None };
        Environment { texture, intensity, light }
    }

    /// Whether it sends any light.
    #[inline]
    pub fn is_light(&self) -> bool {
        self.light.is_some()
    }

    /// Radiance arriving from direction `dir` (unit, pointing away from
    /// the scene): the image read bilinearly at its finest level, repeating
    /// around the horizon and clamped at the poles.
    #[inline]
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        self.radiance_at(latlong_uv(dir))
    }

    /// `radiance` of the direction at point `uv` of the image.
    #[inline]
    pub fn radiance_at(&self, uv: Vec2) -> Vec3 {
        let v = self.texture.levels[0].bilinear_uv(uv, Wrap::Repeat, Wrap::Clamp) * self.intensity;
        if v.is_finite() { v } else { Vec3::ZERO }
    }
}

/// Sampling the environment's directions: a row (latitude) chosen from
/// the marginal distribution, then a column from that row's; inside the
/// texel uniformly. Each texel weighs its luminance times `sin theta` (the
/// solid angle a row's texels cover shrinks towards the poles), taken as
/// the largest of it and its eight neighbours, because `radiance` reads
/// bilinearly and so sees a bright texel half a texel around it.
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentLight {
    width: usize,
    height: usize,
    /// Per row, the running sum of its texels' weights (`width` entries,
    /// the last the row's total); rows one after another.
    columns: Vec<f32>,
    /// The running sum of the rows' totals (`height` entries).
    rows: Vec<f32>,
    /// Per row, the last running sum of each block of `BLOCK` columns
    /// (`blocks` entries a row): a column search first finds its block in
    /// these few, then its column inside one cache line of `columns`, where
    /// a search of the whole row walks through several lines of a table too
    /// big for the cache.
    block_ends: Vec<f32>,
    blocks: usize,
}

/// Columns per block of `EnvironmentLight::block_ends`: one cache line of f32s.
const BLOCK: usize = 16;

impl EnvironmentLight {
    /// `None` when no texel has a finite, positive luminance.
    pub fn build(texture: &Texture) -> Option<EnvironmentLight> {
        let level = &texture.levels[0];
        let (w, h) = (level.width as usize, level.height as usize);
        if w == 0 || h == 0 {
            return None;
        }
        let lum = |x: usize, y: usize| {
            let c = level.texels[x + y * w];
            let l = c.dot(Vec3::new(0.2126, 0.7152, 0.0722));
            if l.is_finite() && l > 0.0 { l } else { 0.0 }
        };
        let mut columns = Vec::with_capacity(w * h);
        let mut rows = Vec::with_capacity(h);
        let mut total = 0.0f64;
        for y in 0..h {
            let sin_theta = (PI * (y as f32 + 0.5) / h as f32).sin();
            let mut row = 0.0f64;
            for x in 0..w {
                let mut m = 0.0f32;
                for dy in [-1i64, 0, 1] {
                    let yy = y as i64 + dy;
                    if yy < 0 || yy >= h as i64 {
                        continue;
                    }
                    for dx in [w - 1, 0, 1] {
                        m = m.max(lum((x + dx) % w, yy as usize));
                    }
                }
                row += (m * sin_theta) as f64;
                columns.push(row as f32);
            }
            total += row;
            rows.push(total as f32);
        }
        let blocks = w.div_ceil(BLOCK);
        let block_ends = columns.chunks(w).flat_map(|row| (0..blocks).map(|b| row[((b + 1) * BLOCK).min(w) - 1])).collect();
        (total > 0.0 && total.is_finite()).then_some(EnvironmentLight { width: w, height: h, columns, rows, block_ends, blocks })
    }

    /// About the integral of the luminance over the sphere (from the
    /// sampling weights, which take each texel's brightest neighbour, so an
    /// overestimate): how often photons leave the sky beside other lights.
    pub fn flux_estimate(&self) -> f32 {
        self.rows[self.height - 1] * 2.0 * PI * PI / (self.width * self.height) as f32
    }

    /// A direction sampled by `u`, and its density in solid angle.
    pub fn sample(&self, u: Vec2) -> Option<(Vec3, f32)> {
        self.sample_uv(u).map(|(_, dir, pdf)| (dir, pdf))
    }

    /// `sample`, with the point of the image the direction comes from (so
    /// that its radiance is read without turning the direction back).
    #[inline]
    pub fn sample_uv(&self, u: Vec2) -> Option<(Vec2, Vec3, f32)> {
        let (w, h) = (self.width, self.height);
        let total = self.rows[h - 1];
        let target = u.y * total;
        let y = self.rows.partition_point(|&c| c <= target).min(h - 1);
        let row_start = if y == 0 { 0.0 } else { self.rows[y - 1] };
        let row = &self.columns[y * w..(y + 1) * w];
        let row_total = row[w - 1];
        if !(row_total > 0.0) {
            return None;
        }
        // The rest of u.y, spread over the chosen row, places the point in
        // the texel's height.
        let fy = ((target - row_start) / (self.rows[y] - row_start)).clamp(0.0, 0.999_999);
        let target_x = u.x * row_total;
        // The sums rise along the row, so every column of the blocks before
        // the first block whose end exceeds the target is at most the
        // target: the same column as a search of the whole row.
        let ends = &self.block_ends[y * self.blocks..(y + 1) * self.blocks];
        let block = ends.partition_point(|&c| c <= target_x).min(self.blocks - 1);
        let first = block * BLOCK;
        let x = (first + row[first..(first + BLOCK).min(w)].partition_point(|&c| c <= target_x)).min(w - 1);
        let col_start = if x == 0 { 0.0 } else { row[x - 1] };
        let fx = ((target_x - col_start) / (row[x] - col_start)).clamp(0.0, 0.999_999);
        let uv = Vec2::new((x as f32 + fx) / w as f32, 1.0 - (y as f32 + fy) / h as f32);
        let dir = latlong_dir(uv);
        let pdf = self.pdf_at(x, y, dir);
        (pdf > 0.0 && pdf.is_finite() && dir.is_finite()).then_some((uv, dir, pdf))
    }

    /// The density in solid angle with which `sample` returns unit `dir`.
    pub fn pdf(&self, dir: Vec3) -> f32 {
        let uv = latlong_uv(dir);
        let x = ((uv.x.rem_euclid(1.0) * self.width as f32) as usize).min(self.width - 1);
        let y = (((1.0 - uv.y) * self.height as f32).max(0.0) as usize).min(self.height - 1);
        self.pdf_at(x, y, dir)
    }

    /// The density in solid angle of unit `dir` inside texel (x, y): the
    /// texel's share of the total weight, spread uniformly over its area
    /// in (u, v) as `sample` places points, over the Jacobian from (u, v)
    /// to directions, `2 pi^2 sin theta` with the direction's own theta.
    fn pdf_at(&self, x: usize, y: usize, dir: Vec3) -> f32 {
        let w = self.width;
        let row = &self.columns[y * w..(y + 1) * w];
        let weight = row[x] - if x == 0 { 0.0 } else { row[x - 1] };
        let sin_theta = (1.0 - dir.y * dir.y).max(0.0).sqrt();
        if !(weight > 0.0 && sin_theta > 0.0) {
            return 0.0;
        }
        let share = weight / self.rows[self.height - 1];
        share * (w * self.height) as f32 / (2.0 * PI * PI * sin_theta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_six_axis_directions_by_hand() {
        // 4 x 4 texels: the top row 100, the bottom row 200, the middle
        // rows 10 * row + column.
        let texels = (0..16)
            .map(|i| {
                let (x, y) = (i % 4, i / 4);
                Vec3::splat(match y {
                    0 => 100.0,
                    3 => 200.0,
                    _ => (10 * y + x) as f32,
                })
            })
            .collect();
        let env = Environment::new(Arc::new(Texture::new(4, 4, texels)), 2.0);
        let at = |d: Vec3| env.radiance(d).x / 2.0;
        // The horizon is v = 0.5, texel row 1.5: rows 1 and 2 equally.
        // -z: u = 0.5, column 1.5 -> (11 + 12 + 21 + 22) / 4.
        assert_eq!(at(-Vec3::Z), 16.5);
        // +x: u = 0.75, column 2.5 -> (12 + 13 + 22 + 23) / 4.
        assert_eq!(at(Vec3::X), 17.5);
        // -x: u = 0.25, column 0.5 -> (10 + 11 + 20 + 21) / 4.
        assert_eq!(at(-Vec3::X), 15.5);
        // +z: u = 1, column 3.5 -> columns 3 and 0 (around the seam).
        assert_eq!(at(Vec3::Z), 16.5);
        // Straight up and down: the top and bottom rows, clamped.
        assert_eq!(at(Vec3::Y), 100.0);
        assert_eq!(at(-Vec3::Y), 200.0);
        assert_eq!(latlong_uv(Vec3::X), Vec2::new(0.75, 0.5));
    }

    #[test]
    fn directions_and_uvs_round_trip() {
        for uv in [Vec2::new(0.1, 0.2), Vec2::new(0.75, 0.5), Vec2::new(0.4, 0.9)] {
            let back = latlong_uv(latlong_dir(uv));
            assert!((back - uv).length() < 1e-5, "{uv} -> {back}");
        }
    }

    #[test]
    fn sampled_densities_integrate_to_one_and_follow_brightness() {
        // 8 x 4 texels, one bright texel; the density integrates to 1 over
        // the sphere (a Riemann sum over directions), and samples land on
        // the bright texel or its neighbours most of the time.
        let mut texels = vec![Vec3::splat(0.1); 32];
        texels[8 + 3] = Vec3::splat(100.0);
        let light = EnvironmentLight::build(&Texture::new(8, 4, texels)).unwrap();
        let n = 400;
        let mut integral = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let (u, v) = ((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let dir = latlong_dir(Vec2::new(u, v));
                let d_omega = 2.0 * PI * PI * ((v - 0.5) * PI).cos() / (n * n) as f32;
                integral += (light.pdf(dir) * d_omega) as f64;
            }
        }
        assert!((integral - 1.0).abs() < 0.01, "{integral}");
        let (dir, pdf) = light.sample(Vec2::new(0.5, 0.5)).unwrap();
        assert!((light.pdf(dir) - pdf).abs() < 1e-3 * pdf);
        let bright = latlong_dir(Vec2::new(3.5 / 8.0, 1.0 - 1.5 / 4.0));
        assert!(light.pdf(bright) > 10.0 * light.pdf(-bright));
        // A black image lights nothing.
        assert!(EnvironmentLight::build(&Texture::new(2, 2, vec![Vec3::ZERO; 4])).is_none());
    }

    #[test]
    fn sampled_texels_come_up_as_often_as_their_density_says() {
        // 8 x 4 texels of different brightness: over a fine grid of u, the
        // fraction of samples landing in each texel is that texel's share
        // of the density, and each sample's pdf is what `pdf` says of its
        // direction.
        let texels = (0..32).map(|i| Vec3::splat(1.0 + (i * 7 % 11) as f32)).collect();
        let light = EnvironmentLight::build(&Texture::new(8, 4, texels)).unwrap();
        let n = 512;
        let mut counts = [0u32; 32];
        for i in 0..n {
            for j in 0..n {
                let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let (uv, dir, pdf) = light.sample_uv(u).unwrap();
                assert!((light.pdf(dir) - pdf).abs() <= 1e-3 * pdf, "{u}: {pdf} against {}", light.pdf(dir));
                assert!((latlong_uv(dir) - uv).length() < 1e-4);
                let (x, y) = ((uv.x * 8.0) as usize, ((1.0 - uv.y) * 4.0) as usize);
                counts[x.min(7) + 8 * y.min(3)] += 1;
            }
        }
        let total = light.rows[3];
        for (t, &c) in counts.iter().enumerate() {
            let row = &light.columns[(t / 8) * 8..(t / 8) * 8 + 8];
            let expected = (row[t % 8] - if t % 8 == 0 { 0.0 } else { row[t % 8 - 1] }) / total;
            let seen = c as f32 / (n * n) as f32;
            assert!((seen - expected).abs() < 0.002, "texel {t}: {seen} against {expected}");
        }
    }

    #[test]
    fn the_block_search_finds_the_column_a_whole_row_search_finds() {
        // 37 columns: two whole blocks of 16 and a short one of 5.
        let texels = (0..37 * 5).map(|i| Vec3::splat(((i * 7919) % 23) as f32)).collect();
        let light = EnvironmentLight::build(&Texture::new(37, 5, texels)).unwrap();
        for i in 0..2000 {
            let u = Vec2::new((i as f32 * 0.618_034).fract(), (i as f32 * 0.414_214).fract());
            let Some((uv, _, _)) = light.sample_uv(u) else { continue };
            let y = light.rows.partition_point(|&c| c <= u.y * light.rows[4]).min(4);
            let row = &light.columns[y * 37..(y + 1) * 37];
            let x = row.partition_point(|&c| c <= u.x * row[36]).min(36);
            assert_eq!((uv.x * 37.0) as usize, x, "u = {u}");
        }
    }
}
