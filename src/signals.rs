//! What happens on SIGINT, SIGTERM and SIGHUP: registered cleanups run (temporary files are
//! removed, the terminal is restored), then the process exits with 128 + the signal number
//! (130 for Ctrl-C), as shells expect.
//!
//! A dedicated thread receives the signals (via `signal-hook`), so the cleanups run in normal
//! code, not in a signal handler, and may take locks.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, Once};

type Hook = Box<dyn Fn() + Send>;

static TEMP_FILES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static HOOKS: Mutex<Vec<(u64, Hook)>> = Mutex::new(Vec::new());
static INSTALL: Once = Once::new();

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
                    run_cleanups();
                    std::process::exit(128 + signal);
                }
            })
            .ok();
    });
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
