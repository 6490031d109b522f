//! The renderer's rows: each picture row is drawn as `grid` rows of pool cells (one cell a
//! fine pixel) into a scratch row that stays in the cache, then each `grid x grid` block is
//! averaged into the picture, so the fine picture never goes through memory.
//!
//! A fine row is drawn in staged spans ([`PoolRenderer::render_span`]): the positions and the
//! light in loops that vectorize, the texture fetches in a scalar loop, the filtering and the
//! lighting in a loop that vectorizes again. The two columns at each edge are drawn one pixel
//! at a time ([`PoolRenderer::pixel`], which clamps). Every loop is compiled for the widest
//! instruction set the CPU has ([`crate::simd`]); every path computes the same integers.

use super::{Fields, PoolRenderer, Rows, lerp_packed, light_pixel_always};
use crate::render::caustics;
use crate::simd::Tier;

/// Pixels per staged span (see [`PoolRenderer::render_span`]).
const SPAN: usize = 64;

/// The per-pixel values a span passes between its stages.
#[derive(Clone, Debug)]
struct SpanScratch {
    index: [u32; SPAN],
    fx: [u32; SPAN],
    fy: [u32; SPAN],
    light_index: [u32; SPAN],
    delta: [i32; SPAN],
    across: [i32; SPAN],
    along: [i32; SPAN],
    /// The texel at the position and its right neighbour, and the two below them, each pair
    /// in one word (see [`split`]).
    top: [u64; SPAN],
    bottom: [u64; SPAN],
    gain: [u8; SPAN],
}

impl Default for SpanScratch {
    fn default() -> Self {
        SpanScratch {
            index: [0; SPAN],
            fx: [0; SPAN],
            fy: [0; SPAN],
            light_index: [0; SPAN],
            delta: [0; SPAN],
            across: [0; SPAN],
            along: [0; SPAN],
            top: [0; SPAN],
            bottom: [0; SPAN],
            gain: [caustics::UNIT_GAIN; SPAN],
        }
    }
}

/// One parallel task's scratch, kept between frames: a span's stages and `grid` fine rows.
#[derive(Clone, Debug, Default)]
pub(super) struct RowScratch {
    span: Box<SpanScratch>,
    fine: Vec<u32>,
}

impl PoolRenderer {
    /// Draws the picture rows starting at `first_row` into `out` (whole rows of RGBA bytes of
    /// the picture, the background's size over the grid).
    pub(super) fn render_rows(&self, fields: Fields<'_>, first_row: usize, out: &mut [u8], scratch: &mut RowScratch) {
        match self.simd.tier() {
            // SAFETY: a `Simd` of this tier exists only when run-time detection found the
            // feature (see `crate::simd`).
            #[cfg(target_arch = "x86_64")]
            Tier::Avx512 => unsafe { self.render_rows_avx512(fields, first_row, out, scratch) },
            #[cfg(target_arch = "x86_64")]
            Tier::Avx2 => unsafe { self.render_rows_avx2(fields, first_row, out, scratch) },
            _ => self.render_rows_with(fields, first_row, out, scratch),
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn render_rows_avx2(&self, fields: Fields<'_>, first_row: usize, out: &mut [u8], scratch: &mut RowScratch) {
        self.render_rows_with(fields, first_row, out, scratch)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512bw")]
    fn render_rows_avx512(&self, fields: Fields<'_>, first_row: usize, out: &mut [u8], scratch: &mut RowScratch) {
        self.render_rows_with(fields, first_row, out, scratch)
    }

    #[inline(always)]
    fn render_rows_with(&self, fields: Fields<'_>, first_row: usize, out: &mut [u8], scratch: &mut RowScratch) {
        let w = self.background.width() as usize;
        let grid = self.grid as usize;
        let RowScratch { span, fine } = scratch;
        fine.resize(w * grid, 0);
        for (i, out_row) in out.chunks_exact_mut(w / grid * 4).enumerate() {
            let y = (first_row + i) * grid;
            for (j, fine_row) in fine.chunks_exact_mut(w).enumerate() {
                self.render_fine_row(fields, y + j, fine_row, span);
            }
            match grid {
                1 => copy_row(fine, out_row),
                2 => mean_of_blocks_packed::<2>(fine, out_row),
                4 => mean_of_blocks_packed::<4>(fine, out_row),
                g => mean_of_blocks(fine, g, out_row),
            }
        }
    }

    /// Fine row `y` (the background's width) into `out`.
    #[inline(always)]
    fn render_fine_row<'a>(&self, fields: Fields<'a>, y: usize, out: &mut [u32], scratch: &mut SpanScratch) {
        let (w, h) = (self.background.width() as usize, self.background.height() as usize);
        // Rows y-2..=y+2 of both fields, the picture's edge rows repeated beyond it.
        let around = |heights: &'a [i16]| {
            [-2isize, -1, 0, 1, 2].map(|dy| {
                let r = (y as isize + dy).clamp(0, h as isize - 1) as usize;
                &heights[r * w..(r + 1) * w]
            })
        };
        let rows = Rows { refraction: around(fields.refraction), light: around(fields.light) };
        // Columns two or more away from the edges need no clamping: they go through the
        // staged span renderer in chunks; the edge columns one pixel at a time.
        let inner = 2..w.saturating_sub(2).max(2);
        for x in (0..w).filter(|x| !inner.contains(x)) {
            let near = [x.saturating_sub(2), x.saturating_sub(1), (x + 1).min(w - 1), (x + 2).min(w - 1)];
            out[x] = self.pixel(&rows, x, y, near);
        }
        let mut start = inner.start;
        while start < inner.end {
            let end = (start + SPAN).min(inner.end);
            self.render_span(&rows, y, start, &mut out[start..end], scratch);
            start = end;
        }
    }

    /// Interior pixels `x0..x0 + out.len()` of row `y` (all at least two columns from the
    /// edges), in stages: positions and light in one loop, the texture fetches in a second,
    /// filtering and lighting in a third. The first and last are free of branches and
    /// clamped indexing, so the compiler vectorizes them; only the fetches stay scalar.
    /// Computes exactly what [`PoolRenderer::pixel`] does.
    #[inline(always)]
    fn render_span(&self, rows: &Rows<'_>, y: usize, x0: usize, out: &mut [u32], scratch: &mut SpanScratch) {
        let (w, h) = (self.background.width() as i32, self.background.height() as i32);
        let n = out.len();
        let [_, up, mid, down, _] = rows.refraction.map(|r| &r[x0 - 2..x0 + n + 2]);
        let (m1, p1) = (&mid[1..n + 1], &mid[3..n + 3]);
        let (u1, d1) = (&up[2..n + 2], &down[2..n + 2]);
        let [up2, up, mid, down, down2] = rows.light.map(|r| &r[x0 - 2..x0 + n + 2]);
        let q = self.refraction_q8;
        let SpanScratch { index, fx, fy, light_index, delta, across, along, top, bottom, gain } = scratch;
        // Every slice exactly `n` long, so the loops below carry no bounds checks.
        let (index, fx, fy) = (&mut index[..n], &mut fx[..n], &mut fy[..n]);
        let (light_index, delta, across, along) =
            (&mut light_index[..n], &mut delta[..n], &mut across[..n], &mut along[..n]);
        let (top, bottom, gain) = (&mut top[..n], &mut bottom[..n], &mut gain[..n]);
        let (lm2, lm1, lp1, lp2) = (&mid[..n], &mid[1..n + 1], &mid[3..n + 3], &mid[4..n + 4]);
        let (lu2, lu1, ld1, ld2) = (&up2[2..n + 2], &up[2..n + 2], &down[2..n + 2], &down2[2..n + 2]);
        let (lw, lshift) = (self.light.width as i32, self.light.shift);
        let (shift_x, shift_y) = self.light_shift;
        let lighting = self.lighting;
        for i in 0..n {
            let x = (x0 + i) as i32;
            let xoff = i32::from(m1[i]) - i32::from(p1[i]);
            let yoff = i32::from(u1[i]) - i32::from(d1[i]);
            let sx = ((x << 8) + xoff * q).clamp(0, (w - 1) << 8);
            let sy = (((y as i32) << 8) + yoff * q).clamp(0, (h - 1) << 8);
            let (tx, ty) = (sx >> 8, sy >> 8);
            // The texel's index.
            index[i] = (ty * w + tx) as u32;
            fx[i] = (sx & 255) as u32;
            fy[i] = (sy & 255) as u32;
            let lx = (tx - shift_x).clamp(0, w - 1) >> lshift;
            let ly = (ty - shift_y).clamp(0, h - 1) >> lshift;
            light_index[i] = (ly * lw + lx) as u32;
            across[i] = i32::from(lm2[i]) + i32::from(lm1[i]) - i32::from(lp1[i]) - i32::from(lp2[i]);
            along[i] = i32::from(lu2[i]) + i32::from(lu1[i]) - i32::from(ld1[i]) - i32::from(ld2[i]);
            delta[i] = ((across[i] * lighting.shade_x_q8 + along[i] * lighting.shade_y_q8) >> 8)
                .clamp(-super::SHADE_LIMIT, super::SHADE_LIMIT);
        }
        if !self.look.shading {
            delta.fill(0);
        } else {
            // The pre-test in a loop that vectorizes; the exact glint (rare) out of line.
            let mut candidates = [false; SPAN];
            let mut any = false;
            for i in 0..n {
                candidates[i] = self.may_glint(across[i], along[i]);
                any |= candidates[i];
            }
            if any {
                for i in 0..n {
                    if candidates[i] {
                        delta[i] += self.glint_exact(across[i], along[i]);
                    }
                }
            }
        }
        // The fetches: the four texels and the floor's light, in a loop of its own for each
        // case (one loop with a test of the case inside kept its pointers on the stack). Each
        // texel is read from a slice of the same length `n` (the texel, its right neighbour,
        // the two below), so one `min` puts the index in range of all four and the compiler
        // drops their bounds checks; indices are in range by construction anyway.
        let stride = w as usize;
        let texels = &self.texels[..];
        let n = texels.len().saturating_sub(stride + 1).max(1);
        let (top_left, top_right) = (&texels[..n], &texels[1..n + 1]);
        let (bottom_left, bottom_right) = (&texels[stride..stride + n], &texels[stride + 1..stride + 1 + n]);
        let last = n - 1;
        let pair = |left: &[u32], right: &[u32], at: usize| u64::from(left[at]) | u64::from(right[at]) << 32;
        let gains = &self.light.gains[..];
        let texel_pairs = top.iter_mut().zip(bottom.iter_mut()).zip(&*index);
        if self.look.caustics.is_some() && !gains.is_empty() {
            let last_gain = gains.len() - 1;
            for (((top, bottom), &index), (gain, &light)) in texel_pairs.zip(gain.iter_mut().zip(&*light_index)) {
                let at = (index as usize).min(last);
                *top = pair(top_left, top_right, at);
                *bottom = pair(bottom_left, bottom_right, at);
                *gain = gains[(light as usize).min(last_gain)];
            }
        } else {
            for ((top, bottom), &index) in texel_pairs {
                let at = (index as usize).min(last);
                *top = pair(top_left, top_right, at);
                *bottom = pair(bottom_left, bottom_right, at);
            }
            gain.fill(caustics::UNIT_GAIN);
        }
        if self.refraction_q8 & 255 == 0 {
            // A whole-number factor moves by whole pixels: no filtering.
            for (((out, &t), &g), &d) in out.iter_mut().zip(&*top).zip(&*gain).zip(&*delta) {
                *out = light_pixel_always(split(t).0, g, d);
            }
            return;
        }
        let weights = fx.iter().zip(&*fy).zip(gain.iter().zip(&*delta));
        for (out, ((&t, &b), ((&fx, &fy), (&g, &l)))) in out.iter_mut().zip(top.iter().zip(&*bottom).zip(weights)) {
            let ((a, b), (c, d)) = (split(t), split(b));
            let colour = lerp_packed(lerp_packed(a, b, fx), lerp_packed(c, d, fx), fy);
            *out = light_pixel_always(colour, g, l);
        }
    }
}

/// Two neighbouring texels in one word, the left in the low half: (the left, the right).
#[inline(always)]
fn split(pair: u64) -> (u32, u32) {
    (pair as u32, (pair >> 32) as u32)
}

/// Grid 1: the fine row is the picture's row.
#[inline(always)]
fn copy_row(fine: &[u32], out: &mut [u8]) {
    for (out, &p) in out.chunks_exact_mut(4).zip(fine) {
        out.copy_from_slice(&p.to_ne_bytes());
    }
}

/// The mean of each `F x F` block of the `F` fine rows in `fine` (each `F` times the picture
/// row's width), per channel `(sum + F²/2) / F²`, two channels at a time in one word: a
/// channel's sum of at most 16 x 255 (+ rounding) fits the 16 bits it has, and dividing by F²
/// = 4 or 16 is a shift. What [`crate::render::supersample::downsample`]'s box filter gives.
#[inline(always)]
fn mean_of_blocks_packed<const F: usize>(fine: &[u32], out: &mut [u8]) {
    const MASK: u32 = 0x00FF_00FF;
    /// Picture pixels a block of the loop below makes: a fixed count the compiler unrolls and
    /// vectorizes (one pixel at a time it stayed scalar, about a tenth of the rows' time).
    const LANES: usize = 8;
    let shift = (F * F).trailing_zeros();
    let round = ((F * F / 2) as u32) * 0x0001_0001;
    let w = fine.len() / F;
    let rows: [&[u32]; F] = std::array::from_fn(|r| &fine[r * w..(r + 1) * w]);
    let mean = |x: usize| {
        let (mut lo, mut hi) = (round, round);
        for row in &rows {
            for &p in &row[x * F..x * F + F] {
                lo += p & MASK;
                hi += (p >> 8) & MASK;
            }
        }
        ((lo >> shift) & MASK) | (((hi >> shift) & MASK) << 8)
    };
    let done = out.len() / (4 * LANES) * LANES;
    let mut blocks = out.chunks_exact_mut(4 * LANES);
    for (b, block) in blocks.by_ref().enumerate() {
        let parts: [&[u32]; F] = std::array::from_fn(|r| &rows[r][b * LANES * F..][..LANES * F]);
        let mut words = [0u32; LANES];
        for (k, word) in words.iter_mut().enumerate() {
            let (mut lo, mut hi) = (round, round);
            for part in &parts {
                for &p in &part[k * F..k * F + F] {
                    lo += p & MASK;
                    hi += (p >> 8) & MASK;
                }
            }
            *word = ((lo >> shift) & MASK) | (((hi >> shift) & MASK) << 8);
        }
        for (o, word) in block.chunks_exact_mut(4).zip(words) {
            o.copy_from_slice(&word.to_ne_bytes());
        }
    }
    for (k, o) in blocks.into_remainder().chunks_exact_mut(4).enumerate() {
        o.copy_from_slice(&mean(done + k).to_ne_bytes());
    }
}

/// [`mean_of_blocks_packed`] for any grid, channel by channel.
fn mean_of_blocks(fine: &[u32], grid: usize, out: &mut [u8]) {
    let w = fine.len() / grid;
    let n = (grid * grid) as u32;
    for (x, out) in out.chunks_exact_mut(4).enumerate() {
        let mut sum = [0u32; 4];
        for r in 0..grid {
            for &p in &fine[r * w + x * grid..r * w + x * grid + grid] {
                for (s, b) in sum.iter_mut().zip(p.to_ne_bytes()) {
                    *s += u32::from(b);
                }
            }
        }
        for (o, s) in out.iter_mut().zip(sum) {
            *o = ((s + n / 2) / n) as u8;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_means_are_the_supersampling_box_filter() {
        use crate::render::supersample::{Downsample, downsample};
        for grid in 1..=4u32 {
            let (w, h) = (7 * grid, 3 * grid);
            let mut fine = tiny_skia::Pixmap::new(w, h).unwrap();
            for (i, p) in fine.data_mut().iter_mut().enumerate() {
                *p = (i * 7919 % 251) as u8;
            }
            let mut want = tiny_skia::Pixmap::new(7, 3).unwrap();
            downsample(&fine, grid, Downsample::Box, &mut want);
            let words: Vec<u32> =
                fine.data().chunks_exact(4).map(|p| u32::from_ne_bytes(p.try_into().unwrap())).collect();
            let g = grid as usize;
            for y in 0..3 {
                let rows = &words[y * g * w as usize..(y + 1) * g * w as usize];
                let mut got = [0u8; 7 * 4];
                match g {
                    1 => copy_row(rows, &mut got),
                    2 => mean_of_blocks_packed::<2>(rows, &mut got),
                    4 => mean_of_blocks_packed::<4>(rows, &mut got),
                    _ => mean_of_blocks(rows, g, &mut got),
                }
                assert_eq!(got[..], want.data()[y * 28..(y + 1) * 28], "grid {grid}, row {y}");
                let mut plain = [0u8; 7 * 4];
                mean_of_blocks(rows, g, &mut plain);
                assert_eq!(plain, got, "grid {grid}, row {y}: the packed and the plain means");
            }
        }
    }
}
