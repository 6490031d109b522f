//! `auto`'s switch between pixels and cells without a blank screen in between.
//!
//! A switch used to repaint from an unknown screen: the kitty image was deleted first and the
//! cell encoder, which could not paint the whole screen within the link's rate, cleared it
//! (`ESC[2J`) and painted the cells over the following frames: about a second of black (seen
//! in real kitty 0.26 over the stock 2 Mbit/s link). Now the terminal's cells stay known
//! across a switch of the same size, and the old picture stays until the new one covers it:
//! - **pixels to cells**: the cells are painted over the picture (kitty's image is drawn at
//!   z = -1, under the cells' glyphs and over their backgrounds, so the half-blocks' upper
//!   halves show through it at once; sixel and iTerm2 pixels are overwritten cell by cell),
//!   and kitty's image is deleted in the frame whose cells leave no picture cell blank;
//! - **cells to pixels**: the cells above the status line are kept as they are until the
//!   first picture has gone (after them, in the same frame); then they are blanked over the
//!   following frames, which uncovers kitty's image beneath them. Sixel, iTerm2 and kitty's
//!   placeholder cells replace the cells they are drawn on: those cells are blank from then on.

use super::{Screen, big_enough};
use crate::output::frame::{Cell, Frame};

/// A switch under way.
#[derive(Debug)]
pub(super) enum Switch {
    /// From pixels to cells: `delete` takes the old picture away once the cells cover it
    /// (kitty's image; empty for sixel and iTerm2, which the cells overwrite).
    ToCells { delete: Vec<u8> },
    /// From cells to pixels: the cells stay until the first picture is sent.
    ToPixels,
}

/// Whether every cell above the status line that `wanted` paints is painted in `shown`: no
/// cell is still blank where a cell of the picture goes.
pub(super) fn covered(shown: &Frame, wanted: &Frame) -> bool {
    if (shown.cols(), shown.rows()) != (wanted.cols(), wanted.rows()) {
        return false;
    }
    let above_status = shown.cols() * shown.rows().saturating_sub(1);
    shown.cells()[..above_status]
        .iter()
        .zip(&wanted.cells()[..above_status])
        .all(|(s, w)| *s != Cell::BLANK || *w == Cell::BLANK)
}

/// `composed` with the cells above the status line taken from `shown` (the same size), so the
/// frame changes only the status line.
pub(super) fn keep_picture_rows(composed: &mut Frame, shown: &Frame) {
    if (shown.cols(), shown.rows()) != (composed.cols(), composed.rows()) {
        return;
    }
    for y in 0..composed.rows().saturating_sub(1) {
        for x in 0..composed.cols() {
            composed.set(x, y, shown.get(x, y));
        }
    }
}

impl Screen {
    /// Before a frame's cells: a screen whose cells are unknown (a resize) is repainted whole
    /// anyway, so a switch under way ends now (kitty's old image goes first, as before).
    pub(super) fn switch_before_cells(&mut self, out: &mut Vec<u8>) {
        if self.shown.frame.is_none()
            && let Some(Switch::ToCells { delete }) = self.switch.take()
        {
            out.extend_from_slice(&delete);
        }
    }

    /// Whether the frame's cells above the status line are to stay as they are (cells to
    /// pixels, the picture not sent yet).
    pub(super) fn keeps_cells(&self) -> bool {
        matches!(self.switch, Some(Switch::ToPixels)) && self.shown.frame.is_some()
    }

    /// After a frame's cells (`covered`: they leave no picture cell blank; `None`: a group's
    /// cells, which are whole): the old picture's delete, appended to `bytes`, once the cells
    /// cover it (or once the terminal is too small to show either).
    pub(super) fn switch_after_cells(&mut self, covered: Option<bool>, bytes: &mut Vec<u8>) {
        let done = covered.unwrap_or(true) || !big_enough(self.term);
        if done && let Some(Switch::ToCells { delete }) = self.switch.take_if(|s| matches!(s, Switch::ToCells { .. })) {
            super::picture::splice_picture(bytes, &delete, self.config.encode.sync);
        }
    }

    /// After the frame's picture (`sent`: its bytes): the first picture after a switch to
    /// pixels ends the switch; cells the picture replaced (sixel, iTerm2, kitty's placeholders)
    /// are blank in the terminal's model now, and the others are blanked by the next frames.
    pub(super) fn switch_after_picture(&mut self, sent: usize) {
        if sent == 0 || !matches!(self.switch, Some(Switch::ToPixels)) {
            return;
        }
        self.switch = None;
        let (Some(p), Some(frame)) = (&self.picture, &mut self.shown.frame) else { return };
        if !p.replaces_cells() {
            return;
        }
        let layout = p.layout();
        let (x0, y0) = (usize::from(layout.origin.0), usize::from(layout.origin.1));
        let x1 = (x0 + usize::from(layout.cells.0)).min(frame.cols());
        let y1 = (y0 + usize::from(layout.cells.1)).min(frame.rows().saturating_sub(1));
        for y in y0..y1 {
            for x in x0..x1 {
                frame.set(x, y, Cell::BLANK);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::color::Color;

    fn pixels(shade: u8) -> Cell {
        Cell::Pixels { top: Color::Rgb([shade, 90, 160]), bottom: Color::Rgb([shade, 80, 150]) }
    }

    #[test]
    fn the_cells_cover_the_picture_only_when_no_picture_cell_is_blank_and_the_status_line_does_not_count() {
        let mut wanted = Frame::new(4, 3);
        let mut shown = Frame::new(4, 3);
        for y in 0..2 {
            for x in 0..4 {
                wanted.set(x, y, pixels(10));
            }
        }
        assert!(!covered(&shown, &wanted), "blank cells where the picture goes");
        for y in 0..2 {
            for x in 0..4 {
                // Approximate cells (a different colour) cover it too.
                shown.set(x, y, pixels(40));
            }
        }
        shown.set(3, 1, Cell::BLANK);
        assert!(!covered(&shown, &wanted), "one cell left");
        shown.set(3, 1, pixels(40));
        assert!(covered(&shown, &wanted), "the status line (blank here) is not the picture");
        assert!(!covered(&Frame::new(5, 3), &wanted), "another size never covers");
    }

    #[test]
    fn a_kept_frame_changes_only_the_status_line() {
        let mut shown = Frame::new(3, 3);
        shown.set(1, 1, pixels(7));
        let mut composed = Frame::new(3, 3);
        composed.set(0, 2, Cell::Text { ch: 'p', fg: Color::Default, bg: Color::Default });
        keep_picture_rows(&mut composed, &shown);
        assert_eq!(composed.get(1, 1), pixels(7));
        assert_eq!(composed.get(0, 2), Cell::Text { ch: 'p', fg: Color::Default, bg: Color::Default });
    }
}
