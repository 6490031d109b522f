//! The ripple pool scene: the simulation, its rain, and the floor it refracts.

use tiny_skia::Pixmap;

use super::Heightmap;
use super::{Action, Controls, Event, Scene, SceneKind};
use crate::error::{Error, Result};
use crate::render::background;
use crate::render::pool::{Fields, PoolLook, PoolRenderer};
use crate::sim::breeze::gusts::{GustShape, Gusts};
use crate::sim::breeze::{Breeze, BreezeStyle};
use crate::sim::rain::Rain;
use crate::sim::ripple::{Damping, RipplePool, Stone};
use crate::simd::Simd;
use compose::{Composer, Sources};

/// Everything about a pool except its size.
#[derive(Clone, Debug, PartialEq)]
pub struct PoolSettings {
    /// Damping of the water.
    pub damping: Damping,
    /// Raindrops per step on average (0 for none; at most 10,000).
    pub rain_rate: f64,
    /// The breeze's level (0: the papers' still water; at most 4).
    pub breeze: f64,
    /// How the breeze moves the water: the first breeze's short wavelets, or gusts.
    pub breeze_style: BreezeStyle,
    /// Simulation cells per picture pixel along each axis, `1..=``MAX_GRID`: 1 is the
    /// papers' pool (its cells are its pixels); a finer grid moves the waves `1/grid` pixels a
    /// step and draws each pixel as the mean of its cells.
    pub grid: u32,
    /// Simulation steps per second of real time, `1..=``MAX_STEPS_PER_SECOND` (the player's
    /// pace; animations follow it): waves move `0.7/grid` pixels a step.
    pub steps_per_second: u32,
    /// Seed of the rain.
    pub seed: u64,
    /// How the water is drawn.
    pub look: PoolLook,
    /// The floor seen through the water, scaled to cover the picture.
    pub floor: Pixmap,
}

impl Default for PoolSettings {
    /// The papers' damping, no rain, no breeze, one cell a pixel, seed 1, the default look over
    /// the built-in tiled floor.
    fn default() -> Self {
        PoolSettings {
            damping: Damping::PAPERS,
            rain_rate: 0.0,
            breeze: 0.0,
            breeze_style: BreezeStyle::default(),
            grid: 1,
            steps_per_second: POOL_STEPS_PER_SECOND as u32,
            seed: 1,
            look: PoolLook::default(),
            floor: background::pool_floor(),
        }
    }
}

impl PoolSettings {
    /// The built-in pool floor (square tiles with grout, `assets/pool_floor.png`), the floor of
    /// [`PoolSettings::default`].
    pub fn default_floor() -> Pixmap {
        background::pool_floor()
    }
}

/// The most simulation steps a second.
pub const MAX_STEPS_PER_SECOND: u32 = 240;

/// Checks a pace (simulation steps per second).
pub fn check_steps_per_second(steps: u64) -> std::result::Result<u32, crate::error::ValueError> {
    match u32::try_from(steps) {
        Ok(s) if (1..=MAX_STEPS_PER_SECOND).contains(&s) => Ok(s),
        _ => Err(crate::error::ValueError::new(
            "steps per second",
            format!(
                "{steps} steps a second is outside 1..={MAX_STEPS_PER_SECOND}; the papers' pool runs 60, the player's 30"
            ),
        )),
    }
}

/// Parses a pace: a whole number of simulation steps a second, `1..=``MAX_STEPS_PER_SECOND`.
pub fn parse_steps_per_second(text: &str) -> std::result::Result<u32, crate::error::ValueError> {
    let steps: u64 = text.trim().parse().map_err(|_| {
        crate::error::ValueError::new("steps per second", format!("'{text}' is not a whole number of steps, e.g. 30"))
    })?;
    check_steps_per_second(steps)
}

/// Height units per amplitude unit of the pictures of a pool with gusts: the gusts' ripples
/// are smooth, and rounding them to whole amplitude units would flicker a unit here and there
/// every frame as they move (a unit of slope is a step of shading), which costs every cell
/// on the wire and looks like grain. The pool's own heights are whole units; piles of stones
/// deeper than 32767 / 4 saturate in the picture (not in the water).
pub const GUST_UNITS: u32 = 4;

/// How much of the gusts' swells displaces the floor (all of them light it), a departure from
/// optics chosen by measuring: the floor's tiles are drawn sharp, and a swell sliding them a
/// fraction of a pixel changes their edges' pixels every frame, structure that a slow link
/// cannot keep up with (SSIM at 50 kB/s 0.70 with the full displacement, 0.73 with this share,
/// on the codec benchmark's pool), while the light a swell focuses drifts smoothly.
pub const GUST_REFRACTION: f32 = 0.3;

/// The units of the pictures of a pool whose breeze is `style`.
fn units_for(style: BreezeStyle) -> u32 {
    match style {
        BreezeStyle::Wavelets => 1,
        BreezeStyle::Gusts => GUST_UNITS,
    }
}

/// The finest simulation grid, in cells per pixel along each axis.
pub const MAX_GRID: u32 = 4;

/// Parses a grid: a whole number of simulation cells per picture pixel, `1..=``MAX_GRID`.
pub fn parse_grid(text: &str) -> std::result::Result<u32, crate::error::ValueError> {
    let grid: u64 = text.trim().parse().map_err(|_| {
        crate::error::ValueError::new("grid", format!("'{text}' is not a whole number of cells per pixel, e.g. 2"))
    })?;
    check_grid(grid)
}

/// Checks a grid (simulation cells per picture pixel).
pub fn check_grid(grid: u64) -> std::result::Result<u32, crate::error::ValueError> {
    match u32::try_from(grid) {
        Ok(g) if (1..=MAX_GRID).contains(&g) => Ok(g),
        _ => Err(crate::error::ValueError::new(
            "grid",
            format!("the grid {grid} is outside 1..={MAX_GRID} simulation cells per pixel; 1 is the papers' pool"),
        )),
    }
}

/// The breeze of a pool, in the style its settings ask for.
#[derive(Clone, Debug)]
enum Wind {
    Wavelets(Breeze),
    Gusts(Gusts),
}

impl Wind {
    fn new(style: BreezeStyle, level: f64, seed: u64, grid: u32) -> Wind {
        match style {
            BreezeStyle::Wavelets => Wind::Wavelets(Breeze::with_shape(
                level,
                seed,
                crate::sim::breeze::BreezeShape::default().on_grid(grid),
            )),
            BreezeStyle::Gusts => Wind::Gusts(Gusts::new(level, seed, GustShape::default().on_grid(grid))),
        }
    }

    fn level(&self) -> f64 {
        match self {
            Wind::Wavelets(b) => b.level(),
            Wind::Gusts(s) => s.level(),
        }
    }

    fn set_level(&mut self, level: f64) {
        match self {
            Wind::Wavelets(b) => b.set_level(level),
            Wind::Gusts(s) => s.set_level(level),
        }
    }
}

/// A ripple pool with its rain and floor, `grid x grid` simulation cells a pixel.
#[derive(Clone, Debug)]
pub struct PoolScene {
    pool: RipplePool,
    rain: Rain,
    wind: Wind,
    renderer: PoolRenderer,
    floor: Pixmap,
    drops: Vec<Stone>,
    /// The picture's size in pixels.
    size: (u32, u32),
    grid: u32,
    steps_per_second: u32,
    /// The pool's heights with the gusts' ripples added ([`GUST_UNITS`] a unit), all of them
    /// (`field`) and [`GUST_REFRACTION`] of them (`refraction`); `composer` makes them.
    field: Vec<i16>,
    refraction: Vec<i16>,
    composer: Composer,
    simd: Simd,
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
/// The papers' pool runs at 60 steps a second: waves cross a 160-pixel terminal in ~4 s (in
/// ~8 s on a grid of two cells a pixel).
pub const POOL_STEPS_PER_SECOND: f64 = 60.0;

impl PoolScene {
    /// A still pool of `width x height` pixels.
    ///
    /// Returns `None` when the size is zero or too large for a pixmap (at the simulation's
    /// resolution), or the grid or the pace is out of range.
    pub fn new(width: u32, height: u32, settings: PoolSettings) -> Option<PoolScene> {
        let grid = check_grid(u64::from(settings.grid)).ok()?;
        let steps_per_second = check_steps_per_second(u64::from(settings.steps_per_second)).ok()?;
        let (cols, rows) = (width.checked_mul(grid)?, height.checked_mul(grid)?);
        let fitted = background::cover(&settings.floor, cols, rows)?;
        Some(PoolScene {
            pool: RipplePool::new(cols as usize, rows as usize, settings.damping),
            rain: Rain::new(settings.rain_rate, settings.seed),
            wind: Wind::new(settings.breeze_style, settings.breeze, settings.seed, grid),
            renderer: PoolRenderer::on_grid(fitted, settings.look, grid, units_for(settings.breeze_style)),
            floor: settings.floor,
            drops: Vec::new(),
            size: (width, height),
            grid,
            steps_per_second,
            field: Vec::new(),
            refraction: Vec::new(),
            composer: Composer::default(),
            simd: Simd::detect(),
            rain_when_on: if settings.rain_rate > 0.0 { settings.rain_rate } else { DEFAULT_TOGGLE_RAIN },
            breeze_when_on: if settings.breeze > 0.0 { settings.breeze } else { crate::sim::breeze::DEFAULT_LEVEL },
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.size.0
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.size.1
    }

    /// Simulation cells per pixel along each axis.
    pub fn grid(&self) -> u32 {
        self.grid
    }

    /// The water (`grid` times the picture's size in cells).
    #[cfg(any(test, feature = "testing"))]
    pub fn pool(&self) -> &RipplePool {
        &self.pool
    }

    #[cfg(any(test, feature = "testing"))]
    /// Runs the simulation and the picture with another instruction set this CPU runs (every
    /// one gives the same water and the same pixels; the default is [`Simd::detect`]).
    pub fn set_simd(&mut self, simd: Simd) {
        self.pool.set_simd(simd);
        self.renderer.set_simd(simd);
        self.simd = simd;
    }

    /// Drops a stone now; its centre and radius are in pixels (on a finer grid it covers the
    /// same pixels' cells).
    pub fn drop_stone(&mut self, stone: Stone) {
        self.pool.drop_stone(self.in_cells(stone));
    }

    /// A stone given in pixels, in the simulation's cells.
    fn in_cells(&self, stone: Stone) -> Stone {
        match self.grid {
            1 => stone,
            g => {
                let centre = |v: i32| v.saturating_mul(g as i32).saturating_add(g as i32 / 2);
                Stone::clamped(centre(stone.x()), centre(stone.y()), stone.radius().saturating_mul(g), stone.weight())
            }
        }
    }

    /// `steps` simulation steps: each step the breeze adds its wave packets (or the gusts
    /// age), the raindrops land, then the water moves.
    ///
    /// The rain is drawn step by step (so the random stream is the same as single steps), and
    /// the calm runs between raindrops go to [`RipplePool::advance`] in one piece, which
    /// computes them many times faster than single steps. The first breeze's wavelets touch
    /// every step, so with them the steps run one at a time; the gusts are not in the pool.
    pub fn advance(&mut self, steps: u64) {
        let (width, height) = (self.size.0 as usize, self.size.1 as usize);
        let (cols, rows) = (self.pool.width(), self.pool.height());
        let wavelets = matches!(&self.wind, Wind::Wavelets(b) if b.level() > 0.0);
        let mut calm = 0;
        for _ in 0..steps {
            if let Wind::Gusts(gusts) = &mut self.wind {
                gusts.step(cols, rows);
            }
            self.drops.clear();
            self.rain.drops(width, height, &mut self.drops);
            if self.drops.is_empty() && !wavelets {
                calm += 1;
                continue;
            }
            self.pool.advance(calm);
            calm = 0;
            if let Wind::Wavelets(breeze) = &mut self.wind {
                breeze.excite(&mut self.pool);
            }
            for k in 0..self.drops.len() {
                let drop = self.in_cells(self.drops[k]);
                self.pool.drop_stone(drop);
            }
            self.pool.advance(1);
        }
        self.pool.advance(calm);
    }

    /// Height units per amplitude unit of the picture's heights.
    fn units(&self) -> u32 {
        match self.wind {
            Wind::Wavelets(_) => 1,
            Wind::Gusts(_) => GUST_UNITS,
        }
    }

    /// With gusts, the heights the picture shows, in [`GUST_UNITS`] a unit: the pool's and
    /// the gusts' ripples in `self.field` (they light the floor), and in `self.refraction` the
    /// pool's with [`GUST_REFRACTION`] of the ripples (they displace it). Returns whether it
    /// made them (otherwise the picture shows the pool's own heights).
    fn compose(&mut self) -> bool {
        let Wind::Gusts(gusts) = &mut self.wind else { return false };
        let (cols, rows) = (self.pool.width(), self.pool.height());
        let sources = Sources { gusts: gusts.field(cols, rows), heights: self.pool.heights(), cols };
        self.composer.compose(sources, (&mut self.field, &mut self.refraction), self.simd);
        true
    }

    /// Draws the current water into `out`, which must have the scene's size.
    pub fn render(&mut self, out: &mut Pixmap) {
        let fields = match self.compose() {
            true => Fields { refraction: &self.refraction, light: &self.field },
            false => Fields { refraction: self.pool.heights(), light: self.pool.heights() },
        };
        self.renderer.render_fields(fields, out);
    }

    /// Starts over at a new size: still water, the floor refitted, the rain continuing.
    ///
    /// Returns `false` (and changes nothing) when the size is zero or too large.
    pub fn resize(&mut self, width: u32, height: u32) -> bool {
        let g = self.grid;
        let Some((cols, rows)) = width.checked_mul(g).zip(height.checked_mul(g)) else {
            return false;
        };
        let Some(fitted) = background::cover(&self.floor, cols, rows) else {
            return false;
        };
        let damping = self.pool.damping();
        self.pool = RipplePool::new(cols as usize, rows as usize, damping);
        self.renderer = PoolRenderer::on_grid(fitted, self.renderer.look(), g, self.units());
        self.size = (width, height);
        if let Wind::Gusts(gusts) = &mut self.wind {
            gusts.clear();
        }
        true
    }

    /// The current heights as a heightmap, one value per simulation cell (raw amplitude
    /// units, one PNG level each; the gusts' ripples included).
    pub fn heightmap(&self) -> Heightmap {
        let mut values: Vec<f32> = self.pool.heights().iter().map(|&v| f32::from(v)).collect();
        if let Wind::Gusts(gusts) = &self.wind {
            let mut gusts = gusts.clone();
            gusts.add_to(&mut values, self.pool.width(), self.pool.height());
        }
        Heightmap { width: self.pool.width(), height: self.pool.height(), values, png_levels_per_unit: 1.0 }
    }
}

impl PoolScene {
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
}

impl Scene for PoolScene {
    fn kind(&self) -> SceneKind {
        SceneKind::Pool
    }

    fn size(&self) -> (u32, u32) {
        (self.width(), self.height())
    }

    fn steps_per_second(&self) -> f64 {
        f64::from(self.steps_per_second)
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
                self.wind.set_level(level);
            }
            Event::Clear => {
                self.pool.clear();
                if let Wind::Gusts(gusts) = &mut self.wind {
                    gusts.clear();
                }
            }
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
                let level = if self.wind.level() > 0.0 { 0.0 } else { self.breeze_when_on };
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
        if self.wind.level() > 0.0 {
            let _ = write!(out, " \u{b7} breeze {}", self.wind.level());
        }
        let _ = write!(out, " \u{b7} damping {}", self.pool.damping());
    }

    fn help(&self) -> Vec<(&'static str, &'static str)> {
        vec![("r", "rain on/off"), ("b", "breeze on/off"), ("c", "clear the water"), ("[ ]", "damp more / less")]
    }
}

mod compose;
mod state;
#[cfg(test)]
mod tests;
