//! The three sea spectra tidepool offers: Pierson–Moskowitz (fully developed, the paper's),
//! JONSWAP (fetch-limited, Hasselmann et al. 1973) and TMA (JONSWAP in finite depth,
//! Bouws et al. 1985), all with Mitsuyasu spreading about their own peak.
//!
//! ```text
//! JONSWAP  E(f) = α·g²/((2π)⁴f⁵) · exp(-5/4·(fp/f)⁴) · γ^r,  r = exp(-(f - fp)² / (2σ²fp²))
//!          σ = 0.07 below fp, 0.09 above;  x = g·F/U² (F the fetch in metres)
//!          fp = 3.5·(g/U)·x^-0.33,  α = 0.076·x^-0.22          (Hasselmann's relations)
//! TMA      E(f) = E_JONSWAP(f) · Φ(ω, h),  Φ = tanh²(kh) / (1 + 2kh/sinh 2kh),  ω² = g·k·tanh(kh)
//! ```
//!
//! # How the fetch relations join the fully developed sea
//! As the fetch grows, fp falls and α falls; neither may pass the fully developed values of
//! the Pierson–Moskowitz sea tidepool draws (fp = 0.13·g/U, α = 0.0081). They reach them at
//! different dimensionless fetches: fp at x ≈ 2.2·10⁴, α at x ≈ 2.6·10⁴. Each is clamped on
//! its own at its limit ([`Jonswap::peak_hz`], [`Jonswap::alpha`]), so both are continuous in
//! the fetch and, past x ≈ 2.6·10⁴, exactly PM's. **An unlimited fetch** (no fetch given)
//! means exactly that limit: PM's fp and α. γ is not a function of fetch in Hasselmann's fit
//! (it scattered about 3.3 at every fetch), so it is kept as given: an unlimited-fetch JONSWAP
//! with γ = 1 *is* the Pierson–Moskowitz sea (tested), and with γ = 3.3 it is PM's peak made
//! 3.3 times taller (Hs about 1.25 times PM's at the same wind).
//!
//! # TMA
//! Kitaigorodskii's factor Φ is the exact ratio of k⁻³·dk/dω in depth h to its deep-water
//! value, so TMA keeps JONSWAP's shape in wavenumber while the frequencies it holds are those
//! of ω² = g·k·tanh(kh): waves of the same period are shorter, and the energy of the long
//! ones is cut (Φ → ω²h/2g for kh → 0). TMA takes γ and the fetch like JONSWAP.

use std::f64::consts::PI;

use super::dispersion;
use super::spectrum::{ALPHA, G, PiersonMoskowitz, spreading};

mod choice;
mod spreading;
pub mod swell;

// JONSWAP's γ and fetch and a TMA depth are checked values the command line and the tests
// build; a library user gives plain numbers to `SeaParams::with_jonswap` and `with_tma`.
#[cfg(any(test, feature = "testing"))]
pub use choice::Depth;
#[cfg(any(test, feature = "cli", feature = "testing"))]
pub use choice::Jonswap;
pub use choice::{SpectrumChoice, SpectrumChoiceError, SpectrumKind};

pub use spreading::Spreading;
use spreading::{donelan_banner_beta, sech2_spreading};

/// JONSWAP's default peak enhancement γ (Hasselmann et al.'s mean).
pub const DEFAULT_GAMMA: f64 = 3.3;
/// The range of γ tidepool accepts (1 = no enhancement, Pierson–Moskowitz's shape).
pub const GAMMA_RANGE: (f64, f64) = (1.0, 10.0);
/// The range of fetch tidepool accepts, km.
pub const FETCH_RANGE_KM: (f64, f64) = (0.01, 10_000.0);
/// The range of water depth tidepool accepts, m.
pub const DEPTH_RANGE_M: (f64, f64) = (0.5, 10_000.0);
/// Peak width below and above fp.
pub const SIGMA_BELOW: f64 = 0.07;
/// Peak width above fp.
pub const SIGMA_ABOVE: f64 = 0.09;
/// Cumulative-variance table: points per factor e of frequency.
const TABLE_PER_E: f64 = 600.0;
/// The table spans this fraction of fp up to this multiple of fp (E is e^-150 below it).
const TABLE_LOW: f64 = 0.3;
const TABLE_HIGH: f64 = 400.0;

/// A spectrum evaluated for one wind: everything a sea needs from it.
///
/// The Pierson–Moskowitz case delegates to [`PiersonMoskowitz`] (closed forms, bit for bit
/// today's sea); JONSWAP and TMA integrate E(f) numerically once, into a table of the
/// cumulative variance on a fine logarithmic grid (600 points per factor e, trapezoids, plus
/// the f⁻⁵ tail in closed form above 400·fp).
#[derive(Clone, Debug, PartialEq)]
pub struct SeaSpectrum {
    choice: SpectrumChoice,
    spreading: Spreading,
    pm: PiersonMoskowitz,
    peak_hz: Option<f64>,
    alpha: f64,
    /// ln f of the table's first point, its step in ln f, and the cumulative variance there.
    table: Option<(f64, f64, Vec<f64>)>,
    m0: f64,
}

impl SeaSpectrum {
    /// The spectrum `choice` for a wind of `wind_m_s` (negative or NaN counts as calm).
    pub fn new(wind_m_s: f64, choice: SpectrumChoice) -> SeaSpectrum {
        let pm = PiersonMoskowitz::new(wind_m_s);
        let wind = pm.wind_m_s();
        let (peak_hz, alpha) = match choice {
            SpectrumChoice::PiersonMoskowitz => (pm.peak_hz(), ALPHA),
            SpectrumChoice::Jonswap(j) | SpectrumChoice::Tma(j, _) => (j.peak_hz(wind), j.alpha(wind)),
        };
        let mut s = SeaSpectrum { choice, spreading: Spreading::Paper, pm, peak_hz, alpha, table: None, m0: pm.m0() };
        if let (Some(fp), false) = (peak_hz, matches!(choice, SpectrumChoice::PiersonMoskowitz)) {
            let (lo, hi) = ((TABLE_LOW * fp).ln(), (TABLE_HIGH * fp).ln());
            let n = ((hi - lo) * TABLE_PER_E).ceil() as usize;
            let step = (hi - lo) / n as f64;
            let mut cumulative = Vec::with_capacity(n + 1);
            let mut sum = 0.0;
            let mut last = s.energy(lo.exp()) * lo.exp();
            cumulative.push(0.0);
            for i in 1..=n {
                let f = (lo + i as f64 * step).exp();
                // In ln f: ∫E df = ∫E·f d(ln f).
                let now = s.energy(f) * f;
                sum += 0.5 * (last + now) * step;
                last = now;
                cumulative.push(sum);
            }
            let f_top = hi.exp();
            let tail = s.alpha * G * G / ((2.0 * PI).powi(4) * 4.0 * f_top.powi(4));
            s.m0 = sum + tail;
            s.table = Some((lo, step, cumulative));
        }
        s
    }

    /// The same spectrum spread over directions by `spreading` (the default is
    /// [`Spreading::Paper`]).
    pub fn with_spreading(self, spreading: Spreading) -> SeaSpectrum {
        SeaSpectrum { spreading, ..self }
    }

    /// The choice it was made from.
    pub fn choice(&self) -> SpectrumChoice {
        self.choice
    }

    /// How its energy spreads over directions.
    pub fn spreading(&self) -> Spreading {
        self.spreading
    }

    /// The wind speed, m/s.
    pub fn wind_m_s(&self) -> f64 {
        self.pm.wind_m_s()
    }

    #[cfg(any(test, feature = "testing"))]
    /// True for a wind of 0.
    pub fn is_calm(&self) -> bool {
        self.pm.is_calm()
    }

    /// The water depth, m (None = deep).
    pub fn depth_m(&self) -> Option<f64> {
        self.choice.depth_m()
    }

    #[cfg(any(test, feature = "cli", feature = "testing"))]
    /// The Phillips constant α in force.
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    #[cfg(any(test, feature = "testing"))]
    /// γ (1 for Pierson–Moskowitz).
    pub fn gamma(&self) -> f64 {
        match self.choice {
            SpectrumChoice::PiersonMoskowitz => 1.0,
            SpectrumChoice::Jonswap(j) | SpectrumChoice::Tma(j, _) => j.gamma(),
        }
    }

    /// The peak frequency fp in Hz (None for a calm).
    pub fn peak_hz(&self) -> Option<f64> {
        self.peak_hz
    }

    /// The peak period 1/fp, s.
    pub fn peak_period_s(&self) -> Option<f64> {
        self.peak_hz.map(|f| 1.0 / f)
    }

    /// The wavenumber (rad/m) of frequency `f_hz` in this sea's depth.
    pub fn wavenumber(&self, f_hz: f64) -> f64 {
        match self.choice {
            SpectrumChoice::PiersonMoskowitz => super::spectrum::wavenumber(f_hz),
            _ => dispersion::wavenumber(2.0 * PI * f_hz, self.depth_m()),
        }
    }

    /// The wavelength of the peak frequency in this depth, m.
    pub fn peak_wavelength_m(&self) -> Option<f64> {
        match self.choice {
            SpectrumChoice::PiersonMoskowitz => self.pm.peak_wavelength_m(),
            _ => self.peak_hz.map(|f| 2.0 * PI / self.wavenumber(f)),
        }
    }

    /// E(f), m²/Hz.
    pub fn energy(&self, f_hz: f64) -> f64 {
        let (Some(fp), SpectrumChoice::Jonswap(j) | SpectrumChoice::Tma(j, _)) = (self.peak_hz, self.choice) else {
            return self.pm.energy(f_hz);
        };
        if f_hz <= 0.0 {
            return 0.0;
        }
        let r = fp / f_hz;
        let sigma = if f_hz <= fp { SIGMA_BELOW } else { SIGMA_ABOVE };
        let peak = (-(f_hz - fp).powi(2) / (2.0 * sigma * sigma * fp * fp)).exp();
        let jonswap =
            self.alpha * G * G / ((2.0 * PI).powi(4) * f_hz.powi(5)) * (-1.25 * r.powi(4)).exp() * j.gamma().powf(peak);
        jonswap * dispersion::depth_factor(2.0 * PI * f_hz, self.depth_m())
    }

    /// The exponent s of the cos-2s spreading at `f_hz` (None for Donelan–Banner's sech², or a
    /// calm).
    pub fn spreading_exponent(&self, f_hz: f64) -> Option<f64> {
        let fp = self.peak_hz?;
        let r = f_hz / fp;
        match self.spreading {
            Spreading::Paper => Some(if r >= 1.0 { 9.77 * r.powf(-2.5) } else { 6.97 * r.powi(5) }),
            Spreading::Mitsuyasu => {
                let sp = 11.5 * (2.0 * PI * fp * self.wind_m_s() / G).powf(-2.5);
                Some(if r <= 1.0 { sp * r.powi(5) } else { sp * r.powf(-2.5) })
            }
            Spreading::Hasselmann => {
                let phase_speed = 2.0 * PI * fp / self.wavenumber(fp);
                let mu = -2.33 - 1.45 * (self.wind_m_s() / phase_speed - 1.17);
                Some(if r < 1.05 { 6.97 * r.powf(4.06) } else { 9.77 * r.powf(mu) })
            }
            Spreading::DonelanBanner => None,
        }
    }

    /// The directional spreading D(f, θ) (1/rad, integrating to 1 over θ in [-π, π]); θ from
    /// downwind.
    pub fn spread(&self, f_hz: f64, theta: f64) -> f64 {
        let Some(fp) = self.peak_hz else { return 0.0 };
        match self.spreading_exponent(f_hz) {
            Some(s) => spreading(s, theta),
            None => sech2_spreading(donelan_banner_beta(f_hz / fp), theta),
        }
    }

    /// E(f, θ) = E(f)·D(f, θ), m²/(Hz·rad); θ from downwind.
    pub fn directional_energy(&self, f_hz: f64, theta: f64) -> f64 {
        match (self.choice, self.spreading) {
            (SpectrumChoice::PiersonMoskowitz, Spreading::Paper) => self.pm.directional_energy(f_hz, theta),
            _ => self.energy(f_hz) * self.spread(f_hz, theta),
        }
    }

    /// The variance carried by frequencies below `f_hz`, m².
    pub fn cumulative_variance(&self, f_hz: f64) -> f64 {
        let Some((lo, step, table)) = &self.table else { return self.pm.cumulative_variance(f_hz) };
        if f_hz.is_nan() || f_hz <= 0.0 {
            return 0.0;
        }
        if !f_hz.is_finite() {
            return self.m0;
        }
        let pos = (f_hz.ln() - lo) / step;
        if pos <= 0.0 {
            return 0.0;
        }
        let last = table.len() - 1;
        if pos >= last as f64 {
            let top = (lo + last as f64 * step).exp();
            let tail_from = |f: f64| self.alpha * G * G / ((2.0 * PI).powi(4) * 4.0 * f.powi(4));
            return table[last] + tail_from(top) - tail_from(f_hz);
        }
        let i = pos as usize;
        let t = pos - i as f64;
        table[i] + (table[i + 1] - table[i]) * t
    }

    #[cfg(any(test, feature = "testing"))]
    /// The variance carried by frequencies in `f_lo..f_hi`, m².
    pub fn band_variance(&self, f_lo_hz: f64, f_hi_hz: f64) -> f64 {
        self.cumulative_variance(f_hi_hz) - self.cumulative_variance(f_lo_hz)
    }

    /// The total variance m0, m².
    pub fn m0(&self) -> f64 {
        self.m0
    }

    /// Hs = 4·√m0, m.
    pub fn significant_height_m(&self) -> f64 {
        4.0 * self.m0.sqrt()
    }

    #[cfg(any(test, feature = "testing"))]
    /// The omnidirectional wavenumber spectrum E(k) = E(f)·df/dk, m³/rad, at `k` rad/m.
    pub fn wavenumber_energy(&self, k: f64) -> f64 {
        if k <= 0.0 {
            return 0.0;
        }
        let depth = self.depth_m();
        let f = dispersion::angular_frequency(k, depth) / (2.0 * PI);
        self.energy(f) * dispersion::group_speed(k, depth) / (2.0 * PI)
    }

    #[cfg(any(test, feature = "testing"))]
    /// The wavenumber where E(k) peaks, rad/m (None for a calm): found on a fine grid and
    /// refined by golden-section search. It lies below the k of fp (for PM, 0.913 times it).
    pub fn wavenumber_peak(&self) -> Option<f64> {
        let kp = self.wavenumber(self.peak_hz?);
        let (mut best, mut best_e) = (kp, 0.0);
        for i in 0..=2000 {
            let k = kp * (0.3 + 1.7 * i as f64 / 2000.0);
            let e = self.wavenumber_energy(k);
            if e > best_e {
                (best, best_e) = (k, e);
            }
        }
        let (mut a, mut b) = (best - 1.7 * kp / 2000.0, best + 1.7 * kp / 2000.0);
        let phi = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..60 {
            let (c, d) = (b - phi * (b - a), a + phi * (b - a));
            if self.wavenumber_energy(c) > self.wavenumber_energy(d) { b = d } else { a = c }
        }
        Some(0.5 * (a + b))
    }
}

#[cfg(test)]
#[path = "spectra_tests.rs"]
pub(crate) mod measured;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::spectrum::PEAK_FACTOR;

    #[test]
    fn pm_is_delegated_exactly() {
        // black_box: a constant-folded powi may round differently from the one run.
        let wind = std::hint::black_box(10.0);
        let s = SeaSpectrum::new(wind, SpectrumChoice::PiersonMoskowitz);
        let pm = PiersonMoskowitz::new(wind);
        assert_eq!(s.m0(), pm.m0());
        assert_eq!(s.peak_hz(), pm.peak_hz());
        let (f, theta) = std::hint::black_box((0.2, 0.3));
        assert_eq!(s.directional_energy(f, theta), pm.directional_energy(f, theta));
        assert_eq!(s.cumulative_variance(f), pm.cumulative_variance(f));
    }

    #[test]
    fn unlimited_jonswap_with_gamma_one_is_pm() {
        let j = SeaSpectrum::new(12.0, SpectrumChoice::Jonswap(Jonswap::new(1.0, None).unwrap()));
        let pm = PiersonMoskowitz::new(12.0);
        assert!((j.m0() / pm.m0() - 1.0).abs() < 1e-6, "{} vs {}", j.m0(), pm.m0());
        for f in [0.05, 0.1, 0.3, 1.0] {
            assert!((j.energy(f) - pm.energy(f)).abs() <= 1e-12 * pm.energy(f).max(1e-300));
            assert!((j.cumulative_variance(f) - pm.cumulative_variance(f)).abs() < 1e-6 * pm.m0());
        }
        // γ = 3.3 lifts the peak 3.3 times and Hs by about a quarter.
        let j33 = SeaSpectrum::new(12.0, SpectrumChoice::Jonswap(Jonswap::default()));
        let fp = j33.peak_hz().unwrap();
        assert!((j33.energy(fp) / pm.energy(fp) - 3.3).abs() < 1e-9);
        let ratio = j33.significant_height_m() / pm.significant_height_m();
        assert!((1.15..1.35).contains(&ratio), "{ratio}");
    }

    #[test]
    fn fetch_relations_and_their_clamps() {
        let u = 10.0;
        let short = Jonswap::new(3.3, Some(20.0)).unwrap();
        let x = G * 20_000.0 / (u * u);
        assert!((short.peak_hz(u).unwrap() - 3.5 * G / u * x.powf(-0.33)).abs() < 1e-12);
        assert!((short.alpha(u) - 0.076 * x.powf(-0.22)).abs() < 1e-12);
        assert!(short.peak_hz(u).unwrap() > PEAK_FACTOR * G / u && short.alpha(u) > ALPHA);
        // fp reaches PM at x ≈ 2.2e4 (about 220 km at 10 m/s), α at x ≈ 2.6e4 (about 270 km).
        let between = Jonswap::new(3.3, Some(245.0)).unwrap();
        assert_eq!(between.peak_hz(u).unwrap(), PEAK_FACTOR * G / u);
        assert!(between.alpha(u) > ALPHA);
        let long = Jonswap::new(3.3, Some(2000.0)).unwrap();
        assert_eq!((long.peak_hz(u).unwrap(), long.alpha(u)), (PEAK_FACTOR * G / u, ALPHA));
        // A shorter fetch: a higher peak frequency and a smaller sea.
        let s = SeaSpectrum::new(u, SpectrumChoice::Jonswap(short));
        let l = SeaSpectrum::new(u, SpectrumChoice::Jonswap(long));
        assert!(s.significant_height_m() < 0.7 * l.significant_height_m());
    }

    #[test]
    fn bad_values_are_refused_with_the_fix() {
        for (gamma, fetch) in
            [(0.0, None), (f64::NAN, None), (3.3, Some(0.0)), (3.3, Some(-5.0)), (3.3, Some(f64::NAN))]
        {
            assert!(Jonswap::new(gamma, fetch).is_err(), "{gamma} {fetch:?}");
        }
        assert!(Jonswap::new(3.3, Some(0.0)).unwrap_err().to_string().contains("raises no waves"));
        assert!(Depth::new(-1.0).unwrap_err().to_string().contains("depth"));
        assert!(Depth::new(f64::INFINITY).is_err());
        use SpectrumChoiceError as E;
        use SpectrumKind as K;
        assert_eq!(SpectrumChoice::new(K::PiersonMoskowitz, Some(3.3), None, None), Err(E::JonswapParameterWithPm));
        assert_eq!(SpectrumChoice::new(K::PiersonMoskowitz, None, Some(9.0), None), Err(E::JonswapParameterWithPm));
        assert_eq!(SpectrumChoice::new(K::Jonswap, None, None, Some(9.0)), Err(E::DepthWithoutTma));
        assert_eq!(SpectrumChoice::new(K::Tma, None, None, None), Err(E::TmaWithoutDepth));
        assert!(matches!(SpectrumChoice::new(K::Tma, Some(0.0), None, Some(9.0)), Err(E::Value(_))));
        let tma = SpectrumChoice::new(K::Tma, None, Some(40.0), Some(9.0)).unwrap();
        assert_eq!(tma.depth_m(), Some(9.0));
        assert_eq!("JONSWAP".parse::<SpectrumKind>(), Ok(K::Jonswap));
        assert!("phillips".parse::<SpectrumKind>().is_err());
    }

    #[test]
    fn tma_cuts_long_waves_and_shortens_them() {
        let deep = SeaSpectrum::new(12.0, SpectrumChoice::Jonswap(Jonswap::default()));
        let shallow = SeaSpectrum::new(12.0, SpectrumChoice::Tma(Jonswap::default(), Depth::new(6.0).unwrap()));
        assert!(shallow.m0() < 0.8 * deep.m0());
        assert!(shallow.peak_wavelength_m().unwrap() < 0.8 * deep.peak_wavelength_m().unwrap());
        // Numerical integration agrees with the table.
        let (lo, hi, n) = (0.01, 20.0, 400_000);
        let df = (hi - lo) / n as f64;
        let sum: f64 = (0..n).map(|i| shallow.energy(lo + (i as f64 + 0.5) * df) * df).sum();
        assert!((sum / shallow.band_variance(lo, hi) - 1.0).abs() < 1e-3);
    }

    #[test]
    fn the_wavenumber_peak_lies_below_the_k_of_fp() {
        let pm = SeaSpectrum::new(10.0, SpectrumChoice::PiersonMoskowitz);
        let kp = pm.wavenumber(pm.peak_hz().unwrap());
        let ratio = pm.wavenumber_peak().unwrap() / kp;
        assert!((ratio - (5.0f64 / 6.0).sqrt()).abs() < 1e-4, "PM: k-peak/k(fp) = {ratio}");
        let j = SeaSpectrum::new(10.0, SpectrumChoice::Jonswap(Jonswap::default()));
        let r = j.wavenumber_peak().unwrap() / j.wavenumber(j.peak_hz().unwrap());
        assert!(r < 1.0 && r > ratio, "a sharper peak moves less: {r}");
    }
}
