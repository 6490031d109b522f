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
//! Everything is safe Rust except the `unsafe` calls of the `#[target_feature]` entry points,
//! which are guarded by run-time feature detection.

use super::ripple::Damping;
use crate::simd::Simd;

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
}

/// Advances the pool by `steps` steps. `current` holds the newest state and `previous` the
/// one before; on return they still do (the buffers are swapped as needed).
#[allow(clippy::too_many_arguments)] // the pool's fields, passed apart to borrow them apart
pub fn advance(
    current: &mut Vec<i16>,
    previous: &mut Vec<i16>,
    width: usize,
    height: usize,
    damping: Damping,
    steps: u64,
    scratch: &mut Scratch,
) {
    if width < 3 || height < 3 {
        // No interior: both buffers stay all zero; only the parity of the swap matters.
        if steps % 2 == 1 {
            std::mem::swap(current, previous);
        }
        return;
    }
    let threads = if width * height >= PARALLEL_MIN_CELLS { rayon::current_num_threads() } else { 1 };
    // Bands must be at least twice the block length for the trapezoids to fit.
    let bands = threads.min((height - 2) / (2 * MAX_BLOCK_STEPS)).max(1);
    let mut remaining = steps;
    while remaining > 0 {
        let block = remaining.min(MAX_BLOCK_STEPS as u64) as usize;
        let plan = Plan { width, rows: height - 2, bands, block, damping, kernel: Kernel::detect() };
        plan.run(current, previous, scratch);
        if block % 2 == 1 {
            std::mem::swap(current, previous);
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
    fn run(&self, a: &mut [i16], b: &mut [i16], scratch: &mut Scratch) {
        let w = self.width;
        scratch.zero_row.clear();
        scratch.zero_row.resize(w, 0);
        scratch.halos.resize(2 * self.bands * w, 0);
        // Each band reads one row of level 0 above and below it, owned by its neighbours:
        // copy those before the rows are handed out to the threads.
        for i in 0..self.bands {
            let grid_row = |interior: usize| &a[(interior + 1) * w..(interior + 2) * w];
            if i > 0 {
                scratch.halos[2 * i * w..(2 * i + 1) * w].copy_from_slice(grid_row(self.edge(i) - 1));
            }
            if i + 1 < self.bands {
                scratch.halos[(2 * i + 1) * w..(2 * i + 2) * w].copy_from_slice(grid_row(self.edge(i + 1)));
            }
        }
        let interior = w..(self.rows + 1) * w;
        self.sweep_bands(&mut a[interior.clone()], &mut b[interior], 0..self.bands, scratch);
        // Phase two: the inverted triangles around each internal band edge.
        for i in 1..self.bands {
            self.fill_between_bands(a, b, self.edge(i));
        }
    }

    /// Phase one for bands `range`, whose rows are `a` and `b`; halves run in parallel.
    fn sweep_bands(&self, a: &mut [i16], b: &mut [i16], range: std::ops::Range<usize>, scratch: &Scratch) {
        let w = self.width;
        if range.len() == 1 {
            let i = range.start;
            let halo = |k: usize| &scratch.halos[k * w..(k + 1) * w];
            let mut band = Band {
                a,
                b,
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
        let split = (self.edge(middle) - self.edge(range.start)) * w;
        let (a_top, a_bottom) = a.split_at_mut(split);
        let (b_top, b_bottom) = b.split_at_mut(split);
        rayon::join(
            || self.sweep_bands(a_top, b_top, range.start..middle, scratch),
            || self.sweep_bands(a_bottom, b_bottom, middle..range.end, scratch),
        );
    }

    /// Phase two at the internal edge `edge` (the first interior row of the lower band): rows
    /// within `t - 1` of the edge are brought to level `t`, for t = 2..=block.
    fn fill_between_bands(&self, a: &mut [i16], b: &mut [i16], edge: usize) {
        let w = self.width;
        for t in 2..=self.block {
            for r in edge + 1 - t..edge + t - 1 {
                let g = r + 1; // interior row r is grid row r + 1
                let (src, dst) = if t % 2 == 1 { (&*a, &mut *b) } else { (&*b, &mut *a) };
                let up = &src[(g - 1) * w..g * w];
                let mid = &src[g * w..(g + 1) * w];
                let down = &src[(g + 1) * w..(g + 2) * w];
                self.kernel.row(up, mid, down, &mut dst[g * w + 1..(g + 1) * w - 1], self.damping);
            }
        }
    }
}

/// A band of interior rows, with what it may read of its neighbours.
struct Band<'a> {
    a: &'a mut [i16],
    b: &'a mut [i16],
    width: usize,
    rows: usize,
    /// Level 0 of the row above the band, when that row belongs to another band (else a wall).
    above: Option<&'a [i16]>,
    /// Level 0 of the row below the band, likewise.
    below: Option<&'a [i16]>,
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
        let (src, dst) = if j % 2 == 1 { (&*self.a, &mut *self.b) } else { (&*self.b, &mut *self.a) };
        let row = |i: isize| -> &[i16] {
            if i < 0 {
                // Only level 0 is ever read across an internal edge (the trapezoid shrinks).
                debug_assert!(self.above.is_none() || j == 1);
                self.above.unwrap_or(self.zero)
            } else if i as usize >= self.rows {
                debug_assert!(self.below.is_none() || j == 1);
                self.below.unwrap_or(self.zero)
            } else {
                &src[i as usize * w..(i as usize + 1) * w]
            }
        };
        let r_i = r as isize;
        let out = &mut dst[r * w + 1..(r + 1) * w - 1];
        row_kernel(row(r_i - 1), row(r_i), row(r_i + 1), out, damping);
    }
}

/// One output row: `out[i] = damp(clamp(((left + right + up + down) >> 1) - out[i]))`, where
/// `out` covers columns 1..w-1 and the input rows are whole rows.
#[inline(always)]
fn row_kernel(up: &[i16], mid: &[i16], down: &[i16], out: &mut [i16], damping: Damping) {
    match damping {
        Damping::Off => row_kernel_with::<false>(up, mid, down, out, 0),
        Damping::Shift(shift) => row_kernel_with::<true>(up, mid, down, out, u32::from(shift)),
    }
}

#[inline(always)]
fn row_kernel_with<const DAMPED: bool>(up: &[i16], mid: &[i16], down: &[i16], out: &mut [i16], shift: u32) {
    let n = out.len();
    let (left, right) = (&mid[..n], &mid[2..n + 2]);
    let (up, down) = (&up[1..n + 1], &down[1..n + 1]);
    for i in 0..n {
        let sum = i32::from(left[i]) + i32::from(right[i]) + i32::from(up[i]) + i32::from(down[i]);
        // Saturate to i16 first, then damp in 16-bit lanes: the clamp becomes one saturating
        // pack (SSE2 `packssdw`) and the damping runs on twice as many lanes per instruction.
        let mut v = ((sum >> 1) - i32::from(out[i])).clamp(i32::from(i16::MIN), i32::from(i16::MAX)) as i16;
        if DAMPED {
            v -= v >> shift;
        }
        out[i] = v;
    }
}

/// The kernels, compiled once per instruction set (see [`crate::simd`]).
pub type Kernel = Simd;

/// Dispatch of the sweep and row kernels to their compiled variants.
trait Kernels {
    fn sweep(self, band: &mut Band<'_>, block: usize, damping: Damping);
    fn row(self, up: &[i16], mid: &[i16], down: &[i16], out: &mut [i16], damping: Damping);
}

impl Kernels for Simd {
    fn sweep(self, band: &mut Band<'_>, block: usize, damping: Damping) {
        match self {
            Kernel::Portable => band.sweep(block, damping),
            // SAFETY: these variants are only constructed after run-time detection of the feature.
            #[cfg(target_arch = "x86_64")]
            Kernel::Sse41 => unsafe { sweep_sse41(band, block, damping) },
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2 => unsafe { sweep_avx2(band, block, damping) },
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512 => unsafe { sweep_avx512(band, block, damping) },
        }
    }

    fn row(self, up: &[i16], mid: &[i16], down: &[i16], out: &mut [i16], damping: Damping) {
        match self {
            Kernel::Portable => row_kernel(up, mid, down, out, damping),
            // SAFETY: as above.
            #[cfg(target_arch = "x86_64")]
            Kernel::Sse41 => unsafe { row_sse41(up, mid, down, out, damping) },
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx2 => unsafe { row_avx2(up, mid, down, out, damping) },
            #[cfg(target_arch = "x86_64")]
            Kernel::Avx512 => unsafe { row_avx512(up, mid, down, out, damping) },
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
fn row_avx2(up: &[i16], mid: &[i16], down: &[i16], out: &mut [i16], damping: Damping) {
    row_kernel(up, mid, down, out, damping)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512bw")]
fn row_avx512(up: &[i16], mid: &[i16], down: &[i16], out: &mut [i16], damping: Damping) {
    row_kernel(up, mid, down, out, damping)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse4.1")]
fn sweep_sse41(band: &mut Band<'_>, block: usize, damping: Damping) {
    band.sweep(block, damping)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse4.1")]
fn row_sse41(up: &[i16], mid: &[i16], down: &[i16], out: &mut [i16], damping: Damping) {
    row_kernel(up, mid, down, out, damping)
}
