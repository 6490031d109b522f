//! The lake: Perlin-noise water (`docs/ALGORITHMS.md` §2) whose height and ripple size follow the wind.
//!
//! The paper sums octaves of lattice noise for the height field Z(x, y, t) and stops there;
//! tidepool gives the sum a physical scale so that `--wind` means metres per second:
//!
//! - **Geometry.** The camera stands on the south shore at the origin; the far (north) shore
//!   runs east-west [`FAR_SHORE_M`] metres away, drawn over ±55° (870 m at the waterline,
//!   see `crate::render::shore`); the east and west shores lie outside the view, so the water
//!   has no edge but the far shore. Z = 0 is the still water plane; heights are metres.
//! - **Wind.** It blows from the far shore towards the camera, over a fetch of
//!   [`FAR_SHORE_M`]. The ripples' length is that of the fetch-limited JONSWAP sea (Hasselmann
//!   et al. 1973): peak frequency `fp = 3.5·(g/U)·(gF/U²)^-0.33`, 0.77 m at 5 m/s. What a
//!   mirror shows depends on the slopes, so those set the height: the sum's mean square slope
//!   is Cox and Munk's `0.00512·U` for a clean surface (without their 0.003 of open-ocean
//!   swell, which a sheltered lake lacks), faded in as (U / [`RIPPLE_ONSET_M_S`])² below the
//!   onset: under about 2 m/s a lake has only cat's paws between glassy patches.
//! - **Noise.** Octave 0's lattice spacing is half the peak wavelength (value noise has features
//!   about two cells across); each further octave halves it. Persistence 0.5 makes the energy
//!   per octave fall as k⁻² — the k⁻³ saturation range of wind waves, whose slopes are spread
//!   evenly over the octaves. `--octaves` and `--persistence` shape the ripples; the total
//!   slope stays the wind's. Octave 0 drifts downwind at the peak wave's phase speed √(gλ/2π),
//!   finer octaves slower, each in its own direction within ±30° of the wind.
//! - **Cat's paws.** A light wind does not roughen a lake evenly: gusts touch down in patches
//!   that drift downwind over glassy water. A coarse noise (lattice 32 m to 4 m, drifting at the wind
//!   speed) marks the rough part of the surface, a fraction [`rough_fraction`] of it (a
//!   quarter at 1 m/s, all of it from 6 m/s), and the ripples are scaled up there so the mean
//!   square slope stays Cox and Munk's. Between patches the lake is a mirror.
//! - **Footprint.** A mesh sample leaves out the octaves it cannot carry (a lattice finer than
//!   about twice the sample step, faded over one octave) and reports their slope variance as
//!   unresolved, which the renderer turns into a blurred reflection.

use std::f32::consts::PI;

use super::noise::{Fractal, MAX_OCTAVES, NoiseKind, NoiseSurface, WaterNoise};
use super::ocean::upper_normal_quantile;
use super::surface::{Footprint, Surface, SurfaceSample};
use crate::error::ValueError;

/// The far shore's distance north of the camera's shore, m: the wind's fetch.
pub const FAR_SHORE_M: f32 = 300.0;
/// Below this wind speed the slopes fade in as (U / onset)², m/s.
pub const RIPPLE_ONSET_M_S: f64 = 2.0;
/// Standard gravity, m/s².
pub const GRAVITY: f64 = 9.81;
/// How far each octave's drift may stray from the wind, radians (30°).
pub const DRIFT_SPREAD_RAD: f32 = PI / 6.0;
/// Lattice spacing of the gust patches' coarsest octave, m (four octaves: 32 m down to 4 m).
pub const GUST_SPACING_M: f32 = 32.0;
/// The wind from which gusts roughen the whole lake, m/s.
pub const FULL_COVER_M_S: f64 = 6.0;
/// The fraction of the lake rough in the lightest air.
pub const MIN_COVER: f64 = 0.15;

/// The fraction of the lake's surface that a wind of `u` m/s roughens (the rest is glassy).
pub fn rough_fraction(u: f64) -> f64 {
    (MIN_COVER + (1.0 - MIN_COVER) * u.max(0.0) / FULL_COVER_M_S).min(1.0)
}

/// The patches of rough water: where a coarse drifting noise exceeds the threshold that leaves
/// the wind's [`rough_fraction`] above it, with a soft edge.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Gusts {
    noise: WaterNoise,
    /// The noise's standard deviation.
    std: f32,
    /// Patches begin where noise / std passes this (-inf: everywhere).
    threshold: f32,
    /// Scales the patches' ripples so that the mean of roughness² is 1.
    gain: f32,
}

/// Half the width of the patches' soft edge, in standard deviations of the gust noise.
const GUST_EDGE: f32 = 0.5;

fn smoothstep(edge0: f32, edge1: f32, x: f32) -> f32 {
    let t = ((x - edge0) / (edge1 - edge0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

impl Gusts {
    fn new(seed: u64, wind_m_s: f64) -> Gusts {
        let fractal = Fractal { kind: NoiseKind::Value, seed: seed ^ 0x6775_7374, octaves: 4, persistence: 0.7 };
        let noise = WaterNoise {
            fractal,
            spacing_m: GUST_SPACING_M,
            speed_m_s: wind_m_s as f32,
            heading_rad: -PI / 2.0,
            spread_rad: 0.2,
        };
        let cover = rough_fraction(wind_m_s);
        let threshold = if cover >= 1.0 { f32::NEG_INFINITY } else { upper_normal_quantile(cover) as f32 };
        // E[roughness²] for a normal noise, by quadrature over ±8 standard deviations.
        let mean_square = if cover >= 1.0 {
            1.0
        } else {
            let n = 1600;
            (0..=n)
                .map(|i| {
                    let z = -8.0 + 16.0 * f64::from(i) / f64::from(n);
                    let r = f64::from(smoothstep(threshold - GUST_EDGE, threshold + GUST_EDGE, z as f32));
                    r * r * (-z * z / 2.0).exp() / (2.0 * std::f64::consts::PI).sqrt() * 16.0 / f64::from(n)
                })
                .sum::<f64>()
        };
        Gusts { noise, std: fractal.variance().sqrt(), threshold, gain: (1.0 / mean_square.max(1e-9).sqrt()) as f32 }
    }
}

/// [`Gusts`] at one moment.
#[derive(Clone, Copy, Debug, PartialEq)]
struct GustFrame {
    noise: NoiseSurface,
    std: f32,
    /// Σ p²ⁱ over the octaves (the variance is this times the noise kind's).
    total_weight: f32,
    threshold: f32,
    gain: f32,
}

impl GustFrame {
    /// The square of how rough the water is at (east, north) relative to the lake's mean (0
    /// glassy; 1 everywhere once the wind covers the whole lake), as seen by a sample standing
    /// for `size_m` metres. Patches finer than the sample are left out and their part of the
    /// answer is the mean, 1: far away, where a patch is thinner than a pixel row, the lake is
    /// evenly rough on average instead of randomly rough or glassy from row to row.
    #[inline]
    fn roughness_squared(&self, x: f32, y: f32, size_m: f32) -> f32 {
        if self.threshold == f32::NEG_INFINITY {
            return 1.0;
        }
        let kind_variance = self.std * self.std / self.total_weight;
        let (mut z, mut kept) = (0.0, 0.0);
        for i in 0..self.noise.octave_count() {
            let w = (self.noise.spacing_m(i) / size_m.max(1e-9) - 1.0).clamp(0.0, 1.0);
            if w > 0.0 {
                z += w * self.noise.octave(i, x, y);
                let a = self.noise.amplitude(i);
                kept += w * w * a * a * kind_variance;
            }
        }
        if kept <= 0.0 {
            return 1.0;
        }
        let r = self.gain * smoothstep(self.threshold - GUST_EDGE, self.threshold + GUST_EDGE, z / kept.sqrt());
        let resolved = kept / (self.std * self.std);
        resolved * r * r + (1.0 - resolved)
    }
}

/// What makes one lake differ from another.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LakeParams {
    /// Wind speed at 10 m, m/s (0 is a mirror calm).
    pub wind_m_s: f64,
    /// Seed of the noise.
    pub seed: u64,
    /// Noise octaves, 1..=12.
    pub octaves: u32,
    /// Amplitude ratio between successive octaves.
    pub persistence: f64,
    /// Value or gradient lattice noise.
    pub noise: NoiseKind,
}

impl LakeParams {
    /// The strongest wind the lake takes, m/s (a storm; beyond it a lake is all spray).
    pub const MAX_WIND_M_S: f64 = crate::sim::wind::MAX_LAKE_WIND_M_S;

    /// The significant wave height (4 standard deviations of the surface) this wind raises, m.
    pub fn significant_height_m(&self) -> f64 {
        Lake::new(*self).significant_height_m()
    }
}

impl Default for LakeParams {
    /// A light breeze (3 m/s), five octaves of value noise at persistence 0.5.
    fn default() -> Self {
        LakeParams { wind_m_s: 3.0, seed: 1, octaves: 5, persistence: 0.5, noise: NoiseKind::Value }
    }
}

/// Parses an octave count, `1..=12`.
pub fn parse_octaves(text: &str) -> Result<u32, ValueError> {
    let v: i64 = text.trim().parse().map_err(|_| {
        ValueError::new("octaves", format!("the octave count '{}' is not a whole number; e.g. 5", text.trim()))
    })?;
    check_octaves(v)
}

/// Checks an octave count.
pub fn check_octaves(v: i64) -> Result<u32, ValueError> {
    if !(1..=MAX_OCTAVES as i64).contains(&v) {
        return Err(ValueError::new(
            "octaves",
            format!("the octave count {v} is outside 1..={MAX_OCTAVES}; 5 is the default"),
        ));
    }
    Ok(v as u32)
}

/// Parses a persistence, `0..=1`.
pub fn parse_persistence(text: &str) -> Result<f64, ValueError> {
    check_persistence(crate::numbers::finite(text, "persistence", "0.5")?)
}

/// Checks a persistence.
pub fn check_persistence(v: f64) -> Result<f64, ValueError> {
    if !(0.0..=1.0).contains(&v) {
        return Err(ValueError::new(
            "persistence",
            format!("the persistence {v} is outside 0..=1; 0.5 halves each octave (the default), higher is rougher"),
        ));
    }
    Ok(v)
}

/// The mean square slope (both axes together) of the lake's surface under `u` m/s of wind:
/// Cox–Munk's clean-surface `0.00512·U`, faded in as (U / [`RIPPLE_ONSET_M_S`])² below the
/// onset, 0 in calm air.
pub fn slope_variance(u: f64) -> f64 {
    let u = u.max(0.0);
    0.00512 * u * (u / RIPPLE_ONSET_M_S).powi(2).min(1.0)
}

/// The peak wavelength (m) of a wind `u` m/s over `fetch_m` metres (fetch-limited JONSWAP),
/// capped at the fully developed sea's; a 1 m/s wind's for calmer air.
pub fn peak_wavelength_m(u: f64, fetch_m: f64) -> f64 {
    let u = u.max(1.0);
    let fp = 3.5 * (GRAVITY / u) * (GRAVITY * fetch_m / (u * u)).powf(-0.33);
    let fp = fp.max(0.13 * GRAVITY / u); // Pierson–Moskowitz's peak, fully developed
    GRAVITY / (2.0 * std::f64::consts::PI * fp * fp)
}

/// A lake: its parameters and the animated noise they give.
#[derive(Clone, Debug, PartialEq)]
pub struct Lake {
    params: LakeParams,
    water: WaterNoise,
    gusts: Gusts,
    hs_m: f64,
    peak_wavelength_m: f64,
    /// Metres per unit of the noise sum.
    scale_m: f32,
}

impl Lake {
    /// The lake `params` describe (octaves clamped to 1..=[`MAX_OCTAVES`], wind and
    /// persistence to >= 0).
    pub fn new(params: LakeParams) -> Lake {
        let wind = params.wind_m_s.max(0.0);
        let peak = peak_wavelength_m(wind, f64::from(FAR_SHORE_M));
        let fractal = Fractal {
            kind: params.noise,
            seed: params.seed,
            octaves: params.octaves.clamp(1, MAX_OCTAVES as u32),
            persistence: params.persistence.max(0.0) as f32,
        };
        let water = WaterNoise {
            fractal,
            spacing_m: (peak / 2.0) as f32,
            speed_m_s: (GRAVITY * peak / (2.0 * std::f64::consts::PI)).sqrt() as f32,
            heading_rad: -PI / 2.0,
            spread_rad: DRIFT_SPREAD_RAD,
        };
        // Slope variance per axis of the sum per unit of scale²: Σ (pⁱ)²·S·(2ⁱ/spacing)².
        let per_unit: f64 = (0..fractal.octave_count())
            .map(|i| {
                let k = f64::from(1u32 << i) / f64::from(water.spacing_m);
                f64::from(fractal.persistence).powi(2 * i as i32) * f64::from(fractal.kind.slope_variance()) * k * k
            })
            .sum();
        let target = slope_variance(wind) / 2.0;
        let scale = if per_unit > 0.0 { (target / per_unit).sqrt() } else { 0.0 };
        let hs_m = 4.0 * scale * f64::from(fractal.variance()).sqrt();
        Lake {
            params,
            water,
            gusts: Gusts::new(params.seed, wind),
            hs_m,
            peak_wavelength_m: peak,
            scale_m: scale as f32,
        }
    }

    /// The parameters.
    pub fn params(&self) -> LakeParams {
        self.params
    }

    /// Significant wave height, m.
    pub fn significant_height_m(&self) -> f64 {
        self.hs_m
    }

    #[cfg(test)]
    /// The animated noise.
    pub fn water(&self) -> &WaterNoise {
        &self.water
    }

    /// The water at `time_s` seconds.
    pub fn surface(&self, time_s: f64) -> LakeSurface {
        let noise = self.water.at(time_s);
        let kind = self.water.fractal.kind;
        let mut slope_variance = [0.0f32; MAX_OCTAVES];
        for (i, v) in slope_variance.iter_mut().enumerate().take(noise.octave_count()) {
            let a = self.scale_m * noise.amplitude(i);
            let k = 1.0 / noise.spacing_m(i);
            *v = a * a * kind.slope_variance() * k * k;
        }
        let g = &self.gusts;
        let f = g.noise.fractal;
        let gusts = GustFrame {
            noise: g.noise.at(time_s),
            std: g.std,
            total_weight: f.variance() / f.kind.variance(),
            threshold: g.threshold,
            gain: g.gain,
        };
        LakeSurface { noise, gusts, scale_m: self.scale_m, rms_m: (self.hs_m / 4.0) as f32, slope_variance }
    }
}

/// The lake's surface at one moment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LakeSurface {
    noise: NoiseSurface,
    gusts: GustFrame,
    scale_m: f32,
    rms_m: f32,
    /// Per octave: the slope variance (per axis, m/m squared) it adds.
    slope_variance: [f32; MAX_OCTAVES],
}

impl LakeSurface {
    /// The full surface height at (east, north) metres, m.
    pub fn height(&self, x_m: f32, y_m: f32) -> f32 {
        if self.scale_m == 0.0 {
            return 0.0;
        }
        let rough = self.roughness(x_m, y_m);
        if rough == 0.0 {
            return 0.0;
        }
        rough * self.scale_m * self.noise.sample(x_m, y_m)
    }

    /// How rough the water is at (east, north) metres, relative to the lake's mean (the gust
    /// patches): 0 where it is glassy; the mean of its square over the lake is 1.
    pub fn roughness(&self, x_m: f32, y_m: f32) -> f32 {
        self.gusts.roughness_squared(x_m, y_m, 0.0).sqrt()
    }

    /// The root mean square height, m (Hs / 4).
    pub fn rms_height_m(&self) -> f32 {
        self.rms_m
    }

    #[cfg(test)]
    /// The slope variance per axis of all octaves together.
    pub fn slope_variance(&self) -> f32 {
        self.slope_variance.iter().sum()
    }

    /// How much of octave `i` a sample standing for `footprint_m` metres keeps: all of it when
    /// the lattice is at least twice the footprint, none at or below the footprint.
    pub fn octave_weight(&self, i: usize, footprint_m: f32) -> f32 {
        (self.noise.spacing_m(i) / footprint_m.max(1e-9) - 1.0).clamp(0.0, 1.0)
    }
}

impl Surface for LakeSurface {
    fn sample(&self, x: f32, y: f32, footprint: &Footprint) -> SurfaceSample {
        if self.scale_m == 0.0 {
            return SurfaceSample::default();
        }
        // Seen at a grazing angle a sample stands for a short step across the view and a long
        // one along it. An octave the short step resolves is kept: neighbouring samples across
        // the view carry its slopes, and along the view it only jitters the faces' tilt,
        // which reads as the short horizontal streaks of a real rippled reflection. What the
        // long step cannot carry tilts the reflection up and down the picture: that slope
        // variance is reported as unresolved, for the renderer to blur.
        let across = (footprint.across[0].powi(2) + footprint.across[1].powi(2)).sqrt();
        let along = (footprint.along[0].powi(2) + footprint.along[1].powi(2)).sqrt();
        let rough2 = self.gusts.roughness_squared(x, y, along.max(across));
        if rough2 == 0.0 {
            return SurfaceSample::default();
        }
        let rough = rough2.sqrt();
        let (mut height, mut unresolved) = (0.0, 0.0);
        for i in 0..self.noise.octave_count() {
            let w = self.octave_weight(i, across);
            if w > 0.0 {
                height += w * self.noise.octave(i, x, y);
            }
            let w_along = self.octave_weight(i, along);
            unresolved += (1.0 - w_along * w_along) * self.slope_variance[i];
        }
        SurfaceSample {
            height_m: rough * self.scale_m * height,
            foam: 0.0,
            unresolved_slope_variance: rough2 * unresolved,
            ..SurfaceSample::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octaves_and_persistence_are_checked() {
        assert_eq!(parse_octaves("1"), Ok(1));
        assert_eq!(parse_octaves("12"), Ok(12));
        for bad in ["0", "13", "-2", "2.5", "x"] {
            assert!(parse_octaves(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_persistence("0"), Ok(0.0));
        assert_eq!(parse_persistence("1"), Ok(1.0));
        for bad in ["-0.1", "1.01", "NaN", "half"] {
            assert!(parse_persistence(bad).is_err(), "{bad}");
        }
        assert!(parse_persistence("2").unwrap_err().to_string().contains("rougher"));
    }

    #[test]
    fn the_wind_sets_slopes_and_wavelength() {
        let f = f64::from(FAR_SHORE_M);
        assert_eq!(slope_variance(0.0), 0.0);
        assert!((slope_variance(5.0) - 0.0256).abs() < 1e-9);
        assert!(slope_variance(1.0) < 0.3 * 0.00512, "cat's paws below the onset");
        let l5 = peak_wavelength_m(5.0, f);
        assert!((l5 - 0.77).abs() < 0.05, "peak wavelength at 5 m/s: {l5}");
        assert!(peak_wavelength_m(10.0, f) > l5);
        // Fetch-limited: a longer fetch grows longer waves, up to the fully developed sea's.
        assert!(peak_wavelength_m(10.0, 1e4) > peak_wavelength_m(10.0, f));
        let developed = GRAVITY / (2.0 * std::f64::consts::PI * (0.13 * GRAVITY / 10.0f64).powi(2));
        assert!(peak_wavelength_m(10.0, 1e9) <= developed + 1e-9);
        // Heights of a few centimetres at 5 m/s, more in stronger wind.
        let hs = |u| Lake::new(LakeParams { wind_m_s: u, ..LakeParams::default() }).significant_height_m();
        assert!((0.02..0.15).contains(&hs(5.0)), "Hs at 5 m/s: {}", hs(5.0));
        assert!(hs(10.0) > 1.5 * hs(5.0));
    }

    #[test]
    fn gusts_roughen_part_of_a_light_breeze_and_all_of_a_strong_wind() {
        assert!((rough_fraction(0.0) - MIN_COVER).abs() < 1e-12);
        assert_eq!(rough_fraction(FULL_COVER_M_S), 1.0);
        for wind in [1.0, 2.5] {
            let frame = Lake::new(LakeParams { wind_m_s: wind, ..LakeParams::default() }).surface(3.0);
            let (mut rough, mut square, n) = (0, 0.0f64, 20_000);
            for i in 0..n {
                let (x, y) = ((i % 200) as f32 * 7.3 - 700.0, (i / 200) as f32 * 6.1);
                let r = frame.roughness(x, y);
                rough += usize::from(r > 0.5 * frame.gusts.gain);
                square += f64::from(r * r);
            }
            let fraction = rough as f64 / f64::from(n);
            assert!((fraction - rough_fraction(wind)).abs() < 0.12, "{wind} m/s: {fraction} rough");
            assert!((square / f64::from(n) - 1.0).abs() < 0.25, "{wind} m/s: mean square {}", square / f64::from(n));
            // Glassy patches are exactly flat.
            let glassy = (0..n).map(|i| ((i % 200) as f32 * 7.3 - 700.0, (i / 200) as f32 * 6.1));
            let (x, y) = glassy.clone().find(|&(x, y)| frame.roughness(x, y) == 0.0).unwrap();
            assert_eq!(frame.height(x, y), 0.0);
            // Seen from far away, where patches are thinner than a sample, every point is
            // evenly rough on average; a middling footprint keeps only the coarse patches.
            assert_eq!(frame.gusts.roughness_squared(x, y, 1e4), 1.0);
            let mid = frame.gusts.roughness_squared(x, y, 10.0);
            assert!(mid > 0.0 && mid < 1.0, "{mid}");
        }
        let strong = Lake::new(LakeParams { wind_m_s: 8.0, ..LakeParams::default() }).surface(0.0);
        assert_eq!(strong.roughness(12.0, 40.0), 1.0);
    }

    #[test]
    fn calm_water_is_flat() {
        let lake = Lake::new(LakeParams { wind_m_s: 0.0, ..LakeParams::default() });
        let frame = lake.surface(5.0);
        assert_eq!(frame.height(3.0, 40.0), 0.0);
        assert_eq!(frame.sample(3.0, 40.0, &Footprint::isotropic(0.0)), SurfaceSample::default());
        assert_eq!(frame.slope_variance(), 0.0);
    }

    #[test]
    fn heights_and_slopes_follow_the_wind_whatever_the_noise() {
        for noise in [NoiseKind::Value, NoiseKind::Gradient] {
            for (octaves, persistence) in [(5, 0.5), (2, 0.8)] {
                let lake = Lake::new(LakeParams { wind_m_s: 6.0, octaves, persistence, noise, seed: 4 });
                let frame = lake.surface(1.0);
                let (mut h2, mut s2) = (0.0f64, 0.0f64);
                let n = 4000;
                let d = 1e-3;
                for i in 0..n {
                    let (x, y) = ((i % 64) as f32 * 0.37, (i / 64) as f32 * 0.41);
                    let h = frame.height(x, y);
                    h2 += f64::from(h).powi(2);
                    s2 += f64::from((frame.height(x + d, y) - h) / d).powi(2);
                }
                let rms = (h2 / f64::from(n)).sqrt();
                let want = lake.significant_height_m() / 4.0;
                assert!((rms / want - 1.0).abs() < 0.15, "{noise:?} {octaves} {persistence}: {rms} vs {want}");
                assert!((frame.rms_height_m() as f64 / want - 1.0).abs() < 1e-3);
                // The measured slope variance along x is half Cox and Munk's total.
                let slope = s2 / f64::from(n);
                let cm = slope_variance(6.0) / 2.0;
                assert!((slope / cm - 1.0).abs() < 0.2, "{noise:?} {octaves} {persistence}: {slope} vs {cm}");
                assert!((f64::from(frame.slope_variance()) / cm - 1.0).abs() < 1e-3);
            }
        }
    }

    #[test]
    fn footprints_drop_fine_octaves_into_unresolved_slope() {
        let lake = Lake::new(LakeParams { wind_m_s: 8.0, ..LakeParams::default() });
        let frame = lake.surface(2.0);
        let full = frame.sample(1.0, 20.0, &Footprint::isotropic(0.0));
        assert_eq!(full.height_m, frame.height(1.0, 20.0));
        assert!(full.unresolved_slope_variance < 1e-9);
        // A 100 m footprint keeps nothing: flat, with all the slope unresolved.
        let far = frame.sample(1.0, 20.0, &Footprint::isotropic(100.0));
        assert_eq!(far.height_m, 0.0);
        assert!((far.unresolved_slope_variance / frame.slope_variance() - 1.0).abs() < 1e-5);
        // In between, part of each.
        let mid = frame.sample(1.0, 20.0, &Footprint::isotropic(0.05));
        assert!(mid.unresolved_slope_variance > 0.0 && mid.unresolved_slope_variance < frame.slope_variance());
        // The wind's slopes are Cox and Munk's.
        assert!((2.0 * frame.slope_variance() - slope_variance(8.0) as f32).abs() < 1e-4);
    }

    #[test]
    fn the_water_moves_and_the_seed_matters() {
        let lake = Lake::new(LakeParams { wind_m_s: 7.0, ..LakeParams::default() });
        let (a, b) = (lake.surface(0.0), lake.surface(0.5));
        assert_ne!(a.height(2.0, 30.0), b.height(2.0, 30.0));
        assert_eq!(a.height(2.0, 30.0), lake.surface(0.0).height(2.0, 30.0));
        let other = Lake::new(LakeParams { seed: 2, ..lake.params() });
        assert_ne!(other.surface(0.0).height(2.0, 30.0), a.height(2.0, 30.0));
        assert!(lake.water().speed_m_s > 0.5 && lake.water().speed_m_s < 2.0);
        // Gust patches drift too: a light breeze's rough patches move downwind.
        let breeze = Lake::new(LakeParams { wind_m_s: 2.0, ..LakeParams::default() });
        let (a, b) = (breeze.surface(0.0), breeze.surface(10.0));
        let moved = (0..400).filter(|&i| {
            let (x, y) = ((i % 20) as f32 * 10.0, (i / 20) as f32 * 10.0);
            a.roughness(x, y) != b.roughness(x, y)
        });
        assert!(moved.count() > 40);
    }
}
