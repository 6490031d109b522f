//! `tidepool serve`: its flags. Values that need more than a type (an address, a count in a
//! range, a file) are checked in `commands::serve`, so each bad value is one line naming the
//! flag and the fix.

use std::path::PathBuf;

use crate::size::Size;
use clap::Args;

use super::{PlayScene, parse_size};

const SERVE_HELP: &str = "\
Everyone who connects plays in the same water: stones, clicks, drags and the scene keys (wind,
rain, clear, pause, tab) act on the one shared scene; `s` (screenshots) is off for remote
players. Exec, sftp, port, agent and X11 forwarding are refused.

Examples:
  tidepool serve                                # localhost:2222; then: ssh -p 2222 localhost
  tidepool serve --listen 0.0.0.0:2222          # open to the network
  tidepool serve --authorized-keys ~/.ssh/authorized_keys   # only these keys may play";

/// `tidepool serve`.
#[derive(Args, Debug, Clone)]
#[command(after_help = SERVE_HELP)]
pub struct ServeCommand {
    /// Address and port to listen on; anything beyond localhost must be asked for
    /// (`0.0.0.0:2222`). Port 0 picks a free port (printed at start).
    #[arg(long, value_name = "ADDR:PORT", default_value = "127.0.0.1:2222")]
    pub listen: String,

    /// The server's ed25519 host key (OpenSSH format, mode 0600), created when missing.
    /// [default: tidepool/serve_host_ed25519_key in the data folder: $XDG_DATA_HOME or
    /// ~/.local/share]
    #[arg(long, value_name = "FILE")]
    pub host_key: Option<PathBuf>,

    /// Admit only the public keys in this file (OpenSSH authorized_keys format); without it
    /// anyone may play, with any key or none.
    #[arg(long, value_name = "FILE")]
    pub authorized_keys: Option<PathBuf>,

    /// Players at once; the next one is told "the pool is full, try again later".
    #[arg(long, value_name = "N", default_value_t = 64)]
    pub max_clients: u64,

    /// Connections from one IP address at once (handshaking or playing).
    #[arg(long, value_name = "N", default_value_t = 8)]
    pub max_per_address: u64,

    /// Milliseconds from connecting until the game starts (key exchange, authentication, pty,
    /// shell); slower connections are dropped.
    #[arg(long, value_name = "MS", default_value_t = 10_000)]
    pub handshake_timeout_ms: u64,

    /// Milliseconds without a key press or click before a player is sent home.
    #[arg(long, value_name = "MS", default_value_t = 600_000)]
    pub idle_timeout_ms: u64,

    /// Milliseconds one frame may wait for a client that does not read before it is cut.
    #[arg(long, value_name = "MS", default_value_t = 20_000)]
    pub stall_timeout_ms: u64,

    /// Stones, clicks and drags one player may make per second; the rest are dropped.
    #[arg(long, value_name = "N", default_value_t = 30)]
    pub actions_per_second: u64,

    /// Scene keys (rain, clear, damping, pause, wind, tab) one player may press per second; the
    /// rest are dropped (each costs the shared game thread more than a stone). All players
    /// together get 8 a second.
    #[arg(long, value_name = "N", default_value_t = 4)]
    pub scene_keys_per_second: u64,

    /// Bytes per second each player's link gets: auto finds each player's own rate from the
    /// terminal's answers (as `play` does); a number (suffixes k and M) fixes it; unlimited.
    #[arg(long, value_name = "BYTES/s|auto|unlimited", default_value = "auto", value_parser = super::parse_bandwidth)]
    pub client_bandwidth: crate::play::Bandwidth,

    /// Do not offer compression. By default a client that asks for it (`ssh -C`) gets
    /// zlib@openssh.com, which starts after authentication: fewer bytes on its link, about
    /// 300 kB more server memory and some CPU per such player.
    #[arg(long)]
    pub no_compression: bool,

    /// Bytes per second for all players together; beyond it frames are skipped.
    #[arg(long, value_name = "BYTES/s", default_value = "16M", value_parser = super::parse_bps)]
    pub total_bandwidth: u64,

    /// The shared scene's size in pixels; each player sees it scaled to their terminal
    /// (a terminal cell is one pixel wide and two tall).
    #[arg(long, value_name = "WxH", default_value = "160x90", value_parser = parse_size)]
    pub size: Size,

    /// Frames per second sent to each player (1..=60); the simulation keeps its own clock.
    #[arg(long, value_name = "N", default_value_t = 30)]
    pub fps: u32,

    /// The scene to start with (`tab` switches, for everyone).
    #[arg(long, value_enum, default_value = "pool")]
    pub scene: PlayScene,

    /// The scenes' water, wind and seed (as for `play`).
    #[command(flatten)]
    pub water: crate::cli::args::LiveSceneArgs,

    /// The bus's flags (`--bus`, `--pool`, ...): one pool across many machines.
    #[cfg(feature = "bus")]
    #[command(flatten)]
    pub bus: super::serve_bus::BusArgs,
}
