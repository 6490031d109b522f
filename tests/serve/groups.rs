//! Encode once per group, through real sessions: players of one size get the same bytes, and
//! one who opens the help draws alone until it closes it.

use std::collections::HashSet;
use std::time::{Duration, Instant};

use crate::common::*;

/// The frames in `raw` (each from its synchronized-output start to its end).
fn frames(raw: &[u8]) -> Vec<Vec<u8>> {
    let end = tidepool::testing::SYNC_END;
    let mut out = Vec::new();
    let mut rest = raw;
    while let Some(start) = rest.windows(SYNC_BEGIN.len()).position(|w| w == SYNC_BEGIN) {
        let Some(len) = rest[start..].windows(end.len()).position(|w| w == end) else { break };
        out.push(rest[start..start + len + end.len()].to_vec());
        rest = &rest[start + len + end.len()..];
    }
    out
}

/// Reads `t` for `time`.
async fn read_for(t: &mut Term, time: Duration) {
    let until = Instant::now() + time;
    t.read_until(|_| Instant::now() >= until).await;
}

/// Reads all three for `time`, round and round, so none of them stalls.
async fn read_all(ts: &mut [&mut Term], time: Duration) {
    let until = Instant::now() + time;
    while Instant::now() < until {
        for t in ts.iter_mut() {
            read_for(t, Duration::from_millis(30)).await;
        }
    }
}

#[tokio::test]
async fn players_of_one_size_get_byte_identical_frames_and_one_who_opens_help_draws_alone_until_it_closes_it() {
    let s = Server::start(&["--client-bandwidth", "unlimited", "--rain", "0.2", "--breeze", "0", "--fps", "15"]);
    let (a, b, c) = (connect_none(s.port).await, connect_none(s.port).await, connect_none(s.port).await);
    let mut ta = Term::new(open_shell(&a, "xterm-256color", 80, 24).await, 80, 24);
    let mut tb = Term::new(open_shell(&b, "xterm-256color", 80, 24).await, 80, 24);
    let mut tc = Term::new(open_shell(&c, "xterm-256color", 80, 24).await, 80, 24);
    for t in [&mut ta, &mut tb, &mut tc] {
        t.read_until_status("3 playing").await;
    }
    // The greeting (a message of each player's own) stays ten seconds.
    read_all(&mut [&mut ta, &mut tb, &mut tc], Duration::from_secs(11)).await;
    let marks = [ta.raw.len(), tb.raw.len(), tc.raw.len()];
    read_all(&mut [&mut ta, &mut tb, &mut tc], Duration::from_secs(2)).await;
    let of_a: HashSet<Vec<u8>> = frames(&ta.raw[marks[0]..]).into_iter().collect();
    let of_b = frames(&tb.raw[marks[1]..]);
    let of_c = frames(&tc.raw[marks[2]..]);
    let common = of_b.iter().filter(|f| of_a.contains(*f)).count();
    eprintln!("{} frames of A, {} of B, {common} of B's byte for byte among A's", of_a.len(), of_b.len());
    assert!(
        of_b.len() >= 10 && common * 10 >= of_b.len() * 8,
        "most of B's frames are A's: {common} of {}",
        of_b.len()
    );
    let common = of_c.iter().filter(|f| of_a.contains(*f)).count();
    assert!(of_c.len() >= 10 && common * 10 >= of_c.len() * 8, "and C's: {common} of {} are A's", of_c.len());
    // C opens the help: its frames are its own.
    tc.ch.data(&b"?"[..]).await.unwrap();
    let mark_a = ta.raw.len();
    let mark_c = tc.raw.len();
    tc.read_until(|t| (0..24).any(|y| t.screen.row_text(y).contains("tidepool keys"))).await;
    read_all(&mut [&mut ta, &mut tb, &mut tc], Duration::from_secs(1)).await;
    let of_a: HashSet<Vec<u8>> = frames(&ta.raw[mark_a..]).into_iter().collect();
    let with_help = frames(&tc.raw[mark_c..]);
    assert!(
        !with_help.is_empty() && with_help.iter().all(|f| !of_a.contains(f)),
        "none of C's frames is A's while its help is open"
    );
    // C closes it: after a frame or two of its own, the group's frames again.
    tc.ch.data(&b"?"[..]).await.unwrap();
    tc.read_until(|t| !(0..24).any(|y| t.screen.row_text(y).contains("tidepool keys"))).await;
    read_all(&mut [&mut ta, &mut tb, &mut tc], Duration::from_millis(500)).await;
    let (mark_a, mark_c) = (ta.raw.len(), tc.raw.len());
    read_all(&mut [&mut ta, &mut tb, &mut tc], Duration::from_secs(2)).await;
    let of_a: HashSet<Vec<u8>> = frames(&ta.raw[mark_a..]).into_iter().collect();
    let of_c = frames(&tc.raw[mark_c..]);
    let back = of_c.iter().filter(|f| of_a.contains(*f)).count();
    eprintln!("after the help: {back} of C's {} frames are A's", of_c.len());
    assert!(of_c.len() >= 10 && back * 10 >= of_c.len() * 8, "C is back in step: {back} of {}", of_c.len());
    for t in [&mut ta, &mut tb, &mut tc] {
        t.ch.data(&b"q"[..]).await.unwrap();
        let _ = read_to_close(&mut t.ch).await;
    }
    let (_, log) = s.stop(15);
    let summary = log.iter().find(|l| l.contains("stopped in")).unwrap();
    eprintln!("{summary}");
    for line in log.iter().filter(|l| l.contains("left (quit)")) {
        eprintln!("{line}");
    }
    let number_before = |line: &str, after: &str| -> u64 {
        let before = line.split(after).next().unwrap();
        before.split_whitespace().last().unwrap().trim_start_matches('(').parse().unwrap()
    };
    let taken: Vec<u64> =
        log.iter().filter(|l| l.contains("left (quit)")).map(|l| number_before(l, " from its group")).collect();
    let encoded = number_before(summary, " group frames encoded");
    // The group encoded a frame for every one published (its members had greetings of their
    // own for the first ten seconds); once in step, each frame went to all three: more frames
    // went out from the group than it ever encoded. Identical bytes alone would not show it
    // (three screens encoding alone make the same bytes).
    assert!(taken.iter().sum::<u64>() > encoded, "{taken:?} frames sent from {encoded} group frames encoded");
    assert!(taken.iter().filter(|&&n| n >= 60).count() == 3, "every player took the group's frames: {taken:?}");
}
