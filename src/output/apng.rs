//! Animated PNG (APNG): lossless frames, read by every current browser; plain viewers show the
//! first frame. Written frame by frame through the `png` crate (already used by `image`).

use std::io::Write;

use tiny_skia::Pixmap;

/// Writes APNG frames to `W` as they come.
pub struct ApngWriter<W: Write> {
    writer: png::Writer<W>,
    rgb: Vec<u8>,
}

impl<W: Write> ApngWriter<W> {
    /// An animation of exactly `frames` frames of `width x height` at `fps`, looping forever.
    pub fn new(out: W, width: u32, height: u32, frames: u32, fps: u32) -> std::io::Result<ApngWriter<W>> {
        let mut encoder = png::Encoder::new(out, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::Fast);
        encoder.set_animated(frames.max(1), 0).map_err(png_error)?;
        encoder.set_frame_delay(1, fps.clamp(1, u32::from(u16::MAX)) as u16).map_err(png_error)?;
        let writer = encoder.write_header().map_err(png_error)?;
        Ok(ApngWriter { writer, rgb: Vec::with_capacity(width as usize * height as usize * 3) })
    }

    /// Appends a frame.
    pub fn write(&mut self, pixmap: &Pixmap) -> std::io::Result<()> {
        self.rgb.clear();
        for p in pixmap.pixels() {
            let c = p.demultiply();
            self.rgb.extend_from_slice(&[c.red(), c.green(), c.blue()]);
        }
        self.writer.write_image_data(&self.rgb).map_err(png_error)
    }

    /// Ends the file (all announced frames must have been written).
    pub fn finish(self) -> std::io::Result<()> {
        self.writer.finish().map_err(png_error)
    }
}

fn png_error(e: png::EncodingError) -> std::io::Error {
    match e {
        png::EncodingError::IoError(io) => io,
        other => std::io::Error::other(other.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_round_trip() {
        let mut frames = Vec::new();
        for k in 0..3u8 {
            let mut p = Pixmap::new(5, 4).unwrap();
            p.fill(tiny_skia::Color::from_rgba8(k * 50, 100, 200, 255));
            frames.push(p);
        }
        let mut out = Vec::new();
        let mut writer = ApngWriter::new(&mut out, 5, 4, 3, 30).unwrap();
        for f in &frames {
            writer.write(f).unwrap();
        }
        writer.finish().unwrap();
        let decoder = png::Decoder::new(std::io::Cursor::new(&out));
        let mut reader = decoder.read_info().unwrap();
        let control = reader.info().animation_control().unwrap();
        assert_eq!((control.num_frames, control.num_plays), (3, 0));
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        for k in 0..3u8 {
            reader.next_frame(&mut buf).unwrap();
            assert_eq!(&buf[..3], &[k * 50, 100, 200]);
        }
    }
}
