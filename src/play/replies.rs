//! Terminal replies in the input stream: recognised at the start of a buffer. The one input
//! parser ([`crate::play::input`]) offers every escape sequence here first, so the graphics
//! probe and the link control read replies framed exactly as the key reader sees them.
//! Unrecognised, a reply would turn into key presses (`ESC _ G i = 3 1 ; O K` would otherwise be
//! Alt-`_` and then keys, and a late kitty reply's digits would set the ocean's Beaufort
//! number).
//!
//! [`parse_reply`] is pure and incremental: given the bytes read so far it says
//! - [`Parsed::Complete`]: a whole reply of so many bytes starts the buffer;
//! - [`Parsed::Incomplete`]: the buffer is a proper prefix of a reply (read more; the caller's
//!   escape timeout still applies: a prefix that stays incomplete is keys after all);
//! - [`Parsed::NotAReply`]: the first bytes are input, not a reply.
//!
//! **Ambiguity.** Keys never produce APC, DCS or OSC strings, nor CSI sequences with a `?` or
//! `>` marker or ending in `t`, `n` or `$y`; those are always replies. Two shapes overlap keys:
//! - A cursor position report `CSI row ; col R` is also how some terminals send F3 with
//!   modifiers (`CSI 1 ; 5 R` is Ctrl-F3). It is taken as a reply only while one is outstanding
//!   ([`Expecting::cursor_position`]); `CSI ? row ; col R` (DECXCPR) is always a reply. For
//!   round trips during play (bandwidth control) prefer DA1, which is never a key.
//! - `ESC P`, `ESC ]` and `ESC _` are also Alt-Shift-P, Alt-`]` and Alt-`_`. A string is only
//!   taken as a reply when its next byte fits the replies tidepool asks for (a digit or `>` for
//!   DCS, a digit for OSC, `G` for APC) and every byte up to the terminator is printable text;
//!   Alt-P followed by a letter, or by Enter, is input at once.
//!
//! Only 7-bit controls are recognised (terminals answer in 7-bit unless switched to 8-bit).
//! Replies are bounded: a string reply longer than [`MAX_STRING_REPLY`] bytes is cut off there
//! and reported as [`Reply::Overlong`] (so the caller drops it instead of typing it); a CSI
//! longer than [`MAX_CSI_REPLY`] is not a reply.

/// The longest APC, DCS or OSC reply accepted, in bytes (kitty's replies are under 200).
pub const MAX_STRING_REPLY: usize = 4096;
/// The longest CSI reply accepted, in bytes.
pub const MAX_CSI_REPLY: usize = 64;
/// The most numeric parameters kept from one CSI reply (DA1 lists about a dozen).
const MAX_PARAMS: usize = 32;

const ESC: u8 = 0x1b;
const BEL: u8 = 0x07;

/// Replies whose shape is also a key, accepted only while one is awaited.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Expecting {
    /// A cursor position report (`CSI 6 n` was sent and not yet answered).
    pub cursor_position: bool,
}

impl Expecting {
    /// Nothing ambiguous is awaited.
    #[cfg(test)]
    pub const NOTHING: Expecting = Expecting { cursor_position: false };
    /// A cursor position report is awaited.
    pub const CURSOR_POSITION: Expecting = Expecting { cursor_position: true };
}

/// A recognised reply.
#[derive(Clone, Debug, PartialEq)]
pub enum Reply {
    /// A kitty graphics reply `ESC _ G i=<id>[,...] ; <message> ESC \`.
    KittyGraphics {
        /// The image id it answers (`i=`).
        id: Option<u32>,
        /// The message: `OK` or an error such as `ENOENT:...`.
        message: String,
    },
    /// Primary device attributes (DA1) `CSI ? Ps ; ... c`: the attributes (4 = sixel).
    PrimaryAttributes(Vec<u32>),
    /// Secondary device attributes (DA2) `CSI > Ps ; ... c`.
    SecondaryAttributes(Vec<u32>),
    /// XTSMGRAPHICS `CSI ? Pi ; Ps ; Pv... S`: item (1 colour registers, 2 sixel geometry),
    /// status (0 success), values.
    GraphicsAttribute {
        /// The item asked about.
        item: u32,
        /// 0 on success.
        status: u32,
        /// The value(s): registers, or width and height.
        values: Vec<u32>,
    },
    /// `CSI 6 ; height ; width t`: the cell size in pixels (answer to `CSI 16 t`).
    CellSize {
        /// Cell width in pixels.
        width: u32,
        /// Cell height in pixels.
        height: u32,
    },
    /// `CSI 4 ; height ; width t`: the text area in pixels (answer to `CSI 14 t`).
    TextAreaSize {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
    /// DECRPM `CSI ? mode ; state $ y` (or without `?` for ANSI modes): 0 unknown mode, 1 set,
    /// 2 reset, 3 permanently set, 4 permanently reset.
    ModeReport {
        /// The mode.
        mode: u32,
        /// Its state.
        state: u32,
        /// A DEC private mode (`?`).
        private: bool,
    },
    /// A cursor position report `CSI row ; col R` (1-based), or DECXCPR `CSI ? row ; col R`.
    CursorPosition {
        /// Row, 1-based.
        row: u32,
        /// Column, 1-based.
        col: u32,
    },
    /// iTerm2's `OSC 1337 ; ReportCellSize=height;width[;scale] ST`: the cell size in points
    /// and the points-to-pixels scale (1 when not given).
    Iterm2CellSize {
        /// Cell width in points.
        width: f64,
        /// Cell height in points.
        height: f64,
        /// Pixels per point.
        scale: f64,
    },
    /// A device status report `CSI Ps n` (the answer to `CSI 5 n`: 0 for "OK"): the link's
    /// round trip inside tmux and screen, where the question is wrapped for their passthrough.
    DeviceStatus(u32),
    /// Another CSI reply (`CSI ? ... u` keyboard flags, `CSI 8 ; rows ; cols t`...): its bytes
    /// between `CSI` and the final byte, and the final byte.
    OtherCsi(Vec<u8>, u8),
    /// A DCS reply (XTGETTCAP `1 + r ...`, XTVERSION `> | ...`, DECRQSS): its body.
    Dcs(Vec<u8>),
    /// Another OSC reply (colours...): its body.
    Osc(Vec<u8>),
    /// A string reply longer than [`MAX_STRING_REPLY`]: its first bytes, dropped.
    Overlong,
}

/// What starts a buffer.
#[derive(Clone, Debug, PartialEq)]
pub enum Parsed {
    /// A whole reply, and its length in bytes.
    Complete(Reply, usize),
    /// The buffer is a proper prefix of a reply.
    Incomplete,
    /// The buffer starts with input, not a reply.
    NotAReply,
}

/// Recognises a terminal reply at the start of `bytes` (see the module docs).
pub fn parse_reply(bytes: &[u8], expecting: Expecting) -> Parsed {
    match bytes {
        [] | [ESC] => Parsed::Incomplete,
        [ESC, b'[', rest @ ..] => parse_csi(rest, expecting),
        [ESC, kind @ (b'_' | b'P' | b']'), rest @ ..] => parse_string(*kind, rest),
        _ => Parsed::NotAReply,
    }
}

fn parse_csi(rest: &[u8], expecting: Expecting) -> Parsed {
    let mut i = 0;
    let marker = match rest.first() {
        None => return Parsed::Incomplete,
        Some(&m @ (b'?' | b'>' | b'<' | b'=')) => {
            i = 1;
            Some(m)
        }
        Some(_) => None,
    };
    let params_start = i;
    while i < rest.len() && matches!(rest[i], b'0'..=b'9' | b';' | b':') {
        i += 1;
    }
    let params_end = i;
    while i < rest.len() && (0x20..=0x2f).contains(&rest[i]) {
        i += 1;
    }
    if i >= rest.len() {
        return if 2 + rest.len() < MAX_CSI_REPLY { Parsed::Incomplete } else { Parsed::NotAReply };
    }
    let last = rest[i];
    if !(0x40..=0x7e).contains(&last) || 2 + i + 1 > MAX_CSI_REPLY {
        return Parsed::NotAReply;
    }
    let len = 2 + i + 1;
    let intermediates = &rest[params_end..i];
    let Some(params) = numbers(&rest[params_start..params_end]) else {
        return Parsed::NotAReply;
    };
    let p = |n: usize| params.get(n).copied().unwrap_or(0);
    let reply = match (marker, intermediates, last) {
        (Some(b'?'), b"", b'c') => Reply::PrimaryAttributes(params),
        (Some(b'>'), b"", b'c') => Reply::SecondaryAttributes(params),
        (Some(b'?'), b"", b'S') if params.len() >= 2 => {
            Reply::GraphicsAttribute { item: p(0), status: p(1), values: params[2..].to_vec() }
        }
        (None, b"", b't') if params.len() == 3 && p(0) == 6 => Reply::CellSize { width: p(2), height: p(1) },
        (None, b"", b't') if params.len() == 3 && p(0) == 4 => Reply::TextAreaSize { width: p(2), height: p(1) },
        (None, b"", b't') if params.len() == 3 => Reply::OtherCsi(rest[..i].to_vec(), last),
        (Some(b'?') | None, b"$", b'y') if params.len() == 2 => {
            Reply::ModeReport { mode: p(0), state: p(1), private: marker.is_some() }
        }
        (Some(b'?'), b"", b'R') if params.len() >= 2 => Reply::CursorPosition { row: p(0), col: p(1) },
        (None, b"", b'R') if params.len() == 2 && expecting.cursor_position => {
            Reply::CursorPosition { row: p(0), col: p(1) }
        }
        (Some(b'?'), b"", b'u') => Reply::OtherCsi(rest[..i].to_vec(), last),
        // No key ends in `n`.
        (None, b"", b'n') if params.len() == 1 => Reply::DeviceStatus(p(0)),
        _ => return Parsed::NotAReply,
    };
    Parsed::Complete(reply, len)
}

/// The numbers of a parameter string (`;`-separated; `:` sub-parameters are kept as numbers
/// too; empty ones are 0), or `None` when one overflows or there are too many.
fn numbers(params: &[u8]) -> Option<Vec<u32>> {
    if params.is_empty() {
        return Some(Vec::new());
    }
    let mut out = Vec::new();
    for part in params.split(|&b| b == b';' || b == b':') {
        if out.len() == MAX_PARAMS {
            return None;
        }
        let mut v: u32 = 0;
        for &d in part {
            v = v.checked_mul(10)?.checked_add(u32::from(d - b'0'))?;
        }
        out.push(v);
    }
    Some(out)
}

/// APC (`_`), DCS (`P`) or OSC (`]`) after its introducer.
fn parse_string(kind: u8, rest: &[u8]) -> Parsed {
    let Some(&first) = rest.first() else {
        return Parsed::Incomplete;
    };
    let plausible = match kind {
        b'_' => first == b'G',
        b'P' => first.is_ascii_digit() || first == b'>',
        _ => first.is_ascii_digit(),
    };
    if !plausible {
        return Parsed::NotAReply;
    }
    for (i, &b) in rest.iter().enumerate() {
        let header = 2;
        if header + i + 2 > MAX_STRING_REPLY {
            return Parsed::Complete(Reply::Overlong, MAX_STRING_REPLY);
        }
        match b {
            ESC => match rest.get(i + 1) {
                Some(b'\\') => return Parsed::Complete(string_reply(kind, &rest[..i]), header + i + 2),
                Some(_) => return Parsed::NotAReply,
                None => return Parsed::Incomplete,
            },
            BEL if kind == b']' => return Parsed::Complete(string_reply(kind, &rest[..i]), header + i + 1),
            0x20..=0x7e => {}
            _ => return Parsed::NotAReply,
        }
    }
    Parsed::Incomplete
}

fn string_reply(kind: u8, body: &[u8]) -> Reply {
    match kind {
        b'_' => {
            let body = &body[1..]; // after `G`
            let (control, message) = match body.iter().position(|&b| b == b';') {
                Some(p) => (&body[..p], &body[p + 1..]),
                None => (body, &body[..0]),
            };
            let id = control
                .split(|&b| b == b',')
                .find_map(|kv| kv.strip_prefix(b"i="))
                .and_then(|v| std::str::from_utf8(v).ok()?.parse().ok());
            Reply::KittyGraphics { id, message: String::from_utf8_lossy(message).into_owned() }
        }
        b'P' => Reply::Dcs(body.to_vec()),
        _ => match iterm2_cell_size(body) {
            Some(reply) => reply,
            None => Reply::Osc(body.to_vec()),
        },
    }
}

/// `1337;ReportCellSize=h;w[;scale]`.
fn iterm2_cell_size(body: &[u8]) -> Option<Reply> {
    let text = std::str::from_utf8(body).ok()?;
    let values = text.strip_prefix("1337;ReportCellSize=")?;
    let mut parts = values.split(';').map(|v| v.parse::<f64>().ok().filter(|x| x.is_finite() && *x > 0.0));
    let height = parts.next()??;
    let width = parts.next()??;
    let scale = match parts.next() {
        Some(s) => s?,
        None => 1.0,
    };
    Some(Reply::Iterm2CellSize { width, height, scale })
}

#[cfg(test)]
mod tests;
