//! Offering a picture and believing it shown: an offer is pending until the caller commits
//! it, and the commit updates the stream's model of the terminal (what it shows, and under a
//! rate what that was made from).

use std::time::Instant;

use super::{Model, Offer, Part, Pending, PictureStream, Protocol, State};
use crate::output::graphics::pack::Packing;

impl PictureStream {
    /// Offers `self.bytes` (the caller has checked they fit); what the commit does to the model
    /// follows from the packing: a limited kitty or iTerm2 picture encoded from this frame's
    /// target sets it.
    pub(super) fn offer(&mut self, rung: usize, part: Part, limited: bool, next: Instant) -> Option<Offer<'_>> {
        let model = match (self.packing(limited, rung), part) {
            (
                Some(Packing::LossyPng(_) | Packing::PalettePng(_) | Packing::Jpeg(_)),
                Part::Whole | Part::Changed(..),
            ) => Model::Set,
            _ => Model::Clear,
        };
        self.offer_as(rung, part, limited, next, model, false)
    }

    /// Offers `self.bytes` with what the commit does to the model.
    pub(super) fn offer_as(
        &mut self,
        rung: usize,
        part: Part,
        limited: bool,
        next: Instant,
        model: Model,
        exact: bool,
    ) -> Option<Offer<'_>> {
        self.pending = Some(Pending { rung, part, model, exact });
        self.state = State { size: self.rungs[rung], packing: self.packing(limited, rung), rate: self.rate, part };
        self.next_due = Some(next);
        Some(Offer { bytes: &self.bytes, state: self.state })
    }

    /// The offer was written: the terminal shows it from now on.
    pub fn commit(&mut self) {
        let Some(Pending { rung, part, model, exact }) = self.pending.take() else { return };
        self.committed_files.extend(self.pending_file.take());
        let sixel = matches!(self.protocol, Protocol::Sixel { .. });
        let (stride, bpp) = self.stride(rung);
        match model {
            Model::Set => {
                let target = std::mem::take(&mut self.target);
                self.target = self.sent.take().map(|(_, v)| v).unwrap_or_default();
                self.sent = Some((rung, target));
                std::mem::swap(&mut self.source_shown, &mut self.source_now);
                self.refine_cost = None;
            }
            Model::Keep => {}
            Model::Clear => {
                self.sent = None;
                self.source_shown.clear();
                self.refine_cost = None;
            }
        }
        self.shown_exact = exact;
        match (part, &mut self.shown) {
            // Only the box: outside it the candidate is what was shown (lossless: equal; lossy:
            // the shown picture with the box re-encoded).
            (Part::Tile(x, y, w, h) | Part::Changed(x, y, w, h), Some((r, shown))) if *r == rung || sixel => {
                *r = rung;
                for row in y as usize..(y + h) as usize {
                    let a = row * stride + x as usize * bpp;
                    let b = a + w as usize * bpp;
                    shown[a..b].copy_from_slice(&self.candidate[a..b]);
                }
            }
            (_, shown) => {
                let old = shown.take().map(|(_, v)| v).unwrap_or_default();
                *shown = Some((rung, std::mem::replace(&mut self.candidate, old)));
                if matches!(self.protocol, Protocol::Kitty(_)) && part == Part::Whole {
                    self.placeholders_due = false;
                }
            }
        }
        self.rung = rung;
    }
}
