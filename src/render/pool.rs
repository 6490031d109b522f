//! The pool renderer: the floor seen through the rippled surface, lit by the sun.
//!
//! Refraction follows the papers: output pixel (x, y) shows the floor at
//! `(x + xoff·F, y + yoff·F)` with `xoff = h[x-1] - h[x+1]` and `yoff = h[y-1] - h[y+1]`,
//! clamped to the picture. F = 1 is the papers' factor; it is right for the papers' 640x480
//! window, but the amplitudes do not shrink with the picture, so at terminal size the same
//! offsets scramble the floor. [`Refraction::Auto`] therefore scales F with the picture's
//! smaller side (see [`Refraction::factor`]). Fractional offsets are filtered bilinearly.
//!
//! Light, beyond the papers: the floor is lit by caustics ([`super::caustics`]), shifted away
//! from the sun by the slant of the refracted sunlight; ripple flanks facing the sun are
//! brightened and the others darkened; crests tilted towards the sun glint.
//!
//! Displacement and filtering are integer arithmetic in 8.8 fixed point; the light is `f32`.
//! Either way the picture is the same on every run.

use tiny_skia::Pixmap;

use super::caustics::{self, AMPLITUDE_PER_PIXEL, CausticsLook, WATER_INDEX};
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

/// Where the sun is: azimuth clockwise from north (the top of the picture), elevation above
/// the horizon, both in degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sun {
    /// Degrees clockwise from north (0 = top of the picture, 90 = right).
    pub azimuth_deg: f32,
    /// Degrees above the horizon, 0..=90.
    pub elevation_deg: f32,
}

impl Default for Sun {
    /// High in the north-west: light from the upper left, as pictures are usually lit.
    fn default() -> Self {
        Sun { azimuth_deg: 315.0, elevation_deg: 60.0 }
    }
}

impl Sun {
    /// The unit vector towards the sun in picture coordinates (x right, y down, z up).
    pub fn direction(self) -> [f32; 3] {
        let (az, el) = (self.azimuth_deg.to_radians(), self.elevation_deg.to_radians());
        [az.sin() * el.cos(), -az.cos() * el.cos(), el.sin()]
    }
}

/// How the pool is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoolLook {
    /// Background displacement per unit of slope.
    pub refraction: Refraction,
    /// Light the slopes from the sun, with glints on crests facing it.
    pub shading: bool,
    /// Caustics on the floor; `None` for none.
    pub caustics: Option<CausticsLook>,
    /// Where the light comes from.
    pub sun: Sun,
}

impl Default for PoolLook {
    fn default() -> Self {
        PoolLook {
            refraction: Refraction::Auto,
            shading: true,
            caustics: Some(CausticsLook::default()),
            sun: Sun::default(),
        }
    }
}

/// Brightness change per unit of the two-cell slope stencil along the sun, in colour steps.
const SHADE_PER_SLOPE: f32 = 1.77;
/// The strongest brightening or darkening, in colour steps.
const SHADE_LIMIT: i32 = 90;
/// The glint lobe starts at this N·H (about 14° from the mirror direction)...
const GLINT_LOBE_START: f32 = 0.97;
/// ...and never closer than this above flat water's N·H.
const GLINT_MARGIN: f32 = 0.004;
/// Colour steps a perfect glint adds.
const GLINT_LEVELS: f32 = 230.0;
/// The two-cell slope stencil spans (1 + 2 + 2 + 1) = 6 cells of gradient.
const STENCIL_SPAN: f32 = 6.0;

/// Draws a ripple pool over a background of exactly the pool's size.
#[derive(Clone, Debug)]
pub struct PoolRenderer {
    background: Pixmap,
    /// The background's pixels as packed RGBA words, for two-channels-at-a-time filtering.
    texels: Vec<u32>,
    look: PoolLook,
    refraction_q8: i32,
    /// The caustics' light on the floor, rebuilt every frame.
    light: caustics::LightMap,
    /// Where the refracted sunlight lands relative to the cell it crossed, in whole pixels.
    light_shift: (i32, i32),
    lighting: Lighting,
}

/// The sun's light, prepared once per renderer.
#[derive(Clone, Copy, Debug)]
struct Lighting {
    /// The sun's horizontal direction, in 1/256 colour steps per unit of slope stencil.
    shade_x_q8: i32,
    shade_y_q8: i32,
    /// The half vector's horizontal part and the glint threshold, in the stencil's integer
    /// units (x1024), for a cheap first test.
    half_x_q10: i32,
    half_y_q10: i32,
    glint_candidate_q10: i32,
    /// The half-way vector between the sun and the viewer (looking straight down).
    half: [f32; 3],
    /// N·H above which a crest glints: a little above flat water's, so that flat water
    /// (which an overhead view would show uniformly lit by the sun) never does.
    glint_from: f32,
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
        let sun = look.sun.direction();
        let horizontal = (sun[0] * sun[0] + sun[1] * sun[1]).sqrt().max(1e-6);
        // Sunlight enters the water at (90° - elevation) from the vertical and is bent
        // towards the vertical; it travels away from the sun, so a cell's light lands
        // downstream by depth · tan(refracted angle).
        let light_shift = match look.caustics {
            Some(c) => {
                let sin_refracted = (horizontal / WATER_INDEX).min(1.0);
                let run = c.depth_px * sin_refracted / (1.0 - sin_refracted * sin_refracted).sqrt();
                ((-sun[0] / horizontal * run).round() as i32, (-sun[1] / horizontal * run).round() as i32)
            }
            None => (0, 0),
        };
        let half = normalize([sun[0], sun[1], sun[2] + 1.0]);
        let glint_from = (half[2] + GLINT_MARGIN).max(GLINT_LOBE_START);
        // numerator = (across·hx + along·hy) / span + hz > glint_from, scaled by span·1024
        // (and made one lower, so rounding can only let more pixels through to the exact test).
        let span = STENCIL_SPAN * AMPLITUDE_PER_PIXEL;
        let lighting = Lighting {
            shade_x_q8: (sun[0] * SHADE_PER_SLOPE * 256.0).round() as i32,
            shade_y_q8: (sun[1] * SHADE_PER_SLOPE * 256.0).round() as i32,
            half_x_q10: (half[0] * 1024.0).round() as i32,
            half_y_q10: (half[1] * 1024.0).round() as i32,
            glint_candidate_q10: ((glint_from - half[2]) * span * 1024.0).floor() as i32 - 1024,
            half,
            glint_from,
        };
        PoolRenderer {
            background,
            texels,
            look,
            refraction_q8,
            light: caustics::LightMap::default(),
            light_shift,
            lighting,
        }
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
    pub fn render(&mut self, pool: &RipplePool, out: &mut Pixmap) {
        let (w, h) = (self.background.width() as usize, self.background.height() as usize);
        assert_eq!((pool.width(), pool.height()), (w, h), "pool and background sizes differ");
        assert_eq!((out.width() as usize, out.height() as usize), (w, h), "output size differs");
        let heights = pool.heights();
        if let Some(look) = self.look.caustics {
            self.light.compute(heights, w, h, look);
        }
        let this = &*self;
        let bytes = out.data_mut();
        if w * h < PARALLEL_MIN_PIXELS {
            this.render_rows(heights, 0, bytes);
        } else {
            use rayon::prelude::*;
            let rows_per_task = (PIXELS_PER_TASK / w).max(1);
            bytes
                .par_chunks_mut(rows_per_task * w * 4)
                .enumerate()
                .for_each(|(task, rows)| this.render_rows(heights, task * rows_per_task, rows));
        }
    }

    /// Draws the rows starting at `first_row` into `out` (whole rows of RGBA bytes).
    fn render_rows(&self, heights: &[i16], first_row: usize, out: &mut [u8]) {
        let (w, h) = (self.background.width() as usize, self.background.height() as usize);
        for (i, out_row) in out.chunks_exact_mut(w * 4).enumerate() {
            let y = first_row + i;
            // Rows y-2..=y+2, the picture's edge rows repeated beyond it.
            let row = |dy: isize| {
                let r = (y as isize + dy).clamp(0, h as isize - 1) as usize;
                &heights[r * w..(r + 1) * w]
            };
            let rows = [row(-2), row(-1), row(0), row(1), row(2)];
            let pixels: &mut [[u8; 4]] = out_row.as_chunks_mut::<4>().0;
            // Columns two or more away from the edges need no clamping: a separate loop lets
            // the compiler drop it.
            let inner = 2..w.saturating_sub(2).max(2);
            for x in (0..w).filter(|x| !inner.contains(x)) {
                let near = [x.saturating_sub(2), x.saturating_sub(1), (x + 1).min(w - 1), (x + 2).min(w - 1)];
                pixels[x] = self.pixel(&rows, x, y, near).to_ne_bytes();
            }
            for x in inner {
                pixels[x] = self.pixel(&rows, x, y, [x - 2, x - 1, x + 1, x + 2]).to_ne_bytes();
            }
        }
    }

    /// One output pixel: `rows` are the height rows y-2..=y+2, `near` the columns x-2, x-1,
    /// x+1, x+2 (clamped at the edges).
    #[inline(always)]
    fn pixel(&self, rows: &[&[i16]; 5], x: usize, y: usize, near: [usize; 4]) -> u32 {
        let (w, h) = (self.background.width() as i32, self.background.height() as i32);
        let [up2, up, mid, down, down2] = *rows;
        let [l2, l1, r1, r2] = near;
        let q = self.refraction_q8;
        // The papers' offsets: left minus right, up minus down.
        let xoff = i32::from(mid[l1]) - i32::from(mid[r1]);
        let yoff = i32::from(up[x]) - i32::from(down[x]);
        let sx = (((x as i32) << 8) + xoff * q).clamp(0, (w - 1) << 8);
        let sy = (((y as i32) << 8) + yoff * q).clamp(0, (h - 1) << 8);
        let colour = self.sample(sx, sy);
        let gain = if self.look.caustics.is_some() {
            // The light that reached the floor point we see came through the surface upstream
            // of it, towards the sun.
            let lx = ((sx >> 8) - self.light_shift.0).clamp(0, w - 1) as usize;
            let ly = ((sy >> 8) - self.light_shift.1).clamp(0, h - 1) as usize;
            self.light.gain(lx, ly)
        } else {
            caustics::UNIT_GAIN
        };
        let delta = if self.look.shading {
            let across = i32::from(mid[l2]) + i32::from(mid[l1]) - i32::from(mid[r1]) - i32::from(mid[r2]);
            let along = i32::from(up2[x]) + i32::from(up[x]) - i32::from(down[x]) - i32::from(down2[x]);
            self.surface_light(across, along)
        } else {
            0
        };
        light_pixel(colour, gain, delta)
    }

    /// Sun light on the surface at a pixel whose two-cell slope stencils are `across`
    /// (left minus right) and `along` (up minus down): the colour steps to add for diffuse
    /// shading and a glint.
    #[inline(always)]
    fn surface_light(&self, across: i32, along: i32) -> i32 {
        if across == 0 && along == 0 {
            return 0; // still water: no shading, and flat water never glints (below)
        }
        let light = &self.lighting;
        let mut delta = ((across * light.shade_x_q8 + along * light.shade_y_q8) >> 8).clamp(-SHADE_LIMIT, SHADE_LIMIT);
        // N·H is at most its numerator, which is checked first in integers, so the root is
        // only taken near a glint.
        if across * light.half_x_q10 + along * light.half_y_q10 > light.glint_candidate_q10 {
            // The normal is (-dh/dx, -dh/dy, 1) in pixels; the stencils are -6x the gradient
            // in amplitude units.
            let scale = 1.0 / (STENCIL_SPAN * AMPLITUDE_PER_PIXEL);
            let (nx, ny) = (across as f32 * scale, along as f32 * scale);
            let n_dot_h = (nx * light.half[0] + ny * light.half[1] + light.half[2]) / (nx * nx + ny * ny + 1.0).sqrt();
            if n_dot_h > light.glint_from {
                // A compact lobe: 0 at `glint_from`, 1 when the crest mirrors the sun exactly.
                let t = (n_dot_h - light.glint_from) / (1.0 - light.glint_from);
                let t2 = t * t;
                delta += (t2 * t2 * GLINT_LEVELS) as i32;
            }
        }
        delta
    }

    /// The background at an 8.8 fixed-point position inside the picture, bilinearly filtered.
    #[inline(always)]
    fn sample(&self, sx: i32, sy: i32) -> u32 {
        let (w, h) = (self.background.width() as usize, self.background.height() as usize);
        let (x0, y0) = ((sx >> 8) as usize, (sy >> 8) as usize);
        let (fx, fy) = ((sx & 255) as u32, (sy & 255) as u32);
        let at = |x: usize, y: usize| self.texels[y * w + x];
        if fx == 0 && fy == 0 {
            return at(x0, y0);
        }
        let x1 = (x0 + 1).min(w - 1);
        let y1 = (y0 + 1).min(h - 1);
        let top = lerp_packed(at(x0, y0), at(x1, y0), fx);
        let bottom = lerp_packed(at(x0, y1), at(x1, y1), fx);
        lerp_packed(top, bottom, fy)
    }
}

fn normalize([x, y, z]: [f32; 3]) -> [f32; 3] {
    let len = (x * x + y * y + z * z).sqrt().max(1e-12);
    [x / len, y / len, z / len]
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

/// Applies the floor's light `gain` (1/64 units, [`caustics::UNIT_GAIN`] = unchanged) and then
/// adds `delta` colour steps, saturating; alpha stays.
#[inline(always)]
fn light_pixel(pixel: u32, gain: u8, delta: i32) -> u32 {
    if gain == caustics::UNIT_GAIN && delta == 0 {
        return pixel;
    }
    let [r, g, b, a] = pixel.to_ne_bytes();
    let gain = i32::from(gain);
    let light = |c: u8| (((i32::from(c) * gain) >> 6) + delta).clamp(0, 255) as u8;
    u32::from_ne_bytes([light(r), light(g), light(b), a])
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
        let mut renderer = PoolRenderer::new(bg.clone(), PoolLook::default());
        let pool = RipplePool::new(20, 10, Damping::PAPERS);
        let mut out = Pixmap::new(20, 10).unwrap();
        renderer.render(&pool, &mut out);
        assert_eq!(out.data(), bg.data());
    }

    #[test]
    fn offsets_follow_the_papers_formula() {
        let bg = striped_background(30, 30);
        let look =
            PoolLook { refraction: Refraction::Factor(1.0), shading: false, caustics: None, ..PoolLook::default() };
        let mut renderer = PoolRenderer::new(bg, look);
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
        let look =
            PoolLook { refraction: Refraction::Factor(10.0), shading: false, caustics: None, ..PoolLook::default() };
        let mut renderer = PoolRenderer::new(bg, look);
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
    fn shading_lights_slopes_facing_the_sun() {
        let renderer = PoolRenderer::new(striped_background(4, 4), PoolLook::default());
        let grey = u32::from_ne_bytes([100, 100, 100, 255]);
        let red = |p: u32| p.to_ne_bytes()[0];
        let renderer = Shader(renderer);
        // The default sun is in the upper left: a surface rising to the right (across < 0)
        // faces it.
        assert!(red(renderer.light_surface(grey, -10, -10)) > 100);
        assert!(red(renderer.light_surface(grey, 10, 10)) < 100);
        assert_eq!(renderer.light_surface(grey, 0, 0), grey, "flat water, sun off the glint angle");
        assert_eq!(renderer.light_surface(grey, -30000, -30000).to_ne_bytes()[3], 255, "alpha untouched");
        let west = Shader(PoolRenderer::new(
            striped_background(4, 4),
            PoolLook { sun: Sun { azimuth_deg: 270.0, elevation_deg: 45.0 }, ..PoolLook::default() },
        ));
        assert!(red(west.light_surface(grey, -10, 0)) > 100);
        assert_eq!(red(west.light_surface(grey, 0, -10)), 100, "a slope across the light is not shaded");
    }

    #[test]
    fn crests_tilted_towards_the_sun_glint() {
        let renderer = Shader(PoolRenderer::new(striped_background(4, 4), PoolLook::default()));
        let dark = u32::from_ne_bytes([20, 40, 80, 255]);
        // The default sun is 30° off the vertical in the north-west: the half vector is 15°
        // off, so a slope of tan 15° ≈ 0.27 towards the upper left mirrors the sun at the eye.
        let slope = (0.268 * STENCIL_SPAN * AMPLITUDE_PER_PIXEL / 2f32.sqrt()) as i32;
        let glint = renderer.light_surface(dark, -slope, -slope).to_ne_bytes();
        assert!(glint[0] > 200 && glint[2] > 200, "{glint:?}");
        let off = renderer.light_surface(dark, slope, slope).to_ne_bytes();
        assert!(off[0] < 20, "{off:?}");
        let flat_enough = renderer.light_surface(dark, -1, -1).to_ne_bytes();
        assert!(flat_enough[0] < 25, "nearly flat water does not glint: {flat_enough:?}");
    }

    #[test]
    fn caustic_gain_scales_colour_and_saturates() {
        let p = u32::from_ne_bytes([100, 200, 10, 255]);
        assert_eq!(light_pixel(p, 64, 0), p);
        assert_eq!(light_pixel(p, 128, 0).to_ne_bytes(), [200, 255, 20, 255]);
        assert_eq!(light_pixel(p, 32, 0).to_ne_bytes(), [50, 100, 5, 255]);
        assert_eq!(light_pixel(p, 32, 10).to_ne_bytes(), [60, 110, 15, 255]);
        assert_eq!(light_pixel(p, 64, -20).to_ne_bytes(), [80, 180, 0, 255]);
    }

    /// The renderer's surface light applied to one colour, as the tests want it.
    struct Shader(PoolRenderer);

    impl Shader {
        fn light_surface(&self, colour: u32, across: i32, along: i32) -> u32 {
            light_pixel(colour, caustics::UNIT_GAIN, self.0.surface_light(across, along))
        }
    }

    #[test]
    fn the_sun_shifts_the_caustics_away_from_it() {
        let look = PoolLook { sun: Sun { azimuth_deg: 90.0, elevation_deg: 45.0 }, ..PoolLook::default() };
        let renderer = PoolRenderer::new(striped_background(4, 4), look);
        // Sun in the east: light travels west (negative x), by depth · tan(asin(cos 45° / 1.33))
        // = 24 · 0.628 ≈ 15 pixels.
        assert_eq!(renderer.light_shift, (-15, 0));
        let overhead = PoolLook { sun: Sun { azimuth_deg: 0.0, elevation_deg: 90.0 }, ..PoolLook::default() };
        assert_eq!(PoolRenderer::new(striped_background(4, 4), overhead).light_shift, (0, 0));
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
        let mut renderer = PoolRenderer::new(striped_background(w, h), PoolLook::default());
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
