//! The bytes of one frame's chosen cells, in screen order, with exact accounting.
//!
//! The same moves and colour codes as [`crate::output::diff`]: the shortest cursor move or a
//! re-print of a short gap whose cells need no colour change, each colour code only when it
//! differs from the pen, and the cheapest of `▀`, `▄`, `█` or a space for the pen in effect.
//! With every changed cell chosen, the bytes are exactly `diff::encode_into`'s.

use crate::output::color::Color;
use crate::output::cursor::{self, Cursor};
use crate::output::diff::{Draw, best_draw, push_color_params};
use crate::output::frame::{Cell, Frame};

/// A cell that is not drawn this frame.
pub(super) const SKIP: u8 = 0;
/// A cell drawn exactly as wanted. Choices `1..=MAX_VARIANTS` draw the cell's variant of that
/// rank.
pub(super) const EXACT: u8 = u8::MAX;

/// The terminal's cursor and the colours in effect (`None`: unknown).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Pen {
    pub cursor: Cursor,
    pub fg: Option<Color>,
    pub bg: Option<Color>,
}

/// The bytes a frame's cells may take: a frame of one cell needs no synchronized-output
/// markers (one cell cannot tear), so it may take a little more than a frame of several.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct Room {
    /// For a single cell.
    pub one: usize,
    /// For two or more cells.
    pub many: usize,
}

impl Room {
    /// Whether `bytes` for `cells` cells fit.
    pub fn fits(self, bytes: usize, cells: usize) -> bool {
        bytes <= if cells <= 1 { self.one } else { self.many }
    }
}

/// What to draw where.
pub(super) struct Plan<'a> {
    /// What the terminal shows now (read for re-printed gaps, which are never drawn cells).
    pub shown: &'a Frame,
    /// The wanted frame.
    pub wanted: &'a Frame,
    /// Per cell: [`SKIP`], [`EXACT`] or the rank of a variant.
    pub choice: &'a [u8],
    /// Per cell, its variants by rank (read only where the choice is a rank).
    pub variants: &'a [[Cell; super::MAX_VARIANTS]],
}

impl Plan<'_> {
    /// Appends the chosen cells' bytes to `out` starting from `pen`, and each drawn cell (its
    /// index and what it now shows) to `drawn`. With a `limit`, stops before the first cell
    /// whose bytes would not fit in it. Returns the pen afterwards.
    pub fn emit(&self, mut pen: Pen, limit: Option<Room>, out: &mut Vec<u8>, drawn: &mut Vec<(u32, Cell)>) -> Pen {
        let (start, first) = (out.len(), drawn.len());
        let cols = self.wanted.cols();
        for (i, &choice) in self.choice.iter().enumerate() {
            if choice == SKIP {
                continue;
            }
            let (x, y) = (i % cols, i / cols);
            let cell = match choice {
                EXACT => self.wanted.get(x, y),
                rank => self.variants[i][usize::from(rank) - 1],
            };
            let (before, saved) = (out.len(), pen);
            self.reach(&mut pen, (x, y), out);
            let draw = best_draw(cell, pen.fg, pen.bg);
            push_draw(out, &mut pen, draw);
            if limit.is_some_and(|room| !room.fits(out.len() - start, drawn.len() - first + 1)) {
                out.truncate(before);
                return saved;
            }
            pen.cursor = if x + 1 < cols { Cursor::At(x + 1, y) } else { Cursor::Wrapped(y) };
            drawn.push((i as u32, cell));
        }
        pen
    }

    /// Moves the cursor to `(x, y)`: a jump, or a re-print of the cells in between when they
    /// are on the same row, need no colour change and cost fewer bytes than the jump.
    fn reach(&self, pen: &mut Pen, (x, y): (usize, usize), out: &mut Vec<u8>) {
        if let Cursor::At(cx, cy) = pen.cursor
            && cy == y
            && cx < x
        {
            let jump = cursor::move_len(pen.cursor, (x, y));
            let gap: Option<usize> = (cx..x)
                .map(|gx| {
                    let d = best_draw(self.shown.get(gx, y), pen.fg, pen.bg);
                    (d.sgr_len(pen.fg, pen.bg) == 0).then(|| d.ch.len_utf8())
                })
                .try_fold(0, |sum, len| len.map(|l| sum + l).filter(|&s| s < jump));
            if gap.is_some() {
                for gx in cx..x {
                    let d = best_draw(self.shown.get(gx, y), pen.fg, pen.bg);
                    let mut buf = [0u8; 4];
                    out.extend_from_slice(d.ch.encode_utf8(&mut buf).as_bytes());
                }
                return;
            }
        }
        cursor::push_move(out, pen.cursor, (x, y));
    }
}

/// Appends the colour codes `draw` needs beyond the pen, then its glyph.
fn push_draw(out: &mut Vec<u8>, pen: &mut Pen, draw: Draw) {
    let new_fg = draw.fg.filter(|&c| pen.fg != Some(c));
    let new_bg = draw.bg.filter(|&c| pen.bg != Some(c));
    if new_fg.is_some() || new_bg.is_some() {
        out.extend_from_slice(b"\x1b[");
        if let Some(f) = new_fg {
            push_color_params(out, f, false);
            pen.fg = Some(f);
        }
        if let Some(b) = new_bg {
            if new_fg.is_some() {
                out.push(b';');
            }
            push_color_params(out, b, true);
            pen.bg = Some(b);
        }
        out.push(b'm');
    }
    let mut buf = [0u8; 4];
    out.extend_from_slice(draw.ch.encode_utf8(&mut buf).as_bytes());
}
