//! `--authorized-keys FILE`: the OpenSSH-format list of public keys admitted when the pool is
//! private. A malformed file is an error at start, naming the line.

use std::fs;
use std::path::Path;

use russh::keys::PublicKey;
use russh::keys::ssh_key::authorized_keys::AuthorizedKeys;
use russh::keys::ssh_key::public::KeyData;

/// Largest authorized_keys file read (OpenSSH users rarely exceed a few KiB).
pub const MAX_AUTHORIZED_KEYS_FILE_BYTES: u64 = 1024 * 1024;
/// Most keys accepted in one file.
pub const MAX_AUTHORIZED_KEYS: usize = 10_000;

/// The admitted keys, compared by key material only (comments and options are ignored).
#[derive(Debug, Clone)]
pub struct AllowList {
    keys: Vec<KeyData>,
}

impl AllowList {
    /// Reads and fully validates the file; any bad line is an error.
    pub fn load(path: &Path) -> Result<Self, String> {
        let shown = path.display();
        let meta =
            fs::metadata(path).map_err(|e| format!("--authorized-keys {shown}: cannot read it ({e}); fix the path"))?;
        if meta.len() > MAX_AUTHORIZED_KEYS_FILE_BYTES {
            return Err(format!(
                "--authorized-keys {shown}: {} bytes is more than the {MAX_AUTHORIZED_KEYS_FILE_BYTES}-byte limit; trim the file",
                meta.len()
            ));
        }
        let text = fs::read_to_string(path)
            .map_err(|e| format!("--authorized-keys {shown}: cannot read it as text ({e}); fix the file"))?;
        Self::parse(&text).map_err(|e| format!("--authorized-keys {shown}: {e}"))
    }

    /// Parses authorized_keys text. Errors name the 1-based line number.
    pub fn parse(text: &str) -> Result<Self, String> {
        let mut keys = Vec::new();
        for (index, line) in text.lines().enumerate() {
            // Parse line by line so the error can name the line (AuthorizedKeys skips blanks/comments).
            for entry in AuthorizedKeys::new(line) {
                let entry = entry
                    .map_err(|e| format!("line {} is not an OpenSSH public key ({e}); fix or remove it", index + 1))?;
                keys.push(entry.public_key().key_data().clone());
                if keys.len() > MAX_AUTHORIZED_KEYS {
                    return Err(format!("more than {MAX_AUTHORIZED_KEYS} keys; trim the file"));
                }
            }
        }
        if keys.is_empty() {
            return Err("no keys in the file; add at least one `ssh-ed25519 AAAA…` line".into());
        }
        Ok(Self { keys })
    }

    /// Whether `key` is listed.
    pub fn admits(&self, key: &PublicKey) -> bool {
        self.keys.iter().any(|k| k == key.key_data())
    }

    /// Number of keys listed.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.keys.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use russh::keys::{Algorithm, PrivateKey};

    #[test]
    fn parses_keys_with_comments_and_options() {
        let k = PrivateKey::random(&mut rand_keys::rng(), Algorithm::Ed25519).unwrap();
        let line = k.public_key().to_openssh().unwrap();
        let text = format!("# players\n\nno-pty {line} alice@host\n");
        let list = AllowList::parse(&text).unwrap();
        assert_eq!(list.len(), 1);
        assert!(list.admits(k.public_key()));
        let other = PrivateKey::random(&mut rand_keys::rng(), Algorithm::Ed25519).unwrap();
        assert!(!list.admits(other.public_key()));
    }

    #[test]
    fn malformed_line_is_named() {
        let k = PrivateKey::random(&mut rand_keys::rng(), Algorithm::Ed25519).unwrap();
        let text = format!("{}\nssh-ed25519 not-base64!!\n", k.public_key().to_openssh().unwrap());
        let err = AllowList::parse(&text).unwrap_err();
        assert!(err.starts_with("line 2 "), "{err}");
    }

    #[test]
    fn empty_file_is_an_error() {
        assert!(AllowList::parse("# nothing\n").is_err());
    }
}
