//! Gusts: the breeze as patches of ripples that rise, drift downwind and fade, as a light
//! breeze's gusts raise them on a pool (cat's paws).
//!
//! The first breeze ([`super::Breeze`]) adds short wave packets to the integer pool at once:
//! each appears whole between two frames, and its wavelets of 9 to 15 cells run 1.4 pixels a
//! frame at the player's 30 fps, so every pixel flickers several times a second. Gusts are
//! what a camera sees instead: packets whose amplitude rises and falls over seconds (a `sin²`
//! window over their life), so nothing ever appears between two frames; many of them, weaker
//! each, in directions spread around the wind, so their crests cross into a loose net.
//!
//! The gusts' ripples are not added to the integer pool: they are a height field of their
//! own, evaluated when a picture is drawn and added to the pool's heights (the scheme is
//! linear, so a stone's ring that crosses a packet keeps its shape either way). The papers'
//! integer step stays exactly as it is, a packet never needs rounding into the pool a little at
//! a time, and stepping costs nothing: only the list of live packets changes. Packets travel at
//! the scheme's own wave speed (`1/√2` cells a step), so the ripples and the rings move alike.
//!
//! A packet is a cosine under a compact envelope, `(1 - (dx/r)²)²·(1 - (dy/r)²)²` within `r` of
//! its centre and 0 beyond (the water outside every packet is exactly still, which is what an
//! encoder of changed cells needs); both factor into a function of the column times a function
//! of the row (`Re(X(x)·Y(y))` with complex `X`, `Y`), so a packet costs two multiplications and
//! a subtraction per cell it covers. Everything is `f32` through
//! `libm` in a fixed order, and the stream of packets is ChaCha8 from the scene's seed: the
//! same seed gives the same water on every machine.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The gusts' shape, in cells of a pool drawn one cell a pixel (see [`GustShape::on_grid`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GustShape {
    /// Packets alive at once per 10,000 cells, on average.
    pub packets_per_10k_cells: f64,
    /// How long a packet lives, in steps (its amplitude is `sin²(π·age/life)`).
    pub life_steps: u32,
    /// The range wavelengths are drawn from, in cells.
    pub wavelength_cells: (f32, f32),
    /// The envelope's half-width, in wavelengths.
    pub envelope_waves: f32,
    /// The crest amplitude at level 1 at the peak of a packet's life, in amplitude units.
    pub amplitude_at_level_1: f32,
    /// Where the breeze blows towards, degrees clockwise from north (the top of the picture).
    pub heading_deg: f32,
    /// The spread of packet directions either side of the heading, in degrees.
    pub spread_deg: f32,
}

impl Default for GustShape {
    /// The player's gusts: broad, low swells of light, 60 to 120 pixels long, each over a patch
    /// 1.2 wavelengths across either way of its centre, three alive per 10,000 pixels, living
    /// ten seconds at the player's 30 steps a second. Chosen by looking at 160x94 pixels on a
    /// grid of two cells a pixel, and by measuring (`tests/integration/coherence.rs`,
    /// `benches/codec.rs`): shorter wavelets, or more of them, kept the water as alive but cost
    /// the rate-controlled encoder far more (every cell they cover changes every frame), and
    /// their structure is what SSIM weighs; broad light moves are what it forgives.
    fn default() -> Self {
        GustShape {
            packets_per_10k_cells: 3.0,
            life_steps: 300,
            wavelength_cells: (60.0, 120.0),
            envelope_waves: 1.2,
            amplitude_at_level_1: 100.0,
            heading_deg: super::HEADING_DEG,
            spread_deg: 60.0,
        }
    }
}

impl GustShape {
    /// The same gusts on a pool of `grid` cells per pixel: the same packets in pixels (lengths
    /// times `grid`, the same number per pixel area); the amplitude is unchanged.
    pub fn on_grid(self, grid: u32) -> GustShape {
        let g = grid.max(1) as f32;
        GustShape {
            packets_per_10k_cells: self.packets_per_10k_cells / f64::from(g * g),
            wavelength_cells: (self.wavelength_cells.0 * g, self.wavelength_cells.1 * g),
            ..self
        }
    }
}

/// How far the scheme's waves travel per step, in cells.
const WAVE_SPEED: f32 = std::f32::consts::FRAC_1_SQRT_2;
/// Mixed into the seed so that the gusts, the first breeze and the rain of one seed differ.
const SEED_SALT: u64 = 0x0067_7573_7473; // "gusts"
/// The most packets alive at once (a bound on work per picture, whatever the pool's size).
pub const MAX_PACKETS: usize = 64;
/// The gusts' columns are added in blocks of this many ([`GustField::add_row_blocks`]): four
/// vectors of AVX-512, eight of AVX2, held in registers while every packet over the block is
/// added. Each packet's column factors start and end on a block's edge (zeros outside the
/// packet), so a block is either wholly in a packet's factors or not in them.
pub const GUST_BLOCK: usize = 64;

/// One packet: where it was born, where it goes, its wave and its strength.
// Its fields are the crate's so that the pool's snapshot (`scene/pool/state.rs`) can hold it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Packet {
    /// Its centre at birth, in cells.
    pub(crate) origin: (f32, f32),
    /// The unit direction it travels, in picture coordinates (x right, y down).
    pub(crate) direction: (f32, f32),
    pub(crate) wavenumber: f32,
    /// The envelope's half-width (it is 0 beyond), in cells.
    pub(crate) radius: f32,
    /// The crest amplitude at the peak of its life.
    pub(crate) amplitude: f32,
    /// The phase of its crests at birth.
    pub(crate) phase: f32,
    /// The step count it was born at (before 0 for the packets the gusts start with).
    pub(crate) born: i64,
}

/// Deterministic gusts: packets born at a steady rate, their strength set by the level.
#[derive(Clone, Debug)]
pub struct Gusts {
    level: f64,
    // The random source, the packets, the step and `primed` are the crate's so that the pool's
    // snapshot (`scene/pool/state.rs`) can hold them.
    pub(crate) rng: ChaCha8Rng,
    shape: GustShape,
    pub(crate) packets: Vec<Packet>,
    /// Steps run.
    pub(crate) step: i64,
    /// Whether the first packets were drawn (the gusts start as if the breeze had always blown).
    pub(crate) primed: bool,
    /// The live packets' factors for the picture being drawn.
    factors: GustFactors,
}

impl Gusts {
    /// Gusts of `level` (0: none; negative, NaN or infinite count as 0; levels above the
    /// breeze's maximum are lowered to it), its packets drawn from `seed`.
    pub fn new(level: f64, seed: u64, shape: GustShape) -> Gusts {
        Gusts {
            level: super::sanitize(level),
            rng: ChaCha8Rng::seed_from_u64(seed ^ SEED_SALT),
            shape,
            packets: Vec::with_capacity(MAX_PACKETS),
            step: 0,
            primed: false,
            factors: GustFactors::default(),
        }
    }

    /// The level in effect (for packets born from now on).
    pub fn level(&self) -> f64 {
        self.level
    }

    /// Changes the level of the packets born from now on; the packets alive live out their
    /// lives (a breeze that drops fades, it does not stop between two frames).
    pub fn set_level(&mut self, level: f64) {
        self.level = super::sanitize(level);
    }

    /// Whether any packet is alive.
    #[cfg(test)]
    pub fn is_calm(&self) -> bool {
        self.packets.is_empty()
    }

    /// Stills the gusts: every packet is gone (new ones are born as before).
    pub fn clear(&mut self) {
        self.packets.clear();
    }

    /// Runs one step on a `width x height` pool: packets at the end of their lives go, and a
    /// new one may be born. Draws nothing from the generator at level 0.
    pub fn step(&mut self, width: usize, height: usize) {
        self.step += 1;
        let (now, life) = (self.step, i64::from(self.shape.life_steps.max(1)));
        self.packets.retain(|p| now - p.born < life);
        if self.level <= 0.0 || width < 3 || height < 3 {
            return;
        }
        let interior = ((width - 2) * (height - 2)) as f64;
        let alive = self.shape.packets_per_10k_cells.max(0.0) * interior / 10_000.0;
        if !self.primed {
            // The packets a breeze that had always blown would have now, at every age.
            self.primed = true;
            for _ in 0..(alive.round() as usize).min(MAX_PACKETS) {
                // Its centre in mid-life is spread over the pool whatever its age.
                let mut packet = self.packet(width, height);
                packet.born = now - self.rng.random_range(0..life);
                self.packets.push(packet);
            }
        }
        let births = alive / life as f64;
        let whole = births.floor();
        let mut count = whole as u64;
        if self.rng.random::<f64>() < births - whole {
            count += 1;
        }
        for _ in 0..count {
            let packet = self.packet(width, height);
            if self.packets.len() < MAX_PACKETS {
                self.packets.push(packet);
            }
        }
    }

    /// Draws one packet for a `width x height` pool, born now. Its centre is drawn so that
    /// the middle of its drift, not its birth place, is spread evenly over the pool.
    fn packet(&mut self, width: usize, height: usize) -> Packet {
        let shape = self.shape;
        let x = self.rng.random_range(1.0..(width - 1) as f64) as f32;
        let y = self.rng.random_range(1.0..(height - 1) as f64) as f32;
        let spread = self.rng.random_range(-1.0..1.0f64) as f32 * shape.spread_deg;
        let (shortest, longest) = shape.wavelength_cells;
        let wavelength = (shortest + (longest - shortest) * self.rng.random::<f32>()).max(2.0);
        let strength = self.rng.random_range(0.5..1.0f64) as f32;
        let phase = self.rng.random_range(0.0..std::f64::consts::TAU) as f32;
        let heading = (shape.heading_deg + spread).to_radians();
        let direction = (libm::sinf(heading), -libm::cosf(heading));
        let half_drift = WAVE_SPEED * shape.life_steps as f32 / 2.0;
        Packet {
            origin: (x - direction.0 * half_drift, y - direction.1 * half_drift),
            direction,
            wavenumber: std::f32::consts::TAU / wavelength,
            radius: (shape.envelope_waves * wavelength).max(1.0),
            amplitude: shape.amplitude_at_level_1 * self.level as f32 * strength,
            phase,
            born: self.step,
        }
    }

    /// Adds the gusts' heights now to `field`, a `width x height` pool row by row. The
    /// ripples run under the pool's walls (the outermost cells) too: they are drawn, not
    /// simulated, and ripples cut off at the wall would draw a false crease along it.
    pub fn add_to(&mut self, field: &mut [f32], width: usize, height: usize) {
        assert_eq!(field.len(), width * height, "the field is the pool's size");
        let gusts = self.field(width, height);
        for (y, row) in field.chunks_exact_mut(width.max(1)).enumerate() {
            gusts.add_row(y, row);
        }
    }

    /// The gusts' heights now on a `width x height` pool, ready to be added row by row
    /// ([`GustField::add_row`], from any thread): each live packet's column and row factors
    /// are computed once here.
    pub fn field(&mut self, width: usize, height: usize) -> GustField<'_> {
        let GustFactors { patches, real, imaginary } = &mut self.factors;
        patches.clear();
        real.clear();
        imaginary.clear();
        // Room for the most packets there can be, each at its widest, from the first frame: no
        // later frame allocates when more packets are alive than before (reserved, the pages
        // untouched until used).
        patches.reserve(MAX_PACKETS);
        let most = MAX_PACKETS * (width + 2 * GUST_BLOCK + height);
        real.reserve(most.saturating_sub(real.len()));
        imaginary.reserve(most.saturating_sub(imaginary.len()));
        let life = self.shape.life_steps.max(1) as f32;
        for p in &self.packets {
            let age = (self.step - p.born) as f32;
            let window = libm::sinf(std::f32::consts::PI * age / life);
            let amplitude = p.amplitude * window * window;
            let travelled = WAVE_SPEED * age;
            let centre = (p.origin.0 + p.direction.0 * travelled, p.origin.1 + p.direction.1 * travelled);
            let reach = p.radius;
            let span = |c: f32, n: usize| {
                let lo = ((c - reach).floor() as i64).clamp(0, n as i64) as usize;
                let hi = ((c + reach).ceil() as i64 + 1).clamp(0, n as i64) as usize;
                lo..hi
            };
            let (xs, ys) = (span(centre.0, width), span(centre.1, height));
            if xs.is_empty() || ys.is_empty() || amplitude == 0.0 {
                continue;
            }
            // cos(k·d·(p - c) + φ)·env(p - c) = Re(X(x)·Y(y)), with the amplitude and the phase
            // in the row factor.
            let factor = |offset: f32, along: f32| {
                let u = (offset / p.radius) * (offset / p.radius);
                let envelope = if u < 1.0 { (1.0 - u) * (1.0 - u) } else { 0.0 };
                let angle = p.wavenumber * along * offset;
                (envelope * libm::cosf(angle), envelope * libm::sinf(angle))
            };
            // Zeros from the block edge before the packet's first column and after its last
            // up to the next (see `GUST_BLOCK`).
            let columns = real.len();
            let first = xs.start / GUST_BLOCK * GUST_BLOCK;
            let blocks = first..xs.end.next_multiple_of(GUST_BLOCK);
            real.resize(columns + (xs.start - first), 0.0);
            imaginary.resize(columns + (xs.start - first), 0.0);
            for x in xs.clone() {
                let (re, im) = factor(x as f32 - centre.0, p.direction.0);
                real.push(re);
                imaginary.push(im);
            }
            real.resize(columns + blocks.len(), 0.0);
            imaginary.resize(columns + blocks.len(), 0.0);
            let rows = real.len();
            let (pc, ps) = (amplitude * libm::cosf(p.phase), amplitude * libm::sinf(p.phase));
            for y in ys.clone() {
                let (c, s) = factor(y as f32 - centre.1, p.direction.1);
                real.push(c * pc - s * ps);
                imaginary.push(c * ps + s * pc);
            }
            patches.push(Patch { columns: blocks, rows: ys, column_factors: columns, row_factors: rows });
        }
        GustField { patches, real, imaginary }
    }
}

/// Where one live packet draws: the cells it covers and where its factors are.
#[derive(Clone, Debug, Default)]
struct Patch {
    /// The columns of its factors: the columns it covers widened to whole [`GUST_BLOCK`]s
    /// (the factors are zero outside the packet).
    columns: std::ops::Range<usize>,
    rows: std::ops::Range<usize>,
    /// Where its column factors (one a column) and its row factors (one a row) start in
    /// [`GustFactors`]'s lists.
    column_factors: usize,
    row_factors: usize,
}

/// The live packets' factors for one picture, kept between frames for their allocations.
#[derive(Clone, Debug, Default)]
struct GustFactors {
    patches: Vec<Patch>,
    /// The factors' real and imaginary parts, the packets' columns and rows one after another.
    real: Vec<f32>,
    imaginary: Vec<f32>,
}

/// The gusts' heights at one step, ready to be added to a field row by row (see
/// [`Gusts::field`]).
#[derive(Clone, Copy, Debug)]
pub struct GustField<'a> {
    patches: &'a [Patch],
    real: &'a [f32],
    imaginary: &'a [f32],
}

impl GustField<'_> {
    /// Adds the gusts' heights in row `y` to `row` (the pool's width): every packet that covers
    /// the row in the order they were born, so each cell sums the same terms in the same order
    /// whichever rows are drawn together and on whichever thread.
    ///
    /// A packet's factors reach past its cells to whole blocks (`GUST_BLOCK`), zeros there:
    /// adding a zero leaves every cell as it is (a sum that starts at +0 never becomes -0, and
    /// +0 + ±0 is +0), so the cells the factors cover beyond the packet add nothing.
    #[inline(always)]
    pub fn add_row(&self, y: usize, row: &mut [f32]) {
        for p in self.patches {
            if !p.rows.contains(&y) {
                continue;
            }
            let at = p.row_factors + (y - p.rows.start);
            let (yr, yi) = (self.real[at], self.imaginary[at]);
            let end = p.columns.end.min(row.len());
            let out = &mut row[p.columns.start.min(end)..end];
            let n = out.len();
            let xr = &self.real[p.column_factors..p.column_factors + n];
            let xi = &self.imaginary[p.column_factors..p.column_factors + n];
            for i in 0..n {
                out[i] += xr[i] * yr - xi[i] * yi;
            }
        }
    }

    /// [`GustField::add_row`] for a `row` of whole blocks (`GUST_BLOCK`) that holds every
    /// packet's factors (the pool's width rounded up to a block): the same sums, a block at a
    /// time, each block's sums kept in registers while every packet over it is added (one
    /// packet at a time over the whole row loaded and stored the row once a packet).
    #[inline(always)]
    pub fn add_row_blocks(&self, y: usize, row: &mut [f32]) {
        // The packets over this row, in the order they were born: (their factors' columns,
        // where their column factors start, their row factor).
        let mut active = [((0, 0), 0, 0.0f32, 0.0f32); MAX_PACKETS];
        let mut count = 0;
        for p in self.patches.iter().filter(|p| p.rows.contains(&y)) {
            let at = p.row_factors + (y - p.rows.start);
            active[count] = ((p.columns.start, p.columns.end), p.column_factors, self.real[at], self.imaginary[at]);
            count += 1;
        }
        let active = &active[..count];
        for (b, block) in row.chunks_exact_mut(GUST_BLOCK).enumerate() {
            let x0 = b * GUST_BLOCK;
            let mut sums: [f32; GUST_BLOCK] = block.try_into().expect("a block");
            for &((start, end), factors, yr, yi) in active {
                if !(start..end).contains(&x0) {
                    continue;
                }
                let at = factors + (x0 - start);
                let xr: &[f32; GUST_BLOCK] = self.real[at..at + GUST_BLOCK].try_into().expect("a block");
                let xi: &[f32; GUST_BLOCK] = self.imaginary[at..at + GUST_BLOCK].try_into().expect("a block");
                for i in 0..GUST_BLOCK {
                    sums[i] += xr[i] * yr - xi[i] * yi;
                }
            }
            block.copy_from_slice(&sums);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(level: f64, seed: u64, steps: usize) -> (Gusts, Vec<f32>) {
        let (w, h) = (160, 94);
        let mut gusts = Gusts::new(level, seed, GustShape::default());
        for _ in 0..steps {
            gusts.step(w, h);
        }
        let mut field = vec![0.0; w * h];
        gusts.add_to(&mut field, w, h);
        (gusts, field)
    }

    #[test]
    fn level_zero_is_still_water() {
        let (gusts, field) = run(0.0, 1, 600);
        assert!(gusts.is_calm() && field.iter().all(|&v| v == 0.0));
    }

    #[test]
    fn same_seed_same_gusts() {
        assert!(run(1.0, 5, 400).1 == run(1.0, 5, 400).1, "the same seed, the same swells");
        assert!(run(1.0, 5, 400).1 != run(1.0, 6, 400).1, "another seed, other swells");
    }

    #[test]
    fn a_packet_is_born_flat_and_rises_over_seconds() {
        // Nothing appears between two frames: a packet adds nothing at birth, a sliver of its
        // crest one frame (two steps) later, and its full crest half a life later.
        let (w, h) = (160, 94);
        let mut gusts = Gusts::new(1.0, 3, GustShape::default());
        gusts.step(w, h);
        let primed = gusts.packets.len();
        while gusts.packets.len() <= primed {
            gusts.step(w, h);
        }
        let newest = *gusts.packets.last().unwrap();
        let alone = |age: i64| {
            let mut one = Gusts::new(1.0, 3, GustShape::default());
            one.packets.push(newest);
            one.step = newest.born + age;
            let mut field = vec![0.0; w * h];
            one.add_to(&mut field, w, h);
            field.iter().fold(0f32, |m, v| m.max(v.abs()))
        };
        let peak = alone(i64::from(GustShape::default().life_steps) / 2);
        assert!(peak > 5.0, "a grown packet moves the water: {peak}");
        assert_eq!(alone(0), 0.0, "born flat");
        assert!(alone(2) < 0.01 * peak, "one frame old: {} of {peak}", alone(2));
    }

    #[test]
    fn packets_travel_downwind_at_the_schemes_speed() {
        let mut gusts = Gusts::new(1.0, 9, GustShape::default());
        let mut p = gusts.packet(400, 400);
        p.origin = (200.0 - 80.0 * p.direction.0, 200.0 - 80.0 * p.direction.1);
        (p.wavenumber, p.radius) = (std::f32::consts::TAU / 20.0, 24.0);
        gusts.packets.push(p);
        let centroid = |gusts: &mut Gusts| {
            let mut field = vec![0.0; 400 * 400];
            gusts.add_to(&mut field, 400, 400);
            let (mut sx, mut sy, mut total) = (0.0f64, 0.0f64, 0.0f64);
            for (i, &v) in field.iter().enumerate() {
                let e = f64::from(v) * f64::from(v);
                (sx, sy, total) = (sx + e * (i % 400) as f64, sy + e * (i / 400) as f64, total + e);
            }
            (sx / total, sy / total)
        };
        for _ in 0..60 {
            gusts.step(0, 0); // no births on an empty pool
        }
        let a = centroid(&mut gusts);
        for _ in 0..100 {
            gusts.step(0, 0);
        }
        let b = centroid(&mut gusts);
        let moved = ((b.0 - a.0) * f64::from(p.direction.0) + (b.1 - a.1) * f64::from(p.direction.1)) / 100.0;
        assert!((moved - f64::from(WAVE_SPEED)).abs() < 0.02, "{moved} cells a step");
    }

    #[test]
    fn the_shape_scales_with_the_grid() {
        let s = GustShape::default().on_grid(2);
        assert_eq!(s.wavelength_cells, (120.0, 240.0));
        assert_eq!(s.packets_per_10k_cells, GustShape::default().packets_per_10k_cells / 4.0);
    }
}
