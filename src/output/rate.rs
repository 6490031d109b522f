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
//!   pen and cursor as the cell's left neighbour would leave them, when that neighbour changes
//!   too; otherwise a fresh pen and a [`MOVE_ESTIMATE`]-byte move) and then *drawn* in screen
//!   order with exact accounting; if the exact bytes overshoot, the least valuable cells are
//!   dropped and the frame is laid out again (and more are added while bytes are left), so a
//!   frame never exceeds its budget.
//! - Cells go in order of error removed per byte, but in tiers: every cell whose error is at
//!   least a just-noticeable difference (either half at least [`crate::output::oklab::JND`]
//!   from its true colour) goes before any cell below it; cells whose exact colours would not
//!   bring them closer to the true colours (in 256 and 16 colours the shown colour can be as
//!   good as the wanted one) go last, so that the screen still converges to the exact frame.
//! - An approximate variant (when [`RateOptions::approximate`]): a cell whose two halves
//!   differ can be drawn as a space of their mean colour, for one colour code instead of two.
//!   When it removes more error per byte than the exact cell it is sent first, and the exact
//!   cell follows as an upgrade when the budget allows (in that frame or a later one). Measured
//!   on the codec fixture (see `benches/codec.rs`), it gains PSNR under tight budgets; with the
//!   budget to spare, every cell is exact.
//! - When nothing changes, the encoder keeps spending the budget on what is left: every
//!   remaining difference is a candidate of some tier, so a still picture converges to the
//!   exact frame (bit-exact truecolor at threshold 0; the mode's exact palette colours in 256
//!   and 16 colours) within about (bytes of a full redraw) / (budget per frame) frames.
//! - An unknown screen (the first frame, after a resize) is painted whole when the budget
//!   allows, exactly as today; otherwise it is cleared first (`ESC[0m ESC[2J`, so that the
//!   model is known) and painted over the following frames, largest errors first.
//! - With an unlimited budget ([`UNLIMITED`]) every candidate is drawn exactly, in screen
//!   order: the bytes are exactly those of [`crate::output::diff::encode_into`].

mod emit;

use tiny_skia::Pixmap;

use self::emit::{EXACT, FLAT, Pen, Plan, Room, SKIP};
use crate::output::color::{Color, ColorMode};
use crate::output::diff::{EncodeOptions, SYNC_BEGIN, SYNC_END, Shown, best_draw};
use crate::output::frame::{Cell, Frame};
use crate::output::halfblock::Rgb;
use crate::output::oklab::{self, JND, Lab};

/// A budget that never runs out: every change is sent exactly.
pub const UNLIMITED: usize = usize::MAX;
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

/// One step of a cell's improvement: its approximate variant, or from there (or from what is
/// shown) to exact.
#[derive(Clone, Copy, Debug)]
struct Item {
    /// 0: a noticeable error; 1: below the JND; 2: no error removed (convergence only).
    tier: u8,
    /// Error removed per byte.
    ratio: f32,
    /// The cell's index.
    cell: u32,
    /// [`FLAT`] or [`EXACT`].
    variant: u8,
    /// Estimated bytes of this step.
    cost: u32,
}

/// `rgb` packed with a valid bit, as a memo key (0: nothing memoized).
fn key(rgb: Rgb) -> u32 {
    1 << 24 | u32::from(rgb[0]) << 16 | u32::from(rgb[1]) << 8 | u32::from(rgb[2])
}

/// OKLab values remembered per cell half, recomputed only when the colour changes.
#[derive(Clone, Debug, Default)]
struct LabMemo {
    entries: Vec<[(u32, Lab); 2]>,
}

impl LabMemo {
    fn resize(&mut self, cells: usize) {
        self.entries.resize(cells, [(0, Lab::default()); 2]);
    }

    #[inline]
    fn get(&mut self, cell: usize, half: usize, rgb: Rgb) -> Lab {
        let entry = &mut self.entries[cell][half];
        let k = key(rgb);
        if entry.0 != k {
            *entry = (k, oklab::from_rgb(rgb));
        }
        entry.1
    }
}

/// The rate-controlled encoder: scratch buffers only, no state that changes what it sends.
#[derive(Clone, Debug, Default)]
pub struct RateEncoder {
    items: Vec<Item>,
    choice: Vec<u8>,
    flat: Vec<Color>,
    candidate: Vec<bool>,
    shown_lab: LabMemo,
    truth_lab: LabMemo,
    attempt: (Vec<u8>, Vec<(u32, Cell)>),
    best: (Vec<u8>, Vec<(u32, Cell)>),
}

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
    /// An encoder with empty scratch buffers.
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
        self.choice.resize(cells, SKIP);
        self.flat.resize(cells, Color::Default);
        self.candidate.resize(cells, false);
        self.shown_lab.resize(cells);
        self.truth_lab.resize(cells);
        let overhead = if options.sync { SYNC_BEGIN.len() + SYNC_END.len() } else { 0 };
        let mut pen = Pen { cursor: shown.cursor, fg: shown.fg, bg: shown.bg };
        let known = shown.frame.as_ref().is_some_and(|f| f.cols() == cols && f.rows() == rows);
        let mut prefix: &[u8] = &[];
        if !known {
            // Paint everything when it fits, exactly as today's encoder does.
            self.choice.fill(EXACT);
            self.attempt.0.clear();
            self.attempt.1.clear();
            let plan = Plan { shown: wanted, wanted, choice: &self.choice, flat: &self.flat };
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
                return Report { bytes: out.len() - start, drawn: cells, pending: 0 };
            }
            if budget < overhead + CLEAR.len() {
                return Report { bytes: 0, drawn: 0, pending: cells };
            }
            // Too big for the budget: clear the screen so that what it shows is known, and
            // paint it over the next frames.
            match &mut shown.frame {
                Some(f) => f.reset(cols, rows),
                None => shown.frame = Some(Frame::new(cols, rows)),
            }
            pen.fg = Some(Color::Default);
            pen.bg = Some(Color::Default);
            prefix = CLEAR;
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
        let candidates = self.candidates(frame, target, room, options);
        let end = self.choose(frame, wanted, pen, room, options);
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
}

/// A cell's errors: what is shown, drawn exactly, and drawn as its flat variant.
#[derive(Clone, Copy, Debug)]
struct Measure {
    /// The error of what is shown now.
    shown: f32,
    /// The error once drawn exactly (0 in truecolor; the quantization error in palettes).
    exact: f32,
    /// Whether what is shown is at least a just-noticeable difference off.
    noticeable: bool,
    /// The flat variant's colour and error, when it has one.
    flat: Option<(Color, f32)>,
    /// For convergence when drawing exactly removes no error: how far the shown cell is from
    /// the wanted one.
    distance: f32,
}

impl RateEncoder {
    /// Lists the candidates' improvement steps in `self.items` (and their flat colours in
    /// `self.flat`); returns the number of candidate cells.
    fn candidates(&mut self, shown: &Frame, target: Target<'_>, room: Room, options: RateOptions) -> usize {
        self.items.clear();
        let wanted = target.frame;
        let cols = wanted.cols();
        let (mut count, mut alone) = (0, 0);
        for (i, (s, w)) in shown.cells().iter().zip(wanted.cells()).enumerate() {
            let changed = !s.close_to(w, options.threshold);
            self.candidate[i] = changed;
            if changed {
                count += 1;
                alone += best_draw(*w, None, None).len(None, None) + MOVE_ESTIMATE;
            }
        }
        // How likely a candidate's left neighbour is drawn too: about the share of all the
        // candidates that the budget pays for.
        let together = (room.many as f32 / alone.max(1) as f32).min(1.0);
        let cost_of = |cell: Cell, left: Option<Cell>| {
            let fresh = (best_draw(cell, None, None).len(None, None) + MOVE_ESTIMATE) as f32;
            match left {
                Some(left) => {
                    let pen = best_draw(left, None, None);
                    let after = best_draw(cell, pen.fg, pen.bg).len(pen.fg, pen.bg) as f32;
                    together * after + (1.0 - together) * fresh
                }
                None => fresh,
            }
        };
        for i in 0..wanted.cells().len() {
            if !self.candidate[i] {
                continue;
            }
            if options.strategy == Strategy::ScanOrder {
                self.items.push(Item { tier: 0, ratio: 0.0, cell: i as u32, variant: EXACT, cost: 0 });
                continue;
            }
            let (x, y) = (i % cols, i / cols);
            let (s, w) = (shown.cells()[i], wanted.cells()[i]);
            // The pen and cursor this cell finds: its left neighbour's when that neighbour is
            // drawn too, otherwise a jump and fresh colour codes.
            let left = (x > 0 && self.candidate[i - 1]).then(|| wanted.cells()[i - 1]);
            let exact_cost = cost_of(w, left).max(1.0);
            let m = self.measure(i, (x, y), s, w, target, options);
            let exact_benefit = m.shown - m.exact;
            let tier = match (exact_benefit > 0.0, m.noticeable) {
                (true, true) => 0,
                (true, false) => 1,
                (false, _) => 2,
            };
            if tier == 2 {
                let ratio = m.distance / exact_cost;
                self.items.push(Item { tier, ratio, cell: i as u32, variant: EXACT, cost: exact_cost as u32 });
                continue;
            }
            if tier == 0
                && let Some((colour, flat_error)) = m.flat
            {
                let flat_cost = cost_of(Cell::Pixels { top: colour, bottom: colour }, left).max(1.0);
                let flat_benefit = m.shown - flat_error;
                if flat_benefit > 0.0 && flat_cost < exact_cost && flat_benefit * exact_cost > exact_benefit * flat_cost
                {
                    self.flat[i] = colour;
                    let cell = i as u32;
                    self.items.push(Item {
                        tier,
                        ratio: flat_benefit / flat_cost,
                        cell,
                        variant: FLAT,
                        cost: flat_cost as u32,
                    });
                    if exact_benefit > flat_benefit {
                        let (benefit, cost) = (exact_benefit - flat_benefit, exact_cost - flat_cost);
                        self.items.push(Item { tier, ratio: benefit / cost, cell, variant: EXACT, cost: cost as u32 });
                    }
                    continue;
                }
            }
            let ratio = exact_benefit / exact_cost;
            self.items.push(Item { tier, ratio, cell: i as u32, variant: EXACT, cost: exact_cost as u32 });
        }
        count
    }

    /// The errors of cell `i` at `(x, y)`, shown as `s`, wanted as `w`.
    fn measure(
        &mut self,
        i: usize,
        (x, y): (usize, usize),
        s: Cell,
        w: Cell,
        target: Target<'_>,
        options: RateOptions,
    ) -> Measure {
        let unmeasurable = Measure {
            shown: TEXT_MISMATCH_ERROR,
            exact: 0.0,
            noticeable: true,
            flat: None,
            distance: TEXT_MISMATCH_ERROR,
        };
        let Cell::Pixels { top: wt, bottom: wb } = w else { return unmeasurable };
        let (Some(wt_rgb), Some(wb_rgb)) = (wt.rgb(), wb.rgb()) else { return unmeasurable };
        let (rt, rb) = match target.truth {
            Some((picture, mode)) => (
                truth(picture, mode, (x, 2 * y), wt).unwrap_or(wt_rgb),
                truth(picture, mode, (x, 2 * y + 1), wb).unwrap_or(wb_rgb),
            ),
            None => (wt_rgb, wb_rgb),
        };
        let (lrt, lrb) = (self.truth_lab.get(i, 0, rt), self.truth_lab.get(i, 1, rb));
        let exact = if (wt_rgb, wb_rgb) == (rt, rb) {
            0.0
        } else {
            oklab::from_rgb(wt_rgb).distance2(lrt) + oklab::from_rgb(wb_rgb).distance2(lrb)
        };
        let flat = (options.approximate && wt != wb).then(|| {
            let mean = [0, 1, 2].map(|c| (u16::from(rt[c]) + u16::from(rb[c])).div_ceil(2) as u8);
            match target.truth {
                Some((_, mode)) => {
                    let colour = mode.quantize(mean, x as u32, 2 * y as u32);
                    let lab = colour.rgb().map_or(lrt, oklab::from_rgb);
                    (colour, lab.distance2(lrt) + lab.distance2(lrb))
                }
                // The mean's OKLab is close to the mean of the two OKLab values, which are
                // each half their distance from it.
                None => (Color::Rgb(mean), lrt.distance2(lrb) / 2.0),
            }
        });
        let (shown, noticeable, distance) = match s {
            Cell::Pixels { top: st, bottom: sb } => match (st.rgb(), sb.rgb()) {
                (Some(st_rgb), Some(sb_rgb)) => {
                    let (lst, lsb) = (self.shown_lab.get(i, 0, st_rgb), self.shown_lab.get(i, 1, sb_rgb));
                    let (dt, db) = (lst.distance2(lrt), lsb.distance2(lrb));
                    let jnd2 = options.jnd * options.jnd;
                    let distance = lst.distance2(oklab::from_rgb(wt_rgb)) + lsb.distance2(oklab::from_rgb(wb_rgb));
                    (dt + db, dt.max(db) >= jnd2, distance)
                }
                _ => (TEXT_MISMATCH_ERROR, true, TEXT_MISMATCH_ERROR),
            },
            Cell::Text { .. } => (TEXT_MISMATCH_ERROR, true, TEXT_MISMATCH_ERROR),
        };
        Measure { shown, exact, noticeable, flat, distance }
    }

    /// Chooses which steps to send within `room` and lays them out; the bytes and the drawn
    /// cells are left in `self.best`. Returns the pen afterwards.
    fn choose(&mut self, shown: &Frame, wanted: &Frame, pen: Pen, room: Room, options: RateOptions) -> Pen {
        self.best.0.clear();
        self.best.1.clear();
        if self.items.is_empty() {
            return pen;
        }
        let unlimited = room.many == UNLIMITED;
        if unlimited || options.strategy == Strategy::ScanOrder {
            // Every candidate, exactly, in screen order (until the budget runs out).
            self.set_choice(self.items.len());
            for c in self.choice.iter_mut().filter(|c| **c != SKIP) {
                *c = EXACT;
            }
            let plan = Plan { shown, wanted, choice: &self.choice, flat: &self.flat };
            let limit = (!unlimited).then_some(room);
            return plan.emit(pen, limit, &mut self.best.0, &mut self.best.1);
        }
        self.items.sort_unstable_by(|a, b| {
            a.tier
                .cmp(&b.tier)
                .then(b.ratio.total_cmp(&a.ratio))
                .then(a.cell.cmp(&b.cell))
                .then(a.variant.cmp(&b.variant))
        });
        let n = self.items.len();
        let fits = |items: &[Item], from: usize, bytes: usize| {
            let (mut k, mut sum) = (from, 0usize);
            while k < items.len() && sum + items[k].cost as usize <= bytes {
                sum += items[k].cost as usize;
                k += 1;
            }
            k
        };
        // At least the most valuable step, which may go alone without the markers.
        let mut k = fits(&self.items, 0, room.many).max(1);
        let (mut best_k, mut best_pen) = (0, pen);
        for layout in 0..MAX_LAYOUTS {
            self.set_choice(k);
            self.attempt.0.clear();
            self.attempt.1.clear();
            let plan = Plan { shown, wanted, choice: &self.choice, flat: &self.flat };
            // The last layout stops where the budget does, so that it always fits.
            let last = layout + 1 == MAX_LAYOUTS;
            let end = plan.emit(pen, last.then_some(room), &mut self.attempt.0, &mut self.attempt.1);
            let (cost, drawn) = (self.attempt.0.len(), self.attempt.1.len());
            let fit = room.fits(cost, drawn);
            if std::env::var_os("RATE_DEBUG").is_some() {
                eprintln!(
                    "layout {layout}: k {k} of {n}, cost {cost}, drawn {drawn}, room {room:?}, fit {fit}, first {:?}",
                    &self.items[..3.min(n)]
                );
            }
            if fit && drawn > self.best.1.len() {
                std::mem::swap(&mut self.attempt, &mut self.best);
                (best_k, best_pen) = (k, end);
            }
            if fit {
                if k == n {
                    break;
                }
                let more = fits(&self.items, k, room.many.saturating_sub(cost));
                if more == k {
                    break;
                }
                k = more;
            } else {
                // Drop the least valuable steps: as many as the estimate says save the excess
                // (and half as much again), but no more than in proportion to the overshoot,
                // in case the estimates were much too low.
                let limit = if drawn <= 1 { room.one } else { room.many };
                let excess = (cost - limit) * 3 / 2;
                let proportional = (k as f64 * limit as f64 / cost as f64 * 0.9) as usize;
                let (mut shrunk, mut removed) = (k, 0);
                while shrunk > best_k && removed < excess {
                    shrunk -= 1;
                    removed += self.items[shrunk].cost as usize;
                }
                k = shrunk.max(proportional.min(k - 1));
                if k <= best_k && !self.best.1.is_empty() || k == 0 {
                    break;
                }
            }
        }
        best_pen
    }

    /// Sets `self.choice` from the first `k` steps: each cell's highest variant among them.
    fn set_choice(&mut self, k: usize) {
        self.choice.fill(SKIP);
        for item in &self.items[..k] {
            let c = &mut self.choice[item.cell as usize];
            *c = (*c).max(item.variant);
        }
    }
}

/// The true colour of picture pixel `(x, y)` when the wanted colour is its quantization in
/// `mode` (otherwise the cell holds something else, such as an overlay).
fn truth(picture: &Pixmap, mode: ColorMode, (x, y): (usize, usize), wanted: Color) -> Option<Rgb> {
    if x >= picture.width() as usize || y >= picture.height() as usize {
        return None;
    }
    let c = picture.pixels()[y * picture.width() as usize + x].demultiply();
    let rgb = [c.red(), c.green(), c.blue()];
    (mode.quantize(rgb, x as u32, y as u32) == wanted).then_some(rgb)
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
