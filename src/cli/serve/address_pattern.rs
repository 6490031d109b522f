//! `from="pattern-list"` of an authorized_keys line: which client addresses may use the key.
//!
//! OpenSSH's rules (`match_host_and_ip`, sshd(8) "AUTHORIZED_KEYS FILE FORMAT"): a comma-separated
//! list of patterns, each an address, an address with the wildcards `*` and `?`, or a CIDR
//! network, any of them negated with a leading `!`. A client matching a negated pattern is
//! refused whatever else matches; otherwise it must match a positive one. tidepool never looks a
//! client's name up (as sshd with its default `UseDNS no`, where the "host name" is the address),
//! so a pattern that names hosts could never match: a list with one is refused when the file is
//! read, rather than silently admitting or refusing nobody (a negated host name would exclude no
//! one).

use std::net::IpAddr;
use std::str::FromStr;

use ipnet::IpNet;

/// The most patterns one `from=` list may hold.
pub const MAX_PATTERNS: usize = 256;

/// One pattern of the list.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Pattern {
    /// `10.0.0.0/8`, `2001:db8::/32`.
    Network(IpNet),
    /// `127.0.0.1`, `::1` (any spelling of the same address).
    Address(IpAddr),
    /// `192.168.1.*`, `10.0.0.?`: matched against the address as it is usually written (IPv4
    /// dotted, IPv6 in its shortest lower-case form).
    Wildcard(String),
}

/// A parsed `from=` list.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AddressPatterns {
    /// Each pattern and whether it is negated.
    patterns: Vec<(bool, Pattern)>,
}

impl FromStr for AddressPatterns {
    type Err = String;

    /// Parses the list (without its quotes). Errors say which pattern and why.
    fn from_str(list: &str) -> Result<Self, String> {
        let mut patterns = Vec::new();
        for item in list.split(',') {
            let (negated, text) = match item.strip_prefix('!') {
                Some(rest) => (true, rest),
                None => (false, item),
            };
            if text.is_empty() {
                return Err(format!("an empty pattern in from=\"{list}\""));
            }
            patterns.push((negated, parse_one(text)?));
            if patterns.len() > MAX_PATTERNS {
                return Err(format!("more than {MAX_PATTERNS} patterns in one from= list"));
            }
        }
        Ok(AddressPatterns { patterns })
    }
}

fn parse_one(text: &str) -> Result<Pattern, String> {
    if text.contains('/') {
        return IpNet::from_str(text)
            .map(|net| Pattern::Network(net.trunc()))
            .map_err(|_| format!("'{text}' is not a CIDR network such as 10.0.0.0/8"));
    }
    if let Ok(address) = IpAddr::from_str(text) {
        return Ok(Pattern::Address(address.to_canonical()));
    }
    let v6 = text.contains(':');
    let allowed =
        |c: char| c == '*' || c == '?' || c.is_ascii_digit() || c == '.' || (v6 && (c == ':' || c.is_ascii_hexdigit()));
    if text.contains(['*', '?']) && text.chars().all(allowed) {
        return Ok(Pattern::Wildcard(text.to_ascii_lowercase()));
    }
    Err(format!(
        "'{text}' is not an address, an address with * or ?, or a CIDR network (tidepool serve does not look up host names)"
    ))
}

impl AddressPatterns {
    /// Whether a client at `peer` may use the key (IPv4-mapped IPv6 addresses count as IPv4).
    pub fn admits(&self, peer: IpAddr) -> bool {
        let peer = peer.to_canonical();
        let written = peer.to_string();
        let mut admitted = false;
        for (negated, pattern) in &self.patterns {
            let matched = match pattern {
                Pattern::Network(net) => net.contains(&peer),
                Pattern::Address(address) => *address == peer,
                Pattern::Wildcard(glob) => wildcard_match(glob.as_bytes(), written.as_bytes()),
            };
            if matched && *negated {
                return false;
            }
            admitted |= matched;
        }
        admitted
    }
}

/// `*` (any run) and `?` (any one character), as OpenSSH's `match_pattern`.
fn wildcard_match(pattern: &[u8], text: &[u8]) -> bool {
    // Iterative with one backtrack point: linear in practice, never exponential.
    let (mut p, mut t) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while t < text.len() {
        match pattern.get(p) {
            Some(b'*') => {
                star = Some((p, t));
                p += 1;
            }
            Some(&c) if c == b'?' || c == text[t] => {
                p += 1;
                t += 1;
            }
            _ => match star {
                Some((sp, st)) => {
                    p = sp + 1;
                    t = st + 1;
                    star = Some((sp, st + 1));
                }
                None => return false,
            },
        }
    }
    pattern[p..].iter().all(|&c| c == b'*')
}

#[cfg(test)]
mod tests {
    use super::*;

    fn admits(list: &str, peer: &str) -> bool {
        list.parse::<AddressPatterns>().unwrap().admits(peer.parse().unwrap())
    }

    #[test]
    fn addresses_networks_and_wildcards_admit_and_a_negation_wins() {
        assert!(admits("127.0.0.1", "127.0.0.1"));
        assert!(!admits("127.0.0.2", "127.0.0.1"));
        assert!(admits("10.0.0.0/8", "10.200.3.4"));
        assert!(!admits("10.0.0.0/8", "11.0.0.1"));
        assert!(admits("192.168.1.*", "192.168.1.77"));
        assert!(!admits("192.168.1.*", "192.168.10.7"));
        assert!(admits("10.0.0.?", "10.0.0.7") && !admits("10.0.0.?", "10.0.0.17"));
        assert!(!admits("!127.0.0.1,127.0.0.0/8", "127.0.0.1"), "a negated match refuses");
        assert!(admits("!127.0.0.1,127.0.0.0/8", "127.0.0.2"));
        assert!(!admits("!10.0.0.0/8", "192.0.2.1"), "only negations: nobody is admitted");
        assert!(admits("2001:db8::/32", "2001:db8:1::5"));
        assert!(admits("0:0:0:0:0:0:0:1", "::1"), "any spelling of an address");
        assert!(admits("127.0.0.1", "::ffff:127.0.0.1"), "an IPv4-mapped client counts as IPv4");
        assert!(admits("fe80::*", "fe80::1"));
    }

    #[test]
    fn host_names_and_malformed_patterns_are_refused_with_the_reason() {
        for bad in ["*.example.com", "localhost", "10.0.0.0/33", "", "a,,b", "10.0.0.1/x"] {
            let err = bad.parse::<AddressPatterns>().unwrap_err();
            assert!(!err.is_empty(), "{bad}");
        }
        assert!("*.example.com".parse::<AddressPatterns>().unwrap_err().contains("host names"));
    }

    #[test]
    fn wildcards_match_as_openssh_does() {
        let m = |p: &str, t: &str| wildcard_match(p.as_bytes(), t.as_bytes());
        assert!(m("*", "") && m("*", "abc") && m("a*c", "abbbc") && m("a?c", "abc"));
        assert!(!m("a?c", "ac") && !m("a*d", "abc") && m("*.*.*.1", "10.0.0.1"));
    }
}
