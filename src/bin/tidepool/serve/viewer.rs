//! One task per player: the player's keys and clicks become shared actions, and the newest
//! shared picture becomes this player's frame: its own size, colours, status line, help and
//! aim marker, its own screen model, encoder and byte budget. Never more than one frame in
//! flight, so a slow player simply skips pictures.
//!
//! Bounded everywhere: the pictures are the one `watch` slot every player shares (newest
//! wins), input is a bounded queue of the channel's packets (the SSH window bounds each), and
//! below us russh holds at most `SESSION_EVENT_QUEUE` messages and the kernel at most
//! `SOCKET_SEND_BUFFER_BYTES`.

use std::net::SocketAddr;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use bytes::Bytes;
use russh::ChannelWriteHalf;
use russh::server::Msg;
use tidepool::Action;
use tidepool::player::{DEFAULT_STONE_RADIUS, coalesce};
use tidepool::player::{ENTER, FrameBuilder, Input, InputParser, Overlay, RESTORE, STONE_RADII, picture_size};
use tidepool::terminal::{ByteBucket, ColorMode, EncodeOptions, RateEncoder, RateOptions, Shown, Target};
use tokio::sync::{mpsc, watch};
use tokio_util::sync::CancellationToken;

use super::game::{Cells, Pictures, Shared};
use super::hub::Hub;
use super::letterbox::Letterbox;
use super::limits::{FAREWELL_TIMEOUT, PlayerSlot, TokenBucket};

/// Time a player's connection may stay open after its game ended before it is cut.
pub const LINGER: Duration = Duration::from_secs(1);
/// How long the aim marker stays after the last aim key.
const AIM_VISIBLE: Duration = Duration::from_secs(4);
/// How long a status message stays.
const MESSAGE_VISIBLE: Duration = Duration::from_secs(4);
/// How long the greeting stays.
const GREETING_VISIBLE: Duration = Duration::from_secs(8);
/// Colour changes of at most this much per channel are not re-sent (as `play` does over SSH).
const COLOR_THRESHOLD: u8 = 3;
/// Below this many bytes a second, cells may be sent approximately first (as in the player).
const APPROXIMATE_BELOW: f64 = 1_000_000.0;
/// Scene pixels one press of an arrow key moves the aim.
const AIM_STEP: i32 = 2;

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
    fn farewell(self) -> Option<&'static str> {
        match self {
            Leave::Quit => Some("bye from the pool"),
            Leave::Idle => Some("you were idle too long; the pool sent you home"),
            Leave::Shutdown => Some("the pool is closing (server shutting down); bye"),
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

/// What the connection's handler tells the player task.
#[derive(Debug, Clone, Copy)]
pub struct Control {
    /// The terminal's size, clamped.
    pub size: Cells,
    /// Set when the client closed its side.
    pub closed: bool,
}

/// Everything the task owns.
pub(crate) struct ViewerCtx {
    pub hub: Arc<Hub>,
    pub id: u64,
    pub peer: SocketAddr,
    pub write: ChannelWriteHalf<Msg>,
    pub control: watch::Receiver<Control>,
    pub input: mpsc::Receiver<Vec<u8>>,
    pub color: ColorMode,
    pub kill: CancellationToken,
    pub slot: PlayerSlot,
}

/// The player's own state: what is theirs alone in the shared pool.
struct Viewer {
    hub: Arc<Hub>,
    size: Cells,
    scene_size: (u32, u32),
    aim: (i32, i32),
    aim_until: Option<Instant>,
    radius: u32,
    help: bool,
    drag: Option<(i32, i32)>,
    message: Option<(&'static str, Instant)>,
    actions: TokenBucket,
}

impl Viewer {
    fn fit(&self) -> Letterbox {
        Letterbox::fit(self.scene_size, picture_size(self.size.0, self.size.1))
    }

    fn say(&mut self, message: &'static str, how_long: Duration) {
        self.message = Some((message, Instant::now() + how_long));
    }

    /// Sends an action to the shared scene, within this player's rate.
    fn share(&mut self, action: Shared) {
        let stats = &self.hub.stats;
        if !self.actions.try_take(1.0) || self.hub.actions.try_send(action).is_err() {
            stats.actions_dropped.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// The scene pixel under cell (col, row), if the cell shows the scene.
    fn pixel_at(&self, col: u16, row: u16) -> Option<(i32, i32)> {
        if row + 1 >= self.size.1 {
            return None; // the status line
        }
        self.fit().to_scene(i32::from(col), 2 * i32::from(row))
    }

    fn handle(&mut self, input: Input) -> Option<Leave> {
        let (w, h) = (self.scene_size.0 as i32, self.scene_size.1 as i32);
        let radius = self.radius;
        match input {
            Input::Quit => return Some(Leave::Quit),
            Input::Escape if self.help => self.help = false,
            Input::Escape => return Some(Leave::Quit),
            Input::Help => self.help = !self.help,
            Input::RandomStone => self.share(Shared::RandomStone(radius)),
            Input::Aim(dx, dy) => {
                self.aim = ((self.aim.0 + AIM_STEP * dx).clamp(0, w - 1), (self.aim.1 + AIM_STEP * dy).clamp(0, h - 1));
                self.aim_until = Some(Instant::now() + AIM_VISIBLE);
            }
            Input::DropAtAim => {
                let (x, y) = self.aim;
                self.aim_until = Some(Instant::now() + AIM_VISIBLE);
                self.share(Shared::Act(Action::Stone { x, y, radius, big: false }));
            }
            Input::ToggleRain => self.share(Shared::Act(Action::ToggleRain)),
            Input::Clear => self.share(Shared::Act(Action::Clear)),
            Input::Damping(stronger) => self.share(Shared::Act(Action::Damping(stronger))),
            Input::StoneSize(bigger) => {
                let i = STONE_RADII.iter().position(|&r| r >= self.radius).unwrap_or(0);
                let i = if bigger { (i + 1).min(STONE_RADII.len() - 1) } else { i.saturating_sub(1) };
                self.radius = STONE_RADII[i];
            }
            Input::Pause => self.share(Shared::Pause),
            Input::NextScene => self.share(Shared::NextScene),
            // The server never writes a file on a player's behalf.
            Input::Screenshot => self.say("screenshots are off on a shared pool", MESSAGE_VISIBLE),
            Input::Other(c) => self.share(Shared::Act(Action::Key(c))),
            Input::Press { col, row, big } => {
                if let Some((x, y)) = self.pixel_at(col, row) {
                    self.share(Shared::Act(Action::Stone { x, y, radius, big }));
                    self.drag = (!big).then_some((x, y));
                }
            }
            Input::Drag { col, row } => {
                if let (Some(from), Some(to)) = (self.drag, self.pixel_at(col, row))
                    && from != to
                {
                    self.share(Shared::Act(Action::Stir { from, to }));
                    self.drag = Some(to);
                }
            }
            Input::Release => self.drag = None,
            Input::Resize(..) | Input::CursorReport(..) | Input::DeviceAttributes => {}
        }
        None
    }

    /// This player's overlay over `set`'s picture.
    fn overlay<'a>(&self, set: &'a Pictures, now: Instant, fps: u32, rate: u64) -> Overlay<'a> {
        let fit = self.fit();
        let aim = self.aim_until.filter(|t| now < *t).map(|_| {
            let (x, y) = fit.to_target(self.aim.0, self.aim.1);
            (x.max(0) as u32, (y.max(0) as u32) & !1)
        });
        Overlay {
            aim,
            help: self.help.then_some(set.info.help.as_slice()),
            message: None,
            fps,
            bytes_per_second: rate,
            // The link's rate is the server's setting, the same for all: not worth the room.
            bandwidth: None,
            stone: self.radius,
            paused: set.paused,
            // Remote players get half-block cells: no image protocol over the shared pool.
            pixels_elsewhere: false,
        }
    }
}

/// Frames and bytes a second, over the last whole second.
#[derive(Default)]
struct Meter {
    since: Option<Instant>,
    frames: u32,
    bytes: u64,
    fps: u32,
    rate: u64,
}

impl Meter {
    fn sent(&mut self, now: Instant, bytes: usize) {
        let since = *self.since.get_or_insert(now);
        self.frames += 1;
        self.bytes += bytes as u64;
        if now - since >= Duration::from_secs(1) {
            (self.fps, self.rate) = (self.frames, self.bytes);
            (self.frames, self.bytes, self.since) = (0, 0, Some(now));
        }
    }
}

/// Runs the player until it leaves, then says goodbye (bounded in time) and frees its place.
pub(crate) async fn run(ctx: ViewerCtx) {
    let ViewerCtx { hub, id, peer, write, mut control, mut input, color, kill, slot } = ctx;
    let stats = hub.stats.clone();
    let scene_size = hub.scene_size;
    let mut viewer = Viewer {
        size: control.borrow().size,
        scene_size,
        aim: ((scene_size.0 / 2) as i32, (scene_size.1 / 2) as i32),
        aim_until: None,
        radius: DEFAULT_STONE_RADIUS,
        help: false,
        drag: None,
        message: None,
        actions: TokenBucket::new(hub.limits.actions_per_second as f64),
        hub: hub.clone(),
    };
    viewer.say("shared pool: all see your stones", GREETING_VISIBLE);
    hub.sizes.lock().unwrap_or_else(|p| p.into_inner()).insert(id, viewer.size);
    let mut frames = hub.frames.clone();
    frames.mark_changed();
    let mut parser = InputParser::new();
    let mut inputs = Vec::new();
    let mut last_input = Instant::now();
    let mut builder = FrameBuilder::default();
    let mut encoder = RateEncoder::new();
    let mut shown = Shown::UNKNOWN;
    let mut bucket = ByteBucket::new(hub.limits.client_bytes_per_second as f64);
    let options = RateOptions {
        approximate: (hub.limits.client_bytes_per_second as f64) < APPROXIMATE_BELOW,
        ..RateOptions::from(EncodeOptions { threshold: COLOR_THRESHOLD, sync: true })
    };
    let mut meter = Meter::default();
    let (mut first_number, mut last_number) = (None, 0u64);
    let (mut sent, mut skipped, mut bytes_total) = (0u64, 0u64, 0u64);

    let reason = 'game: {
        if write.data_bytes(Bytes::from_static(ENTER)).await.is_err() {
            break 'game Leave::Cut;
        }
        loop {
            let idle_at = last_input + hub.limits.idle_timeout;
            let escape_at = parser.deadline();
            tokio::select! {
                biased;
                _ = kill.cancelled() => break 'game Leave::Cut,
                _ = hub.shutdown.cancelled() => break 'game Leave::Shutdown,
                changed = control.changed() => {
                    if changed.is_err() { break 'game Leave::Cut; }
                    let c = *control.borrow_and_update();
                    if c.closed { break 'game Leave::ClientClosed; }
                    if c.size != viewer.size {
                        viewer.size = c.size;
                        shown = Shown::UNKNOWN;
                        hub.sizes.lock().unwrap_or_else(|p| p.into_inner()).insert(id, c.size);
                    }
                    continue;
                }
                bytes = input.recv() => {
                    let Some(bytes) = bytes else { break 'game Leave::Cut };
                    let now = Instant::now();
                    last_input = now;
                    inputs.clear();
                    parser.feed(&bytes, now, &mut inputs);
                    for i in coalesce(inputs.drain(..)) {
                        if let Some(why) = viewer.handle(i) { break 'game why; }
                    }
                    continue;
                }
                _ = tokio::time::sleep_until(escape_at.unwrap_or(idle_at).into()), if escape_at.is_some() => {
                    inputs.clear();
                    parser.flush_stale(Instant::now(), &mut inputs);
                    for i in coalesce(inputs.drain(..)) {
                        if let Some(why) = viewer.handle(i) { break 'game why; }
                    }
                    continue;
                }
                _ = tokio::time::sleep_until(idle_at.into()) => {
                    if last_input + hub.limits.idle_timeout <= Instant::now() {
                        stats.idle_kicks.fetch_add(1, Ordering::Relaxed);
                        break 'game Leave::Idle;
                    }
                    continue;
                }
                changed = frames.changed() => if changed.is_err() { break 'game Leave::Shutdown; },
            }
            let set = frames.borrow_and_update().clone();
            first_number.get_or_insert(set.number);
            if last_number != 0 && set.number > last_number + 1 {
                skipped += set.number - last_number - 1;
            }
            last_number = set.number;
            // Just resized: the next frame has this size.
            let Some(picture) = set.pictures.get(&viewer.size).cloned() else { continue };
            let now = Instant::now();
            if !hub.outbound.lock().unwrap_or_else(|p| p.into_inner()).try_take(0.0) {
                stats.frames_dropped_rate.fetch_add(1, Ordering::Relaxed);
                continue;
            }
            bucket.refill(now);
            let mut overlay = viewer.overlay(&set, now, meter.fps, meter.rate);
            overlay.message = viewer.message.filter(|(_, until)| now < *until).map(|(m, _)| m);
            let frame = builder.compose(viewer.size, &picture, color, &overlay, &set.info);
            let target = match color {
                ColorMode::TrueColor => Target::new(frame),
                mode => Target::with_truth(frame, &picture, mode),
            };
            // The frame's bytes go to russh as `Bytes`, so a buffer cannot be kept between
            // frames; sized for the budget at once instead of doubling up to it.
            let mut out = Vec::with_capacity(bucket.budget().min(64 << 10));
            let report = encoder.encode_into(&mut shown, target, bucket.budget(), options, &mut out);
            bucket.spend(report.bytes);
            if out.is_empty() {
                continue;
            }
            let len = out.len();
            hub.outbound.lock().unwrap_or_else(|p| p.into_inner()).spend(len as f64);
            // data_bytes waits for the client's SSH window and for room in russh's queue: that
            // wait is the backpressure. Meanwhile newer pictures replace older ones in the slot.
            tokio::select! {
                biased;
                _ = kill.cancelled() => break 'game Leave::Cut,
                _ = hub.shutdown.cancelled() => break 'game Leave::Shutdown,
                done = write.data_bytes(Bytes::from(out)) => {
                    if done.is_err() { break 'game Leave::Cut; }
                    sent += 1;
                    bytes_total += len as u64;
                    meter.sent(Instant::now(), len);
                    stats.frames_sent.fetch_add(1, Ordering::Relaxed);
                }
                _ = tokio::time::sleep(hub.limits.stall_timeout) => {
                    stats.stall_kicks.fetch_add(1, Ordering::Relaxed);
                    break 'game Leave::Stalled;
                }
            }
        }
    };

    hub.sizes.lock().unwrap_or_else(|p| p.into_inner()).remove(&id);
    drop(slot); // the place is free as soon as the game ends
    // Pictures published since the last one this player took were skipped too (a stalled
    // player is cut while still waiting on its last send).
    let now_number = frames.borrow().number;
    let published = first_number.map_or(0, |first| now_number.saturating_sub(first) + 1);
    if last_number != 0 && now_number > last_number {
        skipped += now_number - last_number;
    }
    stats.frames_skipped.fetch_add(skipped, Ordering::Relaxed);
    eprintln!(
        "serve: {peer} #{id} left ({}): {sent} frames sent, {skipped} skipped of {published} published, {bytes_total} bytes",
        reason.name()
    );
    match reason.farewell() {
        Some(message) => {
            let mut goodbye = RESTORE.to_vec();
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
                write.data_bytes(Bytes::from_static(RESTORE)).await.ok()?;
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
