//! The options that render a part of the frame (`render --crop`, `--tile`,
//! `--sample-range`): parsed as given here, each refusing a malformed value
//! in one sentence, and turned into a `FramePart` once the frame's size and
//! samples are known.

use crate::render::{FramePart, RenderSettings};
use clap::Args;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crop(pub [u32; 4]);

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tile {
    pub index: u32,
    pub count: u32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleRange {
    pub from: u32,
    pub to: u32,
}

#[derive(Args, Clone, Default)]
pub struct PartOpts {
    /// Render only this rectangle of the full frame (ends exclusive), into an image of its size, with the full frame's pixels there.
    #[arg(long, value_name = "X0,Y0,X1,Y1", value_parser = parse_crop, conflicts_with = "tile")]
    pub crop: Option<Crop>,
    /// Render the I-th of N bands of rows (0-based) into a partial EXR for `pinhole merge`.
    #[arg(long, value_name = "I/N", value_parser = parse_tile)]
    pub tile: Option<Tile>,
    /// Render samples FROM..TO-1 of every pixel into a partial EXR for `pinhole merge`.
    #[arg(long = "sample-range", value_name = "FROM..TO", value_parser = parse_sample_range)]
    pub sample_range: Option<SampleRange>,
}

fn number(s: &str, what: &str) -> Result<u32, String> {
    s.trim().parse::<u32>().map_err(|_| format!("{what} \"{s}\" is not a whole number"))
}

fn parse_crop(s: &str) -> Result<Crop, String> {
    let v: Vec<&str> = s.split(',').collect();
    if v.len() != 4 {
        return Err("give four whole numbers X0,Y0,X1,Y1".into());
    }
    let c = [number(v[0], "X0")?, number(v[1], "Y0")?, number(v[2], "X1")?, number(v[3], "Y1")?];
    if c[2] <= c[0] || c[3] <= c[1] {
        return Err("the rectangle has no area (X1 must exceed X0 and Y1 exceed Y0)".into());
    }
    Ok(Crop(c))
}

fn parse_tile(s: &str) -> Result<Tile, String> {
    let (i, n) = s.split_once('/').ok_or("give the tile as I/N, e.g. 0/4")?;
    let (index, count) = (number(i, "I")?, number(n, "N")?);
    if count == 0 {
        return Err("N must be at least 1".into());
    }
    if index >= count {
        return Err(format!("the index must be below {count} (tiles are numbered from 0)"));
    }
    Ok(Tile { index, count })
}

fn parse_sample_range(s: &str) -> Result<SampleRange, String> {
    let (a, b) = s.split_once("..").ok_or("give the range as FROM..TO, e.g. 0..16")?;
    let (from, to) = (number(a, "FROM")?, number(b, "TO")?);
    if to <= from {
        return Err("TO must exceed FROM".into());
    }
    Ok(SampleRange { from, to })
}

impl PartOpts {
    /// Whether the output is a part for `pinhole merge` (a partial EXR).
    pub fn is_partial(&self) -> bool {
        self.tile.is_some() || self.sample_range.is_some()
    }

    /// The part of a frame of `settings` these options ask for (`None`: the
    /// whole frame), refused in one sentence where it does not fit.
    pub fn part(&self, settings: &RenderSettings) -> Result<Option<FramePart>, String> {
        if self.crop.is_none() && !self.is_partial() {
            return Ok(None);
        }
        let mut part = FramePart::whole(settings);
        if let Some(Crop([x0, y0, x1, y1])) = self.crop {
            part.x = x0..x1;
            part.y = y0..y1;
            if x1 > settings.width || y1 > settings.height {
                return Err(format!("--crop {x0},{y0},{x1},{y1} reaches outside the {}x{} frame", settings.width, settings.height));
            }
        }
        if let Some(Tile { index, count }) = self.tile {
            if count > settings.height {
                return Err(format!("--tile {index}/{count}: {count} bands are more than the frame's {} rows", settings.height));
            }
            part.y = FramePart::band_rows(index, count, settings.height);
        }
        if let Some(SampleRange { from, to }) = self.sample_range {
            if to > settings.spp.max(1) {
                return Err(format!("--sample-range {from}..{to} reaches past the frame's {} samples per pixel", settings.spp.max(1)));
            }
            part.passes = from..to;
        }
        crate::render::frame::check_part(&part, settings)?;
        Ok(Some(part))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn malformed_parts_are_refused() {
        assert!(parse_tile("4/4").unwrap_err().contains("below 4"));
        assert!(parse_tile("0/0").unwrap_err().contains("at least 1"));
        assert!(parse_tile("1").is_err());
        assert_eq!(parse_tile("3/4"), Ok(Tile { index: 3, count: 4 }));
        assert!(parse_crop("5,5,5,9").unwrap_err().contains("no area"));
        assert!(parse_crop("1,2,3").is_err());
        assert_eq!(parse_crop("1,2,3,4"), Ok(Crop([1, 2, 3, 4])));
        assert!(parse_sample_range("4..4").unwrap_err().contains("exceed"));
        assert_eq!(parse_sample_range("0..16"), Ok(SampleRange { from: 0, to: 16 }));
    }

    #[test]
    fn parts_outside_the_frame_are_refused() {
        let s = RenderSettings { width: 64, height: 48, spp: 4, ..RenderSettings::default() };
        let crop = PartOpts { crop: Some(Crop([0, 0, 65, 10])), ..PartOpts::default() };
        assert!(crop.part(&s).unwrap_err().contains("outside the 64x48 frame"));
        let range = PartOpts { sample_range: Some(SampleRange { from: 2, to: 5 }), ..PartOpts::default() };
        assert!(range.part(&s).unwrap_err().contains("4 samples"));
        let tile = PartOpts { tile: Some(Tile { index: 1, count: 4 }), ..PartOpts::default() };
        assert_eq!(tile.part(&s).unwrap().unwrap().y, 12..24);
    }
}
