//! The sun's glitter on the sea, per pixel: the facets tilted to reflect the sun into the eye.
//!
//! # The mean
//! A pixel sees a patch of sea whose slope is the mesh's (the face normal n, or with smooth
//! shading the normal interpolated between the vertices) plus slopes too small for the mesh:
//! a Gaussian of variance σ² per axis, the surface's Cox–Munk total less what the mesh
//! carries there ([`crate::sim::surface::SurfaceSample`]: the unresolved slope variance, plus
//! the part of the kept waves the mesh loses between its samples). The facets that send the
//! sun into the eye have the normal h = normalize(l + v); their expected radiance is Cox and
//! Munk's
//!
//! ```text
//! G = E·F(v·h)·p(h) / (4·(n·v)·(n·h)⁴),   p(h) = exp(-tan²θ / (2σ²)) / (2π·σ²),   cos θ = n·h
//! ```
//!
//! (E the sun's irradiance against the sky's radiance), evaluated at every pixel, so the
//! glitter's extent over the slopes each pixel would need is the sea's slope distribution.
//!
//! # Sparkles
//! A real pixel does not show that mean: it shows the few facets in it that happen to face
//! the sun. The facets of glitter are the short wavelets, about [`FACET_M`] across; one of
//! them reflects some part of the sun's disc (solid angle Ω) when its normal lies within the
//! disc's half-angle of h, which has the probability `p(h)·Ω / (4·(n·h)³)` (the normal's
//! solid angle Ω/4 in slope space). A pixel covering A square metres of sea therefore holds
//! `N = A·p(h)·Ω / (4·(n·h)³·FACET_M²)` glints on average, and shows k of them, k drawn from
//! a Poisson law of mean N (from a hash of the pixel and the moment: facets this small change
//! within a frame), at `G/N` each. The mean is still G, so the glitter follows the slope
//! statistics, but near the camera (a pixel of a few square decimetres, N far below 1) it is
//! single bright sparkles, and far away (hundreds of square metres a pixel) the smooth path
//! towards the horizon. Above [`SMOOTH_GLINTS`] glints the mean is drawn.
//!
//! Everything is plain float arithmetic in a fixed order (its own exponential, no libm), so a
//! picture is the same bytes on every machine and core count.

use crate::render::light::Rgb;
use crate::render::shade::{WaterLook, fresnel};
use crate::render::sky::SUN_RADIUS_DEG;
use crate::render::vec3::{Vec3, dot, normalize};

/// The side of a glitter facet, m: the short wind wavelets (capillary-gravity waves are 1.7 cm
/// at their slowest) that a sea's sun glitter is made of.
pub const FACET_M: f32 = 0.02;
/// Above this many glints a pixel shows their mean.
pub const SMOOTH_GLINTS: f32 = 48.0;
/// The most glints a pixel is drawn with (a Poisson law of mean below [`SMOOTH_GLINTS`]
/// exceeds it with a probability below 1e-7).
const MAX_GLINTS: u32 = 96;
/// A face whose every pixel's mean glitter is below this (linear light) draws none.
pub const GLINT_VISIBLE: f32 = 1e-4;
/// The most a pixel's mean glitter is taken to be (as the lake's glint).
pub const MAX_GLINT: f32 = 50.0;

/// The glitter of one picture: the sun, the look, and the moment's seed for the sparkles.
#[derive(Clone, Copy, Debug)]
pub struct Glitter {
    sun_dir: Vec3,
    sun: Rgb,
    irradiance: f32,
    /// Ω / (4·FACET_M²): glints per square metre per unit of p / (n·h)³.
    density: f32,
    seed: u32,
    /// Rendering pixels per output pixel along each axis (the supersampling).
    cell: u32,
}

/// What varies over a face for its glitter, per corner: the unit vector to the eye (3), the
/// slope variance per axis the mesh does not carry, the share of the glitter the haze leaves,
/// square metres of sea per pixel, and the normal (3: a smooth shading's interpolated one, or
/// the face's at every corner).
pub type GlitterCorner = [f32; 9];

impl Glitter {
    /// The glitter of a sun in direction `sun_dir` with colour `sun`, for the moment `seed`,
    /// drawn at `ssaa` rendering pixels per output pixel (each axis).
    pub fn new(look: &WaterLook, sun_dir: Vec3, sun: Rgb, seed: u32, ssaa: u32) -> Glitter {
        let radius = SUN_RADIUS_DEG.to_radians();
        let omega = std::f32::consts::PI * radius * radius;
        let density = omega / (4.0 * FACET_M * FACET_M);
        Glitter { sun_dir, sun, irradiance: look.sun_irradiance, density, seed, cell: ssaa.max(1) }
    }

    /// Whether the sun is up (no glitter otherwise).
    pub fn shines(&self) -> bool {
        self.sun_dir[2] > 0.0
    }

    /// The mean glitter G (a multiple of the sun's colour) and the glints per pixel N for the
    /// normal `n`, the unit vector `v` to the eye, the slope variance per axis `s2` and
    /// `area_m2` square metres of sea in the pixel.
    #[inline(always)]
    pub fn mean(&self, n: Vec3, v: Vec3, s2: f32, area_m2: f32) -> (f32, f32) {
        let l = self.sun_dir;
        let h = normalize([l[0] + v[0], l[1] + v[1], l[2] + v[2]]);
        let nh = dot(n, h).max(1e-3);
        let nv = dot(n, v).max(0.02);
        let s2 = s2.max(1e-6);
        let nh2 = nh * nh;
        let tan2 = (1.0 - nh2) / nh2;
        let p = exp_neg(tan2 / (2.0 * s2)) / (2.0 * std::f32::consts::PI * s2);
        let g = (self.irradiance * fresnel(dot(v, h)) * p / (4.0 * nv * nh2 * nh2)).min(MAX_GLINT);
        let count = area_m2 * p * self.density / (nh2 * nh);
        (g, count)
    }

    /// The glitter a pixel shows, linear RGB: its corner values `at` interpolated to the
    /// pixel at (`x`, `y`) of the rendering picture, drawn as sparkles. The sparkles are drawn
    /// per output pixel (the glints of its whole area, the same draw for each of its
    /// supersamples), so that supersampling, which averages after tone mapping, does not
    /// dim a sparkle to grey.
    #[inline(always)]
    pub fn pixel(&self, at: &GlitterCorner, x: usize, y: usize) -> Rgb {
        let n = normalize([at[6], at[7], at[8]]);
        let v = normalize([at[0], at[1], at[2]]);
        let cell = self.cell as f32;
        let (g, count) = self.mean(n, v, at[3], at[5] * cell * cell);
        let shown = if count >= SMOOTH_GLINTS || g <= 0.0 {
            g
        } else {
            let k = poisson(count, unit_hash(x as u32 / self.cell, y as u32 / self.cell, self.seed));
            if k == 0 { 0.0 } else { g * k as f32 / count.max(1e-12) }
        };
        let w = shown * at[4].clamp(0.0, 1.0);
        [w * self.sun[0], w * self.sun[1], w * self.sun[2]]
    }

    /// Whether any pixel of a face with these corners can show glitter above
    /// [`GLINT_VISIBLE`]: the facets' tilt from the mesh normal that each corner needs, in
    /// slope space, is interpolated across the face; the face is skipped when even the
    /// smallest tilt within it (less a fifth, for the interpolation's curvature) is too rare.
    pub fn may_show(&self, corners: &[GlitterCorner; 3]) -> bool {
        if !self.shines() {
            return false;
        }
        let l = self.sun_dir;
        let mut d = [[0.0f32; 2]; 3];
        let (mut s2_lo, mut s2_hi, mut nv_lo, mut nh4_lo, mut keep) = (f32::MAX, 0.0f32, 1.0f32, 1.0f32, 0.0f32);
        for (c, dk) in corners.iter().zip(d.iter_mut()) {
            let v = normalize([c[0], c[1], c[2]]);
            let n = normalize([c[6], c[7], c[8]]);
            let h = normalize([l[0] + v[0], l[1] + v[1], l[2] + v[2]]);
            let slope = |u: Vec3| [-u[0] / u[2].max(1e-3), -u[1] / u[2].max(1e-3)];
            let (sh, sn) = (slope(h), slope(n));
            *dk = [sh[0] - sn[0], sh[1] - sn[1]];
            s2_lo = s2_lo.min(c[3].max(1e-6));
            s2_hi = s2_hi.max(c[3].max(1e-6));
            nv_lo = nv_lo.min(dot(n, v).max(0.02));
            nh4_lo = nh4_lo.min(dot(n, h).max(1e-3).powi(4));
            keep = keep.max(c[4]);
        }
        let t = 0.8 * distance_to_triangle(d);
        let p = exp_neg(t * t / (2.0 * s2_hi)) / (2.0 * std::f32::consts::PI * s2_lo);
        let g = (self.irradiance * p / (4.0 * nv_lo * nh4_lo)).min(MAX_GLINT);
        let sun = self.sun[0].max(self.sun[1]).max(self.sun[2]);
        g * keep * sun >= GLINT_VISIBLE
    }
}

/// The distance from the origin to the triangle with corners `d` (0 inside it).
fn distance_to_triangle(d: [[f32; 2]; 3]) -> f32 {
    let cross = |a: [f32; 2], b: [f32; 2]| a[0] * b[1] - a[1] * b[0];
    let side = |i: usize| cross([d[(i + 1) % 3][0] - d[i][0], d[(i + 1) % 3][1] - d[i][1]], [-d[i][0], -d[i][1]]);
    let (s0, s1, s2) = (side(0), side(1), side(2));
    let area = cross([d[1][0] - d[0][0], d[1][1] - d[0][1]], [d[2][0] - d[0][0], d[2][1] - d[0][1]]);
    let inside = (s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0) || (s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0);
    if inside && area != 0.0 {
        return 0.0;
    }
    (0..3)
        .map(|i| {
            let (a, b) = (d[i], d[(i + 1) % 3]);
            let e = [b[0] - a[0], b[1] - a[1]];
            let len2 = e[0] * e[0] + e[1] * e[1];
            let t = if len2 > 0.0 { (-(a[0] * e[0] + a[1] * e[1]) / len2).clamp(0.0, 1.0) } else { 0.0 };
            let q = [a[0] + t * e[0], a[1] + t * e[1]];
            (q[0] * q[0] + q[1] * q[1]).sqrt()
        })
        .fold(f32::MAX, f32::min)
}

/// e^(-x) for x >= 0 (0 beyond 87): 2^(-x·log2 e) split into a whole power of two, set in the
/// float's exponent, and a fraction from a degree-7 polynomial (relative error below 1e-5, most of it the rounding of
/// x·log2 e).
/// Plain arithmetic: the same bits on every machine.
#[inline(always)]
pub fn exp_neg(x: f32) -> f32 {
    if x.is_nan() {
        return 1.0;
    }
    if x >= 87.0 {
        return 0.0;
    }
    let x = x.max(0.0);
    let t = x * std::f32::consts::LOG2_E;
    let whole = t as i32; // t >= 0: truncation is the floor
    let f = t - whole as f32; // 0..1: 2^-f
    let u = -f * std::f32::consts::LN_2;
    let poly = 1.0
        + u * (1.0
            + u * (0.5 + u * (1.0 / 6.0 + u * (1.0 / 24.0 + u * (1.0 / 120.0 + u * (1.0 / 720.0 + u / 5040.0))))));
    f32::from_bits(((127 - whole) as u32) << 23) * poly
}

/// A draw from a Poisson law of mean `mean` by its inverse distribution at `u` (0..1).
#[inline(always)]
fn poisson(mean: f32, u: f32) -> u32 {
    let mut p = exp_neg(mean);
    let mut cdf = p;
    let mut k = 0;
    while cdf <= u && k < MAX_GLINTS {
        k += 1;
        p *= mean / k as f32;
        cdf += p;
    }
    k
}

/// A uniform number in [0, 1) from a pixel and a seed (a 32-bit integer hash).
#[inline(always)]
fn unit_hash(x: u32, y: u32, seed: u32) -> f32 {
    let mut h = x.wrapping_mul(0x8da6_b343) ^ y.wrapping_mul(0xd816_3841) ^ seed.wrapping_mul(0xcb1a_b31f);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_exponential_is_close_everywhere() {
        for i in 0..10_000 {
            let x = i as f32 * 0.0087;
            let (got, want) = (exp_neg(x), (-f64::from(x)).exp());
            assert!((f64::from(got) / want - 1.0).abs() < 1e-5, "{x}: {got} vs {want}");
        }
        assert_eq!(exp_neg(100.0), 0.0);
        assert_eq!(exp_neg(0.0), 1.0);
    }

    /// The sparkles keep the mean: over many pixels, k·G/N averages to G whatever N is.
    #[test]
    fn sparkles_keep_the_mean_glitter() {
        for mean in [0.01f32, 0.3, 2.0, 20.0] {
            let pixels = 200_000u32;
            let total: f64 = (0..pixels).map(|i| f64::from(poisson(mean, unit_hash(i % 640, i / 640, 7)))).sum();
            let got = total / f64::from(pixels);
            assert!((got / f64::from(mean) - 1.0).abs() < 0.05, "mean {mean}: {got}");
        }
    }

    #[test]
    fn the_distance_to_a_triangle() {
        assert_eq!(distance_to_triangle([[-1.0, -1.0], [1.0, -1.0], [0.0, 1.0]]), 0.0);
        assert!((distance_to_triangle([[1.0, -1.0], [1.0, 1.0], [2.0, 0.0]]) - 1.0).abs() < 1e-6);
        assert!((distance_to_triangle([[3.0, 4.0], [3.0, 4.0], [3.0, 4.0]]) - 5.0).abs() < 1e-6);
    }
}
