//! Caustics: the bright network of lines that a rippled surface throws on the pool floor.
//!
//! Sunlight is refracted by the surface; where the surface curves like a lens, the rays of
//! neighbouring cells converge on the floor and the light is concentrated. Instead of tracing a
//! ray per cell and splatting its energy (a scatter, awkward to run on several cores without
//! races), tidepool uses the same ray mapping in gather form: the light on the floor under a
//! cell is the cell's area divided by the area of its image, `1 / |det J|`, where J is the
//! Jacobian of the map from surface cell to floor point. For small slopes the refracted ray is
//! bent by about `(1 - 1/n)·slope` (n = 1.33) uphill, so at depth D the map is
//! `p + D·(1 - 1/n)·∇h` and `J = I + D·(1 - 1/n)·Hessian(h)`: under a crest (negative
//! curvature) the rays converge and the floor is brighter, under a trough they spread.
//!
//! The Hessian is taken with stencils two cells wide: the integer simulation carries a faint
//! grid-scale texture, which one-cell second differences would turn into glitter, and the wide
//! stencils cancel it exactly (the papers' refraction offsets have the same property). The
//! result is a multiplier per cell (1 = flat water) in 8.8 fixed point.

use crate::error::ValueError;
use crate::simd::{Simd, Tier};

mod grid;

use grid::Coarse;

/// Amplitude units per pixel of surface height: a weight-64 stone makes a dent one pixel deep.
pub const AMPLITUDE_PER_PIXEL: f32 = 64.0;
/// Water's refractive index.
pub const WATER_INDEX: f32 = 1.33;

/// How the caustics look: the water's depth in pixels (deeper water focuses the light into
/// sharper, stronger lines), `0..=`[`CausticsLook::MAX_DEPTH_PX`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CausticsLook {
    depth_px: f32,
    /// How much of the floor's light is sunlight that takes part (the rest is ambient).
    strength: f32,
}

impl Default for CausticsLook {
    fn default() -> Self {
        CausticsLook { depth_px: 24.0, strength: 0.8 }
    }
}

impl CausticsLook {
    /// The deepest water, in pixels.
    pub const MAX_DEPTH_PX: f32 = 10_000.0;

    /// Caustics through water `depth_px` pixels deep.
    pub fn with_depth(depth_px: f32) -> Result<CausticsLook, ValueError> {
        Self::checked(depth_px, &depth_px.to_string())
    }

    fn checked(depth_px: f32, shown: &str) -> Result<CausticsLook, ValueError> {
        if !depth_px.is_finite() || !(0.0..=Self::MAX_DEPTH_PX).contains(&depth_px) {
            return Err(ValueError::new("depth", format!("'{shown}' must be between 0 and 10000 pixels")));
        }
        Ok(CausticsLook { depth_px, ..CausticsLook::default() })
    }

    /// Parses a depth in pixels.
    pub fn parse_depth(text: &str) -> Result<CausticsLook, ValueError> {
        let v: f32 = text
            .trim()
            .parse()
            .map_err(|_| ValueError::new("depth", format!("'{text}' is not a number of pixels; e.g. 48")))?;
        Self::checked(v, text)
    }

    /// The water's depth, px.
    pub fn depth_px(&self) -> f32 {
        self.depth_px
    }
}

/// The gain that leaves the floor as it is: gains are in 1/64 (so up to 4x fits in a byte).
pub const UNIT_GAIN: u8 = 64;

/// The brightest a caustic line gets, as a multiple of the floor's normal light.
const MAX_GAIN: f32 = 3.5;
/// The darkest the floor gets between lines.
const MIN_GAIN: f32 = 0.45;

/// Pictures with at least this many pixels get their light computed on every other row and
/// column (a quarter of the work). The smoothing already removes detail finer than about four
/// cells, so the lines keep their shape; below this size every cell gets its own value.
pub const HALF_RESOLUTION_FROM: usize = 1 << 19;

/// The light on the floor, one multiplier in 1/64 ([`UNIT_GAIN`] = unchanged) per cell, or per
/// 2x2 cells for large pools.
#[derive(Clone, Debug, Default)]
pub struct LightMap {
    /// The multipliers, row-major.
    pub gains: Vec<u8>,
    /// Columns of `gains`.
    pub width: usize,
    /// Rows of `gains`.
    pub height: usize,
    /// log2 of the cells per entry along each axis (0 or 1).
    pub shift: u32,
    /// Rolling row caches, one per parallel task, kept between frames.
    windows: Vec<Window>,
    /// For a pool finer than its picture: the heights averaged to one value a pixel, and
    /// their light (see [`LightMap::compute_on_grid`]).
    coarse: Option<Box<Coarse>>,
}

impl LightMap {
    /// The multiplier for pool cell (x, y), which must be inside the pool.
    #[inline(always)]
    pub fn gain(&self, x: usize, y: usize) -> u8 {
        self.gains[(y >> self.shift) * self.width + (x >> self.shift)]
    }

    /// [`LightMap::compute_in_units`] of a pool's own heights.
    #[cfg(test)]
    pub fn compute(&mut self, heights: &[i16], width: usize, height: usize, look: CausticsLook, simd: Simd) {
        self.compute_in_units(heights, width, height, (look, 1.0), simd);
    }

    /// Recomputes the light of the `width x height` pool `heights`, which hold `units` per
    /// amplitude unit (1: the pool's own; more: heights at a finer precision). Rows are split
    /// across threads for large pools; the result does not depend on the split.
    ///
    /// The heights are first smoothed with the binomial filter [1 4 6 4 1] along rows and
    /// columns: the integer scheme carries a grid-scale texture whose curvature would otherwise
    /// turn into glitter (the filter removes the checkerboard exactly and keeps ripples of
    /// eight cells and more). The three passes (along rows, along columns, the Jacobian) run
    /// fused over a few cached rows, so only the heights and the result cross main memory.
    pub fn compute_in_units(
        &mut self,
        heights: &[i16],
        width: usize,
        height: usize,
        (look, units): (CausticsLook, f32),
        simd: Simd,
    ) {
        self.shift = u32::from(width * height >= HALF_RESOLUTION_FROM);
        let step = 1usize << self.shift;
        (self.width, self.height) = (width.div_ceil(step), height.div_ceil(step));
        let (cols, rows) = (self.width, self.height);
        self.gains.resize(cols * rows, UNIT_GAIN);
        if cols == 0 || rows == 0 {
            return;
        }
        // det J with J = I + k·H', where H' is the stencil sum on the smoothed field (which is
        // 256x the heights, sampled every `step` cells): the Hessian in amplitude units per
        // cell² is H' / (256·step²).
        let k =
            look.depth_px * (1.0 - 1.0 / WATER_INDEX) / (AMPLITUDE_PER_PIXEL * units) / (256.0 * (step * step) as f32);
        let field = Field { heights, width, height, rows, step };
        let parallel = width * height >= (1 << 16);
        // Each task smooths a few rows beyond its own (its halo): tasks of 16 rows or more
        // keep that overhead small.
        let rows_per_task = if parallel { ((1 << 15) / width / step).max(16) } else { rows };
        let tasks = rows.div_ceil(rows_per_task);
        self.windows.resize_with(tasks, Window::default);
        let run = |(task, (chunk, window)): (usize, (&mut [u8], &mut Window))| {
            let task = Task { field: &field, first_row: task * rows_per_task, k, strength: look.strength };
            match simd.tier() {
                // SAFETY: a `Simd` of this tier exists only when run-time detection found the
                // feature (see `crate::simd`).
                #[cfg(target_arch = "x86_64")]
                Tier::Avx512 => unsafe { task.run_avx512(window, chunk) },
                #[cfg(target_arch = "x86_64")]
                Tier::Avx2 => unsafe { task.run_avx2(window, chunk) },
                _ => task.run(window, chunk),
            }
        };
        if parallel {
            use rayon::prelude::*;
            self.gains.par_chunks_mut(rows_per_task * cols).zip(self.windows.par_iter_mut()).enumerate().for_each(run);
        } else {
            self.gains.chunks_mut(rows_per_task * cols).zip(self.windows.iter_mut()).enumerate().for_each(run);
        }
    }
}

/// The pool's heights and how the light map samples them.
struct Field<'a> {
    heights: &'a [i16],
    width: usize,
    height: usize,
    /// Light-map rows.
    rows: usize,
    /// Pool cells per light-map entry along each axis.
    step: usize,
}

/// One parallel task: a run of light-map rows.
struct Task<'a> {
    field: &'a Field<'a>,
    first_row: usize,
    k: f32,
    strength: f32,
}

impl Task<'_> {
    #[inline(always)]
    fn run(&self, window: &mut Window, chunk: &mut [u8]) {
        let cols = self.field.width.div_ceil(self.field.step);
        window.reset(cols);
        for (i, out) in chunk.chunks_exact_mut(cols).enumerate() {
            let [up, mid, down] = window.rows_around(self.field, self.first_row + i);
            light_row(up, mid, down, self.k, self.strength, out);
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn run_avx2(&self, window: &mut Window, chunk: &mut [u8]) {
        self.run(window, chunk)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512bw")]
    fn run_avx512(&self, window: &mut Window, chunk: &mut [u8]) {
        self.run(window, chunk)
    }
}

/// Slots in the ring of heights smoothed along rows (five are read at once, plus reuse).
const ACROSS_SLOTS: usize = 8;
/// Slots in the ring of fully smoothed rows (three are read at once).
const SMOOTH_SLOTS: usize = 4;

/// The rows one task has smoothed recently, so each is computed once per task.
#[derive(Clone, Debug, Default)]
struct Window {
    across: Vec<i32>,
    across_keys: [Option<usize>; ACROSS_SLOTS],
    smooth: Vec<i32>,
    smooth_keys: [Option<usize>; SMOOTH_SLOTS],
    /// One pool row smoothed along itself at full resolution, before decimation.
    full_row: Vec<i32>,
    cols: usize,
}

impl Window {
    #[inline(always)]
    fn reset(&mut self, cols: usize) {
        self.cols = cols;
        self.across.resize(ACROSS_SLOTS * cols, 0);
        self.smooth.resize(SMOOTH_SLOTS * cols, 0);
        self.across_keys = [None; ACROSS_SLOTS];
        self.smooth_keys = [None; SMOOTH_SLOTS];
    }

    /// The smoothed light-map rows j-1, j and j+1 (edges repeated).
    #[inline(always)]
    fn rows_around(&mut self, field: &Field<'_>, j: usize) -> [&[i32]; 3] {
        let wanted = [j.saturating_sub(1), j, (j + 1).min(field.rows - 1)];
        for r in wanted {
            self.ensure_smooth(field, r);
        }
        let cols = self.cols;
        wanted.map(|r| {
            let slot = r % SMOOTH_SLOTS;
            &self.smooth[slot * cols..(slot + 1) * cols]
        })
    }

    /// Makes light-map row `r` ([1 4 6 4 1] down the columns at pool row r·step) present.
    #[inline(always)]
    fn ensure_smooth(&mut self, field: &Field<'_>, r: usize) {
        let slot = r % SMOOTH_SLOTS;
        if self.smooth_keys[slot] == Some(r) {
            return;
        }
        let y = (r * field.step) as isize;
        let pool_rows = [-2, -1, 0, 1, 2].map(|dy| (y + dy).clamp(0, field.height as isize - 1) as usize);
        for row in pool_rows {
            self.ensure_across(field, row);
        }
        let cols = self.cols;
        let [a, b, c, d, e] = pool_rows.map(|row| {
            let s = row % ACROSS_SLOTS;
            &self.across[s * cols..(s + 1) * cols]
        });
        let out = &mut self.smooth[slot * cols..(slot + 1) * cols];
        for (x, v) in out.iter_mut().enumerate() {
            *v = a[x] + 4 * b[x] + 6 * c[x] + 4 * d[x] + e[x];
        }
        self.smooth_keys[slot] = Some(r);
    }

    /// Makes pool row `y`, smoothed along the row at every `step`-th column, present.
    #[inline(always)]
    fn ensure_across(&mut self, field: &Field<'_>, y: usize) {
        let slot = y % ACROSS_SLOTS;
        if self.across_keys[slot] == Some(y) {
            return;
        }
        let w = field.width;
        let row = &field.heights[y * w..(y + 1) * w];
        // The whole row first, in a loop the compiler vectorizes, then every `step`-th value.
        self.full_row.resize(w, 0);
        let full = &mut self.full_row;
        let at = |x: isize| i32::from(row[x.clamp(0, w as isize - 1) as usize]);
        for x in (0..w.min(2)).chain(w.saturating_sub(2).max(2)..w) {
            let x = x as isize;
            full[x as usize] = at(x - 2) + 4 * at(x - 1) + 6 * at(x) + 4 * at(x + 1) + at(x + 2);
        }
        if w > 4 {
            let taps = |d: usize| row[d..d + w - 4].iter().map(|&v| i32::from(v));
            let inner = full[2..w - 2].iter_mut().zip(taps(0).zip(taps(1)).zip(taps(2)).zip(taps(3)).zip(taps(4)));
            for (v, ((((a, b), c), d), e)) in inner {
                *v = a + 4 * b + 6 * c + 4 * d + e;
            }
        }
        let out = &mut self.across[slot * self.cols..(slot + 1) * self.cols];
        for (v, &f) in out.iter_mut().zip(full.iter().step_by(field.step)) {
            *v = f;
        }
        self.across_keys[slot] = Some(y);
    }
}

/// One light-map row from the smoothed rows above, at and below it.
#[inline(always)]
fn light_row(up: &[i32], mid: &[i32], down: &[i32], k: f32, strength: f32, out: &mut [u8]) {
    let w = out.len();
    let rows = [up, mid, down];
    for x in (0..w.min(1)).chain(w.saturating_sub(1).max(1)..w) {
        out[x] = light_at(rows, x.saturating_sub(1), x, (x + 1).min(w - 1), k, strength);
    }
    // The interior without clamping, so the compiler can vectorize it (an index loop: the
    // iterator form of the same loop measured 25 % more instructions per frame).
    #[allow(clippy::needless_range_loop)]
    for x in 1..w.saturating_sub(1) {
        out[x] = light_at(rows, x - 1, x, x + 1, k, strength);
    }
}

/// The light at column `x` with neighbours `l` and `r`: `1 / |det J|`, softened and mixed
/// with the ambient light.
#[inline(always)]
fn light_at([up, mid, down]: [&[i32]; 3], l: usize, x: usize, r: usize, k: f32, strength: f32) -> u8 {
    let centre = 2 * mid[x];
    let hxx = mid[l] + mid[r] - centre;
    let hyy = up[x] + down[x] - centre;
    let hxy = (down[r] - down[l] - up[r] + up[l]) / 4;
    let (a, b, c) = (k * hxx as f32, k * hyy as f32, k * hxy as f32);
    let det = (1.0 + a) * (1.0 + b) - c * c;
    // Where det crosses zero the rays cross: the caustic line itself. Soften the pole.
    let focus = 1.0 / det.abs().max(1.0 / MAX_GAIN);
    let gain = (1.0 + strength * (focus - 1.0)).clamp(MIN_GAIN, MAX_GAIN);
    (gain * f32::from(UNIT_GAIN) + 0.5) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_water_lights_the_floor_evenly() {
        let heights = vec![0i16; 30 * 20];
        let mut light = LightMap::default();
        light.compute(&heights, 30, 20, CausticsLook::default(), Simd::detect());
        assert_eq!(light.gains.len(), 600);
        assert!(light.gains.iter().all(|&l| l == UNIT_GAIN));
        // A tilted plane does not focus light either.
        let tilted: Vec<i16> = (0..600).map(|i| (i % 30) as i16 * 10).collect();
        light.compute(&tilted, 30, 20, CausticsLook::default(), Simd::detect());
        assert!(light.gains.iter().enumerate().all(|(i, &l)| (i % 30) < 3 || (i % 30) > 26 || l == UNIT_GAIN));
    }

    #[test]
    fn a_crest_focuses_and_a_trough_spreads() {
        // A gentle crest along a column (a lens that converges light on the floor) and a trough.
        // (A crest much sharper than this focuses above the floor, and the light spreads again.)
        let (w, h) = (40, 10);
        let mut heights = vec![0i16; w * h];
        for y in 0..h {
            for (x, v) in [(9, 6), (10, 12), (11, 6), (29, -6), (30, -12), (31, -6)] {
                heights[y * w + x] = v;
            }
        }
        let mut light = LightMap::default();
        light.compute(&heights, w, h, CausticsLook::default(), Simd::detect());
        let at = |x: usize| light.gain(x, 5);
        assert!(at(10) > UNIT_GAIN, "under the crest: {}", at(10));
        assert!(at(30) < UNIT_GAIN, "under the trough: {}", at(30));
    }

    #[test]
    fn the_grid_scale_texture_does_not_glitter() {
        // A pure checkerboard is the integer scheme's finest mode; the wide stencils ignore it.
        let (w, h) = (16, 16);
        let heights: Vec<i16> = (0..w * h).map(|i| if (i % w + i / w) % 2 == 0 { 50 } else { -50 }).collect();
        let mut light = LightMap::default();
        light.compute(&heights, w, h, CausticsLook { depth_px: 200.0, strength: 1.0 }, Simd::detect());
        for y in 3..h - 3 {
            for x in 3..w - 3 {
                assert_eq!(light.gain(x, y), UNIT_GAIN, "({x}, {y})");
            }
        }
    }

    #[test]
    fn parallel_and_serial_maps_agree() {
        let (w, h) = (512, 300);
        let heights: Vec<i16> = (0..w * h).map(|i| (((i * 7919) % 401) as i16 - 200) / 3).collect();
        let mut parallel = LightMap::default();
        parallel.compute(&heights, w, h, CausticsLook::default(), Simd::detect());
        // The top rows on their own (64 rows are below the parallel threshold).
        let rows = 64;
        let mut serial = LightMap::default();
        serial.compute(&heights[..w * rows], w, rows, CausticsLook::default(), Simd::detect());
        for y in 0..rows - 3 {
            assert_eq!(parallel.gains[y * w..(y + 1) * w], serial.gains[y * w..(y + 1) * w], "row {y}");
        }
    }

    #[test]
    fn large_pools_use_half_resolution_with_the_same_shapes() {
        // A ring of ripples: the same picture at full and at half resolution.
        let (w, h) = (1024, 600);
        let heights: Vec<i16> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32 - 512.0, (i / w) as f32 - 300.0);
                let r = (x * x + y * y).sqrt();
                if (80.0..140.0).contains(&r) { (40.0 * (r * 0.5).sin()) as i16 } else { 0 }
            })
            .collect();
        let mut half = LightMap::default();
        half.compute(&heights, w, h, CausticsLook::default(), Simd::detect());
        assert_eq!((half.shift, half.width, half.height), (1, 512, 300));
        let mut full = LightMap::default();
        full.compute(&heights[..w * 400], w, 400, CausticsLook::default(), Simd::detect()); // under the threshold
        assert_eq!(full.shift, 0);
        let (mut both_bright, mut bright) = (0, 0);
        for y in (0..400).step_by(2) {
            for x in (0..w).step_by(2) {
                if full.gain(x, y) > 100 {
                    bright += 1;
                    both_bright += usize::from(half.gain(x, y) > 75);
                }
            }
        }
        assert!(bright > 100 && both_bright * 10 >= bright * 8, "{both_bright} of {bright}");
    }
}
