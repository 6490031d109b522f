//! kitty's temporary files on disk: the one file of `src/output/` that touches the file system
//! (the import check's no-I/O list names it). The play session never calls it: its frames hand
//! the files out as data and the door writes them with [`write_new_file`]; the door also picks
//! the directory ([`temp_dir`]) and writes the probe's file. [`super::KittyEncoder`], for a
//! picture written once, writes its own.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use super::temp_file_path;

/// Where temporary files go: `/dev/shm` when it exists (memory, not disk), else the system's
/// temporary directory (which kitty also accepts).
pub fn temp_dir() -> PathBuf {
    let shm = Path::new("/dev/shm");
    if shm.is_dir() { shm.to_path_buf() } else { std::env::temp_dir() }
}

/// Writes `data` to a new file at `path` (an existing file of that name is not followed or
/// overwritten); a file written in part is removed.
pub fn write_new_file(path: &Path, data: &[u8]) -> io::Result<()> {
    let mut file = std::fs::OpenOptions::new().write(true).create_new(true).open(path)?;
    if let Err(e) = file.write_all(data) {
        let _ = std::fs::remove_file(path);
        return Err(e);
    }
    Ok(())
}

/// Writes `data` to temporary file `n` in `dir` (see [`write_new_file`]) and returns its path.
pub fn write_temp_file(dir: &Path, n: u64, data: &[u8]) -> io::Result<PathBuf> {
    let path = temp_file_path(dir, n);
    write_new_file(&path, data)?;
    Ok(path)
}
