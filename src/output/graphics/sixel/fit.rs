//! Fitting a palette to a picture: median cut in OKLab over a subsample, then a few rounds of
//! k-means (Lloyd) from the boxes' means.
//!
//! Why by hand and not `quantette` (MIT/Apache, Wu's quantizer and k-means in OKLab, already
//! built for the tests through `icy_sixel`): it would bring `palette` (with its derive macro),
//! `wide`, `bitvec` and `rand` into the player's build for what is here under 150 lines over the
//! crate's own OKLab ([`crate::output::oklab`], IEEE basic operations only, so the same bits on
//! every machine), and its k-means samples with a random generator and runs in parallel with
//! `threads`; here every step is a fixed order over a fixed subsample, so one picture gives
//! one palette on any core count or SIMD tier.
//!
//! Cost: a subsample of at most [`FIT_SAMPLES`] pixels, boxes split at their median (a
//! selection, not a sort), [`ROUNDS`] rounds of nearest-centre assignment: about
//! `FIT_SAMPLES x registers x ROUNDS` distances, a few milliseconds for 256 registers. A
//! picture is fitted once per scene and again only when its colours drift.

use crate::output::oklab::{self, Lab};

/// The most pixels a fit looks at (a regular subsample of the picture).
pub const FIT_SAMPLES: usize = 8192;
/// Rounds of k-means after the median cut.
const ROUNDS: usize = 2;

/// One pixel of the subsample: its OKLab and its sRGB.
#[derive(Clone, Copy, Debug)]
struct Sample {
    lab: [f32; 3],
    rgb: [u8; 3],
}

/// A box of the median cut: `samples[start..end]` and the sum of its squared deviations.
#[derive(Clone, Copy, Debug)]
struct CutBox {
    start: usize,
    end: usize,
    /// The axis of largest spread and the box's total squared deviation (what splitting it
    /// can remove).
    axis: usize,
    spread: f32,
}

/// Every `step`-th pixel of `pixels` (`bpp` bytes a pixel, RGB first), at most
/// [`FIT_SAMPLES`] of them, as sRGB.
pub fn subsample(pixels: &[u8], bpp: usize) -> Vec<[u8; 3]> {
    let n = pixels.len() / bpp;
    let step = n.div_ceil(FIT_SAMPLES).max(1);
    (0..n).step_by(step).map(|i| [pixels[i * bpp], pixels[i * bpp + 1], pixels[i * bpp + 2]]).collect()
}

/// At most `k` colours (sRGB) that represent `colours` well in OKLab: each the mean of the
/// colours nearest it. Fewer when the colours have fewer distinct values.
pub fn fit(colours: &[[u8; 3]], k: usize) -> Vec<[u8; 3]> {
    let mut samples: Vec<Sample> = colours
        .iter()
        .map(|&rgb| {
            let Lab { l, a, b } = oklab::from_rgb(rgb);
            Sample { lab: [l, a, b], rgb }
        })
        .collect();
    if samples.is_empty() || k == 0 {
        return Vec::new();
    }
    let boxes = median_cut(&mut samples, k);
    let mut centres: Vec<[f32; 3]> = boxes.iter().map(|b| mean_lab(&samples[b.start..b.end])).collect();
    let mut members = vec![0usize; samples.len()];
    for round in 0..=ROUNDS {
        for (s, m) in samples.iter().zip(members.iter_mut()) {
            *m = nearest(&centres, s.lab);
        }
        if round == ROUNDS {
            break;
        }
        let mut sums = vec![([0f32; 3], 0usize); centres.len()];
        for (s, &m) in samples.iter().zip(&members) {
            (0..3).for_each(|c| sums[m].0[c] += s.lab[c]);
            sums[m].1 += 1;
        }
        for (centre, (sum, n)) in centres.iter_mut().zip(sums) {
            if n > 0 {
                *centre = sum.map(|v| v / n as f32);
            }
        }
    }
    // Each colour: the mean sRGB of its members (the terminal is given sRGB).
    let mut sums = vec![([0u64; 3], 0u64); centres.len()];
    for (s, &m) in samples.iter().zip(&members) {
        (0..3).for_each(|c| sums[m].0[c] += u64::from(s.rgb[c]));
        sums[m].1 += 1;
    }
    sums.into_iter().filter(|(_, n)| *n > 0).map(|(sum, n)| sum.map(|v| ((v + n / 2) / n) as u8)).collect()
}

/// Splits the samples into at most `k` boxes, always the box with the largest squared
/// deviation, at its median along its axis of largest spread.
fn median_cut(samples: &mut [Sample], k: usize) -> Vec<CutBox> {
    let mut boxes = vec![measure(samples, 0, samples.len())];
    while boxes.len() < k {
        let Some((i, _)) =
            boxes.iter().enumerate().filter(|(_, b)| b.end - b.start > 1 && b.spread > 0.0).max_by(|x, y| {
                // Ties go to the earlier box (max_by keeps the last of equals: compare reversed).
                x.1.spread.total_cmp(&y.1.spread).then(y.0.cmp(&x.0))
            })
        else {
            break;
        };
        let CutBox { start, end, axis, .. } = boxes[i];
        let mid = (end - start) / 2;
        samples[start..end].select_nth_unstable_by(mid, |a, b| a.lab[axis].total_cmp(&b.lab[axis]));
        boxes[i] = measure(samples, start, start + mid);
        boxes.push(measure(samples, start + mid, end));
    }
    boxes
}

/// The box `samples[start..end]` with its axis of largest spread and total squared deviation.
fn measure(samples: &[Sample], start: usize, end: usize) -> CutBox {
    let part = &samples[start..end];
    let mean = mean_lab(part);
    let mut dev = [0f32; 3];
    for s in part {
        (0..3).for_each(|c| dev[c] += (s.lab[c] - mean[c]) * (s.lab[c] - mean[c]));
    }
    let axis = (0..3).fold(0, |best, c| if dev[c] > dev[best] { c } else { best });
    CutBox { start, end, axis, spread: dev.iter().sum() }
}

fn mean_lab(samples: &[Sample]) -> [f32; 3] {
    let mut sum = [0f32; 3];
    for s in samples {
        (0..3).for_each(|c| sum[c] += s.lab[c]);
    }
    sum.map(|v| v / samples.len().max(1) as f32)
}

/// The index of the centre nearest `lab` (the first of equals).
pub fn nearest(centres: &[[f32; 3]], lab: [f32; 3]) -> usize {
    let mut best = (f32::INFINITY, 0);
    for (i, c) in centres.iter().enumerate() {
        let d =
            (c[0] - lab[0]) * (c[0] - lab[0]) + (c[1] - lab[1]) * (c[1] - lab[1]) + (c[2] - lab[2]) * (c[2] - lab[2]);
        if d < best.0 {
            best = (d, i);
        }
    }
    best.1
}
