//! Packing RGB pixels for the wire: zlib, PNG and JPEG into reused buffers.
//!
//! kitty takes raw RGB under zlib (`o=z`) or a PNG (`f=100`); iTerm2 takes any file format it
//! can decode, PNG or JPEG. Which costs fewer bytes depends on the picture and the link: on
//! rendered water PNG's row filters beat plain zlib by a quarter to a third, and JPEG at a
//! middling quality is several times smaller again, lossy. The stream
//! ([`crate::output::graphics::stream`]) chooses among them per frame; these functions only
//! pack.

use crate::output::graphics::deflate::Zlib;
use crate::output::graphics::{lossy_png, palette_png};

/// How a picture's pixels are packed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Packing {
    /// Raw RGB under zlib at this level (1..=9): kitty's `f=24,o=z`.
    Zlib(u8),
    /// A PNG of the RGB pixels (row filters chosen per row, fast deflate): kitty's `f=100`,
    /// iTerm2.
    Png,
    /// A baseline JPEG at this quality (1..=100): iTerm2 only (kitty decodes no JPEG); the
    /// picture stream chooses it (feature `player`).
    #[cfg_attr(not(any(test, feature = "player", feature = "testing")), allow(dead_code))]
    Jpeg(u8),
    /// A lossy PNG, differences rounded to this step (`output::graphics::lossy_png`):
    /// kitty's `f=100` under a rate.
    #[cfg_attr(not(any(test, feature = "player", feature = "testing")), allow(dead_code))]
    LossyPng(u8),
    /// An indexed PNG of at most this many colours fitted to the scene
    /// (`output::graphics::palette_png`): kitty's `f=100` under a rate.
    #[cfg_attr(not(any(test, feature = "player", feature = "testing")), allow(dead_code))]
    PalettePng(u16),
}

impl Packing {
    /// Whether the packing is one of kitty's lossy PNGs, whose encoder rewrites the pixels to
    /// what the terminal will show (the stream's model of the terminal is then exact).
    pub fn rewrites_pixels(self) -> bool {
        matches!(self, Packing::LossyPng(_) | Packing::PalettePng(_))
    }

    #[cfg(any(test, feature = "testing"))]
    /// A short name for tables and the status line.
    pub fn name(self) -> String {
        match self {
            Packing::Zlib(level) => format!("zlib{level}"),
            Packing::Png => "png".to_string(),
            Packing::Jpeg(q) => format!("jpeg{q}"),
            Packing::LossyPng(q) => format!("png/{q}"),
            Packing::PalettePng(n) => format!("png{n}c"),
        }
    }
}

/// Packs `rgb` (`width x height`, 3 bytes a pixel, row-major) into `out` (cleared first).
///
/// # Panics
/// When `rgb` does not hold `width x height` pixels.
pub fn pack(packing: Packing, rgb: &[u8], width: u32, height: u32, out: &mut Vec<u8>) {
    assert_eq!(rgb.len(), width as usize * height as usize * 3, "RGB buffer does not match {width}x{height}");
    out.clear();
    match packing {
        Packing::Zlib(level) => zlib(rgb, level, out),
        Packing::Png => {
            let mut encoder = png::Encoder::new(&mut *out, width, height);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            encoder.set_compression(png::Compression::Fast);
            let mut writer = encoder.write_header().expect("a PNG header in memory");
            writer.write_image_data(rgb).expect("the pixels match the header");
            writer.finish().expect("writing into memory cannot fail");
        }
        Packing::LossyPng(q) => {
            // The caller that keeps the pixels the decoder shows calls `lossy_png::encode`.
            lossy_png::encode(&mut rgb.to_vec(), width, height, q, out);
        }
        Packing::PalettePng(colours) => palette_png::encode(&mut rgb.to_vec(), width, height, colours, out),
        Packing::Jpeg(quality) => {
            image::codecs::jpeg::JpegEncoder::new_with_quality(&mut *out, quality.clamp(1, 100))
                .encode(rgb, width, height, image::ExtendedColorType::Rgb8)
                .expect("a JPEG of valid RGB in memory");
        }
    }
}

/// `data` under zlib at `level` (1..=9) into `out` (cleared first; its allocation reused).
pub fn zlib(data: &[u8], level: u8, out: &mut Vec<u8>) {
    Zlib::default().compress(data, u32::from(level), out);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::graphics::test_pictures::golden_pool;

    #[test]
    fn lossless_packings_round_trip_and_jpeg_stays_close() {
        let (w, h, rgb) = golden_pool();
        let mut out = Vec::new();
        pack(Packing::Zlib(1), &rgb, w, h, &mut out);
        let mut back = Vec::new();
        std::io::Read::read_to_end(&mut flate2::read::ZlibDecoder::new(&out[..]), &mut back).unwrap();
        assert!(back == rgb, "zlib round trip");
        let zlib = out.len();
        pack(Packing::Png, &rgb, w, h, &mut out);
        let png = out.len();
        assert!(image::load_from_memory(&out).unwrap().to_rgb8().into_raw() == rgb, "PNG round trip");
        pack(Packing::Jpeg(60), &rgb, w, h, &mut out);
        let jpeg = out.len();
        let decoded = image::load_from_memory(&out).unwrap().to_rgb8().into_raw();
        let mean_error =
            decoded.iter().zip(&rgb).map(|(a, b)| f64::from(a.abs_diff(*b))).sum::<f64>() / rgb.len() as f64;
        assert!(mean_error < 6.0, "JPEG 60 stays near the picture: {mean_error}");
        assert!(png < zlib && jpeg < png, "zlib {zlib}, PNG {png}, JPEG {jpeg} bytes");
    }
}
