//! Unit tests of the sea (`sim/ocean.rs`): spectra carried into components, the dispersion
//! the waves really follow, lanes and footprints, loops, choppiness and the Eulerian height.

use super::*;
use crate::sim::dispersion;
use crate::sim::looping::LoopPeriod;
use crate::sim::ocean::surface::HEIGHT;
use crate::sim::spectra::{Depth, Jonswap};
use crate::sim::surface::SurfaceSample;

fn sea(wind: f64) -> Sea {
    Sea::new(SeaParams { wind_m_s: wind, wind_from_deg: 270.0, seed: 42, ..SeaParams::default() })
}

#[test]
fn amplitudes_carry_the_band_variance() {
    let tma = SpectrumChoice::Tma(Jonswap::default(), Depth::new(10.0).unwrap());
    for (wind, spectrum) in [
        (2.45, SpectrumChoice::PiersonMoskowitz),
        (10.0, SpectrumChoice::PiersonMoskowitz),
        (30.0, SpectrumChoice::PiersonMoskowitz),
        (10.0, SpectrumChoice::Jonswap(Jonswap::new(3.3, Some(30.0)).unwrap())),
        (10.0, tma),
    ] {
        let s = Sea::new(SeaParams { wind_m_s: wind, spectrum, ..SeaParams::default() });
        let fm = s.spectrum().peak_hz().unwrap();
        let sum: f64 = s.components().iter().map(|c| c.amplitude_m * c.amplitude_m / 2.0).sum();
        let band = s.spectrum().band_variance(BAND_LOW * fm, CUTOFF * fm);
        // JONSWAP's narrow peak is sampled by the bins' midpoints: allow 4 %.
        assert!((sum / band - 1.0).abs() < 0.04, "U = {wind} {spectrum:?}: {sum} vs {band}");
        let total = band + s.tail_variance() + s.spectrum().cumulative_variance(BAND_LOW * fm);
        assert!((total / s.spectrum().m0() - 1.0).abs() < 1e-9, "band + tail = m0");
    }
}

/// The phase of the one wave of `sea` at time `t`, measured from sampled heights: project the
/// heights along two wavelengths onto cos and sin of k·x (the tail is left out by a footprint
/// long across the wave, which does not touch the wave itself).
fn measured_phase(sea: &Sea, t: f64) -> f64 {
    let c = sea.components()[0];
    let (ux, uy) = (c.bearing_rad.sin(), c.bearing_rad.cos());
    let (kx, ky) = (c.wavenumber * ux, c.wavenumber * uy);
    let wavelength = 2.0 * PI / c.wavenumber;
    let fp = Footprint { across: [0.0, 0.0], along: [(uy * 1e5) as f32, (-ux * 1e5) as f32] };
    let frame = sea.surface(t);
    let (mut cs, mut sn) = (0.0f64, 0.0f64);
    let n = 256;
    for i in 0..n {
        let d = 2.0 * wavelength * i as f64 / n as f64;
        let (x, y) = (d * ux + 3.0, d * uy - 7.0);
        let h = f64::from(frame.sample(x as f32, y as f32, &fp).height_m);
        cs += h * (kx * x + ky * y).cos();
        sn += h * (kx * x + ky * y).sin();
    }
    (-sn).atan2(cs)
}

#[test]
fn waves_advance_by_the_dispersion_relation() {
    // One-component seas, deep and 4 m deep, plain and looping: between t and t + dt the
    // measured phase must move back by ω·dt with ω = √(g·k·tanh(k·h)), k the wave's own.
    let shallow = SpectrumChoice::Tma(Jonswap::default(), Depth::new(4.0).unwrap());
    let deep = SeaParams { wind_m_s: 10.0, wind_from_deg: 200.0, seed: 9, ..SeaParams::default() };
    let looping =
        LoopPeriod::new(120.0, SeaSpectrum::new(10.0, SpectrumChoice::PiersonMoskowitz).peak_period_s()).unwrap();
    for params in [deep, SeaParams { spectrum: shallow, ..deep }, SeaParams { loop_period: Some(looping), ..deep }] {
        let sea = Sea::with_bins(params, 1, 1);
        assert_eq!(sea.components().len(), 1);
        let k = sea.components()[0].wavenumber;
        let omega = dispersion::angular_frequency(k, params.spectrum.depth_m());
        if params.spectrum.depth_m().is_none() {
            assert!((omega - (G * k).sqrt()).abs() < 1e-12);
        }
        for (t, dt) in [(0.0, 0.4), (13.0, 0.7), (250.0, 1.1)] {
            let moved = (measured_phase(&sea, t) - measured_phase(&sea, t + dt)).rem_euclid(2.0 * PI);
            assert!((moved / (omega * dt) - 1.0).abs() < 2e-3, "{params:?} t = {t}: {moved} vs {}", omega * dt);
        }
    }
}

#[test]
fn the_surface_variance_is_m0() {
    let s = sea(10.0);
    let m0 = s.spectrum().m0();
    let (mut sum, mut n) = (0.0f64, 0usize);
    for t in 0..20 {
        let frame = s.surface(t as f64 * 7.3);
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
    let energy = |from: f64, axis: fn(f64) -> f64| {
        let s = Sea::new(SeaParams { wind_m_s: 10.0, wind_from_deg: from, seed: 1, ..SeaParams::default() });
        s.components().iter().map(|c| c.amplitude_m.powi(2) * axis(c.bearing_rad)).sum::<f64>()
    };
    assert!(energy(270.0, f64::sin) > 0.0, "a west wind drives waves east");
    assert!(energy(180.0, f64::cos) > 0.0, "a south wind drives waves north");
}

#[test]
fn calm_is_flat() {
    let s = sea(0.0);
    assert!(s.components().is_empty() && s.tail_field().is_none() && s.padded_len() == 0);
    let f = s.surface(12.0);
    assert_eq!(
        f.sample(3.0, 4.0, &Footprint::isotropic(1.0)),
        SurfaceSample { unresolved_slope_variance: 0.0015, ..SurfaceSample::default() }
    );
    assert_eq!(f.jacobian(1.0, 2.0, &Footprint::default()), 1.0);
}

#[test]
fn footprints_filter_short_waves_and_report_their_slope() {
    let s = sea(10.0);
    let f = s.surface(0.0);
    let near = f.sample(10.0, 20.0, &Footprint::default());
    let far = f.sample(10.0, 20.0, &Footprint::isotropic(200.0));
    assert!(far.unresolved_slope_variance > near.unresolved_slope_variance);
    let var = |fp: f32| {
        (0..400)
            .map(|i| f64::from(f.sample(i as f32 * 37.0, i as f32 * 11.0, &Footprint::isotropic(fp)).height_m).powi(2))
            .sum::<f64>()
            / 400.0
    };
    assert!(var(60.0) < var(0.0), "a 60 m footprint removes variance");
}

/// The height as a plain sum over the components a footprint keeps (the tail left out by a
/// footprint beyond its octaves), in f64: the reference for the lanes.
fn reference_height(sea: &Sea, t: f64, x: f64, y: f64, fp: &Footprint) -> f64 {
    let keep = 2.0 * f64::from(fp.min_m());
    sea.components()
        .iter()
        .filter(|c| 2.0 * PI / c.wavenumber > keep)
        .map(|c| {
            let (kx, ky) = (c.wavenumber * c.bearing_rad.sin(), c.wavenumber * c.bearing_rad.cos());
            let w = resolution_weight(fp.phase_step(kx as f32, ky as f32));
            f64::from(w) * c.amplitude_m * (kx * x + ky * y + c.phase_rad - c.omega * t).cos()
        })
        .sum()
}

#[test]
fn lanes_are_padded_by_construction_for_any_bin_count() {
    for (fb, db) in [(1, 1), (3, 5), (7, 3), (24, 16), (13, 11)] {
        let s = Sea::with_bins(SeaParams { wind_m_s: 9.0, ..SeaParams::default() }, fb, db);
        assert_eq!(s.padded_len(), s.components().len().next_multiple_of(LANES), "{fb}x{db}");
        let f = s.surface(3.5);
        // The lanes' sum (the tail is added after it) against a plain sum over exactly the
        // components longer than twice the footprint.
        for size in [0.0f32, 0.4, 3.0] {
            let fp = Footprint::isotropic(size);
            for (x, y) in [(0.0f32, 0.0f32), (31.0, -17.5), (-200.0, 90.0)] {
                let got = f64::from(f.sums::<HEIGHT>(x, y, &fp).h);
                let want = reference_height(&s, 3.5, f64::from(x), f64::from(y), &fp);
                let scale = s.spectrum().significant_height_m();
                assert!((got - want).abs() < 2e-4 * scale, "{fb}x{db} footprint {size}: {got} vs {want}");
            }
        }
    }
}

#[test]
fn a_looping_sea_repeats_bit_for_bit() {
    let base = SeaParams { wind_m_s: 12.0, choppiness: 1.0, seed: 3, ..SeaParams::default() };
    let period =
        LoopPeriod::new(100.0, SeaSpectrum::new(12.0, SpectrumChoice::PiersonMoskowitz).peak_period_s()).unwrap();
    let s = Sea::new(SeaParams { loop_period: Some(period), ..base });
    for c in s.components() {
        assert!(c.harmonic >= 1 && (c.frequency_hz * 100.0 - f64::from(c.harmonic)).abs() < 1e-9);
    }
    let (a, b, c) = (s.surface(0.0), s.surface(100.0), s.surface(37.0));
    let d = s.surface(137.0);
    for (x, y) in [(0.0f32, 0.0f32), (55.0, -310.0), (1234.5, 77.0)] {
        for fp in [Footprint::default(), Footprint::isotropic(7.0)] {
            assert_eq!(a.sample(x, y, &fp), b.sample(x, y, &fp));
            assert_eq!(c.sample(x, y, &fp), d.sample(x, y, &fp));
        }
    }
    assert_ne!(a.sample(5.0, 5.0, &Footprint::default()), c.sample(5.0, 5.0, &Footprint::default()));
    // The quantised frequencies stay within half a step of the plain sea's.
    let plain = Sea::new(base);
    for (q, p) in s.components().iter().zip(plain.components()) {
        assert!((q.frequency_hz - p.frequency_hz).abs() <= 0.5 / 100.0 + 1e-12);
    }
}

#[test]
fn the_eulerian_height_is_the_height_of_the_water_carried_there() {
    let s = Sea::new(SeaParams { wind_m_s: 14.0, choppiness: 1.0, ..SeaParams::default() });
    let f = s.surface(4.0);
    let full = Footprint::default();
    for (x, y) in [(3.0f32, 4.0f32), (-80.0, 41.0), (250.0, 250.0)] {
        // Find the resting point by brute force on the iteration's answer: it lands on (x, y).
        let mut at = (x, y);
        for _ in 0..EULER_ITERATIONS {
            let d = f.sample(at.0, at.1, &full).displacement_m;
            at = (x - d[0], y - d[1]);
        }
        let s0 = f.sample(at.0, at.1, &full);
        let landed = (at.0 + s0.displacement_m[0], at.1 + s0.displacement_m[1]);
        assert!((landed.0 - x).abs() < 0.02 && (landed.1 - y).abs() < 0.02, "{landed:?} vs ({x}, {y})");
        assert_eq!(f.height(x, y), s0.height_m);
    }
    let flat = Sea::new(SeaParams { wind_m_s: 14.0, choppiness: 0.0, ..SeaParams::default() });
    assert_eq!(flat.surface(4.0).sample(3.0, 4.0, &full).displacement_m, [0.0, 0.0]);
}

/// The skewness of Eulerian heights on a 128x128 grid over 48 peak wavelengths (about
/// 2,000 independent waves), at four times.
pub(crate) fn skewness(sea: &Sea) -> f64 {
    let span = 48.0 * sea.spectrum().peak_wavelength_m().unwrap() as f32;
    let mut h = Vec::new();
    for t in [0.0, 31.0, 67.0, 113.0] {
        let f = sea.surface(t);
        for i in 0..128 {
            for j in 0..128 {
                h.push(f64::from(f.height(span * (i as f32 + 0.37) / 128.0, span * (j as f32 + 0.61) / 128.0)));
            }
        }
    }
    let n = h.len() as f64;
    let mean = h.iter().sum::<f64>() / n;
    let m2 = h.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
    let m3 = h.iter().map(|v| (v - mean).powi(3)).sum::<f64>() / n;
    m3 / m2.powf(1.5)
}

#[test]
fn choppiness_sharpens_crests() {
    let b6 = SeaParams { wind_m_s: 12.3, ..SeaParams::default() };
    let (mut linear, mut choppy) = (0.0, 0.0);
    for seed in 1..=3 {
        linear += skewness(&Sea::new(SeaParams { seed, choppiness: 0.0, ..b6 })) / 3.0;
        choppy += skewness(&Sea::new(SeaParams { seed, choppiness: DEFAULT_CHOPPINESS, ..b6 })) / 3.0;
    }
    assert!(choppy >= 0.1, "skewness at Beaufort 6 with λ = 1: {choppy}");
    assert!(choppy - linear > 0.08, "{choppy} vs linear {linear}");
    assert!(
        SeaParams::check_choppiness(f64::NAN).is_err()
            && SeaParams::check_choppiness(-0.1).is_err()
            && SeaParams::check_choppiness(5.0).is_err()
    );
    assert_eq!(SeaParams::check_choppiness(1.5), Ok(1.5));
}

#[test]
fn same_seed_same_sea() {
    let (sa, sb) = (sea(9.0), sea(9.0));
    let (a, b) = (sa.surface(5.0), sb.surface(5.0));
    assert_eq!(a.sample(1.0, 2.0, &Footprint::isotropic(0.5)), b.sample(1.0, 2.0, &Footprint::isotropic(0.5)));
    let c = Sea::new(SeaParams { wind_m_s: 9.0, wind_from_deg: 270.0, seed: 43, ..SeaParams::default() });
    assert_ne!(a.height(1.0, 2.0), c.surface(5.0).height(1.0, 2.0));
}

#[test]
fn the_jacobian_sums_the_sines_that_fold_the_surface() {
    for wind in [6.7, 18.95] {
        let s = sea(wind);
        let slope = |c: &Component| 0.5 * (c.amplitude_m * c.wavenumber).powi(2);
        let total: f64 = s.components().iter().map(slope).sum();
        let kept: f64 = s.components().iter().map(slope).filter(|&v| v >= FOLD_NEGLIGIBLE * total).sum();
        println!("U {wind}: {} of {} sines, {:.3} of the slope", s.fold_len(), s.padded_len(), kept / total);
        assert!(kept / total > 0.95 && s.fold_len() < s.padded_len());
    }
}
