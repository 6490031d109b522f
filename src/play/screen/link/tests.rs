//! The link controller on made-up clocks: a simulated deep-buffered link (SSH's buffers) with
//! a round trip, terminals that answer, answer locally or never, the probe's late answer.

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
    /// Two answers in every four come this much later than the link makes them (a terminal
    /// busy drawing: kitty under a software renderer).
    late_pairs: Option<Duration>,
    /// The share of each frame's budget the sender spends (a picture stream on a small rung
    /// spends part of it; 1: all it may).
    spend_share: f64,
    /// The terminal's own time to answer the `n`th question, on top of the link (a terminal
    /// that draws slowly: [`kitty_0_26`]).
    answer_time: Option<fn(u32) -> Duration>,
    /// The share of the link's speed the terminal reads at, `t` seconds in (a terminal that
    /// falls behind now and then: [`slow_reader`]); `None`: the link's speed.
    reads: Option<fn(f64) -> f64>,
    /// From and to these seconds the terminal reads nothing (a paused terminal, a stalled
    /// link): what would drain then waits for the end.
    pause: Option<(f64, f64)>,
    /// Whether the terminal reads nothing while it answers (its own time to answer is a
    /// stall of its reading, as in a terminal that draws and answers on one thread).
    answering_blocks_reads: bool,
    /// The player's wake-ups are late by [`loaded`]'s sequence of this seed (a loaded
    /// machine: its timer fires late, an answer waits in the pty until the player runs).
    player_late: Option<u32>,
    /// The link carries this many bytes at once after an idle spell (a token bucket's burst:
    /// `tc ... tbf burst 32kbit` is 4 kB), then its rate.
    burst: f64,
    /// The first answers come this many ms late besides, in order (a path whose answers are
    /// slow at first: serve's first round trips over the stock lab read 658 and 428 ms on a
    /// 303 ms link).
    late_first: &'static [u64],
}

impl Link {
    fn far(capacity: f64, rtt: Duration) -> Link {
        Link {
            capacity,
            rtt,
            answers: Answers::FarEnd,
            probe_lead: None,
            probe_answered: true,
            late_pairs: None,
            spend_share: 1.0,
            answer_time: None,
            reads: None,
            pause: None,
            answering_blocks_reads: false,
            player_late: None,
            burst: 0.0,
            late_first: &[],
        }
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
        let mut q: Vec<f64> = self.at.iter().zip(&self.queue).filter(|(t, _)| **t >= from).map(|(_, q)| *q).collect();
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
fn simulate(path: LinkPath, link: Link, seconds: f64, demand: impl Fn(f64) -> f64) -> Run {
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
    let mut asked = 0u32;
    let mut wakes = 0u32;
    let mut late = || {
        wakes += 1;
        link.player_late.map_or(Duration::ZERO, |seed| loaded(seed, wakes))
    };
    let mut last_read = t0;
    // The burst the link may carry at once (a full bucket at the start).
    let (mut tokens, mut counted_to) = (link.burst, t0);
    let end = at(seconds);
    while next_frame < end {
        let frame_at = (next_frame + late()).max(last_read);
        // Answers due before the frame, each read when the player runs.
        while answers.front().is_some_and(|&a| a <= frame_at) {
            let a = answers.pop_front().unwrap();
            let a = (a + late()).clamp(last_read, frame_at);
            last_read = a;
            control.answered(a);
            if let Some(rtt) = control.last_rtt()
                && run.rtts.last() != Some(&rtt)
            {
                run.rtts.push(rtt);
            }
            control.tick(a);
        }
        let now = frame_at.max(last_read);
        last_read = now;
        control.tick(now);
        let t = now.duration_since(t0).as_secs_f64();
        let rate = control.rate().unwrap_or(MAX_RATE);
        let budget = (rate / FPS).min(control.window_left(now, sent) as f64);
        let bytes = (budget * link.spend_share).min(demand(t)).floor();
        control.frame_sent(bytes as usize, budget as usize);
        sent += bytes as u64;
        let speed = link.capacity * link.reads.map_or(1.0, |share| share(t));
        let start = drained.max(now);
        // The bucket fills while the link is idle.
        let idle_from = drained.max(counted_to);
        counted_to = now;
        tokens = (tokens + now.saturating_duration_since(idle_from).as_secs_f64() * speed).min(link.burst);
        let at_once = tokens.min(bytes);
        tokens -= at_once;
        drained = start + Duration::from_secs_f64((bytes - at_once) / speed);
        if let Some((from, to)) = link.pause.map(|(from, to)| (at(from), at(to)))
            && drained > from
            && start < to
        {
            drained += to - start.max(from);
        }
        if control.probe_due() && (bytes > 0.0 || control.question_wanted(now, sent)) {
            control.probed(now, sent);
            asked += 1;
            let late = link.late_pairs.filter(|_| asked % 4 < 2).unwrap_or_default()
                + link.answer_time.map_or(Duration::ZERO, |time| time(asked))
                + link.late_first.get(asked as usize - 1).map_or(Duration::ZERO, |&n| ms(n));
            let reached = drained;
            if link.answering_blocks_reads {
                drained += late;
            }
            let answer = match link.answers {
                Answers::FarEnd => Some(reached + link.rtt + late),
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
fn the_link_is_filled_and_its_queue_stays_under_a_round_trip_at_most_100_ms_and_a_frame() {
    // 2 Mbit/s at 20 and 150 ms, 256 kbit/s at 300 ms: what the real-link harness runs.
    for (capacity, rtt) in [(250_000.0, ms(20)), (250_000.0, ms(150)), (32_000.0, ms(300))] {
        let run = simulate(LinkPath::Direct, Link::far(capacity, rtt), 40.0, busy);
        let used = run.throughput(capacity, 20.0, 40.0) / capacity;
        // A round trip but never more than QUEUE_HIGH (so a key shows within the round trip
        // and 150 ms), one frame's time, and the frame's own bytes crossing the link.
        let bound = rtt.min(QUEUE_HIGH).as_secs_f64() + 2.0 / FPS;
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
fn a_late_probe_answer_does_not_shift_the_pairing() {
    // The probe's DA1 went out 150 ms before the player started and gave up on its
    // answer; over a 300 ms round trip the answer comes 150 ms into the player's life. Were
    // it paired with the player's first question, that round trip would read 150 ms, and
    // every later one a question too early.
    let link = Link { probe_lead: Some(ms(150)), ..Link::far(250_000.0, ms(300)) };
    let run = simulate(LinkPath::Direct, link, 10.0, busy);
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
    let run = simulate(LinkPath::Direct, link, 20.0, busy);
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
    let run = simulate(LinkPath::Direct, link, 20.0, busy);
    never_frozen(&run);
    assert_eq!(run.link.as_ref().unwrap().dropped_answers().0, 1, "the probe's answer came and was dropped");
    let late = run.mean_rate(SILENCE.as_secs_f64() + 1.1);
    assert!(late <= SAFE_RATE, "the rate is {late:.0} B/s");
    assert!(*run.queue.last().unwrap() < 0.5);
}

#[test]
fn a_multiplexer_over_ssh_or_mosh_holds_the_safe_rate_where_local_answers_would_run_away() {
    // zellij (or mosh-server) answers at once from this side; its output crosses a 256
    // kbit/s link unpaced. Taken for the far end, the answers would grow the rate without
    // limit and queue seconds in SSH's buffers; on the multiplexer path it stays safe.
    let link = Link { answers: Answers::Local, ..Link::far(32_000.0, ms(300)) };
    let fooled = simulate(LinkPath::Direct, link, 10.0, busy);
    assert!(*fooled.queue.last().unwrap() > 5.0, "the direct controller is fooled by local answers");
    for path in [LinkPath::Multiplexer("zellij"), LinkPath::Mosh] {
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
    assert_eq!(LinkPath::detect(env(&ssh), ["bash", "sshd"]), LinkPath::Direct);
    assert_eq!(
        LinkPath::detect(env(&[("TMUX", "/tmp/tmux-0/default,1,0")]), ["bash", "tmux: server"]),
        LinkPath::Direct,
        "tmux on this screen"
    );
    let tmux_over_ssh = [("TMUX", "/tmp/tmux-0/default,1,0"), ("SSH_CONNECTION", "a 1 b 22")];
    assert_eq!(LinkPath::detect(env(&tmux_over_ssh), ["bash"]), LinkPath::Multiplexer("tmux"));
    assert_eq!(
        LinkPath::detect(env(&[("STY", "123.pts-0.host"), ("SSH_TTY", "/dev/pts/0")]), []),
        LinkPath::Multiplexer("screen")
    );
    assert_eq!(
        LinkPath::detect(env(&[("TMUX", ""), ("SSH_CLIENT", "a 1 22")]), []),
        LinkPath::Direct,
        "an empty TMUX is none"
    );
    let mosh_env = [("SSH_CONNECTION", "a 1 b 22"), ("NCURSES_NO_UTF8_ACS", "1")];
    assert_eq!(LinkPath::detect(env(&mosh_env), ["bash", "mosh-server"]), LinkPath::Mosh);
    assert_eq!(LinkPath::detect(env(&mosh_env), ["mosh-server"]), LinkPath::Mosh);
}

#[test]
fn an_overdue_question_keeps_its_place_for_its_late_answer() {
    let t0 = Instant::now();
    let mut link = LinkControl::new();
    link.known_fast();
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
    assert!(link.probe_due() && link.question_wanted(t0 + ms(20), 30_000));
    link.probed(t0 + ms(21), 30_000);
    assert!(!link.question_wanted(t0 + ms(21), 30_000));
    link.answered(t0 + ms(40));
    // All answered for: the terminal's own time is measured first (frames held, a bare
    // question), then the window opens.
    assert_eq!(link.window_left(t0 + ms(40), 30_000), 0, "held for the bare question");
    assert!(link.question_wanted(t0 + ms(41), 30_000));
    link.probed(t0 + ms(41), 30_000);
    assert!(link.window_left(t0 + ms(41), 30_000) >= MIN_WINDOW as usize, "the bare question out: open");
    link.answered(t0 + ms(45));
    assert!(link.window_left(t0 + ms(45), 30_000) >= MIN_WINDOW as usize, "all answered for: open");
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
    // (The status lines leave their budget unspent: they neither shrink the window nor grow
    // the rate that bounds it.)
    let t0 = Instant::now();
    let mut link = LinkControl::new();
    let mut sent = 24_000;
    link.frame_sent(24_000, 24_000);
    link.probed(t0, sent);
    link.answered(t0 + ms(2));
    let after_the_frame = link.window(t0 + ms(2));
    for i in 1..=40 {
        sent += 100;
        let at = t0 + ms(33 * i);
        link.frame_sent(100, 13_000);
        link.probed(at, sent);
        link.answered(at + ms(1));
    }
    let now = t0 + ms(33 * 41);
    // (A shorter base round trip, 1 ms instead of 2, trims it by a hair.)
    // (The window itself: a hold for a bare question may be under way.)
    let kept = link.window(now) as f64;
    assert!(kept >= 0.95 * after_the_frame as f64 && kept >= 100_000.0, "{kept} after {after_the_frame}");
}

#[test]
fn a_terminal_slow_on_its_own_that_stalls_with_little_in_flight_is_busy_not_congested() {
    // Kitty 0.26 under llvmpipe setting up its first pictures stalled for more than a second
    // now and then: read as lost questions, each stall lowered the rate, and `auto` fell to
    // cells at 9.1 kB/s on a 250 kB/s link (1 real run in 3).
    let t0 = Instant::now();
    let mut link = LinkControl::new();
    link.probed(t0, 30_000);
    link.answered(t0 + ms(120));
    let rate = link.rate();
    link.probed(t0 + ms(130), 31_000);
    assert_eq!(link.tick(t0 + ms(130) + PROBE_TIMEOUT + ms(1)), Change::Hold, "a stall, not a loss");
    assert_eq!(link.rate(), rate);
    assert!(link.probe_due(), "the overdue question is replaced all the same");
}

#[test]
fn a_local_terminal_grows_to_no_limit() {
    let run = simulate(LinkPath::Direct, Link::far(1e9, ms(0)), 3.0, busy);
    assert_eq!(*run.rates.last().unwrap(), MAX_RATE, "a fast link ends unlimited");
}

#[test]
fn lost_answers_slow_down_and_silence_gets_the_safe_rate() {
    let t0 = Instant::now();
    let mut link = LinkControl::new();
    link.probed(t0, 100);
    assert_eq!(link.tick(t0 + SILENCE - ms(1)), Change::Hold, "a first answer may take a while");
    assert!(link.rate().is_none_or(|r| r >= START_RATE), "{:?}", link.rate());
    link.answered(t0 + ms(5));
    link.known_fast();
    link.probed(t0 + ms(10), 200);
    assert_eq!(link.tick(t0 + ms(10) + PROBE_TIMEOUT + ms(1)), Change::Down);
    assert!(link.rate().unwrap() < START_RATE * INCREASE);
    assert!(link.probe_due(), "the overdue question is replaced");
    assert_eq!(link.tick(t0 + ms(10) + SILENCE + ms(1)), Change::Down, "then silence");
    assert!(link.rate().unwrap() <= SAFE_RATE);
    assert_eq!(LinkControl::new().answered(t0), Change::Hold, "an answer nobody asked for");
}

#[test]
fn a_sender_that_leaves_its_budget_unspent_is_not_taken_for_the_link() {
    // A 2 Mbit/s link of 20 ms and a terminal that answers two questions in four 45 ms late
    // (a software-rendered kitty drawing), while the sender spends a third of each frame's
    // budget (its pictures on a small rung, as the stream picks them from the rate). The late
    // answers are the terminal's, not a queue: the rate must not follow the sender down (it
    // did: 5.4 kB/s, and `auto` left kitty for cells on a link five times above the crossover).
    let link = Link { late_pairs: Some(ms(45)), spend_share: 0.33, ..Link::far(250_000.0, ms(20)) };
    let run = simulate(LinkPath::Direct, link, 10.0, busy);
    let mean = run.mean_rate(3.0);
    assert!(mean > 100_000.0, "the rate followed the sender down: {mean:.0} B/s");
    // The same link filled by a sender that spends its whole budget still finds the link.
    let full = simulate(LinkPath::Direct, Link::far(250_000.0, ms(20)), 10.0, busy);
    let got = full.throughput(250_000.0, 3.0, 10.0);
    assert!(got > 0.8 * 250_000.0, "{got:.0} B/s");
}

/// Debian 12's kitty 0.26 drawing with llvmpipe on a loaded machine, as recorded both ways
/// (`script -B` between kitty and ssh, 4970 answers): its own time from a question reaching it
/// to the answer leaving it has a median of 18 ms, a 90th percentile of 98 ms, and now and then
/// most of a second. A fixed sequence with those quantiles (no clock, no randomness).
fn kitty_0_26(n: u32) -> Duration {
    quantiles(n, 2_654_435_761, &[(500, 2, 18), (900, 18, 98), (990, 98, 398), (1000, 400, 1080)])
}

/// The `n`th of a fixed sequence (no clock, no randomness) with the quantiles of `pieces`: a
/// multiplicative hash by `spread` takes `n` to a thousandth `u`, and each piece `(end, from,
/// to)` maps the thousandths from the previous piece's end up to its own linearly from `from`
/// to `to` ms.
fn quantiles(n: u32, spread: u32, pieces: &[(u64, u64, u64)]) -> Duration {
    let u = u64::from((n.wrapping_mul(spread) >> 8) % 1000);
    let mut start = 0;
    for &(end, from, to) in pieces {
        if u < end {
            return ms(from + (u - start) * (to - from) / (end - start));
        }
        start = end;
    }
    unreachable!("the pieces end at 1000")
}

/// A terminal that reads at half the link's speed for 1.5 s in every 4 (a Python
/// terminal on a loaded machine, as the link harness's is; a sixel decoder in the reading
/// thread): it answers late because it is still reading, which is a queue.
fn slow_reader(t: f64) -> f64 {
    if t % 4.0 >= 2.5 { 0.5 } else { 1.0 }
}

mod late_player;
mod long_links;
mod slow_terminals;
mod stalls;
mod start;

/// A loaded machine's lateness of the player's `n`th wake-up (its timer, or its read of an
/// answer), one fixed sequence per `seed`: median 4 ms, 90th percentile 40 ms, now and then
/// 300 ms (no clock, no randomness).
fn loaded(seed: u32, n: u32) -> Duration {
    let n = n.wrapping_add(seed.wrapping_mul(104_729));
    quantiles(n, 2_246_822_519, &[(500, 0, 4), (900, 4, 40), (990, 40, 200), (1000, 200, 300)])
}
