//! The patch's arithmetic helpers: its own sine, exact rounding and floor, the transpose of
//! its 2-D FFT, and reading its periodic fields between lattice points.

use rayon::prelude::*;
use rustfft::num_complex::Complex32;

/// (sin, cos) of `turns` whole turns (2π·turns radians), in f64, to about 1e-15: reduced
/// exactly to an eighth of a turn (rounding is exact), a short Taylor series there, and the
/// eighth's angle added back. Plain arithmetic, so the same bits on every machine (libm's sin
/// picks FMA or SSE code by CPU).
pub(super) fn sincos_turns(turns: f64) -> (f64, f64) {
    let t = turns - round_even(turns);
    let octant = round_even(t * 8.0);
    let x = (t - octant / 8.0) * std::f64::consts::TAU;
    let u = x * x;
    let sin_x = x
        * (1.0
            - u / 6.0 * (1.0 - u / 20.0 * (1.0 - u / 42.0 * (1.0 - u / 72.0 * (1.0 - u / 110.0 * (1.0 - u / 156.0))))));
    let cos_x =
        1.0 - u / 2.0 * (1.0 - u / 12.0 * (1.0 - u / 30.0 * (1.0 - u / 56.0 * (1.0 - u / 90.0 * (1.0 - u / 132.0)))));
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let (so, co) = match octant as i64 {
        0 => (0.0, 1.0),
        1 => (h, h),
        2 => (1.0, 0.0),
        3 => (h, -h),
        4 | -4 => (0.0, -1.0),
        -1 => (-h, h),
        -2 => (-1.0, 0.0),
        _ => (-h, -h),
    };
    (sin_x * co + cos_x * so, cos_x * co - sin_x * so)
}

/// `x` rounded to the nearest integer (ties to even) for |x| < 2⁵¹: adding and subtracting
/// 1.5·2⁵² leaves no fraction bits. Exact, and no call into libm (baseline x86-64 has no
/// rounding instruction).
#[inline(always)]
pub(super) fn round_even(x: f64) -> f64 {
    const MAGIC: f64 = 6_755_399_441_055_744.0;
    (x + MAGIC) - MAGIC
}

/// Transposes the n x n matrix `src` into `dst`, in 32 x 32 tiles (cache-friendly), on all
/// cores: each task writes its own band of `dst`'s rows, and a copy rounds nothing, so the
/// result is the same whatever the number of threads. (In place it was a serial tenth of a
/// map's step.)
///
/// Each tile is read a source row at a time into a small buffer and written a destination
/// row at a time, so every cache line is read and written whole. (Walking a tile's column
/// read 32 lines n·8 bytes apart for one value each; with n a power of two they all fall in
/// one set of the level-1 cache, which holds 8 to 12, so nearly every read missed: the
/// transposes were about a seventh of a 1024² step.)
pub(super) fn transpose_into(src: &[Complex32], dst: &mut [Complex32], n: usize) {
    const B: usize = 32;
    dst.par_chunks_mut(n * B).enumerate().for_each(|(band, rows)| {
        let (r0, height) = (band * B, rows.len() / n);
        let mut tile = [[Complex32::new(0.0, 0.0); B]; B];
        for c0 in (0..n).step_by(B) {
            let width = B.min(n - c0);
            // Source rows c0..c0 + width, columns r0..r0 + height, as tile[c - c0][r - r0].
            for (dc, line) in tile.iter_mut().enumerate().take(width) {
                let from = (c0 + dc) * n + r0;
                line[..height].copy_from_slice(&src[from..from + height]);
            }
            for (dr, row) in rows.chunks_mut(n).enumerate() {
                for (dc, out) in row[c0..c0 + width].iter_mut().enumerate() {
                    *out = tile[dc][dr];
                }
            }
        }
    });
}

/// ⌊x⌋ for |x| < 2³¹ without a call into libm (baseline x86-64 has no rounding
/// instruction, and `floor` was a tenth of a map's time).
#[inline(always)]
fn floor(x: f32) -> f32 {
    let t = x as i32 as f32;
    if t > x { t - 1.0 } else { t }
}

/// A coordinate wrapped into 0..n (lattice units) with floats (no integer division).
#[inline(always)]
fn wrap(v: f32, n: usize) -> f32 {
    let nf = n as f32;
    // Most positions are already inside: the same value the division below gives them
    // (⌊v/n⌋ = 0), without the division (a division a coordinate was most of a resampling).
    if (0.0..nf).contains(&v) {
        return v;
    }
    let w = v - floor(v / nf) * nf;
    if w >= nf { 0.0 } else { w }
}

/// The four lattice points around a position of a periodic n x n field and their weights,
/// for reading several fields at one point.
pub(super) struct Bilinear {
    i00: usize,
    i01: usize,
    i10: usize,
    i11: usize,
    tx: f32,
    ty: f32,
}

impl Bilinear {
    #[inline(always)]
    pub(super) fn new(n: usize, x: f32, y: f32) -> Bilinear {
        let (x, y) = (wrap(x, n), wrap(y, n));
        let (x0, y0) = ((x as usize).min(n - 1), (y as usize).min(n - 1));
        let (x1, y1) = (if x0 + 1 == n { 0 } else { x0 + 1 }, if y0 + 1 == n { 0 } else { y0 + 1 });
        Bilinear {
            i00: y0 * n + x0,
            i01: y0 * n + x1,
            i10: y1 * n + x0,
            i11: y1 * n + x1,
            tx: x - x0 as f32,
            ty: y - y0 as f32,
        }
    }

    /// Every component of a field of `N` values a point, at once.
    #[inline(always)]
    pub(super) fn of_all<const N: usize>(&self, f: &[[f32; N]]) -> [f32; N] {
        let (a, b, c, d) = (&f[self.i00], &f[self.i01], &f[self.i10], &f[self.i11]);
        std::array::from_fn(|k| {
            let top = a[k] + (b[k] - a[k]) * self.tx;
            let bottom = c[k] + (d[k] - c[k]) * self.tx;
            top + (bottom - top) * self.ty
        })
    }

    #[inline(always)]
    pub(super) fn of(&self, f: &[f32]) -> f32 {
        let top = f[self.i00] + (f[self.i01] - f[self.i00]) * self.tx;
        let bottom = f[self.i10] + (f[self.i11] - f[self.i10]) * self.tx;
        top + (bottom - top) * self.ty
    }
}

/// Catmull–Rom interpolation of a periodic n x n field at (x, y) lattice units.
pub(super) fn cubic(f: &[f32], n: usize, x: f32, y: f32) -> f32 {
    let (x, y) = (wrap(x, n), wrap(y, n));
    let (fx, fy) = (floor(x), floor(y));
    let (tx, ty) = (x - fx, y - fy);
    let (ix, iy) = (fx as usize + n, fy as usize + n);
    let w = |i: usize| {
        if i >= 2 * n {
            i - 2 * n
        } else if i >= n {
            i - n
        } else {
            i
        }
    };
    let weights = |t: f32| {
        let (t2, t3) = (t * t, t * t * t);
        [-0.5 * t3 + t2 - 0.5 * t, 1.5 * t3 - 2.5 * t2 + 1.0, -1.5 * t3 + 2.0 * t2 + 0.5 * t, 0.5 * t3 - 0.5 * t2]
    };
    let (wx, wy) = (weights(tx), weights(ty));
    let mut sum = 0.0;
    for (j, wyj) in wy.iter().enumerate() {
        let row = w(iy + j - 1) * n;
        for (i, wxi) in wx.iter().enumerate() {
            sum += wyj * wxi * f[row + w(ix + i - 1)];
        }
    }
    sum
}
