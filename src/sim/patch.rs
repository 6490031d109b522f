//! A periodic patch of sea for engines: the same spectra (wind sea and swells), choppiness,
//! second-order height, loop and foam as [`super::ocean::Sea`], but with wavenumbers on the
//! patch's lattice (kx, ky multiples of 2π/extent), summed by FFT, so the maps tile without a
//! seam.
//!
//! Each lattice wavenumber k (|k| below the lattice's Nyquist, k ≠ 0) is one travelling wave
//! `a·cos(k·x - ωt + φ)` with `a = √(2·F(k)·Δk²)`, F the directional wavenumber spectrum
//! `E(f, θ)·(df/dk)/k` summed over the wind sea and the swells (so Σa²/2 is the lattice's
//! integral of the spectrum), φ from the seed and ω from the depth's dispersion (rounded to
//! a whole multiple of 2π/T for a loop: on a lattice the wavenumber cannot move, so the
//! dispersion is then exact to half a frequency step). Per moment eight real fields and one
//! complex one come from five complex inverse FFTs (two real fields packed in each, by the
//! Hermitian halves of their spectra): height, displacement, slopes, the displacement's
//! gradient and B = Σ a·√k·e^(iθ) for the second-order height. The waves' rotations use
//! tidepool's own sine ([`sincos_turns`]) and the FFT the arithmetic of rustfft's scalar
//! planner ([`fft`]), so the maps are the same bytes on every machine.
//!
//! Heights are resampled at the fixed lattice points (Eulerian: what a height field holds),
//! like [`super::ocean::SeaSurface::height`]; normals are those of that surface.
//!
//! # Foam
//! Foam follows the model of [`super::foam`] at the resting points of a lattice of its own,
//! the patch's lattice cut to at most [`FOAM_LATTICE`] points a side (the same waves, those
//! beyond its Nyquist counted as unresolved): per foam step the fold fields (two complex
//! FFTs), the source at every point (kept for the memory's W steps), and the cover as the
//! memory's weighted sum, resampled under the Eulerian points like the heights. A series of
//! maps adds one foam step at a time; a single set computes the memory's W steps.

use crate::error::ValueError;
use std::f64::consts::PI;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use rustfft::num_complex::Complex32;

use super::dispersion;
use super::foam::{FoamClock, FoamModel};

mod fft;
mod fill;
mod foam;
mod moment;
mod sampling;
use super::ocean::{EULER_ITERATIONS, Sea, SeaParams, SeaTime, sizing_wavelength_m};
use super::trig::fast_sincos;
use fft::{FftScratch, InverseFft2};
use moment::Workspace;
use sampling::{Bilinear, cubic, round_even, sincos_turns};

/// Smallest and largest lattice side.
pub const PATCH_SIZE_RANGE: (usize, usize) = (8, 4096);
/// Smallest and largest extent, m.
pub const PATCH_EXTENT_RANGE_M: (f64, f64) = (1.0, 100_000.0);
/// The foam lattice's largest side.
pub const FOAM_LATTICE: usize = 512;

/// The fields of one moment, on the lattice; row 0 is the north edge, columns run east.
/// The default is no maps yet (every field empty), for a patch to fill.
#[derive(Clone, Debug, Default, PartialEq)]
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

/// The waves of a square lattice: per point (row-major, FFT order) a·e^(iφ), ω, the loop
/// harmonic and the wavenumber; and its inverse 2-D FFT.
struct Lattice {
    n: usize,
    amp: Vec<Complex32>,
    omega: Vec<f64>,
    harmonic: Vec<u32>,
    kx: Vec<f32>,
    ky: Vec<f32>,
    /// |k| (1 where k = 0, whose wave is silent).
    k: Vec<f32>,
    fft: InverseFft2,
}

/// A periodic patch of sea and the foam it has made so far.
pub struct PatchSea {
    params: SeaParams,
    size: usize,
    extent_m: f64,
    sea: Lattice,
    foam: Option<PatchFoam>,
    /// A moment's buffers, kept between the steps of a series.
    work: Workspace,
}

/// The foam of a patch: its lattice, model, clock and memory.
struct PatchFoam {
    lattice: Lattice,
    model: FoamModel,
    /// The slope variance the foam lattice resolves (both axes).
    resolved_slope: f32,
    clock: FoamClock,
    weights: Vec<f32>,
    /// W + 1 sources per point (step n at slot n mod (W + 1)).
    ring: Vec<u16>,
    /// The newest step in the ring.
    top: Option<i64>,
    /// A foam step and the cover of it and the next at every point (see `cover`).
    sums: Option<(i64, Vec<(f32, f32)>)>,
}

impl std::fmt::Debug for PatchSea {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PatchSea").field("params", &self.params).field("size", &self.size).finish_non_exhaustive()
    }
}

impl PatchSea {
    /// Checks a patch's side and extent.
    pub fn check(size: usize, extent_m: f64) -> Result<(), ValueError> {
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
}

impl PatchSea {
    /// A map's side when it is square: maps tile, so width and height must agree.
    pub fn check_map_size(width: usize, height: usize) -> Result<usize, ValueError> {
        if width != height {
            return Err(ValueError::new(
                "map size",
                format!(
                    "maps are square so that they tile; give a square size such as 1024x1024 (not {width}x{height})"
                ),
            ));
        }
        PatchSea::check(width, PATCH_EXTENT_RANGE_M.0)?;
        Ok(width)
    }
}

/// How many peak wavelengths a map spans when no extent is given.
pub const DEFAULT_MAP_WAVELENGTHS: f64 = 10.0;

impl PatchSea {
    /// The default side of a map of the sea `params` describes, m (10
    /// peak wavelengths of the wind sea, and at least four of the longest swell's; 100 m for a
    /// calm without swell).
    pub fn default_extent_m(params: &SeaParams) -> f64 {
        sizing_wavelength_m(params).map_or(100.0, |l| DEFAULT_MAP_WAVELENGTHS * l)
    }
}

/// A lattice index as a signed wavenumber index.
fn signed(i: usize, n: usize) -> i64 {
    if i < n / 2 { i as i64 } else { i as i64 - n as i64 }
}

impl Lattice {
    /// The waves of `params`' sea on an `n x n` lattice `extent_m` across: the wind sea's
    /// spectrum and every swell's, a phase per point from the seed.
    fn of_sea(params: &SeaParams, n: usize, extent_m: f64) -> Lattice {
        let spectrum = params.wind_spectrum();
        let depth = spectrum.depth_m();
        let swells = params.swell_spectra();
        let downwind = (params.wind_from_deg + 180.0).to_radians();
        let dk = 2.0 * PI / extent_m;
        let mut rng = ChaCha8Rng::seed_from_u64(params.seed ^ 0x9a7c);
        let mut lattice = Lattice::empty(n, extent_m);
        // The phases in the lattice's order from one stream, then each point on its own (on
        // all cores: the same values whatever their number).
        let phases: Vec<f64> = (0..n * n).map(|_| rng.random()).collect();
        let (kx, ky, looping) = (&lattice.kx, &lattice.ky, params.loop_period);
        let waves: Vec<(Complex32, f64, u32)> = (0..n * n)
            .into_par_iter()
            .map(|i| {
                let (mc, mr) = (signed(i % n, n), signed(i / n, n));
                let (kx, ky) = (f64::from(kx[i]), f64::from(ky[i]));
                let k = kx.hypot(ky);
                if k == 0.0 || mc.unsigned_abs() as usize == n / 2 || mr.unsigned_abs() as usize == n / 2 {
                    return (Complex32::new(0.0, 0.0), 0.0, 0);
                }
                let w = dispersion::angular_frequency(k, depth);
                let f = w / (2.0 * PI);
                let bearing = kx.atan2(ky);
                let mut directional = spectrum.directional_energy(f, bearing - downwind);
                for swell in &swells {
                    directional += swell.directional_energy(f, bearing - swell.bearing_rad());
                }
                let density = directional * dispersion::group_speed(k, depth) / (2.0 * PI) / k;
                let a = (2.0 * density * dk * dk).sqrt();
                let (s, co) = sincos_turns(phases[i]);
                let amp = Complex32::new((a * co) as f32, (a * s) as f32);
                match looping {
                    Some(p) => {
                        let harmonic = (f * p.seconds()).round().max(1.0) as u32;
                        (amp, 2.0 * PI * f64::from(harmonic) / p.seconds(), harmonic)
                    }
                    None => (amp, w, 0),
                }
            })
            .collect();
        for (i, (amp, omega, harmonic)) in waves.into_iter().enumerate() {
            (lattice.amp[i], lattice.omega[i], lattice.harmonic[i]) = (amp, omega, harmonic);
        }
        lattice
    }

    /// An `n x n` lattice `extent_m` across with no waves.
    fn empty(n: usize, extent_m: f64) -> Lattice {
        let dk = 2.0 * PI / extent_m;
        let (mut kx, mut ky) = (vec![0.0f32; n * n], vec![0.0f32; n * n]);
        for r in 0..n {
            for c in 0..n {
                // Column: east wavenumber; row: the wavenumber of going south (row 0 is north).
                kx[r * n + c] = (signed(c, n) as f64 * dk) as f32;
                ky[r * n + c] = (-(signed(r, n) as f64) * dk) as f32;
            }
        }
        let fft = InverseFft2::new(n);
        let k = kx.iter().zip(&ky).map(|(x, y)| if *x == 0.0 && *y == 0.0 { 1.0 } else { x.hypot(*y) }).collect();
        Lattice {
            n,
            amp: vec![Complex32::new(0.0, 0.0); n * n],
            omega: vec![0.0; n * n],
            harmonic: vec![0; n * n],
            kx,
            ky,
            k,
            fft,
        }
    }

    /// The waves of `sea` whose indices both lie strictly inside an `m x m` lattice's Nyquist,
    /// on that lattice (the same extent).
    fn cut(sea: &Lattice, m: usize, extent_m: f64) -> Lattice {
        let mut out = Lattice::empty(m, extent_m);
        let n = sea.n;
        for r in 0..m {
            for c in 0..m {
                let (mc, mr) = (signed(c, m), signed(r, m));
                if mc.unsigned_abs() as usize == m / 2 || mr.unsigned_abs() as usize == m / 2 {
                    continue;
                }
                let from = (mr.rem_euclid(n as i64) as usize) * n + mc.rem_euclid(n as i64) as usize;
                let to = r * m + c;
                out.amp[to] = sea.amp[from];
                out.omega[to] = sea.omega[from];
                out.harmonic[to] = sea.harmonic[from];
            }
        }
        out
    }

    /// The slope variance the lattice's waves carry (both axes), Σ a²k²/2.
    fn slope_variance(&self) -> f64 {
        self.amp.iter().zip(&self.k).map(|(a, k)| 0.5 * f64::from(a.norm_sqr()) * f64::from(*k).powi(2)).sum()
    }

    /// The rotation e^(-iωt) of lattice wave `i` at `time`: the turns reduced exactly in f64
    /// (to the nearest whole turn, ±½), the sine and cosine of what is left in f32.
    fn rotation(&self, i: usize, time: SeaTime) -> Complex32 {
        let turns = match time {
            SeaTime::Seconds(t) => self.omega[i] * t / (2.0 * PI),
            SeaTime::Ticks(u) => f64::from(self.harmonic[i].wrapping_mul(u as u32)) / 4_294_967_296.0,
        };
        let left = turns - round_even(turns);
        let (s, c) = fast_sincos((-left * 2.0 * PI) as f32);
        Complex32::new(c, s)
    }

    /// Every lattice wave at `time`: a·e^(iφ)·e^(-iωt).
    fn waves(&self, time: SeaTime) -> Vec<Complex32> {
        let mut waves = Vec::new();
        self.waves_into(time, &mut waves);
        waves
    }

    /// As [`Lattice::waves`], into `waves` (resized to the lattice).
    fn waves_into(&self, time: SeaTime, waves: &mut Vec<Complex32>) {
        waves.resize(self.amp.len(), Complex32::new(0.0, 0.0));
        waves.par_iter_mut().enumerate().for_each(|(i, w)| {
            *w = if self.amp[i].norm_sqr() == 0.0 { self.amp[i] } else { self.amp[i] * self.rotation(i, time) };
        });
    }

    /// The inverse 2-D FFT, in place, of a spectrum in the lattice's order (`buf[r·n + c]`),
    /// leaving the field in row-major order ([`InverseFft2`]).
    fn ifft2(&self, buf: &mut [Complex32], scratch: &mut FftScratch) {
        self.fft.process(buf, scratch);
    }

    /// Two real fields from one complex transform. `coefficients(i, w)` gives, for the
    /// travelling wave w = a·e^(iφ)·e^(-iωt) at lattice point i, its coefficients (c_f, c_g)
    /// in the two fields f = re Σ c_f·e^(ik·x) and g = re Σ c_g·e^(ik·x). Each real field's
    /// spectrum is the Hermitian S(k) = (c(k) + conj(c(-k)))/2, and the transform of
    /// S_f + i·S_g is f + i·g.
    fn real_fields(
        &self,
        waves: &[Complex32],
        coefficients: impl Fn(usize, Complex32) -> (Complex32, Complex32) + Sync,
        scratch: &mut FftScratch,
    ) -> (Vec<f32>, Vec<f32>) {
        let mut buf = Vec::new();
        self.real_fields_into(waves, coefficients, &mut buf, scratch);
        // Element by element, so in parallel with the same bits.
        (buf.par_iter().map(|c| c.re).collect(), buf.par_iter().map(|c| c.im).collect())
    }

    /// As [`Lattice::real_fields`], into `buf` (resized to the lattice), the two fields left packed as the transform gives them:
    /// f in the real parts, g in the imaginary ones; `scratch` is the
    /// transforms' working space, shared by a moment's transforms.
    fn real_fields_into(
        &self,
        waves: &[Complex32],
        coefficients: impl Fn(usize, Complex32) -> (Complex32, Complex32) + Sync,
        buf: &mut Vec<Complex32>,
        scratch: &mut FftScratch,
    ) {
        self.fill_packed(waves, |i, w| [coefficients(i, w)], [buf]);
        self.ifft2(buf, scratch);
    }

    /// The displacement's gradient per unit λ, each times -1: g_ab = Σ a·(k_a·k_b/k)·cos θ.
    /// (Pairing g_xy with the next step's in one transform would save a quarter of a foam
    /// memory's transforms, but round differently from a step computed alone, and a series
    /// must give the same bits as a set computed from nothing.)
    fn fold_fields(&self, waves: &[Complex32]) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
        let coef = |i: usize| {
            let (kx, ky, k) = (self.kx[i], self.ky[i], self.k[i]);
            (kx * kx / k, ky * ky / k, kx * ky / k)
        };
        let mut scratch = FftScratch::default();
        let (gxx, gyy) = self.real_fields(waves, |i, w| (w * coef(i).0, w * coef(i).1), &mut scratch);
        let (gxy, _) = self.real_fields(waves, |i, w| (w * coef(i).2, Complex32::new(0.0, 0.0)), &mut scratch);
        (gxx, gyy, gxy)
    }
}

impl PatchSea {
    /// A `size x size` patch `extent_m` metres across of the sea `params` describes.
    pub fn new(params: SeaParams, size: usize, extent_m: f64) -> Result<PatchSea, ValueError> {
        PatchSea::check(size, extent_m)?;
        let sea = Lattice::of_sea(&params, size, extent_m);
        let model = FoamModel::of(&Sea::new(params));
        let foam = model.is_active().then(|| {
            let lattice = Lattice::cut(&sea, size.min(FOAM_LATTICE), extent_m);
            let clock = FoamClock::of(&params);
            let slots = clock.memory_steps() + 1;
            PatchFoam {
                resolved_slope: lattice.slope_variance() as f32,
                ring: vec![0; lattice.n * lattice.n * slots],
                lattice,
                model,
                clock,
                weights: clock.weights(),
                top: None,
                sums: None,
            }
        });
        Ok(PatchSea { params, size, extent_m, sea, foam, work: Workspace::default() })
    }

    #[cfg(any(test, feature = "testing"))]
    /// Lattice points per side.
    pub fn size(&self) -> usize {
        self.size
    }

    #[cfg(any(test, feature = "testing"))]
    /// The variance the lattice carries, m² (Σa²/2).
    pub fn lattice_variance(&self) -> f64 {
        self.sea.amp.iter().map(|a| 0.5 * f64::from(a.norm_sqr())).sum()
    }

    #[cfg(any(test, feature = "testing"))]
    fn time(&self, time_s: f64) -> SeaTime {
        match self.params.loop_period {
            Some(p) => SeaTime::Ticks(p.ticks(time_s)),
            None => SeaTime::Seconds(time_s),
        }
    }

    fn time_after(&self, start_s: f64, elapsed_s: f64) -> SeaTime {
        match self.params.loop_period {
            Some(p) => SeaTime::Ticks(p.ticks(start_s) + p.ticks(elapsed_s)),
            None => SeaTime::Seconds(start_s + elapsed_s),
        }
    }

    #[cfg(any(test, feature = "testing"))]
    /// The maps at `time_s`. Foam continues from the previous call when time moved forward
    /// by less than the foam's memory, and computes the memory otherwise; the maps are the
    /// same bits either way.
    pub fn maps(&mut self, time_s: f64) -> PatchMaps {
        let time = self.time(time_s);
        self.maps_at(time)
    }

    /// The maps `elapsed_s` after `start_s` into `maps` (a series' frames: for a looping sea a
    /// whole number of loops after the start is exactly the start's maps). `maps` is resized to
    /// the patch and every field overwritten: a series hands back the maps it has written, so
    /// a step reuses their 32 MiB at 1024² rather than faulting in fresh pages.
    pub fn maps_after(&mut self, start_s: f64, elapsed_s: f64, maps: &mut PatchMaps) {
        let time = self.time_after(start_s, elapsed_s);
        self.maps_into(time, maps);
    }

    #[cfg(any(test, feature = "testing"))]
    fn maps_at(&mut self, time: SeaTime) -> PatchMaps {
        let mut maps = PatchMaps::default();
        self.maps_into(time, &mut maps);
        maps
    }

    fn maps_into(&mut self, time: SeaTime, maps: &mut PatchMaps) {
        let foam = self.foam.as_mut().map(|f| f.cover(time));
        let mut work = std::mem::take(&mut self.work);
        self.resample_into(time, foam.as_ref(), &mut work, maps);
        self.work = work;
    }

    #[cfg(any(test, feature = "testing"))]
    /// The maps at `time_s` without foam (its `foam` is all 0): heights, displacement and
    /// normals only, without the foam's memory.
    pub fn surface(&self, time_s: f64) -> PatchMaps {
        let mut maps = PatchMaps::default();
        self.resample_into(self.time(time_s), None, &mut Workspace::default(), &mut maps);
        maps
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The maps are a periodic field, not a picture that happens to tile: a linear sea's
    /// height texels equal, to the centimetre of the 16-bit PNG (one level), the sum of the
    /// lattice's waves evaluated directly in f64, at the last column and one period on,
    /// where the first column is.
    #[test]
    fn the_maps_continue_across_their_edges_to_a_centimetre() {
        let params = SeaParams { wind_m_s: 12.0, choppiness: 0.0, seed: 4, ..SeaParams::default() };
        let (n, extent) = (64, 400.0);
        let patch = PatchSea::new(params, n, extent).unwrap();
        let maps = patch.surface(3.0);
        let waves = patch.sea.waves(patch.time(3.0));
        let direct = |x: f64, y: f64| -> f64 {
            waves
                .iter()
                .zip(patch.sea.kx.iter().zip(&patch.sea.ky))
                .map(|(w, (kx, ky))| {
                    let phase = f64::from(*kx) * x + f64::from(*ky) * y;
                    f64::from(w.re) * phase.cos() - f64::from(w.im) * phase.sin()
                })
                .sum()
        };
        let level = |h: f64| (h * 100.0).round() as i64;
        let cell = extent / n as f64;
        let mut worst = 0;
        for r in [0, 17, 40, 63] {
            let y = -(r as f64) * cell;
            for (c, x) in [(0, extent), (0, 0.0), (n - 1, (n - 1) as f64 * cell), (n / 2, extent * 1.5)] {
                let got = level(f64::from(maps.height[r * n + c]));
                worst = worst.max((got - level(direct(x, y))).abs());
            }
        }
        assert!(worst <= 1, "the maps differ from their waves by {worst} levels at the seam");
        assert!(maps.height.iter().any(|h| h.abs() > 0.3), "a sea with waves");
    }

    /// A series of maps (foam continued one step at a time) and a set computed from nothing at
    /// the same moment are the same bits, foam included.
    #[test]
    fn a_series_and_a_set_from_nothing_are_the_same_bits() {
        let params = SeaParams { wind_m_s: 15.0, seed: 6, ..SeaParams::default() };
        let mut series = PatchSea::new(params, 64, 300.0).unwrap();
        for k in 0..40 {
            series.maps(3.0 + f64::from(k) / 7.0);
        }
        let t = 3.0 + 40.0 / 7.0;
        let (a, b) = (series.maps(t), PatchSea::new(params, 64, 300.0).unwrap().maps(t));
        assert!(a.foam.iter().any(|&f| f > 0.01), "a sea with foam");
        assert!(a == b, "a series and a set from nothing differ");
    }

    /// A series writes each step into the maps it handed back (any size, any contents):
    /// every field is overwritten, so the reused maps equal new ones bit for bit.
    #[test]
    fn maps_written_over_old_ones_are_new_maps() {
        let params = SeaParams { wind_m_s: 17.0, seed: 6, ..SeaParams::default() };
        let mut reused = PatchMaps {
            size: 7,
            extent_m: 1.0,
            height: vec![f32::NAN; 80],
            displacement: vec![[9.0; 3]; 64 * 64 + 5],
            normal: vec![[f32::INFINITY; 3]; 64 * 64],
            foam: vec![2.0; 64 * 64],
        };
        let (mut kept, mut fresh) =
            (PatchSea::new(params, 64, 300.0).unwrap(), PatchSea::new(params, 64, 300.0).unwrap());
        for k in 0..3 {
            kept.maps_after(3.0, f64::from(k) / 7.0, &mut reused);
            let mut new = PatchMaps::default();
            fresh.maps_after(3.0, f64::from(k) / 7.0, &mut new);
            assert!(new.foam.iter().any(|&f| f > 0.01), "a sea with foam");
            assert!(reused == new, "step {k}: maps written over old ones differ from new maps");
        }
    }

    /// Two real fields packed in one complex transform (the height in the real parts, its east
    /// slope in the imaginary ones, as a moment packs them) each equal the field summed
    /// directly from the waves in f64, to 1e-5 of the field's largest value.
    #[test]
    fn a_packed_transform_is_two_real_fields() {
        let params = SeaParams { wind_m_s: 12.0, seed: 8, ..SeaParams::default() };
        let (n, extent) = (32, 200.0);
        let patch = PatchSea::new(params, n, extent).unwrap();
        let l = &patch.sea;
        let waves = l.waves(patch.time(2.0));
        let coefficients = |i: usize, w: Complex32| (w, Complex32::new(0.0, 1.0) * w * l.kx[i]);
        let mut scratch = FftScratch::default();
        let packed = l.real_fields(&waves, coefficients, &mut scratch);
        let cell = extent / n as f64;
        let direct = |r: usize, c: usize| -> (f64, f64) {
            let (x, y) = (c as f64 * cell, -(r as f64) * cell);
            let mut sum = (0.0, 0.0);
            for (i, w) in waves.iter().enumerate() {
                let phase = f64::from(l.kx[i]) * x + f64::from(l.ky[i]) * y;
                let (s, co) = phase.sin_cos();
                let (f, g) = coefficients(i, *w);
                sum.0 += f64::from(f.re) * co - f64::from(f.im) * s;
                sum.1 += f64::from(g.re) * co - f64::from(g.im) * s;
            }
            sum
        };
        let expected: Vec<(f64, f64)> = (0..n * n).map(|i| direct(i / n, i % n)).collect();
        for (field, got, which) in [(0, &packed.0, "height"), (1, &packed.1, "slope")] {
            let value = |e: &(f64, f64)| if field == 0 { e.0 } else { e.1 };
            let largest = expected.iter().map(|e| value(e).abs()).fold(0.0, f64::max);
            let worst = got.iter().zip(&expected).map(|(g, e)| (f64::from(*g) - value(e)).abs()).fold(0.0, f64::max);
            assert!(largest > 0.01, "the {which} is a field of waves");
            assert!(worst <= 1e-5 * largest, "the packed {which} is off by {worst:e} of {largest:e}");
        }
    }

    #[test]
    fn sincos_turns_is_accurate_everywhere() {
        for i in -3000..3000 {
            let t = i as f64 * 0.000_731 + 0.1 * (i % 7) as f64;
            let (s, c) = sincos_turns(t);
            let x = t * std::f64::consts::TAU;
            assert!((s - x.sin()).abs() < 1e-14 && (c - x.cos()).abs() < 1e-14, "{t}");
        }
    }
}
