//! Every bound the server enforces, with its unit, and the small accounting types that enforce
//! the counting ones (connections, connections per address, players, rates).

use std::collections::HashMap;
use std::net::IpAddr;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use crate::output::bucket::ByteBucket;
use crate::play::Bandwidth;

/// Default players in the pool at once (`--max-clients`).
pub const DEFAULT_MAX_CLIENTS: usize = 64;
/// Default TCP connections from one IP address at once, handshaking or playing.
pub const DEFAULT_MAX_PER_ADDRESS: usize = 8;
/// Connections allowed beyond `max_clients` that are still handshaking (so a full pool can still
/// tell newcomers it is full, and handshakes cannot exhaust memory).
pub const HANDSHAKE_SLACK: usize = 16;
/// Default time from TCP accept until the player's shell is running (banner, key exchange,
/// authentication, channel, pty, shell).
pub const DEFAULT_HANDSHAKE_TIMEOUT: Duration = Duration::from_secs(10);
/// Default time without a key press before a player is sent away.
pub const DEFAULT_IDLE_TIMEOUT: Duration = Duration::from_secs(10 * 60);
/// Default time one frame may take to leave for the client before it counts as stalled and is cut.
pub const DEFAULT_STALL_TIMEOUT: Duration = Duration::from_secs(20);
/// Default delay before rejecting a failed authentication (russh `auth_rejection_time`).
pub const DEFAULT_AUTH_REJECTION_TIME: Duration = Duration::from_millis(500);
/// Largest terminal accepted from pty-req/window-change; larger values are clamped.
pub const MAX_COLS: u16 = 500;
/// Largest terminal height accepted; larger values are clamped.
pub const MAX_ROWS: u16 = 200;
/// Smallest terminal drawn; smaller values are clamped up.
pub const MIN_COLS: u16 = 20;
/// Smallest terminal height drawn.
pub const MIN_ROWS: u16 = 5;
/// Default actions (key-press batches) a player may make per second; the rest are dropped.
pub const DEFAULT_ACTIONS_PER_SECOND: u32 = 30;
/// Default scene keys (rain, clear, damping, pause, wind, `tab`: each costs the one game thread
/// more than a stone) a player may press per second; the rest are dropped.
pub const DEFAULT_SCENE_KEYS_PER_SECOND: u32 = 4;
/// Scene keys per second from all players together (a crowd of players each within their own
/// limit must not keep the game thread rebuilding scenes).
pub const SCENE_KEYS_ALL_PLAYERS_PER_SECOND: f64 = 8.0;
/// New terminal sizes (window-change requests) a player's screen takes per second: each new size
/// costs the game thread a picture of that size. Sizes that come faster wait, and the newest
/// is taken when the limit allows (a window dragged by its edge ends at its last size).
pub const RESIZES_PER_SECOND: f64 = 4.0;
/// Default total outbound frame bytes per second across all clients.
pub const DEFAULT_OUTBOUND_BYTES_PER_SECOND: u64 = 16_000_000;
/// Most players `--max-clients` accepts (memory and CPU are planned per client).
pub const MAX_MAX_CLIENTS: u64 = 10_000;
/// Most connections per address `--max-per-address` accepts.
pub const MAX_PER_ADDRESS: u64 = 1_000;
/// Longest timeout any `--*-timeout-ms` flag accepts (a day).
pub const MAX_TIMEOUT_MS: u64 = 24 * 3600 * 1000;
/// Most actions per second `--actions-per-second` accepts.
pub const MAX_ACTIONS_PER_SECOND: u64 = 1_000;
/// Send buffer the kernel may hold per client socket: keeps stale frames out of the pipe.
pub const SOCKET_SEND_BUFFER_BYTES: usize = 64 * 1024;
/// Messages russh may queue per session from our side (`Config::event_buffer_size`).
pub const SESSION_EVENT_QUEUE: usize = 4;
/// Receive window we offer the client for its input (bytes).
pub const INPUT_WINDOW_BYTES: u32 = 64 * 1024;
/// Time the farewell (message + terminal reset + channel close) may take per client at exit.
pub const FAREWELL_TIMEOUT: Duration = Duration::from_millis(300);
/// Time from a shutdown request until every connection is cut.
pub const SHUTDOWN_GRACE: Duration = Duration::from_millis(700);
/// The line a client beyond `max_clients` sees.
pub const POOL_FULL_LINE: &str = "the pool is full, try again later";

/// All runtime limits (built from flags; tests shorten the timeouts).
#[derive(Debug, Clone)]
pub struct Limits {
    /// Players at once.
    pub max_clients: usize,
    /// Connections per IP address at once.
    pub max_per_address: usize,
    /// Accept → shell deadline.
    pub handshake_timeout: Duration,
    /// No-input deadline for a player.
    pub idle_timeout: Duration,
    /// Per-frame send deadline before a client is considered stalled and cut.
    pub stall_timeout: Duration,
    /// Delay on each failed authentication.
    pub auth_rejection_time: Duration,
    /// Per-player input rate (stones, clicks, drags).
    pub actions_per_second: u32,
    /// Per-player scene keys (see [`DEFAULT_SCENE_KEYS_PER_SECOND`]).
    pub scene_keys_per_second: u32,
    /// Server-wide frame byte rate.
    pub outbound_bytes_per_second: u64,
    /// One client's link: found from its own round trips, or fixed.
    pub client_bandwidth: Bandwidth,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_clients: DEFAULT_MAX_CLIENTS,
            max_per_address: DEFAULT_MAX_PER_ADDRESS,
            handshake_timeout: DEFAULT_HANDSHAKE_TIMEOUT,
            idle_timeout: DEFAULT_IDLE_TIMEOUT,
            stall_timeout: DEFAULT_STALL_TIMEOUT,
            auth_rejection_time: DEFAULT_AUTH_REJECTION_TIME,
            actions_per_second: DEFAULT_ACTIONS_PER_SECOND,
            scene_keys_per_second: DEFAULT_SCENE_KEYS_PER_SECOND,
            outbound_bytes_per_second: DEFAULT_OUTBOUND_BYTES_PER_SECOND,
            client_bandwidth: Bandwidth::Auto,
        }
    }
}

impl Limits {
    /// One player's budget of actions: [`Limits::actions_per_second`], a second's burst.
    pub fn actions_bucket(&self) -> ByteBucket {
        ByteBucket::limit(f64::from(self.actions_per_second), RATE_BURST)
    }

    /// One player's budget of scene keys: [`Limits::scene_keys_per_second`], a second's burst.
    pub fn scene_keys_bucket(&self) -> ByteBucket {
        ByteBucket::limit(f64::from(self.scene_keys_per_second), RATE_BURST)
    }

    /// All players' scene keys together.
    pub fn all_scene_keys_bucket(&self) -> ByteBucket {
        ByteBucket::limit(SCENE_KEYS_ALL_PLAYERS_PER_SECOND, RATE_BURST)
    }

    /// One player's new terminal sizes.
    pub fn resizes_bucket(&self) -> ByteBucket {
        ByteBucket::limit(RESIZES_PER_SECOND, RATE_BURST)
    }

    /// All players' bytes together: [`Limits::outbound_bytes_per_second`], a second's burst.
    pub fn outbound_bucket(&self) -> ByteBucket {
        ByteBucket::limit(self.outbound_bytes_per_second as f64, RATE_BURST)
    }
}

/// How much of a rate limit may be spent at once (and owed).
pub const RATE_BURST: Duration = Duration::from_secs(1);

/// The prefix an IPv6 client is counted by: one site's /64 (a host picks any address in its /64
/// at will, so counting single addresses would count nothing).
pub const IPV6_PREFIX: u8 = 64;

/// Who a connection is counted as, for the per-address limit: an IPv4 address (IPv4-mapped IPv6
/// included), or an IPv6 address's /64.
pub fn address_key(ip: IpAddr) -> IpAddr {
    match ip.to_canonical() {
        IpAddr::V6(v6) => IpAddr::V6(ipnet::Ipv6Net::new_assert(v6, IPV6_PREFIX).network()),
        v4 => v4,
    }
}

/// Counts open TCP connections, in total and per IP address (per /64 for IPv6); enforced at
/// accept.
#[derive(Debug)]
pub struct ConnTracker {
    max_total: usize,
    max_per_address: usize,
    inner: Mutex<TrackerInner>,
}

#[derive(Debug, Default)]
struct TrackerInner {
    total: usize,
    per_address: HashMap<IpAddr, usize>,
}

/// Why a connection was refused at accept.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal {
    /// `max_clients + HANDSHAKE_SLACK` connections are open.
    TooManyConnections,
    /// This address has `max_per_address` connections open.
    TooManyFromAddress,
}

impl ConnTracker {
    /// A tracker for `limits`.
    pub fn new(limits: &Limits) -> Arc<Self> {
        Arc::new(Self {
            max_total: limits.max_clients + HANDSHAKE_SLACK,
            max_per_address: limits.max_per_address,
            inner: Mutex::new(TrackerInner::default()),
        })
    }

    /// Counts a new connection from `ip`, or says why it is refused.
    pub fn admit(self: &Arc<Self>, ip: IpAddr) -> Result<ConnGuard, Refusal> {
        let ip = address_key(ip);
        let mut inner = self.inner.lock().unwrap_or_else(|p| p.into_inner());
        if inner.total >= self.max_total {
            return Err(Refusal::TooManyConnections);
        }
        let count = inner.per_address.entry(ip).or_insert(0);
        if *count >= self.max_per_address {
            return Err(Refusal::TooManyFromAddress);
        }
        *count += 1;
        inner.total += 1;
        Ok(ConnGuard { tracker: self.clone(), ip })
    }
}

/// Releases the connection's place when dropped.
#[derive(Debug)]
pub struct ConnGuard {
    tracker: Arc<ConnTracker>,
    ip: IpAddr,
}

impl Drop for ConnGuard {
    fn drop(&mut self) {
        let mut inner = self.tracker.inner.lock().unwrap_or_else(|p| p.into_inner());
        inner.total -= 1;
        if let Some(count) = inner.per_address.get_mut(&self.ip) {
            *count -= 1;
            if *count == 0 {
                inner.per_address.remove(&self.ip);
            }
        }
    }
}

/// Player places in the pool (`max_clients`); a place is taken when a shell starts.
#[derive(Debug)]
pub struct PlayerSlots {
    max: usize,
    taken: AtomicUsize,
}

impl PlayerSlots {
    /// Up to `max` players.
    pub fn new(max: usize) -> Arc<Self> {
        Arc::new(Self { max, taken: AtomicUsize::new(0) })
    }

    /// Takes a place, or None when the pool is full.
    pub fn try_take(self: &Arc<Self>) -> Option<PlayerSlot> {
        self.taken
            .fetch_update(Ordering::AcqRel, Ordering::Acquire, |n| (n < self.max).then_some(n + 1))
            .ok()
            .map(|_| PlayerSlot { slots: self.clone() })
    }

    /// Players now.
    pub fn count(&self) -> usize {
        self.taken.load(Ordering::Acquire)
    }
}

/// A taken place; dropping it frees the place.
#[derive(Debug)]
pub struct PlayerSlot {
    slots: Arc<PlayerSlots>,
}

impl Drop for PlayerSlot {
    fn drop(&mut self) {
        self.slots.taken.fetch_sub(1, Ordering::AcqRel);
    }
}

/// Clamps a client-reported terminal size to what we draw.
pub fn clamp_size(cols: u32, rows: u32) -> (u16, u16) {
    let c = cols.clamp(MIN_COLS as u32, MAX_COLS as u32) as u16;
    let r = rows.clamp(MIN_ROWS as u32, MAX_ROWS as u32) as u16;
    (c, r)
}

/// The largest terminal size in pixels taken from a client (a 16k screen); larger values are
/// taken as unknown (0), as are sizes a pixel count cannot describe.
pub const MAX_PIXELS_SIDE: u32 = 16_384;

/// A client-reported terminal size in pixels, or (0, 0) when it is not believable.
pub fn clamp_pixels(width: u32, height: u32) -> (u16, u16) {
    if width > MAX_PIXELS_SIDE || height > MAX_PIXELS_SIDE { (0, 0) } else { (width as u16, height as u16) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn per_address_and_total_limits() {
        let limits = Limits { max_clients: 1, max_per_address: 2, ..Limits::default() };
        let t = ConnTracker::new(&limits);
        let a: IpAddr = "127.0.0.1".parse().unwrap();
        let b: IpAddr = "127.0.0.2".parse().unwrap();
        let g1 = t.admit(a).unwrap();
        let _g2 = t.admit(a).unwrap();
        assert_eq!(t.admit(a).unwrap_err(), Refusal::TooManyFromAddress);
        drop(g1);
        let _g3 = t.admit(a).unwrap();
        let mut held = Vec::new();
        for i in 0..HANDSHAKE_SLACK - 1 {
            held.push(t.admit(IpAddr::from([10, 0, 0, i as u8])).unwrap());
        }
        assert_eq!(t.admit(b).unwrap_err(), Refusal::TooManyConnections);
    }

    #[test]
    fn ipv6_clients_are_counted_by_their_64_and_mapped_ipv4_as_ipv4() {
        let limits = Limits { max_clients: 100, max_per_address: 2, ..Limits::default() };
        let t = ConnTracker::new(&limits);
        let ip = |s: &str| s.parse::<IpAddr>().unwrap();
        let _a = t.admit(ip("2001:db8:1:2::1")).unwrap();
        let _b = t.admit(ip("2001:db8:1:2:ffff:ffff:ffff:fffe")).unwrap();
        assert_eq!(t.admit(ip("2001:db8:1:2:abcd::9")).unwrap_err(), Refusal::TooManyFromAddress, "same /64");
        let _c = t.admit(ip("2001:db8:1:3::1")).expect("the next /64 is someone else");
        let _d = t.admit(ip("192.0.2.1")).unwrap();
        let _e = t.admit(ip("::ffff:192.0.2.1")).unwrap();
        assert_eq!(t.admit(ip("192.0.2.1")).unwrap_err(), Refusal::TooManyFromAddress, "mapped counts as IPv4");
        assert_eq!(address_key(ip("192.0.2.1")), ip("192.0.2.1"), "IPv4 addresses are counted one by one");
    }

    #[test]
    fn player_slots_are_bounded_and_freed() {
        let s = PlayerSlots::new(1);
        let p = s.try_take().unwrap();
        assert!(s.try_take().is_none());
        drop(p);
        assert!(s.try_take().is_some());
    }

    #[test]
    fn sizes_are_clamped() {
        assert_eq!(clamp_size(0, 0), (MIN_COLS, MIN_ROWS));
        assert_eq!(clamp_size(u32::MAX, u32::MAX), (MAX_COLS, MAX_ROWS));
        assert_eq!(clamp_size(80, 24), (80, 24));
    }
}
