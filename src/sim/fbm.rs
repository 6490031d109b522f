//! A periodic (wrapping) fractional Brownian motion field made by the diamond-square method.
//!
//! The ocean paper fills each patch between four corner heights "from the PM model" with
//! diamond-square fBm. tidepool makes one wrapping field instead of patches, so it tiles the
//! whole sea without seams: the seeded lattice of corner values (spacing `2^levels` cells) is
//! kept as given, and each refinement sets the new points to the mean of their four lattice
//! neighbours (wrapping around the edges) plus a Gaussian displacement whose standard deviation
//! shrinks by `2^(-H/2)` every half step (diamond, then square), i.e. by `2^-H` per octave.
//! With H = 1 this is the k⁻⁴ 2-D spectrum of the Pierson–Moskowitz tail (`docs/ALGORITHMS.md` §3.3).
//!
//! Because coarse lattice values are never changed by finer steps, the field cut off at any
//! octave is simply the bilinear interpolation of the lattice at that stride: [`Fbm::sample`]
//! uses this to filter detail finer than a footprint without a separate mip pyramid.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A square, wrapping grid of heights, `size x size` cells, `size = corners << levels`.
#[derive(Clone, Debug, PartialEq)]
pub struct Fbm {
    size: usize,
    levels: u32,
    values: Vec<f32>,
}

/// The ratio of the first displacement to the corners' standard deviation that makes the
/// field's mean variance equal the corners' variance when H = 1.
///
/// The repeated four-point means of independent corners keep only about a third of their
/// variance; the displacements restore the rest (measured: variance ≈ 0.33 + 0.32·r² times the
/// corners'). Found by bisection over 200 seeded 8-corner, 6-octave fields and checked by the
/// test `variance_is_the_corner_variance`.
pub const UNIT_VARIANCE_DISPLACEMENT: f32 = 1.44;

/// One standard normal variate (Box–Muller), from a seeded generator so fields repeat exactly.
pub fn gaussian(rng: &mut ChaCha8Rng) -> f32 {
    let u1: f64 = rng.random_range(f64::EPSILON..1.0);
    let u2: f64 = rng.random();
    ((-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()) as f32
}

impl Fbm {
    /// Refines `corners` (row-major, `corners_per_side²` values on a lattice of spacing
    /// `2^levels` cells) into a wrapping field of `(corners_per_side << levels)²` cells.
    ///
    /// `first_displacement` is the standard deviation added at the first (diamond) step;
    /// `hurst` is H (1 for the PM tail). The same arguments and `seed` give the same field.
    ///
    /// # Panics
    /// When `corners.len() != corners_per_side²` or `corners_per_side == 0` (programming errors).
    pub fn diamond_square(
        corners_per_side: usize,
        levels: u32,
        corners: &[f32],
        first_displacement: f32,
        hurst: f32,
        seed: u64,
    ) -> Fbm {
        assert!(corners_per_side > 0, "at least one corner per side");
        assert_eq!(corners.len(), corners_per_side * corners_per_side, "corner count");
        let size = corners_per_side << levels;
        let mut values = vec![0.0f32; size * size];
        let mut step = 1usize << levels;
        for (i, &c) in corners.iter().enumerate() {
            let (row, col) = (i / corners_per_side, i % corners_per_side);
            values[row * step * size + col * step] = c;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let shrink = 2f32.powf(-hurst / 2.0);
        let mut d = first_displacement;
        let wrap = |v: usize, off: isize| (v as isize + off).rem_euclid(size as isize) as usize;
        while step > 1 {
            let half = step / 2;
            let h = half as isize;
            // Diamond: cell centres from the four lattice corners around them.
            for y in (half..size).step_by(step) {
                for x in (half..size).step_by(step) {
                    let sum = values[wrap(y, -h) * size + wrap(x, -h)]
                        + values[wrap(y, -h) * size + wrap(x, h)]
                        + values[wrap(y, h) * size + wrap(x, -h)]
                        + values[wrap(y, h) * size + wrap(x, h)];
                    values[y * size + x] = sum / 4.0 + d * gaussian(&mut rng);
                }
            }
            d *= shrink;
            // Square: edge midpoints from their four neighbours (two corners, two centres).
            for y in (0..size).step_by(half) {
                let first = if (y / half).is_multiple_of(2) { half } else { 0 };
                for x in (first..size).step_by(step) {
                    let sum = values[wrap(y, -h) * size + x]
                        + values[wrap(y, h) * size + x]
                        + values[y * size + wrap(x, -h)]
                        + values[y * size + wrap(x, h)];
                    values[y * size + x] = sum / 4.0 + d * gaussian(&mut rng);
                }
            }
            d *= shrink;
            step = half;
        }
        Fbm { size, levels, values }
    }

    /// Cells per side.
    pub fn size(&self) -> usize {
        self.size
    }

    /// Refinement octaves below the corner lattice.
    pub fn levels(&self) -> u32 {
        self.levels
    }

    #[cfg(test)]
    /// All values, row-major.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The value at cell (x, y), wrapping.
    pub fn at(&self, x: isize, y: isize) -> f32 {
        let n = self.size as isize;
        self.values[(y.rem_euclid(n) * n + x.rem_euclid(n)) as usize]
    }

    /// The field at (x, y) in cell units (wrapping), with octaves finer than `2^octave` cells
    /// removed: the bilinear interpolation of the lattice of that stride. Octave 0 is the full
    /// field; octaves at or above `levels` leave only the corner lattice.
    pub fn sample(&self, x: f32, y: f32, octave: u32) -> f32 {
        let stride = 1usize << octave.min(self.levels);
        let s = stride as f32;
        let (gx, gy) = (x / s, y / s);
        let (fx, fy) = (gx.floor(), gy.floor());
        let (tx, ty) = (gx - fx, gy - fy);
        let (ix, iy) = (fx as isize * stride as isize, fy as isize * stride as isize);
        let st = stride as isize;
        let v00 = self.at(ix, iy);
        let v10 = self.at(ix + st, iy);
        let v01 = self.at(ix, iy + st);
        let v11 = self.at(ix + st, iy + st);
        let top = v00 + (v10 - v00) * tx;
        let bottom = v01 + (v11 - v01) * tx;
        top + (bottom - top) * ty
    }

    #[cfg(test)]
    /// The mean of the squared values (the field's variance about zero).
    pub fn mean_square(&self) -> f64 {
        self.values.iter().map(|&v| f64::from(v) * f64::from(v)).sum::<f64>() / self.values.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random_corners(n: usize, seed: u64) -> Vec<f32> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..n * n).map(|_| gaussian(&mut rng)).collect()
    }

    #[test]
    fn seeded_corners_stay() {
        let corners = random_corners(4, 3);
        let f = Fbm::diamond_square(4, 5, &corners, 0.8, 1.0, 9);
        assert_eq!(f.size(), 128);
        for (i, &c) in corners.iter().enumerate() {
            assert_eq!(f.at((i % 4 * 32) as isize, (i / 4 * 32) as isize), c);
        }
        // Every cell was filled.
        assert!(f.values().iter().filter(|&&v| v == 0.0).count() < 3);
    }

    #[test]
    fn the_field_is_periodic() {
        let f = Fbm::diamond_square(2, 6, &random_corners(2, 1), 1.0, 1.0, 5);
        let n = f.size() as isize;
        for (x, y) in [(0, 0), (5, 17), (127, 3), (64, 64)] {
            assert_eq!(f.at(x, y), f.at(x + n, y - n));
        }
        // Sampling across the wrap is continuous: the last column interpolates to the first.
        let (a, b) = (f.sample(n as f32 - 0.001, 7.0, 0), f.sample(-0.001, 7.0, 0));
        assert!((a - b).abs() < 1e-3);
        let (a, b) = (f.sample(n as f32 - 0.5, 9.0, 0), f.sample(0.0, 9.0, 0));
        assert!((a - b).abs() < 0.5 * (f.at(n - 1, 9) - f.at(0, 9)).abs() + 1e-6);
    }

    #[test]
    fn same_seed_same_field_other_seed_other_field() {
        let corners = random_corners(8, 2);
        let a = Fbm::diamond_square(8, 4, &corners, 0.5, 1.0, 11);
        let b = Fbm::diamond_square(8, 4, &corners, 0.5, 1.0, 11);
        let c = Fbm::diamond_square(8, 4, &corners, 0.5, 1.0, 12);
        assert_eq!(a, b);
        assert_ne!(a, c);
    }

    #[test]
    fn variance_is_the_corner_variance() {
        let mut sum = 0.0;
        let mut corner_sum = 0.0;
        for seed in 0..40 {
            let corners = random_corners(8, 1000 + seed);
            corner_sum += corners.iter().map(|&c| f64::from(c * c)).sum::<f64>() / 64.0;
            sum += Fbm::diamond_square(8, 5, &corners, UNIT_VARIANCE_DISPLACEMENT, 1.0, seed).mean_square();
        }
        let ratio = sum / corner_sum;
        assert!((ratio - 1.0).abs() < 0.05, "field variance / corner variance = {ratio}");
    }

    #[test]
    fn hurst_one_doubles_the_amplitude_per_octave_of_scale() {
        // fBm with H = 1: the mean squared difference at lag L grows as L^(2H) = L², so each
        // doubling of the lag multiplies it by about 4 (H = 0.5 would give 2).
        let structure = |f: &Fbm, lag: isize| {
            let n = f.size() as isize;
            let mut s = 0.0f64;
            for y in 0..n {
                for x in 0..n {
                    let d = f64::from(f.at(x + lag, y) - f.at(x, y));
                    s += d * d;
                }
            }
            s / (n * n) as f64
        };
        let mut ratios = [0.0; 2];
        for seed in 0..8 {
            let f = Fbm::diamond_square(4, 7, &[0.0; 16], 1.0, 1.0, seed);
            ratios[0] += structure(&f, 4) / structure(&f, 2) / 8.0;
            ratios[1] += structure(&f, 8) / structure(&f, 4) / 8.0;
        }
        for r in ratios {
            assert!((3.0..5.0).contains(&r), "{ratios:?}");
        }
        let rough = Fbm::diamond_square(4, 7, &[0.0; 16], 1.0, 0.5, 1);
        let r = structure(&rough, 8) / structure(&rough, 4);
        assert!(r < 3.0, "H = 0.5 is rougher: {r}");
    }

    #[test]
    fn coarse_octaves_interpolate_the_lattice() {
        let f = Fbm::diamond_square(4, 3, &random_corners(4, 8), 1.0, 1.0, 2);
        // At the corner stride the sample is the bilinear mean of the corners.
        let mid = f.sample(4.0, 4.0, 3);
        let want = (f.at(0, 0) + f.at(8, 0) + f.at(0, 8) + f.at(8, 8)) / 4.0;
        assert!((mid - want).abs() < 1e-6);
        assert_eq!(f.sample(3.0, 5.0, 0), f.at(3, 5));
    }
}
