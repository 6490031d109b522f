//! The command line's errors: the library's, with the flag that led to them in front.
//!
//! Every variant renders as a single line that names the problem and, where there is one, the
//! fix. `main` prints it after `tidepool: ` and exits with status 2.

use std::io;

/// Everything that can go wrong in a `tidepool` command, as one line of text for the user.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A flag's value is out of range, malformed or does not fit with another flag.
    #[error("{flag}: {message}")]
    Arg {
        /// The flag, e.g. `--size`.
        flag: &'static str,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// The library failed on something a flag named: `--background missing.png: no such file`.
    #[error("{flag} {source}")]
    Flag {
        /// The flag, e.g. `--background`.
        flag: &'static str,
        /// What went wrong.
        #[source]
        source: crate::Error,
    },
    /// The library failed.
    #[error(transparent)]
    Lib(#[from] crate::Error),
    /// Writing to standard output failed.
    #[error("cannot write to standard output: {0}")]
    Stdout(#[source] io::Error),
    /// Something the user asked for cannot be done in this situation.
    #[error("{0}")]
    Usage(String),
}

impl Error {
    /// Builds an [`Error::Arg`].
    pub fn arg(flag: &'static str, message: impl Into<String>) -> Self {
        Error::Arg { flag, message: message.into() }
    }

    /// A failed file operation: what was being done to which file.
    pub fn io(action: &'static str, path: impl Into<std::path::PathBuf>, source: io::Error) -> Self {
        Error::Lib(crate::Error::io(action, path, source))
    }

    /// An error of the library about something `flag` named.
    pub fn flag(flag: &'static str) -> impl FnOnce(crate::Error) -> Error {
        move |source| Error::Flag { flag, source }
    }

    /// True when the error is a closed pipe on standard output (`tidepool ... | head`), which
    /// is how a reader says it has seen enough, not a failure.
    pub fn is_broken_pipe(&self) -> bool {
        match self {
            Error::Stdout(e) => e.kind() == io::ErrorKind::BrokenPipe,
            Error::Lib(e) => e.is_broken_pipe(),
            _ => false,
        }
    }
}

impl From<crate::ValueError> for Error {
    fn from(e: crate::ValueError) -> Self {
        Error::Lib(e.into())
    }
}

/// The result type of the commands.
pub type Result<T, E = Error> = std::result::Result<T, E>;
