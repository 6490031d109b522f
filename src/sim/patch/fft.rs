//! The patch's inverse 2-D FFT, sixteen columns (then sixteen rows) at a time.
//!
//! rustfft's scalar plan is what the maps were made with (its SIMD plans pick other algorithms
//! per instruction set and round differently). For a power-of-two side of 64 or more that plan
//! is radix 4 over a base butterfly of 8 or 16 points: a bit-reversed transpose, the base
//! butterflies, then radix-4 layers with twiddles. [`InverseFft2`] does those very operations,
//! in the same order and on the same twiddles, but on [`Lanes`]: sixteen independent
//! transforms side by side, one in each lane, so every addition and multiplication of a lane
//! is the one the scalar plan does for its transform. Lane-wise arithmetic rounds the same at
//! any vector width (no fused multiply-add: Rust never contracts), so the result is the same
//! bits as the scalar plan on every SIMD tier, now vectorised: the columns go through in strips
//! of sixteen (read a cache line pair a row, no transpose of the whole field), the rows in bands
//! of sixteen (a 16 x 16 block transposed at a time, in cache). Strips and bands run on all
//! cores, each transform whole on one thread, so any thread count gives the same bits.
//!
//! Other sides (not a power of two, or below 64) keep rustfft's scalar plan, between
//! transposes of the whole field. `the_lanes_are_rustfft_s_scalar_plan_bit_for_bit` holds the
//! two to the same bits.

use std::f64::consts::PI;
use std::ops::{Add, Sub};
use std::sync::Arc;

use rayon::prelude::*;
use rustfft::num_complex::Complex32;
use rustfft::{Fft, FftPlannerScalar};

use super::sampling::transpose_into;
use crate::simd::{Simd, Tier};

/// Transforms side by side.
const W: usize = 16;

/// Sixteen complex values, one per transform, real and imaginary parts apart (so each
/// operation is one vector operation on each).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Lanes {
    re: [f32; W],
    im: [f32; W],
}

impl Lanes {
    const ZERO: Lanes = Lanes { re: [0.0; W], im: [0.0; W] };

    /// Lane by lane `self · t`, as num-complex multiplies: (a·c - b·d, a·d + b·c).
    #[inline(always)]
    fn times(self, t: Complex32) -> Lanes {
        Lanes {
            re: std::array::from_fn(|l| self.re[l] * t.re - self.im[l] * t.im),
            im: std::array::from_fn(|l| self.re[l] * t.im + self.im[l] * t.re),
        }
    }

    /// Lane by lane `self · s` for a real `s`.
    #[inline(always)]
    fn scaled(self, s: f32) -> Lanes {
        Lanes { re: std::array::from_fn(|l| self.re[l] * s), im: std::array::from_fn(|l| self.im[l] * s) }
    }

    /// Lane by lane `self · i`: rustfft's `rotate_90` of an inverse transform.
    #[inline(always)]
    fn turned(self) -> Lanes {
        Lanes { re: std::array::from_fn(|l| -self.im[l]), im: self.re }
    }

    /// Sixteen consecutive complex values as lanes.
    #[inline(always)]
    fn load(values: &[Complex32]) -> Lanes {
        let values = &values[..W];
        Lanes { re: std::array::from_fn(|l| values[l].re), im: std::array::from_fn(|l| values[l].im) }
    }
}

impl Add for Lanes {
    type Output = Lanes;
    #[inline(always)]
    fn add(self, o: Lanes) -> Lanes {
        Lanes { re: std::array::from_fn(|l| self.re[l] + o.re[l]), im: std::array::from_fn(|l| self.im[l] + o.im[l]) }
    }
}

impl Sub for Lanes {
    type Output = Lanes;
    #[inline(always)]
    fn sub(self, o: Lanes) -> Lanes {
        Lanes { re: std::array::from_fn(|l| self.re[l] - o.re[l]), im: std::array::from_fn(|l| self.im[l] - o.im[l]) }
    }
}

/// rustfft's `Butterfly2`: (a + b, a - b).
#[inline(always)]
fn bf2(a: &mut Lanes, b: &mut Lanes) {
    let sum = *a + *b;
    *b = *a - *b;
    *a = sum;
}

/// rustfft's `Butterfly4` (inverse), in place on four values.
#[inline(always)]
fn bf4(v: [Lanes; 4]) -> [Lanes; 4] {
    let [mut v0, mut v1, mut v2, mut v3] = v;
    bf2(&mut v0, &mut v2);
    bf2(&mut v1, &mut v3);
    v3 = v3.turned();
    bf2(&mut v0, &mut v1);
    bf2(&mut v2, &mut v3);
    [v0, v2, v1, v3]
}

/// rustfft's `Butterfly8` (inverse).
#[inline(always)]
fn bf8(b: [Lanes; 8], root2: f32) -> [Lanes; 8] {
    let mut s0 = bf4([b[0], b[2], b[4], b[6]]);
    let mut s1 = bf4([b[1], b[3], b[5], b[7]]);
    s1[1] = (s1[1].turned() + s1[1]).scaled(root2);
    s1[2] = s1[2].turned();
    s1[3] = (s1[3].turned() - s1[3]).scaled(root2);
    for i in 0..4 {
        let (a, b) = (&mut s0[i], &mut s1[i]);
        bf2(a, b);
    }
    [s0[0], s0[1], s0[2], s0[3], s1[0], s1[1], s1[2], s1[3]]
}

/// rustfft's `Butterfly16` (inverse): split radix over `Butterfly8` and two `Butterfly4`.
#[inline(always)]
fn bf16(b: [Lanes; 16], t: &[Complex32; 3], root2: f32) -> [Lanes; 16] {
    let evens = bf8([b[0], b[2], b[4], b[6], b[8], b[10], b[12], b[14]], root2);
    let mut n1 = bf4([b[1], b[5], b[9], b[13]]);
    let mut n3 = bf4([b[15], b[3], b[7], b[11]]);
    for i in 1..4 {
        n1[i] = n1[i].times(t[i - 1]);
        n3[i] = n3[i].times(t[i - 1].conj());
    }
    for i in 0..4 {
        let (a, b) = (&mut n1[i], &mut n3[i]);
        bf2(a, b);
        n3[i] = n3[i].turned();
    }
    std::array::from_fn(|j| match j {
        0..4 => evens[j] + n1[j],
        4..8 => evens[j] + n3[j - 4],
        8..12 => evens[j - 8] - n1[j - 8],
        _ => evens[j - 8] - n3[j - 12],
    })
}

/// rustfft's twiddle e^(2πi·index/len) of an inverse transform: its expression, in f64, then
/// to f32.
fn twiddle(index: usize, len: usize) -> Complex32 {
    let angle = -2f64 * PI / len as f64 * index as f64;
    Complex32::new(angle.cos() as f32, angle.sin() as f32).conj()
}

/// The radix-4 plan of one side, as rustfft's scalar planner makes it.
struct Radix4 {
    /// 8 or 16.
    base: usize,
    /// For each input element, its position in the transform's working order (rustfft's
    /// bit-reversed transpose).
    place: Vec<usize>,
    /// The radix-4 layers' twiddles, the first layer's first, three a column.
    twiddles: Vec<Complex32>,
    /// `Butterfly16`'s three twiddles.
    t16: [Complex32; 3],
    root2: f32,
}

impl Radix4 {
    /// The plan for side `n`, if the scalar planner's plan for it is radix 4 over an 8- or
    /// 16-point butterfly (a power of two from 64 on).
    fn new(n: usize) -> Option<Radix4> {
        if !n.is_power_of_two() || n < 64 {
            return None;
        }
        let bits = n.trailing_zeros();
        let base = if bits % 2 == 1 { 8 } else { 16 };
        let width = n / base;
        let digits = width.trailing_zeros() / 2;
        let reversed = |mut x: usize| {
            let mut r = 0;
            for _ in 0..digits {
                r = r * 4 + x % 4;
                x /= 4;
            }
            r
        };
        // Position j takes element reversed(j / base) + (j % base)·width.
        let mut place = vec![0; n];
        for j in 0..n {
            place[reversed(j / base) + (j % base) * width] = j;
        }
        let mut twiddles = Vec::with_capacity(n);
        let mut cross = base;
        while cross < n {
            let columns = cross;
            cross *= 4;
            for i in 0..columns {
                twiddles.extend((1..4).map(|k| twiddle(i * k, cross)));
            }
        }
        let t16 = [twiddle(1, 16), twiddle(2, 16), twiddle(3, 16)];
        Some(Radix4 { base, place, twiddles, t16, root2: 0.5f64.sqrt() as f32 })
    }

    /// The transforms of `x` (in working order: gathered by `place`), in place.
    #[inline(always)]
    fn run(&self, x: &mut [Lanes]) {
        if self.base == 16 {
            for chunk in x.chunks_exact_mut(16) {
                let out = bf16(std::array::from_fn(|j| chunk[j]), &self.t16, self.root2);
                chunk.copy_from_slice(&out);
            }
        } else {
            for chunk in x.chunks_exact_mut(8) {
                let out = bf8(std::array::from_fn(|j| chunk[j]), self.root2);
                chunk.copy_from_slice(&out);
            }
        }
        let (mut cross, mut twiddles) = (self.base, self.twiddles.as_slice());
        while cross < x.len() {
            let columns = cross;
            cross *= 4;
            for data in x.chunks_exact_mut(cross) {
                for idx in 0..columns {
                    let t = &twiddles[3 * idx..3 * idx + 3];
                    let v = bf4([
                        data[idx],
                        data[idx + columns].times(t[0]),
                        data[idx + 2 * columns].times(t[1]),
                        data[idx + 3 * columns].times(t[2]),
                    ]);
                    for (k, value) in v.into_iter().enumerate() {
                        data[idx + k * columns] = value;
                    }
                }
            }
            twiddles = &twiddles[3 * columns..];
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn run_avx2(&self, x: &mut [Lanes]) {
        self.run(x)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f")]
    fn run_avx512(&self, x: &mut [Lanes]) {
        self.run(x)
    }

    /// [`Radix4::run`] compiled for `simd`'s instruction set (the same bits on each).
    fn run_on(&self, simd: Simd, x: &mut [Lanes]) {
        match simd.tier() {
            // SAFETY: a `Simd` of this tier exists only when run-time detection found the
            // feature (see `crate::simd`).
            #[cfg(target_arch = "x86_64")]
            Tier::Avx512 => unsafe { self.run_avx512(x) },
            #[cfg(target_arch = "x86_64")]
            Tier::Avx2 => unsafe { self.run_avx2(x) },
            _ => self.run(x),
        }
    }
}

/// A transform's working space, kept between transforms (contents are scratch).
#[derive(Default)]
pub(super) struct FftScratch {
    /// The whole field transposed (rustfft's path).
    flat: Vec<Complex32>,
    /// The column transforms, a strip of sixteen columns after another (the lanes' path).
    strips: Vec<Lanes>,
}

/// The inverse 2-D FFT of an n x n field: rustfft's scalar plan's bits, by lanes where the
/// plan is radix 4.
pub(super) struct InverseFft2 {
    n: usize,
    radix4: Option<Radix4>,
    /// rustfft's scalar plan for the sides [`Radix4`] does not take.
    rows: Arc<dyn Fft<f32>>,
}

impl InverseFft2 {
    pub(super) fn new(n: usize) -> InverseFft2 {
        // The scalar planner: rustfft's AVX, SSE and NEON plans pick other algorithms and round
        // differently, and maps must be the same bytes on every machine.
        InverseFft2 { n, radix4: Radix4::new(n), rows: FftPlannerScalar::new().plan_fft_inverse(n) }
    }

    /// The inverse 2-D FFT, in place, of a spectrum in the lattice's order (`buf[r·n + c]`):
    /// along ky (the columns), then along kx (the rows), which leaves the field in row-major
    /// order. Strips, bands and rows in parallel: the same result on any number of cores.
    pub(super) fn process(&self, buf: &mut [Complex32], scratch: &mut FftScratch) {
        self.process_on(Simd::detect(), buf, scratch);
    }

    /// [`InverseFft2::process`] with the lanes compiled for `simd` (the same bits on each).
    fn process_on(&self, simd: Simd, buf: &mut [Complex32], scratch: &mut FftScratch) {
        let n = self.n;
        let Some(plan) = &self.radix4 else {
            scratch.flat.resize(n * n, Complex32::new(0.0, 0.0));
            transpose_into(buf, &mut scratch.flat, n);
            scratch.flat.par_chunks_mut(n * 16).for_each(|rows| self.rows.process(rows));
            transpose_into(&scratch.flat, buf, n);
            buf.par_chunks_mut(n * 16).for_each(|rows| self.rows.process(rows));
            return;
        };
        // The columns: strip s holds columns 16s..16s + 16, row r at position place[r] of the
        // working order (read in the rows' order: a constant stride the prefetcher follows);
        // transformed, its entry j is row j.
        scratch.strips.resize(n * n / W, Lanes::ZERO);
        scratch.strips.par_chunks_mut(n).enumerate().for_each(|(s, strip)| {
            for (row, &j) in plan.place.iter().enumerate() {
                strip[j] = Lanes::load(&buf[row * n + s * W..]);
            }
            plan.run_on(simd, strip);
        });
        // The rows, sixteen to a band: each strip's 16 x 16 block of the band transposed into
        // the working order (lane l: row r0 + l), transformed, written back row by row.
        let strips = &scratch.strips;
        buf.par_chunks_mut(n * W).enumerate().for_each_init(
            || vec![Lanes::ZERO; n],
            |band, (b, rows)| {
                for (s, strip) in strips.chunks_exact(n).enumerate() {
                    let block = &strip[b * W..(b + 1) * W];
                    for m in 0..W {
                        let to = &mut band[plan.place[s * W + m]];
                        for (l, from) in block.iter().enumerate() {
                            (to.re[l], to.im[l]) = (from.re[m], from.im[m]);
                        }
                    }
                }
                plan.run_on(simd, band);
                for (l, row) in rows.chunks_exact_mut(n).enumerate() {
                    for (out, lanes) in row.iter_mut().zip(band.iter()) {
                        *out = Complex32::new(lanes.re[l], lanes.im[l]);
                    }
                }
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The 2-D transform the maps were made with before the lanes: rustfft's scalar plan
    /// along the columns (by a transpose), then along the rows.
    fn by_rustfft(buf: &mut [Complex32], n: usize) {
        let fft = FftPlannerScalar::new().plan_fft_inverse(n);
        let mut t = vec![Complex32::new(0.0, 0.0); n * n];
        transpose_into(buf, &mut t, n);
        fft.process(&mut t);
        transpose_into(&t, buf, n);
        fft.process(buf);
    }

    /// Every side the lanes take (base 8 and base 16, one to five radix-4 layers) and one they
    /// do not (96) give rustfft's scalar plan's bits exactly, on every SIMD tier this CPU
    /// runs, for fields with values over many magnitudes.
    #[test]
    fn the_lanes_are_rustfft_s_scalar_plan_bit_for_bit() {
        let mut rng = ChaCha8Rng::seed_from_u64(32);
        for n in [64, 96, 128, 256, 512, 1024] {
            assert_eq!(Radix4::new(n).is_some(), n != 96, "which sides take the lanes");
            let field: Vec<Complex32> = (0..n * n)
                .map(|_| {
                    let scale = 10f32.powi(rng.random_range(-6..4));
                    Complex32::new(rng.random_range(-1.0..1.0) * scale, rng.random_range(-1.0..1.0) * scale)
                })
                .collect();
            let mut expected = field.clone();
            by_rustfft(&mut expected, n);
            let fft = InverseFft2::new(n);
            for simd in Simd::supported() {
                let mut got = field.clone();
                fft.process_on(simd, &mut got, &mut FftScratch::default());
                let differ = got
                    .iter()
                    .zip(&expected)
                    .filter(|(a, b)| a.re.to_bits() != b.re.to_bits() || a.im.to_bits() != b.im.to_bits())
                    .count();
                assert_eq!(differ, 0, "side {n}, {simd}: {differ} values differ from rustfft's scalar plan");
            }
        }
    }
}
