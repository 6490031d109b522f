//! The server's ed25519 host key: created on first start, kept in OpenSSH format with 0600
//! permissions, loaded again after a restart so clients' known_hosts entries stay valid.

use std::fs;
use std::io::Write;
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

use russh::keys::ssh_key::LineEnding;
use russh::keys::{Algorithm, HashAlg, PrivateKey};

/// Largest host key file we read (an ed25519 key is ~400 bytes; RSA-16384 ~12 KiB).
pub const MAX_HOST_KEY_FILE_BYTES: u64 = 64 * 1024;

/// Comment stored in a generated key; `ssh-keygen -lf` prints it.
pub const HOST_KEY_COMMENT: &str = "tidepool serve host key";

/// Permission bits that must be clear on the key file (group and other access).
const LOOSE_PERMISSION_BITS: u32 = 0o077;

/// What happened when the host key was resolved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Origin {
    /// The file existed and was loaded.
    Loaded,
    /// The file was missing and a new key was written.
    Created,
}

/// One-line, user-facing host key error (names the file and the fix).
#[derive(Debug)]
pub struct HostKeyError(pub String);

impl std::fmt::Display for HostKeyError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for HostKeyError {}

/// Loads the key at `path`, or creates it (and its parent folder) when the file does not exist.
pub fn load_or_create(path: &Path) -> Result<(PrivateKey, Origin), HostKeyError> {
    match fs::symlink_metadata(path) {
        Ok(_) => load(path).map(|k| (k, Origin::Loaded)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => create(path).map(|k| (k, Origin::Created)),
        Err(e) => Err(HostKeyError(format!(
            "--host-key {}: cannot read it ({e}); fix the path or its folder's permissions",
            path.display()
        ))),
    }
}

/// Loads an existing key, refusing loose permissions, oversized files, garbage and encrypted keys.
pub fn load(path: &Path) -> Result<PrivateKey, HostKeyError> {
    let shown = path.display();
    let meta = fs::metadata(path)
        .map_err(|e| HostKeyError(format!("--host-key {shown}: cannot read it ({e}); fix the path")))?;
    if !meta.is_file() {
        return Err(HostKeyError(format!(
            "--host-key {shown}: not a regular file; point it at an OpenSSH private key file"
        )));
    }
    let mode = meta.mode() & 0o777;
    if mode & LOOSE_PERMISSION_BITS != 0 {
        return Err(HostKeyError(format!(
            "--host-key {shown}: permissions {mode:04o} are too open; run `chmod 600 {shown}`"
        )));
    }
    if meta.len() > MAX_HOST_KEY_FILE_BYTES {
        return Err(HostKeyError(format!(
            "--host-key {shown}: {} bytes is too large for a private key; point it at an OpenSSH private key file",
            meta.len()
        )));
    }
    let text = fs::read(path).map_err(|e| HostKeyError(format!("--host-key {shown}: cannot read it ({e})")))?;
    let key = PrivateKey::from_openssh(&text).map_err(|e| {
        HostKeyError(format!(
            "--host-key {shown}: not an OpenSSH private key ({e}); delete it to generate a new one, or point it elsewhere"
        ))
    })?;
    if key.is_encrypted() {
        return Err(HostKeyError(format!(
            "--host-key {shown}: the key is passphrase-protected; remove the passphrase with `ssh-keygen -p -f {shown}`"
        )));
    }
    Ok(key)
}

/// Generates an ed25519 key and writes it atomically: a 0600 temporary file in the same folder,
/// fsynced, then hard-linked into place (fails instead of overwriting if another process won).
fn create(path: &Path) -> Result<PrivateKey, HostKeyError> {
    let shown = path.display();
    let mut key = PrivateKey::random(&mut rand_keys::rng(), Algorithm::Ed25519)
        .map_err(|e| HostKeyError(format!("--host-key {shown}: key generation failed ({e})")))?;
    key.set_comment(HOST_KEY_COMMENT);
    let pem = key
        .to_openssh(LineEnding::LF)
        .map_err(|e| HostKeyError(format!("--host-key {shown}: cannot encode the key ({e})")))?;

    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        // Folders we create are private (0700); existing folders are left as they are.
        use std::os::unix::fs::DirBuilderExt;
        fs::DirBuilder::new().recursive(true).mode(0o700).create(dir).map_err(|e| {
            HostKeyError(format!("--host-key {shown}: cannot create its folder ({e}); choose a writable path"))
        })?;
    }
    let tmp = temp_sibling(path);
    let write = || -> std::io::Result<()> {
        let mut file = fs::OpenOptions::new().write(true).create_new(true).mode(0o600).open(&tmp)?;
        file.write_all(pem.as_bytes())?;
        file.sync_all()?;
        fs::hard_link(&tmp, path)?;
        Ok(())
    };
    let result = write();
    let _ = fs::remove_file(&tmp);
    result.map_err(|e| {
        HostKeyError(format!("--host-key {shown}: cannot write the new key ({e}); choose a writable path"))
    })?;
    Ok(key)
}

fn temp_sibling(path: &Path) -> PathBuf {
    let mut name = path.file_name().map(|n| n.to_os_string()).unwrap_or_default();
    name.push(format!(".tmp-{}", std::process::id()));
    path.with_file_name(name)
}

/// The line `ssh-keygen -lf FILE` prints for this key: `256 SHA256:… comment (ED25519)`.
pub fn fingerprint_line(key: &PrivateKey) -> String {
    let public = key.public_key();
    let bits = key_bits(key);
    let comment = if public.comment().is_empty() { "no comment".to_string() } else { public.comment().to_string() };
    let kind = match public.algorithm() {
        Algorithm::Ed25519 => "ED25519".to_string(),
        Algorithm::Rsa { .. } => "RSA".to_string(),
        Algorithm::Ecdsa { .. } => "ECDSA".to_string(),
        other => other.as_str().to_uppercase(),
    };
    format!("{bits} {} {comment} ({kind})", public.fingerprint(HashAlg::Sha256))
}

fn key_bits(key: &PrivateKey) -> u32 {
    match key.algorithm() {
        Algorithm::Ed25519 => 256,
        Algorithm::Ecdsa { curve } => match curve.as_str() {
            "nistp256" => 256,
            "nistp384" => 384,
            _ => 521,
        },
        Algorithm::Rsa { .. } => key
            .key_data()
            .rsa()
            .map(|k| (k.public().n().as_positive_bytes().map(|b| b.len()).unwrap_or(0) * 8) as u32)
            .unwrap_or(0),
        _ => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::PermissionsExt;

    #[test]
    fn created_key_is_0600_and_reloads_identically() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub/host_key");
        let (k1, o1) = load_or_create(&path).unwrap();
        assert_eq!(o1, Origin::Created);
        assert_eq!(fs::metadata(&path).unwrap().mode() & 0o777, 0o600);
        let (k2, o2) = load_or_create(&path).unwrap();
        assert_eq!(o2, Origin::Loaded);
        assert_eq!(k1.public_key().key_data(), k2.public_key().key_data());
        assert!(fingerprint_line(&k2).starts_with("256 SHA256:"));
        assert!(fingerprint_line(&k2).ends_with(" tidepool serve host key (ED25519)"));
    }

    #[test]
    fn loose_permissions_are_refused_with_the_fix() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("host_key");
        load_or_create(&path).unwrap();
        fs::set_permissions(&path, fs::Permissions::from_mode(0o644)).unwrap();
        let err = load_or_create(&path).unwrap_err().0;
        assert!(err.contains("0644") && err.contains("chmod 600"), "{err}");
        assert!(!err.contains('\n'));
    }

    #[test]
    fn garbage_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("host_key");
        fs::OpenOptions::new().write(true).create_new(true).mode(0o600).open(&path).unwrap();
        fs::write(&path, b"this is not a key\n").unwrap();
        let err = load_or_create(&path).unwrap_err().0;
        assert!(err.contains("not an OpenSSH private key"), "{err}");
        assert!(!err.contains('\n'));
    }
}
