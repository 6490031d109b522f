//! `--authorized-keys FILE`: the OpenSSH-format list of public keys admitted when the pool is
//! private. A malformed file is an error at start, naming the line.
//!
//! Options in front of a key are honoured as sshd honours them, or the file is refused at start
//! naming the line and the option: an admin who writes `from="10.0.0.0/8" ssh-ed25519 ...`
//! believes the key is confined, so no option may be read and ignored. Honoured: `from=` (see
//! [`super::address_pattern`]), `no-pty`, `restrict` and `pty` (a terminal is refused unless the
//! line allows one), and the restrictions tidepool applies to every key anyway (`no-agent-forwarding`,
//! `no-port-forwarding`, `no-X11-forwarding`, `no-user-rc`, `permitopen=`, `permitlisten=`:
//! nothing is ever forwarded and no rc file is run). Refused: everything that grants what
//! tidepool never gives or that it cannot check (`command=`, `environment=`, `expiry-time=`,
//! `cert-authority`, `principals=`, `tunnel=`, the forwarding grants, the FIDO flags).

use std::fs;
use std::net::IpAddr;
use std::path::Path;

use russh::keys::ssh_key::public::KeyData;
use russh::keys::{Algorithm, PublicKey};

use super::address_pattern::AddressPatterns;

/// Largest authorized_keys file read (OpenSSH users rarely exceed a few KiB).
pub const MAX_AUTHORIZED_KEYS_FILE_BYTES: u64 = 1024 * 1024;
/// Most keys accepted in one file.
pub const MAX_AUTHORIZED_KEYS: usize = 10_000;

/// One line of the file: a key and what its options allow.
#[derive(Debug, Clone)]
struct Line {
    /// 1-based, for the log.
    number: usize,
    key: KeyData,
    /// `from=`: the addresses the key may come from (`None`: any).
    from: Option<AddressPatterns>,
    /// Whether a pty may be had (`no-pty` and `restrict` without `pty` take it away).
    pty: bool,
}

/// What an admitted key may do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Grant {
    /// The line that admitted it (1-based).
    pub line: usize,
    /// Whether it may have a pty.
    pub pty: bool,
}

/// Why a listed key is not admitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refused {
    /// The key is not in the file.
    Unlisted,
    /// Every line with the key has a `from=` that does not admit the client (the first such line).
    From(usize),
}

/// The admitted keys, compared by key material only (comments are ignored).
#[derive(Debug, Clone)]
pub struct AllowList {
    lines: Vec<Line>,
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
        let mut lines = Vec::new();
        for (index, text) in text.lines().enumerate() {
            let number = index + 1;
            let text = text.trim();
            if text.is_empty() || text.starts_with('#') {
                continue;
            }
            // Split here rather than with ssh-key's reader: it takes `from="a" ssh-ed25519 AAAA`
            // (options, no comment) for a key and fails, and splits options at their first space.
            let (opts, key) = split_options(text);
            let key = PublicKey::from_openssh(key)
                .map_err(|e| format!("line {number} is not an OpenSSH public key ({e}); fix or remove it"))?;
            let (from, pty) = options(opts.map(split_commas).unwrap_or_default().into_iter())
                .map_err(|e| format!("line {number}: {e}"))?;
            lines.push(Line { number, key: key.key_data().clone(), from, pty });
            if lines.len() > MAX_AUTHORIZED_KEYS {
                return Err(format!("more than {MAX_AUTHORIZED_KEYS} keys; trim the file"));
            }
        }
        if lines.is_empty() {
            return Err("no keys in the file; add at least one `ssh-ed25519 AAAA…` line".into());
        }
        Ok(Self { lines })
    }

    /// Whether `key` may play from `peer`, and with what: the first line with the key whose
    /// `from=` admits the client (as sshd reads the file).
    pub fn admit(&self, key: &PublicKey, peer: IpAddr) -> Result<Grant, Refused> {
        let mut refused = Refused::Unlisted;
        for line in self.lines.iter().filter(|l| &l.key == key.key_data()) {
            if line.from.as_ref().is_none_or(|from| from.admits(peer)) {
                return Ok(Grant { line: line.number, pty: line.pty });
            }
            if refused == Refused::Unlisted {
                refused = Refused::From(line.number);
            }
        }
        Err(refused)
    }

    /// Number of keys listed.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.lines.len()
    }
}

/// A line's options (if any) and the key after them: options are the first word unless it is a
/// key type, and end at the first space outside quotes.
fn split_options(line: &str) -> (Option<&str>, &str) {
    let first = line.split_whitespace().next().unwrap_or("");
    if first.parse::<Algorithm>().is_ok() {
        return (None, line);
    }
    let mut quoted = false;
    let mut escaped = false;
    for (i, c) in line.char_indices() {
        match c {
            _ if escaped => escaped = false,
            '\\' => escaped = true,
            '"' => quoted = !quoted,
            ' ' | '\t' if !quoted => return (Some(&line[..i]), line[i..].trim_start()),
            _ => {}
        }
    }
    (Some(line), "")
}

/// Options split at commas outside quotes.
fn split_commas(options: &str) -> Vec<&str> {
    let mut out = Vec::new();
    let (mut start, mut quoted, mut escaped) = (0, false, false);
    for (i, c) in options.char_indices() {
        match c {
            _ if escaped => escaped = false,
            '\\' => escaped = true,
            '"' => quoted = !quoted,
            ',' if !quoted => {
                out.push(&options[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    out.push(&options[start..]);
    out
}

/// Reads a line's options: its `from=` list and whether it allows a pty; an option that is not
/// honoured is an error naming it and saying why.
fn options<'a>(options: impl Iterator<Item = &'a str>) -> Result<(Option<AddressPatterns>, bool), String> {
    let (mut from, mut pty) = (None, true);
    for option in options {
        let (name, value) = match option.split_once('=') {
            Some((name, value)) => (name, Some(value.trim_matches('"'))),
            None => (option, None),
        };
        let lower = name.to_ascii_lowercase();
        let why = match (lower.as_str(), value) {
            ("from", Some(list)) => {
                if from.is_some() {
                    return Err("two from= options; join their patterns with commas".into());
                }
                from = Some(list.parse::<AddressPatterns>().map_err(|e| format!("from=: {e}; fix the pattern"))?);
                continue;
            }
            ("restrict" | "no-pty", None) => {
                pty = false;
                continue;
            }
            ("pty", None) => {
                pty = true;
                continue;
            }
            // Never allowed for any key: honoured as they stand.
            ("no-agent-forwarding" | "no-port-forwarding" | "no-x11-forwarding" | "no-user-rc", None)
            | ("permitopen" | "permitlisten", Some(_)) => continue,
            ("command", _) => "it forces a command, and tidepool serve runs only the game",
            ("environment", _) => "it sets environment variables, and the game takes none",
            ("expiry-time", _) => "tidepool serve does not check key expiry",
            ("cert-authority" | "principals", _) => "tidepool serve does not accept certificates",
            ("agent-forwarding" | "port-forwarding" | "x11-forwarding" | "user-rc" | "tunnel", _) => {
                "it grants what tidepool serve never allows"
            }
            ("no-touch-required" | "verify-required", _) => "tidepool serve does not check FIDO key flags",
            _ => "tidepool serve does not know it",
        };
        let shown: String = name.chars().take(40).collect();
        return Err(format!("option '{shown}' is not honoured ({why}); remove it, or the line"));
    }
    Ok((from, pty))
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
        let here: IpAddr = "127.0.0.1".parse().unwrap();
        assert_eq!(list.admit(k.public_key(), here), Ok(Grant { line: 3, pty: false }));
        let other = PrivateKey::random(&mut rand_keys::rng(), Algorithm::Ed25519).unwrap();
        assert_eq!(list.admit(other.public_key(), here), Err(Refused::Unlisted));
    }

    #[test]
    fn malformed_line_is_named() {
        let k = PrivateKey::random(&mut rand_keys::rng(), Algorithm::Ed25519).unwrap();
        let text = format!("{}\nssh-ed25519 not-base64!!\n", k.public_key().to_openssh().unwrap());
        let err = AllowList::parse(&text).unwrap_err();
        assert!(err.starts_with("line 2 "), "{err}");
    }

    #[test]
    fn from_confines_a_key_and_the_first_line_that_admits_it_decides() {
        let k = PrivateKey::random(&mut rand_keys::rng(), Algorithm::Ed25519).unwrap();
        let key = k.public_key().to_openssh().unwrap();
        let text = format!("from=\"127.0.0.2\" {key}\nrestrict,pty,from=\"!10.0.0.1,10.0.0.0/8\" {key}\n");
        let list = AllowList::parse(&text).unwrap();
        let at = |ip: &str| list.admit(k.public_key(), ip.parse().unwrap());
        assert_eq!(at("127.0.0.1"), Err(Refused::From(1)));
        assert_eq!(at("127.0.0.2"), Ok(Grant { line: 1, pty: true }));
        assert_eq!(at("10.9.9.9"), Ok(Grant { line: 2, pty: true }));
        assert_eq!(at("10.0.0.1"), Err(Refused::From(1)));
    }

    #[test]
    fn an_option_that_is_not_honoured_names_the_line_and_the_option() {
        let k = PrivateKey::random(&mut rand_keys::rng(), Algorithm::Ed25519).unwrap();
        let key = k.public_key().to_openssh().unwrap();
        for (option, why) in [
            ("command=\"/bin/sh -c 'a, b'\"", "forces a command"),
            ("environment=\"A=b\"", "environment"),
            ("expiry-time=\"20300101\"", "expiry"),
            ("agent-forwarding", "never allows"),
            ("from=\"*.example.com\"", "host names"),
            ("no-such-thing", "does not know"),
        ] {
            let err = AllowList::parse(&format!("# ok\n{key}\n{option} {key} a comment\n")).unwrap_err();
            assert!(err.starts_with("line 3: ") && err.contains(why), "{option}: {err}");
        }
        for fine in
            ["no-port-forwarding,no-X11-forwarding,no-agent-forwarding,no-user-rc", "permitopen=\"a:1\"", "no-pty"]
        {
            assert!(AllowList::parse(&format!("{fine} {key}\n")).is_ok(), "{fine}");
        }
    }

    #[test]
    fn empty_file_is_an_error() {
        assert!(AllowList::parse("# nothing\n").is_err());
    }
}
