//! Tileable sea maps for engines as file bytes ([`MapFields`]: plain slices, so this module
//! knows nothing of the simulation that made them): this module encodes, the caller writes
//! (atomically) where it likes.
//!
//! | file | format | content |
//! |---|---|---|
//! | `height.npy` | float32 (N, N) | Eulerian height, m |
//! | `height.png` | 16-bit grey | round(height·100) + 32768: centimetres |
//! | `displacement.npy` | float32 (N, N, 3) | where the water resting at each texel is carried: east, north, up, m |
//! | `displacement.png` | 16-bit RGB | the same, round(·100) + 32768 per channel |
//! | `normal.png` | 8-bit RGB | unit normal of the height surface, OpenGL convention: R = east (+X), G = north (+Y, up the image), B = up; 128 = 0 |
//! | `foam.png` | 8-bit grey | foam cover, 0 = none, 255 = full |
//!
//! With `--map-format exr`, beside those, OpenEXR files of half floats (16-bit, scan lines,
//! ZIP-compressed: what Blender's ocean bake writes and Unreal and Unity import as vector
//! displacement), in metres and unit vectors, unscaled ([`encode_exr_maps`]):
//!
//! | file | channels | content |
//! |---|---|---|
//! | `height.exr` | Y | Eulerian height, m |
//! | `displacement.exr` | R, G, B | where the water resting at each texel is carried: east, north, up, m |
//! | `normal.exr` | R, G, B | unit normal (east, north, up), -1..=1 |
//! | `foam.exr` | Y | foam cover 0..=1 |
//!
//! Row 0 is the north edge, columns run east; texel (r, c) is the point at (c, -r)·extent/N.
//! The maps are periodic: texel N is texel 0, so they tile without a seam. DirectX-style
//! engines (Unreal) want the normal map's green flipped.

use exr::prelude::{Encoding, Image, SpecificChannels, WritableImage, f16};
use image::ImageEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use rayon::prelude::*;

use super::heightmap::{encode_npy_shaped, levels16};
use crate::sim::patch::PatchMaps;

/// The fields of one set of maps, each `size x size`, row-major, row 0 the north edge.
#[derive(Clone, Copy, Debug)]
pub struct MapFields<'a> {
    /// Points per side.
    pub size: usize,
    /// Eulerian height, m.
    pub height: &'a [f32],
    /// Where the water resting at each point is carried (east, north, up), m.
    pub displacement: &'a [[f32; 3]],
    /// Unit normal (east, north, up).
    pub normal: &'a [[f32; 3]],
    /// Foam cover 0..=1.
    pub foam: &'a [f32],
}

impl PatchMaps {
    /// Every file of these maps as (name, bytes): `.npy` arrays and 16-bit PNGs of the height,
    /// displacement, normal and foam (names from `file_names`; with `frame`, each name gets
    /// `_NNNN` before its extension).
    pub fn files(&self, frame: Option<u32>) -> Vec<(String, Vec<u8>)> {
        encode_maps(&self.fields(), frame)
    }

    /// The same maps as OpenEXR files (half floats, lossless ZIP), for renderers that read
    /// EXR.
    pub fn exr_files(&self, frame: Option<u32>) -> Vec<(String, Vec<u8>)> {
        encode_exr_maps(&self.fields(), frame)
    }

    /// A borrowed view of the fields, the form the encoders take.
    fn fields(&self) -> MapFields<'_> {
        MapFields {
            size: self.size,
            height: &self.height,
            displacement: &self.displacement,
            normal: &self.normal,
            foam: &self.foam,
        }
    }
}

/// PNG levels per metre for heights and displacements: centimetres.
pub const MAP_PNG_SCALE: f32 = 100.0;

/// The file names of one set of maps; with `frame`, each gets `_NNNN` before its extension.
pub fn file_names(frame: Option<u32>) -> [String; 6] {
    let name = |stem: &str, ext: &str| match frame {
        Some(k) => format!("{stem}_{k:04}.{ext}"),
        None => format!("{stem}.{ext}"),
    };
    [
        name("height", "npy"),
        name("height", "png"),
        name("displacement", "npy"),
        name("displacement", "png"),
        name("normal", "png"),
        name("foam", "png"),
    ]
}

/// Every file of `maps` as (name, bytes), in `file_names`' order.
///
/// # Panics
/// When a field does not hold `size x size` values (a programming error).
pub fn encode_maps(maps: &MapFields<'_>, frame: Option<u32>) -> Vec<(String, Vec<u8>)> {
    let n = maps.size;
    for len in [maps.height.len(), maps.displacement.len(), maps.normal.len(), maps.foam.len()] {
        assert_eq!(len, n * n, "every map holds size x size values");
    }
    let displacement = maps.displacement.as_flattened();
    // The six files on all cores (each is encoded alone: the bytes do not depend on how).
    let files: Vec<Vec<u8>> = (0..6)
        .into_par_iter()
        .map(|i| match i {
            0 => encode_npy_shaped(&[n, n], maps.height),
            1 => map_png(n, image::ExtendedColorType::L16, &levels16(maps.height, MAP_PNG_SCALE)),
            2 => encode_npy_shaped(&[n, n, 3], displacement),
            3 => map_png(n, image::ExtendedColorType::Rgb16, &levels16(displacement, MAP_PNG_SCALE)),
            4 => map_png(n, image::ExtendedColorType::Rgb8, &normal_bytes(maps.normal)),
            _ => map_png(n, image::ExtendedColorType::L8, &foam_bytes(maps.foam)),
        })
        .collect();
    file_names(frame).into_iter().zip(files).collect()
}

/// The OpenEXR files of `maps` as (name, bytes): height, displacement, normal and foam in half
/// floats; with `frame`, each name gets `_NNNN` before its extension.
///
/// # Panics
/// When a field does not hold `size x size` values (a programming error).
pub fn encode_exr_maps(maps: &MapFields<'_>, frame: Option<u32>) -> Vec<(String, Vec<u8>)> {
    let n = maps.size;
    for len in [maps.height.len(), maps.displacement.len(), maps.normal.len(), maps.foam.len()] {
        assert_eq!(len, n * n, "every map holds size x size values");
    }
    let name = |stem: &str| match frame {
        Some(k) => format!("{stem}_{k:04}.exr"),
        None => format!("{stem}.exr"),
    };
    let files: Vec<Vec<u8>> = (0..4)
        .into_par_iter()
        .map(|i| match i {
            0 => exr_grey(n, maps.height),
            1 => exr_rgb(n, maps.displacement),
            2 => exr_rgb(n, maps.normal),
            _ => exr_grey(n, maps.foam),
        })
        .collect();
    ["height", "displacement", "normal", "foam"].iter().map(|s| name(s)).zip(files).collect()
}

/// The EXR encoding of the maps: ZIP over 16 scan lines, top row first (lossless, and read by
/// every EXR reader).
const EXR_ENCODING: Encoding = Encoding::SMALL_LOSSLESS;

/// A one-channel (Y) half-float EXR of an `n x n` field.
fn exr_grey(n: usize, values: &[f32]) -> Vec<u8> {
    let channels = SpecificChannels::build()
        .with_channel("Y")
        .with_pixel_fn(|p: exr::math::Vec2<usize>| (f16::from_f32(values[p.y() * n + p.x()]),));
    let mut out = std::io::Cursor::new(Vec::new());
    let image = Image::from_encoded_channels((n, n), EXR_ENCODING, channels);
    image.write().non_parallel().to_buffered(&mut out).expect("encoding an EXR into memory cannot fail");
    out.into_inner()
}

/// A three-channel (R, G, B) half-float EXR of an `n x n` vector field.
fn exr_rgb(n: usize, values: &[[f32; 3]]) -> Vec<u8> {
    let channels = SpecificChannels::rgb(|p: exr::math::Vec2<usize>| {
        let [r, g, b] = values[p.y() * n + p.x()];
        (f16::from_f32(r), f16::from_f32(g), f16::from_f32(b))
    });
    let mut out = std::io::Cursor::new(Vec::new());
    let image = Image::from_encoded_channels((n, n), EXR_ENCODING, channels);
    image.write().non_parallel().to_buffered(&mut out).expect("encoding an EXR into memory cannot fail");
    out.into_inner()
}

/// An `n x n` map as PNG with fast compression (maps are noisy; the best compression saved
/// a few per cent and cost most of a series' time).
fn map_png(n: usize, colour: image::ExtendedColorType, samples: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Adaptive)
        .write_image(samples, n as u32, n as u32, colour)
        .expect("encoding a PNG into memory cannot fail for a valid map");
    out
}

/// Unit normals to 8-bit RGB: round((v + 1)·127.5).
pub fn normal_bytes(normals: &[[f32; 3]]) -> Vec<u8> {
    normals.iter().flat_map(|n| n.map(|v| ((v.clamp(-1.0, 1.0) + 1.0) * 127.5).round() as u8)).collect()
}

/// Foam cover to 8-bit grey.
pub fn foam_bytes(foam: &[f32]) -> Vec<u8> {
    foam.iter().map(|&f| (f.clamp(0.0, 1.0) * 255.0).round() as u8).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn npy_shapes_and_pngs_decode() {
        let bytes = encode_npy_shaped(&[2, 2, 3], &[0.5; 12]);
        let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + header_len) % 64, 0);
        assert!(std::str::from_utf8(&bytes[10..10 + header_len]).unwrap().contains("'shape': (2, 2, 3)"));
        assert_eq!(bytes.len(), 10 + header_len + 48);
        let maps = MapFields {
            size: 2,
            height: &[0.0, 1.0, -1.0, 0.25],
            displacement: &[[0.1, -0.2, 0.0]; 4],
            normal: &[[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.6, 0.0, 0.8]],
            foam: &[0.0, 1.0, 0.5, 2.0],
        };
        let files = encode_maps(&maps, Some(7));
        assert_eq!(files[4].0, "normal_0007.png");
        let normal = image::load_from_memory(&files[4].1).unwrap().to_rgb8();
        assert_eq!(normal.get_pixel(0, 0).0, [128, 128, 255]);
        assert_eq!(normal.get_pixel(1, 0).0, [255, 128, 128]);
        assert_eq!(normal.get_pixel(0, 1).0, [128, 0, 128]);
        let foam = image::load_from_memory(&files[5].1).unwrap().to_luma8();
        assert_eq!(foam.as_raw(), &vec![0, 255, 128, 255]);
        let disp = image::load_from_memory(&files[3].1).unwrap();
        assert_eq!(disp.as_rgb16().unwrap().get_pixel(1, 1).0, [32778, 32748, 32768]);
        assert_eq!(file_names(None)[0], "height.npy");
    }
}
