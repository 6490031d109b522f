//! A still scene under a rate: the bytes go to making what the terminal shows exact.
//!
//! Under a rate kitty's pictures are lossy PNGs at the rung the link pays for and iTerm2's are
//! JPEGs, so what a terminal shows is a little off the source everywhere. While the scene
//! moves that is the price of the rate; once it stands still (the source picture is the one
//! the shown picture was made from) the stream keeps a model of what is shown and spends each
//! frame's bytes on what is furthest from the truth:
//!
//! - kitty with frame edits: the shown picture is cut into [`BLOCK`]-pixel blocks, ordered by
//!   their error (the sum of the byte differences from the picture at that rung), and the worst
//!   blocks go as exact (lossless PNG) frame edits while they fit the bytes available now. On
//!   a slow link where even the worst block alone is more than a picture may take, the blocks
//!   are halved (8, 4, 2, 1 pixels) until it fits, as a picture's tiles are: a few hundred
//!   bytes a frame still make a still picture exact.
//!   When the rung is exact and below the top, the picture climbs: a new image at the highest
//!   rung whose first picture fits, that picture being the shown one enlarged (a lossy PNG of
//!   a smooth picture: nearly every difference rounds to zero, a few kilobytes; a flat image
//!   of its mean colour when even that does not fit), which the blocks then make exact; and
//!   so on up to the top rung.
//! - iTerm2 and kitty without frame edits (no partial update): the source's own pixels at the
//!   top rung as one lossless PNG, when the bucket holds it (or the caller can overdraw).
//!
//! When the shown picture is exact, a still scene sends nothing.
//!
//! While the scene moves, kitty's bytes left after a frame's changed box go the same way to
//! the blocks outside it ([`PictureStream::refine_still`]): there the source has not changed
//! since it was sent, so a still region beside moving water becomes exact too.

use std::time::{Duration, Instant};

use tiny_skia::Pixmap;

use super::{Budget, FRAME_MIN, Model, Offer, Part, PictureStream, Protocol};
use crate::output::graphics::pack::Packing;

/// The side of a refinement block, pixels of the rung.
const BLOCK: u32 = 16;
/// A box by its corners: left, top, right, bottom (exclusive), pixels of the rung.
type Corners = (u32, u32, u32, u32);

/// The smallest block the bytes left after a moving picture's changed box are spent on (each
/// block is its own command and PNG: below this the headers outweigh the pixels).
const STILL_MIN_SIDE: u32 = 4;
/// The least bytes left after a changed box worth looking for still blocks with (a 4x4 block's
/// edit alone is about a hundred bytes).
const STILL_LEAST_BYTES: usize = 100;

/// Where the exact pixels of a refinement block come from.
#[derive(Clone, Copy)]
enum Truth {
    /// `sent`: the picture the still scene's shown picture was made from.
    Sent,
    /// `target`: this frame's picture at the rung.
    Target,
}

/// The lossy step of the first picture a still picture climbs to a higher rung with.
const BASE_STEP: u8 = 8;

impl PictureStream {
    /// Whether `picture` is the source the shown picture was encoded from (kitty and iTerm2
    /// under a rate).
    pub(super) fn still(&self, picture: &Pixmap) -> bool {
        !matches!(self.protocol, Protocol::Sixel { .. })
            && !self.source_shown.is_empty()
            && self.source_shown == picture.data()
            && matches!((&self.shown, &self.sent), (Some((r, _)), Some((s, _))) if r == s)
    }

    /// The next refinement of a still picture within `room` bytes (see the module
    /// documentation); `None` when it is exact or nothing fits now.
    pub(super) fn refine(
        &mut self,
        budget: Budget,
        (room, allowance): (usize, usize),
        now: Instant,
        interval: Duration,
    ) -> Option<Offer<'_>> {
        if self.shown_exact {
            self.next_due = Some(now + interval);
            return None;
        }
        match &self.protocol {
            Protocol::Kitty(o) if o.frame_edits => self.refine_blocks(room, allowance, now, interval),
            _ => self.refine_whole(budget, now, interval),
        }
    }

    /// The exact picture at the top rung, whole, when it fits.
    fn refine_whole(&mut self, budget: Budget, now: Instant, interval: Duration) -> Option<Offer<'_>> {
        let fits = |bytes: usize| bytes <= budget.available || budget.overdraw;
        if self.refine_cost.is_some_and(|c| !fits(c)) {
            return None;
        }
        let top = self.rungs[0];
        self.resampler.resample(&self.source_shown, 4, self.source, top, &mut self.candidate);
        self.target.clear();
        self.target.extend_from_slice(&self.candidate);
        self.source_now.clear();
        self.source_now.extend_from_slice(&self.source_shown);
        self.bytes.clear();
        self.push_part(Part::Whole, 0, Some(Packing::Png));
        self.refine_cost = Some(self.bytes.len());
        if !fits(self.bytes.len()) {
            return None;
        }
        // (Labelled as unlimited pictures are: a lossless PNG.)
        self.offer_as(0, Part::Whole, false, now + interval, Model::Set, true)
    }

    /// The worst blocks of the shown picture made exact by frame edits, or the climb to a
    /// higher rung when the shown rung is exact. A block whose edit alone is more than a
    /// picture may take (`allowance`) is halved, and halved again, until the worst one fits:
    /// on a link of a few hundred bytes a frame a still picture still becomes exact, in
    /// smaller pieces. One that fits the allowance but not the bytes available now waits for
    /// the bucket.
    fn refine_blocks(&mut self, room: usize, allowance: usize, now: Instant, interval: Duration) -> Option<Offer<'_>> {
        let rung = self.shown.as_ref()?.0;
        let mut side = BLOCK;
        loop {
            let mut errors = std::mem::take(&mut self.blocks);
            errors.clear();
            {
                let (Some((_, shown)), Some((_, sent))) = (&self.shown, &self.sent) else { return None };
                let size = self.rungs[rung];
                block_errors(shown, sent, size, side, (0, 0, size.0, size.1), (&mut self.block_table, &mut errors));
                worst_first(&mut errors);
            }
            let packed = (!errors.is_empty()).then(|| {
                self.candidate.clear();
                self.candidate.extend_from_slice(&self.shown.as_ref().expect("shown").1);
                self.bytes.clear();
                self.pack_blocks(rung, &errors, room, Truth::Sent)
            });
            self.blocks = errors;
            let Some(packed) = packed else {
                if rung == 0 {
                    self.shown_exact = true;
                    self.next_due = Some(now + interval);
                    return None;
                }
                return self.climb(rung, room, allowance, now);
            };
            match packed {
                Ok(((x0, y0, x1, y1), all)) => {
                    let (part, exact) = (Part::Changed(x0, y0, x1 - x0, y1 - y0), all && rung == 0);
                    return self.offer_as(rung, part, true, now + interval, Model::Keep, exact);
                }
                Err(worst) if worst <= allowance || side == 1 => return None,
                Err(_) => side /= 2,
            }
        }
    }

    /// Appends exact frame edits of the worst of `errors` (blocks at `rung`, worst first)
    /// to `self.bytes` while the whole stays within `limit`, the truth (`sent`, or this frame's
    /// `target`) copied into the candidate with them: the box around those that went and
    /// whether every block went, or the bytes of the worst block alone when even it does not
    /// fit. The candidate is the shown picture wherever a block may go.
    fn pack_blocks(
        &mut self,
        rung: usize,
        errors: &[Block],
        limit: usize,
        truth: Truth,
    ) -> Result<(Corners, bool), usize> {
        let stride = self.rungs[rung].0 as usize * 3;
        let mut bbox = None::<Corners>;
        for &(_, (x, y, w, h)) in errors {
            let from = match truth {
                Truth::Sent => &self.sent.as_ref().expect("sent").1,
                Truth::Target => &self.target,
            };
            copy_box(from, &mut self.candidate, stride, (x, y, w, h));
            let mark = self.bytes.len();
            self.push_part(Part::Tile(x, y, w, h), rung, Some(Packing::Png));
            if self.bytes.len() > limit {
                let worst = self.bytes.len() - mark;
                self.bytes.truncate(mark);
                copy_box(&self.shown.as_ref().expect("shown").1, &mut self.candidate, stride, (x, y, w, h));
                return bbox.map(|b| (b, false)).ok_or(worst);
            }
            bbox = Some(bbox.map_or((x, y, x + w, y + h), |b| union(b, (x, y, x + w, y + h))));
        }
        Ok((bbox.expect("at least one block"), true))
    }

    /// After a moving picture's changed box (kitty's lossy frame edit, in `self.bytes`): the
    /// bytes left within `limit` go to the worst blocks outside the box, made exact. Outside
    /// the box this frame's picture is the one last sent (the box holds every change), so
    /// there the source has not changed and the shown picture is off only by the lossy
    /// error: still regions beside moving water (a letterbox's bars, a still part of the
    /// scene) become exact while the water moves, instead of only once the whole scene stands
    /// still. Blocks are halved (down to [`STILL_MIN_SIDE`]) when the worst does not fit.
    /// Returns the part the offer now covers: the box around the changed box and the blocks.
    pub(super) fn refine_still(&mut self, rung: usize, part: Part, limit: usize) -> Part {
        let Part::Changed(bx, by, bw, bh) = part else { return part };
        let edits = matches!(&self.protocol, Protocol::Kitty(o) if o.frame_edits);
        let lossy = self.packing(true, rung).is_some_and(Packing::rewrites_pixels);
        if !edits || !lossy || self.shown.as_ref().is_none_or(|(r, _)| *r != rung) {
            return part;
        }
        let (w, h) = self.rungs[rung];
        let (x1, y1) = (bx + bw, by + bh);
        // Outside the box: the bands above and below it, and either side of it.
        let outside = [(0, 0, w, by), (0, y1, w, h), (0, by, bx, y1), (x1, by, w, y1)];
        let mut side = BLOCK;
        let mut errors = std::mem::take(&mut self.blocks);
        let mut found = part;
        while self.bytes.len() + STILL_LEAST_BYTES <= limit {
            errors.clear();
            for region in outside {
                let scratch = (&mut self.block_table, &mut errors);
                block_errors(&self.candidate, &self.target, (w, h), side, region, scratch);
            }
            if errors.is_empty() {
                break;
            }
            worst_first(&mut errors);
            match self.pack_blocks(rung, &errors, limit, Truth::Target) {
                Ok((blocks, _)) => {
                    let (x0, y0, x1, y1) = union((bx, by, x1, y1), blocks);
                    found = Part::Changed(x0, y0, x1 - x0, y1 - y0);
                    break;
                }
                Err(_) if side > STILL_MIN_SIDE => side /= 2,
                Err(_) => break,
            }
        }
        self.blocks = errors;
        found
    }

    /// A new image at the highest rung whose first picture fits a picture's bytes
    /// (`allowance`): the exact picture at `rung` enlarged, which the blocks then refine to
    /// the source at that rung. It waits for the bucket when it fits the allowance but not
    /// `room` (its bytes are kept: it is not encoded again until the bucket holds them).
    fn climb(&mut self, rung: usize, room: usize, allowance: usize, now: Instant) -> Option<Offer<'_>> {
        if self.refine_cost.is_some_and(|c| c > room) {
            return None;
        }
        let to = (0..rung).find(|&to| self.climb_base(rung, to, allowance))?;
        self.refine_cost = Some(self.bytes.len());
        if self.bytes.len() > room {
            return None;
        }
        // What the blocks refine towards: the source at that rung.
        self.resampler.resample(&self.source_shown, 4, self.source, self.rungs[to], &mut self.target);
        self.source_now.clear();
        self.source_now.extend_from_slice(&self.source_shown);
        self.offer_as(to, Part::Whole, true, now + FRAME_MIN, Model::Set, false)
    }

    /// Encodes the first picture of the climb from `rung` to `to` into `self.bytes` and the
    /// candidate: the shown picture enlarged (a lossy PNG of a smooth picture, step
    /// [`BASE_STEP`]: a few kilobytes), or a flat image of its mean colour when that is more
    /// than `allowance`; whether it fits `allowance`.
    fn climb_base(&mut self, rung: usize, to: usize, allowance: usize) -> bool {
        let (from, size) = (self.rungs[rung], self.rungs[to]);
        let shown = &self.shown.as_ref().expect("shown").1;
        self.resampler.resample(shown, 3, from, size, &mut self.candidate);
        self.bytes.clear();
        self.push_part(Part::Whole, to, Some(Packing::LossyPng(BASE_STEP)));
        if self.bytes.len() <= allowance {
            return true;
        }
        self.flatten_candidate();
        self.bytes.clear();
        self.push_part(Part::Whole, to, Some(Packing::Zlib(6)));
        self.bytes.len() <= allowance
    }
}

/// A block: its error (the sum of the byte differences) and its box `(x, y, w, h)`.
pub(super) type Block = (u64, (u32, u32, u32, u32));

/// Appends to `out` the `side`-pixel blocks of `region` (corners; blocks at its right and
/// bottom edges are cut to it) where `shown` differs from `truth` (RGB of `size`). `table`:
/// scratch for the region's sums (the stream's, kept from call to call).
fn block_errors(
    shown: &[u8],
    truth: &[u8],
    size: (u32, u32),
    side: u32,
    region: Corners,
    (table, out): (&mut Vec<u64>, &mut Vec<Block>),
) {
    let (x0, y0, x1, y1) = region;
    if x0 >= x1 || y0 >= y1 {
        return;
    }
    let (cols, rows) = ((x1 - x0).div_ceil(side), (y1 - y0).div_ceil(side));
    table.clear();
    table.resize((cols * rows) as usize, 0);
    let errors = &mut table[..];
    let (stride, from, to) = (size.0 as usize * 3, x0 as usize * 3, x1 as usize * 3);
    for y in y0..y1 {
        let at = y as usize * stride;
        let (a, b) = (&shown[at + from..at + to], &truth[at + from..at + to]);
        if a == b {
            continue;
        }
        let row = &mut errors[((y - y0) / side * cols) as usize..][..cols as usize];
        for (col, (p, q)) in a.chunks(side as usize * 3).zip(b.chunks(side as usize * 3)).enumerate() {
            row[col] += p.iter().zip(q).map(|(s, t)| u64::from(s.abs_diff(*t))).sum::<u64>();
        }
    }
    for (i, &e) in (0..).zip(errors.iter()) {
        if e > 0 {
            let (x, y) = (x0 + i % cols * side, y0 + i / cols * side);
            out.push((e, (x, y, side.min(x1 - x), side.min(y1 - y))));
        }
    }
}

/// Orders blocks worst first (ties: raster order).
fn worst_first(blocks: &mut [Block]) {
    blocks.sort_by_key(|&(e, (x, y, _, _))| (std::cmp::Reverse(e), y, x));
}

/// The box around two boxes (corners).
fn union(a: Corners, b: Corners) -> Corners {
    (a.0.min(b.0), a.1.min(b.1), a.2.max(b.2), a.3.max(b.3))
}

/// Copies the box `(x, y, w, h)` of `from` into `to` (RGB pictures `stride` bytes a row).
fn copy_box(from: &[u8], to: &mut [u8], stride: usize, (x, y, w, h): (u32, u32, u32, u32)) {
    for row in y as usize..(y + h) as usize {
        let at = row * stride + x as usize * 3;
        to[at..at + w as usize * 3].copy_from_slice(&from[at..at + w as usize * 3]);
    }
}
