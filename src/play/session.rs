//! A whole local session as one sans-IO state machine: a [`Driver`] beside its own [`Host`],
//! what `tidepool play` runs on this process's terminal and what the tests run with time
//! passed in. The door's loop is its I/O and nothing else:
//!
//! ```text
//! loop {
//!     wait for bytes until session.poll_timeout()   (the door's clock, the door's terminal)
//!     session.handle_bytes(bytes, arrived); session.handle_resize(size)
//!     session.handle_timeout(now)?
//!     while let Some(event) = session.poll_event() { restore prefix / save a file / quit }
//!     if session.poll_transmit(now, writer_idle, &mut transmit)? {
//!         write transmit.files; session.handle_written(clock()); then write transmit.bytes
//!     }
//! }
//! session.finish()   (the recording: a file to save)
//! ```
//!
//! The host is made once the probe is over (its answer sizes the picture the scene renders at).

use std::collections::VecDeque;
use std::path::PathBuf;
use std::time::Instant;

use tiny_skia::Pixmap;

use super::driver::{Driver, DriverEvent, Pacing, Transmit};
use super::host::{Effect, Host, HostConfig, SceneStatus};
use super::player::Player;
use super::screen::{Screen, ScreenConfig};
use super::seat::Seat;
use crate::error::{Error, Result};

/// What the session asks of its door.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SessionEvent {
    /// From now on, write these bytes before `Screen::RESTORE` when the terminal is handed back
    /// (on every way out, a signal too): what the picture needs undone.
    RestorePrefix(Vec<u8>),
    /// The host asks for a file (a screenshot): save it, then [`Session::handle_saved`].
    Effect(Effect),
    /// The person quit.
    Quit,
}

/// A local session (see the module documentation).
#[derive(Debug)]
pub struct Session {
    driver: Driver,
    /// Made when the probe is over.
    host: Option<Host>,
    host_config: Option<HostConfig>,
    picture: Option<Pixmap>,
    /// The probe's questions, sent first.
    questions: Vec<u8>,
    events: VecDeque<SessionEvent>,
    /// The status line while there is no host yet.
    waiting: SceneStatus,
    /// When the session started.
    started: Instant,
}

impl Session {
    /// A session on a terminal of `term` cells, starting at `now`: the screen asks the
    /// terminal what it draws (the first [`Session::poll_transmit`] carries the questions),
    /// and the host of `host` is made once it has answered. `greeting`: a message for the
    /// status line's first seconds.
    pub fn new(
        screen: ScreenConfig,
        host: HostConfig,
        term: (u16, u16),
        greeting: Option<String>,
        now: Instant,
    ) -> Session {
        let screen = Screen::new(screen, term, now);
        let provisional = screen.picture_size();
        let mut driver = Driver::new(Player::new(screen, provisional, greeting), Pacing::Own);
        let mut questions = Vec::new();
        driver.start(now, &mut questions);
        Session {
            driver,
            host: None,
            host_config: Some(host),
            picture: None,
            questions,
            events: VecDeque::new(),
            waiting: SceneStatus::default(),
            started: now,
        }
    }

    /// Takes the terminal's bytes (`arrived`: when they arrived).
    pub fn handle_bytes(&mut self, bytes: &[u8], arrived: Instant) {
        self.driver.handle_bytes(bytes, arrived);
    }

    /// The bytes of the last [`Session::poll_transmit`] were handed to the door's writer at
    /// `at`, after its files were written: the link's round trip counts from then, not from
    /// the frame's `now` (building a frame on a loaded machine is not a queue on the link).
    pub fn handle_written(&mut self, at: Instant) {
        self.driver.handle_written(at);
    }

    /// The terminal is now `size` cells.
    pub fn handle_resize(&mut self, size: (u16, u16)) {
        self.driver.handle_resize(size);
    }

    /// The turn at `now`: the screen's deadlines; once the probe is over, the host (made
    /// then), the person's inputs applied, a new layout fitted. What the door must do is queued
    /// for [`Session::poll_event`].
    ///
    /// Fails when the host cannot be made (see [`Host::new`]).
    pub fn handle_timeout(&mut self, now: Instant) -> Result<()> {
        if self.host.is_none() {
            if self.driver.player().screen.probing() {
                // Only the screen's deadlines while the probe asks (the status is not read).
                self.driver.handle_timeout(now, &self.waiting);
                if self.driver.player().screen.probing() {
                    return Ok(());
                }
            }
            self.open(now)?;
        }
        let host = self.host.as_mut().expect("the host is made once the probe is over");
        self.driver.handle_timeout(now, host.status());
        while let Some(event) = self.driver.poll_event() {
            match event {
                DriverEvent::Request(request) => {
                    if let Some(message) = host.apply(request, now) {
                        self.driver.handle_message(message, now);
                    }
                }
                DriverEvent::Layout => {
                    let screen = &self.driver.player().screen;
                    self.events.push_back(SessionEvent::RestorePrefix(screen.restore_prefix()));
                    let (w, h) = screen.picture_size();
                    if screen.drawable() {
                        host.resize(w, h);
                    }
                    self.driver.refit(host.size());
                }
                DriverEvent::Quit => {
                    self.events.push_back(SessionEvent::Quit);
                    break;
                }
            }
        }
        self.events.extend(std::iter::from_fn(|| host.poll_effect()).map(SessionEvent::Effect));
        Ok(())
    }

    /// The probe is over: the host, at the picture size its answer gave, and the seat on it.
    fn open(&mut self, now: Instant) -> Result<()> {
        let screen = &self.driver.player().screen;
        self.events.push_back(SessionEvent::RestorePrefix(screen.restore_prefix()));
        let config = self.host_config.take().expect("the host is made once");
        let host = Host::new(config, screen.picture_size(), now)?;
        // The seat starts on the scene as the probe's answer sized it (the aim in its middle).
        self.driver.player_mut().seat = Seat::new(self.driver.player().screen.fit(host.size()));
        self.host = Some(host);
        Ok(())
    }

    /// The door saved the host's file as `name` (`Ok`) or could not (`Err`, why): the host
    /// records it and the person is told.
    pub fn handle_saved(&mut self, outcome: std::result::Result<String, String>, now: Instant) {
        if let Some(host) = &mut self.host {
            let message = host.handle_saved(outcome);
            self.driver.handle_message(message, now);
        }
    }

    /// The door could not write a file a frame named: pixels go directly from now on.
    pub fn handle_file_error(&mut self) {
        self.driver.player_mut().screen.handle_file_error();
    }

    /// What the door must do, oldest first.
    pub fn poll_event(&mut self) -> Option<SessionEvent> {
        self.events.pop_front()
    }

    /// When [`Session::handle_timeout`] must run next at the latest: the screen's deadlines
    /// (a lone Escape, the probe, the link), the next frame, a key's frame waiting for the
    /// writer, the host's next step.
    pub fn poll_timeout(&self) -> Option<Instant> {
        if !self.questions.is_empty() {
            // The probe's questions go at once.
            return Some(self.started);
        }
        let screen = self.driver.poll_timeout();
        let host = self.host.as_ref().and_then(Host::next_due);
        match (screen, host) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// Runs the host's steps due by `now`; when a frame goes now (due, and the door's writer
    /// is free: `writer_idle`), appends its bytes (and the files to write before them) to
    /// `out`. Returns whether `out` has bytes to send.
    ///
    /// Fails when the picture cannot be allocated.
    pub fn poll_transmit(&mut self, now: Instant, writer_idle: bool, out: &mut Transmit) -> Result<bool> {
        if !self.questions.is_empty() {
            out.bytes.append(&mut self.questions);
            return Ok(true);
        }
        let Some(host) = &mut self.host else { return Ok(false) };
        host.advance(now);
        if !self.driver.poll_frame(now, writer_idle) {
            return Ok(false);
        }
        let (w, h) = host.size();
        let picture = match &mut self.picture {
            Some(p) if (p.width(), p.height()) == (w, h) => p,
            slot => slot.insert(Pixmap::new(w, h).ok_or(Error::TooLarge { what: "picture", width: w, height: h })?),
        };
        if self.driver.player().screen.drawable() {
            host.render(picture);
        }
        let len = self.driver.transmit(now, picture, host.status(), out);
        Ok(len > 0)
    }

    /// Whether the screen's questions are still unanswered (a door that is closing waits a
    /// little for the answers, so they do not reach the shell as typed text).
    pub fn awaiting_answers(&self) -> bool {
        self.driver.player().screen.awaiting_answers()
    }

    #[cfg(any(test, feature = "cli", feature = "testing"))]
    /// The host, once the probe is over.
    pub(crate) fn host(&self) -> Option<&Host> {
        self.host.as_ref()
    }

    /// Ends the session: the recording's file to save (its path and text), once.
    pub fn finish(&mut self) -> Option<(PathBuf, String)> {
        self.host.as_mut()?.finish()
    }
}
