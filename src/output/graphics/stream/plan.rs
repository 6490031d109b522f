//! How a [`PictureStream`] fits a link: the rung whose whole picture the rate pays for at
//! [`MIN_RATE`] pictures a second ([`KITTY_MIN_RATE`] for kitty) (learned from what each rung cost), the picture rate that
//! follows, and the packing and its lossy setting at each rung.

use std::time::Duration;

use super::{Budget, Part, PictureStream, Protocol};
use crate::output::bucket::{MAX_BURST, MIN_CAPACITY};
use crate::output::graphics::kitty::Medium;
use crate::output::graphics::pack::Packing;

/// The share of a picture interval's bytes a picture may take: the rest is left for the status
/// line and the cells' own changes.
pub(super) const PICTURE_SHARE: f64 = 0.85;
/// The picture rate the rung is chosen for (iTerm2, sixel, and a link whose rate is not known
/// yet): the rung's whole picture fits a tenth of a second of the rate, so a moving picture
/// keeps at least this many pictures a second.
pub(super) const MIN_RATE: f64 = 10.0;
/// kitty's picture rate the rung is chosen for under a known rate: a rung whose whole picture
/// fits a sixteenth of a second of the rate. In the pictures bench (docs/pixels/block-codec.md,
/// Round 11) a picture a frame old scores far below a fresh one (kitty at 239x140: SSIM 0.80 at
/// 30 pictures a second, 0.71 at the 14 a second that 250 kB/s paid for at [`MIN_RATE`]), so
/// at 250 kB/s 169x99 at 22 a second (0.736 / 0.747 on the bench's two phases) beat 239x140 at
/// 14 (0.712 / 0.722), 201x118 at 19 (13: 0.750 / 0.709) and 169x99 at 26 (20: 0.735 /
/// 0.734); 142x83 at 30 (25) scored 0.716. A picture of a sixteenth of a second's bytes also
/// crosses the link in that time, so a key's effect shows sooner. iTerm2's JPEG gained nothing
/// from a higher rate (13: 0.715 / 0.718, 16: 0.714 / 0.723, 20: 0.697), so it keeps
/// [`MIN_RATE`].
/// At 50 kB/s it lost (84x49 at 20 a second 0.643 / 0.644 against 100x59 at 14's 0.657 /
/// 0.652), and at 5 kB/s a sixteenth (265 bytes) held no tile of the bottom rung, so it holds
/// from [`KITTY_MIN_RATE_FROM`] on (between 50 and 250 kB/s not measured).
pub(super) const KITTY_MIN_RATE: f64 = 16.0;
/// The rate (bytes a second) from which kitty's rung is chosen for [`KITTY_MIN_RATE`].
pub(super) const KITTY_MIN_RATE_FROM: f64 = 150e3;
/// A rung above the current one is taken only when it is predicted to fit this share of the
/// allowance (hysteresis: no flapping between two rungs).
const UP_SHARE: f64 = 0.85;
/// The weight of the newest measurement in a rung's cost average.
const LEARN: f64 = 0.3;
/// How per-pixel cost grows as a rung shrinks: bytes a pixel scale as (pixels ratio) ^ this.
const DENSITY_EXPONENT: f64 = 0.2;
/// kitty's colours under a rate (`palette_png`: an indexed PNG of 4 bits a pixel). In the
/// pictures bench (docs/pixels/block-codec.md, Round 10) 16 colours on every rung scored
/// 0.657, 0.712 and 0.956 at 50 kB/s, 250 kB/s and 2 MB/s, where the lossy PNG of step 24
/// (Rounds 6-9) scored 0.633, 0.703 and 0.759: a third of its bytes a picture at a luma error
/// like the step's, so at 2 MB/s 30 pictures a second at 480x282 instead of 15. 8, 24, 32, 48,
/// 64 and 256 colours, a Bayer dither and PNG's row filters on the indices all scored lower;
/// 32 below the top rung won 0.003 at 250 kB/s and lost 0.018 at 50 kB/s.
pub(super) const KITTY_COLOURS: u16 = 16;
/// iTerm2's JPEG quality under a rate on the top rung and on the rungs below half-block
/// resolution: at 2 MB/s 70 lets the top rung go 30 times a second (SSIM 0.931 against 0.858
/// with 85 at 22 a second), and at 50 kB/s 70 at 100x59 scored 0.6456 against 85 at 84x49's
/// 0.6343 (docs/pixels/block-codec.md).
const ITERM2_QUALITY_LOW: u8 = 70;
/// iTerm2's JPEG quality under a rate on the rungs between: at 250 kB/s 85 at 201x118 scored
/// 0.7146 against 70 at 284x167's 0.6959 (docs/pixels/block-codec.md).
const ITERM2_QUALITY: u8 = 85;

/// The bytes a picture may take at `rate` (bytes a second) for `pictures` a second: that share
/// of the rate, within the bucket's burst, less the status line's share.
pub(super) fn allowance(rate: f64, pictures: f64) -> f64 {
    let burst = (rate * MAX_BURST.as_secs_f64()).max(MIN_CAPACITY);
    (rate / pictures).min(burst) * PICTURE_SHARE
}

impl PictureStream {
    /// The least time between pictures: the protocol's picture rate, a picture at most once a
    /// frame. Due half a frame early, so that an interval of two frames is two and not three
    /// when the clock's ticks fall a nanosecond short.
    pub(super) fn interval(&self, budget: Budget) -> Duration {
        let most = self.protocol.max_rate().min(1.0 / budget.frame_interval.as_secs_f64().max(1e-3));
        Duration::from_secs_f64(1.0 / most).max(budget.frame_interval) - budget.frame_interval / 2
    }

    /// The packing at `rung` (`None`: sixel, kitty's temporary files).
    pub(super) fn packing(&self, limited: bool, rung: usize) -> Option<Packing> {
        match &self.protocol {
            Protocol::Kitty(o) if matches!(o.medium, Medium::TempFile(_)) => None,
            Protocol::Kitty(_) if limited => Some(Packing::PalettePng(KITTY_COLOURS)),
            // Without a rate the exact picture as a PNG (row filters, fdeflate) rather than
            // raw RGB under zlib level 1: the same pixels, about two thirds of the bytes, and
            // miniz's deflate of raw RGB was a third of the in-band player's CPU
            // (docs/pixels/cpu.md, Round 6).
            Protocol::Kitty(_) => Some(Packing::Png),
            Protocol::Iterm2 { .. } if limited => Some(Packing::Jpeg(self.jpeg_quality(rung))),
            Protocol::Iterm2 { .. } => Some(Packing::Png),
            Protocol::Sixel { .. } => None,
        }
    }

    /// The picture rate the rung is chosen for at `rate`: [`KITTY_MIN_RATE`] for kitty from
    /// [`KITTY_MIN_RATE_FROM`], [`MIN_RATE`] otherwise.
    pub(super) fn min_rate(&self, rate: f64) -> f64 {
        match self.protocol {
            Protocol::Kitty(_) if rate >= KITTY_MIN_RATE_FROM => KITTY_MIN_RATE,
            _ => MIN_RATE,
        }
    }

    /// iTerm2's JPEG quality under a rate: [`ITERM2_QUALITY_LOW`] on the top rung and on the
    /// rungs with fewer pixels than half-block resolution (four times the bottom rung's),
    /// [`ITERM2_QUALITY`] between.
    pub(super) fn jpeg_quality(&self, rung: usize) -> u8 {
        let pixels = |(w, h): (u32, u32)| u64::from(w) * u64::from(h);
        let bottom = *self.rungs.last().expect("the ladder has a rung");
        if rung == 0 || pixels(self.rungs[rung]) < 4 * pixels(bottom) { ITERM2_QUALITY_LOW } else { ITERM2_QUALITY }
    }

    /// Chooses the rung for `budget` and returns the bytes one picture may take.
    pub(super) fn plan(&mut self, budget: Budget) -> usize {
        let most = self.protocol.max_rate().min(1.0 / budget.frame_interval.as_secs_f64().max(1e-3));
        let Some(rate) = budget.rate else {
            self.rate = most;
            self.rung = 0;
            return usize::MAX;
        };
        let allowance = allowance(rate, self.min_rate(rate));
        let last = self.rungs.len() - 1;
        let mut rung = (0..self.rungs.len()).find(|&r| self.predict(r).is_none_or(|c| c <= allowance)).unwrap_or(last);
        // Hysteresis: a bigger rung only when it fits with room to spare.
        if rung < self.rung && self.predict(rung).is_some_and(|c| c > UP_SHARE * allowance) {
            rung = self.rung.min(last);
        }
        self.rung = rung;
        self.rate = self.predict(rung).map_or(most, |c| (rate * PICTURE_SHARE / c.max(1.0)).min(most));
        allowance as usize
    }

    /// A whole picture's predicted bytes at `rung`: learned, or scaled from the nearest rung
    /// learned; `None` when nothing is known yet (the first picture tries the top).
    pub(super) fn predict(&self, rung: usize) -> Option<f64> {
        let pixels = |r: usize| f64::from(self.rungs[r].0) * f64::from(self.rungs[r].1);
        let (known, bpp) =
            (0..self.rungs.len()).filter_map(|r| self.cost[r].map(|c| (r, c))).min_by_key(|(r, _)| r.abs_diff(rung))?;
        Some(bpp * (pixels(known) / pixels(rung)).powf(DENSITY_EXPONENT) * pixels(rung))
    }

    /// Learns the bytes a pixel of `part` at `rung` (in `self.bytes`): a whole picture, or
    /// kitty's lossy edit of a box at least half the picture (under a rate a moving scene goes
    /// as such edits, and the box's pixels cost what the whole picture's do).
    pub(super) fn learn(&mut self, rung: usize, part: Part, limited: bool) {
        let (w, h) = self.rungs[rung];
        let area = match part {
            Part::Whole => f64::from(w) * f64::from(h),
            Part::Changed(_, _, bw, bh)
                if self.packing(limited, rung).is_some_and(Packing::rewrites_pixels) && 2 * bw * bh >= w * h =>
            {
                f64::from(bw) * f64::from(bh)
            }
            _ => return,
        };
        let bpp = self.bytes.len() as f64 / area;
        let c = &mut self.cost[rung];
        *c = Some(c.map_or(bpp, |old| old + LEARN * (bpp - old)));
    }
}
