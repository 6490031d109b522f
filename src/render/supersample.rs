//! Supersampling: the mesh is filled without anti-aliasing (watertight), so smooth edges come
//! from drawing at `factor` times the size and filtering down.
//!
//! [`Downsample::Box`] (the default) averages each `factor x factor` block exactly: every
//! supersample counts once, which is what SSAA means. [`Downsample::Bicubic`] uses tiny-skia's
//! bicubic filter: slightly sharper edges at factor 2, but it reads only a 4x4 neighbourhood,
//! so at factors 3 and 4 it skips samples and lets some aliasing through.

use rayon::prelude::*;
use tiny_skia::{FilterQuality, Pixmap, PixmapPaint, Transform};

/// How a supersampled picture is filtered down.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Downsample {
    /// The mean of each block (exact SSAA).
    #[default]
    Box,
    /// tiny-skia's bicubic filter.
    Bicubic,
}

/// Filters `src` (`factor` times the size of `dst` in each direction) into `dst`.
///
/// # Panics
/// When the sizes do not match (a programming error).
pub fn downsample(src: &Pixmap, factor: u32, filter: Downsample, dst: &mut Pixmap) {
    assert_eq!((src.width(), src.height()), (dst.width() * factor, dst.height() * factor), "supersample sizes");
    if factor == 1 {
        dst.data_mut().copy_from_slice(src.data());
        return;
    }
    match filter {
        Downsample::Box => box_filter(src, factor as usize, dst),
        Downsample::Bicubic => {
            dst.fill(tiny_skia::Color::TRANSPARENT);
            let paint = PixmapPaint { quality: FilterQuality::Bicubic, ..PixmapPaint::default() };
            let s = 1.0 / factor as f32;
            dst.draw_pixmap(0, 0, src.as_ref(), &paint, Transform::from_scale(s, s), None);
            // The filter fades the outermost pixels against transparency; the picture is opaque.
            for p in dst.pixels_mut() {
                if p.alpha() != 255 && p.alpha() != 0 {
                    let c = p.demultiply();
                    *p = tiny_skia::PremultipliedColorU8::from_rgba(c.red(), c.green(), c.blue(), 255).unwrap();
                }
            }
        }
    }
}

fn box_filter(src: &Pixmap, f: usize, dst: &mut Pixmap) {
    match f {
        2 => box_swar::<2>(src, dst),
        3 => box_n::<3>(src, dst),
        4 => box_swar::<4>(src, dst),
        _ => unreachable!("supersampling factors are 1..=4"),
    }
}

/// The block mean for F = 2 or 4, two channels at a time in one u32 ("SIMD within a
/// register"): red and blue in the low bytes of each half, green and alpha shifted down. A
/// channel's sum of at most 16 x 255 (+ rounding) fits the 16 bits it has, and dividing by
/// F² = 4 or 16 is a shift, so this is exactly `(sum + F²/2) / F²` per channel.
fn box_swar<const F: usize>(src: &Pixmap, dst: &mut Pixmap) {
    const MASK: u32 = 0x00FF_00FF;
    let shift = (F * F).trailing_zeros();
    let round = ((F * F / 2) as u32) * 0x0001_0001;
    let (dw, sw) = (dst.width() as usize, src.width() as usize);
    let data = src.data();
    dst.data_mut().par_chunks_exact_mut(dw * 4).enumerate().for_each(|(dy, out_row)| {
        for (dx, out) in out_row.chunks_exact_mut(4).enumerate() {
            let (mut lo, mut hi) = (round, round);
            for sy in dy * F..(dy + 1) * F {
                let start = (sy * sw + dx * F) * 4;
                for px in data[start..start + 4 * F].chunks_exact(4) {
                    let p = u32::from_le_bytes([px[0], px[1], px[2], px[3]]);
                    lo += p & MASK;
                    hi += (p >> 8) & MASK;
                }
            }
            let p = ((lo >> shift) & MASK) | (((hi >> shift) & MASK) << 8);
            out.copy_from_slice(&p.to_le_bytes());
        }
    });
}

/// The block mean for any F, channel by channel.
fn box_n<const F: usize>(src: &Pixmap, dst: &mut Pixmap) {
    let (dw, sw) = (dst.width() as usize, src.width() as usize);
    let data = src.data();
    let n = (F * F) as u32;
    dst.data_mut().par_chunks_exact_mut(dw * 4).enumerate().for_each(|(dy, out_row)| {
        for (dx, out) in out_row.chunks_exact_mut(4).enumerate() {
            let mut sum = [0u32; 4];
            for sy in dy * F..(dy + 1) * F {
                let start = (sy * sw + dx * F) * 4;
                for px in data[start..start + 4 * F].chunks_exact(4) {
                    for c in 0..4 {
                        sum[c] += u32::from(px[c]);
                    }
                }
            }
            for c in 0..4 {
                out[c] = ((sum[c] + n / 2) / n) as u8;
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use tiny_skia::PremultipliedColorU8;

    fn checker(w: u32, h: u32) -> Pixmap {
        let mut p = Pixmap::new(w, h).unwrap();
        for (i, px) in p.pixels_mut().iter_mut().enumerate() {
            let v = if (i as u32 % w + i as u32 / w).is_multiple_of(2) { 200 } else { 100 };
            *px = PremultipliedColorU8::from_rgba(v, v / 2, 10, 255).unwrap();
        }
        p
    }

    #[test]
    fn swar_matches_the_plain_mean() {
        let mut src = Pixmap::new(12, 8).unwrap();
        for (i, px) in src.pixels_mut().iter_mut().enumerate() {
            let v = (i * 37 % 256) as u8;
            *px = PremultipliedColorU8::from_rgba(v / 2, v, v / 3, 255).unwrap();
        }
        for f in [2u32, 4] {
            let (mut a, mut b) = (Pixmap::new(12 / f, 8 / f).unwrap(), Pixmap::new(12 / f, 8 / f).unwrap());
            if f == 2 {
                box_swar::<2>(&src, &mut a);
                box_n::<2>(&src, &mut b);
            } else {
                box_swar::<4>(&src, &mut a);
                box_n::<4>(&src, &mut b);
            }
            assert_eq!(a.data(), b.data(), "factor {f}");
        }
    }

    #[test]
    fn box_averages_blocks_exactly() {
        let src = checker(8, 6);
        let mut dst = Pixmap::new(4, 3).unwrap();
        downsample(&src, 2, Downsample::Box, &mut dst);
        assert!(dst.pixels().iter().all(|p| (p.red(), p.green(), p.blue(), p.alpha()) == (150, 75, 10, 255)));
        let mut one = Pixmap::new(8, 6).unwrap();
        downsample(&src, 1, Downsample::Box, &mut one);
        assert_eq!(one.data(), src.data());
    }

    #[test]
    fn bicubic_keeps_the_picture_opaque_and_close() {
        let src = checker(12, 12);
        let mut dst = Pixmap::new(4, 4).unwrap();
        downsample(&src, 3, Downsample::Bicubic, &mut dst);
        for p in dst.pixels() {
            assert_eq!(p.alpha(), 255);
            assert!((100..=200).contains(&p.red()));
        }
    }
}
