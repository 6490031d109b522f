//! Foam where waves fold: born where the choppy surface compresses beyond a threshold,
//! carried with the water, fading over seconds.
//!
//! # The source
//! At a resting point the fold indicator q = (1 - J)/(λ·σ) ([`SeaFrame::fold_indicator`];
//! J the Jacobian of the displacement, σ the standard deviation of its divergence over what
//! the footprint resolves, so q has unit variance near and far) makes foam where it passes a
//! threshold z: `s = clamp((q - z)/RAMP, 0, 1)`. In Jacobian terms foam forms where
//! J < J_c = 1 - z·λ·σ ([`FoamCalibration::fold_jacobian`]).
//!
//! # Memory
//! Foam is kept per resting point (it rides on the water, so a point fixed in the water is
//! the right place to keep it) on a clock of [`FOAM_STEP_S`]: `F ← max(F·d, s)` with
//! `d = exp(-step/`[`FOAM_FADE_S`]`)`, and F below [`FOAM_FORGET`] is set to 0. A crest moves
//! on at its phase speed and leaves its foam fading behind it: the foam is drawn out in a
//! trail along the waves' travel, downwind. Between clock steps foam fades smoothly
//! (`F·d^fraction`). Because a larger history is either overtaken by a newer source or
//! forgotten to exactly 0, two trackers that started at different times agree bit for bit
//! once [`FoamClock::warm_up_steps`] have passed: a still picture warms up that long, and a
//! looping sea's foam repeats exactly (its clock counts whole fractions of the loop).
//!
//! # Calibration
//! The Pierson–Moskowitz sea is self-similar: its folding is about the same at every wind,
//! while Monahan's whitecap fraction W = 3.84e-6·U^3.41 grows some sixtyfold from Beaufort 4
//! to 9. So z is calibrated per sea ([`FoamCalibration::calibrate`]): [`PROBES`] resting
//! points spread over 16 peak wavelengths run the tracker through a warm-up and
//! [`MEASURE_S`] seconds, and z is bisected until their mean foam equals W.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use super::ocean::{Sea, SeaFrame, SeaParams, SeaTime, whitecap_fraction};
use super::surface::Footprint;

/// The foam clock's step, s.
pub const FOAM_STEP_S: f64 = 0.1;
/// The time over which foam fades to 1/e, s.
pub const FOAM_FADE_S: f64 = 1.5;
/// Foam thinner than this is gone (exactly 0).
pub const FOAM_FORGET: f32 = 1.0 / 64.0;
/// Width of the source's ramp, in standard deviations of the fold indicator.
pub const RAMP: f32 = 0.5;
/// Resting points the calibration follows.
pub const PROBES: usize = 384;
/// How long the calibration measures after its warm-up, s.
pub const MEASURE_S: f64 = 40.0;
/// The side of the calibration's square, peak wavelengths.
pub const PROBE_SPREAD_WAVELENGTHS: f64 = 16.0;

/// The foam source for a fold indicator `q` and threshold `z`.
#[inline(always)]
pub fn source(q: f32, z: f32) -> f32 {
    ((q - z) / RAMP).clamp(0.0, 1.0)
}

/// One step of the memory: the older foam faded by `decay`, or the new source if larger;
/// below [`FOAM_FORGET`], nothing.
#[inline(always)]
pub fn remember(old: f32, decay: f32, source: f32) -> f32 {
    let f = (old * decay).max(source);
    if f < FOAM_FORGET { 0.0 } else { f }
}

/// The foam clock of a sea: steps of [`FOAM_STEP_S`], or for a looping sea a power of two
/// steps per loop (the nearest to it), counted so that step n and n + steps-per-loop are the
/// same moment of the sea.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FoamClock {
    step_s: f64,
    /// log2 of the steps per loop, for a looping sea.
    loop_bits: Option<(crate::sim::looping::LoopPeriod, u32)>,
}

impl FoamClock {
    /// The clock of `sea`.
    pub fn of(sea: &Sea) -> FoamClock {
        match sea.params().loop_period {
            Some(p) => {
                let bits = (p.seconds() / FOAM_STEP_S).log2().round().clamp(1.0, 24.0) as u32;
                FoamClock { step_s: p.seconds() / f64::from(1u32 << bits), loop_bits: Some((p, bits)) }
            }
            None => FoamClock { step_s: FOAM_STEP_S, loop_bits: None },
        }
    }

    /// The step, s.
    pub fn step_s(&self) -> f64 {
        self.step_s
    }

    /// The fade per step.
    pub fn decay(&self) -> f32 {
        (-self.step_s / FOAM_FADE_S).exp() as f32
    }

    /// Steps after which any earlier history is forgotten exactly (plus one).
    pub fn warm_up_steps(&self) -> i64 {
        let steps = f64::from(FOAM_FORGET).ln() / f64::from(self.decay()).ln();
        steps.ceil() as i64 + 1
    }

    /// The last step at or before `time_s`, and how far past it `time_s` is (0..1 steps).
    pub fn step_at(&self, time_s: f64) -> (i64, f32) {
        match self.loop_bits {
            Some((p, bits)) => {
                let (loops, tick) = p.loops_and_tick(time_s);
                let shift = 32 - bits;
                let within = i64::from(tick >> shift);
                let frac = f64::from(tick & ((1u32 << shift) - 1)) / f64::from(1u32 << shift);
                ((loops << bits) + within, frac as f32)
            }
            None => {
                let pos = time_s / self.step_s;
                let n = pos.floor();
                (n as i64, (pos - n) as f32)
            }
        }
    }

    /// The moment of the sea at step `n`.
    pub fn time_of(&self, n: i64) -> SeaTime {
        match self.loop_bits {
            Some((_, bits)) => {
                let within = n.rem_euclid(1i64 << bits) as u64;
                SeaTime::Tick((within << (32 - bits)) as u32)
            }
            None => SeaTime::Seconds(n as f64 * self.step_s),
        }
    }
}

/// The calibrated threshold of a sea's foam.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FoamCalibration {
    /// The fold indicator's threshold z (+inf: no foam).
    pub threshold: f32,
    /// The same in Jacobian terms at full resolution: foam forms where J < this.
    pub fold_jacobian: f32,
    /// Monahan's fraction it aimed at.
    pub target: f64,
    /// The mean foam the calibration's probes reached.
    pub coverage: f64,
}

impl FoamCalibration {
    /// Bisects the threshold until the probes' mean foam is Monahan's fraction for the wind.
    pub fn calibrate(sea: &Sea) -> FoamCalibration {
        let target = whitecap_fraction(sea.params().wind_m_s);
        let none =
            FoamCalibration { threshold: f32::INFINITY, fold_jacobian: f32::NEG_INFINITY, target, coverage: 0.0 };
        let Some(wavelength) = sea.spectrum().peak_wavelength_m() else { return none };
        if target <= 0.0 || sea.components().is_empty() {
            return none;
        }
        let clock = FoamClock::of(sea);
        let warm = clock.warm_up_steps() as usize;
        let measure = (MEASURE_S / clock.step_s()).ceil() as usize;
        let steps = warm + measure;
        let mut rng = ChaCha8Rng::seed_from_u64(sea.params().seed ^ 0xf0a3);
        let side = (PROBE_SPREAD_WAVELENGTHS * wavelength) as f32;
        let probes: Vec<[f32; 2]> =
            (0..PROBES).map(|_| [side * rng.random::<f32>(), side * rng.random::<f32>()]).collect();
        let frames: Vec<SeaFrame<'_>> = (0..steps).map(|n| sea.frame_at(clock.time_of(n as i64), Vec::new())).collect();
        let full = Footprint::default();
        let series: Vec<Vec<f32>> =
            probes.par_iter().map(|p| frames.iter().map(|f| f.fold_indicator(p[0], p[1], &full)).collect()).collect();
        let decay = clock.decay();
        let coverage = |z: f32| -> f64 {
            let mut sum = 0.0f64;
            for q in &series {
                let mut foam = 0.0f32;
                for (n, &q) in q.iter().enumerate() {
                    foam = remember(foam, decay, source(q, z));
                    if n >= warm {
                        sum += f64::from(foam);
                    }
                }
            }
            sum / (series.len() * measure) as f64
        };
        let (mut lo, mut hi) = (-4.0f32, 12.0f32);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if coverage(mid) > target { lo = mid } else { hi = mid }
        }
        let threshold = 0.5 * (lo + hi);
        // J_c for the sea's λ (for λ = 0, whose surface never folds, the value at λ = 1).
        let lambda = if sea.choppiness() > 0.0 { sea.choppiness() } else { 1.0 };
        let sigma =
            sea.components().iter().map(|c| 0.5 * (c.amplitude_m * c.wavenumber).powi(2)).sum::<f64>().sqrt() as f32;
        FoamCalibration {
            threshold,
            fold_jacobian: 1.0 - threshold * lambda * sigma,
            target,
            coverage: coverage(threshold),
        }
    }
}

/// Foam at a fixed set of resting points, followed through time.
#[derive(Debug, Default)]
pub struct FoamTracker {
    /// The sea's parameters, the number of points and the last step taken.
    at: Option<(SeaParams, usize, i64)>,
    /// The threshold calibrated for a sea's parameters (calibrating takes a while; a tracker
    /// keeps it while the sea stays the same).
    threshold: Option<(SeaParams, f32)>,
    state: Vec<f32>,
    foam: Vec<f32>,
    phases: Vec<f32>,
}

impl FoamTracker {
    /// A tracker with no history.
    pub fn new() -> FoamTracker {
        FoamTracker::default()
    }

    /// Forgets everything (the points moved).
    pub fn reset(&mut self) {
        self.at = None;
    }

    /// Brings the foam at `points` (resting points with their footprints) up to `time_s` and
    /// returns it, one value 0..=1 per point. Continues from the last call when the sea and
    /// the points are the same and time moved forward by less than a warm-up; otherwise warms
    /// up from scratch. Allocates only when the number of points grows.
    pub fn update(&mut self, sea: &Sea, points: &[[f32; 2]], footprints: &[Footprint], time_s: f64) -> &[f32] {
        let clock = FoamClock::of(sea);
        let (now, frac) = clock.step_at(time_s);
        let warm = clock.warm_up_steps();
        let first = match self.at {
            Some((params, count, last)) if params == sea.params() && count == points.len() && now >= last => {
                if now - last > warm { now - warm } else { last + 1 }
            }
            _ => {
                self.state.clear();
                self.state.resize(points.len(), 0.0);
                now - warm
            }
        };
        let z = match self.threshold {
            Some((params, z)) if params == sea.params() => z,
            _ => {
                let z = FoamCalibration::calibrate(sea).threshold;
                self.threshold = Some((sea.params(), z));
                z
            }
        };
        let decay = clock.decay();
        for n in first..=now {
            let frame = sea.frame_at(clock.time_of(n), std::mem::take(&mut self.phases));
            self.state.par_chunks_mut(256).enumerate().for_each(|(chunk, state)| {
                for (i, f) in state.iter_mut().enumerate() {
                    let k = chunk * 256 + i;
                    let q = frame.fold_indicator(points[k][0], points[k][1], &footprints[k]);
                    *f = remember(*f, decay, source(q, z));
                }
            });
            self.phases = frame.into_buffer();
        }
        self.at = Some((sea.params(), points.len(), now));
        let fade = decay.powf(frac);
        self.foam.clear();
        self.foam.extend(self.state.iter().map(|f| f * fade));
        &self.foam
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::looping::LoopPeriod;
    use crate::sim::ocean::{SeaParams, whitecap_fraction};
    use crate::sim::spectra::{SeaSpectrum, SpectrumChoice};

    /// Mean foam over a grid of resting points (not the calibration's probes) followed for
    /// `seconds` after the warm-up, one value per foam step.
    pub(crate) fn measured_coverage(sea: &Sea, seconds: f64) -> f64 {
        let span = 16.0 * sea.spectrum().peak_wavelength_m().unwrap() as f32;
        let points: Vec<[f32; 2]> = (0..1024)
            .map(|i| [span * ((i % 32) as f32 + 0.5) / 32.0 - 900.0, span * ((i / 32) as f32 + 0.5) / 32.0])
            .collect();
        let footprints = vec![Footprint::default(); points.len()];
        let mut tracker = FoamTracker::new();
        let step = FoamClock::of(sea).step_s();
        let (mut sum, mut count) = (0.0f64, 0usize);
        let mut t = 500.0;
        while t < 500.0 + seconds {
            sum += tracker.update(sea, &points, &footprints, t).iter().map(|&f| f64::from(f)).sum::<f64>();
            count += points.len();
            t += step;
        }
        sum / count as f64
    }

    #[test]
    fn whitecaps_follow_monahan() {
        // The calibration aims at Monahan's fraction; measured elsewhere and later, the foam
        // must stay within half of it (no absolute slack: zero foam fails).
        assert!((whitecap_fraction(10.0) - 3.84e-6 * 10f64.powf(3.41)).abs() < 1e-12);
        for wind in [8.0, 15.0, 22.0] {
            let sea = Sea::new(SeaParams { wind_m_s: wind, choppiness: 1.0, seed: 4, ..SeaParams::default() });
            let want = whitecap_fraction(wind);
            let cover = measured_coverage(&sea, 20.0);
            assert!((cover / want - 1.0).abs() < 0.5, "U = {wind}: {cover} vs Monahan {want}");
        }
    }

    #[test]
    fn memory_fades_and_forgets_exactly() {
        let d = 0.95;
        let mut f = remember(0.0, d, 1.0);
        assert_eq!(f, 1.0);
        f = remember(f, d, 0.2);
        assert_eq!(f, 0.95);
        for _ in 0..200 {
            f = remember(f, d, 0.0);
        }
        assert_eq!(f, 0.0, "forgotten exactly");
        assert_eq!(source(2.0, 1.0), 1.0);
        assert_eq!(source(0.9, 1.0), 0.0);
    }

    #[test]
    fn the_clock_counts_whole_fractions_of_a_loop() {
        let params = SeaParams { wind_m_s: 8.0, ..SeaParams::default() };
        let period = LoopPeriod::new(64.0, &SeaSpectrum::new(8.0, SpectrumChoice::PiersonMoskowitz)).unwrap();
        let sea = Sea::new(SeaParams { loop_period: Some(period), ..params });
        let clock = FoamClock::of(&sea);
        assert_eq!(clock.step_s(), 0.125, "512 steps of 1/8 s");
        assert_eq!(clock.step_at(0.0), (0, 0.0));
        assert_eq!(clock.step_at(64.0), (512, 0.0));
        assert_eq!(clock.step_at(64.0 * 29.0 / 29.0), (512, 0.0));
        assert_eq!(clock.time_of(512), clock.time_of(0));
        assert_eq!(clock.time_of(-1), clock.time_of(511));
        let plain = FoamClock::of(&Sea::new(params));
        let (n, frac) = plain.step_at(1.25);
        assert!(n == 12 && (frac - 0.5).abs() < 1e-5, "{n} {frac}");
        // 1.5 s to 1/e, forgotten below 1/64: ln 64 · 1.5 s = 6.2 s, 63 steps of 0.1 s.
        assert_eq!(plain.warm_up_steps(), 64);
    }
}
