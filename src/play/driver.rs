//! The one turn every door takes: a [`Driver`] is a [`Player`] (a seat and a screen) with the
//! few facts a door used to keep beside it (a key's frame still owed, a new shared picture),
//! in the sans-IO shape of quinn-proto's `Connection`:
//!
//! - inputs: [`Driver::handle_bytes`] (the terminal's bytes, when they arrived),
//!   [`Driver::handle_resize`] (the terminal's size), [`Driver::handle_written`] (when a
//!   frame's bytes were handed to the door's writer), [`Driver::handle_picture`] (a door whose
//!   pictures come from elsewhere: a new one is there), [`Driver::handle_timeout`] (`now`:
//!   the turn itself: the screen's deadlines, its layout and notices, the person's inputs);
//! - outputs: [`Driver::poll_event`] (the seat's requests for the host, a new layout, quit),
//!   [`Driver::poll_timeout`] (when to call `handle_timeout` again: the lone Escape's wait,
//!   the probe's deadline, the link's lost questions, the next frame, a key's frame waiting for
//!   the writer), [`Driver::poll_frame`] (whether a frame goes now) and
//!   [`Driver::transmit`] (its bytes, and the files to write first).
//!
//! The local session ([`super::session::Session`]) is a driver beside its own host;
//! `tidepool serve` runs a driver per SSH channel beside the shared host's pictures. Neither
//! decides anything the driver decides, so the two doors behave alike by construction.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use tiny_skia::Pixmap;

use super::host::SceneStatus;
use super::player::Player;
use super::request::Request;
use super::seat::Flow;
use crate::output::graphics::stream::FileWrite;

/// How soon a door looks again when a key's frame waits for its writer.
const OWED_RETRY: Duration = Duration::from_millis(1);

/// What paces a driver's frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pacing {
    /// The screen's own frame pacer (a door that owns its host and renders when it likes).
    Own,
    /// New pictures from elsewhere ([`Driver::handle_picture`]): a shared host's rate paces
    /// the frames.
    Pictures,
}

/// What a turn asks of the door.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DriverEvent {
    /// A request for the host.
    Request(Request),
    /// The picture's size or place changed (a resize, the probe's answer): the door resizes a
    /// scene of its own, then calls [`Driver::refit`]. The bytes that undo the screen on exit
    /// may have changed too (`Screen::restore_prefix`).
    Layout,
    /// The person quit.
    Quit,
}

/// Bytes for the terminal and the files to write before them (kitty's temporary files). The
/// door owns it and reuses its buffers.
#[derive(Debug, Default)]
pub struct Transmit {
    /// The files, written (new) before `bytes` are sent.
    pub files: Vec<FileWrite>,
    /// The bytes.
    pub bytes: Vec<u8>,
}

/// One person at one terminal, driven (see the module documentation).
#[derive(Debug)]
pub struct Driver {
    player: Player,
    pacing: Pacing,
    /// A key's frame (or a repaint) not sent yet.
    owed: bool,
    /// A new picture came since the last frame ([`Pacing::Pictures`]).
    fresh: bool,
    /// The time of the last turn.
    now: Option<Instant>,
    requests: Vec<Request>,
    events: VecDeque<DriverEvent>,
}

impl Driver {
    /// Drives `player`, its frames paced by `pacing`.
    pub fn new(player: Player, pacing: Pacing) -> Driver {
        Driver { player, pacing, owed: false, fresh: false, now: None, requests: Vec::new(), events: VecDeque::new() }
    }

    /// The player.
    pub fn player(&self) -> &Player {
        &self.player
    }

    /// The player, to change (a new seat, a group's frame).
    pub fn player_mut(&mut self) -> &mut Player {
        &mut self.player
    }

    /// Starts the session: appends the probe's questions to `out` (nothing when the terminal
    /// is not asked).
    pub fn start(&mut self, now: Instant, out: &mut Vec<u8>) {
        self.player.screen.start(now, out);
    }

    /// Takes the terminal's bytes (`arrived`: when they arrived); says whether the person did
    /// something (the terminal's own answers are no sign of life).
    pub fn handle_bytes(&mut self, bytes: &[u8], arrived: Instant) -> bool {
        self.player.feed(bytes, arrived)
    }

    /// The bytes of the last [`Driver::transmit`] were handed to the door's writer at `at`
    /// (once built, their files written): the link's round trip counts from then, not from
    /// the frame's `now` (a frame that takes the player long to build is not a queue on the
    /// link). A door that writes at once may skip it.
    pub fn handle_written(&mut self, at: Instant) {
        self.player.screen.handed_over(at);
    }

    /// The terminal is now `size` cells.
    pub fn handle_resize(&mut self, size: (u16, u16)) {
        self.player.screen.resize(size);
    }

    #[cfg(feature = "serve")]
    /// A new picture is there to draw ([`Pacing::Pictures`]).
    pub fn handle_picture(&mut self) {
        self.fresh = true;
    }

    /// A message from the host for this person (a screenshot's name).
    pub fn handle_message(&mut self, message: String, now: Instant) {
        self.player.say(message, now);
    }

    /// The turn at `now`. While the probe is asking, only the screen's deadlines; then the
    /// screen's layout and notices and the person's inputs (`status` is the scene's), with
    /// what they ask for queued for [`Driver::poll_event`].
    pub fn handle_timeout(&mut self, now: Instant, status: &SceneStatus) {
        self.now = Some(now);
        if self.player.screen.probing() {
            self.player.settle(now);
            return;
        }
        let turn = self.player.turn(now, status, &mut self.requests);
        self.events.extend(self.requests.drain(..).map(DriverEvent::Request));
        if turn.flow == Flow::Quit {
            self.events.push_back(DriverEvent::Quit);
        }
        if turn.layout_changed {
            self.events.push_back(DriverEvent::Layout);
        }
        self.owed |= turn.urgent || turn.layout_changed;
    }

    /// What the last turn asks of the door, oldest first.
    pub fn poll_event(&mut self) -> Option<DriverEvent> {
        self.events.pop_front()
    }

    /// After [`DriverEvent::Layout`]: the scene (of `scene` pixels) fits the new layout.
    pub fn refit(&mut self, scene: (u32, u32)) {
        self.player.refit(scene);
    }

    /// When [`Driver::handle_timeout`] must run next, at the latest.
    pub fn poll_timeout(&self) -> Option<Instant> {
        let tick = self.player.screen.next_tick();
        if self.pacing == Pacing::Pictures || self.player.screen.probing() {
            return tick;
        }
        let frame = match (self.owed, self.now) {
            (true, Some(now)) => (now + OWED_RETRY).min(self.player.screen.next_frame()),
            _ => self.player.screen.next_frame(),
        };
        Some(tick.map_or(frame, |t| t.min(frame)))
    }

    /// Whether a frame goes now: the probe is over and a frame is due (the pacer's, a key's,
    /// or a new picture's) and the door's writer is free (`writer_idle`). A due frame the
    /// writer cannot take is dropped, never queued (a key's waits for it). A new picture is
    /// counted once.
    pub fn poll_frame(&mut self, now: Instant, writer_idle: bool) -> bool {
        let screen = &mut self.player.screen;
        match self.pacing {
            Pacing::Own => {
                if !screen.ready(now, self.owed) {
                    return false;
                }
                if !writer_idle && !self.owed {
                    screen.skip(now);
                }
                writer_idle
            }
            Pacing::Pictures => {
                let fresh = std::mem::take(&mut self.fresh);
                (fresh || self.owed) && writer_idle && screen.ready(now, true)
            }
        }
    }

    /// Appends the frame for `now` to `out.bytes` (`picture` of the screen's picture size,
    /// `status` the scene's) and the files to write before it to `out.files`; returns the
    /// bytes appended (0: nothing changed).
    pub fn transmit(&mut self, now: Instant, picture: &Pixmap, status: &SceneStatus, out: &mut Transmit) -> usize {
        self.sent();
        let len = self.player.frame(now, picture, status, &mut out.bytes);
        self.player.screen.take_files(&mut out.files);
        len
    }

    /// A frame went out by another way (a group's bytes): nothing is owed.
    pub fn sent(&mut self) {
        self.owed = false;
    }
}
