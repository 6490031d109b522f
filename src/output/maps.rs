//! Tileable sea maps for engines ([`crate::sim::patch::PatchMaps`]) as file bytes: this
//! module encodes, the caller writes (atomically) where it likes.
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
//! Row 0 is the north edge, columns run east; texel (r, c) is the point at (c, -r)·extent/N.
//! The maps are periodic: texel N is texel 0, so they tile without a seam. DirectX-style
//! engines (Unreal) want the normal map's green flipped.

use image::ImageEncoder;
use image::codecs::png::{CompressionType, FilterType, PngEncoder};

use super::heightmap::{Heightmap, encode_npy, encode_png16};
use crate::sim::patch::PatchMaps;

/// The refusal of maps sent to standard output (a command-line combination the binary checks).
pub const MAPS_TO_STDOUT: &str = "maps are files in a folder and cannot go to standard output; drop --out - or --maps";

/// Checks that `path` can hold maps: a folder, or nothing yet (it will be created).
pub fn check_folder(path: &std::path::Path) -> Result<(), String> {
    if path.exists() && !path.is_dir() {
        return Err(format!("'{}' is a file; maps go into a folder (it is created if missing)", path.display()));
    }
    Ok(())
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

/// Every file of `maps` as (name, bytes), in [`file_names`]' order.
pub fn encode_maps(maps: &PatchMaps, frame: Option<u32>) -> Vec<(String, Vec<u8>)> {
    let n = maps.size;
    let height = Heightmap { width: n, height: n, values: maps.height.clone() };
    let flat: Vec<f32> = maps.displacement.iter().flatten().copied().collect();
    let files = [
        encode_npy(&height),
        encode_png16(&height, MAP_PNG_SCALE),
        encode_npy_shape(&[n, n, 3], &flat),
        encode_png(n, image::ExtendedColorType::Rgb16, &to_levels16(&flat)),
        encode_png(n, image::ExtendedColorType::Rgb8, &normal_bytes(&maps.normal)),
        encode_png(n, image::ExtendedColorType::L8, &foam_bytes(&maps.foam)),
    ];
    file_names(frame).into_iter().zip(files).collect()
}

/// NPY 1.0 of float32s with any C-order shape.
pub fn encode_npy_shape(shape: &[usize], values: &[f32]) -> Vec<u8> {
    let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
    let tuple = if dims.len() == 1 { format!("({},)", dims[0]) } else { format!("({})", dims.join(", ")) };
    let dict = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {tuple}, }}");
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

/// Metres to 16-bit levels, native byte order (as `image` takes them).
fn to_levels16(values: &[f32]) -> Vec<u8> {
    let mut out = Vec::with_capacity(values.len() * 2);
    for &v in values {
        let level = ((v * MAP_PNG_SCALE).round() + 32768.0).clamp(0.0, 65535.0) as u16;
        out.extend_from_slice(&level.to_ne_bytes());
    }
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

fn encode_png(n: usize, colour: image::ExtendedColorType, bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    PngEncoder::new_with_quality(&mut out, CompressionType::Default, FilterType::Adaptive)
        .write_image(bytes, n as u32, n as u32, colour)
        .expect("encoding a PNG into memory cannot fail for a valid map");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn npy_shapes_and_pngs_decode() {
        let bytes = encode_npy_shape(&[2, 2, 3], &[0.5; 12]);
        let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        assert_eq!((10 + header_len) % 64, 0);
        assert!(std::str::from_utf8(&bytes[10..10 + header_len]).unwrap().contains("'shape': (2, 2, 3)"));
        assert_eq!(bytes.len(), 10 + header_len + 48);
        let maps = PatchMaps {
            size: 2,
            extent_m: 10.0,
            height: vec![0.0, 1.0, -1.0, 0.25],
            displacement: vec![[0.1, -0.2, 0.0]; 4],
            normal: vec![[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.6, 0.0, 0.8]],
            foam: vec![0.0, 1.0, 0.5, 2.0],
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
        let file = std::env::temp_dir().join("tidepool_maps_check_folder.txt");
        std::fs::write(&file, b"x").unwrap();
        assert!(check_folder(&file).unwrap_err().contains("is a file"));
        assert!(check_folder(&std::env::temp_dir()).is_ok());
        assert!(check_folder(&std::env::temp_dir().join("tidepool-no-such-folder")).is_ok());
        std::fs::remove_file(file).unwrap();
    }
}
