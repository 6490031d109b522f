//! Where a scene sits on one terminal, both ways: the scene's pixels scaled (aspect kept) and
//! centred into the picture the terminal shows, bars where it does not reach; and from a cell
//! or a pixel the person clicked back to the scene's pixel, and from the aim's scene pixel to
//! the cell its marker goes in.
//!
//! One mapping for every case: the local player renders the scene at the picture's own size
//! (half-block cells: one pixel a column, two a row; real pixels: the picture within the scene
//! cap, scaled by the terminal or the sixel encoder), so its fit is one to one; a shared scene
//! (`tidepool serve`) has one size for everyone and is letterboxed into each terminal.

#[cfg(any(feature = "serve", feature = "testing", test))]
use tiny_skia::{FilterQuality, Pixmap, PixmapPaint, Transform};

use crate::output::graphics::geometry::Layout;

#[cfg(any(feature = "serve", feature = "testing", test))]
/// The bars' colour around a picture that does not fill the terminal (the status line's blue,
/// darker).
pub const BAR_RGB: [u8; 3] = [8, 12, 20];

/// How the terminal's cells cover the picture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellGrid {
    /// Half-block cells: a column is a picture pixel, a row two; `rows` rows of picture (the
    /// status line is below them). A click lands on the upper pixel of its cell.
    HalfBlocks {
        /// Columns.
        cols: u16,
        /// Picture rows.
        rows: u16,
    },
    /// Real pixels placed by `layout` (the picture covers its cells, scaled from its own size
    /// to the picture's). A cell click lands on the cell's centre; with `mouse_pixels` (SGR-pixels
    /// mode) the terminal reports screen pixels and a click lands on its pixel.
    Pixels {
        /// Where the picture is and how big.
        layout: Layout,
        /// Mouse reports come in screen pixels.
        mouse_pixels: bool,
    },
}

/// One scene in one terminal's picture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fit {
    scene: (u32, u32),
    target: (u32, u32),
    /// The scene's rectangle in the target: left, top (even, so half-block rows start on a
    /// cell's upper half), width, height.
    placed: (u32, u32, u32, u32),
    grid: CellGrid,
}

impl Fit {
    /// A `scene` (width, height in pixels) shown in a `target` picture whose pixels the
    /// terminal's cells cover as `grid` says.
    pub(crate) fn new(scene: (u32, u32), target: (u32, u32), grid: CellGrid) -> Fit {
        let scene = (scene.0.max(1), scene.1.max(1));
        let target = (target.0.max(1), target.1.max(1));
        let scale = (f64::from(target.0) / f64::from(scene.0)).min(f64::from(target.1) / f64::from(scene.1));
        let w = ((f64::from(scene.0) * scale).round() as u32).clamp(1, target.0);
        let h = ((f64::from(scene.1) * scale).round() as u32).clamp(1, target.1);
        let x0 = (target.0 - w) / 2;
        let y0 = ((target.1 - h) / 2) & !1;
        Fit { scene, target, placed: (x0, y0, w, h), grid }
    }

    /// The scene's size in pixels.
    pub fn scene(&self) -> (u32, u32) {
        self.scene
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// The terminal's picture size in pixels.
    pub fn target(&self) -> (u32, u32) {
        self.target
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// Whether the scene fills the picture pixel for pixel (then no letterboxing is drawn).
    pub fn one_to_one(&self) -> bool {
        self.scene == self.target
    }

    /// The scene pixel under a mouse report at (`col`, `row`): cells (0-based), or screen
    /// pixels when the grid reports pixels. `None` on the bars, the status line or outside.
    pub fn scene_at(&self, col: u16, row: u16) -> Option<(i32, i32)> {
        let (tx, ty) = match self.grid {
            CellGrid::HalfBlocks { cols, rows } => {
                if col >= cols || row >= rows {
                    return None;
                }
                (u32::from(col), 2 * u32::from(row))
            }
            CellGrid::Pixels { layout, mouse_pixels } => {
                let (lx, ly) = if mouse_pixels {
                    layout.pixel_at(u32::from(col), u32::from(row))?
                } else {
                    layout.pixel_at_cell(col, row)?
                };
                (scale(lx, layout.picture.0, self.target.0), scale(ly, layout.picture.1, self.target.1))
            }
        };
        let (x0, y0, w, h) = self.placed;
        let (dx, dy) = (tx.checked_sub(x0)?, ty.checked_sub(y0)?);
        if dx >= w || dy >= h {
            return None;
        }
        Some((scale(dx, w, self.scene.0) as i32, scale(dy, h, self.scene.1) as i32))
    }

    /// The cell (column, row) showing scene pixel (`x`, `y`): where the aim marker goes.
    pub fn cell_of(&self, x: i32, y: i32) -> (u16, u16) {
        let (x0, y0, w, h) = self.placed;
        let centre = |v: i32, from: u32, to: u32| {
            let v = u64::from(v.clamp(0, from as i32 - 1) as u32);
            ((2 * v + 1) * u64::from(to) / (2 * u64::from(from))) as u32
        };
        let (tx, ty) = (x0 + centre(x, self.scene.0, w), y0 + centre(y, self.scene.1, h));
        match self.grid {
            CellGrid::HalfBlocks { .. } => (clamp16(tx), clamp16(ty / 2)),
            CellGrid::Pixels { layout, .. } => {
                let (lx, ly) = (scale(tx, self.target.0, layout.picture.0), scale(ty, self.target.1, layout.picture.1));
                let col = scale(lx, layout.picture.0, u32::from(layout.cells.0));
                let row = scale(ly, layout.picture.1, u32::from(layout.cells.1));
                (clamp16(col + u32::from(layout.origin.0)), clamp16(row + u32::from(layout.origin.1)))
            }
        }
    }

    /// How far one press of an aim key moves, in scene pixels (x, y), at least 1: in cells two
    /// columns or one row (a square step), with real pixels one cell.
    pub fn aim_step(&self) -> (i32, i32) {
        let (_, _, w, h) = self.placed;
        let (cell_w, cell_h) = match self.grid {
            CellGrid::HalfBlocks { .. } => (2, 2),
            CellGrid::Pixels { layout, .. } => {
                (self.target.0 / u32::from(layout.cells.0.max(1)), self.target.1 / u32::from(layout.cells.1.max(1)))
            }
        };
        let step =
            |cell: u32, scene: u32, shown: u32| (u64::from(cell) * u64::from(scene) / u64::from(shown)).max(1) as i32;
        (step(cell_w, self.scene.0, w), step(cell_h, self.scene.1, h))
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// `scene` fitted into a picture of the target's size, in `old`'s pixels when it has that
    /// size (a shared scene's pictures are reused from frame to frame).
    pub fn fitted(&self, scene: &Pixmap, old: Option<Pixmap>) -> Option<Pixmap> {
        let (w, h) = self.target();
        let mut picture = match old {
            Some(p) if (p.width(), p.height()) == (w, h) => p,
            _ => Pixmap::new(w, h)?,
        };
        if self.one_to_one() {
            picture.data_mut().copy_from_slice(scene.data());
        } else {
            self.draw(scene, &mut picture);
        }
        Some(picture)
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// Draws `scene` (of the scene's size) into `out` (of the target's size): scaled, centred,
    /// bars around it. Whole-number growth stays sharp; anything else is filtered.
    pub fn draw(&self, scene: &Pixmap, out: &mut Pixmap) {
        let [r, g, b] = BAR_RGB;
        out.fill(tiny_skia::Color::from_rgba8(r, g, b, 255));
        let (x0, y0, w, h) = self.placed;
        let (sx, sy) = (w as f32 / scene.width().max(1) as f32, h as f32 / scene.height().max(1) as f32);
        let whole = sx.fract() == 0.0 && sy.fract() == 0.0;
        let quality = if whole { FilterQuality::Nearest } else { FilterQuality::Bilinear };
        let paint = PixmapPaint { quality, ..PixmapPaint::default() };
        let transform = Transform::from_scale(sx, sy).post_translate(x0 as f32, y0 as f32);
        out.draw_pixmap(0, 0, scene.as_ref(), &paint, transform, None);
    }
}

/// `v` of a length `from` mapped onto a length `to`, rounded down.
fn scale(v: u32, from: u32, to: u32) -> u32 {
    (u64::from(v) * u64::from(to) / u64::from(from.max(1))) as u32
}

fn clamp16(v: u32) -> u16 {
    v.min(u32::from(u16::MAX)) as u16
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::graphics::GraphicsMode;
    use crate::output::graphics::geometry::{SCALED_CAP, layout};

    fn half(cols: u16, rows: u16) -> CellGrid {
        CellGrid::HalfBlocks { cols, rows }
    }

    #[test]
    fn the_local_half_block_fit_is_one_to_one_and_clicks_land_on_the_upper_pixel() {
        let fit = Fit::new((40, 22), (40, 22), half(40, 11));
        assert!(fit.one_to_one());
        assert_eq!(fit.scene_at(9, 2), Some((9, 4)));
        assert_eq!(fit.scene_at(9, 11), None, "the status line");
        assert_eq!(fit.scene_at(40, 0), None);
        assert_eq!(fit.cell_of(9, 4), (9, 2));
        assert_eq!(fit.cell_of(9, 5), (9, 2), "the lower pixel is in the same cell");
        assert_eq!(fit.aim_step(), (2, 2));
    }

    #[test]
    fn a_wide_terminal_gets_bars_on_the_sides_and_clicks_map_back() {
        let fit = Fit::new((160, 90), (200, 90), half(200, 45));
        assert_eq!(fit.placed, (20, 0, 160, 90));
        assert_eq!(fit.scene_at(20, 0), Some((0, 0)));
        assert_eq!(fit.scene_at(19, 0), None, "the bar");
        assert_eq!(fit.scene_at(179, 44), Some((159, 88)));
        assert_eq!(fit.scene_at(180, 5), None);
    }

    #[test]
    fn a_small_terminal_shrinks_the_scene_and_the_round_trip_holds() {
        let fit = Fit::new((160, 90), (80, 46), half(80, 23));
        assert_eq!(fit.placed, (0, 0, 80, 45), "(46 - 45) / 2 rounded down to even");
        assert_eq!(fit.aim_step(), (4, 4), "one row is four scene pixels");
        for (x, y) in [(0, 0), (37, 11), (159, 89), (80, 44)] {
            let (col, row) = fit.cell_of(x, y);
            let back = fit.scene_at(col, row).unwrap();
            assert!((back.0 - x).abs() <= 2 && (back.1 - y).abs() <= 4, "{x},{y} -> {col},{row} -> {back:?}");
        }
    }

    #[test]
    fn a_tall_terminal_gets_bars_above_and_below_on_an_even_row() {
        let fit = Fit::new((160, 90), (160, 120), half(160, 60));
        assert_eq!(fit.placed, (0, 14, 160, 90), "15 rounded down to even");
        assert_eq!(fit.scene_at(10, 6), None, "row 6 is pixels 12 and 13: the bar");
        assert_eq!(fit.scene_at(10, 7), Some((10, 0)));
        assert_eq!(fit.cell_of(10, 0), (10, 7));
    }

    #[test]
    fn real_pixels_map_cells_by_their_centre_and_pixel_reports_by_their_pixel() {
        // 20x6 cells of 10x20 pixels for sixel: a 200x96 picture, one pixel a pixel.
        let l = layout(GraphicsMode::Sixel, (20, 6), Some((10, 20)), None, SCALED_CAP);
        assert_eq!(l.picture, (200, 96));
        let cells = Fit::new((200, 96), (200, 96), CellGrid::Pixels { layout: l, mouse_pixels: false });
        assert_eq!(cells.scene_at(3, 2), Some((35, 50)), "the centre of cell (3, 2)");
        assert_eq!(cells.scene_at(3, 5), None, "the status row is not the picture");
        assert_eq!(cells.cell_of(35, 50), (3, 2));
        assert_eq!(cells.aim_step(), (10, 19));
        let pixels = Fit::new((200, 96), (200, 96), CellGrid::Pixels { layout: l, mouse_pixels: true });
        assert_eq!(pixels.scene_at(37, 51), Some((37, 51)), "pixel reports land on that pixel");
    }

    #[test]
    fn a_scene_rendered_under_the_picture_size_scales_both_ways() {
        // kitty at 160x48 cells of 8x16: a 1280x752 picture, the scene rendered at 480x282.
        let l = layout(GraphicsMode::Kitty, (160, 48), Some((8, 16)), None, SCALED_CAP);
        let fit = Fit::new((480, 282), (480, 282), CellGrid::Pixels { layout: l, mouse_pixels: false });
        assert_eq!(fit.scene_at(80, 23), Some((241, 141)), "the centre of cell (80, 23) is pixel (644, 376)");
        assert_eq!(fit.cell_of(241, 141), (80, 23));
        assert_eq!(fit.aim_step(), (3, 6));
    }

    #[test]
    fn the_picture_has_the_target_size_with_bars_where_the_scene_is_not() {
        let mut scene = Pixmap::new(16, 9).unwrap();
        scene.fill(tiny_skia::Color::from_rgba8(200, 100, 50, 255));
        let fit = Fit::new((16, 9), (40, 9), half(40, 4));
        let mut out = Pixmap::new(40, 9).unwrap();
        fit.draw(&scene, &mut out);
        let px = |x: u32, y: u32| {
            let c = out.pixel(x, y).unwrap();
            [c.red(), c.green(), c.blue()]
        };
        assert_eq!(px(0, 4), BAR_RGB);
        assert_eq!(px(20, 4), [200, 100, 50]);
        assert_eq!(px(39, 4), BAR_RGB);
    }
}
