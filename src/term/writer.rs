//! A writer thread that never queues frames.
//!
//! The main loop hands over a frame only when the previous one has been written; while a write
//! is under way (a slow terminal, a slow SSH link) it keeps simulating and reading input, and
//! the frames it would have drawn are dropped. Because a frame is only encoded when the writer
//! is idle, every frame is a diff against what was really sent, and input latency stays one
//! frame even when the link is slower than the frame rate.

use std::io;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, SyncSender};

/// The writer thread's handle.
#[derive(Debug)]
pub struct FrameWriter {
    frames: SyncSender<Vec<u8>>,
    busy: Arc<AtomicBool>,
    errors: Receiver<io::Error>,
    spare: Receiver<Vec<u8>>,
}

impl FrameWriter {
    /// Starts a writer thread that writes each frame with `write` (one call per frame).
    pub fn spawn(mut write: impl FnMut(&[u8]) -> io::Result<()> + Send + 'static) -> io::Result<FrameWriter> {
        let (frames, inbox) = mpsc::sync_channel::<Vec<u8>>(1);
        let (error_tx, errors) = mpsc::channel();
        // Bounded, so handing buffers back never allocates (an unbounded channel allocates a
        // block every few dozen messages); at most two frames are ever in flight.
        let (spare_tx, spare) = mpsc::sync_channel(2);
        let busy = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&busy);
        std::thread::Builder::new().name("tidepool-writer".into()).spawn(move || {
            for mut frame in inbox {
                let result = write(&frame);
                frame.clear();
                let _ = spare_tx.try_send(frame);
                flag.store(false, Ordering::SeqCst);
                if let Err(e) = result {
                    let _ = error_tx.send(e);
                    return;
                }
            }
        })?;
        Ok(FrameWriter { frames, busy, errors, spare })
    }

    /// Whether the last frame has been written, so a new one can be sent.
    pub fn idle(&self) -> bool {
        !self.busy.load(Ordering::SeqCst)
    }

    /// Hands a frame to the thread. Call only when [`FrameWriter::idle`]; a frame sent while
    /// busy waits for the one before (it is never dropped: it is a diff).
    pub fn send(&self, frame: Vec<u8>) {
        self.busy.store(true, Ordering::SeqCst);
        if self.frames.send(frame).is_err() {
            self.busy.store(false, Ordering::SeqCst);
        }
    }

    /// A buffer to encode the next frame into, reusing a written frame's allocation.
    pub fn buffer(&self) -> Vec<u8> {
        self.spare.try_recv().unwrap_or_default()
    }

    /// The error that stopped the thread, if any.
    pub fn error(&self) -> Option<io::Error> {
        self.errors.try_recv().ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;
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
        let w = FrameWriter::spawn(|_| {
            std::thread::sleep(Duration::from_millis(150));
            Ok(())
        })
        .unwrap();
        w.send(vec![1]);
        assert!(!w.idle(), "busy while writing: the caller drops frames instead of queueing");
        wait_idle(&w);
    }

    #[test]
    fn a_write_error_is_reported() {
        let w = FrameWriter::spawn(|_| Err(io::Error::other("gone"))).unwrap();
        w.send(vec![1]);
        wait_idle(&w);
        let deadline = Instant::now() + Duration::from_secs(5);
        let mut error = None;
        while error.is_none() && Instant::now() < deadline {
            error = w.error();
        }
        assert_eq!(error.unwrap().to_string(), "gone");
    }
}
