//! What sits between the player and the screen ([`LinkPath`]): who answers the link's
//! question, and which question to ask.

use super::{PROBE, SCREEN_QUESTION, TMUX_QUESTION};

/// What sits between the player and the screen, as far as the player can tell
/// ([`LinkPath::detect`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LinkPath {
    /// The terminal at the far end answers (plain SSH, a local terminal, a multiplexer on this
    /// machine's own screen): the round trip measures the link.
    #[default]
    Direct,
    /// A multiplexer (`tmux`, `screen`, `zellij`) over SSH: it answers DA1 itself from its
    /// local pane, and its output goes into SSH's buffers unpaced. tmux and screen pass a
    /// wrapped question on to the terminal ([`LinkPath::question`]); zellij's link cannot be
    /// measured in band.
    Multiplexer(&'static str),
    /// mosh: mosh-server is the terminal; it answers DA1 at once and sends the client only the
    /// latest screen, paced to the link, so the program never sees the link. What it does see
    /// of the picture still crosses the link: each screen it sends carries every cell changed
    /// since the last one the client acknowledged.
    Mosh,
}

impl LinkPath {
    /// Reads the path from the environment (`var` looks a variable up) and the names of the
    /// process's ancestors, nearest first (`/proc/PID/comm` on Linux; none elsewhere).
    ///
    /// mosh sets nothing of its own in the environment (only `TERM` and
    /// `NCURSES_NO_UTF8_ACS`, and it removes `STY`), but `mosh-server` is the ancestor of every
    /// program it runs. A multiplexer counts only over SSH (`SSH_CONNECTION`, `SSH_CLIENT` or
    /// `SSH_TTY`, which tmux's default `update-environment` refreshes on every attach): on this
    /// machine's own screen its answers come from a local terminal anyway.
    pub fn detect<'a>(var: impl Fn(&str) -> Option<String>, ancestors: impl IntoIterator<Item = &'a str>) -> LinkPath {
        let set = |name: &str| var(name).is_some_and(|v| !v.is_empty());
        if ancestors.into_iter().any(|name| name.trim() == "mosh-server") {
            return LinkPath::Mosh;
        }
        let remote = set("SSH_CONNECTION") || set("SSH_CLIENT") || set("SSH_TTY");
        let multiplexer = [("TMUX", "tmux"), ("STY", "screen"), ("ZELLIJ", "zellij")]
            .into_iter()
            .find(|(variable, _)| set(variable))
            .map(|(_, name)| name);
        match multiplexer {
            Some(name) if remote => LinkPath::Multiplexer(name),
            _ => LinkPath::Direct,
        }
    }
}

impl LinkPath {
    /// The link's question on this path: DA1, or inside tmux and screen a device status
    /// report wrapped for their passthrough (answered by the terminal, not the multiplexer).
    pub fn question(self) -> &'static [u8] {
        match self {
            LinkPath::Multiplexer("tmux") => TMUX_QUESTION,
            LinkPath::Multiplexer("screen") => SCREEN_QUESTION,
            _ => PROBE,
        }
    }

    /// Whether the link's answers are device status reports (`ESC[0n`) rather than device
    /// attributes: the wrapped question.
    pub fn asks_status(self) -> bool {
        self.question() != PROBE
    }

    /// Whether an answer to the link's question comes from the terminal at the far end.
    pub(super) fn answered_at_far_end(self) -> bool {
        self == LinkPath::Direct || self.asks_status()
    }
}
