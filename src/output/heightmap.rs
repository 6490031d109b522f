//! Heights to bytes: NPY (float32, for numpy, Blender, game engines) and 16-bit grey PNG, from
//! plain values (a scene's `Heightmap` calls these).

use image::ImageEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};

/// NPY 1.0 of float32s in C order with any `shape` (whose product is `values.len()`).
pub fn encode_npy_shaped(shape: &[usize], values: &[f32]) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let tuple = if dims.len() == 1 { format!("({},)", dims[0]) } else { format!("({})", dims.join(", ")) };
    let dict = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {tuple}, }}");
    // magic (6) + version (2) + header length (2) + dict + padding + '\n' = multiple of 64.
    let unpadded = 10 + dict.len() + 1;
    let padding = unpadded.next_multiple_of(64) - unpadded;
    let header_len = dict.len() + padding + 1;
    let mut out = Vec::with_capacity(10 + header_len + values.len() * 4);
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header_len as u16).to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    out.resize(out.len() + padding, b' ');
    out.push(b'\n');
    for v in values {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

/// Encodes `width x height` values as a 16-bit greyscale PNG where a pixel is
/// `round(value · levels_per_unit) + 32768`, clamped to 0..=65535.
pub fn encode_png16(width: usize, height: usize, values: &[f32], levels_per_unit: f32) -> Vec<u8> {
    let samples = levels16(values, levels_per_unit);
    encode_map_png(width, height, image::ExtendedColorType::L16, &samples)
}

/// Values to 16-bit PNG levels, `round(v · scale) + 32768` clamped, in native byte order (as
/// `image` takes 16-bit samples; it writes PNG's big-endian).
pub(crate) fn levels16(values: &[f32], scale: f32) -> Vec<u8> {
    let mut samples = Vec::with_capacity(values.len() * 2);
    for &v in values {
        let level = ((v * scale).round() + 32768.0).clamp(0.0, 65535.0) as u16;
        samples.extend_from_slice(&level.to_ne_bytes());
    }
    samples
}

/// A PNG of `width x height` samples of `colour` (adaptive filters, default compression).
pub(crate) fn encode_map_png(width: usize, height: usize, colour: image::ExtendedColorType, samples: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    PngEncoder::new_with_quality(&mut out, CompressionType::Default, FilterType::Adaptive)
        .write_image(samples, width as u32, height as u32, colour)
        .expect("encoding a PNG into memory cannot fail for a valid map");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const SAMPLE: [f32; 6] = [0.0, 1.5, -2.0, 100.0, -32768.0, 40000.0];

    #[test]
    fn npy_header_is_aligned_and_exact() {
        let bytes = encode_npy_shaped(&[2, 3], &SAMPLE);
        assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
        let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + header_len) % 64, 0);
        let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
        assert!(header.starts_with("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }"));
        assert!(header.ends_with(" \n"));
        let data = &bytes[10 + header_len..];
        assert_eq!(data.len(), 6 * 4);
        assert_eq!(f32::from_le_bytes(data[4..8].try_into().unwrap()), 1.5);
    }

    #[test]
    fn png16_offsets_scales_and_clamps() {
        let png = encode_png16(3, 2, &SAMPLE, 1.0);
        let decoded = image::load_from_memory(&png).unwrap();
        let grey = decoded.as_luma16().expect("16-bit grey").as_raw().clone();
        assert_eq!(grey, vec![32768, 32770, 32766, 32868, 0, 65535]);
        let cm = encode_png16(1, 1, &[0.123], 100.0);
        assert_eq!(image::load_from_memory(&cm).unwrap().as_luma16().unwrap().as_raw(), &vec![32780]);
    }
}
