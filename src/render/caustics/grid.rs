//! The light of a pool finer than its picture (`grid x grid` cells a pixel): computed on the
//! heights averaged over each pixel's cells, then spread back over the cells bilinearly.
//!
//! Both passes around the light itself are loops over whole rows with the grid a constant
//! (2, 3 or 4: the scene's grids), compiled for the widest instruction set the CPU has
//! ([`crate::simd`]): the means sum each pixel's cells and divide by a constant, and the
//! spreading blends two rows of light and then, away from the picture's left and right edges,
//! blends neighbours with weights that repeat every pixel. The edges go through each cell's own
//! taps. Every path computes the same integers.

use super::{CausticsLook, LightMap, UNIT_GAIN};
use crate::simd::{Simd, Tier};

/// The margin of the light computed for a pool finer than its picture, in pixels: the
/// smoothing and the curvature together reach three pixels out.
const PAD: usize = 3;

/// What [`LightMap::compute_on_grid`] keeps between frames: the heights averaged per pixel
/// (with a margin), their light, and the interpolation's taps and row.
#[derive(Clone, Debug, Default)]
pub(super) struct Coarse {
    means: Vec<i16>,
    light: LightMap,
    /// Per cell column: the two light columns it lies between and the weight of the second.
    columns: Vec<(usize, usize, u32)>,
    /// One row of light blended between two light rows, in 1/256.
    line: Vec<u32>,
    /// One row of pixels' sums of heights.
    sums: Vec<i32>,
}

impl LightMap {
    /// The light of a pool of `grid x grid` cells a pixel, `width x height` cells, whose
    /// heights hold `look.1` units per amplitude unit: computed on the heights averaged over
    /// each pixel's cells (so the caustics have the shapes, the smoothing and the depth in
    /// pixels they have on a pool of one cell a pixel), then spread back over the cells
    /// bilinearly. The result has one entry a cell. Grid 1 is
    /// [`LightMap::compute_in_units`].
    pub fn compute_on_grid(
        &mut self,
        heights: &[i16],
        (width, height): (usize, usize),
        grid: usize,
        look: (CausticsLook, f32),
        simd: Simd,
    ) {
        if grid <= 1 {
            self.compute_in_units(heights, width, height, look, simd);
            return;
        }
        let (cols, rows) = (width / grid, height / grid);
        let coarse = self.coarse.get_or_insert_with(Box::default);
        let Coarse { means, light, columns, line, sums } = &mut **coarse;
        // The means with a margin of PAD pixels around them, continued by odd reflection
        // (h(-d) = 2·h(0) - h(d)): a slope runs on past the edge instead of folding back, so
        // the edge draws no false caustic line (repeating the edge value would bend every
        // slope that reaches it).
        let (padded_cols, padded_rows) = (cols + 2 * PAD, rows + 2 * PAD);
        means.clear();
        means.resize(padded_cols * padded_rows, 0);
        sums.clear();
        sums.resize(cols, 0);
        let means_pass = Means { heights, width, grid, cols, rows };
        match simd.tier() {
            // SAFETY: a `Simd` of this tier exists only when run-time detection found the
            // feature (see `crate::simd`).
            #[cfg(target_arch = "x86_64")]
            Tier::Avx512 => unsafe { means_pass.run_avx512(means, sums) },
            #[cfg(target_arch = "x86_64")]
            Tier::Avx2 => unsafe { means_pass.run_avx2(means, sums) },
            _ => means_pass.run(means, sums),
        }
        reflect_margins(means, (cols, rows));
        light.compute_in_units(means, padded_cols, padded_rows, look, simd);
        // Each cell's light from the four nearest pixels' (cell centres at (x + 1/2) / grid),
        // in 1/256 steps: the rows blended first, then the columns.
        self.shift = 0;
        (self.width, self.height) = (width, height);
        self.gains.resize(width * height, UNIT_GAIN);
        columns.clear();
        columns.extend((0..width).map(|x| tap(x, cols, grid)));
        line.resize(padded_cols, 0);
        let spread = Spread { light, columns, grid, cols, rows, width };
        let gains = &mut self.gains;
        match simd.tier() {
            // SAFETY: as above.
            #[cfg(target_arch = "x86_64")]
            Tier::Avx512 => unsafe { spread.run_avx512(line, gains) },
            #[cfg(target_arch = "x86_64")]
            Tier::Avx2 => unsafe { spread.run_avx2(line, gains) },
            _ => spread.run(line, gains),
        }
    }
}

/// The light row or column cell `n` of a pool `grid` cells a pixel takes its light from, for
/// light `size` pixels long: the two pixels around its centre (margin included) and the
/// second's weight in 1/256.
fn tap(n: usize, size: usize, grid: usize) -> (usize, usize, u32) {
    let at = (((2 * n + 1) * 128 / grid) as i64 - 128).clamp(0, 256 * (size as i64 - 1)) as usize;
    let lo = at >> 8;
    (lo + PAD, (lo + 1).min(size - 1) + PAD, (at & 255) as u32)
}

/// The pass that averages each pixel's cells.
struct Means<'a> {
    heights: &'a [i16],
    width: usize,
    grid: usize,
    cols: usize,
    rows: usize,
}

impl Means<'_> {
    /// Fills the means' inner `cols x rows` (the margin stays).
    #[inline(always)]
    fn run(&self, means: &mut [i16], sums: &mut [i32]) {
        match self.grid {
            2 => self.rows_of(2, means, sums),
            3 => self.rows_of(3, means, sums),
            4 => self.rows_of(4, means, sums),
            g => self.rows_of(g, means, sums),
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn run_avx2(&self, means: &mut [i16], sums: &mut [i32]) {
        self.run(means, sums)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512bw")]
    fn run_avx512(&self, means: &mut [i16], sums: &mut [i32]) {
        self.run(means, sums)
    }

    /// [`Means::run`] with `grid` a constant where it is inlined.
    #[inline(always)]
    fn rows_of(&self, grid: usize, means: &mut [i16], sums: &mut [i32]) {
        let (cols, width) = (self.cols, self.width);
        let padded_cols = cols + 2 * PAD;
        // Each pixel's mean, rounded to the nearest unit: floor((2·sum + area) / (2·area)).
        let area = (grid * grid) as i32;
        for cy in 0..self.rows {
            sums.fill(0);
            for y in cy * grid..(cy + 1) * grid {
                let row = &self.heights[y * width..y * width + cols * grid];
                for (sum, cell) in sums.iter_mut().zip(row.chunks_exact(grid)) {
                    *sum += cell.iter().map(|&v| i32::from(v)).sum::<i32>();
                }
            }
            let start = (cy + PAD) * padded_cols + PAD;
            for (mean, &sum) in means[start..start + cols].iter_mut().zip(sums.iter()) {
                *mean = (2 * sum + area).div_euclid(2 * area) as i16;
            }
        }
    }
}

/// Continues the inner `cols x rows` of `means` into its margin by odd reflection.
fn reflect_margins(means: &mut [i16], (cols, rows): (usize, usize)) {
    let padded_cols = cols + 2 * PAD;
    let reflect = |edge: i16, mirrored: i16| (2 * i32::from(edge) - i32::from(mirrored)).clamp(-32768, 32767) as i16;
    for y in PAD..PAD + rows {
        let row = &mut means[y * padded_cols..(y + 1) * padded_cols];
        for d in 1..=PAD {
            let (left, right) = (PAD, PAD + cols - 1);
            row[left - d] = reflect(row[left], row[(left + d).min(right)]);
            row[right + d] = reflect(row[right], row[right.saturating_sub(d).max(left)]);
        }
    }
    for d in 1..=PAD {
        let (top, bottom) = (PAD, PAD + rows - 1);
        for x in 0..padded_cols {
            let at = |means: &[i16], y: usize| means[y * padded_cols + x];
            means[(top - d) * padded_cols + x] = reflect(at(means, top), at(means, (top + d).min(bottom)));
            means[(bottom + d) * padded_cols + x] =
                reflect(at(means, bottom), at(means, bottom.saturating_sub(d).max(top)));
        }
    }
}

/// The pass that spreads the pixels' light over the cells.
struct Spread<'a> {
    /// The light of the means (margin included).
    light: &'a LightMap,
    /// [`tap`] of every cell column.
    columns: &'a [(usize, usize, u32)],
    grid: usize,
    /// The pixels (without the margin).
    cols: usize,
    rows: usize,
    /// Cells a row.
    width: usize,
}

impl Spread<'_> {
    #[inline(always)]
    fn run(&self, line: &mut [u32], gains: &mut [u8]) {
        match self.grid {
            2 => self.rows_of(2, line, gains),
            3 => self.rows_of(3, line, gains),
            4 => self.rows_of(4, line, gains),
            g => self.rows_of(g, line, gains),
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn run_avx2(&self, line: &mut [u32], gains: &mut [u8]) {
        self.run(line, gains)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512bw")]
    fn run_avx512(&self, line: &mut [u32], gains: &mut [u8]) {
        self.run(line, gains)
    }

    /// [`Spread::run`] with `grid` a constant where it is inlined.
    #[inline(always)]
    fn rows_of(&self, grid: usize, line: &mut [u32], gains: &mut [u8]) {
        let light = self.light;
        for (y, out) in gains.chunks_exact_mut(self.width).enumerate() {
            let (y0, y1, wy) = tap(y, self.rows, grid);
            if light.shift == 0 {
                let w = light.width;
                let (above, below) = (&light.gains[y0 * w..(y0 + 1) * w], &light.gains[y1 * w..(y1 + 1) * w]);
                for ((v, &a), &b) in line.iter_mut().zip(above).zip(below) {
                    *v = u32::from(a) * (256 - wy) + u32::from(b) * wy;
                }
            } else {
                for (x, v) in line.iter_mut().enumerate() {
                    *v = u32::from(light.gain(x, y0)) * (256 - wy) + u32::from(light.gain(x, y1)) * wy;
                }
            }
            self.spread_line(grid, line, out);
        }
    }

    /// One row of cells from a blended row of light: the first and last pixels' cells through
    /// their taps, the cells between by the pattern the taps follow there (pixel `m`'s cell
    /// `j` lies between pixels `m - 1 + o` and `m + o` with the same `o` and weight for every
    /// `m`, see [`tap`]).
    #[inline(always)]
    fn spread_line(&self, grid: usize, line: &[u32], out: &mut [u8]) {
        let blend = |a: u32, b: u32, w: u32| ((a * (256 - w) + b * w + (1 << 15)) >> 16) as u8;
        let inner = 1..self.cols.saturating_sub(1);
        let (from, to) = if inner.is_empty() { (0, 0) } else { (inner.start * grid, inner.end * grid) };
        for x in (0..from).chain(to.max(from)..out.len()) {
            let (x0, x1, w) = self.columns[x];
            out[x] = blend(line[x0], line[x1], w);
        }
        if inner.is_empty() {
            return;
        }
        // Cell j of every inner pixel m: centre 256·m + c - 128 in 1/256 pixels, c =
        // floor((2j + 1)·128 / grid).
        let mut offsets = [0usize; 4];
        let mut weights = [0u32; 4];
        for j in 0..grid.min(4) {
            let c = ((2 * j + 1) * 128 / grid) as u32;
            (offsets[j], weights[j]) = if c < 128 { (0, c + 128) } else { (1, c - 128) };
        }
        if grid > 4 {
            for (cell, &(x0, x1, w)) in out[from..to].iter_mut().zip(&self.columns[from..to]) {
                *cell = blend(line[x0], line[x1], w);
            }
            return;
        }
        // line[PAD + m - 1 + o] and the next: a window of three light values per pixel.
        let (before, here, after) = (&line[PAD - 1..], &line[PAD..], &line[PAD + 1..]);
        let cells = &mut out[from..to];
        for (k, cell) in cells.chunks_exact_mut(grid).enumerate() {
            let m = inner.start + k;
            let window = [before[m], here[m], after[m]];
            for j in 0..grid {
                let o = offsets[j];
                cell[j] = blend(window[o], window[o + 1], weights[j]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inner_cells_follow_their_taps() {
        // The pattern the inner cells use is what every cell's own taps say.
        for grid in 2..=4 {
            for cols in [1usize, 2, 3, 5, 17] {
                let width = cols * grid;
                let line: Vec<u32> = (0..cols + 2 * PAD).map(|i| (i as u32 * 9_973) % (255 * 256)).collect();
                let columns: Vec<_> = (0..width).map(|x| tap(x, cols, grid)).collect();
                let light = LightMap::default();
                let spread = Spread { light: &light, columns: &columns, grid, cols, rows: 1, width };
                let mut out = vec![0u8; width];
                spread.spread_line(grid, &line, &mut out);
                for (x, &(x0, x1, w)) in columns.iter().enumerate() {
                    let want = ((line[x0] * (256 - w) + line[x1] * w + (1 << 15)) >> 16) as u8;
                    assert_eq!(out[x], want, "grid {grid}, {cols} pixels, cell {x}");
                }
            }
        }
    }
}
