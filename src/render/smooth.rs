//! The ocean's smooth shading: the shared mesh ([`MeshTopology`]) shaded at its vertices and
//! interpolated across each face, with foam drawn per pixel.
//!
//! One colour per face made the sea a mosaic: blocks at terminal size, and near the horizon,
//! where a mesh row spans a whole crest, the faces between two rows alternate between the
//! crest's front and back slopes — a saw-tooth along every far crest. Here each vertex gets a
//! normal (the area-weighted mean of its faces' normals) and is shaded once
//! ([`shade_facet`]) and encoded to sRGB levels; each pixel interpolates its face's three
//! levels (Gouraud shading in sRGB, so a pixel costs three adds and three casts), so
//! neighbouring faces meet without a step and a far crest is a soft band. Foam is a per-pixel
//! pass: the vertex foam cover F and its fresh share (from
//! [`crate::sim::foam::FoamTracker`]) are interpolated, and the pixel foams where F exceeds
//! the [`FoamTexture`] there, laid on the resting water (so it rides the waves). Aged foam
//! reads the texture stretched along the wind ([`FoamLayout::streak`] times: streaks, longer
//! the stronger the wind) and drifting downwind; fresh foam, the breaking crest, reads it
//! unstretched (patches) and is drawn dense.
//!
//! Faces are filled by [`for_each_span`], the exact integer rule of the face-number fill
//! (watertight: every pixel of the sea is drawn exactly once per face layer), in painter's
//! order, in bands of [`BAND_ROWS`] rows on all cores; the result does not depend on the
//! number of cores. Nothing is allocated once the buffers have grown.

use rayon::prelude::*;
use tiny_skia::Pixmap;

use super::foam_texture::{FOAM_TILE_ACROSS_M, FoamTexture, coverage, detail_for};
use super::light::{Rgb, mix, to_srgb8};
use super::mesh::{BAND_ROWS, MeshTopology, Shading, sample_all};
use super::raster::{for_each_span, shows_front};
use super::shade::{Facet, shade_facet};
use super::sky::Environment;
use super::vec3::{Vec3, add, cross, length, normalize, scale, sub};
use crate::sim::foam::Foam;
use crate::sim::surface::{Surface, SurfaceSample};

/// Foam is a froth over water, never a solid sheet: at most this much of a pixel's colour.
pub const FOAM_OPACITY: f32 = 0.9;
/// How opaque the thinnest foam is, as a fraction of [`FOAM_OPACITY`]: fresh foam is dense,
/// fading foam a translucent lace.
pub const THIN_FOAM: f32 = 0.35;
/// Foam cover below this is not drawn: it would change no pixel by half a level (and the
/// foam's statistics leave a little cover almost everywhere, which would send every face
/// through the per-pixel foam pass).
pub const FOAM_VISIBLE: f32 = 1.0 / 256.0;

/// Where the foam texture lies on the water this frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FoamLayout {
    /// Unit vector (east, north) the wind blows towards: the texture's streaks run along it.
    pub downwind: [f32; 2],
    /// How far the texture has drifted downwind, m.
    pub drift_m: f32,
    /// How much longer aged foam's texture is along the wind than across it (a whole number,
    /// so the drift wraps both layouts at once).
    pub streak: f32,
}

/// A face ready to fill.
#[derive(Clone, Copy, Debug)]
struct SmoothFace {
    corners: [u32; 3],
    points: [(f32, f32); 3],
    min_y: f32,
    max_y: f32,
    foamy: bool,
    level: u8,
    detail: f32,
}

/// Buffers of the smooth pass, kept between frames.
#[derive(Debug, Default)]
pub struct SmoothShader {
    samples: Vec<SurfaceSample>,
    world: Vec<Vec3>,
    screen: Vec<Option<(f32, f32)>>,
    normals: Vec<Vec3>,
    /// sRGB levels (+0.5) of the water and of full foam at each vertex.
    water: Vec<Rgb>,
    foam_rgb: Vec<Rgb>,
    /// Foam cover, its fresh share, and texture coordinates per vertex: along the wind for
    /// aged and for fresh foam, and across.
    foam_uv: Vec<[f32; 5]>,
    faces: Vec<Option<SmoothFace>>,
}

impl SmoothShader {
    /// Empty buffers.
    pub fn new() -> SmoothShader {
        SmoothShader::default()
    }

    /// Samples `surface` at the vertices of `topology`, draws it over `out` (the topology's
    /// camera size) with `foam` (one per vertex, or empty for none).
    pub fn draw<S: Surface + ?Sized, E: Environment + ?Sized>(
        &mut self,
        topology: &MeshTopology,
        surface: &S,
        foam: &[Foam],
        layout: FoamLayout,
        shading: &Shading<'_, E>,
        out: &mut Pixmap,
    ) {
        let camera = topology.camera();
        let (ground, footprints) = (topology.points(), topology.footprints());
        let n = ground.len();
        self.samples.resize(n, SurfaceSample::default());
        sample_all(surface, ground, footprints, &mut self.samples);
        self.world.clear();
        self.screen.clear();
        for (g, s) in ground.iter().zip(&self.samples) {
            let p = [g[0] + s.displacement_m[0], g[1] + s.displacement_m[1], s.height_m];
            self.world.push(p);
            self.screen.push(camera.project(p).map(|(x, y, _)| (x, y)));
        }
        // Vertex normals: the area-weighted mean of the faces around each vertex.
        self.normals.clear();
        self.normals.resize(n, [0.0; 3]);
        for t in topology.triangles() {
            let [a, b, c] = t.map(|i| i as usize);
            let mut f = cross(sub(self.world[b], self.world[a]), sub(self.world[c], self.world[a]));
            if f[2] < 0.0 {
                f = scale(f, -1.0);
            }
            for v in [a, b, c] {
                self.normals[v] = add(self.normals[v], f);
            }
        }
        let eye = camera.eye();
        let [dx, dy] = layout.downwind;
        let tile_along = FOAM_TILE_ACROSS_M * layout.streak;
        let (world, normals, samples) = (&self.world, &self.normals, &self.samples);
        // Foam colours are read only by faces with a foaming vertex: without foam (a linear or
        // calm sea) the second shading of every vertex is skipped.
        let any_foam = foam.iter().any(|f| f.cover >= FOAM_VISIBLE);
        self.water.resize(n, [0.0; 3]);
        self.foam_rgb.resize(n, [0.0; 3]);
        self.foam_uv.resize(n, [0.0; 5]);
        self.water
            .par_iter_mut()
            .zip(self.foam_rgb.par_iter_mut())
            .zip(self.foam_uv.par_iter_mut())
            .enumerate()
            .for_each(|(i, ((water, foam_rgb), foam_uv))| {
                let p = world[i];
                let to_eye = sub(eye, p);
                let distance_m = length(to_eye);
                let normal = if normals[i] == [0.0; 3] { [0.0, 0.0, 1.0] } else { normalize(normals[i]) };
                let facet = Facet {
                    normal,
                    to_eye: scale(to_eye, 1.0 / distance_m.max(1e-6)),
                    distance_m,
                    albedo: shading.texture.sample(p[0], p[1], footprints[i].mean_m()),
                    foam: 0.0,
                    slope_variance: samples[i].unresolved_slope_variance,
                    height_m: p[2],
                };
                let level = |c: Rgb| to_srgb8(c).map(|v| f32::from(v) + 0.5);
                *water = level(shade_facet(&shading.look, &shading.light, shading.environment, &facet));
                *foam_rgb = if any_foam {
                    let foam_facet = Facet { foam: 1.0, ..facet };
                    level(shade_facet(&shading.look, &shading.light, shading.environment, &foam_facet))
                } else {
                    *water
                };
                let g = ground[i];
                let along = g[0] * dx + g[1] * dy - layout.drift_m;
                let across = -g[0] * dy + g[1] * dx;
                let f = foam.get(i).copied().filter(|f| f.cover >= FOAM_VISIBLE).unwrap_or_default();
                *foam_uv =
                    [f.cover, f.fresh, along / tile_along, along / FOAM_TILE_ACROSS_M, across / FOAM_TILE_ACROSS_M];
            });
        self.shade_faces(topology);
        self.fill(out);
    }

    fn shade_faces(&mut self, topology: &MeshTopology) {
        let camera = topology.camera();
        let (w, h) = (camera.width() as f32, camera.height() as f32);
        let spacing = topology.spacing_px();
        let texture = FoamTexture::shared();
        let (screen, foam_uv, footprints) = (&self.screen, &self.foam_uv, topology.footprints());
        topology
            .triangles()
            .par_iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| i as usize);
                let (pa, pb, pc) = (screen[a]?, screen[b]?, screen[c]?);
                if !shows_front(pa, pb, pc, w, h) {
                    return None;
                }
                let (min_y, max_y) = (pa.1.min(pb.1).min(pc.1), pa.1.max(pb.1).max(pc.1));
                let foamy = foam_uv[a][0] > 0.0 || foam_uv[b][0] > 0.0 || foam_uv[c][0] > 0.0;
                let metres = (footprints[a].mean_m() + footprints[b].mean_m() + footprints[c].mean_m()) / 3.0;
                let per_pixel = metres / spacing;
                Some(SmoothFace {
                    corners: [a as u32, b as u32, c as u32],
                    points: [pa, pb, pc],
                    min_y,
                    max_y,
                    foamy,
                    level: texture.level_for(per_pixel) as u8,
                    detail: detail_for(per_pixel),
                })
            })
            .collect_into_vec(&mut self.faces);
    }

    fn fill(&self, out: &mut Pixmap) {
        let width = out.width() as usize;
        let rows = out.height() as usize;
        let texture = FoamTexture::shared();
        let (faces, water, foam_rgb, foam_uv) = (&self.faces, &self.water, &self.foam_rgb, &self.foam_uv);
        out.data_mut().par_chunks_mut(BAND_ROWS * width * 4).enumerate().for_each(|(band, bytes)| {
            let y0 = (band * BAND_ROWS) as f32;
            let band_rows = (rows - band * BAND_ROWS).min(BAND_ROWS);
            let y1 = y0 + band_rows as f32;
            for face in faces.iter().flatten().filter(|f| f.max_y >= y0 && f.min_y <= y1) {
                let [a, b, c] = face.corners.map(|i| i as usize);
                let pts = face.points.map(|(x, y)| (x, y - y0));
                let Some(colour) = Planes::<3>::new(pts, [water[a], water[b], water[c]]) else { continue };
                let foam = if face.foamy {
                    let f = |i: usize| {
                        let [r, g, b] = foam_rgb[i];
                        let [cover, fresh, u_aged, u_fresh, v] = foam_uv[i];
                        [r, g, b, cover, fresh, u_aged, u_fresh, v]
                    };
                    Planes::<8>::new(pts, [f(a), f(b), f(c)])
                } else {
                    None
                };
                let (level, detail) = (face.level as usize, face.detail);
                for_each_span(width, band_rows, pts, |y, x0, x1| {
                    let row = &mut bytes[(y * width + x0) * 4..(y * width + x1 + 1) * 4];
                    let (px, py) = (x0 as f32 + 0.5, y as f32 + 0.5);
                    let mut c = colour.at(px, py);
                    let mut fm = foam.as_ref().map(|p| p.at(px, py));
                    for out in row.chunks_exact_mut(4) {
                        let mut rgb = c;
                        if let Some(f) = &fm {
                            let cover = f[3].clamp(0.0, 1.0);
                            if cover > 0.0 {
                                let fresh = f[4].clamp(0.0, 1.0);
                                // Aged foam in streaks (half the texture's width across the
                                // wind: thin), fresh foam in patches: each keeps the mean cover,
                                // so their blend does too (a texture read only where it counts).
                                let aged = if fresh < 1.0 {
                                    coverage(cover, texture.sample(level, f[5], 2.0 * f[7]), detail)
                                } else {
                                    0.0
                                };
                                let amount = if fresh > 0.0 {
                                    let patch = coverage(cover, texture.sample(level, f[6], f[7] + 0.5), detail);
                                    aged + (patch - aged) * fresh
                                } else {
                                    aged
                                };
                                let dense = THIN_FOAM + (1.0 - THIN_FOAM) * fresh.max(cover);
                                rgb = mix(rgb, [f[0], f[1], f[2]], FOAM_OPACITY * dense * amount);
                            }
                        }
                        // Levels carry +0.5, so the cast rounds (and saturates).
                        out.copy_from_slice(&[rgb[0] as u8, rgb[1] as u8, rgb[2] as u8, 255]);
                        c = colour.step(c);
                        if let (Some(f), Some(p)) = (fm.as_mut(), foam.as_ref()) {
                            *f = p.step(*f);
                        }
                    }
                });
            }
        });
    }
}

/// N attributes as affine functions of the pixel position over one face (exact at its
/// corners): value at (x, y) = at0 + ddx·(x - x0) + ddy·(y - y0).
#[derive(Clone, Copy, Debug)]
struct Planes<const N: usize> {
    origin: (f32, f32),
    at0: [f32; N],
    ddx: [f32; N],
    ddy: [f32; N],
}

impl<const N: usize> Planes<N> {
    fn new(p: [(f32, f32); 3], v: [[f32; N]; 3]) -> Option<Planes<N>> {
        let (e1, e2) = ((p[1].0 - p[0].0, p[1].1 - p[0].1), (p[2].0 - p[0].0, p[2].1 - p[0].1));
        let det = e1.0 * e2.1 - e2.0 * e1.1;
        if det.abs() < 1e-12 {
            return None;
        }
        let (mut ddx, mut ddy) = ([0.0; N], [0.0; N]);
        for k in 0..N {
            let (d1, d2) = (v[1][k] - v[0][k], v[2][k] - v[0][k]);
            ddx[k] = (d1 * e2.1 - d2 * e1.1) / det;
            ddy[k] = (d2 * e1.0 - d1 * e2.0) / det;
        }
        Some(Planes { origin: p[0], at0: v[0], ddx, ddy })
    }

    #[inline(always)]
    fn at(&self, x: f32, y: f32) -> [f32; N] {
        let (dx, dy) = (x - self.origin.0, y - self.origin.1);
        std::array::from_fn(|k| self.at0[k] + self.ddx[k] * dx + self.ddy[k] * dy)
    }

    #[inline(always)]
    fn step(&self, v: [f32; N]) -> [f32; N] {
        std::array::from_fn(|k| v[k] + self.ddx[k])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn planes_are_exact_at_the_corners_and_affine_between() {
        let pts = [(1.0, 1.0), (9.0, 2.0), (3.0, 7.0)];
        let p = Planes::<2>::new(pts, [[0.0, 1.0], [8.0, 1.0], [2.0, 1.0]]).unwrap();
        for (i, &(x, y)) in pts.iter().enumerate() {
            let v = p.at(x, y);
            assert!((v[0] - [0.0, 8.0, 2.0][i]).abs() < 1e-5 && (v[1] - 1.0).abs() < 1e-6);
        }
        let v = p.at(4.0, 3.0);
        assert!((p.step(v)[0] - p.at(5.0, 3.0)[0]).abs() < 1e-5);
        assert!(Planes::<1>::new([(0.0, 0.0), (1.0, 1.0), (2.0, 2.0)], [[0.0]; 3]).is_none());
    }
}
