//! Fair-weather clouds over the lake: a layer of lattice noise at [`CLOUD_BASE_M`], seen in
//! perspective and mirrored by still water (a clear sky reflects as a plain gradient, and a
//! mirror with nothing in it is hard to tell from a flat colour).
//!
//! The layer is the lake's own noise ([`crate::sim::noise::Fractal`]) over the cloud plane,
//! stretched east-west (clouds drift in rows with the wind aloft), thresholded to cover about
//! a third of the sky with soft edges. Each cloud is lit by the sun on top and greyer where it
//! is thick, and fades into the horizon's haze with distance. Like the sky it is evaluated on
//! a grid of [`crate::render::sky::sky_grid_px`] pixels and interpolated: clouds are soft, and
//! the lake draws them once per camera.

use tiny_skia::Pixmap;

use super::camera::Camera;
use super::light::{Rgb, SrgbTable, mix, srgb_decode};
use super::sky::{Environment, Sky, pixel, sky_grid_px};
use super::vec3::normalize;
use crate::sim::noise::{Fractal, NoiseKind};

/// Height of the cloud layer above the lake, m.
pub const CLOUD_BASE_M: f32 = 1_500.0;
/// Lattice spacing of the clouds' coarsest octave, m (east-west; half that north-south).
const CLOUD_SPACING_M: f32 = 2_400.0;
/// Distance over which the clouds fade 63 % into the horizon, m.
const CLOUD_HAZE_M: f32 = 40_000.0;

/// A cloud layer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clouds {
    fractal: Fractal,
    /// Noise level (in its standard deviations) above which there is cloud.
    threshold: f32,
    lit: Rgb,
    shade: Rgb,
    horizon: Rgb,
}

impl Clouds {
    /// Clouds grown from `seed`, lit by `sky`'s sun.
    pub fn new(seed: u64, sky: &Sky) -> Clouds {
        let light = sky.light();
        let lit = std::array::from_fn(|i| 0.62 * light.sun[i] + 0.35 * light.sky[i]);
        let shade = std::array::from_fn(|i| 0.30 * light.sun[i] + 0.42 * light.sky[i]);
        Clouds {
            fractal: Fractal { kind: NoiseKind::Value, seed: seed ^ 0x636c_6f75_6473, octaves: 5, persistence: 0.5 },
            threshold: 0.45,
            lit,
            shade,
            horizon: sky.radiance(normalize([0.0, 1.0, 0.0])),
        }
    }

    /// How much cloud (0..1) and how thick it is (0..1) along the unit direction `dir` from
    /// `eye`; nothing below the horizon.
    fn cover(&self, eye: [f32; 3], dir: [f32; 3]) -> (f32, f32, f32) {
        if dir[2] <= 0.005 {
            return (0.0, 0.0, f32::INFINITY);
        }
        let t = (CLOUD_BASE_M - eye[2]) / dir[2];
        let (x, y) = (eye[0] + t * dir[0], eye[1] + t * dir[1]);
        let std = self.fractal.variance().sqrt();
        let n = self.fractal.sample(x / CLOUD_SPACING_M, 2.0 * y / CLOUD_SPACING_M, 0.0) / std;
        let cover = ((n - self.threshold) / 0.6).clamp(0.0, 1.0);
        let thick = ((n - self.threshold - 0.6) / 1.2).clamp(0.0, 1.0);
        (cover * cover * (3.0 - 2.0 * cover), thick, t)
    }

    /// Paints the clouds over the sky already in `out` (the camera's size), above its horizon.
    pub fn draw(&self, camera: &Camera, out: &mut Pixmap) {
        let (w, h) = (out.width() as usize, out.height() as usize);
        let sky_rows = (camera.horizon_y().floor() + 1.0).clamp(0.0, h as f32) as usize;
        if sky_rows == 0 {
            return;
        }
        let g = sky_grid_px(h as u32);
        let (gw, gh) = (w.div_ceil(g) + 1, sky_rows.div_ceil(g) + 1);
        // (cloud colour premultiplied by its opacity, opacity) at every grid point.
        let eye = camera.eye();
        let grid: Vec<(Rgb, f32)> = (0..gh * gw)
            .map(|i| {
                let (gx, gy) = (i % gw, i / gw);
                let dir = camera.ray((gx * g) as f32 + 0.5, (gy * g) as f32 + 0.5);
                let (cover, thick, distance) = self.cover(eye, dir);
                if cover <= 0.0 {
                    return ([0.0; 3], 0.0);
                }
                let colour =
                    mix(mix(self.lit, self.shade, thick), self.horizon, 1.0 - (-distance / CLOUD_HAZE_M).exp());
                (colour.map(|c| c * cover), cover)
            })
            .collect();
        let decode: Vec<f32> = (0..=255u8).map(srgb_decode).collect();
        let encode = SrgbTable::shared();
        let pixels = out.pixels_mut();
        for y in 0..sky_rows {
            let (gy, ty) = (y / g, (y % g) as f32 / g as f32);
            for x in 0..w {
                let (gx, tx) = (x / g, (x % g) as f32 / g as f32);
                let at = |dx: usize, dy: usize| grid[(gy + dy) * gw + gx + dx];
                let corners = [at(0, 0), at(1, 0), at(0, 1), at(1, 1)];
                let weights = [(1.0 - tx) * (1.0 - ty), tx * (1.0 - ty), (1.0 - tx) * ty, tx * ty];
                let alpha: f32 = corners.iter().zip(weights).map(|(c, w)| c.1 * w).sum();
                if alpha <= 0.0 {
                    continue;
                }
                let p = &mut pixels[y * w + x];
                let under = [p.red(), p.green(), p.blue()].map(|l| decode[usize::from(l)]);
                let rgb: Rgb = std::array::from_fn(|i| {
                    let cloud: f32 = corners.iter().zip(weights).map(|(c, w)| c.0[i] * w).sum();
                    cloud + (1.0 - alpha) * under[i]
                });
                *p = pixel(rgb.map(|v| encode.encode(v)));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::camera::CameraPose;

    #[test]
    fn clouds_cover_part_of_the_sky_and_only_the_sky() {
        let sky = Sky::new(225.0, 35.0);
        let cam = Camera::new(
            CameraPose { height_m: 3.0, pitch_down_deg: -30.0, hfov_deg: 90.0, ..CameraPose::DEFAULT },
            200,
            120,
        );
        let mut clear = Pixmap::new(200, 120).unwrap();
        sky.draw(&cam, [0.0, 0.0, 0.0], &mut clear);
        let mut cloudy = clear.clone();
        Clouds::new(1, &sky).draw(&cam, &mut cloudy);
        let changed = clear.pixels().iter().zip(cloudy.pixels()).filter(|(a, b)| a != b).count();
        let fraction = changed as f32 / (200.0 * 120.0);
        assert!((0.1..0.8).contains(&fraction), "clouds over {fraction} of the sky");
        // Clouds are whiter than the blue sky: less blue than red relative to it.
        let whiter = clear.pixels().iter().zip(cloudy.pixels()).filter(|(a, b)| b.red() > a.red()).count();
        assert!(whiter > changed / 2);
        // Looking down, nothing changes.
        let down = Camera::new(CameraPose { pitch_down_deg: 60.0, hfov_deg: 30.0, ..CameraPose::DEFAULT }, 50, 50);
        let mut a = Pixmap::new(50, 50).unwrap();
        sky.draw(&down, [0.1, 0.1, 0.1], &mut a);
        let mut b = a.clone();
        Clouds::new(1, &sky).draw(&down, &mut b);
        assert!(a == b);
    }
}
