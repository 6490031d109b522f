//! A screenful of cells: what the player wants the terminal to show, before any bytes.
//!
//! A cell is either two pixels (the upper and lower half of a half-block cell) or a character
//! with colours (the status line, the help overlay, the aim marker). Keeping the pixels as
//! colours rather than glyphs lets the encoder pick the cheapest glyph (`▀`, `▄`, `█` or a
//! space) for the colours already in effect; see [`crate::output::diff`].

use tiny_skia::Pixmap;

use crate::output::color::{Color, ColorMode};

/// One character cell.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cell {
    /// Two stacked pixels.
    Pixels {
        /// The upper pixel.
        top: Color,
        /// The lower pixel.
        bottom: Color,
    },
    /// A character; a space shows only its background.
    Text {
        /// The character (one column wide).
        ch: char,
        /// Its colour.
        fg: Color,
        /// The cell's background.
        bg: Color,
    },
}

impl Cell {
    /// A blank cell in the terminal's default colours.
    pub const BLANK: Cell = Cell::Text { ch: ' ', fg: Color::Default, bg: Color::Default };

    /// Whether the terminal would show `self` and `other` alike, colours compared with
    /// [`Color::close_to`]. A space's foreground does not matter.
    pub fn close_to(&self, other: &Cell, threshold: u8) -> bool {
        match (*self, *other) {
            (Cell::Pixels { top: a, bottom: b }, Cell::Pixels { top: c, bottom: d }) => {
                a.close_to(c, threshold) && b.close_to(d, threshold)
            }
            (Cell::Text { ch: a, fg: f1, bg: b1 }, Cell::Text { ch: b, fg: f2, bg: b2 }) => {
                // Text is compared exactly: a threshold is for pictures, not for letters.
                a == b && b1 == b2 && (a == ' ' || f1 == f2)
            }
            _ => false,
        }
    }
}

/// Frames alive in this process: a player's model of its terminal, a group's, its frames'
/// (`tidepool serve --bus` traces it: what an edge's memory in use follows, bus.md round 9).
static ALIVE: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// How many frames are alive in this process.
#[cfg(feature = "bus")]
pub fn frames_alive() -> usize {
    ALIVE.load(std::sync::atomic::Ordering::Relaxed)
}

/// A grid of cells, row-major.
#[derive(Debug, PartialEq, Eq)]
pub struct Frame {
    cols: usize,
    rows: usize,
    cells: Vec<Cell>,
}

impl Clone for Frame {
    fn clone(&self) -> Frame {
        ALIVE.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        Frame { cols: self.cols, rows: self.rows, cells: self.cells.clone() }
    }

    fn clone_from(&mut self, from: &Frame) {
        (self.cols, self.rows) = (from.cols, from.rows);
        self.cells.clone_from(&from.cells);
    }
}

impl Drop for Frame {
    fn drop(&mut self) {
        ALIVE.fetch_sub(1, std::sync::atomic::Ordering::Relaxed);
    }
}

impl Frame {
    /// A `cols x rows` frame of blank cells.
    pub fn new(cols: usize, rows: usize) -> Frame {
        ALIVE.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        Frame { cols, rows, cells: vec![Cell::BLANK; cols * rows] }
    }

    /// Makes this a blank `cols x rows` frame, reusing the allocation.
    pub fn reset(&mut self, cols: usize, rows: usize) {
        (self.cols, self.rows) = (cols, rows);
        self.cells.clear();
        self.cells.resize(cols * rows, Cell::BLANK);
    }

    /// Columns.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Rows.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The cells, row-major.
    pub fn cells(&self) -> &[Cell] {
        &self.cells
    }

    /// The cell at column `x`, row `y`.
    pub fn get(&self, x: usize, y: usize) -> Cell {
        self.cells[y * self.cols + x]
    }

    /// Sets the cell at column `x`, row `y`; positions outside the frame are ignored.
    pub fn set(&mut self, x: usize, y: usize, cell: Cell) {
        if x < self.cols && y < self.rows {
            self.cells[y * self.cols + x] = cell;
        }
    }

    /// Writes `text` from column `x` of row `y`, clipped to the frame. Each `char` takes one
    /// column: only use characters that are one column wide.
    pub fn text(&mut self, x: usize, y: usize, text: &str, fg: Color, bg: Color) {
        for (i, ch) in text.chars().enumerate() {
            self.set(x + i, y, Cell::Text { ch, fg, bg });
        }
    }

    /// Like [`Frame::text`], but at most `max` columns of `text`.
    pub fn text_clipped(&mut self, x: usize, y: usize, text: &str, max: usize, fg: Color, bg: Color) {
        for (i, ch) in text.chars().take(max).enumerate() {
            self.set(x + i, y, Cell::Text { ch, fg, bg });
        }
    }

    /// Fills row `y` from column `x` to the end with spaces of background `bg`.
    pub fn clear_row(&mut self, y: usize, bg: Color) {
        for x in 0..self.cols {
            self.set(x, y, Cell::Text { ch: ' ', fg: Color::Default, bg });
        }
    }

    /// Draws `pixmap` as half-block cells from the top-left corner, two pixel rows per text row,
    /// clipped to the frame. An odd last pixel row leaves its lower halves black.
    pub fn draw_pixels(&mut self, pixmap: &Pixmap, mode: ColorMode) {
        let (w, h) = (pixmap.width() as usize, pixmap.height() as usize);
        let cols = w.min(self.cols);
        let rows = h.div_ceil(2).min(self.rows);
        let pixels = pixmap.pixels();
        let rgb = |x: usize, y: usize| {
            let c = pixels[y * w + x].demultiply();
            [c.red(), c.green(), c.blue()]
        };
        for row in 0..rows {
            let (top_y, bottom_y) = (2 * row, 2 * row + 1);
            let line = &mut self.cells[row * self.cols..row * self.cols + cols];
            for (x, cell) in line.iter_mut().enumerate() {
                let top = mode.quantize(rgb(x, top_y), x as u32, top_y as u32);
                let bottom = if bottom_y < h {
                    mode.quantize(rgb(x, bottom_y), x as u32, bottom_y as u32)
                } else {
                    mode.quantize([0, 0, 0], x as u32, bottom_y as u32)
                };
                *cell = Cell::Pixels { top, bottom };
            }
        }
    }
}

/// Random frames for property tests of the encoders: few distinct colours, so neighbouring
/// cells often share them (the elision paths), and a text cell now and then.
#[cfg(test)]
pub(crate) mod strategies {
    use super::{Cell, Frame};
    use crate::output::color::Color;
    use proptest::prelude::{Just, Strategy, prop, prop_oneof};

    /// A colour of each kind.
    pub fn color() -> impl Strategy<Value = Color> {
        prop_oneof![
            (0u8..4, 0u8..4, 0u8..4).prop_map(|(r, g, b)| Color::Rgb([r * 80, g * 80, b * 80])),
            (0u8..=255).prop_map(Color::Index),
            Just(Color::Default),
        ]
    }

    /// Mostly pixel cells, sometimes text.
    pub fn cell() -> impl Strategy<Value = Cell> {
        prop_oneof![
            4 => (color(), color()).prop_map(|(top, bottom)| Cell::Pixels { top, bottom }),
            1 => (prop::sample::select(vec![' ', 'a', '+', '\u{b7}']), color(), color())
                .prop_map(|(ch, fg, bg)| Cell::Text { ch, fg, bg }),
        ]
    }

    /// A `cols` x `rows` frame of such cells.
    pub fn frame(cols: usize, rows: usize) -> impl Strategy<Value = Frame> {
        proptest::collection::vec(cell(), cols * rows).prop_map(move |cells| {
            let mut f = Frame::new(cols, rows);
            for (i, c) in cells.into_iter().enumerate() {
                f.set(i % cols, i / cols, c);
            }
            f
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tiny_skia::ColorU8;

    #[test]
    fn pixels_become_half_block_cells() {
        let mut p = Pixmap::new(2, 3).unwrap();
        for (i, px) in p.pixels_mut().iter_mut().enumerate() {
            *px = ColorU8::from_rgba(i as u8, 0, 0, 255).premultiply();
        }
        let mut f = Frame::new(3, 2);
        f.draw_pixels(&p, ColorMode::TrueColor);
        let c = |v: u8| Color::Rgb([v, 0, 0]);
        assert_eq!(f.get(1, 0), Cell::Pixels { top: c(1), bottom: c(3) });
        assert_eq!(f.get(0, 1), Cell::Pixels { top: c(4), bottom: c(0) }, "odd row: black lower half");
        assert_eq!(f.get(2, 0), Cell::BLANK, "outside the picture");
    }

    #[test]
    fn text_is_clipped() {
        let mut f = Frame::new(4, 1);
        f.text(2, 0, "abc", Color::Default, Color::Index(1));
        assert_eq!(f.get(3, 0), Cell::Text { ch: 'b', fg: Color::Default, bg: Color::Index(1) });
        f.text(0, 5, "x", Color::Default, Color::Default);
    }

    #[test]
    fn closeness_ignores_a_space_foreground() {
        let a = Cell::Text { ch: ' ', fg: Color::Index(1), bg: Color::Index(2) };
        let b = Cell::Text { ch: ' ', fg: Color::Index(3), bg: Color::Index(2) };
        assert!(a.close_to(&b, 0));
        let p = Cell::Pixels { top: Color::Rgb([1, 1, 1]), bottom: Color::Rgb([2, 2, 2]) };
        let q = Cell::Pixels { top: Color::Rgb([3, 1, 1]), bottom: Color::Rgb([2, 2, 2]) };
        assert!(p.close_to(&q, 2) && !p.close_to(&q, 1));
        assert!(!p.close_to(&a, 255));
    }
}
