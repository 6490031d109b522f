//! OKLab (Björn Ottosson, 2020): a perceptual colour space in which Euclidean distance follows
//! how different two colours look. The rate-controlled encoder ([`crate::output::rate`]) and
//! the codec measurements ([`crate::output::quality`]) measure a cell's error in it.
//!
//! L runs from 0 (black) to 1 (white); a and b are the green-red and blue-yellow axes (about
//! ±0.3 for sRGB colours). A difference of [`JND`] is about the smallest anyone notices.
//!
//! The conversion is exact `f32` arithmetic with a table for the sRGB transfer curve and a cube
//! root by Newton's method from a bit-level first guess (three times faster than `cbrtf` and
//! within 2e-7 of it): only IEEE basic operations, so every machine gets the same bits and the
//! encoder's choices are deterministic.

use crate::output::halfblock::Rgb;

/// The just-noticeable difference in OKLab units: 0.02, the threshold CSS Color 4's gamut
/// mapping uses for "indistinguishable" (OKLab's L is scaled 0..1 where CIELAB's is 0..100,
/// and CIELAB's JND is about 2). One 8-bit sRGB step moves L by 0.002-0.004, so the JND is
/// roughly five to ten steps of one channel.
pub const JND: f32 = 0.02;

/// A colour in OKLab.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Lab {
    /// Perceived lightness, 0..=1.
    pub l: f32,
    /// Green (negative) to red (positive).
    pub a: f32,
    /// Blue (negative) to yellow (positive).
    pub b: f32,
}

impl Lab {
    /// The squared Euclidean distance (ΔE_OK²).
    #[inline]
    pub fn distance2(self, other: Lab) -> f32 {
        let (dl, da, db) = (self.l - other.l, self.a - other.a, self.b - other.b);
        dl * dl + da * da + db * db
    }

    #[cfg(any(test, feature = "testing"))]
    /// The Euclidean distance (ΔE_OK).
    pub fn distance(self, other: Lab) -> f32 {
        self.distance2(other).sqrt()
    }
}

/// The sRGB transfer curve, decoded: 8-bit value -> linear light.
static LINEAR: std::sync::LazyLock<[f32; 256]> = std::sync::LazyLock::new(|| {
    std::array::from_fn(|i| {
        let c = i as f64 / 255.0;
        let linear = if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) };
        linear as f32
    })
});

/// The cube root of `x >= 0`: a first guess from the float's bits (exponent divided by three,
/// within 4%), then two Newton steps (within 2e-6 relative).
#[inline]
fn cbrt(x: f32) -> f32 {
    if x <= 0.0 {
        return 0.0;
    }
    let mut y = f32::from_bits(x.to_bits() / 3 + 0x2a51_4067);
    for _ in 0..2 {
        y = (2.0 * y + x / (y * y)) * (1.0 / 3.0);
    }
    y
}

/// The OKLab of an 8-bit sRGB colour.
#[inline]
pub fn from_rgb([r, g, b]: Rgb) -> Lab {
    let table = &*LINEAR;
    let (r, g, b) = (table[r as usize], table[g as usize], table[b as usize]);
    let l = cbrt(0.412_221_46 * r + 0.536_332_55 * g + 0.051_445_995 * b);
    let m = cbrt(0.211_903_5 * r + 0.680_699_5 * g + 0.107_396_96 * b);
    let s = cbrt(0.088_302_46 * r + 0.281_718_85 * g + 0.629_978_7 * b);
    Lab {
        l: 0.210_454_26 * l + 0.793_617_8 * m - 0.004_072_047 * s,
        a: 1.977_998_5 * l - 2.428_592_2 * m + 0.450_593_7 * s,
        b: 0.025_904_037 * l + 0.782_771_77 * m - 0.808_675_77 * s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_root_matches_libm() {
        let mut worst = 0.0f32;
        for i in 0..=100_000 {
            let x = i as f32 / 100_000.0 * 1.2;
            let (fast, reference) = (cbrt(x), libm::cbrtf(x));
            worst = worst.max((fast - reference).abs());
        }
        assert!(worst < 2e-6, "{worst}");
        assert_eq!(cbrt(0.0), 0.0);
    }

    #[test]
    fn known_colours() {
        let close = |a: Lab, b: Lab| a.distance(b) < 2e-4;
        assert!(close(from_rgb([255, 255, 255]), Lab { l: 1.0, a: 0.0, b: 0.0 }), "{:?}", from_rgb([255; 3]));
        assert!(close(from_rgb([0, 0, 0]), Lab::default()));
        // Ottosson's published values for sRGB red, green and blue.
        assert!(close(from_rgb([255, 0, 0]), Lab { l: 0.627_955, a: 0.224_863, b: 0.125_846 }));
        assert!(close(from_rgb([0, 255, 0]), Lab { l: 0.866_440, a: -0.233_888, b: 0.179_498 }));
        assert!(close(from_rgb([0, 0, 255]), Lab { l: 0.452_014, a: -0.032_457, b: -0.311_528 }));
    }

    #[test]
    fn the_jnd_is_a_few_steps_of_8_bit() {
        let grey = from_rgb([128, 128, 128]);
        assert!(grey.distance(from_rgb([129, 128, 128])) < JND / 4.0);
        assert!(grey.distance(from_rgb([140, 140, 140])) > JND);
    }
}
