//! The sea's physics measured from what tidepool exports (the periodic maps, the sea's frames
//! and pictures): Hs and the spectral peak of each spectrum from the periodic height maps,
//! shallow water shortening the waves, skewness and foam cover per Beaufort number, maps that tile without a
//! seam, and loops that close without a jump. Run with `--nocapture` for the tables:
//! `cargo test --release --lib ocean_physics -- --nocapture`.

use tiny_skia::Pixmap;

use crate::render::ocean::{OceanRenderer, OceanView};
use crate::render::texture::SeaTexture;
use crate::sim::foam::{FoamModel, FoamTracker};
use crate::sim::looping::LoopPeriod;
use crate::sim::ocean::{DEFAULT_CHOPPINESS, Sea, SeaParams};
use crate::sim::patch::{PatchMaps, PatchSea};
use crate::sim::sea_state::beaufort_speed_m_s;
use crate::sim::spectra::{Depth, Jonswap, SeaSpectrum, SpectrumChoice};
use crate::sim::surface::Footprint;

const SEEDS: u64 = 6;
/// Patch side in peak wavelengths: the wavenumber bins are 1/20 of the peak's (finer than
/// the 10 % tolerance).
const SPAN_WAVELENGTHS: f64 = 20.0;
const N: usize = 256;

fn spectra() -> [(&'static str, SpectrumChoice); 3] {
    [
        ("pm", SpectrumChoice::PiersonMoskowitz),
        ("jonswap 100 km", SpectrumChoice::Jonswap(Jonswap::new(3.3, Some(100.0)).unwrap())),
        ("tma 100 km, 8 m", SpectrumChoice::Tma(Jonswap::new(3.3, Some(100.0)).unwrap(), Depth::new(8.0).unwrap())),
    ]
}

fn maps(params: SeaParams, size: usize, extent_m: f64, t: f64) -> PatchMaps {
    PatchSea::new(params, size, extent_m).unwrap().maps(t)
}

fn surface(params: SeaParams, size: usize, extent_m: f64, t: f64) -> PatchMaps {
    PatchSea::new(params, size, extent_m).unwrap().surface(t)
}

/// Adds E(k) of a height map `extent_m` across into `bins` of width `dk` rad/m: each
/// Fourier mode's |FFT|² goes to the two bins around its exact |k|, linearly.
fn deposit_spectrum(m: &PatchMaps, extent_m: f64, dk: f64, bins: &mut [f64]) {
    let n = m.size;
    let data = crate::sim::spectra::measured::fft2(&m.height, n);
    let lattice = 2.0 * std::f64::consts::PI / extent_m;
    let signed = |i: usize| if i < n / 2 { i as f64 } else { i as f64 - n as f64 };
    for r in 0..n {
        for c in 0..n {
            let k = lattice * signed(r).hypot(signed(c));
            let pos = k / dk;
            let (i, t) = (pos.floor() as usize, pos - pos.floor());
            let e = data[r * n + c].norm_sqr() / ((n * n) as f64).powi(2);
            if i + 1 < bins.len() {
                bins[i] += e * (1.0 - t);
                bins[i + 1] += e * t;
            }
        }
    }
}

/// The peak of binned E(k): a least-squares parabola through the largest bin and two
/// neighbours on each side.
fn peak_bin(bins: &[f64]) -> f64 {
    let i = (2..bins.len() - 2).max_by(|&a, &b| bins[a].total_cmp(&bins[b])).unwrap();
    // Fit y = a + b·x + c·x² over x = -2..=2 (centred at i): closed-form normal equations.
    let ys: Vec<f64> = (0..5).map(|j| bins[i + j - 2]).collect();
    let xs = [-2.0, -1.0, 0.0, 1.0, 2.0];
    let sy: f64 = ys.iter().sum();
    let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| x * y).sum();
    let sx2y: f64 = xs.iter().zip(&ys).map(|(x, y)| x * x * y).sum();
    // Σx = Σx³ = 0, Σx² = 10, Σx⁴ = 34, n = 5.
    let b = sxy / 10.0;
    let c = (5.0 * sx2y - 10.0 * sy) / (5.0 * 34.0 - 100.0);
    if c >= 0.0 { i as f64 } else { i as f64 - b / (2.0 * c) }
}

#[test]
fn hs_and_the_peak_match_each_spectrum() {
    println!("spectrum          | Hs theory | Hs maps | error | k-peak E(k) | k-peak maps | error");
    let mut measured_peaks = Vec::new();
    for (name, spectrum) in spectra() {
        let params = SeaParams { wind_m_s: 10.0, spectrum, choppiness: DEFAULT_CHOPPINESS, ..SeaParams::default() };
        let theory = SeaSpectrum::new(10.0, spectrum);
        // Patches of slightly different sizes: the lattice's rings hold a ragged number of
        // modes (more or fewer in the narrow downwind sector), which one lattice cannot
        // average away; several lattices can. Bins are a 20th of the peak wavenumber.
        let base = SPAN_WAVELENGTHS * theory.peak_wavelength_m().unwrap();
        let dk = 2.0 * std::f64::consts::PI / base;
        let (mut var, mut bins) = (0.0, vec![0.0; N]);
        for seed in 1..=SEEDS {
            let extent = base * (1.0 + 0.07 * seed as f64);
            let m = surface(SeaParams { seed, ..params }, N, extent, 7.0 * seed as f64);
            let mean = m.height.iter().map(|&h| f64::from(h)).sum::<f64>() / (N * N) as f64;
            var += m.height.iter().map(|&h| (f64::from(h) - mean).powi(2)).sum::<f64>() / (N * N) as f64;
            deposit_spectrum(&m, extent, dk, &mut bins);
        }
        let hs = 4.0 * (var / SEEDS as f64).sqrt();
        let hs_theory = theory.significant_height_m();
        let k_peak = peak_bin(&bins) * dk;
        let k_theory = theory.wavenumber_peak().unwrap();
        let k_fp = theory.wavenumber(theory.peak_hz().unwrap());
        println!(
            "{name:17} | {hs_theory:7.3} m | {hs:5.3} m | {:+5.1} % | {k_theory:.4} (k(fp) {k_fp:.4}) | {k_peak:.4} | {:+5.1} %",
            100.0 * (hs / hs_theory - 1.0),
            100.0 * (k_peak / k_theory - 1.0)
        );
        assert!((hs / hs_theory - 1.0).abs() < 0.05, "{name}: Hs {hs} vs {hs_theory}");
        assert!((k_peak / k_theory - 1.0).abs() < 0.10, "{name}: peak {k_peak} vs {k_theory}");
        if theory.depth_m().is_none() {
            assert!(k_theory < k_fp, "in deep water the peak of E(k) lies below the k of fp");
        }
        measured_peaks.push((theory, k_peak));
    }
    // Shallow water shortens the waves as tanh predicts: the same frequency's wavenumber
    // rises by 1/tanh(k·h), and so does the measured peak (JONSWAP vs TMA, same fetch).
    let (deep, k_deep) = &measured_peaks[1];
    let (shallow, k_shallow) = &measured_peaks[2];
    let fp = deep.peak_hz().unwrap();
    let k_h = shallow.wavenumber(fp);
    let predicted = 1.0 / (k_h * 8.0).tanh();
    let ratio = k_shallow / k_deep;
    println!("shallow/deep peak wavenumber: measured {ratio:.3}, 1/tanh(k·h) at fp {predicted:.3}");
    assert!(ratio > 1.05 && (ratio / predicted - 1.0).abs() < 0.10, "{ratio} vs {predicted}");
}

fn skewness(values: &[f32]) -> f64 {
    let n = values.len() as f64;
    let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    let m2 = values.iter().map(|&v| (f64::from(v) - mean).powi(2)).sum::<f64>() / n;
    let m3 = values.iter().map(|&v| (f64::from(v) - mean).powi(3)).sum::<f64>() / n;
    m3 / m2.powf(1.5)
}

#[test]
fn crests_are_sharper_than_troughs_at_every_beaufort() {
    println!("Beaufort | U m/s | skewness λ=0 | skewness λ=1 (Eulerian heights of the maps, {SEEDS} seeds)");
    for b in 3..=9u8 {
        let wind = beaufort_speed_m_s(b).unwrap();
        let extent = 30.0 * SeaSpectrum::new(wind, SpectrumChoice::PiersonMoskowitz).peak_wavelength_m().unwrap();
        let skew = |choppiness: f64| {
            (1..=SEEDS)
                .map(|seed| {
                    let p = SeaParams { wind_m_s: wind, seed, choppiness, ..SeaParams::default() };
                    skewness(&surface(p, N, extent, 3.0).height)
                })
                .sum::<f64>()
                / SEEDS as f64
        };
        let (linear, choppy) = (skew(0.0), skew(DEFAULT_CHOPPINESS));
        println!("{b:8} | {wind:5.2} | {linear:+12.3} | {choppy:+12.3}");
        assert!(linear.abs() < 0.05, "a linear sea is not skewed: {linear}");
        if b == 6 {
            assert!(choppy >= 0.1, "Beaufort 6: {choppy}");
        }
        assert!(choppy > linear + 0.05, "Beaufort {b}: {choppy} vs {linear}");
    }
}

/// The mean foam cover of `sea` over a grid of resting points 20 peak wavelengths across,
/// followed for `seconds` after its memory, at `rate` moments a second (the tracker's steps
/// are its own; the rate is how often it is asked, as a renderer would).
pub(crate) fn mean_cover(sea: &Sea, seconds: f64, rate: f64) -> f64 {
    let span = 20.0 * sea.peak_wavelength_m().unwrap() as f32;
    let points: Vec<[f32; 2]> = (0..1600)
        .map(|i| [span * ((i % 40) as f32 + 0.3) / 40.0 + 5e3, span * ((i / 40) as f32 + 0.7) / 40.0])
        .collect();
    let footprints = vec![Footprint::default(); points.len()];
    let mut tracker = FoamTracker::new();
    let (mut sum, mut count) = (0.0f64, 0usize);
    let frames = (seconds * rate).round() as usize;
    for k in 0..frames {
        let time = sea.time_after(1000.0, k as f64 / rate);
        sum += tracker.update(sea, &points, &footprints, time).iter().map(|f| f64::from(f.cover)).sum::<f64>();
        count += points.len();
    }
    sum / count as f64
}

/// Monahan and O'Muircheartaigh's (1980) whitecap fraction `3.84e-6·U^3.41`, capped at 1:
/// what the foam gain was set against (at 10 m/s).
fn whitecap_fraction(wind_m_s: f64) -> f64 {
    (3.84e-6 * wind_m_s.max(0.0).powf(3.41)).min(1.0)
}

/// Callaghan, de Leeuw, Cohen and O'Dowd (2008), GRL 35, L23609: whitecap coverage from 2006 MAP
/// campaign images in the North East Atlantic, valid from 3.70 to 23.09 m/s, as a fraction:
/// `3.18e-5·(U - 3.70)³` up to 11.25 m/s and `4.82e-6·(U + 1.98)³` from 9.25 m/s (their two
/// overlapping groups; the branches cross at 10.18 m/s, where this switches).
fn callaghan_2008(wind_m_s: f64) -> f64 {
    if wind_m_s <= 3.70 {
        0.0
    } else if wind_m_s <= 10.18 {
        3.18e-5 * (wind_m_s - 3.70).powi(3)
    } else {
        4.82e-6 * (wind_m_s + 1.98).powi(3)
    }
}

/// The model's mean foam cover under `wind_m_s` (seed 11, 1600 resting points 20 peak
/// wavelengths across, 30 s at 5 moments a second), measured once per wind for all tests.
fn model_cover(wind_m_s: f64) -> f64 {
    static COVERS: std::sync::Mutex<Vec<(u64, f64)>> = std::sync::Mutex::new(Vec::new());
    let key = wind_m_s.to_bits();
    if let Some(&(_, c)) = COVERS.lock().expect("not poisoned").iter().find(|(k, _)| *k == key) {
        return c;
    }
    let sea = Sea::new(SeaParams { wind_m_s, choppiness: DEFAULT_CHOPPINESS, seed: 11, ..SeaParams::default() });
    let cover = mean_cover(&sea, 30.0, 5.0);
    COVERS.lock().expect("not poisoned").push((key, cover));
    cover
}

/// The foam gain was set so that the cover at 10 m/s is Monahan and O'Muircheartaigh's
/// (1980) 0.99 %: this holds it there (within 5 %), and prints the model against Monahan from
/// Beaufort 3 to 10 (their fit beyond 17 m/s is beyond their data).
#[test]
fn foam_gain_meets_monahan_at_10_m_s() {
    let cover = model_cover(10.0);
    let want = whitecap_fraction(10.0);
    println!("Monahan | U m/s | W | foam cover | ratio");
    for b in 3u8..=10 {
        let wind = beaufort_speed_m_s(b).unwrap();
        let (c, w) = (model_cover(wind), whitecap_fraction(wind));
        println!("B{b} | {wind:5.2} | {w:.5} | {c:.5} | {:.2}", c / w);
    }
    println!("10 m/s | {want:.5} | {cover:.5} | {:.3}", cover / want);
    assert!((cover / want - 1.0).abs() < 0.05, "10 m/s: {cover} vs Monahan {want}");
}

/// The model against a whitecap data set that did not set it: Callaghan et al. (2008), within
/// a factor of 2 at the Beaufort numbers inside its range from Beaufort 4 to 9 (6.7 to
/// 22.6 m/s). Beaufort 3 (4.4 m/s) is printed, not held: there the fit's cubic is a few
/// tenths of a m/s above its zero at 3.70 m/s, and the model is above it (see ALGORITHMS.md
/// §A.3).
#[test]
fn foam_covers_callaghans_whitecaps_from_beaufort_4_to_9() {
    println!("Callaghan 2008 | U m/s | W | foam cover | ratio | model's expected cover");
    for b in 3u8..=9 {
        let wind = beaufort_speed_m_s(b).unwrap();
        let sea =
            Sea::new(SeaParams { wind_m_s: wind, choppiness: DEFAULT_CHOPPINESS, seed: 11, ..SeaParams::default() });
        let (cover, want) = (model_cover(wind), callaghan_2008(wind));
        let expected = FoamModel::of(&sea).expected_cover();
        println!("B{b} | {wind:5.2} | {want:.5} | {cover:.5} | {:.2} | {expected:.5}", cover / want);
        if b >= 4 {
            assert!(cover / want > 0.5 && cover / want < 2.0, "Beaufort {b}: {cover} vs Callaghan {want}");
        }
    }
}

/// The largest jump between neighbouring texels inside the map and across its wrap, along
/// rows and along columns, of one scalar channel.
fn jumps(values: &[f32], n: usize) -> (f32, f32) {
    let (mut inside, mut wrap) = (0.0f32, 0.0f32);
    for r in 0..n {
        for c in 0..n {
            let v = values[r * n + c];
            let right = (values[r * n + (c + 1) % n] - v).abs();
            let down = (values[((r + 1) % n) * n + c] - v).abs();
            if c + 1 < n {
                inside = inside.max(right)
            } else {
                wrap = wrap.max(right)
            }
            if r + 1 < n { inside = inside.max(down) } else { wrap = wrap.max(down) }
        }
    }
    (inside, wrap)
}

#[test]
fn maps_tile_without_a_seam() {
    let params = SeaParams { wind_m_s: 14.0, choppiness: DEFAULT_CHOPPINESS, seed: 2, ..SeaParams::default() };
    let n = 128;
    let m = maps(params, n, 300.0, 12.0);
    assert!(m.foam.iter().any(|&f| f > 0.0), "a 14 m/s sea foams somewhere");
    let channels: Vec<(&str, Vec<f32>)> = vec![
        ("height", m.height.clone()),
        ("east displacement", m.displacement.iter().map(|d| d[0]).collect()),
        ("north displacement", m.displacement.iter().map(|d| d[1]).collect()),
        ("normal x", m.normal.iter().map(|v| v[0]).collect()),
        ("normal y", m.normal.iter().map(|v| v[1]).collect()),
        ("foam", m.foam.clone()),
    ];
    for (name, values) in channels {
        let (inside, wrap) = jumps(&values, n);
        assert!(wrap <= inside, "{name}: the wrap jumps {wrap}, neighbours inside at most {inside}");
    }
}

fn render(renderer: &mut OceanRenderer, sea: &Sea, t: f64) -> Pixmap {
    let mut out = Pixmap::new(renderer.width(), renderer.height()).unwrap();
    renderer.render(&sea.surface(t), &mut out);
    out
}

fn mean_difference(a: &Pixmap, b: &Pixmap) -> f64 {
    a.data().iter().zip(b.data()).map(|(x, y)| f64::from(x.abs_diff(*y))).sum::<f64>() / a.data().len() as f64
}

#[test]
fn a_loop_closes_bit_for_bit_and_without_a_jump() {
    let spectrum = SeaSpectrum::new(8.0, SpectrumChoice::PiersonMoskowitz);
    let period = LoopPeriod::new(64.0, spectrum.peak_period_s()).unwrap();
    let sea = Sea::new(SeaParams {
        wind_m_s: 8.0,
        choppiness: DEFAULT_CHOPPINESS,
        loop_period: Some(period),
        ..SeaParams::default()
    });
    let view = OceanView::default();
    let dt = 1.0 / 30.0;
    // An animation running through the end of the loop, frame after frame...
    let mut running = OceanRenderer::new(view, 96, 54, SeaTexture::builtin()).unwrap();
    let frames: Vec<Pixmap> =
        [64.0 - 2.0 * dt, 64.0 - dt, 64.0, 64.0 + dt].iter().map(|&t| render(&mut running, &sea, t)).collect();
    // ...and its first frame, drawn from scratch.
    let first = render(&mut OceanRenderer::new(view, 96, 54, SeaTexture::builtin()).unwrap(), &sea, 0.0);
    assert_eq!(frames[2].data(), first.data(), "the frame at T is frame 0");
    let neighbours = mean_difference(&frames[0], &frames[1]).max(mean_difference(&frames[2], &frames[3]));
    let jump = mean_difference(&frames[1], &first);
    println!("loop: last -> first {jump:.3} levels, neighbouring frames up to {neighbours:.3}");
    assert!(jump <= 1.25 * neighbours, "last -> first {jump} vs neighbours {neighbours}");
    // The maps loop too.
    let params = sea.params();
    let a = maps(params, 64, 200.0, 64.0);
    let b = maps(params, 64, 200.0, 0.0);
    assert_eq!(a, b, "maps at T equal maps at 0");
}
