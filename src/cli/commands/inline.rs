//! `render ... --out -` to a terminal that shows real pixels: the picture as one kitty, sixel or
//! iTerm2 image, sized to the terminal's cells, instead of half-block text.
//!
//! The terminal is asked what it shows before the scene is rendered (the picture's size depends
//! on the answer: kitty and iTerm2 scale an image to a cell area, so the area's pixel size
//! within 1280x800; sixel is one pixel a pixel). The screen's text scrolls up into the
//! scrollback, the picture is drawn from the top-left cell over every row but the last, and the
//! cursor is left on the last row for the shell's prompt. The image stays on screen (nothing is
//! deleted: it is the output).

use crate::output::graphics::geometry::{Layout, layout};
use crate::output::graphics::iterm2::Iterm2Encoder;
use crate::output::graphics::kitty::{KittyEncoder, KittyOptions};
use crate::output::graphics::push_rgb;
use crate::output::graphics::sixel::{SixelEncoder, SixelPalette};
use crate::play::GraphicsMode;
use crate::play::{GraphicsChoice, GraphicsSupport};
use crate::size::Size;
use tiny_skia::Pixmap;

use crate::cli::args::GraphicsFlag as Request;

/// A picture for this terminal in real pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct Inline {
    choice: GraphicsChoice,
    support: GraphicsSupport,
    layout: Layout,
    /// The terminal's rows.
    rows: u16,
}

impl Inline {
    /// Asks the terminal (see `crate::term::tty::probe_for_picture`); `None` for cells.
    pub fn probe(request: Request) -> Option<Inline> {
        let (choice, support) = crate::term::tty::probe_for_picture(request.into());
        if choice.mode == GraphicsMode::Cells {
            return None;
        }
        let (cols, rows) = crossterm::terminal::size().ok()?;
        let sixel_max = support.sixel.and_then(|s| Some((s.max_w?, s.max_h?)));
        let layout = layout(choice.mode, (cols, rows), support.cell_px, sixel_max, Layout::SCALED_CAP);
        Some(Inline { choice, support, layout, rows })
    }

    /// The picture's size in pixels (`fallback` for a layout with no room).
    pub fn size(&self, fallback: Size) -> Size {
        let (w, h) = self.layout.picture;
        Size::new(i64::from(w), i64::from(h)).unwrap_or(fallback)
    }

    /// The protocol's name, for `--stats`.
    pub fn name(&self) -> &'static str {
        match self.choice.mode {
            GraphicsMode::Kitty => "kitty graphics",
            GraphicsMode::Sixel => "sixel",
            GraphicsMode::Iterm2 => "iTerm2 inline image",
            GraphicsMode::Cells => "half-block text",
        }
    }

    /// The bytes that show `picture` (any size: kitty and iTerm2 scale it to the cell area,
    /// sixel draws it one pixel a pixel).
    pub fn encode(&self, picture: &Pixmap) -> Vec<u8> {
        let rows = usize::from(self.rows);
        // Scroll the screen's text into the scrollback, clear, draw from the top-left cell.
        let mut out = "\n".repeat(rows).into_bytes();
        out.extend_from_slice(b"\x1b[H\x1b[2J");
        let (w, h) = (picture.width(), picture.height());
        let mut rgb = Vec::new();
        match self.choice.mode {
            GraphicsMode::Kitty => {
                push_rgb(picture, &mut rgb);
                let options = KittyOptions {
                    tmux: self.choice.tmux_wrap,
                    placeholders: self.choice.kitty_placeholders,
                    ..KittyOptions::new(self.layout.cells)
                };
                // Direct transmission never fails (only the file medium writes files).
                let _ = KittyEncoder::new(options).encode(&rgb, w, h, &mut out);
            }
            GraphicsMode::Sixel => {
                push_rgb(picture, &mut rgb);
                let registers = self.support.sixel_registers();
                SixelEncoder::new(SixelPalette::fit(&rgb, 3, registers), (0, 0), None).encode(&rgb, w, h, &mut out);
            }
            GraphicsMode::Iterm2 => {
                Iterm2Encoder::new((0, 0), self.layout.cells, self.choice.tmux_wrap).encode(picture, &mut out);
            }
            GraphicsMode::Cells => out = crate::encode::halfblock(picture),
        }
        if self.choice.mode != GraphicsMode::Cells {
            out.extend_from_slice(format!("\x1b[{rows};1H").as_bytes());
        }
        out
    }
}
