//! The Pierson–Moskowitz wave spectrum with Mitsuyasu directional spreading
//! (`docs/ALGORITHMS.md` §3.1).
//!
//! ```text
//! E(f)        = alpha·g² / ((2π)⁴ f⁵) · exp(-5/4 · (fm/f)⁴),  fm = 0.13·g/U,  alpha = 0.0081
//! D(f, theta) = Γ(s+1) / (2·√π·Γ(s+½)) · cos(theta/2)^(2s)
//! s           = 9.77·(f/fm)^-2.5 for f >= fm,  6.97·(f/fm)^5 below
//! ```
//!
//! The paper prints alpha = 0.0008 and the spreading exponent as 2; both are misprints (the
//! Phillips constant is 0.0081, the exponent 2s), fixed here. With the paper's `fm = 0.13 g/U`
//! the spectrum integrates in closed form to `m0 = alpha·g² / ((2π)⁴·5·fm⁴)`, which gives
//! **Hs = 4·√m0 = 0.2413·U²/g** (0.39 m at 4 m/s, 2.46 m at 10 m/s). The textbook 0.21·U²/g
//! uses fm = 0.14 g/U for a wind measured at 19.5 m; tidepool keeps the paper's constant and
//! treats U as the wind at 10 m (the height of the Beaufort table).
//!
//! Frequencies are in Hz, wavelengths and heights in metres, E in m²/Hz. A wind of 0 m/s is a
//! flat calm: every energy is 0 and nothing divides by zero.

use std::f64::consts::PI;

/// Gravity, m/s².
pub const G: f64 = 9.81;
/// The Phillips constant (the paper's misprinted 0.0008 corrected).
pub const ALPHA: f64 = 0.0081;
/// Peak frequency factor: fm = 0.13·g/U (the paper's value).
pub const PEAK_FACTOR: f64 = 0.13;

/// The deep-water wavelength (m) of a wave of frequency `f_hz`: λ = g / (2π f²).
pub fn wavelength_m(f_hz: f64) -> f64 {
    G / (2.0 * PI * f_hz * f_hz)
}

/// The deep-water angular wavenumber (rad/m) of frequency `f_hz`: k = ω²/g.
pub fn wavenumber(f_hz: f64) -> f64 {
    let omega = 2.0 * PI * f_hz;
    omega * omega / G
}

/// A fully developed Pierson–Moskowitz sea for one wind speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PiersonMoskowitz {
    wind_m_s: f64,
}

impl PiersonMoskowitz {
    /// The sea raised by a wind of `wind_m_s` (negative or NaN counts as calm).
    pub fn new(wind_m_s: f64) -> PiersonMoskowitz {
        let wind_m_s = if wind_m_s.is_finite() && wind_m_s > 0.0 { wind_m_s } else { 0.0 };
        PiersonMoskowitz { wind_m_s }
    }

    /// The wind speed, m/s.
    pub fn wind_m_s(&self) -> f64 {
        self.wind_m_s
    }

    /// True for a wind of 0: a flat sea with no peak.
    pub fn is_calm(&self) -> bool {
        self.wind_m_s == 0.0
    }

    /// The peak frequency fm = 0.13·g/U in Hz, or `None` for a calm.
    pub fn peak_hz(&self) -> Option<f64> {
        (!self.is_calm()).then(|| PEAK_FACTOR * G / self.wind_m_s)
    }

    #[cfg(any(test, feature = "testing"))]
    /// The peak period 1/fm in seconds, or `None` for a calm.
    pub fn peak_period_s(&self) -> Option<f64> {
        self.peak_hz().map(|f| 1.0 / f)
    }

    /// The wavelength of the peak frequency in metres, or `None` for a calm.
    pub fn peak_wavelength_m(&self) -> Option<f64> {
        self.peak_hz().map(wavelength_m)
    }

    /// E(f) in m²/Hz (0 for f <= 0 and for a calm).
    pub fn energy(&self, f_hz: f64) -> f64 {
        let Some(fm) = self.peak_hz() else { return 0.0 };
        if f_hz <= 0.0 {
            return 0.0;
        }
        let r = fm / f_hz;
        ALPHA * G * G / ((2.0 * PI).powi(4) * f_hz.powi(5)) * (-1.25 * r.powi(4)).exp()
    }

    /// The variance of the surface carried by frequencies in `0..f_hz`, in m², in closed form:
    /// with u = f⁻⁴ the integral of E is `m0 · exp(-5/4·(fm/f)⁴)`.
    pub fn cumulative_variance(&self, f_hz: f64) -> f64 {
        let Some(fm) = self.peak_hz() else { return 0.0 };
        if f_hz <= 0.0 {
            return 0.0;
        }
        if !f_hz.is_finite() {
            return self.m0();
        }
        self.m0() * (-1.25 * (fm / f_hz).powi(4)).exp()
    }

    #[cfg(any(test, feature = "testing"))]
    /// The variance carried by frequencies in `f_lo..f_hi`, m².
    pub fn band_variance(&self, f_lo_hz: f64, f_hi_hz: f64) -> f64 {
        self.cumulative_variance(f_hi_hz) - self.cumulative_variance(f_lo_hz)
    }

    /// The zeroth moment m0 (total variance of the surface), m².
    pub fn m0(&self) -> f64 {
        let Some(fm) = self.peak_hz() else { return 0.0 };
        ALPHA * G * G / ((2.0 * PI).powi(4) * 5.0 * fm.powi(4))
    }

    #[cfg(any(test, feature = "testing"))]
    /// The significant wave height Hs = 4·√m0 = 0.2413·U²/g, in metres.
    pub fn significant_height_m(&self) -> f64 {
        4.0 * self.m0().sqrt()
    }

    /// The Mitsuyasu spreading exponent s at `f_hz` (0 for a calm).
    pub fn spreading_exponent(&self, f_hz: f64) -> f64 {
        let Some(fm) = self.peak_hz() else { return 0.0 };
        let r = f_hz / fm;
        if r >= 1.0 { 9.77 * r.powf(-2.5) } else { 6.97 * r.powi(5) }
    }

    /// The directional spectrum E(f, theta) = E(f)·D(f, theta) in m²/(Hz·rad); `theta` is the
    /// angle between the wave's travel and the downwind direction.
    pub fn directional_energy(&self, f_hz: f64, theta: f64) -> f64 {
        self.energy(f_hz) * spreading(self.spreading_exponent(f_hz), theta)
    }
}

/// The Mitsuyasu spreading function D(theta) for exponent `s`, normalised to integrate to 1
/// over theta in [-π, π] (angles outside wrap around).
///
/// The constant Γ(s+1) / (2√π Γ(s+½)) is formed from log-gammas: Γ itself overflows f64 for
/// s above about 170, which high-frequency spreading never reaches but user code might.
pub fn spreading(s: f64, theta: f64) -> f64 {
    if !(s.is_finite() && s >= 0.0) {
        return 0.0;
    }
    let theta = theta.rem_euclid(2.0 * PI);
    let half = (theta / 2.0).cos().abs();
    let log_norm = libm::lgamma(s + 1.0) - libm::lgamma(s + 0.5) - (2.0 * PI.sqrt()).ln();
    if half == 0.0 {
        return if s == 0.0 { log_norm.exp() } else { 0.0 };
    }
    (log_norm + 2.0 * s * half.ln()).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_papers_worked_example() {
        let sea = PiersonMoskowitz::new(4.0);
        let fm = sea.peak_hz().unwrap();
        assert!((fm - 0.319).abs() < 0.0005, "fm = {fm}");
        let lambda = sea.peak_wavelength_m().unwrap();
        assert!((lambda - 15.36).abs() < 0.01, "λ = {lambda}");
    }

    #[test]
    fn hs_is_0_2413_u_squared_over_g() {
        for u in [0.15, 4.0, 10.0, 20.0, 35.0] {
            let hs = PiersonMoskowitz::new(u).significant_height_m();
            let want = 0.2413 * u * u / G;
            assert!((hs / want - 1.0).abs() < 1e-3, "U = {u}: {hs} vs {want}");
        }
        assert!((PiersonMoskowitz::new(10.0).significant_height_m() - 2.46).abs() < 0.005);
    }

    #[test]
    fn the_closed_form_matches_numerical_integration() {
        let sea = PiersonMoskowitz::new(7.0);
        let (lo, hi, n) = (0.05, 20.0, 200_000);
        let df = (hi - lo) / n as f64;
        let sum: f64 = (0..n).map(|i| sea.energy(lo + (i as f64 + 0.5) * df) * df).sum();
        assert!((sum / sea.band_variance(lo, hi) - 1.0).abs() < 1e-4);
        assert!((sea.band_variance(0.0, f64::INFINITY) - sea.m0()).abs() < 1e-12);
    }

    #[test]
    fn spreading_integrates_to_one() {
        for s in [0.5, 1.0, 6.97, 9.77, 50.0, 200.0] {
            let n = 100_000;
            let d = 2.0 * PI / n as f64;
            let sum: f64 = (0..n).map(|i| spreading(s, -PI + (i as f64 + 0.5) * d) * d).sum();
            assert!((sum - 1.0).abs() < 1e-6, "s = {s}: {sum}");
        }
        assert!(spreading(3.0, PI) < 1e-90, "no waves travel upwind");
        assert!(spreading(400.0, 0.0).is_finite(), "no overflow at large s");
    }

    #[test]
    fn spreading_follows_mitsuyasu() {
        let sea = PiersonMoskowitz::new(10.0);
        let fm = sea.peak_hz().unwrap();
        assert!((sea.spreading_exponent(fm) - 9.77).abs() < 1e-12);
        assert!((sea.spreading_exponent(fm * 0.999_999) - 6.97).abs() < 1e-3);
        assert!((sea.spreading_exponent(2.0 * fm) - 9.77 * 2f64.powf(-2.5)).abs() < 1e-12);
        assert!(sea.directional_energy(fm, 0.0) > sea.directional_energy(fm, 1.0));
    }

    #[test]
    fn a_calm_is_flat_and_finite() {
        let sea = PiersonMoskowitz::new(0.0);
        assert!(sea.is_calm() && sea.peak_hz().is_none());
        assert_eq!(sea.energy(0.5), 0.0);
        assert_eq!(sea.m0(), 0.0);
        assert_eq!(sea.significant_height_m(), 0.0);
        assert_eq!(sea.directional_energy(0.5, 0.0), 0.0);
        assert!(PiersonMoskowitz::new(f64::NAN).is_calm());
    }
}
