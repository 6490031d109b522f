//! The sixel encoder: a palette fitted to the scene, a position-stable ordered dither,
//! run-length encoding, one pixel per pixel.
//!
//! **A palette fitted to the scene.** The colour registers hold colours fitted to the picture
//! ([`SixelPalette::fit`]: median cut and k-means in OKLab over a subsample), as many as the
//! terminal offers up to 256. Water uses a small part of the RGB cube: the fixed 6x7x6 cube
//! used before left every pixel about 20 luma levels from its colour before dithering, a
//! fitted palette a level or two. The palette is fitted once per scene
//! ([`SixelEncoder::fit_to`]) and again only when the picture's colours drift from it: the
//! mean OKLab distance from a subsample of the picture's pixels to their registers, measured
//! every picture, has grown by `DRIFT` over what it was right after the fit. A refit changes
//! the registers, so the next picture is sent whole; a palette refitted every frame would make
//! the water shimmer and nothing could be skipped.
//!
//! **Ordered dithering, by position.** Each pixel is moved along the grey axis by an 8x8 Bayer
//! offset of its screen position, spanning the palette's typical step, and then mapped to a
//! register through a table filled once per fit (`lookup.rs`). The register depends only on the
//! pixel's colour and position, so an unchanged block gives the same bytes every frame and
//! still water sends nothing. (Error diffusion carries each pixel's error to its neighbours, so
//! one changed pixel changes the rest of the picture.)
//!
//! **Bytes.** Raster attributes `"1;1;W;H` ask for square pixels, one per screen pixel; `P2=1`
//! leaves pixels no colour covers as they are. The picture is cut into bands of six rows; in
//! each band every colour used gets one pass (`#n`, then its sixels from its first to its last
//! column, `$` back to the band's start), runs of four or more equal sixels are `!n`. A register
//! is defined where an image first uses it and then selected again (`#n;2;r;g;b#n`): xterm's
//! definition does not select, and without the second `#n` the band was drawn in the register
//! selected before (a VT340 default: green). The bands are written by `band.rs`: one pass
//! over a band's pixels collects every column's registers and bits, a counting sort lays them
//! out register by register, so the cost grows with the pixels, not with pixels x colours.
//!
//! **Changed rectangles.** Only the text rows and columns whose dithered pixels changed are sent,
//! as a smaller sixel image placed at the top-left cell of that block (a sixel image is drawn
//! from the cursor's cell). The rectangle is widened to whole cells and its height to whole
//! six-row bands (some decoders size an image by its bands); when that would reach below the
//! picture, the whole picture is sent. Dithering uses the picture's coordinates, so the pieces
//! match the whole picture exactly. Whole pictures should be a multiple of 6 rows tall for the
//! same reason ([`crate::output::graphics::geometry`] picks such sizes).

mod band;
pub(crate) mod fit;
pub(crate) mod lookup;
mod palette;

use self::band::{Band, push_decimal};
use self::lookup::{BAYER_SIDE, BAYER8, ColourMap};
pub use self::palette::SixelPalette;
pub use super::Update;

/// The most colour registers used, whatever the terminal offers: 256 registers give a palette
/// whose dither is hard to see; more would make every band's colour passes longer.
pub const MAX_REGISTERS: u16 = 256;
/// The fewest registers a palette is built for (2 levels a channel).
pub const MIN_REGISTERS: u16 = 8;
/// How far the picture's colours may drift from the palette before it is fitted again: the
/// mean OKLab distance from the picture's pixels to their registers may grow this much over
/// the fit's own (a quarter of a just-noticeable difference).
pub const DRIFT: f32 = crate::output::oklab::JND / 4.0;
/// The most bytes tmux (3.3 to 3.6) reads of one escape sequence: a longer sixel image is dropped.
/// Kept a little under 1 MiB for the passthrough wrapper's doubled escapes and the cursor move.
#[cfg(any(test, feature = "player", feature = "testing"))]
pub const TMUX_MAX_IMAGE_BYTES: usize = (1 << 20) - 4096;

/// When the colour registers are defined.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Registers {
    /// Each image defines the registers it uses, where it first uses each (`#i;2;r;g;b#i`:
    /// defined, then selected, since xterm's definition does not select): works in every
    /// terminal, and a small changed block defines only its few colours instead of the whole
    /// palette (about 4 kB at 256 registers).
    PerImage,
    /// Each register is defined once, the first time any image uses it, and kept: only for a
    /// terminal whose images share their registers (xterm after `ESC [ ? 1070 l`, which the player
    /// does not send: it draws `PerImage`). [`SixelEncoder::forget_registers`] starts over.
    #[cfg(any(test, feature = "testing"))]
    Shared,
}

/// The encoder, with the dithered picture the terminal shows.
#[derive(Debug)]
pub struct SixelEncoder {
    palette: SixelPalette,
    /// Each register's definition (`;2;r;g;b` after `#i`).
    definitions: Vec<Vec<u8>>,
    /// When registers are defined, and which are defined now (in this image or this session).
    registers: Registers,
    defined: Vec<bool>,
    /// The most bytes one image may take (tmux's input buffer); `None`: no limit.
    max_image_bytes: Option<usize>,
    /// Wrap every image for tmux passthrough.
    tmux: bool,
    /// The band being written, when images are split ([`SixelEncoder::set_max_image_bytes`]).
    band: Vec<u8>,
    /// The source column of every target column, for [`SixelEncoder::dither_scaled`].
    x_map: Vec<u32>,
    /// From colour and dither threshold to register, for the palette.
    map: ColourMap,
    /// The fitted palette's own error on the picture it was fitted to (`None`: not fitted
    /// yet, the palette is the one given).
    fit_error: Option<f32>,
    /// The registers the terminal offers (the palette given's): the most colours a fit uses.
    registers_cap: u16,
    /// The picture's top-left cell (column, row), 0-based.
    origin: (u16, u16),
    /// The cell size in pixels, for changed rectangles; `None`: always whole pictures.
    cell_px: Option<(u16, u16)>,
    /// The dithered picture being encoded and the one the terminal shows: (width, height,
    /// register per pixel).
    current: Vec<u8>,
    shown: Option<(u32, u32, Vec<u8>)>,
    /// The band writer's scratch.
    bands: Band,
}

impl SixelEncoder {
    /// An encoder for `palette`, the picture's top-left at cell `origin`; changed rectangles
    /// are used when the cell size in pixels is known.
    pub fn new(palette: SixelPalette, origin: (u16, u16), cell_px: Option<(u16, u16)>) -> SixelEncoder {
        let n = palette.len();
        SixelEncoder {
            map: ColourMap::new(&palette),
            fit_error: None,
            registers_cap: palette.registers(),
            definitions: definitions(&palette),
            palette,
            registers: Registers::PerImage,
            defined: vec![false; n],
            max_image_bytes: None,
            tmux: false,
            band: Vec::new(),
            x_map: Vec::new(),
            origin,
            cell_px: cell_px.filter(|&(w, h)| w > 0 && h > 0),
            current: Vec::new(),
            shown: None,
            bands: Band::default(),
        }
    }

    #[cfg(any(test, feature = "testing"))]
    /// The palette.
    pub fn palette(&self) -> &SixelPalette {
        &self.palette
    }

    /// Fits a palette of at most `colours` (and the terminal's registers) to the picture
    /// `pixels` (`bpp` bytes a pixel, RGB first) when none of that size is
    /// fitted yet or when the picture's colours have drifted from it by more than `DRIFT`
    /// (see the module documentation). Returns whether the registers changed: then every
    /// picture shown was drawn with other registers, and the next must be sent whole.
    pub fn fit_to(&mut self, pixels: &[u8], bpp: usize, colours: u16) -> bool {
        let colours = colours.clamp(MIN_REGISTERS, self.registers_cap);
        if let Some(fitted) = self.fit_error
            && self.palette.registers() == colours
            && self.map.error(pixels, bpp) <= fitted + DRIFT
        {
            return false;
        }
        self.set_palette(SixelPalette::fit(pixels, bpp, colours));
        self.fit_error = Some(self.map.error(pixels, bpp));
        true
    }

    /// Uses `palette` from now on: its registers are defined again where next used, and the
    /// next picture is sent whole.
    fn set_palette(&mut self, palette: SixelPalette) {
        let n = palette.len();
        self.map = ColourMap::new(&palette);
        self.definitions = definitions(&palette);
        self.defined = vec![false; n];
        self.palette = palette;
        self.shown = None;
    }

    #[cfg(any(test, feature = "testing"))]
    /// Forgets what the terminal shows (a resize, a cleared screen): the next picture is sent
    /// whole.
    pub fn invalidate(&mut self) {
        self.shown = None;
    }

    /// Chooses when registers are defined (see [`Registers`]); all are undefined after it.
    pub fn set_registers(&mut self, registers: Registers) {
        self.registers = registers;
        self.forget_registers();
    }

    /// Forgets which registers the terminal holds (a new session, a reset terminal): each is
    /// defined again at its next use.
    pub fn forget_registers(&mut self) {
        self.defined.fill(false);
    }

    /// Cuts images so that none takes more than `bytes` (tmux buffers at most 1 MiB of one
    /// sequence and drops a longer one: `TMUX_MAX_IMAGE_BYTES`), and wraps them for tmux
    /// passthrough when `tmux`. An image is cut between bands that start on a text row, so each
    /// piece starts at a cell.
    pub fn set_max_image_bytes(&mut self, bytes: Option<usize>, tmux: bool) {
        self.max_image_bytes = bytes.map(|b| b.max(4096));
        self.tmux = tmux;
    }

    /// Dithers `source` (`width x height` pixels of `bpp` bytes, 3 for RGB or 4 for opaque
    /// RGBA such as a pixmap's data, row-major) scaled to `target` by nearest pixel (each
    /// source pixel repeated): the register of every target pixel. No RGB copy is made.
    ///
    /// `fine`: the dither's threshold follows the target pixel, so the pattern is the screen's
    /// finest (8 pixels) and averages out to the eye; otherwise it follows the source pixel, so
    /// a repeated pixel is one flat colour and costs fewer bytes (runs of equal sixels), at the
    /// price of a pattern as coarse as the scale (21 screen pixels at 2.7x).
    pub fn dither_scaled(
        &mut self,
        source: &[u8],
        bpp: usize,
        (width, height): (u32, u32),
        (tw, th): (u32, u32),
        fine: bool,
        out: &mut Vec<u8>,
    ) {
        assert!(bpp == 3 || bpp == 4, "3 or 4 bytes a pixel");
        assert_eq!(source.len(), width as usize * height as usize * bpp, "source does not match {width}x{height}");
        out.clear();
        out.reserve(tw as usize * th as usize);
        self.x_map.clear();
        self.x_map
            .extend((0..u64::from(tw)).map(|x| (x * u64::from(width) / u64::from(tw.max(1))) as u32 * bpp as u32));
        let map = &mut self.map;
        let stride = width as usize * bpp;
        // The threshold follows the source pixel, so a repeated pixel is one flat colour (runs
        // of equal sixels: a smaller picture costs fewer bytes); at scale 1 it is the target's.
        for y in 0..th as usize {
            let sy = (y as u64 * u64::from(height) / u64::from(th.max(1))) as usize;
            let row = &source[sy * stride..(sy + 1) * stride];
            let thresholds = &BAYER8[if fine { y } else { sy } % BAYER_SIDE];
            for (x, &at) in self.x_map.iter().enumerate() {
                let p = &row[at as usize..at as usize + 3];
                let t = usize::from(thresholds[if fine { x } else { at as usize / bpp } % BAYER_SIDE]);
                out.push(map.register([p[0], p[1], p[2]], t));
            }
        }
    }

    /// Appends the images that show the `(x, y, w, h)` block of the dithered picture `pixels`
    /// (`width` registers a row, as [`SixelEncoder::dither_into`] makes them), placed at its
    /// cell: the block starts on a cell boundary (cell size `cell_px`) from cell `origin`.
    pub fn push_block(
        &mut self,
        out: &mut Vec<u8>,
        pixels: &[u8],
        width: u32,
        (x, y, w, h): (u32, u32, u32, u32),
        origin: (u16, u16),
        cell_px: (u16, u16),
    ) {
        let (cw, ch) = (u32::from(cell_px.0.max(1)), u32::from(cell_px.1.max(1)));
        let (col, row) = (u32::from(origin.0) + x / cw, u32::from(origin.1) + y / ch);
        let mut image = std::mem::take(&mut self.band);
        image.clear();
        let _ = std::io::Write::write_fmt(&mut image, format_args!("\x1b[{};{}H", row + 1, col + 1));
        self.push_image(&mut image, pixels, width, (x, y, w, h), (origin, (cw, ch)), out);
        if out.is_empty() && !self.tmux {
            // The image is all there is to send: handed over, not copied (a megabyte at the
            // screen's size).
            std::mem::swap(out, &mut image);
        } else {
            self.flush(out, &image);
        }
        self.band = image;
    }

    /// Moves a finished image (or a cursor move and image) from `image` to `out`, wrapped for
    /// tmux when asked.
    fn flush(&self, out: &mut Vec<u8>, image: &[u8]) {
        if self.tmux {
            // The cursor move goes as it is (tmux moves its own cursor), the image wrapped.
            let split = image.windows(2).position(|w| w == b"\x1bP").unwrap_or(0);
            out.extend_from_slice(&image[..split]);
            super::tmux::push_wrapped(out, &image[split..]);
        } else {
            out.extend_from_slice(image);
        }
    }

    /// The register of every pixel of `rgb` (`width x height`, 3 bytes a pixel), dithered.
    pub fn dither_into(&mut self, rgb: &[u8], width: u32, height: u32, out: &mut Vec<u8>) {
        assert_eq!(rgb.len(), width as usize * height as usize * 3, "RGB buffer does not match {width}x{height}");
        out.clear();
        out.reserve(width as usize * height as usize);
        for (y, row) in rgb.chunks_exact(width as usize * 3).enumerate() {
            self.dither_row(row, y, out);
        }
    }

    /// Appends the registers of row `y` of a picture one pixel a screen pixel (`rgb`, 3 bytes a
    /// pixel), dithered by position: what [`SixelEncoder::dither_into`] does for each row, for a
    /// caller that makes the picture a row at a time (the stream's enlargement to the screen).
    #[inline(always)]
    pub fn dither_row(&mut self, rgb: &[u8], y: usize, out: &mut Vec<u8>) {
        let start = out.len();
        out.resize(start + rgb.len() / 3, 0);
        self.map.registers_row(rgb, y, &mut out[start..]);
    }

    /// Appends the bytes that make the terminal show `rgb` (`width x height`, 3 bytes a pixel)
    /// from the origin cell, and says what was sent. Nothing is appended when the dithered
    /// picture is unchanged. The caller keeps the picture off the last text row.
    pub fn encode(&mut self, rgb: &[u8], width: u32, height: u32, out: &mut Vec<u8>) -> Update {
        let mut current = std::mem::take(&mut self.current);
        self.dither_into(rgb, width, height, &mut current);
        let update = match (&self.shown, self.cell_px) {
            (Some((w, h, old)), Some((cw, ch))) if (*w, *h) == (width, height) => {
                match changed_cells(old, &current, width, height, (u32::from(cw), u32::from(ch))) {
                    None => Update::Unchanged,
                    Some((0, 0, w, h)) if (w, h) == (width, height) => Update::Full,
                    Some(r) => Update::Rect(r.0, r.1, r.2, r.3),
                }
            }
            (Some((w, h, old)), None) if (*w, *h) == (width, height) && *old == current => Update::Unchanged,
            _ => Update::Full,
        };
        let (x, y, w, h) = match update {
            Update::Unchanged => {
                self.current = current;
                return update;
            }
            Update::Full => (0, 0, width, height),
            Update::Rect(x, y, w, h) => (x, y, w, h),
        };
        let cell_px = self.cell_px.unwrap_or((1, 1));
        self.push_block(out, &current, width, (x, y, w, h), self.origin, cell_px);
        self.current = match self.shown.take() {
            Some((w, h, old)) if (w, h) == (width, height) => old,
            _ => Vec::new(),
        };
        self.shown = Some((width, height, current));
        update
    }

    /// Writes the sixel image(s) of the `(x0, y0, w, h)` block of `pixels` (`stride` registers a
    /// row) into `image` (which holds the cursor move to the block's cell), cutting it where
    /// [`SixelEncoder::set_max_image_bytes`] asks: a finished piece goes to `out` and the next
    /// starts with its own cursor move, at a band that starts a text row (`place`: the origin
    /// cell and the cell size).
    fn push_image(
        &mut self,
        image: &mut Vec<u8>,
        pixels: &[u8],
        stride: u32,
        (x0, y0, w, h): (u32, u32, u32, u32),
        (origin, (cw, ch)): ((u16, u16), (u32, u32)),
        out: &mut Vec<u8>,
    ) {
        let (w_px, stride) = (w as usize, stride as usize);
        let mut piece_top = 0usize; // the first row of the image being written, within the block
        let mut header = image.len();
        push_header(image, w, h);
        if self.registers == Registers::PerImage {
            self.defined.fill(false);
        }
        // The last band that starts a text row, and where its bytes start.
        let mut mark: Option<(usize, usize)> = None;
        let mut band = 0usize;
        while band < h as usize {
            let starts_row = (y0 as usize + band).is_multiple_of(ch as usize);
            if starts_row && band > piece_top {
                mark = Some((band, image.len()));
            }
            let registers = band::Definitions { definitions: &self.definitions, defined: &mut self.defined };
            let rows = 6.min(h as usize - band);
            self.bands.push(image, pixels, stride, (x0 as usize, y0 as usize + band, w_px, rows), registers);
            band += 6;
            let too_big = self.max_image_bytes.is_some_and(|max| image.len() + 2 > max);
            if let (true, Some((cut, at))) = (too_big, mark) {
                // Close the piece before the marked band and start the next image there.
                image.truncate(at);
                image.extend_from_slice(b"\x1b\\");
                let mut fixed = Vec::with_capacity(32);
                push_header(&mut fixed, w, (cut - piece_top) as u32);
                let old_header_end = header + header_len(&image[header..]);
                image.splice(header..old_header_end, fixed);
                self.flush(out, image);
                image.clear();
                let row = u32::from(origin.1) + (y0 + cut as u32) / ch;
                let col = u32::from(origin.0) + x0 / cw;
                let _ = std::io::Write::write_fmt(image, format_args!("\x1b[{};{}H", row + 1, col + 1));
                header = image.len();
                push_header(image, w, h - cut as u32);
                if self.registers == Registers::PerImage {
                    self.defined.fill(false);
                }
                piece_top = cut;
                band = cut;
                mark = None;
            }
        }
        image.extend_from_slice(b"\x1b\\");
    }
}

/// Each register's definition (`;2;r;g;b` after `#i`).
fn definitions(palette: &SixelPalette) -> Vec<Vec<u8>> {
    (0..palette.len())
        .map(|i| {
            let [r, g, b] = palette.percent_rgb(i as u8);
            format!(";2;{r};{g};{b}").into_bytes()
        })
        .collect()
}

/// Appends an image's start: DCS with `P2=1` (uncovered pixels stay as they are) and raster
/// attributes for square pixels of a `w x h` picture.
fn push_header(out: &mut Vec<u8>, w: u32, h: u32) {
    out.extend_from_slice(b"\x1bP0;1;0q\"1;1;");
    push_decimal(out, w as usize);
    out.push(b';');
    push_decimal(out, h as usize);
}

/// The length of the header [`push_header`] wrote at the start of `bytes`.
fn header_len(bytes: &[u8]) -> usize {
    let fixed = b"\x1bP0;1;0q\"1;1;".len();
    fixed + bytes[fixed..].iter().position(|b| !(b.is_ascii_digit() || *b == b';')).unwrap_or(bytes.len() - fixed)
}

/// The block of whole cells (x, y, width, height in pixels, clipped to the picture) that holds
/// every pixel differing between `old` and `new`, or `None` when they are equal.
fn changed_cells(
    old: &[u8],
    new: &[u8],
    width: u32,
    height: u32,
    (cw, ch): (u32, u32),
) -> Option<(u32, u32, u32, u32)> {
    let (left, top, bw, bh) = super::scan::changed_box(old, new, width, 1, 0..height)?;
    let (right, bottom) = (left + bw - 1, top + bh - 1);
    let (x0, y0) = (left / cw * cw, top / ch * ch);
    let x1 = ((right + 1).div_ceil(cw) * cw).min(width);
    let y1 = ((bottom + 1).div_ceil(ch) * ch).min(height);
    // Whole cells, not whole bands (the last band may be partial): mlterm 3.9 sizes an image
    // in whole cells and fills the rest of a row of cells it reaches into with its background,
    // blanking the picture below a block a few rows taller than its cells.
    Some((x0, y0, x1 - x0, y1 - y0))
}

#[cfg(any(test, feature = "testing"))]
/// The picture the terminal shows for `rgb` after dithering with `palette` (each pixel its
/// register's colour): what a decoded stream must equal.
pub fn dithered_rgb(palette: &SixelPalette, rgb: &[u8], width: u32, height: u32) -> Vec<u8> {
    let mut encoder = SixelEncoder::new(palette.clone(), (0, 0), None);
    let mut indices = Vec::new();
    encoder.dither_into(rgb, width, height, &mut indices);
    indices.iter().flat_map(|&i| palette.rgb(i)).collect()
}

#[cfg(test)]
mod tests;
