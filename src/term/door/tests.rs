//! The terminal door is a shim: with its clock and its terminal scripted, it hands out exactly
//! the bytes the test harness gets from the same session turn by turn.

use std::sync::Arc;
use std::sync::Mutex;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use super::*;
use crate::play::tests::{FRAME, host_config, screen_config, session};

/// A terminal of 100x20 cells whose bytes come at frame numbers; each read is one frame of a
/// fake clock, whatever the door's timeout; it closes after `frames` frames.
struct Scripted<'a> {
    script: &'a [(u32, &'a [u8])],
    frame: u32,
    frames: u32,
    clock: &'a Mutex<Instant>,
    t0: Instant,
    /// Set at this frame, as a signal handler sets it.
    quit: Option<(u32, Arc<AtomicBool>)>,
}

impl TerminalInput for Scripted<'_> {
    fn read(&mut self, buf: &mut Vec<u8>, _timeout: Duration) -> std::io::Result<bool> {
        if self.frame == self.frames {
            return Ok(false);
        }
        *self.clock.lock().unwrap() = self.t0 + FRAME * self.frame;
        if let Some((at, quit)) = &self.quit
            && *at == self.frame
        {
            quit.store(true, std::sync::atomic::Ordering::SeqCst);
        }
        for (_, bytes) in self.script.iter().filter(|(at, _)| *at == self.frame) {
            buf.extend_from_slice(bytes);
        }
        self.frame += 1;
        Ok(true)
    }

    fn size(&mut self) -> std::io::Result<(u16, u16)> {
        Ok((100, 20))
    }
}

/// Memory that is always free to take a frame.
#[derive(Default)]
struct Memory(Vec<u8>);

impl Sink for Memory {
    fn idle(&self) -> bool {
        true
    }
    fn send(&mut self, bytes: Vec<u8>) {
        self.0.extend_from_slice(&bytes);
    }
    fn buffer(&mut self) -> Vec<u8> {
        Vec::new()
    }
    fn error(&mut self) -> Option<std::io::Error> {
        None
    }
}

/// Every byte the door writes for `script` over `frames` frames from `t0`.
fn through_the_door(t0: Instant, script: &[(u32, &[u8])], frames: u32) -> Vec<u8> {
    door_run(t0, script, frames, None, screen_config()).0
}

/// The bytes the door writes, and how many reads it made, for `script` over `frames` frames,
/// with the quit flag set at frame `signal_at` when given.
fn door_run(
    t0: Instant,
    script: &[(u32, &[u8])],
    frames: u32,
    signal_at: Option<u32>,
    screen: crate::play::screen::ScreenConfig,
) -> (Vec<u8>, u32) {
    let clock = Mutex::new(t0);
    let quit = Arc::new(AtomicBool::new(false));
    let mut input =
        Scripted { script, frame: 0, frames, clock: &clock, t0, quit: signal_at.map(|at| (at, Arc::clone(&quit))) };
    let mut sink = Memory::default();
    let config = PlayConfig { host: host_config(), screen, greeting: None, storage: None, quit };
    drive(&mut input, &mut sink, config, &mut |_| {}, &|| *clock.lock().unwrap(), false).unwrap();
    (sink.0, input.frame)
}

/// A question in flight when the person quits is waited for (its answer would be echoed to
/// the shell once the terminal is back in cooked mode), for a signal as for `q`: the door
/// keeps reading after the quit until the answer comes.
#[test]
fn a_signal_waits_for_the_last_answer_as_q_does() {
    let t0 = Instant::now();
    // The link control asks after frames; the terminal never answers, so the last question is
    // still in flight at the quit.
    let screen = || crate::play::screen::ScreenConfig { bandwidth: crate::play::Bandwidth::Auto, ..screen_config() };
    let (_, after_q) = door_run(t0, &[(30, b"q")], 200, None, screen());
    let (_, after_signal) = door_run(t0, &[], 200, Some(30), screen());
    assert!(after_q > 32, "q waited for the answer: {after_q} reads");
    assert_eq!(after_signal, after_q, "a signal waits as long as q");
}

#[test]
fn the_door_hands_out_the_bytes_of_the_canonical_turn() {
    let script: &[(u32, &[u8])] = &[(5, b" "), (20, b"+"), (40, b"\x1b[<0;30;8M"), (45, b"?"), (50, b"\x1b")];
    let t0 = Instant::now();
    let harness = session(t0, script, 70);
    let door = through_the_door(t0, script, 70);
    assert!(harness.len() > 10_000, "frames were drawn: {} bytes", harness.len());
    assert!(door == harness, "the door's bytes ({}) are the harness's ({})", door.len(), harness.len());
}
