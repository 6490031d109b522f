//! Which pictures the terminal can show, found by asking it: the queries to send, a pure state
//! machine that folds the replies (with the window size and, only as a fallback, environment
//! hints) into a [`GraphicsSupport`], and the choice of a [`GraphicsMode`] for `--graphics`.
//!
//! **The queries** ([`queries`]), all sent at once, DA1 last: a terminal answers in order, so
//! when the DA1 reply arrives every other answer it will ever give has arrived.
//! - the kitty graphics query (`a=q`, id 31, a 1x1 RGB image): any kitty-protocol terminal
//!   answers `OK` before DA1;
//! - on this machine only (not over SSH), the same query through a temporary file (`t=t`): an
//!   `OK` means the file medium works ([`crate::output::graphics::kitty::Medium::TempFile`]);
//! - a root-frame edit of a scratch image (then deleted): an `OK` means changed rectangles can
//!   be sent as frame edits (kitty); terminals without the animation part answer with an error
//!   or not at all;
//! - a virtual placement (`a=p,U=1`) of another scratch image (then deleted): an `OK` means
//!   Unicode placeholders work (kitty 0.28+); kitty 0.26 (Debian 12's) rejects the unknown key
//!   without a word, checked under Xvfb, while it answers `OK` to the same put without `U=1`;
//! - XTSMGRAPHICS: colour registers (`CSI ? 1 ; 1 ; 0 S`) and the largest sixel image
//!   (`CSI ? 2 ; 1 ; 0 S`);
//! - `CSI 16 t` (cell size) and `CSI 14 t` (text area size), for when TIOCGWINSZ has no pixels;
//! - DECRQM for SGR-pixels mouse (`?1016`) and synchronized output (`?2026`);
//! - iTerm2's `OSC 1337 ; ReportCellSize`, which only iTerm2 answers;
//! - true colour, two ways, since over SSH `COLORTERM` is gone (OpenSSH does not send it and
//!   Debian's sshd accepts only `LANG`/`LC_*`) and `tidepool serve` never sees it:
//!   XTGETTCAP (`DCS + q` for `RGB`, then `Tc`: the terminal's terminfo says it takes 24-bit
//!   colours; xterm, kitty, foot answer from their own terminfo), and a 24-bit SGR colour set
//!   and read back with DECRQSS (`DCS $ q m`): a terminal that keeps 24-bit colours reports
//!   them as set, one that maps them to its palette reports an index (then reset);
//! - DA1 (`CSI c`): sixel when its attributes include 4.
//!
//! **tmux** answers DA1 itself and swallows what it does not understand, so inside tmux (the
//! `TMUX` variable) the probe sends a plain DA1 *first* (tmux answers at once: its attributes
//! say whether tmux itself draws sixel), then the kitty queries, `CSI 16 t`, iTerm2's query and
//! a second DA1, all wrapped for passthrough. With `allow-passthrough on` the outer terminal
//! answers them, so a second DA1 arrives (and the kitty `OK` before it, if the outer terminal
//! speaks kitty); with it off nothing more arrives and the probe ends at its deadline.
//! Passthrough is on when a second DA1 or a kitty reply arrived. kitty inside tmux draws through
//! Unicode placeholders (`U=1`), which tmux moves and clips with the pane; without passthrough
//! the player draws cells and says how to turn it on ([`TMUX_HINT`]). SGR-pixels mouse stays
//! off inside tmux.
//!
//! **No answer, a slow answer, garbage.** If the final DA1 does not arrive within the budget
//! ([`PROBE_BUDGET`]), the terminal gets cells first; answers that come later (within the
//! Screen's `LATE_ANSWERS`) still upgrade it to pixels, and a terminal silent all along is
//! given up on with a word on the status line. An escape sequence that is not a reply arriving
//! first means cells. Bytes that are not replies (keys typed during the probe) are handed back
//! in [`ProbeOutcome::leftover`] for the input parser; a reply never becomes a key (the one
//! input parser frames every reply, early or late).
//!
//! **Environment hints** are used only where no query answers: iTerm2 without its cell-size
//! reply (`TERM_PROGRAM=iTerm.app`), and to skip the file query over SSH.

use std::path::Path;
use std::time::Duration;

use base64::Engine;
use base64::engine::general_purpose::STANDARD as BASE64;

use crate::output::graphics::GraphicsMode;
use crate::output::graphics::{kitty, tmux};
use crate::play::input::{Input, Received};
use crate::play::replies::Reply;

/// The longest the probe waits for the terminal's answers before the first frame. Every
/// terminal answers DA1, and DA1 (asked last) ends the wait the moment it arrives, so a longer
/// deadline costs only a terminal that answers nothing (it sees its first frame this much
/// later, once). 500 ms covers a round trip to another continent (200-300 ms) and a terminal
/// starting on a loaded machine (kitty under Xvfb answered after 150-160 ms here): such
/// terminals get pixels from the first frame instead of cells and a switch. Answers later still
/// upgrade cells to pixels for a while (the Screen's `LATE_ANSWERS`), after which a silent
/// terminal is given up on and the status line says so.
pub const PROBE_BUDGET: Duration = Duration::from_millis(500);
/// The kitty query's image id (the protocol's example; nothing is stored under it).
pub const KITTY_QUERY_ID: u32 = 31;
/// The id of the kitty query through a temporary file.
pub const KITTY_FILE_QUERY_ID: u32 = kitty::IMAGE_ID + 1;
/// The id of the scratch image the frame-edit test edits (deleted at once).
pub const KITTY_EDIT_PROBE_ID: u32 = kitty::IMAGE_ID + 2;
/// The id of the scratch image the Unicode-placeholder test places virtually (deleted at once).
pub const KITTY_PLACEHOLDER_PROBE_ID: u32 = kitty::IMAGE_ID + 3;
/// The most bytes the probe keeps (replies and leftover keys) before it gives up.
pub const MAX_PROBE_BYTES: usize = 64 * 1024;
/// What the status line says in tmux when passthrough is off.
pub const TMUX_HINT: &str = "tmux hides pictures: `set -g allow-passthrough on` for kitty graphics";
/// What the status line says in tmux when the outer terminal speaks kitty graphics but has no
/// Unicode placeholders, which images inside tmux need.
pub const PLACEHOLDER_HINT: &str = "pictures inside tmux need kitty 0.28+ (Unicode placeholders)";
/// What the status line says when `--graphics kitty` meets a terminal that answered the probe
/// but not kitty's graphics query: its pictures would never show.
pub const NO_KITTY: &str = "no answer to kitty's graphics query: half-block cells";
/// What the status line says when `--graphics sixel` meets a terminal whose device attributes
/// do not include sixel.
pub const NO_SIXEL: &str = "the terminal does not say it draws sixel: half-block cells";
/// A 1x1 black RGB pixel, base64.
const ONE_PIXEL: &str = "AAAA";

/// What the process's environment variables say about the terminal (the door reads them):
/// hints the probe uses where no answer comes. (Named apart from the renderer's
/// `Environment`, the sky and light a scene is lit by.)
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EnvHints {
    /// Inside tmux (`TMUX` is set).
    pub tmux: bool,
    /// Over SSH (`SSH_CONNECTION` or `SSH_TTY` is set): no temporary-file query.
    pub ssh: bool,
    /// `TERM_PROGRAM`, a fallback hint only.
    pub term_program: Option<String>,
}

impl EnvHints {
    /// Reads the variables through `var` (`std::env::var` in the player, a table in tests).
    pub fn from_lookup(var: impl Fn(&str) -> Option<String>) -> EnvHints {
        let set = |name: &str| var(name).is_some_and(|v| !v.is_empty());
        EnvHints {
            tmux: set("TMUX"),
            ssh: set("SSH_CONNECTION") || set("SSH_TTY"),
            term_program: var("TERM_PROGRAM").filter(|v| !v.is_empty()),
        }
    }
}

/// The terminal's size as TIOCGWINSZ gives it (pixels 0 when the terminal does not say).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WinSize {
    /// Columns.
    pub cols: u16,
    /// Rows.
    pub rows: u16,
    /// Width in pixels, or 0.
    pub x_px: u16,
    /// Height in pixels, or 0.
    pub y_px: u16,
}

impl WinSize {
    /// The cell size in pixels the pixel fields imply, if they are filled in.
    pub fn cell_px(&self) -> Option<(u16, u16)> {
        (self.x_px > 0 && self.y_px > 0 && self.cols > 0 && self.rows > 0)
            .then(|| (self.x_px / self.cols, self.y_px / self.rows))
            .filter(|&(w, h)| w > 0 && h > 0)
    }
}

/// What the probe starts from: the terminal's size, what its environment says, and whether
/// to ask about kitty's file medium. Built with [`ProbeOptions::new`] and its `with_*`
/// builders (`probe/options.rs`); the fields are the crate's, so the hint and size types the
/// doors fill them with are not part of the API.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ProbeOptions {
    /// The environment hints.
    pub(crate) env: EnvHints,
    /// The window size.
    pub(crate) winsize: WinSize,
    /// A temporary file holding one RGB pixel (3 bytes) whose name carries
    /// `TEMP_FILE_MARKER`, for the file-medium query; `None` skips that query (always
    /// over SSH). The caller writes it before and removes it after the probe if the terminal
    /// did not.
    pub(crate) kitty_file: Option<std::path::PathBuf>,
    /// Ask whether the terminal draws 24-bit colour (`COLOUR_QUERIES`): set by the screen
    /// when `--color auto` guessed 256 colours from the environment (a guess of 16 is a
    /// terminal too plain for the question's 24-bit SGR colour).
    pub(crate) colours: bool,
}

/// Sixel support.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SixelSupport {
    /// Colour registers (XTSMGRAPHICS; 16, the VT340's, when the terminal does not say).
    pub registers: u16,
    /// The largest image, in pixels, if the terminal says.
    pub max_w: Option<u32>,
    /// The largest image's height.
    pub max_h: Option<u32>,
}

/// Colour registers assumed when DA1 says sixel but XTSMGRAPHICS does not answer (a VT340's).
pub const DEFAULT_SIXEL_REGISTERS: u16 = 16;

/// What the terminal can do, as far as the probe found out.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GraphicsSupport {
    /// The terminal answered the probe in time (the final DA1 arrived) and nothing garbled
    /// came first. Without it, `auto` means cells.
    pub answered: bool,
    /// An escape sequence that is not a reply arrived before the answers were complete.
    pub garbled: bool,
    /// The kitty graphics protocol.
    pub kitty: bool,
    /// kitty's temporary-file medium works (the terminal is on this machine).
    pub kitty_temp_file: bool,
    /// kitty root-frame edits work (changed rectangles).
    pub kitty_frame_edits: bool,
    /// kitty Unicode placeholders work (needed inside tmux).
    pub kitty_placeholders: bool,
    /// Sixel (DA1 attribute 4).
    pub sixel: Option<SixelSupport>,
    /// iTerm2 inline images.
    pub iterm2: bool,
    /// The cell size in pixels (TIOCGWINSZ, else `CSI 16 t`, else `CSI 14 t` / the grid, else
    /// iTerm2's report).
    pub cell_px: Option<(u16, u16)>,
    /// SGR-pixels mouse reporting (mode 1016) is available (never inside tmux).
    pub sgr_pixels_mouse: bool,
    /// Synchronized output (mode 2026) is known to the terminal.
    pub sync_output: bool,
    /// Inside tmux.
    pub tmux: bool,
    /// tmux passes sequences through to the outer terminal.
    pub tmux_passthrough: bool,
    /// The terminal says it draws 24-bit colour (XTGETTCAP `RGB` or `Tc`, or a 24-bit SGR
    /// colour read back as set).
    pub true_color: bool,
}

impl GraphicsSupport {
    /// The sixel colour registers to use: what the terminal said, else a VT340's
    /// (`DEFAULT_SIXEL_REGISTERS`).
    pub fn sixel_registers(&self) -> u16 {
        self.sixel.map_or(DEFAULT_SIXEL_REGISTERS, |s| s.registers)
    }
}

/// The bytes to send (see the module docs), for the options given.
pub fn queries(options: &ProbeOptions) -> Vec<u8> {
    let mut kitty_queries = format!("\x1b_Gi={KITTY_QUERY_ID},s=1,v=1,a=q,t=d,f=24;{ONE_PIXEL}\x1b\\").into_bytes();
    if let Some(path) = options.kitty_file.as_deref().filter(|_| !options.env.ssh) {
        kitty_queries.extend_from_slice(file_query(path).as_bytes());
    }
    let (edit, virt) = (KITTY_EDIT_PROBE_ID, KITTY_PLACEHOLDER_PROBE_ID);
    kitty_queries.extend_from_slice(
        format!(
            "\x1b_Ga=t,i={edit},s=1,v=1,f=24,q=1;{ONE_PIXEL}\x1b\\\x1b_Ga=f,r=1,i={edit},s=1,v=1,f=24,X=1;{ONE_PIXEL}\x1b\\\x1b_Ga=d,d=I,i={edit},q=2\x1b\\\
             \x1b_Ga=t,i={virt},s=1,v=1,f=24,q=1;{ONE_PIXEL}\x1b\\\x1b_Ga=p,U=1,i={virt},c=1,r=1\x1b\\\x1b_Ga=d,d=I,i={virt},q=2\x1b\\"
        )
        .as_bytes(),
    );
    const SIXEL: &[u8] = b"\x1b[?1;1;0S\x1b[?2;1;0S";
    const CELLS: &[u8] = b"\x1b[16t\x1b[14t";
    const ITERM2: &[u8] = b"\x1b]1337;ReportCellSize\x1b\\";
    const MODES: &[u8] = b"\x1b[?1016$p\x1b[?2026$p";
    const DA1: &[u8] = b"\x1b[c";
    let mut out = Vec::new();
    if options.env.tmux {
        // tmux answers these itself, at once.
        let colours: &[u8] = if options.colours { COLOUR_QUERIES } else { b"" };
        for q in [SIXEL, b"\x1b[?2026$p", colours, DA1] {
            out.extend_from_slice(q);
        }
        // These reach the outer terminal only through passthrough; each sequence on its own.
        let mut outer: Vec<&[u8]> = split_sequences(&kitty_queries);
        outer.extend([&b"\x1b[16t"[..], ITERM2, DA1]);
        for q in outer {
            tmux::push_wrapped(&mut out, q);
        }
    } else {
        let colours: &[u8] = if options.colours { COLOUR_QUERIES } else { b"" };
        for q in [&kitty_queries[..], SIXEL, CELLS, MODES, ITERM2, colours, DA1] {
            out.extend_from_slice(q);
        }
    }
    out
}

/// The true-colour questions: XTGETTCAP for `RGB` and for `Tc` (one name a request: xterm
/// stops a list at its first unknown name), then a 24-bit foreground set, read back with
/// DECRQSS and reset.
pub const COLOUR_QUERIES: &[u8] = b"\x1bP+q524742\x1b\\\x1bP+q5463\x1b\\\x1b[38;2;1;2;3m\x1bP$qm\x1b\\\x1b[m";

/// Whether a DCS reply says the terminal draws 24-bit colour: XTGETTCAP found `RGB` or `Tc`
/// (`1+r524742...`, `1+r5463...`), or DECRQSS read the probe's colour 1, 2, 3 back as a 24-bit
/// one (`1$r...38:2::1:2:3m`, `38:2:1:2:3` or `38;2;1;2;3`).
fn says_true_color(body: &[u8]) -> bool {
    if let Some(found) = body.strip_prefix(b"1+r") {
        return found.starts_with(b"524742") || found.starts_with(b"5463");
    }
    let Some(sgr) = body.strip_prefix(b"1$r").and_then(|b| b.strip_suffix(b"m")) else {
        return false;
    };
    let text = String::from_utf8_lossy(sgr);
    ["38:2::1:2:3", "38:2:1:2:3", "38;2;1;2;3"].iter().any(|form| {
        text.match_indices(form).any(|(at, f)| {
            let before = text[..at].chars().last();
            let after = text[at + f.len()..].chars().next();
            before.is_none_or(|c| c == ';') && after.is_none_or(|c| c == ';')
        })
    })
}

fn file_query(path: &Path) -> String {
    let path = BASE64.encode(path.as_os_str().as_encoded_bytes());
    format!("\x1b_Gi={KITTY_FILE_QUERY_ID},s=1,v=1,a=q,t=t,f=24;{path}\x1b\\")
}

/// Splits a run of APC commands into its sequences (each ends with `ESC \`).
fn split_sequences(bytes: &[u8]) -> Vec<&[u8]> {
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..bytes.len() {
        if bytes[i - 1] == 0x1b && bytes[i] == b'\\' {
            out.push(&bytes[start..=i]);
            start = i + 1;
        }
    }
    out
}

/// The probe's state: the replies so far.
#[derive(Clone, Debug, Default)]
pub struct Probe {
    options: ProbeOptions,
    replies: Vec<Reply>,
    /// DA1 replies seen.
    da1: u8,
    /// Something that is neither a reply nor a key arrived before the answers were complete.
    garbled: bool,
    /// Bytes read so far (a flood that never ends stops the probe).
    bytes: usize,
    leftover: Vec<Input>,
}

#[cfg(any(test, feature = "cli", feature = "testing"))]
/// What the probe found, and the keys that were typed meanwhile.
#[derive(Clone, Debug, PartialEq)]
pub struct ProbeOutcome {
    /// The capabilities.
    pub support: GraphicsSupport,
    /// Keys and clicks that arrived during the probe, in order.
    pub leftover: Vec<Input>,
}

impl Probe {
    /// A probe that has sent [`queries`]`(&options)`.
    pub fn new(options: ProbeOptions) -> Probe {
        Probe { options, ..Probe::default() }
    }

    /// How many DA1 replies end the probe: 2 in tmux (tmux's and the outer terminal's).
    fn da1_wanted(&self) -> u8 {
        if self.options.env.tmux { 2 } else { 1 }
    }

    /// The DA1 answers the probe can count on (1: outside tmux its own; inside, tmux's own, at
    /// once; the outer terminal's may never come back). The link control leaves that many
    /// answers to the probe.
    pub fn da1_expected(&self) -> u8 {
        1
    }

    /// Whether any device-attributes answer arrived (a terminal that answered something, such
    /// as tmux itself, is not silent).
    pub fn heard(&self) -> bool {
        self.da1 > 0
    }

    /// Whether every answer has arrived.
    pub fn done(&self) -> bool {
        self.da1 >= self.da1_wanted()
    }

    /// Counts `n` bytes read from the terminal; a flood beyond [`MAX_PROBE_BYTES`] ends the
    /// probe as garbled (this is no terminal answering).
    pub fn count_bytes(&mut self, n: usize) {
        self.bytes = self.bytes.saturating_add(n);
        if self.bytes > MAX_PROBE_BYTES && !self.done() {
            self.garbled = true;
            self.da1 = self.da1_wanted();
        }
    }

    /// Takes one thing read from the terminal (framed by the one input parser,
    /// [`crate::play::input::InputParser`]); returns [`Probe::done`].
    pub fn receive(&mut self, received: Received) -> bool {
        match received {
            // A key typed during the probe (or just after its last answer, in the same read):
            // the session handles it once the probe is over.
            Received::Input(input) => {
                if self.leftover.len() < MAX_PROBE_BYTES {
                    self.leftover.push(input);
                }
            }
            _ if self.done() => {}
            Received::Reply(reply) => {
                if matches!(reply, Reply::PrimaryAttributes(_)) {
                    self.da1 += 1;
                }
                if self.replies.len() < MAX_PROBE_BYTES / 8 {
                    self.replies.push(reply);
                }
            }
            // An escape sequence that is neither: the terminal answered something else.
            Received::Unknown => self.garbled = true,
        }
        self.done()
    }

    /// The keys typed during the probe so far, taken.
    pub fn take_leftover(&mut self) -> Vec<Input> {
        std::mem::take(&mut self.leftover)
    }

    #[cfg(any(test, feature = "cli", feature = "testing"))]
    /// What the replies say. The probe may end early ([`Probe::done`]) or at its deadline.
    pub fn finish(mut self) -> ProbeOutcome {
        let leftover = self.take_leftover();
        ProbeOutcome { support: self.support(), leftover }
    }

    /// What the replies so far say (asked again when a late answer arrives).
    pub fn support(&self) -> GraphicsSupport {
        let env = &self.options.env;
        let tmux_answered = env.tmux && self.da1 >= 1;
        let answered = !self.garbled && (self.done() || tmux_answered);
        let mut support = GraphicsSupport { answered, garbled: self.garbled, tmux: env.tmux, ..Default::default() };
        let (mut da1_seen, mut cell_reply, mut text_area, mut iterm2_cell) = (0, None, None, None);
        for reply in &self.replies {
            match reply {
                Reply::KittyGraphics { id: Some(id), message } if message == "OK" => match *id {
                    KITTY_QUERY_ID => support.kitty = true,
                    KITTY_FILE_QUERY_ID => support.kitty_temp_file = true,
                    KITTY_EDIT_PROBE_ID => support.kitty_frame_edits = true,
                    KITTY_PLACEHOLDER_PROBE_ID => support.kitty_placeholders = true,
                    _ => {}
                },
                Reply::PrimaryAttributes(attrs) => {
                    // Outside tmux the only DA1; inside, the first is tmux's own: sixel there
                    // means tmux draws sixel itself.
                    if da1_seen == 0 && attrs.contains(&4) {
                        support.sixel =
                            Some(SixelSupport { registers: DEFAULT_SIXEL_REGISTERS, max_w: None, max_h: None });
                    }
                    da1_seen += 1;
                }
                Reply::CellSize { width, height } => cell_reply = Some((*width, *height)),
                Reply::TextAreaSize { width, height } => text_area = Some((*width, *height)),
                Reply::Iterm2CellSize { width, height, scale } => {
                    support.iterm2 = true;
                    iterm2_cell = Some(((width * scale).round() as u32, (height * scale).round() as u32));
                }
                Reply::ModeReport { mode: 1016, state: 1..=3, private: true } => support.sgr_pixels_mouse = !env.tmux,
                Reply::ModeReport { mode: 2026, state: 1..=3, private: true } => support.sync_output = true,
                Reply::Dcs(body) if says_true_color(body) => support.true_color = true,
                _ => {}
            }
        }
        if let Some(sixel) = &mut support.sixel {
            for reply in &self.replies {
                match reply {
                    Reply::GraphicsAttribute { item: 1, status: 0, values } if !values.is_empty() => {
                        sixel.registers = values[0].clamp(1, u32::from(u16::MAX)) as u16;
                    }
                    Reply::GraphicsAttribute { item: 2, status: 0, values } if values.len() >= 2 => {
                        (sixel.max_w, sixel.max_h) = (Some(values[0]), Some(values[1]));
                    }
                    _ => {}
                }
            }
        }
        support.tmux_passthrough = env.tmux && (da1_seen >= 2 || support.kitty);
        if !support.iterm2 && !env.tmux {
            // No query says iTerm2 without its cell-size reply; its name is the fallback.
            // (A terminal that did not answer gets nothing at all, below.)
            support.iterm2 = env.term_program.as_deref() == Some("iTerm.app");
        }
        let (cols, rows) = (u32::from(self.options.winsize.cols), u32::from(self.options.winsize.rows));
        let per_cell = |(w, h): (u32, u32)| (cols > 0 && rows > 0).then(|| (w / cols, h / rows));
        let fits =
            |c: (u32, u32)| (c.0 > 0 && c.1 > 0 && c.0 <= 1024 && c.1 <= 1024).then_some((c.0 as u16, c.1 as u16));
        support.cell_px = self
            .options
            .winsize
            .cell_px()
            .or_else(|| cell_reply.and_then(fits))
            .or_else(|| text_area.and_then(per_cell).and_then(fits))
            .or_else(|| iterm2_cell.and_then(fits));
        if !answered {
            // Nothing that arrived can be trusted to be complete.
            // Except a colour the terminal said it draws: that answer is complete in itself.
            support = GraphicsSupport {
                garbled: self.garbled,
                tmux: env.tmux,
                cell_px: support.cell_px,
                true_color: support.true_color && !self.garbled,
                ..Default::default()
            };
        }
        support
    }
}

/// What `--graphics` asks for.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GraphicsRequest {
    /// The best the terminal answered for.
    #[default]
    Auto,
    /// This protocol, whatever the probe said.
    Force(GraphicsMode),
}

/// The mode to draw with and how.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GraphicsChoice {
    /// The protocol.
    pub mode: GraphicsMode,
    /// Wrap the protocol's sequences for tmux passthrough.
    pub tmux_wrap: bool,
    /// kitty through Unicode placeholders (inside tmux).
    pub kitty_placeholders: bool,
    /// A note for the status line (how to get pictures), if any.
    pub hint: Option<&'static str>,
}

#[cfg(any(test, feature = "cli", feature = "testing"))]
/// Whether to probe at all: only when both input and output are terminals (`render --out -`
/// into a pipe or file sends no query and draws cells).
pub fn should_probe(stdin_is_tty: bool, stdout_is_tty: bool) -> bool {
    stdin_is_tty && stdout_is_tty
}

/// The mode for `request` given what the probe found (`None`: no probe was made). `auto`
/// prefers kitty (exact colours, scaled by the terminal, changed rectangles), then sixel, then
/// iTerm2 (a whole PNG every frame), then cells. Inside tmux kitty needs passthrough and
/// Unicode placeholders (the probe tests both), sixel is used only when tmux draws it itself,
/// and iTerm2 is not used (its images are not placed through tmux).
///
/// A forced mode is used as asked (wrapped for tmux when inside it) unless the terminal's
/// answers say its pictures would never show: a terminal that answered the probe but not
/// kitty's query, or whose attributes lack sixel, or tmux without passthrough or placeholders,
/// gets cells and the reason ([`NO_KITTY`], [`NO_SIXEL`], [`TMUX_HINT`], [`PLACEHOLDER_HINT`]),
/// never a blank screen. Without answers (a silent terminal) it is used as asked. iTerm2 has
/// no query other terminals answer (WezTerm, mintty and Konsole draw its images too), so a
/// forced iTerm2 is always used as asked.
pub fn choose(request: GraphicsRequest, support: Option<&GraphicsSupport>) -> GraphicsChoice {
    let cells = |hint| GraphicsChoice { mode: GraphicsMode::Cells, tmux_wrap: false, kitty_placeholders: false, hint };
    let Some(s) = support else {
        return match request {
            GraphicsRequest::Force(mode) => {
                GraphicsChoice { mode, tmux_wrap: false, kitty_placeholders: false, hint: None }
            }
            GraphicsRequest::Auto => cells(None),
        };
    };
    let kitty = GraphicsChoice { mode: GraphicsMode::Kitty, tmux_wrap: s.tmux, kitty_placeholders: s.tmux, hint: None };
    match request {
        GraphicsRequest::Force(GraphicsMode::Kitty) if s.answered && s.tmux && !s.tmux_passthrough => {
            cells(Some(TMUX_HINT))
        }
        GraphicsRequest::Force(GraphicsMode::Kitty) if s.answered && !s.kitty => cells(Some(NO_KITTY)),
        GraphicsRequest::Force(GraphicsMode::Kitty) if s.answered && s.tmux && !s.kitty_placeholders => {
            cells(Some(PLACEHOLDER_HINT))
        }
        GraphicsRequest::Force(GraphicsMode::Kitty) => kitty,
        GraphicsRequest::Force(GraphicsMode::Sixel) if s.answered && s.sixel.is_none() => cells(Some(NO_SIXEL)),
        GraphicsRequest::Force(GraphicsMode::Iterm2) => {
            GraphicsChoice { mode: GraphicsMode::Iterm2, tmux_wrap: s.tmux, kitty_placeholders: false, hint: None }
        }
        GraphicsRequest::Force(mode) => {
            GraphicsChoice { mode, tmux_wrap: false, kitty_placeholders: false, hint: None }
        }
        GraphicsRequest::Auto if !s.answered => cells(None),
        GraphicsRequest::Auto if s.kitty && (!s.tmux || s.kitty_placeholders) => kitty,
        GraphicsRequest::Auto if s.sixel.is_some() => {
            GraphicsChoice { mode: GraphicsMode::Sixel, tmux_wrap: false, kitty_placeholders: false, hint: None }
        }
        GraphicsRequest::Auto if s.iterm2 && !s.tmux => {
            GraphicsChoice { mode: GraphicsMode::Iterm2, tmux_wrap: false, kitty_placeholders: false, hint: None }
        }
        GraphicsRequest::Auto if s.tmux && !s.tmux_passthrough => cells(Some(TMUX_HINT)),
        GraphicsRequest::Auto => cells((s.tmux && s.kitty).then_some(PLACEHOLDER_HINT)),
    }
}

mod options;
#[cfg(test)]
mod tests;
