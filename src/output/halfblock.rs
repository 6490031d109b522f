//! Half-block text: two pixel rows per text row, `▀` with the upper pixel as foreground and
//! the lower pixel as background, in 24-bit colour.
//!
//! This is the file/pipe form (`--format ansi`): plain lines, no cursor movement, so `cat`
//! shows the picture in any truecolor terminal. A colour code is only sent when it differs from
//! the one in effect; every line ends with `ESC[0m` and a newline, so lines stand alone.

use std::io::Write;

use tiny_skia::Pixmap;

/// The upper half block, U+2580.
pub const UPPER_HALF: &str = "\u{2580}";

/// An RGB colour.
pub type Rgb = [u8; 3];

/// The straight colour of pixel `(x, y)`.
pub fn pixel_rgb(pixmap: &Pixmap, x: u32, y: u32) -> Rgb {
    let c = pixmap.pixels()[(y * pixmap.width() + x) as usize].demultiply();
    [c.red(), c.green(), c.blue()]
}

/// Appends `ESC[38;2;r;g;bm` (foreground) to `out`.
pub fn push_fg(out: &mut Vec<u8>, [r, g, b]: Rgb) {
    let _ = write!(out, "\x1b[38;2;{r};{g};{b}m");
}

#[cfg(any(test, feature = "player", feature = "ratatui"))]
/// The picture, in pixels, that `cols x rows` half-block cells show: a pixel a column, two a
/// row. The one place this is computed: the play screen's picture and a serve group's
/// (`play/screen/compose.rs`), the cells layout (`output/graphics/geometry.rs`) and the widget
/// take it, each with its own minimum.
pub fn picture_size(cols: u16, rows: u16) -> (u32, u32) {
    (u32::from(cols), 2 * u32::from(rows))
}

/// Appends `ESC[48;2;r;g;bm` (background) to `out`.
pub fn push_bg(out: &mut Vec<u8>, [r, g, b]: Rgb) {
    let _ = write!(out, "\x1b[48;2;{r};{g};{b}m");
}

/// Encodes a whole picture as half-block lines. An odd last pixel row is drawn over the
/// terminal's default background (`ESC[49m`).
pub fn encode(pixmap: &Pixmap) -> Vec<u8> {
    let (w, h) = (pixmap.width(), pixmap.height());
    let mut out = Vec::with_capacity((w as usize * h.div_ceil(2) as usize) * 24);
    for top in (0..h).step_by(2) {
        let mut fg: Option<Rgb> = None;
        // `None` = the default background is in effect (as after `ESC[0m`).
        let mut bg: Option<Rgb> = None;
        for x in 0..w {
            let upper = pixel_rgb(pixmap, x, top);
            let lower = (top + 1 < h).then(|| pixel_rgb(pixmap, x, top + 1));
            if fg != Some(upper) {
                push_fg(&mut out, upper);
                fg = Some(upper);
            }
            match lower {
                Some(lower) if bg != Some(lower) => {
                    push_bg(&mut out, lower);
                    bg = Some(lower);
                }
                None if x == 0 => out.extend_from_slice(b"\x1b[49m"),
                _ => {}
            }
            out.extend_from_slice(UPPER_HALF.as_bytes());
        }
        out.extend_from_slice(b"\x1b[0m\n");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::vt::TerminalModel;
    use tiny_skia::ColorU8;

    fn pixmap(w: u32, h: u32, f: impl Fn(u32, u32) -> Rgb) -> Pixmap {
        let mut p = Pixmap::new(w, h).unwrap();
        for y in 0..h {
            for x in 0..w {
                let [r, g, b] = f(x, y);
                p.pixels_mut()[(y * w + x) as usize] = ColorU8::from_rgba(r, g, b, 255).premultiply();
            }
        }
        p
    }

    #[test]
    fn exact_bytes_of_a_tiny_picture() {
        let p = pixmap(2, 2, |x, y| if y == 0 { [255, 0, 0] } else { [0, 0, x as u8] });
        let text = String::from_utf8(encode(&p)).unwrap();
        assert_eq!(
            text, "\x1b[38;2;255;0;0m\x1b[48;2;0;0;0m▀\x1b[48;2;0;0;1m▀\x1b[0m\n",
            "the repeated foreground is skipped, the changed background is not"
        );
    }

    #[test]
    fn odd_last_row_uses_the_default_background() {
        let p = pixmap(3, 3, |_, _| [9, 9, 9]);
        let text = String::from_utf8(encode(&p)).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 2);
        assert_eq!(lines[1], "\x1b[38;2;9;9;9m\x1b[49m▀▀▀\x1b[0m");
        assert!(!text.contains("\x1b[H") && !text.contains('\r'), "no cursor movement");
    }

    #[test]
    fn a_terminal_model_reproduces_the_picture() {
        let p = pixmap(17, 9, |x, y| [(x * 15) as u8, (y * 28) as u8, ((x ^ y) * 7) as u8]);
        let mut screen = TerminalModel::new(17, 6); // one spare row: the last newline would scroll
        screen.feed(&encode(&p));
        for y in 0..9 {
            for x in 0..17 {
                assert_eq!(screen.pixel(x, y), Some(pixel_rgb(&p, x as u32, y as u32)), "({x}, {y})");
            }
        }
        assert_eq!(screen.pixel(0, 9), None, "the odd row's lower half is the default background");
    }
}
