//! The spreading laws and the swell measured from what tidepool makes: the directional
//! spread of the periodic maps against each law's own moment, and a swell's peak, height and
//! travel from time series of the rendered sea's heights.

use std::f64::consts::PI;

use rustfft::FftPlannerScalar;
use rustfft::num_complex::Complex64;

use super::swell::{Swell, Swells};
use super::*;
use crate::sim::ocean::{Sea, SeaParams};
use crate::sim::patch::PatchSea;
use crate::sim::surface::Footprint;

/// The mean of |cos θ| under each law at r = f/fp, from the law's published form (written
/// again here, not read from the code under test), by the midpoint rule: a real map holds
/// each wave at k and -k, so it cannot tell a wave from one travelling the other way, and
/// the spread it shows is that of the angle folded into ±90°, whose mean resultant is
/// E|cos θ|.
fn mean_abs_cosine(law: Spreading, r: f64, wind: f64, fp: f64) -> f64 {
    let cos_2s = |s: f64| {
        let norm = (libm::lgamma(s + 1.0) - libm::lgamma(s + 0.5)).exp() / (2.0 * PI.sqrt());
        move |t: f64| norm * (t / 2.0).cos().abs().powf(2.0 * s)
    };
    let d: Box<dyn Fn(f64) -> f64> = match law {
        Spreading::Paper => Box::new(cos_2s(if r >= 1.0 { 9.77 * r.powf(-2.5) } else { 6.97 * r.powi(5) })),
        Spreading::Mitsuyasu => {
            let sp = 11.5 * (2.0 * PI * fp * wind / G).powf(-2.5);
            Box::new(cos_2s(if r <= 1.0 { sp * r.powi(5) } else { sp * r.powf(-2.5) }))
        }
        Spreading::Hasselmann => {
            let cp = G / (2.0 * PI * fp);
            let mu = -2.33 - 1.45 * (wind / cp - 1.17);
            Box::new(cos_2s(if r < 1.05 { 6.97 * r.powf(4.06) } else { 9.77 * r.powf(mu) }))
        }
        Spreading::DonelanBanner => {
            let r = r.max(0.56);
            let beta = if r < 0.95 {
                2.61 * r.powf(1.3)
            } else if r < 1.6 {
                2.28 * r.powf(-1.3)
            } else {
                10f64.powf(-0.4 + 0.8393 * (-0.567 * (r * r).ln()).exp())
            };
            Box::new(move |t: f64| beta / (2.0 * (beta * PI).tanh()) / (beta * t).cosh().powi(2))
        }
    };
    let n = 720;
    let dt = 2.0 * PI / n as f64;
    (0..n).map(|i| -PI + (i as f64 + 0.5) * dt).map(|t| d(t) * t.cos().abs() * dt).sum()
}

/// The 2-D FFT of a real n x n field, rows then columns (for power spectra: the sign of the
/// exponent does not matter).
pub(crate) fn fft2(values: &[f32], n: usize) -> Vec<Complex64> {
    let mut data: Vec<Complex64> = values.iter().map(|&v| Complex64::new(f64::from(v), 0.0)).collect();
    let fft = FftPlannerScalar::new().plan_fft_forward(n);
    for _ in 0..2 {
        for row in data.chunks_mut(n) {
            fft.process(row);
        }
        let copy = data.clone();
        for r in 0..n {
            for c in 0..n {
                data[c * n + r] = copy[r * n + c];
            }
        }
    }
    data
}

/// Each spreading law, measured from the periodic maps of a linear sea (so the heights are
/// the spectrum's waves and nothing else): the circular spread 2·(1 - |⟨e^(iθ)⟩|) of the
/// maps' energy, θ from downwind folded into ±90°, against the law's own
/// 2·∫E(f)·(1 - E|cos θ|(f))·df/m0 over the band the lattice carries in every direction.
/// Within 10 %; the laws differ from each other by more.
#[test]
fn each_spreading_law_is_the_spread_of_the_maps() {
    let (n, wind) = (256, 12.0);
    println!("law            | spread of the maps | the law's | error");
    let mut spreads = Vec::new();
    for law in [Spreading::Paper, Spreading::Mitsuyasu, Spreading::Hasselmann, Spreading::DonelanBanner] {
        let params =
            SeaParams { wind_m_s: wind, wind_from_deg: 250.0, spreading: law, choppiness: 0.0, ..SeaParams::default() };
        let spectrum = params.wind_spectrum();
        let fp = spectrum.peak_hz().unwrap();
        let extent = 20.0 * spectrum.peak_wavelength_m().unwrap();
        let maps = PatchSea::new(params, n, extent).unwrap().surface(0.0);
        let data = fft2(&maps.height, n);
        let downwind = (250.0f64 + 180.0).to_radians();
        let signed = |i: usize| if i < n / 2 { i as f64 } else { i as f64 - n as f64 };
        let (mut sum, mut resultant) = (0.0, Complex64::new(0.0, 0.0));
        for r in 0..n {
            for c in 0..n {
                // Row r holds the wavenumber of going south, column c east (as the maps).
                let (kx, ky) = (signed(c), -signed(r));
                // Inside the circle the lattice carries in every direction (its corners hold
                // only diagonal waves).
                if (kx == 0.0 && ky == 0.0) || kx.hypot(ky) >= (n / 2 - 1) as f64 {
                    continue;
                }
                // A real map holds each wave at k and -k: keep the half facing downwind.
                let theta = kx.atan2(ky) - downwind;
                let e = data[r * n + c].norm_sqr();
                if theta.cos() < 0.0 {
                    continue;
                }
                sum += e;
                resultant += Complex64::from_polar(e, theta);
            }
        }
        let measured = 2.0 * (1.0 - resultant.norm() / sum);
        // The law's: over the frequencies the lattice holds.
        let k_of = |m: f64| 2.0 * PI * m / extent;
        let (f_lo, f_hi) = ((G * k_of(1.0)).sqrt() / (2.0 * PI), (G * k_of((n / 2 - 1) as f64)).sqrt() / (2.0 * PI));
        let steps = 4_000;
        let df = (f_hi - f_lo) / steps as f64;
        let (mut e_sum, mut spread_sum) = (0.0, 0.0);
        for i in 0..steps {
            let f = f_lo + (i as f64 + 0.5) * df;
            let e = spectrum.energy(f) * df;
            e_sum += e;
            spread_sum += e * (1.0 - mean_abs_cosine(law, f / fp, wind, fp));
        }
        let theory = 2.0 * spread_sum / e_sum;
        println!("{:14} | {measured:18.4} | {theory:9.4} | {:+5.1} %", law.name(), 100.0 * (measured / theory - 1.0));
        assert!((measured / theory - 1.0).abs() < 0.10, "{}: the maps spread {measured}, the law {theory}", law.name());
        spreads.push(theory);
    }
    // The laws are told apart: no two within 10 % of each other.
    for (i, a) in spreads.iter().enumerate() {
        for b in &spreads[i + 1..] {
            assert!((a / b - 1.0).abs() > 0.1, "{spreads:?}");
        }
    }
}

/// The heights of `sea` at `points` every `dt` seconds, `count` of them, from t = 100 s.
fn series(sea: &Sea, points: &[[f32; 2]], dt: f64, count: usize) -> Vec<Vec<f64>> {
    let mut out = vec![Vec::with_capacity(count); points.len()];
    let full = Footprint::default();
    for k in 0..count {
        let frame = sea.surface(100.0 + k as f64 * dt);
        for (p, s) in points.iter().zip(out.iter_mut()) {
            s.push(f64::from(frame.sample(p[0], p[1], &full).height_m));
        }
    }
    out
}

/// The Fourier transform of a series (Hann-windowed).
fn spectrum_of(s: &[f64]) -> Vec<Complex64> {
    let n = s.len();
    let mut data: Vec<Complex64> = s
        .iter()
        .enumerate()
        .map(|(i, v)| Complex64::new(v * (0.5 - 0.5 * (2.0 * PI * i as f64 / n as f64).cos()), 0.0))
        .collect();
    FftPlannerScalar::new().plan_fft_forward(n).process(&mut data);
    data
}

/// A wind sea of Beaufort 4 with a 1.5 m, 12 s swell from 250°, from the rendered sea's own
/// heights (a linear sea: the swell and the sea, nothing else): the frequency spectrum's
/// second peak is at 1/12 Hz within 5 %, Hs is √(Hs_sea² + 1.5²) within 5 %, and the phase
/// of the swell band advances along the swell's travel (east-north-east) at its wavelength.
#[test]
fn a_swell_peaks_at_its_period_adds_its_height_and_travels_its_way() {
    let swell = Swell::new(1.5, 12.0, 250.0).unwrap();
    let params = SeaParams {
        wind_m_s: 6.7,
        wind_from_deg: 330.0,
        swells: Swells::new(&[swell]).unwrap(),
        choppiness: 0.0,
        seed: 3,
        ..SeaParams::default()
    };
    let (dt, count) = (0.5, 2048);
    // Sixteen places a kilometre apart, each with a neighbour 25 m along the swell's travel
    // and one 25 m across it; four seas of other seeds (the same spectrum, other phases and
    // jitter), so the measured spectrum is the spectrum's and not one draw's.
    let travel = (250.0f64 + 180.0).to_radians();
    let (along, across) = ([travel.sin() as f32, travel.cos() as f32], [travel.cos() as f32, -travel.sin() as f32]);
    let d = 25.0f32;
    let mut points = Vec::new();
    for i in 0..16 {
        let p = [1000.0 * (i % 4) as f32, 1000.0 * (i / 4) as f32];
        points.push(p);
        points.push([p[0] + d * along[0], p[1] + d * along[1]]);
        points.push([p[0] + d * across[0], p[1] + d * across[1]]);
    }
    let heights: Vec<Vec<f64>> =
        (1..=4).flat_map(|seed| series(&Sea::new(SeaParams { seed, ..params }), &points, dt, count)).collect();
    let places = heights.len() / 3;
    // Hs from every place.
    let values: Vec<f64> = heights.iter().step_by(3).flatten().copied().collect();
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    let hs = 4.0 * (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64).sqrt();
    let want = params.wind_spectrum().significant_height_m().hypot(1.5);
    println!("Hs of sea and swell {hs:.3} m, sqrt(Hs_sea² + Hs_swell²) {want:.3} m");
    assert!((hs / want - 1.0).abs() < 0.05, "Hs {hs} vs {want}");
    // The frequency spectrum, averaged over the places and smoothed over nine bins (0.009 Hz).
    let spectra: Vec<Vec<Complex64>> = heights.iter().map(|s| spectrum_of(s)).collect();
    let power: Vec<f64> = (0..count / 2).map(|k| spectra.iter().step_by(3).map(|s| s[k].norm_sqr()).sum()).collect();
    let smooth: Vec<f64> =
        (0..power.len()).map(|k| power[k.saturating_sub(4)..(k + 5).min(power.len())].iter().sum()).collect();
    let df = 1.0 / (dt * count as f64);
    // The highest peak, and the highest 30 % or more away from it in frequency.
    let first = (1..smooth.len()).max_by(|a, b| smooth[*a].total_cmp(&smooth[*b])).unwrap();
    let apart = |k: usize| (k as f64 / first as f64 - 1.0).abs() > 0.3;
    let second = (1..smooth.len()).filter(|&k| apart(k)).max_by(|a, b| smooth[*a].total_cmp(&smooth[*b])).unwrap();
    let is_peak = |k: usize| (1..=3).all(|j| smooth[k] >= smooth[k - j] && smooth[k] >= smooth[k + j]);
    assert!(is_peak(second), "a second peak, not the shoulder of the first");
    let top = [first as f64 * df, second as f64 * df];
    let wind_fp = params.wind_spectrum().peak_hz().unwrap();
    println!(
        "spectral peaks at {:.4} and {:.4} Hz; swell 1/12 = {:.4} Hz, wind sea {wind_fp:.4} Hz",
        top[0],
        top[1],
        1.0 / 12.0
    );
    let swell_peak = top.iter().copied().fold(f64::INFINITY, f64::min);
    assert!((top[0].max(top[1]) / wind_fp - 1.0).abs() < 0.15, "the other peak is the wind sea's: {top:?}");
    assert!((swell_peak * 12.0 - 1.0).abs() < 0.05, "the swell's peak at {swell_peak} Hz");
    // The swell band's phase from each place to its neighbours: ω·d/c = 2π·d/λ along its
    // travel, nothing across it.
    let k_swell = (2.0 * PI / 12.0).powi(2) / G;
    let (lo, hi) = ((0.8 / 12.0 / df) as usize, (1.25 / 12.0 / df) as usize);
    let phase = |a: usize, b: usize| {
        let mut c = Complex64::new(0.0, 0.0);
        for place in 0..places {
            for (x, y) in spectra[3 * place + a][lo..=hi].iter().zip(&spectra[3 * place + b][lo..=hi]) {
                c += x * y.conj();
            }
        }
        c.arg()
    };
    let (ahead, aside) = (phase(0, 1), phase(0, 2));
    let expected = k_swell * f64::from(d);
    let heading = aside.atan2(ahead).to_degrees();
    println!(
        "swell phase {ahead:.3} rad along its travel (wavelength: {expected:.3}), {aside:.3} across; heading {heading:+.1}°"
    );
    assert!((ahead / expected - 1.0).abs() < 0.3, "along: {ahead} rad vs {expected}");
    assert!(heading.abs() < 15.0, "the swell travels {heading:+.1}° off its direction");
}
