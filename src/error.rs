//! The library's errors: typed, one line each, with the operating system's error kept as the
//! source where there is one.
//!
//! Nothing here names a command-line flag: the `tidepool` binary adds the flag in front of the
//! message (`--background missing.png: no such file; check the path`), so a program that
//! embeds the library gets the same plain explanation without flags it does not have.

use std::io;
use std::path::PathBuf;

/// A value outside what tidepool accepts, or text that does not parse as one: says what is
/// wrong and how to fix it. Domain types return it from their checked constructors and
/// `FromStr`; the command line and the replay reader only add where the value came from.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{message}")]
pub struct ValueError {
    what: &'static str,
    message: String,
}

impl ValueError {
    /// An error about `what` (e.g. `"stone radius"`) explained by `message`.
    pub fn new(what: &'static str, message: impl Into<String>) -> ValueError {
        ValueError { what, message: message.into() }
    }

    /// Which value was wrong, e.g. `"stone radius"`.
    pub fn what(&self) -> &'static str {
        self.what
    }
}

/// Everything that can go wrong in the library.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A value is out of range or malformed.
    #[error(transparent)]
    Value(#[from] ValueError),
    /// An image file could not be read or decoded: names the file and the fix.
    #[error("{}: {problem}", path.display())]
    Image {
        /// The file.
        path: PathBuf,
        /// What went wrong, with the fix.
        problem: String,
    },
    /// Reading or writing a file failed.
    #[error("{action} {}: {}", path.display(), explain_io(action, source))]
    Io {
        /// What was being done: "cannot write", "cannot read"...
        action: &'static str,
        /// The file involved.
        path: PathBuf,
        /// The operating system's error.
        #[source]
        source: io::Error,
    },
    /// A replay file is malformed, truncated, of another version or over a limit.
    #[error("{}, line {line}: {message}", path.display())]
    Replay {
        /// The replay file.
        path: PathBuf,
        /// The line at fault, from 1.
        line: usize,
        /// What is wrong, with the fix.
        message: String,
    },
    /// A picture or simulation of this size cannot be allocated.
    #[error("cannot allocate a {width}x{height} {what}")]
    TooLarge {
        /// What was being made: "picture", "pool", "sea", "lake".
        what: &'static str,
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
    },
    /// Talking to the terminal failed.
    #[error("{action}: {source}")]
    Terminal {
        /// What the player was doing: "cannot read the terminal", "cannot set up the terminal"...
        action: &'static str,
        /// The operating system's error.
        #[source]
        source: io::Error,
    },
    /// Writing frames to the terminal (or whatever stream the player draws on) failed.
    #[error("cannot write to the terminal: {0}")]
    Output(#[source] io::Error),
}

impl Error {
    /// Builds an [`Error::Io`] with what was being done to which file.
    pub fn io(action: &'static str, path: impl Into<PathBuf>, source: io::Error) -> Self {
        Error::Io { action, path: path.into(), source }
    }

    /// True when the error is a closed pipe on the output (`tidepool ... | head`, a client that
    /// went away), which is how a reader says it has seen enough, not a failure.
    pub fn is_broken_pipe(&self) -> bool {
        matches!(self, Error::Output(e) if e.kind() == io::ErrorKind::BrokenPipe)
    }
}

/// The operating system's reason, with what to do about it for the errors users meet.
pub fn explain_io(action: &str, error: &io::Error) -> String {
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

/// The result type of the library.
pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_the_file_and_keep_the_source() {
        let e = Error::io("cannot write", "a/b.png", io::Error::from(io::ErrorKind::NotFound));
        assert_eq!(e.to_string(), "cannot write a/b.png: the folder does not exist; create it or choose another path");
        assert!(std::error::Error::source(&e).is_some(), "the io::Error is kept");
        let e = Error::Terminal { action: "cannot read the terminal", source: io::Error::other("gone") };
        assert_eq!(e.to_string(), "cannot read the terminal: gone");
        assert!(std::error::Error::source(&e).is_some());
        let e = Error::TooLarge { what: "pool", width: 3, height: 4 };
        assert_eq!(e.to_string(), "cannot allocate a 3x4 pool");
        assert!(Error::Output(io::Error::from(io::ErrorKind::BrokenPipe)).is_broken_pipe());
        assert_eq!(Error::from(ValueError::new("x", "bad x")).to_string(), "bad x");
    }
}
