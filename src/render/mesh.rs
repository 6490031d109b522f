//! The water mesh renderer: "one renderer, two height sources".
//!
//! Anything that implements [`crate::sim::surface::Surface`] (the ocean's
//! [`crate::sim::ocean::SeaSurface`], the lake's noise field) is drawn the same way:
//!
//! 1. **Sampling** ([`MeshTopology::build`], once per camera): points on a jittered triangular
//!    lattice in screen space, `spacing_px` apart (fixed sampling of the picture), unprojected
//!    onto the mean water level, which makes the sampling of the sea view-dependent: dense
//!    near the camera, sparse towards the horizon. The lattice overhangs the picture on the
//!    sides and below, so waves lifted into view are not cut off, and stops at the real
//!    horizon distance (its first row, at that distance's screen row, spans the whole width,
//!    so no gap opens under the horizon at the sides). Each point also gets its [`Footprint`], the ground step to its
//!    neighbours, which the surface uses to leave out waves the lattice cannot carry.
//!    (Packing rows tighter near the horizon was tried and dropped: tall distant waves then
//!    lift rows past their neighbours on the screen and the mesh folds into a saw-tooth.)
//! 2. **Triangulation**: spade's Delaunay triangulation of the screen positions, sorted far to
//!    near once (painter's order for a height field seen from above: the horizontal distance
//!    of a triangle does not change when heights do). Kept while the camera does not move.
//! 3. **Per frame**, one of two ways:
//!    - **the ocean's pass** ([`crate::render::ocean::shader::SeaShader`]): sample the surface
//!      at every point (on all cores), displace, project, and either shade each spade triangle
//!      once with its own normal (`--shading flat`, the design's faceted look; supersampling
//!      averages the far crests' saw-tooth) or shade each vertex and interpolate across the
//!      face (`--shading smooth`, which keeps a terminal's few pixels from turning into a
//!      mosaic); glitter and foam are drawn per pixel in both;
//!    - **face numbers** ([`MeshRenderer::draw_ids`], the lake): each pixel gets the number of
//!      the face it shows ([`FaceIds`]) and [`MeshRenderer::facet`] gives that face's
//!      [`Facet`], for a renderer that shades per pixel.
//!
//!    Both fill with [`crate::render::raster`]'s exact integer rule (pixels whose centres lie
//!    inside; watertight, as tiny-skia's non-AA fill is not at the picture's border), skip
//!    triangles that turned over on the screen (back faces), and allocate nothing per frame.
//!    Smooth edges come from supersampling ([`crate::render::supersample`]).
//!
//! # The two users
//!
//! ```text
//! // The ocean (crate::render::ocean): flat or smooth faces, glitter and foam per pixel.
//! sky.draw(&camera, far_sea_colour, &mut big);
//! mesh.prepare(&camera, spacing_px * ssaa as f32);              // no-op if nothing moved
//! shader.draw(mesh.topology(), &sea_frame, foam, &pass, &mut big);   // pass: flat | smooth
//! supersample::downsample(&big, ssaa, Downsample::Box, &mut out);
//!
//! // The lake (crate::render::lake): face numbers, then a per-pixel mirror.
//! mesh.prepare(&camera, spacing_px * ssaa as f32);
//! mesh.draw_ids(&lake_frame, &mut ids);
//! for each face i: mesh.facet(i), mesh.face_points(i), mesh.vertex_samples()  -> its shading
//! for each pixel: its face's normal reflects the view ray -> a mirror lookup, Fresnel blend
//! ```
//!
//! - [`Surface`] returns heights in metres plus foam cover and the slope variance the mesh
//!   cannot show; its [`Footprint`] says what the mesh can carry.
//! - [`Environment`] is what the ocean reflects ([`crate::render::sky::Sky`]): light by
//!   direction alone, right for a sky at infinity. The lake's shore is 300 m from a 3 m eye,
//!   where a lookup by direction would lift its reflection twice the eye height off the
//!   waterline; the lake reflects through a mirror camera instead
//!   ([`crate::render::mirror`]).
//! - [`WaterLook`] holds the colours and strengths (body light, glint, foam, haze distance);
//!   [`SeaTexture`] is any image tiled over the water in metres (`SeaTexture::from_pixmap`).

use rayon::prelude::*;
use spade::{DelaunayTriangulation, Point2, Triangulation};

use super::camera::Camera;
use super::light::Light;
use super::raster::{fill_triangle_ids, shows_front};
use super::shade::{Facet, WaterLook};
use super::sky::Environment;
use super::texture::SeaTexture;
use super::vec3::{Vec3, cross, length, normalize, scale, sub};
use crate::sim::surface::{Footprint, Surface, SurfaceSample};

/// How far the lattice overhangs the picture left and right, as a fraction of its width.
pub const SIDE_MARGIN: f32 = 0.05;
/// How far the lattice overhangs the picture below, as a fraction of its height.
pub const BOTTOM_MARGIN: f32 = 0.2;

/// The sample points and triangles for one camera.
#[derive(Clone, Debug)]
pub struct MeshTopology {
    camera: Camera,
    spacing_px: f32,
    ground: Vec<[f32; 2]>,
    footprints: Vec<Footprint>,
    triangles: Vec<[u32; 3]>,
}

/// A small deterministic hash to jitter the lattice (the same picture every run).
fn jitter(row: i32, col: i32, salt: u32) -> f32 {
    let h = mix32((row as u32).wrapping_mul(0x9E37_79B1) ^ (col as u32).wrapping_mul(0x85EB_CA77) ^ salt);
    (h >> 8) as f32 / (1u32 << 24) as f32 - 0.5
}

/// The finishing mix of a 32-bit integer hash (xor-shifts and odd multipliers): every input
/// bit reaches every output bit. Shared by the lattice's jitter and the foam streaks' noise.
pub(crate) fn mix32(mut h: u32) -> u32 {
    h ^= h >> 15;
    h = h.wrapping_mul(0x2C1B_3C6D);
    h ^= h >> 12;
    h = h.wrapping_mul(0x297A_2D39);
    h ^= h >> 15;
    h
}

impl MeshTopology {
    /// Samples and triangulates the water in view of `camera`, about `spacing_px` pixels apart.
    pub fn build(camera: &Camera, spacing_px: f32) -> MeshTopology {
        let (w, h) = (camera.width() as f32, camera.height() as f32);
        let s = spacing_px.max(1.0);
        let max_m = camera.horizon_distance_m().max(2_000.0);
        let eye = camera.eye();
        let horizon = camera.horizon_y();
        // The screen row of the farthest water: the point at max_m straight ahead.
        let f = camera.forward();
        let flat = normalize([f[0], f[1], 0.0]);
        let far = [eye[0] + flat[0] * max_m, eye[1] + flat[1] * max_m, 0.0];
        let y_far = camera.project(far).map_or(horizon + 1.0, |(_, y, _)| y).max(horizon + 0.05);
        let (y_start, y_end) = (y_far.max(-0.1 * h), h * (1.0 + BOTTOM_MARGIN));
        let mut screen = Vec::new();
        let mut ground = Vec::new();
        let mut footprints = Vec::new();
        let mut y = y_start;
        let mut row = 0i32;
        while y <= y_end {
            let dy = s;
            let x0 = -SIDE_MARGIN * w + if row % 2 == 1 { s / 2.0 } else { 0.0 };
            let mut col = 0i32;
            let mut x = x0;
            while x <= w * (1.0 + SIDE_MARGIN) {
                let px = x + 0.3 * s * jitter(row, col, 1);
                let py = if row == 0 { y } else { y + 0.3 * dy * jitter(row, col, 2) };
                if let Some(g) = camera.ground_point(px, py) {
                    let d = length([g[0] - eye[0], g[1] - eye[1], 0.0]);
                    // The first row lies at the far water's screen row across the whole
                    // picture: off the centre its rays reach further than max_m, and dropping
                    // them left a gap under the horizon at the sides, a stepped band of the
                    // far-sea fill at terminal size.
                    if d <= max_m * 1.01 || row == 0 {
                        let across = camera.ground_point(px + s, py).map(|a| [a[0] - g[0], a[1] - g[1]]);
                        let along = camera.ground_point(px, py + dy).map(|b| [b[0] - g[0], b[1] - g[1]]);
                        let fp = Footprint {
                            across: across.unwrap_or([s * d / camera.focal_px(), 0.0]),
                            along: along.unwrap_or([0.0, max_m]),
                        };
                        screen.push(Point2::new(f64::from(px), f64::from(py)));
                        ground.push(g);
                        footprints.push(fp);
                    }
                }
                col += 1;
                x = x0 + col as f32 * s;
            }
            row += 1;
            y += dy;
        }
        let mut triangles: Vec<[u32; 3]> = match DelaunayTriangulation::<Point2<f64>>::bulk_load_stable(screen) {
            Ok(t) => t.inner_faces().map(|face| face.vertices().map(|v| v.fix().index() as u32)).collect(),
            Err(_) => Vec::new(),
        };
        let dist = |t: &[u32; 3]| {
            let c = t.iter().fold([0.0f32; 2], |a, &i| [a[0] + ground[i as usize][0], a[1] + ground[i as usize][1]]);
            let (dx, dy) = (c[0] / 3.0 - eye[0], c[1] / 3.0 - eye[1]);
            dx * dx + dy * dy
        };
        triangles.sort_by(|a, b| dist(b).total_cmp(&dist(a)));
        MeshTopology { camera: *camera, spacing_px, ground, footprints, triangles }
    }

    /// The camera the mesh was built for.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Sample points (east, north metres).
    pub fn points(&self) -> &[[f32; 2]] {
        &self.ground
    }

    /// Each point's footprint.
    pub fn footprints(&self) -> &[Footprint] {
        &self.footprints
    }

    /// Pixels between neighbouring samples.
    pub fn spacing_px(&self) -> f32 {
        self.spacing_px
    }

    /// Triangles as point indices, far to near.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }
}

/// Triangulates a water surface and keeps the triangulation while the camera stays; draws it as
/// face numbers (the lake) or hands its topology to the ocean's flat or smooth pass.
#[derive(Debug, Default)]
pub struct MeshRenderer {
    topology: Option<MeshTopology>,
    samples: Vec<SurfaceSample>,
    projected: Vec<Option<(f32, f32)>>,
    world: Vec<Vec3>,
    faces: Vec<Option<Face>>,
}

/// Everything about the water's appearance the mesh renderer needs besides the surface.
#[derive(Clone, Copy, Debug)]
pub struct Shading<'a, E: Environment + ?Sized> {
    /// What the water reflects.
    pub environment: &'a E,
    /// The sun and sky light.
    pub light: Light,
    /// Colours and strengths.
    pub look: WaterLook,
    /// The image stretched over the water.
    pub texture: &'a SeaTexture,
}

impl MeshRenderer {
    /// A renderer with no triangulation yet.
    pub fn new() -> MeshRenderer {
        MeshRenderer::default()
    }

    /// Builds the triangulation for `camera` and `spacing_px` unless it is already there.
    /// Returns true when it had to be built.
    pub fn prepare(&mut self, camera: &Camera, spacing_px: f32) -> bool {
        let fresh = self.topology.as_ref().is_some_and(|t| t.camera == *camera && t.spacing_px == spacing_px);
        if !fresh {
            self.topology = Some(MeshTopology::build(camera, spacing_px));
        }
        !fresh
    }

    /// The current triangulation, if any.
    pub fn topology(&self) -> Option<&MeshTopology> {
        self.topology.as_ref()
    }

    /// Triangles in the current triangulation.
    pub fn triangle_count(&self) -> usize {
        self.topology.as_ref().map_or(0, |t| t.triangles.len())
    }

    /// Samples `surface`, then writes into `ids` (the camera's size) the number of the face
    /// each pixel shows: triangle `i` of the topology as `i + 1`, back to front, so the nearest
    /// face wins. Pixels no face covers keep their value ([`FaceIds::clear`] them first, or
    /// reset them as they are read). Afterwards [`MeshRenderer::facet`]`(i)` describes face
    /// `i + 1`; its `albedo` is black (no texture is read).
    ///
    /// # Panics
    /// Without a prior `prepare`, or when `ids` is not the camera's size (programming errors).
    pub fn draw_ids<S: Surface + ?Sized>(&mut self, surface: &S, ids: &mut FaceIds) {
        let camera = self.topology.as_ref().expect("MeshRenderer::prepare before draw_ids").camera;
        assert_eq!((ids.width, ids.height), (camera.width() as usize, camera.height() as usize), "face id size");
        self.shade_faces(surface);
        let faces = &self.faces;
        let (width, rows) = (ids.width, ids.height);
        if width == 0 {
            return;
        }
        ids.ids.par_chunks_mut(BAND_ROWS * width).enumerate().for_each(|(band, band_ids)| {
            let y0 = (band * BAND_ROWS) as f32;
            let band_rows = (rows - band * BAND_ROWS).min(BAND_ROWS);
            let y1 = y0 + band_rows as f32;
            for (i, face) in faces.iter().enumerate() {
                if let Some(face) = face.as_ref().filter(|f| f.max_y >= y0 && f.min_y <= y1) {
                    let id = u32::try_from(i + 1).unwrap_or(0);
                    fill_triangle_ids(band_ids, width, band_rows, face.points.map(|(x, y)| (x, y - y0)), id);
                }
            }
        });
    }

    /// The facet of triangle `i` as last drawn, or `None` when it was off screen or turned
    /// away (or does not exist).
    pub fn facet(&self, i: usize) -> Option<&Facet> {
        self.faces.get(i)?.as_ref().map(|f| &f.facet)
    }

    /// Triangles described by the last draw (`facet` takes 0 up to this).
    pub fn face_count(&self) -> usize {
        self.faces.len()
    }

    /// The screen corners of triangle `i` as last drawn (corner k is the topology's vertex
    /// `triangles()[i][k]`), or `None` when it was not drawn.
    pub fn face_points(&self, i: usize) -> Option<[(f32, f32); 3]> {
        self.faces.get(i)?.as_ref().map(|f| f.points)
    }

    /// What the surface was at every topology point in the last draw.
    pub fn vertex_samples(&self) -> &[SurfaceSample] {
        &self.samples
    }

    /// Samples the surface, projects it and describes every visible triangle (its albedo
    /// black: the callers shade per pixel).
    fn shade_faces<S: Surface + ?Sized>(&mut self, surface: &S) {
        let topo = self.topology.as_ref().expect("MeshRenderer::prepare before drawing");
        let n = topo.ground.len();
        self.samples.resize(n, SurfaceSample::default());
        sample_all(surface, &topo.ground, &topo.footprints, &mut self.samples);
        let camera = &topo.camera;
        self.world.clear();
        self.projected.clear();
        for (g, s) in topo.ground.iter().zip(&self.samples) {
            let p = [g[0], g[1], s.height_m];
            self.world.push(p);
            self.projected.push(camera.project(p).map(|(x, y, _)| (x, y)));
        }
        let (w, h) = (camera.width() as f32, camera.height() as f32);
        let eye = camera.eye();
        let (world, projected, samples) = (&self.world, &self.projected, &self.samples);
        // Shade every visible triangle (in parallel, order kept), then fill bands of rows in
        // parallel, each band drawing the faces that reach it in painter's order.
        topo.triangles
            .par_iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| i as usize);
                let (pa, pb, pc) = (projected[a]?, projected[b]?, projected[c]?);
                if !shows_front(pa, pb, pc, w, h) {
                    return None;
                }
                let (min_y, max_y) = (pa.1.min(pb.1).min(pc.1), pa.1.max(pb.1).max(pc.1));
                let (wa, wb, wc) = (world[a], world[b], world[c]);
                let mut normal = normalize(cross(sub(wb, wa), sub(wc, wa)));
                if normal[2] < 0.0 {
                    normal = scale(normal, -1.0);
                }
                let centroid = scale([wa[0] + wb[0] + wc[0], wa[1] + wb[1] + wc[1], wa[2] + wb[2] + wc[2]], 1.0 / 3.0);
                let to_eye = sub(eye, centroid);
                let distance_m = length(to_eye);
                let (sa, sb, sc) = (&samples[a], &samples[b], &samples[c]);
                let facet = Facet {
                    normal,
                    to_eye: scale(to_eye, 1.0 / distance_m.max(1e-6)),
                    distance_m,
                    albedo: [0.0; 3],
                    foam: (sa.foam + sb.foam + sc.foam) / 3.0,
                    slope_variance: (sa.unresolved_slope_variance
                        + sb.unresolved_slope_variance
                        + sc.unresolved_slope_variance)
                        / 3.0,
                    height_m: centroid[2],
                };
                Some(Face { points: [pa, pb, pc], min_y, max_y, facet })
            })
            .collect_into_vec(&mut self.faces);
    }
}

/// The number of the mesh face each pixel shows (0 where none has been drawn), row-major.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FaceIds {
    width: usize,
    height: usize,
    ids: Vec<u32>,
}

impl FaceIds {
    /// A `width x height` picture of zeros.
    pub fn new(width: usize, height: usize) -> FaceIds {
        FaceIds { width, height, ids: vec![0; width * height] }
    }

    #[cfg(test)]
    /// The numbers, row-major.
    pub fn ids(&self) -> &[u32] {
        &self.ids
    }

    /// The numbers, to read and reset.
    pub fn ids_mut(&mut self) -> &mut [u32] {
        &mut self.ids
    }
}

/// Rows per band of the parallel fill. Fixed, so the picture does not depend on the number of
/// cores (a face is translated by the band's origin before filling).
pub const BAND_ROWS: usize = 128;

/// A projected triangle ready to fill: screen points, vertical extent and its facet.
#[derive(Clone, Copy, Debug)]
struct Face {
    points: [(f32, f32); 3],
    min_y: f32,
    max_y: f32,
    facet: Facet,
}

/// Samples the surface at every point, in parallel chunks (the result does not depend on how
/// the chunks are spread over cores: each point is sampled alone).
pub(crate) fn sample_all<S: Surface + ?Sized>(
    surface: &S,
    ground: &[[f32; 2]],
    footprints: &[Footprint],
    out: &mut [SurfaceSample],
) {
    const CHUNK: usize = 512;
    out.par_chunks_mut(CHUNK).enumerate().for_each(|(i, chunk)| {
        let start = i * CHUNK;
        for (k, o) in chunk.iter_mut().enumerate() {
            let (g, f) = (ground[start + k], &footprints[start + k]);
            *o = surface.sample(g[0], g[1], f);
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::camera::CameraPose;

    /// A tilted plane and a calm, for checking the mesh without the ocean.
    struct Flat(f32);
    impl Surface for Flat {
        fn sample(&self, x: f32, _y: f32, _f: &Footprint) -> SurfaceSample {
            SurfaceSample { height_m: self.0 * x, ..SurfaceSample::default() }
        }
    }

    fn camera() -> Camera {
        Camera::new(CameraPose::DEFAULT, 160, 96)
    }

    #[test]
    fn the_lattice_is_dense_near_and_sparse_far() {
        let topo = MeshTopology::build(&camera(), 4.0);
        assert!(topo.triangles().len() > 1000, "{}", topo.triangles().len());
        let eye = camera().eye();
        let (mut near, mut far) = (f32::MAX, 0.0f32);
        for (g, f) in topo.points().iter().zip(topo.footprints()) {
            let d = ((g[0] - eye[0]).powi(2) + (g[1] - eye[1]).powi(2)).sqrt();
            if d < 100.0 {
                near = near.min(f.min_m().max(1e-3)).min(near);
            }
            if d > 5000.0 {
                far = far.max(f.mean_m());
            }
        }
        assert!(far > 50.0 * near, "near {near} m, far {far} m");
        // Far to near: the first triangle is the farthest.
        let d = |t: &[u32; 3]| topo.points()[t[0] as usize][1];
        assert!(d(&topo.triangles()[0]) > d(topo.triangles().last().unwrap()));
    }

    #[test]
    fn face_ids_cover_the_sea_and_name_their_facets() {
        let cam = camera();
        let mut renderer = MeshRenderer::new();
        renderer.prepare(&cam, 4.0);
        let mut ids = FaceIds::new(160, 96);
        renderer.draw_ids(&Flat(0.02), &mut ids);
        assert_eq!(renderer.face_count(), renderer.triangle_count());
        let first_row = (cam.horizon_y() + 0.1 * 96.0).ceil() as usize;
        let want = normalize([-0.02, 0.0, 1.0]);
        let mut seen = std::collections::HashSet::new();
        for y in first_row..96 {
            for x in 0..160 {
                let id = ids.ids()[y * 160 + x];
                assert!(id > 0, "no face at ({x}, {y})");
                let f = renderer.facet(id as usize - 1).expect("a drawn face has a facet");
                assert!((0..3).all(|i| (f.normal[i] - want[i]).abs() < 1e-3), "{:?}", f.normal);
                assert_eq!(f.albedo, [0.0; 3]);
                seen.insert(id);
            }
        }
        assert!(seen.len() > 500, "many faces: {}", seen.len());
        // The facet's height is its centroid's: the tilted plane's height there.
        let f = renderer.facet(*seen.iter().next().unwrap() as usize - 1).unwrap();
        let centroid = sub(cam.eye(), scale(f.to_eye, f.distance_m));
        assert!((f.height_m - 0.02 * centroid[0]).abs() < 1e-3);
        assert!((centroid[2] - f.height_m).abs() < 1e-3);
        assert!(renderer.facet(usize::MAX).is_none());
    }
}
