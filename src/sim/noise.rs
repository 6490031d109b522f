//! Lattice noise in the manner of the lake paper (`docs/ALGORITHMS.md` §2.2): a seeded integer hash on
//! the lattice, the 3x3 smoothing the paper describes, cosine interpolation along x then y, and a fractal
//! sum of octaves with a persistence; plus the gradient-lattice variant of its figure 1.
//!
//! Time is a third lattice axis: the 2-D noise of time slice `floor(t)` and of the next slice
//! are cosine-interpolated, so the field changes smoothly and never repeats. [`WaterNoise`]
//! animates a fractal as water moves: each octave drifts in its own direction (spread around
//! the wind's) at the phase speed of a water wave twice its lattice spacing long, and passes
//! one time slice per period of that wave, so coarse octaves glide and fine ones flicker.
//!
//! Everything is in f32 except the drift offsets, which are kept as whole cells plus a
//! fraction so that `--time 1e7` is as detailed as `--time 0`.

use std::f32::consts::PI;

/// The most octaves a fractal sums (the 12th of a 1 m lattice is 0.5 mm).
pub const MAX_OCTAVES: usize = 12;

/// Which lattice noise.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NoiseKind {
    /// Hashed values at lattice points, smoothed 3x3, cosine-interpolated (the default).
    #[default]
    Value,
    /// Hashed unit gradients at lattice points; each corner contributes dot(gradient, offset).
    Gradient,
}

impl NoiseKind {
    /// The name the command line uses.
    pub fn name(self) -> &'static str {
        match self {
            NoiseKind::Value => "value",
            NoiseKind::Gradient => "gradient",
        }
    }

    /// The mean of noise² over the plane (measured over 2 million samples; checked by the
    /// test `variance_and_slope_constants_hold`).
    pub fn variance(self) -> f32 {
        match self {
            NoiseKind::Value => VALUE_VARIANCE,
            NoiseKind::Gradient => GRADIENT_VARIANCE,
        }
    }

    /// The mean of (∂noise/∂x)² per lattice cell, the same along y (measured likewise).
    pub fn slope_variance(self) -> f32 {
        match self {
            NoiseKind::Value => VALUE_SLOPE_VARIANCE,
            NoiseKind::Gradient => GRADIENT_SLOPE_VARIANCE,
        }
    }
}

impl std::fmt::Display for NoiseKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for NoiseKind {
    type Err = crate::error::ValueError;

    /// `value` or `gradient`.
    fn from_str(text: &str) -> Result<NoiseKind, Self::Err> {
        match text {
            "value" => Ok(NoiseKind::Value),
            "gradient" => Ok(NoiseKind::Gradient),
            other => Err(crate::error::ValueError::new(
                "noise kind",
                format!("unknown kind \"{other}\"; use \"value\" or \"gradient\""),
            )),
        }
    }
}

const VALUE_VARIANCE: f32 = 0.0396;
const VALUE_SLOPE_VARIANCE: f32 = 0.0353;
const GRADIENT_VARIANCE: f32 = 0.0901;
const GRADIENT_SLOPE_VARIANCE: f32 = 0.671;

/// A 64-bit seed folded into the 32 bits the hash takes (splitmix64's finaliser), so that
/// nearby seeds give unrelated fields.
pub fn fold_seed(seed: u64) -> u32 {
    let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    (z ^ (z >> 31)) as u32
}

/// The integer noise: the lattice point (x, y, z) and a seed to 31 bits.
///
/// `n = (n << 13) ^ n; n·(n²·15731 + 789221) + 1376312589`, masked to 31 bits, with the
/// coordinates mixed by the primes 1619, 31337 and 6971 (the classic tutorial form `x + 57·y`
/// repeats along the lines where `x + 57·y` is constant; the paper's own formula did not
/// survive in its text). Wrapping arithmetic throughout: the same input
/// gives the same output on every machine.
#[inline(always)]
pub fn hash(seed: u32, x: i32, y: i32, z: i32) -> u32 {
    let n = (x as u32)
        .wrapping_mul(1619)
        .wrapping_add((y as u32).wrapping_mul(31337))
        .wrapping_add((z as u32).wrapping_mul(6971))
        .wrapping_add(seed.wrapping_mul(1013));
    let n = (n << 13) ^ n;
    n.wrapping_mul(n.wrapping_mul(n).wrapping_mul(15731).wrapping_add(789_221)).wrapping_add(1_376_312_589)
        & 0x7fff_ffff
}

/// The pseudo-random value of a lattice point, in [-1, 1].
#[inline(always)]
pub fn lattice_value(seed: u32, x: i32, y: i32, z: i32) -> f32 {
    1.0 - hash(seed, x, y, z) as f32 / 1_073_741_824.0
}

#[cfg(test)]
/// The smoothing of a lattice value the paper describes: corners/16 + sides/8 + centre/4 over the 3x3
/// neighbourhood (the weights sum to 1, so the result stays in [-1, 1]).
pub fn smoothed_value(seed: u32, x: i32, y: i32, z: i32) -> f32 {
    let v = |dx: i32, dy: i32| lattice_value(seed, x.wrapping_add(dx), y.wrapping_add(dy), z);
    let corners = (v(-1, -1) + v(1, -1) + v(-1, 1) + v(1, 1)) / 16.0;
    let sides = (v(-1, 0) + v(1, 0) + v(0, -1) + v(0, 1)) / 8.0;
    corners + sides + v(0, 0) / 4.0
}

/// The cosine interpolation weight of a fraction t in [0, 1]: (1 - cos πt) / 2.
#[inline(always)]
pub fn cosine_weight(t: f32) -> f32 {
    (1.0 - (PI * t).cos()) * 0.5
}

/// Cosine interpolation from `a` (t = 0) to `b` (t = 1).
#[inline(always)]
#[cfg(test)]
pub fn cosine_interpolate(a: f32, b: f32, t: f32) -> f32 {
    lerp(a, b, cosine_weight(t))
}

#[inline(always)]
fn lerp(a: f32, b: f32, w: f32) -> f32 {
    a + (b - a) * w
}

/// A point of one octave in lattice units: whole cells (wrapping) plus a fraction in [0, 1).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cell {
    ix: i32,
    iy: i32,
    fx: f32,
    fy: f32,
}

impl Cell {
    #[inline(always)]
    fn at(x: f32, y: f32) -> Cell {
        let (flx, fly) = (x.floor(), y.floor());
        Cell { ix: flx as i32, iy: fly as i32, fx: x - flx, fy: y - fly }
    }

    /// Moves the cell by whole lattice steps (wrapping, like the hash).
    #[inline(always)]
    fn shifted(self, dx: i32, dy: i32) -> Cell {
        Cell { ix: self.ix.wrapping_add(dx), iy: self.iy.wrapping_add(dy), ..self }
    }
}

/// Value noise of one time slice at a cell, with the x and y weights precomputed.
#[inline(always)]
fn value_slice(seed: u32, c: Cell, z: i32, wx: f32, wy: f32) -> f32 {
    // The four smoothed corners share a 4x4 block of raw lattice values: 16 hashes, not 36.
    let mut raw = [[0.0f32; 4]; 4];
    for (j, row) in raw.iter_mut().enumerate() {
        for (i, v) in row.iter_mut().enumerate() {
            *v = lattice_value(seed, c.ix.wrapping_add(i as i32 - 1), c.iy.wrapping_add(j as i32 - 1), z);
        }
    }
    let s = |i: usize, j: usize| {
        let corners = (raw[j - 1][i - 1] + raw[j - 1][i + 1] + raw[j + 1][i - 1] + raw[j + 1][i + 1]) / 16.0;
        let sides = (raw[j][i - 1] + raw[j][i + 1] + raw[j - 1][i] + raw[j + 1][i]) / 8.0;
        corners + sides + raw[j][i] / 4.0
    };
    lerp(lerp(s(1, 1), s(2, 1), wx), lerp(s(1, 2), s(2, 2), wx), wy)
}

/// 32 unit gradients evenly around the circle.
fn gradients() -> &'static [[f32; 2]; 32] {
    static TABLE: std::sync::OnceLock<[[f32; 2]; 32]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        std::array::from_fn(|i| {
            let a = (i as f32 + 0.5) * 2.0 * PI / 32.0;
            [a.cos(), a.sin()]
        })
    })
}

/// Gradient noise of one time slice: D1..D4 = dot(gradient, offset to the point) at the four
/// corners, cosine-interpolated, scaled by √2 so that it spans [-1, 1].
#[inline(always)]
fn gradient_slice(seed: u32, c: Cell, z: i32, wx: f32, wy: f32) -> f32 {
    let g = gradients();
    let d = |i: i32, j: i32| {
        let h = hash(seed, c.ix.wrapping_add(i), c.iy.wrapping_add(j), z);
        let v = g[(h >> 7) as usize & 31];
        v[0] * (c.fx - i as f32) + v[1] * (c.fy - j as f32)
    };
    std::f32::consts::SQRT_2 * lerp(lerp(d(0, 0), d(1, 0), wx), lerp(d(0, 1), d(1, 1), wx), wy)
}

#[inline(always)]
fn slice(kind: NoiseKind, seed: u32, c: Cell, z: i32, wx: f32, wy: f32) -> f32 {
    match kind {
        NoiseKind::Value => value_slice(seed, c, z, wx, wy),
        NoiseKind::Gradient => gradient_slice(seed, c, z, wx, wy),
    }
}

/// One octave at a cell and a time (slice `z` plus the fraction `ft`).
///
/// With `keep_variance` the two slices are blended as `((1-w)·a + w·b) / √((1-w)² + w²)`:
/// a plain blend of two independent slices has only half their variance halfway between
/// them, so animated water would visibly calm and roughen at every slice's rhythm. The
/// divisor is smooth and at least √½, so the blend stays continuous, within √2 of the slices'
/// range (and in practice well inside [-1, 1]).
#[inline(always)]
fn noise_at(kind: NoiseKind, seed: u32, c: Cell, z: i32, ft: f32, keep_variance: bool) -> f32 {
    let (wx, wy) = (cosine_weight(c.fx), cosine_weight(c.fy));
    let a = slice(kind, seed, c, z, wx, wy);
    if ft == 0.0 {
        return a;
    }
    let w = cosine_weight(ft);
    let blend = lerp(a, slice(kind, seed, c, z.wrapping_add(1), wx, wy), w);
    if keep_variance { blend / ((1.0 - w) * (1.0 - w) + w * w).sqrt() } else { blend }
}

/// The noise at (x, y) lattice units and time `t` (in time slices): in [-1, 1], continuous,
/// equal to `smoothed_value` at lattice points of whole time slices (value noise) or 0
/// there (gradient noise).
pub fn noise(kind: NoiseKind, seed: u32, x: f32, y: f32, t: f32) -> f32 {
    let z = t.floor();
    noise_at(kind, seed, Cell::at(x, y), z as i32, t - z, false)
}

/// A fractal sum of octaves: `Σ pⁱ · noise(2ⁱ·x, 2ⁱ·y, t)` for i below `octaves`, each octave
/// with its own seed (so octaves are not copies of one pattern lined up at the origin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fractal {
    /// The lattice noise.
    pub kind: NoiseKind,
    /// The seed.
    pub seed: u64,
    /// Octaves summed, 1..=[`MAX_OCTAVES`].
    pub octaves: u32,
    /// The amplitude ratio of each octave to the previous one (the paper's p).
    pub persistence: f32,
}

impl Fractal {
    /// The seed of octave `i`.
    pub fn octave_seed(&self, i: u32) -> u32 {
        fold_seed(self.seed.wrapping_add(u64::from(i).wrapping_mul(0x1000_0000_0001)))
    }

    /// Octaves actually summed (clamped to 1..=[`MAX_OCTAVES`]).
    pub fn octave_count(&self) -> usize {
        (self.octaves as usize).clamp(1, MAX_OCTAVES)
    }

    /// The sum at (x, y) lattice units of octave 0 and time slice `t`.
    pub fn sample(&self, x: f32, y: f32, t: f32) -> f32 {
        let mut sum = 0.0;
        let mut amplitude = 1.0;
        let mut frequency = 1.0;
        for i in 0..self.octave_count() {
            sum += amplitude * noise(self.kind, self.octave_seed(i as u32), x * frequency, y * frequency, t);
            amplitude *= self.persistence;
            frequency *= 2.0;
        }
        sum
    }

    /// The largest |sample| can be: Σ pⁱ.
    pub fn bound(&self) -> f32 {
        (0..self.octave_count()).map(|i| self.persistence.powi(i as i32)).sum()
    }

    /// The expected mean of sample² (octaves are independent): Σ p²ⁱ · variance.
    pub fn variance(&self) -> f32 {
        let p2 = self.persistence * self.persistence;
        (0..self.octave_count()).map(|i| p2.powi(i as i32)).sum::<f32>() * self.kind.variance()
    }
}

/// A fractal that moves like water: heights in lattice-noise units over metres and seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WaterNoise {
    /// The octaves.
    pub fractal: Fractal,
    /// Lattice spacing of octave 0, m; octave i has `spacing_m / 2ⁱ`.
    pub spacing_m: f32,
    /// Drift speed of octave 0, m/s; octave i drifts at `speed_m_s / √(2ⁱ)` (the phase speed
    /// of deep-water waves goes as the square root of their length).
    pub speed_m_s: f32,
    /// Where the drift goes, radians anticlockwise from east (-π/2 is south).
    pub heading_rad: f32,
    /// How far each octave's own direction may stray from `heading_rad`, radians.
    pub spread_rad: f32,
}

/// One octave of a [`WaterNoise`] at one moment, ready to sample.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct OctaveFrame {
    seed: u32,
    cells_per_m: f32,
    /// Whole cells of drift (wrapping) and the fraction left.
    shift: (i32, i32),
    frac: (f32, f32),
    slice: i32,
    slice_frac: f32,
    amplitude: f32,
}

/// A [`WaterNoise`] frozen at one time: samples of any point, octave by octave.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseSurface {
    kind: NoiseKind,
    count: usize,
    octaves: [OctaveFrame; MAX_OCTAVES],
}

impl WaterNoise {
    /// The field at time `time_s` seconds.
    pub fn at(&self, time_s: f64) -> NoiseSurface {
        let f = &self.fractal;
        let mut octaves = [OctaveFrame::default(); MAX_OCTAVES];
        let mut amplitude = 1.0f32;
        for (i, o) in octaves.iter_mut().enumerate().take(f.octave_count()) {
            let seed = f.octave_seed(i as u32);
            let scale = f64::from(1u32 << i);
            let cells_per_m = scale / f64::from(self.spacing_m.max(1e-6));
            let speed = f64::from(self.speed_m_s) / scale.sqrt();
            // Each octave strays from the wind by its own fixed angle in [-spread, spread].
            let stray =
                (f64::from(hash(seed, 7, 11, 13)) / f64::from(0x7fff_ffffu32) * 2.0 - 1.0) * f64::from(self.spread_rad);
            let heading = f64::from(self.heading_rad) + stray;
            // Moving the pattern by +d means sampling it at x - d.
            let dx = -heading.cos() * speed * time_s * cells_per_m;
            let dy = -heading.sin() * speed * time_s * cells_per_m;
            // One slice per period of a wave two cells long: speed / (2 · spacing).
            let slices = speed * cells_per_m / 2.0 * time_s + f64::from(hash(seed, 3, 5, 7) & 0xffff) / 65536.0;
            let split = |v: f64| {
                let whole = v.floor();
                ((whole.rem_euclid(4_294_967_296.0) as u32) as i32, (v - whole) as f32)
            };
            let ((sx, fx), (sy, fy), (sz, fz)) = (split(dx), split(dy), split(slices));
            *o = OctaveFrame {
                seed,
                cells_per_m: cells_per_m as f32,
                shift: (sx, sy),
                frac: (fx, fy),
                slice: sz,
                slice_frac: fz,
                amplitude,
            };
            amplitude *= f.persistence;
        }
        NoiseSurface { kind: f.kind, count: f.octave_count(), octaves }
    }
}

impl NoiseSurface {
    /// Octaves in the sum.
    pub fn octave_count(&self) -> usize {
        self.count
    }

    /// Octave `i` alone at (east, north) metres, times its amplitude pⁱ. Its variance is the
    /// noise's at every moment (see [`noise`]'s slices; the time blend keeps the variance).
    #[inline]
    pub fn octave(&self, i: usize, x_m: f32, y_m: f32) -> f32 {
        let o = &self.octaves[i];
        let c = Cell::at(x_m * o.cells_per_m + o.frac.0, y_m * o.cells_per_m + o.frac.1).shifted(o.shift.0, o.shift.1);
        o.amplitude * noise_at(self.kind, o.seed, c, o.slice, o.slice_frac, true)
    }

    /// Octave `i`'s lattice spacing, m.
    pub fn spacing_m(&self, i: usize) -> f32 {
        1.0 / self.octaves[i].cells_per_m
    }

    /// Octave `i`'s amplitude pⁱ.
    pub fn amplitude(&self, i: usize) -> f32 {
        self.octaves[i].amplitude
    }

    /// The whole sum at (east, north) metres.
    pub fn sample(&self, x_m: f32, y_m: f32) -> f32 {
        (0..self.count).map(|i| self.octave(i, x_m, y_m)).sum()
    }
}

#[cfg(test)]
mod tests;
