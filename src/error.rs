//! One error type for the whole program.
//!
//! Every variant renders as a single line that names the problem and, where there is one, the
//! fix. `main` prints it after `tidepool: ` and exits with status 2; a closed pipe on stdout
//! is not an error (see [`Error::is_broken_pipe`]).

use std::io;
use std::path::PathBuf;

/// Everything that can go wrong in tidepool, as one line of text for the user.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A flag's value is out of range or malformed: names the flag and the fix.
    #[error("{flag}: {message}")]
    InvalidArgument {
        /// The flag, e.g. `--size`.
        flag: &'static str,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// An input image could not be read or decoded.
    #[error("{flag} {path}: {message}")]
    Image {
        /// The flag that named the file.
        flag: &'static str,
        /// The file.
        path: PathBuf,
        /// What went wrong, with the fix.
        message: String,
    },
    /// Reading or writing a file failed.
    #[error("{action} {path}: {}", explain_io(action, source))]
    Io {
        /// What tidepool was doing: "cannot write", "cannot read"...
        action: &'static str,
        /// The file involved.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: io::Error,
    },
    /// Writing to standard output failed.
    #[error("cannot write to standard output: {0}")]
    Stdout(#[source] io::Error),
    /// A replay file (`--replay`) is malformed, truncated or of another version.
    #[error("{path}, line {line}: {message}")]
    Replay {
        /// The replay file.
        path: PathBuf,
        /// The line at fault, from 1.
        line: usize,
        /// What is wrong, with the fix.
        message: String,
    },
    /// Something the user asked for cannot be done in this situation.
    #[error("{0}")]
    Usage(String),
}

impl Error {
    /// Builds an [`Error::InvalidArgument`].
    pub fn arg(flag: &'static str, message: impl Into<String>) -> Self {
        Error::InvalidArgument { flag, message: message.into() }
    }

    /// Builds an [`Error::Io`] with what was being done to which file.
    pub fn io(action: &'static str, path: impl Into<PathBuf>, source: io::Error) -> Self {
        Error::Io { action, path: path.into(), source }
    }

    /// True when the error is a closed pipe on standard output (`tidepool ... | head`), which
    /// is how a reader says it has seen enough, not a failure.
    pub fn is_broken_pipe(&self) -> bool {
        matches!(self, Error::Stdout(e) if e.kind() == io::ErrorKind::BrokenPipe)
    }
}

/// The operating system's reason, with what to do about it for the errors users meet.
fn explain_io(action: &str, error: &io::Error) -> String {
    use io::ErrorKind::*;
    let writing = action.contains("write");
    match error.kind() {
        NotFound if writing => "the folder does not exist; create it or choose another path".into(),
        NotFound => "no such file; check the path".into(),
        PermissionDenied if writing => "permission denied; choose a folder you can write to".into(),
        PermissionDenied => "permission denied; check the file's permissions".into(),
        StorageFull => "no space left on the device; free some space or write somewhere else".into(),
        ReadOnlyFilesystem => "the file system is read-only; write somewhere else".into(),
        QuotaExceeded => "the disk quota is exhausted; free some space or write somewhere else".into(),
        IsADirectory => "it is a directory; give a file name".into(),
        _ => error.to_string(),
    }
}

/// The result type used throughout tidepool.
pub type Result<T, E = Error> = std::result::Result<T, E>;
