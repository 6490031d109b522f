//! The two height fields a gusty pool's picture is drawn from: the pool's heights plus the
//! gusts' ripples, in [`GUST_UNITS`] a unit, one field with all of the ripples (it lights the
//! floor) and one with [`GUST_REFRACTION`] of them (it displaces it).
//!
//! Row by row: each row's ripples are summed in a row of `f32` that stays in the first-level
//! cache (every packet that covers the row, in the order they were born: the same terms in the
//! same order as summing the packets one after another over the whole pool), then rounded into
//! both fields. Bands of rows run on all cores for large pools, the loops compiled for the
//! widest instruction set the CPU has ([`crate::simd`]); every cell is computed the same way
//! whatever the split and the set.

use super::{GUST_REFRACTION, GUST_UNITS};
use crate::sim::breeze::gusts::{GUST_BLOCK, GustField};
use crate::simd::{Simd, Tier};

/// Pools with fewer cells are composed on one thread.
const PARALLEL_MIN_CELLS: usize = 1 << 16;
/// Cells per parallel task.
const CELLS_PER_TASK: usize = 1 << 15;

/// The row scratch of each parallel task, kept between frames.
#[derive(Clone, Debug, Default)]
pub(super) struct Composer {
    rows: Vec<Vec<f32>>,
}

/// The gusts and the pool's heights (`cols` wide) to compose.
#[derive(Clone, Copy)]
pub(super) struct Sources<'a> {
    pub gusts: GustField<'a>,
    pub heights: &'a [i16],
    pub cols: usize,
}

impl Composer {
    /// Fills `light` and `refraction` (resized to the pool's size) from `sources`.
    pub fn compose(&mut self, sources: Sources<'_>, (light, refraction): (&mut Vec<i16>, &mut Vec<i16>), simd: Simd) {
        let n = sources.heights.len();
        light.resize(n, 0);
        refraction.resize(n, 0);
        let cols = sources.cols.max(1);
        let rows_per_task = if n >= PARALLEL_MIN_CELLS { (CELLS_PER_TASK / cols).max(1) } else { n / cols };
        let chunk = rows_per_task.max(1) * cols;
        let tasks = n.div_ceil(chunk);
        self.rows.resize_with(tasks, Vec::new);
        let run = |(task, ((light, refraction), row)): BandTask<'_>| {
            // Whole blocks, room for the packets' padding past the last column (see
            // `GustField::add_row_blocks`).
            row.resize(cols.next_multiple_of(GUST_BLOCK), 0.0);
            let band = Band { sources, first_row: task * rows_per_task };
            match simd.tier() {
                // SAFETY: a `Simd` of this tier exists only when run-time detection found the
                // feature (see `crate::simd`).
                #[cfg(target_arch = "x86_64")]
                Tier::Avx512 => unsafe { band.run_avx512(light, refraction, row) },
                #[cfg(target_arch = "x86_64")]
                Tier::Avx2 => unsafe { band.run_avx2(light, refraction, row) },
                _ => band.run(light, refraction, row),
            }
        };
        if tasks > 1 {
            use rayon::prelude::*;
            light
                .par_chunks_mut(chunk)
                .zip(refraction.par_chunks_mut(chunk))
                .zip(self.rows.par_iter_mut())
                .enumerate()
                .for_each(run);
        } else {
            light
                .chunks_mut(chunk)
                .zip(refraction.chunks_mut(chunk))
                .zip(self.rows.iter_mut())
                .enumerate()
                .for_each(run);
        }
    }
}

/// A task's number, its rows of both fields and its scratch row.
type BandTask<'a> = (usize, ((&'a mut [i16], &'a mut [i16]), &'a mut Vec<f32>));

/// One task's rows.
struct Band<'a> {
    sources: Sources<'a>,
    first_row: usize,
}

impl Band<'_> {
    #[inline(always)]
    fn run(&self, light: &mut [i16], refraction: &mut [i16], ripples: &mut [f32]) {
        let cols = self.sources.cols;
        let rows = light.chunks_exact_mut(cols).zip(refraction.chunks_exact_mut(cols));
        for (i, (light, refraction)) in rows.enumerate() {
            let y = self.first_row + i;
            ripples.fill(0.0);
            self.sources.gusts.add_row_blocks(y, ripples);
            let heights = &self.sources.heights[y * cols..(y + 1) * cols];
            fill_units((light, refraction), heights, ripples, GUST_REFRACTION);
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn run_avx2(&self, light: &mut [i16], refraction: &mut [i16], ripples: &mut [f32]) {
        self.run(light, refraction, ripples)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512bw")]
    fn run_avx512(&self, light: &mut [i16], refraction: &mut [i16], ripples: &mut [f32]) {
        self.run(light, refraction, ripples)
    }
}

/// `heights` plus `ripples` in `light`, and plus `share` of them in `refraction`, in
/// [`GUST_UNITS`] a unit, each rounded to the nearest unit: [`to_unit`].
#[inline(always)]
fn fill_units((light, refraction): (&mut [i16], &mut [i16]), heights: &[i16], ripples: &[f32], share: f32) {
    let n = heights.len().min(ripples.len()).min(light.len()).min(refraction.len());
    let (heights, ripples) = (&heights[..n], &ripples[..n]);
    let (light, refraction) = (&mut light[..n], &mut refraction[..n]);
    for i in 0..n {
        let h = f32::from(heights[i]);
        light[i] = to_unit(h + ripples[i]);
        refraction[i] = to_unit(h + share * ripples[i]);
    }
}

/// Amplitude `v` in [`GUST_UNITS`] a unit, rounded to the nearest (floor(v + 1/2), halves up)
/// and saturated to `i16`: the value `(clamped - i16::MIN + 1/2) as i32 as f32 + i16::MIN`
/// (truncating a positive number), computed in float operations that vectorize. `v` is never
/// NaN (heights and the gusts' sums of finite factors).
#[inline(always)]
fn to_unit(v: f32) -> i16 {
    let (lowest, highest) = (f32::from(i16::MIN), f32::from(i16::MAX));
    let positive = (v * GUST_UNITS as f32).clamp(lowest, highest) - lowest + 0.5;
    (floor_small(positive) + i32::from(i16::MIN)).min(i32::from(i16::MAX)) as i16
}

/// `floor(v)` of `0 <= v < 2^22`: the sum `v + 2^23` holds `v` rounded to the nearest integer
/// in its mantissa's low bits (the spacing of floats there is 1); one less where that rounded
/// up. A float-to-integer `as` saturates, which the compiler leaves scalar; these vectorize.
#[inline(always)]
fn floor_small(v: f32) -> i32 {
    const TWO_23: f32 = 8_388_608.0;
    let sum = v + TWO_23;
    let nearest = (sum.to_bits() & 0x007F_FFFF) as i32;
    nearest - i32::from(sum - TWO_23 > v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rounding as it was written first: `as` conversions.
    fn by_conversions(v: f32) -> i16 {
        let (lowest, highest, units) = (f32::from(i16::MIN), f32::from(i16::MAX), GUST_UNITS as f32);
        let unit = ((v * units).clamp(lowest, highest) - lowest + 0.5) as i32 as f32 + lowest;
        unit.min(highest) as i16
    }

    #[test]
    fn units_round_as_the_conversions_do() {
        let mut values: Vec<f32> = (-40_000 * 64..=40_000 * 64).map(|k| k as f32 / 256.0).collect();
        // Every half unit's neighbours, where the rounding turns.
        for k in -70_000..=70_000 {
            let half = k as f32 / 8.0 + 1.0 / 8.0;
            values.extend([half.next_down(), half, half.next_up()]);
        }
        // Spread over every exponent, and beyond the range.
        let mut bits = 0x2545_f491u32;
        for _ in 0..200_000 {
            bits ^= bits << 13;
            bits ^= bits >> 17;
            bits ^= bits << 5;
            let v = f32::from_bits(bits);
            if !v.is_nan() {
                values.push(v);
            }
        }
        values.extend([0.0, -0.0, f32::INFINITY, f32::NEG_INFINITY, f32::MAX, f32::MIN, 1e-40, -1e-40]);
        for v in values {
            assert_eq!(to_unit(v), by_conversions(v), "{v:e} ({:#x})", v.to_bits());
        }
    }
}
