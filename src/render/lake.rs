//! The lake renderer: the shared water mesh, shaded per pixel with a mirror.
//!
//! What is drawn once per picture size (the camera never moves):
//! - the **background**: the sky ([`Sky::draw`]), its clouds ([`Clouds`]) and the far shore
//!   ([`Shore`]) as this camera sees them, down to the waterline;
//! - the **mirror**: the same sky, clouds and shore drawn by the mirror camera ([`Mirror`]),
//!   which is what still water shows at every pixel.
//!
//! Each frame:
//! 1. the lake surface is sampled and triangulated by the shared mesh renderer, and each pixel
//!    below the waterline gets the number of the face it shows
//!    ([`MeshRenderer::draw_ids`]): one normal per face, as in the paper;
//! 2. each face is shaded once: its colour by height (troughs darker, crests lighter), lit by
//!    the sun and sky, its Fresnel reflectance (Schlick, F0 = 0.02), the sun's glint, and how
//!    far ripples too small for the mesh spread its reflection;
//! 3. each pixel reflects its own view ray about its face's normal and looks the mirror up
//!    where that ray points: `colour = (1 - F)·body + F·mirror + glint`. On calm water every
//!    normal points up and the lookup lands on the pixel itself, a crisp mirror; wind tilts the
//!    faces and breaks the shore's reflection into pieces, and the unresolved ripples smear
//!    the far reflection into vertical streaks (a window of rows of the mirror, ±√3·2σ·focal);
//! 4. supersampled pictures are box-filtered down.
//!
//! The paper meshes its water as a unit grid of quads, one normal each. tidepool samples the
//! noise on the shared mesh's lattice instead, which is laid out on the screen: its faces are
//! a few pixels wide everywhere — centimetres near the camera, metres long near the far
//! shore, where the footprint filter leaves out the octaves they cannot carry. A literal
//! one-metre grid over this lake would be 250,000 quads, most far smaller than a pixel (and
//! aliasing), while the ripples near the camera are shorter than a metre.

use rayon::prelude::*;
use tiny_skia::Pixmap;

use super::camera::{Camera, CameraPose};
use super::clouds::Clouds;
use super::light::{Light, Rgb, SrgbTable, mix};
use super::mesh::{FaceIds, MeshRenderer};
use super::mirror::Mirror;
use super::ocean::mesh_spacing_px;
use super::shade::{Facet, WaterLook, fresnel, glint};
use super::shore::Shore;
use super::sky::{Environment, Sky};
use super::supersample::{Downsample, downsample};
use super::vec3::{Vec3, dot, normalize};
use crate::sim::lake::{FAR_SHORE_M, LakeSurface};

/// Where the lake is seen from: 3 m above the water on the south shore (a person on a low
/// bank), 3° down, 60° wide, looking north across the lake.
pub const LAKE_CAMERA: CameraPose =
    CameraPose { height_m: 3.0, pitch_down_deg: 3.0, hfov_deg: 60.0, heading_deg: 0.0, east_m: 0.0, north_m: 0.0 };
/// The sun's azimuth, degrees clockwise from north: behind the viewer's left shoulder, so it
/// lights the far shore and stays out of the mirror.
pub const SUN_AZIMUTH_DEG: f32 = 225.0;
/// The sun's elevation, degrees.
pub const SUN_ELEVATION_DEG: f32 = 35.0;
/// The mirror keeps this fraction of the picture's width beyond each side (tilted faces near
/// the edges reflect what lies just outside the view).
const MIRROR_PAD_X: f32 = 0.1;
/// ... and this fraction of its height below it (steep reflections of the sky near the camera).
const MIRROR_PAD_Y: f32 = 0.5;

/// How the lake water looks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LakeLook {
    /// Albedo of the water body in the troughs (two root-mean-square heights down), linear.
    pub trough: Rgb,
    /// ... and on the crests, linear.
    pub crest: Rgb,
    /// Lighting weights and the glint's strength.
    pub water: WaterLook,
}

impl Default for LakeLook {
    /// A dark, slightly green lake: most light that enters it is absorbed.
    fn default() -> Self {
        LakeLook { trough: [0.010, 0.020, 0.018], crest: [0.026, 0.050, 0.042], water: WaterLook::default() }
    }
}

/// What one face gives its pixels: its body colour and glint, and four quantities that vary
/// across it — where the mirror is looked up (x and y in mirror pixels), the half-height of
/// the lookup's window (mirror rows) and the Fresnel reflectance — as affine functions of the
/// pixel position through their exact values at the face's corners. The lookup point is
/// projective in the pixel position; over a face a few pixels wide the difference is far
/// below a pixel, and on calm water (every normal up) the fit is exact.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct FaceShade {
    /// The corner the fit is taken from, rendering pixels.
    origin: [f32; 2],
    at: [f32; 4],
    ddx: [f32; 4],
    ddy: [f32; 4],
    /// The water body's lit colour, linear (weighted by 1 - F per pixel).
    body: Rgb,
    /// The sun's glint, linear.
    glint: Rgb,
}

/// Draws lake frames of one size, keeping everything that does not move.
#[derive(Debug)]
pub struct LakeRenderer {
    width: u32,
    height: u32,
    ssaa: u32,
    /// At the rendering (supersampled) size.
    camera: Camera,
    sky: Sky,
    look: LakeLook,
    /// Sky and shore, rendering rows 0..waterline_row.
    background: Pixmap,
    waterline_row: usize,
    mirror: Mirror,
    mesh: MeshRenderer,
    ids: FaceIds,
    faces: Vec<FaceShade>,
    supersampled: Option<Pixmap>,
    /// A level face's albedo lit (for pixels no face covers).
    flat_body: Rgb,
}

impl LakeRenderer {
    /// A renderer for `width x height` pictures supersampled `ssaa x ssaa` (1..=4), with the
    /// shore grown from `seed`.
    ///
    /// Returns `None` when a size is zero or too large for a pixmap.
    pub fn new(width: u32, height: u32, ssaa: u32, seed: u64) -> Option<LakeRenderer> {
        let ssaa = ssaa.clamp(1, 4);
        if width == 0 || height == 0 {
            return None;
        }
        let (rw, rh) = (width.checked_mul(ssaa)?, height.checked_mul(ssaa)?);
        let supersampled = if ssaa > 1 { Some(Pixmap::new(rw, rh)?) } else { None };
        let camera = Camera::new(LAKE_CAMERA, rw, rh);
        let sky = Sky::new(SUN_AZIMUTH_DEG, SUN_ELEVATION_DEG);
        let shore = Shore::new(seed, FAR_SHORE_M, &sky);
        let clouds = Clouds::new(seed, &sky);
        let horizon = sky.radiance(normalize([0.0, 1.0, 0.0]));
        let waterline_row = waterline_row(&camera, FAR_SHORE_M);
        // The background: sky and shore at the rendering size, kept down to the waterline.
        let mut full = Pixmap::new(rw, rh)?;
        sky.draw(&camera, horizon, &mut full);
        clouds.draw(&camera, &mut full);
        shore.draw(&camera, &mut full);
        let mut background = Pixmap::new(rw, (waterline_row as u32).max(1))?;
        let bytes = background.data().len().min(full.data().len());
        background.data_mut()[..bytes].copy_from_slice(&full.data()[..bytes]);
        drop(full);
        // The mirror at the output size: the final picture's own resolution.
        let out_camera = Camera::new(LAKE_CAMERA, width, height);
        let top = waterline_row as f32 / ssaa as f32 - 2.0;
        let (pad_x, pad_y) =
            ((MIRROR_PAD_X * width as f32).ceil() as u32, (MIRROR_PAD_Y * height as f32).ceil() as u32);
        let mirror = Mirror::build(&out_camera, pad_x, pad_y, top.floor() as i32, |cam, image| {
            sky.draw(cam, horizon, image);
            clouds.draw(cam, image);
            shore.draw(cam, image);
        })?;
        let look = LakeLook::default();
        let light = sky.light();
        let flat_body = body(&look, &light, [0.0, 0.0, 1.0], 0.5);
        Some(LakeRenderer {
            width,
            height,
            ssaa,
            camera,
            sky,
            look,
            background,
            waterline_row,
            mirror,
            mesh: MeshRenderer::new(),
            ids: FaceIds::new(rw as usize, rh as usize),
            faces: Vec::new(),
            supersampled,
            flat_body,
        })
    }

    /// Output width, px.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Output height, px.
    pub fn height(&self) -> u32 {
        self.height
    }

    #[cfg(test)]
    /// Supersampling factor per axis.
    pub fn ssaa(&self) -> u32 {
        self.ssaa
    }

    #[cfg(test)]
    /// The camera at the rendering (supersampled) size.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Triangles in the mesh (0 before the first frame).
    pub fn triangle_count(&self) -> usize {
        self.mesh.triangle_count()
    }

    #[cfg(test)]
    /// The first row of the output picture that shows water (the far shore's waterline).
    pub fn waterline_row(&self) -> u32 {
        (self.waterline_row as u32).div_ceil(self.ssaa)
    }

    /// Draws `frame` into `out`, which must be `width x height`.
    ///
    /// # Panics
    /// When `out` has another size (a programming error).
    pub fn render(&mut self, frame: &LakeSurface, out: &mut Pixmap) {
        assert_eq!((out.width(), out.height()), (self.width, self.height), "output size");
        let spacing = mesh_spacing_px(self.width, self.height) * self.ssaa as f32;
        self.mesh.prepare(&self.camera, spacing);
        self.mesh.draw_ids(frame, &mut self.ids);
        // Shade every face once (slot 0 is "no face").
        let optics = Optics {
            camera: self.camera,
            inv_ssaa: 1.0 / self.ssaa as f32,
            look: self.look,
            light: self.sky.light(),
            rms_m: frame.rms_height_m(),
        };
        let mesh = &self.mesh;
        let triangles = mesh.topology().map_or(&[][..], |t| t.triangles());
        let samples = mesh.vertex_samples();
        self.faces.resize(mesh.face_count() + 1, FaceShade::default());
        self.faces[1..].par_iter_mut().enumerate().for_each(|(i, shade)| {
            if let (Some(facet), Some(points), Some(t)) = (mesh.facet(i), mesh.face_points(i), triangles.get(i)) {
                let blur = t.map(|v| samples.get(v as usize).map_or(0.0, |s| s.unresolved_slope_variance));
                *shade = optics.shade_face(facet, points, blur);
            }
        });
        let target = self.supersampled.as_mut().unwrap_or(out);
        let width = target.width() as usize;
        let split = self.waterline_row.min(target.height() as usize) * width * 4;
        target.data_mut()[..split].copy_from_slice(&self.background.data()[..split]);
        let pass = PixelPass {
            optics: &optics,
            mirror: &self.mirror,
            faces: &self.faces,
            flat_body: self.flat_body,
            table: SrgbTable::shared(),
        };
        // Blocks of ssaa x ssaa samples (one output pixel each), from the block holding the
        // waterline; rows above the waterline keep the background.
        let ssaa = self.ssaa as usize;
        let first = self.waterline_row / ssaa * ssaa;
        let (_, water) = target.data_mut().split_at_mut(first * width * 4);
        let ids = &mut self.ids.ids_mut()[first * width..];
        let band = ssaa * width;
        let waterline = self.waterline_row;
        water.par_chunks_mut(band * 4).zip(ids.par_chunks_mut(band)).enumerate().for_each(|(k, (rows, ids))| {
            pass.blocks(first + k * ssaa, ssaa, waterline, rows, ids);
        });
        if let Some(big) = &self.supersampled {
            downsample(big, self.ssaa, Downsample::Box, out);
        }
    }
}

/// The first rendering row whose centre looks at water nearer than the far shore.
fn waterline_row(camera: &Camera, far_shore_m: f32) -> usize {
    let h = camera.height() as usize;
    let x = camera.width() as f32 / 2.0;
    let eye = camera.eye();
    (0..h)
        .rev()
        .find(|&y| camera.ground_point(x, y as f32 + 0.5).is_none_or(|g| g[1] - eye[1] >= far_shore_m))
        .map_or(0, |y| y + 1)
}

/// The water body's colour on a face with normal `n` at relative height `t` (0 trough, 1 crest).
fn body(look: &LakeLook, light: &Light, n: Vec3, t: f32) -> Rgb {
    let albedo = mix(look.trough, look.crest, t.clamp(0.0, 1.0));
    let cos = dot(n, light.sun_dir).max(0.0);
    std::array::from_fn(|i| albedo[i] * (look.water.ambient * light.sky[i] + look.water.diffuse * light.sun[i] * cos))
}

/// The camera and light the face shading needs.
struct Optics {
    /// At the rendering size.
    camera: Camera,
    inv_ssaa: f32,
    look: LakeLook,
    light: Light,
    rms_m: f32,
}

impl Optics {
    /// Where a face with normal `n` seen at rendering pixel position `p` looks the mirror up
    /// (mirror pixels x, y) and its Fresnel reflectance there.
    #[inline]
    fn reflect(&self, n: Vec3, p: (f32, f32)) -> [f32; 3] {
        let c = &self.camera;
        let (f, fwd, right, up) = (c.focal_px(), c.forward(), c.right(), c.up());
        let (cx, cy) = (c.width() as f32 / 2.0, c.height() as f32 / 2.0);
        let (a, b) = ((p.0 - cx) / f, (cy - p.1) / f);
        // The view ray (not normalised: reflection is linear in it).
        let v: Vec3 = std::array::from_fn(|i| fwd[i] + a * right[i] + b * up[i]);
        let d = 2.0 * dot(v, n);
        // The reflected ray turned upside down by the water plane: where the mirror camera
        // looks for it.
        let m = [v[0] - d * n[0], v[1] - d * n[1], d * n[2] - v[2]];
        let inv_depth = 1.0 / dot(m, fwd).max(1e-3);
        let xs = cx + f * dot(m, right) * inv_depth;
        let ys = cy - f * dot(m, up) * inv_depth;
        let cos = -dot(v, n) / dot(v, v).sqrt();
        [xs * self.inv_ssaa, ys * self.inv_ssaa, fresnel(cos.max(0.02))]
    }

    /// A face: its facet, screen corners and the unresolved slope variance at its corners.
    fn shade_face(&self, f: &Facet, points: [(f32, f32); 3], corner_variance: [f32; 3]) -> FaceShade {
        let n = f.normal;
        let focal_out = self.camera.focal_px() * self.inv_ssaa;
        let q: [[f32; 4]; 3] = std::array::from_fn(|k| {
            let [x, y, fr] = self.reflect(n, points[k]);
            // A box of half-height √3·σ has the deviation σ of the reflected elevation, 2σ.
            let blur = 3f32.sqrt() * 2.0 * corner_variance[k].max(0.0).sqrt() * focal_out + 0.5;
            [x, y, blur, fr]
        });
        let (e1, e2) = (
            (points[1].0 - points[0].0, points[1].1 - points[0].1),
            (points[2].0 - points[0].0, points[2].1 - points[0].1),
        );
        let det = e1.0 * e2.1 - e2.0 * e1.1;
        let (mut ddx, mut ddy) = ([0.0; 4], [0.0; 4]);
        if det.abs() > 1e-6 {
            for k in 0..4 {
                let (d1, d2) = (q[1][k] - q[0][k], q[2][k] - q[0][k]);
                ddx[k] = (d1 * e2.1 - d2 * e1.1) / det;
                ddy[k] = (d2 * e1.0 - d1 * e2.0) / det;
            }
        }
        let t = 0.5 + f.height_m / (4.0 * self.rms_m.max(1e-9));
        let g = glint(&self.look.water, &self.light, n, f.to_eye, f.slope_variance);
        FaceShade {
            origin: [points[0].0, points[0].1],
            at: q[0],
            ddx,
            ddy,
            body: body(&self.look, &self.light, n, t),
            glint: self.light.sun.map(|s| g * s),
        }
    }
}

/// Everything the per-pixel pass reads.
struct PixelPass<'a> {
    optics: &'a Optics,
    mirror: &'a Mirror,
    faces: &'a [FaceShade],
    flat_body: Rgb,
    table: &'a SrgbTable,
}

impl PixelPass<'_> {
    /// Shades a band of `ssaa` rendering rows from row `top` (fewer at the bottom): `rows` are
    /// their pixels, `ids` their face numbers (reset to 0 here). Rows above `waterline` are
    /// left alone.
    ///
    /// Each ssaa x ssaa block is one output pixel. Where one face covers the whole block it
    /// is shaded once, at the block's centre (the face's quantities are smooth, so the mean
    /// of its samples is the centre's); only blocks along face edges shade every sample —
    /// multisample anti-aliasing, in effect. At 1920x1080 with 2x2 samples three blocks in
    /// four are whole: 2.0 million lookups instead of 4.6 million, about 95 ms a frame instead
    /// of 120. (Shading each face of an edge block once instead of each sample saved nothing
    /// measurable: the lookups' memory reads, not their arithmetic, set the pace.)
    fn blocks(&self, top: usize, ssaa: usize, waterline: usize, rows: &mut [u8], ids: &mut [u32]) {
        let width = ids.len() / ssaa.max(1);
        let n_rows = ids.len().checked_div(width).unwrap_or(0);
        let whole = n_rows == ssaa && top >= waterline;
        let half = ssaa as f32 / 2.0;
        for bx in 0..width / ssaa {
            let x0 = bx * ssaa;
            let id = ids[x0];
            let uniform = whole && (0..ssaa).all(|r| ids[r * width + x0..][..ssaa].iter().all(|&v| v == id));
            if uniform {
                let rgb = self.shade(id, (x0 as f32 + half, top as f32 + half));
                for r in 0..ssaa {
                    ids[r * width + x0..][..ssaa].fill(0);
                    for px in rows[(r * width + x0) * 4..][..ssaa * 4].chunks_exact_mut(4) {
                        px.copy_from_slice(&[rgb[0], rgb[1], rgb[2], 255]);
                    }
                }
                continue;
            }
            for r in (0..n_rows).filter(|&r| top + r >= waterline) {
                for c in 0..ssaa {
                    let i = r * width + x0 + c;
                    let rgb = self.shade(ids[i], ((x0 + c) as f32 + 0.5, (top + r) as f32 + 0.5));
                    ids[i] = 0;
                    rows[i * 4..i * 4 + 4].copy_from_slice(&[rgb[0], rgb[1], rgb[2], 255]);
                }
            }
        }
    }

    /// The colour of face `id` (0: none) at rendering pixel position `p`.
    #[inline(always)]
    fn shade(&self, id: u32, p: (f32, f32)) -> [u8; 3] {
        let (q, body, glint) = match self.faces.get(id as usize).filter(|_| id != 0) {
            Some(s) => {
                let (dx, dy) = (p.0 - s.origin[0], p.1 - s.origin[1]);
                let q: [f32; 4] = std::array::from_fn(|k| s.at[k] + s.ddx[k] * dx + s.ddy[k] * dy);
                (q, s.body, s.glint)
            }
            None => {
                // No face here (a gap at the edge of the mesh): calm water.
                let [mx, my, fr] = self.optics.reflect([0.0, 0.0, 1.0], p);
                ([mx, my, 0.5, fr], self.flat_body, [0.0; 3])
            }
        };
        let mirrored = self.mirror.sample(q[0], q[1], q[2]);
        let fr = q[3].clamp(0.0, 1.0);
        std::array::from_fn(|i| self.table.encode((1.0 - fr) * body[i] + glint[i] + fr * mirrored[i]))
    }
}

/// An opaque pixel's colour (for tests).
#[cfg(test)]
fn rgb(p: tiny_skia::PremultipliedColorU8) -> [u8; 3] {
    [p.red(), p.green(), p.blue()]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::lake::{Lake, LakeParams};

    fn picture(wind: f64, time: f64, w: u32, h: u32, ssaa: u32) -> (Pixmap, LakeRenderer) {
        let lake = Lake::new(LakeParams { wind_m_s: wind, ..LakeParams::default() });
        let mut r = LakeRenderer::new(w, h, ssaa, 1).unwrap();
        let mut out = Pixmap::new(w, h).unwrap();
        r.render(&lake.surface(time), &mut out);
        (out, r)
    }

    #[test]
    fn calm_water_mirrors_the_shore() {
        let (out, r) = picture(0.0, 0.0, 160, 96, 1);
        let cam = r.camera();
        // A point on the tree line and its reflection: the same colour, give or take the
        // Fresnel loss (the far water reflects over 90 %).
        let (x, y, _) = cam.project([0.0, 302.0, 8.0]).unwrap();
        let (rx, ry, _) = cam.project([0.0, 302.0, -8.0]).unwrap();
        assert!(ry > r.waterline_row() as f32);
        let (a, b) =
            (rgb(out.pixels()[y as usize * 160 + x as usize]), rgb(out.pixels()[ry as usize * 160 + rx as usize]));
        for i in 0..3 {
            assert!(a[i].abs_diff(b[i]) <= 12, "shore {a:?} vs reflection {b:?}");
        }
        // The whole water half is the shore or sky turned over: row by row, the reflection of
        // row y is row 2·waterline - y above, dimmed by less than half.
        assert!(out.pixels().iter().all(|p| p.alpha() == 255));
    }

    #[test]
    fn wind_breaks_the_mirror() {
        let (calm, r) = picture(0.0, 1.0, 160, 96, 1);
        let (windy, _) = picture(8.0, 1.0, 160, 96, 1);
        let w = r.waterline_row() as usize;
        // Above the water nothing changes; below it the wind changes most pixels.
        assert!(calm.data()[..w * 160 * 4] == windy.data()[..w * 160 * 4]);
        let changed = calm.pixels()[w * 160..]
            .iter()
            .zip(&windy.pixels()[w * 160..])
            .filter(|(a, b)| rgb(**a).iter().zip(rgb(**b)).any(|(p, q)| p.abs_diff(q) > 8))
            .count();
        assert!(changed > (96 - w) * 160 / 2, "{changed} of {} water pixels changed", (96 - w) * 160);
        // Where the calm lake mirrors the dark tree line, the rough one reflects mostly sky:
        // the band under the waterline turns lighter.
        let band = (w + 1)..r.camera().project([0.0, 302.0, -12.0]).unwrap().1 as usize;
        let mean = |p: &Pixmap| {
            let rows = &p.pixels()[band.start * 160..band.end * 160];
            rows.iter().map(|q| f32::from(q.green())).sum::<f32>() / rows.len() as f32
        };
        assert!(band.len() >= 3, "{band:?}");
        assert!(mean(&calm) < 0.8 * mean(&windy), "calm {} vs windy {}", mean(&calm), mean(&windy));
    }

    #[test]
    fn deterministic_and_moving() {
        let (a, _) = picture(4.0, 2.0, 96, 54, 1);
        let (b, _) = picture(4.0, 2.0, 96, 54, 1);
        let (c, _) = picture(4.0, 2.5, 96, 54, 1);
        assert!(a.data() == b.data(), "same flags, same picture");
        assert!(a.data() != c.data(), "the water moves");
        let (s, r) = picture(4.0, 2.0, 96, 54, 2);
        assert_eq!(r.ssaa(), 2);
        assert!(r.triangle_count() > 300);
        assert!(s.pixels().iter().all(|p| p.alpha() == 255));
    }
}
