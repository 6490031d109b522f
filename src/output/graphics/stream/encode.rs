//! Encoding one picture for a [`PictureStream`]: resampled to the rung, compared with what the
//! terminal shows, and written as the protocol's commands (kitty and iTerm2 packed, kitty's
//! pixels perhaps in a temporary file that is handed out as data, sixel through its encoder).

use tiny_skia::Pixmap;

use super::ladder::{Resampler, RowSink};
use super::{FileWrite, Part, PictureStream, Protocol};
use crate::output::graphics::kitty::{self, KittyOptions, Medium};
use crate::output::graphics::pack::{Packing, pack};
use crate::output::graphics::sixel::SixelEncoder;
use crate::output::graphics::{iterm2, scan};
use crate::simd::{Simd, Tier};

/// The most colours a sixel palette fitted under a rate below [`FULL_PALETTE_RATE`] has
/// (without a rate, or above it: the terminal's registers, up to 256). 32 scored 0.474 at 50
/// kB/s against 256's 0.434, and within 0.015 of it above (`benches/pictures.rs`).
const LIMITED_COLOURS: u16 = 32;

/// The rate (bytes a second) from which a sixel stream fits the terminal's whole palette, as
/// without a rate: the screen-sized pictures with 256 colours average 28.7 MB/s at 15 a second
/// in `benches/pictures.rs`, so from 32 MB/s they go as they would unlimited (SSIM 0.706 over
/// time there, the cells' 0.671). Below it 32 colours: at 16-24 MB/s the same pictures with 32
/// colours took 12.9 MB/s and scored 0.642 (docs/pixels/cpu.md, Round 5).
pub(super) const FULL_PALETTE_RATE: f64 = 32e6;

/// The colours a sixel palette is fitted with under `rate` (`None`: no limit).
fn sixel_colours(rate: Option<f64>) -> u16 {
    match rate {
        Some(r) if r < FULL_PALETTE_RATE => LIMITED_COLOURS,
        _ => u16::MAX,
    }
}

impl PictureStream {
    /// Fills the candidate with its mean colour.
    pub(super) fn flatten_candidate(&mut self) {
        let n = (self.candidate.len() / 3).max(1) as u64;
        let mut sum = [0u64; 3];
        for p in self.candidate.chunks_exact(3) {
            (0..3).for_each(|c| sum[c] += u64::from(p[c]));
        }
        let mean = sum.map(|s| (s / n) as u8);
        for p in self.candidate.chunks_exact_mut(3) {
            p.copy_from_slice(&mean);
        }
    }

    /// Encodes `picture` at `rung` into `self.bytes` (whole, or the changed box when that is
    /// cheaper) and its pixels into `self.candidate`; `None` when the terminal shows it already.
    /// `rate`: the budget's (`None`: no limit).
    pub(super) fn encode(&mut self, picture: &Pixmap, rung: usize, rate: Option<f64>) -> Option<Part> {
        let limited = rate.is_some();
        let size = self.rungs[rung];
        let from = (picture.width(), picture.height());
        self.bytes.clear();
        if let Protocol::Sixel { .. } = self.protocol {
            let screen = self.layout.picture;
            let sixel = self.sixel.as_mut().expect("a sixel stream has its encoder");
            // The palette fitted to the scene (once, and again when its colours drift): new
            // registers, so what the terminal shows can no longer be compared with.
            // Under a rate, fewer colours: every register an image uses is defined in it and
            // costs a pass over each band, and a tile on a slow link must fit a few hundred
            // bytes.
            let colours = sixel_colours(rate);
            if sixel.fit_to(picture.data(), 4, colours) {
                self.shown = None;
            }
            // Dithered straight from the pixmap (opaque: its bytes are straight RGB) when the
            // rung is the picture's size; otherwise resampled to the rung first (the top rung
            // is the screen's size: the source enlarged smoothly). Each rung pixel becomes a
            // block of screen pixels.
            // The top rung (a link that carries whole pictures) gets the fine pattern; the
            // others the flat blocks that cost fewer bytes.
            let fine = rung == 0;
            if size == from {
                sixel.dither_scaled(picture.data(), 4, from, screen, fine, &mut self.candidate);
            } else if size == screen {
                // The source enlarged to the screen and dithered a row at a time.
                self.candidate.clear();
                let enlarge = Enlarge { resampler: &mut self.resampler, sixel, source: picture.data(), from, to: size };
                enlarge.run(Simd::detect(), &mut self.candidate);
            } else {
                self.resampler.resample(picture.data(), 4, from, size, &mut self.rgb);
                sixel.dither_scaled(&self.rgb, 3, size, screen, fine, &mut self.candidate);
            }
            let part = match &self.shown {
                Some((_, old)) => sixel_part(old, &self.candidate, screen, self.layout.cell_px)?,
                None => Part::Whole,
            };
            let (x, y, w, h) = part_box(part, screen);
            sixel.push_block(
                &mut self.bytes,
                &self.candidate,
                screen.0,
                (x, y, w, h),
                self.layout.origin,
                self.layout.cell_px,
            );
            return Some(part);
        }
        self.resampler.resample(picture.data(), 4, from, size, &mut self.candidate);
        let packing = self.packing(limited, rung);
        if let Some(p) = packing.filter(|p| p.rewrites_pixels()) {
            return self.encode_lossy(rung, p);
        }
        let part = match &self.shown {
            Some((r, old)) if *r == rung => match scan::changed_box(old, &self.candidate, size.0, 3, 0..size.1) {
                None => return None,
                Some(b) if self.protocol.edits() && 2 * b.2 * b.3 <= size.0 * size.1 => {
                    Part::Changed(b.0, b.1, b.2, b.3)
                }
                Some(_) => Part::Whole,
            },
            _ => Part::Whole,
        };
        if limited {
            // iTerm2's JPEG: what it was encoded from, for the commit (`Model::Set`).
            self.target.clear();
            self.target.extend_from_slice(&self.candidate);
        }
        self.push_part(part, rung, packing);
        Some(part)
    }

    /// [`PictureStream::encode`] for a lossy PNG `packing` (kitty under a rate), the picture
    /// at `rung` in `self.candidate`: what changed is found against the picture the shown one
    /// was encoded from (`sent`), the changed box (or the whole picture) is encoded over what
    /// is shown, and the candidate becomes exactly what the terminal will show.
    fn encode_lossy(&mut self, rung: usize, packing: Packing) -> Option<Part> {
        std::mem::swap(&mut self.target, &mut self.candidate);
        let size = self.rungs[rung];
        let part = match (&self.shown, &self.sent) {
            (Some((r, _)), Some((s, sent))) if *r == rung && *s == rung => {
                // Any box short of the whole picture goes as an edit: the rest of what is
                // shown is kept, and with it the still regions refined towards exact.
                match scan::changed_box(sent, &self.target, size.0, 3, 0..size.1) {
                    None => return None,
                    Some(b) if self.protocol.edits() && (b.2, b.3) != size => Part::Changed(b.0, b.1, b.2, b.3),
                    Some(_) => Part::Whole,
                }
            }
            _ => Part::Whole,
        };
        self.candidate.clear();
        match (part, &self.shown) {
            (Part::Changed(x, _, w, _), Some((_, shown))) => {
                self.candidate.extend_from_slice(shown);
                let (stride, x, w) = (size.0 as usize * 3, x as usize * 3, w as usize * 3);
                for row in part_rows(part, size) {
                    let at = row * stride + x;
                    self.candidate[at..at + w].copy_from_slice(&self.target[at..at + w]);
                }
            }
            _ => self.candidate.extend_from_slice(&self.target),
        }
        self.push_part(part, rung, Some(packing));
        Some(part)
    }

    /// Appends the command(s) for `part` of the candidate at `rung` (kitty and iTerm2), packed
    /// with `packing` (`None`: kitty's raw RGB in a temporary file).
    pub(super) fn push_part(&mut self, part: Part, rung: usize, packing: Option<Packing>) {
        let size = self.rungs[rung];
        let (x, y, w, h) = part_box(part, size);
        if let Some(p) = packing.filter(|p| p.rewrites_pixels()) {
            // Packed here, and the candidate's box rewritten to what the terminal will show.
            let (stride, at, len) = (size.0 as usize * 3, x as usize * 3, w as usize * 3);
            self.part_rgb.clear();
            for row in y as usize..(y + h) as usize {
                self.part_rgb.extend_from_slice(&self.candidate[row * stride + at..][..len]);
            }
            match p {
                Packing::PalettePng(colours) => {
                    self.palette.encode(&mut self.part_rgb, w, h, colours, &mut self.packed)
                }
                Packing::LossyPng(q) => self.lossy.encode(&mut self.part_rgb, w, h, q, &mut self.packed),
                _ => unreachable!("only the lossy PNGs rewrite pixels"),
            }
            for (row, shown) in (y as usize..(y + h) as usize).zip(self.part_rgb.chunks_exact(len)) {
                self.candidate[row * stride + at..][..len].copy_from_slice(shown);
            }
        }
        let pixels: &[u8] = if (w, h) == size {
            &self.candidate
        } else {
            self.part_rgb.clear();
            for row in y..y + h {
                let from = (row as usize * size.0 as usize + x as usize) * 3;
                self.part_rgb.extend_from_slice(&self.candidate[from..from + w as usize * 3]);
            }
            &self.part_rgb
        };
        match &self.protocol {
            Protocol::Kitty(options) => {
                let o = KittyOptions { origin: self.layout.origin, cells: self.layout.cells, ..options.clone() };
                let mut keys = Vec::with_capacity(96);
                let whole = part == Part::Whole;
                if whole {
                    kitty::image_keys(&mut keys, &o, size);
                    if !o.placeholders {
                        kitty::push_cursor_to(&mut self.bytes, o.origin);
                    }
                } else {
                    kitty::edit_keys(&mut keys, o.image_id, (x, y, w, h));
                }
                match (&o.medium, packing) {
                    (Medium::TempFile(dir), None) => {
                        self.files += 1;
                        let path = kitty::temp_file_path(dir, self.files);
                        kitty::push_temp_file_command(&mut self.bytes, &keys, &path, o.tmux);
                        self.pending_file = Some(FileWrite { path, bytes: pixels.to_vec() });
                    }
                    _ => {
                        let packing = packing.unwrap_or(Packing::Zlib(1));
                        match packing {
                            Packing::LossyPng(_) | Packing::PalettePng(_) => {}
                            Packing::Zlib(level) => self.zlib.compress(pixels, u32::from(level), &mut self.packed),
                            _ => pack(packing, pixels, w, h, &mut self.packed),
                        }
                        let more: &[u8] = if whole { b"" } else { b"a=f," };
                        kitty::push_chunks(&mut self.bytes, &keys, more, packing, &self.packed, o.tmux);
                    }
                }
                if whole && o.placeholders && self.placeholders_due {
                    kitty::push_placeholders(&mut self.bytes, o.image_id, o.origin.0, o.origin.1, o.cells.0, o.cells.1);
                }
            }
            Protocol::Iterm2 { tmux } => {
                pack(packing.unwrap_or(Packing::Png), pixels, w, h, &mut self.packed);
                iterm2::push_file(&mut self.bytes, self.layout.origin, self.layout.cells, *tmux, &self.packed)
            }
            Protocol::Sixel { .. } => unreachable!("sixel is encoded by its encoder"),
        }
    }
}

/// The box a part covers in a picture of `size`.
pub(super) fn part_box(part: Part, size: (u32, u32)) -> (u32, u32, u32, u32) {
    match part {
        Part::Whole => (0, 0, size.0, size.1),
        Part::Changed(x, y, w, h) | Part::Tile(x, y, w, h) => (x, y, w, h),
    }
}

/// The rows a part covers in a picture of `size`.
pub(super) fn part_rows(part: Part, size: (u32, u32)) -> std::ops::Range<usize> {
    let (_, y, _, h) = part_box(part, size);
    y as usize..(y + h) as usize
}

/// The part of a sixel picture to send: the block of whole cells around the changes (its last
/// band may be partial: mlterm blanks the rest of a row of cells an image reaches into), the
/// whole picture when that block is all of it; `None` when nothing changed.
fn sixel_part(old: &[u8], new: &[u8], screen: (u32, u32), cell_px: (u16, u16)) -> Option<Part> {
    let (cw, ch) = (u32::from(cell_px.0.max(1)), u32::from(cell_px.1.max(1)));
    let (left, top, bw, bh) = scan::changed_box(old, new, screen.0, 1, 0..screen.1)?;
    let (x0, y0) = (left / cw * cw, top / ch * ch);
    let x1 = ((left + bw).div_ceil(cw) * cw).min(screen.0);
    let h = ((top + bh).div_ceil(ch) * ch).min(screen.1) - y0;
    if (x0, y0, x1 - x0, h) == (0, 0, screen.0, screen.1) {
        return Some(Part::Whole);
    }
    Some(Part::Changed(x0, y0, x1 - x0, h))
}

/// The sixel stream's top rung: the source (`from`, RGBA) enlarged to the screen (`to`) and
/// dithered a row at a time.
struct Enlarge<'a> {
    resampler: &'a mut Resampler,
    sixel: &'a mut SixelEncoder,
    source: &'a [u8],
    from: (u32, u32),
    to: (u32, u32),
}

impl Enlarge<'_> {
    /// Appends the registers of the enlarged picture to `out`, the loops compiled for the
    /// widest instruction set `simd` names ([`crate::simd`]; about a fifth of the sixel
    /// player's CPU ran in 128-bit vectors before). The same bytes on every tier: the sums are
    /// IEEE multiplications and additions in a fixed order (no fused multiply-add), the rest
    /// integers.
    fn run(self, simd: Simd, out: &mut Vec<u8>) {
        match simd.tier() {
            // SAFETY: a `Simd` of this tier exists only when run-time detection found the
            // feature (see `crate::simd`).
            #[cfg(target_arch = "x86_64")]
            Tier::Avx512 => unsafe { self.run_avx512(out) },
            #[cfg(target_arch = "x86_64")]
            Tier::Avx2 => unsafe { self.run_avx2(out) },
            _ => self.run_with(out),
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn run_avx2(self, out: &mut Vec<u8>) {
        self.run_with(out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512bw")]
    fn run_avx512(self, out: &mut Vec<u8>) {
        self.run_with(out)
    }

    #[inline(always)]
    fn run_with(self, out: &mut Vec<u8>) {
        let Enlarge { resampler, sixel, source, from, to } = self;
        resampler.resample_rows(source, 4, from, to, &mut Dither { sixel, out });
    }
}

/// Dithers each enlarged row as it comes.
struct Dither<'a> {
    sixel: &'a mut SixelEncoder,
    out: &'a mut Vec<u8>,
}

impl RowSink for Dither<'_> {
    #[inline(always)]
    fn row(&mut self, y: usize, row: &[u8]) {
        self.sixel.dither_row(row, y, self.out);
    }
}
