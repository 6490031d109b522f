//! A patch's foam: the model of `sim::foam` on the foam lattice, one FFT pass a foam step.

use super::*;
use crate::sim::foam::{fir_pairs, quantize, taps};

/// Points of the foam lattice whose cover is summed together (see [`fir_pairs`]).
const POINTS: usize = 4;

impl PatchFoam {
    /// Brings the memory up to the foam step after `time` and returns the cover at `time` on
    /// the foam lattice: (its side, the cover per point).
    pub(super) fn cover(&mut self, time: SeaTime) -> (usize, Vec<f32>) {
        let (now, frac) = self.clock.step_at(time);
        let slots = self.weights.len() + 1;
        let top = now + 1;
        let first = match self.top {
            Some(last) if last <= top => (last + 1).max(top + 1 - slots as i64),
            _ => top + 1 - slots as i64,
        };
        for step in first..=top {
            self.add_step(step, slots);
        }
        self.top = Some(top);
        let m = self.lattice.n;
        // The ring always holds steps top + 1 - slots..=top, each a function of its step
        // alone, so the sums of step `now` are too: kept until the series passes the step
        // (a 1024² series at 30 frames a second meets each foam step six times).
        if self.sums.as_ref().map(|(step, _)| *step) != Some(now) {
            let mut sums = self.sums.take().map(|(_, v)| v).unwrap_or_default();
            self.fir_sums(now, slots, &mut sums);
            self.sums = Some((now, sums));
        }
        let sums = self.sums.as_ref().map_or(&[][..], |(_, v)| v);
        (m, sums.par_iter().map(|&(a, b)| a + (b - a) * frac).collect())
    }

    /// The cover of foam steps `now` and `now + 1` at every point, into `sums`.
    fn fir_sums(&self, now: i64, slots: usize, sums: &mut Vec<(f32, f32)>) {
        let (taps_now, taps_next) = (taps(&self.weights, now, slots), taps(&self.weights, now + 1, slots));
        sums.resize(self.lattice.n * self.lattice.n, (0.0, 0.0));
        sums.par_chunks_mut(POINTS).zip(self.ring.par_chunks(slots * POINTS)).for_each(|(out, ring)| {
            let group: [(f32, f32); POINTS] = fir_pairs(ring, slots, &taps_now, &taps_next);
            for (sum, pair) in out.iter_mut().zip(group) {
                *sum = pair;
            }
        });
    }

    /// The source of foam step `step` at every point, into its slot of the ring.
    fn add_step(&mut self, step: i64, slots: usize) {
        let waves = self.lattice.waves(self.clock.time_of(step));
        let (gxx, gyy, gxy) = self.lattice.fold_fields(&waves);
        let slot = step.rem_euclid(slots as i64) as usize;
        let (model, resolved) = (self.model, self.resolved_slope);
        self.ring.par_chunks_mut(slots).enumerate().for_each(|(i, history)| {
            history[slot] = quantize(model.source([gxx[i], gyy[i], gxy[i]], resolved));
        });
    }
}
