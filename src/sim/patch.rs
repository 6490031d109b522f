//! A periodic patch of sea for engines: the same spectrum, choppiness, second-order height,
//! loop and foam as [`super::ocean::Sea`], but with wavenumbers on the patch's lattice
//! (kx, ky multiples of 2π/extent), summed by FFT, so the maps tile without a seam.
//!
//! Each lattice wavenumber k (|k| below the lattice's Nyquist, k ≠ 0) is one travelling wave
//! `a·cos(k·x - ωt + φ)` with `a = √(2·F(k)·Δk²)`, F the directional wavenumber spectrum
//! `E(f, θ)·(df/dk)/k` (so Σa²/2 is the lattice's integral of the spectrum), φ from the seed
//! and ω from the depth's dispersion (rounded to a whole multiple of 2π/T for a loop: on a
//! lattice the wavenumber cannot move, so the dispersion is then exact to half a frequency
//! step). Per time step eight real fields and one complex one come from five complex inverse
//! FFTs (two real fields packed in each): height, displacement, slopes, the displacement's
//! gradient and B = Σ a·√k·e^(iθ) for the second-order height.
//!
//! Heights are resampled at the fixed lattice points (Eulerian: what a height field holds),
//! like [`super::ocean::SeaFrame::height`]; normals are those of that surface; foam is
//! followed at the resting lattice points by the same memory as the rendered sea
//! ([`super::foam`]) and resampled the same way.

use crate::error::ValueError;
use std::f64::consts::PI;
use std::sync::Arc;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use rustfft::num_complex::Complex32;
use rustfft::{Fft, FftPlannerScalar};

use super::dispersion;
use super::foam::{FoamCalibration, FoamClock, remember, source};
use super::ocean::{EULER_ITERATIONS, Sea, SeaParams, SeaTime};
use super::spectra::SeaSpectrum;

/// Smallest and largest lattice side.
pub const PATCH_SIZE_RANGE: (usize, usize) = (8, 4096);
/// Smallest and largest extent, m.
pub const PATCH_EXTENT_RANGE_M: (f64, f64) = (1.0, 100_000.0);

/// The fields of one moment, on the lattice; row 0 is the north edge, columns run east.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchMaps {
    /// Lattice points per side.
    pub size: usize,
    /// Metres per side.
    pub extent_m: f64,
    /// Eulerian height at each lattice point, m.
    pub height: Vec<f32>,
    /// For the water resting at each lattice point: where it is carried (east, north, up), m.
    pub displacement: Vec<[f32; 3]>,
    /// Unit normal of the Eulerian surface (east, north, up) at each lattice point.
    pub normal: Vec<[f32; 3]>,
    /// Foam cover 0..=1 at each lattice point.
    pub foam: Vec<f32>,
}

/// The lattice fields of one moment before resampling.
struct Lagrangian {
    h: Vec<f32>,
    dx: Vec<f32>,
    dy: Vec<f32>,
    hx: Vec<f32>,
    hy: Vec<f32>,
    gxx: Vec<f32>,
    gyy: Vec<f32>,
    gxy: Vec<f32>,
}

/// A periodic patch of sea and the foam it has made so far.
pub struct PatchSea {
    params: SeaParams,
    size: usize,
    extent_m: f64,
    /// Per lattice point (row-major, FFT order): 2·h0 = a·e^(iφ), ω, harmonic, k components.
    amp: Vec<Complex32>,
    omega: Vec<f64>,
    harmonic: Vec<u32>,
    kx: Vec<f32>,
    ky: Vec<f32>,
    /// |k| (1 where k = 0, whose wave is silent).
    k: Vec<f32>,
    fft: Arc<dyn Fft<f32>>,
    sigma: f32,
    threshold: f32,
    clock: FoamClock,
    foam: Vec<f32>,
    foam_step: Option<i64>,
}

impl std::fmt::Debug for PatchSea {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PatchSea").field("params", &self.params).field("size", &self.size).finish_non_exhaustive()
    }
}

/// Checks a patch's side and extent.
pub fn check_patch(size: usize, extent_m: f64) -> Result<(), ValueError> {
    if !(PATCH_SIZE_RANGE.0..=PATCH_SIZE_RANGE.1).contains(&size) {
        return Err(ValueError::new(
            "map size",
            format!(
                "a map {size} points wide is outside {}..={}; give a square size such as 1024x1024",
                PATCH_SIZE_RANGE.0, PATCH_SIZE_RANGE.1
            ),
        ));
    }
    if !extent_m.is_finite() || !(PATCH_EXTENT_RANGE_M.0..=PATCH_EXTENT_RANGE_M.1).contains(&extent_m) {
        return Err(ValueError::new(
            "map extent",
            format!(
                "the map extent {extent_m} m is outside {}..={} m; give the side of the patch in metres, e.g. 500",
                PATCH_EXTENT_RANGE_M.0, PATCH_EXTENT_RANGE_M.1
            ),
        ));
    }
    Ok(())
}

/// A map's side when it is square: maps tile, so width and height must agree.
pub fn check_map_size(width: usize, height: usize) -> Result<usize, ValueError> {
    if width != height {
        return Err(ValueError::new(
            "map size",
            format!("maps are square so that they tile; give a square size such as 1024x1024 (not {width}x{height})"),
        ));
    }
    check_patch(width, PATCH_EXTENT_RANGE_M.0)?;
    Ok(width)
}

/// How many peak wavelengths a map spans when no extent is given.
pub const DEFAULT_MAP_WAVELENGTHS: f64 = 10.0;

/// The default side of a map of `spectrum`'s sea, m ([`DEFAULT_MAP_WAVELENGTHS`] peak
/// wavelengths; 100 m for a calm).
pub fn default_extent_m(spectrum: &SeaSpectrum) -> f64 {
    spectrum.peak_wavelength_m().map_or(100.0, |l| DEFAULT_MAP_WAVELENGTHS * l)
}

/// A lattice index as a signed wavenumber index.
fn signed(i: usize, n: usize) -> i64 {
    if i < n / 2 { i as i64 } else { i as i64 - n as i64 }
}

impl PatchSea {
    /// A `size x size` patch `extent_m` metres across of the sea `params` describes.
    pub fn new(params: SeaParams, size: usize, extent_m: f64) -> Result<PatchSea, ValueError> {
        check_patch(size, extent_m)?;
        let spectrum = SeaSpectrum::new(params.wind_m_s, params.spectrum);
        let depth = spectrum.depth_m();
        let downwind = (params.wind_from_deg + 180.0).to_radians();
        let dk = 2.0 * PI / extent_m;
        let n = size;
        let mut rng = ChaCha8Rng::seed_from_u64(params.seed ^ 0x9a7c);
        let (mut amp, mut omega, mut harmonic) =
            (vec![Complex32::new(0.0, 0.0); n * n], vec![0.0; n * n], vec![0; n * n]);
        let (mut kxs, mut kys) = (vec![0.0f32; n * n], vec![0.0f32; n * n]);
        let mut slope = 0.0f64;
        for r in 0..n {
            for c in 0..n {
                let i = r * n + c;
                let phase: f64 = rng.random();
                // Column: east wavenumber; row: the wavenumber of going south (row 0 is north).
                let (mc, mr) = (signed(c, n), signed(r, n));
                let (kx, ky) = (mc as f64 * dk, -(mr as f64) * dk);
                (kxs[i], kys[i]) = (kx as f32, ky as f32);
                let k = kx.hypot(ky);
                if k == 0.0 || mc.unsigned_abs() as usize == n / 2 || mr.unsigned_abs() as usize == n / 2 {
                    continue;
                }
                let w = dispersion::angular_frequency(k, depth);
                let f = w / (2.0 * PI);
                let theta = kx.atan2(ky) - downwind;
                let density =
                    spectrum.directional_energy(f, theta) * dispersion::group_speed(k, depth) / (2.0 * PI) / k;
                let a = (2.0 * density * dk * dk).sqrt();
                amp[i] = Complex32::from_polar(a as f32, (2.0 * PI * phase) as f32);
                slope += 0.5 * a * a * k * k;
                omega[i] = w;
                if let Some(p) = params.loop_period {
                    harmonic[i] = (f * p.seconds()).round().max(1.0) as u32;
                    omega[i] = 2.0 * PI * f64::from(harmonic[i]) / p.seconds();
                }
            }
        }
        // The scalar planner: rustfft's AVX, SSE and NEON plans pick other algorithms and round
        // differently, and maps must be the same bytes on every machine.
        let fft = FftPlannerScalar::new().plan_fft_inverse(n);
        let sea = Sea::new(params);
        let threshold = FoamCalibration::calibrate(&sea).threshold;
        Ok(PatchSea {
            params,
            size,
            extent_m,
            amp,
            omega,
            harmonic,
            k: kxs.iter().zip(&kys).map(|(x, y)| if *x == 0.0 && *y == 0.0 { 1.0 } else { x.hypot(*y) }).collect(),
            kx: kxs,
            ky: kys,
            fft,
            sigma: slope.sqrt() as f32,
            threshold,
            clock: FoamClock::of(&sea),
            foam: vec![0.0; n * n],
            foam_step: None,
        })
    }

    /// Lattice points per side.
    pub fn size(&self) -> usize {
        self.size
    }

    /// The variance the lattice carries, m² (Σa²/2).
    pub fn lattice_variance(&self) -> f64 {
        self.amp.iter().map(|a| 0.5 * f64::from(a.norm_sqr())).sum()
    }

    /// The rotation e^(-iωt) of every lattice wave at `time`.
    fn rotation(&self, i: usize, time: SeaTime) -> Complex32 {
        let turns = match time {
            SeaTime::Seconds(t) => (self.omega[i] * t / (2.0 * PI)).rem_euclid(1.0),
            SeaTime::Tick(u) => f64::from(self.harmonic[i].wrapping_mul(u)) / 4_294_967_296.0,
        };
        Complex32::from_polar(1.0, (-2.0 * PI * turns) as f32)
    }

    fn time(&self, time_s: f64) -> SeaTime {
        match self.params.loop_period {
            Some(p) => SeaTime::Tick(p.tick(time_s)),
            None => SeaTime::Seconds(time_s),
        }
    }

    /// The inverse 2-D FFT of `buf` in place (rows, transpose, rows, transpose), rows in
    /// parallel: the same result on any number of cores.
    fn ifft2(&self, buf: &mut [Complex32]) {
        let n = self.size;
        for _ in 0..2 {
            buf.par_chunks_mut(n * 16).for_each(|rows| self.fft.process(rows));
            transpose_square(buf, n);
        }
    }

    /// Every lattice wave at `time`: a·e^(iφ)·e^(-iωt).
    fn waves(&self, time: SeaTime) -> Vec<Complex32> {
        (0..self.amp.len())
            .into_par_iter()
            .map(|i| if self.amp[i].norm_sqr() == 0.0 { self.amp[i] } else { self.amp[i] * self.rotation(i, time) })
            .collect()
    }

    /// Two real fields from one complex transform. `coefficients(i, w)` gives, for the travelling
    /// wave w = a·e^(iφ)·e^(-iωt) at lattice point i, its coefficients (c_f, c_g) in the two
    /// fields f = re Σ c_f·e^(ik·x) and g = re Σ c_g·e^(ik·x). Each real field's spectrum is
    /// the Hermitian S(k) = (c(k) + conj(c(-k)))/2, and the transform of S_f + i·S_g is
    /// f + i·g.
    fn real_fields(
        &self,
        waves: &[Complex32],
        coefficients: impl Fn(usize, Complex32) -> (Complex32, Complex32) + Sync,
    ) -> (Vec<f32>, Vec<f32>) {
        let n = self.size;
        let mut buf: Vec<Complex32> = (0..n * n)
            .into_par_iter()
            .map(|i| {
                let (r, c) = (i / n, i % n);
                let mirror = ((n - r) % n) * n + (n - c) % n;
                let (f, g) = coefficients(i, waves[i]);
                let (fm, gm) = coefficients(mirror, waves[mirror]);
                let sf = (f + fm.conj()) * 0.5;
                let sg = (g + gm.conj()) * 0.5;
                sf + Complex32::new(0.0, 1.0) * sg
            })
            .collect();
        self.ifft2(&mut buf);
        (buf.iter().map(|c| c.re).collect(), buf.iter().map(|c| c.im).collect())
    }

    /// The displacement's gradient per unit λ, each times -1: g_ab = Σ a·(k_a·k_b/k)·cos θ.
    fn fold_fields(&self, waves: &[Complex32]) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
        let coef = |i: usize| {
            let (kx, ky, k) = (self.kx[i], self.ky[i], self.k[i]);
            (kx * kx / k, ky * ky / k, kx * ky / k)
        };
        let (gxx, gyy) = self.real_fields(waves, |i, w| (w * coef(i).0, w * coef(i).1));
        let (gxy, _) = self.real_fields(waves, |i, w| (w * coef(i).2, Complex32::new(0.0, 0.0)));
        (gxx, gyy, gxy)
    }

    fn lagrangian(&self, time: SeaTime) -> (Lagrangian, Vec<Complex32>) {
        let i_unit = Complex32::new(0.0, 1.0);
        let unit = |i: usize| (self.kx[i] / self.k[i], self.ky[i] / self.k[i], self.k[i]);
        let waves = self.waves(time);
        // The displacement per unit λ is -Σ a·û·sin θ = re Σ (i·û·w)·e^(ik·x); slopes re Σ (i·k·w)·e^(ik·x).
        let (h, dx) = self.real_fields(&waves, |i, w| (w, i_unit * w * unit(i).0));
        let (dy, hx) = self.real_fields(&waves, |i, w| (i_unit * w * unit(i).1, i_unit * w * self.kx[i]));
        let (hy, _) = self.real_fields(&waves, |i, w| (i_unit * w * self.ky[i], Complex32::new(0.0, 0.0)));
        let (gxx, gyy, gxy) = self.fold_fields(&waves);
        // B = Σ a·√k·e^(iθ): the waves themselves, a complex field.
        let n = self.size;
        let mut b: Vec<Complex32> = (0..n * n)
            .into_par_iter()
            .map(|i| if self.amp[i].norm_sqr() == 0.0 { Complex32::new(0.0, 0.0) } else { waves[i] * unit(i).2.sqrt() })
            .collect();
        self.ifft2(&mut b);
        (Lagrangian { h, dx, dy, hx, hy, gxx, gyy, gxy }, b)
    }

    /// Brings the foam at the resting lattice points up to `time_s`.
    fn advance_foam(&mut self, time_s: f64) {
        let (now, _) = self.clock.step_at(time_s);
        let warm = self.clock.warm_up_steps();
        let first = match self.foam_step {
            Some(last) if now >= last && now - last <= warm => last + 1,
            _ => {
                self.foam.fill(0.0);
                now - warm
            }
        };
        let (decay, z, lambda, sigma) = (self.clock.decay(), self.threshold, self.params.choppiness as f32, self.sigma);
        for n in first..=now {
            let waves = self.waves(self.clock.time_of(n));
            let (gxx, gyy, gxy) = self.fold_fields(&waves);
            self.foam.par_iter_mut().enumerate().for_each(|(i, f)| {
                let q = if sigma > 0.0 {
                    (gxx[i] + gyy[i] - lambda * (gxx[i] * gyy[i] - gxy[i] * gxy[i])) / sigma
                } else {
                    0.0
                };
                *f = remember(*f, decay, source(q, z));
            });
        }
        self.foam_step = Some(now);
    }

    /// The maps at `time_s`: foam continues from the previous call when time moved forward by
    /// less than a warm-up, and is warmed up otherwise.
    pub fn maps(&mut self, time_s: f64) -> PatchMaps {
        self.advance_foam(time_s);
        let (_, frac) = self.clock.step_at(time_s);
        let fade = self.clock.decay().powf(frac);
        self.resample(time_s, fade)
    }

    /// The maps at `time_s` without foam (its `foam` is all 0): heights, displacement and
    /// normals only, without the foam's warm-up.
    pub fn surface(&self, time_s: f64) -> PatchMaps {
        self.resample(time_s, 0.0)
    }

    fn resample(&self, time_s: f64, fade: f32) -> PatchMaps {
        let (lag, b) = self.lagrangian(self.time(time_s));
        let (n, cell) = (self.size, (self.extent_m / self.size as f64) as f32);
        let lambda = self.params.choppiness as f32;
        let h_l: Vec<f32> = (0..n * n).map(|i| lag.h[i] + 0.5 * lambda * b[i].norm_sqr()).collect();
        let displacement: Vec<[f32; 3]> =
            (0..n * n).map(|i| [lambda * lag.dx[i], lambda * lag.dy[i], h_l[i]]).collect();
        let foam_l: Vec<f32> = self.foam.iter().map(|f| f * fade).collect();
        let mut height = vec![0.0f32; n * n];
        let mut normal = vec![[0.0f32; 3]; n * n];
        let mut foam = vec![0.0f32; n * n];
        height.par_chunks_mut(n).zip(normal.par_chunks_mut(n)).zip(foam.par_chunks_mut(n)).enumerate().for_each(
            |(r, ((height, normal), foam))| {
                for c in 0..n {
                    // Lattice units: column c is x = c, row r is y = -r (north up).
                    let (mut px, mut py) = (c as f32, r as f32);
                    for _ in 0..EULER_ITERATIONS {
                        let at = Bilinear::new(n, px, py);
                        let (dxv, dyv) = (at.of(&lag.dx) * lambda / cell, at.of(&lag.dy) * lambda / cell);
                        (px, py) = (c as f32 - dxv, r as f32 + dyv);
                    }
                    height[c] = cubic(&h_l, n, px, py);
                    let at = Bilinear::new(n, px, py);
                    let (hx, hy) = (at.of(&lag.hx), at.of(&lag.hy));
                    let (gxx, gyy, gxy) = (at.of(&lag.gxx), at.of(&lag.gyy), at.of(&lag.gxy));
                    // ∇D = -λ·g; the Eulerian gradient is (I + ∇D)^-T ∇h.
                    let (a, d, bc) = (1.0 - lambda * gxx, 1.0 - lambda * gyy, -lambda * gxy);
                    let det = a * d - bc * bc;
                    let (ex, ey) =
                        if det.abs() > 1e-3 { ((d * hx - bc * hy) / det, (a * hy - bc * hx) / det) } else { (hx, hy) };
                    let len = (ex * ex + ey * ey + 1.0).sqrt();
                    normal[c] = [-ex / len, -ey / len, 1.0 / len];
                    foam[c] = at.of(&foam_l).clamp(0.0, 1.0);
                }
            },
        );
        PatchMaps { size: n, extent_m: self.extent_m, height, displacement, normal, foam }
    }
}

/// Transposes an n x n matrix in place, in 32 x 32 blocks (cache-friendly).
fn transpose_square(m: &mut [Complex32], n: usize) {
    const B: usize = 32;
    for r0 in (0..n).step_by(B) {
        for c0 in (r0..n).step_by(B) {
            for r in r0..(r0 + B).min(n) {
                for c in c0.max(r + 1)..(c0 + B).min(n) {
                    m.swap(r * n + c, c * n + r);
                }
            }
        }
    }
}

/// A coordinate wrapped into 0..n (lattice units) with floats (no integer division).
#[inline(always)]
fn wrap(v: f32, n: usize) -> f32 {
    let nf = n as f32;
    let w = v - (v / nf).floor() * nf;
    if w >= nf { 0.0 } else { w }
}

/// The four lattice points around a position of a periodic n x n field and their weights,
/// for reading several fields at one point.
struct Bilinear {
    i00: usize,
    i01: usize,
    i10: usize,
    i11: usize,
    tx: f32,
    ty: f32,
}

impl Bilinear {
    #[inline(always)]
    fn new(n: usize, x: f32, y: f32) -> Bilinear {
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

    #[inline(always)]
    fn of(&self, f: &[f32]) -> f32 {
        let top = f[self.i00] + (f[self.i01] - f[self.i00]) * self.tx;
        let bottom = f[self.i10] + (f[self.i11] - f[self.i10]) * self.tx;
        top + (bottom - top) * self.ty
    }
}

/// Catmull–Rom interpolation of a periodic n x n field at (x, y) lattice units.
fn cubic(f: &[f32], n: usize, x: f32, y: f32) -> f32 {
    let (x, y) = (wrap(x, n), wrap(y, n));
    let (fx, fy) = (x.floor(), y.floor());
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
