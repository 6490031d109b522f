//! The wind-driven sea: travelling sines drawn from a spectrum (Pierson–Moskowitz, JONSWAP or
//! TMA, spread by one of four laws, [`super::spectra`]) and from any swells, plus a
//! diamond-square fBm tail, moved sideways by a choppy displacement and foaming where it folds
//! (the foam module, `sim::foam`, which sums the sines through [`Sea::fold_rows`]).
//!
//! # The sines
//! [`FREQUENCY_BINS`] geometric frequency bins from [`BAND_LOW`]·fp to [`CUTOFF`]·fp times
//! [`DIRECTION_BINS`] direction bins over the full circle. Each component's amplitude is
//! `a = √(2·E(f, θ)·df·dθ)` with E taken at the bin's midpoint (so Σa²/2 is the midpoint-rule
//! integral of the band); its frequency and direction are then jittered inside the bin and its
//! phase drawn uniformly, all from the seed, so the sea never visibly repeats. Its wavenumber
//! follows ω² = g·k·tanh(k·h) ([`super::dispersion`]; deep water unless the spectrum is TMA).
//! Components carrying less than [`NEGLIGIBLE`] of m0 (almost all of them upwind) are dropped.
//! The lanes of the vectorised sum are padded with silent components by construction, and a
//! sample leaves out exactly the components its footprint cannot carry.
//!
//! # Swell
//! Each swell ([`super::spectra::swell`]) adds [`SWELL_FREQUENCY_BINS`] x
//! [`SWELL_DIRECTION_BINS`] sines of its own, from [`SWELL_BAND`] times its peak frequency and
//! ±[`SWELL_HALF_WIDTH_RAD`] about its direction, drawn from their own seeded stream (adding a
//! swell leaves the wind sea's sines as they were) and scaled to carry all of its variance.
//! They join the wind sea's in one list, sorted longest first; the tail is the wind sea's.
//!
//! # Loops
//! With a [`LoopPeriod`] T every frequency is rounded to a whole multiple of 1/T (at least
//! one) and its wavenumber recomputed from it, so dispersion stays exact; time is counted in
//! ticks of T/2³² and phases are advanced in whole ticks ([`super::looping`]). The tail's drift
//! is rounded so that it crosses a whole number of tail periods in T. The sea at T is the sea
//! at 0 bit for bit; [`Sea::time_after`] counts a start and the time since it apart, so a
//! whole number of loops after any start is the start.
//!
//! # The tail
//! Above the cut-off fc = 5·fp a wrapping diamond-square fBm with H = 1 carries the variance:
//! its corner lattice has the spacing λc (the paper's "corners from PM", drawn with the tail's
//! standard deviation), 8 corners a side, refined down to about 0.2 m (at most 7 octaves).
//! It drifts downwind at the phase speed of fc.
//!
//! # Choppiness
//! The water that rests at x is carried to `x + λ·D(x)` with the linear Lagrangian
//! displacement `D = -Σ a·(k/|k|)·sin θ` (Gerstner's wave for one component, Tessendorf's
//! "choppy waves", the choppy wave model of Nouguier et al.). λ = 1 ([`DEFAULT_CHOPPINESS`])
//! is the physical value; 0 is today's sea, heights only. Points gather under crests and
//! spread under troughs, so crests are sharper than troughs.
//!
//! That alone does not skew a random sea: seen at fixed points, the displacement's
//! sum-frequency terms (what sharpens crests) come with difference-frequency terms of the same
//! size and opposite sign (a set-down under every wave group), and the two cancel in the
//! third moment (for N independent components the skewness falls as 1/N; measured -0.01 at
//! Beaufort 6). Second-order theory (Longuet-Higgins 1963, collinear deep-water waves) has
//! almost no difference term for waves of similar length. The pair-wise difference between
//! the two is `½·a_i·a_j·min(k_i, k_j)·cos(θ_i - θ_j)`; with min(k_i, k_j) ≈ √(k_i·k_j) it is
//! `λ·|B|²/2`, B = Σ a·√k·e^(iθ), which the resting point's height gets added: one more pair
//! of sums, exact for a single wave (where Gerstner's wave already is Stokes's to second
//! order and the term only restores the mean level), and narrow-band seas. The skewness
//! becomes Longuet-Higgins's ≈ 3·k·σ. [`SeaSurface::height`] returns the
//! **Eulerian** height at a fixed point (what a heightmap holds): it finds the resting point
//! x0 with x0 + λ·D(x0) = x by fixed-point iteration ([`EULER_ITERATIONS`]).
//!
//! # Sampling with a footprint
//! A renderer samples the sea at mesh vertices, each standing for a patch of sea (a
//! [`Footprint`]). A component is kept fully up to a phase step of π/2 per sample and faded
//! out by π (Nyquist); the fBm is read at the octave of the footprint's size. What is removed
//! comes back as the unresolved slope variance (the total is Cox–Munk's `0.003 + 0.00512·U`).

use crate::error::ValueError;
use std::f64::consts::PI;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::fbm::{self, Fbm};
use super::looping::LoopPeriod;
use super::spectra::swell::{SwellSpectrum, Swells};
use super::spectra::{SeaSpectrum, SpectrumChoice, Spreading};
use super::spectrum::{G, wavelength_m};
use super::surface::Footprint;
use super::trig::fast_sincos;

mod build;
mod fold;
mod params;
mod surface;
pub(crate) use fold::{FOLD_ROWS, PhaseRows};
pub use surface::SeaSurface;
use surface::resolution_weight;

/// Lowest frequency of the sines, as a multiple of fp.
pub const BAND_LOW: f64 = 0.5;
/// The cut-off between the sines and the fBm tail, as a multiple of fp.
pub const CUTOFF: f64 = 5.0;
/// Frequency bins of the sines.
pub const FREQUENCY_BINS: usize = 24;
/// Direction bins of the sines over the full circle.
pub const DIRECTION_BINS: usize = 16;
/// Components with less variance than this fraction of m0 are dropped.
pub const NEGLIGIBLE: f64 = 1e-5;
/// Components with less slope variance than this fraction of the sines' are left out of the
/// foam's Jacobian.
pub const FOLD_NEGLIGIBLE: f64 = 1e-3;
/// Lanes of the vectorised sum over components.
pub const LANES: usize = 8;
/// Corner lattice points per side of the tail (its period is this many cut-off wavelengths).
pub const TAIL_CORNERS: usize = 8;
/// The finest cell of the tail the refinement aims at, metres.
pub const TAIL_FINEST_M: f64 = 0.2;
/// The most octaves the tail is refined below its corner lattice.
pub const TAIL_MAX_LEVELS: u32 = 7;
/// The physical choppiness: the linear Lagrangian displacement, unscaled.
pub const DEFAULT_CHOPPINESS: f64 = 1.0;
/// The largest choppiness tidepool accepts (beyond it most of the surface folds over).
pub const MAX_CHOPPINESS: f64 = 4.0;
/// Fixed-point iterations that find the resting point under a fixed position.
pub const EULER_ITERATIONS: usize = 4;
/// Frequency bins of a swell's sines, from [`SWELL_BAND`]`.0` to `.1` times its peak (each
/// bin 5.6 % wide: a sampled swell peaks within 3 % of its period).
pub const SWELL_FREQUENCY_BINS: usize = 16;
/// Direction bins of a swell's sines, over ±[`SWELL_HALF_WIDTH_RAD`] about its direction.
pub const SWELL_DIRECTION_BINS: usize = 8;
/// The frequencies a swell's sines span, as multiples of its peak frequency (95 % of a
/// swell's variance; the sines carry all of it).
pub const SWELL_BAND: (f64, f64) = (0.75, 1.8);
/// Half the width of the directions a swell's sines span, radians (50°: three standard
/// deviations of its cos-2s spread).
pub const SWELL_HALF_WIDTH_RAD: f64 = 50.0 * std::f64::consts::PI / 180.0;

/// Cox and Munk's mean square slope at zero wind (both axes): the slope of waves the local
/// wind did not raise (their clean-surface intercept).
pub const CALM_SLOPE_VARIANCE: f64 = 0.003;

/// The Cox–Munk mean square slope (both axes together) of a sea under `wind_m_s`:
/// `0.003 + 0.00512·U` (clean surface).
pub fn cox_munk_slope_variance(wind_m_s: f64) -> f64 {
    CALM_SLOPE_VARIANCE + 0.00512 * wind_m_s.max(0.0)
}

impl SeaParams {
    /// The choppiness a sea has unless told otherwise: the physical displacement.
    pub const DEFAULT_CHOPPINESS: f64 = DEFAULT_CHOPPINESS;
    /// The wind a sea has unless told otherwise, m/s.
    pub const DEFAULT_WIND_M_S: f64 = crate::sim::wind::DEFAULT_SEA_WIND_M_S;
    /// The direction the wind blows from unless told otherwise, degrees clockwise from north.
    pub const DEFAULT_WIND_FROM_DEG: f64 = crate::sim::wind::DEFAULT_WIND_FROM_DEG;

    /// Checks a choppiness: finite, 0..=4.
    pub fn check_choppiness(value: f64) -> Result<f64, ValueError> {
        if !value.is_finite() || !(0.0..=MAX_CHOPPINESS).contains(&value) {
            return Err(ValueError::new(
                "choppiness",
                format!(
                    "the choppiness {value} is not a number in 0..={MAX_CHOPPINESS}; 0 moves the water only up and \
                     down, {DEFAULT_CHOPPINESS} is the physical displacement"
                ),
            ));
        }
        Ok(value)
    }
}

/// The z with P(N(0,1) > z) = p, for p in (0, 1); +inf for p <= 0, -inf for p >= 1.
pub fn upper_normal_quantile(p: f64) -> f64 {
    if p <= 0.0 {
        return f64::INFINITY;
    }
    if p >= 1.0 {
        return f64::NEG_INFINITY;
    }
    let (mut lo, mut hi) = (-40.0f64, 40.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if 0.5 * libm::erfc(mid / 2f64.sqrt()) > p { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

/// One travelling sine of the sea.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Component {
    /// Amplitude, m.
    pub amplitude_m: f64,
    /// Frequency, Hz.
    pub frequency_hz: f64,
    /// Angular frequency ω = 2πf, rad/s.
    pub omega: f64,
    /// Wavenumber k with ω² = g·k·tanh(k·h), rad/m.
    pub wavenumber: f64,
    /// Where it travels to, radians clockwise from north.
    pub bearing_rad: f64,
    /// Phase at t = 0, radians.
    pub phase_rad: f64,
    /// In a looping sea, its frequency in multiples of 1/T (0 otherwise).
    pub harmonic: u32,
}

/// Everything that defines a sea. `Default` is the command line's sea: Pierson–Moskowitz with
/// the paper's spreading, no swell, the physical choppiness ([`SeaParams::DEFAULT_CHOPPINESS`]), no loop,
/// a 10 m/s wind from 330°, seed 1.
///
/// The four numbers are public fields; the spectrum, the swells and the loop are set through
/// the `with_*` builders, which check them, so their types (JONSWAP's γ and fetch, a TMA depth,
/// a swell list, a loop length) stay out of the API. With private fields a struct literal cannot
/// use `..SeaParams::default()`; a sea is one expression with the builders instead:
///
/// ```
/// use tidepool::SeaParams;
///
/// let sea = SeaParams::default().with_wind_m_s(12.0).with_jonswap(None, Some(50.0))?.with_swell(1.5, 12.0, 250.0)?;
/// assert_eq!(sea.wind_m_s, 12.0);
/// # Ok::<(), tidepool::ValueError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeaParams {
    /// Wind speed at 10 m, m/s (0 = flat calm).
    pub wind_m_s: f64,
    /// Where the wind comes from, degrees clockwise from north; waves travel the other way.
    pub wind_from_deg: f64,
    /// Seed of phases, jitter and the tail.
    pub seed: u64,
    /// The wind sea's spectrum.
    pub(crate) spectrum: SpectrumChoice,
    /// How the wind sea spreads over directions.
    pub(crate) spreading: Spreading,
    /// Swell from distant storms, summed with the wind sea.
    pub(crate) swells: Swells,
    /// λ, the scale of the horizontal displacement ([`SeaParams::check_choppiness`]); 0 = none.
    pub choppiness: f64,
    /// Repeat exactly every this many seconds (None = never).
    pub(crate) loop_period: Option<LoopPeriod>,
}

impl Default for SeaParams {
    fn default() -> Self {
        SeaParams {
            wind_m_s: 10.0,
            wind_from_deg: 330.0,
            seed: 1,
            spectrum: SpectrumChoice::PiersonMoskowitz,
            spreading: Spreading::Paper,
            swells: Swells::NONE,
            choppiness: DEFAULT_CHOPPINESS,
            loop_period: None,
        }
    }
}

impl SeaParams {
    /// The wind sea's spectrum, spread as asked.
    pub(crate) fn wind_spectrum(&self) -> SeaSpectrum {
        SeaSpectrum::new(self.wind_m_s, self.spectrum).with_spreading(self.spreading)
    }

    /// The longest peak period of the wind sea and the swells, s (None: a calm without swell).
    /// A loop must last at least ten of these ([`SeaParams::with_loop_s`]).
    pub fn longest_peak_period_s(&self) -> Option<f64> {
        let wind = self.wind_spectrum().peak_period_s();
        self.swells.iter().map(|s| s.period_s()).chain(wind).reduce(f64::max)
    }

    /// Every swell's spectrum, in the wind sea's depth.
    pub(crate) fn swell_spectra(&self) -> Vec<SwellSpectrum> {
        let depth = self.spectrum.depth_m();
        self.swells.iter().map(|s| SwellSpectrum::new(*s, depth)).collect()
    }

    /// The sea's total variance, m²: the wind sea's plus every swell's.
    pub fn m0(&self) -> f64 {
        self.wind_spectrum().m0() + self.swells.iter().map(|s| (s.height_m() / 4.0).powi(2)).sum::<f64>()
    }

    /// The significant height of the whole sea, m: 4·√m0 = √(Hs_sea² + Σ Hs_swell²).
    pub fn significant_height_m(&self) -> f64 {
        4.0 * self.m0().sqrt()
    }
}

/// A moment of the sea: seconds, or for a looping sea ticks of T/2³² from t = 0 (the sea
/// sees only the low 32 bits, the tick within the loop; the foam's clock counts them all).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SeaTime {
    /// Seconds from t = 0 (a sea that does not loop).
    Seconds(f64),
    /// Ticks of T/2³² from t = 0.
    Ticks(i64),
}

/// The tail: a drifting wrapping fBm field.
#[derive(Clone, Debug)]
struct Tail {
    field: Fbm,
    cell_m: f64,
    velocity_m_s: [f64; 2],
    /// In a looping sea: whole tail periods crossed per loop, east and north.
    loop_periods: [i64; 2],
    /// Its height variance (read by the tests).
    #[cfg_attr(not(test), allow(dead_code))]
    variance: f64,
    /// Per octave: the slope variance per axis of the field cut off there.
    octave_slope: Vec<f32>,
}

/// Per component, f32 for the hot loops, padded with silent components to whole lanes.
#[derive(Clone, Debug, Default)]
struct Lanes {
    kx: Vec<f32>,
    ky: Vec<f32>,
    amp: Vec<f32>,
    /// Unit travel direction (for the displacement).
    ux: Vec<f32>,
    uy: Vec<f32>,
    /// √k (the second-order height's weights).
    sqrt_k: Vec<f32>,
    /// a·kx²/k, a·ky²/k, a·kx·ky/k: the displacement's gradient per unit λ (times cos θ).
    dxx: Vec<f32>,
    dyy: Vec<f32>,
    dxy: Vec<f32>,
}

/// A sea: its spectrum, its sines and its tail. Immutable; sample it through [`Sea::surface`].
#[derive(Clone, Debug)]
pub struct Sea {
    params: SeaParams,
    spectrum: SeaSpectrum,
    components: Vec<Component>,
    lanes: Lanes,
    /// Unpadded, longest first.
    wavelength: Vec<f32>,
    /// The sines the foam's Jacobian sums: each carrying at least [`FOLD_NEGLIGIBLE`] of the
    /// sines' slope variance (the few hundred small side and upwind waves a sea has add
    /// little to its folding; what they carry counts as unresolved).
    fold: Lanes,
    fold_wavelength: Vec<f32>,
    /// For each of those, its index among the components.
    fold_index: Vec<usize>,
    tail: Option<Tail>,
    /// The slope variance of the whole surface (both axes): Cox–Munk's for the wind plus the
    /// swells' own.
    slope_total: f32,
    /// Unit vector (east, north) the wind blows towards.
    downwind: [f32; 2],
}

/// The wavelength that sizes patches and maps of the sea `params` describes, m: the wind
/// sea's peak wavelength (None for a calm without swell), but at least 0.4 of the longest
/// swell's, so that ten of them hold four swell waves.
pub fn sizing_wavelength_m(params: &SeaParams) -> Option<f64> {
    let spectrum = params.wind_spectrum();
    let wind = spectrum.peak_wavelength_m();
    let swell = params.swells.iter().map(|s| 0.4 * 2.0 * PI / spectrum.wavenumber(1.0 / s.period_s())).reduce(f64::max);
    match (wind, swell) {
        (Some(w), Some(s)) => Some(w.max(s)),
        (w, s) => w.or(s),
    }
}

impl Sea {
    /// The parameters it was built from.
    pub fn params(&self) -> SeaParams {
        self.params
    }

    /// Its spectrum.
    pub fn spectrum(&self) -> &SeaSpectrum {
        &self.spectrum
    }

    /// The sines, longest first.
    pub fn components(&self) -> &[Component] {
        &self.components
    }

    /// Components per sum including the silent padding (a whole number of lanes).
    pub fn padded_len(&self) -> usize {
        self.lanes.amp.len()
    }

    #[cfg(test)]
    /// The sines the foam's Jacobian sums (padded), of [`Sea::padded_len`].
    pub fn fold_len(&self) -> usize {
        self.fold.amp.len()
    }

    #[cfg(test)]
    /// The variance carried by the fBm tail, m² (0 for a calm).
    pub fn tail_variance(&self) -> f64 {
        self.tail.as_ref().map_or(0.0, |t| t.variance)
    }

    #[cfg(test)]
    /// The tail's field, if the sea is not calm.
    pub fn tail_field(&self) -> Option<&Fbm> {
        self.tail.as_ref().map(|t| &t.field)
    }

    /// The unit vector (east, north) the wind blows towards.
    pub fn downwind(&self) -> [f32; 2] {
        self.downwind
    }

    /// λ as f32.
    pub fn choppiness(&self) -> f32 {
        self.params.choppiness as f32
    }

    /// The slope variance of the whole surface (both axes): Cox–Munk's for the wind plus the
    /// swells'.
    pub fn slope_variance(&self) -> f32 {
        self.slope_total
    }

    /// The wavelength that sizes patches of this sea, m ([`sizing_wavelength_m`]).
    pub fn peak_wavelength_m(&self) -> Option<f64> {
        sizing_wavelength_m(&self.params)
    }

    #[cfg(test)]
    /// The moment `time_s` seconds from 0: ticks of the loop for a looping sea.
    pub fn time(&self, time_s: f64) -> SeaTime {
        match self.params.loop_period {
            Some(p) => SeaTime::Ticks(p.ticks(time_s)),
            None => SeaTime::Seconds(time_s),
        }
    }

    /// The moment `elapsed_s` after `start_s`. For a looping sea the two are counted in ticks
    /// apart, so a whole number of loops after any start is exactly the start again.
    pub fn time_after(&self, start_s: f64, elapsed_s: f64) -> SeaTime {
        match self.params.loop_period {
            Some(p) => SeaTime::Ticks(p.ticks(start_s) + p.ticks(elapsed_s)),
            None => SeaTime::Seconds(start_s + elapsed_s),
        }
    }

    /// A [`SeaTime`] in seconds (for a looping sea, from t = 0 unwrapped).
    pub fn seconds(&self, time: SeaTime) -> f64 {
        match time {
            SeaTime::Seconds(t) => t,
            SeaTime::Ticks(u) => u as f64 / 4_294_967_296.0 * self.params.loop_period.map_or(0.0, |p| p.seconds()),
        }
    }

    #[cfg(test)]
    /// The sea at `time_s` seconds, ready to sample.
    pub fn surface(&self, time_s: f64) -> SeaSurface<'_> {
        self.surface_at(self.time(time_s), Vec::new())
    }

    /// The phase of component `i` at `time`, radians in [0, 2π).
    #[inline(always)]
    fn phase(&self, c: &Component, time: SeaTime) -> f32 {
        let tau = 2.0 * PI;
        match time {
            SeaTime::Seconds(t) => (c.phase_rad - c.omega * t).rem_euclid(tau) as f32,
            SeaTime::Ticks(u) => {
                let turn = f64::from(c.harmonic.wrapping_mul(u as u32)) / 4_294_967_296.0;
                (c.phase_rad - tau * turn).rem_euclid(tau) as f32
            }
        }
    }

    /// The sea at a [`SeaTime`], reusing `buffer`.
    pub fn surface_at(&self, time: SeaTime, mut phase: Vec<f32>) -> SeaSurface<'_> {
        phase.clear();
        phase.extend(self.components.iter().map(|c| self.phase(c, time)));
        phase.resize(self.padded_len(), 0.0);
        let tail_offset = self.tail.as_ref().map_or([0.0; 2], |t| {
            let period = t.cell_m * t.field.size() as f64;
            let at = |axis: usize| match time {
                SeaTime::Seconds(s) => (t.velocity_m_s[axis] * s).rem_euclid(period) as f32,
                SeaTime::Ticks(u) => {
                    let turns = (t.loop_periods[axis] as u64).wrapping_mul(u64::from(u as u32)) & 0xFFFF_FFFF;
                    (turns as f64 / 4_294_967_296.0 * period) as f32
                }
            };
            [at(0), at(1)]
        });
        SeaSurface { sea: self, phase, tail_offset, time }
    }
}

impl Lanes {
    fn new(components: &[Component]) -> Lanes {
        let padded = components.len().next_multiple_of(LANES);
        let column = |f: &dyn Fn(&Component) -> f64| -> Vec<f32> {
            let mut v: Vec<f32> = components.iter().map(|c| f(c) as f32).collect();
            v.resize(padded, 0.0);
            v
        };
        Lanes {
            kx: column(&|c| c.wavenumber * c.bearing_rad.sin()),
            ky: column(&|c| c.wavenumber * c.bearing_rad.cos()),
            amp: column(&|c| c.amplitude_m),
            ux: column(&|c| c.bearing_rad.sin()),
            uy: column(&|c| c.bearing_rad.cos()),
            sqrt_k: column(&|c| c.wavenumber.sqrt()),
            dxx: column(&|c| c.amplitude_m * c.wavenumber * c.bearing_rad.sin().powi(2)),
            dyy: column(&|c| c.amplitude_m * c.wavenumber * c.bearing_rad.cos().powi(2)),
            dxy: column(&|c| c.amplitude_m * c.wavenumber * c.bearing_rad.sin() * c.bearing_rad.cos()),
        }
    }
}

#[cfg(test)]
#[path = "ocean_tests.rs"]
mod tests;
