//! Seamless loops in time: a sea whose every frequency is a whole multiple of 1/T repeats
//! exactly every T seconds.
//!
//! A looping sea measures time in **ticks**, 2³² to a period: the phase of a component with
//! harmonic number q at tick u is `φ0 - 2π·((q·u) mod 2³²)/2³²`, exact integer arithmetic, so
//! the picture at t = T is the picture at t = 0 bit for bit (tick 2³² is tick 0), and so is
//! every t + T. The frequency step 1/T must be small against the peak frequency, or the
//! quantised frequencies would stand far from the spectrum they sample: [`LoopPeriod::new`]
//! refuses a period under [`MIN_PEAK_PERIODS`] peak periods (the step is then at most a tenth
//! of fp, and a component's frequency moves by at most 5 % of fp).

use super::spectra::SeaSpectrum;
use crate::error::ValueError;

/// The shortest loop, in peak periods.
pub const MIN_PEAK_PERIODS: f64 = 10.0;
/// The longest loop, s (an hour).
pub const MAX_LOOP_S: f64 = 3600.0;
/// Ticks in one loop period, as a shift: 2³².
pub const TICK_BITS: u32 = 32;

/// A checked loop period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopPeriod {
    seconds: f64,
}

impl LoopPeriod {
    /// The loop of `seconds` for a sea with `spectrum`: finite, positive, at most an hour and
    /// at least [`MIN_PEAK_PERIODS`] peak periods (any positive period loops a calm).
    pub fn new(seconds: f64, spectrum: &SeaSpectrum) -> Result<LoopPeriod, ValueError> {
        if !seconds.is_finite() || seconds <= 0.0 {
            return Err(ValueError::new(
                "loop",
                format!(
                    "a loop of {seconds} s cannot repeat; give the loop's length in seconds, at least {}",
                    min_loop_text(spectrum)
                ),
            ));
        }
        if seconds > MAX_LOOP_S {
            return Err(ValueError::new(
                "loop",
                format!(
                    "a loop of {seconds} s is longer than the {MAX_LOOP_S} s tidepool allows; give at most {MAX_LOOP_S}"
                ),
            ));
        }
        let min = minimum_seconds(spectrum);
        if seconds < min {
            return Err(ValueError::new(
                "loop",
                format!(
                    "a loop of {seconds} s is too short for this sea: its frequency step 1/T must stay under a \
                     tenth of the peak frequency, so a loop lasts at least {MIN_PEAK_PERIODS} peak periods ({}); \
                     give {} or more",
                    min_loop_text(spectrum),
                    min.ceil()
                ),
            ));
        }
        Ok(LoopPeriod { seconds })
    }

    /// The period, s.
    pub fn seconds(&self) -> f64 {
        self.seconds
    }

    /// The frequency step 1/T, Hz.
    pub fn frequency_step_hz(&self) -> f64 {
        1.0 / self.seconds
    }

    /// The tick of time `t` seconds: t/T of the way round the loop, in units of 2⁻³².
    pub fn tick(&self, time_s: f64) -> u32 {
        let turns = (time_s / self.seconds).rem_euclid(1.0);
        ((turns * (1u64 << TICK_BITS) as f64).round() as u64 & 0xFFFF_FFFF) as u32
    }

    /// Whole loops before `time_s` and the tick within the loop (a tick that rounds up to
    /// the period carries into the next loop, so the pair never runs backwards).
    pub fn loops_and_tick(&self, time_s: f64) -> (i64, u32) {
        let turns = time_s / self.seconds;
        let mut whole = turns.floor();
        let mut tick = ((turns - whole) * (1u64 << TICK_BITS) as f64).round();
        if tick >= (1u64 << TICK_BITS) as f64 {
            whole += 1.0;
            tick = 0.0;
        }
        (whole as i64, tick as u32)
    }

    /// The time of frame `k` of an `n`-frame loop, s (frame n is the period, which shows frame 0).
    pub fn frame_time(&self, k: u32, n: u32) -> f64 {
        self.seconds * f64::from(k) / f64::from(n.max(1))
    }
}

/// The shortest loop for `spectrum`, s (0 for a calm).
pub fn minimum_seconds(spectrum: &SeaSpectrum) -> f64 {
    spectrum.peak_period_s().map_or(0.0, |tp| MIN_PEAK_PERIODS * tp)
}

fn min_loop_text(spectrum: &SeaSpectrum) -> String {
    match spectrum.peak_period_s() {
        Some(tp) => format!("{:.1} s for this sea, whose peak period is {tp:.2} s", MIN_PEAK_PERIODS * tp),
        None => "any length for a calm".to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::spectra::SpectrumChoice;

    #[test]
    fn periods_are_checked_against_the_peak() {
        let s = SeaSpectrum::new(10.0, SpectrumChoice::PiersonMoskowitz);
        let min = minimum_seconds(&s);
        assert!((min - 78.4).abs() < 0.1, "{min}");
        for bad in [0.0, -3.0, f64::INFINITY, f64::NAN, 30.0, 4000.0] {
            assert!(LoopPeriod::new(bad, &s).is_err(), "{bad}");
        }
        let short = LoopPeriod::new(30.0, &s).unwrap_err().to_string();
        assert!(short.contains("78.4 s") && short.contains("give 79 or more"), "{short}");
        assert!(LoopPeriod::new(80.0, &s).is_ok());
        assert!(LoopPeriod::new(1.0, &SeaSpectrum::new(0.0, SpectrumChoice::PiersonMoskowitz)).is_ok());
    }

    #[test]
    fn ticks_wrap_exactly_at_the_period() {
        let s = SeaSpectrum::new(10.0, SpectrumChoice::PiersonMoskowitz);
        let p = LoopPeriod::new(100.0, &s).unwrap();
        assert_eq!(p.tick(0.0), 0);
        assert_eq!(p.tick(100.0), 0);
        assert_eq!(p.tick(-100.0), 0);
        assert_eq!(p.tick(50.0), 1 << 31);
        assert_eq!(p.tick(p.frame_time(30, 30)), p.tick(p.frame_time(0, 30)));
        assert_eq!(p.tick(125.0), p.tick(25.0));
    }
}
