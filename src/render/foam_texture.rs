//! The foam texture: the detail inside a foaming face. Foam is a froth of patches and
//! lacework, not a white sheet; the simulation gives each vertex a foam cover F (0..=1) and
//! the renderer draws, per pixel, foam where F exceeds this texture's value there.
//!
//! The texture is periodic value noise in four octaves, laid out in the wind's frame (the
//! smooth shader stretches it along the wind for aged foam: streaks, and reads it as it is
//! for fresh foam: patches). Each mip level is remapped to **uniform** values by rank, so
//! that the fraction of a face's pixels that foam is F whatever the level: the picture keeps
//! the simulation's cover while showing its detail. Far faces, whose pixels cover metres,
//! fade to the plain cover F ([`detail_for`]).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Texels per side of the finest level.
pub const FOAM_TEXELS: usize = 256;
/// Metres one copy of the texture spans across the wind.
pub const FOAM_TILE_ACROSS_M: f32 = 24.0;
/// Softness of a foam edge, in the texture's uniform units.
pub const FOAM_EDGE: f32 = 0.3;
/// Lattice spacing of the coarsest octave, texels, and the octaves' weights.
const OCTAVES: [(usize, f32); 4] = [(32, 1.0), (16, 0.55), (8, 0.3), (4, 0.16)];

/// The texture and its mip levels, each of uniform values in (0, 1).
#[derive(Debug)]
pub struct FoamTexture {
    levels: Vec<(usize, Vec<f32>)>,
}

impl FoamTexture {
    /// The one texture (it depends on nothing), built on first use.
    pub fn shared() -> &'static FoamTexture {
        static TEXTURE: std::sync::OnceLock<FoamTexture> = std::sync::OnceLock::new();
        TEXTURE.get_or_init(FoamTexture::build)
    }

    fn build() -> FoamTexture {
        let n = FOAM_TEXELS;
        let mut rng = ChaCha8Rng::seed_from_u64(0xf0a3_7e47);
        let mut base = vec![0.0f32; n * n];
        for (spacing, weight) in OCTAVES {
            let cells = n / spacing;
            let lattice: Vec<f32> = (0..cells * cells).map(|_| rng.random::<f32>() - 0.5).collect();
            let at = |x: usize, y: usize| lattice[(y % cells) * cells + x % cells];
            for y in 0..n {
                for x in 0..n {
                    let (cx, cy) = (x / spacing, y / spacing);
                    let ease = |t: f32| t * t * (3.0 - 2.0 * t);
                    let tx = ease((x % spacing) as f32 / spacing as f32);
                    let ty = ease((y % spacing) as f32 / spacing as f32);
                    let top = at(cx, cy) + (at(cx + 1, cy) - at(cx, cy)) * tx;
                    let bottom = at(cx, cy + 1) + (at(cx + 1, cy + 1) - at(cx, cy + 1)) * tx;
                    base[y * n + x] += weight * (top + (bottom - top) * ty);
                }
            }
        }
        let mut levels = vec![(n, uniform(&base))];
        let (mut size, mut values) = (n, base);
        while size > 1 {
            let half = size / 2;
            let mut next = vec![0.0f32; half * half];
            for y in 0..half {
                for x in 0..half {
                    let v = |dx: usize, dy: usize| values[(2 * y + dy) * size + 2 * x + dx];
                    next[y * half + x] = 0.25 * (v(0, 0) + v(1, 0) + v(0, 1) + v(1, 1));
                }
            }
            (size, values) = (half, next);
            levels.push((size, uniform(&values)));
        }
        FoamTexture { levels }
    }

    /// Mip levels (0 is the finest).
    #[cfg(test)]
    fn level_count(&self) -> usize {
        self.levels.len()
    }

    /// The level whose texel is about `metres_per_pixel` across.
    pub fn level_for(&self, metres_per_pixel: f32) -> usize {
        let texel = FOAM_TILE_ACROSS_M / FOAM_TEXELS as f32;
        let level = (metres_per_pixel / texel).max(1.0).log2() as usize;
        level.min(self.levels.len() - 1)
    }

    /// The value at (u, v) tiles (u across the texture's width, wrapping), nearest texel. The
    /// levels are powers of two, so wrapping is a mask of the texel number (truncated towards
    /// zero: left of the origin the texels shift by one, the same on every frame).
    #[inline(always)]
    pub fn sample(&self, level: usize, u: f32, v: f32) -> f32 {
        let (size, values) = &self.levels[level];
        let (s, mask) = (*size as f32, *size as i32 - 1);
        let x = ((u * s) as i32 & mask) as usize;
        let y = ((v * s) as i32 & mask) as usize;
        values[y * size + x]
    }
}

/// Values replaced by their rank, (rank + ½)/n: uniform on (0, 1).
fn uniform(values: &[f32]) -> Vec<f32> {
    let mut order: Vec<u32> = (0..values.len() as u32).collect();
    order.sort_by(|&a, &b| values[a as usize].total_cmp(&values[b as usize]));
    let mut out = vec![0.0f32; values.len()];
    for (rank, &i) in order.iter().enumerate() {
        out[i as usize] = (rank as f32 + 0.5) / values.len() as f32;
    }
    out
}

/// How much of the texture's detail a face shows whose pixels cover `metres_per_pixel`:
/// all of it up to 1.5 m, none from 6 m (there the cover is drawn as a plain blend).
pub fn detail_for(metres_per_pixel: f32) -> f32 {
    (1.0 - (metres_per_pixel - 1.5) / 4.5).clamp(0.0, 1.0)
}

/// The foam drawn over one pixel for cover `f` and texture value `n`, with `detail` of the
/// texture shown: its mean over uniform n is exactly f at every detail (the edge's ramp
/// narrows near 0 and 1 so that it stays symmetric about f), and 0 where f is 0.
#[inline(always)]
pub fn coverage(f: f32, n: f32, detail: f32) -> f32 {
    let edge = FOAM_EDGE.min(2.0 * f).min(2.0 * (1.0 - f));
    let sharp = if edge > 0.0 { ((f - n) / edge + 0.5).clamp(0.0, 1.0) } else { f32::from(u8::from(n < f)) };
    f + (sharp - f) * detail
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_level_is_uniform_so_coverage_is_kept() {
        let t = FoamTexture::shared();
        assert_eq!(t.level_count(), 9);
        for level in [0, 3, 6] {
            for f in [0.01f32, 0.2, 0.7] {
                let (mut sum, mut n) = (0.0f64, 0);
                for i in 0..200 {
                    for j in 0..200 {
                        let v = t.sample(level, i as f32 / 200.0, j as f32 / 200.0);
                        sum += f64::from(coverage(f, v, 1.0));
                        n += 1;
                    }
                }
                let mean = sum / n as f64;
                assert!((mean - f64::from(f)).abs() < 0.02 + 0.05 * f64::from(f), "level {level} f {f}: {mean}");
            }
        }
        assert_eq!(coverage(0.3, 0.9, 0.0), 0.3);
        assert_eq!(coverage(0.0, 0.01, 1.0), 0.0, "no cover, no foam");
        assert_eq!(detail_for(0.5), 1.0);
        assert_eq!(detail_for(10.0), 0.0);
        // Periodic: the texture wraps.
        assert_eq!(t.sample(0, 0.25, 0.5), t.sample(0, 1.25, -0.5));
    }
}
