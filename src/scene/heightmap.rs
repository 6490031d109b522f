//! A scene's heights on a grid: what `--heightmap` writes and game engines read.

use crate::output::heightmap::{encode_npy_shaped, encode_png16};

/// A grid of heights, row-major, row 0 = the top of the picture (or the north edge).
#[derive(Clone, Debug, PartialEq)]
pub struct Heightmap {
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
    /// `width * height` values in the scene's unit (pool: raw amplitude; ocean/lake: metres).
    pub values: Vec<f32>,
    /// 16-bit PNG levels per unit (pool: 1, the raw amplitude; ocean: 100, centimetres; lake:
    /// 1000, millimetres).
    pub png_levels_per_unit: f32,
}

impl Heightmap {
    /// NPY format 1.0: `{'descr': '<f4', 'fortran_order': False, 'shape': (H, W), }`,
    /// space-padded so the data starts at a multiple of 64 bytes, then little-endian float32s.
    pub fn to_npy(&self) -> Vec<u8> {
        encode_npy_shaped(&[self.height, self.width], &self.values)
    }

    /// A 16-bit greyscale PNG where a pixel is `round(value · png_levels_per_unit) + 32768`,
    /// clamped to 0..=65535.
    pub fn to_png16(&self) -> Vec<u8> {
        encode_png16(self.width, self.height, &self.values, self.png_levels_per_unit)
    }
}
