//! Structural similarity (SSIM) of luma: how alike two pictures look in structure, the measure
//! the codec benchmarks report beside PSNR (PSNR punishes a one-pixel shift of a sharp ripple as
//! much as noise; SSIM reads what the eye reads: local contrast and structure).
//!
//! Wang, Bovik, Sheikh and Simoncelli (2004), as usually computed: luma (BT.601 weights over
//! 8-bit sRGB), local statistics under an 11x11 Gaussian window of sigma 1.5, constants
//! `C1 = (0.01 * 255)²` and `C2 = (0.03 * 255)²`, the mean of the SSIM map. Near the edges the
//! window is cut to the picture and its weights renormalised, so every pixel counts (a terminal
//! picture is only ~100 pixels tall: dropping a 5-pixel border would drop a tenth of it).

use tiny_skia::Pixmap;

/// The Gaussian window's standard deviation, in pixels.
pub const SIGMA: f64 = 1.5;
/// The window's radius, in pixels (11 taps).
const RADIUS: usize = 5;
const C1: f64 = (0.01 * 255.0) * (0.01 * 255.0);
const C2: f64 = (0.03 * 255.0) * (0.03 * 255.0);

/// A picture's luma, 0..=255 per pixel, row by row.
#[derive(Clone, Debug, PartialEq)]
pub struct Luma {
    width: usize,
    height: usize,
    values: Vec<f32>,
}

impl Luma {
    /// The luma of `width x height` pixels given by `rgb(x, y)`.
    pub fn from_fn(width: usize, height: usize, mut rgb: impl FnMut(usize, usize) -> [u8; 3]) -> Luma {
        let mut values = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                values.push(luma(rgb(x, y)));
            }
        }
        Luma { width, height, values }
    }

    /// The luma of an opaque picture.
    pub fn of_pixmap(pixmap: &Pixmap) -> Luma {
        let (w, h) = (pixmap.width() as usize, pixmap.height() as usize);
        let pixels = pixmap.pixels();
        Luma::from_fn(w, h, |x, y| {
            let c = pixels[y * w + x].demultiply();
            [c.red(), c.green(), c.blue()]
        })
    }

    /// The luma of packed RGB bytes (`width * height * 3` of them).
    ///
    /// # Panics
    /// When `rgb` is shorter than the picture.
    pub fn of_rgb(width: usize, height: usize, rgb: &[u8]) -> Luma {
        assert!(rgb.len() >= width * height * 3, "{} RGB bytes for {width}x{height}", rgb.len());
        Luma::from_fn(width, height, |x, y| {
            let i = 3 * (y * width + x);
            [rgb[i], rgb[i + 1], rgb[i + 2]]
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The luma at (`x`, `y`).
    pub fn get(&self, x: usize, y: usize) -> f32 {
        self.values[y * self.width + x]
    }
}

/// BT.601 luma of an 8-bit sRGB colour.
fn luma([r, g, b]: [u8; 3]) -> f32 {
    0.299 * f32::from(r) + 0.587 * f32::from(g) + 0.114 * f32::from(b)
}

/// The mean SSIM of two pictures of the same size: 1 for identical pictures, near 0 for
/// unrelated ones (it can go below 0 for anti-correlated structure).
///
/// # Panics
/// When the sizes differ.
pub fn ssim(a: &Luma, b: &Luma) -> f64 {
    SsimReference::new(a).ssim(b)
}

/// A picture's local means and variances under the window, kept to compare many pictures with
/// it (the codec benchmark compares every strategy's screen with the same true frame): the
/// [`ssim`] of `a` and `b` is `SsimReference::new(a).ssim(b)`, and each comparison blurs three
/// planes instead of five.
#[derive(Clone, Debug)]
pub struct SsimReference {
    luma: Luma,
    /// The local mean and variance of every pixel.
    mean: Vec<f64>,
    variance: Vec<f64>,
}

impl SsimReference {
    /// The statistics of `a`.
    pub fn new(a: &Luma) -> SsimReference {
        let (w, h) = (a.width, a.height);
        let kernel = gaussian();
        let mut scratch = vec![0f64; w * h];
        let mut mean: Vec<f64> = a.values.iter().map(|&v| f64::from(v)).collect();
        let mut square: Vec<f64> = a.values.iter().map(|&v| f64::from(v) * f64::from(v)).collect();
        if w > 0 && h > 0 {
            blur(&mut mean, &mut scratch, w, h, &kernel);
            blur(&mut square, &mut scratch, w, h, &kernel);
        }
        let variance = square.iter().zip(&mean).map(|(&s, &m)| (s - m * m).max(0.0)).collect();
        SsimReference { luma: a.clone(), mean, variance }
    }

    /// The mean SSIM of the reference picture and `b`.
    ///
    /// # Panics
    /// When the sizes differ.
    pub fn ssim(&self, b: &Luma) -> f64 {
        let a = &self.luma;
        assert_eq!((a.width, a.height), (b.width, b.height), "SSIM of pictures of different sizes");
        let (w, h) = (a.width, a.height);
        if w == 0 || h == 0 {
            return 1.0;
        }
        let kernel = gaussian();
        let n = w * h;
        let y: Vec<f64> = b.values.iter().map(|&v| f64::from(v)).collect();
        let yy: Vec<f64> = y.iter().map(|&v| v * v).collect();
        let xy: Vec<f64> = a.values.iter().zip(&y).map(|(&x, &y)| f64::from(x) * y).collect();
        let mut planes = [y, yy, xy];
        let mut scratch = vec![0f64; n];
        for plane in &mut planes {
            blur(plane, &mut scratch, w, h, &kernel);
        }
        let [my, yy, xy] = &planes;
        let mut total = 0.0;
        for i in 0..n {
            let (mx, my) = (self.mean[i], my[i]);
            let vx = self.variance[i];
            let vy = (yy[i] - my * my).max(0.0);
            let cov = xy[i] - mx * my;
            total += ((2.0 * mx * my + C1) * (2.0 * cov + C2)) / ((mx * mx + my * my + C1) * (vx + vy + C2));
        }
        total / n as f64
    }
}

/// The window's weights, from the centre out to [`RADIUS`].
fn gaussian() -> [f64; 2 * RADIUS + 1] {
    let mut k = [0.0; 2 * RADIUS + 1];
    for (i, w) in k.iter_mut().enumerate() {
        let d = i as f64 - RADIUS as f64;
        *w = (-d * d / (2.0 * SIGMA * SIGMA)).exp();
    }
    k
}

/// Blurs `plane` in place with the separable window, cut at the edges and renormalised.
fn blur(plane: &mut [f64], scratch: &mut [f64], w: usize, h: usize, k: &[f64; 2 * RADIUS + 1]) {
    for y in 0..h {
        let row = &plane[y * w..(y + 1) * w];
        for x in 0..w {
            let (lo, hi) = (x.saturating_sub(RADIUS), (x + RADIUS).min(w - 1));
            let (mut sum, mut weight) = (0.0, 0.0);
            for (j, &v) in row[lo..=hi].iter().enumerate() {
                let kw = k[lo + j + RADIUS - x];
                sum += kw * v;
                weight += kw;
            }
            scratch[y * w + x] = sum / weight;
        }
    }
    for x in 0..w {
        for y in 0..h {
            let (lo, hi) = (y.saturating_sub(RADIUS), (y + RADIUS).min(h - 1));
            let (mut sum, mut weight) = (0.0, 0.0);
            for yy in lo..=hi {
                let kw = k[yy + RADIUS - y];
                sum += kw * scratch[yy * w + x];
                weight += kw;
            }
            plane[y * w + x] = sum / weight;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pattern(w: usize, h: usize, mut f: impl FnMut(usize, usize) -> u8) -> Luma {
        Luma::from_fn(w, h, |x, y| {
            let v = f(x, y);
            [v, v, v]
        })
    }

    #[test]
    fn identical_pictures_score_one() {
        let a = pattern(40, 30, |x, y| ((x * 7 + y * 13) % 256) as u8);
        assert!((ssim(&a, &a) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_brightness_shift_costs_little_and_noise_costs_much() {
        let a = pattern(64, 48, |x, y| (128.0 + 60.0 * ((x as f64 / 4.0).sin() * (y as f64 / 5.0).cos())) as u8);
        let brighter = pattern(64, 48, |x, y| a.get(x, y) as u8 + 10);
        let mut seed = 12345u32;
        let noisy = pattern(64, 48, |x, y| {
            seed = seed.wrapping_mul(1_103_515_245).wrapping_add(12345);
            (a.get(x, y) + ((seed >> 16) % 61) as f32 - 30.0).clamp(0.0, 255.0) as u8
        });
        let (shift, noise) = (ssim(&a, &brighter), ssim(&a, &noisy));
        assert!(shift > 0.95, "a uniform +10 keeps the structure: {shift}");
        assert!(noise < 0.8, "noise of ±30 breaks it: {noise}");
    }

    #[test]
    fn a_flat_picture_against_structure_scores_low_and_the_measure_is_symmetric() {
        let stripes = pattern(32, 32, |x, _| if x % 4 < 2 { 40 } else { 210 });
        let flat = pattern(32, 32, |_, _| 125);
        let s = ssim(&stripes, &flat);
        assert!(s < 0.1, "{s}");
        assert!((s - ssim(&flat, &stripes)).abs() < 1e-12);
    }

    #[test]
    fn the_window_matches_the_usual_gaussian() {
        // The reference implementation's 11-tap window: exp(-d²/4.5), normalised; the centre
        // weight is 0.2660 of the sum.
        let k = gaussian();
        let centre = k[RADIUS] / k.iter().sum::<f64>();
        assert!((centre - 0.2660).abs() < 1e-3, "{centre}");
    }
}
