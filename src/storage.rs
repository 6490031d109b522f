//! Where a session saves files (screenshots, recordings): the library never writes a file on
//! its own, so a program that embeds the player decides where files go and how (the `tidepool`
//! binary writes them atomically and removes half-written ones on a signal; a server saves none).

use std::path::Path;

use crate::error::Result;

/// Saves whole files.
pub trait Storage: Send + Sync {
    /// Writes `bytes` to `path`, all or nothing.
    fn save(&self, path: &Path, bytes: &[u8]) -> Result<()>;

    /// Whether something is saved at `path` already (screenshots take the first free name).
    /// A storage that cannot tell says no.
    fn exists(&self, path: &Path) -> bool {
        let _ = path;
        false
    }
}
