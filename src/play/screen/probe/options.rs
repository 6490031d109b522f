//! `ProbeOptions`'s builders: what a caller driving a `Session` on a stream of its own says
//! about the terminal at the other end. The hints and the window size are crate-private types
//! (the doors fill them from the environment and TIOCGWINSZ); a caller gives plain numbers and
//! an environment lookup, so neither type is part of the API.

use std::path::PathBuf;

use super::{EnvHints, ProbeOptions, WinSize};

impl ProbeOptions {
    /// A terminal of `cols` x `rows` cells and `x_px` x `y_px` pixels (0 when the terminal does
    /// not say), as TIOCGWINSZ or SSH's window-change request gives it: the pixels give the
    /// cell size where the terminal does not answer the size query. No environment hints, no
    /// file-medium query.
    pub fn new(cols: u16, rows: u16, x_px: u16, y_px: u16) -> ProbeOptions {
        ProbeOptions { winsize: WinSize { cols, rows, x_px, y_px }, ..ProbeOptions::default() }
    }

    /// Reads the terminal's environment through `var` (`|name| std::env::var(name).ok()` for
    /// this process's terminal): `TMUX` (the queries go through tmux), `SSH_CONNECTION` or
    /// `SSH_TTY` (a remote terminal: no file-medium query) and `TERM_PROGRAM` (a fallback hint
    /// where no answer comes).
    pub fn with_env(mut self, var: impl Fn(&str) -> Option<String>) -> ProbeOptions {
        self.env = EnvHints::from_lookup(var);
        self
    }

    /// The terminal is at the far end of a network connection (what `tidepool serve` says of
    /// every player): it cannot read this machine's files, so the file-medium query is skipped.
    pub fn over_ssh(mut self) -> ProbeOptions {
        self.env.ssh = true;
        self
    }

    /// Asks whether kitty reads pictures from files, with `path`: a temporary file holding one
    /// RGB pixel (3 bytes) whose name carries `TEMP_FILE_MARKER`. The caller writes it before
    /// the probe and removes it after if the terminal did not. Ignored over SSH.
    pub fn with_kitty_file(mut self, path: PathBuf) -> ProbeOptions {
        self.kitty_file = Some(path);
        self
    }
}

#[cfg(test)]
mod tests {
    use super::super::{EnvHints, ProbeOptions, WinSize};

    /// The builders give the options the doors build field by field (the SSH door's and the
    /// terminal door's), so a caller's probe asks what theirs ask.
    #[test]
    fn the_builders_make_the_doors_options() {
        let ssh = ProbeOptions::new(80, 24, 640, 384).over_ssh();
        let door = ProbeOptions {
            env: EnvHints { ssh: true, ..EnvHints::default() },
            winsize: WinSize { cols: 80, rows: 24, x_px: 640, y_px: 384 },
            kitty_file: None,
            colours: false,
        };
        assert_eq!(ssh, door);
        let vars = |name: &str| match name {
            "TMUX" => Some("/tmp/tmux-0/default,1,0".to_string()),
            "TERM_PROGRAM" => Some("WezTerm".to_string()),
            _ => None,
        };
        let local = ProbeOptions::new(100, 40, 0, 0).with_env(vars).with_kitty_file("/dev/shm/x.rgb".into());
        assert_eq!(local.env, EnvHints::from_lookup(vars));
        assert!(local.env.tmux && !local.env.ssh);
        assert_eq!(local.env.term_program.as_deref(), Some("WezTerm"));
        assert_eq!(local.kitty_file.as_deref(), Some(std::path::Path::new("/dev/shm/x.rgb")));
        assert_eq!(local.winsize.cell_px(), None, "no pixels: no cell size");
        assert_eq!(ProbeOptions::new(100, 40, 1000, 800).winsize.cell_px(), Some((10, 20)));
    }
}
