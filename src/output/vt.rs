//! A small terminal model: enough of a VT/xterm to decode what tidepool writes back into
//! pixels. Tests use it to check that encoded frames reproduce the picture, without a terminal.
//!
//! Understood: printable UTF-8 (with pending-wrap at the right margin), CR, LF (with or without
//! an implied CR, like a tty's `onlcr`), backspace, CSI cursor movement (`H f A B C D E F G d`),
//! erase (`J K`), SGR (`0`, `39`, `49`, `38/48;2;r;g;b`, `38/48;5;n`, 30-37/40-47/90-97/100-107)
//! and DEC private modes (`?1049`, `?25`, `?2026`, mouse modes), whose state is recorded.
//! CAN/SUB abort a sequence, ESC inside a CSI restarts it.
//! Anything else is ignored.

use crate::output::color::xterm_256;
use crate::output::halfblock::Rgb;

/// One character cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ModelCell {
    /// The character shown.
    pub ch: char,
    /// Foreground colour; `None` is the terminal's default.
    pub fg: Option<Rgb>,
    /// Background colour; `None` is the terminal's default.
    pub bg: Option<Rgb>,
}

impl Default for ModelCell {
    fn default() -> Self {
        ModelCell { ch: ' ', fg: None, bg: None }
    }
}

/// A grid of cells with a cursor and the current colours.
#[derive(Clone, Debug)]
pub struct TerminalModel {
    cols: usize,
    rows: usize,
    cells: Vec<ModelCell>,
    cursor: (usize, usize),
    wrap_pending: bool,
    fg: Option<Rgb>,
    bg: Option<Rgb>,
    /// Whether LF also returns the carriage (a cooked tty with `onlcr`): true by default.
    pub lf_returns: bool,
    private_modes: std::collections::BTreeMap<u16, bool>,
    state: Parse,
    utf8: Vec<u8>,
}

#[derive(Clone, Debug, PartialEq)]
enum Parse {
    Ground,
    Escape,
    Csi(Vec<u8>),
    /// OSC, DCS, APC, SOS or PM string (a sixel picture, a kitty graphics command), skipped
    /// until ST or BEL.
    Text {
        seen_esc: bool,
    },
}

impl TerminalModel {
    /// A blank `cols x rows` screen with the cursor at the top left.
    pub fn new(cols: usize, rows: usize) -> TerminalModel {
        TerminalModel {
            cols,
            rows,
            cells: vec![ModelCell::default(); cols * rows],
            cursor: (0, 0),
            wrap_pending: false,
            fg: None,
            bg: None,
            lf_returns: true,
            private_modes: Default::default(),
            state: Parse::Ground,
            utf8: Vec::new(),
        }
    }

    /// Columns.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The cell at column `x`, row `y`.
    pub fn cell(&self, x: usize, y: usize) -> ModelCell {
        self.cells[y * self.cols + x]
    }

    /// The cursor as (column, row).
    pub fn cursor(&self) -> (usize, usize) {
        self.cursor
    }

    /// Whether DEC private mode `mode` was last set (`h`) rather than reset (`l`); `None` when
    /// it was never mentioned.
    pub fn private_mode(&self, mode: u16) -> Option<bool> {
        self.private_modes.get(&mode).copied()
    }

    /// The text of row `y`, trailing spaces kept.
    pub fn row_text(&self, y: usize) -> String {
        self.cells[y * self.cols..(y + 1) * self.cols].iter().map(|c| c.ch).collect()
    }

    /// The colour of half-block pixel `(x, y)`: row `y / 2`, upper or lower half. `None` when
    /// that half shows the default colour, or the cell holds something other than `▀`, `▄`,
    /// `█` or a space.
    pub fn pixel(&self, x: usize, y: usize) -> Option<Rgb> {
        if x >= self.cols || y / 2 >= self.rows {
            return None;
        }
        let cell = self.cell(x, y / 2);
        let upper = y.is_multiple_of(2);
        match cell.ch {
            '\u{2580}' => {
                if upper {
                    cell.fg
                } else {
                    cell.bg
                }
            }
            '\u{2584}' => {
                if upper {
                    cell.bg
                } else {
                    cell.fg
                }
            }
            '\u{2588}' => cell.fg,
            ' ' => cell.bg,
            _ => None,
        }
    }

    /// Feeds bytes as a terminal would receive them.
    pub fn feed(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.byte(b);
        }
    }

    fn byte(&mut self, b: u8) {
        // CAN and SUB abort any sequence; ESC starts a new one (as in xterm).
        if self.state != Parse::Ground && matches!(b, 0x18 | 0x1a) {
            self.state = Parse::Ground;
            return;
        }
        if matches!(self.state, Parse::Csi(_)) && b == 0x1b {
            self.state = Parse::Escape;
            return;
        }
        match std::mem::replace(&mut self.state, Parse::Ground) {
            Parse::Ground => self.ground(b),
            Parse::Escape => match b {
                b'[' => self.state = Parse::Csi(Vec::new()),
                b']' | b'P' | b'_' | b'X' | b'^' => self.state = Parse::Text { seen_esc: false },
                b'c' => {
                    *self = TerminalModel { lf_returns: self.lf_returns, ..TerminalModel::new(self.cols, self.rows) }
                }
                _ => {} // ESC 7 / ESC 8 / charset selection: not used by tidepool
            },
            Parse::Csi(mut params) => {
                if (0x40..=0x7e).contains(&b) {
                    self.csi(&params, b);
                } else {
                    params.push(b);
                    self.state = Parse::Csi(params);
                }
            }
            Parse::Text { seen_esc } => {
                if b == 0x07 || (seen_esc && b == b'\\') {
                    return;
                }
                self.state = Parse::Text { seen_esc: b == 0x1b };
            }
        }
    }

    fn ground(&mut self, b: u8) {
        match b {
            0x1b => {
                self.utf8.clear();
                self.state = Parse::Escape;
            }
            b'\r' => {
                self.cursor.0 = 0;
                self.wrap_pending = false;
            }
            b'\n' => {
                if self.lf_returns {
                    self.cursor.0 = 0;
                }
                self.line_feed();
            }
            0x08 => {
                self.cursor.0 = self.cursor.0.saturating_sub(1);
                self.wrap_pending = false;
            }
            0x00..=0x1f | 0x7f => {}
            _ => {
                self.utf8.push(b);
                match std::str::from_utf8(&self.utf8) {
                    Ok(s) => {
                        let ch = s.chars().next().unwrap_or(' ');
                        self.utf8.clear();
                        self.print(ch);
                    }
                    Err(e) if e.error_len().is_some() => self.utf8.clear(),
                    Err(_) => {} // an incomplete sequence: wait for more bytes
                }
            }
        }
    }

    fn line_feed(&mut self) {
        self.wrap_pending = false;
        if self.cursor.1 + 1 < self.rows {
            self.cursor.1 += 1;
        } else if self.rows > 0 {
            self.cells.rotate_left(self.cols);
            let start = (self.rows - 1) * self.cols;
            self.cells[start..].fill(ModelCell { bg: self.bg, ..ModelCell::default() });
        }
    }

    fn print(&mut self, ch: char) {
        if self.cols == 0 || self.rows == 0 {
            return;
        }
        if self.wrap_pending {
            self.cursor.0 = 0;
            self.line_feed();
        }
        let (x, y) = self.cursor;
        self.cells[y * self.cols + x] = ModelCell { ch, fg: self.fg, bg: self.bg };
        if x + 1 < self.cols {
            self.cursor.0 += 1;
        } else {
            self.wrap_pending = true;
        }
    }

    fn csi(&mut self, raw: &[u8], command: u8) {
        let private = raw.first() == Some(&b'?');
        let text = String::from_utf8_lossy(if private { &raw[1..] } else { raw });
        let params: Vec<u32> = text.split(';').map(|p| p.parse().unwrap_or(0)).collect();
        let n = |i: usize| params.get(i).copied().filter(|&v| v > 0).unwrap_or(1) as usize;
        if private {
            if matches!(command, b'h' | b'l') {
                for &mode in &params {
                    self.private_modes.insert(mode as u16, command == b'h');
                }
            }
            return;
        }
        let (cols, rows) = (self.cols.max(1), self.rows.max(1));
        // SGR leaves a pending wrap alone (as xterm does); moves and erases cancel it.
        if command != b'm' {
            self.wrap_pending = false;
        }
        match command {
            b'H' | b'f' => self.cursor = ((n(1) - 1).min(cols - 1), (n(0) - 1).min(rows - 1)),
            b'A' => self.cursor.1 = self.cursor.1.saturating_sub(n(0)),
            b'B' => self.cursor.1 = (self.cursor.1 + n(0)).min(rows - 1),
            b'C' => self.cursor.0 = (self.cursor.0 + n(0)).min(cols - 1),
            b'D' => self.cursor.0 = self.cursor.0.saturating_sub(n(0)),
            b'E' => self.cursor = (0, (self.cursor.1 + n(0)).min(rows - 1)),
            b'F' => self.cursor = (0, self.cursor.1.saturating_sub(n(0))),
            b'G' => self.cursor.0 = (n(0) - 1).min(cols - 1),
            b'd' => self.cursor.1 = (n(0) - 1).min(rows - 1),
            b'J' => self.erase_display(params.first().copied().unwrap_or(0)),
            b'K' => self.erase_line(params.first().copied().unwrap_or(0)),
            b'm' => self.sgr(&params),
            _ => {}
        }
    }

    fn erase(&mut self, from: usize, to: usize) {
        let blank = ModelCell { bg: self.bg, ..ModelCell::default() };
        let to = to.min(self.cells.len());
        if from < to {
            self.cells[from..to].fill(blank);
        }
    }

    fn erase_display(&mut self, mode: u32) {
        let here = self.cursor.1 * self.cols + self.cursor.0;
        match mode {
            0 => self.erase(here, self.cells.len()),
            1 => self.erase(0, here + 1),
            _ => self.erase(0, self.cells.len()),
        }
    }

    fn erase_line(&mut self, mode: u32) {
        let start = self.cursor.1 * self.cols;
        let here = start + self.cursor.0;
        match mode {
            0 => self.erase(here, start + self.cols),
            1 => self.erase(start, here + 1),
            _ => self.erase(start, start + self.cols),
        }
    }

    fn sgr(&mut self, params: &[u32]) {
        let mut i = 0;
        while i < params.len() {
            match params[i] {
                0 => (self.fg, self.bg) = (None, None),
                39 => self.fg = None,
                49 => self.bg = None,
                code @ (38 | 48) => {
                    let colour = match params.get(i + 1) {
                        Some(2) if i + 4 < params.len() => {
                            let c = [params[i + 2], params[i + 3], params[i + 4]].map(|v| v.min(255) as u8);
                            i += 4;
                            Some(c)
                        }
                        Some(5) if i + 2 < params.len() => {
                            i += 2;
                            Some(xterm_256(params[i].min(255) as u8))
                        }
                        _ => None,
                    };
                    if let Some(c) = colour {
                        if code == 38 { self.fg = Some(c) } else { self.bg = Some(c) }
                    }
                }
                c @ 30..=37 => self.fg = Some(xterm_256((c - 30) as u8)),
                c @ 40..=47 => self.bg = Some(xterm_256((c - 40) as u8)),
                c @ 90..=97 => self.fg = Some(xterm_256((c - 90 + 8) as u8)),
                c @ 100..=107 => self.bg = Some(xterm_256((c - 100 + 8) as u8)),
                _ => {}
            }
            i += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cursor_moves_and_colours() {
        let mut s = TerminalModel::new(10, 4);
        s.feed(b"\x1b[2;3H\x1b[38;2;1;2;3m\x1b[48;5;16mX\x1b[2CY\x1b[0mZ");
        assert_eq!(s.cell(2, 1), ModelCell { ch: 'X', fg: Some([1, 2, 3]), bg: Some([0, 0, 0]) });
        assert_eq!(s.cell(5, 1).ch, 'Y');
        assert_eq!(s.cell(6, 1), ModelCell { ch: 'Z', fg: None, bg: None });
        assert_eq!(s.cursor(), (7, 1));
        s.feed(b"\x1b[A\x1b[3D\x1b[B\x1b[B\x1b[G\x1b[1dQ");
        assert_eq!(s.cell(0, 0).ch, 'Q');
    }

    #[test]
    fn pending_wrap_and_scroll() {
        let mut s = TerminalModel::new(3, 2);
        s.feed("abcdefg".as_bytes());
        assert_eq!(s.row_text(0), "def");
        assert_eq!(s.row_text(1), "g  ");
        s.lf_returns = false;
        s.feed(b"\nh");
        assert_eq!(s.row_text(1), " h ");
    }

    #[test]
    fn colour_changes_keep_a_pending_wrap() {
        let mut s = TerminalModel::new(3, 2);
        s.feed(b"abc\x1b[31md");
        assert_eq!(s.row_text(1), "d  ", "SGR does not cancel the wrap");
        s.feed(b"\x1b[1;1Habc\x1b[Cx");
        assert_eq!(s.row_text(0), "abx", "a cursor move does");
    }

    #[test]
    fn private_modes_are_recorded() {
        let mut s = TerminalModel::new(2, 2);
        s.feed(b"\x1b[?1049h\x1b[?25l\x1b[?2026h\x1b[?2026l");
        assert_eq!(s.private_mode(1049), Some(true));
        assert_eq!(s.private_mode(25), Some(false));
        assert_eq!(s.private_mode(2026), Some(false));
        assert_eq!(s.private_mode(1000), None);
    }

    #[test]
    fn half_blocks_decode_to_pixels() {
        let mut s = TerminalModel::new(3, 1);
        s.feed("\x1b[38;2;1;1;1m\x1b[48;2;2;2;2m\u{2580}\u{2584} ".as_bytes());
        assert_eq!((s.pixel(0, 0), s.pixel(0, 1)), (Some([1, 1, 1]), Some([2, 2, 2])));
        assert_eq!((s.pixel(1, 0), s.pixel(1, 1)), (Some([2, 2, 2]), Some([1, 1, 1])));
        assert_eq!((s.pixel(2, 0), s.pixel(2, 1)), (Some([2, 2, 2]), Some([2, 2, 2])));
    }

    #[test]
    fn xterm_palette_levels() {
        assert_eq!(xterm_256(16), [0, 0, 0]);
        assert_eq!(xterm_256(17), [0, 0, 95]);
        assert_eq!(xterm_256(231), [255, 255, 255]);
        assert_eq!(xterm_256(232), [8, 8, 8]);
        assert_eq!(xterm_256(255), [238, 238, 238]);
    }
}
