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
use std::time::{Duration, Instant};

use bytes::Bytes;
use russh::ChannelWriteHalf;
use russh::server::Msg;
use tidepool::play::{Flow, Screen, ScreenConfig, Seat};
use tokio::sync::{mpsc, watch};
use tokio_util::sync::CancellationToken;

use super::game::SharedFrame;
use super::hub::Hub;
use super::limits::{FAREWELL_TIMEOUT, PlayerSlot};

/// Time a player's connection may stay open after its game ended before it is cut.
pub const LINGER: Duration = Duration::from_secs(1);

/// Why a player leaves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Leave {
    /// Pressed q, Esc or Ctrl-C.
    Quit,
    /// Sent EOF or closed the channel.
    ClientClosed,
    /// No key for the idle timeout.
    Idle,
    /// A frame could not be sent within the stall timeout.
    Stalled,
    /// The server is stopping.
    Shutdown,
    /// The connection was cut (it ended, or the server cut it).
    Cut,
}

impl Leave {
    fn farewell(self, scene: &str) -> Option<String> {
        match self {
            Leave::Quit => Some(format!("bye from the {scene}")),
            Leave::Idle => Some(format!("you were idle too long; the {scene} sent you home")),
            Leave::Shutdown => Some(format!("the {scene} is closing (server shutting down); bye")),
            Leave::Stalled | Leave::ClientClosed | Leave::Cut => None,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Leave::Quit => "quit",
            Leave::ClientClosed => "closed",
            Leave::Idle => "idle",
            Leave::Stalled => "stalled",
            Leave::Shutdown => "shutdown",
            Leave::Cut => "cut",
        }
    }
}

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
    pub input: mpsc::Receiver<Vec<u8>>,
    pub screen: ScreenConfig,
    pub kill: CancellationToken,
    pub slot: PlayerSlot,
}

/// What one player's game did, for the log.
#[derive(Default)]
struct Tally {
    first: Option<u64>,
    last: u64,
    sent: u64,
    skipped: u64,
    bytes: u64,
}

/// Runs the player until it leaves, then says goodbye (bounded in time) and frees its place.
pub(crate) async fn run(ctx: ViewerCtx) {
    let ViewerCtx { hub, id, peer, write, mut terminal, mut input, screen, kill, slot } = ctx;
    let stats = hub.stats.clone();
    let now = Instant::now();
    let mut screen = Screen::new(screen, terminal.borrow().size, now);
    let mut seat = Seat::new(screen.fit(hub.scene_size)).without_screenshots();
    hub.fits.lock().unwrap_or_else(|p| p.into_inner()).insert(id, *seat.fit());
    let mut frames = hub.frames.clone();
    let mut actions = hub.limits.actions_bucket();
    let (mut inputs, mut requests) = (Vec::new(), Vec::new());
    let mut last_input = now;
    let mut owed = false;
    let mut greeting = Some("shared pool: all see your stones".to_string());
    let mut tally = Tally::default();
    let mut scene_name = frames.borrow().status.name;

    let reason = 'game: {
        let mut asked = Vec::new();
        screen.start(now, &mut asked);
        if !asked.is_empty() && write.data_bytes(Bytes::from(asked)).await.is_err() {
            break 'game Leave::Cut;
        }
        loop {
            let idle_at = last_input + hub.limits.idle_timeout;
            // The screen's own deadlines only: frames follow the shared pictures.
            let tick = screen.next_tick();
            let mut fresh = false;
            tokio::select! {
                biased;
                _ = kill.cancelled() => break 'game Leave::Cut,
                _ = hub.shutdown.cancelled() => break 'game Leave::Shutdown,
                changed = terminal.changed() => {
                    if changed.is_err() { break 'game Leave::Cut; }
                    let state = *terminal.borrow_and_update();
                    if state.closed { break 'game Leave::ClientClosed; }
                    screen.resize(state.size);
                }
                bytes = input.recv() => {
                    let Some(bytes) = bytes else { break 'game Leave::Cut };
                    let before = inputs.len();
                    screen.feed(&bytes, Instant::now(), &mut inputs);
                    if inputs.len() > before {
                        // Only the person counts: the terminal's own answers are no sign of life.
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
            screen.tick(now, &mut inputs);
            if screen.take_layout_change() {
                seat.set_fit(screen.fit(hub.scene_size));
                hub.fits.lock().unwrap_or_else(|p| p.into_inner()).insert(id, *seat.fit());
                owed = true;
            }
            if !screen.probing()
                && let Some(greeting) = greeting.take()
            {
                let notice = screen.take_notice().map_or(String::new(), |n| format!("{n}; "));
                seat.greet(format!("{notice}{greeting}"), now);
            } else if let Some(notice) = screen.take_notice() {
                seat.say(notice, now);
            }
            owed |= !inputs.is_empty();
            let shared = frames.borrow().clone();
            for i in inputs.drain(..) {
                if seat.handle(i, now, &shared.status, &mut requests) == Flow::Quit {
                    break 'game Leave::Quit;
                }
                for request in requests.drain(..) {
                    if !actions.try_take(1.0, now) || hub.requests.try_send(request).is_err() {
                        stats.actions_dropped.fetch_add(1, Ordering::Relaxed);
                    }
                }
            }
            scene_name = shared.status.name;
            // A new shared picture or a key's frame: the game's rate paces the frames.
            if !(fresh || owed) || !screen.ready(now, true) {
                continue;
            }
            tally.count(&shared);
            // Just resized: the next shared frame has this size.
            let Some(picture) = shared.pictures.get(&seat.fit().target()).cloned() else { continue };
            if !hub.outbound.lock().unwrap_or_else(|p| p.into_inner()).try_take(0.0, now) {
                stats.frames_dropped_rate.fetch_add(1, Ordering::Relaxed);
                screen.skip(now);
                continue;
            }
            owed = false;
            // The frame's bytes go to russh as `Bytes`, so a buffer cannot be kept between frames.
            let mut out = Vec::new();
            let view = seat.view(now, &shared.status);
            let Ok(len) = screen.frame(now, &picture, &shared.status, &view, &mut out) else { continue };
            if len == 0 {
                continue;
            }
            hub.outbound.lock().unwrap_or_else(|p| p.into_inner()).owe(len);
            // data_bytes waits for the client's SSH window and for room in russh's queue: that
            // wait is the backpressure. Meanwhile newer pictures replace older ones in the slot.
            tokio::select! {
                biased;
                _ = kill.cancelled() => break 'game Leave::Cut,
                _ = hub.shutdown.cancelled() => break 'game Leave::Shutdown,
                done = write.data_bytes(Bytes::from(out)) => {
                    if done.is_err() { break 'game Leave::Cut; }
                    tally.sent += 1;
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
    let skipped = tally.finish(published);
    stats.frames_skipped.fetch_add(skipped, Ordering::Relaxed);
    let seen = tally.first.map_or(0, |first| published.saturating_sub(first) + 1);
    eprintln!(
        "serve: {peer} #{id} left ({}): {} frames sent, {skipped} skipped of {seen} published, {} bytes",
        reason.name(),
        tally.sent,
        tally.bytes
    );
    let mut goodbye = Vec::new();
    screen.farewell(&mut goodbye);
    match reason.farewell(scene_name) {
        Some(message) => {
            goodbye.extend_from_slice(format!("{message}\r\n").as_bytes());
            let _ = tokio::time::timeout(FAREWELL_TIMEOUT, async {
                write.data_bytes(Bytes::from(goodbye)).await.ok()?;
                write.exit_status(0).await.ok()?;
                write.eof().await.ok()?;
                // No DISCONNECT after this: OpenSSH exits on DISCONNECT before writing channel
                // data it has already received, so the farewell and the restore would be lost.
                write.close().await.ok()
            })
            .await;
        }
        None if reason == Leave::ClientClosed => {
            let _ = tokio::time::timeout(FAREWELL_TIMEOUT, async {
                write.data_bytes(Bytes::from(goodbye)).await.ok()?;
                write.close().await.ok()
            })
            .await;
        }
        None => {}
    }
    match reason {
        Leave::Cut => {}
        // It is not reading: nothing more will get through, cut now.
        Leave::Stalled => kill.cancel(),
        // A client that keeps the connection open after its game ended is cut shortly after.
        _ => {
            tokio::select! {
                _ = kill.cancelled() => {}
                _ = tokio::time::sleep(LINGER) => kill.cancel(),
            }
        }
    }
}

impl Tally {
    /// A frame of `shared` is being drawn: pictures published since the last one were skipped.
    fn count(&mut self, shared: &SharedFrame) {
        self.first.get_or_insert(shared.number);
        if self.last != 0 && shared.number > self.last + 1 {
            self.skipped += shared.number - self.last - 1;
        }
        self.last = self.last.max(shared.number);
    }

    /// The pictures skipped in all, with those published after the last one drawn.
    fn finish(&self, published: u64) -> u64 {
        self.skipped + if self.last != 0 { published.saturating_sub(self.last) } else { 0 }
    }
}
