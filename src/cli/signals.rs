//! What happens on SIGINT, SIGTERM and SIGHUP: registered cleanups run (temporary files are
//! removed, the terminal is restored), then the process exits with 128 + the signal number
//! (130 for Ctrl-C), as shells expect.
//!
//! A dedicated thread receives the signals (via `signal-hook`), so the cleanups run in normal
//! code, not in a signal handler, and may take locks.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicI32, Ordering};
use std::sync::{Mutex, Once};

type Hook = Box<dyn Fn() + Send>;

static TEMP_FILES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static HOOKS: Mutex<Vec<(u64, Hook)>> = Mutex::new(Vec::new());
static INSTALL: Once = Once::new();
/// The signal that is ending the process (0: none).
static RECEIVED: AtomicI32 = AtomicI32::new(0);

/// Starts the signal thread (once; later calls do nothing).
pub fn install() {
    INSTALL.call_once(|| {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
            return; // without handlers the default actions apply: nothing worse than before
        };
        std::thread::Builder::new()
            .name("tidepool-signals".into())
            .spawn(move || {
                if let Some(signal) = signals.forever().next() {
                    RECEIVED.store(signal, Ordering::SeqCst);
                    run_cleanups();
                    std::process::exit(128 + signal);
                }
            })
            .ok();
    });
}

/// When a signal is ending the process, waits for its thread to finish the cleanups and exit
/// with 128 + the signal (so the main thread, returning from a command the signal stopped,
/// never exits first with another status).
pub fn wait_if_ending() {
    if RECEIVED.load(Ordering::SeqCst) != 0 {
        loop {
            std::thread::park();
        }
    }
}

/// Runs every registered cleanup now: hooks first (newest first), then temporary files.
pub fn run_cleanups() {
    if let Ok(hooks) = HOOKS.lock() {
        for (_, hook) in hooks.iter().rev() {
            hook();
        }
    }
    if let Ok(files) = TEMP_FILES.lock() {
        for file in files.iter() {
            let _ = std::fs::remove_file(file);
        }
    }
}

/// While it lives, a signal ends the player the way `q` does (the recording is saved, the
/// terminal restored), then the process exits with 128 + the signal. If the player does not
/// finish within [`StopOnSignal::GRACE`] (a frozen link), the terminal is restored anyway.
pub struct StopOnSignal {
    key: u64,
    done: std::sync::Arc<std::sync::atomic::AtomicBool>,
}

impl StopOnSignal {
    /// How long a signal waits for the player to finish before restoring the terminal itself.
    pub const GRACE: std::time::Duration = std::time::Duration::from_secs(1);

    /// Sets `quit` on a signal, then waits for this value to be dropped.
    pub fn new(quit: std::sync::Arc<std::sync::atomic::AtomicBool>) -> StopOnSignal {
        let done = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let finished = std::sync::Arc::clone(&done);
        let key = add_hook(move || {
            quit.store(true, Ordering::SeqCst);
            let deadline = std::time::Instant::now() + Self::GRACE;
            while !finished.load(Ordering::SeqCst) && std::time::Instant::now() < deadline {
                std::thread::sleep(std::time::Duration::from_millis(5));
            }
            crate::term::tty::restore();
        });
        StopOnSignal { key, done }
    }
}

impl Drop for StopOnSignal {
    fn drop(&mut self) {
        // First say the player is done (a running hook may be waiting for it), then remove the
        // hook (which waits for running hooks to finish).
        self.done.store(true, Ordering::SeqCst);
        remove_hook(self.key);
    }
}

/// Remembers a temporary file to remove if a signal arrives before it is renamed.
pub fn register_temp_file(path: &Path) {
    if let Ok(mut files) = TEMP_FILES.lock() {
        files.push(path.to_owned());
    }
}

/// Forgets a temporary file (it was renamed or removed).
pub fn unregister_temp_file(path: &Path) {
    if let Ok(mut files) = TEMP_FILES.lock() {
        files.retain(|p| p != path);
    }
}

/// Registers a cleanup to run on a signal; returns a key for [`remove_hook`].
pub fn add_hook(hook: impl Fn() + Send + 'static) -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    let key = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    if let Ok(mut hooks) = HOOKS.lock() {
        hooks.push((key, Box::new(hook)));
    }
    key
}

/// Removes a cleanup registered with [`add_hook`].
pub fn remove_hook(key: u64) {
    if let Ok(mut hooks) = HOOKS.lock() {
        hooks.retain(|(k, _)| *k != key);
    }
}
