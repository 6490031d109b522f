//! The pool renderer: the floor seen through the rippled surface, lit by the sun.
//!
//! Refraction follows the papers: output pixel (x, y) shows the floor at
//! `(x + xoff·F, y + yoff·F)` with `xoff = h[x-1] - h[x+1]` and `yoff = h[y-1] - h[y+1]`,
//! clamped to the picture. F = 1 is the papers' factor; it is right for the papers' 640x480
//! window, but the amplitudes do not shrink with the picture, so at terminal size the same
//! offsets scramble the floor. [`Refraction::AUTO`] therefore scales F with the picture's
//! smaller side (see [`Refraction::factor`]). Fractional offsets are filtered bilinearly.
//!
//! Light, beyond the papers: the floor is lit by caustics ([`super::caustics`]), shifted away
//! from the sun by the slant of the refracted sunlight; ripple flanks facing the sun are
//! brightened and the others darkened; crests tilted towards the sun glint.
//!
//! Displacement and filtering are integer arithmetic in 8.8 fixed point; the light is `f32`.
//! Either way the picture is the same on every run.

use std::str::FromStr;

use tiny_skia::Pixmap;

use super::caustics::{self, AMPLITUDE_PER_PIXEL, CausticsLook, WATER_INDEX};
use crate::error::ValueError;
use crate::sim::ripple::RipplePool;
use crate::simd::Simd;

/// How strongly the surface slope displaces the background: a fixed factor (1.0 is the papers'
/// displacement, 0 shows the floor undistorted) or [`Refraction::AUTO`], which scales with the
/// picture. Fixed factors are finite and within [`Refraction::MAX_FACTOR`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refraction {
    /// The fixed factor, or `None` for automatic.
    fixed: Option<f32>,
}

impl Refraction {
    /// Scale with the picture: `min(width, height) / 720`, between 0.15 and 1.
    pub const AUTO: Refraction = Refraction { fixed: None };
    /// The side (in pixels) at which `AUTO` gives the papers' factor of 1.
    pub const AUTO_REFERENCE_SIDE: f32 = 720.0;
    /// The largest fixed factor.
    pub const MAX_FACTOR: f32 = 100.0;

    /// A fixed factor, `0..=`[`Refraction::MAX_FACTOR`].
    pub fn fixed(factor: f32) -> Result<Refraction, ValueError> {
        Self::checked(factor, &factor.to_string())
    }

    fn checked(factor: f32, shown: &str) -> Result<Refraction, ValueError> {
        if !factor.is_finite() || !(0.0..=Self::MAX_FACTOR).contains(&factor) {
            return Err(ValueError::new(
                "refraction",
                format!("'{shown}' must be between 0 and 100 (1.0 is the papers' factor), or 'auto'"),
            ));
        }
        Ok(Refraction { fixed: Some(factor) })
    }

    /// The fixed factor, or `None` for automatic.
    pub fn fixed_factor(self) -> Option<f32> {
        self.fixed
    }

    /// The factor used for a `width x height` picture.
    pub fn factor(self, width: u32, height: u32) -> f32 {
        match self.fixed {
            Some(f) => f,
            None => (width.min(height) as f32 / Self::AUTO_REFERENCE_SIDE).clamp(0.15, 1.0),
        }
    }
}

impl std::fmt::Display for Refraction {
    /// `auto` or the factor: the form [`Refraction::from_str`] reads back.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.fixed {
            None => f.write_str("auto"),
            Some(v) => write!(f, "{v}"),
        }
    }
}

impl FromStr for Refraction {
    type Err = ValueError;

    /// Parses a factor (finite, `0..=100`) or `auto`.
    fn from_str(text: &str) -> Result<Refraction, ValueError> {
        let text = text.trim();
        if text.eq_ignore_ascii_case("auto") {
            return Ok(Refraction::AUTO);
        }
        let v: f32 = text
            .parse()
            .map_err(|_| ValueError::new("refraction", format!("'{text}' is neither a number nor 'auto'")))?;
        Self::checked(v, text)
    }
}

/// Where the sun is: azimuth clockwise from north (the top of the picture), elevation above
/// the horizon, both in degrees. The azimuth is kept in `0..360`, the elevation in `0..=90`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sun {
    azimuth_deg: f32,
    elevation_deg: f32,
}

impl Default for Sun {
    /// High in the north-west: light from the upper left, as pictures are usually lit.
    fn default() -> Self {
        Sun { azimuth_deg: 315.0, elevation_deg: 60.0 }
    }
}

impl Sun {
    /// A sun at any finite azimuth (wrapped to `0..360`) and an elevation in `0..=90` degrees.
    pub fn new(azimuth_deg: f32, elevation_deg: f32) -> Result<Sun, ValueError> {
        let hint = SUN_HINT;
        if !azimuth_deg.is_finite() {
            return Err(ValueError::new("sun", format!("the azimuth must be finite; {hint}")));
        }
        if !elevation_deg.is_finite() {
            return Err(ValueError::new("sun", format!("the elevation must be finite; {hint}")));
        }
        if !(0.0..=90.0).contains(&elevation_deg) {
            return Err(ValueError::new(
                "sun",
                format!("the elevation {elevation_deg} is outside 0..=90 degrees; {hint}"),
            ));
        }
        Ok(Sun { azimuth_deg: azimuth_deg.rem_euclid(360.0), elevation_deg })
    }

    /// Degrees clockwise from north (0 = top of the picture, 90 = right).
    pub fn azimuth_deg(self) -> f32 {
        self.azimuth_deg
    }

    /// Degrees above the horizon.
    pub fn elevation_deg(self) -> f32 {
        self.elevation_deg
    }

    /// The unit vector towards the sun in picture coordinates (x right, y down, z up).
    pub fn direction(self) -> [f32; 3] {
        let (az, el) = (self.azimuth_deg.to_radians(), self.elevation_deg.to_radians());
        [az.sin() * el.cos(), -az.cos() * el.cos(), el.sin()]
    }
}

const SUN_HINT: &str = "write it as AZIMUTH,ELEVATION in degrees, e.g. 315,60";

impl std::fmt::Display for Sun {
    /// `AZIMUTH,ELEVATION`: the form [`Sun::from_str`] reads back.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{},{}", self.azimuth_deg, self.elevation_deg)
    }
}

impl FromStr for Sun {
    type Err = ValueError;

    /// Parses `AZIMUTH,ELEVATION` in degrees.
    fn from_str(text: &str) -> Result<Sun, ValueError> {
        let hint = SUN_HINT;
        let (az, el) =
            text.split_once(',').ok_or_else(|| ValueError::new("sun", format!("expected two numbers; {hint}")))?;
        let number = |s: &str, name: &str| -> Result<f32, ValueError> {
            s.trim()
                .parse()
                .map_err(|_| ValueError::new("sun", format!("the {name} '{}' is not a number; {hint}", s.trim())))
        };
        let azimuth = number(az, "azimuth")?;
        if !azimuth.is_finite() {
            return Err(ValueError::new("sun", format!("the azimuth must be finite; {hint}")));
        }
        Sun::new(azimuth, number(el, "elevation")?)
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
            refraction: Refraction::AUTO,
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
    /// The background's pixels as packed RGBA words, for two-channels-at-a-time filtering,
    /// followed by a copy of the last row and one more texel.
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
    /// A disc in (across, along) stencil units that holds every slope which can glint: the
    /// slope that mirrors the sun exactly is its centre. Pixels outside skip the exact test.
    glint_centre: [f32; 2],
    glint_radius_sq: f32,
    /// The half-way vector between the sun and the viewer (looking straight down).
    half: [f32; 3],
    /// N·H above which a crest glints: a little above flat water's, so that flat water
    /// (which an overhead view would show uniformly lit by the sun) never does.
    glint_from: f32,
}

/// Pixels per staged span (see [`PoolRenderer::render_span`]).
const SPAN: usize = 64;

/// The per-pixel values a span passes between its stages; kept for a whole band of rows.
struct SpanScratch {
    index: [u32; SPAN],
    fx: [u32; SPAN],
    fy: [u32; SPAN],
    light_index: [u32; SPAN],
    delta: [i32; SPAN],
    across: [i32; SPAN],
    along: [i32; SPAN],
    p00: [u32; SPAN],
    p01: [u32; SPAN],
    p10: [u32; SPAN],
    p11: [u32; SPAN],
    gain: [u8; SPAN],
}

impl Default for SpanScratch {
    fn default() -> Self {
        SpanScratch {
            index: [0; SPAN],
            fx: [0; SPAN],
            fy: [0; SPAN],
            light_index: [0; SPAN],
            delta: [0; SPAN],
            across: [0; SPAN],
            along: [0; SPAN],
            p00: [0; SPAN],
            p01: [0; SPAN],
            p10: [0; SPAN],
            p11: [0; SPAN],
            gain: [caustics::UNIT_GAIN; SPAN],
        }
    }
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
        // One extra row and texel past the end, so the filter's right and lower neighbours can be
        // fetched without a check at the last column and row (their weight is 0 there).
        let (w, h) = (background.width() as usize, background.height() as usize);
        let mut texels: Vec<u32> =
            background.data().chunks_exact(4).map(|p| u32::from_ne_bytes([p[0], p[1], p[2], p[3]])).collect();
        texels.extend_from_within((h - 1) * w..h * w);
        texels.push(texels[texels.len() - 1]);
        let sun = look.sun.direction();
        let horizontal = (sun[0] * sun[0] + sun[1] * sun[1]).sqrt().max(1e-6);
        // Sunlight enters the water at (90° - elevation) from the vertical and is bent
        // towards the vertical; it travels away from the sun, so a cell's light lands
        // downstream by depth · tan(refracted angle).
        let light_shift = match look.caustics {
            Some(c) => {
                let sin_refracted = (horizontal / WATER_INDEX).min(1.0);
                let run = c.depth_px() * sin_refracted / (1.0 - sin_refracted * sin_refracted).sqrt();
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
        let span = STENCIL_SPAN * AMPLITUDE_PER_PIXEL;
        let theta_h = half[2].clamp(-1.0, 1.0).acos();
        let theta_g = glint_from.clamp(-1.0, 1.0).acos();
        let reach = ((theta_h + theta_g).min(1.5).tan() - theta_h.tan()) * 1.1 + 0.01;
        let lighting = Lighting {
            shade_x_q8: (sun[0] * SHADE_PER_SLOPE * 256.0).round() as i32,
            shade_y_q8: (sun[1] * SHADE_PER_SLOPE * 256.0).round() as i32,
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
        }
    }

    /// The look this renderer was made with.
    pub fn look(&self) -> PoolLook {
        self.look
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

    /// Draws the rows starting at `first_row` into `out` (whole rows of RGBA bytes), with the
    /// widest instruction set this CPU has (see [`crate::simd`]).
    fn render_rows(&self, heights: &[i16], first_row: usize, out: &mut [u8]) {
        match Simd::detect() {
            // SAFETY: the variants are only returned after run-time detection of the feature.
            #[cfg(target_arch = "x86_64")]
            Simd::Avx512 => unsafe { self.render_rows_avx512(heights, first_row, out) },
            #[cfg(target_arch = "x86_64")]
            Simd::Avx2 => unsafe { self.render_rows_avx2(heights, first_row, out) },
            _ => self.render_rows_with(heights, first_row, out),
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn render_rows_avx2(&self, heights: &[i16], first_row: usize, out: &mut [u8]) {
        self.render_rows_with(heights, first_row, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512bw")]
    fn render_rows_avx512(&self, heights: &[i16], first_row: usize, out: &mut [u8]) {
        self.render_rows_with(heights, first_row, out)
    }

    #[inline(always)]
    fn render_rows_with(&self, heights: &[i16], first_row: usize, out: &mut [u8]) {
        let (w, h) = (self.background.width() as usize, self.background.height() as usize);
        let mut scratch = SpanScratch::default();
        for (i, out_row) in out.chunks_exact_mut(w * 4).enumerate() {
            let y = first_row + i;
            // Rows y-2..=y+2, the picture's edge rows repeated beyond it.
            let row = |dy: isize| {
                let r = (y as isize + dy).clamp(0, h as isize - 1) as usize;
                &heights[r * w..(r + 1) * w]
            };
            let rows = [row(-2), row(-1), row(0), row(1), row(2)];
            let pixels: &mut [[u8; 4]] = out_row.as_chunks_mut::<4>().0;
            // Columns two or more away from the edges need no clamping: they go through the
            // staged span renderer in chunks; the edge columns one pixel at a time.
            let inner = 2..w.saturating_sub(2).max(2);
            for x in (0..w).filter(|x| !inner.contains(x)) {
                let near = [x.saturating_sub(2), x.saturating_sub(1), (x + 1).min(w - 1), (x + 2).min(w - 1)];
                pixels[x] = self.pixel(&rows, x, y, near).to_ne_bytes();
            }
            let mut start = inner.start;
            while start < inner.end {
                let end = (start + SPAN).min(inner.end);
                self.render_span(&rows, y, start, &mut pixels[start..end], &mut scratch);
                start = end;
            }
        }
    }

    /// Interior pixels `x0..x0 + out.len()` of row `y` (all at least two columns from the
    /// edges), in stages: positions and light in one loop, the texture fetches in a second,
    /// filtering and lighting in a third. The first and last are free of branches and
    /// clamped indexing, so the compiler vectorizes them; only the fetches stay scalar.
    /// Computes exactly what [`PoolRenderer::pixel`] does.
    #[inline(always)]
    fn render_span(&self, rows: &[&[i16]; 5], y: usize, x0: usize, out: &mut [[u8; 4]], scratch: &mut SpanScratch) {
        let (w, h) = (self.background.width() as i32, self.background.height() as i32);
        let n = out.len();
        let [up2, up, mid, down, down2] = rows.map(|r| &r[x0 - 2..x0 + n + 2]);
        let q = self.refraction_q8;
        let SpanScratch { index, fx, fy, light_index, delta, across, along, p00, p01, p10, p11, gain } = scratch;
        // Every slice exactly `n` long, so the loops below carry no bounds checks.
        let (index, fx, fy) = (&mut index[..n], &mut fx[..n], &mut fy[..n]);
        let (light_index, delta, across, along) =
            (&mut light_index[..n], &mut delta[..n], &mut across[..n], &mut along[..n]);
        let (p00, p01, p10, p11, gain) = (&mut p00[..n], &mut p01[..n], &mut p10[..n], &mut p11[..n], &mut gain[..n]);
        let (m2, m1, p1, p2) = (&mid[..n], &mid[1..n + 1], &mid[3..n + 3], &mid[4..n + 4]);
        let (u2, u1, d1, d2) = (&up2[2..n + 2], &up[2..n + 2], &down[2..n + 2], &down2[2..n + 2]);
        let (lw, lshift) = (self.light.width as i32, self.light.shift);
        let (shift_x, shift_y) = self.light_shift;
        let lighting = self.lighting;
        for i in 0..n {
            let x = (x0 + i) as i32;
            let xoff = i32::from(m1[i]) - i32::from(p1[i]);
            let yoff = i32::from(u1[i]) - i32::from(d1[i]);
            let sx = ((x << 8) + xoff * q).clamp(0, (w - 1) << 8);
            let sy = (((y as i32) << 8) + yoff * q).clamp(0, (h - 1) << 8);
            let (tx, ty) = (sx >> 8, sy >> 8);
            index[i] = (ty * w + tx) as u32;
            fx[i] = (sx & 255) as u32;
            fy[i] = (sy & 255) as u32;
            let lx = (tx - shift_x).clamp(0, w - 1) >> lshift;
            let ly = (ty - shift_y).clamp(0, h - 1) >> lshift;
            light_index[i] = (ly * lw + lx) as u32;
            across[i] = i32::from(m2[i]) + i32::from(m1[i]) - i32::from(p1[i]) - i32::from(p2[i]);
            along[i] = i32::from(u2[i]) + i32::from(u1[i]) - i32::from(d1[i]) - i32::from(d2[i]);
            delta[i] = ((across[i] * lighting.shade_x_q8 + along[i] * lighting.shade_y_q8) >> 8)
                .clamp(-SHADE_LIMIT, SHADE_LIMIT);
        }
        if !self.look.shading {
            delta.fill(0);
        } else {
            // The pre-test in a loop that vectorizes; the exact glint (rare) out of line.
            let mut candidates = [false; SPAN];
            let mut any = false;
            for i in 0..n {
                candidates[i] = self.may_glint(across[i], along[i]);
                any |= candidates[i];
            }
            if any {
                for i in 0..n {
                    if candidates[i] {
                        delta[i] += self.glint_exact(across[i], along[i]);
                    }
                }
            }
        }
        if self.look.caustics.is_some() {
            for i in 0..n {
                gain[i] = self.light.gains[light_index[i] as usize];
            }
        } else {
            gain.fill(caustics::UNIT_GAIN);
        }
        let stride = w as usize;
        // Indices are in range by construction; the `min` lets the compiler see it too.
        let last = self.texels.len() - stride - 2;
        if self.refraction_q8 & 255 == 0 {
            // A whole-number factor moves by whole pixels: no filtering, one fetch.
            for i in 0..n {
                p00[i] = self.texels[(index[i] as usize).min(last)];
            }
            for (i, out) in out.iter_mut().enumerate() {
                *out = light_pixel_always(p00[i], gain[i], delta[i]).to_ne_bytes();
            }
            return;
        }
        for i in 0..n {
            let at = (index[i] as usize).min(last);
            (p00[i], p01[i]) = (self.texels[at], self.texels[at + 1]);
            (p10[i], p11[i]) = (self.texels[at + stride], self.texels[at + stride + 1]);
        }
        for (i, out) in out.iter_mut().enumerate() {
            let top = lerp_packed(p00[i], p01[i], fx[i]);
            let bottom = lerp_packed(p10[i], p11[i], fx[i]);
            let colour = lerp_packed(top, bottom, fy[i]);
            *out = light_pixel_always(colour, gain[i], delta[i]).to_ne_bytes();
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
        let scale = 1.0 / (STENCIL_SPAN * AMPLITUDE_PER_PIXEL);
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
        let look = PoolLook {
            refraction: Refraction::fixed(1.0).unwrap(),
            shading: false,
            caustics: None,
            ..PoolLook::default()
        };
        let mut renderer = PoolRenderer::new(bg, look);
        let mut pool = RipplePool::new(30, 30, Damping::OFF);
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
        let look = PoolLook {
            refraction: Refraction::fixed(10.0).unwrap(),
            shading: false,
            caustics: None,
            ..PoolLook::default()
        };
        let mut renderer = PoolRenderer::new(bg, look);
        let mut pool = RipplePool::new(8, 8, Damping::OFF);
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
            PoolLook { sun: Sun::new(270.0, 45.0).unwrap(), ..PoolLook::default() },
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
    fn the_glint_pre_test_never_misses_a_glint() {
        for (az, el) in [(315.0, 60.0), (90.0, 20.0), (0.0, 85.0), (200.0, 45.0), (10.0, 5.0)] {
            let look = PoolLook { sun: Sun::new(az, el).unwrap(), ..PoolLook::default() };
            let renderer = PoolRenderer::new(striped_background(4, 4), look);
            let (mut glints, mut candidates) = (0, 0);
            for across in (-3000..=3000).step_by(7) {
                for along in (-3000..=3000).step_by(7) {
                    let may = renderer.may_glint(across, along);
                    candidates += usize::from(may);
                    if renderer.glint_exact(across, along) > 0 {
                        glints += 1;
                        assert!(may, "sun {az},{el}: slope ({across}, {along}) glints but was skipped");
                    }
                }
            }
            assert!(candidates < 4 * glints + 50, "sun {az},{el}: {candidates} candidates for {glints} glints");
        }
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
        let look = PoolLook { sun: Sun::new(90.0, 45.0).unwrap(), ..PoolLook::default() };
        let renderer = PoolRenderer::new(striped_background(4, 4), look);
        // Sun in the east: light travels west (negative x), by depth · tan(asin(cos 45° / 1.33))
        // = 24 · 0.628 ≈ 15 pixels.
        assert_eq!(renderer.light_shift, (-15, 0));
        let overhead = PoolLook { sun: Sun { azimuth_deg: 0.0, elevation_deg: 90.0 }, ..PoolLook::default() };
        assert_eq!(PoolRenderer::new(striped_background(4, 4), overhead).light_shift, (0, 0));
    }

    #[test]
    fn staged_spans_compute_exactly_what_single_pixels_do() {
        let (w, h) = (150u32, 90u32);
        for look in [
            PoolLook::default(),
            PoolLook {
                refraction: Refraction::fixed(1.0).unwrap(),
                sun: Sun { azimuth_deg: 100.0, elevation_deg: 30.0 },
                ..PoolLook::default()
            },
            PoolLook { caustics: None, shading: false, ..PoolLook::default() },
        ] {
            let mut renderer = PoolRenderer::new(striped_background(w, h), look);
            let mut pool = RipplePool::new(w as usize, h as usize, Damping::PAPERS);
            for k in 0..30 {
                pool.drop_stone(Stone { x: (k * 37 % w) as i32, y: (k * 23 % h) as i32, radius: 3, weight: 400 });
                pool.advance(2);
            }
            let mut out = Pixmap::new(w, h).unwrap();
            renderer.render(&pool, &mut out);
            let heights = pool.heights();
            let (wu, hu) = (w as usize, h as usize);
            for y in 0..hu {
                let row = |dy: isize| {
                    let r = (y as isize + dy).clamp(0, hu as isize - 1) as usize;
                    &heights[r * wu..(r + 1) * wu]
                };
                let rows = [row(-2), row(-1), row(0), row(1), row(2)];
                for x in 0..wu {
                    let near = [x.saturating_sub(2), x.saturating_sub(1), (x + 1).min(wu - 1), (x + 2).min(wu - 1)];
                    let expected = renderer.pixel(&rows, x, y, near).to_ne_bytes();
                    let got = &out.data()[(y * wu + x) * 4..(y * wu + x) * 4 + 4];
                    assert_eq!(got, expected, "({x}, {y}) with {look:?}");
                }
            }
        }
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
        assert_eq!(Refraction::AUTO.factor(1920, 1080), 1.0);
        assert!((Refraction::AUTO.factor(640, 360) - 0.5).abs() < 1e-6);
        assert_eq!(Refraction::AUTO.factor(160, 94), 0.15);
        assert_eq!(Refraction::fixed(2.5).unwrap().factor(10, 10), 2.5);
    }
}
