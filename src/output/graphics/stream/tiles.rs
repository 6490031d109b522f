//! Tiles: a picture too big for the link, sent a piece at a time.
//!
//! When even the bottom rung's whole picture costs more than a picture may, kitty (through
//! frame edits) and sixel (through blocks placed at a cell) replace part of what is shown
//! instead. The picture is cut into a grid of tiles sized from what the bottom rung just cost
//! (full-width bands of rows when a row of cells fits, else pieces of one row of cells), and
//! the tiles are visited in raster order from where the last offer stopped, so every part of
//! the picture is refreshed in turn. Of the first tile that changed, only the box around its
//! changes is sent; when that is still too big for the bytes available, its width is halved
//! until it fits. Sixel tiles start at a cell (a sixel image is drawn from the cursor's cell)
//! and end at one (or at the picture's bottom): their last band may be partial. A tile that
//! reached a few rows into the next row of cells (whole bands) left the rest of that row
//! blank in mlterm 3.9, which sizes an image in whole cells and fills them with its
//! background.

use super::{Part, PictureStream, Protocol, scan};

/// The share of the bytes available a tile is sized for (the rest absorbs the difference
/// between tiles: water is busier in some places than others).
const TILE_SHARE: f64 = 0.8;

impl PictureStream {
    /// Encodes the next changed tile of the candidate at `rung` that fits `room` bytes into
    /// `self.bytes`; `part` is what the whole rung's encoding (in `self.bytes` now) covered.
    /// `None` when no tile changed or none fits.
    pub(super) fn encode_tile(&mut self, rung: usize, part: Part, room: usize, limited: bool) -> Option<Part> {
        let sixel = matches!(self.protocol, Protocol::Sixel { .. });
        let (w, h) = if sixel { self.layout.picture } else { self.rungs[rung] };
        let (ux, uy) = if sixel {
            (u32::from(self.layout.cell_px.0.max(1)), u32::from(self.layout.cell_px.1.max(1)))
        } else {
            (1, 1)
        };
        // Bytes a pixel of what was just encoded, and the pixels a tile may hold.
        let (_, _, pw, ph) = super::encode::part_box(part, (w, h));
        let density = self.bytes.len() as f64 / (f64::from(pw) * f64::from(ph)).max(1.0);
        let area = TILE_SHARE * room as f64 / density.max(1e-9);
        let (tw, th) = if area >= f64::from(w) * f64::from(uy) {
            (w, ((area / f64::from(w)) as u32 / uy * uy).clamp(uy, h.div_ceil(uy) * uy))
        } else {
            (((area / f64::from(uy)) as u32 / ux * ux).clamp(ux, w), uy)
        };
        let (cols, rows) = (w.div_ceil(tw), h.div_ceil(th));
        let count = (cols * rows) as usize;
        let (stride, bpp) = self.stride(rung);
        for k in 0..count {
            let index = (self.next_tile + k) % count;
            let (x, y) = ((index as u32 % cols) * tw, (index as u32 / cols) * th);
            // Whole rows of cells for sixel too, not whole bands: mlterm 3.9 blanks the rest of
            // a row of cells an image reaches into (white holes under every tile).
            let bh = th.min(h - y);
            let cell = (x, y, tw.min(w - x), bh);
            let shown = &self.shown.as_ref()?.1;
            let Some((left, _, bw, _)) = scan::changed_in(shown, &self.candidate, stride, bpp, cell) else { continue };
            // Only the changed columns (whole cells for sixel), all of the tile's rows.
            let x0 = left / ux * ux;
            let mut width = ((left + bw).div_ceil(ux) * ux).min(cell.0 + cell.2) - x0;
            loop {
                let tile = Part::Tile(x0, y, width, bh);
                self.bytes.clear();
                if sixel {
                    let encoder = self.sixel.as_mut().expect("a sixel stream has its encoder");
                    encoder.push_block(
                        &mut self.bytes,
                        &self.candidate,
                        w,
                        (x0, y, width, bh),
                        self.layout.origin,
                        self.layout.cell_px,
                    );
                } else {
                    let packing = self.packing(limited, rung);
                    self.push_part(tile, rung, packing);
                }
                if self.bytes.len() <= room {
                    self.next_tile = (index + 1) % count;
                    return Some(tile);
                }
                if width <= ux {
                    return None;
                }
                width = (width / 2 / ux * ux).max(ux);
            }
        }
        None
    }
}
