//! Taking over the terminal, and always giving it back.
//!
//! A terminal left in raw mode, without a cursor or in the alternate screen is the most common
//! complaint about terminal animation tools, so the restore runs from every exit path:
//! - the [`TerminalGuard`]'s `Drop` (`q`, `Esc`, `Ctrl-C` as a key, errors, unwinding);
//! - a panic hook, *before* the panic message is printed, so the message lands on the normal
//!   screen where it can be read;
//! - a [`crate::signals`] hook for SIGINT, SIGTERM and SIGHUP (the SSH link dropped).
//!
//! The restore runs at most once ([`restore`] is idempotent). Frames and the restore go
//! through one lock, so the restore never lands in the middle of a frame; it also starts with
//! CAN (0x18), which aborts an escape sequence a failed write may have cut in half. Frames are
//! written to a duplicate of stdout's descriptor, bypassing std's stdout lock, so a signal
//! arriving while a frame write is stuck cannot deadlock the restore.

use std::fs::File;
use std::io::{self, Write};
use std::os::fd::AsFd;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard, Once, OnceLock};
use std::time::{Duration, Instant};

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

/// The terminal in player mode; dropping it restores the terminal.
#[derive(Debug)]
pub struct TerminalGuard {
    hook: u64,
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
        let hook = crate::signals::add_hook(restore);
        let guard = TerminalGuard { hook };
        let _lock = lock();
        (&*out).write_all(ENTER)?;
        Ok(guard)
    }
}

impl Drop for TerminalGuard {
    fn drop(&mut self) {
        restore();
        crate::signals::remove_hook(self.hook);
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

/// Writes one whole frame with one `write_all`; does nothing once the terminal is restored
/// (a signal arrived), so no frame is drawn over the user's shell.
pub fn write_frame(bytes: &[u8]) -> io::Result<()> {
    let _lock = WRITE_LOCK.lock().unwrap_or_else(|p| p.into_inner());
    match (ACTIVE.load(Ordering::SeqCst), OUT.get()) {
        (true, Some(mut out)) => out.write_all(bytes),
        _ => Ok(()),
    }
}

/// Restores the terminal if the player has it (safe to call from any thread, any number of
/// times; only the first call after [`TerminalGuard::enter`] does anything).
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

/// Whether the player currently has the terminal.
pub fn active() -> bool {
    ACTIVE.load(Ordering::SeqCst)
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
