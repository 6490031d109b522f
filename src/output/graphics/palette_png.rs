//! An indexed PNG, a few colours fitted to the scene, for kitty under a rate: kitty decodes
//! any PNG libpng reads, palette PNGs of 1 to 8 bits a pixel among them, and has no JPEG.
//!
//! **Why a palette.** Under a rate the measure that counts is pictures a second at the
//! rung (issue 29, `docs/pixels/block-codec.md`): a picture one frame old scores far below a
//! fresh one. The lossy PNG (`lossy_png`, step 24) cost about 0.8 bytes a pixel of the bench's
//! water at 480x282, so 2 MB/s paid for 15 pictures a second; 16 colours fitted to the water
//! cost about a third of that (an index of 4 bits a pixel, few distinct values, long runs) at
//! a smaller luma error than the step of 24 (luma RMS 3.8 against 3.7 on the golden pool at
//! 0.20 against 0.27 bytes a pixel; 32 colours 2.4 at 0.25).
//!
//! **The palette** is sixel's fit (`sixel::fit`: median cut and k-means in OKLab over a fixed
//! subsample) mapped through sixel's lookup (`sixel::lookup`: a table from colour to index,
//! nearest by luma-weighted RGB), without a dither (a position-stable Bayer dither cost 10 to
//! 15 % more bytes and scored lower: see the docs). It is fitted once and again only when the
//! picture's colours drift from it by sixel's `DRIFT`, or when another number of colours is
//! asked for; every PNG carries its palette, so a refit needs nothing else. The colours are
//! sorted by luma (neighbouring indices are neighbouring shades), and the rows go unfiltered
//! (filter type 0): on indices Sub, Paeth and the per-row choice all cost more.
//!
//! The pixels are rewritten in place to the palette's colours, what the decoder shows, so the
//! caller's model of the terminal is exact. Deterministic: the fit and the lookup are (fixed
//! orders, IEEE basic operations), the rest is integers in raster order.

use super::deflate::Zlib;
use super::lossy_png::chunk;
use super::sixel::lookup::ColourMap;
use super::sixel::{DRIFT, fit};

/// The deflate level: as the lossy PNG's.
const LEVEL: u32 = 4;

/// [`Encoder::encode`] with a new encoder (a palette fitted to this picture alone).
///
/// # Panics
/// When `rgb` does not hold `width x height` pixels.
pub fn encode(rgb: &mut [u8], width: u32, height: u32, colours: u16, out: &mut Vec<u8>) {
    Encoder::default().encode(rgb, width, height, colours, out);
}

/// A palette PNG encoder: the fitted palette and its lookup, kept from picture to picture, and
/// the scratch buffers.
#[derive(Default)]
pub struct Encoder {
    /// The colours asked for, the palette (sorted by luma), its lookup and the picture's mean
    /// error right after the fit.
    fitted: Option<Fitted>,
    /// The filter type byte and the packed indices of every row.
    rows: Vec<u8>,
    zlib: Zlib,
    idat: Vec<u8>,
}

struct Fitted {
    asked: u16,
    palette: Vec<[u8; 3]>,
    map: ColourMap,
    error: f32,
}

impl std::fmt::Debug for Encoder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let colours = self.fitted.as_ref().map(|f| f.palette.len());
        f.debug_struct("Encoder").field("colours", &colours).finish_non_exhaustive()
    }
}

impl Encoder {
    /// Rewrites `rgb` (`width x height`, 3 bytes a pixel) to the colours of a palette of at
    /// most `colours` (clamped to 2..=256) fitted to the scene and writes that indexed PNG into
    /// `out` (cleared first).
    ///
    /// # Panics
    /// When `rgb` does not hold `width x height` pixels.
    pub fn encode(&mut self, rgb: &mut [u8], width: u32, height: u32, colours: u16, out: &mut Vec<u8>) {
        let (w, h) = (width as usize, height as usize);
        assert_eq!(rgb.len(), w * h * 3, "RGB buffer does not match {width}x{height}");
        let colours = colours.clamp(2, 256);
        let Fitted { palette, map, .. } = fit_to(&mut self.fitted, rgb, colours);
        // The fewest bits a pixel PNG allows for the palette: 1, 2, 4 or 8.
        let bits = [1usize, 2, 4, 8].into_iter().find(|b| palette.len() <= 1 << b).unwrap_or(8);
        let per_byte = 8 / bits;
        let row_bytes = w.div_ceil(per_byte);
        self.rows.clear();
        self.rows.resize((row_bytes + 1) * h, 0);
        for (row, out_row) in rgb.chunks_exact_mut(w * 3).zip(self.rows.chunks_exact_mut(row_bytes + 1)) {
            // Filter type 0 (none), then the indices packed from the high bits down.
            let packed = &mut out_row[1..];
            for (x, px) in row.chunks_exact_mut(3).enumerate() {
                let index = map.register([px[0], px[1], px[2]], ColourMap::MIDDLE);
                px.copy_from_slice(&palette[usize::from(index)]);
                packed[x / per_byte] |= index << (8 - bits - (x % per_byte) * bits);
            }
        }
        out.clear();
        out.extend_from_slice(b"\x89PNG\r\n\x1a\n");
        let mut header = [0u8; 13];
        header[..4].copy_from_slice(&width.to_be_bytes());
        header[4..8].copy_from_slice(&height.to_be_bytes());
        header[8..].copy_from_slice(&[bits as u8, 3, 0, 0, 0]); // palette, deflate, adaptive filters, no interlace
        chunk(out, b"IHDR", &header);
        chunk(out, b"PLTE", palette.as_flattened());
        self.zlib.compress(&self.rows, LEVEL, &mut self.idat);
        chunk(out, b"IDAT", &self.idat);
        chunk(out, b"IEND", &[]);
    }
}

/// The palette for `rgb`: the one kept, unless it was fitted for another number of colours
/// or the picture's colours have drifted from it (sixel's rule), then a new fit.
fn fit_to<'a>(fitted: &'a mut Option<Fitted>, rgb: &[u8], colours: u16) -> &'a mut Fitted {
    let keep = match fitted {
        Some(f) => f.asked == colours && f.map.error(rgb, 3) <= f.error + DRIFT,
        None => false,
    };
    if !keep {
        let mut palette = fit::fit(&fit::subsample(rgb, 3), usize::from(colours));
        if palette.is_empty() {
            palette.push([0, 0, 0]);
        }
        // By luma (BT.601 weights in integers), then by colour: a total order.
        palette.sort_by_key(|c| (77 * u32::from(c[0]) + 150 * u32::from(c[1]) + 29 * u32::from(c[2]), *c));
        let mut map = ColourMap::of_colours(&palette);
        let error = map.error(rgb, 3);
        *fitted = Some(Fitted { asked: colours, palette, map, error });
    }
    fitted.as_mut().expect("fitted above")
}

#[cfg(test)]
mod tests;
