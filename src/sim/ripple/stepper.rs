//! How ripple steps are executed fast, bit-identical to the plain rule in `ripple.rs`.
//!
//! The step is memory-bound: one step reads two `i16` buffers and writes one, so a
//! 1024x1024 pool (4 MB of state) streams through memory at every step. Three things make it
//! several times faster than the papers' loop:
//!
//! 1. **Vector row kernel.** Each row is computed from zipped row slices (no bounds checks, no
//!    row-end special cases), which the compiler turns into wide SIMD. The kernel is compiled
//!    three times — baseline SSE2, AVX2 and AVX-512BW — and the widest the CPU supports is
//!    chosen at run time, so the default release build is fast on any x86-64.
//! 2. **Temporal blocking (wavefront).** Up to [`MAX_BLOCK_STEPS`] steps are computed in one
//!    sweep down the pool: step `j` of row `r` is computed right after step `j - 1` of row
//!    `r + 1`, so only about `j + 2` rows are live at a time and stay in the L1/L2 cache. The
//!    state crosses main memory once per block instead of once per step.
//! 3. **Row bands on threads.** The interior rows are split into bands, one per thread. In a
//!    first phase each band advances its own rows, skipping (one more row per step) the rows
//!    next to another band, whose neighbours it cannot see yet — a trapezoid in space-time. A
//!    second phase fills the inverted triangles around each band boundary. Every cell is
//!    computed by the same rule from the same inputs whatever the number of threads, so the
//!    result is bit-identical with 1, 2 or 64 threads.
//!
//! 4. **16-bit lanes when they cannot overflow.** Each row carries the largest magnitude it
//!    holds ([`RowMax`]). When a row's inputs are all below 8192 and its old value below 16384
//!    (almost always: ripples are hundreds of units), the exact rule fits in `i16` arithmetic,
//!    which does twice the lanes per instruction and needs no widening shuffles; otherwise the
//!    row takes the widening path with its clamp. Both give the same bits.
//!
//! Everything is safe Rust except the `unsafe` calls of the `#[target_feature]` entry points,
//! which are guarded by run-time feature detection.

use super::Damping;
use crate::simd::{Simd, Tier};

/// The most steps computed in one wavefront sweep. With `k` steps about `k + 2` rows of each
/// buffer are live per band, e.g. 144 KB for a 2048-wide pool at k = 16: it fits in L2.
pub const MAX_BLOCK_STEPS: usize = 16;

/// Below this many cells a pool is stepped on one thread (threads cost more than they save).
const PARALLEL_MIN_CELLS: usize = 1 << 17;

/// Buffers reused from step to step, so stepping allocates nothing in the steady state.
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    zero_row: Vec<i16>,
    /// Two rows per band: level 0 of the rows just above and just below it.
    halos: Vec<i16>,
    /// The row maxima of those halo rows.
    halo_max: Vec<u16>,
}

/// Per grid row, an upper bound of `|v|` over the row's cells (the walls' rows are 0). Kept
/// exact by the kernels and raised by whoever else writes a row (stones).
pub type RowMax = Vec<u16>;

/// Inputs below this magnitude (and an old value below twice it) make the 16-bit path exact.
const NARROW_INPUT: u16 = 8192;
const NARROW_OLD: u16 = 16384;

/// Advances the pool by `steps` steps. `current` holds the newest state and `previous` the
/// one before; on return they still do (the buffers are swapped as needed).
#[allow(clippy::too_many_arguments)] // the pool's fields, passed apart to borrow them apart
pub fn advance(
    (current, current_max): (&mut Vec<i16>, &mut RowMax),
    (previous, previous_max): (&mut Vec<i16>, &mut RowMax),
    width: usize,
    height: usize,
    damping: Damping,
    steps: u64,
    scratch: &mut Scratch,
    simd: Simd,
) {
    if width < 3 || height < 3 {
        // No interior: both buffers stay all zero; only the parity of the swap matters.
        if steps % 2 == 1 {
            std::mem::swap(current, previous);
            std::mem::swap(current_max, previous_max);
        }
        return;
    }
    let threads = if width * height >= PARALLEL_MIN_CELLS { rayon::current_num_threads() } else { 1 };
    // Bands must be at least twice the block length for the trapezoids to fit.
    let bands = threads.min((height - 2) / (2 * MAX_BLOCK_STEPS)).max(1);
    let mut remaining = steps;
    while remaining > 0 {
        let block = remaining.min(MAX_BLOCK_STEPS as u64) as usize;
        let plan = Plan { width, rows: height - 2, bands, block, damping, kernel: simd };
        plan.run((current, current_max), (previous, previous_max), scratch);
        if block % 2 == 1 {
            std::mem::swap(current, previous);
            std::mem::swap(current_max, previous_max);
        }
        remaining -= block as u64;
    }
}

/// One block of steps over the whole pool.
#[derive(Clone, Copy)]
struct Plan {
    width: usize,
    /// Interior rows (the grid's rows minus the two walls).
    rows: usize,
    bands: usize,
    block: usize,
    damping: Damping,
    kernel: Kernel,
}

impl Plan {
    /// The first interior row of band `i` (interior row 0 = grid row 1); `edge(bands)` = rows.
    fn edge(&self, i: usize) -> usize {
        i * self.rows / self.bands
    }

    /// Computes `block` steps: after it, the newest state is in `a` when `block` is even, in
    /// `b` when odd. `a` holds level 0, `b` level -1.
    fn run(&self, (a, a_max): (&mut [i16], &mut [u16]), (b, b_max): (&mut [i16], &mut [u16]), scratch: &mut Scratch) {
        let w = self.width;
        scratch.zero_row.clear();
        scratch.zero_row.resize(w, 0);
        scratch.halos.resize(2 * self.bands * w, 0);
        scratch.halo_max.clear();
        scratch.halo_max.resize(2 * self.bands, 0);
        // Each band reads one row of level 0 above and below it, owned by its neighbours:
        // copy those before the rows are handed out to the threads.
        for i in 0..self.bands {
            let grid_row = |interior: usize| &a[(interior + 1) * w..(interior + 2) * w];
            if i > 0 {
                scratch.halos[2 * i * w..(2 * i + 1) * w].copy_from_slice(grid_row(self.edge(i) - 1));
                scratch.halo_max[2 * i] = a_max[self.edge(i)];
            }
            if i + 1 < self.bands {
                scratch.halos[(2 * i + 1) * w..(2 * i + 2) * w].copy_from_slice(grid_row(self.edge(i + 1)));
                scratch.halo_max[2 * i + 1] = a_max[self.edge(i + 1) + 1];
            }
        }
        let interior = w..(self.rows + 1) * w;
        let interior_max = 1..self.rows + 1;
        self.sweep_bands(
            (&mut a[interior.clone()], &mut a_max[interior_max.clone()]),
            (&mut b[interior], &mut b_max[interior_max]),
            0..self.bands,
            scratch,
        );
        // Phase two: the inverted triangles around each internal band edge.
        for i in 1..self.bands {
            self.fill_between_bands((a, a_max), (b, b_max), self.edge(i));
        }
    }

    /// Phase one for bands `range`, whose rows are `a` and `b`; halves run in parallel.
    fn sweep_bands(
        &self,
        (a, a_max): (&mut [i16], &mut [u16]),
        (b, b_max): (&mut [i16], &mut [u16]),
        range: std::ops::Range<usize>,
        scratch: &Scratch,
    ) {
        let w = self.width;
        if range.len() == 1 {
            let i = range.start;
            let halo = |k: usize| (&scratch.halos[k * w..(k + 1) * w], scratch.halo_max[k]);
            let mut band = Band {
                a,
                b,
                a_max,
                b_max,
                width: w,
                rows: self.edge(i + 1) - self.edge(i),
                above: (i > 0).then(|| halo(2 * i)),
                below: (i + 1 < self.bands).then(|| halo(2 * i + 1)),
                zero: &scratch.zero_row,
            };
            self.kernel.sweep(&mut band, self.block, self.damping);
            return;
        }
        let middle = range.start + range.len() / 2;
        let rows = self.edge(middle) - self.edge(range.start);
        let (a_top, a_bottom) = a.split_at_mut(rows * w);
        let (b_top, b_bottom) = b.split_at_mut(rows * w);
        let (a_max_top, a_max_bottom) = a_max.split_at_mut(rows);
        let (b_max_top, b_max_bottom) = b_max.split_at_mut(rows);
        rayon::join(
            || self.sweep_bands((a_top, a_max_top), (b_top, b_max_top), range.start..middle, scratch),
            || self.sweep_bands((a_bottom, a_max_bottom), (b_bottom, b_max_bottom), middle..range.end, scratch),
        );
    }

    /// Phase two at the internal edge `edge` (the first interior row of the lower band): rows
    /// within `t - 1` of the edge are brought to level `t`, for t = 2..=block.
    fn fill_between_bands(
        &self,
        (a, a_max): (&mut [i16], &mut [u16]),
        (b, b_max): (&mut [i16], &mut [u16]),
        edge: usize,
    ) {
        let w = self.width;
        for t in 2..=self.block {
            for r in edge + 1 - t..edge + t - 1 {
                let g = r + 1; // interior row r is grid row r + 1
                let ((src, src_max), (dst, dst_max)) = if t % 2 == 1 {
                    ((&*a, &*a_max), (&mut *b, &mut *b_max))
                } else {
                    ((&*b, &*b_max), (&mut *a, &mut *a_max))
                };
                let rows = [&src[(g - 1) * w..g * w], &src[g * w..(g + 1) * w], &src[(g + 1) * w..(g + 2) * w]];
                let inputs = src_max[g - 1].max(src_max[g]).max(src_max[g + 1]);
                let out = &mut dst[g * w + 1..(g + 1) * w - 1];
                dst_max[g] = self.kernel.row(rows, inputs, dst_max[g], out, self.damping);
            }
        }
    }
}

/// A band of interior rows, with what it may read of its neighbours.
struct Band<'a> {
    a: &'a mut [i16],
    b: &'a mut [i16],
    a_max: &'a mut [u16],
    b_max: &'a mut [u16],
    width: usize,
    rows: usize,
    /// Level 0 of the row above the band (and its maximum), when that row belongs to another
    /// band (else a wall).
    above: Option<(&'a [i16], u16)>,
    /// Level 0 of the row below the band, likewise.
    below: Option<(&'a [i16], u16)>,
    zero: &'a [i16],
}

impl Band<'_> {
    /// The wavefront sweep of phase one: `block` steps over the band's rows, shrinking by one
    /// row per step at edges shared with another band.
    #[inline(always)]
    fn sweep(&mut self, block: usize, damping: Damping) {
        let (top_shrinks, bottom_shrinks) = (self.above.is_some(), self.below.is_some());
        let rows = self.rows as isize;
        for y in 0..rows + block as isize - 1 {
            for j in 1..=block {
                let r = y - (j as isize - 1);
                let lo = if top_shrinks { j as isize - 1 } else { 0 };
                let hi = rows - if bottom_shrinks { j as isize - 1 } else { 0 };
                if r < lo || r >= hi {
                    continue;
                }
                self.compute(r as usize, j, damping);
            }
        }
    }

    /// Step `j` (level j) of local row `r`.
    #[inline(always)]
    fn compute(&mut self, r: usize, j: usize, damping: Damping) {
        let w = self.width;
        let ((src, src_max), (dst, dst_max)) = if j % 2 == 1 {
            ((&*self.a, &*self.a_max), (&mut *self.b, &mut *self.b_max))
        } else {
            ((&*self.b, &*self.b_max), (&mut *self.a, &mut *self.a_max))
        };
        let row = |i: isize| -> (&[i16], u16) {
            if i < 0 {
                // Only level 0 is ever read across an internal edge (the trapezoid shrinks).
                debug_assert!(self.above.is_none() || j == 1);
                self.above.unwrap_or((self.zero, 0))
            } else if i as usize >= self.rows {
                debug_assert!(self.below.is_none() || j == 1);
                self.below.unwrap_or((self.zero, 0))
            } else {
                (&src[i as usize * w..(i as usize + 1) * w], src_max[i as usize])
            }
        };
        let r_i = r as isize;
        let ((up, up_max), (mid, mid_max), (down, down_max)) = (row(r_i - 1), row(r_i), row(r_i + 1));
        let out = &mut dst[r * w + 1..(r + 1) * w - 1];
        dst_max[r] = row_kernel([up, mid, down], up_max.max(mid_max).max(down_max), dst_max[r], out, damping);
    }
}

/// One output row: `out[i] = damp(clamp(((left + right + up + down) >> 1) - out[i]))`, where
/// `out` covers columns 1..w-1 and the input rows are whole rows. `inputs` bounds the three
/// rows' magnitudes and `old` the output row's; returns the new row's largest magnitude.
#[inline(always)]
fn row_kernel(rows: [&[i16]; 3], inputs: u16, old: u16, out: &mut [i16], damping: Damping) -> u16 {
    let narrow = inputs < NARROW_INPUT && old < NARROW_OLD;
    match (damping.shift(), narrow) {
        (None, true) => narrow_row::<false>(rows, out, 0),
        (None, false) => wide_row::<false>(rows, out, 0),
        (Some(shift), true) => narrow_row::<true>(rows, out, u32::from(shift)),
        (Some(shift), false) => wide_row::<true>(rows, out, u32::from(shift)),
    }
}

/// The rule in 32-bit arithmetic with the clamp: exact for any inputs.
#[inline(always)]
fn wide_row<const DAMPED: bool>([up, mid, down]: [&[i16]; 3], out: &mut [i16], shift: u32) -> u16 {
    let n = out.len();
    let (left, right) = (&mid[..n], &mid[2..n + 2]);
    let (up, down) = (&up[1..n + 1], &down[1..n + 1]);
    let mut largest = 0u16;
    for i in 0..n {
        let sum = i32::from(left[i]) + i32::from(right[i]) + i32::from(up[i]) + i32::from(down[i]);
        // Saturate to i16 first, then damp in 16-bit lanes: the clamp becomes one saturating
        // pack (SSE2 `packssdw`) and the damping runs on twice as many lanes per instruction.
        let mut v = ((sum >> 1) - i32::from(out[i])).clamp(i32::from(i16::MIN), i32::from(i16::MAX)) as i16;
        if DAMPED {
            v -= v >> shift;
        }
        out[i] = v;
        largest = largest.max(v.unsigned_abs());
    }
    largest
}

/// The rule in 16-bit arithmetic: exact when the inputs are below [`NARROW_INPUT`] and the old
/// values below [`NARROW_OLD`] — the sum of four is then at most 32764, half of it minus the
/// old value stays inside `i16`, and the clamp has nothing to do.
#[inline(always)]
fn narrow_row<const DAMPED: bool>([up, mid, down]: [&[i16]; 3], out: &mut [i16], shift: u32) -> u16 {
    let n = out.len();
    let (left, right) = (&mid[..n], &mid[2..n + 2]);
    let (up, down) = (&up[1..n + 1], &down[1..n + 1]);
    let mut largest = 0u16;
    for i in 0..n {
        let sum = left[i] + right[i] + up[i] + down[i];
        let mut v = (sum >> 1) - out[i];
        if DAMPED {
            v -= v >> shift;
        }
        out[i] = v;
        largest = largest.max(v.unsigned_abs());
    }
    largest
}

/// The kernels, compiled once per instruction set (see [`crate::simd`]).
type Kernel = Simd;

/// Dispatch of the sweep and row kernels to their compiled variants.
trait Kernels {
    fn sweep(self, band: &mut Band<'_>, block: usize, damping: Damping);
    fn row(self, rows: [&[i16]; 3], inputs: u16, old: u16, out: &mut [i16], damping: Damping) -> u16;
}

impl Kernels for Simd {
    fn sweep(self, band: &mut Band<'_>, block: usize, damping: Damping) {
        match self.tier() {
            Tier::Portable => band.sweep(block, damping),
            // SAFETY: a `Simd` of this tier exists only when run-time detection found the
            // feature (see `crate::simd`).
            #[cfg(target_arch = "x86_64")]
            Tier::Sse41 => unsafe { sweep_sse41(band, block, damping) },
            #[cfg(target_arch = "x86_64")]
            Tier::Avx2 => unsafe { sweep_avx2(band, block, damping) },
            #[cfg(target_arch = "x86_64")]
            Tier::Avx512 => unsafe { sweep_avx512(band, block, damping) },
        }
    }

    fn row(self, rows: [&[i16]; 3], inputs: u16, old: u16, out: &mut [i16], damping: Damping) -> u16 {
        match self.tier() {
            Tier::Portable => row_kernel(rows, inputs, old, out, damping),
            // SAFETY: as above.
            #[cfg(target_arch = "x86_64")]
            Tier::Sse41 => unsafe { row_sse41(rows, inputs, old, out, damping) },
            #[cfg(target_arch = "x86_64")]
            Tier::Avx2 => unsafe { row_avx2(rows, inputs, old, out, damping) },
            #[cfg(target_arch = "x86_64")]
            Tier::Avx512 => unsafe { row_avx512(rows, inputs, old, out, damping) },
        }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn sweep_avx2(band: &mut Band<'_>, block: usize, damping: Damping) {
    band.sweep(block, damping)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw")]
fn sweep_avx512(band: &mut Band<'_>, block: usize, damping: Damping) {
    band.sweep(block, damping)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn row_avx2(rows: [&[i16]; 3], inputs: u16, old: u16, out: &mut [i16], damping: Damping) -> u16 {
    row_kernel(rows, inputs, old, out, damping)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw")]
fn row_avx512(rows: [&[i16]; 3], inputs: u16, old: u16, out: &mut [i16], damping: Damping) -> u16 {
    row_kernel(rows, inputs, old, out, damping)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse4.1")]
fn sweep_sse41(band: &mut Band<'_>, block: usize, damping: Damping) {
    band.sweep(block, damping)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse4.1")]
fn row_sse41(rows: [&[i16]; 3], inputs: u16, old: u16, out: &mut [i16], damping: Damping) -> u16 {
    row_kernel(rows, inputs, old, out, damping)
}
