//! Swell: waves raised by a distant storm, arriving with their own height, period and
//! direction, summed with the local wind sea.
//!
//! A swell is a narrow JONSWAP-shaped spectrum about fp = 1/T with a large peak enhancement
//! ([`SWELL_GAMMA`]), spread over directions by a narrow cos-2s law ([`SWELL_SPREAD`], a
//! constant exponent: swell has left the wind that made it, so nothing ties its spread to a
//! frequency), and scaled so that it carries exactly the variance of the height it was given:
//! `m0 = (Hs/4)²`. In water of finite depth (a TMA sea) it is cut by the same depth factor
//! as the wind sea before it is scaled, so it keeps the height asked for.
//!
//! Independent systems add their variances, so the sea's significant height is
//! `√(Hs_sea² + Σ Hs_swell²)`.

use std::f64::consts::PI;
use std::str::FromStr;

use super::{SIGMA_ABOVE, SIGMA_BELOW};
use crate::error::ValueError;
use crate::sim::dispersion;
use crate::sim::spectrum::{G, spreading};

/// The swell's peak enhancement: a narrow peak.
pub const SWELL_GAMMA: f64 = 7.0;
/// The swell's cos-2s spreading exponent (a directional spread of about ±16°).
pub const SWELL_SPREAD: f64 = 24.0;
/// The range of swell heights tidepool takes, m.
pub const SWELL_HEIGHT_RANGE_M: (f64, f64) = (0.01, 20.0);
/// The range of swell periods tidepool takes, s.
pub const SWELL_PERIOD_RANGE_S: (f64, f64) = (2.0, 30.0);
/// The most swells one sea takes.
pub const MAX_SWELLS: usize = 4;

/// The frequencies a swell's spectrum is integrated over, as multiples of fp, and the
/// integration steps per unit of that ratio.
const SPAN: (f64, f64) = (0.5, 6.0);
const STEPS: usize = 4000;

/// A swell: significant height, peak period and where it comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Swell {
    height_m: f64,
    period_s: f64,
    from_deg: f64,
}

impl Swell {
    /// Checks a swell of significant height `height_m` (0.01..=20 m) and peak period
    /// `period_s` (2..=30 s) coming from `from_deg` (degrees clockwise from north, any value).
    pub fn new(height_m: f64, period_s: f64, from_deg: f64) -> Result<Swell, ValueError> {
        let bad = |what: &'static str, text: String| Err(ValueError::new(what, text));
        if !height_m.is_finite() || !(SWELL_HEIGHT_RANGE_M.0..=SWELL_HEIGHT_RANGE_M.1).contains(&height_m) {
            return bad(
                "swell height",
                format!(
                    "the swell height {height_m} m is outside {}..={} m; give its significant height, e.g. 1.5",
                    SWELL_HEIGHT_RANGE_M.0, SWELL_HEIGHT_RANGE_M.1
                ),
            );
        }
        if !period_s.is_finite() || !(SWELL_PERIOD_RANGE_S.0..=SWELL_PERIOD_RANGE_S.1).contains(&period_s) {
            return bad(
                "swell period",
                format!(
                    "the swell period {period_s} s is outside {}..={} s; give its peak period, e.g. 12",
                    SWELL_PERIOD_RANGE_S.0, SWELL_PERIOD_RANGE_S.1
                ),
            );
        }
        if !from_deg.is_finite() {
            return bad("swell direction", "the swell direction must be a number of degrees, e.g. 250".into());
        }
        Ok(Swell { height_m, period_s, from_deg: from_deg.rem_euclid(360.0) })
    }

    /// Significant height, m.
    pub fn height_m(&self) -> f64 {
        self.height_m
    }

    /// Peak period, s.
    pub fn period_s(&self) -> f64 {
        self.period_s
    }

    /// Where it comes from, degrees clockwise from north (it travels the other way).
    pub fn direction_from_deg(&self) -> f64 {
        self.from_deg
    }
}

impl FromStr for Swell {
    type Err = ValueError;

    /// `HEIGHT,PERIOD,DIRECTION`: metres, seconds, degrees the swell comes from.
    fn from_str(text: &str) -> Result<Swell, ValueError> {
        let parts: Vec<&str> = text.split(',').map(str::trim).collect();
        let number = |t: &str, what: &'static str| {
            t.parse::<f64>().map_err(|_| {
                ValueError::new(
                    what,
                    format!("'{t}' is not a number; give the swell as HEIGHT,PERIOD,DIRECTION, e.g. 1.5,12,250"),
                )
            })
        };
        let [h, t, d] = parts.as_slice() else {
            return Err(ValueError::new(
                "swell",
                format!(
                    "'{text}' is not HEIGHT,PERIOD,DIRECTION (metres, seconds, degrees it comes from), e.g. 1.5,12,250"
                ),
            ));
        };
        Swell::new(number(h, "swell height")?, number(t, "swell period")?, number(d, "swell direction")?)
    }
}

/// Up to 4 swells (a `Copy` list, so a sea's parameters stay plain values).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Swells {
    list: [Option<Swell>; MAX_SWELLS],
}

impl Swells {
    /// No swell.
    pub const NONE: Swells = Swells { list: [None; MAX_SWELLS] };

    /// The swells of `list` (at most 4).
    pub fn new(list: &[Swell]) -> Result<Swells, ValueError> {
        if list.len() > MAX_SWELLS {
            return Err(ValueError::new(
                "swell",
                format!("{} swells are more than the {MAX_SWELLS} a sea takes; give at most {MAX_SWELLS}", list.len()),
            ));
        }
        let mut s = Swells::NONE;
        for (slot, swell) in s.list.iter_mut().zip(list) {
            *slot = Some(*swell);
        }
        Ok(s)
    }

    /// The swells, in the order given.
    pub fn iter(&self) -> impl Iterator<Item = &Swell> {
        self.list.iter().flatten()
    }

    // The command line's spectrum report and the plots (`cli`, `testing`) read it.
    #[cfg_attr(not(any(feature = "cli", feature = "testing")), allow(dead_code))]
    /// True without swell.
    pub fn is_empty(&self) -> bool {
        self.list[0].is_none()
    }
}

/// One swell's spectrum, ready to sample.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct SwellSpectrum {
    swell: Swell,
    depth_m: Option<f64>,
    fp: f64,
    /// The scale that gives the shape the swell's variance.
    alpha: f64,
}

impl SwellSpectrum {
    /// The spectrum of `swell` in water `depth_m` deep (None = deep).
    pub(crate) fn new(swell: Swell, depth_m: Option<f64>) -> SwellSpectrum {
        let fp = 1.0 / swell.period_s;
        let mut s = SwellSpectrum { swell, depth_m, fp, alpha: 1.0 };
        // Midpoint rule over SPAN·fp; the f⁻⁵ tail above in closed form.
        let (lo, hi) = (SPAN.0 * fp, SPAN.1 * fp);
        let df = (hi - lo) / STEPS as f64;
        let body: f64 = (0..STEPS).map(|i| s.energy(lo + (i as f64 + 0.5) * df) * df).sum();
        let tail = G * G / ((2.0 * PI).powi(4) * 4.0 * hi.powi(4));
        let m0 = (swell.height_m / 4.0).powi(2);
        s.alpha = m0 / (body + tail);
        s
    }

    /// The swell.
    pub(crate) fn swell(&self) -> Swell {
        self.swell
    }

    /// Peak frequency, Hz.
    pub(crate) fn peak_hz(&self) -> f64 {
        self.fp
    }

    /// Variance, m².
    pub(crate) fn m0(&self) -> f64 {
        (self.swell.height_m / 4.0).powi(2)
    }

    /// The bearing it travels to, radians clockwise from north.
    pub(crate) fn bearing_rad(&self) -> f64 {
        (self.swell.from_deg + 180.0).to_radians()
    }

    /// E(f), m²/Hz.
    pub(crate) fn energy(&self, f_hz: f64) -> f64 {
        if f_hz <= 0.0 {
            return 0.0;
        }
        let fp = self.fp;
        let sigma = if f_hz <= fp { SIGMA_BELOW } else { SIGMA_ABOVE };
        let r = (-(f_hz - fp).powi(2) / (2.0 * sigma * sigma * fp * fp)).exp();
        let shape = G * G / ((2.0 * PI).powi(4) * f_hz.powi(5)) * (-1.25 * (fp / f_hz).powi(4)).exp();
        self.alpha * shape * SWELL_GAMMA.powf(r) * dispersion::depth_factor(2.0 * PI * f_hz, self.depth_m)
    }

    /// E(f, θ), m²/(Hz·rad); θ from the swell's travel direction.
    pub(crate) fn directional_energy(&self, f_hz: f64, theta: f64) -> f64 {
        self.energy(f_hz) * spreading(SWELL_SPREAD, theta)
    }

    /// The variance carried by `lo..hi` Hz, m² (midpoint rule, 400 steps).
    #[cfg(test)]
    pub(crate) fn band_variance(&self, lo: f64, hi: f64) -> f64 {
        let n = 400;
        let df = (hi - lo) / f64::from(n);
        (0..n).map(|i| self.energy(lo + (f64::from(i) + 0.5) * df) * df).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_swell_carries_its_height_and_peaks_at_its_period() {
        for depth in [None, Some(12.0)] {
            let s = SwellSpectrum::new(Swell::new(2.0, 12.0, 250.0).unwrap(), depth);
            let (lo, hi, n) = (0.005, 3.0, 300_000);
            let df = (hi - lo) / n as f64;
            let m0: f64 = (0..n).map(|i| s.energy(lo + (i as f64 + 0.5) * df) * df).sum();
            assert!((4.0 * m0.sqrt() / 2.0 - 1.0).abs() < 2e-3, "{depth:?}: Hs {}", 4.0 * m0.sqrt());
            let peak = (1..2000).map(|i| i as f64 * 1e-4).max_by(|a, b| s.energy(*a).total_cmp(&s.energy(*b))).unwrap();
            assert!((peak * 12.0 - 1.0).abs() < 0.01, "{depth:?}: peak at {peak} Hz");
        }
        let s = SwellSpectrum::new(Swell::new(1.0, 10.0, 90.0).unwrap(), None);
        assert!((s.bearing_rad() - 1.5 * PI).abs() < 1e-12, "a swell from the east travels west");
        // Narrow: three quarters of its energy within ±20 % of fp (a Pierson–Moskowitz peak
        // holds half there).
        let near = s.band_variance(0.08, 0.12) / s.m0();
        assert!(near > 0.75, "{near}");
    }

    #[test]
    fn swells_are_checked_and_parsed() {
        let s: Swell = "1.5, 12, -110".parse().unwrap();
        assert_eq!((s.height_m(), s.period_s(), s.direction_from_deg()), (1.5, 12.0, 250.0));
        for bad in ["1.5,12", "0,12,0", "1,1,0", "1,40,0", "x,12,0", "1,12,inf", "21,10,0", "nan,10,0"] {
            assert!(bad.parse::<Swell>().is_err(), "{bad}");
        }
        assert!("1,40,0".parse::<Swell>().unwrap_err().to_string().contains("2..=30 s"));
        let list = [s; 5];
        assert!(Swells::new(&list).is_err());
        let four = Swells::new(&list[..4]).unwrap();
        assert_eq!(four.iter().count(), 4);
        assert!(Swells::NONE.is_empty() && !four.is_empty());
    }
}
