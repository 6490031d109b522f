//! Animated GIF: one palette for the whole animation, ordered dithering, and frames that carry
//! only what changed.
//!
//! GIF allows 256 colours. Per-frame palettes make water shimmer (the palette changes under
//! pixels that did not) and defeat frame-to-frame compression, so the palette is learned once
//! (NeuQuant) from sample frames spread over the animation. Smooth gradients (sky, deep water)
//! would band with plain nearest-colour mapping; an ordered 4x4 Bayer dither breaks the bands
//! and, unlike error diffusion, maps an unchanged pixel to the same index in every frame, so
//! still water costs nothing. Each frame after the first holds only the bounding box of the
//! pixels whose index changed, with unchanged pixels inside it transparent.
//!
//! GIF delays are in 1/100 s: at 30 fps the delays run 3, 3, 4 cs, so frame k starts at
//! exactly round(100·k/fps) cs. Rates above 50 fps cannot be shown (browsers clamp delays
//! below 2 cs) and are refused by the caller.

use std::borrow::Cow;
use std::io::Write;

use color_quant::NeuQuant;
use tiny_skia::Pixmap;

/// Colours in the palette; index 255 is kept for "unchanged" (transparent).
const COLOURS: usize = 255;
const TRANSPARENT: u8 = 255;
/// Pixels the palette learns from at most (spread over all sample frames).
const SAMPLE_PIXELS: usize = 600_000;
/// Half the dither's reach, in colour levels: about the spacing of a 255-colour palette along
/// a gradient.
const DITHER_LEVELS: f32 = 10.0;
const BAYER: [[u8; 4]; 4] = [[0, 8, 2, 10], [12, 4, 14, 6], [3, 11, 1, 9], [15, 7, 13, 5]];

/// The animation's palette and a table from 15-bit colour to palette index.
#[derive(Clone, Debug)]
pub struct GifPalette {
    rgb: Vec<u8>,
    lookup: Vec<u8>,
}

impl GifPalette {
    /// Learns a palette from sample frames (an even share of pixels from each).
    pub fn learn(samples: &[&Pixmap]) -> GifPalette {
        let total: usize = samples.iter().map(|p| p.pixels().len()).sum();
        let stride = total.div_ceil(SAMPLE_PIXELS).max(1);
        let mut rgba = Vec::with_capacity(total / stride * 4 + 4);
        for pixmap in samples {
            for p in pixmap.pixels().iter().step_by(stride) {
                let c = p.demultiply();
                rgba.extend_from_slice(&[c.red(), c.green(), c.blue(), 255]);
            }
        }
        if rgba.is_empty() {
            rgba.extend_from_slice(&[0, 0, 0, 255]);
        }
        let quant = NeuQuant::new(10, COLOURS, &rgba);
        let rgb = quant.color_map_rgb();
        GifPalette::from_rgb(rgb)
    }

    /// A palette of the given colours (at most 255, as RGB triples).
    fn from_rgb(mut rgb: Vec<u8>) -> GifPalette {
        rgb.truncate(COLOURS * 3);
        let colours: Vec<[i32; 3]> = rgb.chunks_exact(3).map(|c| [c[0], c[1], c[2]].map(i32::from)).collect();
        let lookup = (0..1usize << 15)
            .map(|key| {
                let centre = [(key >> 10) & 31, (key >> 5) & 31, key & 31].map(|v| (v as i32) * 8 + 4);
                let distance = |c: &[i32; 3]| {
                    let d = [c[0] - centre[0], c[1] - centre[1], c[2] - centre[2]];
                    // Green weighs most, blue least, as the eye does.
                    3 * d[0] * d[0] + 4 * d[1] * d[1] + 2 * d[2] * d[2]
                };
                colours.iter().enumerate().min_by_key(|(_, c)| distance(c)).map_or(0, |(i, _)| i as u8)
            })
            .collect();
        rgb.resize(256 * 3, 0);
        GifPalette { rgb, lookup }
    }

    /// The palette index for a pixel at (x, y), dithered.
    #[inline(always)]
    fn index(&self, [r, g, b]: [u8; 3], x: usize, y: usize) -> u8 {
        let threshold = (f32::from(BAYER[y & 3][x & 3]) + 0.5) / 16.0 - 0.5;
        let offset = (threshold * 2.0 * DITHER_LEVELS) as i32;
        let q = |c: u8| ((i32::from(c) + offset).clamp(0, 255) >> 3) as usize;
        self.lookup[(q(r) << 10) | (q(g) << 5) | q(b)]
    }
}

/// Writes GIF frames to `W` as they come.
pub struct GifWriter<W: Write> {
    encoder: gif::Encoder<W>,
    palette: GifPalette,
    width: usize,
    height: usize,
    fps: u32,
    frames: u64,
    shown: Vec<u8>,
    next: Vec<u8>,
    patch: Vec<u8>,
}

impl<W: Write> GifWriter<W> {
    /// A looping animation of `width x height` frames at `fps` (1..=50) frames per second.
    pub fn new(out: W, width: u32, height: u32, palette: GifPalette, fps: u32) -> std::io::Result<GifWriter<W>> {
        let side = |v: u32| u16::try_from(v).map_err(|_| std::io::Error::other("a GIF is at most 65535 pixels a side"));
        let mut encoder = gif::Encoder::new(out, side(width)?, side(height)?, &palette.rgb).map_err(gif_error)?;
        encoder.set_repeat(gif::Repeat::Infinite).map_err(gif_error)?;
        let cells = width as usize * height as usize;
        Ok(GifWriter {
            encoder,
            palette,
            width: width as usize,
            height: height as usize,
            fps: fps.clamp(1, 50),
            frames: 0,
            shown: Vec::with_capacity(cells),
            next: vec![0; cells],
            patch: Vec::with_capacity(cells),
        })
    }

    /// The delay of frame `k` in 1/100 s, so that frame k starts at round(100·k/fps).
    pub fn delay_cs(k: u64, fps: u32) -> u16 {
        let start = |k: u64| (200 * k + u64::from(fps)) / (2 * u64::from(fps));
        (start(k + 1) - start(k)) as u16
    }

    /// Appends a frame (the writer's size).
    pub fn write(&mut self, pixmap: &Pixmap) -> std::io::Result<()> {
        assert_eq!((pixmap.width() as usize, pixmap.height() as usize), (self.width, self.height));
        let w = self.width;
        for (i, (p, index)) in pixmap.pixels().iter().zip(self.next.iter_mut()).enumerate() {
            let c = p.demultiply();
            *index = self.palette.index([c.red(), c.green(), c.blue()], i % w, i / w);
        }
        let delay = Self::delay_cs(self.frames, self.fps);
        self.frames += 1;
        let mut frame = gif::Frame { delay, ..gif::Frame::default() };
        if self.shown.is_empty() {
            frame.width = w as u16;
            frame.height = self.height as u16;
            frame.buffer = Cow::Borrowed(&self.next);
            self.encoder.write_frame(&frame).map_err(gif_error)?;
            self.shown.extend_from_slice(&self.next);
            return Ok(());
        }
        // Only the box around what changed, the unchanged pixels in it transparent.
        let (mut x0, mut y0, mut x1, mut y1) = (w, self.height, 0, 0);
        for (i, (a, b)) in self.shown.iter().zip(&self.next).enumerate() {
            if a != b {
                let (x, y) = (i % w, i / w);
                (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x + 1), y1.max(y + 1));
            }
        }
        if x0 >= x1 {
            (x0, y0, x1, y1) = (0, 0, 1, 1); // nothing changed: one transparent pixel keeps the time
        }
        self.patch.clear();
        for y in y0..y1 {
            for x in x0..x1 {
                let i = y * w + x;
                self.patch.push(if self.shown[i] == self.next[i] { TRANSPARENT } else { self.next[i] });
            }
        }
        frame.left = x0 as u16;
        frame.top = y0 as u16;
        frame.width = (x1 - x0) as u16;
        frame.height = (y1 - y0) as u16;
        frame.transparent = Some(TRANSPARENT);
        frame.buffer = Cow::Borrowed(&self.patch);
        self.encoder.write_frame(&frame).map_err(gif_error)?;
        std::mem::swap(&mut self.shown, &mut self.next);
        Ok(())
    }

    /// Ends the file and returns the writer.
    pub fn finish(self) -> std::io::Result<W> {
        self.encoder.into_inner().map_err(gif_error)
    }
}

fn gif_error(e: gif::EncodingError) -> std::io::Error {
    match e {
        gif::EncodingError::Io(io) => io,
        other => std::io::Error::other(other.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tiny_skia::ColorU8;

    fn gradient(w: u32, h: u32, shift: u32) -> Pixmap {
        let mut p = Pixmap::new(w, h).unwrap();
        for (i, px) in p.pixels_mut().iter_mut().enumerate() {
            let (x, y) = (i as u32 % w, i as u32 / w);
            *px = ColorU8::from_rgba((x * 255 / w) as u8, ((y + shift) * 255 / (h + shift)) as u8, 120, 255)
                .premultiply();
        }
        p
    }

    #[test]
    fn delays_keep_exact_time_at_30_fps() {
        let delays: Vec<u16> = (0..6).map(|k| GifWriter::<Vec<u8>>::delay_cs(k, 30)).collect();
        assert_eq!(delays.iter().map(|&d| u32::from(d)).sum::<u32>(), 20, "6 frames at 30 fps = 20 cs");
        assert!(delays.iter().all(|&d| d == 3 || d == 4), "{delays:?}");
        assert_eq!(GifWriter::<Vec<u8>>::delay_cs(7, 50), 2);
        assert_eq!(GifWriter::<Vec<u8>>::delay_cs(0, 1), 100);
    }

    #[test]
    fn frames_decode_to_the_pictures_within_the_dither() {
        let frames = [gradient(40, 30, 0), gradient(40, 30, 5), gradient(40, 30, 5)];
        let palette = GifPalette::learn(&frames.iter().collect::<Vec<_>>());
        let mut writer = GifWriter::new(Vec::new(), 40, 30, palette, 25).unwrap();
        for f in &frames {
            writer.write(f).unwrap();
        }
        let bytes = writer.finish().unwrap();
        let mut options = gif::DecodeOptions::new();
        options.set_color_output(gif::ColorOutput::RGBA);
        let mut decoder = options.read_info(std::io::Cursor::new(&bytes)).unwrap();
        let mut screen = vec![0u8; 40 * 30 * 4];
        let mut count = 0;
        while let Some(frame) = decoder.read_next_frame().unwrap() {
            assert_eq!(frame.delay, 4, "25 fps = 4 cs");
            // Composite the frame onto the screen, as a viewer does.
            for y in 0..frame.height as usize {
                for x in 0..frame.width as usize {
                    let src = &frame.buffer[(y * frame.width as usize + x) * 4..][..4];
                    if src[3] != 0 {
                        let dst = ((y + frame.top as usize) * 40 + x + frame.left as usize) * 4;
                        screen[dst..dst + 4].copy_from_slice(src);
                    }
                }
            }
            let expected = &frames[count];
            let mut total_error = 0u64;
            for (i, p) in expected.pixels().iter().enumerate() {
                let c = p.demultiply();
                for (a, b) in [c.red(), c.green(), c.blue()].iter().zip(&screen[i * 4..i * 4 + 3]) {
                    total_error += u64::from(a.abs_diff(*b));
                }
            }
            let mean = total_error as f64 / (40.0 * 30.0 * 3.0);
            assert!(mean < 12.0, "frame {count}: mean channel error {mean}");
            count += 1;
        }
        assert_eq!(count, 3);
    }

    #[test]
    fn an_unchanged_frame_costs_a_single_transparent_pixel() {
        let still = gradient(64, 48, 0);
        let palette = GifPalette::learn(&[&still]);
        let mut one = GifWriter::new(Vec::new(), 64, 48, palette.clone(), 30).unwrap();
        one.write(&still).unwrap();
        let one = one.finish().unwrap().len();
        let mut two = GifWriter::new(Vec::new(), 64, 48, palette, 30).unwrap();
        two.write(&still).unwrap();
        two.write(&still).unwrap();
        let two = two.finish().unwrap().len();
        assert!(two - one < 40, "a still frame adds {} bytes", two - one);
    }
}
