//! What a sea's spectrum is made of, as checked values: its kind (`pm`, `jonswap`, `tma`),
//! JONSWAP's peak enhancement and fetch ([`Jonswap`], with Hasselmann's fetch relations
//! clamped at the fully developed sea), the water depth ([`Depth`]) and the combination of
//! them a sea follows ([`SpectrumChoice`]).

use crate::error::ValueError;
use std::str::FromStr;

use super::{DEFAULT_GAMMA, DEPTH_RANGE_M, FETCH_RANGE_KM, GAMMA_RANGE};
use crate::sim::spectrum::{ALPHA, G, PEAK_FACTOR};

/// Which spectrum, by name: `pm`, `jonswap` or `tma`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SpectrumKind {
    /// Pierson–Moskowitz: fully developed.
    #[default]
    PiersonMoskowitz,
    /// JONSWAP: fetch-limited, peak-enhanced.
    Jonswap,
    /// TMA: JONSWAP in water of finite depth.
    Tma,
}

impl FromStr for SpectrumKind {
    type Err = ValueError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim().to_ascii_lowercase().as_str() {
            "pm" | "pierson-moskowitz" => Ok(SpectrumKind::PiersonMoskowitz),
            "jonswap" => Ok(SpectrumKind::Jonswap),
            "tma" => Ok(SpectrumKind::Tma),
            other => Err(ValueError::new("spectrum", format!("unknown spectrum '{other}'; use pm, jonswap or tma"))),
        }
    }
}

impl SpectrumKind {
    // The command line's spectrum report and the plots (`cli`, `testing`) read it.
    #[cfg_attr(not(any(feature = "cli", feature = "testing")), allow(dead_code))]
    /// The short name (`pm`, `jonswap`, `tma`).
    pub fn name(self) -> &'static str {
        match self {
            SpectrumKind::PiersonMoskowitz => "pm",
            SpectrumKind::Jonswap => "jonswap",
            SpectrumKind::Tma => "tma",
        }
    }
}

fn finite(v: f64, what: &'static str, example: &str) -> Result<f64, ValueError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ValueError::new(what, format!("the {what} must be a finite number, e.g. {example}")))
    }
}

/// JONSWAP's two free parameters: the peak enhancement γ and the fetch (None = unlimited).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Jonswap {
    gamma: f64,
    fetch_km: Option<f64>,
}

impl Default for Jonswap {
    fn default() -> Self {
        Jonswap { gamma: DEFAULT_GAMMA, fetch_km: None }
    }
}

impl Jonswap {
    /// Checks γ (1..=10) and the fetch (0.01..=10000 km, or None for unlimited).
    pub fn new(gamma: f64, fetch_km: Option<f64>) -> Result<Jonswap, ValueError> {
        let g = finite(gamma, "peak enhancement gamma", "3.3")?;
        if !(GAMMA_RANGE.0..=GAMMA_RANGE.1).contains(&g) {
            return Err(ValueError::new(
                "peak enhancement gamma",
                format!(
                    "the peak enhancement gamma {g} is outside {}..={}; 1 is Pierson-Moskowitz's shape, 3.3 \
                     JONSWAP's mean",
                    GAMMA_RANGE.0, GAMMA_RANGE.1
                ),
            ));
        }
        if let Some(f) = fetch_km {
            let f = finite(f, "fetch", "50 (km)")?;
            if f <= 0.0 {
                return Err(ValueError::new(
                    "fetch",
                    format!(
                        "a fetch of {f} km raises no waves; give the distance the wind blows over open water in \
                         km (e.g. 50), or leave it out for an unlimited fetch"
                    ),
                ));
            }
            if !(FETCH_RANGE_KM.0..=FETCH_RANGE_KM.1).contains(&f) {
                return Err(ValueError::new(
                    "fetch",
                    format!(
                        "the fetch {f} km is outside {}..={} km; give the distance the wind blows over open water",
                        FETCH_RANGE_KM.0, FETCH_RANGE_KM.1
                    ),
                ));
            }
        }
        Ok(Jonswap { gamma: g, fetch_km })
    }

    /// γ.
    pub fn gamma(&self) -> f64 {
        self.gamma
    }

    /// The fetch in km, or None for unlimited.
    pub fn fetch_km(&self) -> Option<f64> {
        self.fetch_km
    }

    /// x = g·F/U², or None for an unlimited fetch or a calm.
    fn dimensionless_fetch(&self, wind_m_s: f64) -> Option<f64> {
        let f = self.fetch_km? * 1000.0;
        (wind_m_s > 0.0).then(|| G * f / (wind_m_s * wind_m_s))
    }

    /// The peak frequency, Hz: 3.5·(g/U)·x^-0.33, never below PM's 0.13·g/U (None for a calm).
    pub fn peak_hz(&self, wind_m_s: f64) -> Option<f64> {
        if wind_m_s.is_nan() || wind_m_s <= 0.0 {
            return None;
        }
        let developed = PEAK_FACTOR * G / wind_m_s;
        Some(match self.dimensionless_fetch(wind_m_s) {
            Some(x) => (3.5 * G / wind_m_s * x.powf(-0.33)).max(developed),
            None => developed,
        })
    }

    /// α: 0.076·x^-0.22, never below PM's 0.0081.
    pub fn alpha(&self, wind_m_s: f64) -> f64 {
        match self.dimensionless_fetch(wind_m_s) {
            Some(x) => (0.076 * x.powf(-0.22)).max(ALPHA),
            None => ALPHA,
        }
    }
}

/// Water depth for TMA, m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Depth(f64);

impl Depth {
    /// Checks a depth (0.5..=10000 m).
    pub fn new(metres: f64) -> Result<Depth, ValueError> {
        let m = finite(metres, "water depth", "8 (m)")?;
        if m <= 0.0 {
            return Err(ValueError::new(
                "water depth",
                format!("a water depth of {m} m leaves no sea; give the depth in metres, e.g. 8"),
            ));
        }
        if !(DEPTH_RANGE_M.0..=DEPTH_RANGE_M.1).contains(&m) {
            return Err(ValueError::new(
                "water depth",
                format!("the water depth {m} m is outside {}..={} m", DEPTH_RANGE_M.0, DEPTH_RANGE_M.1),
            ));
        }
        Ok(Depth(m))
    }

    /// Metres.
    pub fn metres(&self) -> f64 {
        self.0
    }
}

/// Which spectrum a sea follows, with its parameters.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum SpectrumChoice {
    /// Pierson–Moskowitz (today's sea).
    #[default]
    PiersonMoskowitz,
    /// JONSWAP.
    Jonswap(Jonswap),
    /// TMA: JONSWAP in water of the given depth.
    Tma(Jonswap, Depth),
}

/// A combination of spectrum parameters that does not make sense, with the fix.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SpectrumChoiceError {
    /// γ or the fetch given for the Pierson–Moskowitz spectrum.
    #[error(
        "the peak enhancement and the fetch shape JONSWAP and TMA seas; choose the jonswap or tma spectrum, or drop them (Pierson-Moskowitz is fully developed)"
    )]
    JonswapParameterWithPm,
    /// A depth given for a deep-water spectrum.
    #[error("only the tma spectrum feels the bottom; choose tma, or drop the depth for deep water")]
    DepthWithoutTma,
    /// TMA without a depth.
    #[error("the tma spectrum needs the water depth in metres, e.g. 8")]
    TmaWithoutDepth,
    /// A value out of range (the message names it).
    #[error(transparent)]
    Value(#[from] ValueError),
}

impl SpectrumChoice {
    /// Puts a spectrum together from what a user gave: the kind, and optionally γ (default
    /// 3.3), the fetch in km (default unlimited) and the depth in m (TMA only, required).
    pub fn new(
        kind: SpectrumKind,
        gamma: Option<f64>,
        fetch_km: Option<f64>,
        depth_m: Option<f64>,
    ) -> Result<SpectrumChoice, SpectrumChoiceError> {
        let jonswap = || Jonswap::new(gamma.unwrap_or(DEFAULT_GAMMA), fetch_km).map_err(SpectrumChoiceError::Value);
        match kind {
            SpectrumKind::PiersonMoskowitz if gamma.is_some() || fetch_km.is_some() => {
                Err(SpectrumChoiceError::JonswapParameterWithPm)
            }
            SpectrumKind::PiersonMoskowitz | SpectrumKind::Jonswap if depth_m.is_some() => {
                Err(SpectrumChoiceError::DepthWithoutTma)
            }
            SpectrumKind::PiersonMoskowitz => Ok(SpectrumChoice::PiersonMoskowitz),
            SpectrumKind::Jonswap => Ok(SpectrumChoice::Jonswap(jonswap()?)),
            SpectrumKind::Tma => {
                let depth = depth_m.ok_or(SpectrumChoiceError::TmaWithoutDepth)?;
                let depth = Depth::new(depth).map_err(SpectrumChoiceError::Value)?;
                Ok(SpectrumChoice::Tma(jonswap()?, depth))
            }
        }
    }

    // The command line's spectrum report and the plots (`cli`, `testing`) read it.
    #[cfg_attr(not(any(feature = "cli", feature = "testing")), allow(dead_code))]
    /// The kind.
    pub fn kind(&self) -> SpectrumKind {
        match self {
            SpectrumChoice::PiersonMoskowitz => SpectrumKind::PiersonMoskowitz,
            SpectrumChoice::Jonswap(_) => SpectrumKind::Jonswap,
            SpectrumChoice::Tma(..) => SpectrumKind::Tma,
        }
    }

    /// The water depth, m (None = deep).
    pub fn depth_m(&self) -> Option<f64> {
        match self {
            SpectrumChoice::Tma(_, d) => Some(d.metres()),
            _ => None,
        }
    }
}
