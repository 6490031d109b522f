//! The ways to draw a picture cell besides exactly (the approximations), and the colour
//! facts they are weighed with: each half's nearest palette colours and its OKLab, remembered
//! per cell so that a colour is converted again only when it changes.

use std::sync::LazyLock;

use tiny_skia::Pixmap;

use crate::output::color::xterm_256;
use crate::output::color::{Color, ColorMode, nearest_256};
use crate::output::frame::Cell;
use crate::output::halfblock::Rgb;
use crate::output::oklab::{self, Lab};

/// `rgb` packed with a valid bit, as a memo key (0: nothing memoized).
fn key(rgb: Rgb) -> u32 {
    1 << 24 | u32::from(rgb[0]) << 16 | u32::from(rgb[1]) << 8 | u32::from(rgb[2])
}

/// OKLab values remembered per cell half, recomputed only when the colour changes.
#[derive(Clone, Debug, Default)]
pub(crate) struct LabMemo {
    entries: Vec<[(u32, Lab); 2]>,
}

impl LabMemo {
    pub fn resize(&mut self, cells: usize) {
        self.entries.resize(cells, [(0, Lab::default()); 2]);
    }

    #[inline]
    pub(super) fn get(&mut self, cell: usize, half: usize, rgb: Rgb) -> Lab {
        let entry = &mut self.entries[cell][half];
        let k = key(rgb);
        if entry.0 != k {
            *entry = (k, oklab::from_rgb(rgb));
        }
        entry.1
    }
}

/// The OKLab of every xterm palette entry.
static PALETTE_LAB: LazyLock<[Lab; 256]> =
    LazyLock::new(|| std::array::from_fn(|i| oklab::from_rgb(xterm_256(i as u8))));

/// The cheaper ways to draw a picture cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Approximation {
    /// A space in the mean of the two true colours (one colour code instead of two).
    Flat,
    /// A space in the palette colour nearest that mean (`ESC[48;5;nm`, about half the bytes of
    /// a truecolor code). Truecolor only.
    FlatPalette,
    /// Both halves in their nearest palette colours. Truecolor only.
    PairPalette,
}

impl Approximation {
    /// The approximations worth trying for a cell of these true colours in `mode`.
    pub(super) fn all(mode: ColorMode, equal_halves: bool) -> &'static [Approximation] {
        match (mode, equal_halves) {
            (ColorMode::TrueColor, false) => {
                &[Approximation::Flat, Approximation::FlatPalette, Approximation::PairPalette]
            }
            (ColorMode::TrueColor, true) => &[Approximation::FlatPalette],
            (_, false) => &[Approximation::Flat],
            (_, true) => &[],
        }
    }

    /// The cell drawn this way for true colours `top` and `bottom` at cell `(x, y)`, given
    /// their nearest palette colours.
    pub(super) fn cell(
        self,
        mode: ColorMode,
        (top, bottom): (Rgb, Rgb),
        palette: Palette,
        (x, y): (usize, usize),
    ) -> Cell {
        let flat = |c: Color| Cell::Pixels { top: c, bottom: c };
        match self {
            Approximation::Flat => flat(mode.quantize(mean(top, bottom), x as u32, 2 * y as u32)),
            Approximation::FlatPalette => flat(Color::Index(palette.mean)),
            Approximation::PairPalette => {
                Cell::Pixels { top: Color::Index(palette.top), bottom: Color::Index(palette.bottom) }
            }
        }
    }
}

/// The mean of two colours, per channel.
fn mean(a: Rgb, b: Rgb) -> Rgb {
    [0, 1, 2].map(|c| (u16::from(a[c]) + u16::from(b[c])).div_ceil(2) as u8)
}

/// The palette colours nearest a cell's two halves and their mean.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Palette {
    top: u8,
    bottom: u8,
    mean: u8,
}

impl Palette {
    pub(super) fn of((top, bottom): (Rgb, Rgb)) -> Palette {
        Palette { top: nearest_256(top), bottom: nearest_256(bottom), mean: nearest_256(mean(top, bottom)) }
    }
}

/// The colours of a picture cell, or `None` for text and default colours.
pub(super) fn pixel_colours(cell: Cell) -> Option<(Rgb, Rgb)> {
    match cell {
        Cell::Pixels { top, bottom } => Some((top.rgb()?, bottom.rgb()?)),
        Cell::Text { .. } => None,
    }
}

/// The OKLab of a palette or RGB colour (`None`: the default colour).
pub(super) fn lab_of(colour: Color) -> Option<Lab> {
    match colour {
        Color::Index(i) => Some(PALETTE_LAB[usize::from(i)]),
        Color::Rgb(rgb) => Some(oklab::from_rgb(rgb)),
        Color::Default => None,
    }
}

/// The true colour of picture pixel `(x, y)` when the wanted colour is its quantization in
/// `mode` (otherwise the cell holds something else, such as an overlay).
pub(super) fn truth(picture: &Pixmap, mode: ColorMode, (x, y): (usize, usize), wanted: Color) -> Option<Rgb> {
    if x >= picture.width() as usize || y >= picture.height() as usize {
        return None;
    }
    let c = picture.pixels()[y * picture.width() as usize + x].demultiply();
    let rgb = [c.red(), c.green(), c.blue()];
    (mode.quantize(rgb, x as u32, y as u32) == wanted).then_some(rgb)
}
