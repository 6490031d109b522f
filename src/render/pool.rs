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

use tiny_skia::Pixmap;

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
    /// The background's pixels as packed RGBA words, for two-channels-at-a-time filtering.
    texels: Vec<u32>,
    look: PoolLook,
    refraction_q8: i32,
}

/// Pictures smaller than this are drawn on one thread.
const PARALLEL_MIN_PIXELS: usize = 1 << 16;
/// Pixels per parallel task: big enough to amortise scheduling, small enough to balance.
const PIXELS_PER_TASK: usize = 1 << 15;

impl PoolRenderer {
    /// A renderer for pools the size of `background` (already fitted, e.g. with
    /// [`crate::render::background::cover`]).
    pub fn new(background: Pixmap, look: PoolLook) -> PoolRenderer {
        let factor = look.refraction.factor(background.width(), background.height());
        let refraction_q8 = (factor * 256.0).round().clamp(0.0, 1e6) as i32;
        let texels = background.data().chunks_exact(4).map(|p| u32::from_ne_bytes([p[0], p[1], p[2], p[3]])).collect();
        PoolRenderer { background, texels, look, refraction_q8 }
    }

    /// The look this renderer was made with.
    pub fn look(&self) -> PoolLook {
        self.look
    }

    /// The background it refracts.
    pub fn background(&self) -> &Pixmap {
        &self.background
    }

    /// Draws `pool` into `out`. Both must have the background's size. Large pictures are drawn
    /// in row bands on all cores; every pixel is computed the same way whatever the split.
    ///
    /// # Panics
    /// When the sizes differ (a programming error, not a user error).
    pub fn render(&self, pool: &RipplePool, out: &mut Pixmap) {
        let (w, h) = (self.background.width() as usize, self.background.height() as usize);
        assert_eq!((pool.width(), pool.height()), (w, h), "pool and background sizes differ");
        assert_eq!((out.width() as usize, out.height() as usize), (w, h), "output size differs");
        let heights = pool.heights();
        let bytes = out.data_mut();
        if w * h < PARALLEL_MIN_PIXELS {
            self.render_rows(heights, 0, bytes);
        } else {
            use rayon::prelude::*;
            let rows_per_task = (PIXELS_PER_TASK / w).max(1);
            bytes
                .par_chunks_mut(rows_per_task * w * 4)
                .enumerate()
                .for_each(|(task, rows)| self.render_rows(heights, task * rows_per_task, rows));
        }
    }

    /// Draws the rows starting at `first_row` into `out` (whole rows of RGBA bytes).
    fn render_rows(&self, heights: &[i16], first_row: usize, out: &mut [u8]) {
        let (w, h) = (self.background.width() as usize, self.background.height() as usize);
        let q = self.refraction_q8;
        for (i, out_row) in out.chunks_exact_mut(w * 4).enumerate() {
            let y = first_row + i;
            // Rows y-2..=y+2, the picture's edge rows repeated beyond it.
            let row = |dy: isize| {
                let r = (y as isize + dy).clamp(0, h as isize - 1) as usize;
                &heights[r * w..(r + 1) * w]
            };
            let (up2, up, mid, down, down2) = (row(-2), row(-1), row(0), row(1), row(2));
            for (x, pixel) in out_row.chunks_exact_mut(4).enumerate() {
                let (l1, r1) = (x.saturating_sub(1), (x + 1).min(w - 1));
                // The papers' offsets: left minus right, up minus down.
                let xoff = i32::from(mid[l1]) - i32::from(mid[r1]);
                let yoff = i32::from(up[x]) - i32::from(down[x]);
                let mut colour = self.sample(((x as i32) << 8) + xoff * q, ((y as i32) << 8) + yoff * q);
                if self.look.shading {
                    let (l2, r2) = (x.saturating_sub(2), (x + 2).min(w - 1));
                    let across = i32::from(mid[l2]) + i32::from(mid[l1]) - i32::from(mid[r1]) - i32::from(mid[r2]);
                    let along = i32::from(up2[x]) + i32::from(up[x]) - i32::from(down[x]) - i32::from(down2[x]);
                    colour = shade(colour, across + along);
                }
                pixel.copy_from_slice(&colour.to_ne_bytes());
            }
        }
    }

    /// The background at an 8.8 fixed-point position, bilinearly filtered, clamped to the edges.
    #[inline(always)]
    fn sample(&self, sx: i32, sy: i32) -> u32 {
        let (w, h) = (self.background.width() as i32, self.background.height() as i32);
        let sx = sx.clamp(0, (w - 1) << 8);
        let sy = sy.clamp(0, (h - 1) << 8);
        let (x0, y0) = ((sx >> 8) as usize, (sy >> 8) as usize);
        let (fx, fy) = ((sx & 255) as u32, (sy & 255) as u32);
        let w = w as usize;
        let at = |x: usize, y: usize| self.texels[y * w + x];
        if fx == 0 && fy == 0 {
            return at(x0, y0);
        }
        let x1 = (x0 + 1).min(w - 1);
        let y1 = (y0 + 1).min(h as usize - 1);
        let top = lerp_packed(at(x0, y0), at(x1, y0), fx);
        let bottom = lerp_packed(at(x0, y1), at(x1, y1), fx);
        lerp_packed(top, bottom, fy)
    }
}

/// Linear interpolation of two packed RGBA words, two channels per multiply: `f` in 0..=256
/// is the weight of `b`. Each channel is `(a·(256-f) + b·f) >> 8`, which keeps 255 at 255.
#[inline(always)]
fn lerp_packed(a: u32, b: u32, f: u32) -> u32 {
    const MASK: u32 = 0x00FF_00FF;
    let g = 256 - f;
    let even = (((a & MASK) * g + (b & MASK) * f) >> 8) & MASK;
    let odd = ((((a >> 8) & MASK) * g + ((b >> 8) & MASK) * f) >> 8) & MASK;
    even | (odd << 8)
}

/// Brightens a packed opaque pixel whose surface faces the light (upper left) and darkens the
/// others, by an amount proportional to `slope_sum` (the slope away from the light).
#[inline(always)]
fn shade(pixel: u32, slope_sum: i32) -> u32 {
    let delta = ((-slope_sum * SHADE_PER_SLOPE_Q8) >> 8).clamp(-SHADE_LIMIT, SHADE_LIMIT);
    if delta == 0 {
        return pixel;
    }
    let [r, g, b, a] = pixel.to_ne_bytes();
    let adjust = |c: u8| (i32::from(c) + delta).clamp(0, 255) as u8;
    u32::from_ne_bytes([adjust(r), adjust(g), adjust(b), a])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::ripple::{Damping, Stone};

    fn striped_background(w: u32, h: u32) -> Pixmap {
        let mut bg = Pixmap::new(w, h).unwrap();
        for (i, p) in bg.pixels_mut().iter_mut().enumerate() {
            let (x, y) = ((i as u32 % w) as u8, (i as u32 / w) as u8);
            *p = tiny_skia::PremultipliedColorU8::from_rgba(x, y, 7, 255).unwrap();
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
        let grey = u32::from_ne_bytes([100, 100, 100, 255]);
        let red = |p: u32| p.to_ne_bytes()[0];
        assert!(red(shade(grey, -10)) > 100);
        assert!(red(shade(grey, 10)) < 100);
        assert_eq!(shade(grey, 0), grey);
        assert_eq!(red(shade(grey, -100_000)), 100 + SHADE_LIMIT as u8);
        assert_eq!(shade(grey, -100_000).to_ne_bytes()[3], 255, "alpha untouched");
    }

    #[test]
    fn packed_lerp_is_exact_per_channel() {
        let a = u32::from_ne_bytes([0, 255, 10, 255]);
        let b = u32::from_ne_bytes([255, 0, 30, 255]);
        assert_eq!(lerp_packed(a, b, 0), a);
        assert_eq!(lerp_packed(a, b, 256), b);
        assert_eq!(lerp_packed(a, b, 128).to_ne_bytes(), [127, 127, 20, 255]);
    }

    #[test]
    fn parallel_rows_equal_single_thread_rows() {
        let (w, h) = (400u32, 300u32);
        let renderer = PoolRenderer::new(striped_background(w, h), PoolLook::default());
        let mut pool = RipplePool::new(w as usize, h as usize, Damping::PAPERS);
        for k in 0..9 {
            pool.drop_stone(Stone { x: 40 * k, y: 30 * k, radius: 7, weight: 300 });
        }
        pool.advance(25);
        let mut parallel = Pixmap::new(w, h).unwrap();
        renderer.render(&pool, &mut parallel);
        let mut single = Pixmap::new(w, h).unwrap();
        renderer.render_rows(pool.heights(), 0, single.data_mut());
        assert_eq!(parallel.data(), single.data());
    }

    #[test]
    fn auto_refraction_scales_with_size() {
        assert_eq!(Refraction::Auto.factor(1920, 1080), 1.0);
        assert!((Refraction::Auto.factor(640, 360) - 0.5).abs() < 1e-6);
        assert_eq!(Refraction::Auto.factor(160, 94), 0.15);
        assert_eq!(Refraction::Factor(2.5).factor(10, 10), 2.5);
    }
}
