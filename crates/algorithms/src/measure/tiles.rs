//! Sums over square tiles of pixels, made while the pixels are classified (one pass over the
//! image for both): how many pixels, their sum, and how many are contact. The light budget of
//! an image ([`crate::analysis::light`]) works on these instead of on the pixels.

use crate::image::Plane;

use super::{ClassSums, Mask, SUM_BLOCK};

/// Side of a tile, pixels.
pub const TILE: usize = 4;

/// Tiles per side of a block (blocks of 16 × 16 pixels).
pub const BLOCK_TILES: usize = 4;

/// Per-tile sums of one image, row-major over the tiles; tiles on the right and bottom edges
/// hold what is left of the image.
#[derive(Debug, Clone, PartialEq)]
pub struct TileSums {
    /// Tiles per row.
    pub tw: usize,
    /// Rows of tiles.
    pub th: usize,
    /// Finite pixels of each tile.
    pub n: Vec<f64>,
    /// Sum of their values.
    pub sum: Vec<f64>,
    /// Contact pixels of each tile (at most `TILE²`).
    pub contact: Vec<u8>,
    /// Blocks of [`BLOCK_TILES`]² tiles per row.
    pub bw: usize,
    /// Rows of blocks.
    pub bh: usize,
    /// Finite pixels of each block.
    pub block_n: Vec<f64>,
    /// Sum of their values.
    pub block_sum: Vec<f64>,
    /// The most contact pixels any tile of the block has.
    pub block_contact: Vec<u8>,
}

impl TileSums {
    fn empty(width: usize, height: usize) -> TileSums {
        let (tw, th) = (width.div_ceil(TILE), height.div_ceil(TILE));
        let (bw, bh) = (tw.div_ceil(BLOCK_TILES), th.div_ceil(BLOCK_TILES));
        TileSums {
            tw,
            th,
            n: vec![0.0; tw * th],
            sum: vec![0.0; tw * th],
            contact: vec![0; tw * th],
            bw,
            bh,
            block_n: vec![0.0; bw * bh],
            block_sum: vec![0.0; bw * bh],
            block_contact: vec![0; bw * bh],
        }
    }

    /// Add the tiles of tile row `ty` into their blocks.
    fn add_to_blocks(&mut self, ty: usize) {
        let (k0, b0) = (ty * self.tw, ty / BLOCK_TILES * self.bw);
        let tiles = k0..k0 + self.tw;
        let blocks = b0..b0 + self.bw;
        for (((n, s), c), ((bn, bs), bc)) in self.n[tiles.clone()]
            .chunks(BLOCK_TILES)
            .zip(self.sum[tiles.clone()].chunks(BLOCK_TILES))
            .zip(self.contact[tiles].chunks(BLOCK_TILES))
            .zip(
                self.block_n[blocks.clone()]
                    .iter_mut()
                    .zip(&mut self.block_sum[blocks.clone()])
                    .zip(&mut self.block_contact[blocks]),
            )
        {
            *bn += n.iter().sum::<f64>();
            *bs += s.iter().sum::<f64>();
            *bc = c.iter().fold(*bc, |a, &b| a.max(b));
        }
    }

    /// The sums of `plane` with its contact `mask`, from the pixels (any sample type).
    pub fn of(plane: &Plane, mask: &Mask) -> TileSums {
        let (w, h) = (plane.width, plane.height);
        let mut t = TileSums::empty(w, h);
        for y in 0..h {
            let row = (y / TILE) * t.tw;
            for x in 0..w {
                let (i, k) = (y * w + x, row + x / TILE);
                t.contact[k] += u8::from(mask.data[i] != 0);
                let v = plane.value(i);
                if v.is_finite() {
                    t.n[k] += 1.0;
                    t.sum[k] += v;
                }
            }
        }
        for ty in 0..t.th {
            t.add_to_blocks(ty);
        }
        t
    }

    /// Add one row of tiles from its columns' sums (`rows` pixel rows deep).
    fn add_tile_row(&mut self, ty: usize, rows: usize, sum: &[u32], contact: &[u8], offset: f64) {
        let k0 = ty * self.tw;
        let full_tiles = sum.len() / TILE;
        let pixels = (rows * TILE) as f64;
        let n = &mut self.n[k0..k0 + self.tw];
        let s = &mut self.sum[k0..k0 + self.tw];
        let c = &mut self.contact[k0..k0 + self.tw];
        for (tx, (col, cnt)) in sum
            .chunks_exact(TILE)
            .zip(contact.chunks_exact(TILE))
            .enumerate()
        {
            n[tx] = pixels;
            s[tx] = f64::from(col[0] + col[1] + col[2] + col[3]) + pixels * offset;
            c[tx] = cnt[0] + cnt[1] + cnt[2] + cnt[3];
        }
        if full_tiles < self.tw {
            let rest = full_tiles * TILE..sum.len();
            let pixels = (rows * rest.len()) as f64;
            n[full_tiles] = pixels;
            s[full_tiles] = f64::from(sum[rest.clone()].iter().sum::<u32>()) + pixels * offset;
            c[full_tiles] = contact[rest].iter().sum();
        }
    }
}

/// [`super::classify_codes`] for integer codes of a `width`-pixel-wide image, with the tile
/// sums made in the same pass: each pixel is compared, counted, summed into its class and into
/// its column's running sums, row by row (a loop the compiler vectorises); every [`TILE`] rows
/// the columns are added up into tiles. Exactly the classification and class sums of the plain
/// loop (a test checks).
pub(super) fn classify_codes_tiled(
    codes: &[u16],
    width: usize,
    offset: i32,
    code_threshold: i64,
    mask: &mut [u8],
) -> (ClassSums, ClassSums, TileSums) {
    let height = codes.len().checked_div(width).unwrap_or(0);
    if !(0..i64::from(u16::MAX)).contains(&code_threshold) || width == 0 {
        // Everything or nothing is contact: the plain loop, then the tiles from its mask.
        let (c, b) = super::classify_codes(codes, offset, code_threshold, mask);
        let plane = Plane::from_u16(width, height, codes.to_vec());
        let mut t = TileSums::of(
            &plane,
            &Mask {
                width,
                height,
                data: mask.to_vec(),
            },
        );
        if offset != 0 {
            for (s, n) in t.sum.iter_mut().zip(&t.n) {
                *s += n * f64::from(offset);
            }
            for (s, n) in t.block_sum.iter_mut().zip(&t.block_n) {
                *s += n * f64::from(offset);
            }
        }
        return (c, b, t);
    }
    let k = code_threshold as u16;
    let mut tiles = TileSums::empty(width, height);
    let mut col_sum = vec![0u32; width];
    let mut col_contact = vec![0u8; width];
    let (mut n_contact, mut s_contact, mut s_all) = (0u64, 0u64, 0u64);
    for ty in 0..tiles.th {
        col_sum.fill(0);
        col_contact.fill(0);
        let (y0, y1) = (ty * TILE, ((ty + 1) * TILE).min(height));
        for y in y0..y1 {
            let row = &codes[y * width..(y + 1) * width];
            let mrow = &mut mask[y * width..(y + 1) * width];
            // Segments of at most SUM_BLOCK pixels keep the u32 class sums exact.
            // One loop: the pixel's class, the class sums and its column's running sums.
            for start in (0..width).step_by(SUM_BLOCK) {
                let end = (start + SUM_BLOCK).min(width);
                let (mut n, mut sc, mut sa) = (0u32, 0u32, 0u32);
                for (((m, &c), s), cc) in mrow[start..end]
                    .iter_mut()
                    .zip(&row[start..end])
                    .zip(&mut col_sum[start..end])
                    .zip(&mut col_contact[start..end])
                {
                    let is_contact = u8::from(c > k);
                    *m = is_contact;
                    *cc += is_contact;
                    *s += u32::from(c);
                    n += u32::from(is_contact);
                    sc += u32::from(c) * u32::from(is_contact);
                    sa += u32::from(c);
                }
                n_contact += u64::from(n);
                s_contact += u64::from(sc);
                s_all += u64::from(sa);
            }
        }
        tiles.add_tile_row(ty, y1 - y0, &col_sum, &col_contact, f64::from(offset));
        tiles.add_to_blocks(ty);
    }
    let (contact, background) =
        super::class_sums(codes.len() as u64, n_contact, s_contact, s_all, offset);
    (contact, background, tiles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fused_pass_gives_the_plain_classification_and_the_tiles() {
        // 13 × 7 codes over the whole u16 range (tiles cut at the right and bottom edges).
        let (w, h) = (13, 7);
        let codes: Vec<u16> = (0..w * h)
            .map(|i| ((i as u64 * 2_654_435_761) % 65_536) as u16)
            .collect();
        for k in [-1i64, 0, 1000, 40_000, 65_535] {
            let mut plain = vec![9u8; w * h];
            let (c0, b0) = super::super::classify_codes(&codes, 0, k, &mut plain);
            let mut fused = vec![9u8; w * h];
            let (c1, b1, t) = classify_codes_tiled(&codes, w, 0, k, &mut fused);
            assert_eq!(plain, fused, "k = {k}");
            assert_eq!(
                (c0.count, c0.sum, b0.count, b0.sum),
                (c1.count, c1.sum, b1.count, b1.sum)
            );
            let reference = TileSums::of(
                &Plane::from_u16(w, h, codes.clone()),
                &Mask {
                    width: w,
                    height: h,
                    data: plain.clone(),
                },
            );
            assert_eq!(t, reference, "k = {k}");
            assert_eq!((t.tw, t.th), (4, 2));
            assert_eq!(t.n.iter().sum::<f64>(), (w * h) as f64);
        }
    }
}
