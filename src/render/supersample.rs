//! Supersampling: the mesh is filled without anti-aliasing (watertight), so smooth edges come
//! from drawing at `factor` times the size and filtering down.
//!
//! [`Downsample::Box`] (the default) averages each `factor x factor` block exactly: every
//! supersample counts once, which is what SSAA means. [`Downsample::Bicubic`] uses tiny-skia's
//! bicubic filter: slightly sharper edges at factor 2, but it reads only a 4x4 neighbourhood,
//! so at factors 3 and 4 it skips samples and lets some aliasing through.

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
        2 => box_n::<2>(src, dst),
        3 => box_n::<3>(src, dst),
        4 => box_n::<4>(src, dst),
        _ => unreachable!("supersampling factors are 1..=4"),
    }
}

/// The block mean for a factor known at compile time: rows are summed in u16 (at most
/// 16 x 255), a block of F pixels at a time, so the loops unroll and vectorise.
fn box_n<const F: usize>(src: &Pixmap, dst: &mut Pixmap) {
    let (dw, sw) = (dst.width() as usize, src.width() as usize);
    let data = src.data();
    let n = (F * F) as u32;
    let mut sums = vec![0u16; dw * 4];
    for (dy, out_row) in dst.data_mut().chunks_exact_mut(dw * 4).enumerate() {
        sums.fill(0);
        for sy in dy * F..(dy + 1) * F {
            let row = &data[sy * sw * 4..(sy + 1) * sw * 4];
            for (sum, block) in sums.chunks_exact_mut(4).zip(row.chunks_exact(4 * F)) {
                for px in block.chunks_exact(4) {
                    for c in 0..4 {
                        sum[c] += u16::from(px[c]);
                    }
                }
            }
        }
        for (o, &s) in out_row.iter_mut().zip(&sums) {
            *o = ((u32::from(s) + n / 2) / n) as u8;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tiny_skia::PremultipliedColorU8;

    fn checker(w: u32, h: u32) -> Pixmap {
        let mut p = Pixmap::new(w, h).unwrap();
        for (i, px) in p.pixels_mut().iter_mut().enumerate() {
            let v = if (i as u32 % w + i as u32 / w) % 2 == 0 { 200 } else { 100 };
            *px = PremultipliedColorU8::from_rgba(v, v / 2, 10, 255).unwrap();
        }
        p
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
