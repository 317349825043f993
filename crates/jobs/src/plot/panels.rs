//! Micrographs with contact edges in green (Fig. 2 of Weber et al. 2018), one panel or several
//! side by side on one grey scale.

use super::encode_png;
use crate::error::{Error, Result};

/// Pure green for contact edges, as in Fig. 2a of Weber et al. 2018.
const EDGE_GREEN: [u8; 3] = [0, 255, 0];

/// Upper bound on overlay output pixels, so that an absurd `scale` becomes an error instead of
/// an allocation failure (which aborts the process).
const MAX_OVERLAY_PIXELS: usize = 1 << 28;

/// Micrograph with contact edges in green, as in Fig. 2a of Weber et al. 2018; PNG bytes (RGB8).
///
/// `values` and `mask` are row-major, `height` rows of `width` (`true` = contact). Grey levels
/// are stretched between the 0.5th and 99.5th percentiles of the finite values (min..max if
/// those coincide, mid-grey if all values are equal); NaN and infinite pixels are black.
///
/// An edge pixel is a contact pixel with at least one 4-neighbour that is not contact; pixels
/// outside the image do not count as non-contact. Edge pixels are pure green (0, 255, 0).
/// Each pixel becomes a `scale`×`scale` block (nearest neighbour), edge pixels included: whole
/// green blocks stand out far better than 1-pixel lines at large scales, and the picture stays
/// the `scale == 1` overlay magnified, so every green block is exactly one edge pixel.
///
/// Errors with [`Error::Plot`] on zero sizes or `scale`, lengths that do not match
/// `width × height`, or an output that would be unreasonably large (over 2²⁸ pixels).
pub fn overlay_png(
    values: &[f64],
    width: usize,
    height: usize,
    mask: &[bool],
    scale: usize,
) -> Result<Vec<u8>> {
    edge_panels_png(&[values], width, height, mask, scale)
}

/// Several images of one scene side by side (left to right, 2 white pixels apart before
/// scaling), each with the same contact edges in green, as in Fig. 2 of Weber et al. 2018
/// (micrograph, then simulations). All panels share the grey scale of the first one, so a
/// simulated image put on the micrograph's intensity scale looks comparable; otherwise as
/// [`overlay_png`], which is the one-panel case.
pub fn edge_panels_png(
    panels: &[&[f64]],
    width: usize,
    height: usize,
    mask: &[bool],
    scale: usize,
) -> Result<Vec<u8>> {
    let Some(first) = panels.first() else {
        return Err(Error::Plot("no panels to draw".into()));
    };
    for p in panels {
        overlay_size(p.len(), width, height, mask.len(), scale)?;
    }
    let gap = if panels.len() > 1 { 2 * scale } else { 0 };
    let panel_w = width * scale;
    let total_w = panels.len() * panel_w + (panels.len() - 1) * gap;
    let out_h = height * scale;
    if total_w
        .checked_mul(out_h)
        .is_none_or(|n| n > MAX_OVERLAY_PIXELS)
    {
        return Err(Error::Plot(format!(
            "{} panels of {width}×{height} at scale {scale} exceed {MAX_OVERLAY_PIXELS} pixels",
            panels.len()
        )));
    }
    let range = stretch_range(first);
    let greys: Vec<Vec<u8>> = panels.iter().map(|p| grey_levels(p, range)).collect();
    let mut rgb = Vec::with_capacity(total_w * out_h * 3);
    let mut row = Vec::with_capacity(total_w * 3);
    for y in 0..height {
        row.clear();
        for (k, grey) in greys.iter().enumerate() {
            if k > 0 {
                row.extend(std::iter::repeat_n(255u8, gap * 3));
            }
            for x in 0..width {
                let colour = if is_edge(mask, width, height, x, y) {
                    EDGE_GREEN
                } else {
                    [grey[y * width + x]; 3]
                };
                for _ in 0..scale {
                    row.extend_from_slice(&colour);
                }
            }
        }
        for _ in 0..scale {
            rgb.extend_from_slice(&row);
        }
    }
    let dim = |n: usize| u32::try_from(n).map_err(|_| Error::Plot("overlay too large".into()));
    encode_png(&rgb, dim(total_w)?, dim(out_h)?)
}

/// The pixel values of a thumbnail's micrograph, row-major: integer codes with their offset
/// (value = code + offset) or floats.
#[derive(Debug, Clone, Copy)]
pub enum Pixels<'a> {
    /// Integer codes and the offset of their values.
    Codes(&'a [u16], i32),
    /// Float values (non-finite ones are left out of a box's mean).
    Floats(&'a [f32]),
}

impl Pixels<'_> {
    fn len(&self) -> usize {
        match self {
            Pixels::Codes(c, _) => c.len(),
            Pixels::Floats(v) => v.len(),
        }
    }

    /// Sum and count of the finite values in `range`.
    fn sum(&self, range: std::ops::Range<usize>) -> (f64, u32) {
        match *self {
            Pixels::Codes(codes, offset) => {
                let n = range.len() as u32;
                let sum: u64 = codes[range].iter().map(|&c| u64::from(c)).sum();
                (sum as f64 + f64::from(offset) * f64::from(n), n)
            }
            Pixels::Floats(values) => values[range]
                .iter()
                .filter(|v| v.is_finite())
                .fold((0.0, 0), |(s, n), &v| (s + f64::from(v), n + 1)),
        }
    }
}

/// A small overlay for pages that show many series (the batch's QC page): the micrograph
/// reduced by whole-pixel boxes to at most `max_side` pixels a side (each thumbnail pixel the
/// mean of the finite values in its box), grey levels stretched as in [`overlay_png`], and a
/// thumbnail pixel pure green where its box holds a contact edge pixel (a contact pixel with a
/// non-contact 4-neighbour inside the image). `contact` is row-major, non-zero for contact.
///
/// Errors as [`overlay_png`] on zero or mismatched sizes, and on `max_side` 0.
pub fn thumbnail_png(
    pixels: Pixels,
    width: usize,
    height: usize,
    contact: &[u8],
    max_side: usize,
) -> Result<Vec<u8>> {
    overlay_size(pixels.len(), width, height, contact.len(), 1)?;
    if max_side == 0 {
        return Err(Error::Plot(
            "a thumbnail needs a size of at least 1 pixel".into(),
        ));
    }
    let factor = width.max(height).div_ceil(max_side).max(1);
    let (tw, th) = (width.div_ceil(factor), height.div_ceil(factor));
    let mut sums = vec![(0.0f64, 0u32); tw * th];
    let mut edges = vec![false; tw * th];
    let is_contact = |x: usize, y: usize| contact[y * width + x] != 0;
    for y in 0..height {
        let row = (y / factor) * tw;
        let line = &contact[y * width..(y + 1) * width];
        for (bx, cell) in sums[row..row + tw].iter_mut().enumerate() {
            let (x0, x1) = (bx * factor, ((bx + 1) * factor).min(width));
            let (s, n) = pixels.sum(y * width + x0..y * width + x1);
            cell.0 += s;
            cell.1 += n;
            // Contact is sparse: most boxes have none on this line.
            if edges[row + bx] || line[x0..x1].iter().all(|&c| c == 0) {
                continue;
            }
            edges[row + bx] = (x0..x1).any(|x| {
                is_contact(x, y)
                    && ((x > 0 && !is_contact(x - 1, y))
                        || (x + 1 < width && !is_contact(x + 1, y))
                        || (y > 0 && !is_contact(x, y - 1))
                        || (y + 1 < height && !is_contact(x, y + 1)))
            });
        }
    }
    let means: Vec<f64> = sums
        .iter()
        .map(|&(s, n)| if n > 0 { s / f64::from(n) } else { f64::NAN })
        .collect();
    let grey = grey_levels(&means, stretch_range(&means));
    let mut rgb = Vec::with_capacity(tw * th * 3);
    for (g, edge) in grey.iter().zip(&edges) {
        rgb.extend_from_slice(&if *edge { EDGE_GREEN } else { [*g; 3] });
    }
    let dim = |n: usize| u32::try_from(n).map_err(|_| Error::Plot("thumbnail too large".into()));
    encode_png(&rgb, dim(tw)?, dim(th)?)
}

/// Checks the overlay inputs; returns the output size in pixels.
fn overlay_size(
    n_values: usize,
    width: usize,
    height: usize,
    n_mask: usize,
    scale: usize,
) -> Result<(usize, usize)> {
    if width == 0 || height == 0 || scale == 0 {
        return Err(Error::Plot(format!(
            "overlay needs non-zero sizes, got {width}×{height} at scale {scale}"
        )));
    }
    let n = width
        .checked_mul(height)
        .ok_or_else(|| Error::Plot(format!("overlay size {width}×{height} overflows")))?;
    if n_values != n || n_mask != n {
        return Err(Error::Plot(format!(
            "overlay of {width}×{height} = {n} pixels got {n_values} values and {n_mask} mask entries"
        )));
    }
    let out = (width.checked_mul(scale), height.checked_mul(scale));
    match out {
        (Some(w), Some(h)) if w.checked_mul(h).is_some_and(|p| p <= MAX_OVERLAY_PIXELS) => {
            Ok((w, h))
        }
        _ => Err(Error::Plot(format!(
            "overlay of {width}×{height} at scale {scale} exceeds {MAX_OVERLAY_PIXELS} pixels"
        ))),
    }
}

/// Whether contact pixel `(x, y)` has a non-contact 4-neighbour inside the image.
fn is_edge(mask: &[bool], width: usize, height: usize, x: usize, y: usize) -> bool {
    let not_contact = |x: usize, y: usize| !mask[y * width + x];
    mask[y * width + x]
        && ((x > 0 && not_contact(x - 1, y))
            || (x + 1 < width && not_contact(x + 1, y))
            || (y > 0 && not_contact(x, y - 1))
            || (y + 1 < height && not_contact(x, y + 1)))
}

/// Grey-scale limits of an image: its 0.5th and 99.5th percentiles of the finite values (min and
/// max if those coincide); `None` without finite values.
fn stretch_range(values: &[f64]) -> Option<(f64, f64)> {
    let mut finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    finite.sort_unstable_by(f64::total_cmp);
    let (&min, &max) = finite.first().zip(finite.last())?;
    let (lo, hi) = (percentile(&finite, 0.005), percentile(&finite, 0.995));
    Some(if lo < hi { (lo, hi) } else { (min, max) })
}

/// Contrast-stretched 8-bit grey level per pixel between `range`; non-finite values become 0
/// (black), everything is mid-grey when the range is empty.
fn grey_levels(values: &[f64], range: Option<(f64, f64)>) -> Vec<u8> {
    let Some((lo, hi)) = range else {
        return vec![0; values.len()];
    };
    values
        .iter()
        .map(|&v| match v {
            v if !v.is_finite() => 0,
            _ if lo >= hi => 128,
            // The clamp keeps the cast in 0..=255.
            v => (255.0 * (v.clamp(lo, hi) - lo) / (hi - lo)).round() as u8,
        })
        .collect()
}

/// Linearly interpolated percentile `p` (0..=1) of sorted, non-empty `sorted`.
fn percentile(sorted: &[f64], p: f64) -> f64 {
    let pos = p * (sorted.len() - 1) as f64;
    let (i, frac) = (pos.floor() as usize, pos.fract());
    match sorted.get(i + 1) {
        Some(&next) => sorted[i] + frac * (next - sorted[i]),
        None => sorted[i],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 20×10 image, contact rectangle x in 5..11, y in 3..7, on a background gradient.
    fn rectangle_scene() -> (Vec<f64>, Vec<bool>) {
        let (w, h) = (20, 10);
        let inside = |x: usize, y: usize| (5..11).contains(&x) && (3..7).contains(&y);
        let mut values = Vec::new();
        let mut mask = Vec::new();
        for y in 0..h {
            for x in 0..w {
                values.push(if inside(x, y) { 200.0 } else { (x + y) as f64 });
                mask.push(inside(x, y));
            }
        }
        values[0] = f64::NAN;
        (values, mask)
    }

    #[test]
    fn thumbnails_shrink_by_whole_boxes_and_keep_every_edge() {
        let (values, mask) = rectangle_scene();
        let contact: Vec<u8> = mask.iter().map(|&m| u8::from(m)).collect();
        // 20×10 into at most 5 pixels a side: boxes of 4, a 5×3 thumbnail.
        let floats: Vec<f32> = values.iter().map(|&v| v as f32).collect();
        let value = Pixels::Floats(&floats);
        let png = thumbnail_png(value, 20, 10, &contact, 5).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (5, 3));
        for (x, y, p) in img.enumerate_pixels() {
            // The rectangle x 5..11, y 3..7 has edge pixels in boxes x 1..=2, y 0..=1.
            let green = (1..=2).contains(&x) && (0..=1).contains(&y);
            assert_eq!(p.0 == EDGE_GREEN, green, "({x}, {y})");
        }
        // No shrinking needed: one box per pixel, the overlay itself.
        let same = thumbnail_png(value, 20, 10, &contact, 64).unwrap();
        assert_eq!(same, overlay_png(&values, 20, 10, &mask, 1).unwrap());
        assert!(thumbnail_png(value, 20, 10, &contact, 0).is_err());
        assert!(thumbnail_png(value, 20, 9, &contact, 5).is_err());
        // Integer codes with an offset give the same picture as their values.
        let codes: Vec<u16> = values
            .iter()
            .map(|&v| if v.is_finite() { v as u16 + 100 } else { 0 })
            .collect();
        let mut no_nan = values.clone();
        no_nan[0] = -100.0;
        let from_codes = thumbnail_png(Pixels::Codes(&codes, -100), 20, 10, &contact, 5).unwrap();
        let floats: Vec<f32> = no_nan.iter().map(|&v| v as f32).collect();
        assert_eq!(
            from_codes,
            thumbnail_png(Pixels::Floats(&floats), 20, 10, &contact, 5).unwrap()
        );
    }

    #[test]
    fn overlay_green_exactly_on_rectangle_boundary() {
        let (values, mask) = rectangle_scene();
        for scale in [1, 3] {
            let png = overlay_png(&values, 20, 10, &mask, scale).unwrap();
            let img = image::load_from_memory(&png).unwrap().to_rgb8();
            let s = scale as u32;
            assert_eq!(img.dimensions(), (20 * s, 10 * s));
            for (x, y, p) in img.enumerate_pixels() {
                let (sx, sy) = (x / s, y / s);
                let inside = (5..11).contains(&sx) && (3..7).contains(&sy);
                let ring = inside && (sx == 5 || sx == 10 || sy == 3 || sy == 6);
                assert_eq!(p.0 == EDGE_GREEN, ring, "pixel ({x}, {y}) at scale {scale}");
            }
            // Corner and side of the rectangle, an interior pixel, a background pixel.
            assert_eq!(img.get_pixel(5 * s, 3 * s).0, EDGE_GREEN);
            assert_eq!(img.get_pixel(8 * s, 7 * s - 1).0, EDGE_GREEN);
            let interior = img.get_pixel(6 * s, 4 * s).0;
            assert_eq!(interior, [255, 255, 255], "contact is the brightest grey");
            let bg = img.get_pixel(15 * s, s).0;
            assert!(bg[0] == bg[1] && bg[1] == bg[2] && bg[0] > 0, "{bg:?}");
            assert_eq!(img.get_pixel(0, 0).0, [0, 0, 0], "NaN pixel is black");
        }
    }

    #[test]
    fn overlay_edge_at_image_border_is_not_an_edge() {
        let png = overlay_png(&[1.0, 2.0, 3.0, 4.0], 2, 2, &[true; 4], 2).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert!(img.pixels().all(|p| p.0 != EDGE_GREEN));
    }

    #[test]
    fn overlay_constant_image_is_mid_grey() {
        let png = overlay_png(&[7.0; 6], 3, 2, &[false; 6], 1).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert!(img.pixels().all(|p| p.0 == [128, 128, 128]));
    }

    #[test]
    fn panels_share_the_first_panels_grey_scale() {
        let (values, mask) = rectangle_scene();
        let dimmer: Vec<f64> = values.iter().map(|v| v * 0.5).collect();
        let png = edge_panels_png(&[&values, &dimmer], 20, 10, &mask, 2).unwrap();
        let img = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), (2 * 40 + 4, 20));
        // Same interior pixel: full white in panel 1, about half grey in panel 2.
        let left = img.get_pixel(12, 8).0[0];
        let right = img.get_pixel(44 + 12, 8).0[0];
        assert_eq!(left, 255);
        assert!((100..=160).contains(&right), "{right}");
        assert_eq!(img.get_pixel(41, 8).0, [255, 255, 255], "white gap");
        assert_eq!(
            img.get_pixel(44 + 10, 6).0,
            EDGE_GREEN,
            "edges on both panels"
        );
        assert!(edge_panels_png(&[], 20, 10, &mask, 1).is_err());
    }

    #[test]
    fn overlay_rejects_bad_shapes() {
        let (values, mask) = rectangle_scene();
        let short = &mask[..mask.len() - 1];
        assert!(matches!(
            overlay_png(&values, 20, 10, short, 1),
            Err(Error::Plot(_))
        ));
        assert!(matches!(
            overlay_png(&values, 10, 10, &mask, 1),
            Err(Error::Plot(_))
        ));
        assert!(matches!(
            overlay_png(&[], 0, 0, &[], 1),
            Err(Error::Plot(_))
        ));
        assert!(matches!(
            overlay_png(&values, 20, 10, &mask, 0),
            Err(Error::Plot(_))
        ));
        assert!(matches!(
            overlay_png(&values, 20, 10, &mask, usize::MAX),
            Err(Error::Plot(_))
        ));
    }
}
