//! One moment of a patch: the lattice fields by five inverse FFTs, then resampled under the
//! Eulerian lattice points.
//!
//! The buffers a moment needs (about 90 bytes a point: the waves, the transforms' spectra and
//! scratch, the fields the resampling reads) live in a [`Workspace`] that a series keeps from
//! step to step: fresh, they were about 90 MiB of new pages a 1024² step, each page faulted
//! in and cleared by the kernel.

use super::*;

/// Texels followed together through the Euler iterations. Each iteration's bilinear waits
/// for the one before (a chain of dependent loads and arithmetic a texel); a group of
/// independent texels lets the processor overlap their chains. Every texel's arithmetic is
/// the same as alone, so the same bits.
const LANES: usize = 8;

/// The buffers of one moment, kept between the steps of a series (contents are scratch).
#[derive(Default)]
pub(super) struct Workspace {
    waves: Vec<Complex32>,
    scratch: FftScratch,
    /// Two real fields to a complex buffer as the inverse transforms leave them (re, im):
    /// (h, dx), (dy, hx), (hy, gxy), (gxx, gyy).
    packed: [Vec<Complex32>; 4],
    /// B = Σ a·√k·e^(iθ) for the second-order height.
    b: Vec<Complex32>,
    /// The Lagrangian height with its second-order part, m.
    h_l: Vec<f32>,
    /// The displacement in lattice units (east, north): the Euler iterations read it four
    /// times a texel.
    carried: Vec<[f32; 2]>,
    /// Slopes and the displacement's gradient side by side: hx, hy, gxx, gyy, gxy.
    gradients: Vec<[f32; 5]>,
}

/// `v` as `len` elements (contents left as they were: every caller overwrites them all).
fn sized<T: Copy + Default>(v: &mut Vec<T>, len: usize) {
    v.resize(len, T::default());
}

impl PatchSea {
    /// The moment's lattice fields into `work`: five complex inverse FFTs, eight real
    /// fields packed two to a transform and the complex B.
    fn lagrangian(&self, time: SeaTime, work: &mut Workspace) {
        let l = &self.sea;
        let nn = l.n * l.n;
        let i_unit = Complex32::new(0.0, 1.0);
        let unit = |i: usize| (l.kx[i] / l.k[i], l.ky[i] / l.k[i], l.k[i]);
        l.waves_into(time, &mut work.waves);
        let (waves, scratch) = (&work.waves, &mut work.scratch);
        // The displacement per unit λ is -Σ a·û·sin θ = re Σ (i·û·w)·e^(ik·x); slopes
        // re Σ (i·k·w)·e^(ik·x); the displacement's gradient per unit λ, each times -1,
        // g_ab = Σ a·(k_a·k_b/k)·cos θ.
        let (k, kx, ky) = (l.k.as_slice(), l.kx.as_slice(), l.ky.as_slice());
        let coefficients = |i: usize, w: Complex32| {
            [
                (w, i_unit * w * unit(i).0),
                (i_unit * w * unit(i).1, i_unit * w * kx[i]),
                (i_unit * w * ky[i], w * (kx[i] * ky[i] / k[i])),
                (w * (kx[i] * kx[i] / k[i]), w * (ky[i] * ky[i] / k[i])),
            ]
        };
        let [h_dx, dy_hx, hy_gxy, gxx_gyy] = &mut work.packed;
        l.fill_packed(waves, coefficients, [&mut *h_dx, &mut *dy_hx, &mut *hy_gxy, &mut *gxx_gyy]);
        for buf in [h_dx, dy_hx, hy_gxy, gxx_gyy] {
            l.ifft2(buf, scratch);
        }
        // B = Σ a·√k·e^(iθ): the waves themselves, a complex field.
        let n = self.size;
        sized(&mut work.b, nn);
        work.b.par_chunks_mut(n).enumerate().for_each(|(r, row)| {
            for (c, out) in row.iter_mut().enumerate() {
                let i = r * n + c;
                *out = if l.amp[i].norm_sqr() != 0.0 { waves[i] * unit(i).2.sqrt() } else { Complex32::new(0.0, 0.0) };
            }
        });
        l.ifft2(&mut work.b, scratch);
    }

    /// The fields the resampling reads, from the transforms' packed buffers, in one pass
    /// (element by element, so in parallel with the same bits); the displacement map into
    /// `displacement`.
    fn lagrangian_fields(&self, work: &mut Workspace, displacement: &mut [[f32; 3]]) {
        let (n, cell) = (self.size, (self.extent_m / self.size as f64) as f32);
        let lambda = self.params.choppiness as f32;
        let to_cell = lambda / cell;
        sized(&mut work.h_l, n * n);
        sized(&mut work.carried, n * n);
        sized(&mut work.gradients, n * n);
        let [h_dx, dy_hx, hy_gxy, gxx_gyy] = &work.packed;
        let b = &work.b;
        let outputs =
            work.h_l.par_chunks_mut(n).zip(work.carried.par_chunks_mut(n)).zip(work.gradients.par_chunks_mut(n));
        outputs.zip(displacement.par_chunks_mut(n)).enumerate().for_each(|(r, (((h_l, carried), gradients), disp))| {
            for c in 0..n {
                let i = r * n + c;
                let (a, d, g, gg) = (h_dx[i], dy_hx[i], hy_gxy[i], gxx_gyy[i]);
                h_l[c] = a.re + 0.5 * lambda * b[i].norm_sqr();
                disp[c] = [lambda * a.im, lambda * d.re, h_l[c]];
                carried[c] = [a.im * to_cell, d.re * to_cell];
                gradients[c] = [d.im, g.re, gg.re, gg.im, g.im];
            }
        });
    }

    /// The maps at `time` into `maps` (resized to the patch), `foam_cover` the cover on the
    /// foam lattice; `work` holds the moment's buffers.
    pub(super) fn resample_into(
        &self,
        time: SeaTime,
        foam_cover: Option<&(usize, Vec<f32>)>,
        work: &mut Workspace,
        maps: &mut PatchMaps,
    ) {
        let n = self.size;
        maps.size = n;
        maps.extent_m = self.extent_m;
        sized(&mut maps.height, n * n);
        sized(&mut maps.displacement, n * n);
        sized(&mut maps.normal, n * n);
        sized(&mut maps.foam, n * n);
        self.lagrangian(time, work);
        self.lagrangian_fields(work, &mut maps.displacement);
        let rows = maps.height.par_chunks_mut(n).zip(maps.normal.par_chunks_mut(n)).zip(maps.foam.par_chunks_mut(n));
        rows.enumerate().for_each(|(r, ((height, normal), foam))| {
            for c0 in (0..n).step_by(LANES) {
                let lanes = LANES.min(n - c0);
                let at = self.carried_from(work, r, c0, lanes);
                for (j, &(px, py)) in at.iter().enumerate().take(lanes) {
                    let c = c0 + j;
                    height[c] = cubic(&work.h_l, n, px, py);
                    normal[c] = self.normal_at(work, px, py);
                    foam[c] = match foam_cover {
                        Some((m, cover)) => {
                            let scale = *m as f32 / n as f32;
                            Bilinear::new(*m, px * scale, py * scale).of(cover).clamp(0.0, 1.0)
                        }
                        None => 0.0,
                    };
                }
            }
        });
    }

    /// Where the water under texels (c0..c0 + lanes, r) rests, lattice units: x0 with
    /// x0 + λ·D(x0) = x by [`EULER_ITERATIONS`] fixed-point steps, the texels side by side.
    #[inline(always)]
    fn carried_from(&self, work: &Workspace, r: usize, c0: usize, lanes: usize) -> [(f32, f32); LANES] {
        let n = self.size;
        // Lattice units: column c is x = c, row r is y = -r (north up).
        let mut at: [(f32, f32); LANES] = std::array::from_fn(|j| ((c0 + j) as f32, r as f32));
        for _ in 0..EULER_ITERATIONS {
            for (j, p) in at.iter_mut().enumerate().take(lanes) {
                let [dxv, dyv] = Bilinear::new(n, p.0, p.1).of_all(&work.carried);
                *p = ((c0 + j) as f32 - dxv, r as f32 + dyv);
            }
        }
        at
    }

    /// The unit normal of the Eulerian surface over the water resting at (px, py).
    #[inline(always)]
    fn normal_at(&self, work: &Workspace, px: f32, py: f32) -> [f32; 3] {
        let lambda = self.params.choppiness as f32;
        let [hx, hy, gxx, gyy, gxy] = Bilinear::new(self.size, px, py).of_all(&work.gradients);
        // ∇D = -λ·g; the Eulerian gradient is (I + ∇D)^-T ∇h.
        let (a, d, bc) = (1.0 - lambda * gxx, 1.0 - lambda * gyy, -lambda * gxy);
        let det = a * d - bc * bc;
        let (ex, ey) = if det.abs() > 1e-3 { ((d * hx - bc * hy) / det, (a * hy - bc * hx) / det) } else { (hx, hy) };
        let len = (ex * ex + ey * ey + 1.0).sqrt();
        [-ex / len, -ey / len, 1.0 / len]
    }
}
