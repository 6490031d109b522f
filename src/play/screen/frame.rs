//! A frame's bytes: the cells (composed here, or a group's), the picture in real pixels, the
//! link's question, within the byte bucket and the link's window of unanswered bytes.

use std::time::{Duration, Instant};

use tiny_skia::Pixmap;

use super::compose::{Figures, big_enough, half_block_picture};
use super::scratch::{self, Scratch};
use super::switch::{self, Switch};
use super::{APPROXIMATE_BELOW, CellSource, Screen, link, picture};
use crate::output::color::ColorMode;
use crate::output::cursor::Cursor;
use crate::output::diff::Shown;
use crate::output::frame::Frame;
use crate::output::graphics::stream::Budget;
use crate::output::rate::{RateOptions, Report, Target, budget_after};
use crate::play::host::SceneStatus;
use crate::play::seat::SeatView;

/// What a frame may spend, found once at its start.
struct Plan {
    /// The link's rate in effect (`None`: no limit).
    rate: Option<f64>,
    /// The status line's figures.
    figures: Figures,
    /// The bytes the frame may send now.
    budget: usize,
    /// A picture bigger than the budget may go now and be owed.
    overdraw: bool,
    options: RateOptions,
}

impl Screen {
    /// Appends the frame for now to `out`: `picture` (of [`Screen::picture_size`]), the seat's
    /// overlay, the status line. Returns the bytes appended (0 when nothing changed). Nothing
    /// in it can fail: it writes to memory (kitty's temporary files are data the door writes).
    pub(crate) fn frame(
        &mut self,
        now: Instant,
        picture: &Pixmap,
        status: &SceneStatus,
        seat: &SeatView<'_>,
        out: &mut Vec<u8>,
    ) -> usize {
        self.frame_from(now, picture, status, seat, CellSource::Own { figures: None }, out)
    }

    /// [`Screen::frame`] with its cells from `cells`: everything else (the byte bucket, the
    /// link's questions, the meter, the pacer, real pixels) as for any frame.
    pub(crate) fn frame_from(
        &mut self,
        now: Instant,
        picture: &Pixmap,
        status: &SceneStatus,
        seat: &SeatView<'_>,
        cells: CellSource<'_>,
        out: &mut Vec<u8>,
    ) -> usize {
        let start = out.len();
        if !self.entered {
            out.extend_from_slice(Self::ENTER);
            self.entered = true;
        }
        if std::mem::take(&mut self.mouse_pixels_pending) {
            out.extend_from_slice(picture::PIXEL_MOUSE_ON);
        }
        if self.auto() {
            self.bucket.set_rate(self.link.rate());
        }
        self.bucket.refill(now);
        self.follow_link(now, out);
        self.switch_before_cells(out);
        let plan = self.plan(now);
        let resized = self.shown.frame.is_none();
        // Borrowed for this frame only (see `scratch`): a screen keeps no encoder of its own.
        let mut scratch = scratch::take();
        scratch.bytes.clear();
        let (report, covered) = self.encode_cells(picture, status, seat, cells, &plan, &mut scratch, out);
        self.bucket.spend(report.bytes);
        self.switch_after_cells(covered, &mut scratch.bytes);
        let sent = self.add_picture(now, picture, seat, resized, &report, &plan, &mut scratch.bytes);
        self.switch_after_picture(sent);
        if self.auto() {
            self.link.frame_sent(report.bytes + sent, plan.budget);
        }
        // Room for the largest frame at once (rounded up as a growing buffer would be, so a
        // frame a little larger than the last largest still fits), so the caller's buffers
        // stop growing after the first frames: steady frames allocate nothing.
        self.largest_frame = self.largest_frame.max(scratch.bytes.len().next_power_of_two());
        out.reserve(self.largest_frame);
        out.extend_from_slice(&scratch.bytes);
        scratch::give(scratch);
        let wanted = self.link.question_wanted(now, self.bytes_sent + (out.len() - start) as u64);
        if self.auto() && self.link.probe_due() && (out.len() > start || wanted) {
            // The question goes after the frame: its answer says the frame has arrived.
            out.extend_from_slice(self.link.question());
            self.link.probed(now, self.bytes_sent + (out.len() - start) as u64);
        }
        let len = out.len() - start;
        self.bytes_sent += len as u64;
        self.meter.frame(now, len);
        self.pacer.sent(now);
        len
    }

    /// What the frame at `now` may spend (the bucket refilled already).
    fn plan(&self, now: Instant) -> Plan {
        let rate = self.bucket.rate();
        let figures = Figures {
            fps: self.meter.fps,
            bytes_per_second: self.meter.bytes_per_second,
            bandwidth: rate.map(|r| r as u64),
            pixels_elsewhere: self.picture.is_some(),
            note: if self.auto() { self.link.hint() } else { None },
        };
        // On an auto link the unanswered bytes are capped too (see `link`: the first seconds).
        let window_left = if self.auto() { self.link.window_left(now, self.bytes_sent) } else { usize::MAX };
        let budget = self.bucket.budget().min(window_left);
        // The bucket as full as it gets and nothing big unanswered: a picture bigger than both
        // may go now (and is owed), so a picture that never fits them still shows.
        let overdraw =
            self.bucket.budget() as f64 + 1.0 >= self.bucket.capacity() && window_left >= link::MIN_WINDOW as usize / 2;
        let options = RateOptions {
            approximate: rate.is_some_and(|r| r < APPROXIMATE_BELOW),
            ..RateOptions::from(self.config.encode)
        };
        Plan { rate, figures, budget, overdraw, options }
    }

    /// The frame's cells into the scratch's bytes (a group's taken bytes straight into `out`),
    /// and whether they cover the picture area when a switch to cells waits for that (`None`:
    /// a group's cells, whole).
    #[allow(clippy::too_many_arguments)]
    fn encode_cells(
        &mut self,
        picture: &Pixmap,
        status: &SceneStatus,
        seat: &SeatView<'_>,
        cells: CellSource<'_>,
        plan: &Plan,
        scratch: &mut Scratch,
        out: &mut Vec<u8>,
    ) -> (Report, Option<bool>) {
        let Scratch { encoder, builder, bytes, cells_picture } = scratch;
        let waits = matches!(self.switch, Some(Switch::ToCells { .. }));
        let covered = |shown: &Shown, wanted: &Frame| {
            waits.then(|| shown.frame.as_ref().is_some_and(|s| switch::covered(s, wanted)))
        };
        match cells {
            CellSource::Own { figures: given } => {
                let figures = given.unwrap_or(plan.figures);
                // Under real pixels the cells draw no picture (and the picture is the pixels').
                let picture = if figures.pixels_elsewhere {
                    picture
                } else {
                    cells_picture.fit(picture, half_block_picture(self.term))
                };
                builder.compose(self.term, picture, self.config.color, status, seat, &figures);
                if self.keeps_cells()
                    && let Some(shown) = &self.shown.frame
                {
                    switch::keep_picture_rows(builder.last_mut(), shown);
                }
                let frame = builder.last();
                let target = match self.config.color {
                    ColorMode::TrueColor => Target::new(frame),
                    mode => Target::with_truth(frame, picture, mode),
                };
                let report = encoder.encode_into(&mut self.shown, target, plan.budget, plan.options, bytes);
                (report, covered(&self.shown, frame))
            }
            CellSource::Toward(model) => {
                // Exactly (no colour threshold), so that the model becomes equal, not close.
                let exact = RateOptions { threshold: 0, ..plan.options };
                let report = encoder.encode_into(&mut self.shown, Target::new(model), plan.budget, exact, bytes);
                (report, covered(&self.shown, model))
            }
            CellSource::Taken(taken) => {
                // Straight to the caller: the group's bytes need no copy in the scratch.
                out.extend_from_slice(taken);
                (Report { bytes: taken.len(), drawn: 0, pending: 0 }, None)
            }
        }
    }

    /// The picture in real pixels after the cells, within what they left; returns its bytes.
    #[allow(clippy::too_many_arguments)]
    fn add_picture(
        &mut self,
        now: Instant,
        picture: &Pixmap,
        seat: &SeatView<'_>,
        resized: bool,
        report: &Report,
        plan: &Plan,
        bytes: &mut Vec<u8>,
    ) -> usize {
        let Some(p) = &mut self.picture else { return 0 };
        let frame = picture::FrameFacts {
            resized,
            help_open: seat.help.is_some(),
            cells_shown: report.pending == 0,
            drawable: big_enough(self.term),
            sync: plan.options.sync,
        };
        // What the cells left of this frame's budget: the picture is never owed.
        let left = Budget {
            available: budget_after(plan.budget, report.bytes),
            rate: plan.rate,
            frame_interval: Duration::from_secs(1) / self.config.fps.max(1),
            overdraw: plan.overdraw,
        };
        let sent = p.add_to_frame(picture, &frame, left, now, bytes);
        if sent > 0 {
            // Beyond the budget when overdrawn: the bucket is in debt until the rate has
            // repaid it.
            self.bucket.owe(sent);
            self.shown.cursor = Cursor::Unknown;
        }
        sent
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// The bytes a frame may send now (the byte bucket, and on an auto link the window of
    /// unanswered bytes): whether a group's frame fits this screen's link.
    pub(crate) fn budget(&mut self, now: Instant) -> usize {
        if self.auto() {
            self.bucket.set_rate(self.link.rate());
        }
        self.bucket.refill(now);
        if self.auto() {
            self.bucket.budget().min(self.link.window_left(now, self.bytes_sent))
        } else {
            self.bucket.budget()
        }
    }
}
