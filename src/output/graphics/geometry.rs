//! Where the picture goes and how big it is rendered, per protocol; and which picture pixel a
//! click lands on.
//!
//! The picture covers every row but the last (the status line stays text, and a sixel touching
//! the last row scrolls the screen):
//! - **kitty, iTerm2** scale an image to a cell area, so the picture is rendered at the area's
//!   pixel size, shrunk (keeping its aspect) to fit [`SCALED_CAP`]: the terminal scales it up,
//!   and the renderer and compressor never pay for more than ~1 megapixel.
//! - **sixel** is drawn one pixel per pixel, so the picture is the area's pixel size, within
//!   the largest image the terminal reports (XTSMGRAPHICS), its height a whole number of
//!   six-row sixel bands.
//! - **cells** is today's half-block picture: one pixel a column, two a row.

use crate::output::graphics::GraphicsMode;

/// The largest picture rendered for terminals that scale (kitty, iTerm2), in pixels.
pub const SCALED_CAP: (u32, u32) = (1280, 800);
/// The cell size assumed when the terminal does not say (pixels, width x height).
pub const DEFAULT_CELL_PX: (u16, u16) = (8, 16);
/// Rows of a sixel band: sixel pictures are a multiple of this tall.
pub const SIXEL_BAND: u32 = 6;
/// Rows kept for text at the bottom (the status line).
pub const STATUS_ROWS: u16 = 1;

/// The picture's place and size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// The protocol.
    pub mode: GraphicsMode,
    /// The picture's top-left cell (column, row), 0-based.
    pub origin: (u16, u16),
    /// The cells the picture covers (columns, rows): kitty's `c,r`, iTerm2's width and height.
    pub cells: (u16, u16),
    /// The picture to render, in pixels.
    pub picture: (u32, u32),
    /// The screen pixels the picture covers (equal to `picture` for sixel, which does not scale).
    pub shown_px: (u32, u32),
    /// The cell size in pixels used for all of this.
    pub cell_px: (u16, u16),
}

impl Layout {
    /// The largest picture rendered for terminals that scale (kitty, iTerm2), in pixels: the
    /// usual `cap` of [`layout`].
    pub const SCALED_CAP: (u32, u32) = SCALED_CAP;
}

/// The layout for a terminal of `term` cells (columns, rows) with cells of `cell_px` pixels
/// (`None`: unknown, 8x16 is assumed), the largest sixel image `sixel_max`, and
/// `cap` for scaling protocols ([`Layout::SCALED_CAP`]). Sizes are at least one pixel and one cell.
pub fn layout(
    mode: GraphicsMode,
    term: (u16, u16),
    cell_px: Option<(u16, u16)>,
    sixel_max: Option<(u32, u32)>,
    cap: (u32, u32),
) -> Layout {
    let cell_px = cell_px.filter(|&(w, h)| w > 0 && h > 0).unwrap_or(DEFAULT_CELL_PX);
    let cells = (term.0.max(1), term.1.saturating_sub(STATUS_ROWS).max(1));
    let area = (u32::from(cells.0) * u32::from(cell_px.0), u32::from(cells.1) * u32::from(cell_px.1));
    let (picture, shown_px, cells) = match mode {
        GraphicsMode::Kitty | GraphicsMode::Iterm2 => {
            let scale = (f64::from(cap.0) / f64::from(area.0)).min(f64::from(cap.1) / f64::from(area.1)).min(1.0);
            let size = |v: u32| ((f64::from(v) * scale).round() as u32).max(1);
            ((size(area.0), size(area.1)), area, cells)
        }
        GraphicsMode::Sixel => {
            let (max_w, max_h) = sixel_max.unwrap_or((u32::MAX, u32::MAX));
            let w = area.0.min(max_w).max(1);
            let h = (area.1.min(max_h) / SIXEL_BAND * SIXEL_BAND).max(SIXEL_BAND.min(area.1));
            let covered = (w.div_ceil(u32::from(cell_px.0)) as u16, h.div_ceil(u32::from(cell_px.1)) as u16);
            ((w, h), (w, h), covered)
        }
        GraphicsMode::Cells => (crate::output::halfblock::picture_size(cells.0, cells.1), area, cells),
    };
    Layout { mode, origin: (0, 0), cells, picture, shown_px, cell_px }
}

impl Layout {
    /// The picture pixel under screen pixel (`x`, `y`) (0-based from the screen's top-left
    /// corner; an SGR-pixels mouse report's values minus one), or `None` outside the picture.
    pub fn pixel_at(&self, x: u32, y: u32) -> Option<(u32, u32)> {
        let left = u32::from(self.origin.0) * u32::from(self.cell_px.0);
        let top = u32::from(self.origin.1) * u32::from(self.cell_px.1);
        let (dx, dy) = (x.checked_sub(left)?, y.checked_sub(top)?);
        if dx >= self.shown_px.0 || dy >= self.shown_px.1 {
            return None;
        }
        let scale = |d: u32, picture: u32, shown: u32| (u64::from(d) * u64::from(picture) / u64::from(shown)) as u32;
        Some((scale(dx, self.picture.0, self.shown_px.0), scale(dy, self.picture.1, self.shown_px.1)))
    }

    /// The picture pixel under the centre of cell (`col`, `row`) (0-based), for terminals that
    /// report the mouse in cells; `None` outside the picture.
    pub fn pixel_at_cell(&self, col: u16, row: u16) -> Option<(u32, u32)> {
        let (cw, ch) = (u32::from(self.cell_px.0), u32::from(self.cell_px.1));
        self.pixel_at(u32::from(col) * cw + cw / 2, u32::from(row) * ch + ch / 2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use GraphicsMode::*;

    #[test]
    fn scaling_protocols_cap_the_resolution_and_keep_the_aspect() {
        // 160x48 cells of 8x16: the area is 1280x752, under the cap.
        let l = layout(Kitty, (160, 48), Some((8, 16)), None, SCALED_CAP);
        assert_eq!((l.cells, l.picture, l.shown_px), ((160, 47), (1280, 752), (1280, 752)));
        // 10x20 cells: 1600x940 shrinks to fit 1280x800, aspect kept (1600/940 = 1280/752).
        let l = layout(Iterm2, (160, 48), Some((10, 20)), None, SCALED_CAP);
        assert_eq!((l.cells, l.picture, l.shown_px), ((160, 47), (1280, 752), (1600, 940)));
        // Unknown cell size: 8x16 assumed.
        assert_eq!(layout(Kitty, (80, 25), None, None, SCALED_CAP).picture, (640, 384));
    }

    #[test]
    fn sixel_is_one_pixel_a_pixel_in_whole_bands_within_the_terminals_limit() {
        let l = layout(Sixel, (160, 48), Some((8, 16)), Some((2000, 2000)), SCALED_CAP);
        assert_eq!((l.picture, l.cells), ((1280, 750), (160, 47)), "752 rounds down to 125 bands");
        assert!(l.picture.1 <= 47 * 16, "never into the last row");
        // xterm's default limit (1000x1000) clips the picture; it covers fewer cells.
        let l = layout(Sixel, (160, 80), Some((8, 16)), Some((1000, 1000)), SCALED_CAP);
        assert_eq!((l.picture, l.cells), ((1000, 996), (125, 63)));
        for cell_h in [7u16, 9, 13, 16, 17, 24] {
            let l = layout(Sixel, (40, 12), Some((8, cell_h)), None, SCALED_CAP);
            assert_eq!(l.picture.1 % SIXEL_BAND, 0);
            assert!(l.picture.1 <= 11 * u32::from(cell_h), "cell height {cell_h}");
        }
    }

    #[test]
    fn tiny_terminals_still_get_a_picture() {
        for mode in [Kitty, Sixel, Iterm2, Cells] {
            let l = layout(mode, (1, 1), Some((1, 1)), Some((0, 0)), SCALED_CAP);
            assert!(l.picture.0 >= 1 && l.picture.1 >= 1 && l.cells.0 >= 1 && l.cells.1 >= 1, "{mode:?}: {l:?}");
        }
        assert_eq!(layout(Cells, (80, 24), None, None, SCALED_CAP).picture, (80, 46));
    }

    #[test]
    fn clicks_land_on_the_exact_picture_pixel() {
        for (cw, ch) in [(8u16, 16u16), (10, 20), (7, 15), (12, 25)] {
            let scaled = layout(Kitty, (160, 48), Some((cw, ch)), None, SCALED_CAP);
            let (pw, ph) = scaled.picture;
            let (sw, sh) = scaled.shown_px;
            // Screen pixel corners map to picture corners.
            assert_eq!(scaled.pixel_at(0, 0), Some((0, 0)));
            assert_eq!(scaled.pixel_at(sw - 1, sh - 1), Some((pw - 1, ph - 1)), "cells {cw}x{ch}");
            assert_eq!(scaled.pixel_at(sw, 0), None);
            assert_eq!(scaled.pixel_at(0, sh), None, "the status row is not the picture");
            // A cell's centre: cell (40, 10) of a picture scaled by pw/sw.
            let (x, y) = scaled.pixel_at_cell(40, 10).unwrap();
            let cx = 40 * u32::from(cw) + u32::from(cw) / 2;
            let cy = 10 * u32::from(ch) + u32::from(ch) / 2;
            assert_eq!((x, y), (cx * pw / sw, cy * ph / sh));
            assert_eq!(scaled.pixel_at_cell(0, 47), None, "the status row");

            // Sixel is not scaled: a screen pixel is a picture pixel.
            let sixel = layout(Sixel, (100, 30), Some((cw, ch)), Some((4096, 4096)), SCALED_CAP);
            assert_eq!(sixel.pixel_at(123, 45), Some((123, 45)));
            assert_eq!(
                sixel.pixel_at_cell(3, 2),
                Some((3 * u32::from(cw) + u32::from(cw) / 2, 2 * u32::from(ch) + u32::from(ch) / 2))
            );
        }
        // 10x20 cells scaled by 0.8: screen pixel 1599 is picture pixel 1279, 1000 is 800.
        let l = layout(Kitty, (160, 48), Some((10, 20)), None, SCALED_CAP);
        assert_eq!(l.pixel_at(1000, 500), Some((800, 400)));
        // Cells: cell (5, 3)'s centre lies on the boundary between its two pixels: the lower one.
        let cells = layout(Cells, (80, 24), Some((8, 16)), None, SCALED_CAP);
        assert_eq!(cells.pixel_at_cell(5, 3), Some((5, 7)));
        // An origin moves everything.
        let moved = Layout { origin: (2, 1), ..layout(Sixel, (40, 12), Some((8, 16)), None, SCALED_CAP) };
        assert_eq!(moved.pixel_at(16, 16), Some((0, 0)));
        assert_eq!(moved.pixel_at(15, 16), None);
    }
}
