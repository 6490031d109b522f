//! One task per player: the play session's [`Driver`] (the turn every door takes) on an SSH
//! channel, paced by the shared pictures. The channel's bytes go to the driver (the terminal's
//! answers stay in its screen: the graphics probe, the link's round trips), the seat's
//! requests to the shared host through the player's gate; the newest shared picture becomes
//! this player's frame. A frame is built only while the player's earlier frames hold fewer than
//! `FLIGHT_BUDGET_BYTES` in russh (`flight.rs`), so a slow player skips pictures, and the link
//! control finds each player's own rate. This file is the channel's I/O only.
//!
//! Bounded everywhere: the pictures are the one `watch` slot every player shares (newest wins),
//! input is a bounded queue of the channel's packets (the SSH window bounds each), the frames
//! handed to russh and not yet taken into its write buffer by the byte budget (and russh's
//! queue by `SESSION_EVENT_QUEUE` messages), and the kernel holds at most
//! `SOCKET_SEND_BUFFER_BYTES`.

use std::net::SocketAddr;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::Instant;

use crate::output::bucket::ByteBucket;
use crate::play::group::{Membership, Source};
use crate::play::{Driver, DriverEvent, Pacing, Player, Screen, ScreenConfig};
use bytes::Bytes;
use tokio::sync::{mpsc, watch};
use tokio_util::sync::CancellationToken;

use super::channel::{Channel, now as clock};
use super::flight::Flight;
use super::game::{SharedFrame, Viewing};
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

/// Everything the task owns; `W` is the channel's write half (`ChannelWriteHalf`, or a test's
/// memory).
pub(crate) struct ViewerCtx<W> {
    pub hub: Arc<Hub>,
    pub id: u64,
    pub peer: SocketAddr,
    pub write: W,
    pub terminal: watch::Receiver<TerminalState>,
    /// The channel's packets and when each arrived: the link's answers are timed by their
    /// arrival, not by when this task got to them (after a frame's encoding or a write that
    /// waited for the client's window).
    pub input: mpsc::Receiver<(Instant, Vec<u8>)>,
    pub screen: ScreenConfig,
    pub kill: CancellationToken,
    pub slot: PlayerSlot,
}

thread_local! {
    /// The buffer frames are built in, one per thread of the runtime (a frame is built without
    /// a pause, so no other player's task runs on the thread meanwhile): a player keeps only
    /// its frame's bytes until they are written, at their own size (issue 31: a buffer per
    /// player held room for its largest frame as long as it played).
    static BUILD: std::cell::RefCell<Vec<u8>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// How soon a new terminal size that had to wait is tried again.
const RESIZE_RETRY: std::time::Duration = std::time::Duration::from_millis(100);

/// Runs the player until it leaves, then says goodbye (bounded in time) and frees its place.
pub(crate) async fn run<W: Channel>(ctx: ViewerCtx<W>) {
    let ViewerCtx { hub, id, peer, write, mut terminal, mut input, screen, kill, slot } = ctx;
    let now = clock();
    let player = new_player(&hub, screen, terminal.borrow().size, now);
    let viewing = Viewing { fit: *player.fit(), group: None, note: None };
    hub.fits.lock().unwrap_or_else(|p| p.into_inner()).insert(id, viewing.clone());
    let mut frames = hub.frames.clone();
    let mut v = Viewer {
        driver: Driver::new(player, Pacing::Pictures),
        membership: Membership::new(),
        viewing,
        gate: RequestGate::new(&hub.limits, id),
        resizes: hub.limits.resizes_bucket(),
        resize: None,
        deferred: false,
        last_input: now,
        out: Bytes::new(),
        flight: Flight::default(),
        from_group: false,
        tally: Tally::default(),
        scene_name: frames.borrow().status.name,
        hub,
        id,
    };
    let reason = v.play(&write, &mut terminal, &mut input, &mut frames, &kill).await;
    let Viewer { hub, driver, membership, tally, scene_name, .. } = v;
    hub.fits.lock().unwrap_or_else(|p| p.into_inner()).remove(&id);
    drop(slot); // the place is free as soon as the game ends
    let published = frames.borrow().number;
    hub.stats.frames_skipped.fetch_add(tally.skipped(published), Ordering::Relaxed);
    let rate = driver.player().screen.rate();
    eprintln!("{}", tally.report(peer, id, reason, published, rate, &membership));
    let mut goodbye = Vec::new();
    driver.player().screen.farewell(&mut goodbye);
    leave::say_goodbye(reason, scene_name, goodbye, &write, &kill).await;
}

/// A new player on a terminal of `size` cells at `now`, as the server greets them.
fn new_player(hub: &Hub, screen: ScreenConfig, size: (u16, u16), now: Instant) -> Player {
    let screen = Screen::new(screen, size, now);
    let player = Player::new(screen, hub.scene_size, Some("shared pool: all see your stones".into()));
    if hub.screenshots { player } else { player.without_screenshots() }
}

/// One player's state beside its driver: its group membership, what it views, its limits.
struct Viewer {
    hub: Arc<Hub>,
    id: u64,
    driver: Driver,
    membership: Membership,
    viewing: Viewing,
    gate: RequestGate,
    resizes: ByteBucket,
    /// A new terminal size waiting for the resize rate, and whether that was counted.
    resize: Option<(u16, u16)>,
    deferred: bool,
    last_input: Instant,
    /// The frame to write, and whether its bytes are the group's.
    out: Bytes,
    /// This player's frames handed to russh and not yet taken by it, in bytes.
    flight: Flight,
    from_group: bool,
    tally: Tally,
    scene_name: &'static str,
}

impl Viewer {
    /// The channel's loop: wait for bytes, a new size, a new picture or a deadline; take the
    /// turn; send the frame when one goes. Returns why the player left.
    async fn play(
        &mut self,
        write: &impl Channel,
        terminal: &mut watch::Receiver<TerminalState>,
        input: &mut mpsc::Receiver<(Instant, Vec<u8>)>,
        frames: &mut watch::Receiver<Arc<SharedFrame>>,
        kill: &CancellationToken,
    ) -> Leave {
        let hub = self.hub.clone();
        let mut asked = Vec::new();
        self.driver.start(clock(), &mut asked);
        if !asked.is_empty() && write.data(Bytes::from(asked)).await.is_err() {
            return Leave::Cut;
        }
        loop {
            let idle_at = self.last_input + hub.limits.idle_timeout;
            // The driver's own deadlines only: frames follow the shared pictures.
            let tick = self.driver.poll_timeout();
            tokio::select! {
                biased;
                _ = kill.cancelled() => return Leave::Cut,
                _ = hub.shutdown.cancelled() => return Leave::Shutdown,
                changed = terminal.changed() => {
                    if changed.is_err() { return Leave::Cut; }
                    let state = *terminal.borrow_and_update();
                    if state.closed { return Leave::ClientClosed; }
                    self.resize = Some(state.size);
                }
                _ = tokio::time::sleep(RESIZE_RETRY), if self.resize.is_some() => {}
                bytes = input.recv() => {
                    let Some((arrived, bytes)) = bytes else { return Leave::Cut };
                    if self.driver.handle_bytes(&bytes, arrived) {
                        self.last_input = clock();
                    }
                }
                _ = tokio::time::sleep_until(tick.unwrap_or(idle_at).into()), if tick.is_some() => {}
                _ = tokio::time::sleep_until(idle_at.into()) => {
                    if self.last_input + hub.limits.idle_timeout <= clock() {
                        hub.stats.idle_kicks.fetch_add(1, Ordering::Relaxed);
                        return Leave::Idle;
                    }
                }
                changed = frames.changed() => {
                    if changed.is_err() { return Leave::Shutdown; }
                    self.driver.handle_picture();
                }
                // Over the budget: the waiting picture or key's frame goes when bytes land.
                _ = self.flight.landed(), if !self.flight.has_room() => {}
            }
            let now = clock();
            let shared = frames.borrow().clone();
            if let Some(leave) = self.turn(now, &shared) {
                return leave;
            }
            if !self.frame(now, &shared) {
                continue;
            }
            // The frame's question leaves now: building the frame on a loaded server is the
            // player's time, not the link's.
            self.driver.handle_written(clock());
            if let Some(leave) = self.send(write, kill).await {
                return leave;
            }
        }
    }

    /// The turn at `now`: a waiting resize within its rate, the driver's turn, the seat's
    /// requests through the gate, a new layout; `Some` when the player leaves.
    fn turn(&mut self, now: Instant, shared: &SharedFrame) -> Option<Leave> {
        if let Some(size) = self.resize {
            if self.resizes.try_take(1.0, now) {
                self.driver.handle_resize(size);
                self.tally.resizes += 1;
                self.resize = None;
            } else if !self.deferred {
                self.hub.stats.resizes_deferred.fetch_add(1, Ordering::Relaxed);
            }
            self.deferred = self.resize.is_some();
        }
        self.scene_name = shared.status.name;
        self.driver.handle_timeout(now, &shared.status);
        while let Some(event) = self.driver.poll_event() {
            match event {
                DriverEvent::Quit => return Some(Leave::Quit),
                DriverEvent::Request(request) => self.tally.request(self.gate.send(request, &self.hub, now)),
                DriverEvent::Layout => {
                    self.driver.refit(self.hub.scene_size);
                    self.membership.reset();
                }
            }
        }
        let player = self.driver.player();
        let message = player.message(now);
        let (fit, group) = (*player.fit(), self.membership.key(&player.screen).map(|k| k.with_note(message)));
        if (fit, group) != (self.viewing.fit, self.viewing.group) {
            // The note's text travels with the key, to the group that shows it.
            let note = message.filter(|_| group.is_some()).map(Arc::from);
            self.viewing = Viewing { fit, group, note };
            self.hub.fits.lock().unwrap_or_else(|p| p.into_inner()).insert(self.id, self.viewing.clone());
        }
        None
    }

    /// Builds the frame for `now` into `self.out` when one goes (a new shared picture or a
    /// key's frame, within the server's outbound rate); whether there is one to send.
    fn frame(&mut self, now: Instant, shared: &SharedFrame) -> bool {
        // The last write was awaited; a new frame waits (the driver keeps what it owes and
        // that a picture came) while the earlier ones hold the budget in russh.
        if !self.flight.has_room() || !self.driver.poll_frame(now, true) {
            return false;
        }
        self.tally.count(shared);
        // Just resized: the next shared frame has this size.
        let Some(picture) = shared.pictures.get(&self.driver.player().fit().target()).cloned() else {
            return false;
        };
        if !self.hub.outbound.lock().unwrap_or_else(|p| p.into_inner()).try_take(0.0, now) {
            self.hub.stats.frames_dropped_rate.fetch_add(1, Ordering::Relaxed);
            return false;
        }
        self.driver.sent();
        // The frame is built in the thread's buffer (the screen reserves room for its largest
        // frame in it) and copied out at its own size: handing the buffer itself to russh
        // would hold that reservation per frame in flight.
        let feed = self.viewing.group.and_then(|key| shared.groups.get(&key));
        let player = self.driver.player_mut();
        let (len, source) = BUILD.with_borrow_mut(|out| {
            out.clear();
            let made = self.membership.frame(player, now, &picture, &shared.status, feed, out);
            self.out = if made.0 == 0 { Bytes::new() } else { self.flight.carry(out) };
            made
        });
        if len == 0 {
            return false;
        }
        self.from_group = source == Source::Group;
        self.hub.outbound.lock().unwrap_or_else(|p| p.into_inner()).owe(len);
        true
    }

    /// Sends `self.out` (and lets it go). The write waits for the client's SSH window and for
    /// room in russh's queue: that wait is the backpressure (newer pictures replace older ones
    /// in the slot meanwhile). `Some` when the player is cut.
    async fn send(&mut self, write: &impl Channel, kill: &CancellationToken) -> Option<Leave> {
        let (hub, len) = (&self.hub, self.out.len());
        tokio::select! {
            biased;
            _ = kill.cancelled() => Some(Leave::Cut),
            _ = hub.shutdown.cancelled() => Some(Leave::Shutdown),
            done = write.data(std::mem::take(&mut self.out)) => {
                if done.is_err() { return Some(Leave::Cut); }
                self.tally.sent += 1;
                self.tally.from_group += u64::from(self.from_group);
                self.tally.bytes += len as u64;
                hub.stats.frames_sent.fetch_add(1, Ordering::Relaxed);
                None
            }
            _ = tokio::time::sleep(hub.limits.stall_timeout) => {
                hub.stats.stall_kicks.fetch_add(1, Ordering::Relaxed);
                Some(Leave::Stalled)
            }
        }
    }
}

#[cfg(test)]
mod tests;
