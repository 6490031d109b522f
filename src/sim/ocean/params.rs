//! `SeaParams`'s builders: how a library user sets a sea's spectrum, swells and loop. The
//! fields behind them are crate-private so that the checked types they hold (`Jonswap`,
//! `Depth`, `Swells`, `LoopPeriod`, ...) are not part of the API; each builder takes plain
//! numbers and checks them with the same rules and messages as the command line's flags.

use super::SeaParams;
use crate::error::ValueError;
use crate::sim::looping::LoopPeriod;
use crate::sim::spectra::swell::{Swell, Swells};
use crate::sim::spectra::{SpectrumChoice, SpectrumChoiceError, SpectrumKind, Spreading};

impl SeaParams {
    /// The wind speed at 10 m, m/s (the field `wind_m_s`), as a builder: with the spectrum
    /// private, `SeaParams { wind_m_s, ..SeaParams::default() }` no longer compiles outside
    /// the crate.
    pub fn with_wind_m_s(mut self, m_s: f64) -> SeaParams {
        self.wind_m_s = m_s;
        self
    }

    /// Where the wind comes from, degrees clockwise from north (the field `wind_from_deg`).
    pub fn with_wind_from_deg(mut self, degrees: f64) -> SeaParams {
        self.wind_from_deg = degrees;
        self
    }

    /// The seed of the phases, jitter and tail (the field `seed`).
    pub fn with_seed(mut self, seed: u64) -> SeaParams {
        self.seed = seed;
        self
    }

    /// λ, the scale of the horizontal displacement (the field `choppiness`; checked when the
    /// scene is made, [`SeaParams::check_choppiness`]).
    pub fn with_choppiness(mut self, choppiness: f64) -> SeaParams {
        self.choppiness = choppiness;
        self
    }

    /// A fetch-limited JONSWAP sea: the peak enhancement γ (1..=10, None: 3.3) and the fetch in
    /// km (0.01..=10000, None: unlimited), as `--spectrum jonswap --gamma --fetch` check them.
    pub fn with_jonswap(self, gamma: Option<f64>, fetch_km: Option<f64>) -> Result<SeaParams, ValueError> {
        self.with_choice(SpectrumKind::Jonswap, gamma, fetch_km, None)
    }

    /// A TMA sea: JONSWAP (γ and fetch as [`SeaParams::with_jonswap`]) in water `depth_m`
    /// metres deep (0.5..=10000), the only spectrum that feels the bottom.
    pub fn with_tma(self, gamma: Option<f64>, fetch_km: Option<f64>, depth_m: f64) -> Result<SeaParams, ValueError> {
        self.with_choice(SpectrumKind::Tma, gamma, fetch_km, Some(depth_m))
    }

    /// How the wind sea spreads over directions.
    pub fn with_spreading(mut self, spreading: Spreading) -> SeaParams {
        self.spreading = spreading;
        self
    }

    /// Adds a swell from a distant storm: significant height in m (0.01..=20), peak period in s
    /// (2..=30), the direction it comes from in degrees; at most four, as `--swell H,T,DIR`.
    pub fn with_swell(mut self, height_m: f64, period_s: f64, from_deg: f64) -> Result<SeaParams, ValueError> {
        let swell = Swell::new(height_m, period_s, from_deg)?;
        let mut list: Vec<Swell> = self.swells.iter().copied().collect();
        list.push(swell);
        self.swells = Swells::new(&list)?;
        Ok(self)
    }

    /// Repeats the sea exactly every `seconds` (at most an hour, at least ten of the longest
    /// peak period, [`SeaParams::longest_peak_period_s`]), as `--loop` does. Checked against the
    /// wind, spectrum and swells set so far, so set it last.
    pub fn with_loop_s(mut self, seconds: f64) -> Result<SeaParams, ValueError> {
        self.loop_period = Some(LoopPeriod::new(seconds, self.longest_peak_period_s())?);
        Ok(self)
    }

    /// The spectrum checked as the command line checks it; the combinations the builders cannot
    /// form (γ on Pierson–Moskowitz, a depth without TMA) become a `ValueError` all the same.
    fn with_choice(
        mut self,
        kind: SpectrumKind,
        gamma: Option<f64>,
        fetch_km: Option<f64>,
        depth_m: Option<f64>,
    ) -> Result<SeaParams, ValueError> {
        self.spectrum = SpectrumChoice::new(kind, gamma, fetch_km, depth_m).map_err(|e| match e {
            SpectrumChoiceError::Value(v) => v,
            other => ValueError::new("spectrum", other.to_string()),
        })?;
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use crate::SeaParams;
    use crate::sim::looping::LoopPeriod;
    use crate::sim::spectra::swell::{Swell, Swells};
    use crate::sim::spectra::{Depth, Jonswap, SpectrumChoice, Spreading};

    /// The builders make the very sea a struct literal of the checked types made (what the
    /// examples and benches wrote before the fields went private), so pictures stay the same.
    #[test]
    fn the_builders_make_the_literal_sea() {
        let built = SeaParams::default()
            .with_wind_m_s(12.0)
            .with_wind_from_deg(60.0)
            .with_seed(7)
            .with_choppiness(0.5)
            .with_spreading(Spreading::DonelanBanner)
            .with_tma(None, Some(40.0), 4.0)
            .and_then(|s| s.with_swell(1.5, 12.0, 250.0))
            .and_then(|s| s.with_swell(0.6, 16.0, 200.0))
            .unwrap();
        let swells = [Swell::new(1.5, 12.0, 250.0).unwrap(), Swell::new(0.6, 16.0, 200.0).unwrap()];
        let literal = SeaParams {
            wind_m_s: 12.0,
            wind_from_deg: 60.0,
            seed: 7,
            choppiness: 0.5,
            spreading: Spreading::DonelanBanner,
            spectrum: SpectrumChoice::Tma(Jonswap::new(3.3, Some(40.0)).unwrap(), Depth::new(4.0).unwrap()),
            swells: Swells::new(&swells).unwrap(),
            loop_period: None,
        };
        assert_eq!(built, literal);
        let jonswap = SeaParams::default().with_jonswap(Some(2.0), None).unwrap();
        assert_eq!(jonswap.spectrum, SpectrumChoice::Jonswap(Jonswap::new(2.0, None).unwrap()));
        let looped = built.with_loop_s(600.0).unwrap();
        assert_eq!(looped.loop_period, Some(LoopPeriod::new(600.0, built.longest_peak_period_s()).unwrap()));
    }

    /// Bad numbers come back as the command line's messages, naming the value.
    #[test]
    fn the_builders_refuse_what_the_flags_refuse() {
        let sea = SeaParams::default();
        let err = |r: Result<SeaParams, crate::ValueError>| r.unwrap_err().to_string();
        assert!(err(sea.with_jonswap(Some(0.0), None)).contains("gamma"));
        assert!(err(sea.with_tma(None, None, -1.0)).contains("depth"));
        assert!(err(sea.with_swell(1.0, 99.0, 0.0)).contains("period"));
        let four = (0..4).try_fold(sea, |s, _| s.with_swell(1.0, 10.0, 0.0)).unwrap();
        assert!(err(four.with_swell(1.0, 10.0, 0.0)).contains("at most 4"));
        assert!(err(sea.with_loop_s(1.0)).contains("too short"));
    }
}
