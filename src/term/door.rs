//! The door of one terminal: the I/O around a [`Session`] and nothing else. It reads the
//! terminal's bytes (waiting at most until the session's [`Session::poll_timeout`]), hands
//! them, the terminal's size and the time to the session, does what the session asks (the
//! restore prefix, a screenshot to save) and writes what [`Session::poll_transmit`] hands out:
//! the files first (kitty's temporary files), then the bytes, through a writer thread
//! ([`super::writer`]) that never queues frames.
//!
//! The loop knows nothing of the device: input comes from a [`TerminalInput`] (bytes and the
//! terminal's size; [`super::tty`] reads this process's terminal, a test a script), frames go
//! to a [`Sink`] and the time comes from a clock (the real one, or a test's).

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use super::writer::FrameWriter;
use crate::error::{Error, Result};
use crate::output::graphics::kitty;
use crate::play::host::{Effect, HostConfig};
use crate::play::screen::ScreenConfig;
use crate::play::{FileWrite, Session, SessionEvent, Transmit};
use crate::storage::Storage;

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
#[derive(Clone)]
pub struct PlayConfig {
    /// The scene, its list, its seed, the recording.
    pub host: HostConfig,
    /// How the terminal is drawn.
    pub screen: ScreenConfig,
    /// A message for the status line's first seconds (e.g. how to get true colour).
    pub greeting: Option<String>,
    /// Where screenshots and the recording are saved (`None`: nowhere; then the host's
    /// screenshots should be off).
    pub storage: Option<Arc<dyn Storage>>,
    /// Set from outside (a signal handler) to end the session as if the person quit.
    pub quit: Arc<AtomicBool>,
}

impl std::fmt::Debug for PlayConfig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PlayConfig")
            .field("host", &self.host)
            .field("screen", &self.screen)
            .field("greeting", &self.greeting)
            .finish_non_exhaustive()
    }
}

/// Where the door's frames go: a writer thread ([`FrameWriter`]) or, in a test, memory.
pub trait Sink {
    /// Whether the last frame has been written (a frame is drawn only then).
    fn idle(&self) -> bool;
    /// Hands over a frame to write.
    fn send(&mut self, bytes: Vec<u8>);
    /// An empty buffer for the next frame (a written one, for reuse).
    fn buffer(&mut self) -> Vec<u8>;
    /// The error that stopped the writing, if one did.
    fn error(&mut self) -> Option<std::io::Error>;
}

impl Sink for FrameWriter {
    fn idle(&self) -> bool {
        FrameWriter::idle(self)
    }
    fn send(&mut self, bytes: Vec<u8>) {
        FrameWriter::send(self, bytes);
    }
    fn buffer(&mut self) -> Vec<u8> {
        FrameWriter::buffer(self)
    }
    fn error(&mut self) -> Option<std::io::Error> {
        FrameWriter::error(self)
    }
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
    let mut output = output;
    let mut writer = FrameWriter::spawn(move |bytes| output.write_all(bytes).and_then(|()| output.flush()))
        .map_err(Error::Output)?;
    let test_panic = std::env::var_os(TEST_PANIC_VAR).is_some();
    // The loop runs on a rayon worker: the parallel parts of a frame (simulation bands,
    // picture rows) then go to the worker's own queue instead of rayon's global injector,
    // which allocates a block every 63 jobs. Steady-state frames allocate nothing.
    rayon::scope(|_| drive(input, &mut writer, config, restore_prefix, &Instant::now, test_panic))
}

/// The door's loop over any input, sink and clock (see the module documentation). A panic
/// in it still saves the recording, then goes on.
pub fn drive(
    input: &mut dyn TerminalInput,
    sink: &mut dyn Sink,
    config: PlayConfig,
    restore_prefix: &mut (dyn FnMut(Vec<u8>) + Send),
    clock: &dyn Fn() -> Instant,
    test_panic: bool,
) -> Result<()> {
    let size = input.size().map_err(read_error)?;
    let (storage, quit) = (config.storage.clone(), config.quit.clone());
    let mut session = Session::new(config.screen, config.host, size, config.greeting, clock());
    let played = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let mut io = DoorIo { input, sink, restore_prefix, storage: storage.as_deref(), clock };
        io.play(&mut session, &quit, test_panic)
    }));
    // The recording is saved on every way out: a quit, a closed input, an error, a panic.
    let saved = save_recording(&mut session, storage.as_deref());
    match played {
        Ok(played) => played.and(saved),
        Err(panic) => std::panic::resume_unwind(panic),
    }
}

fn read_error(source: std::io::Error) -> Error {
    Error::Terminal { action: "cannot read the terminal", source }
}

/// The door's I/O: what the loop reads from and writes to.
struct DoorIo<'a> {
    input: &'a mut dyn TerminalInput,
    sink: &'a mut dyn Sink,
    restore_prefix: &'a mut (dyn FnMut(Vec<u8>) + Send),
    storage: Option<&'a dyn Storage>,
    clock: &'a dyn Fn() -> Instant,
}

impl DoorIo<'_> {
    /// Reads, hands over, does what the session asks and writes, until the person quits.
    fn play(&mut self, session: &mut Session, quit: &AtomicBool, test_panic: bool) -> Result<()> {
        let mut bytes = Vec::new();
        let mut transmit = Transmit::default();
        while !quit.load(Ordering::SeqCst) {
            let now = (self.clock)();
            let wait = session.poll_timeout().map_or(MAX_WAIT, |t| t.saturating_duration_since(now).min(MAX_WAIT));
            bytes.clear();
            if !self.input.read(&mut bytes, wait).map_err(read_error)? {
                return Ok(());
            }
            let now = (self.clock)();
            session.handle_bytes(&bytes, self.input.arrived().unwrap_or(now));
            session.handle_resize(self.input.size().map_err(read_error)?);
            session.handle_timeout(now)?;
            while let Some(event) = session.poll_event() {
                match event {
                    SessionEvent::Quit => return self.linger(session),
                    SessionEvent::RestorePrefix(prefix) => (self.restore_prefix)(prefix),
                    SessionEvent::Effect(Effect::Screenshot { base, png }) => {
                        let saved = save_screenshot(self.storage, &base, &png);
                        session.handle_saved(saved, now);
                    }
                }
            }
            if let Some(e) = self.sink.error() {
                return Err(Error::Output(e));
            }
            if transmit.bytes.capacity() == 0 {
                transmit.bytes = self.sink.buffer();
            }
            if !session.poll_transmit((self.clock)(), self.sink.idle(), &mut transmit)? {
                // Nothing to send: the buffer is kept for the next frame instead of being lost.
                continue;
            }
            if write_files(&mut transmit.files).is_err() {
                session.handle_file_error();
            }
            // The frame's question leaves now: building the frame (on a loaded machine, most
            // of a frame interval) is the player's time, not the link's.
            session.handle_written((self.clock)());
            self.sink.send(std::mem::take(&mut transmit.bytes));
            // After the first frame (not the probe's questions, which go before the host).
            if test_panic && session.host().is_some() {
                panic!("{TEST_PANIC_VAR} is set: panicking on purpose to test the terminal restore");
            }
        }
        // A signal ends the session as `q` does: its questions' answers must not reach the
        // shell either (echoed by the terminal once it is back in cooked mode).
        self.linger(session)
    }

    /// A question asked but not yet answered would reach the shell as typed text once the
    /// terminal is restored: wait a little for the answers (and for the last frame, which
    /// carries the question, to be written).
    fn linger(&mut self, session: &mut Session) -> Result<()> {
        let mut bytes = Vec::new();
        let grace = (self.clock)() + REPLY_GRACE;
        while session.awaiting_answers() && (self.clock)() < grace {
            let wait = grace.saturating_duration_since((self.clock)());
            if !self.sink.idle() {
                std::thread::sleep(wait.min(Duration::from_millis(2)));
                continue;
            }
            bytes.clear();
            if !self.input.read(&mut bytes, wait.min(MAX_WAIT)).map_err(read_error)? {
                break;
            }
            session.handle_bytes(&bytes, self.input.arrived().unwrap_or_else(self.clock));
        }
        Ok(())
    }
}

/// Writes each file (new: an existing file of that name is not followed or overwritten);
/// the list is emptied either way. Fails at the first that cannot be written.
fn write_files(files: &mut Vec<FileWrite>) -> std::io::Result<()> {
    files.drain(..).try_for_each(|file| kitty::write_new_file(&file.path, &file.bytes))
}

/// Saves a screenshot under the first free name for `base`: the name, or why not.
fn save_screenshot(storage: Option<&dyn Storage>, base: &str, png: &[u8]) -> std::result::Result<String, String> {
    let storage = storage.ok_or_else(|| "nowhere to save it".to_string())?;
    let name = Effect::names(base).find(|n| !storage.exists(Path::new(n))).unwrap_or_else(|| format!("{base}.png"));
    storage.save(name.as_ref(), png).map(|()| name).map_err(|e| e.to_string())
}

/// Saves the session's recording, if it has one (once).
fn save_recording(session: &mut Session, storage: Option<&dyn Storage>) -> Result<()> {
    match (session.finish(), storage) {
        (Some((path, text)), Some(storage)) => storage.save(&path, text.as_bytes()),
        _ => Ok(()),
    }
}

#[cfg(any(feature = "testing", test))]
/// Runs a session on any terminal until the person quits (or the input closes, or
/// `config.quit` is set), reading `input` and writing to `output`: the door an embedding
/// program (or a test) uses for a byte stream of its own. `crate::term::tty::play` is the door of
/// this process's terminal.
pub fn run(
    input: &mut dyn TerminalInput,
    output: impl std::io::Write + Send + 'static,
    config: PlayConfig,
) -> Result<()> {
    run_door(input, output, config, &mut |_| {})
}

#[cfg(test)]
mod tests;
