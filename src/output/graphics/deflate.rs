//! A zlib compressor kept from picture to picture (kitty's zlib pixels, the lossy PNG's
//! data): a new `flate2` compressor is a few hundred kilobytes of tables, allocated and zeroed
//! for every picture a stream sent.

use std::io::Write;

use flate2::Compression;
use flate2::write::ZlibEncoder;

/// A zlib compressor kept from picture to picture: [`crate::output::graphics::pack::zlib`]'s bytes without a new compressor
/// (a few hundred kilobytes of tables, allocated and zeroed) for every picture. Reset to a new
/// one's state before each picture and fed the same way (one `write_all`, then finished), so
/// the bytes are a new compressor's.
#[derive(Default)]
pub struct Zlib {
    /// The level it was made for, and the compressor (its output: an empty buffer between
    /// pictures, the caller's last allocation).
    encoder: Option<(u32, ZlibEncoder<Vec<u8>>)>,
}

impl std::fmt::Debug for Zlib {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Zlib").field("level", &self.encoder.as_ref().map(|(l, _)| *l)).finish()
    }
}

impl Zlib {
    /// `data` under zlib at `level` (clamped to 1..=9) into `out` (cleared first): the bytes
    /// of [`crate::output::graphics::pack::zlib`]. `out`'s allocation becomes the compressor's output for the next call.
    pub fn compress(&mut self, data: &[u8], level: u32, out: &mut Vec<u8>) {
        let level = level.clamp(1, 9);
        out.clear();
        let spare = std::mem::take(out);
        let z = match &mut self.encoder {
            Some((made, z)) if *made == level => {
                // Finished at the last call: the reset only clears the state (and hands back
                // the empty buffer left there).
                z.reset(spare).expect("writing into memory cannot fail");
                z
            }
            slot => &mut slot.insert((level, ZlibEncoder::new(spare, Compression::new(level)))).1,
        };
        z.write_all(data).expect("writing into memory cannot fail");
        z.try_finish().expect("writing into memory cannot fail");
        std::mem::swap(out, z.get_mut());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::graphics::test_pictures::golden_pool;

    /// A new compressor's bytes, as `pack::zlib` made them before.
    fn fresh(data: &[u8], level: u32) -> Vec<u8> {
        let mut z = ZlibEncoder::new(Vec::new(), Compression::new(level));
        z.write_all(data).unwrap();
        z.finish().unwrap()
    }

    #[test]
    fn a_kept_compressor_gives_a_new_ones_bytes() {
        let (_, _, rgb) = golden_pool();
        // Pictures of different sizes and contents one after another, and a change of level:
        // each must come out as a new compressor makes it (a stale dictionary, hash chain or
        // bit buffer would show as different bytes).
        let half = &rgb[..rgb.len() / 2];
        let shifted: Vec<u8> = rgb.iter().map(|b| b.wrapping_add(3)).collect();
        let mut zlib = Zlib::default();
        let mut out = vec![1, 2, 3];
        for (data, level) in [(&rgb[..], 1), (half, 1), (&shifted[..], 1), (&rgb[..], 4), (half, 4), (&[][..], 4)] {
            zlib.compress(data, level, &mut out);
            assert!(out == fresh(data, level), "{} bytes at level {level}", data.len());
        }
    }
}
