//! PNG encoding of a tiny-skia pixmap.

use image::ImageEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use tiny_skia::Pixmap;

/// Straight (un-premultiplied) RGBA bytes of a pixmap.
///
/// tiny-skia stores premultiplied colour; handing its bytes to a PNG encoder unconverted makes
/// every translucent pixel too dark.
pub fn straight_rgba(pixmap: &Pixmap) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(pixmap.data().len());
    for p in pixmap.pixels() {
        let c = p.demultiply();
        bytes.extend_from_slice(&[c.red(), c.green(), c.blue(), c.alpha()]);
    }
    bytes
}

/// Encodes a pixmap as PNG: RGB when every pixel is opaque (the usual case, a quarter smaller),
/// RGBA otherwise. The bytes depend only on the pixels.
pub fn encode(pixmap: &Pixmap) -> Vec<u8> {
    let rgba = straight_rgba(pixmap);
    let opaque = rgba.chunks_exact(4).all(|p| p[3] == 255);
    let (data, color) = if opaque {
        let rgb: Vec<u8> = rgba.chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect();
        (rgb, image::ExtendedColorType::Rgb8)
    } else {
        (rgba, image::ExtendedColorType::Rgba8)
    };
    let mut out = Vec::new();
    PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Adaptive)
        .write_image(&data, pixmap.width(), pixmap.height(), color)
        .expect("encoding a PNG into memory cannot fail for a valid pixmap");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use tiny_skia::ColorU8;

    #[test]
    fn premultiplied_pixels_are_un_premultiplied() {
        let mut pixmap = Pixmap::new(2, 1).unwrap();
        pixmap.pixels_mut()[0] = ColorU8::from_rgba(200, 100, 50, 128).premultiply();
        pixmap.pixels_mut()[1] = ColorU8::from_rgba(10, 20, 30, 255).premultiply();
        let bytes = straight_rgba(&pixmap);
        // Premultiplying loses a little precision at alpha 128; within 1 of the original.
        for (got, want) in bytes[..4].iter().zip([200u8, 100, 50, 128]) {
            assert!(got.abs_diff(want) <= 1, "{bytes:?}");
        }
        assert_eq!(&bytes[4..], &[10, 20, 30, 255]);
    }

    #[test]
    fn round_trips_through_the_decoder() {
        let mut pixmap = Pixmap::new(3, 2).unwrap();
        for (i, p) in pixmap.pixels_mut().iter_mut().enumerate() {
            *p = ColorU8::from_rgba(i as u8 * 40, 255 - i as u8, 7, 255).premultiply();
        }
        let png = encode(&pixmap);
        let decoded = image::load_from_memory(&png).unwrap().to_rgba8();
        assert_eq!(decoded.as_raw(), &straight_rgba(&pixmap));
        assert_eq!(decoded.dimensions(), (3, 2));
    }
}
