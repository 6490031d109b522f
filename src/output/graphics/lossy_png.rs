//! A lossy PNG any PNG decoder reads: the picture is predicted as PNG's own Average filter
//! predicts it (each byte from the mean of its left and upper neighbours), and the difference
//! is rounded to a multiple of a step `q` before it is written, the prediction made from the
//! pixels as the decoder will rebuild them (closed-loop DPCM). Every written difference is then
//! one of about `256 / q` values crowded around 0, which deflate codes in a few bits where the
//! full differences of rendered water took five to six: kitty (which decodes PNG and raw RGB,
//! no JPEG) gets a picture several times smaller for an error of at most `q / 2` a channel.
//!
//! Flat regions start right: the first pixel of every row is written exactly, and the first
//! row is predicted from its left neighbour alone (PNG's Sub filter) rather than from the
//! mean with a row of zeros above. A flat run keeps the value it starts from (its differences
//! round to 0), so a letterbox bar or a still flat area comes out exact, where starting from a
//! rounded first pixel (and, on the first row, a prediction halved towards 0 at every pixel)
//! left it off by up to half a step for as long as the picture was lossy (a dark bar tinted
//! teal: `[0, 24, 31]` for `[8, 12, 20]` at step 24).
//!
//! The pixels are rewritten in place to what the decoder shows, so the caller's model of the
//! terminal is exact. Deterministic: integers only, one pass in raster order; the same pixels
//! give the same bytes. `q = 1` is lossless (the filter alone).

use super::deflate::Zlib;

/// PNG's Sub filter type (the first row: the left neighbour alone).
const SUB: u8 = 1;
/// PNG's Average filter type (every other row).
const AVERAGE: u8 = 3;

/// The deflate level (1..=9): the differences are few distinct values, so a middling level finds most
/// of what there is (level 6 and 9 differ by under a percent on water).
const LEVEL: u32 = 4;

/// Rewrites `rgb` (`width x height`, 3 bytes a pixel) to the picture the decoder will show and
/// writes that PNG (8-bit RGB, the Sub filter on the first row and the Average filter on the
/// others) into `out` (cleared first).
/// `q` (at least 1) is the step differences are rounded to. A caller that encodes a picture a
/// frame keeps an [`Encoder`] instead: the same bytes without its buffers made anew each time.
///
/// # Panics
/// When `rgb` does not hold `width x height` pixels.
pub fn encode(rgb: &mut [u8], width: u32, height: u32, q: u8, out: &mut Vec<u8>) {
    Encoder::default().encode(rgb, width, height, q, out);
}

/// [`encode`] with its scratch kept from picture to picture: the filtered bytes (a picture's
/// size), the step's table and the deflate state (a few hundred kilobytes), which were each
/// allocated, and the large ones zeroed, for every picture a stream sent (issue 29, Round 9 of
/// `docs/pixels/block-codec.md`). The bytes are those of [`encode`]: the compressor is reset
/// to the state of a new one, and is fed the same way.
#[derive(Default)]
pub struct Encoder {
    /// The filter type byte and the filtered bytes of every row.
    filtered: Vec<u8>,
    /// The table of the last step.
    steps: Option<Steps>,
    /// The compressor, and its output (the IDAT's data).
    zlib: Zlib,
    idat: Vec<u8>,
}

impl std::fmt::Debug for Encoder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Encoder").field("filtered", &self.filtered.len()).finish_non_exhaustive()
    }
}

impl Encoder {
    /// As [`encode`].
    ///
    /// # Panics
    /// When `rgb` does not hold `width x height` pixels.
    pub fn encode(&mut self, rgb: &mut [u8], width: u32, height: u32, q: u8, out: &mut Vec<u8>) {
        let (w, h) = (width as usize, height as usize);
        assert_eq!(rgb.len(), w * h * 3, "RGB buffer does not match {width}x{height}");
        let q = i32::from(q.max(1));
        let steps = match &mut self.steps {
            Some(s) if s.q == q => s,
            slot => slot.insert(Steps::new(q)),
        };
        let stride = w * 3;
        // Every byte is written below: only a larger picture than before fills.
        self.filtered.resize((stride + 1) * h, 0);
        for (y, out_row) in self.filtered.chunks_exact_mut(stride + 1).enumerate() {
            let (above, row) = rgb.split_at_mut(y * stride);
            if y == 0 {
                out_row[0] = SUB;
                filter_row::<false>(&mut row[..stride], &[], &mut out_row[1..], steps);
            } else {
                out_row[0] = AVERAGE;
                filter_row::<true>(&mut row[..stride], &above[(y - 1) * stride..][..stride], &mut out_row[1..], steps);
            }
        }
        out.clear();
        out.extend_from_slice(b"\x89PNG\r\n\x1a\n");
        let mut header = [0u8; 13];
        header[..4].copy_from_slice(&width.to_be_bytes());
        header[4..8].copy_from_slice(&height.to_be_bytes());
        header[8..].copy_from_slice(&[8, 2, 0, 0, 0]); // 8 bits, RGB, deflate, adaptive filters, no interlace
        chunk(out, b"IHDR", &header);
        self.zlib.compress(&self.filtered, LEVEL, &mut self.idat);
        chunk(out, b"IDAT", &self.idat);
        chunk(out, b"IEND", &[]);
    }
}

/// Rewrites one row to what the decoder rebuilds and writes its filtered bytes into `out`:
/// with `AVG` PNG's Average filter (`up`: the row above as rebuilt), without it the Sub filter
/// (the first row; `up` is not read). The first pixel is written exactly (its prediction is
/// PNG's: half the pixel above, or 0), so a flat run starts right. The prediction of each
/// other byte depends on the byte just rebuilt to its left, so the loop is a chain of a table
/// look-up and a few additions a byte (no division), the left pixel kept in registers.
#[inline(always)]
fn filter_row<const AVG: bool>(row: &mut [u8], up: &[u8], out: &mut [u8], steps: &Steps) {
    let Some((first, rest)) = row.split_at_mut_checked(3) else { return };
    let mut left = [0i32; 3];
    for c in 0..3 {
        let predicted = if AVG { i32::from(up[c]) / 2 } else { 0 };
        left[c] = i32::from(first[c]);
        out[c] = (left[c] - predicted) as u8;
    }
    let (rest, out) = (rest.as_chunks_mut::<3>().0, out[3..].as_chunks_mut::<3>().0);
    if AVG {
        filter_rest::<true>(rest, up[3..].as_chunks::<3>().0.iter(), out, left, steps);
    } else {
        filter_rest::<false>(rest, std::iter::repeat(&[0; 3]), out, left, steps);
    }
}

/// The pixels after the first of [`filter_row`]'s row, `left` the first as rebuilt: one loop
/// for both filters (with `AVG` the prediction is the mean of the left and upper bytes, without
/// it the left byte alone; `above` is then never read).
#[inline(always)]
fn filter_rest<'a, const AVG: bool>(
    row: &mut [[u8; 3]],
    above: impl Iterator<Item = &'a [u8; 3]>,
    out: &mut [[u8; 3]],
    mut left: [i32; 3],
    steps: &Steps,
) {
    for ((px, above), filtered) in row.iter_mut().zip(above).zip(out) {
        for c in 0..3 {
            let predicted = if AVG { (left[c] + i32::from(above[c])) / 2 } else { left[c] };
            let value = steps.quantise(i32::from(px[c]), predicted);
            px[c] = value as u8;
            filtered[c] = (value - predicted) as u8;
            left[c] = value;
        }
    }
}

/// [`quantise`] for one step `q` as a table of the rounded difference for each difference
/// (-255..=255): the same values, without a division a byte.
struct Steps {
    q: i32,
    rounded: [i16; 511],
}

impl Steps {
    fn new(q: i32) -> Steps {
        let mut rounded = [0i16; 511];
        for (d, r) in (-255..=255).zip(rounded.iter_mut()) {
            *r = round_to(d, q) as i16;
        }
        Steps { q, rounded }
    }

    /// [`quantise`]`(value, predicted, q)`, both within 0..=255.
    #[inline(always)]
    fn quantise(&self, value: i32, predicted: i32) -> i32 {
        let v = predicted + i32::from(self.rounded[(value - predicted + 255) as usize]);
        // The rounded value is within half a step of `value` (0..=255), so one step back in
        // range is enough (the loops of [`quantise`] run at most once), and without a branch.
        v - self.q * i32::from(v > 255) + self.q * i32::from(v < 0)
    }
}

/// `d` rounded to the nearest multiple of `q` (halves away from zero).
fn round_to(d: i32, q: i32) -> i32 {
    if d >= 0 { (d + q / 2) / q * q } else { -((-d + q / 2) / q * q) }
}

/// The value nearest `value` that `predicted` plus a multiple of `q` reaches within 0..=255.
#[cfg(test)]
fn quantise(value: i32, predicted: i32, q: i32) -> i32 {
    if q == 1 {
        return value;
    }
    let d = value - predicted;
    // Rounded to the nearest multiple (halves away from zero), then kept within a byte.
    let k = if d >= 0 { (d + q / 2) / q } else { -((-d + q / 2) / q) };
    let mut v = predicted + k * q;
    while v > 255 {
        v -= q;
    }
    while v < 0 {
        v += q;
    }
    v
}

/// Appends a PNG chunk: length, type, data, CRC of type and data.
pub(super) fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let mut crc = flate2::Crc::new();
    crc.update(kind);
    crc.update(data);
    out.extend_from_slice(&crc.sum().to_be_bytes());
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::graphics::pack::{Packing, pack};
    use crate::output::graphics::test_pictures::golden_pool;

    #[test]
    fn decoders_read_exactly_the_rewritten_pixels_within_a_step() {
        let (w, h, rgb) = golden_pool();
        let mut lossless = Vec::new();
        pack(Packing::Png, &rgb, w, h, &mut lossless);
        let mut sizes = Vec::new();
        for q in [1u8, 4, 8, 16] {
            let mut shown = rgb.clone();
            let mut png = Vec::new();
            encode(&mut shown, w, h, q, &mut png);
            let decoded = image::load_from_memory(&png).unwrap().to_rgb8().into_raw();
            assert!(decoded == shown, "q {q}: the decoder shows the rewritten pixels");
            let worst = shown.iter().zip(&rgb).map(|(a, b)| a.abs_diff(*b)).max().unwrap();
            assert!(worst <= q, "q {q}: {worst}");
            // Beyond half a step only where the rounding would leave 0..=255.
            let mean = shown.iter().zip(&rgb).map(|(a, b)| f64::from(a.abs_diff(*b))).sum::<f64>() / rgb.len() as f64;
            assert!(mean <= f64::from(q) / 2.0, "q {q}: mean error {mean}");
            if q == 1 {
                assert!(shown == rgb, "q 1 is lossless");
            }
            sizes.push(png.len());
        }
        assert!(sizes.windows(2).all(|s| s[1] < s[0]), "a coarser step costs fewer bytes: {sizes:?}");
        assert!(sizes[2] * 2 < lossless.len(), "q 8 at most half the lossless PNG: {sizes:?} vs {}", lossless.len());
    }

    #[test]
    fn a_kept_encoder_writes_what_a_new_one_writes() {
        let (w, h, rgb) = golden_pool();
        // Pictures of different sizes and steps one after another (a larger one after a
        // smaller, a step back to an earlier one): each picture's bytes and rewritten pixels
        // must be a new encoder's, whatever came before.
        let half = h / 2;
        let small = &rgb[..(w * half * 3) as usize];
        let mut kept = Encoder::default();
        for (pixels, height, q) in
            [(&rgb[..], h, 24), (small, half, 24), (&rgb[..], h, 8), (small, half, 1), (&rgb[..], h, 24)]
        {
            let (mut fresh, mut fresh_png) = (pixels.to_vec(), Vec::new());
            encode(&mut fresh, w, height, q, &mut fresh_png);
            let (mut again, mut again_png) = (pixels.to_vec(), vec![7; 5]);
            kept.encode(&mut again, w, height, q, &mut again_png);
            assert!(again_png == fresh_png, "{w}x{height} at step {q}: the PNG");
            assert!(again == fresh, "{w}x{height} at step {q}: the pixels shown");
        }
    }

    #[test]
    fn quantised_values_stay_in_a_byte_and_on_the_grid() {
        for q in [1, 2, 3, 8, 24, 31, 64] {
            let steps = Steps::new(q);
            for p in 0..=255 {
                for v in 0..=255 {
                    let r = quantise(v, p, q);
                    assert!((0..=255).contains(&r) && (r - p) % q == 0, "{v} from {p} by {q}: {r}");
                    assert!((r - v).abs() <= q, "{v} from {p} by {q}: {r}");
                    // The table the encoder uses gives the same values.
                    assert_eq!(steps.quantise(v, p), r, "{v} from {p} by {q}");
                }
            }
        }
    }

    #[test]
    fn flat_regions_start_right_and_stay_exact() {
        // The serve test's letterbox: a dark bar above and below the pool at 480x278, step 24.
        // The bars, and the flat run at the start of each row (the left column exact), come
        // out as the colour itself, not the colour rounded from a prediction of 0.
        let (w, h, pool) = golden_pool();
        let (bw, bh, bar) = (480u32, 278u32, [8u8, 12, 20]);
        let mut rgb = Vec::new();
        for y in 0..bh {
            for x in 0..bw {
                let inside = (4..bh - 4).contains(&y) && x >= 16;
                let at = (((y % h) * w + x % w) * 3) as usize;
                rgb.extend_from_slice(if inside { &pool[at..at + 3] } else { &bar });
            }
        }
        let (mut shown, mut png) = (rgb.clone(), Vec::new());
        encode(&mut shown, bw, bh, 24, &mut png);
        let decoded = image::load_from_memory(&png).unwrap().to_rgb8().into_raw();
        assert!(decoded == shown, "the decoder shows the rewritten pixels");
        let stride = bw as usize * 3;
        for y in 0..4 {
            let row = &shown[y * stride..][..stride];
            assert!(row.chunks_exact(3).all(|p| p == bar), "the bar's row {y}: {:?}", &row[..12]);
        }
        for y in 0..bh as usize {
            let left = &shown[y * stride..][..16 * 3];
            assert!(left.chunks_exact(3).all(|p| p == bar), "row {y}'s left bar: {:?}", &left[..12]);
        }
    }
}
