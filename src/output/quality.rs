//! How close a terminal's screen is to the picture it should show, measured like a codec:
//! PSNR over 8-bit sRGB and the mean OKLab distance, both halves of every picture cell.
//!
//! The screen is a [`crate::output::vt::TerminalModel`] fed the encoder's bytes. A pixel it shows in
//! the terminal's default colour, or under a glyph that is not a half block, counts as
//! [`UNKNOWN_PIXEL`] (black, the usual terminal background): a screen that was never painted
//! scores as a black picture.

use tiny_skia::Pixmap;

use crate::output::halfblock::{Rgb, pixel_rgb};
use crate::output::oklab;
use crate::output::ssim::Luma;
use crate::output::vt::TerminalModel;

/// What a pixel the screen does not show as a half-block colour counts as.
pub const UNKNOWN_PIXEL: Rgb = [0, 0, 0];
/// The PSNR reported for an exact picture (whose PSNR is infinite), in dB.
pub const EXACT_PSNR_DB: f64 = 99.0;

/// The error of one screen against its picture.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Quality {
    /// Mean squared error per channel, in 8-bit steps squared.
    pub mse: f64,
    /// Mean OKLab distance per pixel.
    pub oklab: f64,
    /// Pixels compared.
    pub pixels: usize,
}

impl Quality {
    /// The peak signal-to-noise ratio in dB, `EXACT_PSNR_DB` when the picture is exact.
    pub fn psnr(&self) -> f64 {
        psnr(self.mse)
    }
}

/// PSNR in dB of a mean squared error over 8-bit channels ([`EXACT_PSNR_DB`] for 0).
pub fn psnr(mse: f64) -> f64 {
    if mse <= 0.0 { EXACT_PSNR_DB } else { (10.0 * (255.0 * 255.0 / mse).log10()).min(EXACT_PSNR_DB) }
}

/// Compares the half-block pixels of `screen` with `truth`, drawn from the screen's top-left
/// corner (two pixel rows a text row). Only the picture's pixels count, so rows below it (the
/// status line) are left out.
pub fn measure(screen: &TerminalModel, truth: &Pixmap) -> Quality {
    let (w, h) = (truth.width() as usize, truth.height() as usize);
    let (mut squared, mut distance) = (0f64, 0f64);
    for y in 0..h {
        for x in 0..w {
            let want = pixel_rgb(truth, x as u32, y as u32);
            let shown = screen.pixel(x, y).unwrap_or(UNKNOWN_PIXEL);
            if shown == want {
                continue;
            }
            squared += want.iter().zip(shown).map(|(&a, b)| (f64::from(a) - f64::from(b)).powi(2)).sum::<f64>();
            distance += f64::from(oklab::from_rgb(want).distance(oklab::from_rgb(shown)));
        }
    }
    let pixels = w * h;
    Quality { mse: squared / (3 * pixels).max(1) as f64, oklab: distance / pixels.max(1) as f64, pixels }
}

/// The luma `screen` shows over a `width x height` picture drawn from its top-left corner (two
/// pixel rows a text row), for SSIM: what the terminal shows, against the true frame. Pixels it
/// does not show as half-block colours count as black, as in [`measure`].
pub fn screen_luma(screen: &TerminalModel, width: usize, height: usize) -> Luma {
    Luma::from_fn(width, height, |x, y| screen.pixel(x, y).unwrap_or(UNKNOWN_PIXEL))
}

#[cfg(test)]
mod tests {
    use super::*;
    use tiny_skia::ColorU8;

    fn grey(w: u32, h: u32, v: u8) -> Pixmap {
        let mut p = Pixmap::new(w, h).unwrap();
        p.pixels_mut().fill(ColorU8::from_rgba(v, v, v, 255).premultiply());
        p
    }

    #[test]
    fn an_exact_screen_and_a_known_error() {
        let truth = grey(2, 2, 100);
        let mut screen = TerminalModel::new(2, 2);
        screen.feed("\x1b[38;2;100;100;100;48;2;100;100;100m\u{2580}\u{2580}".as_bytes());
        let exact = measure(&screen, &truth);
        assert_eq!((exact.mse, exact.oklab, exact.psnr()), (0.0, 0.0, EXACT_PSNR_DB));
        // One of the four pixels 10 steps off in every channel: MSE 100 / 4 = 25.
        let mut screen = TerminalModel::new(2, 2);
        screen.feed("\x1b[38;2;110;110;110;48;2;100;100;100m\u{2580}\x1b[38;2;100;100;100m\u{2580}".as_bytes());
        let q = measure(&screen, &truth);
        assert_eq!(q.mse, 25.0);
        assert!((q.psnr() - 34.15).abs() < 0.01, "{}", q.psnr());
        assert!(q.oklab > 0.0 && q.oklab < f64::from(oklab::JND));
        // The screen's luma: the exact screen's is the picture's; the other differs in one pixel.
        let exact = screen_luma(&TerminalModel::new(2, 2), 2, 2);
        assert_eq!(exact.get(0, 0), 0.0, "an empty screen is black");
        let shown = screen_luma(&screen, 2, 2);
        assert_eq!(shown, Luma::from_fn(2, 2, |x, y| if (x, y) == (0, 0) { [110; 3] } else { [100; 3] }));
    }

    #[test]
    fn unpainted_pixels_count_as_black_and_the_status_row_is_left_out() {
        let truth = grey(3, 2, 255);
        let mut screen = TerminalModel::new(3, 2);
        screen.feed(b"\x1b[2;1Hstatus");
        let q = measure(&screen, &truth);
        assert_eq!(q.mse, 255.0 * 255.0);
        assert_eq!(q.psnr(), 0.0);
        assert_eq!(q.pixels, 6);
    }
}
