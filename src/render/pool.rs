//! The pool renderer: the floor seen through the rippled surface, lit by the sun.
//!
//! Refraction follows the papers: output pixel (x, y) shows the floor at
//! `(x + xoff·F, y + yoff·F)` with `xoff = h[x-1] - h[x+1]` and `yoff = h[y-1] - h[y+1]`,
//! clamped to the picture. F = 1 is the papers' factor; it suits a picture of about 720 pixels,
//! but the amplitudes do not shrink with the picture, so at terminal size the same
//! offsets scramble the floor. [`Refraction::AUTO`] therefore scales F with the picture's
//! smaller side (see [`Refraction::factor`]). Fractional offsets are filtered bilinearly.
//!
//! Light, beyond the papers: the floor is lit by caustics ([`super::caustics`]), shifted away
//! from the sun by the slant of the refracted sunlight; ripple flanks facing the sun are
//! brightened and the others darkened; crests tilted towards the sun glint.
//!
//! Displacement and filtering are integer arithmetic in 8.8 fixed point; the light is `f32`.
//! Either way the picture is the same on every run.

use tiny_skia::Pixmap;

mod look;
mod rows;

pub use look::{PoolLook, Refraction, Sun};

use super::caustics::{self, AMPLITUDE_PER_PIXEL, WATER_INDEX};
#[cfg(test)]
use crate::sim::ripple::RipplePool;
use crate::simd::Simd;
use rows::RowScratch;

/// Brightness change per unit of the two-cell slope stencil along the sun, in colour steps.
const SHADE_PER_SLOPE: f32 = 1.77;
/// The strongest brightening or darkening, in colour steps.
const SHADE_LIMIT: i32 = 90;
/// The glint lobe starts at this N·H (about 10° from the mirror direction)...
const GLINT_LOBE_START: f32 = 0.985;
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
    /// The background's RGBA pixels, each a packed word (its bytes in memory order, for
    /// two-channels-at-a-time filtering), followed by a copy of the last row and one more
    /// pixel.
    texels: Vec<u32>,
    look: PoolLook,
    refraction_q8: i32,
    /// The caustics' light on the floor, rebuilt every frame.
    light: caustics::LightMap,
    /// Where the refracted sunlight lands relative to the cell it crossed, in whole pixels.
    light_shift: (i32, i32),
    lighting: Lighting,
    /// The instruction set the rows and the caustics run with.
    simd: Simd,
    /// Pool cells per picture pixel along each axis (the background has the pool's size).
    grid: u32,
    /// Height units per amplitude unit of the pool.
    units: f32,
    /// Each parallel task's scratch rows, kept between frames.
    scratch: Vec<RowScratch>,
}

/// The sun's light, prepared once per renderer.
#[derive(Clone, Copy, Debug)]
struct Lighting {
    /// The sun's horizontal direction, in 1/256 colour steps per unit of slope stencil.
    shade_x_q8: i32,
    shade_y_q8: i32,
    /// A disc in (across, along) stencil units that holds every slope which can glint: the
    /// slope that mirrors the sun exactly is its centre. Pixels outside skip the exact test.
    glint_centre: [f32; 2],
    glint_radius_sq: f32,
    /// From the stencils to the normal's (nx, ny): 1 / (the stencil's span in height units
    /// per pixel of slope).
    glint_scale: f32,
    /// The half-way vector between the sun and the viewer (looking straight down).
    half: [f32; 3],
    /// N·H above which a crest glints: a little above flat water's, so that flat water
    /// (which an overhead view would show uniformly lit by the sun) never does.
    glint_from: f32,
}

/// The heights a picture is drawn from, each the background's size: `refraction` displaces the
/// floor (the papers' offsets), `light` lights it (caustics, shading, glints). For a pool's
/// own picture both are its heights.
#[derive(Clone, Copy, Debug)]
pub struct Fields<'a> {
    /// Displaces the floor.
    pub refraction: &'a [i16],
    /// Lights the floor and the surface.
    pub light: &'a [i16],
}

/// Rows y-2..=y+2 of both fields around one picture row.
struct Rows<'a> {
    refraction: [&'a [i16]; 5],
    light: [&'a [i16]; 5],
}

/// Pictures of fewer cells are drawn on one thread.
const PARALLEL_MIN_PIXELS: usize = 1 << 16;
/// Cells per parallel task: big enough to amortise scheduling, small enough to balance.
const PIXELS_PER_TASK: usize = 1 << 15;

impl PoolRenderer {
    /// A renderer for pools the size of `background` (already fitted, e.g. with
    /// [`crate::render::background::cover`]), one cell a pixel.
    #[cfg(test)]
    pub fn new(background: Pixmap, look: PoolLook) -> PoolRenderer {
        PoolRenderer::on_grid(background, look, 1, 1)
    }

    /// A renderer for pools of `grid x grid` cells a picture pixel, the size of `background`
    /// (already fitted), drawn at the pool's resolution: the caustics are computed per picture
    /// pixel and their depth is in picture pixels, so they look as on a pool of one cell a
    /// pixel. The heights it is given hold `units` per amplitude unit of the pool (1: the
    /// pool's own; more: heights at a finer precision, such as the pool with the gusts' ripples
    /// added, which would flicker by whole units where they are rounded).
    pub fn on_grid(background: Pixmap, look: PoolLook, grid: u32, units: u32) -> PoolRenderer {
        let grid = grid.max(1);
        let units = units.max(1) as f32;
        let factor = look.refraction.factor(background.width(), background.height());
        let refraction_q8 = (factor / units * 256.0).round().clamp(0.0, 1e6) as i32;
        // One extra row and texel past the end, so the filter's right and lower neighbours can be
        // fetched without a check at the last column and row (their weight is 0 there).
        let (w, h) = (background.width() as usize, background.height() as usize);
        let mut texels: Vec<u32> =
            background.data().chunks_exact(4).map(|p| u32::from_ne_bytes(p.try_into().expect("four bytes"))).collect();
        texels.extend_from_within((h - 1) * w..h * w);
        texels.extend_from_within(texels.len() - 1..);
        let sun = look.sun.direction();
        let horizontal = (sun[0] * sun[0] + sun[1] * sun[1]).sqrt().max(1e-6);
        // Sunlight enters the water at (90° - elevation) from the vertical and is bent
        // towards the vertical; it travels away from the sun, so a cell's light lands
        // downstream by depth · tan(refracted angle).
        let light_shift = match look.caustics {
            Some(c) => {
                let sin_refracted = (horizontal / WATER_INDEX).min(1.0);
                let run = grid as f32 * c.depth_px() * sin_refracted / (1.0 - sin_refracted * sin_refracted).sqrt();
                ((-sun[0] / horizontal * run).round() as i32, (-sun[1] / horizontal * run).round() as i32)
            }
            None => (0, 0),
        };
        let half = normalize([sun[0], sun[1], sun[2] + 1.0]);
        let glint_from = (half[2] + GLINT_MARGIN).max(GLINT_LOBE_START);
        // Normals (nx, ny, 1) within angle acos(glint_from) of H lie, in the plane z = 1, inside
        // a conic around H's trace tan(θH)·(hx, hy)/|h|; its farthest point is at
        // tan(θH + θg) - tan(θH) from that centre, so a disc of that radius (plus a margin)
        // holds all of them.
        let span = STENCIL_SPAN * AMPLITUDE_PER_PIXEL * units;
        let theta_h = half[2].clamp(-1.0, 1.0).acos();
        let theta_g = glint_from.clamp(-1.0, 1.0).acos();
        let reach = ((theta_h + theta_g).min(1.5).tan() - theta_h.tan()) * 1.1 + 0.01;
        let lighting = Lighting {
            shade_x_q8: (sun[0] * SHADE_PER_SLOPE / units * 256.0).round() as i32,
            shade_y_q8: (sun[1] * SHADE_PER_SLOPE / units * 256.0).round() as i32,
            glint_scale: 1.0 / span,
            // The normal's (nx, ny) is (across, along) / span, and points along (hx, hy)/hz.
            glint_centre: [half[0] / half[2] * span, half[1] / half[2] * span],
            glint_radius_sq: (reach * span) * (reach * span),
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
            simd: Simd::detect(),
            grid,
            units,
            scratch: Vec::new(),
        }
    }

    #[cfg(any(test, feature = "testing"))]
    /// Draws with another instruction set this CPU runs (every one gives the same picture).
    pub fn set_simd(&mut self, simd: Simd) {
        self.simd = simd;
    }

    /// The look this renderer was made with.
    pub fn look(&self) -> PoolLook {
        self.look
    }

    /// Draws `pool` into `out` ([`PoolRenderer::render_fields`] of its heights).
    #[cfg(test)]
    pub fn render(&mut self, pool: &RipplePool, out: &mut Pixmap) {
        let (w, h) = (self.background.width() as usize, self.background.height() as usize);
        assert_eq!((pool.width(), pool.height()), (w, h), "pool and background sizes differ");
        self.render_fields(Fields { refraction: pool.heights(), light: pool.heights() }, out);
    }

    /// Draws the water into `out`, which has the picture's size (the background's over the
    /// grid): the floor displaced by one set of heights and lit (caustics, shading, glints) by
    /// another, each a pool of the background's size row by row (for a pool's own picture both
    /// are its heights; the scene adds the gusts' swells to them), each picture pixel the mean
    /// of its `grid x grid` cells' ([`crate::render::supersample`]'s box filter). Large
    /// pictures are drawn in row bands on all cores; every pixel is computed the same way
    /// whatever the split.
    ///
    /// # Panics
    /// When the sizes differ (a programming error, not a user error).
    pub fn render_fields(&mut self, fields: Fields<'_>, out: &mut Pixmap) {
        let (w, h) = (self.background.width() as usize, self.background.height() as usize);
        let grid = self.grid as usize;
        assert_eq!(fields.refraction.len(), w * h, "heights and background sizes differ");
        assert_eq!(fields.light.len(), w * h, "heights and background sizes differ");
        assert_eq!((out.width() as usize * grid, out.height() as usize * grid), (w, h), "output size differs");
        if let Some(look) = self.look.caustics {
            self.light.compute_on_grid(fields.light, (w, h), grid, (look, self.units), self.simd);
        }
        let picture_rows = h / grid;
        let rows_per_task =
            if w * h < PARALLEL_MIN_PIXELS { picture_rows } else { (PIXELS_PER_TASK / (w * grid)).max(1) };
        let tasks = picture_rows.div_ceil(rows_per_task.max(1));
        let mut scratch = std::mem::take(&mut self.scratch);
        scratch.resize_with(tasks, RowScratch::default);
        let this = &*self;
        let chunk = rows_per_task.max(1) * (w / grid) * 4;
        let run = |(task, (rows, scratch)): (usize, (&mut [u8], &mut RowScratch))| {
            this.render_rows(fields, task * rows_per_task, rows, scratch)
        };
        if tasks > 1 {
            use rayon::prelude::*;
            out.data_mut().par_chunks_mut(chunk).zip(scratch.par_iter_mut()).enumerate().for_each(run);
        } else {
            out.data_mut().chunks_mut(chunk).zip(scratch.iter_mut()).enumerate().for_each(run);
        }
        self.scratch = scratch;
    }

    /// One output pixel: `rows` are the height rows y-2..=y+2, `near` the columns x-2, x-1,
    /// x+1, x+2 (clamped at the edges).
    #[inline(always)]
    fn pixel(&self, rows: &Rows<'_>, x: usize, y: usize, near: [usize; 4]) -> u32 {
        let (w, h) = (self.background.width() as i32, self.background.height() as i32);
        let [l2, l1, r1, r2] = near;
        let q = self.refraction_q8;
        // The papers' offsets: left minus right, up minus down.
        let [_, up, mid, down, _] = rows.refraction;
        let xoff = i32::from(mid[l1]) - i32::from(mid[r1]);
        let yoff = i32::from(up[x]) - i32::from(down[x]);
        let [up2, up, mid, down, down2] = rows.light;
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
        self.diffuse(across, along) + self.glint(across, along)
    }

    /// Flanks facing the sun brighter, the others darker (colour steps).
    #[inline(always)]
    fn diffuse(&self, across: i32, along: i32) -> i32 {
        let light = &self.lighting;
        ((across * light.shade_x_q8 + along * light.shade_y_q8) >> 8).clamp(-SHADE_LIMIT, SHADE_LIMIT)
    }

    /// The sun mirrored by a crest (colour steps); flat water never glints.
    #[inline(always)]
    fn glint(&self, across: i32, along: i32) -> i32 {
        if !self.may_glint(across, along) {
            return 0;
        }
        self.glint_exact(across, along)
    }

    /// Whether a slope lies in the disc that holds every glinting slope (a cheap pre-test).
    #[inline(always)]
    fn may_glint(&self, across: i32, along: i32) -> bool {
        let light = &self.lighting;
        let dx = across as f32 - light.glint_centre[0];
        let dy = along as f32 - light.glint_centre[1];
        dx * dx + dy * dy < light.glint_radius_sq
    }

    /// The glint of a candidate pixel (see [`PoolRenderer::glint`]).
    #[inline(never)]
    fn glint_exact(&self, across: i32, along: i32) -> i32 {
        let light = &self.lighting;
        // The normal is (-dh/dx, -dh/dy, 1) in pixels; the stencils are -6x the gradient in
        // amplitude units.
        let scale = light.glint_scale;
        let (nx, ny) = (across as f32 * scale, along as f32 * scale);
        let n_dot_h = (nx * light.half[0] + ny * light.half[1] + light.half[2]) / (nx * nx + ny * ny + 1.0).sqrt();
        if n_dot_h <= light.glint_from {
            return 0;
        }
        // A compact lobe: 0 at `glint_from`, 1 when the crest mirrors the sun exactly.
        let t = (n_dot_h - light.glint_from) / (1.0 - light.glint_from);
        let t2 = t * t;
        (t2 * t2 * GLINT_LEVELS) as i32
    }

    /// Texel `i` (row-major, the extra row and pixel included) as a packed word.
    #[inline(always)]
    fn texel(&self, i: usize) -> u32 {
        self.texels[i]
    }

    /// The background at an 8.8 fixed-point position inside the picture, bilinearly filtered.
    #[inline(always)]
    fn sample(&self, sx: i32, sy: i32) -> u32 {
        let (w, h) = (self.background.width() as usize, self.background.height() as usize);
        let (x0, y0) = ((sx >> 8) as usize, (sy >> 8) as usize);
        let (fx, fy) = ((sx & 255) as u32, (sy & 255) as u32);
        let at = |x: usize, y: usize| self.texel(y * w + x);
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
    light_pixel_always(pixel, gain, delta)
}

/// [`light_pixel`] without the shortcut (the same result), on whole words so that loops of it
/// vectorize.
#[inline(always)]
fn light_pixel_always(pixel: u32, gain: u8, delta: i32) -> u32 {
    let gain = i32::from(gain);
    let light = |shift: u32| (((((pixel >> shift) & 255) as i32 * gain) >> 6) + delta).clamp(0, 255) as u32;
    // The colour channels sit in the low three bytes of the native-endian word on little-endian
    // machines, the high three on big-endian ones; alpha in the remaining byte.
    if cfg!(target_endian = "little") {
        light(0) | (light(8) << 8) | (light(16) << 16) | (pixel & 0xFF00_0000)
    } else {
        (light(24) << 24) | (light(16) << 16) | (light(8) << 8) | (pixel & 0xFF)
    }
}

#[cfg(test)]
mod tests;
