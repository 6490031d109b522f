use super::*;

fn points(n: usize, seed: u64) -> Vec<(f32, f32)> {
    // A fixed scatter of points over a 64x64-cell area (no rand needed).
    (0..n)
        .map(|i| {
            let h = fold_seed(seed.wrapping_mul(1_000_003).wrapping_add(i as u64));
            let g = fold_seed(u64::from(h));
            ((h % 65_536) as f32 / 1024.0, (g % 65_536) as f32 / 1024.0)
        })
        .collect()
}

#[test]
fn the_hash_is_deterministic_and_seeded() {
    assert_eq!(lattice_value(5, 3, -7, 2), lattice_value(5, 3, -7, 2));
    assert_ne!(lattice_value(5, 3, -7, 2), lattice_value(6, 3, -7, 2));
    for kind in [NoiseKind::Value, NoiseKind::Gradient] {
        let a: Vec<f32> = points(200, 1).iter().map(|&(x, y)| noise(kind, 9, x, y, 0.3)).collect();
        let b: Vec<f32> = points(200, 1).iter().map(|&(x, y)| noise(kind, 9, x, y, 0.3)).collect();
        let c: Vec<f32> = points(200, 1).iter().map(|&(x, y)| noise(kind, 10, x, y, 0.3)).collect();
        assert_eq!(a, b, "{kind:?}: same seed, same field");
        assert!(a.iter().zip(&c).filter(|(p, q)| p != q).count() > 190, "{kind:?}: other seed, other field");
    }
    let f = Fractal { kind: NoiseKind::Value, seed: 42, octaves: 5, persistence: 0.5 };
    assert_eq!(f.sample(1.3, 2.7, 0.5), f.sample(1.3, 2.7, 0.5));
    assert_ne!(f.sample(1.3, 2.7, 0.5), Fractal { seed: 43, ..f }.sample(1.3, 2.7, 0.5));
}

#[test]
fn lattice_values_span_minus_one_to_one_evenly() {
    let values: Vec<f32> = (0..20_000).map(|i| lattice_value(1, i % 200, i / 200, 0)).collect();
    assert!(values.iter().all(|v| (-1.0..=1.0).contains(v)));
    let mean = values.iter().sum::<f32>() / values.len() as f32;
    let below = values.iter().filter(|&&v| v < -0.5).count() as f32 / values.len() as f32;
    assert!(mean.abs() < 0.02, "mean {mean}");
    assert!((below - 0.25).abs() < 0.02, "a quarter below -0.5: {below}");
}

#[test]
fn value_noise_at_lattice_points_is_the_smoothed_lattice_value() {
    for (x, y, z) in [(0, 0, 0), (3, -4, 1), (-17, 25, 9), (1000, 1000, -3)] {
        let want = smoothed_value(7, x, y, z);
        assert_eq!(noise(NoiseKind::Value, 7, x as f32, y as f32, z as f32), want, "({x}, {y}, {z})");
        assert_eq!(noise(NoiseKind::Gradient, 7, x as f32, y as f32, z as f32), 0.0);
    }
    // Halfway between two lattice points along x (y on the lattice) it is their mean.
    let (a, b) = (smoothed_value(7, 2, 5, 0), smoothed_value(7, 3, 5, 0));
    assert!((noise(NoiseKind::Value, 7, 2.5, 5.0, 0.0) - (a + b) / 2.0).abs() < 1e-6);
    // The smoothing is the paper's weighting of the nine lattice values.
    let v = |dx, dy| lattice_value(7, 4 + dx, 4 + dy, 0);
    let by_hand = (v(-1, -1) + v(1, -1) + v(-1, 1) + v(1, 1)) / 16.0
        + (v(-1, 0) + v(1, 0) + v(0, -1) + v(0, 1)) / 8.0
        + v(0, 0) / 4.0;
    assert_eq!(smoothed_value(7, 4, 4, 0), by_hand);
}

#[test]
fn cosine_interpolation_eases_in_and_out() {
    assert_eq!(cosine_interpolate(2.0, 4.0, 0.0), 2.0);
    assert!((cosine_interpolate(2.0, 4.0, 1.0) - 4.0).abs() < 1e-6);
    assert!((cosine_interpolate(2.0, 4.0, 0.5) - 3.0).abs() < 1e-6);
    // Flat at the ends: a tenth of the way it has moved far less than a tenth.
    assert!(cosine_weight(0.1) < 0.03 && cosine_weight(0.9) > 0.97);
}

#[test]
fn noise_is_continuous() {
    // The steepest a cosine-interpolated cell can be is π/2 per unit of value difference
    // (at most 2), so a step of ε moves the noise by at most about π·ε along x, y or t.
    let eps = 1e-3;
    for kind in [NoiseKind::Value, NoiseKind::Gradient] {
        let bound = if kind == NoiseKind::Value { PI } else { 2.0 * PI } * eps * 1.01 + 1e-5;
        let mut pts = points(500, 4);
        // Include points on cell edges, where the interpolation changes cells.
        pts.extend([(3.0 - eps / 2.0, 1.2), (5.5, 9.0 - eps / 2.0), (-0.0005, -0.0005)]);
        for (x, y) in pts {
            let at = |dx: f32, dy: f32, dt: f32| noise(kind, 3, x + dx, y + dy, 2.0 - eps / 2.0 + dt);
            let here = at(0.0, 0.0, 0.0);
            for (dx, dy, dt) in [(eps, 0.0, 0.0), (0.0, eps, 0.0), (0.0, 0.0, eps)] {
                let d = (at(dx, dy, dt) - here).abs();
                assert!(d <= bound, "{kind:?} jumps by {d} at ({x}, {y}) for ({dx}, {dy}, {dt})");
            }
        }
    }
}

#[test]
fn ranges_are_bounded() {
    for kind in [NoiseKind::Value, NoiseKind::Gradient] {
        let mut extreme = 0.0f32;
        for (x, y) in points(20_000, 8) {
            let v = noise(kind, 11, x, y, x * 0.37);
            assert!((-1.0..=1.0).contains(&v), "{kind:?}: {v} at ({x}, {y})");
            extreme = extreme.max(v.abs());
        }
        assert!(extreme > 0.3, "{kind:?} uses its range: {extreme}");
        let f = Fractal { kind, seed: 2, octaves: 6, persistence: 0.7 };
        for (x, y) in points(2_000, 9) {
            assert!(f.sample(x, y, 1.5).abs() <= f.bound());
        }
    }
    let f = Fractal { kind: NoiseKind::Value, seed: 2, octaves: 3, persistence: 0.5 };
    assert_eq!(f.bound(), 1.75);
}

#[test]
fn variance_and_slope_constants_hold() {
    // The constants the lake uses to set its height and roughness, re-measured.
    for kind in [NoiseKind::Value, NoiseKind::Gradient] {
        let (mut v2, mut s2, mut n) = (0.0f64, 0.0f64, 0.0f64);
        let h = 1e-3;
        for seed in 0..4u32 {
            for j in 0..100 {
                for i in 0..100 {
                    let (x, y) = (i as f32 * 0.371 + 0.05, j as f32 * 0.419 + 0.07);
                    let v = noise(kind, seed, x, y, 0.0);
                    let s = (noise(kind, seed, x + h, y, 0.0) - v) / h;
                    v2 += f64::from(v * v);
                    s2 += f64::from(s * s);
                    n += 1.0;
                }
            }
        }
        let (var, slope) = ((v2 / n) as f32, (s2 / n) as f32);
        assert!((var / kind.variance() - 1.0).abs() < 0.1, "{kind:?}: variance {var} vs {}", kind.variance());
        assert!(
            (slope / kind.slope_variance() - 1.0).abs() < 0.1,
            "{kind:?}: slope variance {slope} vs {}",
            kind.slope_variance()
        );
    }
}

/// The mean squared difference of the fractal between points `lag` cells apart along x.
fn structure(f: &Fractal, lag: f32) -> f32 {
    let pts = points(3_000, 12);
    pts.iter().map(|&(x, y)| (f.sample(x + lag, y, 0.0) - f.sample(x, y, 0.0)).powi(2)).sum::<f32>() / pts.len() as f32
}

#[test]
fn octaves_add_fine_detail_and_persistence_weights_it() {
    let base = Fractal { kind: NoiseKind::Value, seed: 5, octaves: 1, persistence: 0.5 };
    // One octave is the plain noise.
    assert_eq!(base.sample(2.3, 4.1, 0.0), noise(NoiseKind::Value, base.octave_seed(0), 2.3, 4.1, 0.0));
    // More octaves: more variation between close points (fine scales), about the same
    // between far ones (the coarse octave dominates there).
    let fine = |f: &Fractal| structure(f, 1.0 / 32.0);
    let coarse = |f: &Fractal| structure(f, 4.0);
    let six = Fractal { octaves: 6, ..base };
    assert!(fine(&six) > 4.0 * fine(&base), "{} vs {}", fine(&six), fine(&base));
    assert!(coarse(&six) < 1.6 * coarse(&base), "{} vs {}", coarse(&six), coarse(&base));
    // Higher persistence: relatively more fine-scale energy (a rougher, whiter spectrum).
    let rough = Fractal { persistence: 0.8, ..six };
    let smooth = Fractal { persistence: 0.3, ..six };
    let ratio = |f: &Fractal| fine(f) / coarse(f);
    assert!(ratio(&rough) > 3.0 * ratio(&smooth), "{} vs {}", ratio(&rough), ratio(&smooth));
    // The variance follows Σ p²ⁱ.
    for f in [base, six, rough, smooth] {
        let pts = points(4_000, 13);
        let measured = pts.iter().map(|&(x, y)| f.sample(x, y, 0.0).powi(2)).sum::<f32>() / pts.len() as f32;
        assert!((measured / f.variance() - 1.0).abs() < 0.15, "{f:?}: {measured} vs {}", f.variance());
    }
}

fn water(kind: NoiseKind) -> WaterNoise {
    WaterNoise {
        fractal: Fractal { kind, seed: 3, octaves: 4, persistence: 0.5 },
        spacing_m: 2.0,
        speed_m_s: 1.5,
        heading_rad: -PI / 2.0,
        spread_rad: 0.0,
    }
}

#[test]
fn water_noise_moves_smoothly_and_drifts_downwind() {
    let w = water(NoiseKind::Value);
    let (a, b) = (w.at(10.0), w.at(10.0 + 1e-3));
    for (x, y) in points(200, 2) {
        assert!((a.sample(x, y) - b.sample(x, y)).abs() < 0.01, "a millisecond changes little");
    }
    assert_eq!(w.at(3.0), w.at(3.0));
    // Octave 0 drifts south at 1.5 m/s (and evolves, one slice per period): a tenth of a
    // second later its pattern is found 0.15 m further south, changed less than the same
    // spot has, and far less than 0.15 m north.
    let (t0, t1) = (w.at(0.0), w.at(0.1));
    let (mut south, mut still, mut north) = (0.0, 0.0, 0.0);
    for (x, y) in points(500, 3) {
        let before = t0.octave(0, x, y);
        south += (t1.octave(0, x, y - 0.15) - before).powi(2);
        still += (t1.octave(0, x, y) - before).powi(2);
        north += (t1.octave(0, x, y + 0.15) - before).powi(2);
    }
    assert!(south < 0.8 * still && south < 0.4 * north, "south {south}, standing {still}, north {north}");
}

#[test]
fn animated_octaves_keep_their_variance_between_time_slices() {
    // Octave 0 of this field passes a slice every 2.7 s; sample a slice's worth of moments.
    let w = water(NoiseKind::Value);
    for step in 0..6 {
        let f = w.at(f64::from(step) * 0.45);
        let pts = points(3_000, 6);
        let var = pts.iter().map(|&(x, y)| f.octave(0, 30.0 * x, 30.0 * y).powi(2)).sum::<f32>() / 3000.0;
        assert!((var / VALUE_VARIANCE - 1.0).abs() < 0.15, "at step {step}: {var}");
    }
}

#[test]
fn huge_times_keep_their_detail() {
    // Whole cells are tracked apart from the fraction: a frame at 10 million seconds is as
    // smooth between close points as one at 0.
    let w = water(NoiseKind::Gradient);
    for t in [0.0, 1e7] {
        let f = w.at(t);
        let (a, b) = (f.sample(1.0, 1.0), f.sample(1.001, 1.0));
        assert!((a - b).abs() < 0.01, "t = {t}: {a} vs {b}");
        assert!(f.sample(1.0, 1.0) != f.sample(1.3, 1.0));
    }
    let (a, b) = (w.at(1e7), w.at(1e7 + 0.01));
    assert!((a.sample(0.5, 0.5) - b.sample(0.5, 0.5)).abs() < 0.05);
}

#[test]
fn frames_sum_their_octaves() {
    let w = water(NoiseKind::Value);
    let f = w.at(2.0);
    assert_eq!(f.octave_count(), 4);
    assert_eq!(f.spacing_m(2), 0.5);
    assert_eq!(f.amplitude(3), 0.125);
    let sum: f32 = (0..4).map(|i| f.octave(i, 3.0, 4.0)).sum();
    assert_eq!(f.sample(3.0, 4.0), sum);
    // At time 0 with no drift the octaves are the fractal's noises at their own slices.
    let still = WaterNoise { speed_m_s: 0.0, ..w }.at(0.0);
    let o = still.octaves[0];
    let n0 = noise(NoiseKind::Value, w.fractal.octave_seed(0), 1.5, 0.75, o.slice as f32 + o.slice_frac);
    let wt = cosine_weight(o.slice_frac);
    let keep = ((1.0 - wt) * (1.0 - wt) + wt * wt).sqrt();
    assert!((still.octave(0, 3.0, 1.5) - n0 / keep).abs() < 1e-5);
}
