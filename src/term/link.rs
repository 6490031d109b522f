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
//! [`INCREASE_AFTER_LIMIT`] once the link has shown its limit; not at all while the frames use
//! under half of it, as still water does); over the high mark it falls to a little under what
//! the terminal was seen to take (the bytes between two answers over the time between them:
//! while a queue stands, that is the link's own rate), or by [`DECREASE`] when that is not
//! known yet, and the byte bucket is emptied, so the backlog drains; in between it holds. The
//! marks scale with the shortest round trip ([`queue_marks`]): a queue of one round trip, never
//! more than [`QUEUE_HIGH`], so a key's frame waits behind at most that. An answer that does not
//! come within [`PROBE_TIMEOUT`] (or four base round trips) counts as congestion too.
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
//! round trip measures the local side, not the link ([`Path`]): the rate is held at
//! [`SAFE_RATE`] there and [`LinkControl::hint`] says how to set `--bandwidth`. Time comes in as
//! an argument: the tests run on made-up clocks.

use std::time::{Duration, Instant};

/// The question: primary device attributes.
pub const PROBE: &[u8] = b"\x1b[c";
/// The rate the player starts at, bytes per second: a whole 160x48 frame in under a second
/// (coarse first, then exact), grown to a local terminal's speed within half a second, and not
/// so far above a slow link's rate that the first second leaves a long queue behind.
pub const START_RATE: f64 = 400_000.0;
/// The lowest rate: a few cells a frame.
pub const MIN_RATE: f64 = 2_000.0;
/// The highest rate; at it the link is treated as unlimited.
pub const MAX_RATE: f64 = 64_000_000.0;
/// The rate where the link cannot be measured (a silent terminal, a multiplexer over SSH,
/// mosh): under a 256 kbit/s link's 32 kB/s with room for a multiplexer's re-encoding, so no
/// backlog forms on any common link; a mosaic on a fast one, which `--bandwidth` lifts.
pub const SAFE_RATE: f64 = 24_000.0;
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
/// A round trip this much under the base is a new base (the queue was draining), not jitter.
const NEW_LOW_MARGIN: Duration = Duration::from_millis(2);
/// Questions remembered at most (one link question at a time, overdue ones, foreign ones).
const MAX_QUESTIONS: usize = 8;
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

/// What sits between the player and the screen, as far as the player can tell
/// ([`Path::detect`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(dead_code, reason = "detected by the player loop's rewrite (issue 21); today's player.rs predates it")]
pub enum Path {
    /// The terminal at the far end answers (plain SSH, a local terminal, a multiplexer on this
    /// machine's own screen): the round trip measures the link.
    Direct,
    /// A multiplexer (`tmux`, `screen`, `zellij`) over SSH: it answers DA1 itself from its
    /// local pane, and its output goes into SSH's buffers unpaced, so the link cannot be
    /// measured in band.
    Multiplexer(&'static str),
    /// mosh: mosh-server is the terminal; it answers DA1 at once and sends the client only the
    /// latest screen, paced to the link, so the program never sees the link. What it does see
    /// of the picture still crosses the link: each screen it sends carries every cell changed
    /// since the last one the client acknowledged.
    Mosh,
}

#[allow(dead_code, reason = "called by the player loop's rewrite (issue 21)")]
impl Path {
    /// Reads the path from the environment (`var` looks a variable up) and the names of the
    /// process's ancestors, nearest first (`/proc/PID/comm` on Linux; none elsewhere).
    ///
    /// mosh sets nothing of its own in the environment (only `TERM` and
    /// `NCURSES_NO_UTF8_ACS`, and it removes `STY`), but `mosh-server` is the ancestor of every
    /// program it runs. A multiplexer counts only over SSH (`SSH_CONNECTION`, `SSH_CLIENT` or
    /// `SSH_TTY`, which tmux's default `update-environment` refreshes on every attach): on this
    /// machine's own screen its answers come from a local terminal anyway.
    pub fn detect<'a>(var: impl Fn(&str) -> Option<String>, ancestors: impl IntoIterator<Item = &'a str>) -> Path {
        let set = |name: &str| var(name).is_some_and(|v| !v.is_empty());
        if ancestors.into_iter().any(|name| name.trim() == "mosh-server") {
            return Path::Mosh;
        }
        let remote = set("SSH_CONNECTION") || set("SSH_CLIENT") || set("SSH_TTY");
        let multiplexer = [("TMUX", "tmux"), ("STY", "screen"), ("ZELLIJ", "zellij")]
            .into_iter()
            .find(|(variable, _)| set(variable))
            .map(|(_, name)| name);
        match multiplexer {
            Some(name) if remote => Path::Multiplexer(name),
            _ => Path::Direct,
        }
    }
}

/// A question in flight, in the order asked.
#[derive(Clone, Copy, Debug)]
struct Question {
    /// When it went out.
    asked: Instant,
    /// The bytes sent up to it (0 for a foreign one).
    bytes: u64,
    /// Asked by somebody else (the graphics probe): its answer is dropped.
    foreign: bool,
    /// Unanswered for longer than the loss timeout: counted as congestion once, its bytes
    /// taken as delivered; it keeps its place for its late answer.
    overdue: bool,
}

/// The questions in flight, oldest first (a fixed array: steady-state frames allocate nothing).
#[derive(Clone, Debug)]
struct Questions {
    list: [Option<Question>; MAX_QUESTIONS],
    len: usize,
}

impl Questions {
    fn iter(&self) -> impl Iterator<Item = &Question> {
        self.list[..self.len].iter().flatten()
    }

    fn push(&mut self, question: Question) -> bool {
        if self.len == MAX_QUESTIONS {
            return false;
        }
        self.list[self.len] = Some(question);
        self.len += 1;
        true
    }

    fn pop_oldest(&mut self) -> Option<Question> {
        let oldest = self.list[..self.len].first().copied().flatten()?;
        self.list.copy_within(1..self.len, 0);
        self.len -= 1;
        self.list[self.len] = None;
        Some(oldest)
    }

    /// Drops the questions `forget` says to, keeping the others in order.
    fn forget(&mut self, mut forget: impl FnMut(&Question) -> bool) {
        let mut kept = 0;
        for i in 0..self.len {
            if let Some(q) = self.list[i].filter(|q| !forget(q)) {
                self.list[kept] = Some(q);
                kept += 1;
            }
        }
        self.list[kept..].fill(None);
        self.len = kept;
    }
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
    path: Path,
    /// The highest rate this path allows ([`MAX_RATE`], or [`SAFE_RATE`] where the link cannot
    /// be measured).
    ceiling: f64,
    rate: f64,
    /// The questions not yet answered, oldest first.
    questions: Questions,
    /// The last answer: when it came and the bytes its question followed.
    last_answer: Option<(Instant, u64)>,
    /// What the terminal was last seen to take, bytes per second.
    delivered: Option<f64>,
    /// What the link can carry, bytes per second, for the window: what the terminal took while
    /// a queue stood (then the link was the limit), else the most it was seen to take (still
    /// water takes little and must not shrink the window).
    capacity: Option<f64>,
    /// The last round trips, for the base.
    samples: [Duration; BASE_SAMPLES],
    sample_count: usize,
    /// The queue the last answer showed (two answers in a row over the high mark make a fall,
    /// so one late read of an answer does not).
    last_queue: Option<Duration>,
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
    /// The bytes the terminal has answered for (or given up on): everything sent up to the
    /// last answered or overdue question.
    acknowledged: u64,
    /// The bytes sent up to the last question asked.
    asked_up_to: u64,
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
    /// A controller for a terminal that answers from the far end ([`Path::Direct`]).
    pub fn new() -> LinkControl {
        LinkControl::on(Path::Direct)
    }

    /// A controller for what sits between the player and the screen.
    pub fn on(path: Path) -> LinkControl {
        let ceiling = match path {
            Path::Direct => MAX_RATE,
            Path::Multiplexer(_) | Path::Mosh => SAFE_RATE,
        };
        LinkControl {
            path,
            ceiling,
            rate: START_RATE.min(ceiling),
            questions: Questions { list: [None; MAX_QUESTIONS], len: 0 },
            last_answer: None,
            delivered: None,
            capacity: None,
            samples: [Duration::ZERO; BASE_SAMPLES],
            sample_count: 0,
            last_queue: None,
            answered: false,
            silent: false,
            last_rtt: None,
            decided_at: None,
            fell: false,
            acknowledged: 0,
            asked_up_to: 0,
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
        self.questions.push(Question { asked: now, bytes: bytes_sent, foreign: false, overdue: false });
    }

    /// The terminal answered at `now`: the oldest question is the one answered; a link
    /// question's round trip adjusts the rate.
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
        let (sent, bytes) = (question.asked, question.bytes);
        let first = !self.answered;
        self.answered = true;
        self.silent = false;
        self.acknowledged = self.acknowledged.max(bytes);
        let took = match self.last_answer {
            Some((then, before)) => Some((then, bytes.saturating_sub(before))),
            // The first answer: its frame crossed the link within the round trip (a lower
            // bound of the link's rate, what the window starts from).
            None => Some((sent, bytes)),
        }
        .map(|(since, b)| (now.saturating_duration_since(since).as_secs_f64(), b))
        .filter(|&(dt, b)| dt > 0.0 && b > 0)
        .map(|(dt, b)| b as f64 / dt);
        if let Some(rate) = took.filter(|_| self.last_answer.is_some()) {
            self.delivered = Some(rate);
        }
        self.last_answer = Some((now, bytes));
        let rtt = now.saturating_duration_since(sent);
        self.last_rtt = Some(rtt);
        let old_base = self.base();
        self.samples[self.sample_count % BASE_SAMPLES] = rtt;
        self.sample_count += 1;
        let base = self.base().unwrap_or(rtt);
        // A round trip shorter than every recent one: a queue is still draining (or the
        // first samples held one), so the base is not known yet and a short "queue" means
        // nothing.
        let new_low = old_base.is_some_and(|b| rtt + NEW_LOW_MARGIN < b);
        let queue = rtt.saturating_sub(base);
        let last_queue = self.last_queue.replace(queue);
        let (low, high) = queue_marks(base);
        if let Some(took) = took {
            self.capacity = Some(match self.capacity {
                Some(c) if queue <= low => c.max(took),
                _ => took,
            });
        }
        if first {
            // The first frame crossed the link within this round trip: the link carries at
            // least that much, and the rate may be far above it (a 400 kB/s start on a 32 kB/s
            // link). Starting from it drains what the first frames queued, so the next round
            // trips show the link's own delay: a base taken from a queue would hide every
            // later queue.
            // (A question after a few bytes says little: then the rate stays.)
            let shown = took.filter(|_| bytes >= MIN_WINDOW).map_or(self.rate, |t| t * DRAIN_SHARE).max(MIN_RATE);
            if shown < self.rate {
                self.rate = shown.min(self.ceiling);
                self.decided_at = Some(now);
                return Change::Down;
            }
        }
        if self.decided_at.is_some_and(|decided| sent < decided) {
            // Asked before the last change: it measures the queue that change is acting on.
            return Change::Hold;
        }
        // Two answers in a row over the high mark, the second no lower than the first: a
        // queue that stands and is not draining.
        let standing = last_queue.is_some_and(|last| last > high && queue >= last);
        if queue > high && standing {
            self.fall(now);
            Change::Down
        } else if queue < low && !new_low && self.rate < self.ceiling {
            let growth = if self.fell { INCREASE_AFTER_LIMIT } else { INCREASE };
            self.rate = (self.rate * growth).min(self.ceiling);
            self.decided_at = Some(now);
            Change::Up
        } else {
            Change::Hold
        }
    }

    fn fall(&mut self, now: Instant) {
        let target = match self.delivered {
            // Under what the link was seen to carry (an estimate from two answers, so never
            // below half the rate in one fall), and never up.
            Some(delivered) => (delivered * DRAIN_SHARE).max(self.rate * 0.5).min(self.rate * DRAIN_SHARE),
            None => self.rate * DECREASE,
        };
        self.rate = target.max(MIN_RATE);
        self.decided_at = Some(now);
        self.fell = true;
    }

    /// Whether the terminal has not answered for [`SILENCE`] (a question waits that long).
    fn is_silent(&self, now: Instant) -> bool {
        self.silent || self.questions.iter().any(|q| !q.foreign && now.saturating_duration_since(q.asked) > SILENCE)
    }

    /// How many more bytes may go out now, `bytes_sent` counting every byte written so far:
    /// the window less what is still unanswered for ([`usize::MAX`] for a terminal that does
    /// not answer).
    pub fn window_left(&self, now: Instant, bytes_sent: u64) -> usize {
        if self.is_silent(now) {
            return usize::MAX;
        }
        let window = if self.answered {
            // The bandwidth-delay product: one question at a time, so two round trips (each
            // with the queue the window allows) and a frame; never below what the rate sends
            // in that time, and the link's capacity as seen, not a rate still growing past it.
            let taken = self.capacity.unwrap_or(self.rate).min(self.rate);
            let base = self.base().unwrap_or(Duration::ZERO).min(WINDOW_RTT_MAX);
            let time = 2.0 * (base + WINDOW_QUEUE).as_secs_f64() + FRAME_ALLOWANCE.as_secs_f64();
            (taken * time).max(MIN_WINDOW as f64) as u64
        } else {
            let waited = self
                .questions
                .iter()
                .find(|q| !q.foreign)
                .map_or(Duration::ZERO, |q| now.saturating_duration_since(q.asked));
            FIRST_WINDOW + (FIRST_TRICKLE * waited.as_secs_f64()) as u64
        };
        usize::try_from(window.saturating_sub(bytes_sent.saturating_sub(self.acknowledged))).unwrap_or(usize::MAX)
    }

    /// Whether bytes went out after the last question: with none in flight, a question must
    /// follow them even without a frame, or a closed window would never open.
    pub fn unasked(&self, bytes_sent: u64) -> bool {
        bytes_sent > self.asked_up_to
    }

    /// Looks at the clock: a question unanswered too long is congestion (once per question); a
    /// terminal silent for [`SILENCE`] gets [`SAFE_RATE`]; foreign answers overdue by
    /// [`FOREIGN_WAIT`] and questions older than [`GIVE_UP`] are forgotten.
    pub fn tick(&mut self, now: Instant) -> Change {
        let age = |q: &Question| now.saturating_duration_since(q.asked);
        self.questions.forget(|q| age(q) > GIVE_UP || (q.foreign && age(q) > FOREIGN_WAIT));
        let limit = self.base().map_or(PROBE_TIMEOUT, |b| (4 * b).max(PROBE_TIMEOUT));
        let mut lost = false;
        for q in self.questions.list[..self.questions.len].iter_mut().flatten() {
            // A terminal that has never answered is not congested: it is silent (below).
            if self.answered && !q.foreign && !q.overdue && age(q) > limit {
                // Its bytes are taken as delivered, or the window would never open again; it
                // keeps its place, so its late answer is still paired with it.
                self.acknowledged = self.acknowledged.max(q.bytes);
                q.overdue = true;
                lost = true;
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
        if lost {
            self.fall(now);
            Change::Down
        } else {
            Change::Hold
        }
    }
}

/// What the Screen of the player's rewrite (`src/play/`) calls besides the loop above: the
/// path, the status line's hint, the probe's answers, the answers to wait for at the end.
#[allow(dead_code, reason = "called by the player loop's rewrite (issue 21); today's player.rs predates it")]
impl LinkControl {
    /// What sits between the player and the screen.
    pub fn path(&self) -> Path {
        self.path
    }

    /// A few words for the status line when the link cannot be measured and the rate is a
    /// guess ([`SAFE_RATE`]): how to set it.
    pub fn hint(&self) -> Option<&'static str> {
        match self.path {
            Path::Multiplexer("tmux") => Some("tmux over SSH: link not measured, set --bandwidth (250k = 2 Mbit/s)"),
            Path::Multiplexer("screen") => {
                Some("screen over SSH: link not measured, set --bandwidth (250k = 2 Mbit/s)")
            }
            Path::Multiplexer(_) => Some("multiplexer over SSH: link not measured, set --bandwidth (250k = 2 Mbit/s)"),
            Path::Mosh => Some("mosh: link not measured, set --bandwidth (250k = 2 Mbit/s)"),
            Path::Direct if self.silent => Some("the terminal does not answer: set --bandwidth (250k = 2 Mbit/s)"),
            Path::Direct => None,
        }
    }

    /// The last round trip measured.
    pub fn last_rtt(&self) -> Option<Duration> {
        self.last_rtt
    }

    /// Answers counted as foreign ([`LinkControl::expect_foreign`]) and answers that came with
    /// no question waiting, so far.
    pub fn dropped_answers(&self) -> (u64, u64) {
        (self.foreign_answers, self.stray_answers)
    }

    /// How many answers are still expected (link and foreign questions): at the end, wait a
    /// little for them, or they reach the shell as typed text.
    pub fn awaiting(&self) -> usize {
        self.questions.len
    }

    /// `count` DA1 questions somebody else asked (the graphics probe) are still to be answered,
    /// ahead of every link question asked from now on: their answers are counted and dropped.
    /// Until they come, or [`FOREIGN_WAIT`] has passed, no link question is asked, so an answer
    /// that never comes cannot shift the pairing.
    pub fn expect_foreign(&mut self, now: Instant, count: usize) {
        for _ in 0..count {
            if !self.questions.push(Question { asked: now, bytes: 0, foreign: true, overdue: false }) {
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(n: u64) -> Duration {
        Duration::from_millis(n)
    }

    const FPS: f64 = 30.0;

    /// Who answers the questions.
    #[derive(Clone, Copy, PartialEq)]
    enum Answers {
        /// The terminal at the far end, once it has read everything before the question.
        FarEnd,
        /// Something on this side of the link, at once (a multiplexer, mosh-server).
        Local,
        /// Nobody.
        Never,
    }

    /// A link of `capacity` bytes per second with a deep buffer (like SSH's: everything is
    /// accepted at once, the terminal reads at that rate) and a round trip of `rtt` on top.
    #[derive(Clone, Copy)]
    struct Link {
        capacity: f64,
        rtt: Duration,
        answers: Answers,
        /// The graphics probe's DA1 went out this long before the player started; its answer
        /// comes a round trip later (the player is told with `expect_foreign`). `None`: no
        /// probe answer is outstanding.
        probe_lead: Option<Duration>,
        /// Whether the probe's answer ever comes.
        probe_answered: bool,
    }

    impl Link {
        fn far(capacity: f64, rtt: Duration) -> Link {
            Link { capacity, rtt, answers: Answers::FarEnd, probe_lead: None, probe_answered: true }
        }
    }

    /// What a run saw, one entry a frame.
    #[derive(Default)]
    struct Run {
        /// Seconds since the start.
        at: Vec<f64>,
        /// The rate in effect (bytes per second).
        rates: Vec<f64>,
        /// Seconds of bytes written but not yet read by the terminal, after the frame.
        queue: Vec<f64>,
        /// Bytes written so far.
        sent: Vec<u64>,
        /// Every round trip the controller measured.
        rtts: Vec<Duration>,
        link: Option<LinkControl>,
    }

    impl Run {
        /// Bytes the terminal read per second between `from` and `to` seconds.
        fn throughput(&self, capacity: f64, from: f64, to: f64) -> f64 {
            let i = self.at.iter().position(|&t| t >= from).unwrap();
            let j = self.at.iter().rposition(|&t| t <= to).unwrap();
            let read = |k: usize| self.sent[k] as f64 - self.queue[k] * capacity;
            (read(j) - read(i)) / (self.at[j] - self.at[i])
        }

        /// The `p` quantile of the queue between `from` seconds and the end.
        fn queue_quantile(&self, from: f64, p: f64) -> f64 {
            let mut q: Vec<f64> =
                self.at.iter().zip(&self.queue).filter(|(t, _)| **t >= from).map(|(_, q)| *q).collect();
            q.sort_by(f64::total_cmp);
            q[((q.len() - 1) as f64 * p).round() as usize]
        }

        fn mean_rate(&self, from: f64) -> f64 {
            let r: Vec<f64> = self.at.iter().zip(&self.rates).filter(|(t, _)| **t >= from).map(|(_, r)| *r).collect();
            r.iter().sum::<f64>() / r.len() as f64
        }
    }

    /// Runs the controller for `seconds` on `path` over `link`, the player sending a frame
    /// every 1/30 s of what the rate allows (the bucket, simplified) within the window, or
    /// `demand(t)` bytes when the water needs less. Answers are handled when they arrive (the
    /// player's loop wakes on input), the clock is made up.
    fn simulate(path: Path, link: Link, seconds: f64, demand: impl Fn(f64) -> f64) -> Run {
        let t0 = Instant::now() + Duration::from_secs(1);
        let at = |s: f64| t0 + Duration::from_secs_f64(s);
        let mut control = LinkControl::on(path);
        let mut run = Run::default();
        // When the terminal has read everything written so far.
        let mut drained = t0;
        let mut sent = 0u64;
        // When each pending answer arrives, in order (a terminal answers in order).
        let mut answers: std::collections::VecDeque<Instant> = Default::default();
        if let Some(lead) = link.probe_lead {
            control.expect_foreign(t0, 1);
            if link.probe_answered {
                answers.push_back(t0 - lead + link.rtt);
            }
        }
        let mut next_frame = t0;
        let end = at(seconds);
        while next_frame < end {
            // Answers due before the next frame, each at its own time.
            while answers.front().is_some_and(|&a| a <= next_frame) {
                let a = answers.pop_front().unwrap();
                control.answered(a);
                if let Some(rtt) = control.last_rtt()
                    && run.rtts.last() != Some(&rtt)
                {
                    run.rtts.push(rtt);
                }
                control.tick(a);
            }
            let now = next_frame;
            control.tick(now);
            let t = now.duration_since(t0).as_secs_f64();
            let rate = control.rate().unwrap_or(MAX_RATE);
            let bytes = (rate / FPS).min(demand(t)).min(control.window_left(now, sent) as f64).floor();
            sent += bytes as u64;
            drained = drained.max(now) + Duration::from_secs_f64(bytes / link.capacity);
            if control.probe_due() && (bytes > 0.0 || control.unasked(sent)) {
                control.probed(now, sent);
                let answer = match link.answers {
                    Answers::FarEnd => Some(drained + link.rtt),
                    Answers::Local => Some(now + ms(1)),
                    Answers::Never => None,
                };
                if let Some(a) = answer {
                    let a = answers.back().map_or(a, |&last| a.max(last));
                    answers.push_back(a);
                }
            }
            run.at.push(t);
            run.rates.push(rate);
            run.queue.push(drained.saturating_duration_since(now).as_secs_f64());
            run.sent.push(sent);
            next_frame += Duration::from_secs_f64(1.0 / FPS);
        }
        run.link = Some(control);
        run
    }

    fn busy(_: f64) -> f64 {
        f64::INFINITY
    }

    #[test]
    fn the_link_is_filled_and_its_queue_stays_under_a_round_trip_and_a_frame() {
        // 2 Mbit/s at 20 and 150 ms, 256 kbit/s at 300 ms: what the real-link harness runs.
        for (capacity, rtt) in [(250_000.0, ms(20)), (250_000.0, ms(150)), (32_000.0, ms(300))] {
            let run = simulate(Path::Direct, Link::far(capacity, rtt), 40.0, busy);
            let used = run.throughput(capacity, 20.0, 40.0) / capacity;
            // One frame's time, and the frame's own bytes crossing the link.
            let bound = rtt.as_secs_f64() + 2.0 / FPS;
            let p90 = run.queue_quantile(20.0, 0.9);
            println!(
                "{capacity:>7.0} B/s, {rtt:?}: {:.0} % of the link, queue p90 {:.0} ms (bound {:.0} ms)",
                used * 100.0,
                p90 * 1e3,
                bound * 1e3
            );
            assert!(used >= 0.8, "{capacity} B/s, {rtt:?}: only {:.0} % of the link used", used * 100.0);
            assert!(
                p90 <= bound,
                "{capacity} B/s, {rtt:?}: the queue's p90 is {:.0} ms, over {:.0} ms",
                p90 * 1e3,
                bound * 1e3
            );
        }
    }

    #[test]
    fn the_first_seconds_never_queue_long_even_on_a_very_slow_link() {
        // 20 kB/s, 30 ms away: at the start rate alone, the first second would queue 20 s.
        let run = simulate(Path::Direct, Link::far(20_000.0, ms(30)), 20.0, busy);
        let worst = run.queue.iter().copied().fold(0.0, f64::max);
        assert!(worst < 1.5, "the longest queue is {worst:.2} s");
        let p90 = run.queue_quantile(10.0, 0.9);
        assert!(p90 < 0.2, "the queue settles short: p90 {p90:.2} s");
        let used = run.throughput(20_000.0, 10.0, 20.0);
        assert!(used > 16_000.0, "and the link is used: {used:.0} B/s");
        // And at 300 ms the first seconds stay within the window's bound.
        let run = simulate(Path::Direct, Link::far(32_000.0, ms(300)), 10.0, busy);
        let worst = run.queue.iter().copied().fold(0.0, f64::max);
        assert!(worst < 1.5, "the longest queue at 300 ms is {worst:.2} s");
    }

    #[test]
    fn a_late_probe_answer_does_not_shift_the_pairing() {
        // The probe's DA1 went out 150 ms before the player started and gave up on its
        // answer; over a 300 ms round trip the answer comes 150 ms into the player's life. Were
        // it paired with the player's first question, that round trip would read 150 ms, and
        // every later one a question too early.
        let link = Link { probe_lead: Some(ms(150)), ..Link::far(250_000.0, ms(300)) };
        let run = simulate(Path::Direct, link, 10.0, busy);
        let control = run.link.as_ref().unwrap();
        assert_eq!(control.dropped_answers(), (1, 0), "the probe's answer is counted as foreign");
        let shortest = run.rtts.iter().min().unwrap();
        assert!(*shortest >= ms(300), "a round trip read {shortest:?}, shorter than the link's 300 ms");
        let used = run.throughput(250_000.0, 5.0, 10.0) / 250_000.0;
        assert!(used >= 0.8, "and the link is used: {:.0} %", used * 100.0);
    }

    #[test]
    fn a_probe_answer_that_never_comes_holds_the_questions_only_for_a_while() {
        let t0 = Instant::now();
        let mut link = LinkControl::new();
        link.expect_foreign(t0, 1);
        assert!(!link.probe_due(), "no link question while a foreign answer is due");
        link.tick(t0 + FOREIGN_WAIT - ms(1));
        assert!(!link.probe_due());
        link.tick(t0 + FOREIGN_WAIT + ms(1));
        assert!(link.probe_due(), "the foreign answer is taken never to come");
        link.probed(t0 + FOREIGN_WAIT + ms(2), 1000);
        link.answered(t0 + FOREIGN_WAIT + ms(52));
        assert_eq!(link.last_rtt(), Some(ms(50)));
        assert_eq!(link.dropped_answers(), (0, 0));
    }

    /// Asserts the player kept drawing: bytes went out in every half second of the run.
    fn never_frozen(run: &Run) {
        for half in 0..(run.at.last().unwrap() * 2.0) as usize {
            let (from, to) = (half as f64 / 2.0, (half + 1) as f64 / 2.0);
            let i = run.at.iter().position(|&t| t >= from).unwrap();
            let j = run.at.iter().rposition(|&t| t < to).unwrap();
            assert!(run.sent[j] > run.sent[i.saturating_sub(1)], "nothing sent between {from} s and {to} s");
        }
    }

    #[test]
    fn a_terminal_that_never_answers_is_sent_a_safe_rate_and_never_freezes() {
        let link = Link { answers: Answers::Never, ..Link::far(32_000.0, ms(300)) };
        let run = simulate(Path::Direct, link, 20.0, busy);
        never_frozen(&run);
        let late = run.mean_rate(SILENCE.as_secs_f64() + 0.1);
        assert!(late <= SAFE_RATE, "after {SILENCE:?} of silence the rate is {late:.0} B/s");
        // 24 kB/s into a 32 kB/s link: the first seconds' backlog drains, none builds.
        let queue = *run.queue.last().unwrap();
        assert!(queue < 0.5, "the queue at the end is {queue:.2} s");
        let control = run.link.as_ref().unwrap();
        assert!(control.hint().is_some_and(|h| h.contains("--bandwidth")), "the status line says how to set it");
        assert_eq!(control.window_left(Instant::now() + Duration::from_secs(30), u64::MAX / 2), usize::MAX);
    }

    #[test]
    fn a_terminal_that_answers_only_the_probe_is_sent_a_safe_rate_and_never_freezes() {
        let link = Link { answers: Answers::Never, probe_lead: Some(ms(100)), ..Link::far(32_000.0, ms(300)) };
        let run = simulate(Path::Direct, link, 20.0, busy);
        never_frozen(&run);
        assert_eq!(run.link.as_ref().unwrap().dropped_answers().0, 1, "the probe's answer came and was dropped");
        let late = run.mean_rate(SILENCE.as_secs_f64() + 1.1);
        assert!(late <= SAFE_RATE, "the rate is {late:.0} B/s");
        assert!(*run.queue.last().unwrap() < 0.5);
    }

    #[test]
    fn a_multiplexer_over_ssh_or_mosh_holds_the_safe_rate_where_local_answers_would_run_away() {
        // tmux (or mosh-server) answers at once from this side; its output crosses a 256
        // kbit/s link unpaced. Taken for the far end, the answers would grow the rate without
        // limit and queue seconds in SSH's buffers; on the multiplexer path it stays safe.
        let link = Link { answers: Answers::Local, ..Link::far(32_000.0, ms(300)) };
        let fooled = simulate(Path::Direct, link, 10.0, busy);
        assert!(*fooled.queue.last().unwrap() > 5.0, "the direct controller is fooled by local answers");
        for path in [Path::Multiplexer("tmux"), Path::Mosh] {
            let run = simulate(path, link, 20.0, busy);
            never_frozen(&run);
            let highest = run.rates.iter().copied().fold(0.0, f64::max);
            assert!(highest <= SAFE_RATE, "{path:?}: the rate reached {highest:.0} B/s");
            let queue = *run.queue.last().unwrap();
            assert!(queue < 0.5, "{path:?}: the queue at the end is {queue:.2} s");
            assert!(run.link.as_ref().unwrap().hint().is_some_and(|h| h.contains("--bandwidth")));
        }
    }

    #[test]
    fn the_path_is_read_from_the_environment_and_the_ancestors() {
        fn env<'a>(pairs: &'a [(&'a str, &'a str)]) -> impl Fn(&str) -> Option<String> + 'a {
            move |name: &str| pairs.iter().find(|(k, _)| *k == name).map(|(_, v)| v.to_string())
        }
        let ssh = [("SSH_CONNECTION", "10.0.0.1 5000 10.0.0.2 22")];
        assert_eq!(Path::detect(env(&ssh), ["bash", "sshd"]), Path::Direct);
        assert_eq!(
            Path::detect(env(&[("TMUX", "/tmp/tmux-0/default,1,0")]), ["bash", "tmux: server"]),
            Path::Direct,
            "tmux on this screen"
        );
        let tmux_over_ssh = [("TMUX", "/tmp/tmux-0/default,1,0"), ("SSH_CONNECTION", "a 1 b 22")];
        assert_eq!(Path::detect(env(&tmux_over_ssh), ["bash"]), Path::Multiplexer("tmux"));
        assert_eq!(
            Path::detect(env(&[("STY", "123.pts-0.host"), ("SSH_TTY", "/dev/pts/0")]), []),
            Path::Multiplexer("screen")
        );
        assert_eq!(
            Path::detect(env(&[("TMUX", ""), ("SSH_CLIENT", "a 1 22")]), []),
            Path::Direct,
            "an empty TMUX is none"
        );
        let mosh_env = [("SSH_CONNECTION", "a 1 b 22"), ("NCURSES_NO_UTF8_ACS", "1")];
        assert_eq!(Path::detect(env(&mosh_env), ["bash", "mosh-server"]), Path::Mosh);
        assert_eq!(Path::detect(env(&mosh_env), ["mosh-server"]), Path::Mosh);
    }

    #[test]
    fn an_overdue_question_keeps_its_place_for_its_late_answer() {
        let t0 = Instant::now();
        let mut link = LinkControl::new();
        link.probed(t0, 1000);
        link.answered(t0 + ms(50));
        link.probed(t0 + ms(60), 2000);
        assert_eq!(link.tick(t0 + ms(60) + PROBE_TIMEOUT + ms(1)), Change::Down, "overdue: congestion");
        assert!(link.probe_due(), "an overdue question is replaced");
        link.probed(t0 + ms(1100), 3000);
        // The late answer is the overdue question's own, the next one the next question's.
        link.answered(t0 + ms(1500));
        assert_eq!(link.last_rtt(), Some(ms(1440)));
        link.answered(t0 + ms(1550));
        assert_eq!(link.last_rtt(), Some(ms(450)));
        assert_eq!(link.dropped_answers(), (0, 0));
    }

    #[test]
    fn the_window_opens_with_a_bare_question_and_is_dropped_for_a_silent_terminal() {
        let t0 = Instant::now();
        let mut link = LinkControl::new();
        assert_eq!(link.window_left(t0, 0), FIRST_WINDOW as usize);
        link.probed(t0, 10_000);
        assert_eq!(link.window_left(t0, 30_000), 0, "30 kB sent, none answered for");
        link.answered(t0 + ms(20));
        // Answered for 10 kB; 20 kB went out after the question: none in flight, so a bare
        // question must follow them.
        assert!(link.probe_due() && link.unasked(30_000));
        link.probed(t0 + ms(21), 30_000);
        assert!(!link.unasked(30_000));
        link.answered(t0 + ms(40));
        assert!(link.window_left(t0 + ms(40), 30_000) >= MIN_WINDOW as usize, "all answered for: open");
        // A terminal that never answers gets no window once the first answer is overdue.
        let mut silent = LinkControl::new();
        silent.probed(t0, 5_000);
        assert_eq!(silent.window_left(t0 + ms(100), 50_000), 0);
        assert_eq!(silent.window_left(t0 + SILENCE + ms(1), 50_000), usize::MAX);
    }

    #[test]
    fn still_water_does_not_shrink_the_window() {
        // A local terminal takes a 24 kB frame in 2 ms; then only status lines go out for a
        // while (tiny deliveries); a whole frame after that must still fit at once.
        let t0 = Instant::now();
        let mut link = LinkControl::new();
        let mut sent = 24_000;
        link.probed(t0, sent);
        link.answered(t0 + ms(2));
        for i in 1..=40 {
            sent += 100;
            let at = t0 + ms(33 * i);
            link.probed(at, sent);
            link.answered(at + ms(1));
        }
        let now = t0 + ms(33 * 41);
        assert!(link.window_left(now, sent) >= 300_000, "{}", link.window_left(now, sent));
    }

    #[test]
    fn a_local_terminal_grows_to_no_limit() {
        let run = simulate(Path::Direct, Link::far(1e9, ms(0)), 3.0, busy);
        assert_eq!(*run.rates.last().unwrap(), MAX_RATE, "a fast link ends unlimited");
    }

    #[test]
    fn lost_answers_slow_down_and_silence_gets_the_safe_rate() {
        let t0 = Instant::now();
        let mut link = LinkControl::new();
        link.probed(t0, 100);
        assert_eq!(link.tick(t0 + SILENCE - ms(1)), Change::Hold, "a first answer may take a while");
        assert_eq!(link.rate(), Some(START_RATE));
        link.answered(t0 + ms(5));
        link.probed(t0 + ms(10), 200);
        assert_eq!(link.tick(t0 + ms(10) + PROBE_TIMEOUT + ms(1)), Change::Down);
        assert!(link.rate().unwrap() < START_RATE * INCREASE);
        assert!(link.probe_due(), "the overdue question is replaced");
        assert_eq!(link.tick(t0 + ms(10) + SILENCE + ms(1)), Change::Down, "then silence");
        assert!(link.rate().unwrap() <= SAFE_RATE);
        assert_eq!(LinkControl::new().answered(t0), Change::Hold, "an answer nobody asked for");
    }
}
