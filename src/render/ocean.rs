//! The ocean renderer: sky, then the sea mesh, at `ssaa` times the size, filtered down.
//!
//! The sea is sampled at the mesh's vertices (displaced sideways by its choppiness), its foam
//! followed at those resting points through time ([`FoamTracker`]: a still picture computes
//! the foam's whole memory, a stream of frames continues it), and drawn flat (one normal per
//! spade triangle, the design's look) or smooth ([`SeaShading`]), with the sun's glitter and
//! the foam per pixel ([`shader`], [`glitter`], [`streaks`]).
//!
//! The mesh density is tied to the output resolution ([`mesh_spacing_px`]): about 3 output
//! pixels between samples for a terminal frame (so its few pixels still show facets), growing
//! to about 8 at 1920x1080 so the triangle count (and time) stays bounded while each facet
//! stays small on screen. Everything else is in metres, so from the same camera a storm looks
//! bigger than a breeze.

use tiny_skia::Pixmap;

use super::camera::{Camera, CameraPose};
use super::foam_texture::FOAM_TILE_ACROSS_M;
use super::mesh::{MeshRenderer, Shading};
use super::shade::{Facet, WaterLook, shade_facet};
use super::sky::Sky;
use super::supersample::{Downsample, downsample};
use super::texture::SeaTexture;
use crate::sim::foam::FoamTracker;
use crate::sim::ocean::{Sea, SeaSurface, SeaTime, cox_munk_slope_variance};

pub mod glitter;
pub mod shader;
pub mod streaks;

use glitter::Glitter;
use shader::{FoamLayout, SeaPass, SeaShader};
use streaks::Streaks;

/// How the sea's mesh is lit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SeaShading {
    /// One normal and one colour per spade triangle: the design's faceted sea (supersampling
    /// averages the far crests' saw-tooth). The default: pictures are supersampled.
    #[default]
    Flat,
    /// Shaded at the vertices and interpolated across each face: no facets, soft far crests;
    /// the better look at a terminal's few pixels without supersampling.
    Smooth,
}

impl SeaShading {
    /// The name the command line uses.
    pub fn name(self) -> &'static str {
        match self {
            SeaShading::Flat => "flat",
            SeaShading::Smooth => "smooth",
        }
    }
}

impl std::fmt::Display for SeaShading {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for SeaShading {
    type Err = crate::ValueError;

    fn from_str(text: &str) -> Result<SeaShading, crate::ValueError> {
        match text.trim() {
            "flat" => Ok(SeaShading::Flat),
            "smooth" => Ok(SeaShading::Smooth),
            other => Err(crate::ValueError::new(
                "shading",
                format!("'{other}' is not a shading: flat (one colour per triangle) or smooth (interpolated)"),
            )),
        }
    }
}

/// How fast foam drifts downwind with the surface water, as a fraction of the wind speed
/// (the wind drift of the top centimetres, about 3 %).
pub const FOAM_DRIFT_FRACTION: f64 = 0.03;

/// How much longer aged foam's streaks are along the wind than across it: 2 + U/4, a whole
/// number from 3 (Beaufort 4) to 9 (a storm): a gale's foam lies in long streaks.
pub fn foam_streak(wind_m_s: f64) -> f32 {
    (2.0 + wind_m_s / 4.0).round().clamp(3.0, 9.0) as f32
}

/// How far the foam texture has drifted downwind at `time`, m: modulo one texture length,
/// and for a looping sea at a speed that crosses a whole number of texture lengths per loop.
pub fn foam_drift_m(sea: &Sea, time: SeaTime) -> f32 {
    let length = f64::from(FOAM_TILE_ACROSS_M * foam_streak(sea.params().wind_m_s));
    let speed = FOAM_DRIFT_FRACTION * sea.params().wind_m_s;
    match (time, sea.params().loop_period) {
        (SeaTime::Ticks(u), Some(p)) => {
            let lengths = (speed * p.seconds() / length).round() as u64;
            let turns = lengths.wrapping_mul(u64::from(u as u32)) & 0xFFFF_FFFF;
            (turns as f64 / 4_294_967_296.0 * length) as f32
        }
        _ => (speed * sea.seconds(time)).rem_euclid(length) as f32,
    }
}

/// How the sea is looked at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OceanView {
    /// The camera.
    pub camera: CameraPose,
    /// The sun's azimuth, degrees clockwise from north.
    pub sun_azimuth_deg: f32,
    /// The sun's elevation above the horizon, degrees.
    pub sun_elevation_deg: f32,
    /// Supersampling factor per axis (1 = none).
    pub ssaa: u32,
    /// The filter that brings a supersampled picture down.
    pub downsample: Downsample,
    /// Flat or smooth shading of the mesh.
    pub shading: SeaShading,
}

impl Default for OceanView {
    /// The default camera, the sun ahead and to the right, 22° up (its glitter path lies on
    /// the water in view), no supersampling, flat shading.
    fn default() -> Self {
        OceanView {
            camera: CameraPose::DEFAULT,
            sun_azimuth_deg: 15.0,
            sun_elevation_deg: 22.0,
            ssaa: 1,
            downsample: Downsample::Box,
            shading: SeaShading::default(),
        }
    }
}

/// Output pixels between mesh samples for a `width x height` picture: √(W·H)/180, within
/// 3.2..=8 (a terminal frame gets a triangle per 5 or so pixels, 1080p one per 30). The lake
/// uses this spacing; the ocean's smooth shading goes denser on small pictures
/// ([`ocean_spacing_px`]).
pub fn mesh_spacing_px(width: u32, height: u32) -> f32 {
    ((f64::from(width) * f64::from(height)).sqrt() / 180.0).clamp(3.2, 8.0) as f32
}

/// The ocean's densest mesh, output pixels between samples: a terminal frame (160x94) gets a
/// vertex every 2.4 pixels, so either shading has the short waves to show (at 3.2 smooth
/// shading's few pixels were smoothed flat; 1.6 looked a little crisper but cost twice as
/// much).
pub const MIN_SPACING_PX: f32 = 2.4;

/// The ocean's mesh spacing: √(W·H)/180 within [`MIN_SPACING_PX`]..=8 (1080p: every 8 pixels).
pub fn ocean_spacing_px(width: u32, height: u32) -> f32 {
    ((f64::from(width) * f64::from(height)).sqrt() / 180.0).clamp(f64::from(MIN_SPACING_PX), 8.0) as f32
}

/// The seed of a moment's sparkles: the sea's seed and the moment, in sixtieths of a second
/// (or 2²⁶ steps to a loop, so a loop's frame N·T sparkles as its frame 0).
pub fn glitter_seed(sea: &Sea, time: SeaTime) -> u32 {
    let moment = match time {
        SeaTime::Ticks(u) => (u as u32 >> 6) as u64,
        SeaTime::Seconds(t) => (t * 60.0).floor() as i64 as u64,
    };
    let seed = sea.params().seed;
    ((seed ^ (seed >> 32)) as u32) ^ (moment as u32).wrapping_mul(0x9e37_79b9) ^ ((moment >> 32) as u32)
}

/// Draws a sea into pictures of one size, keeping its mesh and buffers between frames.
#[derive(Debug)]
pub struct OceanRenderer {
    view: OceanView,
    width: u32,
    height: u32,
    camera: Camera,
    sky: Sky,
    texture: SeaTexture,
    look: WaterLook,
    mesh: MeshRenderer,
    shader: SeaShader,
    foam: FoamTracker,
    supersampled: Option<Pixmap>,
}

impl OceanRenderer {
    /// A renderer for `width x height` pictures.
    ///
    /// Returns `None` when the supersampled size is zero or too large for a pixmap.
    pub fn new(view: OceanView, width: u32, height: u32, texture: SeaTexture) -> Option<OceanRenderer> {
        let ssaa = view.ssaa.max(1);
        let (rw, rh) = (width.checked_mul(ssaa)?, height.checked_mul(ssaa)?);
        let supersampled = if ssaa > 1 { Some(Pixmap::new(rw, rh)?) } else { None };
        if width == 0 || height == 0 {
            return None;
        }
        Some(OceanRenderer {
            view: OceanView { ssaa, ..view },
            width,
            height,
            camera: Camera::new(view.camera, rw, rh),
            sky: Sky::new(view.sun_azimuth_deg, view.sun_elevation_deg),
            texture,
            // The sea's unresolved slope variance already holds all of Cox–Munk's.
            look: WaterLook { base_slope_variance: 0.0, ..WaterLook::default() },
            mesh: MeshRenderer::new(),
            shader: SeaShader::new(),
            foam: FoamTracker::new(),
            supersampled,
        })
    }

    /// The view.
    pub fn view(&self) -> OceanView {
        self.view
    }

    /// Output width, px.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Output height, px.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The camera at the rendering (supersampled) resolution.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    #[cfg(test)]
    /// The sky.
    pub fn sky(&self) -> &Sky {
        &self.sky
    }

    /// Triangles in the mesh (0 before the first frame).
    pub fn triangle_count(&self) -> usize {
        self.mesh.triangle_count()
    }

    /// The colour of the sea at the horizon straight ahead: a level facet seen at a grazing
    /// angle with all of the Cox–Munk roughness unresolved. It fills the sliver between the
    /// farthest mesh row and the horizon.
    fn far_sea(&self, wind_m_s: f64) -> super::light::Rgb {
        let f = self.camera.forward();
        let level = super::vec3::normalize([f[0], f[1], 0.0]);
        let distance_m = self.camera.horizon_distance_m();
        let drop = self.camera.eye()[2] / distance_m;
        let facet = Facet {
            normal: [0.0, 0.0, 1.0],
            to_eye: super::vec3::normalize([-level[0], -level[1], drop]),
            distance_m,
            albedo: self.texture.mean(),
            foam: 0.0,
            slope_variance: (cox_munk_slope_variance(wind_m_s) / 2.0) as f32,
            height_m: 0.0,
        };
        shade_facet(&self.look, &self.sky.light(), &self.sky, &facet)
    }

    /// Draws `frame` into `out`, which must be `width x height`.
    ///
    /// Foam continues from the previous frame when the sea and camera are the same and time
    /// moved on by less than the foam's memory; otherwise the memory is computed whole
    /// ([`FoamTracker::update`]). Either way the foam is the same bits, so a frame's picture
    /// does not depend on the frames drawn before it.
    ///
    /// # Panics
    /// When `out` has another size (a programming error).
    pub fn render(&mut self, frame: &SeaSurface<'_>, out: &mut Pixmap) {
        assert_eq!((out.width(), out.height()), (self.width, self.height), "output size");
        let spacing = ocean_spacing_px(self.width, self.height) * self.view.ssaa as f32;
        if self.mesh.prepare(&self.camera, spacing) {
            self.foam.reset();
        }
        let sea = frame.sea();
        let below = self.far_sea(sea.params().wind_m_s);
        let Some(topology) = self.mesh.topology() else { return };
        let foam = self.foam.update(sea, topology.points(), topology.footprints(), frame.time());
        let streak = foam_streak(sea.params().wind_m_s);
        let layout = FoamLayout { downwind: sea.downwind(), drift_m: foam_drift_m(sea, frame.time()), streak };
        let light = self.sky.light();
        let pass = SeaPass {
            mode: self.view.shading,
            shading: Shading { environment: &self.sky, light, look: self.look, texture: &self.texture },
            glitter: Glitter::new(
                &self.look,
                light.sun_dir,
                light.sun,
                glitter_seed(sea, frame.time()),
                self.view.ssaa,
            ),
            layout,
            streaks: Streaks::new(streak, sea.params().seed),
        };
        let target = self.supersampled.as_mut().unwrap_or(out);
        self.sky.draw(&self.camera, below, target);
        self.shader.draw(topology, frame, foam, &pass, target);
        if let Some(big) = &self.supersampled {
            downsample(big, self.view.ssaa, self.view.downsample, out);
        }
    }
}

#[cfg(test)]
impl OceanRenderer {
    /// Draws `frame` and returns the mean glitter at every rendering pixel (a multiple of the
    /// sun's colour, before sparkles, haze and tone mapping): what a measurement of the
    /// glitter's spread reads.
    pub(crate) fn mean_glitter(&mut self, frame: &SeaSurface<'_>) -> Vec<f32> {
        let mut out = Pixmap::new(self.width, self.height).expect("a valid size");
        self.render(frame, &mut out);
        let light = self.sky.light();
        let glitter = Glitter::new(&self.look, light.sun_dir, light.sun, 0, self.view.ssaa);
        self.shader.mean_glitter(&glitter, self.camera.width() as usize, self.camera.height() as usize)
    }

    /// The water's look.
    pub(crate) fn look(&self) -> WaterLook {
        self.look
    }
}

#[cfg(test)]
mod glitter_tests;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::ocean::{Sea, SeaParams};

    #[test]
    fn spacing_follows_the_resolution() {
        assert_eq!(mesh_spacing_px(160, 96), 3.2);
        assert_eq!(ocean_spacing_px(160, 96), MIN_SPACING_PX);
        assert_eq!(mesh_spacing_px(1920, 1080), 8.0);
        let mid = mesh_spacing_px(1280, 720);
        assert!(mid > 5.0 && mid < 5.5);
    }

    #[test]
    fn renders_opaque_and_deterministic_and_supersampled() {
        let sea = Sea::new(SeaParams { wind_m_s: 9.0, wind_from_deg: 300.0, seed: 3, ..SeaParams::default() });
        let frame = sea.surface(2.0);
        let draw = |ssaa| {
            let view = OceanView { ssaa, ..OceanView::default() };
            let mut r = OceanRenderer::new(view, 96, 54, SeaTexture::builtin()).unwrap();
            let mut out = Pixmap::new(96, 54).unwrap();
            r.render(&frame, &mut out);
            assert!(r.triangle_count() > 500);
            out
        };
        let (a, b, c) = (draw(1), draw(1), draw(2));
        assert_eq!(a.data(), b.data());
        assert_ne!(a.data(), c.data());
        assert!(c.pixels().iter().all(|p| p.alpha() == 255));
        // Sky on top (bluish, bright), sea below (darker).
        let top = a.pixels()[2 * 96 + 48];
        let bottom = a.pixels()[50 * 96 + 48];
        assert!(top.blue() > top.red() && u32::from(top.blue()) > u32::from(bottom.blue()));
    }
}
