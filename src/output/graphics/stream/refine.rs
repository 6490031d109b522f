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
//!   blocks go as exact (lossless PNG) frame edits while they fit the bytes available now.
//!   When the rung is exact and below the top, the picture climbs: a new image at the top rung
//!   whose pixels are the shown picture enlarged (a lossy PNG of a smooth picture: nearly every
//!   difference rounds to zero, a few kilobytes; a flat image of its mean colour when even that
//!   does not fit), which the blocks then make exact.
//! - iTerm2 and kitty without frame edits (no partial update): the source's own pixels at the
//!   top rung as one lossless PNG, when the bucket holds it (or the caller can overdraw).
//!
//! When the shown picture is exact, a still scene sends nothing.

use std::time::{Duration, Instant};

use tiny_skia::Pixmap;

use super::{Budget, FRAME_MIN, Model, Offer, Part, PictureStream, Protocol};
use crate::output::graphics::pack::Packing;

/// The side of a refinement block, pixels of the rung.
const BLOCK: u32 = 16;
/// The lossy step of the base image a still picture climbs to the top rung with.
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
        room: usize,
        now: Instant,
        interval: Duration,
    ) -> Option<Offer<'_>> {
        if self.shown_exact {
            self.next_due = Some(now + interval);
            return None;
        }
        match &self.protocol {
            Protocol::Kitty(o) if o.frame_edits => self.refine_blocks(room, now, interval),
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

    /// The worst blocks of the shown picture made exact by frame edits, or the climb to the
    /// top rung when the shown rung is exact.
    fn refine_blocks(&mut self, room: usize, now: Instant, interval: Duration) -> Option<Offer<'_>> {
        let (rung, errors) = {
            let (Some((rung, shown)), Some((_, sent))) = (&self.shown, &self.sent) else { return None };
            (*rung, block_errors(shown, sent, self.rungs[*rung]))
        };
        if errors.is_empty() {
            if rung == 0 {
                self.shown_exact = true;
                self.next_due = Some(now + interval);
                return None;
            }
            return self.climb(rung, room, now);
        }
        let size = self.rungs[rung];
        let (cols, stride) = (size.0.div_ceil(BLOCK), size.0 as usize * 3);
        self.candidate.clear();
        self.candidate.extend_from_slice(&self.shown.as_ref().expect("shown").1);
        self.bytes.clear();
        let (mut sent_all, mut bbox) = (true, None::<(u32, u32, u32, u32)>);
        for &(_, index) in &errors {
            let (x, y) = ((index % cols) * BLOCK, (index / cols) * BLOCK);
            let (w, h) = (BLOCK.min(size.0 - x), BLOCK.min(size.1 - y));
            let from = &self.sent.as_ref().expect("sent").1;
            copy_box(from, &mut self.candidate, stride, (x, y, w, h));
            let mark = self.bytes.len();
            self.push_part(Part::Tile(x, y, w, h), rung, Some(Packing::Png));
            if self.bytes.len() > room {
                self.bytes.truncate(mark);
                copy_box(&self.shown.as_ref().expect("shown").1, &mut self.candidate, stride, (x, y, w, h));
                sent_all = false;
                break;
            }
            bbox =
                Some(bbox.map_or((x, y, x + w, y + h), |b| (b.0.min(x), b.1.min(y), b.2.max(x + w), b.3.max(y + h))));
        }
        let (x0, y0, x1, y1) = bbox?;
        let exact = sent_all && rung == 0;
        self.offer_as(rung, Part::Changed(x0, y0, x1 - x0, y1 - y0), true, now + interval, Model::Keep, exact)
    }

    /// A new image at the top rung showing the exact picture at `rung` enlarged, which the
    /// blocks then refine to the source's top rung.
    fn climb(&mut self, rung: usize, room: usize, now: Instant) -> Option<Offer<'_>> {
        let (from, top) = (self.rungs[rung], self.rungs[0]);
        let shown = &self.shown.as_ref().expect("shown").1;
        self.resampler.resample(shown, 3, from, top, &mut self.candidate);
        self.bytes.clear();
        self.push_part(Part::Whole, 0, Some(Packing::LossyPng(BASE_STEP)));
        if self.bytes.len() > room {
            self.flatten_candidate();
            self.bytes.clear();
            self.push_part(Part::Whole, 0, Some(Packing::Zlib(6)));
            if self.bytes.len() > room {
                return None;
            }
        }
        // What the blocks refine towards: the source at the top rung.
        self.resampler.resample(&self.source_shown, 4, self.source, top, &mut self.target);
        self.source_now.clear();
        self.source_now.extend_from_slice(&self.source_shown);
        self.offer_as(0, Part::Whole, true, now + FRAME_MIN, Model::Set, false)
    }
}

/// The blocks of `shown` that differ from `truth` (RGB of `size`): their error (the sum of the
/// byte differences) and index in raster order, worst first (ties: raster order).
fn block_errors(shown: &[u8], truth: &[u8], size: (u32, u32)) -> Vec<(u64, u32)> {
    let (cols, rows) = (size.0.div_ceil(BLOCK), size.1.div_ceil(BLOCK));
    let mut errors = vec![0u64; (cols * rows) as usize];
    for (y, (a, b)) in shown.chunks_exact(size.0 as usize * 3).zip(truth.chunks_exact(size.0 as usize * 3)).enumerate()
    {
        if a == b {
            continue;
        }
        let row = &mut errors[(y as u32 / BLOCK * cols) as usize..][..cols as usize];
        for (col, (p, q)) in a.chunks(BLOCK as usize * 3).zip(b.chunks(BLOCK as usize * 3)).enumerate() {
            row[col] += p.iter().zip(q).map(|(s, t)| u64::from(s.abs_diff(*t))).sum::<u64>();
        }
    }
    let mut out: Vec<(u64, u32)> = (0..).zip(errors).filter(|&(_, e)| e > 0).map(|(i, e)| (e, i)).collect();
    out.sort_by_key(|&(e, i)| (std::cmp::Reverse(e), i));
    out
}

/// Copies the box `(x, y, w, h)` of `from` into `to` (RGB pictures `stride` bytes a row).
fn copy_box(from: &[u8], to: &mut [u8], stride: usize, (x, y, w, h): (u32, u32, u32, u32)) {
    for row in y as usize..(y + h) as usize {
        let at = row * stride + x as usize * 3;
        to[at..at + w as usize * 3].copy_from_slice(&from[at..at + w as usize * 3]);
    }
}
