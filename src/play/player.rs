//! A player: one person at one terminal, a [`Seat`] and a [`Screen`] together. The turn every
//! door takes with them (the terminal's bytes to the screen, its deadlines, a new layout, its
//! notices, the person's inputs to the seat, the seat's requests out, a frame with the seat's
//! overlay) is [`super::driver::Driver`]'s, built on the steps here.

use std::time::Instant;

use tiny_skia::Pixmap;

#[cfg(any(feature = "serve", feature = "testing", test))]
use super::fit::Fit;
use super::host::SceneStatus;
use super::input::Input;
use super::request::Request;
use super::screen::Screen;
use super::seat::{Flow, Seat};

/// What a turn found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Turn {
    /// Whether the person stays.
    pub flow: Flow,
    /// The picture's layout changed (a resize, the probe's answer): the door makes the scene
    /// fit again ([`Player::refit`]), after resizing a scene of its own.
    pub layout_changed: bool,
    /// The person did something: their frame should go out at once.
    pub urgent: bool,
}

/// One person at one terminal.
#[derive(Debug)]
pub struct Player {
    /// What is theirs: aim, stone size, help, messages.
    pub(crate) seat: Seat,
    /// Their terminal.
    pub screen: Screen,
    inputs: Vec<Input>,
    /// The greeting, shown with the screen's first notice once the probe is over.
    greeting: Option<String>,
}

impl Player {
    /// A player whose `screen` shows a scene of `scene` pixels, greeted with `greeting` (shown
    /// once the terminal has been asked what it draws, with what that found).
    pub fn new(screen: Screen, scene: (u32, u32), greeting: Option<String>) -> Player {
        let seat = Seat::new(screen.fit(scene));
        Player { seat, screen, inputs: Vec::new(), greeting: Some(greeting.unwrap_or_default()) }
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// How their terminal's cells map to the scene's pixels (the seat's).
    pub fn fit(&self) -> &Fit {
        self.seat.fit()
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// The passing message on their status line at `now` (the greeting, a notice), if any:
    /// players who show the same one share a group's frames ([`GroupKey::with_note`]).
    ///
    /// [`GroupKey::with_note`]: crate::play::group::GroupKey::with_note
    pub fn message(&self, now: Instant) -> Option<&str> {
        self.seat.message(now)
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// A player whose `s` key says screenshots are off instead of asking the host (a shared
    /// scene saves no files on a player's behalf).
    pub fn without_screenshots(mut self) -> Player {
        self.seat = self.seat.without_screenshots();
        self
    }

    /// Takes the terminal's bytes; says whether the person did something (the terminal's own
    /// answers are no sign of life: an idle timeout must not count them).
    pub(crate) fn feed(&mut self, bytes: &[u8], now: Instant) -> bool {
        let before = self.inputs.len();
        self.screen.feed(bytes, now, &mut self.inputs);
        self.inputs.len() > before
    }

    /// While the screen is asking the terminal what it draws (before a door can size its
    /// scene): looks at the clock (the probe's deadline); keys typed meanwhile wait for the
    /// first [`Player::turn`].
    pub(crate) fn settle(&mut self, now: Instant) {
        self.screen.tick(now, &mut self.inputs);
    }

    /// One turn at `now`: the screen's deadlines, its layout and notices, and the person's
    /// inputs as requests for the host (appended to `requests`). `status` is the scene's.
    pub(crate) fn turn(&mut self, now: Instant, status: &SceneStatus, requests: &mut Vec<Request>) -> Turn {
        self.screen.tick(now, &mut self.inputs);
        let layout_changed = self.screen.take_layout_change();
        if !self.screen.probing()
            && let Some(greeting) = self.greeting.take()
        {
            let text: Vec<String> = [self.screen.take_notice(), Some(greeting)].into_iter().flatten().collect();
            let text = text.into_iter().filter(|t| !t.is_empty()).collect::<Vec<_>>().join("; ");
            if !text.is_empty() {
                self.seat.greet(text, now);
            }
        } else if let Some(notice) = self.screen.take_notice() {
            self.seat.say(notice, now);
        }
        let urgent = !self.inputs.is_empty();
        let mut flow = Flow::Continue;
        for input in self.inputs.drain(..) {
            if self.seat.handle(input, now, status, requests) == Flow::Quit {
                flow = Flow::Quit;
                break;
            }
        }
        Turn { flow, layout_changed, urgent }
    }

    /// The scene (of `scene` pixels) fits the screen's new layout.
    pub(crate) fn refit(&mut self, scene: (u32, u32)) {
        self.seat.set_fit(self.screen.fit(scene));
    }

    /// A message for this person on their status line (a screenshot's name; a crowd's
    /// greeting).
    pub fn say(&mut self, message: String, now: Instant) {
        self.seat.say(message, now);
    }

    /// Appends the frame for now: `picture` (of the screen's picture size) with the seat's
    /// overlay and `status`'s status line. Returns the bytes appended.
    pub fn frame(&mut self, now: Instant, picture: &Pixmap, status: &SceneStatus, out: &mut Vec<u8>) -> usize {
        let view = self.seat.view(now, status);
        self.screen.frame(now, picture, status, &view, out)
    }
}
