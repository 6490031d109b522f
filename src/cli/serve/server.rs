//! The SSH server: binds, accepts with per-address and total limits, runs each connection under
//! a handshake deadline and a kill switch, and shuts down within a second.

use std::borrow::Cow;
use std::collections::HashMap;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::SceneSpec;
use crate::play::{Host, HostConfig};
use russh::keys::PrivateKey;
use russh::server::Config;
use russh::{MethodKind, MethodSet, Preferred, SshId, compression};
use tokio::net::{TcpListener, TcpStream};
use tokio::sync::{mpsc, watch};
use tokio::task::JoinHandle;
use tokio_util::sync::CancellationToken;
use tokio_util::task::TaskTracker;

use super::authorized_keys::AllowList;
use super::game::{self, Fits, GameLinks, GameStats, SharedFrame};
use super::handler::ClientHandler;
use super::hub::Hub;
pub use super::hub::Stats;
use super::killable::Killable;
use super::limits::{self, ConnGuard, ConnTracker, Limits, PlayerSlots};

/// Identification string sent to clients (no library version, nothing to fingerprint).
pub const SERVER_ID: &str = "SSH-2.0-tidepool";
/// Pause after a failed accept (e.g. out of file descriptors) before accepting again.
const ACCEPT_ERROR_PAUSE: Duration = Duration::from_millis(100);
/// Time between keepalives to a quiet client (at most half the stall timeout).
const KEEPALIVE_INTERVAL: Duration = Duration::from_secs(15);
/// Time the last step of shutdown waits for cut connections to finish.
const CUT_WAIT: Duration = Duration::from_millis(150);

/// What `start` needs.
pub struct ServerOptions {
    /// Address to listen on.
    pub listen: SocketAddr,
    /// Host key (see `host_key`).
    pub host_key: PrivateKey,
    /// `None`: anyone may play. `Some`: only these keys.
    pub allow: Option<AllowList>,
    /// Limits and timeouts.
    pub limits: Limits,
    /// The shared scene.
    pub game: GameOptions,
    /// Offer `zlib@openssh.com` compression to clients that ask for it.
    pub compression: bool,
    /// Share the pool with other machines over this bus (`--bus`).
    #[cfg(feature = "bus")]
    pub bus: Option<super::bus::BusOptions>,
}

/// A running server.
pub struct Running {
    /// Bound address (useful with port 0).
    pub local_addr: SocketAddr,
    /// Counters.
    pub stats: Arc<Stats>,
    /// The shared scene's counters.
    pub game_stats: Arc<GameStats>,
    shutdown: CancellationToken,
    join: JoinHandle<()>,
}

impl Running {
    /// Asks every player to leave and stops accepting; `wait` returns within about a second.
    pub fn shutdown(&self) {
        self.shutdown.cancel();
    }

    /// Waits until the server has stopped (after `shutdown`).
    pub async fn wait(self) {
        let _ = self.join.await;
    }
}

/// The compression offered: `zlib@openssh.com` only, which starts after authentication (so no
/// stranger reaches the decompressor before logging in; plain `zlib` would start at once), and
/// none. The client's order decides: `ssh -C` asks for zlib first, plain `ssh` for none.
const COMPRESSION: &[compression::Name] = &[compression::NONE, compression::ZLIB_LEGACY];

/// Builds russh's configuration. Public mode offers none, publickey and keyboard-interactive;
/// private mode (authorized_keys) offers publickey only. Password is never offered: a public
/// pool must not invite people to type their real password. `compress`: offer
/// `zlib@openssh.com`.
pub fn russh_config(host_key: PrivateKey, private: bool, limits: &Limits, compress: bool) -> Config {
    let methods: &[MethodKind] = if private {
        &[MethodKind::PublicKey]
    } else {
        &[MethodKind::None, MethodKind::PublicKey, MethodKind::KeyboardInteractive]
    };
    let compression = if compress { COMPRESSION } else { &[compression::NONE] };
    Config {
        server_id: SshId::Standard(SERVER_ID.into()),
        preferred: Preferred { compression: Cow::Borrowed(compression), ..Preferred::default() },
        methods: MethodSet::from(methods),
        auth_rejection_time: limits.auth_rejection_time,
        // OpenSSH always probes with "none" first: do not make every private-mode login wait.
        auth_rejection_time_initial: Some(Duration::ZERO),
        keys: vec![host_key],
        // russh resets this timer on every loop turn, including our own frames, so it is not an
        // idle timeout; it bounds the banner read and a write blocked on a full socket. Twice
        // the stall timeout, so a player who stops reading is found stalled by the game (and
        // told why) before the session is cut under it; the two timers raced at equal lengths.
        inactivity_timeout: Some(limits.stall_timeout * 2),
        // Keepalives also keep a player watching still water from counting as inactive.
        keepalive_interval: Some(KEEPALIVE_INTERVAL.min(limits.stall_timeout / 2)),
        keepalive_max: 3,
        window_size: limits::INPUT_WINDOW_BYTES,
        event_buffer_size: limits::SESSION_EVENT_QUEUE,
        max_auth_attempts: 6,
        // run_stream ignores `nodelay` (only run_on_socket applies it); we set it on accept.
        nodelay: true,
        ..Config::default()
    }
}

/// How the game runs.
pub struct GameOptions {
    /// The scenes `tab` cycles through; the first is shown at the start.
    pub scenes: Vec<SceneSpec>,
    /// The shared scene's size in pixels.
    pub size: (u32, u32),
    /// Frames per second.
    pub fps: u32,
    /// Seed of the random stones.
    pub seed: u64,
}

impl GameOptions {
    /// The host of the first scene (so a bad scene setting fails before the server starts).
    /// Nothing is recorded and no file is saved on a player's behalf.
    pub fn host(&self) -> crate::Result<Host> {
        let config = HostConfig { scenes: self.scenes.clone(), seed: self.seed, record: None, screenshots: false };
        Host::new(config, self.size, Instant::now())
    }
}

/// Binds and starts serving. Errors only for the bind (e.g. port in use) and the first scene.
pub async fn start(opts: ServerOptions) -> Result<Running, StartError> {
    let host = opts.game.host().map_err(StartError::Scene)?;
    let listener = TcpListener::bind(opts.listen).await.map_err(StartError::Bind)?;
    let local_addr = listener.local_addr().map_err(StartError::Bind)?;
    let config = Arc::new(russh_config(opts.host_key, opts.allow.is_some(), &opts.limits, opts.compression));
    let stats = Arc::new(Stats::default());
    let game_stats = Arc::new(GameStats::default());
    let players = PlayerSlots::new(opts.limits.max_clients);
    let tracker = ConnTracker::new(&opts.limits);
    let first = SharedFrame { status: Arc::new(host.status().clone()), ..SharedFrame::default() };
    let (frames_tx, frames_rx) = watch::channel(Arc::new(first));
    let (requests_tx, requests_rx) = mpsc::channel(game::REQUEST_QUEUE);
    let fits: Fits = Arc::new(Mutex::new(HashMap::new()));
    let shutdown = CancellationToken::new();
    let hub = Arc::new(Hub {
        outbound: Mutex::new(opts.limits.outbound_bucket()),
        scene_keys: Mutex::new(opts.limits.all_scene_keys_bucket()),
        limits: opts.limits,
        allow: opts.allow,
        config,
        tracker,
        players: players.clone(),
        shutdown: shutdown.clone(),
        cut_all: CancellationToken::new(),
        frames: frames_rx,
        fits: fits.clone(),
        requests: requests_tx,
        stats: stats.clone(),
        tasks: TaskTracker::new(),
        next_id: AtomicU64::new(1),
        scene_size: opts.game.size,
        fps: opts.game.fps,
        #[cfg(feature = "bus")]
        screenshots: opts.bus.as_ref().is_some_and(|b| b.shots.is_some()),
        #[cfg(not(feature = "bus"))]
        screenshots: false,
    });
    let stop = Arc::new(AtomicBool::new(false));
    let fps = opts.game.fps;
    let links = GameLinks {
        requests: requests_rx,
        fits,
        players: players.clone(),
        publish: frames_tx,
        stats: game_stats.clone(),
        stop: stop.clone(),
    };
    // The simulation and rendering are CPU work on their own thread, off the async workers.
    #[cfg(feature = "bus")]
    let game = match opts.bus {
        Some(bus) => {
            let Some(SceneSpec::Pool(settings)) = opts.game.scenes.first().cloned() else {
                return Err(StartError::Bus("--bus runs the pool only".into()));
            };
            let spec = super::bus::PoolSpec { settings, size: opts.game.size, fps, seed: opts.game.seed };
            super::bus::start(bus, spec, links, players.clone(), shutdown.clone()).await.map_err(StartError::Bus)?
        }
        None => spawn_game(host, fps, links)?,
    };
    #[cfg(not(feature = "bus"))]
    let game = spawn_game(host, fps, links)?;
    let join = tokio::spawn(async move {
        accept_loop(&hub, listener).await;
        finish(&hub).await;
        stop.store(true, Ordering::Relaxed);
        let _ = tokio::task::spawn_blocking(move || game.join()).await;
    });
    Ok(Running { local_addr, stats, game_stats, shutdown, join })
}

/// Runs the single machine's game on its own thread.
fn spawn_game(host: Host, fps: u32, links: GameLinks) -> Result<std::thread::JoinHandle<()>, StartError> {
    std::thread::Builder::new()
        .name("tidepool-game".into())
        .spawn(move || game::run(host, fps, links))
        .map_err(StartError::Bind)
}

/// Why the server could not start.
#[derive(Debug)]
pub enum StartError {
    /// The address could not be bound (in use, not ours, no permission).
    Bind(std::io::Error),
    /// The first scene could not be built.
    Scene(crate::Error),
    /// The bus could not be reached or the pool joined (one line for the user).
    #[cfg(feature = "bus")]
    Bus(String),
}

async fn accept_loop(hub: &Arc<Hub>, listener: TcpListener) {
    loop {
        let accepted = tokio::select! {
            _ = hub.shutdown.cancelled() => return,
            r = listener.accept() => r,
        };
        let (stream, peer) = match accepted {
            Ok(x) => x,
            Err(e) => {
                eprintln!("serve: accept failed: {e}");
                tokio::time::sleep(ACCEPT_ERROR_PAUSE).await;
                continue;
            }
        };
        match hub.tracker.admit(peer.ip()) {
            Ok(guard) => {
                hub.stats.accepted.fetch_add(1, Ordering::Relaxed);
                hub.tasks.spawn(connection(hub.clone(), stream, peer, guard));
            }
            Err(refusal) => {
                hub.stats.refused_at_accept.fetch_add(1, Ordering::Relaxed);
                eprintln!("serve: {peer} refused at accept: {refusal:?}");
                drop(stream);
            }
        }
    }
}

/// Shutdown: players already got `shutdown` and say goodbye; give them SHUTDOWN_GRACE, then cut
/// whatever is left (stalled clients, handshakes) and wait briefly for the tasks to notice.
async fn finish(hub: &Arc<Hub>) {
    hub.tasks.close();
    if tokio::time::timeout(limits::SHUTDOWN_GRACE, hub.tasks.wait()).await.is_err() {
        hub.cut_all.cancel();
        let _ = tokio::time::timeout(CUT_WAIT, hub.tasks.wait()).await;
    }
    hub.cut_all.cancel();
}

async fn connection(hub: Arc<Hub>, stream: TcpStream, peer: SocketAddr, guard: ConnGuard) {
    let _ = stream.set_nodelay(true);
    // Small kernel send buffer: a slow client's backlog stays small, so frames are dropped
    // upstream (latest-wins) instead of aging in the socket.
    let _ = socket2::SockRef::from(&stream).set_send_buffer_size(limits::SOCKET_SEND_BUFFER_BYTES);
    let id = hub.next_id.fetch_add(1, Ordering::Relaxed);
    let kill = hub.cut_all.child_token();
    let playing = CancellationToken::new();
    let handler = ClientHandler::new(hub.clone(), id, peer, kill.clone(), playing.clone());
    let stream = Killable::new(stream, kill.clone());
    let counts = stream.counts();

    let deadline = {
        let (kill, playing, stats) = (kill.clone(), playing.clone(), hub.stats.clone());
        let (timeout, shutdown) = (hub.limits.handshake_timeout, hub.shutdown.clone());
        async move {
            tokio::select! {
                _ = playing.cancelled() => {}
                _ = kill.cancelled() => {}
                // Nothing to say goodbye to before the game starts: cut handshakes at once.
                _ = shutdown.cancelled() => kill.cancel(),
                _ = tokio::time::sleep(timeout) => {
                    stats.handshake_timeouts.fetch_add(1, Ordering::Relaxed);
                    kill.cancel();
                }
            }
        }
    };
    let session = {
        let config = hub.config.clone();
        let kill = kill.clone();
        async move {
            let result = match russh::server::run_stream(config, stream, handler).await {
                Ok(running) => running.await,
                Err(e) => Err(e),
            };
            kill.cancel(); // ends the deadline task and the player's writer
            result
        }
    };
    let ((), result) = tokio::join!(deadline, session);
    let (out, into) = counts.get();
    match result {
        Err(e) => eprintln!("serve: {peer} #{id} ended: {e}; {out} bytes out, {into} in on the socket"),
        Ok(()) => eprintln!("serve: {peer} #{id} closed: {out} bytes out, {into} in on the socket"),
    }
    drop(guard);
}
