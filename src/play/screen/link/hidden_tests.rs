//! The link controller inside a multiplexer over a stock sshd, on made-up clocks: a path that
//! buffers megabytes out of the player's sight (issue 30).
//!
//! The player writes into tmux's or screen's pane; the multiplexer passes it on at once into
//! sshd's pty; sshd reads the pty as long as the client's SSH window (2 MB) allows and keeps
//! what its socket cannot take in its own channel buffer; the socket holds at most its send
//! buffer (tens of kilobytes with the kernel's autotuning on a short path: 17-31 kB measured in
//! the stock lab); the link drains it at its capacity. The multiplexer answers device
//! attributes itself; the link's question, wrapped for its passthrough, is answered by the
//! terminal once it has read everything before it, or (tmux without `allow-passthrough`, its
//! default) never.
//!
//! Before this issue the player followed the socket's queue (`/proc/net/tcp`) here: fed the
//! socket's view of the same paths (at most the socket's size; an idle connection's for the
//! attached case), that rule ran to 64 MB/s and queued 8.5 s on every 2 Mbit/s path below.

use super::*;

const FPS: f64 = 30.0;

fn ms(n: u64) -> Duration {
    Duration::from_millis(n)
}

/// OpenSSH's client window: sshd reads the pty until this much is unacknowledged, then the
/// multiplexer's writes and the player's block (the player's frames are then dropped).
const SSH_WINDOW: f64 = 2_097_152.0;

/// The path behind the multiplexer.
#[derive(Clone, Copy)]
struct Hidden {
    /// Bytes a second the link carries.
    capacity: f64,
    /// The link's round trip.
    rtt: Duration,
    /// The most the socket holds (in flight and not yet sent); sshd holds the rest.
    socket: f64,
    /// A burst the multiplexer writes by itself (a whole-screen redraw: on attach, on a
    /// resize, after a client that backed up), at this many seconds, of this many bytes.
    redraw: Option<(f64, f64)>,
    /// Whether the terminal's answers to the wrapped question come back (screen; tmux with
    /// `allow-passthrough on`); tmux drops the question by default.
    passthrough: bool,
}

/// What a run saw, one entry a frame.
struct Run {
    at: Vec<f64>,
    rates: Vec<f64>,
    /// Seconds a byte written now waits before the link has carried it (the queue).
    queue: Vec<f64>,
    sent: Vec<u64>,
    control: LinkControl,
}

impl Run {
    fn queue_quantile(&self, from: f64, p: f64) -> f64 {
        let mut q: Vec<f64> = self.at.iter().zip(&self.queue).filter(|(t, _)| **t >= from).map(|(_, q)| *q).collect();
        q.sort_by(f64::total_cmp);
        q[((q.len() - 1) as f64 * p).round() as usize]
    }

    /// The longest queue from `from` seconds on, but for the `skip` seconds from `skip_from`.
    fn worst_queue(&self, from: f64, (skip_from, skip): (f64, f64)) -> f64 {
        let counted = |t: f64| t >= from && !(skip_from..skip_from + skip).contains(&t);
        self.at.iter().zip(&self.queue).filter(|(t, _)| counted(**t)).map(|(_, q)| *q).fold(0.0, f64::max)
    }

    /// The share of the link's capacity carried from `from` seconds to the end.
    fn used(&self, capacity: f64, from: f64) -> f64 {
        let i = self.at.iter().position(|&t| t >= from).unwrap();
        let j = self.at.len() - 1;
        let carried = |k: usize| self.sent[k] as f64 - self.queue[k] * capacity;
        (carried(j) - carried(i)) / (self.at[j] - self.at[i]) / capacity
    }

    /// Bytes sent by `t` seconds.
    fn sent_at(&self, t: f64) -> u64 {
        self.at.iter().rposition(|&s| s <= t).map_or(0, |k| self.sent[k])
    }

    fn highest_rate(&self, from: f64) -> f64 {
        self.at.iter().zip(&self.rates).filter(|(t, _)| **t >= from).map(|(_, r)| *r).fold(0.0, f64::max)
    }
}

/// Runs a busy player (it always wants more than the link) inside `multiplexer` for `seconds`
/// on `path`: frames 30 a second of what the rate allows within the window, the link's
/// question after each frame when one is due; the multiplexer answers the probe's DA1 itself
/// at once, the terminal the wrapped question (if it gets it) a round trip after the link has
/// carried everything before it.
fn simulate(multiplexer: &'static str, path: Hidden, seconds: f64) -> Run {
    let t0 = Instant::now();
    let mut control = LinkControl::on(LinkPath::Multiplexer(multiplexer));
    assert!(control.asks_status(), "{multiplexer}: the question is wrapped");
    control.expect_foreign(t0, 1);
    control.answered(t0 + ms(1));
    let mut answers: std::collections::VecDeque<Instant> = Default::default();
    let (mut at, mut rates, mut queue, mut sent_log) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    // When the link has carried everything written so far (socket and sshd's buffer are one
    // line: sshd refills the socket as soon as it has room).
    let mut drained = t0;
    let mut sent = 0u64;
    let mut redraw = path.redraw;
    let frame = Duration::from_secs_f64(1.0 / FPS);
    let mut now = t0;
    while now < t0 + Duration::from_secs_f64(seconds) {
        let t = now.duration_since(t0).as_secs_f64();
        while answers.front().is_some_and(|&a| a <= now) {
            let a = answers.pop_front().unwrap();
            control.status_answered(a);
            control.tick(a);
        }
        control.tick(now);
        let rate = control.rate().unwrap_or(MAX_RATE);
        let backlog = drained.saturating_duration_since(now).as_secs_f64() * path.capacity;
        let room = (SSH_WINDOW + path.socket - backlog).max(0.0);
        let budget = (rate / FPS).min(control.window_left(now, sent) as f64);
        let bytes = budget.min(room).floor();
        control.frame_sent(bytes as usize, budget as usize);
        sent += bytes as u64;
        drained = drained.max(now) + Duration::from_secs_f64(bytes / path.capacity);
        if let Some((_, size)) = redraw.filter(|&(when, _)| t >= when) {
            drained += Duration::from_secs_f64(size / path.capacity);
            redraw = None;
        }
        if control.probe_due() && (bytes > 0.0 || control.question_wanted(now, sent)) {
            control.probed(now, sent);
            if path.passthrough {
                answers.push_back(drained.max(now) + path.rtt);
            }
        }
        at.push(t);
        rates.push(rate);
        queue.push(drained.saturating_duration_since(now).as_secs_f64());
        sent_log.push(sent);
        now += frame;
    }
    Run { at, rates, queue, sent: sent_log, control }
}

/// The bound: the queue under a round trip and a frame, or the safe rate held; the
/// failure, if any: a round trip (at least [`QUEUE_HIGH_MIN`], under which a queue is the
/// player's own loop), a frame's time and the frame's own bytes crossing the link; never a
/// second, but for a redraw's own bytes (the multiplexer's, not the player's: 300 kB are 1.2 s
/// at 2 Mbit/s) and a second after them.
fn holds(run: &Run, path: &Hidden, what: &str) -> Option<String> {
    let p90 = run.queue_quantile(5.0, 0.9);
    let redraw = path.redraw.map_or((0.0, 0.0), |(at, size)| (at, size / path.capacity + 1.0));
    let worst = run.worst_queue(5.0, redraw);
    let highest = run.highest_rate(5.0);
    let bound = path.rtt.max(QUEUE_HIGH_MIN).as_secs_f64() + 2.0 / FPS;
    println!(
        "{what}: queue p90 {:.0} ms, worst {:.0} ms (bound {:.0} ms), highest rate {:.0} B/s, sent {} B",
        p90 * 1e3,
        worst * 1e3,
        bound * 1e3,
        highest,
        run.sent.last().unwrap()
    );
    if !(p90 <= bound || highest <= SAFE_RATE) {
        return Some(format!(
            "{what}: the queue's p90 is {:.0} ms (bound {:.0} ms) at rates up to {highest:.0} B/s",
            p90 * 1e3,
            bound * 1e3
        ));
    }
    (worst >= 1.0).then(|| format!("{what}: a queue of {worst:.1} s"))
}

fn stock(rtt: Duration) -> Hidden {
    Hidden { capacity: 250_000.0, rtt, socket: 24_000.0, redraw: None, passthrough: true }
}

/// The links of the targets.
fn links() -> [(&'static str, Hidden); 3] {
    [
        ("2 Mbit/s, 20 ms", stock(ms(20))),
        ("2 Mbit/s, 150 ms", stock(ms(150))),
        ("256 kbit/s, 300 ms", Hidden { capacity: 32_000.0, ..stock(ms(300)) }),
    ]
}

#[test]
fn a_multiplexer_over_a_stock_sshd_never_queues_behind_sshd_s_buffer() {
    let mut failures = Vec::new();
    for (what, path) in links().into_iter().chain([(
        "2 Mbit/s, 20 ms, a redraw of 300 kB at 10 s",
        Hidden { redraw: Some((10.0, 300_000.0)), ..stock(ms(20)) },
    )]) {
        for multiplexer in ["tmux", "screen"] {
            let what = format!("{multiplexer}, {what}");
            let run = simulate(multiplexer, path, 30.0);
            failures.extend(holds(&run, &path, &what));
            // The link is measured through the terminal: it is filled, and nothing says otherwise.
            let used = run.used(path.capacity, 10.0);
            if used < 0.8 {
                failures.push(format!("{what}: only {:.0} % of the link used", used * 100.0));
            }
            if run.control.hint().is_some() {
                failures.push(format!("{what}: a hint on a measured link: {:?}", run.control.hint()));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn tmux_without_passthrough_holds_the_safe_rate_and_says_how_to_lift_it() {
    // The command: tmux drops the wrapped question, and nothing else sees the path.
    for (what, path) in links() {
        let path = Hidden { passthrough: false, ..path };
        let run = simulate("tmux", path, 30.0);
        assert_eq!(holds(&run, &path, what), None);
        let highest = run.highest_rate(0.0);
        assert!(highest <= SAFE_RATE, "{what}: the rate reached {highest:.0} B/s");
        let hint = run.control.hint().unwrap_or_default();
        assert!(hint.contains("allow-passthrough") && hint.contains("--bandwidth"), "{what}: {hint:?}");
        // Never frozen: every half second some bytes go out.
        for half in 1..60 {
            let (from, to) = (run.sent_at(half as f64 / 2.0 - 0.5), run.sent_at(half as f64 / 2.0));
            assert!(to > from, "{what}: nothing sent in the half second before {} s", half as f64 / 2.0);
        }
    }
}
