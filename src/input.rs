//! Bounds on everything that input controls, and the one reader for input
//! files. Every file pinhole reads (scene TOML, OBJ, MTL, textures, images to
//! compare) goes through `read_file`, which refuses what is not a regular
//! file (a FIFO would block forever, `/dev/zero` never ends) and what is
//! larger than its kind's limit, in one sentence naming the file. Images are
//! measured from their header before any pixel is decoded.

use std::io::Read;
use std::path::Path;

/// The kinds of input file, each with its own size limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum InputKind {
    Scene,
    Mesh,
    Mtl,
    Image,
}

/// Largest scene file (TOML): 16 MiB.
pub const MAX_SCENE_BYTES: u64 = 16 << 20;
/// Largest mesh file (OBJ, PLY): 512 MiB.
pub const MAX_MESH_BYTES: u64 = 512 << 20;
/// Largest MTL file: 16 MiB.
pub const MAX_MTL_BYTES: u64 = 16 << 20;
/// Largest image file (texture, reference, compare input): 256 MiB.
pub const MAX_IMAGE_BYTES: u64 = 256 << 20;
/// Longest side of an image read or written.
pub const MAX_IMAGE_SIDE: u32 = 16384;
/// Most pixels in an image read or rendered (32 Mi, e.g. 8192 x 4096 or
/// 5792 x 5792): one linear RGB copy of it takes 384 MiB, and decoding or
/// encoding holds a few copies at once.
pub const MAX_IMAGE_PIXELS: u64 = 1 << 25;

/// Largest coordinate (positions, vertices, sphere radius, translation) in
/// scene units: squares and cross products of coordinates stay far inside
/// f32, and intersections keep enough precision to hit.
pub const MAX_COORDINATE: f32 = 1e6;
/// Largest material term, texel, background, ambient, exposure or sharpness.
pub const MAX_VALUE: f32 = 1e6;
/// Largest light power or irradiance.
pub const MAX_LIGHT: f32 = 1e12;

impl InputKind {
    pub fn max_bytes(self) -> u64 {
        match self {
            InputKind::Scene => MAX_SCENE_BYTES,
            InputKind::Mesh => MAX_MESH_BYTES,
            InputKind::Mtl => MAX_MTL_BYTES,
            InputKind::Image => MAX_IMAGE_BYTES,
        }
    }

    fn noun(self) -> &'static str {
        match self {
            InputKind::Scene => "scene file",
            InputKind::Mesh => "mesh file",
            InputKind::Mtl => "MTL file",
            InputKind::Image => "image",
        }
    }
}

/// Reads a whole input file: only a regular file (symlinks followed) of at
/// most `kind.max_bytes()`. Errors are one sentence starting with the path.
pub fn read_file(path: &Path, kind: InputKind) -> Result<Vec<u8>, String> {
    let name = path.display();
    let meta = std::fs::metadata(path).map_err(|e| format!("{name}: cannot read {}: {e}", kind.noun()))?;
    if !meta.is_file() {
        let what = if meta.is_dir() { "a directory" } else { "not a regular file (a device, FIFO or socket)" };
        return Err(format!("{name}: cannot read {}: it is {what}", kind.noun()));
    }
    let limit = kind.max_bytes();
    if meta.len() > limit {
        return Err(format!("{name}: the {} is {} bytes, more than the limit of {}", kind.noun(), meta.len(), size_text(limit)));
    }
    let file = std::fs::File::open(path).map_err(|e| format!("{name}: cannot read {}: {e}", kind.noun()))?;
    // Recorded before reading, so no output of this run may replace it.
    if let Ok(opened) = file.metadata() {
        crate::file_identity::record_input(path, &opened);
    }
    // The file may grow between the size check and the read: never read past the limit.
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(limit + 1).read_to_end(&mut bytes).map_err(|e| format!("{name}: cannot read {}: {e}", kind.noun()))?;
    if bytes.len() as u64 > limit {
        return Err(format!("{name}: the {} is more than the limit of {}", kind.noun(), size_text(limit)));
    }
    Ok(bytes)
}

/// Checks an image size (from a header, a scene or the command line)
/// against `MAX_IMAGE_SIDE` and `MAX_IMAGE_PIXELS`.
pub fn check_image_size(width: u32, height: u32) -> Result<(), String> {
    if width == 0 || height == 0 || width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
        return Err(format!("{width}x{height} is outside 1..{MAX_IMAGE_SIDE} per side"));
    }
    if width as u64 * height as u64 > MAX_IMAGE_PIXELS {
        return Err(format!("{width}x{height} has more than the limit of {MAX_IMAGE_PIXELS} pixels (e.g. 8192x4096)"));
    }
    Ok(())
}

/// Decodes an image (PNG or EXR) from bytes, after checking the size its
/// header declares, so that a small file declaring a huge image fails
/// before anything large is allocated. `name` names the file in messages.
pub fn decode_image(bytes: &[u8], name: &str) -> Result<image::DynamicImage, String> {
    let reader = || {
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| format!("cannot decode {name}: {e}"))
    };
    let (w, h) = reader()?.into_dimensions().map_err(|e| format!("cannot decode {name}: {e}"))?;
    check_image_size(w, h).map_err(|e| format!("{name}: the image is {e}"))?;
    let mut r = reader()?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_IMAGE_SIDE);
    limits.max_image_height = Some(MAX_IMAGE_SIDE);
    // Room for the decoded image at 32-bit float RGBA, the widest format.
    limits.max_alloc = Some(MAX_IMAGE_PIXELS * 16 + (64 << 20));
    r.limits(limits);
    r.decode().map_err(|e| format!("cannot decode {name}: {e}"))
}

/// Longest error message about an input, in characters.
pub const MAX_MESSAGE_CHARS: usize = 600;

/// A message cut to `MAX_MESSAGE_CHARS` when it quotes something huge from
/// the input: the start (file and line) and the end (usually the valid
/// range) are kept, the middle is elided.
pub fn bounded_message(msg: &str) -> String {
    let n = msg.chars().count();
    if n <= MAX_MESSAGE_CHARS {
        return msg.to_string();
    }
    let head: String = msg.chars().take(300).collect();
    let tail: String = msg.chars().skip(n - 250).collect();
    format!("{head} ... {tail}")
}

fn size_text(bytes: u64) -> String {
    format!("{} MiB", bytes >> 20)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn special_files_and_directories_are_refused() {
        let e = read_file(Path::new("/dev/zero"), InputKind::Mesh).unwrap_err();
        assert!(e.starts_with("/dev/zero:") && e.contains("not a regular file"), "{e}");
        let e = read_file(Path::new("/tmp"), InputKind::Scene).unwrap_err();
        assert!(e.contains("a directory"), "{e}");
    }

    #[test]
    fn files_over_the_limit_are_refused_by_size() {
        let d = std::env::temp_dir().join(format!("pinhole-input-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let p = d.join("big.toml");
        let f = std::fs::File::create(&p).unwrap();
        f.set_len(MAX_SCENE_BYTES + 1).unwrap();
        let e = read_file(&p, InputKind::Scene).unwrap_err();
        assert!(e.contains("big.toml") && e.contains("limit of 16 MiB"), "{e}");
        std::fs::write(&p, b"x = 1").unwrap();
        assert_eq!(read_file(&p, InputKind::Scene).unwrap(), b"x = 1");
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn long_messages_keep_their_start_and_end() {
        let m = format!("a.toml:3: material \"{}\" is bad; allowed: 0 to 1", "x".repeat(10_000));
        let b = bounded_message(&m);
        assert!(b.chars().count() <= MAX_MESSAGE_CHARS && b.starts_with("a.toml:3:") && b.ends_with("allowed: 0 to 1"), "{b}");
        assert_eq!(bounded_message("short"), "short");
    }

    #[test]
    fn image_sizes_are_bounded_per_side_and_in_total() {
        assert!(check_image_size(16384, 1).is_ok());
        assert!(check_image_size(16385, 1).is_err());
        assert!(check_image_size(8192, 4096).is_ok());
        assert!(check_image_size(8192, 4097).unwrap_err().contains("33554432"));
        assert!(check_image_size(0, 5).is_err());
    }
}
