//! The resolved displacement gradient the foam's Jacobian needs, at a point for many moments
//! at once (`sim::foam` keeps the memory).

use super::*;

impl Sea {
    /// cos and sin of the phase of every sine the foam's Jacobian sums at each of `times`,
    /// one row each, for [`Sea::fold_rows`] (padding lanes are 0).
    pub(crate) fn phase_rows(&self, times: impl Iterator<Item = SeaTime>, rows: &mut PhaseRows) {
        let padded = self.fold.amp.len();
        rows.padded = padded;
        rows.cos.clear();
        rows.sin.clear();
        for time in times {
            for i in 0..padded {
                let (s, c) = match self.fold_index.get(i) {
                    Some(&k) => fast_sincos(self.phase(&self.components[k], time)),
                    None => (0.0, 0.0),
                };
                rows.cos.push(c);
                rows.sin.push(s);
            }
        }
    }

    /// The resolved displacement gradient at the resting point (x, y) for a sample standing
    /// for `footprint` (from the sines the Jacobian sums, [`FOLD_NEGLIGIBLE`]), at each of
    /// the rows `first..first + count` of `rows`: per row
    /// `[gxx, gyy, gxy]` with ∇D = -λ·g (so J = (1 - λ·gxx)(1 - λ·gyy) - λ²·gxy²), into `out`.
    /// Returns the slope variance the kept sines carry (both axes).
    ///
    /// Each sine's cos(k·x + φ) is taken as cos(k·x)·cos φ - sin(k·x)·sin φ, the first
    /// factors once per point and the second once per moment for every point, so a point's
    /// history costs a few multiplications a sine and moment. Every row is summed in the same
    /// order whatever the rows around it: a moment gives the same bits in a batch of many as
    /// alone.
    pub(crate) fn fold_rows(
        &self,
        x: f32,
        y: f32,
        footprint: &Footprint,
        rows: &PhaseRows,
        first: usize,
        out: &mut [[f32; 3]],
    ) -> f32 {
        let l = &self.fold;
        let n = self.fold_wavelength.partition_point(|&w| w > 2.0 * footprint.min_m());
        let count = out.len();
        debug_assert!(count <= FOLD_ROWS);
        let mut acc = [[[0.0f32; LANES]; 3]; FOLD_ROWS];
        let mut slope = [0.0f32; LANES];
        let lane = |v: &[f32], base: usize| -> [f32; LANES] { v[base..base + LANES].try_into().expect("whole lanes") };
        let mut base = 0;
        while base < n {
            let (kx, ky, amp) = (lane(&l.kx, base), lane(&l.ky, base), lane(&l.amp, base));
            let (dxx, dyy, dxy) = (lane(&l.dxx, base), lane(&l.dyy, base), lane(&l.dxy, base));
            let mut wd = [[0.0f32; LANES]; 3];
            let (mut sx, mut cx) = ([0.0f32; LANES], [0.0f32; LANES]);
            for i in 0..LANES {
                let live = if base + i < n { 1.0 } else { 0.0 };
                let w = resolution_weight(footprint.phase_step(kx[i], ky[i])) * live;
                (sx[i], cx[i]) = fast_sincos(kx[i] * x + ky[i] * y);
                wd[0][i] = w * dxx[i];
                wd[1][i] = w * dyy[i];
                wd[2][i] = w * dxy[i];
                let a = w * amp[i];
                slope[i] += 0.5 * a * a * (kx[i] * kx[i] + ky[i] * ky[i]);
            }
            for (r, acc) in acc.iter_mut().enumerate().take(count) {
                let at = (first + r) * rows.padded + base;
                let (cp, sp) = (lane(&rows.cos, at), lane(&rows.sin, at));
                for i in 0..LANES {
                    let c = cx[i] * cp[i] - sx[i] * sp[i];
                    acc[0][i] += wd[0][i] * c;
                    acc[1][i] += wd[1][i] * c;
                    acc[2][i] += wd[2][i] * c;
                }
            }
            base += LANES;
        }
        for (o, acc) in out.iter_mut().zip(&acc) {
            *o = [0, 1, 2].map(|k| acc[k].iter().sum::<f32>());
        }
        slope.iter().sum()
    }
}

/// The most rows one call of [`Sea::fold_rows`] fills.
pub(crate) const FOLD_ROWS: usize = 16;

/// cos and sin of the sines' phases at a few moments ([`Sea::phase_rows`]).
#[derive(Clone, Debug, Default)]
pub(crate) struct PhaseRows {
    padded: usize,
    cos: Vec<f32>,
    sin: Vec<f32>,
}

impl PhaseRows {
    /// The number of moments held.
    pub(crate) fn len(&self) -> usize {
        self.cos.len().checked_div(self.padded).unwrap_or(0)
    }
}
