//! `tidepool serve`: one shared scene, many players over SSH.
//!
//! Module by module: [`host_key`] (the server's identity), [`authorized_keys`] (who may play,
//! from where: [`address_pattern`]),
//! [`server`] (accept, limits per address, handshake deadline, shutdown), [`handler`] (what an
//! SSH connection may ask for: a pty and a shell, nothing else), [`viewer`] (one player: keys
//! in, frames out: a seat and a screen of the play session), [`game`] (the one simulation: the
//! session's host on a thread, and its pictures), [`limits`] (every bound, with its unit), [`killable`] (a socket
//! the server can cut).
//!
//! The library stays free of tokio and russh: this module uses its player pieces (the input
//! parser, the frame builder, the rate-controlled encoder and byte bucket, the sim clock).

pub mod address_pattern;
pub mod authorized_keys;
#[cfg(feature = "bus")]
pub mod bus;
mod channel;
pub mod flight;
pub mod game;
mod gate;
pub mod handler;
pub mod host_key;
mod hub;
pub mod killable;
pub mod leave;
pub mod limits;
pub mod server;
mod tally;
pub mod viewer;

use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::Duration;

use crate::cli::args::serve::ServeCommand;
use crate::cli::commands::scenes::specs;
use crate::cli::error::{Error, Result};
use limits::Limits;

/// Host key file name inside the data folder.
pub const HOST_KEY_FILE_NAME: &str = "serve_host_ed25519_key";
/// Most frames per second `--fps` accepts for a shared scene.
pub const MAX_FPS: u32 = 60;
/// The largest shared scene, in pixels (one simulation and one picture per frame for all).
pub const MAX_SCENE_PIXELS: u32 = 640 * 360;
/// Exit status after Ctrl-C (128 + SIGINT), as the rest of the command line.
const EXIT_INTERRUPTED: i32 = 130;
/// How long the runtime waits at exit for tasks that did not finish (every connection was
/// told and cut already).
const RUNTIME_EXIT_WAIT: Duration = Duration::from_millis(50);

/// The data folder: `$XDG_DATA_HOME/tidepool` or `~/.local/share/tidepool`.
pub fn data_dir() -> Option<PathBuf> {
    let base = std::env::var_os("XDG_DATA_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".local/share")))?;
    Some(base.join("tidepool"))
}

fn in_range(flag: &'static str, value: u64, min: u64, max: u64, what: &str) -> Result<u64> {
    if (min..=max).contains(&value) {
        Ok(value)
    } else {
        Err(Error::arg(flag, format!("{value} is out of range; give {min} to {max} {what}")))
    }
}

/// The limits from the flags, each checked.
pub fn limits(args: &ServeCommand) -> Result<Limits> {
    let ms = |flag, v| in_range(flag, v, 1, limits::MAX_TIMEOUT_MS, "milliseconds").map(Duration::from_millis);
    Ok(Limits {
        max_clients: in_range("--max-clients", args.max_clients, 1, limits::MAX_MAX_CLIENTS, "players")? as usize,
        max_per_address: in_range("--max-per-address", args.max_per_address, 1, limits::MAX_PER_ADDRESS, "connections")?
            as usize,
        handshake_timeout: ms("--handshake-timeout-ms", args.handshake_timeout_ms)?,
        idle_timeout: ms("--idle-timeout-ms", args.idle_timeout_ms)?,
        stall_timeout: ms("--stall-timeout-ms", args.stall_timeout_ms)?,
        actions_per_second: in_range(
            "--actions-per-second",
            args.actions_per_second,
            1,
            limits::MAX_ACTIONS_PER_SECOND,
            "actions a second",
        )? as u32,
        scene_keys_per_second: in_range(
            "--scene-keys-per-second",
            args.scene_keys_per_second,
            1,
            limits::MAX_ACTIONS_PER_SECOND,
            "scene keys a second",
        )? as u32,
        client_bandwidth: args.client_bandwidth,
        outbound_bytes_per_second: args.total_bandwidth.max(1),
        ..Limits::default()
    })
}

/// Runs the server until SIGTERM (exit 0) or Ctrl-C (exit 130).
pub fn run(args: ServeCommand) -> Result<()> {
    let listen: SocketAddr = args.listen.trim().parse().map_err(|_| {
        Error::arg(
            "--listen",
            format!(
                "'{}' is not an address and port; use e.g. 127.0.0.1:2222 (this machine) or 0.0.0.0:2222 (the network)",
                args.listen
            ),
        )
    })?;
    let limits = limits(&args)?;
    if !(1..=MAX_FPS).contains(&args.fps) {
        return Err(Error::arg("--fps", format!("{} is out of range; give 1 to {MAX_FPS}", args.fps)));
    }
    let size = (args.size.width(), args.size.height());
    if size.0.saturating_mul(size.1) > MAX_SCENE_PIXELS {
        return Err(Error::arg(
            "--size",
            format!("{}x{} is more than the shared scene's {MAX_SCENE_PIXELS} pixels; e.g. 160x90", size.0, size.1),
        ));
    }
    let allow = match &args.authorized_keys {
        Some(path) => Some(authorized_keys::AllowList::load(path).map_err(Error::Usage)?),
        None => None,
    };
    let key_path = match &args.host_key {
        Some(path) => path.clone(),
        None => data_dir()
            .ok_or_else(|| {
                Error::arg("--host-key", "no HOME or XDG_DATA_HOME to keep the key in; pass --host-key FILE")
            })?
            .join(HOST_KEY_FILE_NAME),
    };
    let (key, origin) = host_key::load_or_create(&key_path).map_err(|e| Error::Usage(e.0))?;
    let fingerprint = host_key::fingerprint_line(&key);
    let scenes = specs(args.scene, &args.water)?;
    let game = server::GameOptions { scenes, size, fps: args.fps, seed: args.water.seed };
    #[cfg(feature = "bus")]
    let bus = bus_options(&args, &limits)?;
    // An edge's threads share one malloc arena; asked before they start (`bus/heap.rs`).
    #[cfg(feature = "bus")]
    if bus.is_some() {
        bus::one_arena();
    }
    let runtime =
        tokio::runtime::Builder::new_multi_thread().enable_all().thread_name("tidepool-serve").build().map_err(
            |e| Error::Usage(format!("cannot start the server's threads ({e}); free some memory and try again")),
        )?;
    let options = server::ServerOptions {
        listen,
        host_key: key,
        allow,
        limits,
        game,
        compression: !args.no_compression,
        #[cfg(feature = "bus")]
        bus,
    };
    let interrupted = runtime.block_on(async move {
        let running = server::start(options).await.map_err(|e| match e {
            server::StartError::Bind(e) => {
                Error::arg("--listen", format!("cannot listen on {listen} ({e}); pick a free port or another address"))
            }
            server::StartError::Scene(e) => Error::Lib(e),
            #[cfg(feature = "bus")]
            server::StartError::Bus(e) => Error::arg("--bus", e),
        })?;
        let verb = match origin {
            host_key::Origin::Created => "created",
            host_key::Origin::Loaded => "loaded",
        };
        println!("host key {verb}: {} ({fingerprint})", key_path.display());
        let addr = running.local_addr;
        println!("listening on {addr}: ssh -p {} {}", addr.port(), addr.ip());
        let interrupted = wait_for_signal().await;
        let stopping = std::time::Instant::now();
        let (stats, game_stats) = (running.stats.clone(), running.game_stats.clone());
        running.shutdown();
        running.wait().await;
        eprintln!("serve: stopped in {} ms; {}", stopping.elapsed().as_millis(), stats.summary(&game_stats));
        Ok::<bool, Error>(interrupted)
    })?;
    runtime.shutdown_timeout(RUNTIME_EXIT_WAIT);
    if interrupted {
        // Every player was told and every connection closed: nothing is left to clean up.
        std::process::exit(EXIT_INTERRUPTED);
    }
    Ok(())
}

/// The bus's options from the flags (`None` without `--bus`), each checked.
#[cfg(feature = "bus")]
fn bus_options(args: &ServeCommand, limits: &Limits) -> Result<Option<bus::BusOptions>> {
    use bus::protocol::{MAX_EDGE_NAME, Names, valid_name};
    let flags = &args.bus;
    let Some(url) = &flags.bus else { return Ok(None) };
    if !(url.starts_with("nats://") || url.starts_with("tls://")) {
        return Err(Error::arg(
            "--bus",
            format!("'{url}' is not a NATS address; use nats://HOST:4222 or tls://HOST:4222"),
        ));
    }
    if args.scene != crate::cli::args::PlayScene::Pool {
        return Err(Error::arg("--scene", "--bus runs the pool only; leave --scene out or give --scene pool"));
    }
    Names::of(&flags.pool).map_err(|e| Error::arg("--pool", e.0))?;
    let edge = match &flags.bus_edge {
        Some(name) if valid_name(name, MAX_EDGE_NAME) => name.clone(),
        Some(name) => {
            return Err(Error::arg(
                "--bus-edge",
                format!("'{name}' is not an edge name; use 1 to {MAX_EDGE_NAME} letters, digits, '-' or '_'"),
            ));
        }
        None => default_edge_name(),
    };
    if let Some(dir) = flags.bus_shots.as_ref().filter(|d| !d.is_dir()) {
        return Err(Error::arg("--bus-shots", format!("{} is not a folder; make it first", dir.display())));
    }
    Ok(Some(bus::BusOptions {
        url: url.clone(),
        pool: flags.pool.clone(),
        edge,
        credentials: flags.bus_credentials.clone(),
        ca: flags.bus_ca.clone(),
        shots: flags.bus_shots.clone(),
        limits: bus::sequencer::SequencerLimits {
            actions_per_second: f64::from(limits.actions_per_second),
            scene_keys_per_second: f64::from(limits.scene_keys_per_second),
            pool_scene_keys_per_second: limits::SCENE_KEYS_ALL_PLAYERS_PER_SECOND,
        },
    }))
}

/// This machine's name and the process id, in the characters an edge name may have.
#[cfg(feature = "bus")]
fn default_edge_name() -> String {
    let host = std::fs::read_to_string("/etc/hostname").unwrap_or_default();
    let host: String = host.trim().chars().filter(|c| c.is_ascii_alphanumeric() || *c == '-').take(40).collect();
    let host = if host.is_empty() { "edge".to_owned() } else { host };
    format!("{host}-{}", std::process::id())
}

/// Waits for SIGTERM (false) or SIGINT, Ctrl-C (true).
async fn wait_for_signal() -> bool {
    use tokio::signal::unix::{SignalKind, signal};
    let Ok(mut term) = signal(SignalKind::terminate()) else {
        return tokio::signal::ctrl_c().await.is_ok();
    };
    tokio::select! {
        _ = term.recv() => false,
        _ = tokio::signal::ctrl_c() => true,
    }
}
