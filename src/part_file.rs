//! Partial renders on disk: an OpenEXR image of a part of a frame (a band
//! of rows, a range of sample passes, or both) whose header records what a
//! merge needs to check the parts belong together and to add them up
//! exactly. The record is one JSON text attribute, `pinhole.part`.
//!
//! The pixels are linear f32 RGB: the final values when the part holds
//! every sample pass, otherwise the sums of its passes' samples (the merge
//! adds the sums and divides once, as the whole frame does).

use crate::math::Radiance;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The header attribute that holds a part's `PartRecord`.
pub const ATTRIBUTE: &str = "pinhole.part";

/// What a part file records beside its pixels.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartRecord {
    /// pinhole's version: parts of other versions may render differently.
    pub version: String,
    pub scene: String,
    /// FNV-1a 64 over the scene's name and the bytes of every file its load read.
    pub scene_hash: String,
    pub renderer: String,
    /// The whole frame's settings (size, samples, seed, every option).
    pub settings: serde_json::Value,
    pub frame_width: u32,
    pub frame_height: u32,
    pub spp: u32,
    /// The part's rectangle in the frame: x0, y0, x1, y1 (ends exclusive).
    pub region: [u32; 4],
    /// The sample passes it holds: from, to (exclusive).
    pub passes: [u32; 2],
    /// `--tile I/N` as given, if the part is a tile.
    pub tile: Option<[u32; 2]>,
    /// The part's own run statistics (the `--stats` JSON of its render),
    /// with its start and end times in Unix milliseconds.
    pub stats: serde_json::Value,
}

impl PartRecord {
    /// Whether the pixels are final values (every pass) rather than sums.
    pub fn holds_final_values(&self) -> bool {
        self.passes == [0, self.spp.max(1)]
    }

    pub fn width(&self) -> u32 {
        self.region[2].saturating_sub(self.region[0])
    }

    pub fn height(&self) -> u32 {
        self.region[3].saturating_sub(self.region[1])
    }
}

/// A part as read back.
pub struct PartFile {
    pub record: PartRecord,
    /// Row-major, `record.width()` x `record.height()`.
    pub pixels: Vec<Radiance>,
}

/// FNV-1a 64 over `name` and, in order of their paths, the bytes of `files`:
/// the same scene read from the same files gives the same hash on any
/// machine, wherever the files are.
pub fn scene_hash(name: &str, files: &[std::path::PathBuf]) -> Result<String, String> {
    let mut files = files.to_vec();
    files.sort();
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut feed = |bytes: &[u8]| {
        for b in bytes {
            h ^= *b as u64;
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    };
    feed(name.as_bytes());
    for f in &files {
        let bytes = std::fs::read(f).map_err(|e| format!("{}: cannot read it again to hash the scene: {e}", f.display()))?;
        feed(&(bytes.len() as u64).to_le_bytes());
        feed(&bytes);
    }
    Ok(format!("{h:016x}"))
}

/// Encodes a part file: `pixels` of the record's region size.
pub fn encode(record: &PartRecord, pixels: &[Radiance]) -> Result<Vec<u8>, String> {
    use exr::prelude::*;
    let (w, h) = (record.width() as usize, record.height() as usize);
    if pixels.len() != w * h || w == 0 {
        return Err(format!("a part of {w}x{h} pixels was given {} pixels", pixels.len()));
    }
    let json = serde_json::to_string(record).map_err(|e| e.to_string())?;
    let mut attributes = LayerAttributes::named("");
    // Text attributes are bytes; the record is UTF-8 JSON, read back as such.
    attributes.other.insert(Text::new_or_panic(ATTRIBUTE), AttributeValue::Text(Text::from_slice_unchecked(json.as_bytes())));
    attributes.software_name = Some(Text::new_or_panic(format!("pinhole {}", env!("CARGO_PKG_VERSION"))));
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| {
        let c = pixels[p.x() + p.y() * w];
        (c.x, c.y, c.z)
    });
    let image = Image::from_layer(Layer::new((w, h), attributes, Encoding::SMALL_LOSSLESS, channels));
    let mut out = std::io::Cursor::new(Vec::new());
    image.write().non_parallel().to_buffered(&mut out).map_err(|e| format!("cannot encode the part's EXR: {e}"))?;
    Ok(out.into_inner())
}

/// Reads a part file, refusing (in one sentence naming it) a file that is
/// not one or whose record disagrees with its pixels.
pub fn read(path: &Path) -> Result<PartFile, String> {
    use exr::prelude::*;
    let name = path.display();
    let bytes = crate::input::read_file(path, crate::input::InputKind::Image)?;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgb_channels(
            |size, _| (size.width(), vec![Radiance::ZERO; size.area()]),
            |(w, px): &mut (usize, Vec<Radiance>), p: Vec2<usize>, (r, g, b): (f32, f32, f32)| px[p.x() + p.y() * *w] = Radiance::new(r, g, b),
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| format!("{name}: not a readable RGB EXR: {e}"))?;
    let layer = image.layer_data;
    let record = checked_record(path, &layer.attributes, layer.size.width(), layer.size.height())?;
    let w = layer.size.width();
    let pixels = layer.channel_data.pixels.1;
    if let Some(i) = pixels.iter().position(|p| !p.is_finite()) {
        return Err(format!("{name}: pixel ({}, {}) is not finite", i % w, i / w));
    }
    Ok(PartFile { record, pixels })
}

/// Reads only a part file's header (its record and size), not its pixels:
/// what `pinhole merge --status` needs of every part, however large.
pub fn read_record(path: &Path) -> Result<PartRecord, String> {
    let name = path.display();
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| format!("{name}: not a readable EXR: {e}"))?;
    let header = meta.headers.first().ok_or_else(|| format!("{name}: an EXR without a layer"))?;
    checked_record(path, &header.own_attributes, header.layer_size.width(), header.layer_size.height())
}

/// The record in a part's layer `attributes`, checked against its `w` x `h`
/// pixels.
fn checked_record(path: &Path, attributes: &exr::prelude::LayerAttributes, w: usize, h: usize) -> Result<PartRecord, String> {
    use exr::prelude::*;
    let name = path.display();
    let text = match attributes.other.get(&Text::new_or_panic(ATTRIBUTE)) {
        Some(AttributeValue::Text(t)) => String::from_utf8_lossy(t.as_slice()).into_owned(),
        _ => return Err(format!("{name}: not a pinhole part (its header has no {ATTRIBUTE} record)")),
    };
    let record: PartRecord = serde_json::from_str(&text).map_err(|e| format!("{name}: its {ATTRIBUTE} record is unreadable: {e}"))?;
    let [x0, y0, x1, y1] = record.region;
    if x1 <= x0 || y1 <= y0 || x1 > record.frame_width || y1 > record.frame_height || record.width() as usize != w || record.height() as usize != h {
        return Err(format!("{name}: its region {x0},{y0},{x1},{y1} does not match its {w}x{h} pixels inside a {}x{} frame", record.frame_width, record.frame_height));
    }
    if record.passes[0] >= record.passes[1] || record.passes[1] > record.spp.max(1) {
        return Err(format!("{name}: its sample range {}..{} is not within 0..{}", record.passes[0], record.passes[1], record.spp));
    }
    Ok(record)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record() -> PartRecord {
        PartRecord {
            version: "0.1.0".into(),
            scene: "café".into(),
            scene_hash: "0123".into(),
            renderer: "raytrace".into(),
            settings: serde_json::json!({"spp": 4}),
            frame_width: 5,
            frame_height: 4,
            spp: 4,
            region: [1, 1, 4, 3],
            passes: [1, 3],
            tile: None,
            stats: serde_json::json!({"render_ms": 1.5}),
        }
    }

    #[test]
    fn a_part_reads_back_as_written() {
        let pixels: Vec<Radiance> = (0..6).map(|i| Radiance::new(i as f32 * 0.1, -0.0, 1e30)).collect();
        let bytes = encode(&record(), &pixels).unwrap();
        let path = std::env::temp_dir().join(format!("pinhole-part-file-{}.exr", std::process::id()));
        std::fs::write(&path, bytes).unwrap();
        let back = read(&path).unwrap();
        let header_only = read_record(&path).unwrap();
        let _ = std::fs::remove_file(&path);
        assert_eq!(back.record, record());
        assert_eq!(header_only, record());
        let bits = |v: &[Radiance]| v.iter().map(|c| [c.x.to_bits(), c.y.to_bits(), c.z.to_bits()]).collect::<Vec<_>>();
        assert_eq!(bits(&back.pixels), bits(&pixels));
    }

    #[test]
    fn a_plain_exr_is_not_a_part() {
        let path = std::env::temp_dir().join(format!("pinhole-part-plain-{}.exr", std::process::id()));
        crate::image_io::save_image(&path, 2, 2, &[Radiance::ZERO; 4], 1.0).unwrap();
        let e = read(&path).err().unwrap();
        let _ = std::fs::remove_file(&path);
        assert!(e.contains("not a pinhole part"), "{e}");
    }
}
