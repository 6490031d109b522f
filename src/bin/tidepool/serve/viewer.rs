//! One task per player: the play session's [`Seat`] and [`Screen`] on an SSH channel. The
//! channel's bytes go to the screen (the terminal's answers stay there: the graphics probe, the
//! link's round trips), the person's inputs to the seat, the seat's requests to the shared host;
//! the newest shared picture becomes this player's frame. Never more than one frame in flight,
//! so a slow player skips pictures, and the link control finds each player's own rate.
//!
//! Bounded everywhere: the pictures are the one `watch` slot every player shares (newest wins),
//! input is a bounded queue of the channel's packets (the SSH window bounds each), and below us
//! russh holds at most `SESSION_EVENT_QUEUE` messages and the kernel at most
//! `SOCKET_SEND_BUFFER_BYTES`.

use std::net::SocketAddr;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::Instant;

use bytes::Bytes;
use russh::ChannelWriteHalf;
use russh::server::Msg;
use tidepool::play::{Flow, Membership, Player, Screen, ScreenConfig, Source};
use tokio::sync::{mpsc, watch};
use tokio_util::sync::CancellationToken;

use super::game::Viewing;
use super::gate::RequestGate;
use super::hub::Hub;
use super::leave::{self, Leave};
use super::limits::PlayerSlot;
use super::tally::Tally;

/// What the connection's handler tells the player task about its terminal.
#[derive(Debug, Clone, Copy)]
pub struct TerminalState {
    /// The terminal's size in cells, clamped.
    pub size: (u16, u16),
    /// Set when the client closed its side.
    pub closed: bool,
}

/// Everything the task owns.
pub(crate) struct ViewerCtx {
    pub hub: Arc<Hub>,
    pub id: u64,
    pub peer: SocketAddr,
    pub write: ChannelWriteHalf<Msg>,
    pub terminal: watch::Receiver<TerminalState>,
    /// The channel's packets and when each arrived: the link's answers are timed by their
    /// arrival, not by when this task got to them (after a frame's encoding or a write that
    /// waited for the client's window).
    pub input: mpsc::Receiver<(Instant, Vec<u8>)>,
    pub screen: ScreenConfig,
    pub kill: CancellationToken,
    pub slot: PlayerSlot,
}

/// The frame buffer a player in step with its group keeps at most, in bytes.
const IN_STEP_BUFFER: usize = 64 * 1024;

/// How soon a new terminal size that had to wait is tried again.
const RESIZE_RETRY: std::time::Duration = std::time::Duration::from_millis(100);

/// Runs the player until it leaves, then says goodbye (bounded in time) and frees its place.
pub(crate) async fn run(ctx: ViewerCtx) {
    let ViewerCtx { hub, id, peer, write, mut terminal, mut input, screen, kill, slot } = ctx;
    let stats = hub.stats.clone();
    let now = Instant::now();
    let screen = Screen::new(screen, terminal.borrow().size, now);
    let mut player = Player::new(screen, hub.scene_size, Some("shared pool: all see your stones".into()));
    if !hub.screenshots {
        player = player.without_screenshots();
    }
    let mut membership = Membership::new();
    let mut viewing = Viewing { fit: *player.seat.fit(), group: None };
    hub.fits.lock().unwrap_or_else(|p| p.into_inner()).insert(id, viewing);
    let mut frames = hub.frames.clone();
    let mut gate = RequestGate::new(&hub.limits, id);
    let mut resizes = hub.limits.resizes_bucket();
    // A new terminal size waiting for the resize rate.
    let mut resize: Option<(u16, u16)> = None;
    let mut requests = Vec::new();
    let mut out = Vec::new();
    let (mut last_input, mut owed, mut deferred) = (now, false, false);
    let mut tally = Tally::default();
    let mut scene_name = frames.borrow().status.name;

    let reason = 'game: {
        let mut asked = Vec::new();
        player.screen.start(now, &mut asked);
        if !asked.is_empty() && write.data_bytes(Bytes::from(asked)).await.is_err() {
            break 'game Leave::Cut;
        }
        loop {
            let idle_at = last_input + hub.limits.idle_timeout;
            // The screen's own deadlines only: frames follow the shared pictures.
            let tick = player.screen.next_tick();
            let mut fresh = false;
            tokio::select! {
                biased;
                _ = kill.cancelled() => break 'game Leave::Cut,
                _ = hub.shutdown.cancelled() => break 'game Leave::Shutdown,
                changed = terminal.changed() => {
                    if changed.is_err() { break 'game Leave::Cut; }
                    let state = *terminal.borrow_and_update();
                    if state.closed { break 'game Leave::ClientClosed; }
                    resize = Some(state.size);
                }
                _ = tokio::time::sleep(RESIZE_RETRY), if resize.is_some() => {}
                bytes = input.recv() => {
                    let Some((arrived, bytes)) = bytes else { break 'game Leave::Cut };
                    if player.feed(&bytes, arrived) {
                        last_input = Instant::now();
                    }
                }
                _ = tokio::time::sleep_until(tick.unwrap_or(idle_at).into()), if tick.is_some() => {}
                _ = tokio::time::sleep_until(idle_at.into()) => {
                    if last_input + hub.limits.idle_timeout <= Instant::now() {
                        stats.idle_kicks.fetch_add(1, Ordering::Relaxed);
                        break 'game Leave::Idle;
                    }
                }
                changed = frames.changed() => {
                    if changed.is_err() { break 'game Leave::Shutdown; }
                    fresh = true;
                }
            }
            let now = Instant::now();
            if let Some(size) = resize {
                if resizes.try_take(1.0, now) {
                    player.screen.resize(size);
                    tally.resizes += 1;
                    resize = None;
                } else if !deferred {
                    stats.resizes_deferred.fetch_add(1, Ordering::Relaxed);
                }
                deferred = resize.is_some();
            }
            let shared = frames.borrow().clone();
            scene_name = shared.status.name;
            let turn = player.turn(now, &shared.status, &mut requests);
            if turn.flow == Flow::Quit {
                break 'game Leave::Quit;
            }
            for request in requests.drain(..) {
                tally.request(gate.send(request, &hub, now));
            }
            if turn.layout_changed {
                player.refit(hub.scene_size);
                membership.reset();
            }
            let now_viewing = Viewing { fit: *player.seat.fit(), group: membership.key(&player.screen) };
            if (now_viewing.fit, now_viewing.group) != (viewing.fit, viewing.group) {
                viewing = now_viewing;
                hub.fits.lock().unwrap_or_else(|p| p.into_inner()).insert(id, viewing);
            }
            owed |= turn.urgent || turn.layout_changed;
            // A new shared picture or a key's frame: the game's rate paces the frames.
            if !(fresh || owed) || !player.screen.ready(now, true) {
                continue;
            }
            tally.count(&shared);
            // Just resized: the next shared frame has this size.
            let Some(picture) = shared.pictures.get(&player.seat.fit().target()).cloned() else { continue };
            if !hub.outbound.lock().unwrap_or_else(|p| p.into_inner()).try_take(0.0, now) {
                stats.frames_dropped_rate.fetch_add(1, Ordering::Relaxed);
                continue;
            }
            owed = false;
            // The frame is built in a buffer kept from frame to frame (the screen reserves room
            // for its largest frame in it) and copied out at its own size: handing the buffer
            // itself to russh would hold that reservation per frame in flight.
            out.clear();
            let feed = viewing.group.and_then(|key| shared.groups.get(&key));
            let Ok((len, source)) = membership.frame(&mut player, now, &picture, &shared.status, feed, &mut out) else {
                continue;
            };
            if len == 0 {
                continue;
            }
            let from_group = source == Source::Group;
            hub.outbound.lock().unwrap_or_else(|p| p.into_inner()).owe(len);
            // data_bytes waits for the client's SSH window and for room in russh's queue: that
            // wait is the backpressure. Meanwhile newer pictures replace older ones in the slot.
            tokio::select! {
                biased;
                _ = kill.cancelled() => break 'game Leave::Cut,
                _ = hub.shutdown.cancelled() => break 'game Leave::Shutdown,
                done = write.data_bytes(Bytes::copy_from_slice(&out)) => {
                    if done.is_err() { break 'game Leave::Cut; }
                    tally.sent += 1;
                    tally.from_group += u64::from(from_group);
                    if membership.in_step() && out.capacity() > IN_STEP_BUFFER {
                        // Room for a whole frame of its own is not needed while the group's
                        // bytes come: give it back (it comes again if the player leaves).
                        out = Vec::new();
                    }
                    tally.bytes += len as u64;
                    stats.frames_sent.fetch_add(1, Ordering::Relaxed);
                }
                _ = tokio::time::sleep(hub.limits.stall_timeout) => {
                    stats.stall_kicks.fetch_add(1, Ordering::Relaxed);
                    break 'game Leave::Stalled;
                }
            }
        }
    };

    hub.fits.lock().unwrap_or_else(|p| p.into_inner()).remove(&id);
    drop(slot); // the place is free as soon as the game ends
    let published = frames.borrow().number;
    stats.frames_skipped.fetch_add(tally.skipped(published), Ordering::Relaxed);
    let rate = player.screen.rate();
    eprintln!("{}", tally.report(peer, id, reason, published, rate, &membership));
    let mut goodbye = Vec::new();
    player.screen.farewell(&mut goodbye);
    leave::say_goodbye(reason, scene_name, goodbye, &write, &kill).await;
}
