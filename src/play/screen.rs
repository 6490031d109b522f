//! A screen: one terminal, bytes in and bytes out. It asks the terminal what it can show (the
//! graphics probe: questions out, answers fed back as bytes, the same deadline rule everywhere),
//! finds the link's rate from the terminal's answers (the link control and the byte bucket),
//! and turns the scene's picture, the seat's overlay and the status line into the frame's
//! bytes: half-block cells through the rate-controlled encoder, or real pixels (kitty, sixel,
//! iTerm2) beside a cell frame that carries the status line. It does no I/O and reads no clock:
//! the door that owns it (this process's terminal, an SSH channel) writes what it appends and
//! passes the time in.
//!
//! The terminal's bytes are framed once ([`InputParser`]): the person's inputs go back to the
//! door (for the seat), the replies stay here. Device-attributes answers are paired with their
//! questions in order: the probe's are counted first, so an answer that arrives after the
//! probe's deadline is still the probe's and never shifts the link's round trips.

pub(crate) mod compose;
mod frame;
pub(crate) mod link;
mod picture;
pub mod probe;
mod routing;
mod scratch;
mod switch;
mod ui;

use std::time::{Duration, Instant};

use self::compose::{Figures, big_enough, half_block_picture};
pub use self::link::LinkPath;
use self::link::{Change, LinkControl};
use self::picture::Picture;
use self::probe::{GraphicsChoice, GraphicsRequest, GraphicsSupport, Probe, ProbeOptions};
use super::fit::{CellGrid, Fit};
use super::input::{Input, InputParser, Received};
use super::replies::Reply;
use crate::output::bucket::ByteBucket;
use crate::output::color::ColorMode;
#[cfg(any(feature = "serve", feature = "testing", test))]
use crate::output::cursor::Cursor;
use crate::output::diff::{EncodeOptions, Shown};
use crate::output::frame::Frame;
use crate::output::graphics::GraphicsMode;
use crate::output::graphics::stream::FileWrite;
use crate::output::graphics::stream::crossover::AutoSwitch;
use crate::play::clock::{FramePacer, Meter};

/// How many bytes a second a screen may send.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bandwidth {
    /// Found by itself from the terminal's answers (the link control).
    Auto,
    /// This many bytes a second.
    Fixed(u64),
    /// No limit: every frame is sent whole (what changed of it).
    Unlimited,
}

/// How a screen draws.
#[derive(Clone, Debug)]
pub struct ScreenConfig {
    /// Frames per second at most.
    pub fps: u32,
    /// What the link carries.
    pub bandwidth: Bandwidth,
    /// Terminal colours.
    pub color: ColorMode,
    /// `color` is a guess from the environment (`--color auto`): the terminal's answers to the
    /// probe raise it to true colour, and otherwise the status line says how to get it.
    pub color_auto: bool,
    /// Under `color_auto`, the status line says how to get true colour (`--color truecolor`)
    /// when the terminal's answers did not give it. Only where the person passes the flags:
    /// `tidepool serve`'s are the server's, and its players would be told of a flag they cannot
    /// pass (while the hint covered the status line's count of players).
    pub colour_hint: bool,
    /// Encoder options (colour threshold, synchronized output).
    pub encode: EncodeOptions,
    /// How the picture is drawn (`--graphics`).
    pub graphics: GraphicsRequest,
    /// Ask the terminal what it shows before the first frame; `None` sends no question (then
    /// `auto` means cells and a forced mode is used as asked).
    pub probe: Option<ProbeOptions>,
    /// What sits between the program and the terminal (a multiplexer over SSH, mosh answer the
    /// link's questions themselves: the rate is held safe there). A door that cannot tell says
    /// [`LinkPath::Direct`].
    pub link_path: LinkPath,
}

/// Where a frame's cells come from: composed and encoded here (a lone screen), or shared with
/// the other screens of a group ([`crate::play::group`]).
#[derive(Clone, Copy, Debug)]
/// `Toward` and `Taken` are a group's (`tidepool serve`); without it only `Own` is made.
pub(crate) enum CellSource<'a> {
    /// Composed and encoded here; `figures`: the status line's figures instead of this
    /// screen's own (a group's, so that its members' status lines are alike).
    Own { figures: Option<Figures> },
    /// Encoded here, towards these cells exactly (a group's screen model: catching up with it).
    #[cfg_attr(not(any(feature = "serve", feature = "testing")), allow(dead_code))]
    Toward(&'a Frame),
    /// Encoded elsewhere (a group's frames, from the model this screen's terminal shows); the
    /// screen's own model is left as it was, the group's stands for it.
    #[cfg_attr(not(any(feature = "serve", feature = "testing")), allow(dead_code))]
    Taken(&'a [u8]),
}

/// Above this rate approximate cells are not worth their CPU: the link carries exact ones.
const APPROXIMATE_BELOW: f64 = 1_000_000.0;
/// After the probe's deadline, how long its answers may still arrive and upgrade the picture
/// (a far terminal answers a round trip later; a silent one is given up on after this).
pub const LATE_ANSWERS: Duration = Duration::from_secs(5);

/// What the status line says when `--color auto` stays below true colour: neither the
/// environment (`COLORTERM`, which SSH does not carry, or a `TERM` known for it) nor the
/// terminal's answers said it draws more, and the one flag that gives it.
pub(crate) fn colour_hint(mode: ColorMode) -> String {
    format!("{} colours (the terminal did not say more): try --color truecolor", mode.name())
}

/// Where the door writes kitty's temporary files: beside the probe's file, which the door
/// wrote there to ask the terminal whether it reads them (`None`: no file medium).
fn files_dir(config: &ScreenConfig) -> Option<std::path::PathBuf> {
    config.probe.as_ref()?.kitty_file.as_ref()?.parent().map(|d| d.to_path_buf())
}

/// The probe's progress.
#[derive(Debug)]
enum Asking {
    /// No question out (never asked, or done).
    No,
    /// The questions are out; no frame is drawn until they are answered or the deadline passes.
    First { probe: Box<Probe>, deadline: Instant },
    /// Drawing already (cells); the answers may still come until `until`.
    Late { probe: Box<Probe>, until: Instant },
}

/// One terminal.
#[derive(Debug)]
pub struct Screen {
    config: ScreenConfig,
    term: (u16, u16),
    parser: InputParser,
    received: Vec<Received>,
    asking: Asking,
    /// Device-attributes answers still owed to the probe: they come before any answer to the
    /// link's questions, which are asked after them.
    probe_answers: u8,
    choice: GraphicsChoice,
    support: GraphicsSupport,
    picture: Option<Picture>,
    /// `auto` with a terminal that shows pixels: when to draw them instead of cells (the link's
    /// rate against the protocol's crossover), and the pixel choice to come back to.
    auto_pixels: Option<(AutoSwitch, GraphicsChoice)>,
    mouse_pixels: bool,
    /// The terminal has been set up ([`Screen::ENTER`]).
    entered: bool,
    /// Pixel mouse reports must be turned on (a late upgrade to pixels).
    mouse_pixels_pending: bool,
    /// The picture's layout changed since [`Screen::take_layout_change`] last said so.
    layout_changed: bool,
    notice: Option<String>,
    /// The colours stayed below true colour under `--color auto`: say how to get it, once.
    colour_hint: bool,
    pacer: FramePacer,
    bucket: ByteBucket,
    link: LinkControl,
    /// `auto`'s switch between pixels and cells under way (the old picture stays until the
    /// new one covers it).
    switch: Option<switch::Switch>,
    /// What the terminal shows: the one model a screen keeps of its own (the encoder's, the
    /// composed frame's and the bytes' buffers are borrowed per frame: `scratch`).
    shown: Shown,
    meter: Meter,
    /// Every byte handed out, for the link's delivery rate.
    bytes_sent: u64,
    /// The most bytes a frame of this screen took: the caller's buffer is given room for it
    /// at once, so it stops growing after the first frames.
    largest_frame: usize,
}

impl Screen {
    /// Sent once before the first frame: alternate screen, hidden cursor, mouse reporting
    /// (buttons and drags only, mode 1002, not every motion; SGR coordinates, mode 1006),
    /// screen cleared.
    pub const ENTER: &'static [u8] = b"\x1b[?1049h\x1b[?25l\x1b[?1000h\x1b[?1002h\x1b[?1006h\x1b[0m\x1b[2J";
    #[cfg(any(test, feature = "cli", feature = "testing"))]
    /// Sent when the session ends (after the restore prefix, see [`Screen::farewell`]): abort any cut sequence,
    /// end synchronized output, reset colours, mouse off, cursor on, back to the normal screen.
    pub const RESTORE: &'static [u8] = b"\x18\x1b[?2026l\x1b[0m\x1b[?1006l\x1b[?1002l\x1b[?1000l\x1b[?25h\x1b[?1049l";

    /// A screen for a terminal of `term` cells (columns, rows), its clock starting at `now`.
    pub fn new(config: ScreenConfig, term: (u16, u16), now: Instant) -> Screen {
        let asks = config.probe.is_some() && config.graphics != GraphicsRequest::Force(GraphicsMode::Cells);
        let choice = probe::choose(if asks { GraphicsRequest::Auto } else { config.graphics }, None);
        let support = GraphicsSupport::default();
        let link = LinkControl::on(config.link_path);
        let bucket = match config.bandwidth {
            Bandwidth::Auto => ByteBucket::new(link.rate().unwrap_or(link::START_RATE)),
            Bandwidth::Fixed(rate) => ByteBucket::new(rate as f64),
            Bandwidth::Unlimited => ByteBucket::unlimited(),
        };
        Screen {
            picture: Picture::new(&choice, &support, term, files_dir(&config)),
            pacer: FramePacer::new(config.fps, now),
            meter: Meter::new(now),
            config,
            term,
            parser: InputParser::new(),
            received: Vec::new(),
            asking: Asking::No,
            probe_answers: 0,
            choice,
            support,
            auto_pixels: None,
            mouse_pixels: false,
            entered: false,
            mouse_pixels_pending: false,
            layout_changed: false,
            notice: None,
            colour_hint: false,
            bucket,
            link,
            switch: None,
            shown: Shown::UNKNOWN,
            bytes_sent: 0,
            largest_frame: 0,
        }
    }

    /// Starts the session: appends the probe's questions to `out` when the terminal is to be
    /// asked (nothing otherwise). No frame is drawn until the answers are in or
    /// `PROBE_BUDGET` (500 ms) has passed.
    pub(crate) fn start(&mut self, now: Instant, out: &mut Vec<u8>) {
        let Some(mut options) = self.config.probe.clone().filter(|_| matches!(self.asking, Asking::No)) else {
            self.settle_colours(false);
            return;
        };
        options.colours = self.config.color_auto && self.config.color == ColorMode::Palette256;
        if self.config.graphics == GraphicsRequest::Force(GraphicsMode::Cells) || self.entered {
            self.settle_colours(false);
            return;
        }
        out.extend_from_slice(&probe::queries(&options));
        let probe = Probe::new(options);
        self.probe_answers = probe.da1_expected();
        // The link asks nothing until the probe's answers are in (or given up on).
        self.link.expect_foreign(now, usize::from(self.probe_answers));
        self.asking = Asking::First { probe: Box::new(probe), deadline: now + probe::PROBE_BUDGET };
    }

    /// Whether the probe's first answers are still awaited (no frame is drawn meanwhile).
    pub(crate) fn probing(&self) -> bool {
        matches!(self.asking, Asking::First { .. })
    }

    /// Takes bytes the terminal sent at `now`: replies are used here, the person's inputs are
    /// appended to `inputs` (keys typed during the probe come once it is over; a run of drags
    /// is merged into its last position).
    pub(crate) fn feed(&mut self, bytes: &[u8], now: Instant, inputs: &mut Vec<Input>) {
        if let Asking::First { probe, .. } = &mut self.asking {
            probe.count_bytes(bytes.len());
        }
        self.parser.feed(bytes, now, &mut self.received);
        self.route(now, inputs);
    }

    /// Looks at the clock: a lone Escape that waited long enough, the probe's deadline, the
    /// link's lost questions.
    pub(crate) fn tick(&mut self, now: Instant, inputs: &mut Vec<Input>) {
        self.parser.flush_stale(now, &mut self.received);
        self.route(now, inputs);
        match &self.asking {
            Asking::First { deadline, .. } if now >= *deadline => self.end_probe(now, inputs),
            Asking::Late { probe, until } if now >= *until => {
                // The answers still owed will not come (inside tmux without passthrough, the
                // outer terminal's never does).
                let silent = !probe.heard();
                self.asking = Asking::No;
                self.probe_answers = 0;
                if silent && self.config.graphics == GraphicsRequest::Auto {
                    self.notice = Some("the terminal did not answer: half-block cells".into());
                }
            }
            _ => {}
        }
        if self.auto() && !self.probing() {
            if self.link.tick(now) == Change::Down {
                self.bucket.drain();
            }
            self.bucket.set_rate(self.link.rate());
        }
    }

    /// When [`Screen::tick`] must next look at the clock (a lone Escape's wait, the probe's
    /// deadline), if at all.
    pub(crate) fn next_tick(&self) -> Option<Instant> {
        let asking = match &self.asking {
            Asking::First { deadline, .. } => Some(*deadline),
            Asking::Late { until, .. } => Some(*until),
            Asking::No => None,
        };
        match (asking, self.parser.deadline()) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// When the next frame is due (frames are drawn at most `fps` a second).
    pub(crate) fn next_frame(&self) -> Instant {
        self.pacer.next_due()
    }

    /// The terminal is now `term` cells: the next frame repaints everything.
    pub(crate) fn resize(&mut self, term: (u16, u16)) {
        if term == self.term {
            return;
        }
        self.term = term;
        self.shown = Shown::UNKNOWN;
        if let Some(p) = &mut self.picture {
            p.resize(term);
        }
        self.layout_changed = true;
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// The terminal's size in cells.
    pub(crate) fn term(&self) -> (u16, u16) {
        self.term
    }

    /// Whether the terminal is big enough for the picture and the status line (a smaller one
    /// shows a notice, and the scene need not be drawn).
    pub(crate) fn drawable(&self) -> bool {
        big_enough(self.term)
    }

    /// Whether the picture's size or place changed (a resize, the probe's answer) since this
    /// was last asked: the door then makes a new fit (and the local player resizes its scene).
    pub(crate) fn take_layout_change(&mut self) -> bool {
        std::mem::take(&mut self.layout_changed)
    }

    /// Something to tell the person (which protocol draws, how to get pictures), once.
    pub(crate) fn take_notice(&mut self) -> Option<String> {
        let colours = std::mem::take(&mut self.colour_hint).then(|| colour_hint(self.config.color));
        match (self.notice.take(), colours) {
            (Some(notice), Some(colours)) => Some(format!("{notice}; {colours}")),
            (notice, colours) => notice.or(colours),
        }
    }

    /// The picture `Screen::frame` takes, in pixels: the half-block picture (a pixel a
    /// column, two a row, above the status line), or the real-pixel picture within the scene
    /// cap (scaled up by the terminal or the sixel encoder).
    pub fn picture_size(&self) -> (u32, u32) {
        match &self.picture {
            Some(p) => p.scene_size(),
            None => half_block_picture(self.term),
        }
    }

    /// How a scene of `scene` pixels sits in this terminal's picture.
    pub(crate) fn fit(&self, scene: (u32, u32)) -> Fit {
        let grid = match &self.picture {
            _ if !big_enough(self.term) => CellGrid::HalfBlocks { cols: 0, rows: 0 },
            Some(p) => CellGrid::Pixels { layout: *p.layout(), mouse_pixels: self.mouse_pixels },
            None => CellGrid::HalfBlocks { cols: self.term.0, rows: self.term.1.saturating_sub(1) },
        };
        Fit::new(scene, self.picture_size(), grid)
    }

    /// Whether a frame should be drawn now: the probe is not holding the screen, and the frame
    /// is due or `urgent` (a key's frame goes out at once).
    pub(crate) fn ready(&self, now: Instant, urgent: bool) -> bool {
        !self.probing() && (urgent || self.pacer.ready(now))
    }

    /// A due frame was not drawn (the door's writer was still busy): the cadence moves on.
    pub(crate) fn skip(&mut self, now: Instant) {
        self.pacer.sent(now);
    }

    /// Moves the temporary files the frames handed out so far name (kitty's file medium) to
    /// `out`: the door writes them before it sends those frames' bytes.
    pub(crate) fn take_files(&mut self, out: &mut Vec<FileWrite>) {
        if let Some(p) = &mut self.picture {
            p.take_files(out);
        }
    }

    /// The last frame's bytes were handed to the door's writer at `at` (after they were built
    /// and their files written): the link's question among them left then
    /// ([`link::LinkControl::handed_over`]).
    pub(crate) fn handed_over(&mut self, at: Instant) {
        self.link.handed_over(at);
    }

    /// The door could not write a temporary file: pixels go directly from now on (the next
    /// picture whole).
    pub(crate) fn handle_file_error(&mut self) {
        self.config.probe.iter_mut().for_each(|p| p.kitty_file = None);
        if let Some(p) = &mut self.picture {
            p.files_failed();
        }
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// The link's rate in effect, bytes a second (`None`: no limit).
    pub fn rate(&self) -> Option<f64> {
        self.bucket.rate()
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// How the screen draws.
    pub(crate) fn config(&self) -> &ScreenConfig {
        &self.config
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// What the encoder takes the terminal to show.
    pub(crate) fn shown(&self) -> &Shown {
        &self.shown
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// The terminal shows `shown` (a group's model: this screen leaves the group).
    pub(crate) fn set_shown(&mut self, shown: &Shown) {
        self.shown.clone_from(shown);
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// Forgets the cursor and the colours in effect, so that the next frame starts with an
    /// absolute move and explicit colours: a group's frame is then right for every terminal
    /// whose cells are the group's, wherever its cursor is.
    pub(crate) fn forget_pen(&mut self) {
        (self.shown.cursor, self.shown.fg, self.shown.bg) = (Cursor::Unknown, None, None);
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// Frees what only a screen that encodes needs (its model of the terminal: the encoder's
    /// buffers are the process's, borrowed per frame): a group member in step takes its
    /// group's bytes instead. The model comes back, at its cost, when it encodes again.
    pub(crate) fn release(&mut self) {
        self.shown = Shown::UNKNOWN;
        self.largest_frame = 0;
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// A screen that writes to no terminal (a group's): no set-up bytes before its first frame.
    pub(crate) fn without_enter(mut self) -> Screen {
        self.entered = true;
        self
    }

    /// Whether link questions are still unanswered (a door that is closing waits a little for
    /// their answers, so they do not reach the shell as typed text).
    pub(crate) fn awaiting_answers(&self) -> bool {
        self.link.awaiting() > 0 || matches!(self.asking, Asking::Late { .. })
    }

    /// What must be undone before [`Screen::RESTORE`] when the session ends: kitty's image
    /// deleted, pixel mouse reports off. A door writes it on every way out (a signal too).
    pub(crate) fn restore_prefix(&self) -> Vec<u8> {
        let mut out = picture::restore_bytes(&self.choice, self.mouse_pixels);
        if let Some(switch::Switch::ToCells { delete }) = &self.switch {
            // The picture a switch to cells has not taken away yet.
            out.extend_from_slice(delete);
        }
        out
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// The bytes that hand the terminal back: what the picture needs undone (kitty's image
    /// deleted, pixel mouse reports off), then [`Screen::RESTORE`].
    pub fn farewell(&self, out: &mut Vec<u8>) {
        out.extend_from_slice(&self.restore_prefix());
        out.extend_from_slice(Self::RESTORE);
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// Frames and bytes a second over the last whole second.
    pub(crate) fn figures(&self) -> (u32, u64) {
        (self.meter.fps, self.meter.bytes_per_second)
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// The protocol drawing the picture.
    pub(crate) fn mode(&self) -> GraphicsMode {
        self.choice.mode
    }
}

#[cfg(test)]
mod tests;
