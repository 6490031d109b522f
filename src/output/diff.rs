//! The frame encoder: what the terminal shows now plus the frame wanted next, in; the fewest
//! bytes that turn one into the other, out.
//!
//! [`encode`] is a pure function of ([`Shown`], [`Frame`], [`EncodeOptions`]); it returns the
//! bytes and the new [`Shown`]. Nothing here touches a terminal, so every choice is tested
//! against the terminal model in [`crate::output::vt`].
//!
//! What it does, cheapest first (the numbers are a 160x48 pool with rain, see docs/GUIDE.md):
//! - Only cells that changed are sent; a cell within `threshold` of what is shown counts as
//!   unchanged and the shown colour is kept, so slow drifts still add up to a change.
//! - The cursor takes the shortest move ([`crate::output::cursor`]); a short gap whose cells
//!   can be re-printed without a colour change is printed over instead of jumped.
//! - The foreground and background codes are each sent only when they differ from the colours
//!   in effect, and both go in one `ESC[...m` when both change.
//! - A pixel cell is drawn with whichever of `▀`, `▄`, `█` or a space needs the fewest colour
//!   bytes given the colours in effect: two equal halves are a space with a background (or a
//!   full block when the foreground already matches); `▄` swaps the roles when that reuses a
//!   colour.
//! - The whole frame is wrapped in synchronized output (`ESC[?2026h` ... `ESC[?2026l`) unless
//!   switched off; a frame with no change is no bytes at all.

use crate::output::color::Color;
#[cfg(any(test, feature = "testing"))]
use crate::output::cursor;
use crate::output::cursor::Cursor;
use crate::output::frame::{Cell, Frame};

/// Start of a synchronized update (DEC mode 2026).
pub const SYNC_BEGIN: &[u8] = b"\x1b[?2026h";
/// End of a synchronized update.
pub const SYNC_END: &[u8] = b"\x1b[?2026l";

/// How frames are encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct EncodeOptions {
    /// A colour that changed by at most this much in every channel is not re-sent (0: exact).
    pub threshold: u8,
    /// Wrap each frame in synchronized output.
    pub sync: bool,
}

impl Default for EncodeOptions {
    fn default() -> Self {
        EncodeOptions { threshold: 0, sync: true }
    }
}

/// What the terminal shows, as far as the encoder knows: the cells, the cursor and the colours
/// in effect (`None`: unknown).
#[derive(Clone, Debug, PartialEq)]
pub struct Shown {
    /// The cells on screen; `None` before the first frame or after a resize (everything is
    /// sent).
    pub frame: Option<Frame>,
    /// The cursor.
    pub(crate) cursor: Cursor,
    /// The foreground colour in effect.
    pub fg: Option<Color>,
    /// The background colour in effect.
    pub bg: Option<Color>,
}

impl Shown {
    /// Nothing known: the next frame is sent whole.
    pub const UNKNOWN: Shown = Shown { frame: None, cursor: Cursor::Unknown, fg: None, bg: None };
}

/// The upper half block `▀`, lower half block `▄` and full block `█`.
pub(crate) const UPPER: char = '\u{2580}';
pub(crate) const LOWER: char = '\u{2584}';
pub(crate) const FULL: char = '\u{2588}';

/// Length of one SGR colour parameter list (without `ESC[` and `m`).
pub(crate) fn color_params_len(c: Color, background: bool) -> usize {
    let digits = |v: u8| match v {
        0..=9 => 1,
        10..=99 => 2,
        _ => 3,
    };
    match c {
        Color::Default => 2,
        Color::Index(i) if i < 16 => {
            if background && i >= 8 {
                3
            } else {
                2
            }
        }
        Color::Index(i) => 5 + digits(i),
        Color::Rgb([r, g, b]) => 7 + digits(r) + digits(g) + digits(b),
    }
}

/// Appends `v` in decimal (`write!` is several times slower, and this runs per colour code).
#[inline]
fn push_u8(out: &mut Vec<u8>, v: u8) {
    if v >= 100 {
        out.push(b'0' + v / 100);
    }
    if v >= 10 {
        out.push(b'0' + v / 10 % 10);
    }
    out.push(b'0' + v % 10);
}

pub(crate) fn push_color_params(out: &mut Vec<u8>, c: Color, background: bool) {
    let base = if background { 40 } else { 30 };
    match c {
        Color::Default => push_u8(out, base + 9),
        Color::Index(i) if i < 8 => push_u8(out, base + i),
        Color::Index(i) if i < 16 => push_u8(out, base + 60 + (i - 8)),
        Color::Index(i) => {
            push_u8(out, base + 8);
            out.extend_from_slice(b";5;");
            push_u8(out, i);
        }
        Color::Rgb([r, g, b]) => {
            push_u8(out, base + 8);
            out.extend_from_slice(b";2;");
            push_u8(out, r);
            out.push(b';');
            push_u8(out, g);
            out.push(b';');
            push_u8(out, b);
        }
    }
}

/// A glyph with the colours it needs (`None`: this colour does not matter).
#[derive(Clone, Copy)]
pub(crate) struct Draw {
    pub(crate) ch: char,
    pub(crate) fg: Option<Color>,
    pub(crate) bg: Option<Color>,
}

impl Draw {
    /// Bytes of SGR needed before printing, given the colours in effect.
    pub(crate) fn sgr_len(&self, pen_fg: Option<Color>, pen_bg: Option<Color>) -> usize {
        let fg = self.fg.filter(|&c| pen_fg != Some(c));
        let bg = self.bg.filter(|&c| pen_bg != Some(c));
        match (fg, bg) {
            (None, None) => 0,
            (Some(f), None) => 3 + color_params_len(f, false),
            (None, Some(b)) => 3 + color_params_len(b, true),
            (Some(f), Some(b)) => 4 + color_params_len(f, false) + color_params_len(b, true),
        }
    }

    pub(crate) fn len(&self, pen_fg: Option<Color>, pen_bg: Option<Color>) -> usize {
        self.sgr_len(pen_fg, pen_bg) + self.ch.len_utf8()
    }
}

/// The cheapest way to draw `cell` with the colours in effect.
pub(crate) fn best_draw(cell: Cell, fg: Option<Color>, bg: Option<Color>) -> Draw {
    match cell {
        Cell::Text { ch, fg: f, bg: b } => Draw { ch, fg: (ch != ' ').then_some(f), bg: Some(b) },
        Cell::Pixels { top, bottom } if top == bottom => {
            let space = Draw { ch: ' ', fg: None, bg: Some(top) };
            let full = Draw { ch: FULL, fg: Some(top), bg: None };
            if full.len(fg, bg) < space.len(fg, bg) { full } else { space }
        }
        Cell::Pixels { top, bottom } => {
            let upper = Draw { ch: UPPER, fg: Some(top), bg: Some(bottom) };
            let lower = Draw { ch: LOWER, fg: Some(bottom), bg: Some(top) };
            if lower.len(fg, bg) < upper.len(fg, bg) { lower } else { upper }
        }
    }
}

#[cfg(any(test, feature = "testing"))]
/// Encodes the change from `shown` to `next`: returns the bytes and what the terminal shows
/// after them. When `shown` has no frame or one of another size, every cell is sent.
pub fn encode(shown: &Shown, next: &Frame, options: EncodeOptions) -> (Vec<u8>, Shown) {
    let mut out = Vec::new();
    let mut state = shown.clone();
    encode_into(&mut state, next, options, &mut out);
    (out, state)
}

#[cfg(any(test, feature = "testing"))]
/// [`encode`] without allocating: appends the bytes to `out` and updates `shown` in place.
pub fn encode_into(shown: &mut Shown, next: &Frame, options: EncodeOptions, out: &mut Vec<u8>) {
    let start = out.len();
    if options.sync {
        out.extend_from_slice(SYNC_BEGIN);
    }
    let body_start = out.len();
    let full = shown.frame.as_ref().is_none_or(|f| f.cols() != next.cols() || f.rows() != next.rows());
    if full {
        shown.frame = Some(next.clone());
    }
    let (cols, rows) = (next.cols(), next.rows());
    let frame = shown.frame.as_mut().expect("set above");
    let (mut cursor, mut fg, mut bg) = (shown.cursor, shown.fg, shown.bg);
    for y in 0..rows {
        let mut x = 0;
        while x < cols {
            let want = next.get(x, y);
            if !full && frame.get(x, y).close_to(&want, options.threshold) {
                x += 1;
                continue;
            }
            // Reach (x, y): jump, or re-print a short gap of unchanged cells in the same row
            // when that is cheaper and needs no colour change.
            let mut reprinted = false;
            if let Cursor::At(cx, cy) = cursor
                && cy == y
                && cx < x
            {
                let jump = cursor::move_len(cursor, (x, y));
                let gap: Option<usize> = (cx..x)
                    .map(|gx| {
                        let d = best_draw(frame.get(gx, y), fg, bg);
                        (d.sgr_len(fg, bg) == 0).then(|| d.ch.len_utf8())
                    })
                    .try_fold(0, |sum, len| len.map(|l| sum + l).filter(|&s| s < jump));
                if let Some(_bytes) = gap {
                    for gx in cx..x {
                        let d = best_draw(frame.get(gx, y), fg, bg);
                        let mut buf = [0u8; 4];
                        out.extend_from_slice(d.ch.encode_utf8(&mut buf).as_bytes());
                    }
                    reprinted = true;
                }
            }
            if !reprinted {
                cursor::push_move(out, cursor, (x, y));
            }
            let draw = best_draw(want, fg, bg);
            let new_fg = draw.fg.filter(|&c| fg != Some(c));
            let new_bg = draw.bg.filter(|&c| bg != Some(c));
            match (new_fg, new_bg) {
                (None, None) => {}
                (f, b) => {
                    out.extend_from_slice(b"\x1b[");
                    if let Some(f) = f {
                        push_color_params(out, f, false);
                        fg = Some(f);
                    }
                    if let Some(b) = b {
                        if f.is_some() {
                            out.push(b';');
                        }
                        push_color_params(out, b, true);
                        bg = Some(b);
                    }
                    out.push(b'm');
                }
            }
            let mut buf = [0u8; 4];
            out.extend_from_slice(draw.ch.encode_utf8(&mut buf).as_bytes());
            frame.set(x, y, want);
            cursor = if x + 1 < cols { Cursor::At(x + 1, y) } else { Cursor::Wrapped(y) };
            x += 1;
        }
    }
    (shown.cursor, shown.fg, shown.bg) = (cursor, fg, bg);
    if out.len() == body_start {
        out.truncate(start);
    } else if options.sync {
        out.extend_from_slice(SYNC_END);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::color::ColorMode;
    use crate::output::vt::TerminalModel;
    use tiny_skia::{ColorU8, Pixmap};

    fn rgb(v: u8) -> Color {
        Color::Rgb([v, v, v])
    }

    fn picture(cols: u32, rows: u32, f: impl Fn(u32, u32) -> [u8; 3]) -> Pixmap {
        let mut p = Pixmap::new(cols, 2 * rows).unwrap();
        for y in 0..2 * rows {
            for x in 0..cols {
                let [r, g, b] = f(x, y);
                p.pixels_mut()[(y * cols + x) as usize] = ColorU8::from_rgba(r, g, b, 255).premultiply();
            }
        }
        p
    }

    fn frame_of(p: &Pixmap, mode: ColorMode) -> Frame {
        let mut f = Frame::new(p.width() as usize, p.height() as usize / 2);
        f.draw_pixels(p, mode);
        f
    }

    fn model(cols: usize, rows: usize) -> TerminalModel {
        let mut s = TerminalModel::new(cols, rows);
        s.lf_returns = false;
        s
    }

    /// Every pixel the screen shows equals the frame's.
    fn assert_screen_shows(screen: &TerminalModel, frame: &Frame) {
        for y in 0..frame.rows() {
            for x in 0..frame.cols() {
                match frame.get(x, y) {
                    Cell::Pixels { top, bottom } => {
                        assert_eq!(screen.pixel(x, 2 * y), top.rgb(), "top of ({x}, {y})");
                        assert_eq!(screen.pixel(x, 2 * y + 1), bottom.rgb(), "bottom of ({x}, {y})");
                    }
                    Cell::Text { ch, fg, bg } => {
                        let c = screen.cell(x, y);
                        assert_eq!((c.ch, c.bg), (ch, bg.rgb()), "text at ({x}, {y})");
                        if ch != ' ' {
                            assert_eq!(c.fg, fg.rgb(), "the colour of {ch:?} at ({x}, {y})");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn a_sequence_of_frames_round_trips_through_the_terminal_model() {
        for mode in [ColorMode::TrueColor, ColorMode::Palette256, ColorMode::Palette16] {
            let (cols, rows) = (23, 9);
            let mut screen = model(cols, rows);
            let mut shown = Shown::UNKNOWN;
            for t in 0..6u32 {
                // Moving blobs over a gradient, with flat areas, so every glyph choice occurs.
                let p = picture(cols as u32, rows as u32, |x, y| {
                    let d = (x as i32 - 3 * t as i32 - 4).pow(2) + (y as i32 - 2 * t as i32).pow(2);
                    if d < 20 {
                        [200, 40, (t * 30) as u8]
                    } else if y > 12 {
                        [9, 9, 9]
                    } else {
                        [(x * 11) as u8, (y * 13) as u8, 90]
                    }
                });
                let mut frame = frame_of(&p, mode);
                frame.text(2, 3, &format!("t={t}"), Color::Index(15), Color::Index(4));
                let (bytes, next) = encode(&shown, &frame, EncodeOptions::default());
                screen.feed(&bytes);
                assert_screen_shows(&screen, &frame);
                assert_eq!(screen.private_mode(2026), Some(false), "sync closed");
                shown = next;
            }
        }
    }

    #[test]
    fn still_frames_cost_nothing() {
        let p = picture(10, 4, |x, y| [x as u8 * 20, y as u8 * 20, 0]);
        let frame = frame_of(&p, ColorMode::TrueColor);
        let (first, shown) = encode(&Shown::UNKNOWN, &frame, EncodeOptions::default());
        assert!(first.starts_with(SYNC_BEGIN) && first.ends_with(SYNC_END));
        let (again, same) = encode(&shown, &frame, EncodeOptions::default());
        assert!(again.is_empty(), "{:?}", String::from_utf8_lossy(&again));
        assert_eq!(same, shown);
        // Dithered palettes are stable too.
        let frame = frame_of(&p, ColorMode::Palette256);
        let (_, shown) = encode(&Shown::UNKNOWN, &frame, EncodeOptions::default());
        assert!(encode(&shown, &frame_of(&p, ColorMode::Palette256), EncodeOptions::default()).0.is_empty());
    }

    #[test]
    fn one_changed_cell_is_a_move_a_colour_and_a_glyph() {
        let mut a = Frame::new(40, 10);
        for y in 0..10 {
            for x in 0..40 {
                a.set(x, y, Cell::Pixels { top: rgb(1), bottom: rgb(2) });
            }
        }
        let (_, shown) = encode(&Shown::UNKNOWN, &a, EncodeOptions { threshold: 0, sync: false });
        let mut b = a.clone();
        b.set(20, 5, Cell::Pixels { top: rgb(3), bottom: rgb(2) });
        let (bytes, _) = encode(&shown, &b, EncodeOptions { threshold: 0, sync: false });
        // Background 2 is still in effect: only the foreground is sent.
        assert_eq!(String::from_utf8(bytes).unwrap(), "\x1b[6;21H\x1b[38;2;3;3;3m\u{2580}");
    }

    #[test]
    fn equal_halves_are_a_space_or_a_full_block() {
        let mut f = Frame::new(3, 1);
        f.set(0, 0, Cell::Pixels { top: rgb(7), bottom: rgb(7) });
        f.set(1, 0, Cell::Pixels { top: rgb(8), bottom: rgb(7) });
        f.set(2, 0, Cell::Pixels { top: rgb(8), bottom: rgb(8) });
        let (bytes, _) = encode(&Shown::UNKNOWN, &f, EncodeOptions { threshold: 0, sync: false });
        assert_eq!(
            String::from_utf8(bytes).unwrap(),
            "\x1b[H\x1b[48;2;7;7;7m \x1b[38;2;8;8;8m\u{2580}\u{2588}",
            "a space needs only the background; then the foreground in effect makes a full block free"
        );
    }

    #[test]
    fn lower_half_block_reuses_the_colours_in_effect() {
        let mut f = Frame::new(2, 1);
        f.set(0, 0, Cell::Pixels { top: rgb(1), bottom: rgb(2) });
        f.set(1, 0, Cell::Pixels { top: rgb(2), bottom: rgb(1) });
        let (bytes, _) = encode(&Shown::UNKNOWN, &f, EncodeOptions { threshold: 0, sync: false });
        assert_eq!(String::from_utf8(bytes).unwrap(), "\x1b[H\x1b[38;2;1;1;1;48;2;2;2;2m\u{2580}\u{2584}");
    }

    #[test]
    fn threshold_keeps_small_changes_until_they_add_up() {
        let mut f = Frame::new(1, 1);
        let opts = EncodeOptions { threshold: 3, sync: false };
        f.set(0, 0, Cell::Pixels { top: rgb(100), bottom: rgb(100) });
        let (_, mut shown) = encode(&Shown::UNKNOWN, &f, opts);
        let mut sent = 0;
        for v in 101..=110 {
            f.set(0, 0, Cell::Pixels { top: rgb(v), bottom: rgb(100) });
            let (bytes, next) = encode(&shown, &f, opts);
            sent += usize::from(!bytes.is_empty());
            shown = next;
        }
        assert_eq!(sent, 2, "sent at 104 and 108, not every step");
        let exact = EncodeOptions { threshold: 0, sync: false };
        f.set(0, 0, Cell::Pixels { top: rgb(111), bottom: rgb(100) });
        assert!(!encode(&shown, &f, exact).0.is_empty());
    }

    #[test]
    fn short_gaps_are_printed_over() {
        let mut a = Frame::new(10, 1);
        for x in 0..10 {
            a.set(x, 0, Cell::Pixels { top: rgb(5), bottom: rgb(5) });
        }
        let opts = EncodeOptions { threshold: 0, sync: false };
        let (_, shown) = encode(&Shown::UNKNOWN, &a, opts);
        let mut b = a.clone();
        b.set(2, 0, Cell::Pixels { top: rgb(6), bottom: rgb(5) });
        b.set(4, 0, Cell::Pixels { top: rgb(6), bottom: rgb(5) });
        let (bytes, _) = encode(&shown, &b, opts);
        let text = String::from_utf8(bytes.clone()).unwrap();
        assert!(text.ends_with("\u{2580} \u{2580}"), "the unchanged space between is re-printed: {text:?}");
        let mut s = model(10, 1);
        s.feed(&encode(&Shown::UNKNOWN, &a, opts).0);
        s.feed(&bytes);
        assert_screen_shows(&s, &b);
    }

    #[test]
    fn a_resize_sends_everything() {
        let a = Frame::new(4, 2);
        let (_, shown) = encode(&Shown::UNKNOWN, &a, EncodeOptions::default());
        let b = Frame::new(5, 2);
        let (bytes, shown) = encode(&shown, &b, EncodeOptions::default());
        assert!(!bytes.is_empty());
        assert_eq!(shown.frame.as_ref().map(Frame::cols), Some(5));
    }

    mod properties {
        use super::*;
        use crate::output::frame::strategies::frame;
        use proptest::prelude::*;

        proptest! {
            #![proptest_config(ProptestConfig::with_cases(96))]

            /// Whatever the frames, the diff of each against the one before, fed to a terminal
            /// that shows the one before, shows exactly the new one (colours exact at threshold
            /// 0), with synchronized output opened and closed.
            #[test]
            fn diffs_reproduce_the_next_frame(
                (cols, rows, frames) in (1usize..14, 1usize..7).prop_flat_map(|(c, r)| {
                    (Just(c), Just(r), proptest::collection::vec(frame(c, r), 1..5))
                }),
                sync in any::<bool>(),
            ) {
                let mut screen = model(cols, rows);
                let mut shown = Shown::UNKNOWN;
                for frame in &frames {
                    let (bytes, next) = encode(&shown, frame, EncodeOptions { threshold: 0, sync });
                    screen.feed(&bytes);
                    assert_screen_shows(&screen, frame);
                    shown = next;
                }
                // A frame identical to what is shown costs nothing but the sync markers.
                let (again, _) = encode(&shown, frames.last().unwrap(), EncodeOptions { threshold: 0, sync: false });
                prop_assert!(again.is_empty(), "{:?}", String::from_utf8_lossy(&again));
            }
        }
    }
}
