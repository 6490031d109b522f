//! Fast cosine and sine for the sea's sums over hundreds of components: branch-free, so the
//! loops over eight lanes vectorise on plain SSE2, and deterministic (the same bits on every
//! machine: no `floor`, no libm).

use std::f32::consts::TAU;

const INV_TAU: f32 = 1.0 / TAU;
/// 1.5·2^23: adding and subtracting it rounds an f32 to an integer.
const ROUND: f32 = 12_582_912.0;

/// x reduced to [-π, π].
#[inline(always)]
fn reduce(x: f32) -> f32 {
    let turns = x * INV_TAU;
    let r = (turns + ROUND) - ROUND;
    (turns - r) * TAU
}

#[inline(always)]
fn cos_poly(t: f32) -> f32 {
    let u = t * t;
    let p = 1.0 / 479_001_600.0;
    let p = p * u - 1.0 / 3_628_800.0;
    let p = p * u + 1.0 / 40_320.0;
    let p = p * u - 1.0 / 720.0;
    let p = p * u + 1.0 / 24.0;
    let p = p * u - 0.5;
    p * u + 1.0
}

#[inline(always)]
fn sin_poly(t: f32) -> f32 {
    let u = t * t;
    let p = -1.0 / 6_227_020_800.0;
    let p = p * u + 1.0 / 39_916_800.0;
    let p = p * u - 1.0 / 362_880.0;
    let p = p * u + 1.0 / 5_040.0;
    let p = p * u - 1.0 / 120.0;
    let p = p * u + 1.0 / 6.0;
    t - t * u * p
}

/// cos(x) for any x, to about 1e-5: reduce to [-π, π] with an add-and-subtract round and
/// evaluate the Taylor series to x¹².
#[inline(always)]
pub fn fast_cos(x: f32) -> f32 {
    cos_poly(reduce(x))
}

/// (sin x, cos x) for any x, to about 1e-5, sharing one reduction.
#[inline(always)]
pub fn fast_sincos(x: f32) -> (f32, f32) {
    let t = reduce(x);
    (sin_poly(t), cos_poly(t))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accurate_everywhere() {
        for i in -2000..2000 {
            let x = i as f32 * 0.37;
            assert!((fast_cos(x) - x.cos()).abs() < 2e-4, "{x}");
            let (s, c) = fast_sincos(x);
            assert!((s - x.sin()).abs() < 2e-4 && (c - x.cos()).abs() < 2e-4, "{x}");
            assert_eq!(c, fast_cos(x));
        }
    }
}
