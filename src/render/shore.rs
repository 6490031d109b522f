//! The far shore of the lake: a tree line on a strip of stones, wooded hills behind it and a
//! hazy ridge far away, drawn with tiny-skia paths.
//!
//! The shapes live in world metres (east, north, up), so any camera can draw them: the lake's
//! own, and its mirror camera for the reflection ([`crate::render::mirror`]). Ridge lines are
//! the lake's own lattice noise ([`crate::sim::noise::Fractal`]) along the shore — the paper's
//! point that the same noise makes water and terrain. Every shape stands on a vertical plane
//! at its distance and reaches [`BELOW_WATER_M`] under the water level, so that a reflection
//! looked up a little below the waterline still finds the shore, not a gap.
//!
//! Colours are lit once, as the water is: albedo × (sky + sun · cos), then mixed towards the
//! horizon's colour with distance (aerial perspective, 63 % at [`HAZE_M`]). Nothing here
//! changes per frame; the lake renderer draws the shore once per camera.

use tiny_skia::{
    Color, FillRule, GradientStop, LinearGradient, Paint, PathBuilder, Pixmap, Point, SpreadMode, Transform,
};

use super::camera::Camera;
use super::light::{Rgb, mix, to_srgb8};
use super::sky::{Environment, Sky};
use super::vec3::{Vec3, dot, normalize};
use crate::sim::noise::{Fractal, NoiseKind, fold_seed, lattice_value};

/// How far every shape reaches below the still water level, m.
pub const BELOW_WATER_M: f32 = 6.0;
/// The distance over which haze takes 63 % of a colour, m.
pub const HAZE_M: f32 = 4_000.0;
/// How far the shore extends east and west, as a multiple of its distance (±55°: the lake's
/// 60° view plus the reflections of tilted water beside it).
const SPAN: f32 = 1.45;

/// How a shape is painted.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Fill {
    /// One colour.
    Solid([u8; 3]),
    /// `top` at height `z_top` to `bottom` at `z_bottom` (m), on the shape's plane.
    Vertical { top: [u8; 3], bottom: [u8; 3], z_top: f32, z_bottom: f32 },
    /// `lit` at the west edge `x_west` to `shaded` at the east edge `x_east` (m): trees lit from
    /// the south-west.
    Across { lit: [u8; 3], shaded: [u8; 3], x_west: f32, x_east: f32 },
}

/// One flat shape on the vertical plane `north` metres north of the camera's shore.
#[derive(Clone, Debug, PartialEq)]
struct Shape {
    north: f32,
    /// Outline as (east, up) metres.
    outline: Vec<[f32; 2]>,
    fill: Fill,
}

/// The far shore: shapes back to front.
#[derive(Clone, Debug, PartialEq)]
pub struct Shore {
    shapes: Vec<Shape>,
    distance_m: f32,
}

/// Lighting shared by the shapes.
struct Lighting {
    sun_dir: Vec3,
    sun: Rgb,
    sky: Rgb,
    horizon: Rgb,
}

impl Lighting {
    /// Albedo lit on a surface with normal `n`, hazed for `distance_m`.
    fn colour(&self, albedo: Rgb, n: Vec3, distance_m: f32) -> [u8; 3] {
        let cos = dot(n, self.sun_dir).max(0.0);
        let lit = std::array::from_fn(|i| albedo[i] * (0.55 * self.sky[i] + 0.8 * self.sun[i] * cos));
        to_srgb8(mix(lit, self.horizon, 1.0 - (-distance_m / HAZE_M).exp()))
    }
}

/// A ridge line: `base + amplitude · noise` along east, the noise in [-1, 1] roughly.
fn ridge(seed: u64, east_m: f32, wavelength_m: f32, octaves: u32) -> f32 {
    let f = Fractal { kind: NoiseKind::Value, seed, octaves, persistence: 0.5 };
    // The smoothed value noise rarely leaves ±0.45 (its deviation is 0.2); stretch it to ±1.
    (f.sample(east_m / wavelength_m, 0.5, 0.0) / (0.45 * f.bound())).clamp(-1.0, 1.0)
}

/// A uniform value in [0, 1) for item `i` of stream `salt`.
fn unit(seed: u32, i: i32, salt: i32) -> f32 {
    (lattice_value(seed, i, salt, 17) + 1.0) * 0.5
}

impl Shore {
    /// The shore `distance_m` metres north, its ridges and trees from `seed`, lit by `sky`.
    pub fn new(seed: u64, distance_m: f32, sky: &Sky) -> Shore {
        let light = sky.light();
        let lighting = Lighting {
            sun_dir: light.sun_dir,
            sun: light.sun,
            sky: light.sky,
            horizon: sky.radiance(normalize([0.0, 1.0, 0.02])),
        };
        let d = distance_m;
        let mut shapes = Vec::new();
        // Slopes facing the camera (south), tilted back.
        let slope = |tilt_deg: f32| {
            let t = tilt_deg.to_radians();
            [0.0, -t.sin(), t.cos()]
        };
        let hill_seed = |k: u64| seed.wrapping_mul(31).wrapping_add(k);

        // The far ridge: blue with distance.
        let far = d + 1_700.0;
        shapes.push(Shape {
            north: far,
            outline: ridge_outline(far, 14.0, |e| 290.0 + 130.0 * ridge(hill_seed(1), e, 900.0, 5)),
            fill: Fill::Solid(lighting.colour([0.05, 0.085, 0.05], slope(35.0), far)),
        });
        // Two ranges of wooded hills.
        for (k, north, base, amplitude, wavelength) in
            [(2u64, d + 260.0, 52.0, 36.0, 320.0), (3, d + 70.0, 24.0, 16.0, 150.0)]
        {
            let albedo = if k == 2 { [0.05, 0.095, 0.035] } else { [0.04, 0.085, 0.03] };
            let top = lighting.colour(albedo, slope(40.0), north);
            let bottom = lighting.colour(albedo.map(|v| v * 0.55), slope(10.0), north);
            shapes.push(Shape {
                north,
                outline: ridge_outline(north, 3.0, |e| base + amplitude * ridge(hill_seed(k), e, wavelength, 5)),
                fill: Fill::Vertical { top, bottom, z_top: base + amplitude, z_bottom: 0.0 },
            });
        }
        // Undergrowth: a dark band the trees stand in, so no light shows between trunks.
        let under = d + 1.0;
        shapes.push(Shape {
            north: under,
            outline: ridge_outline(under, 2.0, |e| 4.5 + 1.5 * ridge(hill_seed(4), e, 25.0, 3)),
            fill: Fill::Solid(lighting.colour([0.02, 0.035, 0.018], slope(0.0), under)),
        });
        shapes.extend(trees(fold_seed(hill_seed(5)), d, &lighting));
        // The stones at the waterline.
        shapes.push(Shape {
            north: d,
            outline: ridge_outline(d, 1.5, |e| 0.7 + 0.35 * ridge(hill_seed(6), e, 9.0, 3)),
            fill: Fill::Vertical {
                top: lighting.colour([0.25, 0.23, 0.19], slope(50.0), d),
                bottom: lighting.colour([0.12, 0.11, 0.09], slope(0.0), d),
                z_top: 1.0,
                z_bottom: 0.0,
            },
        });
        Shore { shapes, distance_m }
    }

    /// Draws the shore as `camera` sees it into `out` (the camera's size), anti-aliased, over
    /// whatever is there.
    pub fn draw(&self, camera: &Camera, out: &mut Pixmap) {
        let mut builder = PathBuilder::new();
        for shape in &self.shapes {
            let project = |[e, z]: [f32; 2]| camera.project([e, shape.north, z]).map(|(x, y, _)| Point::from_xy(x, y));
            let Some(points) = shape.outline.iter().map(|&p| project(p)).collect::<Option<Vec<Point>>>() else {
                continue;
            };
            builder.move_to(points[0].x, points[0].y);
            for p in &points[1..] {
                builder.line_to(p.x, p.y);
            }
            builder.close();
            let Some(path) = builder.finish() else {
                builder = PathBuilder::new();
                continue;
            };
            let colour = |c: [u8; 3]| Color::from_rgba8(c[0], c[1], c[2], 255);
            let gradient = |a: Option<Point>, b: Option<Point>, ca: [u8; 3], cb: [u8; 3]| {
                let (a, b) = (a?, b?);
                LinearGradient::new(
                    a,
                    b,
                    vec![GradientStop::new(0.0, colour(ca)), GradientStop::new(1.0, colour(cb))],
                    SpreadMode::Pad,
                    Transform::identity(),
                )
            };
            let mut paint = Paint::default();
            match shape.fill {
                Fill::Solid(c) => paint.set_color(colour(c)),
                Fill::Vertical { top, bottom, z_top, z_bottom } => {
                    match gradient(project([0.0, z_top]), project([0.0, z_bottom]), top, bottom) {
                        Some(shader) => paint.shader = shader,
                        None => paint.set_color(colour(top)),
                    }
                }
                Fill::Across { lit, shaded, x_west, x_east } => {
                    let z = shape.outline[0][1];
                    match gradient(project([x_west, z]), project([x_east, z]), lit, shaded) {
                        Some(shader) => paint.shader = shader,
                        None => paint.set_color(colour(lit)),
                    }
                }
            }
            out.fill_path(&path, &paint, FillRule::Winding, Transform::identity(), None);
            builder = path.clear();
        }
    }
}

/// The outline of a ridge `north` metres away: the top sampled every `step_m` metres across
/// the span, closed along the bottom under the water.
fn ridge_outline(north: f32, step_m: f32, top: impl Fn(f32) -> f32) -> Vec<[f32; 2]> {
    let half = SPAN * north;
    let n = (2.0 * half / step_m).ceil() as usize;
    let mut outline: Vec<[f32; 2]> = (0..=n)
        .map(|i| {
            let e = -half + 2.0 * half * i as f32 / n as f32;
            [e, top(e)]
        })
        .collect();
    outline.push([half, -BELOW_WATER_M]);
    outline.push([-half, -BELOW_WATER_M]);
    outline
}

/// The tree line along the shore, `distance_m` away and up to 30 m behind it, farthest first.
fn trees(seed: u32, distance_m: f32, lighting: &Lighting) -> Vec<Shape> {
    let half = SPAN * (distance_m + 30.0);
    let mut shapes = Vec::new();
    let mut east = -half;
    let mut i = 0;
    let facing = [0.0, -1.0, 0.0];
    while east < half {
        let u = |salt| unit(seed, i, salt);
        // Clumps: tall stands and gaps of low scrub follow a slow noise along the shore.
        let stand = 0.5 + 0.5 * ridge(u64::from(seed), east, 60.0, 3);
        let height = 7.0 + 13.0 * stand + 4.0 * (u(1) - 0.5);
        let north = distance_m + 2.0 + 26.0 * u(2);
        let conifer = u(3) < 0.45 + 0.35 * stand;
        let tone = 0.75 + 0.5 * u(4);
        let albedo = if conifer {
            [0.018, 0.040, 0.024].map(|v| v * tone)
        } else if u(5) < 0.2 {
            [0.075, 0.115, 0.040].map(|v| v * tone) // birches, lighter
        } else {
            [0.040, 0.085, 0.028].map(|v| v * tone)
        };
        let lit = lighting.colour(albedo.map(|v| v * 1.35), facing, north);
        let shaded = lighting.colour(albedo.map(|v| v * 0.7), facing, north);
        let (outline, half_width) = if conifer { spruce(east, height) } else { crown(east, height, seed, i) };
        shapes.push(Shape {
            north,
            outline,
            fill: Fill::Across { lit, shaded, x_west: east - half_width, x_east: east + half_width },
        });
        east += 2.2 + 2.6 * u(6) + if conifer { 0.0 } else { 1.5 };
        i += 1;
    }
    shapes.sort_by(|a, b| b.north.total_cmp(&a.north));
    shapes
}

/// A spruce `height` metres tall at `east`: a narrow cone with four notched tiers, standing in
/// the undergrowth. Returns the outline and its half-width.
fn spruce(east: f32, height: f32) -> (Vec<[f32; 2]>, f32) {
    let base_half = 0.15 * height;
    let mut right = Vec::new();
    for k in 1..=4 {
        let y = height * (1.0 - k as f32 / 4.6);
        let w = base_half * k as f32 / 4.0;
        right.push([east + w, y]);
        if k < 4 {
            right.push([east + 0.45 * w, y + 0.04 * height]);
        }
    }
    right.push([east + 0.35 * base_half, 1.0]);
    let mut outline = vec![[east, height]];
    outline.extend(right.iter().copied());
    outline.extend(right.iter().rev().map(|&[e, z]| [2.0 * east - e, z]));
    (outline, base_half)
}

/// A broadleaf crown `height` metres tall at `east`: a lumpy ellipse on a short trunk.
fn crown(east: f32, height: f32, seed: u32, i: i32) -> (Vec<[f32; 2]>, f32) {
    let (rx, rz) = (0.3 * height, 0.36 * height);
    let cz = height - rz;
    let mut outline: Vec<[f32; 2]> = (0..16)
        .map(|k| {
            let a = k as f32 * std::f32::consts::TAU / 16.0;
            let lump = 0.85 + 0.3 * unit(seed, i * 16 + k, 9);
            [east + rx * lump * a.cos(), cz + rz * lump * a.sin()]
        })
        .collect();
    // The trunk down into the undergrowth.
    let bottom = outline.iter().position(|p| p[1] == outline.iter().map(|q| q[1]).fold(f32::MAX, f32::min));
    let k = bottom.unwrap_or(12);
    outline.splice(k..k, [[east + 0.05 * height, 1.0], [east - 0.05 * height, 1.0]]);
    (outline, rx)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::camera::CameraPose;

    fn camera() -> Camera {
        Camera::new(CameraPose { height_m: 3.0, pitch_down_deg: 3.0, hfov_deg: 60.0, ..CameraPose::DEFAULT }, 160, 96)
    }

    fn drawn(cam: &Camera, shore: &Shore) -> Pixmap {
        let mut out = Pixmap::new(cam.width(), cam.height()).unwrap();
        out.fill(Color::from_rgba8(255, 0, 255, 255));
        shore.draw(cam, &mut out);
        out
    }

    #[test]
    fn the_shore_stands_on_the_waterline_across_the_view() {
        let sky = Sky::new(225.0, 35.0);
        let shore = Shore::new(1, 300.0, &sky);
        let cam = camera();
        let out = drawn(&cam, &shore);
        let waterline = cam.project([0.0, 300.0, 0.0]).unwrap().1;
        let magenta = |x: usize, y: usize| {
            let p = out.pixels()[y * 160 + x];
            (p.red(), p.green(), p.blue()) == (255, 0, 255)
        };
        // Just above the waterline, every column shows the shore; the top rows show none of it.
        let row = (waterline - 1.5) as usize;
        assert!((0..160).all(|x| !magenta(x, row)), "a gap in the shore at row {row}");
        assert!((0..160).all(|x| magenta(x, 0)), "the hills stay below the top of the picture");
        // Green land, lit: greener than it is red or blue, not black.
        let p = out.pixels()[(waterline - 8.0) as usize * 160 + 80];
        assert!(p.green() > p.red() && p.green() > 20, "{p:?}");
        // The same seed draws the same shore; another seed another one.
        assert_eq!(drawn(&cam, &Shore::new(1, 300.0, &sky)).data(), out.data());
        assert_ne!(drawn(&cam, &Shore::new(2, 300.0, &sky)).data(), out.data());
    }

    #[test]
    fn the_mirror_camera_draws_it_upside_down_below_the_waterline() {
        let sky = Sky::new(225.0, 35.0);
        let shore = Shore::new(1, 300.0, &sky);
        let cam = camera();
        let mirrored = drawn(&cam.mirrored(), &shore);
        // Flipped, the reflection's first rows below the waterline are shore, not magenta.
        let waterline = cam.project([0.0, 300.0, 0.0]).unwrap().1;
        let flipped_row = 96 - 1 - (waterline + 1.5) as usize;
        let p = mirrored.pixels()[flipped_row * 160 + 80];
        assert!(!(p.red() == 255 && p.blue() == 255), "{p:?}");
    }

    #[test]
    fn trees_are_closed_outlines_of_sensible_size() {
        let (spruce, w) = spruce(10.0, 20.0);
        assert_eq!(spruce[0], [10.0, 20.0]);
        assert!(spruce.iter().all(|p| (p[0] - 10.0).abs() <= w + 1e-4 && (0.0..=20.0).contains(&p[1])));
        let (round, r) = crown(0.0, 15.0, 3, 4);
        assert!(round.iter().all(|p| p[0].abs() <= 1.15 * r && p[1] >= 0.9));
        assert_eq!(round.len(), 18);
    }
}
