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

use crate::error::ValueError;

/// The shortest loop, in peak periods.
pub const MIN_PEAK_PERIODS: f64 = 10.0;
/// The longest loop, s (an hour).
pub const MAX_LOOP_S: f64 = 3600.0;
/// The shortest loop of any sea, s (a calm has no peak period to bound it; a second keeps
/// the tick count of any moment tidepool takes, |t| <= 10⁷ s, far inside an i64).
pub const MIN_LOOP_S: f64 = 1.0;
/// Ticks in one loop period, as a shift: 2³².
pub const TICK_BITS: u32 = 32;

/// A checked loop period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopPeriod {
    seconds: f64,
}

impl LoopPeriod {
    /// The loop of `seconds` for a sea whose longest peak period is `peak_period_s` (None: a
    /// calm; [`crate::SeaParams::longest_peak_period_s`]): finite, positive, at most an hour and
    /// at least 10 peak periods (a calm: at least 1 s).
    pub fn new(seconds: f64, peak_period_s: Option<f64>) -> Result<LoopPeriod, ValueError> {
        if !seconds.is_finite() || seconds <= 0.0 {
            return Err(ValueError::new(
                "loop",
                format!(
                    "a loop of {seconds} s cannot repeat; give the loop's length in seconds, at least {}",
                    min_loop_text(peak_period_s)
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
        let min = minimum_seconds(peak_period_s);
        if seconds < min {
            return Err(ValueError::new(
                "loop",
                format!(
                    "a loop of {seconds} s is too short for this sea: its frequency step 1/T must stay under a \
                     tenth of the peak frequency, so a loop lasts at least {MIN_PEAK_PERIODS} peak periods ({}); \
                     give {} or more",
                    min_loop_text(peak_period_s),
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

    /// Ticks (2³² a loop) from t = 0 to `time_s`, rounded to the nearest: the clock of a
    /// looping sea. A moment given as a start and a time elapsed since it is best counted as
    /// `ticks(start) + ticks(elapsed)`: an elapsed whole number of loops is then exactly a
    /// whole number of 2³² ticks, whatever the start.
    pub fn ticks(&self, time_s: f64) -> i64 {
        (time_s / self.seconds * (1u64 << TICK_BITS) as f64).round() as i64
    }
}

/// The shortest loop for a sea whose longest peak period is `peak_period_s`, s.
pub fn minimum_seconds(peak_period_s: Option<f64>) -> f64 {
    peak_period_s.map_or(MIN_LOOP_S, |tp| (MIN_PEAK_PERIODS * tp).max(MIN_LOOP_S))
}

fn min_loop_text(peak_period_s: Option<f64>) -> String {
    match peak_period_s {
        Some(tp) => format!("{:.1} s for this sea, whose peak period is {tp:.2} s", MIN_PEAK_PERIODS * tp),
        None => format!("{MIN_LOOP_S} s for a calm"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::spectra::{SeaSpectrum, SpectrumChoice};

    #[test]
    fn periods_are_checked_against_the_peak() {
        let s = SeaSpectrum::new(10.0, SpectrumChoice::PiersonMoskowitz).peak_period_s();
        let min = minimum_seconds(s);
        assert!((min - 78.4).abs() < 0.1, "{min}");
        for bad in [0.0, -3.0, f64::INFINITY, f64::NAN, 30.0, 4000.0] {
            assert!(LoopPeriod::new(bad, s).is_err(), "{bad}");
        }
        let short = LoopPeriod::new(30.0, s).unwrap_err().to_string();
        assert!(short.contains("78.4 s") && short.contains("give 79 or more"), "{short}");
        assert!(LoopPeriod::new(80.0, s).is_ok());
        assert!(LoopPeriod::new(1.0, None).is_ok() && LoopPeriod::new(0.5, None).is_err());
    }

    #[test]
    fn ticks_count_whole_loops_exactly() {
        let s = SeaSpectrum::new(10.0, SpectrumChoice::PiersonMoskowitz).peak_period_s();
        let p = LoopPeriod::new(100.0, s).unwrap();
        assert_eq!(p.ticks(0.0), 0);
        assert_eq!(p.ticks(100.0), 1 << 32);
        assert_eq!(p.ticks(-100.0), -(1 << 32));
        assert_eq!(p.ticks(50.0), 1 << 31);
        assert_eq!(p.ticks(125.0) - p.ticks(25.0), 1 << 32);
        // A loop that is no whole number of milliseconds: 30 frames of 1/fps each still add up
        // to exactly one loop of ticks.
        let odd = LoopPeriod::new(97.3, s).unwrap();
        let frame = odd.ticks(97.3 / 30.0 * 30.0);
        assert_eq!(frame, 1 << 32);
        assert_eq!(odd.ticks(0.3) + odd.ticks(97.3), odd.ticks(0.3) + (1 << 32));
    }
}
