//! The mirror image: what a calm water surface (the plane z = 0) shows a camera, pixel by
//! pixel, ready to be looked up with a blur along the picture's columns.
//!
//! The paper reflects its terrain with a stencil buffer: draw the scene mirrored in the water
//! plane, limited to the water. [`Mirror::build`] does the same with
//! [`Camera::mirrored`]: the world above the water (sky, shore) drawn by the mirror camera and
//! turned upside down is, at every pixel, what a still surface reflects there — crisp, and
//! exactly meeting the shore at the waterline (a reflection looked up by direction alone,
//! as for the ocean's sky, would put the shore's reflection twice the eye height too high).
//!
//! Water that is not still tilts each face; the renderer then looks the mirror up where the
//! face's reflected ray points ([`Mirror::sample`] takes any point, also in the padding around
//! the picture). Ripples too small for the mesh spread the reflection up and down the picture,
//! so a lookup also averages the column over a window of rows. The image is kept as prefix
//! sums of each column in linear light (16 bits per channel, exact in u32), so a window of any
//! height costs two reads per end — the blur of a wind-roughened lake is hundreds of rows tall.

use tiny_skia::Pixmap;

use super::camera::Camera;
use super::light::{Rgb, srgb_decode};

/// Linear light is kept as this many levels per unit.
const LEVELS: f32 = 65535.0;

/// Column prefix sums of a mirror image.
#[derive(Clone, Debug, PartialEq)]
pub struct Mirror {
    /// Columns (the picture's plus the padding on both sides).
    width: usize,
    /// Rows kept.
    rows: usize,
    pad_x: usize,
    /// The picture row (continuous) where kept row 0 begins.
    first_row: f32,
    /// `(rows + 1) x width` running sums down each column (red, green, blue, unused: four
    /// lanes line up with 16-byte loads); row 0 is zero.
    sums: Vec<[u32; 4]>,
}

impl Mirror {
    /// The mirror image for `camera`: `draw` paints the world above the water as seen by the
    /// camera it is given (the mirror camera, padded by `pad_x` columns on each side and
    /// `pad_y` rows at the top and bottom). Rows above picture row `top_row` are dropped (a
    /// calm surface never shows them: they lie beyond the far shore).
    ///
    /// Returns `None` when the padded picture is too large for a pixmap.
    pub fn build(
        camera: &Camera,
        pad_x: u32,
        pad_y: u32,
        top_row: i32,
        draw: impl FnOnce(&Camera, &mut Pixmap),
    ) -> Option<Mirror> {
        let mirror = camera.padded(pad_x, pad_y).mirrored();
        let mut image = Pixmap::new(mirror.width(), mirror.height())?;
        draw(&mirror, &mut image);
        let (width, height) = (mirror.width() as usize, mirror.height() as usize);
        let first = (i64::from(top_row) + i64::from(pad_y)).clamp(0, height as i64 - 1) as usize;
        let rows = height - first;
        let decode: Vec<u32> = (0..=255u8).map(|l| (srgb_decode(l) * LEVELS).round() as u32).collect();
        let mut sums = vec![[0u32; 4]; (rows + 1) * width];
        let pixels = image.pixels();
        for k in 0..rows {
            // Kept row k is mirror row first + k, which the mirror camera drew upside down.
            let source = &pixels[(height - 1 - first - k) * width..][..width];
            let (done, next) = sums.split_at_mut((k + 1) * width);
            let above = &done[k * width..];
            for ((sum, prev), p) in next[..width].iter_mut().zip(above).zip(source) {
                let lin = [p.red(), p.green(), p.blue()].map(|l| decode[usize::from(l)]);
                *sum = [prev[0] + lin[0], prev[1] + lin[1], prev[2] + lin[2], 0];
            }
        }
        Some(Mirror { width, rows, pad_x: pad_x as usize, first_row: first as f32 - pad_y as f32, sums })
    }

    #[cfg(test)]
    /// Columns kept (the picture's plus the padding).
    pub fn width(&self) -> usize {
        self.width
    }

    #[cfg(test)]
    /// Rows kept.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The mean linear colour of the mirror in the column under picture x (continuous pixel
    /// coordinates: pixel (0, 0) spans 0..1) over rows `y - half_height ..= y + half_height`.
    /// Points outside the kept image use its nearest column and its first or last row; a
    /// window is at least half a row tall.
    #[inline]
    pub fn sample(&self, x: f32, y: f32, half_height: f32) -> Rgb {
        let col = (floor(x) + self.pad_x as i64).clamp(0, self.width as i64 - 1) as usize;
        let n = self.rows as f32;
        let t = y - self.first_row;
        let half = half_height.max(0.25);
        // max/min, not clamp: a NaN point lands on row 0 instead of panicking.
        let a = (t - half).max(0.0).min(n - 0.5);
        let b = (t + half).max(a + 0.5).min(n);
        // The running sum at a continuous row s: sums[i] plus the fraction of row i.
        let at = |s: f32| {
            let i = (s as i32 as usize).min(self.rows - 1);
            (i, s - i as f32)
        };
        let ((ia, fa), (ib, fb)) = (at(a), at(b));
        let w = self.width;
        let (pa, qa) = (self.sums[ia * w + col], self.sums[(ia + 1) * w + col]);
        let (pb, qb) = (self.sums[ib * w + col], self.sums[(ib + 1) * w + col]);
        let scale = 1.0 / ((b - a) * LEVELS);
        // Lane by lane over four lanes, so the compiler can keep it in vector registers.
        let lanes: [f32; 4] = std::array::from_fn(|c| {
            let whole = pb[c].wrapping_sub(pa[c]) as i32 as f32;
            let row_b = qb[c].wrapping_sub(pb[c]) as i32 as f32;
            let row_a = qa[c].wrapping_sub(pa[c]) as i32 as f32;
            (whole + fb * row_b - fa * row_a) * scale
        });
        [lanes[0], lanes[1], lanes[2]]
    }
}

/// ⌊x⌋ without a library call (`f32::floor` is one on the default x86-64 target); NaN is 0.
#[inline(always)]
fn floor(x: f32) -> i64 {
    let i = x as i64;
    i - i64::from(x < i as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::camera::CameraPose;
    use tiny_skia::{Color, Paint, PathBuilder, Transform};

    fn camera() -> Camera {
        Camera::new(CameraPose { height_m: 3.0, pitch_down_deg: 3.0, hfov_deg: 60.0, ..CameraPose::DEFAULT }, 120, 80)
    }

    /// A white world above a black one: a wall from z = 0 to 30 m, 300 m north, over black.
    fn wall(cam: &Camera, out: &mut Pixmap) {
        out.fill(Color::BLACK);
        let p = |x: f32, z: f32| cam.project([x, 300.0, z]).map(|(px, py, _)| (px, py)).unwrap();
        let mut pb = PathBuilder::new();
        let corners = [p(-1000.0, 0.0), p(1000.0, 0.0), p(1000.0, 30.0), p(-1000.0, 30.0)];
        pb.move_to(corners[0].0, corners[0].1);
        for c in &corners[1..] {
            pb.line_to(c.0, c.1);
        }
        pb.close();
        let mut paint = Paint::default();
        paint.set_color_rgba8(255, 255, 255, 255);
        out.fill_path(&pb.finish().unwrap(), &paint, tiny_skia::FillRule::Winding, Transform::identity(), None);
    }

    #[test]
    fn a_calm_mirror_shows_the_wall_below_the_waterline() {
        let cam = camera();
        let m = Mirror::build(&cam, 10, 20, 0, wall).unwrap();
        assert_eq!(m.width(), 140);
        // The wall's foot and top, as seen directly, and where their reflections must be.
        let foot = cam.project([0.0, 300.0, 0.0]).unwrap().1;
        let top_reflected = cam.project([0.0, 300.0, -30.0]).unwrap().1;
        let white = |y: f32| m.sample(60.5, y, 0.5)[0];
        assert!(white(foot + 1.0) > 0.99, "just below the waterline: {}", white(foot + 1.0));
        assert!(white(top_reflected - 1.0) > 0.99);
        assert!(white(top_reflected + 1.5) < 0.01, "below the reflected top: black");
        // A tall window averages: half of it on the white, half below.
        let mid = m.sample(60.5, top_reflected, 4.0)[1];
        assert!((mid - 0.5).abs() < 0.05, "{mid}");
        // Far outside: clamped, never a panic.
        assert!(m.sample(-1e6, 1e9, 3.0)[0].is_finite());
        assert!(m.sample(f32::NAN, f32::NAN, f32::NAN)[0].is_finite());
        for x in [-2.5f32, -2.0, -0.1, 0.0, 0.7, 3.0, 1e9, -1e9] {
            assert_eq!(floor(x), x.floor() as i64, "{x}");
        }
    }

    #[test]
    fn windows_are_exact_means_of_the_rows() {
        let cam = camera();
        // Stripes: every row a different grey.
        let m = Mirror::build(&cam, 0, 0, 0, |c, out| {
            for (i, p) in out.pixels_mut().iter_mut().enumerate() {
                let v = ((i / c.width() as usize) * 3 % 256) as u8;
                *p = tiny_skia::PremultipliedColorU8::from_rgba(v, v, v, 255).unwrap();
            }
        })
        .unwrap();
        assert_eq!(m.rows(), 80);
        // Kept row k is mirror row 79 - k: grey level (79 - k)·3.
        let level = |k: usize| srgb_decode(((79 - k) * 3 % 256) as u8);
        for k in [0usize, 10, 79] {
            let got = m.sample(5.5, k as f32 + 0.5, 0.5)[2];
            assert!((got - level(k)).abs() < 1e-4, "row {k}: {got} vs {}", level(k));
        }
        let mean = (10..20).map(level).sum::<f32>() / 10.0;
        assert!((m.sample(5.5, 15.0, 5.0)[0] - mean).abs() < 1e-4);
    }
}
