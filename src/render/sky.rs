//! The sky: a gradient from a pale horizon to a deep zenith, a sun with its glow, and the
//! environment lookup water reflects.
//!
//! [`Environment`] is the one thing the water shading needs from the world above it: the
//! light arriving from a direction. [`Sky`] is the ocean's environment; the lake can wrap it
//! with its shore (return the shore's colour for directions that hit the shore, the sky's
//! otherwise) and hand that to the same [`crate::render::mesh::MeshRenderer`].
//!
//! Drawing the sky per pixel would cost more than the sea at 4K, so [`Sky::draw`] evaluates it
//! on a grid every [`sky_grid_px`] pixels, interpolates bilinearly and tone-maps through a
//! table; only the sun's disc and its tight glow are evaluated per pixel.

use tiny_skia::{Pixmap, PremultipliedColorU8};

use super::camera::Camera;
use super::light::{Light, Rgb, mix, to_srgb8};
use super::vec3::{Vec3, dot};

/// Spacing of the sky's evaluation grid, px: a 135th of the picture height, within 4..=16
/// (16 px at 4K, where the sky's smallest feature, the sun's wide glow, spans hundreds).
pub fn sky_grid_px(height: u32) -> usize {
    (height as usize / 135).clamp(4, 16)
}
/// The sun's apparent radius as drawn, degrees (about twice the real one, so it shows at
/// terminal sizes).
pub const SUN_RADIUS_DEG: f32 = 0.5;

/// Buffers the sky's drawing reuses, one set per thread: a steady stream of frames allocates
/// nothing.
#[derive(Default)]
struct SkyScratch {
    grid: Vec<Rgb>,
    row_levels: Vec<[u32; 3]>,
    weights: Vec<u32>,
}

thread_local! {
    static SKY_SCRATCH: std::cell::RefCell<SkyScratch> = std::cell::RefCell::new(SkyScratch::default());
}

/// The light arriving from a direction: what water reflects.
pub trait Environment: Sync {
    /// Linear radiance arriving along the unit direction `dir` (pointing away from the
    /// viewer, towards the sky). Directions below the horizon may be asked for.
    fn radiance(&self, dir: Vec3) -> Rgb;
}

/// A clear sky with one sun.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sky {
    sun_dir: Vec3,
    sun: Rgb,
    zenith: Rgb,
    horizon: Rgb,
    warm: Rgb,
    warmth: f32,
    cos_disc: f32,
}

impl Sky {
    /// The sky with the sun at `azimuth_deg` (clockwise from north) and `elevation_deg`
    /// above the horizon. A low sun warms the light and the horizon around it.
    pub fn new(azimuth_deg: f32, elevation_deg: f32) -> Sky {
        let (az, el) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
        let sun_dir = [az.sin() * el.cos(), az.cos() * el.cos(), el.sin()];
        let low = (1.0 - elevation_deg / 30.0).clamp(0.0, 1.0);
        Sky {
            sun_dir,
            sun: mix([1.0, 0.94, 0.84], [1.0, 0.66, 0.40], low * low),
            zenith: [0.05, 0.17, 0.48],
            horizon: [0.50, 0.63, 0.80],
            warm: [0.95, 0.66, 0.45],
            warmth: low,
            cos_disc: SUN_RADIUS_DEG.to_radians().cos(),
        }
    }

    #[cfg(test)]
    /// The unit direction towards the sun.
    pub fn sun_direction(&self) -> Vec3 {
        self.sun_dir
    }

    /// Per row: the grid colours at this height, tone-mapped, then integer interpolation along
    /// the row (the sky changes slowly; this keeps a 4K sky to a few milliseconds).
    #[allow(clippy::too_many_arguments)] // the pieces of one drawing pass
    fn fill_rows(
        &self,
        pixels: &mut [PremultipliedColorU8],
        w: usize,
        sky_rows: usize,
        g: usize,
        gw: usize,
        lut: &ToneTable,
        grid: &[Rgb],
        row_levels: &mut [[u32; 3]],
        weights: &[u32],
    ) {
        let inv = 1.0 / g as f32;
        for y in 0..sky_rows {
            let (gy, ty) = (y / g, (y % g) as f32 * inv);
            for (gx, level) in row_levels.iter_mut().enumerate() {
                let c = mix(grid[gy * gw + gx], grid[(gy + 1) * gw + gx], ty);
                *level = [0, 1, 2].map(|i| u32::from(lut.level(c[i])));
            }
            let row = &mut pixels[y * w..(y + 1) * w];
            for (block, pair) in row.chunks_mut(g).zip(row_levels.windows(2)) {
                let (a, b) = (pair[0], pair[1]);
                for (p, &wb) in block.iter_mut().zip(weights) {
                    let lerp = |i: usize| ((a[i] * (65536 - wb) + b[i] * wb + 32768) >> 16) as u8;
                    *p = pixel([lerp(0), lerp(1), lerp(2)]);
                }
            }
        }
    }

    /// The light the water gets: the sun and the sky's average.
    pub fn light(&self) -> Light {
        Light { sun_dir: self.sun_dir, sun: self.sun, sky: mix(self.horizon, self.zenith, 0.4) }
    }

    /// The sky without the sun's disc and tight glow (smooth enough to interpolate).
    fn smooth(&self, dir: Vec3) -> Rgb {
        let e = dir[2].max(0.0);
        let mut base = mix(self.horizon, self.zenith, e.sqrt().min(1.0));
        let c = dot(dir, self.sun_dir);
        if self.warmth > 0.0 {
            let flat = (dir[0] * dir[0] + dir[1] * dir[1]).sqrt().max(1e-6);
            let sflat = (self.sun_dir[0] * self.sun_dir[0] + self.sun_dir[1] * self.sun_dir[1]).sqrt().max(1e-6);
            let toward = ((dir[0] * self.sun_dir[0] + dir[1] * self.sun_dir[1]) / (flat * sflat) + 1.0) / 2.0;
            base = mix(base, self.warm, self.warmth * toward * toward * (-e * 5.0).exp() * 0.8);
        }
        let glow = 0.35 * ((c - 1.0) * 10.0).exp();
        [base[0] + glow * self.sun[0], base[1] + glow * self.sun[1], base[2] + glow * self.sun[2]]
    }

    /// The sun's disc and tight glow alone.
    fn sun_term(&self, dir: Vec3) -> f32 {
        let c = dot(dir, self.sun_dir);
        let disc = if c >= self.cos_disc { 40.0 } else { 0.0 };
        disc + 1.2 * ((c - 1.0) * 900.0).exp()
    }

    /// Paints the sky above the horizon of `camera` into `out` (which has the camera's size),
    /// and `below` under it (what shows between the farthest sea sample and the horizon).
    pub fn draw(&self, camera: &Camera, below: Rgb, out: &mut Pixmap) {
        let (w, h) = (out.width() as usize, out.height() as usize);
        let sky_rows = (camera.horizon_y().floor() + 1.0).clamp(0.0, h as f32) as usize;
        let below_px = pixel(to_srgb8(below));
        let lut = ToneTable::shared();
        let pixels = out.pixels_mut();
        pixels[sky_rows * w..].fill(below_px);
        if sky_rows == 0 {
            return;
        }
        let g = sky_grid_px(h as u32);
        let (gw, gh) = (w.div_ceil(g) + 1, sky_rows.div_ceil(g) + 1);
        SKY_SCRATCH.with_borrow_mut(|scratch| {
            let SkyScratch { grid, row_levels, weights } = scratch;
            grid.clear();
            for gy in 0..gh {
                for gx in 0..gw {
                    let d = camera.ray((gx * g) as f32 + 0.5, ((gy * g) as f32 + 0.5).min(camera.horizon_y()));
                    grid.push(self.smooth(d));
                }
            }
            row_levels.clear();
            row_levels.resize(gw, [0u32; 3]);
            // 16.16 fixed-point weight of the right-hand grid point at each offset in a cell.
            weights.clear();
            weights.extend((0..g as u32).map(|t| (t << 16) / g as u32));
            self.fill_rows(pixels, w, sky_rows, g, gw, lut, grid, row_levels, weights);
        });
        // The sun, exactly, where its disc and tight glow matter: the glow 1.2·e^(900(cos γ - 1))
        // falls below the 1e-3 the loop skips at γ = 7.2°, so the box reaches 7.5° (at 4° it
        // cut the glow off at 0.13 in a visible square when the sun was in view).
        if let Some((sx, sy, _)) = camera.project(add_eye(camera, self.sun_dir)) {
            let r = (7.5f32.to_radians().tan() * camera.focal_px()).ceil();
            let (x0, x1) = ((sx - r).max(0.0) as usize, ((sx + r).max(0.0) as usize).min(w));
            let (y0, y1) = ((sy - r).max(0.0) as usize, ((sy + r).max(0.0) as usize).min(sky_rows));
            for y in y0..y1 {
                for x in x0..x1 {
                    let d = camera.ray(x as f32 + 0.5, y as f32 + 0.5);
                    let s = self.sun_term(d);
                    if s > 1e-3 {
                        let base = self.smooth(d);
                        pixels[y * w + x] = pixel(to_srgb8([0, 1, 2].map(|i| base[i] + s * self.sun[i])));
                    }
                }
            }
        }
    }
}

fn add_eye(camera: &Camera, dir: Vec3) -> Vec3 {
    let e = camera.eye();
    [e[0] + dir[0] * 1e4, e[1] + dir[1] * 1e4, e[2] + dir[2] * 1e4]
}

impl Environment for Sky {
    fn radiance(&self, dir: Vec3) -> Rgb {
        let s = self.sun_term(dir);
        let base = self.smooth(dir);
        [base[0] + s * self.sun[0], base[1] + s * self.sun[1], base[2] + s * self.sun[2]]
    }
}

/// An opaque pixel of an sRGB colour.
pub fn pixel([r, g, b]: [u8; 3]) -> PremultipliedColorU8 {
    PremultipliedColorU8::from_rgba(r, g, b, 255).expect("opaque pixels are always valid")
}

/// [`to_srgb8`] for values 0..4 through a table (the sky's per-pixel path).
struct ToneTable {
    levels: Vec<u8>,
}

impl ToneTable {
    const STEPS: f32 = 1024.0;
    const MAX: f32 = 4.0;

    fn shared() -> &'static ToneTable {
        static TABLE: std::sync::OnceLock<ToneTable> = std::sync::OnceLock::new();
        TABLE.get_or_init(ToneTable::new)
    }

    fn new() -> ToneTable {
        let n = (Self::STEPS * Self::MAX) as usize + 1;
        ToneTable { levels: (0..n).map(|i| to_srgb8([i as f32 / Self::STEPS, 0.0, 0.0])[0]).collect() }
    }

    #[inline(always)]
    fn level(&self, v: f32) -> u8 {
        let i = (v.clamp(0.0, Self::MAX) * Self::STEPS + 0.5) as usize;
        self.levels[i.min(self.levels.len() - 1)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::camera::CameraPose;

    #[test]
    fn the_zenith_is_deeper_than_the_horizon() {
        let sky = Sky::new(180.0, 40.0);
        let up = sky.radiance([0.0, 0.0, 1.0]);
        let level = sky.radiance([0.0, 1.0, 0.0]);
        assert!(up[2] / up[0] > level[2] / level[0], "more saturated blue overhead");
        assert!(level[1] > up[1]);
        assert_eq!(sky.radiance([0.0, 1.0, -0.5]), sky.radiance([0.0, 1.0, 0.0]).map(|v| v), "below = horizon");
    }

    #[test]
    fn the_sun_is_bright_and_where_it_should_be() {
        let sky = Sky::new(0.0, 5.0);
        let toward = sky.radiance(sky.sun_direction());
        assert!(toward[0] > 10.0);
        let cam = Camera::new(CameraPose { pitch_down_deg: 0.0, ..CameraPose::DEFAULT }, 200, 120);
        let mut out = Pixmap::new(200, 120).unwrap();
        sky.draw(&cam, [0.1, 0.2, 0.3], &mut out);
        // The sun is straight ahead, 5° up: above the centre, on the middle column.
        let sy = (60.0 - cam.focal_px() * 5f32.to_radians().tan()) as usize;
        let p = out.pixels()[sy * 200 + 100];
        assert!(p.red() > 250 && p.green() > 240, "{p:?}");
        let below = out.pixels()[110 * 200 + 3];
        assert_eq!((below.red(), below.alpha()), (to_srgb8([0.1, 0.2, 0.3])[0], 255));
        // A low sun warms the horizon towards it.
        let warm = sky.radiance([0.1, 0.99, 0.0]);
        let away = sky.radiance([-0.1, -0.99, 0.0]);
        assert!(warm[0] / warm[2] > away[0] / away[2]);
    }

    #[test]
    fn interpolated_sky_matches_the_exact_one() {
        let sky = Sky::new(120.0, 30.0);
        let cam = Camera::new(CameraPose::DEFAULT, 97, 61);
        let mut out = Pixmap::new(97, 61).unwrap();
        sky.draw(&cam, [0.0; 3], &mut out);
        for (x, y) in [(0, 0), (50, 7), (96, 12)] {
            let want = to_srgb8(sky.radiance(cam.ray(x as f32 + 0.5, y as f32 + 0.5)));
            let p = out.pixels()[y * 97 + x];
            for (got, want) in [p.red(), p.green(), p.blue()].into_iter().zip(want) {
                assert!(got.abs_diff(want) <= 2, "({x}, {y}): {got} vs {want}");
            }
        }
    }
}
