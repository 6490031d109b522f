//! One terminal's pictures under rate control: a [`PictureStream`] is the picture encoder of a
//! pixel mode (kitty, sixel, iTerm2) together with the choices that fit it to a link — the
//! resolution (a [`ladder`] from the source picture's size down to half-block resolution), the
//! packing (kitty: a PNG, or under a rate a palette PNG of a few colours fitted to the scene
//! ([`crate::output::graphics::palette_png`]), whole images or `a=f` frame edits of changed
//! rectangles,
//! or temporary files for a terminal on this machine; sixel: changed cell blocks; iTerm2: PNG
//! or JPEG) and the picture rate — so that a picture never costs more than the bytes the caller
//! has now.
//!
//! Pure and clock-injected: no terminal, no clock, no file. Time comes in as an argument.
//! kitty's temporary files (a terminal on this machine reads the pixels from them) are data
//! too: a committed offer's file is handed out by [`PictureStream::take_files`] and the door
//! writes it before the offer's bytes; a file it cannot write is reported back
//! ([`PictureStream::files_failed`]) and the stream sends pixels directly from then on.
//!
//! # The contract (how the Screen calls it)
//!
//! 1. Make one stream per terminal and mode: [`PictureStream::new`] with the layout
//!    ([`crate::output::graphics::geometry::layout`]) and the protocol's [`Protocol`] settings
//!    from the probe. After a resize make a new one.
//! 2. Each frame, after the cells (the status line goes first), call [`PictureStream::prepare`]
//!    with the scene's picture (any size up to the layout's picture: the pool renders within
//!    the player's scene cap, and the stream never sends more pixels than it is given), the
//!    [`Budget`] (the bucket's bytes now, its rate, the frame interval) and `now`. The picture
//!    is encoded into the stream's own buffer: nothing is committed yet.
//! 3. `prepare` returns `None` (nothing to send: not due, unchanged, or nothing fits the bytes
//!    available now) or an [`Offer`] whose `bytes` are at most `budget.available`. Put them in
//!    the frame's synchronized update, take them from the bucket (`ByteBucket::spend`), and
//!    call [`PictureStream::commit`] once they are written. Only then does the stream believe
//!    the terminal shows the picture; an offer not committed is forgotten at the next
//!    `prepare`.
//! 4. Text written over the picture (the help overlay over sixel or iTerm2 pixels) or a cleared
//!    screen: [`PictureStream::invalidate`]; the next picture is sent whole.
//! 5. [`PictureStream::state`] says what the stream does (rung, packing, picture rate) for the
//!    status line; [`crossover`] says when `auto` should prefer cells.
//!
//! # Rate control
//!
//! The rung is the largest whose whole picture is predicted to cost at most the bytes the rate
//! brings in a tenth of a second ([`MIN_RATE`] pictures a second; kitty from 150 kB/s
//! a sixteenth, `plan::KITTY_MIN_RATE`: fresher, smaller pictures scored truer), within the bucket's burst
//! and less a share kept for the status line ([`PICTURE_SHARE`]). The stream learns what each
//! rung costs (bytes a pixel, a moving average per rung, the first guess scaled from a
//! neighbour). Pictures then go as often as the bucket holds the rung's predicted cost (at most
//! the protocol's rate and once a frame), so a link's whole rate is used: what a rung leaves
//! below the allowance becomes a higher picture rate, not idle bytes. While the bucket holds
//! less than the prediction nothing is encoded (no CPU for pictures that would not fit). The
//! encoded picture's real cost is known before it is offered: above the allowance the next
//! rung down is tried. When even the bottom rung is too big, kitty (with frame edits) and sixel
//! send it in tiles, oldest first, each an edit of what is shown and each within the bytes
//! available now; iTerm2 and kitty without frame edits send the bottom rung less often, when
//! the bucket holds it. Without a rate every picture goes at the source's own size (no
//! interpolated pixels; sixel: at the screen's, the source enlarged smoothly, since the
//! terminal does not scale sixel), in the packing that costs least CPU.
//!
//! Under a rate the stream keeps a model of what the terminal shows (the lossy pixels), of the
//! picture it was encoded from and of the source picture: changes are found against the
//! picture encoded, not the lossy one shown, and a still scene's bytes go to the blocks
//! furthest from the truth until the top rung is exact; then it sends nothing (`refine.rs`).
//! While the scene moves, kitty's changed box goes as a lossy frame edit and the bytes a whole
//! picture would have taken beyond it refine the blocks outside it, whose source is still.

#[cfg(feature = "player")]
pub mod crossover;
pub mod ladder;
mod tiles;

use std::path::PathBuf;
use std::time::{Duration, Instant};

use tiny_skia::Pixmap;

use self::ladder::Resampler;
#[cfg(test)]
use self::plan::KITTY_COLOURS;
use self::plan::{MIN_RATE, PICTURE_SHARE};
use crate::output::graphics::deflate::Zlib;
use crate::output::graphics::geometry::Layout;
use crate::output::graphics::kitty::{KittyOptions, Medium};
use crate::output::graphics::pack::Packing;
use crate::output::graphics::scan;
use crate::output::graphics::sixel::{Registers, SixelEncoder, SixelPalette, TMUX_MAX_IMAGE_BYTES};
use crate::output::graphics::{lossy_png, palette_png};

/// The soonest the next picture may follow a base image sent for tiles.
const FRAME_MIN: Duration = Duration::from_millis(1);

/// The protocol and its settings, from the probe.
#[derive(Clone, Debug)]
pub enum Protocol {
    /// kitty graphics: image id, placement, tmux wrapping and placeholders, frame edits, the
    /// medium (direct, or temporary files for a terminal on this machine), z-index (the cell
    /// area and origin are taken from the layout).
    Kitty(KittyOptions),
    /// sixel: the palette for the terminal's registers, when registers are defined, and tmux
    /// (images wrapped for passthrough and kept under tmux's input buffer).
    Sixel {
        /// The palette.
        palette: SixelPalette,
        /// When registers are defined.
        registers: Registers,
        /// Inside tmux.
        tmux: bool,
    },
    /// iTerm2 inline images, wrapped for tmux when asked.
    Iterm2 {
        /// Inside tmux.
        tmux: bool,
    },
}

impl Protocol {
    /// The most pictures a second: kitty and iTerm2 scale in the terminal and keep up with the
    /// player's 30 frames; sixel pictures are drawn pixel for pixel and cost several times more
    /// to encode and to draw, so 15.
    fn max_rate(&self) -> f64 {
        match self {
            Protocol::Sixel { .. } => 15.0,
            _ => 30.0,
        }
    }

    /// Whether part of the shown picture can be replaced (kitty's frame edits, sixel's blocks):
    /// then a picture too big for the link goes in tiles.
    fn edits(&self) -> bool {
        match self {
            Protocol::Kitty(o) => o.frame_edits,
            Protocol::Sixel { .. } => true,
            Protocol::Iterm2 { .. } => false,
        }
    }
}

/// What the caller can spend now.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Budget {
    /// Bytes the caller's bucket holds now (`usize::MAX`: no limit).
    pub available: usize,
    /// The link's rate in bytes a second (`None`: no limit).
    pub rate: Option<f64>,
    /// The caller's frame interval (pictures come at most once a frame).
    pub frame_interval: Duration,
    /// The caller may take one picture beyond `available` now (its bucket is as full as it
    /// gets and nothing big waits on the link) and owe the excess. A protocol that cannot send
    /// part of a picture (iTerm2, kitty without frame edits) sends its smallest whole picture
    /// then when even that is more than the bucket ever holds: fewer pictures, never none.
    pub overdraw: bool,
}

impl Budget {
    #[cfg(any(test, feature = "testing"))]
    /// No limit, frames every `frame_interval`.
    pub fn unlimited(frame_interval: Duration) -> Budget {
        Budget { available: usize::MAX, rate: None, frame_interval, overdraw: false }
    }

    #[cfg(any(test, feature = "testing"))]
    /// `available` bytes now at `rate`, frames every `frame_interval`, no overdraw.
    pub fn new(available: usize, rate: Option<f64>, frame_interval: Duration) -> Budget {
        Budget { available, rate, frame_interval, overdraw: false }
    }
}

/// A picture ready to send.
#[derive(Debug)]
pub struct Offer<'a> {
    /// The bytes, at most the budget's `available`.
    pub bytes: &'a [u8],
    /// What they show (read by the tests and benchmarks, feature `testing`).
    #[cfg_attr(not(any(test, feature = "testing")), allow(dead_code))]
    pub state: State,
}

/// What the stream is doing, for the status line and the benchmarks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State {
    /// The picture's size on the wire (the rung), pixels.
    pub size: (u32, u32),
    /// The packing (sixel and kitty's temporary files: `None`).
    pub packing: Option<Packing>,
    /// Pictures a second the link's rate pays for at this rung.
    pub rate: f64,
    /// The part of the picture the last offer carried.
    pub part: Part,
}

/// Which part of the picture an offer carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    /// The whole picture.
    Whole,
    /// The box `(x, y, w, h)` holding every change (pixels of the picture on the wire; for
    /// sixel, screen pixels).
    Changed(u32, u32, u32, u32),
    /// The box `(x, y, w, h)` only: a tile of a picture too big for the link (the rest follows
    /// in later offers).
    Tile(u32, u32, u32, u32),
}

/// A file the door writes before it sends the bytes that name it (kitty's temporary-file
/// medium: the terminal reads the pixels from it and deletes it).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FileWrite {
    /// Where the file goes (a new file: an existing one of that name is not followed).
    pub path: PathBuf,
    /// Its bytes.
    pub bytes: Vec<u8>,
}

/// What is pending until [`PictureStream::commit`].
#[derive(Clone, Copy, Debug)]
struct Pending {
    rung: usize,
    part: Part,
    /// What the commit does to the model of where the shown picture came from.
    model: Model,
    /// The offer makes the shown picture the source's own pixels at the top rung.
    exact: bool,
}

/// What a commit does to `sent` and `source_shown` (see [`PictureStream`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Model {
    /// The offer was encoded from this frame's `target` and `source_now`: they become `sent`
    /// and `source_shown`.
    Set,
    /// The offer refined what was shown towards `sent`: both stay.
    Keep,
    /// The offer is not an encoding of a known source picture: both are forgotten.
    Clear,
}

/// One terminal's pictures under rate control (see the module documentation).
#[derive(Debug)]
pub struct PictureStream {
    protocol: Protocol,
    layout: Layout,
    /// The source picture size the ladder was built for.
    source: (u32, u32),
    rungs: Vec<(u32, u32)>,
    rung: usize,
    /// Learned bytes a pixel of a whole picture, per rung.
    cost: Vec<Option<f64>>,
    /// Pictures a second the rate pays for, and when the next picture may go.
    rate: f64,
    next_due: Option<Instant>,
    /// What the terminal shows: the rung and its pixels (RGB at the rung; sixel: registers at
    /// screen size), `None` when unknown.
    shown: Option<(usize, Vec<u8>)>,
    /// The picture being offered (same form as `shown`).
    candidate: Vec<u8>,
    /// Under a rate (kitty and iTerm2): this frame's picture at the rung as the source gives it
    /// (the lossy packings show something near it), and the one the shown picture was encoded
    /// from with its rung: changes are found between these two, not against `shown`, which a
    /// lossy packing leaves a little off everywhere.
    target: Vec<u8>,
    sent: Option<(usize, Vec<u8>)>,
    /// Under a rate: this frame's source picture and the one `sent` was made from (RGBA as
    /// given): equal, the scene is still and the bytes go to refining what is shown
    /// (`refine.rs`).
    source_now: Vec<u8>,
    source_shown: Vec<u8>,
    /// The terminal shows the source's own pixels at the top rung (a still scene is done).
    shown_exact: bool,
    /// The bytes of the last whole picture a refinement encoded and the bucket did not hold
    /// (the exact picture of a protocol without frame edits, kitty's first picture of a climb
    /// to a higher rung): it is not encoded again until the bucket holds them.
    refine_cost: Option<usize>,
    pending: Option<Pending>,
    /// The next tile (its index in raster order) when pictures go in tiles.
    next_tile: usize,
    /// The last state, for the status line.
    state: State,
    /// Scratch: the offer's bytes, the packed pixels, a box's pixels, the resampled picture.
    bytes: Vec<u8>,
    packed: Vec<u8>,
    part_rgb: Vec<u8>,
    rgb: Vec<u8>,
    resampler: Resampler,
    /// kitty's compressors, kept from picture to picture (the same bytes as new ones).
    zlib: Zlib,
    lossy: lossy_png::Encoder,
    palette: palette_png::Encoder,
    /// Scratch of the block search (`refine.rs`): the blocks, and one region's error table.
    blocks: Vec<refine::Block>,
    block_table: Vec<u64>,
    sixel: Option<Box<SixelEncoder>>,
    /// kitty's placeholder text must be (re)printed after the next whole image.
    placeholders_due: bool,
    /// kitty's temporary files: how many were named, the one the pending offer names (dropped
    /// when the offer is not committed: it is never written), and the committed ones the door
    /// has not taken yet.
    files: u64,
    pending_file: Option<FileWrite>,
    committed_files: Vec<FileWrite>,
}

impl PictureStream {
    /// A stream for `protocol` over `layout` (whose `picture` bounds the top rung). Nothing is
    /// shown yet.
    pub fn new(protocol: Protocol, layout: Layout) -> PictureStream {
        let sixel = match &protocol {
            Protocol::Sixel { palette, registers, tmux } => {
                let mut s = SixelEncoder::new(palette.clone(), layout.origin, Some(layout.cell_px));
                s.set_registers(*registers);
                // Under tmux's input buffer always: harmless elsewhere (an image that big is
                // cut at a row of cells), and tmux drawing sixel itself needs it unwrapped.
                s.set_max_image_bytes(Some(TMUX_MAX_IMAGE_BYTES), *tmux);
                Some(Box::new(s))
            }
            _ => None,
        };
        let rate = protocol.max_rate();
        let mut stream = PictureStream {
            cost: Vec::new(),
            protocol,
            layout,
            source: (0, 0),
            rungs: Vec::new(),
            rung: 0,
            rate,
            next_due: None,
            shown: None,
            candidate: Vec::new(),
            target: Vec::new(),
            sent: None,
            source_now: Vec::new(),
            source_shown: Vec::new(),
            shown_exact: false,
            refine_cost: None,
            pending: None,
            next_tile: 0,
            state: State { size: layout.picture, packing: None, rate, part: Part::Whole },
            bytes: Vec::new(),
            packed: Vec::new(),
            part_rgb: Vec::new(),
            rgb: Vec::new(),
            resampler: Resampler::default(),
            zlib: Zlib::default(),
            lossy: lossy_png::Encoder::default(),
            palette: palette_png::Encoder::default(),
            blocks: Vec::new(),
            block_table: Vec::new(),
            sixel,
            placeholders_due: true,
            files: 0,
            pending_file: None,
            committed_files: Vec::new(),
        };
        stream.build_ladder(layout.picture);
        stream
    }

    /// The layout in force.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    #[cfg(any(test, feature = "testing"))]
    /// What the stream did last.
    pub fn state(&self) -> State {
        self.state
    }

    /// Forgets what the terminal shows: the next picture is sent whole.
    pub fn invalidate(&mut self) {
        self.forget_pending();
        self.shown = None;
        self.forget_model();
        self.next_due = None;
        self.next_tile = 0;
        self.placeholders_due = true;
    }

    /// Whether a picture may go at `now` (the protocol's picture rate; the bucket decides too).
    fn due(&self, now: Instant) -> bool {
        self.next_due.is_none_or(|t| now >= t)
    }

    /// The ladder for a `source`-sized picture: from the source within the layout's picture
    /// (sixel: the layout's picture above it) down to a quarter of half-block resolution.
    fn build_ladder(&mut self, source: (u32, u32)) {
        let area = self.layout.picture;
        let k = (f64::from(area.0) / f64::from(source.0.max(1)))
            .min(f64::from(area.1) / f64::from(source.1.max(1)))
            .min(1.0);
        let top = (((f64::from(source.0) * k) as u32).max(1), ((f64::from(source.1) * k) as u32).max(1));
        // A quarter of half-block resolution: below cells' own, but whole pictures there
        // score better than tiles of a finer rung (`benches/pictures.rs`: kitty at 250 kB/s,
        // SSIM 0.65 with whole 100x59 pictures against 0.62 with tiles of 160x94).
        let bottom = (u32::from(self.layout.cells.0) / 2, u32::from(self.layout.cells.1));
        self.source = source;
        self.rungs = ladder::rungs(top, bottom);
        // Sixel pixels are screen pixels (the terminal does not scale them): above the source
        // goes the screen's own size, the source enlarged by the resampler's tent filter, so
        // a link that carries it shows the smooth picture kitty and iTerm2 show rather than
        // each source pixel repeated into a block. The rungs below stay the source's, so a
        // slow link keeps its fine steps near the bottom.
        if matches!(self.protocol, Protocol::Sixel { .. }) && area != top {
            self.rungs.insert(0, area);
        }
        self.cost = vec![None; self.rungs.len()];
        self.rung = 0;
        self.shown = None;
        self.forget_model();
        self.next_tile = 0;
    }

    /// Forgets where the shown picture came from.
    fn forget_model(&mut self) {
        self.sent = None;
        self.source_shown.clear();
        self.shown_exact = false;
        self.refine_cost = None;
    }

    /// The picture `picture` encoded for the terminal within `budget`, or `None` (see the
    /// module documentation). Nothing is believed shown until [`PictureStream::commit`].
    pub fn prepare(&mut self, picture: &Pixmap, budget: Budget, now: Instant) -> Option<Offer<'_>> {
        self.forget_pending();
        if !self.due(now) {
            return None;
        }
        let source = (picture.width(), picture.height());
        if source != self.source {
            self.build_ladder(source);
        }
        // No rate but a bound on the bytes now (the link's window of unanswered bytes while
        // its rate is still unknown): planned as the rate that pays for those bytes in a
        // picture interval, so the pictures fit the window as it opens.
        let budget = Budget {
            rate: budget.rate.or_else(|| {
                (budget.available < usize::MAX).then(|| budget.available as f64 * MIN_RATE / PICTURE_SHARE)
            }),
            ..budget
        };
        let allowance = self.plan(budget);
        let room = allowance.min(budget.available);
        let limited = budget.rate.is_some();
        // A still scene under a rate: the bytes refine what is shown towards the source.
        if limited && self.still(picture) {
            // Refined at [`MIN_RATE`]'s allowance whatever the moving picture's rate: a still
            // picture is not made staler by bigger steps (as before kitty's own rate).
            let allowance = budget.rate.map_or(allowance, |r| plan::allowance(r, MIN_RATE) as usize);
            let room = allowance.min(budget.available);
            let interval = self.interval(budget);
            return self.refine(budget, (room, allowance), now, interval);
        }
        if limited && !matches!(self.protocol, Protocol::Sixel { .. }) {
            self.source_now.clear();
            self.source_now.extend_from_slice(picture.data());
        }
        let interval = self.interval(budget);
        // The bucket does not hold what this rung costs yet: no picture is encoded for nothing.
        if limited
            && !budget.overdraw
            && self.predict(self.rung).is_some_and(|c| c > room as f64 && c <= allowance as f64)
        {
            return None;
        }
        // Nor the bottom rung of a protocol without tiles, and the caller cannot overdraw.
        let bottom = self.rungs.len() - 1;
        if self.rung == bottom
            && !self.protocol.edits()
            && !budget.overdraw
            && self.predict(bottom).is_some_and(|c| c > budget.available as f64)
        {
            return None;
        }
        let mut rung = self.rung;
        let part = loop {
            // Unchanged: nothing to send, and nothing owed.
            let Some(part) = self.encode(picture, rung, budget.rate) else {
                self.next_due = Some(now + interval);
                return None;
            };
            self.learn(rung, part, limited);
            if self.bytes.len() <= room || (budget.overdraw && self.bytes.len() <= allowance) {
                // What a whole picture at this rung is expected to cost bounds the bytes
                // still regions are refined with, so the moving picture keeps its rate.
                let limit = room.min(self.predict(rung).map_or(allowance, |c| c as usize));
                let part = if limited { self.refine_still(rung, part, limit) } else { part };
                return self.offer(rung, part, limited, now + interval);
            }
            if self.bytes.len() <= allowance {
                // Within the rung's allowance but not the bucket's bytes now: a later frame.
                return None;
            }
            if rung + 1 < self.rungs.len() {
                rung += 1;
                continue;
            }
            // The bottom rung of a protocol without tiles: fewer than 10 pictures a second,
            // each when the bucket holds it, or (bigger than the bucket ever holds) when the
            // caller can overdraw.
            if !self.protocol.edits() {
                if self.bytes.len() > budget.available && !budget.overdraw {
                    return None;
                }
                return self.offer(rung, part, limited, now + interval);
            }
            break part;
        };
        // Even the bottom rung is too big: tiles of it, where the protocol edits.
        if !self.protocol.edits() {
            return None;
        }
        match self.protocol {
            // Nothing known shown: every tile differs from "unknown".
            Protocol::Sixel { .. } if self.shown.is_none() => {
                self.shown = Some((rung, vec![u8::MAX; self.candidate.len()]));
            }
            // An image of the picture's mean colour first (a few bytes), which the tiles then
            // edit.
            Protocol::Kitty(_) if self.shown.as_ref().is_none_or(|(r, _)| *r != rung) => {
                self.flatten_candidate();
                self.bytes.clear();
                self.push_part(Part::Whole, rung, Some(Packing::Zlib(6)));
                return self.offer_as(rung, Part::Whole, limited, now + FRAME_MIN, Model::Clear, false);
            }
            _ => {}
        }
        let Some(part) = self.encode_tile(rung, part, room, limited) else {
            self.tiles_done(rung, limited);
            return None;
        };
        self.offer(rung, part, limited, now + interval)
    }

    /// No tile to send: under a rate, when kitty's lossy tiles show all of this frame's
    /// picture at `rung` (the shown picture is the candidate), the model learns where it came
    /// from (this frame's picture at the rung and its source), so a still scene is refined to
    /// exact and climbs from there (`refine.rs`) as it does after a whole picture. Without
    /// this a link too slow for the bottom rung's whole picture kept a still picture at the
    /// bottom rung's lossy tiles for good.
    fn tiles_done(&mut self, rung: usize, limited: bool) {
        let lossy = self.packing(limited, rung).is_some_and(Packing::rewrites_pixels);
        if !lossy || self.sent.is_some() || self.source_now.is_empty() {
            return;
        }
        if self.shown.as_ref().is_some_and(|(r, shown)| *r == rung && *shown == self.candidate) {
            self.sent = Some((rung, self.target.clone()));
            self.source_shown.clone_from(&self.source_now);
        }
    }

    /// An offer not committed: its temporary file is never written.
    fn forget_pending(&mut self) {
        self.pending = None;
        self.pending_file = None;
    }

    /// Moves the files the committed offers name to `out`: the door writes them before it
    /// sends those offers' bytes.
    pub fn take_files(&mut self, out: &mut Vec<FileWrite>) {
        out.append(&mut self.committed_files);
    }

    /// The door could not write a file (a full or read-only `/dev/shm`): pixels go directly
    /// from now on, and the next picture is sent whole (the terminal did not get the last one).
    pub fn files_failed(&mut self) {
        if let Protocol::Kitty(options) = &mut self.protocol {
            options.medium = Medium::Direct;
        }
        self.invalidate();
    }

    /// Bytes a row of the shown picture at `rung` takes, and bytes a pixel.
    fn stride(&self, rung: usize) -> (usize, usize) {
        match self.protocol {
            Protocol::Sixel { .. } => (self.layout.picture.0 as usize, 1),
            _ => (self.rungs[rung].0 as usize * 3, 3),
        }
    }
}

mod commit;
mod encode;
mod plan;
mod refine;

#[cfg(test)]
mod tests;
