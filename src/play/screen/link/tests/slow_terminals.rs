//! Terminals slow on their own (kitty 0.26 drawing in software), terminals slow to read, and a
//! loaded machine's late wake-ups: none of them is a link that slowed, and a queue the
//! terminal builds by reading slowly is one.

use super::*;

#[test]
fn the_kitty_answer_times_have_the_recorded_quantiles() {
    let mut times: Vec<Duration> = (1..=5000).map(kitty_0_26).collect();
    times.sort();
    let (median, p90) = (times[2500], times[4500]);
    assert!(median >= ms(14) && median <= ms(22), "median {median:?}");
    assert!(p90 >= ms(90) && p90 <= ms(110), "p90 {p90:?}");
}

#[test]
fn a_terminal_slow_to_answer_is_not_taken_for_a_queue() {
    // The stock 2 Mbit/s link with no added delay and kitty 0.26 answering in its own time:
    // the rate fell to the 2 kB/s floor within 5 s (every real kitty run, round 3), the
    // picture black or half painted for seconds, then cells in palette colours.
    for rtt in [ms(2), ms(20)] {
        let link = Link { answer_time: Some(kitty_0_26), ..Link::far(250_000.0, rtt) };
        let run = simulate(LinkPath::Direct, link, 30.0, busy);
        let lowest =
            run.at.iter().zip(&run.rates).filter(|(t, _)| **t >= 1.0).map(|(_, r)| *r).fold(f64::MAX, f64::min);
        let used = run.throughput(250_000.0, 5.0, 30.0) / 250_000.0;
        let p90 = run.queue_quantile(5.0, 0.9);
        println!(
            "kitty 0.26, {rtt:?}: lowest rate {lowest:.0} B/s, {:.0} % of the link, queue p90 {:.0} ms",
            used * 100.0,
            p90 * 1e3
        );
        assert!(lowest >= 0.25 * 250_000.0, "{rtt:?}: the rate fell to {lowest:.0} B/s");
        // (1 % before the terminal's own time was told from the queue; 81 % at 2 ms and 77 %
        // at 20 ms when it was inferred from every answer the bytes could not explain; 86 %
        // and 74 % since bare questions measure it and decide whether to infer it at all.)
        assert!(used >= 0.7, "{rtt:?}: only {:.0} % of the link used", used * 100.0);
        // The queue may stand as long as the terminal's own slow answers (they hide it): the
        // high mark, at most OWN_MAX of them, and the frames.
        let bound = QUEUE_HIGH + super::answer_time::OWN_MAX;
        assert!(p90 <= bound.as_secs_f64() + 2.0 / FPS, "{rtt:?}: the queue's p90 is {:.0} ms", p90 * 1e3);
    }
}

#[test]
fn a_terminal_slow_to_read_is_a_queue_not_its_own_time() {
    // Round 4 learned the terminal's own time from answers the bytes in flight (timed at the
    // link's capacity) could not explain: this terminal's backlog was learned as its own time,
    // and the link harness's key-to-effect p90 went from 16-104 ms to 169-374 ms.
    for rtt in [ms(2), ms(20)] {
        let link = Link { reads: Some(slow_reader), ..Link::far(250_000.0, rtt) };
        let run = simulate(LinkPath::Direct, link, 40.0, busy);
        let p90 = run.queue_quantile(5.0, 0.9);
        let own = run.link.as_ref().unwrap().answer_time.slow();
        println!("a slow reader, {rtt:?}: queue p90 {:.0} ms, the terminal's slow answers learned {own:?}", p90 * 1e3);
        assert!(own <= ms(5), "{rtt:?}: the backlog was learned as the terminal's own time ({own:?})");
        let bound = 0.2;
        assert!(p90 <= bound, "{rtt:?}: the queue's p90 is {:.0} ms, over {:.0} ms", p90 * 1e3, bound * 1e3);
    }
}

#[test]
fn a_loaded_machine_is_not_taken_for_a_slowing_link() {
    // The integration tests' slow kitty on CI's loaded machine (load 7 and more): a pty read
    // by a terminal that reads nothing while it answers in kitty 0.26's time, and the
    // player's wake-ups late. A late answer read as a queue lowered the rate to a share of
    // what the terminal took, which the rate itself had set, and the window to that take:
    // each late read took the rate lower, to the 2 kB/s floor here (17.8 kB/s in CI, against
    // the test's 20). Six sequences of lateness on three links.
    let mut failed = Vec::new();
    for (capacity, rtt) in [(300_000.0, ms(1)), (150_000.0, ms(30)), (50_000.0, ms(30))] {
        for seed in 0..6 {
            let link = Link {
                answer_time: Some(kitty_0_26),
                answering_blocks_reads: true,
                player_late: Some(seed),
                ..Link::far(capacity, rtt)
            };
            let run = simulate(LinkPath::Direct, link, 30.0, busy);
            let after: Vec<f64> = run.at.iter().zip(&run.rates).filter(|(t, _)| **t >= 2.0).map(|(_, r)| *r).collect();
            let low = after.iter().filter(|&&r| r < 0.1 * capacity).count() as f64 / after.len() as f64;
            let lowest = after.iter().copied().fold(f64::MAX, f64::min);
            let read = run.throughput(capacity, 2.0, 30.0);
            println!(
                "{capacity:.0} B/s, {rtt:?}, lateness {seed}: lowest rate {lowest:.0} B/s, under a tenth of the link \
                 {:.1} % of the time, the terminal read {read:.0} B/s",
                low * 100.0
            );
            // Under a tenth of the link for a moment, never for long: before, two of the slow
            // link's runs sat there (at the 2 kB/s floor, where kitty's pictures stop) 63 and
            // 64 % of the time, and one of the fast link's 16 %; now at most 4.4 %.
            if low > 0.05 {
                failed.push(format!(
                    "{capacity} B/s {rtt:?} lateness {seed}: under a tenth of the link {:.0} % of the time (lowest \
                     {lowest:.0} B/s)",
                    low * 100.0
                ));
            }
        }
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

/// Debian's kitty 0.26 drawing through Mesa's softpipe on two busy cores: a drawing takes most
/// of a second and it answers between drawings, 0.7-1.3 s after a question reached it, now and
/// then at once (two questions read in one drawing are answered together: about two answers in
/// five came within 150 ms in the tap's log). A fixed sequence with about those times.
fn softpipe(n: u32) -> Duration {
    quantiles(n, 2_654_435_761, &[(400, 20, 150), (1000, 700, 1300)])
}

#[test]
fn a_terminal_that_takes_a_second_to_answer_keeps_the_window_it_was_given() {
    // Real kitty through softpipe over the stock 2 Mbit/s link with 20 ms (the link harness):
    // it read whatever came at once and answered a second later with as little as 237 bytes
    // before the question. Each answer's take was what the window had let through in that
    // second, a standing "queue" took the capacity down to it, the window followed, and the
    // next take was smaller: the rate at the 2 kB/s floor within 8 s, keys' status lines
    // held for seconds. A take the window held back never lowers the capacity now, so the
    // rate stays at a quarter of the link seen (a late answer the bytes cannot explain).
    // Before (the window's takes lowering the capacity), at 2 ms: lowest rate 7.8 kB/s, the
    // terminal read 3.2 kB/s, the capacity ended at 2.1 kB/s; now 25 kB/s, 13 and 17 kB/s.
    for rtt in [ms(2), ms(20)] {
        let link = Link { answer_time: Some(softpipe), ..Link::far(250_000.0, rtt) };
        let run = simulate(LinkPath::Direct, link, 30.0, busy);
        let after: Vec<f64> = run.at.iter().zip(&run.rates).filter(|(t, _)| **t >= 5.0).map(|(_, r)| *r).collect();
        let lowest = after.iter().copied().fold(f64::MAX, f64::min);
        let read = run.throughput(250_000.0, 5.0, 30.0);
        let capacity = run.link.as_ref().and_then(|l| l.capacity).unwrap_or(0.0);
        println!(
            "{rtt:?}: lowest rate {lowest:.0} B/s, the terminal read {read:.0} B/s, capacity at the end {capacity:.0} B/s"
        );
        assert!(lowest >= 20_000.0, "{rtt:?}: the rate fell to {lowest:.0} B/s on a 250 kB/s link");
        assert!(read >= 8_000.0, "{rtt:?}: the terminal read only {read:.0} B/s");
    }
}
