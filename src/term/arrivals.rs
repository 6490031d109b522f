//! This process's terminal input, read on its own thread and timed as it arrives.
//!
//! The player's loop reads its input between frames. A frame on a busy machine (the scene's
//! steps, its picture, a sixel picture's dither) can take longer than the frame interval, and
//! an answer to the link's question that arrived meanwhile was then timed when the loop got to
//! it: up to a frame late. The link control took that delay for a queue on the link and fell
//! (a local xterm drawing sixel: round trips of 45-140 ms where the terminal answered within
//! a few, and the rate at 2 kB/s). Here a thread waits on the descriptor and stamps each chunk
//! with the moment it was read; the loop takes the chunks with their times.

use std::io;
use std::os::fd::{AsFd, BorrowedFd};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, SyncSender, sync_channel};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// How often the thread looks at the stop flag while nothing arrives.
const POLL: Duration = Duration::from_millis(20);
/// Chunks waiting for the loop at most (each up to 4 kB): a flood waits in the descriptor.
const QUEUE: usize = 64;

/// What the thread hands over.
enum Chunk {
    /// Bytes, and when they were read.
    Bytes(Instant, Vec<u8>),
    /// The input closed (the terminal went away).
    Closed,
    /// Reading failed.
    Failed(io::Error),
}

/// Standard input, read on a thread (see the module docs). Dropping it stops the thread
/// within [`POLL`], before the terminal is given back: nothing typed after the session is
/// taken from the shell.
pub struct Arrivals {
    chunks: Receiver<Chunk>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    closed: bool,
}

impl Arrivals {
    /// Starts reading standard input.
    pub fn stdin() -> io::Result<Arrivals> {
        let (send, chunks) = sync_channel(QUEUE);
        let stop = Arc::new(AtomicBool::new(false));
        let stopped = Arc::clone(&stop);
        let thread = std::thread::Builder::new()
            .name("tidepool-input".into())
            .spawn(move || read_until_stopped(io::stdin().as_fd(), &send, &stopped))?;
        Ok(Arrivals { chunks, stop, thread: Some(thread), closed: false })
    }

    /// Waits at most `timeout` for a chunk and appends it to `buf`; returns when it arrived
    /// (`Ok(None)`: nothing within the timeout). `Err` with `UnexpectedEof` once the input
    /// closed.
    pub fn next(&mut self, buf: &mut Vec<u8>, timeout: Duration) -> io::Result<Option<Instant>> {
        if self.closed {
            return Err(io::ErrorKind::UnexpectedEof.into());
        }
        match self.chunks.recv_timeout(timeout) {
            Ok(Chunk::Bytes(at, bytes)) => {
                buf.extend_from_slice(&bytes);
                Ok(Some(at))
            }
            Ok(Chunk::Closed) | Err(RecvTimeoutError::Disconnected) => {
                self.closed = true;
                Err(io::ErrorKind::UnexpectedEof.into())
            }
            Ok(Chunk::Failed(e)) => {
                self.closed = true;
                Err(e)
            }
            Err(RecvTimeoutError::Timeout) => Ok(None),
        }
    }
}

impl Drop for Arrivals {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The thread: waits on `fd`, reads what arrives, stamps it, until told to stop or the input
/// closes.
fn read_until_stopped(fd: BorrowedFd<'_>, send: &SyncSender<Chunk>, stop: &AtomicBool) {
    use rustix::event::{PollFd, PollFlags, Timespec, poll};
    let timeout = Timespec::try_from(POLL).expect("a small timeout");
    let mut chunk = [0u8; 4096];
    while !stop.load(Ordering::SeqCst) {
        let mut fds = [PollFd::new(&fd, PollFlags::IN)];
        match poll(&mut fds, Some(&timeout)) {
            Ok(0) | Err(rustix::io::Errno::INTR) => continue,
            Ok(_) => {}
            Err(e) => {
                let _ = send.send(Chunk::Failed(e.into()));
                return;
            }
        }
        if stop.load(Ordering::SeqCst) {
            return;
        }
        let revents = fds[0].revents();
        if revents.intersects(PollFlags::HUP | PollFlags::ERR | PollFlags::NVAL) && !revents.contains(PollFlags::IN) {
            let _ = send.send(Chunk::Closed);
            return;
        }
        // The descriptor itself: std's buffered `Stdin` could keep bytes `poll` no longer sees.
        match rustix::io::read(fd, &mut chunk) {
            Ok(0) => {
                let _ = send.send(Chunk::Closed);
                return;
            }
            Ok(n) => {
                if send.send(Chunk::Bytes(Instant::now(), chunk[..n].to_vec())).is_err() {
                    return;
                }
            }
            Err(rustix::io::Errno::INTR | rustix::io::Errno::AGAIN) => {}
            Err(e) => {
                let _ = send.send(Chunk::Failed(e.into()));
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chunks_carry_the_time_they_arrived_not_the_time_they_were_taken() {
        let (reader, mut writer) = std::io::pipe().unwrap();
        let watch = reader.try_clone().unwrap();
        let (send, chunks) = sync_channel(QUEUE);
        let stop = Arc::new(AtomicBool::new(false));
        let stopped = Arc::clone(&stop);
        let thread = std::thread::spawn(move || read_until_stopped(reader.as_fd(), &send, &stopped));
        let mut arrivals = Arrivals { chunks, stop, thread: Some(thread), closed: false };
        std::io::Write::write_all(&mut writer, b"\x1b[?62;22c").unwrap();
        // Once the thread has read the answer (the pipe is empty: a readiness signal, not a
        // time), the loop stays busy for a while (a long frame) before it takes it.
        while rustix::io::ioctl_fionread(&watch).unwrap() > 0 {
            std::thread::yield_now();
        }
        let drained = Instant::now();
        std::thread::sleep(Duration::from_millis(200));
        let mut buf = Vec::new();
        let at = arrivals.next(&mut buf, Duration::from_secs(5)).unwrap().expect("the chunk");
        assert_eq!(buf, b"\x1b[?62;22c");
        assert!(at < drained + Duration::from_millis(100), "stamped when it was read, not when it was taken");
        drop(writer);
        let closed = arrivals.next(&mut buf, Duration::from_secs(5));
        assert_eq!(closed.unwrap_err().kind(), io::ErrorKind::UnexpectedEof);
        drop(arrivals);
    }
}
