//! The ocean's mesh pass: the shared mesh ([`MeshTopology`]) sampled, lit and filled, either
//! flat (one normal and one colour per spade triangle, the design's look) or smooth (shaded at
//! the vertices and interpolated across each face), with the sun's glitter and the foam drawn
//! per pixel in both.
//!
//! - **Flat** ([`SeaShading::Flat`]): each face's normal is the cross product of its edges
//!   (the displaced triangle), shaded once at its centroid ([`shade_water`]): the sea is a
//!   mosaic of facets, as the paper's mesh. Near the horizon a mesh row spans a whole crest, so
//!   the faces between two rows alternate between its front and back slopes; supersampling
//!   (`--ssaa`) averages that saw-tooth into the crest's mean. The haze is the air's, not the
//!   facet's: it is mixed in per pixel from the vertices' distances (one haze per face made
//!   the first row under the horizon a saw-tooth of near and far triangles).
//! - **Smooth** ([`SeaShading::Smooth`]): each vertex gets a normal (the area-weighted mean of
//!   its faces' normals), is shaded once and encoded to sRGB levels; each pixel interpolates
//!   its face's three levels (Gouraud shading in sRGB: three adds and three casts a pixel), so
//!   neighbouring faces meet without a step and a far crest is a soft band.
//!
//! **Glitter** ([`Glitter`]) is evaluated per pixel on the faces that can show it, with the
//! pixel's normal (the face's, or the interpolated one) and the slope variance the mesh does
//! not carry there: the surface's unresolved slope plus what the mesh loses of the kept waves
//! between its samples ([`FLAT_LOSS`], [`SMOOTH_LOSS`]). It is added in linear light to the
//! pixel's water colour and tone-mapped again.
//!
//! **Foam** is a per-pixel pass: the vertex foam cover F and its fresh share (from
//! [`crate::sim::foam::FoamTracker`]) are interpolated, and the pixel foams where F exceeds the
//! [`FoamTexture`] there, laid on the resting water (so it rides the waves). Aged foam reads
//! the texture stretched along the wind ([`FoamLayout::streak`] times) and drifting downwind,
//! in streaks whose length and spacing vary over the sea (`super::streaks`); fresh foam, the
//! breaking crest, reads it unstretched (patches) and is drawn dense.
//!
//! Faces are filled by [`for_each_span`], the exact integer rule of the face-number fill
//! (watertight: every pixel of the sea is drawn exactly once per face layer), in painter's
//! order, in bands of [`BAND_ROWS`] rows on all cores; the result does not depend on the
//! number of cores. Nothing is allocated once the buffers have grown.

use rayon::prelude::*;
use tiny_skia::Pixmap;

use super::SeaShading;
use super::glitter::{Glitter, GlitterCorner};
use super::streaks::Streaks;
use crate::render::foam_texture::{FOAM_TILE_ACROSS_M, FoamTexture, coverage, detail_for};
use crate::render::light::{Rgb, SrgbTable, mix, srgb_decode, to_srgb8};
use crate::render::mesh::{BAND_ROWS, MeshTopology, Shading, sample_all};
use crate::render::raster::{for_each_span, shows_front};
use crate::render::shade::{Facet, shade_water};
use crate::render::sky::Environment;
use crate::render::vec3::{Vec3, add, cross, length, normalize, scale, sub};
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
/// The share of a kept wave's slope variance a flat triangle loses, per squared phase step
/// between samples: a face's slope is a difference quotient over one step, sinc²(φ/2) of the
/// wave's, 1 - φ²/12 for small φ.
pub const FLAT_LOSS: f32 = 1.0 / 12.0;
/// The same for smooth shading: a vertex normal is a difference over two steps (sinc²(φ),
/// 1 - φ²/3), and interpolating it between vertices loses about φ²/6 more.
pub const SMOOTH_LOSS: f32 = 0.5;

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
struct SeaFace {
    corners: [u32; 3],
    points: [(f32, f32); 3],
    min_y: f32,
    max_y: f32,
    foamy: bool,
    level: u8,
    detail: f32,
    /// Flat shading: the face's sRGB levels (+0.5) of water and of full foam.
    flat: Option<[Rgb; 2]>,
    /// Flat shading: the face's normal (the glitter's at every corner).
    normal: Vec3,
    /// Whether any pixel can show glitter.
    glints: bool,
}

/// Buffers of the mesh pass, kept between frames.
#[derive(Debug, Default)]
pub struct SeaShader {
    samples: Vec<SurfaceSample>,
    world: Vec<Vec3>,
    screen: Vec<Option<(f32, f32)>>,
    normals: Vec<Vec3>,
    /// Smooth shading: sRGB levels (+0.5) of the water and of full foam at each vertex.
    water: Vec<Rgb>,
    foam_rgb: Vec<Rgb>,
    /// Flat shading: the haze's sRGB levels (+0.5) at each vertex and how much of the water's
    /// colour it keeps there.
    haze: Vec<[f32; 4]>,
    /// Foam cover, its fresh share, texture coordinates per vertex: aged foam's along and
    /// across the wind (warped, [`Streaks`]), and fresh foam's; and aged foam's density.
    foam_uv: Vec<[f32; 7]>,
    /// The glitter's corner values per vertex.
    glitter: Vec<GlitterCorner>,
    faces: Vec<Option<SeaFace>>,
}

/// Everything a frame's mesh pass needs besides the mesh and the surface.
pub struct SeaPass<'a, E: Environment + ?Sized> {
    /// Flat or smooth.
    pub mode: SeaShading,
    /// Light, look, texture and what the water reflects.
    pub shading: Shading<'a, E>,
    /// The sun's glitter.
    pub glitter: Glitter,
    /// Where the foam texture lies.
    pub layout: FoamLayout,
    /// How aged foam's streaks vary over the sea.
    pub streaks: Streaks,
}

impl SeaShader {
    /// Empty buffers.
    pub fn new() -> SeaShader {
        SeaShader::default()
    }

    /// Samples `surface` at the vertices of `topology`, draws it over `out` (the topology's
    /// camera size) with `foam` (one per vertex, or empty for none).
    pub fn draw<S: Surface + ?Sized, E: Environment + ?Sized>(
        &mut self,
        topology: &MeshTopology,
        surface: &S,
        foam: &[Foam],
        pass: &SeaPass<'_, E>,
        out: &mut Pixmap,
    ) {
        self.prepare(topology, surface, foam, pass);
        self.shade_faces(topology, pass);
        self.fill(&pass.glitter, out);
    }

    /// Samples, displaces and projects the vertices and gives each its normal, foam and
    /// glitter values (and with smooth shading its colours).
    fn prepare<S: Surface + ?Sized, E: Environment + ?Sized>(
        &mut self,
        topology: &MeshTopology,
        surface: &S,
        foam: &[Foam],
        pass: &SeaPass<'_, E>,
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
            let f = face_normal(self.world[a], self.world[b], self.world[c]);
            for v in [a, b, c] {
                self.normals[v] = add(self.normals[v], f);
            }
        }
        let eye = camera.eye();
        let spacing = topology.spacing_px();
        let shading = &pass.shading;
        let smooth = pass.mode == SeaShading::Smooth;
        let loss = if smooth { SMOOTH_LOSS } else { FLAT_LOSS };
        let [dx, dy] = pass.layout.downwind;
        let tile_along = FOAM_TILE_ACROSS_M * pass.layout.streak;
        let (world, normals, samples) = (&self.world, &self.normals, &self.samples);
        // Foam colours are read only by faces with a foaming vertex: without foam (a linear or
        // calm sea) the second shading of every vertex is skipped.
        let any_foam = foam.iter().any(|f| f.cover >= FOAM_VISIBLE);
        self.water.resize(n, [0.0; 3]);
        self.foam_rgb.resize(n, [0.0; 3]);
        self.foam_uv.resize(n, [0.0; 7]);
        self.glitter.resize(n, [0.0; 9]);
        self.haze.resize(n, [0.0; 4]);
        self.water
            .par_iter_mut()
            .zip(self.foam_rgb.par_iter_mut())
            .zip(self.foam_uv.par_iter_mut())
            .zip(self.glitter.par_iter_mut())
            .zip(self.haze.par_iter_mut())
            .enumerate()
            .for_each(|(i, ((((water, foam_rgb), foam_uv), glitter), haze))| {
                let p = world[i];
                let to_eye = sub(eye, p);
                let distance_m = length(to_eye);
                let v = scale(to_eye, 1.0 / distance_m.max(1e-6));
                let normal = if normals[i] == [0.0; 3] { [0.0, 0.0, 1.0] } else { normalize(normals[i]) };
                let s = &samples[i];
                let slope = s.unresolved_slope_variance + loss * 0.5 * s.mesh_slope_loss;
                if smooth {
                    let facet = Facet {
                        normal,
                        to_eye: v,
                        distance_m,
                        albedo: shading.texture.sample(p[0], p[1], footprints[i].mean_m()),
                        foam: 0.0,
                        slope_variance: slope,
                        height_m: p[2],
                    };
                    *water = levels(shade_water(&shading.look, &shading.light, shading.environment, &facet).colour);
                    *foam_rgb = if any_foam {
                        let foam_facet = Facet { foam: 1.0, ..facet };
                        levels(shade_water(&shading.look, &shading.light, shading.environment, &foam_facet).colour)
                    } else {
                        *water
                    };
                }
                let keep = (-distance_m / shading.look.haze_m).exp();
                if !smooth {
                    let away = shading.environment.radiance(normalize([-v[0], -v[1], 0.0]));
                    let [r, g, b] = levels(away);
                    *haze = [r, g, b, keep];
                }
                let fp = footprints[i];
                let area = (fp.across[0] * fp.along[1] - fp.across[1] * fp.along[0]).abs() / (spacing * spacing);
                let s2 = slope + shading.look.base_slope_variance;
                *glitter = [v[0], v[1], v[2], s2, keep, area, normal[0], normal[1], normal[2]];
                let g = ground[i];
                let along = g[0] * dx + g[1] * dy - pass.layout.drift_m;
                let across = -g[0] * dy + g[1] * dx;
                let v_fresh = across / FOAM_TILE_ACROSS_M;
                let (u_aged, v_aged, density) = pass.streaks.warp(along / tile_along, v_fresh);
                let f = foam.get(i).copied().filter(|f| f.cover >= FOAM_VISIBLE).unwrap_or_default();
                *foam_uv = [f.cover, f.fresh, u_aged, v_aged, along / FOAM_TILE_ACROSS_M, v_fresh, density];
            });
    }

    fn shade_faces<E: Environment + ?Sized>(&mut self, topology: &MeshTopology, pass: &SeaPass<'_, E>) {
        let camera = topology.camera();
        let (w, h) = (camera.width() as f32, camera.height() as f32);
        let spacing = topology.spacing_px();
        let texture = FoamTexture::shared();
        let eye = camera.eye();
        let (screen, foam_uv, footprints) = (&self.screen, &self.foam_uv, topology.footprints());
        let (world, glitter) = (&self.world, &self.glitter);
        let shading = &pass.shading;
        let flat = pass.mode == SeaShading::Flat;
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
                let mut corners = [glitter[a], glitter[b], glitter[c]];
                let (mut colours, mut normal) = (None, [0.0, 0.0, 1.0]);
                if flat {
                    normal = normalize(face_normal(world[a], world[b], world[c]));
                    for k in &mut corners {
                        k[6..9].copy_from_slice(&normal);
                    }
                    let centroid = scale(add(add(world[a], world[b]), world[c]), 1.0 / 3.0);
                    let to_eye = sub(eye, centroid);
                    let distance_m = length(to_eye);
                    // The haze is mixed in per pixel (see the module docs).
                    let facet = Facet {
                        normal,
                        to_eye: scale(to_eye, 1.0 / distance_m.max(1e-6)),
                        distance_m: 0.0,
                        albedo: shading.texture.sample(centroid[0], centroid[1], metres),
                        foam: 0.0,
                        slope_variance: (corners[0][3] + corners[1][3] + corners[2][3]) / 3.0
                            - shading.look.base_slope_variance,
                        height_m: centroid[2],
                    };
                    let water = levels(shade_water(&shading.look, &shading.light, shading.environment, &facet).colour);
                    let foam = if foamy {
                        let foam_facet = Facet { foam: 1.0, ..facet };
                        levels(shade_water(&shading.look, &shading.light, shading.environment, &foam_facet).colour)
                    } else {
                        water
                    };
                    colours = Some([water, foam]);
                }
                Some(SeaFace {
                    corners: [a as u32, b as u32, c as u32],
                    points: [pa, pb, pc],
                    min_y,
                    max_y,
                    foamy,
                    level: texture.level_for(per_pixel) as u8,
                    detail: detail_for(per_pixel),
                    flat: colours,
                    normal,
                    glints: pass.glitter.may_show(&corners),
                })
            })
            .collect_into_vec(&mut self.faces);
    }

    fn fill(&self, glitter: &Glitter, out: &mut Pixmap) {
        let width = out.width() as usize;
        let rows = out.height() as usize;
        let texture = FoamTexture::shared();
        let srgb = SrgbTable::shared();
        let (faces, water, foam_rgb, foam_uv, haze) =
            (&self.faces, &self.water, &self.foam_rgb, &self.foam_uv, &self.haze);
        out.data_mut().par_chunks_mut(BAND_ROWS * width * 4).enumerate().for_each(|(band, bytes)| {
            let y0 = (band * BAND_ROWS) as f32;
            let band_rows = (rows - band * BAND_ROWS).min(BAND_ROWS);
            let y1 = y0 + band_rows as f32;
            for face in faces.iter().flatten().filter(|f| f.max_y >= y0 && f.min_y <= y1) {
                let [a, b, c] = face.corners.map(|i| i as usize);
                let pts = face.points.map(|(x, y)| (x, y - y0));
                let (water_at, foam_at) = match face.flat {
                    Some([w, f]) => ([w; 3], [f; 3]),
                    None => ([water[a], water[b], water[c]], [foam_rgb[a], foam_rgb[b], foam_rgb[c]]),
                };
                let Some(colour) = Planes::<3>::new(pts, water_at) else { continue };
                let foam = if face.foamy {
                    let f = |k: usize, i: usize| {
                        let [r, g, b] = foam_at[k];
                        let [cover, fresh, u_aged, v_aged, u_fresh, v_fresh, density] = foam_uv[i];
                        [r, g, b, cover, fresh, u_aged, v_aged, u_fresh, v_fresh, density]
                    };
                    Planes::<10>::new(pts, [f(0, a), f(1, b), f(2, c)])
                } else {
                    None
                };
                let glints = if face.glints { self.glitter_planes(face, pts) } else { None };
                let hazes = face.flat.and_then(|_| Planes::<4>::new(pts, [haze[a], haze[b], haze[c]]));
                let (level, detail) = (face.level as usize, face.detail);
                for_each_span(width, band_rows, pts, |y, x0, x1| {
                    let row = &mut bytes[(y * width + x0) * 4..(y * width + x1 + 1) * 4];
                    let (px, py) = (x0 as f32 + 0.5, y as f32 + 0.5);
                    let mut c = colour.at(px, py);
                    let mut fm = foam.as_ref().map(|p| p.at(px, py));
                    let mut gl = glints.as_ref().map(|p| p.at(px, py));
                    let mut hz = hazes.as_ref().map(|p| p.at(px, py));
                    for (k, out) in row.chunks_exact_mut(4).enumerate() {
                        let mut rgb = c;
                        if let Some(g) = &gl {
                            let sparkle = glitter.pixel(g, x0 + k, band * BAND_ROWS + y);
                            if sparkle != [0.0; 3] {
                                rgb = [0, 1, 2].map(|i| f32::from(srgb.encode(linear(rgb[i]) + sparkle[i])) + 0.5);
                            }
                        }
                        if let Some(f) = &fm {
                            rgb = foam_over(rgb, f, texture, level, detail);
                        }
                        if let Some(h) = &hz {
                            rgb = mix([h[0], h[1], h[2]], rgb, h[3].clamp(0.0, 1.0));
                        }
                        // Levels carry +0.5, so the cast rounds (and saturates).
                        out.copy_from_slice(&[rgb[0] as u8, rgb[1] as u8, rgb[2] as u8, 255]);
                        c = colour.step(c);
                        if let (Some(f), Some(p)) = (fm.as_mut(), foam.as_ref()) {
                            *f = p.step(*f);
                        }
                        if let (Some(g), Some(p)) = (gl.as_mut(), glints.as_ref()) {
                            *g = p.step(*g);
                        }
                        if let (Some(h), Some(p)) = (hz.as_mut(), hazes.as_ref()) {
                            *h = p.step(*h);
                        }
                    }
                });
            }
        });
    }

    /// The glitter's corner values of `face` as planes over its pixels (`pts`: its corners in
    /// the band's coordinates).
    fn glitter_planes(&self, face: &SeaFace, pts: [(f32, f32); 3]) -> Option<Planes<9>> {
        let mut corners = face.corners.map(|i| self.glitter[i as usize]);
        if face.flat.is_some() {
            for k in &mut corners {
                k[6..9].copy_from_slice(&face.normal);
                // Flat faces take the haze per pixel, after the glitter.
                k[4] = 1.0;
            }
        }
        Planes::<9>::new(pts, corners)
    }

    /// The mean glitter (a multiple of the sun's colour, before sparkles, tone mapping and
    /// haze) at every pixel of the last drawn frame, row-major, 0 where no face shows any:
    /// what the glitter's measurement reads (`glitter_tests.rs`).
    #[cfg(test)]
    pub(crate) fn mean_glitter(&self, glitter: &Glitter, width: usize, rows: usize) -> Vec<f32> {
        let mut out = vec![0.0f32; width * rows];
        for face in self.faces.iter().flatten() {
            let planes = if face.glints { self.glitter_planes(face, face.points) } else { None };
            for_each_span(width, rows, face.points, |y, x0, x1| {
                for x in x0..=x1 {
                    out[y * width + x] = planes.as_ref().map_or(0.0, |p| {
                        let g = p.at(x as f32 + 0.5, y as f32 + 0.5);
                        glitter.mean(normalize([g[6], g[7], g[8]]), normalize([g[0], g[1], g[2]]), g[3], g[5]).0
                    });
                }
            });
        }
        out
    }
}

/// A triangle's normal, pointing up, as long as twice its area.
fn face_normal(a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let f = cross(sub(b, a), sub(c, a));
    if f[2] < 0.0 { scale(f, -1.0) } else { f }
}

/// A linear colour's sRGB levels, +0.5 (for interpolation; the final cast rounds).
fn levels(c: Rgb) -> Rgb {
    to_srgb8(c).map(|v| f32::from(v) + 0.5)
}

/// The linear light of an interpolated sRGB level (+0.5), undoing the tone mapping of
/// [`to_srgb8`]: the light a glint is added to.
#[inline(always)]
fn linear(level: f32) -> f32 {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        std::array::from_fn(|i| {
            let t = srgb_decode(i as u8);
            if t <= 0.8 { t } else { 0.8 - 0.2 * (1.0 - ((t - 0.8) / 0.2).min(0.999)).ln() }
        })
    });
    let l = (level - 0.5).clamp(0.0, 255.0);
    let i = (l as usize).min(254);
    table[i] + (table[i + 1] - table[i]) * (l - i as f32)
}

/// A pixel's levels `rgb` under the foam interpolated there (`f`: the foam's levels, cover,
/// fresh share, aged and fresh foam's texture coordinates, and aged foam's density).
#[inline(always)]
fn foam_over(rgb: Rgb, f: &[f32; 10], texture: &FoamTexture, level: usize, detail: f32) -> Rgb {
    let cover = f[3].clamp(0.0, 1.0);
    if cover <= 0.0 {
        return rgb;
    }
    let fresh = f[4].clamp(0.0, 1.0);
    // Aged foam in streaks (half the texture's width across the wind: thin), fresh foam in
    // patches: each keeps the mean cover, so their blend does too (a texture read only where
    // it counts).
    let aged = if fresh < 1.0 {
        (coverage(cover, texture.sample(level, f[5], 2.0 * f[6]), detail) * f[9]).min(1.0)
    } else {
        0.0
    };
    let amount = if fresh > 0.0 {
        let patch = coverage(cover, texture.sample(level, f[7], f[8] + 0.5), detail);
        aged + (patch - aged) * fresh
    } else {
        aged
    };
    let dense = THIN_FOAM + (1.0 - THIN_FOAM) * fresh.max(cover);
    mix(rgb, [f[0], f[1], f[2]], FOAM_OPACITY * dense * amount)
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

    #[test]
    fn a_level_goes_back_to_its_light() {
        for v in [0.0f32, 0.004, 0.05, 0.3, 0.79, 0.9, 1.5] {
            let l = to_srgb8([v; 3])[0];
            let back = linear(f32::from(l) + 0.5);
            assert_eq!(to_srgb8([back; 3])[0], l, "{v}");
        }
    }
}
