//! A player late on its own (a loaded machine, a debug build): its frames take most of a frame
//! interval to build, so its questions leave late, which is no queue on the link; and the
//! same player on a link that does queue.

use super::*;

/// The time a loaded machine's player takes to build its `n`th frame (the scene's steps, the
/// picture, the encoding), as traced at load 6 for the integration tests' debug player beside
/// a fake kitty: a 10th percentile of 51 ms, a median of 64 ms, a 90th of 92 ms, now and then
/// 320 ms. A fixed sequence with about those quantiles (no clock, no randomness).
fn building(n: u32) -> Duration {
    quantiles(n, 2_246_822_519, &[(100, 40, 51), (500, 51, 64), (900, 64, 92), (990, 92, 192), (1000, 200, 320)])
}

#[test]
fn the_build_times_have_the_traced_quantiles() {
    let mut times: Vec<Duration> = (1..=5000).map(building).collect();
    times.sort();
    let (p10, median, p90) = (times[500], times[2500], times[4500]);
    assert!(p10 >= ms(45) && p10 <= ms(55), "p10 {p10:?}");
    assert!(median >= ms(58) && median <= ms(70), "median {median:?}");
    assert!(p90 >= ms(85) && p90 <= ms(100), "p90 {p90:?}");
}

/// What a late player saw, one entry a frame.
#[derive(Default)]
struct Late {
    /// Seconds since the start, when each frame left.
    at: Vec<f64>,
    /// The rate in effect then.
    rates: Vec<f64>,
    /// Seconds of bytes still to cross the link when each frame left (before it).
    queue: Vec<f64>,
    /// When the rate fell, in seconds.
    falls: Vec<f64>,
}

/// A player that takes [`building`]'s time to build each frame (planned at its start, handed
/// to the writer at its end, the next one planned then) on a link `rtt` away that carries
/// `capacity(t)` bytes a second and has read everything before a question when it answers.
/// Each frame spends what the rate gave it since the last one (at most 64 kB) within the
/// window; answers are
/// stamped on arrival (the reading thread) and handed to the controller before the next frame.
fn late_player(capacity: impl Fn(f64) -> f64, rtt: Duration, seconds: f64) -> Late {
    let t0 = Instant::now() + Duration::from_secs(1);
    let secs = |t: Instant| t.duration_since(t0).as_secs_f64();
    let mut control = LinkControl::new();
    control.known_fast();
    let (mut late, mut sent, mut drained, mut frame_at) = (Late::default(), 0u64, t0, t0);
    let mut answer: Option<Instant> = None;
    let mut last = t0 - Duration::from_secs_f64(1.0 / FPS);
    for n in 1.. {
        if secs(frame_at) >= seconds {
            break;
        }
        if let Some(a) = answer.filter(|&a| a <= frame_at) {
            answer = None;
            if control.answered(a) == Change::Down {
                late.falls.push(secs(a));
            }
        }
        if control.tick(frame_at) == Change::Down {
            late.falls.push(secs(frame_at));
        }
        let rate = control.rate().unwrap_or(MAX_RATE);
        let budget = (rate * frame_at.duration_since(last).as_secs_f64())
            .min(64_000.0)
            .min(control.window_left(frame_at, sent) as f64);
        last = frame_at;
        control.frame_sent(budget as usize, budget as usize);
        sent += budget as u64;
        let out = frame_at + building(n);
        let asks = control.probe_due();
        if asks {
            control.probed(frame_at, sent);
            control.handed_over(out);
        }
        late.at.push(secs(out));
        late.rates.push(rate);
        late.queue.push(drained.saturating_duration_since(out).as_secs_f64());
        drained = drained.max(out) + Duration::from_secs_f64(budget / capacity(secs(out)));
        if asks {
            answer = Some(drained + rtt);
        }
        frame_at = out;
    }
    late
}

#[test]
fn a_player_late_on_its_own_is_not_taken_for_a_queue() {
    // The integration tests' slow kitty beside the test command's other tests, its terminal's
    // own time aside: a pty (2 MB/s, 1 ms) and a player that takes 40-300 ms to build each
    // frame. Timed from the frame's start, each question carried the build's spread into its
    // round trip, read as a queue over the high mark, and the rate fell (to 10 kB/s in CI).
    // Timed from when it left (the door's hand-over to its writer), nothing queues and the rate
    // never falls. Broken on purpose (`handed_over` a no-op): 3 falls at 1 ms, the rate down to
    // 139 kB/s.
    for rtt in [ms(1), ms(20)] {
        let run = late_player(|_| 2_000_000.0, rtt, 20.0);
        let lowest = run.rates.iter().skip(1).copied().fold(f64::MAX, f64::min);
        println!("a late player, 2 MB/s, {rtt:?}: {} falls, lowest rate {lowest:.0} B/s", run.falls.len());
        assert!(run.falls.is_empty(), "{rtt:?}: the rate fell at {:?} s", run.falls);
    }
}

#[test]
fn a_late_player_still_sees_a_queue_on_the_link() {
    // Both at once: the same late player, and the link narrowing from 300 kB/s to 75 kB/s at
    // 5 s (a shared link filling up). The queue that builds then is the link's, and the rate
    // follows it down. Broken on purpose by a rule that forgives more than the player's own
    // time (the build time taken off the queue as well as off the round trip, as a loosened
    // mark would), the queue stood over the high mark's ceiling and the rate at the link's.
    for rtt in [ms(1), ms(20)] {
        let run = late_player(|t| if t >= 5.0 { 75_000.0 } else { 300_000.0 }, rtt, 20.0);
        let first_fall = run.falls.iter().copied().find(|&t| t >= 5.0);
        let after: Vec<usize> = (0..run.at.len()).filter(|&i| run.at[i] >= 8.0).collect();
        let mut queue: Vec<f64> = after.iter().map(|&i| run.queue[i]).collect();
        queue.sort_by(f64::total_cmp);
        let p90 = queue[(queue.len() - 1) * 9 / 10];
        let rate = after.iter().map(|&i| run.rates[i]).sum::<f64>() / after.len() as f64;
        println!(
            "a late player on a link narrowing to 75 kB/s at 5 s, {rtt:?}: first fall at {first_fall:?} s, queue \
             p90 {:.0} ms from 8 s, mean rate {rate:.0} B/s",
            p90 * 1e3
        );
        assert!(first_fall.is_some_and(|t| t < 7.0), "{rtt:?}: no fall within two seconds ({first_fall:?})");
        // Within the high mark's ceiling, and the rate under the link: 16 and 41 ms, 37 and 47
        // kB/s (forgiving the build time as well: 131 and 149 ms, 75 and 77 kB/s).
        let (bound, over) = (QUEUE_HIGH.as_secs_f64(), rate > 75_000.0);
        assert!(p90 <= bound, "{rtt:?}: the queue's p90 is {:.0} ms from 8 s", p90 * 1e3);
        assert!(!over, "{rtt:?}: the rate stayed at {rate:.0} B/s on a 75 kB/s link");
    }
}
