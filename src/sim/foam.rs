//! Foam as a simulated field: made where the water is squeezed until it breaks, kept on the
//! water that made it, fading with a time constant in seconds. The same constants hold for
//! every wind; one of them, the gain G, is set against a measurement (see "The constants"),
//! and the model is tested against whitecap data that did not set it.
//!
//! # Where foam is made
//! The water resting at a point is carried to `x + λ·D(x)`; the Jacobian
//! `J = det(I + λ·∇D)` is the area it covers per unit of its area at rest. Where J falls below
//! [`FOLD_JACOBIAN`] (the water squeezed into half its area) the surface breaks. The sines a
//! sample keeps give the resolved Jacobian `J_r`; the waves it cannot carry (the short waves
//! beyond the sines, and those its footprint drops) squeeze it further by `λ·Y`, Y their
//! divergence, a Gaussian whose variance is their slope variance `S_u = S - S_r`. S is the
//! slope variance of the waves the wind raised: Cox–Munk's `0.00512·U` without their zero-wind
//! intercept of 0.003 (slope that is there without a local wind, which does not whitecap),
//! plus the swells' (carried by the sines, so it cancels in `S_u`); S_r is what the kept sines
//! carry. The source is the expected depth of the break,
//!
//! ```text
//! s = E[(J_c - J_r - λ·Y)⁺] = σ·φ(m/σ) + m·Φ(m/σ),   m = J_c - J_r,  σ = λ·√S_u
//! ```
//!
//! Short waves break on the crests of long ones, where the long ones squeeze the water: the
//! source follows the resolved folds, and a sample far away (which resolves little) gets the
//! same expected source from statistics alone, so the foam cover does not depend on how
//! finely a sea is sampled.
//!
//! # Memory
//! Foam obeys `dF/dt = -F/τ + (G/τ)·s` ([`FOAM_LIFETIME_S`] τ, [`FOAM_GAIN`] G): made in
//! proportion to the source, fading to 1/e in τ seconds. It is kept per resting point: foam
//! rides on the water that made it, carried by the water's horizontal motion (the orbital
//! displacement that carries the point; the mean drift, a few per cent of the wind over a
//! foam's few seconds, moves it less than a metre and is left to the foam texture). The
//! equation is integrated on a clock of its own ([`FOAM_STEP_S`]), whatever the frame rate,
//! as a finite impulse response over the last [`FOAM_MEMORY_S`] seconds (three lifetimes):
//!
//! ```text
//! F_n = Σ_{a < W} w_a·s_{n-a},   w_a ∝ e^(-a·Δt/τ),   Σ w_a = G
//! ```
//!
//! so the mean cover is exactly `G·E[s]`, and the foam at a moment depends only on the sea
//! in the W steps before it: a still picture computes those steps, a stream of frames adds
//! one step at a time, and the two agree bit for bit (each step's source is a function of
//! the point and the step alone). A looping sea's clock counts a power of two steps per
//! loop, so its foam loops exactly. Between steps the cover is interpolated linearly.
//!
//! # The constants
//! J_c = 0.5 and τ = 2 s are physical choices (whitecaps fade over seconds; Callaghan et al.
//! 2012 measured e-folding times of 1–10 s). **G is the one constant set against data**, and
//! the physics needs one: s is the area of water overturning now (the actively breaking
//! crest), and G turns it into the area of visible foam that overturning leaves over its
//! lifetime, a matter of bubbles that a linear wave model does not carry. It was set once so
//! that the model's mean cover at 10 m/s equals Monahan and O'Muircheartaigh's (1980)
//! `W = 3.84·10⁻⁶·U^3.41` there (0.99 %, the middle of the winds their data cover); the growth
//! with the wind is the physics' own (the short waves' slope variance grows with U, and the
//! expected break grows faster than linearly with it). The model is tested against Callaghan
//! et al. (2008), whose data did not set it (`ocean_physics_tests.rs`). A sea whose
//! expected cover is below [`NEGLIGIBLE_COVER`] (Beaufort 2 and calmer: glassy crests that do
//! not break) skips foam altogether.

use rayon::prelude::*;

use super::looping::LoopPeriod;
use super::ocean::{CALM_SLOPE_VARIANCE, FOLD_ROWS, PhaseRows, Sea, SeaParams, SeaTime};
use super::surface::Footprint;

/// The Jacobian below which the surface breaks: squeezed to half its area.
pub const FOLD_JACOBIAN: f32 = 0.5;
/// G, foam made per unit of expected break over its lifetime: the mean cover is G·E[s]. The
/// one constant set against data: the model's mean cover at 10 m/s equals Monahan and
/// O'Muircheartaigh's (1980) 0.99 % (see the module docs; tested against Callaghan et al.
/// 2008, which did not set it).
pub const FOAM_GAIN: f32 = 9.6;
/// The time over which foam fades to 1/e, s.
pub const FOAM_LIFETIME_S: f64 = 2.0;
/// The foam clock's step, s (a looping sea: the power of two steps per loop nearest to it).
pub const FOAM_STEP_S: f64 = 0.2;
/// How far back a moment's foam remembers the sea, s: three lifetimes.
pub const FOAM_MEMORY_S: f64 = 6.0;
/// Below this expected cover a sea draws no foam.
pub const NEGLIGIBLE_COVER: f64 = 1e-4;
/// Foam younger than this is fresh (the breaking crest itself: dense white), s.
pub const FRESH_FOAM_S: f64 = 1.0;
/// Sources are kept as 16-bit fixed point, this many to 1 (at most 16).
const SOURCE_SCALE: f32 = 4096.0;

/// E[(m + σ·Z)⁺] for a standard normal Z: the expected excess of a Gaussian over -m,
/// `σ·h(m/σ)` with `h(z) = φ(z) + z·Φ(z)` read from a table ([`EXCESS_TABLE`] points over
/// ±[`EXCESS_RANGE`], linear between them: within 1e-6 of the integral, and a few
/// operations where libm's erf and exp took most of a foam step).
#[inline(always)]
pub fn expected_excess(m: f32, sigma: f32) -> f32 {
    if sigma <= 1e-6 {
        return m.max(0.0);
    }
    let z = m / sigma;
    if z <= -EXCESS_RANGE {
        return 0.0;
    }
    if z >= EXCESS_RANGE {
        return m;
    }
    let table = excess_table();
    let pos = (z + EXCESS_RANGE) * ((EXCESS_TABLE - 1) as f32 / (2.0 * EXCESS_RANGE));
    let i = (pos as usize).min(EXCESS_TABLE - 2);
    let t = pos - i as f32;
    sigma * (table[i] + (table[i + 1] - table[i]) * t)
}

/// Points of the table of h(z) = φ(z) + z·Φ(z).
pub const EXCESS_TABLE: usize = 4097;
/// The table spans z in ±this (beyond, h is 0 below and z above to within 1e-16).
pub const EXCESS_RANGE: f32 = 8.0;

fn excess_table() -> &'static [f32; EXCESS_TABLE] {
    static TABLE: std::sync::OnceLock<Box<[f32; EXCESS_TABLE]>> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t = Box::new([0.0f32; EXCESS_TABLE]);
        for (i, v) in t.iter_mut().enumerate() {
            let z = -f64::from(EXCESS_RANGE) + 2.0 * f64::from(EXCESS_RANGE) * i as f64 / (EXCESS_TABLE - 1) as f64;
            // libm, not std: the same bits on every machine (glibc picks code by CPU).
            let pdf = libm::exp(-0.5 * z * z) / (2.0 * std::f64::consts::PI).sqrt();
            let cdf = 0.5 * libm::erfc(-z / std::f64::consts::SQRT_2);
            *v = (pdf + z * cdf) as f32;
        }
        t
    })
}

/// The foam model of one sea: its choppiness and the slope variance of its whole surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FoamModel {
    lambda: f32,
    slope_total: f32,
    active: bool,
}

impl FoamModel {
    /// The model of `sea`.
    pub fn of(sea: &Sea) -> FoamModel {
        let lambda = sea.choppiness();
        // The slope of waves the wind raised: the zero-wind intercept does not whitecap.
        let slope_total = (f64::from(sea.slope_variance()) - CALM_SLOPE_VARIANCE).max(0.0) as f32;
        let mut model = FoamModel { lambda, slope_total, active: true };
        model.active = lambda > 0.0 && !sea.components().is_empty() && model.expected_cover() >= NEGLIGIBLE_COVER;
        model
    }

    /// The source where the kept sines give the displacement gradient `g` (`[gxx, gyy, gxy]`,
    /// ∇D = -λ·g) and carry the slope variance `resolved_slope`.
    #[inline(always)]
    pub fn source(&self, g: [f32; 3], resolved_slope: f32) -> f32 {
        let l = self.lambda;
        let j = (1.0 - l * g[0]) * (1.0 - l * g[1]) - l * l * g[2] * g[2];
        let sigma = l * (self.slope_total - resolved_slope).max(0.0).sqrt();
        expected_excess(FOLD_JACOBIAN - j, sigma)
    }

    /// The mean cover the model expects of the sea: G·E[s] with J ≈ 1 - λ·(divergence), the
    /// divergence Gaussian with the surface's slope variance.
    pub fn expected_cover(&self) -> f64 {
        let sigma = self.lambda * self.slope_total.max(0.0).sqrt();
        f64::from(FOAM_GAIN) * f64::from(expected_excess(FOLD_JACOBIAN - 1.0, sigma))
    }

    /// False for a sea that makes no visible foam (a linear sea, a calm, or an expected cover
    /// below [`NEGLIGIBLE_COVER`]).
    pub fn is_active(&self) -> bool {
        self.active
    }
}

/// The foam clock of a sea: steps of [`FOAM_STEP_S`], or for a looping sea a power of two
/// steps per loop (the nearest to it), counted so that step n and n + steps-per-loop are the
/// same moment of the sea.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FoamClock {
    step_s: f64,
    /// The loop and log2 of its steps.
    looping: Option<(LoopPeriod, u32)>,
}

impl FoamClock {
    /// The clock of a sea with `params`.
    pub fn of(params: &SeaParams) -> FoamClock {
        match params.loop_period {
            Some(p) => {
                let bits = (p.seconds() / FOAM_STEP_S).log2().round().clamp(1.0, 24.0) as u32;
                FoamClock { step_s: p.seconds() / f64::from(1u32 << bits), looping: Some((p, bits)) }
            }
            None => FoamClock { step_s: FOAM_STEP_S, looping: None },
        }
    }

    /// The step, s.
    #[cfg(test)]
    pub fn step_s(&self) -> f64 {
        self.step_s
    }

    /// W, the steps of memory.
    pub fn memory_steps(&self) -> usize {
        ((FOAM_MEMORY_S / self.step_s).round() as usize).max(1)
    }

    /// The weights w_a of ages a = 0..W (the newest first): ∝ e^(-a·Δt/τ), summing to G.
    pub fn weights(&self) -> Vec<f32> {
        let decay = |a: usize| libm::exp(-(a as f64) * self.step_s / FOAM_LIFETIME_S);
        let raw: Vec<f64> = (0..self.memory_steps()).map(decay).collect();
        let sum: f64 = raw.iter().sum();
        raw.iter().map(|w| (w / sum * f64::from(FOAM_GAIN)) as f32).collect()
    }

    /// The last step at or before `time`, and how far past it `time` is (0..1 steps).
    pub fn step_at(&self, time: SeaTime) -> (i64, f32) {
        match (time, self.looping) {
            (SeaTime::Ticks(u), Some((_, bits))) => {
                let shift = 32 - bits;
                let frac = (u & ((1i64 << shift) - 1)) as f64 / (1i64 << shift) as f64;
                (u >> shift, frac as f32)
            }
            (SeaTime::Seconds(t), _) => {
                let pos = t / self.step_s;
                let n = pos.floor();
                (n as i64, (pos - n) as f32)
            }
            (SeaTime::Ticks(u), None) => (u, 0.0),
        }
    }

    /// The moment of the sea at step `n`.
    pub fn time_of(&self, n: i64) -> SeaTime {
        match self.looping {
            Some((_, bits)) => SeaTime::Ticks(n << (32 - bits)),
            None => SeaTime::Seconds(n as f64 * self.step_s),
        }
    }
}

/// Foam at a fixed set of resting points, followed through time: the last W + 1 steps'
/// sources per point (a ring), and the cover they give.
#[derive(Debug, Default)]
pub struct FoamTracker {
    /// The sea and number of points the ring belongs to, and its newest step.
    at: Option<(SeaParams, usize, i64)>,
    ring: Vec<u16>,
    foam: Vec<Foam>,
    rows: PhaseRows,
}

/// The foam at a point: its cover 0..=1, and how much of it is fresh (younger than
/// [`FRESH_FOAM_S`], 0..=1 of the cover).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Foam {
    /// The fraction of the surface covered, 0..=1.
    pub cover: f32,
    /// The fraction of that foam made in the last [`FRESH_FOAM_S`], 0..=1.
    pub fresh: f32,
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

    /// Brings the foam at `points` (resting points with their footprints) up to `time` and
    /// returns it, one per point. Continues from the last call when the sea and
    /// the points are the same and time moved forward by less than the memory; otherwise
    /// computes the whole memory. Either way the result is the same bits. Allocates only when
    /// the number of points grows.
    pub fn update(&mut self, sea: &Sea, points: &[[f32; 2]], footprints: &[Footprint], time: SeaTime) -> &[Foam] {
        let model = FoamModel::of(sea);
        self.foam.clear();
        if !model.is_active() {
            self.foam.resize(points.len(), Foam::default());
            self.at = None;
            return &self.foam;
        }
        let clock = FoamClock::of(&sea.params());
        let (now, frac) = clock.step_at(time);
        let memory = clock.memory_steps();
        let slots = memory + 1;
        // The ring must hold steps now + 1 - W ..= now + 1.
        let top = now + 1;
        let first = match self.at {
            Some((params, count, last)) if params == sea.params() && count == points.len() && last <= top => {
                (last + 1).max(top + 1 - slots as i64)
            }
            _ => top + 1 - slots as i64,
        };
        if self.ring.len() != points.len() * slots {
            self.ring.clear();
            self.ring.resize(points.len() * slots, 0);
        }
        if first <= top {
            sea.phase_rows((first..=top).map(|n| clock.time_of(n)), &mut self.rows);
            let rows = &self.rows;
            self.ring.par_chunks_mut(slots * 64).enumerate().for_each(|(chunk, ring)| {
                let mut g = [[0.0f32; 3]; FOLD_ROWS];
                for (i, history) in ring.chunks_exact_mut(slots).enumerate() {
                    let k = chunk * 64 + i;
                    let (p, fp) = (points[k], &footprints[k]);
                    let mut row = 0;
                    while row < rows.len() {
                        let count = (rows.len() - row).min(FOLD_ROWS);
                        let slope = sea.fold_rows(p[0], p[1], fp, rows, row, &mut g[..count]);
                        for (r, g) in g[..count].iter().enumerate() {
                            let n = first + (row + r) as i64;
                            let s = model.source(*g, slope);
                            history[n.rem_euclid(slots as i64) as usize] = quantize(s);
                        }
                        row += count;
                    }
                }
            });
        }
        self.at = Some((sea.params(), points.len(), top));
        let weights = clock.weights();
        let fresh = ((FRESH_FOAM_S / clock.step_s).round() as usize).clamp(1, weights.len());
        let (taps_now, taps_next) = (taps(&weights, now, slots), taps(&weights, now + 1, slots));
        // The taps run oldest first: the fresh ones are the last.
        let (fresh_now, fresh_next) = (&taps_now[taps_now.len() - fresh..], &taps_next[taps_next.len() - fresh..]);
        self.foam.resize(points.len(), Foam::default());
        self.foam.par_chunks_mut(64).zip(self.ring.par_chunks(slots * 64)).for_each(|(foam, ring)| {
            for (f, history) in foam.iter_mut().zip(ring.chunks_exact(slots)) {
                let (a, b) = (fir(history, &taps_now), fir(history, &taps_next));
                let all = a + (b - a) * frac;
                let (a, b) = (fir(history, fresh_now), fir(history, fresh_next));
                let young = a + (b - a) * frac;
                *f = Foam {
                    cover: all.clamp(0.0, 1.0),
                    fresh: if all > 0.0 { (young / all).clamp(0.0, 1.0) } else { 0.0 },
                };
            }
        });
        &self.foam
    }
}

/// A source as 16-bit fixed point, rounded (saturating at 16).
#[inline(always)]
pub(crate) fn quantize(s: f32) -> u16 {
    (s * SOURCE_SCALE + 0.5).clamp(0.0, 65535.0) as u16
}

/// The FIR of step `n` over a ring of `slots` steps (step m at slot m mod slots): each
/// weight with the slot of its step, the oldest first.
pub(crate) fn taps(weights: &[f32], n: i64, slots: usize) -> Vec<(f32, usize)> {
    weights.iter().enumerate().rev().map(|(a, &w)| (w, (n - a as i64).rem_euclid(slots as i64) as usize)).collect()
}

/// F_n = Σ w_a·s_{n-a} by the [`taps`] of step n, the oldest first: a fixed order, so the
/// same ring gives the same bits.
#[inline(always)]
pub(crate) fn fir(history: &[u16], taps: &[(f32, usize)]) -> f32 {
    let mut sum = 0.0f32;
    for &(w, slot) in taps {
        sum += w * f32::from(history[slot]);
    }
    sum / SOURCE_SCALE
}

/// [`fir`] by the taps of steps n (`now`) and n + 1 (`next`: the same weights, in the same
/// order) for up to `N` points of a ring (`slots` a point): each sum the same additions in
/// the same order as `fir`'s, so the same bits, but 2·N independent chains of additions for
/// the processor to overlap (one point's sum at a time waited on every addition). The patch's
/// (compiled with it).
#[cfg(any(feature = "cli", feature = "testing", test))]
#[inline(always)]
pub(crate) fn fir_pairs<const N: usize>(
    ring: &[u16],
    slots: usize,
    now: &[(f32, usize)],
    next: &[(f32, usize)],
) -> [(f32, f32); N] {
    let mut sums = [(0.0f32, 0.0f32); N];
    for (&(w, a), &(_, b)) in now.iter().zip(next) {
        for (sum, history) in sums.iter_mut().zip(ring.chunks_exact(slots)) {
            sum.0 += w * f32::from(history[a]);
            sum.1 += w * f32::from(history[b]);
        }
    }
    sums.map(|(a, b)| (a / SOURCE_SCALE, b / SOURCE_SCALE))
}

#[cfg(test)]
#[path = "foam_tests.rs"]
mod measured;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::ocean::SeaParams;
    use crate::sim::spectra::SpectrumChoice;

    #[test]
    fn the_expected_excess_is_the_gaussian_integral() {
        for (m, sigma) in [(-0.5f32, 0.2f32), (0.0, 0.3), (0.2, 0.1), (-1.0, 0.4)] {
            let n = 200_000;
            let mut sum = 0.0f64;
            for i in 0..n {
                // Midpoint rule over ±8σ.
                let z = -8.0 + 16.0 * (i as f64 + 0.5) / n as f64;
                let pdf = (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt();
                sum += (f64::from(m) + f64::from(sigma) * z).max(0.0) * pdf * 16.0 / n as f64;
            }
            let got = f64::from(expected_excess(m, sigma));
            assert!((got - sum).abs() < 1e-5 + 1e-3 * sum, "m {m} σ {sigma}: {got} vs {sum}");
        }
        assert_eq!(expected_excess(0.3, 0.0), 0.3);
        assert_eq!(expected_excess(-0.3, 0.0), 0.0);
    }

    #[test]
    fn weights_sum_to_the_gain_and_fade_with_the_lifetime() {
        let clock = FoamClock::of(&SeaParams::default());
        let w = clock.weights();
        assert_eq!(w.len(), 30, "6 s of 0.2 s steps");
        assert!((w.iter().sum::<f32>() - FOAM_GAIN).abs() < 1e-4);
        // One lifetime (10 steps) fades a weight to 1/e.
        assert!((w[10] / w[0] - (-1.0f32).exp()).abs() < 1e-5);
    }

    #[test]
    fn the_clock_counts_whole_fractions_of_a_loop() {
        let params = SeaParams { wind_m_s: 8.0, ..SeaParams::default() };
        let period = LoopPeriod::new(64.0, params.longest_peak_period_s()).unwrap();
        let looping = SeaParams { loop_period: Some(period), ..params };
        let sea = Sea::new(looping);
        let clock = FoamClock::of(&looping);
        assert_eq!(clock.step_s(), 0.25, "256 steps of 1/4 s");
        assert_eq!(clock.step_at(sea.time(0.0)), (0, 0.0));
        assert_eq!(clock.step_at(sea.time(64.0)), (256, 0.0));
        assert_eq!(clock.step_at(sea.time_after(0.3, 64.0)).0, clock.step_at(sea.time(0.3)).0 + 256);
        assert_eq!(
            sea.surface_at(clock.time_of(256), Vec::new()).into_buffer(),
            sea.surface_at(clock.time_of(0), Vec::new()).into_buffer()
        );
        let plain = FoamClock::of(&params);
        let (n, frac) = plain.step_at(SeaTime::Seconds(1.25));
        assert!(n == 6 && (frac - 0.25).abs() < 1e-5, "{n} {frac}");
        let _ = SpectrumChoice::PiersonMoskowitz;
    }
}
