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

/// The most steps computed in one wavefront sweep. With `k` steps about `k + 2` rows of each
/// buffer are live per band, e.g. 144 KB for a 2048-wide pool at k = 16: it fits in L2.
pub const MAX_BLOCK_STEPS: usize = 16;

/// Below this many cells a pool is stepped on one thread (threads cost more than they save).
const PARALLEL_MIN_CELLS: usize = 1 << 17;

/// Advances the pool by `steps` steps. `current` holds the newest state and `previous` the
/// one before; on return they still do (the buffers are swapped as needed).
pub fn advance(
    current: &mut Vec<i16>,
    previous: &mut Vec<i16>,
    width: usize,
    height: usize,
    damping: Damping,
    steps: u64,
) {
    if width < 3 || height < 3 {
        // No interior: both buffers stay all zero; only the parity of the swap matters.
        if steps % 2 == 1 {
            std::mem::swap(current, previous);
        }
        return;
    }
    let mut remaining = steps;
    while remaining > 0 {
        let threads = if width * height >= PARALLEL_MIN_CELLS { rayon::current_num_threads() } else { 1 };
        let rows = height - 2;
        // Bands must be at least twice the block length for the trapezoids to work.
        let bands = threads.min(rows / (2 * MAX_BLOCK_STEPS)).max(1);
        let block = remaining.min(MAX_BLOCK_STEPS as u64) as usize;
        advance_block(current, previous, width, height, damping, block, bands);
        if block % 2 == 1 {
            std::mem::swap(current, previous);
        }
        remaining -= block as u64;
    }
}

/// Computes `block` steps: after it, the newest state is in `a` when `block` is even, in `b`
/// when odd. `a` holds the state at level 0, `b` level -1.
fn advance_block(
    a: &mut [i16],
    b: &mut [i16],
    width: usize,
    height: usize,
    damping: Damping,
    block: usize,
    bands: usize,
) {
    let rows = height - 2;
    let kernel = Kernel::detect();
    // Band boundaries in interior-row coordinates (interior row 0 = grid row 1).
    let edges: Vec<usize> = (0..=bands).map(|i| i * rows / bands).collect();
    // Each band reads one row of level 0 above and below it; copy those before splitting.
    let halo = |r: usize| a[(r + 1) * width..(r + 2) * width].to_vec();
    let halos: Vec<(Option<Vec<i16>>, Option<Vec<i16>>)> = (0..bands)
        .map(|i| {
            let above = (i > 0).then(|| halo(edges[i] - 1));
            let below = (i + 1 < bands).then(|| halo(edges[i + 1]));
            (above, below)
        })
        .collect();
    let zero_row = vec![0i16; width];
    {
        let mut a_rest = &mut a[width..(height - 1) * width];
        let mut b_rest = &mut b[width..(height - 1) * width];
        let mut views = Vec::with_capacity(bands);
        for (i, (above, below)) in halos.iter().enumerate() {
            let n = edges[i + 1] - edges[i];
            let (a_band, a_tail) = std::mem::take(&mut a_rest).split_at_mut(n * width);
            let (b_band, b_tail) = std::mem::take(&mut b_rest).split_at_mut(n * width);
            a_rest = a_tail;
            b_rest = b_tail;
            views.push(Band {
                a: a_band,
                b: b_band,
                width,
                rows: n,
                above: above.as_deref(),
                below: below.as_deref(),
                zero: &zero_row,
            });
        }
        if views.len() == 1 {
            kernel.sweep(&mut views[0], block, damping);
        } else {
            use rayon::prelude::*;
            views.par_iter_mut().for_each(|band| kernel.sweep(band, block, damping));
        }
    }
    // Phase two: the inverted triangles around each internal band edge.
    for &edge in &edges[1..bands] {
        fill_between_bands(a, b, width, edge, block, damping, kernel);
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

/// Phase two at the internal edge `edge` (the first interior row of the lower band): rows
/// within `t - 1` of the edge are brought to level `t`, for t = 2..=block.
#[inline(always)]
fn fill_between_bands(
    a: &mut [i16],
    b: &mut [i16],
    width: usize,
    edge: usize,
    block: usize,
    damping: Damping,
    kernel: Kernel,
) {
    for t in 2..=block {
        for r in edge + 1 - t..edge + t - 1 {
            // Interior row r is grid row r + 1.
            let g = r + 1;
            let (src, dst) = if t % 2 == 1 { (&*a, &mut *b) } else { (&*b, &mut *a) };
            let up = &src[(g - 1) * width..g * width];
            let mid = &src[g * width..(g + 1) * width];
            let down = &src[(g + 1) * width..(g + 2) * width];
            kernel.row(up, mid, down, &mut dst[g * width + 1..(g + 1) * width - 1], damping);
        }
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

/// The instruction set the kernels run with, detected once per block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    /// The baseline x86-64 (SSE2) or non-x86 build.
    Portable,
    /// SSE4.1 (128-bit vectors with sign extension and 32-bit min/max, which the clamp needs;
    /// plain SSE2 has to emulate them and is slower than scalar code).
    #[cfg(target_arch = "x86_64")]
    Sse41,
    /// AVX2 (256-bit vectors).
    #[cfg(target_arch = "x86_64")]
    Avx2,
    /// AVX-512BW (512-bit vectors).
    #[cfg(target_arch = "x86_64")]
    Avx512,
}

impl Kernel {
    /// The widest kernel this CPU runs. `TIDEPOOL_SIMD=portable|sse4.1|avx2` caps it (for
    /// benchmarks and for comparing the paths).
    pub fn detect() -> Kernel {
        #[cfg(target_arch = "x86_64")]
        {
            static DETECTED: std::sync::OnceLock<Kernel> = std::sync::OnceLock::new();
            *DETECTED.get_or_init(|| {
                let cap = std::env::var("TIDEPOOL_SIMD").unwrap_or_default();
                let allowed = |level: &str| {
                    let order = ["portable", "sse4.1", "avx2", "avx512"];
                    let cap = order.iter().position(|l| *l == cap).unwrap_or(order.len());
                    order.iter().position(|l| *l == level).is_some_and(|i| i <= cap)
                };
                if allowed("avx512") && std::is_x86_feature_detected!("avx512bw") {
                    Kernel::Avx512
                } else if allowed("avx2") && std::is_x86_feature_detected!("avx2") {
                    Kernel::Avx2
                } else if allowed("sse4.1") && std::is_x86_feature_detected!("sse4.1") {
                    Kernel::Sse41
                } else {
                    Kernel::Portable
                }
            })
        }
        #[cfg(not(target_arch = "x86_64"))]
        Kernel::Portable
    }

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
