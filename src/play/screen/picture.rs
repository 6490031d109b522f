//! The player's picture in real pixels (kitty graphics, sixel, iTerm2), beside the cell frame
//! that still carries the status line.
//!
//! The player keeps its cell frame for every mode: in `cells` mode it holds the half-block
//! picture; in a pixel mode its picture rows stay blank cells (which, once sent, cost nothing)
//! and this module sends the picture itself over them through a
//! [`PictureStream`]: the protocol's encoder under the link's rate (the resolution, the packing
//! and the picture rate chosen per frame; only what changed is sent, so still water sends no
//! bytes). The layout says where the picture goes (mouse reports map to scene pixels through
//! the seat's [`crate::play::fit::Fit`]).

use std::path::PathBuf;
use std::time::Instant;

use tiny_skia::Pixmap;

use super::link::START_RATE;
use super::probe::{GraphicsChoice, GraphicsSupport};
use crate::output::diff::{SYNC_BEGIN, SYNC_END};
use crate::output::graphics::GraphicsMode;
use crate::output::graphics::geometry::{self, Layout};
use crate::output::graphics::kitty::{self, KittyOptions, Medium};
use crate::output::graphics::sixel::{Registers, SixelPalette};
use crate::output::graphics::stream::crossover::{AutoSwitch, crossover};
use crate::output::graphics::stream::{Budget, FileWrite, PictureStream, Protocol};
use crate::output::rate::budget_after;
use crate::output::units::write_human_rate;

/// The largest picture a scene renders at in a pixel mode, in pixels. The pool's simulation
/// grid is its picture, and its breeze costs about 33 ns a cell a step (`tidepool render pool
/// --breeze 1 --stats`): at the full 1280x752 of a 160x48 window, 60 steps a second would need
/// two cores. Within this size the pool (simulation, picture, encoding) stays near half a core
/// (`scripts/pixel_cpu.py`); kitty and iTerm2 scale the picture up to the cell area
/// themselves, the sixel stream repeats its pixels.
pub const SCENE_CAP: (u32, u32) = (480, 300);

/// The kitty image's stacking order: under text glyphs, so the help overlay and the aim marker
/// (text cells over the picture) stay readable.
pub const KITTY_Z_INDEX: i32 = -1;

/// The picture of a pixel mode: its stream.
#[derive(Debug)]
pub struct Picture {
    choice: GraphicsChoice,
    support: GraphicsSupport,
    /// Where the door writes kitty's temporary files (`None`: it writes none).
    files_dir: Option<PathBuf>,
    stream: PictureStream,
    /// The size the scene renders at: the layout's picture within [`SCENE_CAP`].
    scene: (u32, u32),
    /// The help was open at the last frame (its text erases sixel and iTerm2 pixels, so the
    /// picture is sent whole when it closes).
    help_was_open: bool,
}

impl Picture {
    /// The picture for `choice` in a terminal of `term` cells, or `None` for `cells` mode (the
    /// cell frame is the picture then). `files_dir`: where the door writes kitty's temporary
    /// files, when the terminal reads them.
    pub fn new(
        choice: &GraphicsChoice,
        support: &GraphicsSupport,
        term: (u16, u16),
        files_dir: Option<PathBuf>,
    ) -> Option<Picture> {
        if choice.mode == GraphicsMode::Cells {
            return None;
        }
        let layout = layout_for(choice.mode, support, term);
        Some(Picture {
            stream: PictureStream::new(protocol(choice, support, &layout, files_dir.as_deref()), layout),
            files_dir,
            scene: fit(layout.picture, SCENE_CAP),
            choice: choice.clone(),
            support: support.clone(),
            help_was_open: false,
        })
    }

    /// Where the picture goes and its size in pixels.
    pub fn layout(&self) -> &Layout {
        self.stream.layout()
    }

    /// The size the scene renders at (the picture within [`SCENE_CAP`]).
    pub fn scene_size(&self) -> (u32, u32) {
        self.scene
    }

    /// What the stream did last (the rung, packing and picture rate).
    #[cfg(test)]
    pub fn state(&self) -> crate::output::graphics::stream::State {
        self.stream.state()
    }

    /// A new terminal size: a new layout, and the next picture is sent whole (the caller clears
    /// the screen in the same frame).
    pub fn resize(&mut self, term: (u16, u16)) {
        let layout = layout_for(self.choice.mode, &self.support, term);
        let protocol = protocol(&self.choice, &self.support, &layout, self.files_dir.as_deref());
        self.stream = PictureStream::new(protocol, layout);
        self.scene = fit(layout.picture, SCENE_CAP);
    }

    /// Moves the temporary files the sent pictures name to `out` (the door writes them first).
    pub fn take_files(&mut self, out: &mut Vec<FileWrite>) {
        self.stream.take_files(out);
    }

    /// The door could not write a temporary file: pixels go directly from now on.
    pub fn files_failed(&mut self) {
        self.files_dir = None;
        self.stream.files_failed();
    }

    /// Whether text written over the picture erases its pixels (sixel, iTerm2), so the picture
    /// must be resent after the text goes; kitty draws its image under text and keeps it.
    fn text_erases_pixels(&self) -> bool {
        self.choice.mode != GraphicsMode::Kitty
    }

    /// Whether drawing the picture replaces the cells it covers (sixel and iTerm2 pixels,
    /// kitty's placeholder cells); a kitty placement lies under them instead.
    pub fn replaces_cells(&self) -> bool {
        self.text_erases_pixels() || self.choice.kitty_placeholders
    }
}

/// What the player's frame is like, for [`Picture::add_to_frame`].
#[derive(Clone, Copy, Debug)]
pub struct FrameFacts {
    /// The cell frame repaints the whole screen (the first frame, a resize).
    pub resized: bool,
    /// The help overlay is open.
    pub help_open: bool,
    /// Every cell (the status line) is shown as wanted after this frame's cells.
    pub cells_shown: bool,
    /// The terminal is big enough for the picture.
    pub drawable: bool,
    /// Frames are wrapped in synchronized output.
    pub sync: bool,
}

impl Picture {
    /// Adds the picture to the frame's `bytes` (inside its synchronized update) when one is
    /// due and fits `budget` (the bytes left after the cells), and returns the bytes added (0:
    /// none; then the terminal's cursor is where the cells left it).
    ///
    /// The status line goes first: a picture is sent only once the cells are all shown. The
    /// stream chooses the picture's resolution, packing and rate so that it fits what the link
    /// has now, or sends nothing (see [`PictureStream`]); nothing is owed and nothing queues.
    /// Sixel and iTerm2 would paint over the help, so the picture waits while it is open.
    pub fn add_to_frame(
        &mut self,
        pixmap: &Pixmap,
        frame: &FrameFacts,
        budget: Budget,
        now: Instant,
        bytes: &mut Vec<u8>,
    ) -> usize {
        let erases = self.text_erases_pixels();
        if frame.resized || (self.help_was_open && !frame.help_open && erases) {
            self.stream.invalidate();
        }
        self.help_was_open = frame.help_open;
        if (frame.help_open && erases) || !frame.cells_shown || !frame.drawable {
            return 0;
        }
        // The synchronized-output markers a frame without cells needs come out of the budget.
        let markers = if frame.sync && !bytes.ends_with(SYNC_END) { SYNC_BEGIN.len() + SYNC_END.len() } else { 0 };
        let budget = Budget { available: budget_after(budget.available, markers), ..budget };
        let Some(offer) = self.stream.prepare(pixmap, budget, now) else { return 0 };
        let before = bytes.len();
        splice_picture(bytes, offer.bytes, frame.sync);
        self.stream.commit();
        bytes.len() - before
    }
}

/// Puts a picture's bytes into the frame's synchronized update (before its end marker), so the
/// picture and the status line change together; a frame without markers gets them. (A
/// switch's delete of the old picture goes the same way.)
pub(super) fn splice_picture(frame: &mut Vec<u8>, picture: &[u8], sync: bool) {
    if !sync {
        frame.extend_from_slice(picture);
    } else if frame.ends_with(SYNC_END) {
        frame.truncate(frame.len() - SYNC_END.len());
        frame.extend_from_slice(picture);
        frame.extend_from_slice(SYNC_END);
    } else {
        frame.splice(0..0, SYNC_BEGIN.iter().copied());
        frame.extend_from_slice(picture);
        frame.extend_from_slice(SYNC_END);
    }
}

/// `size` shrunk (aspect kept) to fit within `cap`, at least 1x1.
fn fit(size: (u32, u32), cap: (u32, u32)) -> (u32, u32) {
    let k = (f64::from(cap.0) / f64::from(size.0.max(1))).min(f64::from(cap.1) / f64::from(size.1.max(1))).min(1.0);
    (((f64::from(size.0) * k).round() as u32).max(1), ((f64::from(size.1) * k).round() as u32).max(1))
}

/// What the status line says when `auto` switches to `to` (cells, or back to `pixels`) at the
/// link's `rate` (`None`: unlimited), which crossed `pixels`' crossover: which mode draws and
/// why.
pub fn switch_notice(pixels: GraphicsMode, to: GraphicsMode, rate: Option<f64>) -> String {
    let mut link = String::new();
    match rate {
        Some(r) => write_human_rate(&mut link, r as u64),
        None => link.push_str("no limit"),
    }
    let mut at = String::new();
    if let Some(c) = crossover(pixels) {
        write_human_rate(&mut at, c as u64);
    }
    match to {
        GraphicsMode::Cells if at.is_empty() => format!("{} over a link: half-block cells are truer", pixels.name()),
        // Cells at no limit: the start on a link still to be measured, below the crossover.
        GraphicsMode::Cells if rate.is_none() => {
            format!("{} over a link: half-block cells are truer below {at}", pixels.name())
        }
        GraphicsMode::Cells => format!("link {link}: half-block cells (truer than {} below {at})", pixels.name()),
        _ => format!("link {link}: pixels again"),
    }
}

/// `auto`'s switch between `choice`'s pixels and cells at the link's rate (`known`: a fixed
/// `--bandwidth`; `measured`: the rate will be measured, no `--bandwidth` was given). A kitty that reads the pictures from temporary files is on this machine and
/// its pictures do not cross the link: it keeps them whatever the rate is measured at (see
/// [`AutoSwitch::local`]).
///
/// A link still to be measured starts in the truer mode at the rate its measure starts from
/// ([`START_RATE`]): kitty and iTerm2 (crossovers below it) with pixels, sixel (its crossover is
/// tens of MB/s) with cells, and the switch moves to pixels once the link is measured past the
/// crossover; pictures started there would only show for the seconds before the switch.
pub fn auto_switch(
    choice: &GraphicsChoice,
    support: &GraphicsSupport,
    known: Option<f64>,
    measured: bool,
) -> AutoSwitch {
    if choice.mode == GraphicsMode::Kitty && support.kitty_temp_file && !choice.tmux_wrap {
        AutoSwitch::local(choice.mode)
    } else if measured {
        AutoSwitch::new(choice.mode, Some(START_RATE))
    } else {
        AutoSwitch::new(choice.mode, known)
    }
}

/// Whether mouse reports come in pixels: SGR-pixels mode (1016) is turned on when the terminal
/// has it (the probe never says so inside tmux) and the picture is in real pixels, where a
/// cell holds many picture pixels. In cells mode a cell is the picture's resolution anyway.
pub fn pixel_mouse(choice: &GraphicsChoice, support: &GraphicsSupport) -> bool {
    choice.mode != GraphicsMode::Cells && support.sgr_pixels_mouse && !support.tmux
}

/// Turns on SGR-pixels mouse reports (after the player's mouse modes, which include 1006).
pub const PIXEL_MOUSE_ON: &[u8] = b"\x1b[?1016h";
/// Turns them off again.
pub const PIXEL_MOUSE_OFF: &[u8] = b"\x1b[?1016l";

/// The bytes that take the picture away for good on exit, written before the terminal's usual
/// restore on every path: kitty's image and its data are deleted (leaving the alternate screen
/// drops sixel and iTerm2 pixels by itself), and pixel mouse reports are turned off.
pub fn restore_bytes(choice: &GraphicsChoice, pixel_mouse: bool) -> Vec<u8> {
    let mut out = Vec::new();
    if choice.mode == GraphicsMode::Kitty {
        kitty::push_delete(&mut out, kitty::IMAGE_ID, choice.tmux_wrap);
    }
    if pixel_mouse {
        out.extend_from_slice(PIXEL_MOUSE_OFF);
    }
    out
}

fn layout_for(mode: GraphicsMode, support: &GraphicsSupport, term: (u16, u16)) -> Layout {
    let sixel_max = support.sixel.and_then(|s| Some((s.max_w?, s.max_h?)));
    geometry::layout(mode, term, support.cell_px, sixel_max, geometry::SCALED_CAP)
}

/// The stream's protocol settings for `choice` from what the probe found: kitty with the frame
/// edits and the temporary-file medium the terminal answered for, sixel with a palette for its
/// registers (each image defines the registers it uses: that works in every terminal),
/// iTerm2; each wrapped for tmux when the choice says so.
fn protocol(
    choice: &GraphicsChoice,
    support: &GraphicsSupport,
    layout: &Layout,
    files_dir: Option<&std::path::Path>,
) -> Protocol {
    match choice.mode {
        GraphicsMode::Kitty => Protocol::Kitty(KittyOptions {
            origin: layout.origin,
            tmux: choice.tmux_wrap,
            placeholders: choice.kitty_placeholders,
            frame_edits: support.kitty_frame_edits,
            medium: match files_dir {
                Some(dir) if support.kitty_temp_file => Medium::TempFile(dir.to_path_buf()),
                _ => Medium::Direct,
            },
            z_index: KITTY_Z_INDEX,
            ..KittyOptions::new(layout.cells)
        }),
        GraphicsMode::Sixel => Protocol::Sixel {
            palette: SixelPalette::for_registers(support.sixel_registers()),
            registers: Registers::PerImage,
            tmux: choice.tmux_wrap,
        },
        GraphicsMode::Iterm2 | GraphicsMode::Cells => Protocol::Iterm2 { tmux: choice.tmux_wrap },
    }
}

#[cfg(test)]
mod tests;
