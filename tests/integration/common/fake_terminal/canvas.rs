//! The pixels sixel images paint: each image decoded by icy_sixel and drawn at the cursor's
//! cell, as a sixel terminal draws it (transparent pixels, `P2=1`, leave what was there).

use super::FakeTerminal;

/// The screen's pixels, `None` where nothing was painted.
pub struct Canvas {
    pub width: usize,
    pub height: usize,
    pub cell: (usize, usize),
    pixels: Vec<Option<[u8; 3]>>,
    /// The pixels above the last text row that were painted, counted as they are: the test
    /// looks at the coverage every 20 ms while the fake is locked, and counting a million
    /// pixels each time (at opt-level 1, under load) kept the fake from reading for much of
    /// each 20 ms; the player took that for a slow link and fell to its floor.
    painted: usize,
}

impl Canvas {
    /// A blank canvas for `cols x rows` cells of `cell` pixels.
    pub fn new(cols: usize, rows: usize, cell: (usize, usize)) -> Canvas {
        let (width, height) = (cols * cell.0, rows * cell.1);
        Canvas { width, height, cell, pixels: vec![None; width * height], painted: 0 }
    }

    /// The share of the pixels above the last text row that were painted.
    pub fn coverage(&self) -> f64 {
        let rows = self.height - self.cell.1;
        self.painted as f64 / (rows * self.width) as f64
    }

    /// Paints the pixel at (`x`, `y`), inside the canvas.
    fn paint(&mut self, x: usize, y: usize, rgb: [u8; 3]) {
        let pixel = &mut self.pixels[y * self.width + x];
        if pixel.is_none() && y < self.height - self.cell.1 {
            self.painted += 1;
        }
        *pixel = Some(rgb);
    }

    /// The painted pixels above the last text row, as RGB (unpainted ones black).
    pub fn rgb(&self) -> Vec<u8> {
        let rows = self.height - self.cell.1;
        self.pixels[..rows * self.width].iter().flat_map(|p| p.unwrap_or([0, 0, 0])).collect()
    }
}

impl FakeTerminal {
    /// Draws a sixel image (from `ESC P` to `ESC \\`) at the cursor's cell.
    pub(super) fn draw_sixel(&mut self, image: &[u8]) {
        let Ok(decoded) = icy_sixel::SixelImage::decode(image) else {
            self.broken_sixels += 1;
            return;
        };
        let (col, row) = self.screen.cursor();
        let canvas = &mut self.canvas;
        let (x0, y0) = (col * canvas.cell.0, row * canvas.cell.1);
        for y in 0..decoded.height {
            for x in 0..decoded.width {
                let p = &decoded.pixels[(y * decoded.width + x) * 4..][..4];
                let (cx, cy) = (x0 + x, y0 + y);
                if p[3] == 255 && cx < canvas.width && cy < canvas.height {
                    canvas.paint(cx, cy, [p[0], p[1], p[2]]);
                }
            }
        }
    }
}
