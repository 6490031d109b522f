//! A ratatui widget (feature `ratatui`): any scene drawn into a ratatui `Buffer`, two pixels a
//! cell, in true colour — the same cells as [`crate::encode::halfblock`] writes.
//!
//! ```no_run
//! # use ratatui_core::{buffer::Buffer, layout::Rect, widgets::StatefulWidget};
//! use tidepool::widget::{SceneWidget, SceneWidgetState};
//! use tidepool::{PoolScene, PoolSettings, Scene};
//!
//! let area = Rect::new(0, 0, 40, 12);
//! let (w, h) = SceneWidget::picture_size(area);
//! let mut pool = PoolScene::new(w, h, PoolSettings::default()).unwrap();
//! let mut state = SceneWidgetState::default();
//! let mut buffer = Buffer::empty(area);
//! pool.advance(1);
//! SceneWidget::new(&mut pool).render(area, &mut buffer, &mut state);
//! ```

use ratatui_core::buffer::Buffer;
use ratatui_core::layout::Rect;
use ratatui_core::style::Color;
use ratatui_core::widgets::StatefulWidget;
use tiny_skia::Pixmap;

use crate::scene::Scene;

/// The upper half block: its foreground is the upper pixel, its background the lower one.
const UPPER_HALF: &str = "\u{2580}";

/// Draws a scene's current picture into an area, from its top-left corner, clipped to the area.
///
/// The widget draws the scene at the scene's own size; size the scene to
/// [`SceneWidget::picture_size`] of the area (and resize it when the area changes) to fill it.
pub struct SceneWidget<'a> {
    scene: &'a mut dyn Scene,
}

impl<'a> SceneWidget<'a> {
    /// A widget showing `scene`.
    pub fn new(scene: &'a mut dyn Scene) -> SceneWidget<'a> {
        SceneWidget { scene }
    }

    /// The picture size in pixels that fills `area`: its width, and two pixels a row.
    pub fn picture_size(area: Rect) -> (u32, u32) {
        let (width, height) = crate::output::halfblock::picture_size(area.width, area.height);
        (width.max(1), height.max(1))
    }
}

/// What the widget keeps between frames: the picture it draws into, so a steady stream of
/// frames allocates nothing.
#[derive(Debug, Default)]
pub struct SceneWidgetState {
    pixmap: Option<Pixmap>,
}

impl StatefulWidget for SceneWidget<'_> {
    type State = SceneWidgetState;

    fn render(self, area: Rect, buf: &mut Buffer, state: &mut SceneWidgetState) {
        let (w, h) = self.scene.size();
        if state.pixmap.as_ref().is_none_or(|p| (p.width(), p.height()) != (w, h)) {
            state.pixmap = Pixmap::new(w, h);
        }
        let Some(pixmap) = state.pixmap.as_mut() else { return };
        self.scene.render(pixmap);
        let area = area.intersection(buf.area);
        let rgb = |x: u32, y: u32| {
            let c = pixmap.pixels()[(y * w + x) as usize].demultiply();
            Color::Rgb(c.red(), c.green(), c.blue())
        };
        for row in 0..u32::from(area.height).min(h.div_ceil(2)) {
            for col in 0..u32::from(area.width).min(w) {
                let (top, bottom) = (2 * row, 2 * row + 1);
                let lower = if bottom < h { rgb(col, bottom) } else { Color::Reset };
                if let Some(cell) = buf.cell_mut((area.x + col as u16, area.y + row as u16)) {
                    cell.set_symbol(UPPER_HALF).set_fg(rgb(col, top)).set_bg(lower);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use ratatui_core::backend::TestBackend;
    use ratatui_core::terminal::Terminal;

    use super::*;
    use crate::output::vt::TerminalModel;
    use crate::scene::pool::{PoolScene, PoolSettings};
    use crate::sim::ripple::Stone;

    /// The widget's cells in a `TestBackend` are the half-block encoding of the scene's
    /// picture, cell for cell: the same glyph, the upper pixel as foreground, the lower as
    /// background (an odd last row over the default background).
    #[test]
    fn the_widget_draws_the_half_block_encoding_of_the_picture() {
        for (cols, rows, picture_h) in [(40u16, 12u16, 24u32), (31, 9, 17)] {
            let mut pool = PoolScene::new(u32::from(cols), picture_h, PoolSettings::default()).unwrap();
            pool.drop_stone(Stone::new(15, 9, 4, 200).unwrap());
            Scene::advance(&mut pool, 12);
            let mut terminal = Terminal::new(TestBackend::new(cols, rows)).unwrap();
            let mut state = SceneWidgetState::default();
            terminal.draw(|f| f.render_stateful_widget(SceneWidget::new(&mut pool), f.area(), &mut state)).unwrap();

            let text = crate::output::halfblock::encode(&pool.snapshot().unwrap());
            let mut screen = TerminalModel::new(usize::from(cols), usize::from(rows) + 1);
            screen.feed(&text);
            let buffer = terminal.backend().buffer();
            let to_rgb = |c: Color| match c {
                Color::Rgb(r, g, b) => Some([r, g, b]),
                _ => None,
            };
            for y in 0..picture_h.div_ceil(2) as u16 {
                for x in 0..cols {
                    let cell = &buffer[(x, y)];
                    assert_eq!(cell.symbol(), UPPER_HALF, "({x}, {y})");
                    assert_eq!(to_rgb(cell.fg), screen.pixel(x.into(), 2 * usize::from(y)), "top of ({x}, {y})");
                    assert_eq!(to_rgb(cell.bg), screen.pixel(x.into(), 2 * usize::from(y) + 1), "bottom of ({x}, {y})");
                }
            }
            let below = picture_h.div_ceil(2) as u16;
            if below < rows {
                assert_eq!(buffer[(0, below)].symbol(), " ", "rows below the picture are left alone");
            }
        }
    }
}
