//! What one answer does: what the terminal took since the last one, the round trip and its
//! queue, the link's capacity for the window, and the rate's decision (the rules are in the
//! parent module's documentation). Each step is its own function; [`LinkControl::round_trip`]
//! runs them in order.

use std::time::{Duration, Instant};

use super::drain::START_KEEP_UP;
use super::questions::Question;
use super::{
    BASE_SAMPLES, CAPACITY_MEMORY, Change, DECREASE, DEEP_DRAIN_SHARE, DELIVERY_BYTES, DRAIN_SHARE, FIRST_WINDOW,
    INCREASE, INCREASE_AFTER_LIMIT, LinkControl, MAX_RATE, MIN_RATE, QUEUE_HIGH, QUEUE_HIGH_MIN, RECENT_TAKES,
    SAFE_RATE, answer_time, queue_marks,
};

/// How an answer's queue reads against the marks.
struct Reading {
    /// The queue less the terminal's usual time to answer.
    link_queue: Duration,
    /// The base round trip and its marks.
    base: Duration,
    low: Duration,
    high: Duration,
    /// The bytes in flight explain the queue (or the terminal is not one slow on its own).
    explained: bool,
    /// The terminal is taken for one slow on its own (shown so, or not judged yet).
    slow_terminal: bool,
    /// Over the high mark, and the link's.
    over: bool,
    /// The answer before: its link queue and whether it was over.
    last: Option<(Duration, bool)>,
}

impl Reading {
    fn was_over(&self) -> bool {
        self.last.is_some_and(|(_, was_over)| was_over)
    }
}

impl LinkControl {
    /// The link's question `question` was answered at `now`.
    pub(super) fn round_trip(&mut self, question: Question, now: Instant) -> Change {
        let (sent, bytes, app_limited) = (question.asked, question.bytes, question.app_limited);
        let first = !self.answered;
        if first && self.path.asks_status() {
            // The terminal at the far end answers through the multiplexer: the path can be
            // measured, and the rate may grow past the safe one.
            self.ceiling = MAX_RATE;
        }
        self.answered = true;
        self.silent = false;
        self.acknowledged = self.acknowledged.max(bytes);
        let took = self.take(&question, now);
        let window_bound = std::mem::take(&mut self.window_bound);
        // From when the question left the player: building its frame took the player's time,
        // not the link's.
        let rtt = now.saturating_duration_since(question.out);
        self.last_rtt = Some(rtt);
        self.samples[self.sample_count % BASE_SAMPLES] = rtt;
        self.sample_count += 1;
        let base = self.base().unwrap_or(rtt);
        let queue = rtt.saturating_sub(base);
        self.flight.answered(now, bytes);
        if question.clean {
            self.learn_own_time(queue, base, now);
            return Change::Hold;
        }
        if first && self.path.answered_at_far_end() {
            // The first measurement of the terminal's own time comes right after: holding the
            // frames until the first answer is in also drains what the start rate queued, so
            // the bare question's round trip is the link's own.
            self.clean_due = Some(now);
        }
        let reading = self.read_queue(queue, base, question.in_flight);
        let measured_before = self.capacity.is_some();
        if self.measure_capacity(took, &reading, first, &question, window_bound, now)
            && let Some(took) = took
        {
            let busy = reading.link_queue >= reading.low && reading.last.is_some_and(|(last, _)| last >= reading.low);
            self.drain.took(took, busy);
        }
        if !self.path.answered_at_far_end() {
            // The answers come from this side of the link (a multiplexer, mosh-server): they
            // pace the window, never the rate.
            return Change::Hold;
        }
        if let Some(change) = self.drain_step(sent, reading.link_queue, (reading.low, base), now) {
            return change;
        }
        if first && let Some(change) = self.start_from_first(took, app_limited, bytes, now) {
            return change;
        }
        if !first && !measured_before && self.capacity.is_some() && base > QUEUE_HIGH {
            // The first answer that measures the link (the first one followed the set-up's few
            // bytes): the start ends here as it would have at the first answer, by a drain when
            // the queue already shows.
            if reading.over && self.drain.first_fall() {
                return self.start_drain(now, DECREASE);
            }
            if let Some(change) = self.start_from_first(took, app_limited, bytes, now) {
                return change;
            }
        }
        if self.decided_at.is_some_and(|decided| sent < decided) {
            // Asked before the last change: it measures the queue that change is acting on.
            return Change::Hold;
        }
        // Asked within a round trip of a fall that took the rate under what the link was
        // seen to carry: its answer still carries the queue the bytes sent before the fall
        // built (they were in the link when it was asked), so it says nothing of whether the
        // queue drains. A second fall on it took the rate to 0.57 of the link on the stock
        // 256 kbit/s lab, and the rate then took six seconds to come back.
        let settling = base > QUEUE_HIGH
            && self.fell_at.is_some_and(|fell| sent < fell + base)
            && self.delivered.is_some_and(|delivered| self.rate < delivered);
        self.decide(&reading, question.in_flight, app_limited, settling, now)
    }

    /// What the terminal took since the last answer, bytes per second, for a question that
    /// followed `question.bytes` bytes; remembered as delivered (unless the sender set the
    /// pace) and as the last answer.
    fn take(&mut self, question: &Question, now: Instant) -> Option<f64> {
        let bytes = question.bytes;
        let took = match self.last_answer {
            Some((then, before)) => Some((then, bytes.saturating_sub(before))),
            // The first answer: its frame crossed the link within the round trip (a lower
            // bound of the link's rate, what the window starts from).
            None => Some((question.out, bytes)),
        }
        // Between two answers, at least DELIVERY_BYTES: a question that followed a few bytes
        // (a frame with its window closed) and came late says how long the terminal took, not
        // what the link carries (kitty 0.26 stalled 385 ms after 32 bytes, read as 78 B/s).
        // A shorter interval is measured on with the next.
        .filter(|&(_, b)| b > 0 && (self.last_answer.is_none() || b >= DELIVERY_BYTES))
        .map(|(since, b)| (now.saturating_duration_since(since).as_secs_f64(), b))
        .filter(|&(dt, _)| dt > 0.0)
        .map(|(dt, b)| b as f64 / dt);
        if let Some(rate) = took.filter(|_| self.last_answer.is_some() && !question.app_limited) {
            self.delivered_before = self.delivered.replace(rate);
        }
        if took.is_some() || self.last_answer.is_none() {
            self.last_answer = Some((now, bytes));
        }
        took
    }

    /// A bare question's answer, `queue` past the base round trip `base`: nothing was in flight
    /// under it, so its delay is the terminal's own time, and it says nothing of what the link
    /// carries (no frames crossed). The next measurement is planned.
    fn learn_own_time(&mut self, queue: Duration, base: Duration, now: Instant) {
        self.answer_time.record(queue);
        let gap =
            answer_time::next_gap(self.answer_time.bare_count(), self.answer_time.slow(), queue_marks(base).0, base);
        self.clean_due = Some(now + gap);
    }

    /// Reads an answer's `queue` (past the base round trip `base`, behind bytes that would take
    /// `in_flight` to cross) against the marks and the terminal's own time.
    fn read_queue(&mut self, queue: Duration, base: Duration, in_flight: Duration) -> Reading {
        let (low, high) = queue_marks(base);
        self.answer_time.infer(queue, in_flight, (low, high));
        // The terminal's usual time to answer is not queue; its slow answers raise the high
        // mark (a queue must stand beyond them to be the link's).
        let (usual, slow) = (self.answer_time.usual(), self.answer_time.slow());
        let link_queue = queue.saturating_sub(usual);
        // Over the high mark, and either the bytes in flight explain it (a queue grows with
        // them; the terminal's time does not) or it is beyond the terminal's slow answers too.
        // Only a terminal the bare questions showed slow on its own is asked for that
        // explanation: any other is late because it is still reading, a queue.
        // (Until a few bare answers are in, it is taken for one: main's rules collapsed kitty
        // 0.26 to 2 kB/s within the first second.)
        let slow_terminal = self.answer_time.treat_as_slow((low, high));
        let explained = !slow_terminal || 2 * in_flight >= link_queue;
        let over = link_queue > high && (explained || queue > high + slow);
        let last = self.last_queue.replace((link_queue, over));
        Reading { link_queue, base, low, high, explained, slow_terminal, over, last }
    }

    /// The link's capacity for the window, from what the terminal `took` since the last answer
    /// to `question` (whose sender may have left its budget unspent), the window holding frames
    /// (`window_bound`) or not; whether the take measured the link.
    fn measure_capacity(
        &mut self,
        took: Option<f64>,
        reading: &Reading,
        first: bool,
        question: &Question,
        window_bound: bool,
        now: Instant,
    ) -> bool {
        let (app_limited, bytes) = (question.app_limited, question.bytes);
        // The link is first measured by a take that says something of it: a sender that used its
        // budget, and after the first question more than the set-up's few bytes. Until then the
        // window stays the first one (`window`): a capacity taken from 57 bytes of set-up
        // answered in 66 ms (857 B/s) held the window at its 4 kB floor, every frame then
        // filled it, the takes stayed small, and a loaded machine's late answers took the rate
        // down to 2-4 kB/s (the fake WezTerm with forced sixel over SSH, blank for 20 s in CI).
        let measures = self.capacity.is_some() || (!app_limited && (!first || bytes >= FIRST_WINDOW / 4));
        let Some(took) = took.filter(|_| measures) else {
            return false;
        };
        // A queue says the link was the limit; from a terminal slow on its own only a standing
        // one (two answers over the mark in a row): its late answers must not shrink the window
        // to one frame's take.
        let standing = reading.over && (reading.was_over() || !reading.slow_terminal);
        // A take the window held back says the link carries at least that much, never less: a
        // terminal that draws for a second before it answers (kitty through Mesa's softpipe on
        // a busy machine) let each window through in a second, the window shrank to each
        // take's size and the takes with it, to the 4 kB window floor and a 2 kB/s rate on a
        // 250 kB/s link.
        self.capacity = Some(match self.capacity {
            Some(c) if !standing || window_bound => c.max(took),
            _ => self
                .recent_takes
                .iter()
                .flatten()
                .filter(|(at, _)| now.saturating_duration_since(*at) <= CAPACITY_MEMORY)
                .map(|(_, t)| *t)
                .fold(took, f64::max),
        });
        self.recent_takes[self.take_count % RECENT_TAKES] = Some((now, took));
        self.take_count += 1;
        true
    }

    /// The first answer: the rate starts from what the first frame was seen to take, when that
    /// says something of the link; `Some` when the rate fell.
    fn start_from_first(&mut self, took: Option<f64>, app_limited: bool, bytes: u64, now: Instant) -> Option<Change> {
        // Too few bytes before the first question (the set-up and a status line, sent before
        // the bucket held anything) say nothing of the link either.
        if app_limited || bytes < FIRST_WINDOW / 4 {
            return None;
        }
        // The first frame crossed the link within this round trip: the link carries at
        // least that much, and the rate may be far above it (a 400 kB/s start on a 32 kB/s
        // link). Starting from it drains what the first frames queued, so the next round
        // trips show the link's own delay: a base taken from a queue would hide every
        // later queue.
        // A question after a few bytes says little of the link: never below the safe rate
        // then (measured on the real 256 kbit/s link: the player's first question followed
        // 4 kB, and 400 kB/s ran on for seconds of falls).
        // A question after frames that left most of their budget unspent (the status line
        // alone while the picture waits), or after a few hundred bytes, says nothing of the
        // link at all: the rate stays, and the window (sized from what those bytes took)
        // bounds the queue until answers to full frames measure the link (the rate fell to
        // 16 kB/s on a 250 kB/s link, and on a local xterm whose first question followed
        // 57 bytes).
        let shown = took.map_or(self.rate, |t| (t * DRAIN_SHARE).max(SAFE_RATE)).max(MIN_RATE);
        (shown < self.rate).then(|| {
            self.rate = shown.min(self.ceiling);
            self.decided_at = Some(now);
            Change::Down
        })
    }

    /// The rate's decision on a queue read as `reading`, behind bytes that would take
    /// `in_flight` to cross, from a sender `app_limited` or not.
    /// `settling`: the question was asked while a fall's drain had not begun to show (no
    /// second fall on it).
    fn decide(
        &mut self,
        reading: &Reading,
        in_flight: Duration,
        app_limited: bool,
        settling: bool,
        now: Instant,
    ) -> Change {
        let Reading { link_queue, low, high, explained, over, last, .. } = *reading;
        // A queue that is not draining, over the high mark twice in a row, or once when it
        // is beyond what a busy machine's late reads of an answer make (a long link then
        // falls a round trip sooner).
        let not_draining = last.is_none_or(|(last, _)| link_queue >= last);
        // One answer alone confirms a queue only when the bytes in flight explain it: a single
        // late answer is the terminal's (kitty 0.26 under llvmpipe took up to a second now and
        // then), never a collapse of the link. That holds for a terminal not found slow on
        // its own too: a loaded machine reads answers late whatever the terminal (a slow
        // kitty's rate fell to the floor by one late answer in four).
        let bytes_explain = 2 * in_flight >= link_queue;
        // On a long link a queue that grew from over the low mark is confirmed too: the rate past
        // the link's held between the marks while the queue grew 30-40 ms a round trip, and the
        // answer that confirmed it came a round trip later (the sawtooth's top 221 ms, now 169).
        let growing = reading.base > QUEUE_HIGH && last.is_some_and(|(last, _)| last >= low && link_queue > last);
        let confirmed =
            reading.was_over() || growing || (link_queue > 2 * QUEUE_HIGH_MIN && explained && bytes_explain);
        // A sender that left its budget unspent cannot have built a queue of a few marks: only
        // a deep one lowers the rate then.
        let caused = !app_limited || link_queue > 2 * high;
        // The start's first queue on a long link needs no confirmation: it is drained at once
        // (the answer that would confirm it comes a round trip later, behind another round trip
        // of the start's growth); `fall` turns that fall into the drain.
        let drain_due = self.drain_due(reading.base);
        if over && not_draining && caused && (drain_due || (confirmed && !settling)) {
            // A queue of several marks drains faster: at 15 % under the link, a second of
            // queue would take six to go.
            // A late answer the bytes in flight cannot explain (a terminal slow on its own, in
            // a standing queue of its own making) never takes the rate under a quarter of the
            // link seen: kitty 0.26 stalling under load fell to 4 kB/s on a 250 kB/s link.
            let floor = if explained { MIN_RATE } else { self.capacity.map_or(SAFE_RATE, |c| c * 0.25).max(SAFE_RATE) };
            let deep = link_queue > 2 * high;
            // What the terminal took measures the link only when a queue stood from the
            // interval's start: else the sender set it (the rate, or less), and a fall to a
            // share of it is a fall to a share of the rate, again at every late answer (a
            // loaded machine's late reads took a slow kitty from 75 to 3 kB/s in 8 s).
            let stood = last.is_some_and(|(last, _)| last >= low);
            self.fall(now, if deep { DEEP_DRAIN_SHARE } else { DRAIN_SHARE }, floor, stood);
            Change::Down
        } else if link_queue < low && self.rate < self.ceiling {
            // Only a sender that used its budget learns that the link carries more: one that
            // left it unspent (cells of calm water) would grow the rate without evidence, to
            // "no limit" on a 250 kB/s link, and `auto` then switched to pixels that queued
            // for seconds.
            // Past what the link was seen to carry, a step over the link's rate is a queue that
            // grows each round trip until the answers that stop it come, a round trip late: a
            // step of the same share of the high mark at any round trip (on a link whose round
            // trip is longer than the mark, a smaller step: at 300 ms, 1 % rather than 3 %).
            let past = self.link_rate.or(self.capacity).is_some_and(|c| self.rate >= c);
            // The start grows fast while the terminal takes what it is sent; on a long link,
            // once it takes less, the link has shown its limit though no queue shows yet (the
            // answer that shows it comes a round trip later).
            let keeping_up =
                reading.base <= QUEUE_HIGH || self.delivered.is_none_or(|d| d >= START_KEEP_UP * self.rate);
            let growth = match (self.fell, past) {
                (false, _) if keeping_up => INCREASE,
                (false, _) => INCREASE_AFTER_LIMIT,
                (true, false) => INCREASE_AFTER_LIMIT,
                (true, true) => {
                    let share = (high.as_secs_f64() / reading.base.as_secs_f64().max(1e-3)).min(1.0);
                    1.0 + (INCREASE_AFTER_LIMIT - 1.0) * share
                }
            };
            self.rate = (self.rate * growth).min(self.ceiling);
            self.decided_at = Some(now);
            Change::Up
        } else {
            Change::Hold
        }
    }

    /// Lowers the rate to under what the terminal was seen to take (`measured`: while a queue
    /// stood, so the link set it), else by [`DRAIN_SHARE`]; never under `floor`.
    pub(super) fn fall(&mut self, now: Instant, share: f64, floor: f64, measured: bool) {
        if self.base().is_some_and(|b| self.drain_due(b)) {
            self.start_drain(now, DECREASE);
            return;
        }
        let delivered = self.delivered.map(|d| d.max(self.delivered_before.unwrap_or(0.0)));
        if measured && let Some(d) = delivered {
            self.link_rate = Some(d);
        }
        let target = match delivered {
            // Far under the rate, though, the link (or the terminal) is the limit whatever
            // stood before: a start rate far over a slow link comes down at once.
            Some(d) if !measured && d >= self.rate * 0.5 => self.rate * DRAIN_SHARE,
            // Under what the link was seen to carry (an estimate from two answers, so never
            // below a quarter of the rate in one fall: a rate far over the link comes down in
            // one or two round trips), and never up.
            Some(delivered) => (delivered * share).max(self.rate * 0.25).min(self.rate * DRAIN_SHARE),
            None => self.rate * DECREASE,
        };
        self.rate = target.max(floor.min(self.rate)).max(MIN_RATE);
        self.decided_at = Some(now);
        self.fell_at = Some(now);
        self.fell = true;
    }
}
