//! Writing files so that a failure never leaves a partial or clobbered file: the bytes go to
//! a temporary file in the same folder, which is renamed over the target only when complete.

use std::fs::OpenOptions;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::cli::error::{Error, Result};
use crate::cli::signals;

/// Writes `bytes` to `path` atomically.
///
/// The temporary file (`.NAME.tidepool-PID.tmp` beside the target) is registered with
/// [`signals`], so Ctrl-C or SIGTERM mid-write removes it. On any error the temporary file is
/// removed and an existing file at `path` is left as it was.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    // A device, FIFO or socket (`/dev/null`, `/dev/stdout`, a named pipe) is written as it is:
    // renaming a file over it would replace the device node itself.
    if let Ok(meta) = std::fs::metadata(path)
        && !meta.is_file()
        && !meta.is_dir()
    {
        let mut file = OpenOptions::new().write(true).open(path).map_err(|e| Error::io("cannot write", path, e))?;
        return file.write_all(bytes).and_then(|()| file.flush()).map_err(|e| Error::io("cannot write", path, e));
    }
    let temp = temp_path(path)?;
    signals::register_temp_file(&temp);
    let result = write_then_rename(&temp, path, bytes);
    if result.is_err() {
        let _ = std::fs::remove_file(&temp);
    }
    signals::unregister_temp_file(&temp);
    result
}

/// Whether a file could ever be written at `path` (a file name in an existing folder); checked
/// before a session starts, so `--record` fails on a normal screen, not at the end of play.
pub fn check_writable(path: &Path) -> std::result::Result<(), String> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if path.is_dir() || !dir.is_dir() {
        return Err(format!("cannot write {}: give a file in an existing folder", path.display()));
    }
    Ok(())
}

/// The player's screenshots and recordings, written like every other file: atomically, and
/// removed if a signal arrives mid-write.
pub struct AtomicStorage;

impl crate::storage::Storage for AtomicStorage {
    fn save(&self, path: &Path, bytes: &[u8]) -> crate::Result<()> {
        write_file(path, bytes).map_err(|e| match e {
            Error::Lib(e) => e,
            other => crate::Error::io("cannot write", path, std::io::Error::other(other.to_string())),
        })
    }

    fn exists(&self, path: &Path) -> bool {
        path.exists()
    }
}

/// A file written in pieces (an animation, frame by frame) that appears under its name only
/// when [`AtomicFile::commit`] is called; dropped without a commit, it leaves nothing behind.
#[derive(Debug)]
pub struct AtomicFile {
    path: PathBuf,
    temp: PathBuf,
    file: Option<std::io::BufWriter<std::fs::File>>,
}

impl AtomicFile {
    /// Starts writing `path` (checks the folder first; the bytes go to a temporary file).
    pub fn create(path: &Path) -> Result<AtomicFile> {
        let temp = temp_path(path)?;
        signals::register_temp_file(&temp);
        let file = OpenOptions::new().write(true).create_new(true).open(&temp).map_err(|e| {
            signals::unregister_temp_file(&temp);
            Error::io("cannot write", path, e)
        })?;
        Ok(AtomicFile { path: path.to_owned(), temp, file: Some(std::io::BufWriter::new(file)) })
    }

    /// Flushes, syncs and renames the file into place.
    pub fn commit(mut self) -> Result<()> {
        let file = self.file.take().expect("a file until committed");
        let io = |e| Error::io("cannot write", &self.path, e);
        let file = file.into_inner().map_err(|e| io(e.into_error()))?;
        file.sync_all().map_err(io)?;
        drop(file);
        if self.path.is_dir() {
            return Err(Error::Usage(format!(
                "cannot write {}: it is a directory; give a file name",
                self.path.display()
            )));
        }
        std::fs::rename(&self.temp, &self.path).map_err(io)
    }
}

impl std::io::Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.file.as_mut().expect("a file until committed").write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.file.as_mut().expect("a file until committed").flush()
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        // Committed or not, the temporary name is gone afterwards.
        drop(self.file.take());
        let _ = std::fs::remove_file(&self.temp);
        signals::unregister_temp_file(&self.temp);
    }
}

fn write_then_rename(temp: &Path, path: &Path, bytes: &[u8]) -> Result<()> {
    let mut file =
        OpenOptions::new().write(true).create_new(true).open(temp).map_err(|e| Error::io("cannot write", path, e))?;
    file.write_all(bytes).map_err(|e| Error::io("cannot write", path, e))?;
    // Flush to the device so a full disk reports here, not silently at close.
    file.sync_all().map_err(|e| Error::io("cannot write", path, e))?;
    drop(file);
    if path.is_dir() {
        return Err(Error::Usage(format!("cannot write {}: it is a directory; give a file name", path.display())));
    }
    std::fs::rename(temp, path).map_err(|e| Error::io("cannot write", path, e))
}

/// The temporary name beside `path`, after checking that the folder exists.
fn temp_path(path: &Path) -> Result<PathBuf> {
    let name =
        path.file_name().ok_or_else(|| Error::Usage(format!("cannot write {}: not a file name", path.display())))?;
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        let what = if dir.exists() { "is not a directory" } else { "does not exist" };
        return Err(Error::Usage(format!(
            "cannot write {}: the folder {} {what}; create it or choose another --out",
            path.display(),
            dir.display()
        )));
    }
    let mut temp_name = std::ffi::OsString::from(".");
    temp_name.push(name);
    temp_name.push(format!(".tidepool-{}.tmp", std::process::id()));
    Ok(dir.join(temp_name))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("tidepool-atomic-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn writes_and_replaces_without_leftovers() {
        let dir = scratch("replace");
        let target = dir.join("out.bin");
        write_file(&target, b"first").unwrap();
        write_file(&target, b"second").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"second");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "no temporary file left");
    }

    #[test]
    fn a_missing_folder_is_a_clear_error() {
        let dir = scratch("missing");
        let err = write_file(&dir.join("nope/out.png"), b"x").unwrap_err().to_string();
        assert!(err.contains("does not exist") && err.contains("--out"), "{err}");
    }

    #[test]
    fn a_directory_target_is_refused_and_kept() {
        let dir = scratch("dir");
        let target = dir.join("taken");
        std::fs::create_dir(&target).unwrap();
        let err = write_file(&target, b"x").unwrap_err().to_string();
        assert!(err.contains("directory"), "{err}");
        assert!(target.is_dir());
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "no temporary file left");
    }

    #[test]
    fn streamed_files_appear_only_when_committed() {
        use std::io::Write;
        let dir = scratch("streamed");
        let target = dir.join("anim.gif");
        std::fs::write(&target, b"old").unwrap();
        {
            let mut file = AtomicFile::create(&target).unwrap();
            file.write_all(b"half an animation").unwrap();
            // Dropped without commit: an error or Ctrl-C half way.
        }
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "no temporary file left");
        let mut file = AtomicFile::create(&target).unwrap();
        file.write_all(b"new").unwrap();
        file.commit().unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
    }

    #[test]
    fn devices_are_written_in_place_never_replaced() {
        write_file(Path::new("/dev/null"), b"into the void").unwrap();
        let meta = std::fs::metadata("/dev/null").unwrap();
        assert!(!meta.is_file(), "/dev/null is still a device");
        let err = write_file(Path::new("/dev/full"), b"no room").unwrap_err().to_string();
        assert!(err.contains("no space left on the device"), "{err}");
    }

    #[test]
    fn a_full_disk_leaves_the_old_file() {
        // /dev/full is a character device, so the temporary file cannot be created there; the
        // important part is that the error is reported and nothing is clobbered.
        let err = write_file(Path::new("/dev/full/x.png"), b"x");
        assert!(err.is_err());
    }
}
