//! Time: the simulation's fixed step rate, the display's frame rate and byte budget, and the
//! figures of the status line. Every function takes `now` so tests can run on made-up clocks.

use std::time::{Duration, Instant};

/// Keeps the simulation at a fixed rate of steps per second, whatever the frame rate.
///
/// When the machine cannot keep up, at most [`SimClock::MAX_CATCH_UP`] of backlog is
/// simulated and the rest is forgotten: the water slows down instead of the player freezing.
#[derive(Clone, Debug)]
pub struct SimClock {
    period: Duration,
    next: Instant,
    paused: bool,
}

impl SimClock {
    /// The most simulated time run at once to catch up.
    pub const MAX_CATCH_UP: Duration = Duration::from_millis(250);

    /// A clock of `steps_per_second`, starting at `now`.
    pub fn new(steps_per_second: f64, now: Instant) -> SimClock {
        let period = Duration::from_secs_f64(1.0 / steps_per_second.max(1e-3));
        SimClock { period, next: now + period, paused: false }
    }

    /// How many steps to run now.
    pub fn due(&mut self, now: Instant) -> u64 {
        if self.paused || now < self.next {
            return 0;
        }
        let behind = now - self.next;
        if behind > Self::MAX_CATCH_UP {
            self.next = now - Self::MAX_CATCH_UP;
        }
        let n = ((now - self.next).as_nanos() / self.period.as_nanos().max(1)) as u64 + 1;
        self.next += self.period * n as u32;
        n
    }

    /// When the next step is due (`None` while paused).
    pub fn next_due(&self) -> Option<Instant> {
        (!self.paused).then_some(self.next)
    }

    /// Pauses or resumes; a resumed clock does not catch up the paused time.
    pub fn set_paused(&mut self, paused: bool, now: Instant) {
        if self.paused && !paused {
            self.next = now + self.period;
        }
        self.paused = paused;
    }

    /// Whether it is paused.
    pub fn paused(&self) -> bool {
        self.paused
    }
}

/// Decides when the next frame may be drawn: at most `fps` a second. (How many bytes a frame
/// may send is the byte bucket's business: see `output/bucket.rs`.)
#[derive(Clone, Debug)]
pub struct FramePacer {
    interval: Duration,
    next: Instant,
}

impl FramePacer {
    /// A pacer for `fps` frames a second, ready at `now`.
    pub fn new(fps: u32, now: Instant) -> FramePacer {
        FramePacer { interval: Duration::from_secs_f64(1.0 / f64::from(fps.max(1))), next: now }
    }

    /// When the next frame is due.
    pub fn next_due(&self) -> Instant {
        self.next
    }

    /// Whether a frame is due now.
    pub fn ready(&self, now: Instant) -> bool {
        now >= self.next
    }

    /// Notes that a frame was sent (or skipped) at `now`.
    pub fn sent(&mut self, now: Instant) {
        // Keep the cadence; if more than a frame late, start again from now.
        let mut next = self.next + self.interval;
        if next < now {
            next = now + self.interval;
        }
        self.next = next;
    }
}

/// Frames and bytes per second over the last whole second, for the status line.
#[derive(Clone, Debug)]
pub struct Meter {
    start: Instant,
    frames: u32,
    bytes: u64,
    /// Frames drawn in the last whole second.
    pub fps: u32,
    /// Bytes written in the last whole second.
    pub bytes_per_second: u64,
}

impl Meter {
    /// A meter starting at `now`.
    pub fn new(now: Instant) -> Meter {
        Meter { start: now, frames: 0, bytes: 0, fps: 0, bytes_per_second: 0 }
    }

    /// Counts a frame of `bytes`; returns true when the per-second figures changed.
    pub fn frame(&mut self, now: Instant, bytes: usize) -> bool {
        self.frames += 1;
        self.bytes += bytes as u64;
        self.tick(now)
    }

    /// Rolls the window over once a second; returns true when it did.
    pub fn tick(&mut self, now: Instant) -> bool {
        let elapsed = now - self.start;
        if elapsed < Duration::from_secs(1) {
            return false;
        }
        let secs = elapsed.as_secs_f64();
        self.fps = (f64::from(self.frames) / secs).round() as u32;
        self.bytes_per_second = (self.bytes as f64 / secs).round() as u64;
        (self.start, self.frames, self.bytes) = (now, 0, 0);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ms(n: u64) -> Duration {
        Duration::from_millis(n)
    }

    #[test]
    fn sim_clock_runs_at_its_rate_whatever_the_polling() {
        let t0 = Instant::now();
        let mut clock = SimClock::new(60.0, t0);
        let mut steps = 0;
        // Polled irregularly for one second.
        let mut t = t0;
        for gap in [1, 40, 3, 100, 7, 33, 250, 16, 200, 350].iter().cycle().take(40) {
            t += ms(*gap / 4);
            steps += clock.due(t);
        }
        let expected = ((t - t0).as_secs_f64() * 60.0).floor() as u64;
        assert!(steps.abs_diff(expected) <= 1, "{steps} vs {expected}");
    }

    #[test]
    fn sim_clock_forgets_a_long_stall_and_pauses() {
        let t0 = Instant::now();
        let mut clock = SimClock::new(60.0, t0);
        let n = clock.due(t0 + Duration::from_secs(10));
        assert!((15..=16).contains(&n), "250 ms of steps, not 600: {n}");
        let t1 = t0 + Duration::from_secs(11);
        clock.set_paused(true, t1);
        assert_eq!(clock.due(t1 + ms(500)), 0);
        clock.set_paused(false, t1 + ms(500));
        assert_eq!(clock.due(t1 + ms(517)), 1, "no catch-up of the pause");
    }

    #[test]
    fn pacer_keeps_the_frame_rate() {
        let t0 = Instant::now();
        let mut p = FramePacer::new(25, t0);
        assert!(p.ready(t0));
        p.sent(t0);
        assert!(!p.ready(t0 + ms(39)) && p.ready(t0 + ms(40)));
        p.sent(t0 + ms(200));
        assert!(!p.ready(t0 + ms(239)) && p.ready(t0 + ms(240)), "a late frame starts the cadence again");
    }

    #[test]
    fn meter_reports_per_second() {
        let t0 = Instant::now();
        let mut m = Meter::new(t0);
        for i in 1..30 {
            assert!(!m.frame(t0 + ms(i * 33), 100));
        }
        assert!(m.frame(t0 + ms(1000), 100));
        assert_eq!((m.fps, m.bytes_per_second), (30, 3000));
    }
}
