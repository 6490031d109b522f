//! The rate-controlled frame encoder: what the terminal shows, the frame wanted next and a
//! byte budget in; the bytes that bring the screen closest to the frame within the budget, out.
//!
//! [`RateEncoder::encode_into`] is a pure function of ([`Shown`], [`Target`], budget,
//! [`RateOptions`]) — the encoder only keeps scratch buffers, so a steady stream of frames
//! allocates nothing — and returns the bytes and the new [`Shown`]. Tested without a
//! terminal, through [`crate::output::vt`].
//!
//! How it spends the budget:
//! - Every cell the terminal shows differently from the wanted frame (colours compared with
//!   the `threshold` of today's encoder, [`crate::output::diff`]) is a candidate. Its error is
//!   the OKLab distance ([`crate::output::oklab`]) between what is shown and the true colour,
//!   squared and summed over both halves of the cell (the squared distance is what PSNR
//!   counts); a text cell whose glyph, foreground or background is wrong counts as
//!   [`TEXT_MISMATCH_ERROR`], more than any picture cell can.
//! - A candidate's cost is the bytes of its cursor move, colour codes and glyph. The pen in
//!   effect depends on the order cells are drawn in, so cells are *chosen* with an estimate (the
//!   pen and cursor as the cell's left neighbour would leave them, weighted by how likely that
//!   neighbour is drawn too, otherwise a fresh pen and a [`MOVE_ESTIMATE`]-byte move) and then
//!   *drawn* in screen order with exact accounting; the set is trimmed or extended by the
//!   estimates calibrated on that layout until the exact bytes fit (usually two layouts), and
//!   the last layout stops where the budget does, so a frame never exceeds its budget.
//! - Cells go in order of error removed per byte, but in tiers: every cell whose error is at
//!   least a just-noticeable difference (either half at least [`crate::output::oklab::JND`]
//!   from its true colour) goes before any cell below it; cells whose exact colours would not
//!   bring them closer to the true colours (in 256 and 16 colours the shown colour can be as
//!   good as the wanted one) go last, so that the screen still converges to the exact frame.
//! - Approximations (when [`RateOptions::approximate`]), for cells with a noticeable error
//!   only: a space in the mean of the two halves (one colour code instead of two), a space in
//!   the nearest xterm-256 colour of that mean (`ESC[48;5;Nm`, about half a truecolor code), or
//!   both halves in their nearest 256 colours. A cell's ways of being drawn are points (bytes,
//!   error removed); those on the upper convex hull become steps with falling error per byte,
//!   so the greedy order sends a cheap approximation first and the exact upgrade later (the
//!   multiple-choice knapsack greedy). On the codec fixture (`benches/codec.rs`) they add 2 to
//!   4.5 dB of PSNR at 50-500 kB/s. Drawing a half in a colour already in effect when it is
//!   within the JND (pen reuse) was tried as well and measured at -0.2 to +0.2 dB, so it was
//!   left out.
//! - Only the most promising candidates are weighed in full (their variants and steps): all
//!   are measured, ordered by the most error per byte they could possibly remove, and weighed
//!   in that order until their bytes reach a few budgets (more if the budget outlasts them).
//! - When nothing changes, the encoder keeps spending the budget on what is left: every
//!   remaining difference is a candidate of some tier, and no cell is approximated twice once
//!   it is below the JND, so a still picture converges to the exact frame (bit-exact truecolor
//!   at threshold 0; the mode's exact palette colours in 256 and 16 colours) within about two
//!   redraws' worth of budget.
//! - An unknown screen (the first frame, after a resize) is painted whole when the budget
//!   allows, exactly as today; otherwise it is cleared first (`ESC[0m ESC[2J`, so that the
//!   model is known) and painted over the following frames, coarse before exact.
//! - With an unlimited budget ([`UNLIMITED`]), or whenever every change fits, every candidate
//!   is drawn exactly, in screen order: the bytes are exactly those of
//!   [`crate::output::diff::encode_into`], except that a frame of a single cell goes without
//!   the synchronized-output markers (one cell cannot tear).

mod candidates;
mod emit;
mod variants;

use tiny_skia::Pixmap;

use self::candidates::{Item, MAX_VARIANTS, Measure, Weighing};
use self::emit::{EXACT, Pen, Plan, Room, SKIP};
use self::variants::{LabMemo, Palette};
use crate::output::color::{Color, ColorMode};
use crate::output::diff::{EncodeOptions, SYNC_BEGIN, SYNC_END, Shown};
use crate::output::frame::{Cell, Frame};
use crate::output::oklab::JND;

/// A budget that never runs out: every change is sent exactly.
pub const UNLIMITED: usize = usize::MAX;

/// What `budget` leaves once `spent` bytes are taken from it: [`UNLIMITED`] stays unlimited
/// (a plain subtraction would turn it into a huge but finite budget, which the picture stream
/// reads as a link with a rate: lossy JPEG for iTerm2 under `--bandwidth unlimited`).
#[cfg(feature = "player")]
pub(crate) fn budget_after(budget: usize, spent: usize) -> usize {
    if budget == UNLIMITED { UNLIMITED } else { budget.saturating_sub(spent) }
}
/// The error of a text cell whose glyph or colours are wrong (or of any cell the encoder
/// cannot measure, such as one in the terminal's default colours): more than a picture cell
/// can have (the OKLab distance between two sRGB colours is at most about 1, and a cell has
/// two halves), so text is always sent first.
pub const TEXT_MISMATCH_ERROR: f32 = 8.0;
/// The bytes a cursor move is guessed to take when the cell's left neighbour is not drawn
/// too (`ESC[nC` is 4 or 5 bytes; a short gap re-printed costs about as much).
pub const MOVE_ESTIMATE: usize = 4;
/// Layouts tried per frame to fit the exact bytes to the budget.
const MAX_LAYOUTS: usize = 6;
/// A layout that leaves less than this fraction (1/N) of the budget unspent is kept: another
/// layout costs as much CPU as the first, and what is left carries over in the bucket.
const GOOD_ENOUGH: usize = 16;
/// After a layout, the next one aims at this share of the budget (by the estimates calibrated
/// on the layout), so that it likely fits.
const AIM: f64 = 0.97;
/// The most bytes one cell can take: a cursor jump (`ESC[rrrrr;cccccH`), both truecolor codes
/// in one SGR and a three-byte glyph.
const MAX_CELL_BYTES: usize = 56;
/// Clears the screen to the default colours: what an unknown screen becomes when it cannot be
/// painted whole.
pub const CLEAR: &[u8] = b"\x1b[0m\x1b[2J";

/// Which cells go first when the budget is short.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Strategy {
    /// The most error removed per byte, noticeable errors first (the encoder).
    ErrorPerByte,
    /// Changed cells in screen order until the budget runs out (the naive baseline the codec
    /// benchmark compares against).
    ScanOrder,
}

/// How frames are encoded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RateOptions {
    /// A colour that changed by at most this much in every channel is not re-sent (0: exact),
    /// as in [`EncodeOptions::threshold`].
    pub threshold: u8,
    /// Wrap each frame in synchronized output.
    pub sync: bool,
    /// The just-noticeable difference in OKLab units: errors below it wait while larger ones
    /// are pending.
    pub jnd: f32,
    /// The order cells are sent in.
    pub strategy: Strategy,
    /// Allow a cell to be sent approximately (one mean colour) when that buys more per byte.
    pub approximate: bool,
}

impl Default for RateOptions {
    fn default() -> Self {
        RateOptions { threshold: 0, sync: true, jnd: JND, strategy: Strategy::ErrorPerByte, approximate: true }
    }
}

impl From<EncodeOptions> for RateOptions {
    fn from(o: EncodeOptions) -> Self {
        RateOptions { threshold: o.threshold, sync: o.sync, ..RateOptions::default() }
    }
}

/// The frame wanted next, and the true colours its pixel cells stand for.
#[derive(Clone, Copy, Debug)]
pub struct Target<'a> {
    /// The cells to show, their colours already in the terminal's colour mode.
    pub frame: &'a Frame,
    /// The picture `frame`'s pixel cells were drawn from (at its top-left corner, two pixel
    /// rows a cell, as [`Frame::draw_pixels`] does) and the colour mode that drew them: errors
    /// are measured against these true colours. `None`: the frame's own colours are the truth
    /// (right for truecolor).
    pub truth: Option<(&'a Pixmap, ColorMode)>,
}

impl<'a> Target<'a> {
    /// A frame whose colours are the truth (truecolor).
    pub fn new(frame: &'a Frame) -> Target<'a> {
        Target { frame, truth: None }
    }

    /// A frame drawn from `picture` in `mode`: in 256 and 16 colours, errors are measured
    /// against the picture's true colours (the wanted frame is still what the screen
    /// converges to). Cells that do not match the picture's quantized colour (overlays) are
    /// their own truth.
    pub fn with_truth(frame: &'a Frame, picture: &'a Pixmap, mode: ColorMode) -> Target<'a> {
        Target { frame, truth: Some((picture, mode)) }
    }
}

/// What a frame did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Report {
    /// Bytes appended (0 when nothing was sent).
    pub bytes: usize,
    /// Cells drawn.
    pub drawn: usize,
    /// Cells that still differ from the wanted frame afterwards (0: the screen is exact).
    pub pending: usize,
}

/// The rate-controlled encoder: scratch buffers only, no state that changes what it sends.
#[derive(Clone, Debug, Default)]
pub struct RateEncoder {
    items: Vec<Item>,
    /// The candidates' sort keys (see `candidates::order_key`).
    order: Vec<u64>,
    /// Per cell: its bytes drawn exactly alone, and its errors (valid for candidates).
    fresh: Vec<u16>,
    measures: Vec<Measure>,
    /// Per cell, its nearest palette colours and the frame count they were found at.
    palettes: Vec<(u32, Palette)>,
    /// Frames encoded (wrapping), to stamp per-frame memos.
    frames: u32,
    /// Candidates picked to be weighed next.
    pick: Vec<bool>,
    /// How many candidates of `order` are weighed, and how.
    weighed: usize,
    weighing: Weighing,
    choice: Vec<u8>,
    /// Per cell, 1 + the place on its hull of the furthest step chosen (0: none).
    furthest: Vec<u8>,
    variants: Vec<[Cell; MAX_VARIANTS]>,
    candidate: Vec<bool>,
    shown_lab: LabMemo,
    truth_lab: LabMemo,
    attempt: (Vec<u8>, Vec<(u32, Cell)>),
    /// How many of the sorted steps the best layout took.
    best_taken: usize,
    best: (Vec<u8>, Vec<(u32, Cell)>),
}

#[cfg(test)]
/// Encodes the change from `shown` towards `target` within `budget` bytes: returns the bytes
/// and what the terminal shows after them. Allocates its scratch; a player keeps a
/// [`RateEncoder`] instead.
pub fn encode(shown: &Shown, target: Target<'_>, budget: usize, options: RateOptions) -> (Vec<u8>, Shown) {
    let mut out = Vec::new();
    let mut state = shown.clone();
    RateEncoder::default().encode_into(&mut state, target, budget, options, &mut out);
    (out, state)
}

impl RateEncoder {
    /// An encoder with empty scratch buffers (the screens borrow theirs from the process's
    /// pool, `play::screen::scratch`; this is for the tests and benches).
    #[cfg(any(test, feature = "testing"))]
    pub fn new() -> RateEncoder {
        RateEncoder::default()
    }

    /// Appends to `out` at most `budget` bytes that bring the terminal from `shown` towards
    /// `target`, and updates `shown` to what the terminal shows after them.
    pub fn encode_into(
        &mut self,
        shown: &mut Shown,
        target: Target<'_>,
        budget: usize,
        options: RateOptions,
        out: &mut Vec<u8>,
    ) -> Report {
        let wanted = target.frame;
        let (cols, rows) = (wanted.cols(), wanted.rows());
        let cells = cols * rows;
        self.prepare(cells, out);
        let overhead = if options.sync { SYNC_BEGIN.len() + SYNC_END.len() } else { 0 };
        let mut pen = Pen { cursor: shown.cursor, fg: shown.fg, bg: shown.bg };
        let known = shown.frame.as_ref().is_some_and(|f| f.cols() == cols && f.rows() == rows);
        let mut prefix: &[u8] = &[];
        if !known {
            match self.start_unknown(shown, wanted, budget, options, out) {
                Unknown::Done(report) => return report,
                Unknown::Cleared => {
                    pen.fg = Some(Color::Default);
                    pen.bg = Some(Color::Default);
                    prefix = CLEAR;
                }
            }
        }
        let frame = shown.frame.as_mut().expect("known or just cleared");
        let room = if budget == UNLIMITED {
            Room { one: UNLIMITED, many: UNLIMITED }
        } else if prefix.is_empty() {
            Room { one: budget, many: budget.saturating_sub(overhead) }
        } else {
            let left = budget.saturating_sub(overhead + prefix.len());
            Room { one: left, many: left }
        };
        let weigh = budget != UNLIMITED && options.strategy == Strategy::ErrorPerByte;
        let (candidates, alone) = self.mark(frame, wanted, options, weigh);
        let end = match self.everything_fits(frame, wanted, pen, room, alone, options) {
            Some(end) => end,
            None => {
                let mut cutoff = self.candidates(frame, target, room, alone, options);
                let mut end = self.choose(frame, wanted, pen, room);
                let mut more = candidates::reach(room);
                while cutoff.is_some() && self.needs_more() {
                    // The steps weighed ran out before the budget did: weigh more, four times
                    // as many bytes' worth each time.
                    more = more.saturating_mul(4);
                    cutoff = self.weigh_upto(wanted, more);
                    end = self.choose(frame, wanted, pen, room);
                }
                end
            }
        };
        let drawn = self.best.1.len();
        let exact = self.best.1.iter().filter(|&&(i, c)| c == wanted.cells()[i as usize]).count();
        let start = out.len();
        if !self.best.0.is_empty() || !prefix.is_empty() {
            // One cell cannot tear: it goes without the synchronized-output markers.
            wrap(out, options.sync && (drawn > 1 || !prefix.is_empty()), prefix, &self.best.0);
        }
        for &(i, cell) in &self.best.1 {
            let i = i as usize;
            frame.set(i % cols, i / cols, cell);
        }
        (shown.cursor, shown.fg, shown.bg) = (end.cursor, end.fg, end.bg);
        Report { bytes: out.len() - start, drawn, pending: candidates - exact }
    }

    /// Sizes the per-cell scratch for `cells` cells, and reserves room for the largest frame
    /// once, so that frames growing past the ones before never reallocate in the steady state.
    fn prepare(&mut self, cells: usize, out: &mut Vec<u8>) {
        self.choice.resize(cells, SKIP);
        self.variants.resize(cells, [Cell::BLANK; MAX_VARIANTS]);
        self.candidate.resize(cells, false);
        self.fresh.resize(cells, 0);
        self.pick.resize(cells, false);
        self.measures.resize(cells, Measure::default());
        self.palettes.resize(cells, (0, Palette::default()));
        self.shown_lab.resize(cells);
        self.truth_lab.resize(cells);
        let most = cells * MAX_CELL_BYTES + CLEAR.len() + SYNC_BEGIN.len() + SYNC_END.len();
        for buffer in [&mut self.best.0, &mut self.attempt.0, &mut *out] {
            buffer.reserve(most.saturating_sub(buffer.len()));
        }
        for drawn in [&mut self.best.1, &mut self.attempt.1] {
            drawn.reserve(cells.saturating_sub(drawn.len()));
        }
    }

    /// A screen whose contents are unknown (the first frame, or a new size): the whole frame
    /// when it fits the budget, exactly as the plain encoder paints it; else nothing when not
    /// even a clear fits; else the screen is taken as cleared, to be painted over the next
    /// frames (the caller sends the clear in front of this frame's cells).
    fn start_unknown(
        &mut self,
        shown: &mut Shown,
        wanted: &Frame,
        budget: usize,
        options: RateOptions,
        out: &mut Vec<u8>,
    ) -> Unknown {
        let (cols, rows) = (wanted.cols(), wanted.rows());
        let cells = cols * rows;
        let overhead = if options.sync { SYNC_BEGIN.len() + SYNC_END.len() } else { 0 };
        let pen = Pen { cursor: shown.cursor, fg: shown.fg, bg: shown.bg };
        self.choice.fill(EXACT);
        self.attempt.0.clear();
        self.attempt.1.clear();
        let plan = Plan { shown: wanted, wanted, choice: &self.choice, variants: &self.variants };
        let end = plan.emit(pen, None, &mut self.attempt.0, &mut self.attempt.1);
        let markers = if cells > 1 { overhead } else { 0 };
        if self.attempt.0.len().saturating_add(markers) <= budget {
            let start = out.len();
            wrap(out, options.sync && cells > 1, &[], &self.attempt.0);
            match &mut shown.frame {
                Some(f) => f.clone_from(wanted),
                None => shown.frame = Some(wanted.clone()),
            }
            (shown.cursor, shown.fg, shown.bg) = (end.cursor, end.fg, end.bg);
            return Unknown::Done(Report { bytes: out.len() - start, drawn: cells, pending: 0 });
        }
        if budget < overhead + CLEAR.len() {
            return Unknown::Done(Report { bytes: 0, drawn: 0, pending: cells });
        }
        match &mut shown.frame {
            Some(f) => f.reset(cols, rows),
            None => shown.frame = Some(Frame::new(cols, rows)),
        }
        Unknown::Cleared
    }
}

/// What became of a frame on a screen whose contents were unknown.
enum Unknown {
    /// The frame was sent whole, or nothing fitted: this is the frame's report.
    Done(Report),
    /// The screen is taken as cleared (a clear goes in front of the frame's cells).
    Cleared,
}

impl RateEncoder {
    /// Chooses which steps to send within `room` and lays them out; the bytes and the drawn
    /// cells are left in `self.best`. Returns the pen afterwards.
    fn choose(&mut self, shown: &Frame, wanted: &Frame, pen: Pen, room: Room) -> Pen {
        self.best.0.clear();
        self.best.1.clear();
        self.best_taken = 0;
        if self.items.is_empty() {
            return pen;
        }
        let n = self.items.len();
        // Only the front of the order matters: sort what the budget could reach (by the
        // cheapest step, twice over), and more later if a layout needs it.
        let cheapest = self.items.iter().map(|i| i.cost.max(1) as usize).min().unwrap_or(1);
        let mut sorted = 0;
        self.sort_front(&mut sorted, (2 * room.many / cheapest).saturating_add(64).min(n));
        let fits = |items: &[Item], from: usize, bytes: usize| {
            let (mut k, mut sum) = (from, 0usize);
            while k < items.len() && sum + items[k].cost as usize <= bytes {
                sum += items[k].cost as usize;
                k += 1;
            }
            k
        };
        // At least the most valuable step, which may go alone without the markers.
        let mut k = fits(&self.items[..sorted], 0, room.many).max(1);
        let (mut best_k, mut best_pen) = (0, pen);
        for layout in 0..MAX_LAYOUTS {
            self.set_choice(k);
            self.attempt.0.clear();
            self.attempt.1.clear();
            let plan = Plan { shown, wanted, choice: &self.choice, variants: &self.variants };
            // The last layout stops where the budget does, so that it always fits.
            let last = layout + 1 == MAX_LAYOUTS;
            let end = plan.emit(pen, last.then_some(room), &mut self.attempt.0, &mut self.attempt.1);
            let (cost, drawn) = (self.attempt.0.len(), self.attempt.1.len());
            let fit = room.fits(cost, drawn);
            if fit && drawn > self.best.1.len() {
                std::mem::swap(&mut self.attempt, &mut self.best);
                (best_k, best_pen) = (k, end);
                self.best_taken = k;
            }
            let limit = if drawn <= 1 { room.one } else { room.many };
            // Close enough: what is left carries over to the next frame in the bucket.
            if fit && (k == n || limit - cost < limit / GOOD_ENOUGH) {
                break;
            }
            // Calibrate the estimates by this layout and aim a little under the budget.
            let estimated: usize = self.items[..k].iter().map(|i| i.cost as usize).sum();
            let scale = estimated.max(1) as f64 / cost.max(1) as f64;
            let aim = (limit as f64 * scale * AIM) as usize;
            self.sort_front(&mut sorted, (2 * aim / cheapest).saturating_add(64).min(n));
            let next = fits(&self.items[..sorted], 0, aim);
            k = match fit {
                true if next <= k => break,
                true => next,
                // Over: fewer steps, at least one fewer, never fewer than a layout that fit.
                false => next.min(k - 1).max(best_k + 1).min(k - 1),
            };
            if k == 0 || !fit && k <= best_k {
                break;
            }
        }
        best_pen
    }

    /// Draws every candidate exactly when that fits in `room` (or the budget is unlimited, or
    /// the order is the naive one, which draws them in screen order until the budget runs
    /// out): nothing to weigh then. `alone` is the candidates' bytes drawn one by one, which
    /// their bytes in runs rarely exceed by much.
    fn everything_fits(
        &mut self,
        shown: &Frame,
        wanted: &Frame,
        pen: Pen,
        room: Room,
        alone: usize,
        options: RateOptions,
    ) -> Option<Pen> {
        self.best.0.clear();
        self.best.1.clear();
        let unlimited = room.many == UNLIMITED;
        let naive = options.strategy == Strategy::ScanOrder;
        if !unlimited && !naive && alone / 2 > room.many {
            return None;
        }
        for (c, &candidate) in self.choice.iter_mut().zip(&self.candidate) {
            *c = if candidate { EXACT } else { SKIP };
        }
        let plan = Plan { shown, wanted, choice: &self.choice, variants: &self.variants };
        let limit = (naive && !unlimited).then_some(room);
        let end = plan.emit(pen, limit, &mut self.best.0, &mut self.best.1);
        if unlimited || naive || room.fits(self.best.0.len(), self.best.1.len()) {
            return Some(end);
        }
        self.best.0.clear();
        self.best.1.clear();
        None
    }

    /// Whether the chosen steps took every step weighed: the budget outlasted them, so more
    /// candidates are worth weighing.
    fn needs_more(&self) -> bool {
        self.best_taken == self.items.len()
    }

    /// Puts the `upto` most valuable steps first, in order (the first `sorted` already are).
    fn sort_front(&mut self, sorted: &mut usize, upto: usize) {
        if upto <= *sorted {
            return;
        }
        let rest = &mut self.items[*sorted..];
        let m = upto - *sorted;
        if m < rest.len() {
            rest.select_nth_unstable_by_key(m, |item| item.order);
        }
        rest[..m].sort_unstable_by_key(|item| item.order);
        *sorted = upto;
    }

    /// Sets `self.choice` from the first `k` steps: each cell is drawn with the variant of the
    /// furthest of its steps among them. A cell's steps run from the cheapest way to draw it
    /// to the exact cell, each improving on the one before, so the furthest step paid for is
    /// the best way paid for (the variants' ranks are not in that order: a space in the
    /// nearest palette colour of the mean costs less than a space in the mean itself).
    fn set_choice(&mut self, k: usize) {
        self.choice.fill(SKIP);
        self.furthest.clear();
        self.furthest.resize(self.choice.len(), 0);
        for item in &self.items[..k] {
            let (cell, step) = (item.cell(), item.step() + 1);
            if step > self.furthest[cell] {
                self.furthest[cell] = step;
                self.choice[cell] = item.rank();
            }
        }
    }
}

/// Appends `body` wrapped in synchronized output (when `sync`), after `prefix`.
fn wrap(out: &mut Vec<u8>, sync: bool, prefix: &[u8], body: &[u8]) {
    if sync {
        out.extend_from_slice(SYNC_BEGIN);
    }
    out.extend_from_slice(prefix);
    out.extend_from_slice(body);
    if sync {
        out.extend_from_slice(SYNC_END);
    }
}

#[cfg(test)]
mod tests;
