//! The player's loop over any terminal: read input bytes, step the simulation at its fixed
//! rate, draw a frame when one is due and the writer is free.
//!
//! The loop knows nothing of the device: input comes from a [`TerminalInput`] (bytes and the
//! terminal's size; [`super::tty`] reads this process's terminal, a server would read an SSH
//! channel) and frames go to any `Write` through a writer thread ([`super::writer`]). One
//! thread does input, simulation, rendering and encoding; input is waited for with a timeout
//! that ends at the next due step or frame, so a key press is handled at once.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tiny_skia::Pixmap;

use super::input::{Input, InputParser, coalesce};
use super::link::{self, Change, LinkControl};
use super::pacing::{FramePacer, Meter, SimClock};
use super::picture::{self, Picture};
use super::probe::{self, GraphicsRequest, GraphicsSupport};
use super::screen::{FrameBuilder, Overlay, big_enough};
use super::ui;
use super::writer::FrameWriter;
use crate::error::{Error, Result};
use crate::output::bucket::ByteBucket;
use crate::output::color::ColorMode;
use crate::output::cursor::Cursor;
use crate::output::diff::{EncodeOptions, Shown};
use crate::output::frame::Frame;
use crate::output::rate::{RateEncoder, RateOptions, Target};
use crate::replay::{FORMAT, Header, PoolOptions, Recorder};
use crate::scene::{Action, Event, Playable, SceneSpec};
use crate::storage::Storage;

/// Stone radii `+` and `-` step through, in pixels.
pub const STONE_RADII: [u32; 10] = [1, 2, 3, 4, 6, 8, 12, 16, 24, 32];
/// The stone radius the player starts with, in pixels (a terminal pool is ~100 pixels tall).
pub const DEFAULT_STONE_RADIUS: u32 = 3;
/// How long the aim marker stays after the last aim key.
const AIM_VISIBLE: Duration = Duration::from_secs(4);
/// How long a status message (screenshot saved) stays.
const MESSAGE_VISIBLE: Duration = Duration::from_secs(4);
/// How long [`PlayerConfig::greeting`] stays.
const GREETING_VISIBLE: Duration = Duration::from_secs(10);
/// How long the player waits, when it quits, for the answers to its last questions (so that
/// they do not reach the shell).
const REPLY_GRACE: Duration = Duration::from_millis(300);
/// The longest the loop waits for input before looking at the clock, the size and the quit flag.
const MAX_WAIT: Duration = Duration::from_millis(50);
/// Random stones use their own generator, seeded from `--seed` xor this, so that pressing
/// `space` does not change the rain.
const STONE_SEED_MIX: u64 = 0x5354_4f4e_4553_0001;
/// Setting this variable makes the player panic after its first frame: the pty tests use it to
/// check that a panic restores the terminal. Not a user feature.
pub const TEST_PANIC_VAR: &str = "TIDEPOOL_TEST_PANIC";

/// Where the player's input comes from.
pub trait TerminalInput: Send {
    /// Waits at most `timeout` for input and appends what arrived to `buf`. `Ok(false)` when
    /// the input is closed for good (the terminal or the client went away).
    fn read(&mut self, buf: &mut Vec<u8>, timeout: Duration) -> std::io::Result<bool>;

    /// The terminal's size in cells (columns, rows), asked for on every turn of the loop.
    fn size(&mut self) -> std::io::Result<(u16, u16)>;
}

/// How many bytes a second the player may send.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bandwidth {
    /// Found by itself from the terminal's answers (see `term/link.rs`).
    Auto,
    /// This many bytes a second.
    Fixed(u64),
    /// No limit: every frame is sent whole (what changed of it).
    Unlimited,
}

/// Above this rate approximate cells are not worth their CPU: the link carries exact ones.
const APPROXIMATE_BELOW: f64 = 1_000_000.0;

/// How the player runs.
#[derive(Clone)]
pub struct PlayerConfig {
    /// The scenes `tab` cycles through; the first is shown at the start.
    pub scenes: Vec<SceneSpec>,
    /// Display frames per second.
    pub fps: u32,
    /// What the link carries.
    pub bandwidth: Bandwidth,
    /// Terminal colours.
    pub color: ColorMode,
    /// Encoder options.
    pub encode: EncodeOptions,
    /// Seed of the random stones.
    pub seed: u64,
    /// Record the session (the pool only) to this file, with the floor's file for the header.
    pub record: Option<(PathBuf, Option<PathBuf>)>,
    /// Where screenshots and recordings are saved; without one, `s` says screenshots are off.
    pub storage: Option<Arc<dyn Storage>>,
    /// A message for the status line's first seconds (e.g. how to get true colour).
    pub greeting: Option<String>,
    /// Set from outside (a signal handler) to end the session as if the user quit.
    pub quit: Arc<AtomicBool>,
    /// How the picture is drawn (`--graphics`): `Force(Cells)` is the half-block picture.
    /// Without a probe (see [`run_probed`]) `Auto` means cells and a forced mode is used as
    /// asked.
    pub graphics: GraphicsRequest,
}

/// What the terminal answered to the graphics probe (`term/probe.rs`) before the player started.
#[derive(Clone, Debug, Default)]
pub struct Probed {
    /// What it can show.
    pub support: GraphicsSupport,
    /// Bytes that arrived during the probe and were not answers (keys typed meanwhile): the
    /// player reads them first, so they are not lost.
    pub leftover: Vec<u8>,
}

impl std::fmt::Debug for PlayerConfig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PlayerConfig")
            .field("scenes", &self.scenes.iter().map(SceneSpec::kind).collect::<Vec<_>>())
            .field("fps", &self.fps)
            .field("bandwidth", &self.bandwidth)
            .field("color", &self.color)
            .field("graphics", &self.graphics)
            .finish_non_exhaustive()
    }
}

/// The picture size in pixels for a terminal of `cols x rows` (one row for the status line).
pub fn picture_size(cols: u16, rows: u16) -> (u32, u32) {
    (u32::from(cols).max(3), (2 * u32::from(rows).saturating_sub(1)).max(3))
}

enum Flow {
    Continue,
    Quit,
}

/// Everything the loop keeps besides the scene.
struct Player {
    scene: Box<dyn Playable>,
    /// Index into `config.scenes` of the scene shown.
    current: usize,
    config: PlayerConfig,
    recorder: Option<Recorder>,
    step: u64,
    term: (u16, u16),
    sim: SimClock,
    /// The help overlay's lines while it is open (built when opened, not every frame).
    help: Option<Vec<(&'static str, &'static str)>>,
    aim: (i32, i32),
    aim_until: Option<Instant>,
    message: Option<(String, Instant)>,
    drag: Option<(i32, i32)>,
    radius: u32,
    rng: ChaCha8Rng,
    /// The picture in real pixels; `None` in cells mode.
    picture: Option<Picture>,
    /// Mouse reports are in pixels (SGR-pixels mode 1016 is on).
    mouse_pixels: bool,
    /// Input that arrived before the loop started (during the probe).
    leftover: Vec<u8>,
}

/// Runs the player until the user quits (or the input closes, or `config.quit` is set),
/// reading `input` and writing frames to `output`. No probe was made: `--graphics auto` means
/// cells.
pub fn run(
    input: &mut dyn TerminalInput,
    output: impl std::io::Write + Send + 'static,
    config: PlayerConfig,
) -> Result<()> {
    run_probed(input, output, config, None)
}

/// [`run`], after the terminal answered the graphics probe: the mode is chosen from its
/// answers, and the bytes read during the probe are the first input.
pub fn run_probed(
    input: &mut dyn TerminalInput,
    output: impl std::io::Write + Send + 'static,
    mut config: PlayerConfig,
    probed: Option<Probed>,
) -> Result<()> {
    let term = input.size().map_err(|source| Error::Terminal { action: "cannot read the terminal size", source })?;
    let (support, leftover) = probed.map_or((None, Vec::new()), |p| (Some(p.support), p.leftover));
    let choice = probe::choose(config.graphics, support.as_ref());
    let support = support.unwrap_or_default();
    let picture = Picture::new(&choice, &support, term);
    let mouse_pixels = picture::pixel_mouse(&choice, &support);
    if let Some(p) = &picture {
        // Say which protocol draws, before any other greeting (the colour greeting is about
        // cells, which then only draw the status line).
        let (w, h) = p.scene_size();
        config.greeting = Some(format!("{} graphics, {w}x{h} pixels", choice.mode.name()));
    }
    if let Some(hint) = choice.hint {
        // The hint says how to get pictures: it goes first, the colour greeting after it.
        config.greeting = Some(match config.greeting.take() {
            Some(g) => format!("{hint}; {g}"),
            None => hint.to_owned(),
        });
    }
    let (w, h) = match &picture {
        Some(p) => p.scene_size(),
        None => picture_size(term.0, term.1),
    };
    let first = config
        .scenes
        .first()
        .ok_or_else(|| Error::Value(crate::error::ValueError::new("scenes", "the player needs at least one scene")))?;
    let scene = first.build(w, h)?;
    let recorder = match (&config.record, first) {
        (Some((path, background)), SceneSpec::Pool(settings)) => {
            let header = Header {
                format: FORMAT,
                version: env!("CARGO_PKG_VERSION").into(),
                scene: scene.kind(),
                seed: config.seed,
                size: [w, h],
                options: PoolOptions::of(settings, background.clone()),
            };
            let storage = config.storage.clone().ok_or_else(|| {
                Error::Value(crate::error::ValueError::new("record", "recording needs somewhere to save the file"))
            })?;
            Some(Recorder::new(path, &header, storage))
        }
        (Some(_), _) => {
            return Err(Error::Value(crate::error::ValueError::new("record", "replays hold the pool only")));
        }
        (None, _) => None,
    };
    let now = Instant::now();
    let message = config.greeting.clone().map(|m| (m, now + GREETING_VISIBLE));
    let mut player = Player {
        current: 0,
        sim: SimClock::new(scene.steps_per_second(), now),
        scene,
        rng: ChaCha8Rng::seed_from_u64(config.seed ^ STONE_SEED_MIX),
        config,
        recorder,
        step: 0,
        term,
        help: None,
        aim: ((w / 2) as i32, ((h / 2) & !1) as i32),
        aim_until: None,
        message,
        drag: None,
        radius: DEFAULT_STONE_RADIUS,
        picture,
        mouse_pixels,
        leftover,
    };
    // The loop runs on a rayon worker: the parallel parts of a frame (simulation bands,
    // picture rows) then go to the worker's own queue instead of rayon's global injector,
    // which allocates a block every 63 jobs. Steady-state frames allocate nothing.
    let result = rayon::scope(|_| player.run_loop(input, output));
    let finished = match &mut player.recorder {
        Some(r) => r.finish(player.step),
        None => Ok(()),
    };
    result.and(finished)
}

impl Player {
    fn run_loop(&mut self, input: &mut dyn TerminalInput, output: impl std::io::Write + Send + 'static) -> Result<()> {
        let mut output = output;
        let writer = FrameWriter::spawn(move |bytes| output.write_all(bytes).and_then(|()| output.flush()))
            .map_err(Error::Output)?;
        let start = Instant::now();
        let mut pacer = FramePacer::new(self.config.fps, start);
        let auto = self.config.bandwidth == Bandwidth::Auto;
        let mut link = LinkControl::new();
        let mut bucket = match self.config.bandwidth {
            Bandwidth::Auto => ByteBucket::new(link::START_RATE),
            Bandwidth::Fixed(rate) => ByteBucket::new(rate as f64),
            Bandwidth::Unlimited => ByteBucket::unlimited(),
        };
        let mut encoder = RateEncoder::new();
        // Every byte written, for the link's delivery rate.
        let mut bytes_sent = 0u64;
        let mut meter = Meter::new(start);
        let mut shown = Shown::UNKNOWN;
        let (w, h) = self.scene.size();
        let mut pixmap = Pixmap::new(w, h).ok_or(Error::TooLarge { what: "picture", width: w, height: h })?;
        let test_panic = std::env::var_os(TEST_PANIC_VAR).is_some();
        let mut parser = InputParser::new();
        let mut bytes_in = Vec::new();
        let mut inputs = Vec::new();
        let mut builder = FrameBuilder::default();
        // A buffer kept back from a frame that had nothing to send, so it is not lost.
        let mut unused: Option<Vec<u8>> = None;
        // A key or click whose frame has not gone out yet.
        let mut owed = false;
        let read_error = |source| Error::Terminal { action: "cannot read the terminal", source };
        'play: loop {
            if self.config.quit.load(Ordering::SeqCst) {
                break 'play;
            }
            let now = Instant::now();
            let mut deadline = self.sim.next_due().map_or(pacer.next_due(), |s| s.min(pacer.next_due()));
            if let Some(escape) = parser.deadline() {
                deadline = deadline.min(escape);
            }
            let mut timeout = deadline.saturating_duration_since(now).min(MAX_WAIT);
            if owed {
                // A key's frame waits for the writer: look again soon, not at the next tick.
                timeout = timeout.min(Duration::from_millis(1));
            }
            bytes_in.clear();
            bytes_in.append(&mut self.leftover);
            let timeout = if bytes_in.is_empty() { timeout } else { Duration::ZERO };
            if !input.read(&mut bytes_in, timeout).map_err(read_error)? {
                return Ok(());
            }
            let now = Instant::now();
            inputs.clear();
            parser.feed(&bytes_in, now, &mut inputs);
            parser.flush_stale(now, &mut inputs);
            let size = input.size().map_err(read_error)?;
            if size != self.term {
                inputs.push(Input::Resize(size.0, size.1));
            }
            // A key or a click draws its frame at once, not at the next tick.
            let mut urgent = false;
            for input in coalesce(inputs.drain(..)) {
                match input {
                    Input::DeviceAttributes => {
                        if auto && link.answered(now) == Change::Down {
                            bucket.drain();
                        }
                        continue;
                    }
                    Input::CursorReport(..) => continue,
                    Input::Resize(..) => shown = Shown::UNKNOWN,
                    _ => {}
                }
                urgent = true;
                if let Flow::Quit = self.handle(input)? {
                    break 'play;
                }
            }
            if auto {
                if link.tick(now) == Change::Down {
                    bucket.drain();
                }
                bucket.set_rate(link.rate());
            }
            let now = Instant::now();
            let due = self.sim.due(now);
            self.scene.advance(due);
            self.step += due;
            if let Some(r) = &mut self.recorder {
                r.advance(self.step);
            }
            if let Some(e) = writer.error() {
                return Err(Error::Output(e));
            }
            meter.tick(now);
            // A key's frame is owed until it is sent, even when the writer is busy now.
            owed |= urgent;
            if !pacer.ready(now) && !owed {
                continue;
            }
            if !writer.idle() {
                // The terminal is still busy with the last frame: drop this one (a key's frame
                // goes as soon as the writer is free).
                if !owed {
                    pacer.sent(now);
                }
                continue;
            }
            owed = false;
            let size = self.scene.size();
            if (pixmap.width(), pixmap.height()) != size {
                pixmap = Pixmap::new(size.0, size.1).ok_or(Error::TooLarge {
                    what: "picture",
                    width: size.0,
                    height: size.1,
                })?;
            }
            bucket.refill(now);
            let rate = bucket.rate();
            let frame = self.frame(&mut builder, &mut pixmap, &meter, rate, now);
            let target = match self.config.color {
                ColorMode::TrueColor => Target::new(frame),
                mode => Target::with_truth(frame, &pixmap, mode),
            };
            let options = RateOptions {
                approximate: rate.is_some_and(|r| r < APPROXIMATE_BELOW),
                ..RateOptions::from(self.config.encode)
            };
            let mut bytes = unused.take().unwrap_or_else(|| writer.buffer());
            // On an auto link the unanswered bytes are capped too (see `link`: the first seconds).
            let budget = if auto { bucket.budget().min(link.window_left(now, bytes_sent)) } else { bucket.budget() };
            let resized = shown.frame.is_none();
            let report = encoder.encode_into(&mut shown, target, budget, options, &mut bytes);
            bucket.spend(report.bytes);
            if let Some(picture) = &mut self.picture {
                let frame = picture::Frame {
                    resized,
                    help_open: self.help.is_some(),
                    cells_shown: report.pending == 0,
                    drawable: big_enough(self.term),
                    sync: options.sync,
                };
                if picture.add_to_frame(&pixmap, &frame, &mut bucket, &mut bytes).map_err(Error::Output)? {
                    shown.cursor = Cursor::Unknown;
                }
            }
            if auto && link.probe_due() && (!bytes.is_empty() || link.unasked(bytes_sent)) {
                // The question goes after the frame: its answer says the frame has arrived.
                bytes.extend_from_slice(link::PROBE);
                link.probed(now, bytes_sent + bytes.len() as u64);
            }
            let len = bytes.len();
            bytes_sent += len as u64;
            if len > 0 {
                writer.send(bytes);
            } else {
                unused = Some(bytes);
            }
            meter.frame(now, len);
            pacer.sent(now);
            if test_panic && len > 0 {
                panic!("{TEST_PANIC_VAR} is set: panicking on purpose to test the terminal restore");
            }
        }
        // A question asked but not yet answered would reach the shell as typed text once the
        // terminal is restored: wait a little for the answers (and for the last frame, which
        // carries the question, to be written).
        let grace = Instant::now() + REPLY_GRACE;
        while !link.probe_due() && Instant::now() < grace {
            bytes_in.clear();
            let wait = grace.saturating_duration_since(Instant::now());
            if !writer.idle() {
                std::thread::sleep(wait.min(Duration::from_millis(2)));
                continue;
            }
            if !input.read(&mut bytes_in, wait.min(MAX_WAIT)).map_err(read_error)? {
                break;
            }
            inputs.clear();
            parser.feed(&bytes_in, Instant::now(), &mut inputs);
            for _ in inputs.iter().filter(|i| **i == Input::DeviceAttributes) {
                link.answered(Instant::now());
            }
        }
        Ok(())
    }

    /// The frame to show now, built by `builder` (which keeps its buffers between frames).
    fn frame<'b>(
        &mut self,
        builder: &'b mut FrameBuilder,
        pixmap: &mut Pixmap,
        meter: &Meter,
        bandwidth: Option<f64>,
        now: Instant,
    ) -> &'b Frame {
        let overlay = Overlay {
            aim: self.aim_until.is_some_and(|t| now < t).then(|| {
                let (x, y) = (self.aim.0 as u32, self.aim.1 as u32);
                // The marker is a text cell: with real pixels, the cell over the aimed pixel
                // (in the cell frame's coordinates, two pixel rows a cell).
                self.picture.as_ref().map_or((x, y), |p| {
                    let (col, row) = p.cell_of(x, y);
                    (col, 2 * row)
                })
            }),
            help: self.help.as_deref(),
            message: self.message.as_ref().filter(|(_, until)| now < *until).map(|(m, _)| m.as_str()),
            fps: meter.fps,
            bytes_per_second: meter.bytes_per_second,
            bandwidth: bandwidth.map(|b| b as u64),
            stone: self.radius,
            paused: self.sim.paused(),
            pixels_elsewhere: self.picture.is_some(),
        };
        builder.build(self.term, self.scene.as_mut(), pixmap, self.config.color, &overlay)
    }

    /// Resolves an action with the scene, applies and records its events.
    fn act(&mut self, action: Action) {
        for event in self.scene.resolve(action) {
            self.apply(event);
        }
    }

    fn apply(&mut self, event: Event) {
        self.scene.apply(&event);
        if let Some(r) = &mut self.recorder {
            r.record(self.step, event);
        }
    }

    fn say(&mut self, message: String) {
        self.message = Some((message, Instant::now() + MESSAGE_VISIBLE));
    }

    /// The picture pixel under a mouse report at (col, row): in cells mode the cell's upper
    /// half; with real pixels the pixel under the cell's centre, or with SGR-pixels reports
    /// (then `col`, `row` are screen pixels) the pixel under the pointer.
    fn pixel_at(&self, col: u16, row: u16) -> Option<(i32, i32)> {
        if !big_enough(self.term) {
            return None;
        }
        match &self.picture {
            Some(p) => p.pixel_at((col, row), self.mouse_pixels),
            None => (row + 1 < self.term.1).then_some((i32::from(col), 2 * i32::from(row))),
        }
    }

    /// How far one aim step moves, in picture pixels (x, y): in cells mode two pixels each
    /// way (two columns, one row: a square step), with real pixels one cell.
    fn aim_step(&self) -> (i32, i32) {
        match &self.picture {
            Some(p) => {
                let (x, y) = p.pixels_per_cell();
                (x as i32, y as i32)
            }
            None => (2, 2),
        }
    }

    fn handle(&mut self, input: Input) -> Result<Flow> {
        let (w, h) = self.scene.size();
        let now = Instant::now();
        match input {
            Input::Quit => return Ok(Flow::Quit),
            Input::Escape if self.help.is_some() => self.help = None,
            Input::Escape => return Ok(Flow::Quit),
            Input::Help => {
                self.help = match self.help {
                    Some(_) => None,
                    None => Some(ui::help_lines(&self.scene.help(), self.scene.takes_stones())),
                }
            }
            Input::RandomStone => {
                let (x, y) = (self.rng.random_range(0..w) as i32, self.rng.random_range(0..h) as i32);
                self.act(Action::Stone { x, y, radius: self.radius, big: false });
            }
            Input::Aim(dx, dy) => {
                let (sx, sy) = self.aim_step();
                self.aim.0 = (self.aim.0 + sx * dx).clamp(0, w as i32 - 1);
                self.aim.1 = (self.aim.1 + sy * dy).clamp(0, (h as i32 - 1) & !1);
                self.aim_until = Some(now + AIM_VISIBLE);
            }
            Input::DropAtAim => {
                let (x, y) = self.aim;
                self.aim_until = Some(now + AIM_VISIBLE);
                self.act(Action::Stone { x, y, radius: self.radius, big: false });
            }
            Input::ToggleRain => self.act(Action::ToggleRain),
            Input::Clear => self.act(Action::Clear),
            Input::Damping(stronger) => self.act(Action::Damping(stronger)),
            Input::StoneSize(bigger) => {
                let i = STONE_RADII.iter().position(|&r| r >= self.radius).unwrap_or(0);
                let i = if bigger { (i + 1).min(STONE_RADII.len() - 1) } else { i.saturating_sub(1) };
                self.radius = STONE_RADII[i];
            }
            Input::Pause => self.sim.set_paused(!self.sim.paused(), now),
            Input::Screenshot => self.screenshot(),
            Input::NextScene => self.next_scene()?,
            Input::Other(c) => self.act(Action::Key(c)),
            Input::Press { col, row, big } => {
                if let Some((x, y)) = self.pixel_at(col, row) {
                    self.act(Action::Stone { x, y, radius: self.radius, big });
                    self.drag = (!big).then_some((x, y));
                }
            }
            Input::Drag { col, row } => {
                if let (Some(from), Some(to)) = (self.drag, self.pixel_at(col, row))
                    && from != to
                {
                    self.act(Action::Stir { from, to });
                    self.drag = Some(to);
                }
            }
            Input::Release => self.drag = None,
            Input::Resize(cols, rows) => {
                self.term = (cols, rows);
                let size = match &mut self.picture {
                    Some(p) => {
                        p.resize((cols, rows));
                        p.scene_size()
                    }
                    None => picture_size(cols, rows),
                };
                if big_enough(self.term) && size != self.scene.size() {
                    self.apply(Event::Resize([size.0, size.1]));
                    self.aim = (self.aim.0.min(size.0 as i32 - 1), self.aim.1.min((size.1 as i32 - 1) & !1));
                }
            }
            Input::CursorReport(..) | Input::DeviceAttributes => {}
        }
        Ok(Flow::Continue)
    }

    /// Saves the current picture (exact pixels, no overlays) as a PNG in the current folder.
    fn screenshot(&mut self) {
        let Some(storage) = self.config.storage.clone() else {
            self.say("screenshots are off here".into());
            return;
        };
        let Ok(shot) = self.scene.snapshot() else { return };
        let base = format!("tidepool-{}-{:06}", self.scene.kind(), self.step);
        let name = (1..1000)
            .map(|i| if i == 1 { format!("{base}.png") } else { format!("{base}-{i}.png") })
            .find(|n| !std::path::Path::new(n).exists())
            .unwrap_or_else(|| format!("{base}.png"));
        match storage.save(name.as_ref(), &crate::output::png::encode(&shot)) {
            Ok(()) => {
                self.say(format!("saved {name}"));
                self.apply(Event::Screenshot(name));
            }
            Err(e) => self.say(format!("screenshot failed: {e}")),
        }
    }

    /// `tab`: the next scene, at the same size.
    fn next_scene(&mut self) -> Result<()> {
        let count = self.config.scenes.len();
        if count < 2 {
            self.say(format!("the {} is the only scene here", self.scene.kind()));
            return Ok(());
        }
        if self.recorder.is_some() {
            // A replay holds one scene; switching would make it lie.
            self.say("tab is off while recording (a replay holds one scene)".into());
            return Ok(());
        }
        let (w, h) = self.scene.size();
        let next = (self.current + 1) % count;
        self.scene = self.config.scenes[next].build(w, h)?;
        self.current = next;
        if self.help.is_some() {
            self.help = Some(ui::help_lines(&self.scene.help(), self.scene.takes_stones()));
        }
        self.sim = SimClock::new(self.scene.steps_per_second(), Instant::now());
        Ok(())
    }
}
