//! The loop that drives a play session on one terminal: read its bytes, step the host's scene,
//! draw a frame when the screen says one is due and the writer is free.
//!
//! The loop knows nothing of the device: input comes from a [`TerminalInput`] (bytes and the
//! terminal's size; [`super::tty`] reads this process's terminal, a test a script) and frames go
//! to any `Write` through a writer thread ([`super::writer`]). Input is waited for with a
//! timeout that ends at the next due step or frame, so a key press is handled at once.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use tiny_skia::Pixmap;

use super::writer::FrameWriter;
use crate::error::{Error, Result};
use crate::play::host::{Host, HostConfig};
use crate::play::player::Player;
use crate::play::screen::{Screen, ScreenConfig};
use crate::play::seat::{Flow, Seat};

/// How long the door waits, when the person quits, for the answers to the screen's last
/// questions (so that they do not reach the shell).
const REPLY_GRACE: Duration = Duration::from_millis(300);
/// The longest the loop waits for input before looking at the clock, the size and the quit flag.
const MAX_WAIT: Duration = Duration::from_millis(50);
/// Setting this variable makes the player panic after its first frame: the pty tests use it to
/// check that a panic restores the terminal. Not a user feature.
const TEST_PANIC_VAR: &str = "TIDEPOOL_TEST_PANIC";

/// Where a terminal's input comes from.
pub trait TerminalInput: Send {
    /// Waits at most `timeout` for input and appends what arrived to `buf`. `Ok(false)` when
    /// the input is closed for good (the terminal or the client went away).
    fn read(&mut self, buf: &mut Vec<u8>, timeout: Duration) -> std::io::Result<bool>;

    /// The terminal's size in cells (columns, rows), asked for on every turn of the loop.
    fn size(&mut self) -> std::io::Result<(u16, u16)>;

    /// When the bytes the last [`TerminalInput::read`] appended arrived, if the input knows
    /// (it reads on a thread of its own); `None`: when they were read. The answers to the
    /// link's questions are timed by it: read after a long frame, they still measure the
    /// round trip, not the loop.
    fn arrived(&self) -> Option<Instant> {
        None
    }
}

/// A session on one terminal.
#[derive(Clone, Debug)]
pub struct PlayConfig {
    /// The scene, its list, its seed, the recording.
    pub host: HostConfig,
    /// How the terminal is drawn.
    pub screen: ScreenConfig,
    /// A message for the status line's first seconds (e.g. how to get true colour).
    pub greeting: Option<String>,
    /// Set from outside (a signal handler) to end the session as if the person quit.
    pub quit: Arc<AtomicBool>,
}

/// Runs a session until the person quits (or the input closes, or `config.quit` is set),
/// reading `input` and writing to `output`. `restore_prefix` is told what the screen needs
/// undone on exit whenever that changes (this process's terminal writes it from a signal too).
pub fn run_door(
    input: &mut dyn TerminalInput,
    output: impl std::io::Write + Send + 'static,
    config: PlayConfig,
    restore_prefix: &mut (dyn FnMut(Vec<u8>) + Send),
) -> Result<()> {
    let read_error = |source| Error::Terminal { action: "cannot read the terminal", source };
    let mut output = output;
    let writer = FrameWriter::spawn(move |bytes| output.write_all(bytes).and_then(|()| output.flush()))
        .map_err(Error::Output)?;
    let now = Instant::now();
    let mut screen = Screen::new(config.screen, input.size().map_err(read_error)?, now);
    let mut bytes = Vec::new();
    // The probe first: its answer decides the picture's size, so the scene waits for it.
    let mut asked = writer.buffer();
    screen.start(now, &mut asked);
    if !asked.is_empty() {
        writer.send(asked);
    }
    let provisional = screen.picture_size();
    let mut player = Player::new(screen, provisional, config.greeting);
    while player.screen.probing() && !config.quit.load(Ordering::SeqCst) {
        let now = Instant::now();
        let wait = player.screen.next_tick().map_or(MAX_WAIT, |t| t.saturating_duration_since(now).min(MAX_WAIT));
        bytes.clear();
        if !input.read(&mut bytes, wait).map_err(read_error)? {
            return Ok(());
        }
        player.settle(&bytes, input.arrived().unwrap_or_else(Instant::now));
    }
    player.screen.resize(input.size().map_err(read_error)?);
    restore_prefix(player.screen.restore_prefix());
    let mut host = Host::new(config.host, player.screen.picture_size(), Instant::now())?;
    // The seat starts on the scene as the probe's answer sized it (the aim in its middle).
    player.seat = Seat::new(player.screen.fit(host.size()));
    let (w, h) = host.size();
    let mut picture = Pixmap::new(w, h).ok_or(Error::TooLarge { what: "picture", width: w, height: h })?;
    let test_panic = std::env::var_os(TEST_PANIC_VAR).is_some();
    let mut requests = Vec::new();
    // A key or click whose frame has not gone out yet.
    let mut owed = false;
    // A buffer kept back from a frame that had nothing to send.
    let mut unused: Option<Vec<u8>> = None;
    // The loop runs on a rayon worker: the parallel parts of a frame (simulation bands,
    // picture rows) then go to the worker's own queue instead of rayon's global injector,
    // which allocates a block every 63 jobs. Steady-state frames allocate nothing.
    let played = rayon::scope(|_| -> Result<()> {
        while !config.quit.load(Ordering::SeqCst) {
            let now = Instant::now();
            let screen = &player.screen;
            let wake =
                [host.next_due(), screen.next_tick()].into_iter().flatten().fold(screen.next_frame(), Instant::min);
            // A key's frame waits for the writer: look again soon, not at the next tick.
            let wait = if owed { Duration::from_millis(1) } else { MAX_WAIT };
            bytes.clear();
            if !input.read(&mut bytes, wake.saturating_duration_since(now).min(wait)).map_err(read_error)? {
                return Ok(());
            }
            let now = Instant::now();
            player.feed(&bytes, input.arrived().unwrap_or(now));
            player.screen.resize(input.size().map_err(read_error)?);
            let turn = player.turn(now, host.status(), &mut requests);
            if turn.flow == Flow::Quit {
                break;
            }
            for request in requests.drain(..) {
                if let Some(message) = host.apply(request, now) {
                    player.say(message, now);
                }
            }
            if turn.layout_changed {
                restore_prefix(player.screen.restore_prefix());
                let (w, h) = player.screen.picture_size();
                if player.screen.drawable() {
                    host.resize(w, h);
                }
                player.refit(host.size());
            }
            // A key's frame (or a repaint) is owed until it is sent, even when the writer is busy.
            owed |= turn.urgent || turn.layout_changed;
            host.advance(Instant::now());
            if let Some(e) = writer.error() {
                return Err(Error::Output(e));
            }
            let now = Instant::now();
            if !player.screen.ready(now, owed) {
                continue;
            }
            if !writer.idle() {
                // The terminal is still busy with the last frame: drop this one (a key's frame
                // goes as soon as the writer is free).
                if !owed {
                    player.screen.skip(now);
                }
                continue;
            }
            owed = false;
            let (w, h) = host.size();
            if (picture.width(), picture.height()) != (w, h) {
                picture = Pixmap::new(w, h).ok_or(Error::TooLarge { what: "picture", width: w, height: h })?;
            }
            if player.screen.drawable() {
                host.render(&mut picture);
            }
            let mut out = unused.take().unwrap_or_else(|| writer.buffer());
            let len = player.frame(now, &picture, host.status(), &mut out).map_err(Error::Output)?;
            if len > 0 {
                writer.send(out);
            } else {
                // Nothing changed: the buffer is kept for the next frame instead of being lost.
                unused = Some(out);
            }
            if test_panic && len > 0 {
                panic!("{TEST_PANIC_VAR} is set: panicking on purpose to test the terminal restore");
            }
        }
        Ok(())
    });
    // A question asked but not yet answered would reach the shell as typed text once the
    // terminal is restored: wait a little for the answers (and for the last frame, which
    // carries the question, to be written).
    let grace = Instant::now() + REPLY_GRACE;
    while played.is_ok() && player.screen.awaiting_answers() && Instant::now() < grace {
        let wait = grace.saturating_duration_since(Instant::now());
        if !writer.idle() {
            std::thread::sleep(wait.min(Duration::from_millis(2)));
            continue;
        }
        bytes.clear();
        if !input.read(&mut bytes, wait.min(MAX_WAIT)).map_err(read_error)? {
            break;
        }
        player.feed(&bytes, input.arrived().unwrap_or_else(Instant::now));
    }
    let finished = host.finish();
    played.and(finished)
}

/// Runs a session on any terminal until the person quits (or the input closes, or
/// `config.quit` is set), reading `input` and writing to `output`: the door an embedding
/// program (or a test) uses for a byte stream of its own. [`crate::tty::play`] is the door of
/// this process's terminal.
pub fn run(
    input: &mut dyn TerminalInput,
    output: impl std::io::Write + Send + 'static,
    config: PlayConfig,
) -> Result<()> {
    run_door(input, output, config, &mut |_| {})
}
