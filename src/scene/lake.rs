//! The lake scene: the noise water, its clock, and the renderer with its shore and mirror.

use tiny_skia::Pixmap;

use super::Heightmap;
use super::{Action, Controls, Event, Scene, SceneKind};
use crate::error::{Error, Result};
use crate::render::lake::LakeRenderer;
use crate::sim::lake::{FAR_SHORE_M, Lake, LakeParams};
use crate::sim::noise::{MAX_OCTAVES, NoiseKind};
use crate::sim::sea_state::beaufort_speed_m_s;
use crate::sim::wind::MAX_LAKE_WIND_M_S;

/// Heightmap PNG levels per metre: millimetres (lake ripples are millimetres to centimetres).
pub const HEIGHTMAP_PNG_LEVELS_PER_M: f32 = 1000.0;
/// How much `[` and `]` change the wind in the player, m/s.
pub const WIND_STEP_M_S: f64 = 1.0;
/// How much `>` and `<` change the persistence in the player.
pub const PERSISTENCE_STEP: f64 = 0.05;
/// Simulated time per player step: the player steps 30 times a second, in real time.
pub const PLAYER_STEP_S: f64 = 1.0 / 30.0;

/// Everything about a lake picture except its size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LakeSettings {
    /// Wind, seed and noise.
    pub lake: LakeParams,
    /// Supersampling per axis, 1..=4.
    pub ssaa: u32,
    /// The lake's time at step 0, s.
    pub start_time_s: f64,
}

impl Default for LakeSettings {
    /// The default breeze and noise, no supersampling, time 0.
    fn default() -> Self {
        LakeSettings { lake: LakeParams::default(), ssaa: 1, start_time_s: 0.0 }
    }
}

/// A lake, its clock (seconds) and its renderer.
#[derive(Debug)]
pub struct LakeScene {
    lake: Lake,
    renderer: LakeRenderer,
    ssaa: u32,
    time_s: f64,
}

impl LakeScene {
    /// A scene at its start time drawing `width x height` pictures.
    ///
    /// Returns `None` when the (supersampled) size is zero or too large for a pixmap.
    pub fn new(settings: LakeSettings, width: u32, height: u32) -> Option<LakeScene> {
        let renderer = LakeRenderer::new(width, height, settings.ssaa, settings.lake.seed)?;
        Some(LakeScene { lake: Lake::new(settings.lake), renderer, ssaa: settings.ssaa, time_s: settings.start_time_s })
    }

    #[cfg(test)]
    /// The lake.
    pub(crate) fn lake(&self) -> &Lake {
        &self.lake
    }

    /// Output width, px.
    pub fn width(&self) -> u32 {
        self.renderer.width()
    }

    /// Output height, px.
    pub fn height(&self) -> u32 {
        self.renderer.height()
    }

    /// Time, s.
    pub fn time_s(&self) -> f64 {
        self.time_s
    }

    /// Sets the clock.
    pub fn set_time(&mut self, time_s: f64) {
        self.time_s = time_s;
    }

    /// Moves the clock on by `dt_s` seconds.
    pub fn advance(&mut self, dt_s: f64) {
        self.time_s += dt_s;
    }

    /// New wind or noise; the clock and the shore stay (the shore's seed is the scene's).
    pub fn set_params(&mut self, params: LakeParams) {
        self.lake = Lake::new(LakeParams { seed: self.lake.params().seed, ..params });
    }

    /// Draws the lake at the current time into `out` (the scene's size).
    pub fn render(&mut self, out: &mut Pixmap) {
        let frame = self.lake.surface(self.time_s);
        self.renderer.render(&frame, out);
    }

    /// Starts drawing at a new size (same lake and clock).
    ///
    /// Returns `false` (and changes nothing) when the size is zero or too large.
    pub fn resize(&mut self, width: u32, height: u32) -> bool {
        match LakeRenderer::new(width, height, self.ssaa, self.lake.params().seed) {
            Some(r) => {
                self.renderer = r;
                true
            }
            None => false,
        }
    }

    /// The full surface height (m) on a `width x height` grid of square cells covering the
    /// lake from the far shore (row 0) to the camera's shore (300 m north-south,
    /// `FAR_SHORE_M·width/height` east-west, centred on the camera), at cell centres; columns
    /// run east.
    pub fn heightmap(&self, width: usize, height: usize) -> Heightmap {
        let frame = self.lake.surface(self.time_s);
        let cell = f64::from(FAR_SHORE_M) / height.max(1) as f64;
        let west = -cell * width as f64 / 2.0;
        let north = f64::from(FAR_SHORE_M);
        let mut values = vec![0.0f32; width * height];
        use rayon::prelude::*;
        values.par_chunks_mut(width.max(1)).enumerate().for_each(|(row, line)| {
            let y = north - (row as f64 + 0.5) * cell;
            for (col, v) in line.iter_mut().enumerate() {
                *v = frame.height((west + (col as f64 + 0.5) * cell) as f32, y as f32);
            }
        });
        Heightmap { width, height, values, png_levels_per_unit: HEIGHTMAP_PNG_LEVELS_PER_M }
    }
}

impl Scene for LakeScene {
    fn kind(&self) -> SceneKind {
        SceneKind::Lake
    }

    fn size(&self) -> (u32, u32) {
        (self.width(), self.height())
    }

    /// One step is 1/30 s of lake time: the water moves in real time.
    fn steps_per_second(&self) -> f64 {
        1.0 / PLAYER_STEP_S
    }

    fn advance(&mut self, steps: u64) {
        for _ in 0..steps {
            LakeScene::advance(self, PLAYER_STEP_S);
        }
    }

    fn render(&mut self, out: &mut Pixmap) {
        LakeScene::render(self, out);
    }

    fn apply(&mut self, event: &Event) {
        let p = self.lake.params();
        match *event {
            Event::Wind([speed, _]) => {
                self.set_params(LakeParams { wind_m_s: speed.clamp(0.0, MAX_LAKE_WIND_M_S), ..p });
            }
            Event::Noise { octaves, persistence, kind } => {
                self.set_params(LakeParams { octaves, persistence, noise: kind, ..p });
            }
            Event::Resize([w, h]) => {
                LakeScene::resize(self, w, h);
            }
            _ => {}
        }
    }

    fn resize(&mut self, width: u32, height: u32) -> Result<()> {
        match LakeScene::resize(self, width, height) {
            true => Ok(()),
            false => Err(Error::TooLarge { what: "lake", width, height }),
        }
    }

    fn describe(&self) -> String {
        format!("ssaa {}, {} triangles", self.ssaa, self.renderer.triangle_count())
    }

    fn heightmap(&self, width: usize, height: usize) -> Heightmap {
        LakeScene::heightmap(self, width, height)
    }
}

impl Controls for LakeScene {
    /// The ocean's wind keys: digits set the wind to that Beaufort number, `[` and `]` weaken
    /// and strengthen it by 1 m/s, `c` calms the lake; `o`/`O` add and drop an octave, `>` and
    /// `<` raise and lower the persistence, `n` switches value and gradient noise. Stones,
    /// stirring and rain mean nothing to noise water (it has no wave equation).
    fn resolve(&self, action: Action) -> Vec<Event> {
        let p = self.lake.params();
        // The lake's wind always blows from the far shore, the north.
        let wind = |w: f64| vec![Event::Wind([(w.clamp(0.0, MAX_LAKE_WIND_M_S) * 10.0).round() / 10.0, 0.0])];
        let noise = |octaves: u32, persistence: f64, kind: NoiseKind| {
            let persistence = (persistence.clamp(0.0, 1.0) * 100.0).round() / 100.0;
            vec![Event::Noise { octaves: octaves.clamp(1, MAX_OCTAVES as u32), persistence, kind }]
        };
        match action {
            Action::Clear => wind(0.0),
            Action::Key(c @ '0'..='9') => wind(beaufort_speed_m_s(c as u8 - b'0').unwrap_or(p.wind_m_s)),
            Action::Damping(weaker) => wind(p.wind_m_s + if weaker { -WIND_STEP_M_S } else { WIND_STEP_M_S }),
            Action::Key('o') => noise(p.octaves + 1, p.persistence, p.noise),
            Action::Key('O') => noise(p.octaves.saturating_sub(1), p.persistence, p.noise),
            Action::Key('>') => noise(p.octaves, p.persistence + PERSISTENCE_STEP, p.noise),
            Action::Key('<') => noise(p.octaves, p.persistence - PERSISTENCE_STEP, p.noise),
            Action::Key('n') => {
                let other = if p.noise == NoiseKind::Value { NoiseKind::Gradient } else { NoiseKind::Value };
                noise(p.octaves, p.persistence, other)
            }
            _ => Vec::new(),
        }
    }

    fn status(&self, out: &mut String) {
        use std::fmt::Write;
        let p = self.lake.params();
        out.clear();
        let _ = write!(
            out,
            "wind {} m/s \u{b7} {} octaves \u{b7} p {:.2} \u{b7} {}",
            p.wind_m_s,
            p.octaves,
            p.persistence,
            p.noise.name()
        );
    }

    fn help(&self) -> Vec<(&'static str, &'static str)> {
        vec![
            ("0 .. 9", "wind: Beaufort 0 to 9"),
            ("[ ]", "less / more wind (1 m/s)"),
            ("c", "calm: no wind, a mirror"),
            ("o O", "more / fewer noise octaves"),
            ("> <", "rougher / smoother (persistence)"),
            ("n", "value / gradient noise"),
        ]
    }

    fn takes_stones(&self) -> bool {
        false
    }

    fn hints(&self) -> &'static [&'static str] {
        &[
            "0-9 Beaufort \u{b7} [ ] wind \u{b7} c calm \u{b7} o O octaves \u{b7} < > rough \u{b7} n noise \u{b7} p pause \u{b7} s shot \u{b7} ? help \u{b7} q quit",
            "[ ] wind \u{b7} c calm \u{b7} ? help \u{b7} q quit",
            "? help \u{b7} q quit",
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(wind: f64) -> LakeScene {
        let settings =
            LakeSettings { lake: LakeParams { wind_m_s: wind, ..LakeParams::default() }, ..LakeSettings::default() };
        LakeScene::new(settings, 64, 40).unwrap()
    }

    #[test]
    fn time_moves_the_water_and_calm_stays_still() {
        let mut s = scene(5.0);
        let a = s.snapshot().unwrap();
        Scene::advance(&mut s, 1);
        assert!((s.time_s() - PLAYER_STEP_S).abs() < 1e-12);
        assert!(a.data() != s.snapshot().unwrap().data());
        s.set_time(0.0);
        assert!(a.data() == s.snapshot().unwrap().data(), "the same time, the same picture");
        let mut calm = scene(0.0);
        let still = calm.snapshot().unwrap();
        LakeScene::advance(&mut calm, 3.0);
        assert!(still.data() == calm.snapshot().unwrap().data(), "a calm lake does not move");
    }

    #[test]
    fn keys_change_the_wind_and_the_noise() {
        let mut s = scene(3.0);
        let up = s.resolve(Action::Damping(false));
        assert_eq!(up, vec![Event::Wind([4.0, 0.0])]);
        s.apply(&up[0]);
        assert_eq!(s.lake().params().wind_m_s, 4.0);
        assert_eq!(s.resolve(Action::Clear), vec![Event::Wind([0.0, 0.0])]);
        assert_eq!(s.resolve(Action::Damping(true)), vec![Event::Wind([3.0, 0.0])]);
        assert_eq!(s.resolve(Action::Key('5')), vec![Event::Wind([9.4, 0.0])], "Beaufort 5 is 9.35 m/s");
        let n = s.resolve(Action::Key('n'));
        assert_eq!(n, vec![Event::Noise { octaves: 5, persistence: 0.5, kind: NoiseKind::Gradient }]);
        s.apply(&n[0]);
        assert_eq!(s.lake().params().noise, NoiseKind::Gradient);
        s.apply(&s.resolve(Action::Key('O'))[0]);
        s.apply(&s.resolve(Action::Key('>'))[0]);
        assert_eq!((s.lake().params().octaves, s.lake().params().persistence), (4, 0.55));
        assert!(s.resolve(Action::Stone { x: 1, y: 1, radius: 2, big: false }).is_empty());
        assert!(s.resolve(Action::ToggleRain).is_empty());
        assert!(!s.takes_stones());
        let mut status = String::new();
        s.status(&mut status);
        assert_eq!(status, "wind 4 m/s \u{b7} 4 octaves \u{b7} p 0.55 \u{b7} gradient");
        // Limits hold: no wind below 0, at most MAX_OCTAVES octaves; an ocean's wind from
        // another direction still sets the lake's speed.
        let mut calm = scene(0.0);
        assert_eq!(calm.resolve(Action::Damping(true)), vec![Event::Wind([0.0, 0.0])]);
        for _ in 0..20 {
            let e = calm.resolve(Action::Key('o'));
            calm.apply(&e[0]);
        }
        assert_eq!(calm.lake().params().octaves, MAX_OCTAVES as u32);
        calm.apply(&Event::Wind([50.0, 200.0]));
        assert_eq!(calm.lake().params().wind_m_s, MAX_LAKE_WIND_M_S);
        calm.apply(&Event::Resize([30, 20]));
        assert_eq!(Scene::size(&calm), (30, 20));
    }

    #[test]
    fn heightmaps_cover_the_lake() {
        let s = scene(6.0);
        let map = LakeScene::heightmap(&s, 40, 20);
        assert_eq!((map.width, map.height, map.values.len()), (40, 20, 800));
        // Cells of 15 m: row 0 is the far shore, column 0 the west edge.
        let frame = s.lake().surface(0.0);
        assert_eq!(map.values[0], frame.height(-292.5, 292.5));
        assert_eq!(map.values[19 * 40 + 39], frame.height(292.5, 7.5));
        assert!(map.values.iter().all(|v| v.abs() < 0.2));
        assert!(LakeScene::heightmap(&scene(0.0), 4, 4).values.iter().all(|&v| v == 0.0));
    }
}
