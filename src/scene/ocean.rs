//! The ocean scene: a wind-driven sea, the clock, and the renderer that draws it.

use tiny_skia::Pixmap;

use super::Heightmap;
use super::{Action, Controls, Event, Scene, SceneKind};
use crate::error::{Error, Result};
use crate::render::ocean::{OceanRenderer, OceanView};
use crate::render::texture::SeaTexture;
use crate::sim::ocean::{Sea, SeaParams};
use crate::sim::sea_state;
use crate::sim::wind::{DEFAULT_SEA_WIND_M_S, DEFAULT_WIND_FROM_DEG};

/// Heightmap PNG levels per metre: centimetres.
pub const HEIGHTMAP_PNG_LEVELS_PER_M: f32 = 100.0;

/// Everything about an ocean picture except its size.
#[derive(Clone, Debug)]
pub struct OceanSettings {
    /// Wind and seed.
    pub sea: SeaParams,
    /// Camera, sun and supersampling.
    pub view: OceanView,
    /// The picture stretched over the sea.
    pub texture: SeaTexture,
    /// The sea's time at step 0, s.
    pub start_time_s: f64,
    /// East-west size of the heightmap patch, m (`None`: 8 peak wavelengths).
    pub heightmap_extent_m: Option<f64>,
}

impl Default for OceanSettings {
    /// A 10 m/s wind from 330°, seed 1, the default view without supersampling, the built-in
    /// texture, time 0.
    fn default() -> Self {
        OceanSettings {
            sea: SeaParams {
                wind_m_s: DEFAULT_SEA_WIND_M_S,
                wind_from_deg: DEFAULT_WIND_FROM_DEG,
                seed: 1,
                ..SeaParams::default()
            },
            view: OceanView::default(),
            texture: SeaTexture::builtin(),
            start_time_s: 0.0,
            heightmap_extent_m: None,
        }
    }
}

/// A sea, its clock (physical seconds) and its renderer.
#[derive(Debug)]
pub struct OceanScene {
    sea: Sea,
    renderer: OceanRenderer,
    texture: SeaTexture,
    /// The clock: a start and the time since, counted apart (a looping sea counts each in
    /// whole ticks, so a whole number of loops after any start is the start exactly).
    start_s: f64,
    elapsed_s: f64,
    /// Player steps since the clock was last set, and the elapsed time then (the elapsed
    /// time is that plus steps/60, never a running sum).
    steps: u64,
    set_elapsed_s: f64,
    /// The component phases of the last frame, reused.
    phases: Vec<f32>,
    /// The heightmap patch's east-west size, m.
    extent_m: Option<f64>,
}

/// The heightmap's east-west extent when none is given: 8 peak wavelengths (100 m for a calm).
pub fn default_extent_m(sea: &Sea) -> f64 {
    sea.peak_wavelength_m().map_or(100.0, |l| 8.0 * l)
}

impl OceanScene {
    /// A scene at its start time drawing `width x height` pictures.
    ///
    /// Returns `None` when the (supersampled) size is zero or too large for a pixmap.
    pub fn new(settings: OceanSettings, width: u32, height: u32) -> Option<OceanScene> {
        let renderer = OceanRenderer::new(settings.view, width, height, settings.texture.clone())?;
        Some(OceanScene {
            sea: Sea::new(settings.sea),
            renderer,
            texture: settings.texture,
            start_s: settings.start_time_s,
            elapsed_s: 0.0,
            steps: 0,
            set_elapsed_s: 0.0,
            phases: Vec::new(),
            extent_m: settings.heightmap_extent_m,
        })
    }

    #[cfg(test)]
    /// The sea.
    pub(crate) fn sea(&self) -> &Sea {
        &self.sea
    }

    /// Output width, px.
    pub fn width(&self) -> u32 {
        self.renderer.width()
    }

    /// Output height, px.
    pub fn height(&self) -> u32 {
        self.renderer.height()
    }

    /// Physical time, s.
    pub fn time_s(&self) -> f64 {
        self.start_s + self.elapsed_s
    }

    /// Sets the clock.
    pub fn set_time(&mut self, time_s: f64) {
        self.set_clock(time_s, 0.0);
    }

    /// Sets the clock to `elapsed_s` after `start_s`. The two are counted apart, so in a
    /// looping sea a whole number of loops after a start is exactly the start's sea and foam
    /// (an animation's frame N·T is its frame 0).
    pub fn set_clock(&mut self, start_s: f64, elapsed_s: f64) {
        (self.start_s, self.elapsed_s, self.steps, self.set_elapsed_s) = (start_s, elapsed_s, 0, elapsed_s);
    }

    /// Moves the clock on by `dt_s` seconds: the sea moves exactly that much.
    pub fn advance(&mut self, dt_s: f64) {
        self.start_s += dt_s;
    }

    /// Replaces the sea (new wind, direction or seed); the clock and camera stay.
    pub fn set_sea(&mut self, params: SeaParams) {
        self.sea = Sea::new(params);
    }

    /// Draws the sea at the current time into `out` (the scene's size).
    pub fn render(&mut self, out: &mut Pixmap) {
        let time = self.sea.time_after(self.start_s, self.elapsed_s);
        let frame = self.sea.surface_at(time, std::mem::take(&mut self.phases));
        self.renderer.render(&frame, out);
        self.phases = frame.into_buffer();
    }

    /// Starts drawing at a new size (same sea, clock and camera).
    ///
    /// Returns `false` (and changes nothing) when the size is zero or too large.
    pub fn resize(&mut self, width: u32, height: u32) -> bool {
        let mut view = self.renderer.view();
        view.camera = self.renderer.camera().pose();
        match OceanRenderer::new(view, width, height, self.texture.clone()) {
            Some(r) => {
                self.renderer = r;
                true
            }
            None => false,
        }
    }

    /// The full surface height (m) on a `width x height` grid covering `extent_m` metres
    /// east-west and `extent_m·height/width` north-south, centred under the camera, at cell
    /// centres; columns run east, row 0 is the north edge.
    pub fn heightmap(&self, extent_m: f64, width: usize, height: usize) -> Heightmap {
        let frame = self.sea.surface_at(self.sea.time_after(self.start_s, self.elapsed_s), Vec::new());
        let pose = self.renderer.camera().pose();
        let cell = extent_m / width.max(1) as f64;
        let (west, north) = (pose.east_m - extent_m / 2.0, pose.north_m + cell * height as f64 / 2.0);
        let mut values = vec![0.0f32; width * height];
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).clamp(1, 8);
        let rows_per = height.div_ceil(threads).max(1);
        std::thread::scope(|scope| {
            for (chunk, rows) in values.chunks_mut((rows_per * width).max(1)).enumerate() {
                let frame = &frame;
                scope.spawn(move || {
                    for (i, v) in rows.iter_mut().enumerate() {
                        let (row, col) = (chunk * rows_per + i / width, i % width);
                        let x = west + (col as f64 + 0.5) * cell;
                        let y = north - (row as f64 + 0.5) * cell;
                        *v = frame.height(x as f32, y as f32);
                    }
                });
            }
        });
        Heightmap { width, height, values, png_levels_per_unit: HEIGHTMAP_PNG_LEVELS_PER_M }
    }
}

/// The player steps the sea 60 times a second, each step 1/60 s of physical time: the sea on
/// screen moves in real time.
pub const OCEAN_STEPS_PER_SECOND: f64 = 60.0;
/// How far `,` and `.` turn the wind, degrees.
pub const WIND_TURN_DEG: f64 = 15.0;

impl OceanScene {
    /// The wind after one Beaufort step down (`weaker`) or up from the current wind.
    fn wind_step(&self, weaker: bool) -> f64 {
        let b = sea_state::beaufort_number(self.sea.params().wind_m_s);
        let next = if weaker { b.saturating_sub(1) } else { (b + 1).min(12) };
        sea_state::beaufort_speed_m_s(next).unwrap_or(self.sea.params().wind_m_s)
    }
}

impl Scene for OceanScene {
    fn kind(&self) -> SceneKind {
        SceneKind::Ocean
    }

    fn size(&self) -> (u32, u32) {
        (self.width(), self.height())
    }

    fn steps_per_second(&self) -> f64 {
        OCEAN_STEPS_PER_SECOND
    }

    /// Each step is 1/60 s of the sea's time.
    fn advance(&mut self, steps: u64) {
        self.steps += steps;
        self.elapsed_s = self.set_elapsed_s + self.steps as f64 / OCEAN_STEPS_PER_SECOND;
    }

    fn render(&mut self, out: &mut Pixmap) {
        OceanScene::render(self, out);
    }

    fn apply(&mut self, event: &Event) {
        match *event {
            Event::Wind([speed, from]) => {
                let params = self.sea.params();
                self.set_sea(SeaParams { wind_m_s: speed, wind_from_deg: from, ..params });
            }
            Event::Resize([w, h]) => {
                OceanScene::resize(self, w, h);
            }
            _ => {}
        }
    }

    fn resize(&mut self, width: u32, height: u32) -> Result<()> {
        match OceanScene::resize(self, width, height) {
            true => Ok(()),
            false => Err(Error::TooLarge { what: "sea", width, height }),
        }
    }

    /// The patch is `heightmap_extent_m` wide (default 8 peak wavelengths); see
    /// [`OceanScene::heightmap`].
    fn describe(&self) -> String {
        format!("ssaa {}, {} triangles", self.renderer.view().ssaa, self.renderer.triangle_count())
    }

    fn heightmap(&self, width: usize, height: usize) -> Heightmap {
        let extent = self.extent_m.unwrap_or_else(|| default_extent_m(&self.sea));
        OceanScene::heightmap(self, extent, width, height)
    }
}

impl Controls for OceanScene {
    /// Digits set the wind to that Beaufort number, `[` and `]` weaken and strengthen it by one,
    /// `,` and `.` turn it; stones, rain and clearing mean nothing to the open sea.
    fn resolve(&self, action: Action) -> Vec<Event> {
        let params = self.sea.params();
        let (speed, from) = match action {
            Action::Key(c @ '0'..='9') => {
                let b = c as u8 - b'0';
                (sea_state::beaufort_speed_m_s(b).unwrap_or(params.wind_m_s), params.wind_from_deg)
            }
            Action::Damping(weaker) => (self.wind_step(weaker), params.wind_from_deg),
            Action::Key(',') => (params.wind_m_s, (params.wind_from_deg - WIND_TURN_DEG).rem_euclid(360.0)),
            Action::Key('.') => (params.wind_m_s, (params.wind_from_deg + WIND_TURN_DEG).rem_euclid(360.0)),
            _ => return Vec::new(),
        };
        if (speed, from) == (params.wind_m_s, params.wind_from_deg) {
            return Vec::new();
        }
        vec![Event::Wind([speed, from])]
    }

    fn status(&self, out: &mut String) {
        use std::fmt::Write;
        out.clear();
        let params = self.sea.params();
        let _ = write!(
            out,
            "wind {:.1} m/s from {:.0}\u{b0} \u{b7} Beaufort {} \u{b7} Hs {:.1} m",
            params.wind_m_s,
            params.wind_from_deg,
            sea_state::beaufort_number(params.wind_m_s),
            self.sea.spectrum().significant_height_m()
        );
    }

    fn help(&self) -> Vec<(&'static str, &'static str)> {
        vec![("0 .. 9", "wind: Beaufort 0 to 9"), ("[ ]", "weaker / stronger wind"), (", .", "turn the wind 15\u{b0}")]
    }

    fn takes_stones(&self) -> bool {
        false
    }

    fn hints(&self) -> &'static [&'static str] {
        &[
            "0-9 Beaufort \u{b7} [ ] wind \u{b7} , . turn \u{b7} p pause \u{b7} s shot \u{b7} tab scene \u{b7} ? help \u{b7} q quit",
            "0-9 Beaufort \u{b7} ? help \u{b7} q quit",
            "? help \u{b7} q quit",
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(wind: f64) -> OceanScene {
        let settings = OceanSettings {
            sea: SeaParams { wind_m_s: wind, wind_from_deg: 0.0, seed: 5, ..SeaParams::default() },
            ..OceanSettings::default()
        };
        OceanScene::new(settings, 64, 36).unwrap()
    }

    #[test]
    fn time_moves_the_sea() {
        let mut s = scene(8.0);
        let a = s.snapshot().unwrap();
        OceanScene::advance(&mut s, 1.5);
        assert_eq!(s.time_s(), 1.5);
        assert_ne!(a.data(), s.snapshot().unwrap().data());
        s.set_time(0.0);
        assert_eq!(a.data(), s.snapshot().unwrap().data(), "the same time gives the same picture");
    }

    #[test]
    fn heightmaps_are_oriented_and_sized() {
        let s = scene(10.0);
        let map = OceanScene::heightmap(&s, 800.0, 40, 20);
        assert_eq!((map.width, map.height, map.values.len()), (40, 20, 800));
        let frame = s.sea().surface(0.0);
        // Row 0 is north, column 0 is west: cell (0, 0) is centred at (-390, 190).
        assert_eq!(map.values[0], frame.height(-390.0, 190.0));
        assert_eq!(map.values[19 * 40 + 39], frame.height(390.0, -190.0));
        assert!((default_extent_m(s.sea()) - 8.0 * s.sea().spectrum().peak_wavelength_m().unwrap()).abs() < 1e-9);
        assert!(OceanScene::heightmap(&scene(0.0), 10.0, 3, 3).values.iter().all(|&v| v == 0.0));
    }

    #[test]
    fn keys_change_the_wind_and_nothing_else() {
        let mut s = scene(10.0);
        assert!(s.resolve(Action::Stone { x: 3, y: 3, radius: 3, big: false }).is_empty());
        assert!(s.resolve(Action::ToggleRain).is_empty());
        let gale = s.resolve(Action::Key('8'));
        assert_eq!(gale, vec![Event::Wind([18.95, 0.0])]);
        s.apply(&gale[0]);
        assert_eq!(s.sea().params().wind_m_s, 18.95);
        assert_eq!(s.resolve(Action::Damping(true)), vec![Event::Wind([15.5, 0.0])]);
        assert_eq!(s.resolve(Action::Damping(false)), vec![Event::Wind([22.6, 0.0])]);
        assert_eq!(s.resolve(Action::Key(',')), vec![Event::Wind([18.95, 345.0])]);
        assert_eq!(s.resolve(Action::Key('.')), vec![Event::Wind([18.95, 15.0])]);
        assert!(s.resolve(Action::Key('8')).is_empty(), "already Beaufort 8");
        let mut status = String::new();
        s.status(&mut status);
        assert!(status.contains("Beaufort 8"), "{status}");
        let before = s.time_s();
        Scene::advance(&mut s, 1);
        assert!((s.time_s() - before - 1.0 / 60.0).abs() < 1e-12);
    }

    #[test]
    fn resize_keeps_the_sea() {
        let mut s = scene(6.0);
        assert!(OceanScene::resize(&mut s, 32, 20));
        assert_eq!((s.width(), s.height()), (32, 20));
        assert_eq!(s.snapshot().unwrap().width(), 32);
        assert!(Scene::resize(&mut s, 0, 5).is_err());
    }
}
