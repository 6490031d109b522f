//! Finding the link's bandwidth by itself, from a round trip measured in band.
//!
//! Over SSH the socket buffers swallow megabytes before a write ever blocks, so the time a
//! write takes says nothing until a backlog of seconds has formed. The terminal can say more:
//! after a frame the player asks for the primary device attributes (`ESC[c`, which every
//! terminal answers and which is never a key), and the reply comes back only once the terminal
//! has read everything sent before the question. The round trip's excess over the shortest one
//! seen recently is the queue the frames have built in the link.
//!
//! The rate follows that queue like a delay-based congestion controller: while the queue stays
//! under [`QUEUE_LOW`] the rate grows by [`INCREASE`] per reply (by [`INCREASE_AFTER_LIMIT`] once
//! the link has shown its limit); over [`QUEUE_HIGH`] it falls to
//! a little under what the terminal was seen to take (the bytes between two answers over the
//! time between them: while a queue stands, that is the link's own rate), or by [`DECREASE`]
//! when that is not known yet, and the byte bucket is emptied, so the backlog drains instead
//! of growing; in between it holds. An answer that does not come within [`PROBE_TIMEOUT`] (or four base round
//! trips) counts as congestion too. A terminal that never answers at all is left at the rate it
//! has. Time comes in as an argument: the tests run on made-up clocks.
//!
//! A rate alone cannot keep the first seconds short on a very slow link: the first answer comes
//! back only once the first frame has crossed the link, and until then the player would keep
//! sending at [`START_RATE`] (at 20 kB/s, a minute of backlog in the first few seconds). So the
//! bytes sent and not yet answered for are also capped, as TCP caps its unacknowledged bytes:
//! [`FIRST_WINDOW`] until the first answer, then 1.5 times what the terminal was seen to take
//! in [`WINDOW_TIME`] ([`LinkControl::window_left`]). A terminal that does not answer within
//! [`FIRST_ANSWER_WAIT`] is taken never to answer and gets no window.

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
/// A queue shorter than this lets the rate grow.
pub const QUEUE_LOW: Duration = Duration::from_millis(50);
/// A queue longer than this makes the rate fall.
pub const QUEUE_HIGH: Duration = Duration::from_millis(150);
/// Growth per answer while the queue is short, until the link first shows a queue (to find a
/// fast link within a few frames).
pub const INCREASE: f64 = 1.25;
/// Growth per answer while the queue is short, once the link has shown its limit (gentle: the
/// answers that would stop it come a round trip late).
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
/// Once answered, the unanswered bytes may be 1.5 times what the terminal was seen to take in this
/// long: a queue of at most about this long, more than [`QUEUE_HIGH`] so the rate control acts
/// first and the window bounds the worst case (the first seconds, a link that slows down).
pub const WINDOW_TIME: Duration = Duration::from_millis(250);
/// The smallest window once the terminal answers: a status line and a few cells.
pub const MIN_WINDOW: u64 = 4_000;
/// How long the first question may wait for its answer before the terminal is taken never to
/// answer (then there is no window: nothing would ever open it).
pub const FIRST_ANSWER_WAIT: Duration = Duration::from_secs(3);
/// Questions in flight at most (one is the rule; a lost one is replaced).
const MAX_IN_FLIGHT: usize = 4;
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

/// The controller: the rate in effect and the questions in flight.
#[derive(Clone, Debug)]
pub struct LinkControl {
    rate: f64,
    /// The questions not yet answered: when each went out and the bytes sent up to it.
    in_flight: [Option<(Instant, u64)>; MAX_IN_FLIGHT],
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
    /// Whether any question was ever answered (a terminal that never answers is left alone).
    answered: bool,
    /// The last round trip measured.
    last_rtt: Option<Duration>,
    /// When the rate last fell: answers to questions sent before it still carry the old
    /// queue, so they do not make it fall again.
    fell_at: Option<Instant>,
    /// The bytes the terminal has answered for (or given up on): everything sent up to the
    /// last answered or lost question.
    acknowledged: u64,
    /// When the first question went out.
    first_question: Option<Instant>,
    /// The bytes sent up to the last question asked.
    asked_up_to: u64,
}

impl Default for LinkControl {
    fn default() -> Self {
        LinkControl::new()
    }
}

impl LinkControl {
    /// A controller at [`START_RATE`].
    pub fn new() -> LinkControl {
        LinkControl {
            rate: START_RATE,
            in_flight: [None; MAX_IN_FLIGHT],
            last_answer: None,
            delivered: None,
            capacity: None,
            samples: [Duration::ZERO; BASE_SAMPLES],
            sample_count: 0,
            answered: false,
            last_rtt: None,
            fell_at: None,
            acknowledged: 0,
            first_question: None,
            asked_up_to: 0,
        }
    }

    /// The rate in effect, bytes per second; `None` at [`MAX_RATE`] (no limit).
    pub fn rate(&self) -> Option<f64> {
        (self.rate < MAX_RATE).then_some(self.rate)
    }

    /// The last round trip measured.
    #[cfg(test)]
    pub fn last_rtt(&self) -> Option<Duration> {
        self.last_rtt
    }

    /// The shortest recent round trip.
    fn base(&self) -> Option<Duration> {
        self.samples[..self.sample_count.min(BASE_SAMPLES)].iter().min().copied()
    }

    fn outstanding(&self) -> usize {
        self.in_flight.iter().filter(|t| t.is_some()).count()
    }

    /// Whether a question should go out with the frame being sent: none is in flight.
    pub fn probe_due(&self) -> bool {
        self.outstanding() == 0
    }

    /// A question went out at `now`, appended to a frame; `bytes_sent` counts every byte the
    /// player has written, that frame included.
    pub fn probed(&mut self, now: Instant, bytes_sent: u64) {
        self.first_question.get_or_insert(now);
        self.asked_up_to = self.asked_up_to.max(bytes_sent);
        if let Some(slot) = self.in_flight.iter_mut().find(|t| t.is_none()) {
            *slot = Some((now, bytes_sent));
        }
    }

    /// The terminal answered at `now`: the oldest question's round trip adjusts the rate.
    pub fn answered(&mut self, now: Instant) -> Change {
        let Some((slot, (sent, bytes))) =
            self.in_flight.iter().enumerate().filter_map(|(i, t)| t.map(|t| (i, t))).min_by_key(|&(_, (t, _))| t)
        else {
            return Change::Hold; // an answer nobody asked for (the probe at start, a typed one)
        };
        self.in_flight[slot] = None;
        self.answered = true;
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
        self.samples[self.sample_count % BASE_SAMPLES] = rtt;
        self.sample_count += 1;
        let queue = rtt.saturating_sub(self.base().unwrap_or(rtt));
        if let Some(took) = took {
            self.capacity = Some(match self.capacity {
                Some(c) if queue <= QUEUE_LOW => c.max(took),
                _ => took,
            });
        }
        let stale = self.fell_at.is_some_and(|fell| sent < fell);
        if stale {
            // Asked before the last fall: it measures the queue that fall is draining.
            Change::Hold
        } else if queue > QUEUE_HIGH {
            self.fall(now);
            Change::Down
        } else if queue < QUEUE_LOW {
            let growth = if self.fell_at.is_some() { INCREASE_AFTER_LIMIT } else { INCREASE };
            self.rate = (self.rate * growth).min(MAX_RATE);
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
        self.fell_at = Some(now);
    }

    /// How many more bytes may go out now, `bytes_sent` counting every byte written so far:
    /// the window less what is still unanswered for ([`usize::MAX`] for a terminal that does
    /// not answer).
    pub fn window_left(&self, now: Instant, bytes_sent: u64) -> usize {
        let window = if self.answered {
            // 1.5 times what the terminal was seen to take in WINDOW_TIME: room to grow (the
            // window grows by half per round trip while the link keeps up), never seconds.
            let taken = self.capacity.unwrap_or(self.rate).min(self.rate);
            (1.5 * taken * WINDOW_TIME.as_secs_f64()).max(MIN_WINDOW as f64) as u64
        } else if self.first_question.is_some_and(|t| now.saturating_duration_since(t) > FIRST_ANSWER_WAIT) {
            return usize::MAX;
        } else {
            FIRST_WINDOW
        };
        usize::try_from(window.saturating_sub(bytes_sent.saturating_sub(self.acknowledged))).unwrap_or(usize::MAX)
    }

    /// Whether bytes went out after the last question: with none in flight, a question must
    /// follow them even without a frame, or a closed window would never open.
    pub fn unasked(&self, bytes_sent: u64) -> bool {
        bytes_sent > self.asked_up_to
    }

    /// Checks for a question unanswered too long: congestion (once per question). A terminal
    /// that has never answered is not slowed down.
    pub fn tick(&mut self, now: Instant) -> Change {
        if !self.answered {
            return Change::Hold;
        }
        let limit = self.base().map_or(PROBE_TIMEOUT, |b| (4 * b).max(PROBE_TIMEOUT));
        let mut lost = false;
        for slot in &mut self.in_flight {
            if let Some((sent, bytes)) = *slot
                && now.saturating_duration_since(sent) > limit
            {
                // Its bytes are taken as delivered, or the window would never open again.
                self.acknowledged = self.acknowledged.max(bytes);
                // Given up on: its late answer would be matched to a newer question, so it
                // leaves the list; the link is congested.
                *slot = None;
                lost = true;
            }
        }
        if lost {
            self.fall(now);
            Change::Down
        } else {
            Change::Hold
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(n: u64) -> Duration {
        Duration::from_millis(n)
    }

    /// A link of `bytes_per_second` with a deep buffer (like SSH's): the terminal reads bytes
    /// at that rate after a fixed latency; the controller's rate decides what is written.
    fn simulate(bytes_per_second: f64, latency: Duration, seconds: u64) -> (Vec<f64>, Vec<Duration>) {
        let (rates, rtts, _) = simulate_queue(bytes_per_second, latency, seconds);
        (rates, rtts)
    }

    /// As [`simulate`], also returning the link's queue (seconds of bytes not yet read by the
    /// terminal) after each frame, and honouring the window as the player does.
    fn simulate_queue(bytes_per_second: f64, latency: Duration, seconds: u64) -> (Vec<f64>, Vec<Duration>, Vec<f64>) {
        let t0 = Instant::now();
        let mut link = LinkControl::new();
        let frame = Duration::from_nanos(33_333_333);
        // When the terminal has read everything written so far (the queue's end).
        let mut drained = t0;
        let mut sent = 0u64;
        let mut answers: Vec<Instant> = Vec::new();
        let (mut rates, mut rtts, mut queue) = (Vec::new(), Vec::new(), Vec::new());
        let mut now = t0;
        while now < t0 + Duration::from_secs(seconds) {
            // A frame of what one frame's share of the rate allows (the bucket, simplified),
            // within the window.
            let bytes = (link.rate().unwrap_or(MAX_RATE) / 30.0).min(link.window_left(now, sent) as f64).floor();
            sent += bytes as u64;
            drained = drained.max(now) + Duration::from_secs_f64(bytes / bytes_per_second);
            if link.probe_due() && (bytes > 0.0 || link.unasked(sent)) {
                link.probed(now, sent);
                answers.push(drained + latency);
            }
            queue.push(drained.saturating_duration_since(now).as_secs_f64());
            now += frame;
            answers.sort();
            while answers.first().is_some_and(|&a| a <= now) {
                answers.remove(0);
                link.answered(now);
                rtts.push(link.last_rtt().unwrap());
            }
            link.tick(now);
            rates.push(link.rate().unwrap_or(MAX_RATE));
        }
        (rates, rtts, queue)
    }

    #[test]
    fn a_slow_link_is_found_and_its_queue_stays_short() {
        // 2 Mbit/s = 250 kB/s, 20 ms away.
        let (rates, rtts) = simulate(250_000.0, ms(20), 20);
        let late = &rates[rates.len() - 300..];
        let mean = late.iter().sum::<f64>() / late.len() as f64;

        assert!((120_000.0..=320_000.0).contains(&mean), "settles near the link's rate: {mean:.0} B/s");
        let mut late_rtts = rtts[rtts.len() / 2..].to_vec();
        late_rtts.sort();
        let p90 = late_rtts[late_rtts.len() * 9 / 10];
        assert!(p90 < ms(400), "the queue stays short: p90 round trip {p90:?}");
    }

    #[test]
    fn a_very_slow_link_never_queues_seconds_even_at_the_start() {
        // 20 kB/s, 30 ms away: at the start rate alone, the first second would queue 20 s.
        let (rates, _, queue) = simulate_queue(20_000.0, ms(30), 20);
        let worst = queue.iter().copied().fold(0.0, f64::max);
        assert!(worst < 1.5, "the longest queue is {worst:.2} s");
        let late = &queue[queue.len() - 300..];
        let p90 = {
            let mut q = late.to_vec();
            q.sort_by(f64::total_cmp);
            q[q.len() * 9 / 10]
        };
        assert!(p90 < 0.5, "the queue settles short: p90 {p90:.2} s");
        let mean = rates[rates.len() - 300..].iter().sum::<f64>() / 300.0;
        assert!(mean > 8_000.0, "and the link is used: {mean:.0} B/s");
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
        assert_eq!(silent.window_left(t0 + FIRST_ANSWER_WAIT + ms(1), 50_000), usize::MAX);
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
        let (rates, _) = simulate(1e9, ms(0), 3);
        assert_eq!(*rates.last().unwrap(), MAX_RATE, "a fast link ends unlimited");
    }

    #[test]
    fn silence_before_any_answer_changes_nothing_and_lost_answers_slow_down() {
        let t0 = Instant::now();
        let mut link = LinkControl::new();
        link.probed(t0, 100);
        assert_eq!(link.tick(t0 + Duration::from_secs(10)), Change::Hold, "a terminal that never answers");
        assert_eq!(link.rate(), Some(START_RATE));
        link.answered(t0 + ms(5));
        link.probed(t0 + ms(10), 200);
        assert_eq!(link.tick(t0 + ms(10) + PROBE_TIMEOUT + ms(1)), Change::Down);
        assert!(link.rate().unwrap() < START_RATE * INCREASE);
        assert!(link.probe_due(), "the lost question is forgotten, a new one may go");
        assert_eq!(LinkControl::new().answered(t0), Change::Hold, "an answer nobody asked for");
    }
}
