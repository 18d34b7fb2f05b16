//! The gallery's contact sheet: one row per case, the failing image beside
//! the cured one, each captioned with its setting and wrong-pixel count,
//! and a third image marking the failing image's wrong pixels in red over the
//! dimmed truth (so a subtle failure is found at a glance).
//! Text is drawn with plotters in egui's font, as the charts are.

use crate::gallery::measure::CaseResult;
use plotters::prelude::*;

/// Width of one image cell; images are enlarged by a whole factor to fill it.
const CELL_W: u32 = 330;
/// Images per row: failing, cured, where the failing one is wrong.
const COLUMNS: u32 = 3;
const PAD: u32 = 10;
/// Height of a row's caption (case, explanation) above its images.
const CAPTION_H: u32 = 62;
/// Characters per line of a wrapped explanation.
const WRAP: usize = 125;
/// Height of the line under each image (setting, wrong pixels).
const LABEL_H: u32 = 38;
/// Characters per line of an image's label (it wraps onto a second line).
const LABEL_WRAP: usize = 50;
const TITLE_H: u32 = 36;

fn scale_of(r: &CaseResult) -> u32 {
    (CELL_W / r.width.max(1)).max(1)
}

fn row_height(r: &CaseResult) -> u32 {
    CAPTION_H + r.height * scale_of(r) + LABEL_H + PAD
}

/// Draws the sheet for `results` (with their explanations, by case) as PNG bytes.
pub fn draw_png(results: &[(CaseResult, &str)]) -> Result<Vec<u8>, String> {
    let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
    // Images wider than a cell widen every cell.
    let cell_w = results.iter().map(|(r, _)| r.width * scale_of(r)).fold(CELL_W, u32::max);
    let width = PAD + COLUMNS * (cell_w + PAD);
    let height = TITLE_H + results.iter().map(|(r, _)| row_height(r)).sum::<u32>() + PAD;
    let mut buf = vec![255u8; (width * height * 3) as usize];
    // Images first (plain copies into the buffer), text over them after.
    let mut y = TITLE_H;
    for (r, _) in results {
        let s = scale_of(r);
        for (col, rgb) in [
            crate::image_io::to_rgb8(&r.failing.image, r.exposure, true),
            crate::image_io::to_rgb8(&r.cured.image, r.exposure, true),
            wrong_pixel_map(r),
        ]
        .into_iter()
        .enumerate()
        {
            let x0 = PAD + col as u32 * (cell_w + PAD);
            blit(&mut buf, width, &rgb, r.width, r.height, s, x0, y + CAPTION_H);
        }
        y += row_height(r);
    }
    {
        let root = BitMapBackend::with_buffer(&mut buf, (width, height)).into_drawing_area();
        let text = |s: &str, x: u32, y: u32, size: u32, color: RGBColor| {
            root.draw(&Text::new(s.to_string(), (x as i32, y as i32), ("sans-serif", size).into_font().color(&color))).map_err(|e| e.to_string())
        };
        text("pinhole stress gallery: failing setting | cured setting | the failing image's wrong pixels (red) on the truth", PAD, 8, 20, BLACK)?;
        let mut y = TITLE_H;
        for (r, explanation) in results {
            let verdict = if r.demonstrated() { "" } else { "  (NOT DEMONSTRATED)" };
            text(&format!("{}  [{}, knob: {}]{verdict}", r.case, r.method, r.knob), PAD, y + 2, 18, BLACK)?;
            for (k, line) in wrap(explanation, WRAP).iter().take(2).enumerate() {
                text(line, PAD, y + 23 + 17 * k as u32, 14, RGBColor(60, 60, 60))?;
            }
            let label_y = y + CAPTION_H + r.height * scale_of(r) + 3;
            let label = |s: &str, x: u32, color: RGBColor| -> Result<(), String> {
                for (k, line) in wrap(s, LABEL_WRAP).iter().take(2).enumerate() {
                    text(line, x, label_y + 16 * k as u32, 13, color)?;
                }
                Ok(())
            };
            for (col, s) in [&r.failing, &r.cured].into_iter().enumerate() {
                let color = if s.wrong_pixels > r.threshold { RGBColor(180, 0, 0) } else { RGBColor(0, 120, 0) };
                let x = PAD + col as u32 * (cell_w + PAD);
                label(&format!("{}: {} wrong px", s.setting, s.wrong_pixels), x, color)?;
            }
            label(&format!("truth: {}", r.truth_setting), PAD + 2 * (cell_w + PAD), RGBColor(60, 60, 60))?;
            y += row_height(r);
        }
        root.present().map_err(|e| e.to_string())?;
    }
    crate::image_io::encode_png(width, height, &buf)
}

/// The truth, dimmed to grey, with the failing image's wrong pixels in red.
fn wrong_pixel_map(r: &CaseResult) -> Vec<u8> {
    let truth = crate::image_io::to_rgb8(&r.truth, r.exposure, true);
    let mut out = Vec::with_capacity(truth.len());
    for (i, (&a, &b)) in r.failing.image.iter().zip(&r.truth).enumerate() {
        if crate::gallery::measure::pixel_wrong(a, b) {
            out.extend_from_slice(&[230, 20, 20]);
        } else {
            let t = &truth[3 * i..3 * i + 3];
            let grey = ((t[0] as u32 + t[1] as u32 + t[2] as u32) / 3 / 2 + 40) as u8;
            out.extend_from_slice(&[grey, grey, grey]);
        }
    }
    out
}

/// Copies an RGB8 image of `w` x `h` into `buf` (`buf_w` wide) at `(x0, y0)`,
/// each pixel as an `s` x `s` block (nearest: pixels stay visible).
#[allow(clippy::too_many_arguments)]
fn blit(buf: &mut [u8], buf_w: u32, rgb: &[u8], w: u32, h: u32, s: u32, x0: u32, y0: u32) {
    for y in 0..h * s {
        for x in 0..w * s {
            let src = (((y / s) * w + x / s) * 3) as usize;
            let dst = (((y0 + y) * buf_w + x0 + x) * 3) as usize;
            buf[dst..dst + 3].copy_from_slice(&rgb[src..src + 3]);
        }
    }
}

/// `text` broken at spaces into lines of at most `width` characters.
fn wrap(text: &str, width: usize) -> Vec<String> {
    let mut lines = vec![String::new()];
    for word in text.split_whitespace() {
        let line = lines.last_mut().expect("one line");
        if !line.is_empty() && line.chars().count() + 1 + word.chars().count() > width {
            lines.push(word.to_string());
        } else {
            if !line.is_empty() {
                line.push(' ');
            }
            line.push_str(word);
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn explanations_wrap_at_spaces() {
        assert_eq!(wrap("aa bb cc", 5), vec!["aa bb", "cc"]);
        assert_eq!(wrap("short", 80), vec!["short"]);
    }
}
