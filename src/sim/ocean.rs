//! The wind-driven sea: a Pierson–Moskowitz surface as travelling sines plus a diamond-square
//! fBm tail (`docs/ALGORITHMS.md` §3.3, "How tidepool makes the parts agree").
//!
//! # The sines
//! [`FREQUENCY_BINS`] geometric frequency bins from [`BAND_LOW`]·fm to [`CUTOFF`]·fm times
//! [`DIRECTION_BINS`] direction bins over the full circle. Each component's amplitude is
//! `a = √(2·E(f, θ)·df·dθ)` with E taken at the bin's midpoint (so Σa²/2 is the midpoint-rule
//! integral of the band); its frequency and direction are then jittered inside the bin and its
//! phase drawn uniformly, all from the seed, so the sea never visibly repeats. Each travels
//! with deep-water dispersion ω² = g·k, in physical seconds. Components carrying less than
//! [`NEGLIGIBLE`] of m0 (almost all of them upwind) are dropped; the band below 0.5·fm holds
//! e^-20 of m0.
//!
//! # The tail
//! Above the cut-off fc = 5·fm (wavelength λc = λp/25, 0.2 % of m0) a wrapping diamond-square
//! fBm with H = 1 carries the variance: its corner lattice has the spacing λc (the paper's
//! "corners from PM", drawn with the tail's standard deviation), 8 corners a side (so the
//! period is 8·λc and the tiling does not show), and it refines down to about 0.2 m (at most
//! 7 octaves, 1024² cells). Coarser scales carry nothing: the sines own them. The field
//! drifts downwind at the phase speed of fc.
//!
//! # Sampling with a footprint
//! A renderer samples the sea at mesh vertices, each standing for a patch of sea (a
//! [`Footprint`]: the ground step to the next sample across and along the view). Waves that
//! change phase by more than π/2 over one step cannot be drawn there and would alias into
//! noise, so [`SeaFrame::sample`] keeps a component fully up to a phase step of π/2 and fades
//! it out by π (the Nyquist limit); the footprint is anisotropic, so far away the crests that
//! run across the view survive while waves travelling towards the viewer fade. The fBm is read
//! at the octave of the footprint's size. What is removed comes back as statistics the shading
//! needs: the unresolved slope variance (to spread the sun's glint; the total is Cox–Munk's
//! `0.003 + 0.00512·U`), and the standard deviation of what remains (so whitecaps keep
//! Monahan's coverage at every distance). A zero footprint is the full surface (heightmaps).
//!
//! # Whitecaps
//! Monahan's whitecap fraction `W = 3.84e-6·U^3.41` (capped at 1): a point foams when the
//! indicator `q = 0.6·h/σ + 0.8·p` exceeds the Gaussian quantile z with P(N > z) = W, through
//! a soft ramp centred on z (which keeps the mean coverage). `h/σ` puts the foam on the
//! crests of wave groups, where breaking happens; `p` is a unit-variance patch pattern (the
//! tail's fBm read with its corners [`FOAM_PATCH_M`] apart across the wind and
//! [`FOAM_STREAK`] times that along it, so patches are metres wide at any wind and lie in
//! streaks along the wind, as the Beaufort descriptions have them) that breaks the foam up
//! instead of painting whole crests white.
//! The two are independent, so q has unit variance.

use std::f64::consts::PI;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::fbm::{self, Fbm};
use super::spectrum::{G, PiersonMoskowitz, wavelength_m, wavenumber};
use super::surface::{Footprint, Surface, SurfaceSample};

/// Lowest frequency of the sines, as a multiple of fm.
pub const BAND_LOW: f64 = 0.5;
/// The cut-off between the sines and the fBm tail, as a multiple of fm. At 3·fm the sea
/// looked smooth near the camera: the steeper short waves that show crests were left to the
/// isotropic fBm; at 5·fm they are directional sines.
pub const CUTOFF: f64 = 5.0;
/// Frequency bins of the sines.
pub const FREQUENCY_BINS: usize = 24;
/// Direction bins of the sines over the full circle.
pub const DIRECTION_BINS: usize = 16;
/// Components with less variance than this fraction of m0 are dropped (together well under
/// 1 % of m0).
pub const NEGLIGIBLE: f64 = 1e-5;
/// Lanes of the vectorised sum over components.
const LANES: usize = 8;
/// Corner lattice points per side of the tail (its period is this many cut-off wavelengths).
pub const TAIL_CORNERS: usize = 8;
/// Weight of the long waves' normalised height in the whitecap indicator.
pub const FOAM_LONG: f32 = 0.6;
/// Weight of the patch pattern in the whitecap indicator (0.6² + 0.8² = 1).
pub const FOAM_SHORT: f32 = 0.8;
/// The width of whitecap patches across the wind, m: the spacing of the patch pattern's
/// corner lattice.
pub const FOAM_PATCH_M: f32 = 6.0;
/// How much longer foam patches are along the wind than across it.
pub const FOAM_STREAK: f32 = 4.0;
/// The finest cell of the tail the refinement aims at, metres.
pub const TAIL_FINEST_M: f64 = 0.2;
/// The most octaves the tail is refined below its corner lattice.
pub const TAIL_MAX_LEVELS: u32 = 7;

/// Monahan's whitecap fraction 3.84e-6·U^3.41 for a wind of `wind_m_s`, capped at 1.
pub fn whitecap_fraction(wind_m_s: f64) -> f64 {
    (3.84e-6 * wind_m_s.max(0.0).powf(3.41)).min(1.0)
}

/// The Cox–Munk mean square slope (both axes together) of a sea under `wind_m_s`.
pub fn cox_munk_slope_variance(wind_m_s: f64) -> f64 {
    0.003 + 0.00512 * wind_m_s.max(0.0)
}

/// The z with P(N(0,1) > z) = p, for p in (0, 1); +inf for p <= 0, -inf for p >= 1.
pub fn upper_normal_quantile(p: f64) -> f64 {
    if p <= 0.0 {
        return f64::INFINITY;
    }
    if p >= 1.0 {
        return f64::NEG_INFINITY;
    }
    let (mut lo, mut hi) = (-40.0f64, 40.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if 0.5 * libm::erfc(mid / 2f64.sqrt()) > p { lo = mid } else { hi = mid }
    }
    0.5 * (lo + hi)
}

/// One travelling sine of the sea.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Component {
    /// Amplitude, m.
    pub amplitude_m: f64,
    /// Frequency, Hz.
    pub frequency_hz: f64,
    /// Angular frequency ω = 2πf, rad/s.
    pub omega: f64,
    /// Wavenumber k = ω²/g, rad/m.
    pub wavenumber: f64,
    /// Where it travels to, radians clockwise from north.
    pub bearing_rad: f64,
    /// Phase at t = 0, radians.
    pub phase_rad: f64,
}

/// Everything that defines a sea.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SeaParams {
    /// Wind speed at 10 m, m/s (0 = flat calm).
    pub wind_m_s: f64,
    /// Where the wind comes from, degrees clockwise from north; waves travel the other way.
    pub wind_from_deg: f64,
    /// Seed of phases, jitter and the tail.
    pub seed: u64,
}

/// The tail: a drifting wrapping fBm field.
#[derive(Clone, Debug)]
struct Tail {
    field: Fbm,
    cell_m: f64,
    velocity_m_s: [f64; 2],
    variance: f64,
    /// Per octave: the variance (m²) and slope variance per axis of the field cut off there.
    octave_variance: Vec<f32>,
    octave_slope: Vec<f32>,
}

/// A sea: its spectrum, its sines and its tail. Immutable; sample it through [`Sea::frame`].
#[derive(Clone, Debug)]
pub struct Sea {
    params: SeaParams,
    spectrum: PiersonMoskowitz,
    components: Vec<Component>,
    /// Per component, f32 for the hot loop: east and north wavenumber, amplitude, wavelength.
    kx: Vec<f32>,
    ky: Vec<f32>,
    amp: Vec<f32>,
    wavelength: Vec<f32>,
    tail: Option<Tail>,
    foam_z: f32,
    slope_total: f32,
    /// Unit vector (east, north) the wind blows towards.
    downwind: [f32; 2],
}

impl Sea {
    /// Builds the sea for `params` (deterministic in its seed).
    pub fn new(params: SeaParams) -> Sea {
        let spectrum = PiersonMoskowitz::new(params.wind_m_s);
        let mut rng = ChaCha8Rng::seed_from_u64(params.seed ^ 0x5ea_5ea_5ea);
        let mut components = Vec::new();
        let mut tail = None;
        if let Some(fm) = spectrum.peak_hz() {
            let downwind = (params.wind_from_deg + 180.0).to_radians();
            let (f_lo, f_hi) = (BAND_LOW * fm, CUTOFF * fm);
            let ratio = (f_hi / f_lo).powf(1.0 / FREQUENCY_BINS as f64);
            let dtheta = 2.0 * PI / DIRECTION_BINS as f64;
            let floor = NEGLIGIBLE * spectrum.m0();
            for i in 0..FREQUENCY_BINS {
                let (e0, e1) = (f_lo * ratio.powi(i as i32), f_lo * ratio.powi(i as i32 + 1));
                let (centre, df) = (0.5 * (e0 + e1), e1 - e0);
                for j in 0..DIRECTION_BINS {
                    let theta = -PI + (j as f64 + 0.5) * dtheta;
                    let variance = spectrum.directional_energy(centre, theta) * df * dtheta;
                    // Draw the jitter and phase even for dropped components, so that the
                    // stream (and every other component) does not depend on the threshold.
                    let (uf, ut, phase): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
                    if variance < floor {
                        continue;
                    }
                    let f = e0 + uf * df;
                    let omega = 2.0 * PI * f;
                    components.push(Component {
                        amplitude_m: (2.0 * variance).sqrt(),
                        frequency_hz: f,
                        omega,
                        wavenumber: wavenumber(f),
                        bearing_rad: downwind + theta + (ut - 0.5) * dtheta,
                        phase_rad: 2.0 * PI * phase,
                    });
                }
            }
            components.sort_by(|a, b| a.wavenumber.total_cmp(&b.wavenumber));
            tail = Some(Self::tail(&spectrum, f_hi, downwind, params.seed));
        }
        // Padded with silent components to whole lanes, for the vectorised loop.
        let padded = components.len().next_multiple_of(LANES);
        let pad = |v: Vec<f32>| -> Vec<f32> {
            let mut v = v;
            v.resize(padded, 0.0);
            v
        };
        let kx = pad(components.iter().map(|c| (c.wavenumber * c.bearing_rad.sin()) as f32).collect());
        let ky = pad(components.iter().map(|c| (c.wavenumber * c.bearing_rad.cos()) as f32).collect());
        let amp = pad(components.iter().map(|c| c.amplitude_m as f32).collect());
        let wavelength = components.iter().map(|c| (2.0 * PI / c.wavenumber) as f32).collect();
        let foam_z = upper_normal_quantile(whitecap_fraction(spectrum.wind_m_s())) as f32;
        let slope_total = cox_munk_slope_variance(spectrum.wind_m_s()) as f32;
        let to = (params.wind_from_deg + 180.0).to_radians();
        let downwind = [to.sin() as f32, to.cos() as f32];
        Sea { params, spectrum, components, kx, ky, amp, wavelength, tail, foam_z, slope_total, downwind }
    }

    fn tail(spectrum: &PiersonMoskowitz, cutoff_hz: f64, downwind: f64, seed: u64) -> Tail {
        let lambda_c = wavelength_m(cutoff_hz);
        let variance = spectrum.m0() - spectrum.cumulative_variance(cutoff_hz);
        let levels = ((lambda_c / TAIL_FINEST_M).log2().ceil().max(0.0) as u32).min(TAIL_MAX_LEVELS);
        let sigma = variance.sqrt() as f32;
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x7a11);
        let corners: Vec<f32> = (0..TAIL_CORNERS * TAIL_CORNERS).map(|_| sigma * fbm::gaussian(&mut rng)).collect();
        let field = Fbm::diamond_square(
            TAIL_CORNERS,
            levels,
            &corners,
            sigma * fbm::UNIT_VARIANCE_DISPLACEMENT,
            1.0,
            seed ^ 0xd1a,
        );
        let speed = G / (2.0 * PI * cutoff_hz);
        let cell_m = lambda_c / f64::from(1u32 << levels);
        // Measure each octave's variance and slope on its own lattice (exact for the field).
        let (mut octave_variance, mut octave_slope) = (Vec::new(), Vec::new());
        let n = field.size() as isize;
        for octave in 0..=levels {
            let st = 1isize << octave;
            let (mut v, mut sl, mut count) = (0.0f64, 0.0f64, 0.0f64);
            for y in (0..n).step_by(st as usize) {
                for x in (0..n).step_by(st as usize) {
                    let h = f64::from(field.at(x, y));
                    let d = f64::from(field.at(x + st, y)) - h;
                    v += h * h;
                    sl += d * d;
                    count += 1.0;
                }
            }
            octave_variance.push((v / count) as f32);
            octave_slope.push((sl / count / (st as f64 * cell_m).powi(2)) as f32);
        }
        Tail {
            field,
            cell_m,
            velocity_m_s: [speed * downwind.sin(), speed * downwind.cos()],
            variance,
            octave_variance,
            octave_slope,
        }
    }

    /// The parameters it was built from.
    pub fn params(&self) -> SeaParams {
        self.params
    }

    /// Its spectrum.
    pub fn spectrum(&self) -> &PiersonMoskowitz {
        &self.spectrum
    }

    /// The sines, longest first (the hot loop's copies are padded to whole lanes).
    pub fn components(&self) -> &[Component] {
        &self.components
    }

    /// The variance carried by the fBm tail, m² (0 for a calm).
    pub fn tail_variance(&self) -> f64 {
        self.tail.as_ref().map_or(0.0, |t| t.variance)
    }

    /// The tail's field, if the sea is not calm.
    pub fn tail_field(&self) -> Option<&Fbm> {
        self.tail.as_ref().map(|t| &t.field)
    }

    /// The sea at `time_s` seconds, ready to sample.
    pub fn frame(&self, time_s: f64) -> SeaFrame<'_> {
        self.frame_in(time_s, Vec::new())
    }

    /// [`Sea::frame`] reusing `buffer` (from [`SeaFrame::into_buffer`]), so that a stream of
    /// frames allocates nothing.
    pub fn frame_in(&self, time_s: f64, mut phase: Vec<f32>) -> SeaFrame<'_> {
        phase.clear();
        phase.extend(self.components.iter().map(|c| (c.phase_rad - c.omega * time_s).rem_euclid(2.0 * PI) as f32));
        let tail_offset = self.tail.as_ref().map_or([0.0; 2], |t| {
            let period = t.cell_m * t.field.size() as f64;
            [
                (t.velocity_m_s[0] * time_s).rem_euclid(period) as f32,
                (t.velocity_m_s[1] * time_s).rem_euclid(period) as f32,
            ]
        });
        SeaFrame { sea: self, phase, tail_offset }
    }
}

/// The sea at one moment.
#[derive(Clone, Debug)]
pub struct SeaFrame<'a> {
    sea: &'a Sea,
    phase: Vec<f32>,
    tail_offset: [f32; 2],
}

impl SeaFrame<'_> {
    /// Gives back the frame's buffer, for [`Sea::frame_in`].
    pub fn into_buffer(self) -> Vec<f32> {
        self.phase
    }
}

/// cos(x) for any x, to about 1e-5: reduce to [-π, π] with an add-and-subtract round (no
/// `floor` call, so the loop vectorises on plain SSE2) and evaluate the Taylor series to x¹².
#[inline(always)]
pub fn fast_cos(x: f32) -> f32 {
    const INV_TAU: f32 = 1.0 / std::f32::consts::TAU;
    const ROUND: f32 = 12_582_912.0; // 1.5·2^23: adding and subtracting it rounds to an integer
    let turns = x * INV_TAU;
    let r = (turns + ROUND) - ROUND;
    let t = (turns - r) * std::f32::consts::TAU;
    let u = t * t;
    let p = 1.0 / 479_001_600.0;
    let p = p * u - 1.0 / 3_628_800.0;
    let p = p * u + 1.0 / 40_320.0;
    let p = p * u - 1.0 / 720.0;
    let p = p * u + 1.0 / 24.0;
    let p = p * u - 0.5;
    p * u + 1.0
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl SeaFrame<'_> {
    /// The sea this frame belongs to.
    pub fn sea(&self) -> &Sea {
        self.sea
    }

    /// Samples the surface at (east, north) metres for a sample standing for `footprint`
    /// (see the module docs for what the footprint removes).
    pub fn sample(&self, x: f32, y: f32, footprint: &Footprint) -> SurfaceSample {
        let sea = self.sea;
        // Components are sorted longest first; those shorter than two of the footprint's
        // shorter side alias whatever their direction.
        let n = sea.wavelength.partition_point(|&l| l > 2.0 * footprint.min_m());
        // Eight lanes of independent sums, added up in a fixed order at the end: the compiler
        // may vectorise lanes (it may not reorder a float sum), and the result is the same
        // on every run.
        let (mut hs, mut vs, mut ss) = ([0.0f32; LANES], [0.0f32; LANES], [0.0f32; LANES]);
        let end = n.next_multiple_of(LANES);
        let chunks = sea.kx[..end]
            .chunks_exact(LANES)
            .zip(sea.ky[..end].chunks_exact(LANES))
            .zip(sea.amp[..end].chunks_exact(LANES))
            .zip(self.phase[..end].chunks_exact(LANES));
        for (((kx, ky), amp), phase) in chunks {
            for l in 0..LANES {
                let (kx, ky) = (kx[l], ky[l]);
                let a = resolution_weight(footprint.phase_step(kx, ky)) * amp[l];
                hs[l] += a * fast_cos(kx * x + ky * y + phase[l]);
                let a2 = 0.5 * a * a;
                vs[l] += a2;
                ss[l] += a2 * (kx * kx + ky * ky);
            }
        }
        let mut h: f32 = hs.iter().sum();
        let mut resolved_var: f32 = vs.iter().sum();
        let mut resolved_slope: f32 = ss.iter().sum();
        let (mut tail_h, mut tail_var) = (0.0f32, 0.0f32);
        if let Some(tail) = &sea.tail {
            let cell = tail.cell_m as f32;
            // The longer side: the fBm is isotropic, so it must not alias along either axis.
            let size = footprint.max_m();
            let octave = if size <= cell { 0 } else { (size / cell).log2().ceil() as u32 };
            if octave <= tail.field.levels() {
                let gx = (x - self.tail_offset[0]) / cell;
                let gy = (y - self.tail_offset[1]) / cell;
                tail_h = tail.field.sample(gx, gy, octave);
                tail_var = tail.octave_variance[octave as usize];
                resolved_slope += tail.octave_slope[octave as usize];
            }
        }
        h += tail_h;
        resolved_var += tail_var;
        let foam = if sea.foam_z == f32::NEG_INFINITY {
            1.0
        } else if sea.foam_z.is_finite() && resolved_var > 0.0 {
            let q = match self.foam_patches(x, y, footprint) {
                Some(patch) => FOAM_LONG * h / resolved_var.sqrt() + FOAM_SHORT * patch,
                None => h / resolved_var.sqrt(),
            };
            smoothstep(sea.foam_z - 0.4, sea.foam_z + 0.4, q)
        } else {
            0.0
        };
        let unresolved = (sea.slope_total - resolved_slope).max(0.1 * sea.slope_total) * 0.5;
        SurfaceSample { height_m: h, foam, unresolved_slope_variance: unresolved }
    }

    /// The patch pattern that breaks whitecaps up: the tail's field read as a noise whose
    /// corner lattice is [`FOAM_PATCH_M`] apart, normalised to unit variance; `None` where the
    /// footprint is too coarse to show patches.
    fn foam_patches(&self, x: f32, y: f32, footprint: &Footprint) -> Option<f32> {
        let tail = self.sea.tail.as_ref()?;
        let cells = tail.field.size() as f32 / TAIL_CORNERS as f32;
        let cell = FOAM_PATCH_M / cells;
        let size = footprint.max_m();
        let octave = if size <= cell { 0 } else { (size / cell).log2().ceil() as u32 };
        if octave >= tail.field.levels() {
            return None;
        }
        // In the wind's frame, stretched along it: foam lies in streaks along the wind.
        let (px, py) = (x - self.tail_offset[0], y - self.tail_offset[1]);
        let [dx, dy] = self.sea.downwind;
        let along = (px * dx + py * dy) / FOAM_STREAK;
        let across = -px * dy + py * dx;
        Some(tail.field.sample(along / cell, across / cell, octave) / tail.octave_variance[octave as usize].sqrt())
    }

    /// The full surface height at (east, north) metres.
    pub fn height(&self, x: f32, y: f32) -> f32 {
        self.sample(x, y, &Footprint::default()).height_m
    }
}

impl Surface for SeaFrame<'_> {
    fn sample(&self, x: f32, y: f32, footprint: &Footprint) -> SurfaceSample {
        SeaFrame::sample(self, x, y, footprint)
    }
}

/// How much of a wave a sample keeps, from the wave's phase change per sample step: all of it
/// up to π/2 (four samples a wavelength), none from π (two samples, the Nyquist limit).
#[inline(always)]
fn resolution_weight(phase_step: f32) -> f32 {
    let t = ((std::f32::consts::PI - phase_step) * std::f32::consts::FRAC_2_PI).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sea(wind: f64) -> Sea {
        Sea::new(SeaParams { wind_m_s: wind, wind_from_deg: 270.0, seed: 42 })
    }

    #[test]
    fn amplitudes_carry_the_band_variance() {
        for wind in [2.45, 10.0, 30.0] {
            let s = sea(wind);
            let fm = s.spectrum().peak_hz().unwrap();
            let sum: f64 = s.components().iter().map(|c| c.amplitude_m * c.amplitude_m / 2.0).sum();
            let band = s.spectrum().band_variance(BAND_LOW * fm, CUTOFF * fm);
            assert!((sum / band - 1.0).abs() < 0.02, "U = {wind}: {sum} vs {band}");
            let total = band + s.tail_variance() + s.spectrum().cumulative_variance(BAND_LOW * fm);
            assert!((total / s.spectrum().m0() - 1.0).abs() < 1e-9, "band + tail = m0");
        }
    }

    #[test]
    fn every_component_obeys_deep_water_dispersion() {
        let s = sea(12.0);
        assert!(s.components().len() > FREQUENCY_BINS * DIRECTION_BINS / 2);
        for c in s.components() {
            assert!((c.omega * c.omega / (G * c.wavenumber) - 1.0).abs() < 1e-12);
            assert!((c.omega - 2.0 * PI * c.frequency_hz).abs() < 1e-12);
        }
    }

    #[test]
    fn the_surface_variance_is_m0() {
        let s = sea(10.0);
        let m0 = s.spectrum().m0();
        let (mut sum, mut n) = (0.0f64, 0usize);
        for t in 0..20 {
            let frame = s.frame(t as f64 * 7.3);
            for i in 0..40 {
                for j in 0..40 {
                    let h = f64::from(frame.height(i as f32 * 23.7 - 400.0, j as f32 * 19.1 + 100.0));
                    sum += h * h;
                    n += 1;
                }
            }
        }
        let var = sum / n as f64;
        assert!((var / m0 - 1.0).abs() < 0.10, "variance {var} vs m0 {m0}");
    }

    #[test]
    fn waves_travel_downwind() {
        // Wind from the west: the sea at x + c·t, t matches the sea at x, 0 for the peak wave.
        let s = Sea::new(SeaParams { wind_m_s: 10.0, wind_from_deg: 270.0, seed: 1 });
        let mean_bearing: f64 = s.components().iter().map(|c| c.amplitude_m.powi(2) * c.bearing_rad.sin()).sum();
        assert!(mean_bearing > 0.0, "energy travels east");
        let n = Sea::new(SeaParams { wind_m_s: 10.0, wind_from_deg: 180.0, seed: 1 });
        let north: f64 = n.components().iter().map(|c| c.amplitude_m.powi(2) * c.bearing_rad.cos()).sum();
        assert!(north > 0.0, "a south wind drives waves north");
    }

    #[test]
    fn calm_is_flat() {
        let s = sea(0.0);
        assert!(s.components().is_empty() && s.tail_field().is_none());
        let f = s.frame(12.0);
        assert_eq!(
            f.sample(3.0, 4.0, &Footprint::isotropic(1.0)),
            SurfaceSample { height_m: 0.0, foam: 0.0, unresolved_slope_variance: 0.0015 }
        );
    }

    #[test]
    fn footprints_filter_short_waves_and_report_their_slope() {
        let s = sea(10.0);
        let f = s.frame(0.0);
        let near = f.sample(10.0, 20.0, &Footprint::default());
        let far = f.sample(10.0, 20.0, &Footprint::isotropic(200.0));
        assert!(far.unresolved_slope_variance > near.unresolved_slope_variance);
        let var = |fp: f32| {
            (0..400)
                .map(|i| {
                    f64::from(f.sample(i as f32 * 37.0, i as f32 * 11.0, &Footprint::isotropic(fp)).height_m).powi(2)
                })
                .sum::<f64>()
                / 400.0
        };
        assert!(var(60.0) < var(0.0), "a 60 m footprint removes variance");
    }

    #[test]
    fn whitecaps_follow_monahan() {
        assert!((whitecap_fraction(10.0) - 3.84e-6 * 10f64.powf(3.41)).abs() < 1e-12);
        assert_eq!(whitecap_fraction(60.0), 1.0);
        assert!((upper_normal_quantile(0.5)).abs() < 1e-9);
        assert!((upper_normal_quantile(0.02275) - 2.0).abs() < 1e-3);
        for wind in [8.0, 15.0, 22.0] {
            let s = sea(wind);
            let f = s.frame(3.0);
            let n = 4000;
            let cover: f64 = (0..n)
                .map(|i| {
                    f64::from(f.sample((i % 63) as f32 * 13.1, (i / 63) as f32 * 17.3, &Footprint::default()).foam)
                })
                .sum::<f64>()
                / n as f64;
            let want = whitecap_fraction(wind);
            assert!((cover - want).abs() < 0.5 * want + 0.003, "U = {wind}: {cover} vs {want}");
        }
    }

    #[test]
    fn fast_cos_is_accurate() {
        for i in -2000..2000 {
            let x = i as f32 * 0.37;
            assert!((fast_cos(x) - x.cos()).abs() < 2e-4, "{x}");
        }
    }

    #[test]
    fn same_seed_same_sea() {
        let (sa, sb) = (sea(9.0), sea(9.0));
        let (a, b) = (sa.frame(5.0), sb.frame(5.0));
        assert_eq!(a.sample(1.0, 2.0, &Footprint::isotropic(0.5)), b.sample(1.0, 2.0, &Footprint::isotropic(0.5)));
        let c = Sea::new(SeaParams { wind_m_s: 9.0, wind_from_deg: 270.0, seed: 43 });
        assert_ne!(a.height(1.0, 2.0), c.frame(5.0).height(1.0, 2.0));
    }
}
