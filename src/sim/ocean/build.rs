//! Building a sea: the wind sea's sines from its spectrum, each swell's sines, and the fBm
//! tail (see the parent module's docs for the sampling).

use super::*;

/// Turns a sampled bin into a component: its frequency (rounded to a whole multiple of 1/T
/// in a looping sea) and its wavenumber in the sea's depth.
fn component(
    spectrum: &SeaSpectrum,
    loop_period: Option<LoopPeriod>,
    variance: f64,
    f: f64,
    bearing: f64,
    phase: f64,
) -> Component {
    let (mut f, mut harmonic) = (f, 0);
    if let Some(period) = loop_period {
        harmonic = (f * period.seconds()).round().max(1.0) as u32;
        f = f64::from(harmonic) / period.seconds();
    }
    Component {
        amplitude_m: (2.0 * variance).sqrt(),
        frequency_hz: f,
        omega: 2.0 * PI * f,
        wavenumber: spectrum.wavenumber(f),
        bearing_rad: bearing,
        phase_rad: 2.0 * PI * phase,
        harmonic,
    }
}

impl Sea {
    /// Builds the sea for `params` (deterministic in its seed).
    pub fn new(params: SeaParams) -> Sea {
        Sea::with_bins(params, FREQUENCY_BINS, DIRECTION_BINS)
    }

    /// [`Sea::new`] with another number of frequency and direction bins for the wind sea
    /// (tests and studies).
    pub fn with_bins(params: SeaParams, frequency_bins: usize, direction_bins: usize) -> Sea {
        let spectrum = params.wind_spectrum();
        let mut rng = ChaCha8Rng::seed_from_u64(params.seed ^ 0x5ea_5ea_5ea);
        let mut components = Vec::new();
        let mut tail = None;
        let downwind = (params.wind_from_deg + 180.0).to_radians();
        if let Some(fm) = spectrum.peak_hz() {
            let (f_lo, f_hi) = (BAND_LOW * fm, CUTOFF * fm);
            let ratio = (f_hi / f_lo).powf(1.0 / frequency_bins.max(1) as f64);
            let dtheta = 2.0 * PI / direction_bins.max(1) as f64;
            let floor = NEGLIGIBLE * spectrum.m0();
            for i in 0..frequency_bins {
                let (e0, e1) = (f_lo * ratio.powi(i as i32), f_lo * ratio.powi(i as i32 + 1));
                let (centre, df) = (0.5 * (e0 + e1), e1 - e0);
                for j in 0..direction_bins {
                    let theta = -PI + (j as f64 + 0.5) * dtheta;
                    let variance = spectrum.directional_energy(centre, theta) * df * dtheta;
                    // Draw the jitter and phase even for dropped components, so that the
                    // stream (and every other component) does not depend on the threshold.
                    let (uf, ut, phase): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
                    if variance < floor {
                        continue;
                    }
                    let bearing = downwind + theta + (ut - 0.5) * dtheta;
                    components.push(component(&spectrum, params.loop_period, variance, e0 + uf * df, bearing, phase));
                }
            }
            tail = Some(Self::tail(&spectrum, f_hi, downwind, &params));
        }
        let slope = |c: &Component| 0.5 * (c.amplitude_m * c.wavenumber).powi(2);
        let swells = params.swell_spectra();
        let mut swell_slope = 0.0;
        for (n, swell) in swells.iter().enumerate() {
            let before = components.len();
            Self::swell_components(swell, &spectrum, &params, n as u64, &mut components);
            swell_slope += components[before..].iter().map(slope).sum::<f64>();
        }
        components.sort_by(|a, b| a.wavenumber.total_cmp(&b.wavenumber));
        let lanes = Lanes::new(&components);
        let wavelength = components.iter().map(|c| (2.0 * PI / c.wavenumber) as f32).collect();
        let total_slope: f64 = components.iter().map(slope).sum();
        let fold_index: Vec<usize> =
            (0..components.len()).filter(|&i| slope(&components[i]) >= FOLD_NEGLIGIBLE * total_slope).collect();
        let kept: Vec<Component> = fold_index.iter().map(|&i| components[i]).collect();
        let fold = Lanes::new(&kept);
        let fold_wavelength = kept.iter().map(|c| (2.0 * PI / c.wavenumber) as f32).collect();
        let slope_total = (cox_munk_slope_variance(spectrum.wind_m_s()) + swell_slope) as f32;
        let downwind = [downwind.sin() as f32, downwind.cos() as f32];
        Sea {
            params,
            spectrum,
            components,
            lanes,
            wavelength,
            fold,
            fold_wavelength,
            fold_index,
            tail,
            slope_total,
            downwind,
        }
    }

    /// A swell's sines: [`SWELL_FREQUENCY_BINS`] x [`SWELL_DIRECTION_BINS`] bins about its
    /// peak and direction, jittered and phased from their own stream, scaled to carry all of
    /// the swell's variance (the little its band leaves out goes to the band).
    fn swell_components(
        swell: &SwellSpectrum,
        spectrum: &SeaSpectrum,
        params: &SeaParams,
        index: u64,
        out: &mut Vec<Component>,
    ) {
        let mut rng = ChaCha8Rng::seed_from_u64(params.seed ^ 0x5e11_0000 ^ (index << 8));
        let fp = swell.peak_hz();
        let (f_lo, f_hi) = (SWELL_BAND.0 * fp, SWELL_BAND.1 * fp);
        let ratio = (f_hi / f_lo).powf(1.0 / SWELL_FREQUENCY_BINS as f64);
        let dtheta = 2.0 * SWELL_HALF_WIDTH_RAD / SWELL_DIRECTION_BINS as f64;
        let mut bins = Vec::new();
        for i in 0..SWELL_FREQUENCY_BINS {
            let (e0, e1) = (f_lo * ratio.powi(i as i32), f_lo * ratio.powi(i as i32 + 1));
            let (centre, df) = (0.5 * (e0 + e1), e1 - e0);
            for j in 0..SWELL_DIRECTION_BINS {
                let theta = -SWELL_HALF_WIDTH_RAD + (j as f64 + 0.5) * dtheta;
                let variance = swell.directional_energy(centre, theta) * df * dtheta;
                let (uf, ut, phase): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
                bins.push((variance, e0 + uf * df, swell.bearing_rad() + theta + (ut - 0.5) * dtheta, phase));
            }
        }
        let scale = swell.m0() / bins.iter().map(|b| b.0).sum::<f64>();
        for (variance, f, bearing, phase) in bins {
            if variance * scale >= NEGLIGIBLE * swell.m0() {
                out.push(component(spectrum, params.loop_period, variance * scale, f, bearing, phase));
            }
        }
    }

    fn tail(spectrum: &SeaSpectrum, cutoff_hz: f64, downwind: f64, params: &SeaParams) -> Tail {
        let deep = matches!(params.spectrum, SpectrumChoice::PiersonMoskowitz);
        let lambda_c = if deep { wavelength_m(cutoff_hz) } else { 2.0 * PI / spectrum.wavenumber(cutoff_hz) };
        let variance = spectrum.m0() - spectrum.cumulative_variance(cutoff_hz);
        let levels = ((lambda_c / TAIL_FINEST_M).log2().ceil().max(0.0) as u32).min(TAIL_MAX_LEVELS);
        let sigma = variance.max(0.0).sqrt() as f32;
        let seed = params.seed;
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
        let speed =
            if deep { G / (2.0 * PI * cutoff_hz) } else { 2.0 * PI * cutoff_hz / spectrum.wavenumber(cutoff_hz) };
        let cell_m = lambda_c / f64::from(1u32 << levels);
        let mut velocity_m_s = [speed * downwind.sin(), speed * downwind.cos()];
        let mut loop_periods = [0; 2];
        if let Some(period) = params.loop_period {
            // Whole tail periods per loop, so the drift wraps exactly every T.
            let tail_period = cell_m * field.size() as f64;
            for axis in 0..2 {
                loop_periods[axis] = (velocity_m_s[axis] * period.seconds() / tail_period).round() as i64;
                velocity_m_s[axis] = loop_periods[axis] as f64 * tail_period / period.seconds();
            }
        }
        // Measure each octave's slope on its own lattice (exact for the field).
        let mut octave_slope = Vec::new();
        let n = field.size() as isize;
        for octave in 0..=levels {
            let st = 1isize << octave;
            let (mut sl, mut count) = (0.0f64, 0.0f64);
            for y in (0..n).step_by(st as usize) {
                for x in (0..n).step_by(st as usize) {
                    let h = f64::from(field.at(x, y));
                    let d = f64::from(field.at(x + st, y)) - h;
                    sl += d * d;
                    count += 1.0;
                }
            }
            octave_slope.push((sl / count / (st as f64 * cell_m).powi(2)) as f32);
        }
        Tail { field, cell_m, velocity_m_s, loop_periods, variance, octave_slope }
    }
}
