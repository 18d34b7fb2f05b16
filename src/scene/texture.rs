//! Textures: image files decoded into linear RGB, with a mip pyramid built
//! once at load time, sampled nearest, bilinear, from the nearest mip level,
//! trilinear or anisotropically (Computer Graphics from Scratch ch. 14).

use crate::scene::assets::read_asset;
use crate::input::{decode_image, InputKind, MAX_VALUE};
use crate::math::{Vec2, Vec3};
use crate::named::named_enum;
use std::path::Path;

named_enum! {
    /// How a texture is read at a sample.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum TextureFilter ("texture filter") {
        /// The one texel of level 0 the sample falls in.
        Nearest = "nearest",
        /// The four nearest texels of level 0, blended by distance.
        Bilinear = "bilinear",
        /// Bilinear in the one mip level whose texels are nearest the
        /// sample's footprint in size (GL's LINEAR_MIPMAP_NEAREST): no
        /// blend, so the level's seams show where the level changes.
        MipmapNearest = "mipmap-nearest",
        /// Bilinear in the two mip levels whose texels are nearest the
        /// sample's footprint in size, blended by the level of detail.
        #[default]
        Trilinear = "trilinear",
        /// Up to 2 trilinear taps spread along the footprint's longer
        /// axis, each read at the level of its share of that axis.
        Anisotropic2 = "anisotropic:2",
        /// Up to 4 taps (see `Anisotropic2`).
        Anisotropic4 = "anisotropic:4",
        /// Up to 8 taps (see `Anisotropic2`).
        Anisotropic8 = "anisotropic:8",
        /// Up to 16 taps (see `Anisotropic2`), as many as GPUs offer.
        Anisotropic16 = "anisotropic:16",
    }
}

named_enum! {
    /// Texture addressing outside [0, 1]: tile, hold the edge texel, or
    /// tile with every other copy mirrored.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub enum Wrap ("wrap mode") {
        #[default]
        Repeat = "repeat",
        Clamp = "clamp",
        MirroredRepeat = "mirrored-repeat",
    }
}

/// One level of the pyramid: `width x height` linear texels, row 0 at the top.
#[derive(Debug, PartialEq)]
pub struct MipLevel {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<Vec3>,
}

/// A linear-RGB texture and its mip pyramid: `levels[0]` is the image,
/// each next level half the size (rounded down, at least 1) down to 1 x 1.
#[derive(Debug, PartialEq)]
pub struct Texture {
    pub levels: Vec<MipLevel>,
}

/// How much of the texture one pixel covers: the uv derivatives along the
/// image's x and y (already scaled by the material's `uv_scale`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Footprint {
    pub duv_dx: Vec2,
    pub duv_dy: Vec2,
}

impl TextureFilter {
    /// This filter, or `finest` when that reads fewer texels (a texture's
    /// sampler may ask for nearest or unmipmapped reads).
    #[inline]
    pub fn at_most(self, finest: TextureFilter) -> TextureFilter {
        // A sampler that allows mipmapping (trilinear) allows the
        // anisotropic reads too: they read the same pyramid.
        let rank = |f: TextureFilter| match f {
            TextureFilter::Nearest => 0,
            TextureFilter::Bilinear => 1,
            TextureFilter::MipmapNearest => 2,
            _ => 3,
        };
        if rank(finest) < rank(self) { finest } else { self }
    }

    /// The most taps an anisotropic read takes (1 for the other filters).
    pub fn anisotropic_taps(self) -> u32 {
        match self {
            TextureFilter::Anisotropic2 => 2,
            TextureFilter::Anisotropic4 => 4,
            TextureFilter::Anisotropic8 => 8,
            TextureFilter::Anisotropic16 => 16,
            _ => 1,
        }
    }
}

impl MipLevel {

    /// Texel `(x, y)` with the columns addressed by `wrap_u`, the rows by `wrap_v`.
    #[inline]
    fn texel_uv(&self, x: i64, y: i64, wrap_u: Wrap, wrap_v: Wrap) -> Vec3 {
        let address = |i: i64, n: i64, wrap: Wrap| match wrap {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::MirroredRepeat => {
                let m = i.rem_euclid(2 * n);
                if m < n { m } else { 2 * n - 1 - m }
            }
        };
        let (x, y) = (address(x, self.width as i64, wrap_u), address(y, self.height as i64, wrap_v));
        self.texels[(x + y * self.width as i64) as usize]
    }

    /// Texel-space position of `uv` (texel centres at +0.5; v = 0 is the
    /// bottom row, the OBJ convention); `None` when not finite.
    #[inline]
    fn position(&self, uv: Vec2) -> Option<(f32, f32)> {
        let x = uv.x * self.width as f32;
        let y = (1.0 - uv.y) * self.height as f32;
        // Far outside the texture the integer conversion below would saturate.
        (x.is_finite() && y.is_finite() && x.abs() < 1e9 && y.abs() < 1e9).then_some((x, y))
    }

    /// The texel `uv` falls in, columns addressed by `wrap[0]`, rows by `wrap[1]`.
    pub fn nearest(&self, uv: Vec2, wrap: [Wrap; 2]) -> Vec3 {
        match self.position(uv) {
            Some((x, y)) => self.texel_uv(x.floor() as i64, y.floor() as i64, wrap[0], wrap[1]),
            None => Vec3::ZERO,
        }
    }

    pub fn bilinear(&self, uv: Vec2, wrap: [Wrap; 2]) -> Vec3 {
        self.bilinear_uv(uv, wrap[0], wrap[1])
    }

    /// `bilinear` with separate addressing of columns and rows (a
    /// latitude-longitude map repeats around and clamps at the poles).
    pub fn bilinear_uv(&self, uv: Vec2, wrap_u: Wrap, wrap_v: Wrap) -> Vec3 {
        let Some((x, y)) = self.position(uv) else { return Vec3::ZERO };
        let (x, y) = (x - 0.5, y - 0.5);
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let (xi, yi) = (x0 as i64, y0 as i64);
        let t = |x, y| self.texel_uv(x, y, wrap_u, wrap_v);
        let top = t(xi, yi).lerp(t(xi + 1, yi), fx);
        let bottom = t(xi, yi + 1).lerp(t(xi + 1, yi + 1), fx);
        top.lerp(bottom, fy)
    }

    /// The next level: half the size (rounded down, at least 1); each texel
    /// the plain average of the 2 x 2 texels it covers in linear space (on
    /// an odd side the last texel takes the leftover row or column too, so
    /// every texel counts).
    fn halved(&self) -> MipLevel {
        let (w, h) = ((self.width / 2).max(1), (self.height / 2).max(1));
        let span = |i: u32, n: u32, src: u32| -> (u32, u32) {
            let start = (2 * i).min(src - 1);
            let end = if i + 1 == n { src } else { (2 * i + 2).min(src) };
            (start, end)
        };
        let mut texels = Vec::with_capacity(w as usize * h as usize);
        for y in 0..h {
            let (y0, y1) = span(y, h, self.height);
            for x in 0..w {
                let (x0, x1) = span(x, w, self.width);
                let mut sum = Vec3::ZERO;
                for sy in y0..y1 {
                    for sx in x0..x1 {
                        sum += self.texels[(sx + sy * self.width) as usize];
                    }
                }
                texels.push(sum / ((x1 - x0) * (y1 - y0)) as f32);
            }
        }
        MipLevel { width: w, height: h, texels }
    }
}

impl Texture {
    /// A texture from level 0, its pyramid built here.
    pub fn new(width: u32, height: u32, texels: Vec<Vec3>) -> Texture {
        assert_eq!(texels.len(), width as usize * height as usize);
        let mut levels = vec![MipLevel { width, height, texels }];
        loop {
            let last = levels.last().unwrap();
            if last.width == 1 && last.height == 1 {
                break;
            }
            let next = last.halved();
            levels.push(next);
        }
        Texture { levels }
    }

    pub fn width(&self) -> u32 {
        self.levels[0].width
    }

    pub fn height(&self) -> u32 {
        self.levels[0].height
    }

    /// The level of detail of a footprint (OpenGL's lambda): log2 of the
    /// longer of the two pixel steps measured in level-0 texels, clamped
    /// to the pyramid. 0 when a pixel step is at most one texel.
    pub fn level_of_detail(&self, f: &Footprint) -> f32 {
        let size = Vec2::new(self.width() as f32, self.height() as f32);
        let (along_x, along_y) = ((f.duv_dx * size).length(), (f.duv_dy * size).length());
        if along_x.is_nan() || along_y.is_nan() {
            return (self.levels.len() - 1) as f32;
        }
        self.level_of_step(along_x.max(along_y))
    }

    /// The level of detail of a pixel step `rho` level-0 texels long.
    fn level_of_step(&self, rho: f32) -> f32 {
        let top = (self.levels.len() - 1) as f32;
        if rho.is_nan() {
            return top;
        }
        if rho <= 1.0 {
            return 0.0;
        }
        rho.log2().min(top)
    }

    /// The one level GL's MIPMAP_NEAREST reads at level of detail `lambda`:
    /// the nearest, level 0 up to 0.5.
    fn nearest_level(&self, lambda: f32) -> usize {
        if lambda <= 0.5 { 0 } else { ((lambda + 0.5).ceil() as usize - 1).min(self.levels.len() - 1) }
    }

    /// Bilinear reads of the two levels around `lambda`, blended.
    fn trilinear(&self, uv: Vec2, lambda: f32, wrap: [Wrap; 2]) -> Vec3 {
        let base = lambda.floor();
        let fine = &self.levels[base as usize];
        let blend = lambda - base;
        if blend == 0.0 {
            fine.bilinear(uv, wrap)
        } else {
            let coarse = &self.levels[(base as usize + 1).min(self.levels.len() - 1)];
            fine.bilinear(uv, wrap).lerp(coarse.bilinear(uv, wrap), blend)
        }
    }

    /// The taps and level of detail of an anisotropic read of at most
    /// `max_taps` taps: a footprint n times longer than wide takes n taps
    /// (at most `max_taps`) along its longer axis, each covering 1/n of it,
    /// so each is read at the level of the longer of that share and the
    /// footprint's width, where trilinear reads the whole length at once
    /// and blurs across the width. `None` when one trilinear read is the
    /// same (a round footprint, or an unknown one).
    fn anisotropic_taps(&self, f: &Footprint, max_taps: u32) -> Option<(Vec2, u32, f32)> {
        let size = Vec2::new(self.width() as f32, self.height() as f32);
        let (along_x, along_y) = ((f.duv_dx * size).length(), (f.duv_dy * size).length());
        if !(along_x.is_finite() && along_y.is_finite()) {
            return None;
        }
        let (major_uv, major, minor) = if along_x >= along_y { (f.duv_dx, along_x, along_y) } else { (f.duv_dy, along_y, along_x) };
        let taps = (major / minor.max(1e-12)).ceil().min(max_taps as f32) as u32;
        (taps > 1).then(|| (major_uv, taps, self.level_of_step((major / taps as f32).max(minor))))
    }

    /// The anisotropic read (see `anisotropic_taps`): the mean of its taps,
    /// spread evenly over the footprint's longer axis about `uv`.
    fn anisotropic(&self, uv: Vec2, f: &Footprint, max_taps: u32, wrap: [Wrap; 2]) -> Vec3 {
        let Some((axis, taps, lambda)) = self.anisotropic_taps(f, max_taps) else {
            return self.trilinear(uv, self.level_of_detail(f), wrap);
        };
        let mut sum = Vec3::ZERO;
        for k in 0..taps {
            let offset = (k as f32 + 0.5) / taps as f32 - 0.5;
            sum += self.trilinear(uv + axis * offset, lambda, wrap);
        }
        sum / taps as f32
    }

    /// The texture at `uv` with footprint `f`, read with `filter`; `wrap`
    /// addresses u (columns) and v (rows) outside [0, 1].
    pub fn sample(&self, uv: Vec2, f: &Footprint, filter: TextureFilter, wrap: [Wrap; 2]) -> Vec3 {
        match filter {
            TextureFilter::Nearest => self.levels[0].nearest(uv, wrap),
            TextureFilter::Bilinear => self.levels[0].bilinear(uv, wrap),
            TextureFilter::MipmapNearest => self.levels[self.nearest_level(self.level_of_detail(f))].bilinear(uv, wrap),
            TextureFilter::Trilinear => self.trilinear(uv, self.level_of_detail(f), wrap),
            TextureFilter::Anisotropic2 | TextureFilter::Anisotropic4 | TextureFilter::Anisotropic8 | TextureFilter::Anisotropic16 => {
                self.anisotropic(uv, f, filter.anisotropic_taps(), wrap)
            }
        }
    }

    /// The mip level `sample` reads with `filter` (0 for the single-level filters).
    pub fn level_used(&self, f: &Footprint, filter: TextureFilter) -> f32 {
        match filter {
            TextureFilter::Trilinear => self.level_of_detail(f),
            TextureFilter::MipmapNearest => self.nearest_level(self.level_of_detail(f)) as f32,
            TextureFilter::Anisotropic2 | TextureFilter::Anisotropic4 | TextureFilter::Anisotropic8 | TextureFilter::Anisotropic16 => {
                self.anisotropic_taps(f, filter.anisotropic_taps()).map_or_else(|| self.level_of_detail(f), |(_, _, lambda)| lambda)
            }
            TextureFilter::Nearest | TextureFilter::Bilinear => 0.0,
        }
    }
}

/// How a texture's 8-bit values are turned into numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    /// Colours: sRGB-decoded to linear radiance factors.
    Srgb,
    /// Data (normal maps): the stored value itself, 0..1.
    Linear,
}

/// Loads an 8-bit sRGB image (or a float EXR/HDR) into a linear texture and
/// builds its pyramid. A float texel that is NaN, infinite, negative or
/// above `MAX_VALUE` is an error naming the texel: such a value would reach
/// pixels through every sample.
pub fn load_texture(path: &Path) -> Result<Texture, String> {
    load_texture_as(path, Encoding::Srgb)
}

/// `load_texture` with the 8-bit values read as `encoding` says.
pub fn load_texture_as(path: &Path, encoding: Encoding) -> Result<Texture, String> {
    let bytes = read_asset(path, InputKind::Image).map_err(|e| format!("cannot read {e}"))?;
    decode_texture(bytes, &path.display().to_string(), encoding)
}

/// An image file's bytes as a texture (see `load_texture`); `name` names
/// the image in messages.
pub fn decode_texture(bytes: Vec<u8>, name: &str, encoding: Encoding) -> Result<Texture, String> {
    let img = decode_image(&bytes, name)?;
    drop(bytes);
    let is_float = matches!(img, image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_));
    let rgb = img.into_rgb32f();
    let mut texels = Vec::with_capacity(rgb.width() as usize * rgb.height() as usize);
    for (x, y, p) in rgb.enumerate_pixels() {
        let c = Vec3::new(p[0], p[1], p[2]);
        if is_float {
            if let Some(bad) = c.to_array().into_iter().find(|v| !(v.is_finite() && (0.0..=MAX_VALUE).contains(v))) {
                return Err(format!("{name}: texel ({x}, {y}) is {bad}; texels must be finite numbers from 0 to {MAX_VALUE:e}"));
            }
            texels.push(c);
        } else if encoding == Encoding::Srgb {
            texels.push(Vec3::new(srgb_to_linear(c.x), srgb_to_linear(c.y), srgb_to_linear(c.z)));
        } else {
            texels.push(c);
        }
    }
    Ok(Texture::new(rgb.width(), rgb.height(), texels))
}

/// The alpha channel of an image file's bytes as a texture (alpha in
/// every channel, linear as glTF defines it), or `None` when the image has
/// no alpha channel (opaque everywhere). `name` names the image in messages.
pub fn decode_alpha(bytes: &[u8], name: &str) -> Result<Option<Texture>, String> {
    let img = decode_image(bytes, name)?;
    if !img.color().has_alpha() {
        return Ok(None);
    }
    let rgba = img.into_rgba32f();
    let texels = rgba.pixels().map(|p| Vec3::splat(if p[3].is_finite() { p[3].clamp(0.0, 1.0) } else { 1.0 })).collect();
    Ok(Some(Texture::new(rgba.width(), rgba.height(), texels)))
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mipmap_nearest_and_anisotropic_levels_by_hand() {
        // 64 x 64 texels: levels 0..=6.
        let t = Texture::new(64, 64, vec![Vec3::ONE; 64 * 64]);
        // GL's MIPMAP_NEAREST: level 0 up to lambda 0.5, then the nearest.
        for (lambda, level) in [(0.0, 0), (0.4, 0), (0.6, 1), (1.4, 1), (1.6, 2), (9.0, 6)] {
            assert_eq!(t.nearest_level(lambda), level, "lambda {lambda}");
        }
        // A footprint 8 texels along u and 1 along v: 8 taps of one texel
        // each read level 0; with at most 4 taps each covers 2 texels,
        // level 1; trilinear reads the whole length, level 3.
        let f = Footprint { duv_dx: Vec2::new(8.0 / 64.0, 0.0), duv_dy: Vec2::new(0.0, 1.0 / 64.0) };
        assert_eq!(t.anisotropic_taps(&f, 16), Some((f.duv_dx, 8, 0.0)));
        assert_eq!(t.anisotropic_taps(&f, 4), Some((f.duv_dx, 4, 1.0)));
        assert_eq!(t.level_of_detail(&f), 3.0);
        // A round footprint takes one trilinear read.
        let round = Footprint { duv_dx: Vec2::new(4.0 / 64.0, 0.0), duv_dy: Vec2::new(0.0, 4.0 / 64.0) };
        assert_eq!(t.anisotropic_taps(&round, 16), None);
        // Anisotropic reads stay within a sampler that allows mipmaps, and
        // drop to what one that does not allows.
        assert_eq!(TextureFilter::Anisotropic8.at_most(TextureFilter::Trilinear), TextureFilter::Anisotropic8);
        assert_eq!(TextureFilter::Anisotropic8.at_most(TextureFilter::Bilinear), TextureFilter::Bilinear);
    }

    fn grey(values: &[f32]) -> Vec<Vec3> {
        values.iter().map(|&v| Vec3::splat(v)).collect()
    }

    #[test]
    fn a_4x4_pyramid_by_hand() {
        #[rustfmt::skip]
        let t = Texture::new(4, 4, grey(&[
            0.0, 1.0,  2.0, 3.0,
            4.0, 5.0,  6.0, 7.0,
            8.0, 9.0,  10.0, 11.0,
            12.0, 13.0, 14.0, 15.0,
        ]));
        assert_eq!(t.levels.len(), 3);
        // Level 1: each texel the mean of a 2 x 2 block.
        assert_eq!((t.levels[1].width, t.levels[1].height), (2, 2));
        assert_eq!(t.levels[1].texels, grey(&[2.5, 4.5, 10.5, 12.5]));
        // Level 2: the mean of everything.
        assert_eq!(t.levels[2].texels, grey(&[7.5]));
    }

    #[test]
    fn odd_sides_keep_every_texel() {
        let t = Texture::new(3, 1, grey(&[1.0, 2.0, 6.0]));
        assert_eq!(t.levels.len(), 2);
        assert_eq!(t.levels[1].texels, grey(&[3.0]));
    }

    #[test]
    fn level_of_detail_for_known_footprints() {
        let t = Texture::new(256, 256, vec![Vec3::ONE; 256 * 256]);
        let f = |dx: Vec2, dy: Vec2| Footprint { duv_dx: dx, duv_dy: dy };
        // One pixel step spans 4 texels along u: level 2.
        assert_eq!(t.level_of_detail(&f(Vec2::new(4.0 / 256.0, 0.0), Vec2::new(0.0, 1.0 / 256.0))), 2.0);
        // The longer step decides: 16 texels along v -> level 4.
        assert_eq!(t.level_of_detail(&f(Vec2::new(1.0 / 256.0, 0.0), Vec2::new(0.0, 16.0 / 256.0))), 4.0);
        // A diagonal step of (3, 4) texels is 5 texels long.
        assert!((t.level_of_detail(&f(Vec2::new(3.0 / 256.0, 4.0 / 256.0), Vec2::ZERO)) - 5f32.log2()).abs() < 1e-6);
        // Magnified: level 0; enormous: the 1 x 1 level; NaN: the coarsest.
        assert_eq!(t.level_of_detail(&f(Vec2::new(0.1 / 256.0, 0.0), Vec2::ZERO)), 0.0);
        assert_eq!(t.level_of_detail(&f(Vec2::new(1e6, 0.0), Vec2::ZERO)), 8.0);
        assert_eq!(t.level_of_detail(&f(Vec2::new(f32::NAN, 0.0), Vec2::ZERO)), 8.0);
    }

    #[test]
    fn filters_and_wrap_by_hand() {
        let t = Texture::new(2, 1, grey(&[0.0, 1.0]));
        let none = Footprint::default();
        // Texel centres are at u = 0.25 and 0.75.
        assert_eq!(t.sample(Vec2::new(0.3, 0.5), &none, TextureFilter::Nearest, [Wrap::Repeat; 2]), Vec3::ZERO);
        assert_eq!(t.sample(Vec2::new(0.5, 0.5), &none, TextureFilter::Bilinear, [Wrap::Repeat; 2]), Vec3::splat(0.5));
        // Beyond the right edge: repeat blends towards texel 0, clamp holds texel 1.
        assert_eq!(t.sample(Vec2::new(1.0, 0.5), &none, TextureFilter::Bilinear, [Wrap::Repeat; 2]), Vec3::splat(0.5));
        assert_eq!(t.sample(Vec2::new(1.0, 0.5), &none, TextureFilter::Bilinear, [Wrap::Clamp; 2]), Vec3::ONE);
        assert_eq!(t.sample(Vec2::new(-3.9, 0.5), &none, TextureFilter::Nearest, [Wrap::Clamp; 2]), Vec3::ZERO);
        // Trilinear halfway between level 0 and the 1 x 1 level (0.5).
        let half = Footprint { duv_dx: Vec2::new(2f32.sqrt() / 2.0, 0.0), duv_dy: Vec2::ZERO };
        let v = t.sample(Vec2::new(0.75, 0.5), &half, TextureFilter::Trilinear, [Wrap::Repeat; 2]);
        assert!((v.x - 0.75).abs() < 1e-6, "{v}");
    }

    #[test]
    fn mirrored_repeat_and_wrap_per_axis_by_hand() {
        // Three texels 0, 1, 2 along u; one row.
        let t = Texture::new(3, 1, grey(&[0.0, 1.0, 2.0]));
        let none = Footprint::default();
        let at = |u: f32, wrap: [Wrap; 2]| t.sample(Vec2::new(u, 0.5), &none, TextureFilter::Nearest, wrap).x;
        let mirrored = [Wrap::MirroredRepeat, Wrap::Repeat];
        // Columns -3..6 of a mirrored row: 2 1 0 | 0 1 2 | 2 1 0.
        let columns: Vec<f32> = (-3..6).map(|c| at((c as f32 + 0.5) / 3.0, mirrored)).collect();
        assert_eq!(columns, vec![2.0, 1.0, 0.0, 0.0, 1.0, 2.0, 2.0, 1.0, 0.0]);
        // Beyond the right edge: repeat starts over, clamp holds, mirror turns back.
        assert_eq!(at(1.0 + 0.5 / 3.0, [Wrap::Repeat; 2]), 0.0);
        assert_eq!(at(1.0 + 0.5 / 3.0, [Wrap::Clamp; 2]), 2.0);
        assert_eq!(at(1.0 + 0.5 / 3.0, mirrored), 2.0);
        // Rows follow wrap[1] only: a column of texels 0 (top) and 1 (bottom).
        let c = Texture::new(1, 2, grey(&[0.0, 1.0]));
        let row = |v: f32, wrap: [Wrap; 2]| c.sample(Vec2::new(0.5, v), &none, TextureFilter::Nearest, wrap).x;
        // v = 1.25 is a quarter of a copy above the top: repeat reads the
        // bottom texel again, clamp the top one.
        assert_eq!(row(1.25, [Wrap::Clamp, Wrap::Repeat]), 1.0);
        assert_eq!(row(1.25, [Wrap::Repeat, Wrap::Clamp]), 0.0);
    }

    #[test]
    fn a_sampler_caps_the_filter() {
        use TextureFilter::*;
        assert_eq!(Trilinear.at_most(Nearest), Nearest);
        assert_eq!(Trilinear.at_most(Bilinear), Bilinear);
        assert_eq!(Nearest.at_most(Trilinear), Nearest);
        assert_eq!(Bilinear.at_most(Trilinear), Bilinear);
    }
}
