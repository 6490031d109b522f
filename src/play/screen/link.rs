//! Finding the link's bandwidth by itself, from a round trip measured in band.
//!
//! Over SSH the socket buffers swallow megabytes before a write ever blocks, so the time a
//! write takes says nothing until a backlog of seconds has formed. The terminal can say more:
//! after a frame the player asks for the primary device attributes (`ESC[c`, which every
//! terminal answers and which is never a key), and the reply comes back only once the terminal
//! has read everything sent before the question. The round trip's excess over the shortest one
//! seen recently is the queue the frames have built in the link.
//!
//! **The rate** follows that queue like a delay-based congestion controller, one decision per
//! round trip: while the queue stays under the low mark the rate grows by [`INCREASE`] (by
//! [`INCREASE_AFTER_LIMIT`] once the link has shown its limit); over the high mark, and not
//! draining (twice in a row, or once past [`QUEUE_HIGH_MIN`] twice over, beyond what a busy
//! machine's late reads of an answer make), it falls to a little under what the terminal was
//! seen to take (the bytes between two answers over the time between them: while a queue
//! stands, that is the link's own rate; [`DEEP_DRAIN_SHARE`] of it for a deep queue), or by
//! [`DECREASE`] when that is not known yet, and the byte bucket is emptied, so the backlog
//! drains; in between it holds. The terminal's own time to answer is not queue: it is measured
//! now and then with a bare question asked with nothing in flight (see `answer_time`); its
//! usual time is taken off every answer's queue and its slow answers raise the high mark. The
//! marks scale with the shortest round trip
//! ([`queue_marks`]): a queue of one round trip, never more than [`QUEUE_HIGH`], so a key's frame
//! waits behind at most that. The first answer starts the rate from what the first frame was
//! seen to take (never under [`SAFE_RATE`]): a base round trip taken while the start rate's
//! queue stood would hide every later queue. An answer that does not come within
//! [`PROBE_TIMEOUT`] (or four base round trips) counts as congestion too. A round trip counts
//! from when the question's frame was handed to the door's writer
//! ([`LinkControl::handed_over`]), not from when the frame began: on a loaded machine building
//! a frame takes the player most of a frame interval, and its spread is not a queue.
//!
//! **The start's end on a long link** (a base round trip over [`QUEUE_HIGH`]; see `drain`):
//! the first answer that measures the link starts the rate from it as the first answer would;
//! the start grows by [`INCREASE`] only while the terminal takes what it is sent; and the first
//! queue over the high mark drains at once, at half the least take seen, until an answer shows
//! the queue under the low mark, the rate then starting under what the terminal took while that
//! queue stood. On the stock 256 kbit/s 300 ms lab the first takes read 14 % to twice the link
//! (a token bucket's burst, serve's late first answers), and the window and a single fall sized
//! from them left the start's queue (0.7-2.2 s) standing when the first keys came.
//!
//! **The window.** A rate alone cannot keep the first seconds short on a very slow link: the
//! first answer comes back only once the first frame has crossed the link, and until then the
//! player would keep sending at [`START_RATE`]. So the bytes sent and not yet answered for are
//! capped, as TCP caps its unacknowledged bytes ([`LinkControl::window_left`]): [`FIRST_WINDOW`]
//! until the first answer, then the link's bandwidth times its delay. One question is in flight
//! at a time, so the answered-for point moves once a round trip and the unanswered bytes reach
//! two round trips' worth plus a frame just before each answer: the window is the capacity times
//! twice (the base round trip plus [`WINDOW_QUEUE`]) plus [`FRAME_ALLOWANCE`]. That fills the
//! link at any round trip and bounds the queue to about one round trip plus [`WINDOW_QUEUE`]
//! when the rate control is behind (the first seconds, a link that slows down).
//!
//! **Whose answer is it.** Answers carry nothing that says which question they answer; a
//! terminal answers in order, so they are paired with the questions in the order asked. The
//! graphics probe asks DA1 too, before the player starts, and its answer may come after the
//! probe's deadline: [`LinkControl::expect_foreign`] records those questions in the same queue,
//! so their answers are counted and dropped, never paired with a link question; until they come
//! (or [`FOREIGN_WAIT`] has passed) no link question is asked, so a foreign answer that never
//! comes cannot shift the pairing either. A question overdue for congestion stays in the queue
//! (its late answer is still its own) until [`GIVE_UP`].
//!
//! **When the far end cannot be heard.** A terminal that does not answer within [`SILENCE`]
//! (never, or no longer) is sent [`SAFE_RATE`] with no window: never a freeze, and no backlog
//! on any link faster than that. Inside a multiplexer over SSH (tmux, screen, zellij) the
//! multiplexer answers at once from its local pane and under mosh mosh-server does, so the
//! round trip measures the local side, not the link ([`LinkPath`]): the rate is held at
//! [`SAFE_RATE`] there and [`LinkControl::hint`] says how to set `--bandwidth`.
//!
//! **Inside tmux or screen over SSH the question is wrapped for the multiplexer's
//! passthrough** ([`LinkPath::question`]): a device status report (`ESC[5n`, answered `ESC[0n`
//! by every VT100-compatible terminal) inside `ESC P tmux; ... ESC \` (tmux, with
//! `allow-passthrough on`) or `ESC P ... ESC \` (GNU screen, always). The multiplexer hands it
//! to the outer terminal in order with the frames before it, and passes the terminal's answer
//! back to the pane as input, so the round trip covers the whole path: the multiplexer, sshd's
//! buffers (the client's 2 MB window), the socket and the link. Measured with tmux 3.3a and
//! screen 4.9: DA1 wrapped the same way reaches the terminal too, but tmux keeps its answer;
//! unwrapped, both multiplexers answer DA1 and DSR themselves. Until the first wrapped answer
//! comes the rate stays under [`SAFE_RATE`]; when none comes (tmux without passthrough, the
//! default) the controller goes silent after [`SILENCE`] and the status line names the
//! passthrough option and `--bandwidth` ([`LinkControl::hint`]). Nothing short of the
//! terminal's answer sees sshd's buffer: the queue of sshd's socket (`/proc/net/tcp`), which
//! the player followed before, stands still at the socket's size while sshd holds megabytes
//! behind it, and names another connection when the multiplexer was attached from elsewhere.
//! Time comes in as an argument: the tests run on made-up clocks.

use std::time::{Duration, Instant};

mod answer;
mod answer_time;
mod drain;
mod flight;
mod handover;
mod path;
mod questions;
mod screen_side;
mod window;

use answer_time::AnswerTime;
use drain::Drain;
use flight::Flight;
pub use path::LinkPath;
use questions::{Question, Questions};

/// The question: primary device attributes.
pub const PROBE: &[u8] = b"\x1b[c";
/// The question inside tmux over SSH: a device status report wrapped for tmux's passthrough
/// (each ESC inside doubled). tmux drops it unless `allow-passthrough` is on.
pub const TMUX_QUESTION: &[u8] = b"\x1bPtmux;\x1b\x1b[5n\x1b\\";
/// The question inside GNU screen over SSH: a device status report in screen's passthrough
/// (a DCS string, whose contents screen writes to the terminal as they are).
pub const SCREEN_QUESTION: &[u8] = b"\x1bP\x1b[5n\x1b\\";
/// The rate the player starts at, bytes per second: a whole 160x48 frame in under a second
/// (coarse first, then exact), grown to a local terminal's speed within half a second, and not
/// so far above a slow link's rate that the first second leaves a long queue behind.
pub const START_RATE: f64 = 400_000.0;
/// The lowest rate: a few cells a frame.
pub const MIN_RATE: f64 = 2_000.0;
/// The highest rate; at it the link is treated as unlimited.
pub const MAX_RATE: f64 = 64_000_000.0;
/// The rate where the link cannot be measured (a silent terminal, a multiplexer over SSH,
/// mosh): half a 256 kbit/s link's 32 kB/s, room for SSH's framing and a multiplexer's or
/// mosh's re-encoding, so no backlog forms on any common link; a mosaic on a fast one, which
/// `--bandwidth` lifts. Measured by `scripts/link_harness` at 256 kbit/s and 300 ms: 24 kB/s
/// left tmux and mosh at a p90 of 1.9 and 2.1 s key to effect, 16 kB/s at 0.31 and 0.50 s.
pub const SAFE_RATE: f64 = 16_000.0;
/// The high mark's floor: under it a queue is the jitter of the player's own loop (a frame's
/// rendering delays reading an answer), not the link.
pub const QUEUE_HIGH_MIN: Duration = Duration::from_millis(30);
/// The high mark's ceiling: a key's frame never waits behind more than about this.
pub const QUEUE_HIGH: Duration = Duration::from_millis(100);
/// Growth per round trip while the queue is short, until the link first shows a queue (to
/// find a fast link within a few frames).
pub const INCREASE: f64 = 1.25;
/// Growth per round trip while the queue is short, once the link has shown its limit (gentle:
/// the answers that would stop it come a round trip late).
pub const INCREASE_AFTER_LIMIT: f64 = 1.03;
/// Fall per answer (or lost question) while the queue is long and the link's own rate is not
/// known yet.
pub const DECREASE: f64 = 0.7;
/// After a fall the rate is this share of the rate the terminal was seen to take, so the
/// standing queue drains.
pub const DRAIN_SHARE: f64 = 0.85;
/// The share a queue of more than twice the high mark drains to.
pub const DEEP_DRAIN_SHARE: f64 = 0.6;
/// The longest wait for an answer before it counts as congestion (at least four base round
/// trips).
pub const PROBE_TIMEOUT: Duration = Duration::from_millis(1000);
/// The most bytes sent before the terminal's first answer: a coarse whole frame at 160x48.
pub const FIRST_WINDOW: u64 = 24_000;
/// The queue the window allows beyond the round trip: more than [`QUEUE_HIGH`], so the rate
/// control acts first and the window bounds the worst case.
pub const WINDOW_QUEUE: Duration = Duration::from_millis(150);
/// The longest round trip the window is sized for: beyond it a base round trip is more likely
/// a standing queue than distance, and a window sized for it would let the queue grow.
pub const WINDOW_RTT_MAX: Duration = Duration::from_millis(500);
/// Before the first answer the window opens by this many bytes a second after
/// [`FIRST_WINDOW`]: the status line and a few cells keep moving while the first frame crosses
/// a slow link.
pub const FIRST_TRICKLE: f64 = 2_000.0;
/// The window's room for the frame that goes out between an answer and the next question.
pub const FRAME_ALLOWANCE: Duration = Duration::from_millis(50);
/// The fewest bytes between two answers that measure what the link carries.
pub const DELIVERY_BYTES: u64 = 2_000;
/// The smallest window once the terminal answers: a status line and a few cells.
pub const MIN_WINDOW: u64 = 4_000;
/// How long a question may wait with no answer at all before the terminal is taken not to
/// answer ([`SAFE_RATE`], no window: nothing would ever open it).
pub const SILENCE: Duration = Duration::from_secs(3);
/// How long answers to questions somebody else asked ([`LinkControl::expect_foreign`]) are
/// waited for before they are taken never to come.
pub const FOREIGN_WAIT: Duration = Duration::from_secs(1);
/// How long an overdue question keeps its place for its late answer.
pub const GIVE_UP: Duration = Duration::from_secs(10);
/// Questions remembered at most (one link question at a time, overdue ones, foreign ones).
const MAX_QUESTIONS: usize = 8;
/// What the terminal took between answers, remembered for the capacity (the most of them
/// within [`CAPACITY_MEMORY`]).
const RECENT_TAKES: usize = 8;
/// How long a take still counts for the capacity when a standing queue measures it anew: one
/// answer's take is low when that answer was read late (a loaded machine, a terminal busy
/// drawing), and a window cut to it let the sender take less, and the next take less again.
/// Half a second: a link that truly slows is followed within it (a terminal reading at half
/// speed kept its queue's p90 under 200 ms).
const CAPACITY_MEMORY: Duration = Duration::from_millis(500);
/// Round trips remembered for the base (the shortest of them).
const BASE_SAMPLES: usize = 16;

/// What a reply did to the rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Change {
    /// Nothing.
    Hold,
    /// The rate grew.
    Up,
    /// The rate fell: empty the byte bucket so the backlog drains.
    Down,
}

/// The marks the queue is held between for a base round trip `base`: the high one is one
/// round trip, within [`QUEUE_HIGH_MIN`] and [`QUEUE_HIGH`]; the low one a third of it.
pub fn queue_marks(base: Duration) -> (Duration, Duration) {
    let high = base.clamp(QUEUE_HIGH_MIN, QUEUE_HIGH);
    (high / 3, high)
}

/// The controller: the rate in effect and the questions in flight.
#[derive(Clone, Debug)]
pub struct LinkControl {
    path: LinkPath,
    /// The highest rate this path allows ([`MAX_RATE`], or [`SAFE_RATE`] where the link cannot
    /// be measured).
    ceiling: f64,
    rate: f64,
    /// The questions not yet answered, oldest first.
    questions: Questions,
    /// The last answer: when it came and the bytes its question followed.
    last_answer: Option<(Instant, u64)>,
    /// What the terminal was seen to take between the last two answers, bytes per second.
    delivered: Option<f64>,
    /// What it was seen to take the interval before: a late answer (a terminal busy drawing,
    /// a player whose machine is loaded and reads it late) stretches its own interval, not
    /// the one before it.
    delivered_before: Option<f64>,
    /// The last takes and when they were measured ([`CAPACITY_MEMORY`]).
    recent_takes: [Option<(Instant, f64)>; RECENT_TAKES],
    take_count: usize,
    /// What the link can carry, bytes per second, for the window: what the terminal took while
    /// a queue stood (then the link was the limit), else the most it was seen to take (still
    /// water takes little and must not shrink the window).
    capacity: Option<f64>,
    /// The last round trips, for the base.
    samples: [Duration; BASE_SAMPLES],
    sample_count: usize,
    /// The queue the last answer showed (two answers in a row over the high mark make a fall,
    /// so one late read of an answer does not).
    last_queue: Option<(Duration, bool)>,
    /// Whether any link question was ever answered.
    answered: bool,
    /// The terminal has not answered for [`SILENCE`]: [`SAFE_RATE`] and no window.
    silent: bool,
    /// The last round trip measured.
    last_rtt: Option<Duration>,
    /// When the rate last changed: answers to questions asked before it still carry the old
    /// queue, so they do not change it again.
    decided_at: Option<Instant>,
    /// Whether the rate ever fell (the link has shown its limit).
    fell: bool,
    /// When the rate last fell.
    fell_at: Option<Instant>,
    /// What the terminal took while a queue stood, at the last fall that measured it: the
    /// link's own rate (the takes between answers scatter above it; the capacity, their
    /// most, sized the window, and growth past it kept queueing).
    link_rate: Option<f64>,
    /// The start's queue drained at the first fall (`drain`).
    drain: Drain,
    /// The bytes the terminal has answered for (or given up on): everything sent up to the
    /// last answered or overdue question.
    acknowledged: u64,
    /// The bytes sent up to the last question asked.
    asked_up_to: u64,
    /// Every frame since the last question left most of its budget unspent.
    spare_since_question: bool,
    /// The terminal's own answer times, which widen the queue's marks.
    answer_time: AnswerTime,
    /// When the next measurement of the terminal's own time is due (frames are held from
    /// then until a bare question has gone out, at most [`answer_time::HOLD_MAX`]); `None`
    /// until the first answer, and while a bare question waits for its answer.
    clean_due: Option<Instant>,
    /// The bytes sent, as the link would carry them at the capacity seen.
    flight: Flight,
    /// The bytes of the last frame sent.
    last_frame: u64,
    /// The last question asked has not been handed to the writer yet
    /// ([`LinkControl::handed_over`]).
    unwritten: bool,
    /// Since the last answer, a question waited past the window's time, so frames were held
    /// ([`LinkControl::window_left`]): what the terminal took then is what the window let
    /// through, a lower bound of the link, never a measure that lowers its capacity.
    window_bound: bool,
    /// Answers to foreign questions seen, and answers nobody asked for.
    foreign_answers: u64,
    stray_answers: u64,
}

impl Default for LinkControl {
    fn default() -> Self {
        LinkControl::new()
    }
}

impl LinkControl {
    /// A controller for a terminal that answers from the far end ([`LinkPath::Direct`]).
    pub fn new() -> LinkControl {
        LinkControl::on(LinkPath::Direct)
    }

    /// A controller for what sits between the player and the screen.
    pub fn on(path: LinkPath) -> LinkControl {
        let ceiling = match path {
            LinkPath::Direct => MAX_RATE,
            LinkPath::Multiplexer(_) | LinkPath::Mosh => SAFE_RATE,
        };
        LinkControl {
            path,
            ceiling,
            rate: START_RATE.min(ceiling),
            questions: Questions { list: [None; MAX_QUESTIONS], len: 0 },
            last_answer: None,
            delivered: None,
            delivered_before: None,
            recent_takes: [None; RECENT_TAKES],
            take_count: 0,
            capacity: None,
            samples: [Duration::ZERO; BASE_SAMPLES],
            sample_count: 0,
            last_queue: None,
            answered: false,
            silent: false,
            last_rtt: None,
            decided_at: None,
            fell: false,
            fell_at: None,
            link_rate: None,
            drain: Drain::default(),
            acknowledged: 0,
            asked_up_to: 0,
            spare_since_question: true,
            answer_time: AnswerTime::default(),
            clean_due: None,
            flight: Flight::default(),
            last_frame: 0,
            unwritten: false,
            window_bound: false,
            foreign_answers: 0,
            stray_answers: 0,
        }
    }

    /// The rate in effect, bytes per second; `None` at [`MAX_RATE`] (no limit).
    pub fn rate(&self) -> Option<f64> {
        (self.rate < MAX_RATE).then_some(self.rate)
    }

    /// The shortest recent round trip.
    fn base(&self) -> Option<Duration> {
        self.samples[..self.sample_count.min(BASE_SAMPLES)].iter().min().copied()
    }

    /// Whether a question should go out with the frame being sent: no link question is waiting
    /// for its answer (an overdue one has been replaced) and no foreign answer is due.
    pub fn probe_due(&self) -> bool {
        self.questions.len < MAX_QUESTIONS && self.questions.iter().all(|q| !q.foreign && q.overdue)
    }

    /// A question went out at `now`, appended to a frame; `bytes_sent` counts every byte the
    /// player has written, that frame included.
    pub fn probed(&mut self, now: Instant, bytes_sent: u64) {
        self.asked_up_to = self.asked_up_to.max(bytes_sent);
        let app_limited = std::mem::replace(&mut self.spare_since_question, true);
        let clean = self.holding(now) && bytes_sent.saturating_sub(self.acknowledged) <= answer_time::CLEAN_BYTES;
        if clean {
            // Frames may go again: they follow the question, so they cannot delay its answer.
            self.clean_due = None;
        }
        let in_flight = self.flight.sent(now, bytes_sent, self.last_frame, self.capacity.unwrap_or(self.rate));
        self.unwritten = true;
        self.questions.push(Question {
            asked: now,
            out: now,
            bytes: bytes_sent,
            foreign: false,
            overdue: false,
            app_limited,
            clean,
            in_flight,
        });
    }

    /// A frame went out that spent `spent` of the `budget` it was given. A sender that leaves
    /// most of its budget unspent (calm water; a picture stream on a small rung) sets the pace
    /// itself: what the terminal takes then is the sender's rate, not the link's, and a late
    /// answer is the terminal's own delay (a software-rendered kitty drawing), not a queue.
    /// Such intervals never lower the rate on a short queue, and never set what the link was
    /// seen to deliver (measured over SSH: kitty's pictures on their lowest rung, 5.4 kB/s
    /// read as the link on a 250 kB/s link, and `auto` left pixels for cells).
    pub fn frame_sent(&mut self, spent: usize, budget: usize) {
        self.last_frame = spent as u64;
        if spent.saturating_mul(2) >= budget {
            self.spare_since_question = false;
        }
    }

    /// The terminal answered at `now` (device attributes): the oldest question is the one
    /// answered; a link question's round trip adjusts the rate.
    pub fn answered(&mut self, now: Instant) -> Change {
        let Some(question) = self.questions.pop_oldest() else {
            // An answer nobody asked for (typed, or one given up on).
            self.stray_answers += 1;
            return Change::Hold;
        };
        if question.foreign {
            self.foreign_answers += 1;
            return Change::Hold;
        }
        self.round_trip(question, now)
    }

    /// The terminal answered a device status report at `now` (the question wrapped for a
    /// multiplexer's passthrough, [`LinkPath::question`]): the oldest of the link's own
    /// questions is the one answered (the probe's are answered with device attributes).
    pub fn status_answered(&mut self, now: Instant) -> Change {
        match self.questions.pop_oldest_own() {
            Some(question) => self.round_trip(question, now),
            None => {
                self.stray_answers += 1;
                Change::Hold
            }
        }
    }

    /// Whether the terminal has not answered for [`SILENCE`] (a question waits that long).
    fn is_silent(&self, now: Instant) -> bool {
        self.silent || self.questions.iter().any(|q| !q.foreign && now.saturating_duration_since(q.asked) > SILENCE)
    }

    /// Looks at the clock: a question unanswered too long is congestion (once per question); a
    /// terminal silent for [`SILENCE`] gets [`SAFE_RATE`]; foreign answers overdue by
    /// [`FOREIGN_WAIT`] and questions older than [`GIVE_UP`] are forgotten.
    pub fn tick(&mut self, now: Instant) -> Change {
        self.window_bound |= self.waited_past_window(now);
        let age = |q: &Question| now.saturating_duration_since(q.asked);
        self.questions.forget(|q| age(q) > GIVE_UP || (q.foreign && age(q) > FOREIGN_WAIT));
        let base = self.base().unwrap_or(Duration::ZERO);
        if let Some(due) = self.clean_due
            && now >= answer_time::hold_end(due, base)
        {
            // The question in flight took too long: measure another time, frames go on.
            let gap = answer_time::next_gap(0, Duration::ZERO, Duration::ZERO, base);
            self.clean_due = Some(now + gap);
        }
        let limit = self.base().map_or(PROBE_TIMEOUT, |b| (4 * b).max(PROBE_TIMEOUT));
        // A terminal slow on its own (or not known yet) that stalls for a second with few
        // bytes in flight is busy, not congested (kitty 0.26 under llvmpipe, setting up its
        // first pictures): its lost question lowers the rate only when those bytes explain the
        // wait, as for a late answer.
        let marks = queue_marks(base);
        let mut lost = false;
        for q in self.questions.list[..self.questions.len].iter_mut().flatten() {
            // A terminal that has never answered is not congested: it is silent (below).
            if self.answered && !q.foreign && !q.overdue && age(q) > limit {
                // A small part of its bytes is taken as delivered, so a status line can still
                // go (the window, shrunk by the fall, stays shut for frames); all of them were,
                // and a stalled link or a paused terminal got a whole window more each second
                // (at 2 Mbit/s a 3 s stall queued 0.7 s, at 150 ms 1.2 s). It keeps its place,
                // so its late answer still opens the window; a terminal that never answers
                // again is silent at SILENCE and needs no window.
                self.acknowledged = self.acknowledged.max(q.bytes.min(self.acknowledged + MIN_WINDOW));
                q.overdue = true;
                lost |= 2 * q.in_flight >= age(q) || !self.answer_time.treat_as_slow(marks);
            }
        }
        if !self.silent && self.is_silent(now) {
            self.silent = true;
            // Questions stay one at a time: the oldest keeps waiting (until GIVE_UP).
            for q in self.questions.list[..self.questions.len].iter_mut().flatten() {
                q.overdue = false;
            }
            self.rate = self.rate.min(SAFE_RATE).min(self.ceiling);
            self.decided_at = Some(now);
            return Change::Down;
        }
        if lost && !self.drain.draining() {
            self.fall(now, DRAIN_SHARE, MIN_RATE, true);
            Change::Down
        } else {
            Change::Hold
        }
    }
}

#[cfg(test)]
mod hidden_tests;
#[cfg(test)]
mod tests;
