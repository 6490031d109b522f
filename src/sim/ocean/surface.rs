//! The sea at one moment ([`SeaSurface`]): the sines summed at a resting point for a sample
//! standing for a footprint (its height, displacement and the slope it cannot carry), the
//! Jacobian of the displacement, and the Eulerian height at a fixed point.

use super::{EULER_ITERATIONS, LANES, Sea, SeaTime};
use crate::sim::surface::{Footprint, Surface, SurfaceSample};
use crate::sim::trig::{fast_cos, fast_sincos};

#[cfg(test)]
use super::fold::PhaseRows;

/// The sea at one moment.
#[derive(Clone, Debug)]
pub struct SeaSurface<'a> {
    pub(super) sea: &'a Sea,
    pub(super) phase: Vec<f32>,
    pub(super) tail_offset: [f32; 2],
    pub(super) time: SeaTime,
}

/// The sums of one pass over the components: height, resolved slope variance,
/// displacement, and in the displaced pass Re B and Im B (the second-order height's sums).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Sums {
    pub(crate) h: f32,
    slope: f32,
    /// Σ a²/2·k²·φ², φ the phase step between samples: what a mesh loses of `slope`.
    loss: f32,
    dx: f32,
    dy: f32,
    b_re: f32,
    b_im: f32,
}

/// What a pass over the components computes (a const parameter, so each pass is its own loop).
pub(super) const HEIGHT: u8 = 0;
const DISPLACED: u8 = 1;

impl SeaSurface<'_> {
    /// Gives back the surface's buffer, for [`Sea::surface_at`].
    pub fn into_buffer(self) -> Vec<f32> {
        self.phase
    }

    /// The sea this frame belongs to.
    pub fn sea(&self) -> &Sea {
        self.sea
    }

    /// Its moment.
    pub fn time(&self) -> SeaTime {
        self.time
    }

    /// One pass over the components a footprint keeps, in eight lanes of independent sums
    /// added in a fixed order (the compiler may vectorise lanes, never reorder a float sum):
    /// the same result on every run and machine.
    #[inline(always)]
    pub(crate) fn sums<const PASS: u8>(&self, x: f32, y: f32, footprint: &Footprint) -> Sums {
        let (sea, l) = (self.sea, &self.sea.lanes);
        // Components are sorted longest first; those shorter than two of the footprint's
        // shorter side alias whatever their direction, and are left out exactly.
        let n = sea.wavelength.partition_point(|&w| w > 2.0 * footprint.min_m());
        let mut acc = [[0.0f32; LANES]; 7];
        let lane =
            |v: &Vec<f32>, base: usize| -> [f32; LANES] { v[base..base + LANES].try_into().expect("whole lanes") };
        let mut base = 0;
        while base < n {
            // Lanes past the footprint's cut count for nothing.
            let live: [f32; LANES] = std::array::from_fn(|i| if base + i < n { 1.0 } else { 0.0 });
            let (kx, ky, amp, phase) =
                (lane(&l.kx, base), lane(&l.ky, base), lane(&l.amp, base), lane(&self.phase, base));
            if PASS == HEIGHT {
                for i in 0..LANES {
                    let step = footprint.phase_step(kx[i], ky[i]);
                    let a = resolution_weight(step) * amp[i] * live[i];
                    acc[0][i] += a * fast_cos(kx[i] * x + ky[i] * y + phase[i]);
                    let slope = 0.5 * a * a * (kx[i] * kx[i] + ky[i] * ky[i]);
                    acc[2][i] += slope;
                    acc[1][i] += slope * step * step;
                }
            } else {
                let (ux, uy, sk) = (lane(&l.ux, base), lane(&l.uy, base), lane(&l.sqrt_k, base));
                for i in 0..LANES {
                    let step = footprint.phase_step(kx[i], ky[i]);
                    let a = resolution_weight(step) * amp[i] * live[i];
                    let (s, c) = fast_sincos(kx[i] * x + ky[i] * y + phase[i]);
                    acc[0][i] += a * c;
                    acc[3][i] += a * s * ux[i];
                    acc[4][i] += a * s * uy[i];
                    acc[5][i] += a * c * sk[i];
                    acc[6][i] += a * s * sk[i];
                    let slope = 0.5 * a * a * (kx[i] * kx[i] + ky[i] * ky[i]);
                    acc[2][i] += slope;
                    acc[1][i] += slope * step * step;
                }
            }
            base += LANES;
        }
        let s = |k: usize| acc[k].iter().sum::<f32>();
        Sums { h: s(0), loss: s(1), slope: s(2), dx: s(3), dy: s(4), b_re: s(5), b_im: s(6) }
    }

    /// Samples the surface at the resting point (east, north) metres for a sample standing
    /// for `footprint`: its height, how far λ carries it, and the unresolved slope variance.
    /// `foam` is 0: foam has a memory, kept by the foam module's `FoamTracker`.
    pub fn sample(&self, x: f32, y: f32, footprint: &Footprint) -> SurfaceSample {
        let sea = self.sea;
        let chop = sea.choppiness();
        let s = if chop > 0.0 { self.sums::<DISPLACED>(x, y, footprint) } else { self.sums::<HEIGHT>(x, y, footprint) };
        // The second-order height (see the module docs): λ·|B|²/2, B = Σ a·√k·e^(iθ).
        let bound = 0.5 * chop * (s.b_re * s.b_re + s.b_im * s.b_im);
        let (mut h, mut resolved_slope) = (s.h + bound, s.slope);
        if let Some(tail) = &sea.tail {
            let cell = tail.cell_m as f32;
            // The longer side: the fBm is isotropic, so it must not alias along either axis.
            let size = footprint.max_m();
            let octave = if size <= cell { 0 } else { (size / cell).log2().ceil() as u32 };
            if octave <= tail.field.levels() {
                let gx = (x - self.tail_offset[0]) / cell;
                let gy = (y - self.tail_offset[1]) / cell;
                h += tail.field.sample(gx, gy, octave);
                // The octave's slope is measured per axis; the sines' is both axes together.
                resolved_slope += 2.0 * tail.octave_slope[octave as usize];
            }
        }
        let unresolved = (sea.slope_total - resolved_slope).max(0.1 * sea.slope_total) * 0.5;
        SurfaceSample {
            height_m: h,
            displacement_m: [-chop * s.dx, -chop * s.dy],
            foam: 0.0,
            unresolved_slope_variance: unresolved,
            mesh_slope_loss: s.loss,
        }
    }

    #[cfg(test)]
    /// The Jacobian J of the displacement at the resting point (x, y) from the sines a
    /// sample standing for `footprint` keeps: the area the water resting there now covers,
    /// per unit of its area at rest (below 0 the surface has folded over).
    pub fn jacobian(&self, x: f32, y: f32, footprint: &Footprint) -> f32 {
        let mut rows = PhaseRows::default();
        self.sea.phase_rows(std::iter::once(self.time), &mut rows);
        let mut g = [[0.0f32; 3]];
        self.sea.fold_rows(x, y, footprint, &rows, 0, &mut g);
        let chop = self.sea.choppiness();
        let [gxx, gyy, gxy] = g[0];
        (1.0 - chop * gxx) * (1.0 - chop * gyy) - chop * chop * gxy * gxy
    }

    /// The full (Eulerian) surface height at the fixed position (east, north) metres: the
    /// height of the water carried there, found by fixed-point iteration of x0 = x - λ·D(x0).
    pub fn height(&self, x: f32, y: f32) -> f32 {
        let full = Footprint::default();
        if self.sea.choppiness() == 0.0 {
            return self.sample(x, y, &full).height_m;
        }
        let mut at = (x, y);
        for _ in 0..EULER_ITERATIONS {
            let d = self.sample(at.0, at.1, &full).displacement_m;
            at = (x - d[0], y - d[1]);
        }
        self.sample(at.0, at.1, &full).height_m
    }
}

impl Surface for SeaSurface<'_> {
    fn sample(&self, x: f32, y: f32, footprint: &Footprint) -> SurfaceSample {
        SeaSurface::sample(self, x, y, footprint)
    }
}

/// How much of a wave a sample keeps, from the wave's phase change per sample step: all of it
/// up to π/2 (four samples a wavelength), none from π (two samples, the Nyquist limit).
#[inline(always)]
pub(super) fn resolution_weight(phase_step: f32) -> f32 {
    let t = ((std::f32::consts::PI - phase_step) * std::f32::consts::FRAC_2_PI).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}
