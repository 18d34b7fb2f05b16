//! Display and export: exposure and sRGB encoding happen here, once; inside
//! the core everything is linear radiance. Files are written atomically
//! (a temporary file in the same directory, then a rename).

use crate::display::{DisplaySettings, Gamma, ToneMap};
use crate::math::{Radiance, Vec3};
use std::path::{Path, PathBuf};

/// sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1].
pub fn linear_to_srgb(c: f32) -> f32 {
    crate::display::transfer::srgb(c)
}

/// One pixel as displayed: exposure `d` (CGPP's display constant), clamp,
/// then sRGB encoding (or plain scaling when `gamma` is off), 8 bits.
pub fn display_pixel(c: Radiance, exposure: f32, gamma: bool) -> [u8; 3] {
    crate::display::display_rgb8(c, exposure, ToneMap::Standard, if gamma { Gamma::Srgb } else { Gamma::Off })
}

/// The whole image as 8-bit RGB, row-major.
pub fn to_rgb8(pixels: &[Radiance], exposure: f32, gamma: bool) -> Vec<u8> {
    pixels.iter().flat_map(|&c| display_pixel(c, exposure, gamma)).collect()
}

/// Writes `pixels` (width x height, linear) by the extension of `path`:
/// `.png` (sRGB 8-bit with exposure), `.exr` (linear f32), `.ppm` (ASCII, sRGB 8-bit).
pub fn save_image(path: &Path, width: u32, height: u32, pixels: &[Radiance], exposure: f32) -> Result<(), String> {
    save_image_displayed(path, width, height, pixels, exposure, &DisplaySettings::default())
}

/// As `save_image`, the 8-bit types through `display` (exposure in stops on
/// top of the linear `exposure`, tone map, transfer curve); `.exr` stays
/// linear, untouched by either.
pub fn save_image_displayed(path: &Path, width: u32, height: u32, pixels: &[Radiance], exposure: f32, display: &DisplaySettings) -> Result<(), String> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
    let rgb8 = || crate::display::image_rgb8(pixels, display.scale(exposure), display.tonemap, display.gamma);
    let bytes = match ext.as_str() {
        "png" => encode_png(width, height, &rgb8())?,
        "exr" => encode_exr(width, height, pixels)?,
        "ppm" => encode_ppm(width, height, &rgb8()),
        _ => return Err(format!("{}: unknown image type (use .png, .exr or .ppm)", path.display())),
    };
    write_atomic(path, &bytes)
}

pub fn encode_png(width: u32, height: u32, rgb8: &[u8]) -> Result<Vec<u8>, String> {
    let img = image::RgbImage::from_raw(width, height, rgb8.to_vec()).ok_or("image buffer has the wrong size")?;
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).map_err(|e| format!("cannot encode PNG: {e}"))?;
    Ok(out.into_inner())
}

fn encode_exr(width: u32, height: u32, pixels: &[Radiance]) -> Result<Vec<u8>, String> {
    let data: Vec<f32> = pixels.iter().flat_map(|c| [c.x, c.y, c.z]).collect();
    let img = image::Rgb32FImage::from_raw(width, height, data).ok_or("image buffer has the wrong size")?;
    let mut out = std::io::Cursor::new(Vec::new());
    image::DynamicImage::ImageRgb32F(img)
        .write_to(&mut out, image::ImageFormat::OpenExr)
        .map_err(|e| format!("cannot encode EXR: {e}"))?;
    Ok(out.into_inner())
}

/// A single-part EXR of f32 channels: the image as `R`, `G`, `B` and, beside
/// it, `extra` named channels (`layer.channel`, e.g. `normal.X`: readers
/// such as tev and OpenImageIO group them into layers by the prefix), each
/// `width * height` values, row-major.
pub fn encode_layered_exr(width: u32, height: u32, pixels: &[Radiance], extra: &[(String, Vec<f32>)]) -> Result<Vec<u8>, String> {
    use exr::prelude::*;
    let n = width as usize * height as usize;
    if pixels.len() != n || extra.iter().any(|(_, v)| v.len() != n) || n == 0 {
        return Err(format!("a layered EXR of {width}x{height} pixels was given layers of other sizes"));
    }
    let mut channels: Vec<AnyChannel<FlatSamples>> = ["R", "G", "B"]
        .iter()
        .enumerate()
        .map(|(k, name)| AnyChannel::new(*name, FlatSamples::F32(pixels.iter().map(|c| c[k]).collect())))
        .collect();
    for (name, values) in extra {
        let text = Text::new_or_none(name.as_str()).ok_or_else(|| format!("\"{name}\" cannot name an EXR channel"))?;
        channels.push(AnyChannel::new(text, FlatSamples::F32(values.clone())));
    }
    let mut attributes = LayerAttributes::named("");
    attributes.software_name = Some(Text::new_or_panic(format!("pinhole {}", env!("CARGO_PKG_VERSION"))));
    let layer = Layer::new((width as usize, height as usize), attributes, Encoding::SMALL_LOSSLESS, AnyChannels::sort(channels.into()));
    let mut out = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer).write().to_buffered(&mut out).map_err(|e| format!("cannot encode the layered EXR: {e}"))?;
    Ok(out.into_inner())
}

fn encode_ppm(width: u32, height: u32, rgb8: &[u8]) -> Vec<u8> {
    // Plain (ASCII) PPM, as CGPP listing 15.6 writes it.
    let mut s = format!("P3\n{width} {height}\n255\n");
    for row in rgb8.chunks(width as usize * 3) {
        let line: Vec<String> = row.iter().map(|v| v.to_string()).collect();
        s.push_str(&line.join(" "));
        s.push('\n');
    }
    s.into_bytes()
}

/// Writes a file so that readers never see it half-written.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), String> {
    write_all_atomic(&[(path, bytes)])
}

/// Writes several files, all or none: every file goes to a temporary name
/// beside its target first, and only when all of them are written are they
/// renamed into place. A failure removes the temporary files.
///
/// A symlink is written through: its target is replaced and the link stays.
/// A special file (`/dev/null`, a terminal, a FIFO) is written into
/// directly, never replaced by a regular file.
pub fn write_all_atomic(files: &[(&Path, &[u8])]) -> Result<(), String> {
    let mut temps = Vec::new();
    let cleanup = |temps: &[PathBuf]| {
        for t in temps {
            let _ = std::fs::remove_file(t);
        }
    };
    let mut renames = Vec::new();
    let mut direct = Vec::new();
    for (path, bytes) in files {
        let target = match output_target(path) {
            Ok(t) => t,
            Err(e) => {
                cleanup(&temps);
                return Err(e);
            }
        };
        if let OutputTarget::Special(t) = target {
            direct.push((*path, t, *bytes));
            continue;
        }
        let OutputTarget::Regular(target) = target else { unreachable!() };
        let dir = target.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        let Some(name) = target.file_name() else {
            cleanup(&temps);
            return Err(format!("{}: not a file name", path.display()));
        };
        let tmp = dir.join(format!(".{}.{}.tmp", name.to_string_lossy(), std::process::id()));
        temps.push(tmp.clone());
        if let Err(e) = std::fs::write(&tmp, bytes) {
            cleanup(&temps);
            return Err(format!("cannot write {}: {e}", path.display()));
        }
        renames.push((*path, target));
    }
    for (i, ((path, target), tmp)) in renames.iter().zip(&temps).enumerate() {
        if let Err(e) = std::fs::rename(tmp, target) {
            cleanup(&temps[i..]);
            return Err(format!("cannot write {}: {e}", path.display()));
        }
    }
    for (path, target, bytes) in direct {
        use std::io::Write;
        let written = std::fs::OpenOptions::new().write(true).open(&target).and_then(|mut f| f.write_all(bytes));
        if let Err(e) = written {
            return Err(format!("cannot write {}: {e}", path.display()));
        }
    }
    Ok(())
}

/// Where writing `path` really goes.
enum OutputTarget {
    /// A regular file (or nothing yet) at this path: replaced by rename.
    Regular(PathBuf),
    /// A device or FIFO at this path: written into.
    Special(PathBuf),
}

/// Follows symlinks (even one pointing at a file not made yet) and tells a
/// regular destination from a special file; a directory is an error.
fn output_target(path: &Path) -> Result<OutputTarget, String> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => Err(format!("cannot write {}: it is a directory", path.display())),
        // Opening follows every link, including /proc's (`/dev/stdout`).
        Ok(m) if !m.is_file() => Ok(OutputTarget::Special(path.to_path_buf())),
        // `/dev/stdout` redirected to a file: written into, so the shell's
        // open file gets the bytes (a rename would leave it empty).
        Ok(_) if path.starts_with("/dev") || path.starts_with("/proc") => Ok(OutputTarget::Special(path.to_path_buf())),
        Ok(_) => Ok(OutputTarget::Regular(std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()))),
        Err(_) => {
            // Nothing there yet, or a link to a file not made yet: the file is
            // created where the last link points. Links are followed a bounded
            // number of times, as the kernel bounds them.
            let mut target = path.to_path_buf();
            for _ in 0..40 {
                match std::fs::symlink_metadata(&target) {
                    Ok(m) if m.file_type().is_symlink() => {
                        let link = std::fs::read_link(&target).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
                        let base = target.parent().map(Path::to_path_buf).unwrap_or_default();
                        target = base.join(link);
                    }
                    _ => return Ok(OutputTarget::Regular(target)),
                }
            }
            Err(format!("cannot write {}: too many levels of symbolic links", path.display()))
        }
    }
}

/// Checks, before any work, that `path` can be written: it is not a
/// directory, and its directory exists and lets us create a file (tried
/// with a temporary file that is removed at once). A special file is
/// checked by opening it for writing, except a FIFO, which would block.
pub fn check_writable(path: &Path) -> Result<(), String> {
    match output_target(path)? {
        OutputTarget::Special(t) => {
            use std::os::unix::fs::FileTypeExt;
            let fifo = std::fs::metadata(&t).map(|m| m.file_type().is_fifo() || m.file_type().is_socket()).unwrap_or(false);
            if !fifo {
                std::fs::OpenOptions::new().write(true).open(&t).map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            }
            Ok(())
        }
        OutputTarget::Regular(t) => {
            let dir = t.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
            let name = t.file_name().ok_or(format!("{}: not a file name", path.display()))?;
            let probe = dir.join(format!(".{}.{}.check", name.to_string_lossy(), std::process::id()));
            match std::fs::OpenOptions::new().write(true).create_new(true).open(&probe) {
                Ok(_) => {
                    let _ = std::fs::remove_file(&probe);
                    Ok(())
                }
                Err(e) => Err(format!("cannot write {}: {e}", path.display())),
            }
        }
    }
}

/// A loaded image in linear radiance, for `compare` and the reference tests.
pub struct LinearImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<Radiance>,
}

/// Reads `.exr` as linear values and `.png`/`.ppm` as sRGB-encoded 8-bit (decoded
/// to linear), through the bounded reader and with the declared size checked first.
pub fn load_image(path: &Path) -> Result<LinearImage, String> {
    let bytes = crate::input::read_file(path, crate::input::InputKind::Image).map_err(|e| format!("cannot read image {e}"))?;
    let img = crate::input::decode_image(&bytes, &path.display().to_string()).map_err(|e| format!("cannot read image {e}"))?;
    drop(bytes);
    let is_float = matches!(img, image::DynamicImage::ImageRgb32F(_) | image::DynamicImage::ImageRgba32F(_));
    // Consumed, not copied: a float RGB image is taken over as it is.
    let rgb = img.into_rgb32f();
    let (width, height) = rgb.dimensions();
    let decode = |v: f32| if is_float { v } else if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) };
    let pixels = rgb.into_raw().chunks_exact(3).map(|p| Vec3::new(decode(p[0]), decode(p[1]), decode(p[2]))).collect();
    Ok(LinearImage { width, height, pixels })
}

#[cfg(test)]
mod tests {

    #[test]
    fn several_files_are_written_all_or_none() {
        let d = std::env::temp_dir().join(format!("pinhole-all-or-none-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        let (a, b) = (d.join("a.png"), d.join("missing-dir").join("a.csv"));
        std::fs::write(&a, b"old").unwrap();
        let e = write_all_atomic(&[(&a, b"new png"), (&b, b"csv")]).unwrap_err();
        assert!(e.contains("a.csv"), "{e}");
        assert_eq!(std::fs::read(&a).unwrap(), b"old", "the first file stays as it was");
        let left: Vec<_> = std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(left.len(), 1, "temporary files are removed: {left:?}");
        let c = d.join("a.csv");
        write_all_atomic(&[(&a, b"new png"), (&c, b"csv")]).unwrap();
        assert_eq!((std::fs::read(&a).unwrap(), std::fs::read(&c).unwrap()), (b"new png".to_vec(), b"csv".to_vec()));
        let _ = std::fs::remove_dir_all(&d);
    }

    use super::*;

    #[test]
    fn symlinks_and_special_files_are_written_through() {
        let d = std::env::temp_dir().join(format!("pinhole-through-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        let (real, link) = (d.join("real.json"), d.join("link.json"));
        std::fs::write(&real, b"old").unwrap();
        std::os::unix::fs::symlink("real.json", &link).unwrap();
        write_atomic(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink(), "the link stays a link");
        assert_eq!(std::fs::read(&real).unwrap(), b"new");
        // A link to a file not made yet makes the file where it points.
        let (dangling, later) = (d.join("dangling.json"), d.join("later.json"));
        std::os::unix::fs::symlink("later.json", &dangling).unwrap();
        write_atomic(&dangling, b"made").unwrap();
        assert!(std::fs::symlink_metadata(&dangling).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read(&later).unwrap(), b"made");
        // A character device is written into, not replaced by a regular file.
        write_atomic(Path::new("/dev/null"), b"x").unwrap();
        assert!(!std::fs::metadata("/dev/null").unwrap().is_file());
        check_writable(Path::new("/dev/null")).unwrap();
        // A full device fails with a sentence naming it.
        let e = write_atomic(Path::new("/dev/full"), b"x").unwrap_err();
        assert!(e.contains("/dev/full"), "{e}");
        assert!(check_writable(&d).unwrap_err().contains("directory"));
        assert!(check_writable(&d.join("missing").join("a.png")).is_err());
        assert!(check_writable(&d.join("a.png")).is_ok());
        let left: Vec<_> = std::fs::read_dir(&d).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(left.len(), 4, "no probe or temporary files left: {left:?}");
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn srgb_known_values() {
        assert_eq!(display_pixel(Vec3::ZERO, 1.0, true), [0, 0, 0]);
        assert_eq!(display_pixel(Vec3::ONE, 1.0, true), [255, 255, 255]);
        // Linear 0.5 encodes to about 0.7354 -> 188.
        assert_eq!(display_pixel(Vec3::splat(0.5), 1.0, true), [188, 188, 188]);
        assert_eq!(display_pixel(Vec3::splat(0.5), 1.0, false), [128, 128, 128]);
        // Exposure scales before encoding; NaN never reaches a pixel.
        assert_eq!(display_pixel(Vec3::splat(0.25), 2.0, true), [188, 188, 188]);
        assert_eq!(display_pixel(Vec3::new(f32::NAN, 2.0, -1.0), 1.0, true), [0, 255, 0]);
    }

    #[test]
    fn exr_round_trips_linear_values() {
        let dir = std::env::temp_dir().join(format!("pinhole-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let px = vec![Vec3::new(0.1, 2.5, 100.0), Vec3::new(0.0, 1e-3, 7.0)];
        let path = dir.join("a.exr");
        save_image(&path, 2, 1, &px, 1.0).unwrap();
        let back = load_image(&path).unwrap();
        assert_eq!(back.pixels, px);
        let ppm = dir.join("a.ppm");
        save_image(&ppm, 2, 1, &px, 1.0).unwrap();
        assert!(std::fs::read_to_string(&ppm).unwrap().starts_with("P3\n2 1\n255\n"));
        assert!(save_image(&dir.join("a.gif"), 2, 1, &px, 1.0).unwrap_err().contains("unknown image type"));
    }
}
