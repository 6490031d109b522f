//! From colour to register for any palette: a table indexed by the colour's top six bits a
//! channel (64x64x64 entries), each filled the first time a pixel falls in it with the
//! register nearest the cell's centre, and an ordered dither that works along the grey axis.
//!
//! **Nearest by luma-weighted RGB.** The palette is fitted in OKLab (perceptual clusters), but
//! a pixel is mapped by the squared sRGB difference weighted by each channel's share of luma
//! (0.30, 0.59, 0.11): the same space the dither moves pixels in, so a dithered area keeps its
//! mean (in OKLab a grey halfway between black and white is nearer white, and a two-colour
//! dither of it comes out light), and luma, what the eye resolves finest, is kept best.
//!
//! **The table.** A fitted palette has no structure to compute a register from, and a search
//! over 256 colours for each of a million screen pixels would cost about a second; the table
//! makes it a load. It is filled lazily (a picture of water touches a few thousand of its
//! 262,144 cells), and what a cell holds depends only on the palette, so the order pixels come
//! in changes nothing. Six bits a channel: a cell is 4 levels wide, under the dither's step.
//!
//! **The dither.** Each pixel is moved along the grey axis by an offset taken from an 8x8
//! Bayer matrix at its screen position before its register is looked up, the offsets spanning
//! one typical step between neighbouring palette colours ([`ColourMap::spread`]). So an area
//! between two registers shows a fine mix of both whose mean is its colour, and a pixel's
//! register depends only on its colour and position: an unchanged block gives the same
//! registers, and the same bytes, every frame (error diffusion would carry changes from
//! anywhere above and left of it).

use super::SixelPalette;
use crate::output::oklab;

/// Bits a channel the table is indexed by.
const BITS: u32 = 6;
/// An empty table cell.
const EMPTY: u16 = u16::MAX;
/// The side of the Bayer matrix.
pub const BAYER_SIDE: usize = 8;
/// Pixels the drift measure looks at (a regular subsample).
const DRIFT_SAMPLES: usize = 1024;
/// The dither's offsets span this many typical steps between palette colours.
const SPREAD_STEPS: f32 = 1.0;

/// 8x8 Bayer thresholds, 0..64.
pub const BAYER8: [[u8; 8]; 8] = [
    [0, 32, 8, 40, 2, 34, 10, 42],
    [48, 16, 56, 24, 50, 18, 58, 26],
    [12, 44, 4, 36, 14, 46, 6, 38],
    [60, 28, 52, 20, 62, 30, 54, 22],
    [3, 35, 11, 43, 1, 33, 9, 41],
    [51, 19, 59, 27, 49, 17, 57, 25],
    [15, 47, 7, 39, 13, 45, 5, 37],
    [63, 31, 55, 23, 61, 29, 53, 21],
];

/// The table from colour to register, and the dither's offsets, for one palette.
#[derive(Debug)]
pub struct ColourMap {
    /// Each register's colour as shown, in OKLab (the drift measure) and in sRGB (the map).
    labs: Vec<oklab::Lab>,
    rgbs: Vec<[f32; 3]>,
    /// 64x64x64 registers (`EMPTY` until first used).
    table: Vec<u16>,
    /// The grey-axis offset for each Bayer threshold, in 8-bit levels.
    offsets: [i16; 64],
    /// The offsets along each row of the Bayer matrix, one a channel (three a pixel).
    row_offsets: [[i16; 3 * BAYER_SIDE]; BAYER_SIDE],
    /// A row's channels moved by their offsets and cut to the table's bits.
    quantized: Vec<u8>,
}

impl ColourMap {
    /// The map for `palette`: an empty table and offsets that span its typical step.
    pub fn new(palette: &SixelPalette) -> ColourMap {
        let colours: Vec<[u8; 3]> = (0..palette.len()).map(|i| palette.rgb(i as u8)).collect();
        Self::of_colours(&colours)
    }

    /// The map for registers of these sRGB colours (at most 256): what [`ColourMap::new`]
    /// makes of a sixel palette as shown, and kitty's palette PNG (`palette_png`) of its own.
    pub fn of_colours(colours: &[[u8; 3]]) -> ColourMap {
        let labs = colours.iter().map(|&c| oklab::from_rgb(c)).collect();
        let rgbs: Vec<[f32; 3]> = colours.iter().map(|c| c.map(f32::from)).collect();
        let spread = Self::spread(&rgbs) * SPREAD_STEPS;
        let offsets = std::array::from_fn(|t| (((t as f32 + 0.5) / 64.0 - 0.5) * spread).round() as i16);
        let row_offsets = BAYER8.map(|row| std::array::from_fn(|k| offsets[usize::from(row[k / 3])]));
        ColourMap { labs, rgbs, table: vec![EMPTY; 1 << (3 * BITS)], offsets, row_offsets, quantized: Vec::new() }
    }

    /// The palette's typical step: the median distance (luma-weighted, in 8-bit levels: a
    /// move of `d` along the grey axis is a distance of `d`) from a colour (`colours`, its
    /// registers as shown) to its nearest neighbour. 17 for the 6x7x6 cube (its blue step); a
    /// few levels for a palette fitted to water.
    fn spread(colours: &[[f32; 3]]) -> f32 {
        let mut steps: Vec<f32> = colours
            .iter()
            .enumerate()
            .filter_map(|(i, a)| {
                colours
                    .iter()
                    .enumerate()
                    .filter(|&(j, _)| j != i)
                    .map(|(_, b)| distance2(*a, *b))
                    .min_by(f32::total_cmp)
            })
            .map(f32::sqrt)
            .collect();
        if steps.is_empty() {
            return 0.0;
        }
        let mid = steps.len() / 2;
        *steps.select_nth_unstable_by(mid, f32::total_cmp).1
    }

    /// The register for a pixel of colour `[r, g, b]` at Bayer threshold `t` (0..64).
    #[inline]
    pub fn register(&mut self, [r, g, b]: [u8; 3], t: usize) -> u8 {
        let o = self.offsets[t];
        let q = |v: u8| ((i16::from(v) + o).clamp(0, 255) as usize) >> (8 - BITS);
        let cell = q(r) << (2 * BITS) | q(g) << BITS | q(b);
        match self.table[cell] {
            EMPTY => self.fill(cell),
            reg => reg as u8,
        }
    }

    /// The registers of row `y` of a picture one pixel a screen pixel (`rgb`, 3 bytes a pixel)
    /// into `out` (one a pixel): [`ColourMap::register`] of each pixel at its Bayer threshold,
    /// in two passes: the channels moved and cut to the table's bits in a loop along the row
    /// that the compiler vectorizes, then a table load a pixel (one pass doing both was scalar).
    #[inline(always)]
    pub fn registers_row(&mut self, rgb: &[u8], y: usize, out: &mut [u8]) {
        let offsets = &self.row_offsets[y % BAYER_SIDE];
        self.quantized.resize(rgb.len(), 0);
        for (q, p) in self.quantized.chunks_mut(3 * BAYER_SIDE).zip(rgb.chunks(3 * BAYER_SIDE)) {
            for ((q, &v), &o) in q.iter_mut().zip(p).zip(offsets) {
                *q = ((i16::from(v) + o).clamp(0, 255) >> (8 - BITS)) as u8;
            }
        }
        let quantized = std::mem::take(&mut self.quantized);
        for (o, q) in out.iter_mut().zip(quantized.chunks_exact(3)) {
            let cell = usize::from(q[0]) << (2 * BITS) | usize::from(q[1]) << BITS | usize::from(q[2]);
            *o = match self.table[cell] {
                EMPTY => self.fill(cell),
                reg => reg as u8,
            };
        }
        self.quantized = quantized;
    }

    /// The register nearest the centre of table cell `cell`, stored there.
    #[cold]
    fn fill(&mut self, cell: usize) -> u8 {
        let mask = (1 << BITS) - 1;
        let centre = |shift: u32| (((cell >> shift) & mask) << (8 - BITS) | 1 << (7 - BITS)) as u8;
        let rgb = [centre(2 * BITS), centre(BITS), centre(0)].map(f32::from);
        let mut best = (f32::INFINITY, 0u16);
        for (i, &c) in self.rgbs.iter().enumerate() {
            let d = distance2(rgb, c);
            if d < best.0 {
                best = (d, i as u16);
            }
        }
        let reg = best.1;
        self.table[cell] = reg;
        reg as u8
    }

    /// How far the picture `pixels` (`bpp` bytes a pixel, RGB first) is from the palette: the
    /// mean OKLab distance from a regular subsample of its pixels to their registers (no
    /// dither). What [`super::SixelEncoder::fit_to`] compares with the fit's own error to see
    /// the colours drift.
    pub fn error(&mut self, pixels: &[u8], bpp: usize) -> f32 {
        let n = pixels.len() / bpp;
        if n == 0 {
            return 0.0;
        }
        let step = n.div_ceil(DRIFT_SAMPLES).max(1);
        let (mut sum, mut count) = (0f32, 0u32);
        for i in (0..n).step_by(step) {
            let rgb = [pixels[i * bpp], pixels[i * bpp + 1], pixels[i * bpp + 2]];
            let reg = self.register(rgb, Self::MIDDLE);
            sum += oklab::from_rgb(rgb).distance2(self.labs[usize::from(reg)]).sqrt();
            count += 1;
        }
        sum / count as f32
    }

    /// A threshold whose offset is (about) zero: the undithered register.
    pub const MIDDLE: usize = 32;
}

/// The luma-weighted squared distance of two sRGB colours.
#[inline]
fn distance2(a: [f32; 3], b: [f32; 3]) -> f32 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    0.30 * d[0] * d[0] + 0.59 * d[1] * d[1] + 0.11 * d[2] * d[2]
}
