//! Linear dispersion of surface gravity waves in water of any depth: ω² = g·k·tanh(k·h).
//!
//! In deep water (`depth = None`, or k·h large) this is ω² = g·k; in shallow water the same
//! frequency has a larger wavenumber (a shorter wave), which is how a TMA sea "shortens the
//! waves as it feels the bottom".

use super::spectrum::G;

/// Above this k·h, tanh(k·h) is 1 to double precision and the water counts as deep.
const DEEP_KH: f64 = 20.0;

#[cfg(any(test, feature = "cli", feature = "testing"))]
/// ω (rad/s) of a wave of wavenumber `k` (rad/m) in water `depth_m` deep (None = deep).
pub fn angular_frequency(k: f64, depth_m: Option<f64>) -> f64 {
    let k = k.max(0.0);
    match depth_m {
        Some(h) if k * h < DEEP_KH => (G * k * (k * h).tanh()).sqrt(),
        _ => (G * k).sqrt(),
    }
}

/// The wavenumber (rad/m) of angular frequency `omega` (rad/s) in water `depth_m` deep: the
/// root of g·k·tanh(k·h) = ω², by Newton's method from Eckart's approximation (it converges
/// to double precision in a few steps for every depth).
pub fn wavenumber(omega: f64, depth_m: Option<f64>) -> f64 {
    let k0 = omega * omega / G;
    let Some(h) = depth_m else { return k0 };
    if k0.is_nan() || k0 <= 0.0 || k0 * h >= DEEP_KH {
        return k0.max(0.0);
    }
    let mut k = k0 / (k0 * h).tanh().sqrt();
    for _ in 0..50 {
        let t = (k * h).tanh();
        let f = G * k * t - omega * omega;
        let df = G * t + G * k * h * (1.0 - t * t);
        let next = k - f / df;
        if (next - k).abs() <= 1e-15 * k {
            return next;
        }
        k = next;
    }
    k
}

#[cfg(any(test, feature = "cli", feature = "testing"))]
/// dω/dk (the group speed, m/s) at wavenumber `k` in water `depth_m` deep.
pub fn group_speed(k: f64, depth_m: Option<f64>) -> f64 {
    let omega = angular_frequency(k, depth_m);
    if omega == 0.0 {
        return 0.0;
    }
    match depth_m {
        Some(h) if k * h < DEEP_KH => {
            let t = (k * h).tanh();
            G * (t + k * h * (1.0 - t * t)) / (2.0 * omega)
        }
        _ => omega / (2.0 * k),
    }
}

/// Kitaigorodskii's depth factor Φ(ω, h) = tanh²(k·h) / (1 + 2k·h / sinh(2k·h)): the ratio
/// of the saturated k⁻³ wavenumber spectrum in depth h to deep water's, carried into the
/// frequency domain (the TMA spectrum is JONSWAP times Φ). 1 in deep water.
pub fn depth_factor(omega: f64, depth_m: Option<f64>) -> f64 {
    let Some(h) = depth_m else { return 1.0 };
    let k = wavenumber(omega, Some(h));
    let kh = k * h;
    if kh >= DEEP_KH {
        return 1.0;
    }
    if kh <= 0.0 {
        return 0.0;
    }
    let t = kh.tanh();
    t * t / (1.0 + 2.0 * kh / (2.0 * kh).sinh())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_root_satisfies_the_dispersion_relation() {
        for depth in [None, Some(0.5), Some(3.0), Some(20.0), Some(4000.0)] {
            for omega in [0.05, 0.3, 0.8, 2.0, 9.0] {
                let k = wavenumber(omega, depth);
                let back = angular_frequency(k, depth);
                assert!((back / omega - 1.0).abs() < 1e-12, "{depth:?} {omega}: {back}");
            }
        }
    }

    #[test]
    fn shallow_water_shortens_waves_and_slows_them() {
        let omega = 2.0 * std::f64::consts::PI / 8.0;
        let deep = wavenumber(omega, None);
        let shallow = wavenumber(omega, Some(5.0));
        assert!(shallow > 1.5 * deep, "{shallow} vs {deep}");
        // Long-wave limit: ω = k·√(g·h).
        let k = wavenumber(0.01, Some(2.0));
        assert!((0.01 / k / (G * 2.0f64).sqrt() - 1.0).abs() < 1e-4);
        // Group speed: half the phase speed in deep water, all of it in very shallow water.
        let kd = wavenumber(1.0, None);
        assert!((group_speed(kd, None) - 0.5 / kd).abs() < 1e-12);
        let ks = wavenumber(0.01, Some(2.0));
        assert!((group_speed(ks, Some(2.0)) / (0.01 / ks) - 1.0).abs() < 1e-3);
    }

    #[test]
    fn the_depth_factor_goes_from_half_omega_h_squared_to_one() {
        assert_eq!(depth_factor(1.0, None), 1.0);
        assert!((depth_factor(5.0, Some(50.0)) - 1.0).abs() < 1e-12);
        // Shallow limit: Φ ≈ ω_h²/2 with ω_h = ω·√(h/g).
        let (omega, h) = (0.05, 1.0);
        let wh2 = omega * omega * h / G;
        assert!((depth_factor(omega, Some(h)) / (0.5 * wh2) - 1.0).abs() < 0.01);
    }
}
