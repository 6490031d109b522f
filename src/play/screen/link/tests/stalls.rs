//! A terminal that stops reading for a while, or a link that stalls: what waits for it when it
//! reads again.

use super::*;

/// The seconds of bytes waiting when a pause of `from..to` ends, on `capacity` B/s `rtt` away
/// with frames of `frame` bytes at most, and the bytes sent in the pause.
fn queue_after_pause(capacity: f64, rtt: Duration, (from, to): (f64, f64), frame: f64) -> (f64, u64) {
    let link = Link { pause: Some((from, to)), ..Link::far(capacity, rtt) };
    let run = simulate(LinkPath::Direct, link, to + 2.0, |_| frame);
    let i = run.at.iter().position(|&t| t >= to).unwrap();
    let sent_in_pause = run.sent[i] - run.sent[run.at.iter().position(|&t| t >= from).unwrap()];
    println!(
        "{capacity:.0} B/s, {rtt:?}, frames of {frame:.0} B, paused {from}-{to} s: {:.0} ms queued at the end, \
         {sent_in_pause} B sent in the pause",
        run.queue[i] * 1e3
    );
    (run.queue[i], sent_in_pause)
}

#[test]
fn a_pause_leaves_at_most_the_windows_time_of_frames_to_draw() {
    // A 2 Mbit/s link that stalls for 3 s (a Wi-Fi hiccup) with busy water, and a local
    // terminal paused for 4 s with 7 kB frames (160x48 rain). When the pause ends, what waits
    // is at most the window's time (two round trips with their queue, and a frame) on the
    // link, never the seconds the pause lasted: before, an overdue question reopened the whole
    // window each second (0.71 and 1.16 s queued at 20 and 150 ms), and on the fast link the
    // bytes' window let 0.63 MB (3 s of frames) go into the pause.
    let failed = [
        (250_000.0, ms(20), (10.0, 13.0), f64::INFINITY),
        (250_000.0, ms(150), (10.0, 13.0), f64::INFINITY),
        (5_000_000.0, ms(1), (10.0, 14.0), 7_000.0),
    ]
    .map(|(capacity, rtt, pause, frame)| {
        let (waiting, sent) = queue_after_pause(capacity, rtt, pause, frame);
        let window_time = 2.0 * (rtt + WINDOW_QUEUE).as_secs_f64() + FRAME_ALLOWANCE.as_secs_f64();
        let bound = window_time + 1.0 / FPS;
        // In frames: the window's time of them, the safe rate once the terminal is found
        // silent, and one more (on a fast link the queue in seconds says little: 0.6 MB of
        // stale frames drain in 0.1 s, but they are drawn).
        let frames =
            frame * FPS * window_time + SAFE_RATE * (pause.1 - pause.0 - SILENCE.as_secs_f64()).max(0.0) + frame;
        if waiting > bound {
            Err(format!(
                "{capacity} B/s, {rtt:?}: {:.0} ms queued when the pause ended, over {:.0} ms",
                waiting * 1e3,
                bound * 1e3
            ))
        } else if frame.is_finite() && sent as f64 > frames {
            Err(format!("{capacity} B/s, {rtt:?}: {sent} B sent in the pause, over {frames:.0} B"))
        } else {
            Ok(())
        }
    });
    let failed: Vec<String> = failed.into_iter().filter_map(Result::err).collect();
    assert!(failed.is_empty(), "{failed:?}");
}
