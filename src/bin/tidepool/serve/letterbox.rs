//! Where the shared picture sits in one player's terminal: scaled to fit, centred, with bars
//! on the sides that do not fit, and the way back from a cell the player clicked to the shared
//! scene's pixel.
//!
//! The shared scene has one fixed size (resizing the pool stills its water, which one player
//! cannot be allowed to do to everyone), so each terminal gets its own fit.

use tiny_skia::{FilterQuality, Pixmap, PixmapPaint, Transform};

/// The bars' colour around a picture that does not fill the terminal (the status line's blue,
/// darker).
pub const BAR_RGB: [u8; 3] = [8, 12, 20];

/// How the scene's picture maps into a terminal picture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Letterbox {
    /// Terminal picture pixels per scene pixel.
    pub scale: f32,
    /// Left edge of the scene in the terminal picture, in pixels.
    pub x0: u32,
    /// Top edge, in pixels (even, so the scene's rows start on a cell's upper half).
    pub y0: u32,
    /// Scene width and height, in scene pixels.
    pub scene: (u32, u32),
    /// Terminal picture width and height, in pixels.
    pub target: (u32, u32),
}

impl Letterbox {
    /// The fit of a `scene` picture into a `target` picture (both width, height in pixels).
    pub fn fit(scene: (u32, u32), target: (u32, u32)) -> Letterbox {
        let (sw, sh) = (scene.0.max(1) as f32, scene.1.max(1) as f32);
        let scale = (target.0 as f32 / sw).min(target.1 as f32 / sh);
        let (w, h) = ((sw * scale).round() as u32, (sh * scale).round() as u32);
        let x0 = target.0.saturating_sub(w) / 2;
        let y0 = (target.1.saturating_sub(h) / 2) & !1;
        Letterbox { scale, x0, y0, scene, target }
    }

    /// The scene pixel under terminal picture pixel `(x, y)`, or `None` on the bars.
    pub fn to_scene(self, x: i32, y: i32) -> Option<(i32, i32)> {
        let sx = ((x as f32 - self.x0 as f32 + 0.5) / self.scale).floor() as i32;
        let sy = ((y as f32 - self.y0 as f32 + 0.5) / self.scale).floor() as i32;
        let inside = (0..self.scene.0 as i32).contains(&sx) && (0..self.scene.1 as i32).contains(&sy);
        inside.then_some((sx, sy))
    }

    /// The terminal picture pixel at the centre of scene pixel `(x, y)`.
    pub fn to_target(self, x: i32, y: i32) -> (i32, i32) {
        let tx = self.x0 as f32 + (x as f32 + 0.5) * self.scale;
        let ty = self.y0 as f32 + (y as f32 + 0.5) * self.scale;
        (tx.floor() as i32, ty.floor() as i32)
    }

    /// Draws `scene` into a new picture of the target's size, bars included (`None` when the
    /// target is empty).
    pub fn draw(&self, scene: &Pixmap) -> Option<Pixmap> {
        let mut out = Pixmap::new(self.target.0.max(1), self.target.1.max(1))?;
        let [r, g, b] = BAR_RGB;
        out.fill(tiny_skia::Color::from_rgba8(r, g, b, 255));
        // Bilinear when shrinking or growing by a fraction; whole-number growth stays sharp.
        let quality = if self.scale.fract() == 0.0 { FilterQuality::Nearest } else { FilterQuality::Bilinear };
        let paint = PixmapPaint { quality, ..PixmapPaint::default() };
        let transform = Transform::from_scale(self.scale, self.scale).post_translate(self.x0 as f32, self.y0 as f32);
        out.draw_pixmap(0, 0, scene.as_ref(), &paint, transform, None);
        Some(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wide_terminal_gets_bars_on_the_sides_and_clicks_map_back() {
        let fit = Letterbox::fit((160, 90), (200, 90));
        assert_eq!((fit.scale, fit.x0, fit.y0), (1.0, 20, 0));
        assert_eq!(fit.to_scene(20, 0), Some((0, 0)));
        assert_eq!(fit.to_scene(19, 0), None, "the bar");
        assert_eq!(fit.to_scene(179, 89), Some((159, 89)));
        assert_eq!(fit.to_scene(180, 10), None);
    }

    #[test]
    fn a_small_terminal_shrinks_the_scene_and_the_round_trip_holds() {
        let fit = Letterbox::fit((160, 90), (80, 46));
        assert_eq!(fit.scale, 0.5);
        assert_eq!(fit.y0, 0, "(46 - 45) / 2 rounded down to even");
        for (x, y) in [(0, 0), (37, 11), (159, 89), (80, 44)] {
            let (tx, ty) = fit.to_target(x, y);
            let back = fit.to_scene(tx, ty).unwrap();
            assert!((back.0 - x).abs() <= 1 && (back.1 - y).abs() <= 1, "{x},{y} -> {tx},{ty} -> {back:?}");
        }
    }

    #[test]
    fn the_picture_has_the_target_size_with_bars_where_the_scene_is_not() {
        let mut scene = Pixmap::new(16, 9).unwrap();
        scene.fill(tiny_skia::Color::from_rgba8(200, 100, 50, 255));
        let fit = Letterbox::fit((16, 9), (40, 9));
        let out = fit.draw(&scene).unwrap();
        assert_eq!((out.width(), out.height()), (40, 9));
        let px = |x: u32, y: u32| {
            let c = out.pixel(x, y).unwrap();
            [c.red(), c.green(), c.blue()]
        };
        assert_eq!(px(0, 4), BAR_RGB);
        assert_eq!(px(20, 4), [200, 100, 50]);
        assert_eq!(px(39, 4), BAR_RGB);
    }
}
