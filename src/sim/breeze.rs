//! A light breeze over the ripple pool: the ambient excitation that keeps water alive at rest.
//!
//! A real pool in daylight is never still: gusts of a light breeze raise patches of fine
//! wavelets that run downwind, and the floor's caustic net dances under them. The breeze adds
//! such wave packets to the pool at random places and times: each is a few wavelengths of a
//! cosine under a Gaussian envelope, launched so that it travels one way (downwind, give or
//! take [`GUST_SPREAD_DEG`]), by adding it to the current amplitudes and its image half a
//! step upwind to the previous ones (the scheme's waves run at `1/√2` cells a step). Packets
//! are added, not set like stones, so a stone's ring that a packet crosses keeps its shape.
//!
//! Everything is drawn from a ChaCha8 stream seeded by the scene's seed (mixed with a constant,
//! so the breeze and the rain of one seed are independent) and the arithmetic is `f32` through
//! the `libm` crate: the same seed gives the same water on every machine. A level of 0 draws
//! nothing and adds nothing: the papers' still water, bit for bit.
//!
//! The numbers were tuned by looking at the pool's renderer at 160x94 pixels with the
//! player's damping (see `examples/alive_pool.rs`).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::ripple::RipplePool;

pub mod gusts;

/// How a breeze moves the pool.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BreezeStyle {
    /// Short wave packets added to the integer pool at once, here and there: the
    /// first breeze, what a replay without a style means.
    #[default]
    Wavelets,
    /// Broad swells of light that rise and fade over seconds as they drift downwind, drawn
    /// over the water rather than added to it: water that moves like water filmed at 30 fps.
    Gusts,
}

impl BreezeStyle {
    /// The style's name on the command line and in replays.
    pub fn name(self) -> &'static str {
        match self {
            BreezeStyle::Wavelets => "wavelets",
            BreezeStyle::Gusts => "gusts",
        }
    }
}

impl std::fmt::Display for BreezeStyle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for BreezeStyle {
    type Err = crate::error::ValueError;

    /// `gusts` or `wavelets`.
    fn from_str(text: &str) -> Result<BreezeStyle, Self::Err> {
        match text.trim() {
            "wavelets" => Ok(BreezeStyle::Wavelets),
            "gusts" => Ok(BreezeStyle::Gusts),
            other => Err(crate::error::ValueError::new(
                "breeze style",
                format!("'{other}' is not a breeze style; use 'gusts' (ripples that rise and fade) or 'wavelets'"),
            )),
        }
    }
}

/// Parses a breeze level, `0..=``MAX_LEVEL` (0 is the papers' still water).
pub fn parse_level(text: &str) -> Result<f64, crate::error::ValueError> {
    check_level(crate::numbers::finite(text, "breeze", "1")?)
}

/// Checks a breeze level.
pub fn check_level(level: f64) -> Result<f64, crate::error::ValueError> {
    if !(0.0..=MAX_LEVEL).contains(&level) {
        return Err(crate::error::ValueError::new(
            "breeze",
            format!("the breeze {level} is outside 0..={MAX_LEVEL}; 0 is still water, 1 a light breeze"),
        ));
    }
    Ok(level)
}

/// The level of a light breeze, the player's default.
pub const DEFAULT_LEVEL: f64 = 1.0;
/// The strongest breeze: beyond it the wavelets drown the stones' rings.
pub const MAX_LEVEL: f64 = 4.0;
/// Packets launched per step per 10,000 interior cells, at any level.
pub const PACKETS_PER_10K_CELLS: f64 = 0.8;
/// The crest amplitude of a packet at level 1, in amplitude units (a player's stone is 48).
pub const AMPLITUDE_AT_LEVEL_1: f32 = 10.0;
/// Wavelengths are drawn between these, in cells. The caustics smooth away detail under about
/// eight cells, so shorter wavelets would only jitter the refraction.
pub const WAVELENGTH_CELLS: (f32, f32) = (9.0, 15.0);
/// The envelope's standard deviation along the travel direction, in wavelengths.
pub const PACKET_LENGTH_WAVES: f32 = 0.9;
/// The envelope's standard deviation across the travel direction, in wavelengths.
pub const PACKET_WIDTH_WAVES: f32 = 1.4;
/// The direction the breeze blows towards, degrees clockwise from north (the top of the
/// picture): from the upper left, like the default sun.
pub const HEADING_DEG: f32 = 135.0;
/// Each packet's direction differs from the heading by up to this much either way.
pub const GUST_SPREAD_DEG: f32 = 35.0;

/// The breeze's shape: the constants above, gathered so that a caller can try others.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BreezeShape {
    /// Packets per step per 10,000 interior cells.
    pub packets_per_10k_cells: f64,
    /// Crest amplitude at level 1, in amplitude units.
    pub amplitude_at_level_1: f32,
    /// The range wavelengths are drawn from, in cells.
    pub wavelength_cells: (f32, f32),
    /// Envelope length along the travel direction, in wavelengths.
    pub packet_length_waves: f32,
    /// Envelope width across the travel direction, in wavelengths.
    pub packet_width_waves: f32,
    /// Where the breeze blows towards, degrees clockwise from north.
    pub heading_deg: f32,
    /// The spread of packet directions either side of the heading, in degrees.
    pub gust_spread_deg: f32,
}

impl Default for BreezeShape {
    fn default() -> Self {
        BreezeShape {
            packets_per_10k_cells: PACKETS_PER_10K_CELLS,
            amplitude_at_level_1: AMPLITUDE_AT_LEVEL_1,
            wavelength_cells: WAVELENGTH_CELLS,
            packet_length_waves: PACKET_LENGTH_WAVES,
            packet_width_waves: PACKET_WIDTH_WAVES,
            heading_deg: HEADING_DEG,
            gust_spread_deg: GUST_SPREAD_DEG,
        }
    }
}

impl BreezeShape {
    /// The same breeze on a pool of `grid` cells per pixel: the same packets in pixels
    /// (lengths times `grid`, the same number per pixel area). Grid 1 is this shape unchanged.
    pub fn on_grid(self, grid: u32) -> BreezeShape {
        if grid <= 1 {
            return self;
        }
        let g = grid as f32;
        BreezeShape {
            packets_per_10k_cells: self.packets_per_10k_cells / f64::from(g * g),
            wavelength_cells: (self.wavelength_cells.0 * g, self.wavelength_cells.1 * g),
            ..self
        }
    }
}

/// How far the scheme's waves travel per step, in cells: `c² dt² / dx² = 1/2`.
const WAVE_SPEED: f32 = std::f32::consts::FRAC_1_SQRT_2;
/// The envelope is cut off this many standard deviations out.
const ENVELOPE_CUTOFF: f32 = 3.0;
/// Mixed into the seed so that the breeze and the rain of the same seed are independent.
const SEED_SALT: u64 = 0x6272_6565_7a65; // "breeze"

/// A deterministic breeze: wave packets at a steady rate, their strength set by the level.
#[derive(Clone, Debug)]
pub struct Breeze {
    level: f64,
    /// Read and set by the pool's snapshot (`scene/pool/state.rs`).
    pub(crate) rng: ChaCha8Rng,
    shape: BreezeShape,
}

impl Breeze {
    /// A breeze of `level` (0 = still water; negative, NaN or infinite count as 0; levels over
    /// [`MAX_LEVEL`] are lowered to it), its gusts drawn from `seed`.
    #[cfg(test)]
    pub fn new(level: f64, seed: u64) -> Breeze {
        Breeze::with_shape(level, seed, BreezeShape::default())
    }

    /// [`Breeze::new`] with another shape than the tuned default.
    pub fn with_shape(level: f64, seed: u64, shape: BreezeShape) -> Breeze {
        Breeze { level: sanitize(level), rng: ChaCha8Rng::seed_from_u64(seed ^ SEED_SALT), shape }
    }

    /// The level in effect.
    pub fn level(&self) -> f64 {
        self.level
    }

    /// Changes the level; the random stream continues where it was.
    pub fn set_level(&mut self, level: f64) {
        self.level = sanitize(level);
    }

    /// Adds one step's worth of breeze to `pool`: call it once per simulation step, before the
    /// step (where the rain's drops land). Draws nothing from the generator at level 0.
    pub fn excite(&mut self, pool: &mut RipplePool) {
        let (width, height) = (pool.width(), pool.height());
        if self.level <= 0.0 || width < 3 || height < 3 {
            return;
        }
        let interior = ((width - 2) * (height - 2)) as f64;
        let rate = self.shape.packets_per_10k_cells.max(0.0) * interior / 10_000.0;
        let whole = rate.floor();
        let mut count = whole as u64;
        if self.rng.random::<f64>() < rate - whole {
            count += 1;
        }
        for _ in 0..count {
            let packet = self.packet(width, height);
            packet.add_to(pool);
        }
    }

    /// Draws one packet somewhere on a `width x height` pool.
    fn packet(&mut self, width: usize, height: usize) -> Packet {
        let x = self.rng.random_range(1.0..(width - 1) as f64) as f32;
        let y = self.rng.random_range(1.0..(height - 1) as f64) as f32;
        let shape = self.shape;
        let spread = self.rng.random_range(-1.0..1.0f64) as f32 * shape.gust_spread_deg;
        let (shortest, longest) = shape.wavelength_cells;
        let wavelength = (shortest + (longest - shortest) * self.rng.random::<f32>()).max(2.0);
        let strength = self.rng.random_range(0.5..1.0f64) as f32;
        let heading = (shape.heading_deg + spread).to_radians();
        Packet {
            centre: (x, y),
            // Clockwise from north in picture coordinates (x right, y down).
            direction: (libm::sinf(heading), -libm::cosf(heading)),
            wavenumber: std::f32::consts::TAU / wavelength,
            length: (shape.packet_length_waves * wavelength).max(1.0),
            width: (shape.packet_width_waves * wavelength).max(1.0),
            amplitude: shape.amplitude_at_level_1 * self.level as f32 * strength,
        }
    }
}

/// One wave packet: `amplitude · cos(k s) · exp(-(s/length)²/2 - (t/width)²/2)`, with `s`
/// along the travel direction from the centre and `t` across it.
#[derive(Clone, Copy, Debug)]
struct Packet {
    centre: (f32, f32),
    direction: (f32, f32),
    wavenumber: f32,
    length: f32,
    width: f32,
    amplitude: f32,
}

impl Packet {
    /// The packet's height at `(s, t)`.
    fn height(&self, s: f32, t: f32) -> f32 {
        let (a, b) = (s / self.length, t / self.width);
        self.amplitude * libm::cosf(self.wavenumber * s) * libm::expf(-0.5 * (a * a + b * b))
    }

    /// Adds the packet to the current amplitudes and its position one step ago (upwind by the
    /// wave speed) to the previous ones, so that it runs downwind.
    fn add_to(&self, pool: &mut RipplePool) {
        let reach = ENVELOPE_CUTOFF * self.length.max(self.width);
        let (cx, cy) = self.centre;
        let from = ((cx - reach).floor() as i64, (cy - reach).floor() as i64);
        let to = ((cx + reach).ceil() as i64 + 1, (cy + reach).ceil() as i64 + 1);
        let (dx, dy) = self.direction;
        pool.disturb(from, to, |x, y| {
            let (rx, ry) = (x as f32 - cx, y as f32 - cy);
            let s = rx * dx + ry * dy;
            let t = ry * dx - rx * dy;
            let now = self.height(s, t);
            let before = self.height(s + WAVE_SPEED, t);
            (now.round() as i16, before.round() as i16)
        });
    }
}

fn sanitize(level: f64) -> f64 {
    if level.is_finite() && level > 0.0 { level.min(MAX_LEVEL) } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::ripple::Damping;

    fn breezy(level: f64, seed: u64, steps: usize) -> RipplePool {
        let mut pool = RipplePool::new(160, 94, Damping::from_shift(6).unwrap());
        let mut breeze = Breeze::new(level, seed);
        for _ in 0..steps {
            breeze.excite(&mut pool);
            pool.step();
        }
        pool
    }

    #[test]
    fn level_zero_is_still_water() {
        let pool = breezy(0.0, 1, 200);
        assert!(pool.heights().iter().all(|&v| v == 0));
        assert_eq!(Breeze::new(f64::NAN, 1).level(), 0.0);
        assert_eq!(Breeze::new(-3.0, 1).level(), 0.0);
        assert_eq!(Breeze::new(99.0, 1).level(), MAX_LEVEL);
    }

    #[test]
    fn same_seed_same_water() {
        assert_eq!(breezy(1.0, 5, 120).heights(), breezy(1.0, 5, 120).heights());
        assert_ne!(breezy(1.0, 5, 120).heights(), breezy(1.0, 6, 120).heights());
    }

    #[test]
    fn the_whole_pool_moves_and_stronger_breezes_move_it_more() {
        let energy = |p: &RipplePool| p.heights().iter().map(|&v| i64::from(v).abs()).sum::<i64>();
        let light = breezy(1.0, 3, 600);
        let strong = breezy(3.0, 3, 600);
        assert!(energy(&strong) > 2 * energy(&light), "{} vs {}", energy(&strong), energy(&light));
        // Every 20x20 block of the pool has wavelets after ten seconds.
        let (w, h) = (light.width(), light.height());
        for by in 0..h / 20 {
            for bx in 0..w / 20 {
                let moving = (by * 20..by * 20 + 20)
                    .flat_map(|y| (bx * 20..bx * 20 + 20).map(move |x| (x, y)))
                    .any(|(x, y)| light.heights()[y * w + x].abs() >= 2);
                assert!(moving, "block ({bx}, {by}) is still");
            }
        }
    }

    #[test]
    fn packets_run_downwind() {
        // One packet in a big still pool: after 60 steps its energy has moved along the
        // heading (towards the lower right) by roughly the wave speed times the steps.
        // Damped: undamped, the papers' rounding lets the mean level sink (see sim::ripple).
        let mut pool = RipplePool::new(200, 200, Damping::from_shift(7).unwrap());
        let packet = Packet {
            centre: (100.0, 100.0),
            direction: (libm::sinf(HEADING_DEG.to_radians()), -libm::cosf(HEADING_DEG.to_radians())),
            wavenumber: std::f32::consts::TAU / 12.0,
            length: 0.9 * 12.0,
            width: 1.4 * 12.0,
            amplitude: 400.0,
        };
        packet.add_to(&mut pool);
        pool.advance(60);
        let (mut sx, mut sy, mut total) = (0.0f64, 0.0f64, 0.0f64);
        for (i, &v) in pool.heights().iter().enumerate() {
            let e = f64::from(v) * f64::from(v);
            sx += e * (i % 200) as f64;
            sy += e * (i / 200) as f64;
            total += e;
        }
        let (mx, my) = (sx / total - 100.0, sy / total - 100.0);
        let along = (mx + my) / 2f64.sqrt();
        assert!(along > 20.0, "the energy moved {along:.1} cells downwind ({mx:.1}, {my:.1})");
        assert!((mx - my).abs() < 8.0, "and not sideways ({mx:.1}, {my:.1})");
    }
}
