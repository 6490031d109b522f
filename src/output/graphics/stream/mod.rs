//! One terminal's pictures under rate control: a [`PictureStream`] is the picture encoder of a
//! pixel mode (kitty, sixel, iTerm2) together with the choices that fit it to a link — the
//! resolution (a [`ladder`] from the cell area's pixel size down to half-block resolution), the
//! packing (kitty: zlib RGB or PNG, whole images or `a=f` frame edits of changed rectangles;
//! sixel: changed cell blocks, colour registers defined once; iTerm2: PNG or JPEG) and the
//! picture rate — so that a picture never costs more than the bytes the caller has now.
//!
//! Pure and clock-injected: no terminal, no clock, no I/O. Time comes in as an argument.
//!
//! # The contract (how the Screen calls it)
//!
//! 1. Make one stream per terminal and mode: [`PictureStream::new`] with the layout
//!    ([`crate::output::graphics::geometry::layout`]) and the protocol's [`Protocol`] settings
//!    from the probe. After a resize make a new one (or [`PictureStream::resize`]).
//! 2. Each frame, after the cells (the status line goes first), ask [`PictureStream::due`]
//!    (`now`); when it is, render the scene (at [`PictureStream::render_size`] when the scene
//!    can change size cheaply; the pool cannot — its grid is its picture — so it keeps its size
//!    and the stream resamples whatever it is given) and call [`PictureStream::prepare`] with
//!    the picture, the [`Budget`] (the bucket's bytes now, its rate, the frame interval) and
//!    `now`. The picture is encoded into the stream's own buffer: nothing is committed yet.
//! 3. `prepare` returns `None` (nothing to send: not due, unchanged, or nothing fits the bytes
//!    available now) or an [`Offer`] whose `bytes` are at most `budget.available`. Put them in
//!    the frame's synchronized update, take them from the bucket (`ByteBucket::spend`, never
//!    `owe`), and call [`PictureStream::commit`] once they are written. Only then does the
//!    stream believe the terminal shows the picture; an offer not committed is forgotten at the
//!    next `prepare`.
//! 4. Text written over the picture (the help overlay over sixel or iTerm2 pixels) or a cleared
//!    screen: [`PictureStream::invalidate`]; the next picture is sent whole.
//! 5. [`PictureStream::state`] says what the stream does (rung, packing, picture rate) for the
//!    status line; [`crossover`] says when `auto` should prefer cells.
//!
//! # Rate control
//!
//! With a rate, each picture may cost the bytes the rate brings in one picture interval,
//! within the bucket's burst (100 ms of the rate: [`crate::output::bucket::MAX_BURST`]), less a
//! share kept for the status line. The stream learns what each rung costs (bytes a pixel, a
//! moving average per rung, the first guess scaled from a neighbour), and picks the highest
//! picture rate (its maximum, then 15, then 10 a second) at which a rung near the top fits;
//! otherwise 10 a second at the largest rung that fits. The encoded picture's real cost is
//! known before it is offered: if it exceeds the bytes available now, the next rung down is
//! tried, and for kitty and sixel, when even the bottom rung is too big, the picture is sent in
//! horizontal strips, oldest first, each an edit of what is shown. Without a rate the stream
//! sends every picture at the rung that holds the source picture (no interpolated pixels), in
//! the packing that costs least CPU.

pub mod crossover;
pub mod ladder;

use std::time::{Duration, Instant};

use tiny_skia::Pixmap;

use self::ladder::Resampler;
use crate::output::bucket::{MAX_BURST, MIN_CAPACITY};
use crate::output::graphics::geometry::Layout;
use crate::output::graphics::kitty::{self, KittyOptions};
use crate::output::graphics::pack::{Packing, pack};
use crate::output::graphics::sixel::{Registers, SixelEncoder, SixelPalette, TMUX_MAX_IMAGE_BYTES};
use crate::output::graphics::{GraphicsMode, iterm2, scan};

/// The share of a picture interval's bytes a picture may take: the rest is left for the status
/// line and the cells' own changes.
pub const PICTURE_SHARE: f64 = 0.85;
/// The picture rates tried below the protocol's maximum, highest first (pictures a second).
pub const RATES: [f64; 2] = [15.0, 10.0];
/// How many rungs below the top useful one still count as "near the top" (see the module
/// documentation).
const NEAR_TOP: usize = 2;
/// A rung above the current one is taken only when it is predicted to fit this share of the
/// allowance (hysteresis: no flapping between two rungs).
const UP_SHARE: f64 = 0.8;
/// The weight of the newest measurement in a rung's cost average.
const LEARN: f64 = 0.3;
/// How per-pixel cost grows as a rung shrinks: bytes a pixel scale as (pixels ratio) ^ this.
const DENSITY_EXPONENT: f64 = 0.2;
/// The soonest the next picture may follow a base image sent for strips.
const FRAME_MIN: Duration = Duration::from_millis(1);
/// Strips a picture is cut into when even the bottom rung is too big.
const MAX_STRIPS: u32 = 16;

/// The protocol and its settings, from the probe.
#[derive(Clone, Debug)]
pub enum Protocol {
    /// kitty graphics: image id, placement, tmux wrapping and placeholders, z-index (the cell
    /// area and origin are taken from the layout). Only direct transmission: temporary files
    /// are for a local terminal, where the stream has no rate to fit.
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
    fn mode(&self) -> GraphicsMode {
        match self {
            Protocol::Kitty(_) => GraphicsMode::Kitty,
            Protocol::Sixel { .. } => GraphicsMode::Sixel,
            Protocol::Iterm2 { .. } => GraphicsMode::Iterm2,
        }
    }

    /// The most pictures a second: kitty and iTerm2 scale in the terminal and keep up with the
    /// player's 30 frames; sixel pictures are drawn pixel for pixel and cost several times more
    /// to encode and to draw, so 15.
    pub fn max_rate(&self) -> f64 {
        match self {
            Protocol::Sixel { .. } => 15.0,
            _ => 30.0,
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
}

impl Budget {
    /// No limit, frames every `frame_interval`.
    pub fn unlimited(frame_interval: Duration) -> Budget {
        Budget { available: usize::MAX, rate: None, frame_interval }
    }
}

/// A picture ready to send.
#[derive(Debug)]
pub struct Offer<'a> {
    /// The bytes, at most the budget's `available`.
    pub bytes: &'a [u8],
    /// What they show.
    pub state: State,
}

/// What the stream is doing, for the status line and the benchmarks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct State {
    /// The picture's size on the wire (the rung), pixels.
    pub size: (u32, u32),
    /// The packing (sixel: `None`).
    pub packing: Option<Packing>,
    /// Pictures a second the stream aims at.
    pub rate: f64,
    /// The part of the picture the last offer carried: the whole, a changed box or a strip.
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
    /// Rows `y0..y1` only (the rest follows in later pictures).
    Strip(u32, u32),
}

/// What is pending until [`PictureStream::commit`].
#[derive(Clone, Copy, Debug)]
struct Pending {
    rung: usize,
    part: Part,
}

/// One terminal's pictures under rate control (see the module documentation).
#[derive(Debug)]
pub struct PictureStream {
    protocol: Protocol,
    layout: Layout,
    rungs: Vec<(u32, u32)>,
    rung: usize,
    /// Learned bytes a pixel of a whole picture, per rung.
    cost: Vec<Option<f64>>,
    /// Pictures a second aimed at, and when the next is due.
    rate: f64,
    next_due: Option<Instant>,
    /// What the terminal shows: the rung and its pixels (RGB at the rung; sixel: registers at
    /// screen size), `None` when unknown.
    shown: Option<(usize, Vec<u8>)>,
    /// The picture being offered (same form as `shown`) and what the offer carries.
    candidate: Vec<u8>,
    pending: Option<Pending>,
    /// The next strip to send when pictures go in strips.
    next_strip: u32,
    /// The last state, for the status line.
    state: State,
    /// Scratch: the offer's bytes, the packed pixels, a box's pixels, the resampled picture.
    bytes: Vec<u8>,
    packed: Vec<u8>,
    part_rgb: Vec<u8>,
    rgb: Vec<u8>,
    resampler: Resampler,
    sixel: Option<Box<SixelEncoder>>,
    /// kitty's placeholder text must be (re)printed after the next whole image.
    placeholders_due: bool,
}

impl PictureStream {
    /// A stream for `protocol` over `layout` (whose `picture` is the top rung). Nothing is
    /// shown yet.
    pub fn new(protocol: Protocol, layout: Layout) -> PictureStream {
        let sixel = match &protocol {
            Protocol::Sixel { palette, registers, tmux } => {
                let mut s = SixelEncoder::new(palette.clone(), layout.origin, Some(layout.cell_px));
                s.set_registers(*registers);
                s.set_max_image_bytes(tmux.then_some(TMUX_MAX_IMAGE_BYTES), *tmux);
                Some(Box::new(s))
            }
            _ => None,
        };
        let rungs = ladder::rungs(layout.picture, (u32::from(layout.cells.0), 2 * u32::from(layout.cells.1)));
        let rate = protocol.max_rate();
        let state = State { size: rungs[0], packing: None, rate, part: Part::Whole };
        PictureStream {
            cost: vec![None; rungs.len()],
            protocol,
            layout,
            rungs,
            rung: 0,
            rate,
            next_due: None,
            shown: None,
            candidate: Vec::new(),
            pending: None,
            next_strip: 0,
            state,
            bytes: Vec::new(),
            packed: Vec::new(),
            part_rgb: Vec::new(),
            rgb: Vec::new(),
            resampler: Resampler::default(),
            sixel,
            placeholders_due: true,
        }
    }

    /// A new layout (a resize): the ladder is rebuilt and the next picture is sent whole.
    pub fn resize(&mut self, layout: Layout) {
        *self = PictureStream::new(self.protocol.clone(), layout);
    }

    /// The layout in force.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The resolution ladder, largest first.
    pub fn rungs(&self) -> &[(u32, u32)] {
        &self.rungs
    }

    /// The size the next picture goes at: a scene that can change size cheaply renders at this
    /// size (anything bigger is resampled down; see the module documentation).
    pub fn render_size(&self) -> (u32, u32) {
        self.rungs[self.rung]
    }

    /// What the stream did last.
    pub fn state(&self) -> State {
        self.state
    }

    /// Forgets what the terminal shows: the next picture is sent whole.
    pub fn invalidate(&mut self) {
        self.shown = None;
        self.pending = None;
        self.next_due = None;
        self.placeholders_due = true;
    }

    /// Whether a picture is due at `now`.
    pub fn due(&self, now: Instant) -> bool {
        self.next_due.is_none_or(|t| now >= t)
    }

    /// The picture `picture` encoded for the terminal within `budget`, or `None` (see the
    /// module documentation). Nothing is believed shown until [`PictureStream::commit`].
    pub fn prepare(&mut self, picture: &Pixmap, budget: Budget, now: Instant) -> Option<Offer<'_>> {
        self.pending = None;
        if !self.due(now) {
            return None;
        }
        let source = (picture.width(), picture.height());
        let top = ladder::top_useful(&self.rungs, source);
        let allowance = self.plan(top, budget);
        // Due half a frame early, so that a picture interval of three frames is three frames
        // and not four when the clock's ticks fall a nanosecond short.
        let interval = Duration::from_secs_f64(1.0 / self.rate).max(budget.frame_interval) - budget.frame_interval / 2;
        // Above its share the rung is too expensive: the next one down is tried.
        let limit = allowance;
        let mut rung = self.rung;
        loop {
            // Unchanged: nothing to send, and nothing owed.
            let Some(part) = self.encode(picture, rung, budget.rate.is_some()) else {
                self.next_due = Some(now + interval);
                return None;
            };
            self.learn(rung, part);
            if self.bytes.len() <= limit {
                // Within its share: sent when the bucket holds it, else the next frame retries.
                return self.offer(rung, part, budget, now + interval);
            }
            if rung + 1 < self.rungs.len() {
                rung += 1;
                continue;
            }
            // Even the bottom rung is too big: a strip of it, where the protocol edits.
            let strips_possible = match self.protocol {
                Protocol::Iterm2 { .. } => false,
                Protocol::Sixel { .. } => self.shown.is_some(),
                Protocol::Kitty(_) => self.shown.as_ref().is_some_and(|(r, _)| *r == rung),
            };
            if !strips_possible {
                if self.bytes.len() <= budget.available {
                    return self.offer(rung, part, budget, now + interval);
                }
                match self.protocol {
                    // No partial update: it waits for a bucket that holds it.
                    Protocol::Iterm2 { .. } => return None,
                    // Nothing known shown: every strip differs from "unknown".
                    Protocol::Sixel { .. } => self.shown = Some((rung, vec![u8::MAX; self.candidate.len()])),
                    // An image of the picture's mean colour first (a few bytes), which the
                    // strips then edit.
                    Protocol::Kitty(_) => {
                        self.flatten_candidate();
                        self.bytes.clear();
                        self.push_part(Part::Whole, rung, Packing::Zlib(6));
                        return self.offer(rung, Part::Whole, budget, now + FRAME_MIN);
                    }
                }
            }
            let part = self.encode_strip(rung, allowance.min(budget.available), budget.rate.is_some())?;
            return self.offer(rung, part, budget, now + interval);
        }
    }

    /// Fills the candidate with its mean colour.
    fn flatten_candidate(&mut self) {
        let n = (self.candidate.len() / 3).max(1) as u64;
        let mut sum = [0u64; 3];
        for p in self.candidate.chunks_exact(3) {
            (0..3).for_each(|c| sum[c] += u64::from(p[c]));
        }
        let mean = sum.map(|s| (s / n) as u8);
        for p in self.candidate.chunks_exact_mut(3) {
            p.copy_from_slice(&mean);
        }
    }

    /// Offers `self.bytes` when they fit what is available now.
    fn offer(&mut self, rung: usize, part: Part, budget: Budget, next: Instant) -> Option<Offer<'_>> {
        if self.bytes.len() > budget.available {
            return None;
        }
        self.pending = Some(Pending { rung, part });
        self.state =
            State { size: self.rungs[rung], packing: self.packing(budget.rate.is_some()), rate: self.rate, part };
        self.next_due = Some(next);
        Some(Offer { bytes: &self.bytes, state: self.state })
    }

    /// The offer was written: the terminal shows it from now on.
    pub fn commit(&mut self) {
        let Some(Pending { rung, part }) = self.pending.take() else { return };
        let row = self.row_bytes(rung);
        let sixel = matches!(self.protocol, Protocol::Sixel { .. });
        match (part, &mut self.shown) {
            (Part::Strip(y0, y1), Some((r, shown))) if *r == rung || sixel => {
                *r = rung;
                let (a, b) = (y0 as usize * row, y1 as usize * row);
                shown[a..b].copy_from_slice(&self.candidate[a..b]);
            }
            (_, shown) => {
                let old = shown.take().map(|(_, v)| v).unwrap_or_default();
                *shown = Some((rung, std::mem::replace(&mut self.candidate, old)));
                if matches!(self.protocol, Protocol::Kitty(_)) && part == Part::Whole {
                    self.placeholders_due = false;
                }
            }
        }
        self.rung = rung;
    }

    /// Bytes a row of the shown picture at `rung` takes.
    fn row_bytes(&self, rung: usize) -> usize {
        match self.protocol {
            Protocol::Sixel { .. } => self.layout.picture.0 as usize,
            _ => self.rungs[rung].0 as usize * 3,
        }
    }

    fn packing(&self, limited: bool) -> Option<Packing> {
        match self.protocol {
            Protocol::Kitty(_) if limited => Some(Packing::Png),
            Protocol::Kitty(_) => Some(Packing::Zlib(1)),
            Protocol::Iterm2 { .. } if limited => Some(Packing::Jpeg(self.jpeg_quality())),
            Protocol::Iterm2 { .. } => Some(Packing::Png),
            Protocol::Sixel { .. } => None,
        }
    }

    /// iTerm2's JPEG quality: lower on the lower rungs, where each pixel is bigger on screen
    /// and the rung was chosen because bytes are short.
    fn jpeg_quality(&self) -> u8 {
        let from_bottom = self.rungs.len() - 1 - self.rung;
        [50, 65, 75, 80].get(from_bottom).copied().unwrap_or(85)
    }

    /// Chooses the picture rate and the rung for `budget` (the top useful rung being `top`) and
    /// returns the bytes one picture may take.
    fn plan(&mut self, top: usize, budget: Budget) -> usize {
        let Some(rate) = budget.rate else {
            self.rate = self.protocol.max_rate().min(1.0 / budget.frame_interval.as_secs_f64().max(1e-3));
            self.rung = top;
            return usize::MAX;
        };
        let burst = (rate * MAX_BURST.as_secs_f64()).max(MIN_CAPACITY);
        let most = self.protocol.max_rate().min(1.0 / budget.frame_interval.as_secs_f64().max(1e-3));
        let allowance = |fps: f64| (rate / fps).min(burst) * PICTURE_SHARE;
        let mut choice = None;
        for fps in std::iter::once(most).chain(RATES.into_iter().filter(|&r| r < most)) {
            let fit = self.largest_fitting(top, allowance(fps));
            if fit.is_some_and(|r| r <= top + NEAR_TOP) || fps <= RATES[RATES.len() - 1] {
                choice = Some((fps, fit.unwrap_or(self.rungs.len() - 1)));
                break;
            }
        }
        let (fps, mut rung) = choice.unwrap_or((most, self.rungs.len() - 1));
        // Hysteresis: a bigger rung only when it fits with room to spare.
        if rung < self.rung && self.predict(rung).is_some_and(|c| c > UP_SHARE * allowance(fps)) {
            rung = self.rung.min(self.rungs.len() - 1);
        }
        self.rate = fps;
        self.rung = rung.max(top);
        allowance(fps) as usize
    }

    /// The largest rung at or below `top` whose predicted cost fits `allowance`.
    fn largest_fitting(&self, top: usize, allowance: f64) -> Option<usize> {
        (top..self.rungs.len()).find(|&r| self.predict(r).is_none_or(|c| c <= allowance))
    }

    /// A whole picture's predicted bytes at `rung`: learned, or scaled from the nearest rung
    /// learned; `None` when nothing is known yet (the first picture tries the top).
    fn predict(&self, rung: usize) -> Option<f64> {
        let pixels = |r: usize| f64::from(self.rungs[r].0) * f64::from(self.rungs[r].1);
        let (known, bpp) =
            (0..self.rungs.len()).filter_map(|r| self.cost[r].map(|c| (r, c))).min_by_key(|(r, _)| r.abs_diff(rung))?;
        Some(bpp * (pixels(known) / pixels(rung)).powf(DENSITY_EXPONENT) * pixels(rung))
    }

    fn learn(&mut self, rung: usize, part: Part) {
        if part != Part::Whole {
            return;
        }
        let (w, h) = self.rungs[rung];
        let bpp = self.bytes.len() as f64 / (f64::from(w) * f64::from(h));
        let c = &mut self.cost[rung];
        *c = Some(c.map_or(bpp, |old| old + LEARN * (bpp - old)));
    }

    /// Encodes `picture` at `rung` into `self.bytes` (whole, or the changed box when that is
    /// cheaper) and its pixels into `self.candidate`; `None` when the terminal shows it already.
    fn encode(&mut self, picture: &Pixmap, rung: usize, limited: bool) -> Option<Part> {
        let size = self.rungs[rung];
        let from = (picture.width(), picture.height());
        self.bytes.clear();
        if let Protocol::Sixel { .. } = self.protocol {
            let screen = self.layout.picture;
            let sixel = self.sixel.as_mut().expect("a sixel stream has its encoder");
            // Dithered straight from the pixmap (opaque: its bytes are straight RGB) when the
            // rung is the picture's size; otherwise resampled to the rung first.
            if size == from {
                sixel.dither_scaled(picture.data(), 4, from, screen, &mut self.candidate);
            } else {
                self.resampler.resample(picture.data(), 4, from, size, &mut self.rgb);
                sixel.dither_scaled(&self.rgb, 3, size, screen, &mut self.candidate);
            }
            let part = match &self.shown {
                Some((_, old)) => sixel_part(old, &self.candidate, screen, self.layout.cell_px)?,
                None => Part::Whole,
            };
            let (x, y, w, h) = part_box(part, screen);
            sixel.push_block(
                &mut self.bytes,
                &self.candidate,
                screen.0,
                (x, y, w, h),
                self.layout.origin,
                self.layout.cell_px,
            );
            return Some(part);
        }
        self.resampler.resample(picture.data(), 4, from, size, &mut self.candidate);
        let part = match &self.shown {
            Some((r, old)) if *r == rung => match scan::changed_box(old, &self.candidate, size.0, 3, 0..size.1) {
                None => return None,
                Some(b) if matches!(self.protocol, Protocol::Kitty(_)) && 2 * b.2 * b.3 <= size.0 * size.1 => {
                    Part::Changed(b.0, b.1, b.2, b.3)
                }
                Some(_) => Part::Whole,
            },
            _ => Part::Whole,
        };
        let packing = self.packing(limited).expect("kitty and iTerm2 pack");
        self.push_part(part, rung, packing);
        Some(part)
    }

    /// Encodes the next strip of the bottom rung that fits `available` bytes (kitty and sixel,
    /// whose edits replace part of what is shown); `None` when none does or nothing changed.
    fn encode_strip(&mut self, rung: usize, available: usize, limited: bool) -> Option<Part> {
        let height = match self.protocol {
            Protocol::Sixel { .. } => self.layout.picture.1,
            _ => self.rungs[rung].1,
        };
        // Strips of whole sixel bands that start on text rows (lcm of 6 and the cell height).
        let unit = match self.protocol {
            Protocol::Sixel { .. } => lcm(6, u32::from(self.layout.cell_px.1.max(1))),
            _ => 1,
        };
        let whole = self.bytes.len().max(1);
        let strips = (whole.div_ceil(available.max(1)) as u32 + 1).clamp(2, MAX_STRIPS);
        let strip_h = height.div_ceil(strips).div_ceil(unit) * unit;
        let count = height.div_ceil(strip_h);
        for k in 0..count {
            let s = (self.next_strip + k) % count;
            let (y0, y1) = (s * strip_h, ((s + 1) * strip_h).min(height));
            let (_, shown) = self.shown.as_ref()?;
            let row = self.row_bytes(rung);
            if shown[y0 as usize * row..y1 as usize * row] == self.candidate[y0 as usize * row..y1 as usize * row] {
                continue;
            }
            let part = Part::Strip(y0, y1);
            self.bytes.clear();
            if let Some(sixel) = self.sixel.as_mut() {
                let screen = self.layout.picture;
                // Sixel strips must end on a band; the last one may be shorter.
                sixel.push_block(
                    &mut self.bytes,
                    &self.candidate,
                    screen.0,
                    (0, y0, screen.0, y1 - y0),
                    self.layout.origin,
                    self.layout.cell_px,
                );
            } else {
                let packing = self.packing(limited).expect("kitty packs");
                self.push_part(part, rung, packing);
            }
            if self.bytes.len() <= available {
                self.next_strip = (s + 1) % count;
                return Some(part);
            }
        }
        None
    }

    /// Appends the command(s) for `part` of the candidate at `rung` (kitty and iTerm2).
    fn push_part(&mut self, part: Part, rung: usize, packing: Packing) {
        let size = self.rungs[rung];
        let (x, y, w, h) = part_box(part, size);
        let pixels: &[u8] = if (w, h) == size {
            &self.candidate
        } else {
            self.part_rgb.clear();
            for row in y..y + h {
                let from = (row as usize * size.0 as usize + x as usize) * 3;
                self.part_rgb.extend_from_slice(&self.candidate[from..from + w as usize * 3]);
            }
            &self.part_rgb
        };
        pack(packing, pixels, w, h, &mut self.packed);
        match &self.protocol {
            Protocol::Kitty(options) => {
                let o = KittyOptions { origin: self.layout.origin, cells: self.layout.cells, ..options.clone() };
                let mut keys = Vec::with_capacity(96);
                if part == Part::Whole {
                    kitty::image_keys(&mut keys, &o, size);
                    if !o.placeholders {
                        kitty::push_cursor_to(&mut self.bytes, o.origin);
                    }
                    kitty::push_chunks(&mut self.bytes, &keys, b"", packing, &self.packed, o.tmux);
                    if o.placeholders && self.placeholders_due {
                        kitty::push_placeholders(
                            &mut self.bytes,
                            o.image_id,
                            o.origin.0,
                            o.origin.1,
                            o.cells.0,
                            o.cells.1,
                        );
                    }
                } else {
                    kitty::edit_keys(&mut keys, o.image_id, (x, y, w, h));
                    kitty::push_chunks(&mut self.bytes, &keys, b"a=f,", packing, &self.packed, o.tmux);
                }
            }
            Protocol::Iterm2 { tmux } => {
                iterm2::push_file(&mut self.bytes, self.layout.origin, self.layout.cells, *tmux, &self.packed)
            }
            Protocol::Sixel { .. } => unreachable!("sixel is encoded by its encoder"),
        }
    }

    /// The protocol's mode.
    pub fn mode(&self) -> GraphicsMode {
        self.protocol.mode()
    }
}

/// The box a part covers in a picture of `size`.
fn part_box(part: Part, size: (u32, u32)) -> (u32, u32, u32, u32) {
    match part {
        Part::Whole => (0, 0, size.0, size.1),
        Part::Changed(x, y, w, h) => (x, y, w, h),
        Part::Strip(y0, y1) => (0, y0, size.0, y1 - y0),
    }
}

/// The part of a sixel picture to send: the block of whole cells (and whole bands) around the
/// changes, the whole picture when that block reaches its bottom; `None` when nothing changed.
fn sixel_part(old: &[u8], new: &[u8], screen: (u32, u32), cell_px: (u16, u16)) -> Option<Part> {
    let (cw, ch) = (u32::from(cell_px.0.max(1)), u32::from(cell_px.1.max(1)));
    let (left, top, bw, bh) = scan::changed_box(old, new, screen.0, 1, 0..screen.1)?;
    let (x0, y0) = (left / cw * cw, top / ch * ch);
    let x1 = ((left + bw).div_ceil(cw) * cw).min(screen.0);
    let h = ((top + bh).div_ceil(ch) * ch).min(screen.1).saturating_sub(y0).div_ceil(6) * 6;
    if y0 + h > screen.1 || (x0, y0, x1 - x0, h) == (0, 0, screen.0, screen.1) {
        return Some(Part::Whole);
    }
    Some(Part::Changed(x0, y0, x1 - x0, h))
}

fn lcm(a: u32, b: u32) -> u32 {
    let gcd = |mut a: u32, mut b: u32| {
        while b != 0 {
            (a, b) = (b, a % b);
        }
        a
    };
    a / gcd(a, b) * b
}

#[cfg(test)]
mod tests;
