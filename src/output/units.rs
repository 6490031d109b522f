//! Byte counts and rates for people, in one unit everywhere: SI kilobytes (1 kB = 1000 bytes).

#[cfg(any(feature = "player", test))]
use std::fmt::Write;

#[cfg(any(feature = "cli", feature = "testing", test))]
/// `850 B`, `12.3 kB`, `1.20 MB`.
pub fn human_bytes(bytes: u64) -> String {
    let mut text = String::new();
    write_human_bytes(&mut text, bytes);
    text
}

#[cfg(any(feature = "player", test))]
/// [`human_bytes`] into a reused buffer (appended; allocates nothing once it has grown).
pub fn write_human_bytes(out: &mut String, bytes: u64) {
    let b = bytes as f64;
    let _ = if b < 1e3 {
        write!(out, "{bytes} B")
    } else if b < 1e6 {
        write!(out, "{:.1} kB", b / 1e3)
    } else {
        write!(out, "{:.2} MB", b / 1e6)
    };
}

/// `12.3 kB/s`, into a reused buffer (cleared first).
#[cfg(any(feature = "player", test))]
pub fn write_human_rate(out: &mut String, bytes_per_second: u64) {
    out.clear();
    write_human_bytes(out, bytes_per_second);
    out.push_str("/s");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_unit() {
        assert_eq!(human_bytes(850), "850 B");
        assert_eq!(human_bytes(12_345), "12.3 kB");
        assert_eq!(human_bytes(1_200_000), "1.20 MB");
        let mut s = String::from("old");
        write_human_rate(&mut s, 12_345);
        assert_eq!(s, "12.3 kB/s");
    }
}
