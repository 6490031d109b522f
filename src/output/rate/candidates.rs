//! The candidates of a frame: which cells differ, how wrong each is, the ways to draw it
//! (exactly, or one of the cheaper approximations), and what each way buys per byte.
//!
//! A cell's ways of being drawn are points (bytes, error removed). Only the points on the
//! upper convex hull from (0, 0) are worth sending (any other is beaten by a mix of its
//! neighbours), and the steps between consecutive hull points have falling error per byte, so
//! a greedy choice over all cells' steps, best ratio first, takes each cell's steps in order:
//! the classic greedy of the multiple-choice knapsack.

use super::emit::{EXACT, Room};
use super::variants::{Approximation, Palette, lab_of, pixel_colours, truth};
use super::{MOVE_ESTIMATE, RateEncoder, RateOptions, TEXT_MISMATCH_ERROR, Target};
use crate::output::color::{Color, ColorMode};
use crate::output::diff::{FULL, UPPER, best_draw, color_params_len};
use crate::output::frame::{Cell, Frame};
use crate::output::halfblock::Rgb;
use crate::output::oklab::Lab;

/// The most ways to draw a cell: three approximations and the exact cell.
pub(crate) const MAX_VARIANTS: usize = 4;

/// One step of a cell's improvement: from what is shown (or the previous hull point) to the
/// variant of a rank.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Item {
    /// The sort key, smallest first: the tier (0: a noticeable error; 1: below the JND; 2: no
    /// error removed, convergence only), then the most error removed per byte (a positive
    /// float's bits order like the float; inverted, so the largest comes first), then the cell
    /// (22 bits) and the step's place on the cell's hull (8 bits), so that the order is total.
    pub order: u64,
    /// Estimated bytes of this step.
    pub cost: u32,
    /// The variant this step reaches ([`EXACT`] or a rank into the cell's variants).
    rank: u8,
}

impl Item {
    fn new(tier: u8, ratio: f32, cell: u32, (step, rank): (u8, u8), cost: f32) -> Item {
        let ratio = !ratio.max(0.0).to_bits();
        let order = u64::from(tier) << 62 | u64::from(ratio) << 30 | u64::from(cell & 0x3f_ffff) << 8 | u64::from(step);
        Item { order, cost: cost.round() as u32, rank }
    }

    /// The cell's index.
    pub fn cell(&self) -> usize {
        (self.order >> 8 & 0x3f_ffff) as usize
    }

    /// The step's place on its cell's hull: 0 for the cheapest, each step improving on the one
    /// before it.
    pub fn step(&self) -> u8 {
        self.order as u8
    }

    /// The variant this step reaches ([`EXACT`] or a rank into the cell's variants).
    pub fn rank(&self) -> u8 {
        self.rank
    }
}

/// The bytes of colour codes and glyph that draw `cell` right after `left` (with the pen that
/// drawing leaves), or with a fresh pen: `best_draw(..).len(..)`, without building the draws
/// for picture cells (this runs several times per cell and frame).
#[inline]
fn draw_cost(cell: Cell, left: Option<Cell>) -> usize {
    let (fg, bg) = left.map_or((None, None), |left| {
        let pen = best_draw(left, None, None);
        (pen.fg, pen.bg)
    });
    let Cell::Pixels { top, bottom } = cell else { return best_draw(cell, fg, bg).len(fg, bg) };
    let code =
        |c: Color, background: bool, pen: Option<Color>| (pen != Some(c)).then(|| color_params_len(c, background));
    let sgr = |f: Option<usize>, b: Option<usize>| match (f, b) {
        (None, None) => 0,
        (Some(x), None) | (None, Some(x)) => 3 + x,
        (Some(x), Some(y)) => 4 + x + y,
    };
    if top == bottom {
        let space = sgr(None, code(top, true, bg)) + 1;
        let full = sgr(code(top, false, fg), None) + FULL.len_utf8();
        space.min(full)
    } else {
        let upper = sgr(code(top, false, fg), code(bottom, true, bg));
        let lower = sgr(code(bottom, false, fg), code(top, true, bg));
        upper.min(lower) + UPPER.len_utf8()
    }
}

/// A cell's errors against its true colours.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Measure {
    /// The error of what is shown now.
    shown: f32,
    /// The error once drawn exactly (0 in truecolor; the quantization error in palettes).
    exact: f32,
    /// Whether what is shown is at least a just-noticeable difference off.
    noticeable: bool,
    /// For convergence when drawing exactly removes no error: how far the shown cell is from
    /// the wanted one.
    distance: f32,
    /// The true colours and their OKLab, for a picture cell.
    truth: Option<((Rgb, Rgb), (Lab, Lab))>,
}

impl Measure {
    /// 0: drawing it removes a noticeable error; 1: it removes an error below the JND; 2: it
    /// removes none (it only converges to the wanted frame).
    fn tier(&self) -> u8 {
        match (self.shown - self.exact > 0.0, self.noticeable) {
            (true, true) => 0,
            (true, false) => 1,
            (false, _) => 2,
        }
    }
}

/// The sort key of a candidate: its tier, then the most error per byte it might remove (a
/// positive float's bits order like the float; inverted, so the largest comes first), then
/// its index (24 bits).
fn order_key(tier: u8, bound: f32, cell: usize) -> u64 {
    u64::from(tier) << 56 | u64::from(!bound.max(0.0).to_bits()) << 24 | (cell as u64 & 0xff_ffff)
}

/// The tier and bound of an [`order_key`].
fn split_key(key: u64) -> (u8, f32) {
    ((key >> 56) as u8, f32::from_bits(!((key >> 24) as u32)))
}

/// A point of a cell's hull: a rank (or [`EXACT`]), its estimated bytes and the error it
/// removes.
#[derive(Clone, Copy, Debug)]
struct Point {
    rank: u8,
    cost: f32,
    benefit: f32,
}

/// Candidates whose fresh exact bytes add up to this many budgets are weighed in full (their
/// variants and steps); the rest are left out unless the frame turns out to need them.
const REACH: usize = 4;
/// The fewest bytes weighed, for tiny budgets.
const MIN_REACH: usize = 256;
/// The fewest bytes an approximation drawn alone can take: a jump ([`MOVE_ESTIMATE`]), the
/// shortest colour code of the mode (`ESC[40m` in 16 colours, `ESC[48;5;Nm` otherwise) and a
/// space.
fn cheapest_approximation(mode: ColorMode) -> usize {
    MOVE_ESTIMATE + 1 + if mode == ColorMode::Palette16 { 3 + 2 } else { 3 + 6 }
}

/// The fresh bytes of the candidates weighed first: a few budgets' worth.
pub(crate) fn reach(room: Room) -> usize {
    REACH.saturating_mul(room.one.max(MIN_REACH))
}

/// What weighing a candidate needs besides the frame.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Weighing {
    mode: ColorMode,
    together: f32,
    options: RateOptions,
}

impl Default for Weighing {
    fn default() -> Self {
        Weighing { mode: ColorMode::TrueColor, together: 0.0, options: RateOptions::default() }
    }
}

/// Where the weighed candidates end: no step of a candidate left out removes more error per
/// byte than `bound` in tier `tier` (or any step of a lower tier).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Cutoff {
    pub tier: u8,
    pub bound: f32,
}

impl RateEncoder {
    /// Measures the candidates (marked by [`RateEncoder::mark`]; `alone` is their bytes drawn
    /// one by one) and lists the steps of the most promising ones in `self.items`, with their
    /// variants in `self.variants`. Returns where the weighed candidates end, when some were
    /// left out.
    pub(super) fn candidates(
        &mut self,
        shown: &Frame,
        target: Target<'_>,
        room: Room,
        alone: usize,
        options: RateOptions,
    ) -> Option<Cutoff> {
        self.items.clear();
        self.order.clear();
        let wanted = target.frame;
        // How likely a candidate's left neighbour is drawn too: about the share of all the
        // candidates that the budget pays for.
        let together = (room.many as f32 / alone.max(1) as f32).min(1.0);
        let mode = target.truth.map_or(ColorMode::TrueColor, |(_, mode)| mode);
        let cols = wanted.cols();
        // Measure every candidate and bound the error per byte its best step can remove.
        for i in 0..wanted.cells().len() {
            if !self.candidate[i] {
                continue;
            }
            let (s, w) = (shown.cells()[i], wanted.cells()[i]);
            let m = self.measure(i, (i % cols, i / cols), s, w, target, options);
            let tier = m.tier();
            let approximable = tier == 0
                && options.approximate
                && m.truth.is_some_and(|((t, b), _)| !Approximation::all(mode, t == b).is_empty());
            let fresh = usize::from(self.fresh[i]);
            let cheapest = if approximable { fresh.min(cheapest_approximation(mode)) } else { fresh };
            // After a drawn neighbour a cell can cost as little as its glyph.
            let least = (together + (1.0 - together) * cheapest as f32).max(1.0);
            let most = if tier == 2 { m.distance } else { m.shown };
            self.measures[i] = m;
            self.order.push(order_key(tier, most / least, i));
        }
        self.order.sort_unstable();
        self.weighed = 0;
        self.weighing = Weighing { mode, together, options };
        self.weigh_upto(wanted, reach(room))
    }

    /// Weighs more candidates, best bound first, until their fresh bytes since the last call
    /// reach `bytes`; returns where the weighed ones end (`None`: all are weighed).
    pub(super) fn weigh_upto(&mut self, wanted: &Frame, bytes: usize) -> Option<Cutoff> {
        // Pick them best bound first, but weigh them in screen order: their data and their
        // left neighbours' then come from memory in sequence.
        let (mut sum, mut cutoff) = (0usize, None);
        let (from, mut to) = (self.weighed, self.weighed);
        while to < self.order.len() {
            let key = self.order[to];
            if sum >= bytes {
                let (tier, bound) = split_key(key);
                cutoff = Some(Cutoff { tier, bound });
                break;
            }
            let i = (key & 0xff_ffff) as usize;
            sum += usize::from(self.fresh[i]);
            self.pick[i] = true;
            to += 1;
        }
        self.weighed = to;
        let Weighing { mode, together, options } = self.weighing;
        let (mut i, mut left) = (0, to - from);
        while left > 0 {
            if self.pick[i] {
                self.pick[i] = false;
                self.weigh(i, wanted, mode, together, options);
                left -= 1;
            }
            i += 1;
        }
        cutoff
    }

    /// The nearest palette colours of cell `i`, whose true colours (truecolor) are `colours`,
    /// computed once a frame.
    fn palette_of(&mut self, i: usize, colours: (Rgb, Rgb)) -> Palette {
        let (stamp, palette) = &mut self.palettes[i];
        if *stamp != self.frames {
            *palette = Palette::of(colours);
            *stamp = self.frames;
        }
        *palette
    }

    /// Marks the cells that differ (`self.candidate`) and, when they are to be weighed, their
    /// bytes drawn exactly alone (`self.fresh`); returns how many there are and those bytes in
    /// all.
    pub(super) fn mark(&mut self, shown: &Frame, wanted: &Frame, options: RateOptions, weigh: bool) -> (usize, usize) {
        // A new frame: every memo stamped with an older count is stale.
        self.frames = self.frames.wrapping_add(1);
        if self.frames == 0 {
            self.palettes.fill((0, Palette::default()));
            self.frames = 1;
        }
        let (mut count, mut alone) = (0, 0);
        for (i, (s, w)) in shown.cells().iter().zip(wanted.cells()).enumerate() {
            let changed = !s.close_to(w, options.threshold);
            self.candidate[i] = changed;
            if changed && !weigh {
                count += 1;
            } else if changed {
                let fresh = draw_cost(*w, None) + MOVE_ESTIMATE;
                self.fresh[i] = fresh.min(usize::from(u16::MAX)) as u16;
                count += 1;
                alone += fresh;
            }
        }
        (count, alone)
    }

    /// Lists the steps of candidate `i`: the exact cell, and from a noticeable error the
    /// approximations on the hull before it.
    fn weigh(&mut self, i: usize, wanted: &Frame, mode: ColorMode, together: f32, options: RateOptions) {
        let cols = wanted.cols();
        let (x, y) = (i % cols, i / cols);
        let w = wanted.cells()[i];
        let m = self.measures[i];
        let cell = i as u32;
        // The pen and cursor the cell finds: its left neighbour's when that neighbour is drawn
        // too, otherwise a jump and fresh colour codes.
        let left = (x > 0 && self.candidate[i - 1]).then(|| wanted.cells()[i - 1]);
        let cost_of = |cell: Cell, left: Option<Cell>, fresh: Option<u16>| {
            let fresh = fresh.map_or_else(|| (draw_cost(cell, None) + MOVE_ESTIMATE) as f32, f32::from);
            let cost = match left {
                Some(left) => together * draw_cost(cell, Some(left)) as f32 + (1.0 - together) * fresh,
                None => fresh,
            };
            cost.max(1.0)
        };
        let exact_cost = cost_of(w, left, Some(self.fresh[i]));
        let exact_benefit = m.shown - m.exact;
        let tier = m.tier();
        if tier == 2 {
            let ratio = m.distance / exact_cost;
            self.items.push(Item::new(tier, ratio, cell, (0, EXACT), exact_cost));
            return;
        }
        // Approximations only for noticeable errors: a cell below the JND is drawn exactly,
        // so that a still picture converges.
        let mut points = [Point { rank: EXACT, cost: exact_cost, benefit: exact_benefit }; MAX_VARIANTS];
        let mut n = 1;
        if let Some(((top, bottom), (lab_top, lab_bottom))) = m.truth
            && tier == 0
            && options.approximate
        {
            for (k, approximation) in Approximation::all(mode, top == bottom).iter().enumerate() {
                let variant = approximation.cell(mode, (top, bottom), self.palette_of(i, (top, bottom)), (x, y));
                let Cell::Pixels { top: vt, bottom: vb } = variant else { continue };
                let error = if mode == ColorMode::TrueColor && *approximation == Approximation::Flat {
                    // The mean's OKLab is close to the mean of the two OKLab values, which are
                    // each half their distance from it.
                    lab_top.distance2(lab_bottom) / 2.0
                } else {
                    let (Some(lt), Some(lb)) = (lab_of(vt), lab_of(vb)) else { continue };
                    lt.distance2(lab_top) + lb.distance2(lab_bottom)
                };
                // The left neighbour would probably be drawn the same way.
                let left = left
                    .and_then(pixel_colours)
                    .map(|colours| approximation.cell(mode, colours, self.palette_of(i - 1, colours), (x - 1, y)));
                self.variants[i][k] = variant;
                points[n] = Point { rank: k as u8 + 1, cost: cost_of(variant, left, None), benefit: m.shown - error };
                n += 1;
            }
        }
        let (mut cost, mut benefit) = (0.0, 0.0);
        for (step, p) in upper_hull(&mut points[..n]).enumerate() {
            let (dc, db) = (p.cost - cost, p.benefit - benefit);
            self.items.push(Item::new(tier, db / dc, cell, (step as u8, p.rank), dc));
            (cost, benefit) = (p.cost, p.benefit);
        }
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
            distance: TEXT_MISMATCH_ERROR,
            truth: None,
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
        let exact_is_truth = (wt_rgb, wb_rgb) == (rt, rb);
        let (lwt, lwb) =
            if exact_is_truth { (lrt, lrb) } else { (lab_of(wt).unwrap_or(lrt), lab_of(wb).unwrap_or(lrb)) };
        let exact = if exact_is_truth { 0.0 } else { lwt.distance2(lrt) + lwb.distance2(lrb) };
        let truth = Some(((rt, rb), (lrt, lrb)));
        let (shown, noticeable, distance) = match pixel_colours(s) {
            Some((st, sb)) => {
                let (lst, lsb) = (self.shown_lab.get(i, 0, st), self.shown_lab.get(i, 1, sb));
                let (dt, db) = (lst.distance2(lrt), lsb.distance2(lrb));
                let jnd2 = options.jnd * options.jnd;
                (dt + db, dt.max(db) >= jnd2, lst.distance2(lwt) + lsb.distance2(lwb))
            }
            // Text, or a colour of unknown value, where a picture cell should be.
            None => (TEXT_MISMATCH_ERROR, true, TEXT_MISMATCH_ERROR),
        };
        Measure { shown, exact, noticeable, distance, truth }
    }
}

/// The upper convex hull from (0 bytes, 0 removed) through `points` (each removing some
/// error): the points worth sending, cheapest first, with falling error per byte between them.
fn upper_hull(points: &mut [Point]) -> impl Iterator<Item = Point> + '_ {
    points.sort_unstable_by(|a, b| a.cost.total_cmp(&b.cost).then(b.benefit.total_cmp(&a.benefit)));
    let mut len = 0;
    for i in 0..points.len() {
        let p = points[i];
        if p.benefit <= 0.0 || len > 0 && p.benefit <= points[len - 1].benefit {
            continue; // removes nothing, or less than a cheaper point
        }
        // Drop earlier points that lie under the line from their predecessor to `p`.
        while len > 0 {
            let last = points[len - 1];
            let (pc, pb) = if len > 1 { (points[len - 2].cost, points[len - 2].benefit) } else { (0.0, 0.0) };
            // slope(prev -> last) <= slope(last -> p): `last` is not on the hull.
            if (last.benefit - pb) * (p.cost - last.cost) <= (p.benefit - last.benefit) * (last.cost - pc) {
                len -= 1;
            } else {
                break;
            }
        }
        points[len] = p;
        len += 1;
    }
    points[..len].iter().copied()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(rank: u8, cost: f32, benefit: f32) -> Point {
        Point { rank, cost, benefit }
    }

    #[test]
    fn draw_costs_are_the_encoders_bytes() {
        let colours = [
            Color::Rgb([1, 2, 3]),
            Color::Rgb([100, 200, 255]),
            Color::Index(7),
            Color::Index(12),
            Color::Index(200),
            Color::Default,
        ];
        let mut cells: Vec<Cell> = Vec::new();
        for &top in &colours {
            for &bottom in &colours {
                cells.push(Cell::Pixels { top, bottom });
            }
            cells.push(Cell::Text { ch: 'x', fg: top, bg: colours[1] });
            cells.push(Cell::Text { ch: ' ', fg: top, bg: colours[2] });
        }
        for &cell in &cells {
            assert_eq!(draw_cost(cell, None), best_draw(cell, None, None).len(None, None), "{cell:?}");
            for &left in &cells {
                let pen = best_draw(left, None, None);
                assert_eq!(
                    draw_cost(cell, Some(left)),
                    best_draw(cell, pen.fg, pen.bg).len(pen.fg, pen.bg),
                    "{cell:?} after {left:?}"
                );
            }
        }
    }

    #[test]
    fn the_hull_keeps_the_points_worth_sending() {
        // Ranks 1..4 plus exact: 2 is dominated (dearer than 1, removes less), 3 lies under
        // the line from 1 to exact.
        let mut points = [p(1, 10.0, 5.0), p(2, 12.0, 4.0), p(3, 20.0, 6.0), p(EXACT, 30.0, 9.0), p(4, 5.0, -1.0)];
        let hull: Vec<u8> = upper_hull(&mut points).map(|p| p.rank).collect();
        assert_eq!(hull, [1, EXACT]);
        // An approximation that buys less per byte than the exact cell is left out.
        let mut points = [p(1, 20.0, 1.0), p(EXACT, 40.0, 9.0)];
        let hull: Vec<u8> = upper_hull(&mut points).map(|p| p.rank).collect();
        assert_eq!(hull, [EXACT]);
        // Equal slopes keep only the end point.
        let mut points = [p(1, 10.0, 3.0), p(EXACT, 20.0, 6.0)];
        assert_eq!(upper_hull(&mut points).count(), 1);
    }
}
