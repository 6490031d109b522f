//! What a screen draws over the picture: the status line, the aim marker, the help overlay
//! and the "terminal too small" notice. All of it is text cells in a [`Frame`], so it costs
//! bytes only when it changes.

use crate::output::color::{Color, ColorMode};
use crate::output::frame::{Cell, Frame};

/// The smallest terminal the player draws in (columns, rows).
pub const MIN_SIZE: (u16, u16) = (10, 5);

const STATUS_FG: [u8; 3] = [225, 232, 240];
const STATUS_BG: [u8; 3] = [24, 38, 56];
const HELP_BG: [u8; 3] = [14, 22, 34];
const HELP_KEY: [u8; 3] = [255, 214, 120];

fn solid(mode: ColorMode, rgb: [u8; 3]) -> Color {
    match mode {
        // Text is never dithered: a flat status line must stay flat.
        ColorMode::TrueColor => Color::Rgb(rgb),
        ColorMode::Palette256 => Color::Index(crate::output::color::nearest_256(rgb)),
        ColorMode::Palette16 => Color::Index(crate::output::color::nearest_16(rgb)),
    }
}

/// What the status line says.
#[derive(Clone, Debug, Default)]
pub struct Status<'a> {
    /// The scene's name.
    pub scene: &'static str,
    /// Frames drawn per second.
    pub fps: u32,
    /// Bytes per second, formatted.
    pub rate: &'a str,
    /// The scene's own summary.
    pub detail: &'a str,
    /// The stone radius in pixels, for scenes that take stones.
    pub stone: Option<u32>,
    /// Key hints, longest first: the first that fits is shown.
    pub hints: &'a [&'static str],
    /// Paused.
    pub paused: bool,
    /// A passing message (screenshot saved...), shown instead of the key hints.
    pub message: Option<&'a str>,
}

/// Draws the status line into row `row`; `scratch` is a reusable buffer (no allocation once it
/// has grown to a line's length).
pub fn status_line(frame: &mut Frame, row: usize, status: &Status<'_>, mode: ColorMode, scratch: &mut String) {
    use std::fmt::Write;
    let (fg, bg) = (solid(mode, STATUS_FG), solid(mode, STATUS_BG));
    frame.clear_row(row, bg);
    let paused = if status.paused { " \u{b7} PAUSED" } else { "" };
    scratch.clear();
    let _ = write!(
        scratch,
        " {}{paused} \u{b7} {} fps \u{b7} {} \u{b7} {} ",
        status.scene, status.fps, status.rate, status.detail
    );
    if let Some(stone) = status.stone {
        let _ = write!(scratch, "\u{b7} stone {stone} ");
    }
    let cols = frame.cols();
    let left_len = scratch.chars().count();
    frame.text(0, row, scratch, fg, bg);
    scratch.clear();
    match status.message {
        Some(m) => {
            let _ = write!(scratch, " {m} ");
        }
        None => {
            let room = cols.saturating_sub(left_len + 1);
            if let Some(h) = status.hints.iter().find(|h| h.chars().count() <= room) {
                let _ = write!(scratch, "{h} ");
            }
        }
    }
    let right_len = scratch.chars().count();
    // A message wins over the left part when the line is short; hints only take free room.
    let x = if status.message.is_some() {
        cols.saturating_sub(right_len)
    } else {
        cols.saturating_sub(right_len).max(left_len.min(cols))
    };
    let key = if status.message.is_some() { solid(mode, HELP_KEY) } else { fg };
    frame.text(x, row, scratch, key, bg);
}

/// Marks the aim in cell (`col`, `row`): a `+` over the cell's own colour.
pub fn aim_marker(frame: &mut Frame, col: usize, row: usize) {
    if col >= frame.cols() || row >= frame.rows() {
        return;
    }
    let under = match frame.get(col, row) {
        Cell::Pixels { top, .. } => top,
        Cell::Text { bg, .. } => bg,
    };
    let light = under.rgb().is_none_or(|[r, g, b]| u32::from(r) * 3 + u32::from(g) * 6 + u32::from(b) < 1300);
    let fg = if light { Color::Rgb([255, 255, 255]) } else { Color::Rgb([0, 0, 0]) };
    let fg = match under {
        Color::Rgb(_) => fg,
        _ => Color::Index(if light { 15 } else { 0 }),
    };
    frame.set(col, row, Cell::Text { ch: '+', fg, bg: under });
}

/// Draws a centred box listing `lines`, clipped to the frame's picture rows (all but the last).
pub fn help_overlay(frame: &mut Frame, lines: &[(&str, &str)], mode: ColorMode) {
    let (fg, bg, key) = (solid(mode, STATUS_FG), solid(mode, HELP_BG), solid(mode, HELP_KEY));
    let key_width = lines.iter().map(|(k, _)| k.chars().count()).max().unwrap_or(0);
    let text_width = lines.iter().map(|(_, t)| t.chars().count()).max().unwrap_or(0);
    let width = (key_width + text_width + 6).min(frame.cols());
    let height = (lines.len() + 4).min(frame.rows().saturating_sub(1));
    let x0 = (frame.cols() - width) / 2;
    let y0 = (frame.rows().saturating_sub(1) - height) / 2;
    for y in y0..y0 + height {
        for x in x0..x0 + width {
            frame.set(x, y, Cell::Text { ch: ' ', fg, bg });
        }
    }
    let title = "tidepool keys";
    frame.text(x0 + width.saturating_sub(title.len()) / 2, y0 + 1, title, key, bg);
    for (i, (k, t)) in lines.iter().enumerate() {
        let y = y0 + 3 + i;
        if y >= y0 + height {
            break;
        }
        let room = |from: usize| (x0 + width).saturating_sub(from + 1);
        frame.text_clipped(x0 + 2, y, k, room(x0 + 2), key, bg);
        frame.text_clipped(x0 + 4 + key_width, y, t, room(x0 + 4 + key_width), fg, bg);
    }
}

/// The second line of the "terminal too small" notice (kept in step with [`MIN_SIZE`] by a test
/// that reads the drawn notice; a constant, so drawing the notice allocates nothing).
const MIN_SIZE_NOTE: &str = "need 10x5";

/// Fills the frame with the "terminal too small" notice.
pub fn too_small(frame: &mut Frame) {
    for y in 0..frame.rows() {
        frame.clear_row(y, Color::Default);
    }
    let lines = ["terminal too small", MIN_SIZE_NOTE];
    let top = frame.rows().saturating_sub(lines.len()) / 2;
    for (i, line) in lines.iter().enumerate() {
        let x = frame.cols().saturating_sub(line.len()) / 2;
        frame.text(x, top + i, line, Color::Default, Color::Default);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(frame: &Frame, y: usize) -> String {
        (0..frame.cols())
            .map(|x| match frame.get(x, y) {
                Cell::Text { ch, .. } => ch,
                Cell::Pixels { .. } => '#',
            })
            .collect()
    }

    /// The size the drawn notice asks for is exactly the one the screen starts drawing at: it
    /// fits, and a column or a row less does not.
    #[test]
    fn too_small_asks_for_the_size_the_screen_needs() {
        let mut f = Frame::new(30, 6);
        too_small(&mut f);
        let text: String = (0..f.rows()).map(|y| row(&f, y)).collect::<Vec<_>>().join("\n");
        let need = text.split("need ").nth(1).and_then(|rest| rest.split_whitespace().next()).expect("a size");
        let (cols, rows) = need.split_once('x').expect("COLSxROWS");
        let size: (u16, u16) = (cols.parse().unwrap(), rows.parse().unwrap());
        use super::super::compose::big_enough;
        assert!(big_enough(size), "{need} is not enough");
        assert!(!big_enough((size.0 - 1, size.1)) && !big_enough((size.0, size.1 - 1)), "{need} is more than needed");
    }

    fn status() -> Status<'static> {
        Status {
            scene: "pool",
            fps: 30,
            rate: "1.2 kB/s",
            detail: "rain 0.02 \u{b7} damping 5",
            stone: Some(4),
            hints: &["space stone \u{b7} ? help \u{b7} q quit", "? help \u{b7} q quit"],
            ..Status::default()
        }
    }

    #[test]
    fn status_line_fits_any_width() {
        for cols in [10, 40, 80, 160, 300] {
            let mut f = Frame::new(cols, 3);
            status_line(&mut f, 2, &status(), ColorMode::TrueColor, &mut String::new());
            let text = row(&f, 2);
            assert!(text.starts_with(" pool"), "{text}");
            if cols >= 160 {
                assert!(text.contains("30 fps") && text.contains("q quit"), "{text}");
            }
        }
        let mut f = Frame::new(120, 1);
        let s = Status { message: Some("saved x.png"), paused: true, ..status() };
        status_line(&mut f, 0, &s, ColorMode::Palette16, &mut String::new());
        assert!(row(&f, 0).trim_end().ends_with("saved x.png") && row(&f, 0).contains("PAUSED"));
        let mut narrow = Frame::new(30, 1);
        status_line(&mut narrow, 0, &s, ColorMode::TrueColor, &mut String::new());
        assert!(row(&narrow, 0).starts_with(" pool \u{b7} PAUSED") && row(&narrow, 0).ends_with("saved x.png "));
    }

    #[test]
    fn help_lists_every_key_and_fits() {
        let lines = crate::play::seat::help_lines(&[("r", "rain on/off")], true);
        let mut f = Frame::new(80, 30);
        help_overlay(&mut f, &lines, ColorMode::TrueColor);
        let all: String = (0..30).map(|y| row(&f, y)).collect();
        for (k, t) in &lines {
            assert!(all.contains(k) && all.contains(t), "{k} {t}");
        }
        let mut tiny = Frame::new(10, 5);
        help_overlay(&mut tiny, &lines, ColorMode::TrueColor);
    }

    #[test]
    fn aim_marker_sits_in_its_cell_over_its_colour() {
        let mut f = Frame::new(5, 3);
        let dark = Color::Rgb([10, 10, 10]);
        for y in 0..3 {
            for x in 0..5 {
                f.set(x, y, Cell::Pixels { top: dark, bottom: dark });
            }
        }
        aim_marker(&mut f, 3, 2);
        assert_eq!(f.get(3, 2), Cell::Text { ch: '+', fg: Color::Rgb([255, 255, 255]), bg: dark });
        aim_marker(&mut f, 30, 20);
    }

    #[test]
    fn too_small_says_so() {
        let mut f = Frame::new(20, 4);
        too_small(&mut f);
        assert!((0..4).any(|y| row(&f, y).contains("terminal too small")));
    }
}
