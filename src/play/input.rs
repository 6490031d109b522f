//! Bytes from the terminal -> what they mean: the person's [`Input`]s and the terminal's
//! [`Reply`]s, framed in one place.
//!
//! The session reads the terminal's bytes itself instead of through crossterm's event reader, so
//! it runs the same over a local terminal and an SSH channel, and so it can tell the terminal's
//! *replies* (device attributes, kitty graphics answers, mode and size reports) from key presses:
//! crossterm turns `ESC _` into Alt-`_` and the rest of an APC reply into keys, so a late kitty
//! reply's digits would set the ocean's Beaufort number. Every escape sequence is first offered to
//! [`crate::play::replies::parse_reply`] (the one description of what a reply looks like, which
//! the graphics probe and the link control read); what is not a reply is read as a key here. So
//! the two can never disagree on where a sequence ends (`ESC P` + a letter is Alt-P and a letter
//! to both).
//!
//! Keys understood: printable characters (UTF-8), Enter, Tab and Shift-Tab, Ctrl-C, Esc, the arrow
//! keys (`CSI A..D` and `SS3 A..D`), and mouse reports in SGR form (`CSI < b;x;y M/m`, mode 1006)
//! and the legacy X10 form (`CSI M b x y`). Everything else (function keys, modified keys, Alt
//! combinations, unknown sequences) is [`Received::Unknown`]. A lone `ESC` is the Escape key only
//! once no more bytes follow within [`ESC_WAIT`]; until then it may start a sequence.
//!
//! Mouse motion is reported for button presses and drags only (mode 1002), not for every motion;
//! [`coalesce`] reduces a burst of drags to the latest position (the stir interpolates the path).

use std::time::{Duration, Instant};

/// How long a lone `ESC` waits for the rest of a sequence before it counts as the Escape key.
pub const ESC_WAIT: Duration = Duration::from_millis(40);
/// The longest sequence kept while waiting for its end; longer ones are dropped as garbage.
pub const MAX_SEQUENCE: usize = 8192;

use super::replies::{Expecting, Reply, parse_reply};

/// What the person asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Input {
    /// Leave (`q`, `Ctrl-C`).
    Quit,
    /// `Esc`: closes the help if it is open, else quits.
    Escape,
    /// A stone at a random spot (`space`).
    RandomStone,
    /// Move the aim by (columns, rows) (arrow keys, `hjkl`).
    Aim(i32, i32),
    /// A stone at the aim (`enter`).
    DropAtAim,
    /// `r`.
    ToggleRain,
    /// `c`.
    Clear,
    /// `+` (true) or `-` (false).
    StoneSize(bool),
    /// `[` (true: damp more) or `]`.
    Damping(bool),
    /// `p`.
    Pause,
    /// `s`.
    Screenshot,
    /// `Tab`.
    NextScene,
    /// `?`.
    Help,
    /// Any other character, for the scene's own keys.
    Other(char),
    /// A mouse button went down in cell (column, row); `big` for the right button.
    Press {
        /// Column, from 0.
        col: u16,
        /// Row, from 0.
        row: u16,
        /// Right button.
        big: bool,
    },
    /// The left button was dragged to cell (column, row).
    Drag {
        /// Column, from 0.
        col: u16,
        /// Row, from 0.
        row: u16,
    },
    /// The mouse button was released.
    Release,
}

/// One thing read from the terminal.
#[derive(Clone, Debug, PartialEq)]
pub enum Received {
    /// Something the person did.
    Input(Input),
    /// The terminal's answer to a question (see [`crate::play::replies`]).
    Reply(Reply),
    /// An escape sequence that is neither a key tidepool knows nor a reply (a function key, an
    /// Alt combination, garbage): ignored in play; during the graphics probe it means the
    /// terminal answered something else.
    Unknown,
}

/// An incremental parser: feed it bytes as they arrive, get inputs out.
#[derive(Clone, Debug, Default)]
pub struct InputParser {
    pending: Vec<u8>,
    /// When the oldest pending byte arrived.
    since: Option<Instant>,
    /// Inside a string sequence (APC, DCS, OSC) longer than [`MAX_SEQUENCE`]: its bytes are
    /// dropped until its terminator, or until the terminal falls silent for [`ESC_WAIT`].
    skipping: bool,
}

/// What the start of the buffer holds.
enum Framed {
    /// A complete item of this many bytes, and what it means (nothing: a control byte).
    Item(usize, Option<Received>),
    /// The start of a sequence whose end has not arrived.
    Incomplete,
}

impl InputParser {
    /// A parser with nothing pending.
    pub fn new() -> InputParser {
        InputParser::default()
    }

    /// Parses `bytes` that arrived at `now`, appending what they mean to `out`.
    pub fn feed(&mut self, bytes: &[u8], now: Instant, out: &mut Vec<Received>) {
        if bytes.is_empty() {
            return;
        }
        let mut bytes = bytes;
        if self.skipping {
            // The rest of an overlong string: drop up to its terminator.
            match bytes.iter().position(|&b| b == 0x07 || b == b'\\') {
                Some(end) => {
                    bytes = &bytes[end + 1..];
                    self.skipping = false;
                }
                None => {
                    self.since = Some(now);
                    return;
                }
            }
        }
        if self.pending.is_empty() {
            self.since = Some(now);
        }
        self.pending.extend_from_slice(bytes);
        self.drain(out, false);
        if self.pending.is_empty() {
            self.since = None;
        } else if self.pending.len() > MAX_SEQUENCE {
            // A sequence that never ends (or a flood of garbage): drop what is kept and, if it
            // is a string, the rest of it as it comes.
            self.skipping = matches!(self.pending.get(1), Some(b'_' | b'P' | b']' | b'X' | b'^'));
            self.pending.clear();
            self.since = Some(now);
        }
    }

    /// Resolves what is pending once no more bytes have come for `ESC_WAIT` (40 ms): a lone `ESC` is
    /// the Escape key, an unfinished sequence is dropped.
    pub fn flush_stale(&mut self, now: Instant, out: &mut Vec<Received>) {
        if self.since.is_some_and(|t| now.saturating_duration_since(t) >= ESC_WAIT) {
            self.drain(out, true);
            self.pending.clear();
            self.since = None;
            self.skipping = false;
        }
    }

    /// When [`InputParser::flush_stale`] should next be called (`None`: nothing pending).
    pub fn deadline(&self) -> Option<Instant> {
        self.since.map(|t| t + ESC_WAIT)
    }

    fn drain(&mut self, out: &mut Vec<Received>, stale: bool) {
        let mut at = 0;
        while at < self.pending.len() {
            match parse_one(&self.pending[at..], stale) {
                Framed::Item(len, Some(Received::Reply(Reply::Overlong))) => {
                    // The rest of an overlong string follows: drop it up to its terminator.
                    out.push(Received::Unknown);
                    at += len.max(1);
                    match self.pending[at..].iter().position(|&b| b == 0x07 || b == b'\\') {
                        Some(end) => at += end + 1,
                        None => {
                            at = self.pending.len();
                            self.skipping = true;
                        }
                    }
                }
                Framed::Item(len, received) => {
                    out.extend(received);
                    at += len.max(1);
                }
                Framed::Incomplete => break,
            }
        }
        self.pending.drain(..at);
    }
}

const ESC: u8 = 0x1b;

/// Parses the item at the start of `b`. With `stale`, an incomplete sequence is taken as what
/// it is so far: a lone ESC is the Escape key, anything longer is dropped.
fn parse_one(b: &[u8], stale: bool) -> Framed {
    let incomplete = |len: usize, lone_escape: bool| {
        if !stale {
            Framed::Incomplete
        } else if lone_escape {
            Framed::Item(1, Some(Received::Input(Input::Escape)))
        } else {
            Framed::Item(len, Some(Received::Unknown))
        }
    };
    let input =
        |len: usize, input: Option<Input>| Framed::Item(len, Some(input.map_or(Received::Unknown, Received::Input)));
    match b[0] {
        ESC => match b.get(1) {
            None => incomplete(1, true),
            // Replies first: the one description of where a reply ends.
            Some(b'[' | b'_' | b'P' | b']') => match parse_reply(b, Expecting::CURSOR_POSITION) {
                crate::play::replies::Parsed::Complete(reply, len) => Framed::Item(len, Some(Received::Reply(reply))),
                crate::play::replies::Parsed::Incomplete if !stale => Framed::Incomplete,
                crate::play::replies::Parsed::Incomplete if b[1] != b'[' => incomplete(b.len(), false),
                _ if b[1] == b'[' => parse_csi(b, stale),
                // `ESC P`, `ESC ]`, `ESC _` that cannot be a reply: Alt and a key, ignored.
                _ => input(2, None),
            },
            Some(b'O') => match b.get(2) {
                None => incomplete(2, false),
                Some(&c) => input(3, arrow(c)),
            },
            // SOS and PM strings, up to ST: never keys, never replies tidepool asks for.
            Some(b'X' | b'^') => match string_end(b) {
                Some(len) => input(len, None),
                None => incomplete(b.len(), false),
            },
            // ESC ESC: the first is a lone Escape key pressed twice, or Alt-Esc.
            Some(&ESC) => input(1, Some(Input::Escape)),
            // Alt plus a key (or a stray ESC): ignored, with the byte after it.
            Some(&c) => input((1 + utf8_len(Some(c))).min(b.len()), None),
        },
        0x03 => input(1, Some(Input::Quit)),
        b'\r' | b'\n' => input(1, Some(Input::DropAtAim)),
        b'\t' => input(1, Some(Input::NextScene)),
        c if c < 0x20 || c == 0x7f => Framed::Item(1, None),
        c if c < 0x80 => input(1, Some(key(c as char))),
        c => {
            let len = utf8_len(Some(c));
            if b.len() < len {
                return incomplete(b.len(), false);
            }
            match std::str::from_utf8(&b[..len]).ok().and_then(|s| s.chars().next()) {
                Some(ch) => input(len, Some(Input::Other(ch))),
                None => Framed::Item(1, None),
            }
        }
    }
}

/// The length of a UTF-8 sequence from its first byte (1 for anything invalid).
fn utf8_len(first: Option<u8>) -> usize {
    match first {
        Some(0xC2..=0xDF) => 2,
        Some(0xE0..=0xEF) => 3,
        Some(0xF0..=0xF4) => 4,
        _ => 1,
    }
}

/// The length of an ESC-introduced string up to and including its terminator, if it is there.
fn string_end(b: &[u8]) -> Option<usize> {
    let osc = b[1] == b']';
    (2..b.len()).find_map(|i| match b[i] {
        0x07 if osc => Some(i + 1),
        ESC if b.get(i + 1) == Some(&b'\\') => Some(i + 2),
        _ => None,
    })
}

fn arrow(c: u8) -> Option<Input> {
    match c {
        b'A' => Some(Input::Aim(0, -1)),
        b'B' => Some(Input::Aim(0, 1)),
        b'C' => Some(Input::Aim(1, 0)),
        b'D' => Some(Input::Aim(-1, 0)),
        _ => None,
    }
}

/// `ESC [` parameters, intermediates, final byte: a key (replies were tried first).
fn parse_csi(b: &[u8], stale: bool) -> Framed {
    let known =
        |len: usize, input: Option<Input>| Framed::Item(len, Some(input.map_or(Received::Unknown, Received::Input)));
    // The legacy X10 mouse report: `ESC [ M` and three raw bytes.
    if b.get(2) == Some(&b'M') {
        return match b.get(3..6) {
            Some(&[cb, cx, cy]) => known(6, x10_mouse(u32::from(cb.wrapping_sub(32)), cx, cy)),
            _ if stale => known(b.len(), None),
            _ => Framed::Incomplete,
        };
    }
    let Some(end) = (2..b.len()).find(|&i| (0x40..=0x7e).contains(&b[i])) else {
        return if stale { known(b.len(), None) } else { Framed::Incomplete };
    };
    let body = &b[2..end];
    let final_byte = b[end];
    let len = end + 1;
    // A byte that cannot be in a sequence ends it as garbage.
    if body.iter().any(|&c| !(0x20..=0x3f).contains(&c)) {
        return known(len, None);
    }
    let input = match (body.first(), final_byte) {
        (None, b'A'..=b'D') => arrow(final_byte),
        (None, b'Z') => Some(Input::NextScene),
        (Some(b'<'), b'M' | b'm') => sgr_mouse(&body[1..], final_byte == b'M'),
        // Function keys, modified keys, unknown sequences.
        _ => None,
    };
    known(len, input)
}

/// The numbers of a `;`-separated parameter list (`None` for an empty or oversized one).
fn params(body: &[u8]) -> impl Iterator<Item = Option<u16>> + '_ {
    body.split(|&c| c == b';').map(|p| std::str::from_utf8(p).ok()?.parse::<u16>().ok())
}

fn sgr_mouse(body: &[u8], pressed: bool) -> Option<Input> {
    let mut numbers = params(body);
    let (Some(Some(cb)), Some(Some(x)), Some(Some(y)), None) =
        (numbers.next(), numbers.next(), numbers.next(), numbers.next())
    else {
        return None;
    };
    if !pressed {
        return Some(Input::Release);
    }
    let (col, row) = (x.saturating_sub(1), y.saturating_sub(1));
    button(u32::from(cb), col, row)
}

/// An X10 report: button byte and 1-based coordinates offset by 32.
fn x10_mouse(cb: u32, cx: u8, cy: u8) -> Option<Input> {
    let (col, row) = (u16::from(cx.saturating_sub(33)), u16::from(cy.saturating_sub(33)));
    if cb & 3 == 3 && cb & 32 == 0 {
        return Some(Input::Release);
    }
    button(cb, col, row)
}

/// Button code (low bits: 0 left, 1 middle, 2 right; +32 motion; +64 wheel) at a cell.
fn button(cb: u32, col: u16, row: u16) -> Option<Input> {
    if cb & 64 != 0 {
        return None; // the wheel
    }
    let motion = cb & 32 != 0;
    match (cb & 3, motion) {
        (0, false) => Some(Input::Press { col, row, big: false }),
        (2, false) => Some(Input::Press { col, row, big: true }),
        (0, true) => Some(Input::Drag { col, row }),
        _ => None,
    }
}

/// The input a plain character means.
fn key(c: char) -> Input {
    match c {
        'q' | 'Q' => Input::Quit,
        ' ' => Input::RandomStone,
        'h' => Input::Aim(-1, 0),
        'l' => Input::Aim(1, 0),
        'k' => Input::Aim(0, -1),
        'j' => Input::Aim(0, 1),
        'r' => Input::ToggleRain,
        'c' => Input::Clear,
        '+' | '=' => Input::StoneSize(true),
        '-' | '_' => Input::StoneSize(false),
        '[' => Input::Damping(true),
        ']' => Input::Damping(false),
        'p' => Input::Pause,
        's' => Input::Screenshot,
        '?' => Input::Help,
        other => Input::Other(other),
    }
}

/// Merges runs of drags into their last position, in place; everything else is kept in order.
pub fn coalesce(inputs: &mut Vec<Input>) {
    inputs.dedup_by(|next, last| {
        let drags = matches!((&*last, &*next), (Input::Drag { .. }, Input::Drag { .. }));
        if drags {
            *last = *next;
        }
        drags
    });
}

#[cfg(test)]
mod tests;
