//! tmux passthrough: `ESC P tmux ; <sequence with every ESC doubled> ESC \`.
//!
//! tmux (3.3+ only with `set -g allow-passthrough on`) hands the inner sequence to the outer
//! terminal unchanged; without the option it drops it silently. Each escape sequence is wrapped
//! on its own: tmux buffers a passthrough sequence whole before forwarding it, so a kitty image
//! is wrapped chunk by chunk (each at most a few kilobytes), never as one multi-megabyte
//! sequence.

/// Start of a tmux passthrough sequence.
pub const PASSTHROUGH_BEGIN: &[u8] = b"\x1bPtmux;";
/// End of a tmux passthrough sequence (string terminator).
pub const PASSTHROUGH_END: &[u8] = b"\x1b\\";

/// Appends `inner` wrapped for tmux passthrough, every ESC in it doubled.
pub fn push_wrapped(out: &mut Vec<u8>, inner: &[u8]) {
    out.reserve(inner.len() + PASSTHROUGH_BEGIN.len() + PASSTHROUGH_END.len() + 8);
    out.extend_from_slice(PASSTHROUGH_BEGIN);
    let mut rest = inner;
    while let Some(i) = rest.iter().position(|&b| b == 0x1b) {
        out.extend_from_slice(&rest[..=i]);
        out.push(0x1b);
        rest = &rest[i + 1..];
    }
    out.extend_from_slice(rest);
    out.extend_from_slice(PASSTHROUGH_END);
}

/// `inner` wrapped for tmux passthrough.
#[cfg(test)]
pub fn wrap(inner: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    push_wrapped(&mut out, inner);
    out
}

#[cfg(any(test, feature = "testing"))]
/// Undoes [`wrap`]: the inner sequence of one passthrough sequence at the start of `bytes`
/// and the length it took, or `None` when `bytes` does not start with a whole one.
pub fn unwrap(bytes: &[u8]) -> Option<(Vec<u8>, usize)> {
    let body = bytes.strip_prefix(PASSTHROUGH_BEGIN)?;
    let mut inner = Vec::new();
    let mut i = 0;
    while i < body.len() {
        if body[i] == 0x1b {
            match body.get(i + 1) {
                Some(0x1b) => {
                    inner.push(0x1b);
                    i += 2;
                }
                Some(b'\\') => return Some((inner, PASSTHROUGH_BEGIN.len() + i + 2)),
                _ => return None,
            }
        } else {
            inner.push(body[i]);
            i += 1;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_inner_escape_is_doubled() {
        let inner = b"\x1b_Ga=d;\x1b\\";
        assert_eq!(wrap(inner), b"\x1bPtmux;\x1b\x1b_Ga=d;\x1b\x1b\\\x1b\\".to_vec());
        // An inner sequence with no ESC passes as it is.
        assert_eq!(wrap(b"abc"), b"\x1bPtmux;abc\x1b\\".to_vec());
    }

    #[test]
    fn unwrap_round_trips() {
        let inner = b"\x1b[c\x1b_Gi=31;AAAA\x1b\\\x1b\x1b";
        let mut stream = wrap(inner);
        let len = stream.len();
        stream.extend_from_slice(b"tail");
        assert_eq!(unwrap(&stream), Some((inner.to_vec(), len)));
        assert_eq!(unwrap(&stream[..len - 1]), None, "cut short");
    }
}
