//! Seeded rain: raindrops at random spots, a given number per step on average.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::ripple::Stone;
use crate::error::ValueError;

/// The heaviest rain tidepool accepts, drops per step (beyond it the pool boils).
pub const MAX_RATE: f64 = 10_000.0;

/// Parses a rain rate: a finite number of drops per step, `0..=10000`.
pub fn parse_rate(text: &str) -> Result<f64, ValueError> {
    let v: f64 =
        text.trim().parse().map_err(|_| ValueError::new("rain", format!("'{text}' is not a number; e.g. 0.05")))?;
    check(v, text)
}

/// Checks a rain rate read as a number (from a replay).
pub fn check_rate(v: f64) -> Result<f64, ValueError> {
    check(v, &v.to_string())
}

fn check(v: f64, shown: &str) -> Result<f64, ValueError> {
    if !v.is_finite() || v < 0.0 {
        return Err(ValueError::new(
            "rain",
            format!("'{shown}' must be a finite number >= 0 (drops per step), e.g. 0.05"),
        ));
    }
    if v > MAX_RATE {
        return Err(ValueError::new("rain", format!("{v} drops per step would boil the pool; use at most {MAX_RATE}")));
    }
    Ok(v)
}

/// A deterministic source of raindrops (the papers' radius 2, weight 64).
///
/// Each step drops `floor(rate)` drops plus one more with probability `fract(rate)`, so the
/// expected number per step is exactly `rate` and a rate of 0 never draws from the generator.
/// The generator is ChaCha8, whose stream is fixed by its seed on every platform.
#[derive(Clone, Debug)]
pub struct Rain {
    rate: f64,
    /// Read and set by the pool's snapshot (`scene/pool/state.rs`).
    pub(crate) rng: ChaCha8Rng,
}

impl Rain {
    /// Rain with `rate` expected drops per step (negative or NaN rates count as 0).
    pub fn new(rate: f64, seed: u64) -> Rain {
        Rain { rate: sanitize(rate), rng: ChaCha8Rng::seed_from_u64(seed) }
    }

    /// Expected drops per step.
    pub fn rate(&self) -> f64 {
        self.rate
    }

    /// Changes the rate; the random stream continues where it was.
    pub fn set_rate(&mut self, rate: f64) {
        self.rate = sanitize(rate);
    }

    /// The drops that fall during one step on a `width x height` pool, appended to `drops`.
    pub fn drops(&mut self, width: usize, height: usize, drops: &mut Vec<Stone>) {
        if self.rate <= 0.0 || width < 3 || height < 3 {
            return;
        }
        let whole = self.rate.floor();
        let mut count = whole as u64;
        if self.rng.random::<f64>() < self.rate - whole {
            count += 1;
        }
        for _ in 0..count {
            let x = self.rng.random_range(1..width - 1) as i32;
            let y = self.rng.random_range(1..height - 1) as i32;
            drops.push(Stone::raindrop(x, y));
        }
    }
}

fn sanitize(rate: f64) -> f64 {
    if rate.is_finite() && rate > 0.0 { rate } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rates_are_checked() {
        assert_eq!(parse_rate("0.02"), Ok(0.02));
        for bad in ["-1", "NaN", "inf", "x", "1e9"] {
            assert!(parse_rate(bad).is_err(), "{bad}");
        }
        assert_eq!(
            parse_rate("1e9").unwrap_err().to_string(),
            "1000000000 drops per step would boil the pool; use at most 10000"
        );
        assert!(check_rate(f64::NAN).is_err() && check_rate(0.0).is_ok());
    }

    fn count(rate: f64, steps: usize, seed: u64) -> (usize, Vec<Stone>) {
        let mut rain = Rain::new(rate, seed);
        let mut drops = Vec::new();
        for _ in 0..steps {
            rain.drops(50, 40, &mut drops);
        }
        (drops.len(), drops)
    }

    #[test]
    fn expected_drops_per_step_is_the_rate() {
        let (n, _) = count(0.3, 10_000, 1);
        assert!((2800..3200).contains(&n), "{n}");
        let (n, _) = count(2.5, 1000, 2);
        assert!((2450..2550).contains(&n), "{n}");
        assert_eq!(count(0.0, 1000, 3).0, 0);
        assert_eq!(count(f64::NAN, 1000, 3).0, 0);
    }

    #[test]
    fn same_seed_same_rain() {
        assert_eq!(count(0.7, 500, 9).1, count(0.7, 500, 9).1);
        assert_ne!(count(0.7, 500, 9).1, count(0.7, 500, 10).1);
    }

    #[test]
    fn drops_land_inside_the_walls() {
        for s in count(3.0, 300, 4).1 {
            assert!((1..49).contains(&s.x) && (1..39).contains(&s.y), "{s:?}");
            assert_eq!((s.radius, s.weight), (2, 64));
        }
    }
}
