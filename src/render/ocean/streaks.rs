//! Streaks that read as spindrift: aged foam's texture coordinates warped by smooth noise, so
//! that the streaks the wind draws out are of many lengths and unevenly spaced.
//!
//! Aged foam reads the foam texture stretched [`super::foam_streak`] times along the wind. On
//! its own that stretch is the same everywhere, and a gale's sea showed straight streaks of
//! one length at one spacing, as if combed. Here two noise fields warp the coordinates:
//!
//! ```text
//! u' = u + A·n₁(u, v)      along the wind: where n₁ rises, the texture is stretched less
//!                          (short streaks), where it falls, more (long ones), 1 ± 0.6 times
//! v' = v + B·n₂(u, v)      across: streaks crowd together and spread apart (n₂ varies slowly
//!                          along the wind, so they stay nearly straight)
//! d  = 1 + C·n₃(u, v)      how dense a streak's foam is, about 0.45 to 1.55: faint and dense
//! ```
//!
//! The n are value noise periodic in u with the texture's period (a looping sea's foam drift
//! crosses a whole number of texture lengths, so its streaks loop too) and in v over four
//! texture widths (96 m: the pattern no longer repeats every 24 m across). The warp grows with
//! the wind, from none at Beaufort 4's short streaks to full from Beaufort 7 up, where the
//! Beaufort scale's foam "blown in streaks" begins. d averages 1 over the sea, so the drawn
//! foam keeps the simulated cover.

/// Noise cells per texture length along the wind (n₁ and n₃; n₂ has one).
const CELLS_ALONG: u32 = 3;
/// Noise cells per texture width across the wind, and the widths in one period across.
const CELLS_ACROSS: u32 = 2;
const WIDTHS: u32 = 4;
/// How far along the wind the warp moves a point at most, in texture lengths: its slope, at
/// most 0.6, sets how much streak lengths vary.
const ALONG_AMPLITUDE: f32 = 0.6 / (std::f32::consts::PI * CELLS_ALONG as f32);
/// How far across, in texture widths.
const ACROSS_AMPLITUDE: f32 = 0.35;
/// How much a streak's density varies about 1.
const DENSITY_AMPLITUDE: f32 = 0.55;

/// Lattice rows across one period of the noise.
const ROWS: usize = (CELLS_ACROSS * WIDTHS) as usize;

/// The warp of one sea: its strength (0..=1) and the three noise fields' lattice values, each
/// of zero mean over its period (so the density averages exactly 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Streaks {
    strength: f32,
    along: Lattice<{ CELLS_ALONG as usize }>,
    across: Lattice<1>,
    density: Lattice<{ CELLS_ALONG as usize }>,
}

/// Periodic lattice values: `COLS` cells along the wind times [`ROWS`] across.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Lattice<const COLS: usize> {
    values: [[f32; COLS]; ROWS],
}

impl<const COLS: usize> Lattice<COLS> {
    fn new(seed: u32) -> Lattice<COLS> {
        let mut values = [[0.0f32; COLS]; ROWS];
        for (j, row) in values.iter_mut().enumerate() {
            for (i, v) in row.iter_mut().enumerate() {
                *v = lattice(i as u32, j as u32, seed);
            }
        }
        let mean = values.iter().flatten().sum::<f32>() / (COLS * ROWS) as f32;
        values.iter_mut().flatten().for_each(|v| *v -= mean);
        Lattice { values }
    }

    /// Smooth value noise at (x, y) lattice cells, periodic.
    #[inline]
    fn at(&self, x: f32, y: f32) -> f32 {
        let (fx, fy) = (floor(x), floor(y));
        let (ix, iy) = ((fx as i64).rem_euclid(COLS as i64) as usize, (fy as i64).rem_euclid(ROWS as i64) as usize);
        let (ix1, iy1) = ((ix + 1) % COLS, (iy + 1) % ROWS);
        let ease = |t: f32| t * t * (3.0 - 2.0 * t);
        let (sx, sy) = (ease(x - fx), ease(y - fy));
        let v = &self.values;
        let top = v[iy][ix] + (v[iy][ix1] - v[iy][ix]) * sx;
        let bottom = v[iy1][ix] + (v[iy1][ix1] - v[iy1][ix]) * sx;
        top + (bottom - top) * sy
    }
}

impl Streaks {
    /// The streaks of a sea with aged foam `streak` times longer than wide (3 to 9), seeded.
    pub fn new(streak: f32, seed: u64) -> Streaks {
        let seed = (seed ^ (seed >> 32)) as u32;
        Streaks {
            strength: ((streak - 3.0) / 3.0).clamp(0.0, 1.0),
            along: Lattice::new(seed),
            across: Lattice::new(seed ^ 0x5bd1_e995),
            density: Lattice::new(seed ^ 0x1b87_3593),
        }
    }

    /// Aged foam's texture coordinates (`u` along the wind in texture lengths, `v` across in
    /// texture widths), warped, and the density of its foam there.
    #[inline]
    pub fn warp(&self, u: f32, v: f32) -> (f32, f32, f32) {
        if self.strength == 0.0 {
            return (u, v, 1.0);
        }
        let (x, y) = (u * CELLS_ALONG as f32, v * CELLS_ACROSS as f32);
        let along = self.along.at(x, y);
        let across = self.across.at(u + 0.5, y + 3.25);
        let density = self.density.at(x + 1.5, y + 7.75);
        (
            u + self.strength * ALONG_AMPLITUDE * along,
            v + self.strength * ACROSS_AMPLITUDE * across,
            1.0 + self.strength * DENSITY_AMPLITUDE * density,
        )
    }
}

/// ⌊x⌋ without libm, for |x| < 2³¹.
fn floor(x: f32) -> f32 {
    let t = x as i32 as f32;
    if t > x { t - 1.0 } else { t }
}

/// A lattice value in -1..=1 (before its field's mean is taken off).
fn lattice(i: u32, j: u32, seed: u32) -> f32 {
    let h = crate::render::mesh::mix32(
        i.wrapping_mul(0x9e37_79b1) ^ j.wrapping_mul(0x85eb_ca77) ^ seed.wrapping_mul(0xc2b2_ae3d),
    );
    (h >> 8) as f32 / (1u32 << 23) as f32 - 1.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The warp repeats with the texture along the wind (so a loop's drifting foam loops),
    /// changes nothing for short streaks, varies the stretch by up to 1 ± 0.6 and the density
    /// about a mean of 1.
    #[test]
    fn the_warp_loops_along_the_wind_and_varies_the_stretch() {
        let gale = Streaks::new(8.0, 3);
        for i in 0..200 {
            let (u, v) = (i as f32 * 0.0137, i as f32 * 0.031);
            let (a, b) = (gale.warp(u, v), gale.warp(u + 1.0, v));
            assert!((a.0 + 1.0 - b.0).abs() < 1e-4 && (a.1 - b.1).abs() < 1e-4 && (a.2 - b.2).abs() < 1e-4, "{u} {v}");
        }
        assert_eq!(Streaks::new(3.0, 3).warp(0.3, 0.7), (0.3, 0.7, 1.0));
        let densities: Vec<f32> =
            (0..40_000).map(|i| gale.warp((i % 200) as f32 / 200.0, (i / 200) as f32 / 50.0).2).collect();
        let mean = densities.iter().sum::<f32>() / densities.len() as f32;
        assert!((mean - 1.0).abs() < 0.05 && densities.iter().all(|d| (0.2..=1.8).contains(d)), "mean density {mean}");
        let (mut lo, mut hi) = (f32::MAX, 0.0f32);
        for i in 0..30_000 {
            let (u, v) = ((i % 1000) as f32 * 0.001, (i / 1000) as f32 * 0.13);
            let du = (gale.warp(u + 1e-3, v).0 - gale.warp(u, v).0) / 1e-3;
            (lo, hi) = (lo.min(du), hi.max(du));
        }
        assert!(lo > 0.35 && hi < 1.65 && hi - lo > 0.5, "stretch from {lo} to {hi}");
    }
}
