//! Statistics of a rectangle of the image on show, per channel, from its
//! linear values: what the A|B bar shows for a dragged region.

use crate::math::Radiance;

/// One channel's statistics over the finite values of a region.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChannelStats {
    pub mean: f64,
    pub min: f32,
    pub max: f32,
    /// The middle value; of an even count, the mean of the two middle ones
    /// (numpy's `median`).
    pub median: f64,
    /// Population standard deviation (numpy's `std`, `ddof = 0`).
    pub std: f64,
}

/// Statistics of a region `[x0, y0, x1)` x `[y0, y1)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegionStats {
    pub region: [u32; 4],
    pub pixels: u64,
    /// Values (channel by channel) that are not finite numbers, left out of
    /// the statistics. A frame zeroes its non-finite samples, so a rendered
    /// image has none; an image read from a file may.
    pub non_finite: u64,
    /// Red, green, blue; `None` for a channel with no finite value.
    pub channels: [Option<ChannelStats>; 3],
}

/// The statistics of `region` (clipped to the image) of `pixels`, an image
/// `width` wide, row-major.
pub fn region_stats(pixels: &[Radiance], width: u32, region: [u32; 4]) -> RegionStats {
    let w = width as usize;
    let height = if w == 0 { 0 } else { pixels.len() / w };
    let [x0, y0, x1, y1] = region;
    let (x1, y1) = ((x1 as usize).min(w), (y1 as usize).min(height));
    let (x0, y0) = ((x0 as usize).min(x1), (y0 as usize).min(y1));
    let mut non_finite = 0;
    let channels = [0, 1, 2].map(|k| {
        let mut values: Vec<f32> = Vec::with_capacity((x1 - x0) * (y1 - y0));
        for y in y0..y1 {
            for p in &pixels[y * w + x0..y * w + x1] {
                if p[k].is_finite() {
                    values.push(p[k]);
                } else {
                    non_finite += 1;
                }
            }
        }
        channel_stats(&mut values)
    });
    RegionStats { region, pixels: ((x1 - x0) * (y1 - y0)) as u64, non_finite, channels }
}

fn channel_stats(values: &mut [f32]) -> Option<ChannelStats> {
    if values.is_empty() {
        return None;
    }
    let n = values.len() as f64;
    let mean = values.iter().map(|&v| v as f64).sum::<f64>() / n;
    let variance = values.iter().map(|&v| (v as f64 - mean).powi(2)).sum::<f64>() / n;
    values.sort_by(f32::total_cmp);
    let mid = values.len() / 2;
    let median = if values.len() % 2 == 1 { values[mid] as f64 } else { (values[mid - 1] as f64 + values[mid] as f64) / 2.0 };
    Some(ChannelStats { mean, min: values[0], max: values[values.len() - 1], median, std: variance.sqrt() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_of_a_small_region_by_hand() {
        // A 3x2 image; the region is its right two columns.
        let px = |v: f32| Radiance::new(v, 2.0 * v, f32::NAN);
        let pixels = vec![px(9.0), px(1.0), px(2.0), px(9.0), px(3.0), px(10.0)];
        let s = region_stats(&pixels, 3, [1, 0, 3, 2]);
        assert_eq!((s.pixels, s.non_finite), (4, 4));
        let r = s.channels[0].unwrap();
        assert_eq!((r.min, r.max, r.mean, r.median), (1.0, 10.0, 4.0, 2.5));
        // Values 1, 2, 3, 10 about 4: deviations 9, 4, 1, 36, mean 12.5.
        assert!((r.std - 12.5f64.sqrt()).abs() < 1e-12);
        assert_eq!(s.channels[1].unwrap().median, 5.0);
        assert_eq!(s.channels[2], None);
        // A region past the image is clipped to it.
        assert_eq!(region_stats(&pixels, 3, [2, 1, 9, 9]).pixels, 1);
    }
}
