//! A writer thread that never queues frames.
//!
//! The main loop hands over a frame only when the previous one has been written; while a write
//! is under way (a slow terminal, a slow SSH link) it keeps simulating and reading input, and
//! the frames it would have drawn are dropped. Because a frame is only encoded when the writer
//! is idle, every frame is a diff against what was really sent, and input latency stays one
//! frame even when the link is slower than the frame rate.
//!
//! The hand-over is one slot under a mutex with a condition variable, and written buffers come
//! back for reuse, so a steady stream of frames allocates nothing (a channel would allocate
//! when a thread blocks on it).

use std::io;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};

/// What the two threads share.
#[derive(Debug, Default)]
struct Slot {
    /// The frame to write next.
    frame: Option<Vec<u8>>,
    /// Written buffers, for reuse (at most two exist).
    spare: Vec<Vec<u8>>,
    /// A frame is waiting or being written.
    busy: bool,
    /// The error that stopped the writer.
    error: Option<io::Error>,
    /// The handle was dropped: the thread ends.
    closed: bool,
}

/// The writer thread's handle; dropping it ends the thread after the frame in hand.
#[derive(Debug)]
pub struct FrameWriter {
    shared: Arc<(Mutex<Slot>, Condvar)>,
}

fn lock(shared: &(Mutex<Slot>, Condvar)) -> MutexGuard<'_, Slot> {
    shared.0.lock().unwrap_or_else(|p| p.into_inner())
}

impl FrameWriter {
    /// Starts a writer thread that writes each frame with `write` (one call per frame).
    pub fn spawn(mut write: impl FnMut(&[u8]) -> io::Result<()> + Send + 'static) -> io::Result<FrameWriter> {
        let slot = Slot { spare: Vec::with_capacity(2), ..Slot::default() };
        let shared = Arc::new((Mutex::new(slot), Condvar::new()));
        let theirs = Arc::clone(&shared);
        std::thread::Builder::new().name("tidepool-writer".into()).spawn(move || {
            loop {
                let mut frame = {
                    let mut slot = lock(&theirs);
                    loop {
                        if let Some(frame) = slot.frame.take() {
                            break frame;
                        }
                        if slot.closed {
                            return;
                        }
                        slot = theirs.1.wait(slot).unwrap_or_else(|p| p.into_inner());
                    }
                };
                let result = write(&frame);
                frame.clear();
                let mut slot = lock(&theirs);
                if slot.spare.len() < slot.spare.capacity() {
                    slot.spare.push(frame);
                }
                slot.busy = false;
                if let Err(e) = result {
                    slot.error = Some(e);
                    return;
                }
            }
        })?;
        Ok(FrameWriter { shared })
    }

    /// Whether the last frame has been written, so a new one can be sent.
    pub fn idle(&self) -> bool {
        !lock(&self.shared).busy
    }

    /// Hands a frame to the thread. Call only when [`FrameWriter::idle`]; a frame sent while
    /// busy replaces nothing: it waits for the one before (it is never dropped: it is a diff).
    pub fn send(&self, frame: Vec<u8>) {
        let mut slot = lock(&self.shared);
        if slot.error.is_some() {
            return;
        }
        while slot.frame.is_some() {
            slot = self.shared.1.wait(slot).unwrap_or_else(|p| p.into_inner());
        }
        slot.frame = Some(frame);
        slot.busy = true;
        self.shared.1.notify_all();
    }

    /// A buffer to encode the next frame into, reusing a written frame's allocation.
    pub fn buffer(&self) -> Vec<u8> {
        lock(&self.shared).spare.pop().unwrap_or_default()
    }

    /// The error that stopped the thread, if any.
    pub fn error(&self) -> Option<io::Error> {
        lock(&self.shared).error.take()
    }
}

impl Drop for FrameWriter {
    fn drop(&mut self) {
        lock(&self.shared).closed = true;
        self.shared.1.notify_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, Instant};

    fn wait_idle(w: &FrameWriter) {
        let deadline = Instant::now() + Duration::from_secs(5);
        while !w.idle() && Instant::now() < deadline {
            std::thread::sleep(Duration::from_millis(1));
        }
        assert!(w.idle());
    }

    #[test]
    fn frames_are_written_in_order_and_buffers_come_back() {
        let seen = Arc::new(Mutex::new(Vec::new()));
        let sink = Arc::clone(&seen);
        let w = FrameWriter::spawn(move |b| {
            sink.lock().unwrap().extend_from_slice(b);
            Ok(())
        })
        .unwrap();
        for frame in [&b"ab"[..], b"cd"] {
            w.send(frame.to_vec());
            wait_idle(&w);
        }
        assert_eq!(*seen.lock().unwrap(), b"abcd");
        let buffer = w.buffer();
        assert!(buffer.is_empty() && buffer.capacity() >= 2);
    }

    #[test]
    fn a_slow_write_keeps_the_writer_busy() {
        let (tx, rx) = std::sync::mpsc::channel::<()>();
        let rx = Mutex::new(rx);
        let w = FrameWriter::spawn(move |_| {
            let _ = rx.lock().unwrap().recv();
            Ok(())
        })
        .unwrap();
        w.send(vec![1]);
        assert!(!w.idle(), "busy while writing: the caller drops frames instead of queueing");
        tx.send(()).unwrap();
        wait_idle(&w);
    }

    #[test]
    fn a_write_error_is_reported() {
        let w = FrameWriter::spawn(|_| Err(io::Error::other("gone"))).unwrap();
        w.send(vec![1]);
        wait_idle(&w);
        assert_eq!(w.error().unwrap().to_string(), "gone");
    }
}
