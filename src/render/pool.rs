//! The pool renderer: the background seen through the rippled surface, plus a slope light.
//!
//! Refraction follows the papers: output pixel (x, y) shows the background at
//! `(x + xoff·F, y + yoff·F)` with `xoff = h[x-1] - h[x+1]` and `yoff = h[y-1] - h[y+1]`,
//! clamped to the picture. F = 1 is the papers' factor; it is right for the papers' 640x480
//! window, but the amplitudes do not shrink with the picture, so at terminal size the same
//! offsets scramble the floor. [`Refraction::Auto`] therefore scales F with the picture's
//! smaller side (see [`Refraction::factor`]).
//!
//! Everything is integer arithmetic in 8.8 fixed point, so the picture is the same on every
//! machine and the loop is cheap.

use tiny_skia::{Pixmap, PremultipliedColorU8};

use crate::sim::ripple::RipplePool;

/// How strongly the surface slope displaces the background.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Refraction {
    /// Scale with the picture: `min(width, height) / 720`, between 0.15 and 1.
    Auto,
    /// A fixed factor; 1.0 is the papers' displacement, 0 shows the floor undistorted.
    Factor(f32),
}

impl Refraction {
    /// The side (in pixels) at which `Auto` gives the papers' factor of 1.
    pub const AUTO_REFERENCE_SIDE: f32 = 720.0;

    /// The factor used for a `width x height` picture.
    pub fn factor(self, width: u32, height: u32) -> f32 {
        match self {
            Refraction::Factor(f) => f,
            Refraction::Auto => (width.min(height) as f32 / Self::AUTO_REFERENCE_SIDE).clamp(0.15, 1.0),
        }
    }
}

/// How the pool is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoolLook {
    /// Background displacement per unit of slope.
    pub refraction: Refraction,
    /// Brighten slopes that face the light (from the upper left) and darken the others.
    pub shading: bool,
}

impl Default for PoolLook {
    fn default() -> Self {
        PoolLook { refraction: Refraction::Auto, shading: true }
    }
}

/// Brightness change per unit of slope, in 1/256 of a colour step.
const SHADE_PER_SLOPE_Q8: i32 = 320;
/// The strongest brightening or darkening, in colour steps.
const SHADE_LIMIT: i32 = 90;

/// Draws a ripple pool over a background of exactly the pool's size.
#[derive(Clone, Debug)]
pub struct PoolRenderer {
    background: Pixmap,
    look: PoolLook,
    refraction_q8: i32,
}

impl PoolRenderer {
    /// A renderer for pools the size of `background` (already fitted, e.g. with
    /// [`crate::render::background::cover`]).
    pub fn new(background: Pixmap, look: PoolLook) -> PoolRenderer {
        let factor = look.refraction.factor(background.width(), background.height());
        let refraction_q8 = (factor * 256.0).round().clamp(0.0, 1e6) as i32;
        PoolRenderer { background, look, refraction_q8 }
    }

    /// The look this renderer was made with.
    pub fn look(&self) -> PoolLook {
        self.look
    }

    /// The background it refracts.
    pub fn background(&self) -> &Pixmap {
        &self.background
    }

    /// Draws `pool` into `out`. Both must have the background's size.
    ///
    /// # Panics
    /// When the sizes differ (a programming error, not a user error).
    pub fn render(&self, pool: &RipplePool, out: &mut Pixmap) {
        let (w, h) = (self.background.width() as usize, self.background.height() as usize);
        assert_eq!((pool.width(), pool.height()), (w, h), "pool and background sizes differ");
        assert_eq!((out.width() as usize, out.height() as usize), (w, h), "output size differs");
        let heights = pool.heights();
        let dst = out.pixels_mut();
        for y in 0..h {
            for x in 0..w {
                let (xoff, yoff) = slope(heights, w, h, x, y);
                // Displaced position in 8.8 fixed point; fractional positions are filtered.
                let sx = ((x as i32) << 8) + xoff * self.refraction_q8;
                let sy = ((y as i32) << 8) + yoff * self.refraction_q8;
                let mut pixel = self.sample(sx, sy);
                if self.look.shading {
                    pixel = shade(pixel, light_slope(heights, w, h, x, y));
                }
                dst[y * w + x] = pixel;
            }
        }
    }

    /// The background at an 8.8 fixed-point position, bilinearly filtered, clamped to the edges.
    #[inline(always)]
    fn sample(&self, sx: i32, sy: i32) -> PremultipliedColorU8 {
        let (w, h) = (self.background.width() as i32, self.background.height() as i32);
        let bg = self.background.pixels();
        let sx = sx.clamp(0, (w - 1) << 8);
        let sy = sy.clamp(0, (h - 1) << 8);
        let (x0, y0) = ((sx >> 8) as usize, (sy >> 8) as usize);
        let (fx, fy) = ((sx & 255) as u32, (sy & 255) as u32);
        let at = |x: usize, y: usize| bg[y * w as usize + x];
        if fx == 0 && fy == 0 {
            return at(x0, y0);
        }
        let x1 = (x0 + 1).min(w as usize - 1);
        let y1 = (y0 + 1).min(h as usize - 1);
        let (p00, p01, p10, p11) = (at(x0, y0), at(x1, y0), at(x0, y1), at(x1, y1));
        let mix = |a: u8, b: u8, c: u8, d: u8| {
            let top = u32::from(a) * (256 - fx) + u32::from(b) * fx;
            let bottom = u32::from(c) * (256 - fx) + u32::from(d) * fx;
            ((top * (256 - fy) + bottom * fy + (1 << 15)) >> 16) as u8
        };
        PremultipliedColorU8::from_rgba(
            mix(p00.red(), p01.red(), p10.red(), p11.red()),
            mix(p00.green(), p01.green(), p10.green(), p11.green()),
            mix(p00.blue(), p01.blue(), p10.blue(), p11.blue()),
            255,
        )
        .expect("opaque pixels are always valid")
    }
}

/// The height at (x, y), with the picture's edge cells repeated outside it.
#[inline(always)]
fn height_at(heights: &[i16], w: usize, h: usize, x: isize, y: isize) -> i32 {
    let x = x.clamp(0, w as isize - 1) as usize;
    let y = y.clamp(0, h as isize - 1) as usize;
    i32::from(heights[y * w + x])
}

/// The papers' offsets at (x, y): left minus right, up minus down.
#[inline(always)]
fn slope(heights: &[i16], w: usize, h: usize, x: usize, y: usize) -> (i32, i32) {
    let (x, y) = (x as isize, y as isize);
    let at = |dx: isize, dy: isize| height_at(heights, w, h, x + dx, y + dy);
    (at(-1, 0) - at(1, 0), at(0, -1) - at(0, 1))
}

/// The slope towards the light (upper left), measured over two cells each side.
///
/// The integer scheme carries a faint grid-scale texture (the two sub-lattices drift apart);
/// the papers' one-cell slope turns it into speckle. The wider stencil [1, 1, 0, -1, -1]
/// cancels the finest modes and keeps the ring fronts, so the light follows the waves.
#[inline(always)]
fn light_slope(heights: &[i16], w: usize, h: usize, x: usize, y: usize) -> i32 {
    let (x, y) = (x as isize, y as isize);
    let at = |dx: isize, dy: isize| height_at(heights, w, h, x + dx, y + dy);
    let sx = at(-2, 0) + at(-1, 0) - at(1, 0) - at(2, 0);
    let sy = at(0, -2) + at(0, -1) - at(0, 1) - at(0, 2);
    sx + sy
}

/// Brightens a pixel whose surface faces the light (upper left) and darkens the others.
///
/// The surface normal is proportional to (xoff, yoff, 2), so its dot product with a light from
/// the upper left falls as the slope sum rises.
#[inline(always)]
fn shade(pixel: PremultipliedColorU8, slope_sum: i32) -> PremultipliedColorU8 {
    let delta = ((-slope_sum * SHADE_PER_SLOPE_Q8) >> 8).clamp(-SHADE_LIMIT, SHADE_LIMIT);
    let adjust = |c: u8| (i32::from(c) + delta).clamp(0, 255) as u8;
    PremultipliedColorU8::from_rgba(adjust(pixel.red()), adjust(pixel.green()), adjust(pixel.blue()), 255)
        .expect("opaque pixels are always valid")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::ripple::{Damping, Stone};

    fn striped_background(w: u32, h: u32) -> Pixmap {
        let mut bg = Pixmap::new(w, h).unwrap();
        for (i, p) in bg.pixels_mut().iter_mut().enumerate() {
            let (x, y) = ((i as u32 % w) as u8, (i as u32 / w) as u8);
            *p = PremultipliedColorU8::from_rgba(x, y, 7, 255).unwrap();
        }
        bg
    }

    #[test]
    fn still_water_shows_the_floor_unchanged() {
        let bg = striped_background(20, 10);
        let renderer = PoolRenderer::new(bg.clone(), PoolLook::default());
        let pool = RipplePool::new(20, 10, Damping::PAPERS);
        let mut out = Pixmap::new(20, 10).unwrap();
        renderer.render(&pool, &mut out);
        assert_eq!(out.data(), bg.data());
    }

    #[test]
    fn offsets_follow_the_papers_formula() {
        let bg = striped_background(30, 30);
        let look = PoolLook { refraction: Refraction::Factor(1.0), shading: false };
        let renderer = PoolRenderer::new(bg, look);
        let mut pool = RipplePool::new(30, 30, Damping::Off);
        // A single deep cell at (10, 10): its neighbours see a slope of ±5.
        pool.drop_stone(Stone { x: 10, y: 10, radius: 1, weight: 5 });
        let mut out = Pixmap::new(30, 30).unwrap();
        renderer.render(&pool, &mut out);
        let at = |x: usize, y: usize| {
            let p = out.pixels()[y * 30 + x];
            (p.red(), p.green())
        };
        // Left of the dent: xoff = h[x-1] - h[x+1] = 0 - (-5) = 5, so it shows x + 5.
        assert_eq!(at(9, 10), (14, 10));
        // Right of it: xoff = -5 - 0 = -5.
        assert_eq!(at(11, 10), (6, 10));
        // Above: yoff = 0 - (-5) = 5; below: -5.
        assert_eq!(at(10, 9), (10, 14));
        assert_eq!(at(10, 11), (10, 6));
        // The dent itself is flat around it.
        assert_eq!(at(10, 10), (10, 10));
    }

    #[test]
    fn offsets_clamp_at_the_edges() {
        let bg = striped_background(8, 8);
        let look = PoolLook { refraction: Refraction::Factor(10.0), shading: false };
        let renderer = PoolRenderer::new(bg, look);
        let mut pool = RipplePool::new(8, 8, Damping::Off);
        pool.drop_stone(Stone { x: 3, y: 3, radius: 1, weight: 100 });
        let mut out = Pixmap::new(8, 8).unwrap();
        renderer.render(&pool, &mut out);
        let p = out.pixels()[3 * 8 + 2];
        assert_eq!((p.red(), p.green()), (7, 3), "pushed past the right edge, clamped to it");
        let p = out.pixels()[3 * 8 + 4];
        assert_eq!((p.red(), p.green()), (0, 3), "pushed past the left edge");
    }

    #[test]
    fn shading_lights_slopes_facing_the_upper_left() {
        let grey = PremultipliedColorU8::from_rgba(100, 100, 100, 255).unwrap();
        assert!(shade(grey, -10).red() > 100);
        assert!(shade(grey, 10).red() < 100);
        assert_eq!(shade(grey, 0), grey);
        assert_eq!(shade(grey, -100_000).red(), 100 + SHADE_LIMIT as u8);
    }

    #[test]
    fn auto_refraction_scales_with_size() {
        assert_eq!(Refraction::Auto.factor(1920, 1080), 1.0);
        assert!((Refraction::Auto.factor(640, 360) - 0.5).abs() < 1e-6);
        assert_eq!(Refraction::Auto.factor(160, 94), 0.15);
        assert_eq!(Refraction::Factor(2.5).factor(10, 10), 2.5);
    }
}
