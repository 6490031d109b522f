//! The player on this process's own terminal: raw mode, the alternate screen, reading the
//! keyboard, and always giving the terminal back.
//!
//! A terminal left in raw mode, without a cursor or in the alternate screen is the most common
//! complaint about terminal animation tools, so the restore runs from every exit path:
//! - the [`TerminalGuard`]'s `Drop` (`q`, `Esc`, `Ctrl-C` as a key, errors, unwinding);
//! - a panic hook, *before* the panic message is printed, so the message lands on the normal
//!   screen where it can be read;
//! - [`restore`], which a program calls from its signal handler (the `tidepool` binary does for
//!   SIGINT, SIGTERM and SIGHUP: the SSH link dropped).
//!
//! The restore runs at most once. Frames and the restore go through one lock, so the restore
//! never lands in the middle of a frame; it also starts with CAN (0x18), which aborts an escape
//! sequence a failed write may have cut in half. Frames are written to a duplicate of stdout's
//! descriptor, bypassing std's stdout lock, so a signal arriving while a frame write is stuck
//! cannot deadlock the restore.

use std::fs::File;
use std::io::{self, Write};
use std::os::fd::AsFd;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard, Once, OnceLock};
use std::time::{Duration, Instant};

use super::player::{self, PlayerConfig, TerminalInput};
use crate::error::{Error, Result};

/// Sent when the player starts: alternate screen, hidden cursor, mouse reporting (buttons and
/// drags only, mode 1002, not every motion; SGR coordinates, mode 1006), screen cleared.
pub const ENTER: &[u8] = b"\x1b[?1049h\x1b[?25l\x1b[?1000h\x1b[?1002h\x1b[?1006h\x1b[0m\x1b[2J";

/// Sent when the player stops: abort any cut sequence, end synchronized output, reset
/// colours, mouse off, cursor on, back to the normal screen.
pub const RESTORE: &[u8] = b"\x18\x1b[?2026l\x1b[0m\x1b[?1006l\x1b[?1002l\x1b[?1000l\x1b[?25h\x1b[?1049l";

static ACTIVE: AtomicBool = AtomicBool::new(false);
static WRITE_LOCK: Mutex<()> = Mutex::new(());
static OUT: OnceLock<File> = OnceLock::new();
static PANIC_HOOK: Once = Once::new();

/// Plays in this process's terminal (standard input and output) until the user quits; the
/// terminal is restored on every way out. Standard output must be a terminal.
pub fn play(config: PlayerConfig) -> Result<()> {
    let size = crossterm::terminal::size()
        .map_err(|source| Error::Terminal { action: "cannot read the terminal size", source })?;
    let guard =
        TerminalGuard::enter().map_err(|source| Error::Terminal { action: "cannot set up the terminal", source })?;
    let mut input = Stdin { size };
    let result = player::run(&mut input, TtyOut, config);
    drop(guard);
    result
}

/// The terminal in player mode; dropping it restores the terminal.
#[derive(Debug)]
pub struct TerminalGuard {
    _private: (),
}

impl TerminalGuard {
    /// Puts the terminal in raw mode and the alternate screen, hides the cursor and turns on
    /// mouse reporting. Fails (leaving the terminal as it was) when raw mode cannot be set.
    pub fn enter() -> io::Result<TerminalGuard> {
        let out = match OUT.get() {
            Some(f) => f,
            None => {
                let fd = io::stdout().as_fd().try_clone_to_owned()?;
                OUT.get_or_init(|| File::from(fd))
            }
        };
        crossterm::terminal::enable_raw_mode()?;
        ACTIVE.store(true, Ordering::SeqCst);
        PANIC_HOOK.call_once(|| {
            let previous = std::panic::take_hook();
            std::panic::set_hook(Box::new(move |info| {
                restore();
                previous(info);
            }));
        });
        let guard = TerminalGuard { _private: () };
        let _lock = lock();
        (&*out).write_all(ENTER)?;
        Ok(guard)
    }
}

impl Drop for TerminalGuard {
    fn drop(&mut self) {
        restore();
    }
}

/// Takes the write lock, waiting at most 200 ms: a frame write that is stuck (a frozen link)
/// must not keep the terminal from being restored when the process is told to stop.
fn lock() -> Option<MutexGuard<'static, ()>> {
    let deadline = Instant::now() + Duration::from_millis(200);
    loop {
        match WRITE_LOCK.try_lock() {
            Ok(g) => return Some(g),
            Err(std::sync::TryLockError::Poisoned(p)) => return Some(p.into_inner()),
            Err(std::sync::TryLockError::WouldBlock) if Instant::now() < deadline => {
                std::thread::sleep(Duration::from_millis(2));
            }
            Err(std::sync::TryLockError::WouldBlock) => return None,
        }
    }
}

/// Frames to the terminal: one `write_all` per frame, nothing once the terminal is restored
/// (a signal arrived), so no frame is drawn over the user's shell.
struct TtyOut;

impl Write for TtyOut {
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        self.write_all(bytes).map(|()| bytes.len())
    }

    fn write_all(&mut self, bytes: &[u8]) -> io::Result<()> {
        let _lock = WRITE_LOCK.lock().unwrap_or_else(|p| p.into_inner());
        match (ACTIVE.load(Ordering::SeqCst), OUT.get()) {
            (true, Some(mut out)) => out.write_all(bytes),
            _ => Ok(()),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// Restores the terminal if the player has it (safe to call from any thread, any number of
/// times, from a signal-handling thread too; only the first call after the player took the
/// terminal does anything).
pub fn restore() {
    if !ACTIVE.swap(false, Ordering::SeqCst) {
        return;
    }
    let _lock = lock();
    if let Some(mut out) = OUT.get() {
        let _ = out.write_all(RESTORE);
    }
    let _ = crossterm::terminal::disable_raw_mode();
}

/// Standard input, read without blocking past the player's deadline.
struct Stdin {
    size: (u16, u16),
}

impl TerminalInput for Stdin {
    fn read(&mut self, buf: &mut Vec<u8>, timeout: Duration) -> io::Result<bool> {
        use rustix::event::{PollFd, PollFlags, Timespec, poll};
        let stdin = io::stdin();
        let mut fds = [PollFd::new(&stdin, PollFlags::IN)];
        let timeout = Timespec::try_from(timeout).unwrap_or(Timespec { tv_sec: 0, tv_nsec: 50_000_000 });
        match poll(&mut fds, Some(&timeout)) {
            Ok(0) => return Ok(true),
            Ok(_) => {}
            Err(rustix::io::Errno::INTR) => return Ok(true),
            Err(e) => return Err(e.into()),
        }
        if fds[0].revents().intersects(PollFlags::HUP | PollFlags::ERR | PollFlags::NVAL)
            && !fds[0].revents().contains(PollFlags::IN)
        {
            return Ok(false);
        }
        // Read the descriptor itself: std's buffered `Stdin` could keep bytes that `poll` then
        // no longer sees.
        let mut chunk = [0u8; 4096];
        match rustix::io::read(stdin.as_fd(), &mut chunk) {
            Ok(0) => Ok(false),
            Ok(n) => {
                buf.extend_from_slice(&chunk[..n]);
                Ok(true)
            }
            Err(rustix::io::Errno::INTR | rustix::io::Errno::AGAIN) => Ok(true),
            Err(e) => Err(e.into()),
        }
    }

    fn size(&mut self) -> io::Result<(u16, u16)> {
        if let Ok(size) = crossterm::terminal::size() {
            self.size = size;
        }
        Ok(self.size)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::vt::Screen;

    #[test]
    fn restore_undoes_every_mode_enter_sets() {
        let mut s = Screen::new(10, 3);
        s.feed(ENTER);
        s.feed(b"\x1b[?2026h\x1b[38;2;1;2;3mx\x1b[");
        s.feed(RESTORE);
        for mode in [1049, 1000, 1002, 1006, 2026] {
            assert_eq!(s.private_mode(mode), Some(false), "mode {mode}");
        }
        assert_eq!(s.private_mode(25), Some(true), "cursor shown");
        s.feed(b"y");
        assert_eq!(s.cell(1, 0).fg, None, "colours reset");
    }
}
