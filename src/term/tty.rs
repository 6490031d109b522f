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
//! With `--graphics` other than `cells`, the terminal is first asked what it can show
//! ([`super::probe`]): in raw mode, before the alternate screen and mouse reporting (a mouse
//! report during the probe would look like a garbled answer), with the replies read here with a
//! deadline, so nothing is left blocked on the terminal for the player's own reader. What the
//! picture needs undone on exit (kitty's image, pixel mouse reports) is written before
//! [`RESTORE`] on every path, by [`set_restore_prefix`].
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

use super::picture;
use super::player::{self, PlayerConfig, Probed, TerminalInput};
use super::probe::{self, GraphicsRequest, ProbeOptions};
use crate::error::{Error, Result};
use crate::output::graphics::{GraphicsMode, kitty};

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
/// Written before [`RESTORE`]: what the picture needs undone (see [`set_restore_prefix`]).
static RESTORE_PREFIX: Mutex<Vec<u8>> = Mutex::new(Vec::new());

/// After a probe the terminal did not answer in time, how long the player waits on exit for
/// answers still on their way, and drops them, so that none reach the shell as typed text.
pub const LATE_REPLY_GRACE: Duration = Duration::from_millis(50);
/// The temporary file of the probe's kitty file-medium query (a number the encoder never
/// reaches, so the names never collide).
const PROBE_FILE_NUMBER: u64 = u64::MAX;

/// Plays in this process's terminal (standard input and output) until the user quits; the
/// terminal is restored on every way out. Standard output must be a terminal.
///
/// Unless `config.graphics` is `cells`, the terminal is probed first (at most
/// [`probe::PROBE_BUDGET`]; only when standard input and output are both terminals, else no
/// query is sent and `auto` means cells).
pub fn play(config: PlayerConfig) -> Result<()> {
    use std::io::IsTerminal;
    let setup = |source| Error::Terminal { action: "cannot set up the terminal", source };
    let size = crossterm::terminal::size()
        .map_err(|source| Error::Terminal { action: "cannot read the terminal size", source })?;
    let wants_probe = config.graphics != GraphicsRequest::Force(GraphicsMode::Cells)
        && probe::should_probe(io::stdin().is_terminal(), io::stdout().is_terminal());
    let guard = TerminalGuard::raw().map_err(setup)?;
    let probed = if wants_probe { Some(probe_terminal().map_err(setup)?) } else { None };
    let choice = probe::choose(config.graphics, probed.as_ref().map(|p| &p.support));
    let pixel_mouse = probed.as_ref().is_some_and(|p| picture::pixel_mouse(&choice, &p.support));
    set_restore_prefix(picture::restore_bytes(&choice, pixel_mouse));
    guard.enter_screen(if pixel_mouse { picture::PIXEL_MOUSE_ON } else { b"" }).map_err(setup)?;
    let unanswered = probed.as_ref().is_some_and(|p| !p.support.answered);
    let mut input = Stdin { size };
    let result = player::run_probed(&mut input, TtyOut, config, probed);
    if unanswered {
        drop_late_replies();
    }
    drop(guard);
    set_restore_prefix(Vec::new());
    remove_temp_files();
    result
}

/// What a picture written once to this process's terminal (`render --out -`) is drawn with:
/// the terminal is asked (raw mode for at most [`probe::PROBE_BUDGET`], then back to how it
/// was) unless `request` is `cells` or standard input and output are not both terminals; then
/// `auto` means cells. The file medium is not offered (the process may end before the terminal
/// reads a file), nor pixel mouse reports.
pub fn probe_for_picture(request: GraphicsRequest) -> (probe::GraphicsChoice, probe::GraphicsSupport) {
    use std::io::IsTerminal;
    let asks = request != GraphicsRequest::Force(GraphicsMode::Cells)
        && probe::should_probe(io::stdin().is_terminal(), io::stdout().is_terminal());
    let support = asks
        .then(|| {
            if OUT.get().is_none() {
                let fd = io::stdout().as_fd().try_clone_to_owned().ok()?;
                OUT.get_or_init(|| File::from(fd));
            }
            crossterm::terminal::enable_raw_mode().ok()?;
            let probed = probe_terminal();
            if probed.as_ref().is_ok_and(|p| !p.support.answered) {
                drop_late_replies();
            }
            let _ = crossterm::terminal::disable_raw_mode();
            let mut support = probed.ok()?.support;
            support.kitty_temp_file = false;
            support.sgr_pixels_mouse = false;
            Some(support)
        })
        .flatten();
    (probe::choose(request, support.as_ref()), support.unwrap_or_default())
}

/// Asks the terminal what it can show (see [`super::probe`]); the terminal is in raw mode.
fn probe_terminal() -> io::Result<Probed> {
    let env = probe::Environment::current();
    let winsize = probe::WinSize::current()?;
    let kitty_file =
        if env.ssh { None } else { kitty::write_temp_file(&kitty::temp_dir(), PROBE_FILE_NUMBER, &[0, 0, 0]).ok() };
    let options = ProbeOptions { env, winsize, kitty_file: kitty_file.clone() };
    let stdin = io::stdin();
    let mut read = |buf: &mut [u8], deadline: Instant| probe::read_fd_with_deadline(stdin.as_fd(), buf, deadline);
    let mut write = |bytes: &[u8]| {
        let _lock = lock();
        match OUT.get() {
            Some(mut out) => out.write_all(bytes),
            None => Ok(()),
        }
    };
    let mut outcome = probe::run_probe(&options, &mut write, &mut read, &Instant::now, probe::PROBE_BUDGET)?;
    if let Some(path) = &kitty_file
        && path.exists()
    {
        // The terminal did not read (and delete) the file: the file medium does not work.
        outcome.support.kitty_temp_file = false;
        let _ = std::fs::remove_file(path);
    }
    Ok(Probed { support: outcome.support, leftover: outcome.leftover })
}

/// Reads and drops what arrives within [`LATE_REPLY_GRACE`]: the answers of a probe that timed
/// out, which would otherwise reach the shell.
fn drop_late_replies() {
    let deadline = Instant::now() + LATE_REPLY_GRACE;
    let mut buf = [0u8; 4096];
    while Instant::now() < deadline {
        if !matches!(probe::read_fd_with_deadline(io::stdin().as_fd(), &mut buf, deadline), Ok(n) if n > 0) {
            break;
        }
    }
}

/// Removes kitty temporary files of this process the terminal did not read (it deletes the
/// ones it reads).
fn remove_temp_files() {
    let prefix = format!("tidepool-{}-", std::process::id());
    let Ok(entries) = std::fs::read_dir(kitty::temp_dir()) else { return };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if name.starts_with(&prefix) && name.contains(kitty::TEMP_FILE_MARKER) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Sets the bytes written before [`RESTORE`] when the terminal is restored (on every path:
/// the guard, the panic hook, [`restore`] from a signal handler): what the picture needs
/// undone, such as deleting kitty's image.
pub fn set_restore_prefix(bytes: Vec<u8>) {
    *RESTORE_PREFIX.lock().unwrap_or_else(|p| p.into_inner()) = bytes;
}

/// The terminal in player mode; dropping it restores the terminal.
#[derive(Debug)]
pub struct TerminalGuard {
    _private: (),
}

impl TerminalGuard {
    /// Puts the terminal in raw mode, with the restore armed (the guard's drop, the panic
    /// hook, [`restore`]), so the terminal can be asked questions before the screen is taken
    /// over with [`TerminalGuard::enter_screen`]. Fails (leaving the terminal as it was) when
    /// raw mode cannot be set.
    pub fn raw() -> io::Result<TerminalGuard> {
        if OUT.get().is_none() {
            let fd = io::stdout().as_fd().try_clone_to_owned()?;
            OUT.get_or_init(|| File::from(fd));
        }
        crossterm::terminal::enable_raw_mode()?;
        ACTIVE.store(true, Ordering::SeqCst);
        PANIC_HOOK.call_once(|| {
            let previous = std::panic::take_hook();
            std::panic::set_hook(Box::new(move |info| {
                restore();
                previous(info);
            }));
        });
        Ok(TerminalGuard { _private: () })
    }

    /// The alternate screen, hidden cursor and mouse reporting ([`ENTER`]), then `extra` (modes
    /// the picture needs, such as pixel mouse reports).
    pub fn enter_screen(&self, extra: &[u8]) -> io::Result<()> {
        let _lock = lock();
        let mut out = OUT.get().ok_or_else(|| io::Error::other("the terminal's output is not open"))?;
        out.write_all(ENTER)?;
        if !extra.is_empty() {
            out.write_all(extra)?;
        }
        Ok(())
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
        // CAN first: the prefix must not land inside a sequence a failed write cut in half.
        let prefix = match RESTORE_PREFIX.try_lock() {
            Ok(p) => p.clone(),
            Err(std::sync::TryLockError::Poisoned(p)) => p.into_inner().clone(),
            Err(std::sync::TryLockError::WouldBlock) => Vec::new(),
        };
        if !prefix.is_empty() {
            let _ = out.write_all(b"\x18").and_then(|()| out.write_all(&prefix));
        }
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
