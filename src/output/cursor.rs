//! The shortest byte sequence that moves the terminal's cursor from one cell to another.
//!
//! Candidates: nothing (already there); absolute `CUP` (`ESC[r;cH`); a vertical part (line
//! feeds, `CUU`/`CUD`, `VPA`) followed by a horizontal part (backspaces, carriage return,
//! `CUF`/`CUB`, `CHA`). Line feed is used as "one row down, same column", which holds for a
//! terminal in raw mode (no `onlcr`); the player always puts the terminal in raw mode. A move
//! down never starts at the bottom row, so a line feed never scrolls.
//!
//! After a character is written in the last column the cursor waits to wrap ("pending wrap");
//! terminals disagree about relative moves from there, so its column is treated as unknown,
//! except that the next character written lands at the start of the next row, which costs
//! nothing.

use std::io::Write;

/// Where the cursor is, as far as the encoder knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cursor {
    /// Unknown: only an absolute move is safe.
    Unknown,
    /// At column `.0`, row `.1`.
    At(usize, usize),
    /// Just wrote the last column of row `.0`: the next character lands at the start of the
    /// next row; the column is otherwise unknown.
    Wrapped(usize),
}

fn digits(n: usize) -> usize {
    match n {
        0..=9 => 1,
        10..=99 => 2,
        100..=999 => 3,
        1000..=9999 => 4,
        _ => 5,
    }
}

/// `ESC[{n}X`, with the count left out when it is 1.
fn csi_len(n: usize) -> usize {
    if n == 1 { 3 } else { 3 + digits(n) }
}

fn push_csi(out: &mut Vec<u8>, n: usize, command: u8) {
    if n == 1 {
        out.extend_from_slice(&[0x1b, b'[', command]);
    } else {
        let _ = write!(out, "\x1b[{n}");
        out.push(command);
    }
}

#[derive(Clone, Copy)]
enum Vertical {
    None,
    LineFeeds(usize),
    Down(usize),
    Up(usize),
    Row(usize),
}

#[derive(Clone, Copy)]
enum Horizontal {
    None,
    Backspaces(usize),
    Right(usize),
    Left(usize),
    Column(usize),
    Return,
    ReturnRight(usize),
}

impl Vertical {
    fn len(self) -> usize {
        match self {
            Vertical::None => 0,
            Vertical::LineFeeds(n) => n,
            Vertical::Down(n) | Vertical::Up(n) => csi_len(n),
            Vertical::Row(y) => csi_len(y + 1),
        }
    }

    fn push(self, out: &mut Vec<u8>) {
        match self {
            Vertical::None => {}
            Vertical::LineFeeds(n) => out.extend(std::iter::repeat_n(b'\n', n)),
            Vertical::Down(n) => push_csi(out, n, b'B'),
            Vertical::Up(n) => push_csi(out, n, b'A'),
            Vertical::Row(y) => push_csi(out, y + 1, b'd'),
        }
    }
}

impl Horizontal {
    fn len(self) -> usize {
        match self {
            Horizontal::None => 0,
            Horizontal::Backspaces(n) => n,
            Horizontal::Right(n) | Horizontal::Left(n) => csi_len(n),
            Horizontal::Column(x) => csi_len(x + 1),
            Horizontal::Return => 1,
            Horizontal::ReturnRight(n) => 1 + csi_len(n),
        }
    }

    fn push(self, out: &mut Vec<u8>) {
        match self {
            Horizontal::None => {}
            Horizontal::Backspaces(n) => out.extend(std::iter::repeat_n(0x08, n)),
            Horizontal::Right(n) => push_csi(out, n, b'C'),
            Horizontal::Left(n) => push_csi(out, n, b'D'),
            Horizontal::Column(x) => push_csi(out, x + 1, b'G'),
            Horizontal::Return => out.push(b'\r'),
            Horizontal::ReturnRight(n) => {
                out.push(b'\r');
                push_csi(out, n, b'C');
            }
        }
    }
}

fn shortest<T: Copy>(options: &[Option<T>], len: impl Fn(T) -> usize) -> T {
    options.iter().flatten().copied().min_by_key(|&o| len(o)).expect("at least one option")
}

fn vertical(from: Option<usize>, to: usize) -> Vertical {
    let Some(from) = from else { return Vertical::Row(to) };
    match to.cmp(&from) {
        std::cmp::Ordering::Equal => Vertical::None,
        std::cmp::Ordering::Greater => {
            let n = to - from;
            shortest(&[Some(Vertical::LineFeeds(n)), Some(Vertical::Down(n)), Some(Vertical::Row(to))], Vertical::len)
        }
        std::cmp::Ordering::Less => shortest(&[Some(Vertical::Up(from - to)), Some(Vertical::Row(to))], Vertical::len),
    }
}

fn horizontal(from: Option<usize>, to: usize) -> Horizontal {
    let absolute = [
        Some(Horizontal::Column(to)),
        (to == 0).then_some(Horizontal::Return),
        (to > 0).then_some(Horizontal::ReturnRight(to)),
    ];
    let Some(from) = from else { return shortest(&absolute, Horizontal::len) };
    let relative = match to.cmp(&from) {
        std::cmp::Ordering::Equal => return Horizontal::None,
        std::cmp::Ordering::Greater => [Some(Horizontal::Right(to - from)), None],
        std::cmp::Ordering::Less => [Some(Horizontal::Left(from - to)), Some(Horizontal::Backspaces(from - to))],
    };
    let all = [absolute[0], absolute[1], absolute[2], relative[0], relative[1]];
    shortest(&all, Horizontal::len)
}

/// The number of bytes [`push_move`] would write.
pub fn move_len(from: Cursor, to: (usize, usize)) -> usize {
    plan(from, to).map_or(0, |p| p.len())
}

enum Plan {
    Absolute(usize, usize),
    Relative(Vertical, Horizontal),
}

impl Plan {
    fn len(&self) -> usize {
        match *self {
            Plan::Absolute(x, y) => {
                if x == 0 && y == 0 {
                    3
                } else if x == 0 {
                    3 + digits(y + 1)
                } else {
                    4 + digits(y + 1) + digits(x + 1)
                }
            }
            Plan::Relative(v, h) => v.len() + h.len(),
        }
    }
}

fn plan(from: Cursor, (x, y): (usize, usize)) -> Option<Plan> {
    let (col, row) = match from {
        Cursor::At(cx, cy) if (cx, cy) == (x, y) => return None,
        Cursor::Wrapped(r) if x == 0 && y == r + 1 => return None,
        Cursor::At(cx, cy) => (Some(cx), Some(cy)),
        Cursor::Wrapped(r) => (None, Some(r)),
        Cursor::Unknown => (None, None),
    };
    let absolute = Plan::Absolute(x, y);
    if row.is_none() {
        return Some(absolute);
    }
    let relative = Plan::Relative(vertical(row, y), horizontal(col, x));
    Some(if relative.len() < absolute.len() { relative } else { absolute })
}

/// Appends the shortest move from `from` to column `x`, row `y` (zero-based) to `out`.
pub fn push_move(out: &mut Vec<u8>, from: Cursor, to: (usize, usize)) {
    match plan(from, to) {
        None => {}
        Some(Plan::Absolute(0, 0)) => out.extend_from_slice(b"\x1b[H"),
        Some(Plan::Absolute(0, y)) => push_csi(out, y + 1, b'H'),
        Some(Plan::Absolute(x, y)) => {
            let _ = write!(out, "\x1b[{};{}H", y + 1, x + 1);
        }
        Some(Plan::Relative(v, h)) => {
            v.push(out);
            h.push(out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::vt::TerminalModel;

    /// Moves in a 200x60 terminal model land where asked, and are never longer than `CUP`.
    #[test]
    fn every_move_lands_and_is_no_longer_than_absolute() {
        let mut rng = 12345u64;
        let mut next = |n: usize| {
            rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (rng >> 33) as usize % n
        };
        for _ in 0..3000 {
            let from = (next(200), next(60));
            let to = (next(200), next(60));
            let mut s = TerminalModel::new(200, 60);
            s.lf_returns = false;
            s.feed(format!("\x1b[{};{}H", from.1 + 1, from.0 + 1).as_bytes());
            let mut out = Vec::new();
            push_move(&mut out, Cursor::At(from.0, from.1), to);
            s.feed(&out);
            assert_eq!(s.cursor(), to, "{from:?} -> {to:?}: {:?}", String::from_utf8_lossy(&out));
            assert_eq!(out.len(), move_len(Cursor::At(from.0, from.1), to));
            let absolute = format!("\x1b[{};{}H", to.1 + 1, to.0 + 1).len();
            assert!(out.len() <= absolute);
        }
    }

    #[test]
    fn typical_moves() {
        let m = |from, to| {
            let mut out = Vec::new();
            push_move(&mut out, from, to);
            String::from_utf8(out).unwrap()
        };
        assert_eq!(m(Cursor::At(5, 5), (5, 5)), "");
        assert_eq!(m(Cursor::At(5, 5), (9, 5)), "\x1b[4C");
        assert_eq!(m(Cursor::At(5, 5), (6, 5)), "\x1b[C");
        assert_eq!(m(Cursor::At(5, 5), (4, 5)), "\x08");
        assert_eq!(m(Cursor::At(5, 5), (5, 6)), "\n");
        assert_eq!(m(Cursor::At(5, 5), (0, 6)), "\n\r");
        assert_eq!(m(Cursor::Unknown, (0, 0)), "\x1b[H");
        assert_eq!(m(Cursor::Unknown, (3, 7)), "\x1b[8;4H");
        assert_eq!(m(Cursor::Wrapped(3), (0, 4)), "", "the pending wrap does it");
        assert_eq!(m(Cursor::Wrapped(3), (2, 4)), "\n\x1b[3G");
        assert_eq!(m(Cursor::At(150, 40), (2, 3)), "\x1b[4;3H");
    }

    #[test]
    fn wrapped_cursor_in_the_model() {
        let mut s = TerminalModel::new(4, 3);
        s.lf_returns = false;
        s.feed("\x1b[2;1Habcd".as_bytes());
        let mut out = Vec::new();
        push_move(&mut out, Cursor::Wrapped(1), (2, 2));
        s.feed(&out);
        assert_eq!(s.cursor(), (2, 2));
    }
}
