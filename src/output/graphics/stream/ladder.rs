//! The resolution ladder and the resampler that puts any picture on a rung.
//!
//! The top rung is the source picture (the scene as rendered, within the layout's picture:
//! a rung above it would only interpolate, except for sixel, whose stream puts the screen's
//! size above it because the terminal does not scale sixel pixels); the bottom rung is given (the stream takes a
//! quarter of half-block resolution: a whole picture there moves truer than tiles of a finer
//! one on a slow link). Between them the sides shrink by
//! about a sixth a rung, so each rung has about 70% of the pixels of the one above and costs
//! about three quarters of its bytes: fine enough that the rung chosen for a link uses most
//! of what the link carries.

/// The most rungs (top and bottom included).
const MAX_RUNGS: usize = 12;
/// Each rung's side is this fraction of the one above (about 70% of the pixels).
const STEP: f64 = 0.84;

/// The rungs from `top` down to `bottom` (pixels), largest first, each at least 1x1; `bottom`
/// is clamped to `top`.
pub fn rungs(top: (u32, u32), bottom: (u32, u32)) -> Vec<(u32, u32)> {
    let top = (top.0.max(1), top.1.max(1));
    let bottom = (bottom.0.clamp(1, top.0), bottom.1.clamp(1, top.1));
    let mut out = vec![top];
    let mut scale = 1.0;
    loop {
        scale *= STEP;
        let w = (f64::from(top.0) * scale).round() as u32;
        let h = (f64::from(top.1) * scale).round() as u32;
        if w <= bottom.0 || h <= bottom.1 || out.len() + 1 >= MAX_RUNGS {
            break;
        }
        out.push((w, h));
    }
    if *out.last().expect("the top rung") != bottom {
        out.push(bottom);
    }
    out
}

/// Where [`Resampler::resample_rows`] hands each row. A trait rather than a closure, so that
/// a caller compiled for a wider instruction set can have the row's work inlined (a closure's
/// body stayed a call, compiled for the baseline).
pub trait RowSink {
    /// Takes target row `y` (RGB).
    fn row(&mut self, y: usize, row: &[u8]);
}

/// Appends every row to a picture.
struct Append<'a>(&'a mut Vec<u8>);

impl RowSink for Append<'_> {
    #[inline(always)]
    fn row(&mut self, _: usize, row: &[u8]) {
        self.0.extend_from_slice(row);
    }
}

/// A separable resampler from one size to another: a tent filter whose radius is one source
/// pixel when enlarging (bilinear) and the scale when shrinking (an area-like average), so
/// water neither aliases when shrunk nor blocks when enlarged. Weights are computed once per
/// pair of sizes.
#[derive(Debug, Default)]
pub struct Resampler {
    sizes: Option<((u32, u32), (u32, u32))>,
    columns: Axis,
    rows: Axis,
    /// One horizontally resampled row per source row, 3 floats a pixel.
    rows_buf: Vec<f32>,
    /// One target row: its sums (3 floats a pixel) and its RGB.
    acc: Vec<f32>,
    line: Vec<u8>,
}

#[derive(Debug, Default)]
struct Axis {
    /// For each target pixel: the first source pixel and how many follow.
    spans: Vec<(u32, u32)>,
    /// The weights of every span, one after another.
    weights: Vec<f32>,
    /// When every span has one or two pixels (an enlargement): each as two, the first
    /// source pixel, the second (the first again at the edge) and their weights (0 for a
    /// span of one: `s + 0 * p` is `s` for the non-negative sums here, so the sums are the
    /// spans' to the bit).
    pairs: Option<Vec<(u32, u32, f32, f32)>>,
}

impl Axis {
    fn new(source: u32, target: u32) -> Axis {
        let scale = f64::from(source) / f64::from(target);
        let radius = scale.max(1.0);
        let mut axis = Axis::default();
        for i in 0..target {
            let centre = (f64::from(i) + 0.5) * scale - 0.5;
            let lo = ((centre - radius).floor() + 1.0).max(0.0) as u32;
            let hi = ((centre + radius).ceil() - 1.0).min(f64::from(source) - 1.0).max(f64::from(lo)) as u32;
            let start = axis.weights.len();
            for j in lo..=hi {
                axis.weights.push((1.0 - (f64::from(j) - centre).abs() / radius).max(0.0) as f32);
            }
            let sum: f32 = axis.weights[start..].iter().sum();
            if sum > 0.0 {
                axis.weights[start..].iter_mut().for_each(|w| *w /= sum);
            } else {
                // Cannot happen for a tent of radius >= 1 around a point inside the source;
                // kept safe: the nearest pixel.
                axis.weights[start..].fill(0.0);
                axis.weights[start] = 1.0;
            }
            axis.spans.push((lo, hi - lo + 1));
        }
        if axis.spans.iter().all(|&(_, n)| n <= 2) {
            let mut weights = &axis.weights[..];
            let pairs = axis.spans.iter().map(|&(lo, n)| {
                let (w, rest) = weights.split_at(n as usize);
                weights = rest;
                match *w {
                    [a, b] => (lo, lo + 1, a, b),
                    _ => (lo, lo, w[0], 0.0),
                }
            });
            axis.pairs = Some(pairs.collect());
        }
        axis
    }
}

impl Resampler {
    /// Writes `source` (`from` pixels of `bpp` bytes, 3 or 4; the first three are taken as RGB)
    /// resampled to `to` as RGB into `out` (cleared first). Equal sizes copy the pixels.
    pub fn resample(&mut self, source: &[u8], bpp: usize, from: (u32, u32), to: (u32, u32), out: &mut Vec<u8>) {
        out.clear();
        out.reserve(to.0 as usize * to.1 as usize * 3);
        self.resample_rows(source, bpp, from, to, &mut Append(out));
    }

    /// Resamples as [`Resampler::resample`], handing each target row (RGB, top to bottom) to
    /// `row` with its index instead of keeping the picture: a caller that maps pixels on (the
    /// sixel dither) reads each row while it is in the cache, and no picture-sized buffer is
    /// written and read again.
    ///
    /// The arithmetic is the same, in the same order, as one pixel at a time (each target
    /// value is `0 + w0 * s0 + w1 * s1 + ...` in f32, IEEE basic operations): only the loops
    /// are turned so the vertical pass runs along a row, which the compiler vectorizes.
    #[inline(always)]
    pub fn resample_rows(
        &mut self,
        source: &[u8],
        bpp: usize,
        from: (u32, u32),
        to: (u32, u32),
        sink: &mut impl RowSink,
    ) {
        assert_eq!(source.len(), from.0 as usize * from.1 as usize * bpp, "source does not match {from:?}");
        let (tw, sw) = (to.0 as usize, from.0 as usize);
        if from == to {
            // Written in place (a push of three bytes a pixel checked the capacity every
            // pixel: about 3 % of a kitty player without a rate).
            self.line.resize(sw * 3, 0);
            for (y, line) in source.chunks_exact(sw * bpp).enumerate() {
                match bpp {
                    4 => copy_rgb::<4>(line, &mut self.line),
                    3 => copy_rgb::<3>(line, &mut self.line),
                    _ => self
                        .line
                        .chunks_exact_mut(3)
                        .zip(line.chunks_exact(bpp))
                        .for_each(|(d, p)| d.copy_from_slice(&p[..3])),
                }
                sink.row(y, &self.line);
            }
            return;
        }
        if self.sizes != Some((from, to)) {
            self.columns = Axis::new(from.0, to.0);
            self.rows = Axis::new(from.1, to.1);
            self.sizes = Some((from, to));
        }
        // Every value is written below: only a new size fills (a clear here was a 4 MB memset
        // a picture).
        self.rows_buf.resize(from.1 as usize * tw * 3, 0.0);
        for (line, dst) in source.chunks_exact(sw * bpp).zip(self.rows_buf.chunks_exact_mut(tw * 3)) {
            if let Some(pairs) = &self.columns.pairs {
                for (&(a, b, wa, wb), d) in pairs.iter().zip(dst.chunks_exact_mut(3)) {
                    let (p, q) = (&line[a as usize * bpp..][..3], &line[b as usize * bpp..][..3]);
                    for c in 0..3 {
                        d[c] = 0.0 + wa * f32::from(p[c]) + wb * f32::from(q[c]);
                    }
                }
                continue;
            }
            let mut weights = &self.columns.weights[..];
            for (&(lo, n), d) in self.columns.spans.iter().zip(dst.chunks_exact_mut(3)) {
                let (w, rest) = weights.split_at(n as usize);
                weights = rest;
                let pixels = &line[lo as usize * bpp..(lo + n) as usize * bpp];
                let mut acc = [0f32; 3];
                for (&w, p) in w.iter().zip(pixels.chunks_exact(bpp)) {
                    acc[0] += w * f32::from(p[0]);
                    acc[1] += w * f32::from(p[1]);
                    acc[2] += w * f32::from(p[2]);
                }
                d.copy_from_slice(&acc);
            }
        }
        let mut weights = &self.rows.weights[..];
        self.acc.resize(tw * 3, 0.0);
        for (y, &(lo, n)) in self.rows.spans.iter().enumerate() {
            let (w, rest) = weights.split_at(n as usize);
            weights = rest;
            // The first tap sets the sums (`0 + w * s`, as a zeroed sum plus it: no memset of
            // the row), the others add to them.
            for (k, &w) in w.iter().enumerate() {
                let src = &self.rows_buf[(lo as usize + k) * tw * 3..][..tw * 3];
                if k == 0 {
                    self.acc.iter_mut().zip(src).for_each(|(a, &s)| *a = 0.0 + w * s);
                } else {
                    self.acc.iter_mut().zip(src).for_each(|(a, &s)| *a += w * s);
                }
            }
            self.line.clear();
            self.line.extend(self.acc.iter().map(|&a| to_byte(a)));
            sink.row(y, &self.line);
        }
    }
}

/// `(a + 0.5).clamp(0.0, 255.0) as u8`, the same byte for every f32 (NaN: 0), in operations
/// the compiler vectorizes: the float clamp's NaN test and the saturating `as` were scalar code
/// a value, about a tenth of the sixel player's CPU at the screen's size. `v + 2^23` holds
/// `v` rounded to the nearest integer (ties to even) in its low mantissa bits; one is taken
/// off when that rounded up, which gives the truncation `as` does.
#[inline(always)]
#[allow(clippy::manual_clamp, reason = "max and min map NaN to 0 as the cast does; clamp keeps NaN")]
fn to_byte(a: f32) -> u8 {
    const SHIFT: f32 = 8_388_608.0; // 2^23
    let v = (a + 0.5).max(0.0).min(255.0); // max(NaN, 0) is 0, as the clamp's NaN cast to u8
    let big = v + SHIFT;
    (big.to_bits() - u32::from(big - SHIFT > v)) as u8
}

/// The first three bytes of each `BPP`-byte pixel of `line` into `rgb` (as long as its
/// pixels); `BPP` a constant, so that the loop is unrolled.
#[inline(always)]
fn copy_rgb<const BPP: usize>(line: &[u8], rgb: &mut [u8]) {
    for (d, p) in rgb.chunks_exact_mut(3).zip(line.chunks_exact(BPP)) {
        d.copy_from_slice(&p[..3]);
    }
}

#[cfg(any(test, feature = "testing"))]
/// `source` resampled to `to` as RGB into `out` (`Resampler::resample` without keeping its
/// weights): for measurements that scale a picture the way a terminal does.
pub fn resample(source: &[u8], bpp: usize, from: (u32, u32), to: (u32, u32), out: &mut Vec<u8>) {
    Resampler::default().resample(source, bpp, from, to, out);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bytes_are_the_clamped_truncation_of_every_float() {
        let cast = |a: f32| (a + 0.5).clamp(0.0, 255.0) as u8;
        let mut specials = vec![f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -0.0, 0.0, -0.5, 254.5, 255.0, 1e30];
        // Every integer and half from -2 to 258 and the floats either side of them.
        for k in -4..=516 {
            let x = k as f32 / 2.0;
            specials.extend([x, f32::from_bits(x.to_bits() + 1), f32::from_bits(x.to_bits().saturating_sub(1))]);
        }
        for a in specials {
            assert_eq!(to_byte(a), cast(a), "{a} ({:#x})", a.to_bits());
        }
        // And a spread of every magnitude.
        for bits in (0..u32::MAX).step_by(65_537) {
            let a = f32::from_bits(bits);
            assert_eq!(to_byte(a), cast(a), "{a} ({bits:#x})");
        }
    }

    #[test]
    fn the_ladder_runs_from_the_area_to_half_blocks() {
        let r = rungs((480, 282), (160, 94));
        assert_eq!(r[0], (480, 282));
        assert_eq!(*r.last().unwrap(), (160, 94));
        assert!(r.len() <= MAX_RUNGS && r.len() >= 7, "{r:?}");
        // Each rung has 60-80% of the pixels of the one above (the bottom may be closer).
        let pixels = |s: &(u32, u32)| f64::from(s.0 * s.1);
        assert!(r[..r.len() - 1].windows(2).all(|p| (0.6..0.8).contains(&(pixels(&p[1]) / pixels(&p[0])))), "{r:?}");
        assert!(r.windows(2).all(|p| p[1].0 < p[0].0 && p[1].1 < p[0].1), "strictly shrinking: {r:?}");
        assert_eq!(rungs((100, 40), (100, 40)), vec![(100, 40)], "a tiny area has one rung");
        assert_eq!(rungs((10, 10), (50, 50)), vec![(10, 10)], "the bottom never exceeds the top");
    }

    #[test]
    fn resampling_keeps_flat_colours_and_averages_when_shrinking() {
        let mut rs = Resampler::default();
        let flat: Vec<u8> = [10u8, 200, 30, 255].repeat(7 * 5);
        let mut out = Vec::new();
        for to in [(3, 2), (7, 5), (20, 13)] {
            rs.resample(&flat, 4, (7, 5), to, &mut out);
            assert_eq!(out.len(), (to.0 * to.1 * 3) as usize);
            assert!(out.chunks_exact(3).all(|p| p == [10, 200, 30]), "{to:?}");
        }
        // A 1-pixel checkerboard shrunk by 2 is its mean grey.
        let checker: Vec<u8> =
            (0..8 * 8).flat_map(|i| if (i % 8 + i / 8) % 2 == 0 { [0u8; 3] } else { [200; 3] }).collect();
        rs.resample(&checker, 3, (8, 8), (4, 4), &mut out);
        assert!(out.iter().all(|&v| (90..=110).contains(&v)), "{out:?}");
        // Enlarging interpolates between neighbours.
        rs.resample(&[0, 0, 0, 100, 100, 100], 3, (2, 1), (4, 1), &mut out);
        assert_eq!(out.chunks_exact(3).map(|p| p[0]).collect::<Vec<_>>(), vec![0, 25, 75, 100]);
    }
}
