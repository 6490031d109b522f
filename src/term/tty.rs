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
//! With `--graphics` other than `cells`, the session's screen first asks the terminal what it
//! can show (`crate::play`'s probe): in raw mode, before the alternate screen and mouse
//! reporting (a mouse report during the probe would look like a garbled answer). What the
//! picture needs undone on exit (kitty's image, pixel mouse reports) is written before
//! [`Screen::RESTORE`] on every path, by [`set_restore_prefix`].
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

use super::arrivals::Arrivals;
use super::door::{PlayConfig, TerminalInput, run_door};
use crate::error::{Error, Result};
use crate::output::graphics::{GraphicsMode, kitty};
use crate::play::screen::probe::{
    self, EnvHints, GraphicsChoice, GraphicsRequest, GraphicsSupport, ProbeOptions, WinSize,
};
use crate::play::screen::{LinkPath, Screen};

static ACTIVE: AtomicBool = AtomicBool::new(false);
static WRITE_LOCK: Mutex<()> = Mutex::new(());
static OUT: OnceLock<File> = OnceLock::new();
static PANIC_HOOK: Once = Once::new();
/// Written before [`Screen::RESTORE`]: what the picture needs undone (see [`set_restore_prefix`]).
static RESTORE_PREFIX: Mutex<Vec<u8>> = Mutex::new(Vec::new());

/// After a probe the terminal did not answer in time, how long a picture written once waits
/// for answers still on their way, and drops them, so that none reach the shell as typed text.
pub const LATE_REPLY_GRACE: Duration = Duration::from_millis(50);
/// The temporary file of the probe's kitty file-medium query (a number the encoder never
/// reaches, so the names never collide).
const PROBE_FILE_NUMBER: u64 = u64::MAX;

/// Plays in this process's terminal (standard input and output) until the person quits; the
/// terminal is restored on every way out. Standard output must be a terminal.
///
/// Unless `config.screen.graphics` is `cells`, the terminal is asked what it shows first (only
/// when standard input and output are both terminals; else no question is sent and `auto`
/// means cells).
pub fn play(mut config: PlayConfig) -> Result<()> {
    use std::io::IsTerminal;
    let setup = |source| Error::Terminal { action: "cannot set up the terminal", source };
    let winsize =
        window_size().map_err(|source| Error::Terminal { action: "cannot read the terminal size", source })?;
    let asks = config.screen.graphics != GraphicsRequest::Force(GraphicsMode::Cells)
        && probe::should_probe(io::stdin().is_terminal(), io::stdout().is_terminal());
    let guard = TerminalGuard::raw().map_err(setup)?;
    config.screen.probe = asks.then(|| probe_options(winsize, true));
    config.screen.link_path = link_path();
    let arrivals = Arrivals::stdin().map_err(setup)?;
    let mut input = Stdin { size: (winsize.cols, winsize.rows), arrivals, arrived: None };
    let result = run_door(&mut input, TtyOut, config, &mut set_restore_prefix);
    // The reading thread stops before the terminal is given back.
    drop(input);
    drop(guard);
    set_restore_prefix(Vec::new());
    remove_temp_files();
    result
}

/// What a picture written once to this process's terminal (`render --out -`) is drawn with:
/// the terminal is asked (raw mode for at most `PROBE_BUDGET` (500 ms), then back to how it
/// was) unless `request` is `cells` or standard input and output are not both terminals; then
/// `auto` means cells. The file medium is not offered (the process may end before the terminal
/// reads a file), nor pixel mouse reports.
pub fn probe_for_picture(request: GraphicsRequest) -> (GraphicsChoice, GraphicsSupport) {
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
            let probed = window_size().and_then(|w| ask(&probe_options(w, false)));
            if probed.as_ref().is_ok_and(|s| !s.answered) {
                drop_late_replies();
            }
            let _ = crossterm::terminal::disable_raw_mode();
            let mut support = probed.ok()?;
            support.kitty_temp_file = false;
            support.sgr_pixels_mouse = false;
            Some(support)
        })
        .flatten();
    (probe::choose(request, support.as_ref()), support.unwrap_or_default())
}

/// The probe's starting point for this process's terminal: its environment and window size,
/// and (when `file_medium` and not over SSH) a temporary file for the kitty file-medium query.
fn probe_options(winsize: WinSize, file_medium: bool) -> ProbeOptions {
    let env = EnvHints::from_lookup(|name| std::env::var(name).ok());
    let kitty_file = (file_medium && !env.ssh)
        .then(|| kitty::write_temp_file(&kitty::temp_dir(), PROBE_FILE_NUMBER, &[0, 0, 0]).ok())
        .flatten();
    ProbeOptions { env, winsize, kitty_file, colours: false }
}

/// Asks the terminal what it can show, waiting at most [`probe::PROBE_BUDGET`]; the terminal
/// is in raw mode.
fn ask(options: &ProbeOptions) -> io::Result<GraphicsSupport> {
    let stdin = io::stdin();
    let mut read = |buf: &mut [u8], deadline: Instant| read_fd_with_deadline(stdin.as_fd(), buf, deadline);
    let mut write = |bytes: &[u8]| {
        let _lock = lock();
        match OUT.get() {
            Some(mut out) => out.write_all(bytes),
            None => Ok(()),
        }
    };
    Ok(super::probe::run_probe(options, &mut write, &mut read, &Instant::now, probe::PROBE_BUDGET)?.support)
}

/// What sits between this process and the terminal: the environment (a multiplexer over SSH)
/// and the names of the process's ancestors (mosh-server), read from `/proc`.
fn link_path() -> LinkPath {
    let mut names = Vec::new();
    let mut pid = std::os::unix::process::parent_id();
    // At most a few generations: a shell, a multiplexer, sshd or mosh-server, init.
    for _ in 0..16 {
        if pid <= 1 {
            break;
        }
        let Ok(comm) = std::fs::read_to_string(format!("/proc/{pid}/comm")) else { break };
        names.push(comm.trim().to_owned());
        let Some(parent) = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok().and_then(|stat| {
            // `pid (comm) state ppid ...`: the parent after the last ')' (comm may hold spaces).
            stat.rsplit_once(')')?.1.split_whitespace().nth(1)?.parse().ok()
        }) else {
            break;
        };
        pid = parent;
    }
    LinkPath::detect(|name| std::env::var(name).ok(), names.iter().map(String::as_str))
}

/// The window size of the terminal on standard output (TIOCGWINSZ, through crossterm).
fn window_size() -> io::Result<WinSize> {
    let w = crossterm::terminal::window_size()?;
    Ok(WinSize { cols: w.columns, rows: w.rows, x_px: w.width, y_px: w.height })
}

/// Reads and drops what arrives within [`LATE_REPLY_GRACE`]: the answers of a probe that timed
/// out, which would otherwise reach the shell.
fn drop_late_replies() {
    let deadline = Instant::now() + LATE_REPLY_GRACE;
    let mut buf = [0u8; 4096];
    while Instant::now() < deadline {
        if !matches!(read_fd_with_deadline(io::stdin().as_fd(), &mut buf, deadline), Ok(n) if n > 0) {
            break;
        }
    }
}

/// A `read_with_deadline` for the probe's [`super::probe::run_probe`] on a terminal (or any pollable descriptor): waits
/// until input is there or `deadline` has passed (`poll`), then reads what is there. Returns 0
/// when the deadline passed with nothing to read. Unlike a reader thread, it leaves nothing
/// blocked on the terminal for the player's own input reader to compete with.
#[cfg(unix)]
pub fn read_fd_with_deadline(fd: std::os::fd::BorrowedFd<'_>, buf: &mut [u8], deadline: Instant) -> io::Result<usize> {
    use rustix::event::{PollFd, PollFlags, Timespec, poll};
    loop {
        let wait = deadline.saturating_duration_since(Instant::now());
        let timeout = Timespec { tv_sec: wait.as_secs() as i64, tv_nsec: i64::from(wait.subsec_nanos()) };
        let mut fds = [PollFd::new(&fd, PollFlags::IN)];
        match poll(&mut fds, Some(&timeout)) {
            Ok(0) => return Ok(0),
            Ok(_) => return rustix::io::read(fd, buf).map_err(io::Error::from),
            Err(rustix::io::Errno::INTR) => continue,
            Err(e) => return Err(e.into()),
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

/// Sets the bytes written before [`Screen::RESTORE`] when the terminal is restored (on every path:
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
    /// hook, [`restore`]), so the terminal can be asked questions before the session's screen
    /// takes it over ([`Screen::ENTER`]). Fails (leaving the terminal as it was) when
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
        let _ = out.write_all(Screen::RESTORE);
    }
    let _ = crossterm::terminal::disable_raw_mode();
}

/// Standard input, read without blocking past the player's deadline.
struct Stdin {
    size: (u16, u16),
    /// The descriptor, read on a thread that times each chunk as it arrives.
    arrivals: Arrivals,
    /// When the chunk the last read appended arrived.
    arrived: Option<Instant>,
}

impl TerminalInput for Stdin {
    fn read(&mut self, buf: &mut Vec<u8>, timeout: Duration) -> io::Result<bool> {
        match self.arrivals.next(buf, timeout) {
            Ok(at) => {
                self.arrived = at;
                Ok(true)
            }
            Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => Ok(false),
            Err(e) => Err(e),
        }
    }

    fn arrived(&self) -> Option<Instant> {
        self.arrived
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
    use crate::output::vt::TerminalModel as Vt;

    #[test]
    fn a_real_descriptor_is_read_until_the_deadline() {
        use std::os::fd::AsFd;
        let (reader, mut writer) = std::io::pipe().unwrap();
        let feeder = std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(20));
            writer.write_all(b"\x1b_Gi=31;OK\x1b\\\x1b[?62;22c").unwrap();
            writer
        });
        let mut sent = Vec::new();
        let mut write = |b: &[u8]| {
            sent.extend_from_slice(b);
            Ok(())
        };
        let mut read = |buf: &mut [u8], deadline: Instant| read_fd_with_deadline(reader.as_fd(), buf, deadline);
        let options =
            ProbeOptions { winsize: WinSize { cols: 80, rows: 24, x_px: 0, y_px: 0 }, ..ProbeOptions::default() };
        let outcome =
            crate::term::probe::run_probe(&options, &mut write, &mut read, &Instant::now, Duration::from_secs(5))
                .unwrap();
        assert!(outcome.support.answered && outcome.support.kitty);
        assert!(sent.ends_with(b"\x1b[c"));
        // Nothing more to read: it returns 0 once the deadline has passed.
        let _writer = feeder.join().unwrap();
        let deadline = Instant::now() + Duration::from_millis(30);
        assert_eq!(read_fd_with_deadline(reader.as_fd(), &mut [0; 16], deadline).unwrap(), 0);
        assert!(Instant::now() >= deadline, "returned before its deadline");
    }

    #[test]
    fn restore_undoes_every_mode_enter_sets() {
        let mut s = Vt::new(10, 3);
        s.feed(Screen::ENTER);
        s.feed(b"\x1b[?2026h\x1b[38;2;1;2;3mx\x1b[");
        s.feed(Screen::RESTORE);
        for mode in [1049, 1000, 1002, 1006, 2026] {
            assert_eq!(s.private_mode(mode), Some(false), "mode {mode}");
        }
        assert_eq!(s.private_mode(25), Some(true), "cursor shown");
        s.feed(b"y");
        assert_eq!(s.cell(1, 0).fg, None, "colours reset");
    }
}
