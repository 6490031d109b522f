//! The ripple pool scene: the simulation, its rain, and the floor it refracts.

use tiny_skia::Pixmap;

use super::Heightmap;
use super::{Action, Controls, Event, Scene, SceneKind};
use crate::error::{Error, Result};
use crate::render::background;
use crate::render::pool::{PoolLook, PoolRenderer};
use crate::sim::breeze::Breeze;
use crate::sim::rain::Rain;
use crate::sim::ripple::{Damping, RipplePool, Stone};
use crate::simd::Simd;

/// Everything about a pool except its size.
#[derive(Clone, Debug, PartialEq)]
pub struct PoolSettings {
    /// Damping of the water.
    pub damping: Damping,
    /// Raindrops per step on average (0 for none; at most 10,000).
    pub rain_rate: f64,
    /// The breeze's level (0: the papers' still water; at most 4).
    pub breeze: f64,
    /// Seed of the rain.
    pub seed: u64,
    /// How the water is drawn.
    pub look: PoolLook,
    /// The floor seen through the water, scaled to cover the picture.
    pub floor: Pixmap,
}

impl Default for PoolSettings {
    /// The papers' damping, no rain, no breeze, seed 1, the default look over the built-in tiled
    /// floor.
    fn default() -> Self {
        PoolSettings {
            damping: Damping::PAPERS,
            rain_rate: 0.0,
            breeze: 0.0,
            seed: 1,
            look: PoolLook::default(),
            floor: background::pool_floor(),
        }
    }
}

/// A ripple pool with its rain and floor, one simulation cell per pixel.
#[derive(Clone, Debug)]
pub struct PoolScene {
    pool: RipplePool,
    rain: Rain,
    breeze: Breeze,
    renderer: PoolRenderer,
    floor: Pixmap,
    drops: Vec<Stone>,
    /// The rate `r` switches the rain back on to.
    rain_when_on: f64,
    /// The level `b` switches the breeze back on to.
    breeze_when_on: f64,
}

/// The rain rate the player's `r` key switches on when the pool started without rain.
pub const DEFAULT_TOGGLE_RAIN: f64 = 0.02;
/// The weight of a stone dropped by the player. With the papers' integer damping a ring of
/// weight 48 is flattened within a second (small amplitudes lose a unit a step), so it neither
/// crosses the pool nor stands out from the breeze; a ring of 128 crosses most of a
/// 160-pixel pool and dominates the wavelets.
pub const PLAYER_STONE_WEIGHT: i16 = 128;
/// A right click drops a stone this many times wider and twice as heavy.
pub const BIG_STONE_FACTOR: u32 = 2;
/// Stirring drops small light stones this many pixels apart along the drag.
const STIR_SPACING: f32 = 2.0;
/// The weight of the small stones of a stir.
const STIR_WEIGHT: i16 = 32;
/// The papers' pool runs at 60 steps a second: waves cross a 160-pixel terminal in ~4 s.
pub const POOL_STEPS_PER_SECOND: f64 = 60.0;

impl PoolScene {
    /// A still pool of `width x height` pixels.
    ///
    /// Returns `None` when the size is zero or too large for a pixmap.
    pub fn new(width: u32, height: u32, settings: PoolSettings) -> Option<PoolScene> {
        let fitted = background::cover(&settings.floor, width, height)?;
        Some(PoolScene {
            pool: RipplePool::new(width as usize, height as usize, settings.damping),
            rain: Rain::new(settings.rain_rate, settings.seed),
            breeze: Breeze::new(settings.breeze, settings.seed),
            renderer: PoolRenderer::new(fitted, settings.look),
            floor: settings.floor,
            drops: Vec::new(),
            rain_when_on: if settings.rain_rate > 0.0 { settings.rain_rate } else { DEFAULT_TOGGLE_RAIN },
            breeze_when_on: if settings.breeze > 0.0 { settings.breeze } else { crate::sim::breeze::DEFAULT_LEVEL },
        })
    }

    /// Width in pixels (= cells).
    pub fn width(&self) -> u32 {
        self.pool.width() as u32
    }

    /// Height in pixels (= cells).
    pub fn height(&self) -> u32 {
        self.pool.height() as u32
    }

    /// The water.
    pub fn pool(&self) -> &RipplePool {
        &self.pool
    }

    /// Runs the simulation and the picture with another instruction set this CPU runs (every
    /// one gives the same water and the same pixels; the default is [`Simd::detect`]).
    pub fn set_simd(&mut self, simd: Simd) {
        self.pool.set_simd(simd);
        self.renderer.set_simd(simd);
    }

    /// Drops a stone now.
    pub fn drop_stone(&mut self, stone: Stone) {
        self.pool.drop_stone(stone);
    }

    /// `steps` simulation steps: each step the breeze adds its wave packets, the raindrops
    /// land, then the water moves.
    ///
    /// The rain is drawn step by step (so the random stream is the same as single steps), and
    /// the calm runs between raindrops go to [`RipplePool::advance`] in one piece, which
    /// computes them many times faster than single steps. A breeze touches every step, so with
    /// one the steps run one at a time.
    pub fn advance(&mut self, steps: u64) {
        let (width, height) = (self.pool.width(), self.pool.height());
        let breezy = self.breeze.level() > 0.0;
        let mut calm = 0;
        for _ in 0..steps {
            self.drops.clear();
            self.rain.drops(width, height, &mut self.drops);
            if self.drops.is_empty() && !breezy {
                calm += 1;
                continue;
            }
            self.pool.advance(calm);
            calm = 0;
            self.breeze.excite(&mut self.pool);
            for &drop in &self.drops {
                self.pool.drop_stone(drop);
            }
            self.pool.advance(1);
        }
        self.pool.advance(calm);
    }

    /// Draws the current water into `out`, which must have the scene's size.
    pub fn render(&mut self, out: &mut Pixmap) {
        self.renderer.render(&self.pool, out);
    }

    /// Starts over at a new size: still water, the floor refitted, the rain continuing.
    ///
    /// Returns `false` (and changes nothing) when the size is zero or too large.
    pub fn resize(&mut self, width: u32, height: u32) -> bool {
        let Some(fitted) = background::cover(&self.floor, width, height) else {
            return false;
        };
        let damping = self.pool.damping();
        self.pool = RipplePool::new(width as usize, height as usize, damping);
        self.renderer = PoolRenderer::new(fitted, self.renderer.look());
        true
    }

    /// The current amplitudes as a heightmap (raw amplitude units, one PNG level each).
    pub fn heightmap(&self) -> Heightmap {
        Heightmap {
            width: self.pool.width(),
            height: self.pool.height(),
            values: self.pool.heights().iter().map(|&v| f32::from(v)).collect(),
            png_levels_per_unit: 1.0,
        }
    }
}

/// The default picture's stones, as events at their steps, and the step the picture is taken
/// at, for a `width x height` pool: six stones falling one after another in a cluster, so the
/// picture shows young and old rings overlapping.
///
/// A ring lives about a hundred steps at the papers' damping whatever the picture's size, so
/// the cluster is laid out in pixels for a 360-pixel picture and shrunk (never enlarged) to fit
/// smaller ones, and the picture is taken after 90 steps at 360 pixels and above, fewer (at
/// least 30) for smaller pictures, whose rings have less room.
pub fn showcase(width: u32, height: u32) -> (Vec<(u64, Event)>, u64) {
    let scale = (width.min(height) as f32 / 360.0).min(1.0);
    let steps_scale = scale.max(1.0 / 3.0);
    let (cx, cy) = (width as f32 / 2.0, height as f32 / 2.0);
    // (step at scale 1, x, y offsets from the centre and radius, in pixels at scale 1)
    let script: [(f32, f32, f32, f32); 6] = [
        (0.0, -70.0, -40.0, 4.0),
        (0.0, 30.0, -10.0, 4.0),
        (15.0, -20.0, 45.0, 3.0),
        (30.0, 95.0, -55.0, 3.0),
        (50.0, -120.0, 35.0, 3.0),
        (65.0, 70.0, 55.0, 2.0),
    ];
    let stones = script
        .iter()
        .map(|&(step, dx, dy, r)| {
            let stone = Stone::clamped(
                (cx + dx * scale) as i32,
                (cy + dy * scale) as i32,
                (r * scale.sqrt()).round().max(2.0) as u32,
                160,
            );
            ((step * steps_scale) as u64, Event::Stone(stone))
        })
        .collect();
    (stones, (90.0 * steps_scale).round() as u64)
}

impl Scene for PoolScene {
    fn kind(&self) -> SceneKind {
        SceneKind::Pool
    }

    fn size(&self) -> (u32, u32) {
        (self.width(), self.height())
    }

    fn steps_per_second(&self) -> f64 {
        POOL_STEPS_PER_SECOND
    }

    fn advance(&mut self, steps: u64) {
        PoolScene::advance(self, steps);
    }

    fn render(&mut self, out: &mut Pixmap) {
        PoolScene::render(self, out);
    }

    fn apply(&mut self, event: &Event) {
        match *event {
            Event::Stone(stone) => self.drop_stone(stone),
            Event::Rain(rate) => {
                if rate > 0.0 {
                    self.rain_when_on = rate;
                }
                self.rain.set_rate(rate);
            }
            Event::Damping(d) => self.pool.set_damping(d),
            Event::Breeze(level) => {
                if level > 0.0 {
                    self.breeze_when_on = level;
                }
                self.breeze.set_level(level);
            }
            Event::Clear => self.pool.clear(),
            Event::Resize([w, h]) => {
                PoolScene::resize(self, w, h);
            }
            Event::Screenshot(_) | Event::Wind(_) | Event::Noise { .. } | Event::End => {}
        }
    }

    fn resize(&mut self, width: u32, height: u32) -> Result<()> {
        match PoolScene::resize(self, width, height) {
            true => Ok(()),
            false => Err(Error::TooLarge { what: "pool", width, height }),
        }
    }

    /// The pool's own cells, whatever size is asked for.
    fn heightmap(&self, _width: usize, _height: usize) -> Heightmap {
        PoolScene::heightmap(self)
    }
}

impl Controls for PoolScene {
    fn resolve(&self, action: Action) -> Vec<Event> {
        match action {
            Action::Stone { x, y, radius, big } => {
                let (radius, weight) = if big {
                    (radius * BIG_STONE_FACTOR, PLAYER_STONE_WEIGHT.saturating_mul(2))
                } else {
                    (radius, PLAYER_STONE_WEIGHT)
                };
                vec![Event::Stone(Stone::clamped(x, y, radius, weight))]
            }
            Action::Stir { from, to } => {
                let (dx, dy) = ((to.0 - from.0) as f32, (to.1 - from.1) as f32);
                let n = ((dx.hypot(dy) / STIR_SPACING).ceil() as i32).clamp(1, 512);
                (1..=n)
                    .map(|i| {
                        let t = i as f32 / n as f32;
                        let x = from.0 + (dx * t).round() as i32;
                        let y = from.1 + (dy * t).round() as i32;
                        Event::Stone(Stone::clamped(x, y, 2, STIR_WEIGHT))
                    })
                    .collect()
            }
            Action::ToggleRain => {
                let rate = if self.rain.rate() > 0.0 { 0.0 } else { self.rain_when_on };
                vec![Event::Rain(rate)]
            }
            Action::Clear => vec![Event::Clear],
            Action::Damping(stronger) => {
                let d = self.pool.damping();
                vec![Event::Damping(if stronger { d.stronger() } else { d.weaker() })]
            }
            Action::Key('b') => {
                let level = if self.breeze.level() > 0.0 { 0.0 } else { self.breeze_when_on };
                vec![Event::Breeze(level)]
            }
            Action::Key(_) => Vec::new(),
        }
    }

    fn status(&self, out: &mut String) {
        use std::fmt::Write;
        out.clear();
        let _ = match self.rain.rate() {
            rate if rate > 0.0 => write!(out, "rain {rate}"),
            _ => write!(out, "rain off"),
        };
        if self.breeze.level() > 0.0 {
            let _ = write!(out, " \u{b7} breeze {}", self.breeze.level());
        }
        let _ = write!(out, " \u{b7} damping {}", self.pool.damping());
    }

    fn help(&self) -> Vec<(&'static str, &'static str)> {
        vec![("r", "rain on/off"), ("b", "breeze on/off"), ("c", "clear the water"), ("[ ]", "damp more / less")]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(rain_rate: f64) -> PoolSettings {
        PoolSettings { rain_rate, seed: 7, ..PoolSettings::default() }
    }

    #[test]
    fn rain_moves_the_water_deterministically() {
        let run = || {
            let mut scene = PoolScene::new(64, 48, settings(0.5)).unwrap();
            for _ in 0..40 {
                scene.advance(1);
            }
            scene.snapshot().unwrap().data().to_vec()
        };
        let still = PoolScene::new(64, 48, settings(0.0)).unwrap().snapshot().unwrap();
        assert_eq!(run(), run());
        assert_ne!(run(), still.data());
    }

    /// The stepper, the refraction rows and the caustics give the same bytes on every
    /// instruction set this CPU runs, at terminal size and at a size whose caustics are
    /// computed at half resolution on several threads.
    #[test]
    fn every_simd_tier_draws_the_same_pixels() {
        for (w, h) in [(160u32, 94u32), (1024, 600)] {
            let run = |simd: Simd| {
                let mut scene = PoolScene::new(w, h, settings(0.4)).unwrap();
                scene.set_simd(simd);
                for k in 0..12 {
                    scene.drop_stone(Stone::clamped((k * 37 % w) as i32, (k * 53 % h) as i32, 5, 300));
                    scene.advance(7);
                }
                (scene.pool().heights().to_vec(), scene.snapshot().unwrap().data().to_vec())
            };
            let portable = run(Simd::PORTABLE);
            for simd in Simd::supported() {
                let (heights, pixels) = run(simd);
                assert!(heights == portable.0, "{w}x{h}: the water on {simd} differs from portable");
                assert!(pixels == portable.1, "{w}x{h}: the picture on {simd} differs from portable");
            }
        }
    }

    #[test]
    fn advance_equals_single_steps() {
        let mut stepped = PoolScene::new(80, 60, settings(0.3)).unwrap();
        let mut advanced = stepped.clone();
        for _ in 0..77 {
            stepped.advance(1);
        }
        advanced.advance(77);
        assert_eq!(stepped.pool().heights(), advanced.pool().heights());
        assert_eq!(stepped.pool().steps(), 77);
        assert_eq!(advanced.pool().steps(), 77);
    }

    #[test]
    fn resize_reallocates() {
        let mut scene = PoolScene::new(64, 48, settings(0.0)).unwrap();
        scene.drop_stone(Stone { x: 10, y: 10, radius: 4, weight: 64 });
        assert!(PoolScene::resize(&mut scene, 30, 20));
        assert_eq!((scene.width(), scene.height()), (30, 20));
        assert!(scene.pool().heights().iter().all(|&v| v == 0));
        assert_eq!(scene.snapshot().unwrap().width(), 30);
        assert!(Scene::resize(&mut scene, 0, 10).is_err());
        assert_eq!(scene.width(), 30);
    }

    #[test]
    fn actions_resolve_to_events_that_apply() {
        let mut scene = PoolScene::new(40, 30, settings(0.0)).unwrap();
        let events = scene.resolve(Action::Stone { x: 10, y: 12, radius: 3, big: true });
        assert_eq!(events, vec![Event::Stone(Stone::new(10, 12, 6, 256).unwrap())]);
        scene.apply(&events[0]);
        assert!(scene.pool().heights()[12 * 40 + 10] < 0);
        let stir = scene.resolve(Action::Stir { from: (5, 5), to: (15, 5) });
        assert_eq!(stir.len(), 5);
        assert_eq!(stir[4], Event::Stone(Stone::clamped(15, 5, 2, STIR_WEIGHT)));
        let rain = scene.resolve(Action::ToggleRain);
        assert_eq!(rain, vec![Event::Rain(DEFAULT_TOGGLE_RAIN)]);
        scene.apply(&rain[0]);
        assert_eq!(scene.resolve(Action::ToggleRain), vec![Event::Rain(0.0)]);
        let damping = scene.resolve(Action::Damping(true));
        assert_eq!(damping, vec![Event::Damping(Damping::from_shift(4).unwrap())]);
        scene.apply(&Event::Clear);
        assert!(scene.pool().heights().iter().all(|&v| v == 0));
        scene.apply(&Event::Resize([20, 10]));
        assert_eq!(Scene::size(&scene), (20, 10));
        assert!(scene.resolve(Action::Key('w')).is_empty());
        let mut status = String::new();
        scene.status(&mut status);
        assert!(status.contains("rain 0.02"));
    }

    #[test]
    fn the_showcase_stays_inside_small_pictures() {
        for (w, h) in [(1, 1), (80, 48), (4000, 300)] {
            let (stones, steps) = showcase(w, h);
            assert!((30..=90).contains(&steps));
            for (at, event) in stones {
                let Event::Stone(s) = event else { panic!("stones only") };
                assert!(s.x() >= 0 && s.y() >= 0 && s.x() < w as i32 && s.y() < h as i32);
                assert!((2..=1000).contains(&s.radius()) && at < steps);
            }
        }
    }

    #[test]
    fn heightmap_mirrors_the_amplitudes() {
        let mut scene = PoolScene::new(10, 8, settings(0.0)).unwrap();
        scene.drop_stone(Stone { x: 4, y: 3, radius: 1, weight: 99 });
        let map = scene.heightmap();
        assert_eq!((map.width, map.height), (10, 8));
        assert_eq!(map.values[3 * 10 + 4], -99.0);
    }
}
