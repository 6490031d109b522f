//! The frame the player shows: the scene's picture as half-block cells, with the aim marker,
//! the help overlay and the status line on top. Every buffer is kept from frame to frame, so
//! a steady stream of frames allocates nothing.

use tiny_skia::Pixmap;

use super::ui::{self, MIN_SIZE, Status};
use crate::output::color::ColorMode;
use crate::output::frame::Frame;
use crate::output::units::{write_human_bytes, write_human_rate};
use crate::scene::Playable;

/// What goes over the picture this frame.
#[derive(Clone, Copy, Debug, Default)]
pub struct Overlay<'a> {
    /// The aim marker's pixel, when it is visible.
    pub aim: Option<(u32, u32)>,
    /// The help overlay's lines, when it is open.
    pub help: Option<&'a [(&'static str, &'static str)]>,
    /// A passing message for the status line.
    pub message: Option<&'a str>,
    /// Frames drawn per second.
    pub fps: u32,
    /// Bytes sent per second.
    pub bytes_per_second: u64,
    /// The link's rate in effect, bytes per second (`None`: no limit).
    pub bandwidth: Option<u64>,
    /// The stone radius in pixels (shown when the scene takes stones).
    pub stone: u32,
    /// Whether the simulation is paused.
    pub paused: bool,
    /// The picture goes to the terminal in real pixels (kitty, sixel, iTerm2), not in these
    /// cells: the scene is still rendered, but its rows stay blank cells under it.
    pub pixels_elsewhere: bool,
}

/// Bytes reserved for the formatted byte rate.
const RATE_ROOM: usize = 40;
/// Bytes reserved for the scene's status summary.
const DETAIL_ROOM: usize = 128;

/// Whether a `cols x rows` terminal is big enough for the picture and the status line.
pub fn big_enough((cols, rows): (u16, u16)) -> bool {
    cols >= MIN_SIZE.0 && rows >= MIN_SIZE.1
}

/// Builds frames, reusing its buffers.
#[derive(Debug)]
pub struct FrameBuilder {
    frame: Frame,
    rate: String,
    detail: String,
    line: String,
}

impl Default for FrameBuilder {
    fn default() -> Self {
        FrameBuilder { frame: Frame::new(0, 0), rate: String::new(), detail: String::new(), line: String::new() }
    }
}

impl FrameBuilder {
    /// The frame for a `term` (columns, rows) terminal: `scene` drawn into `pixmap` (which has
    /// the scene's size) and shown as cells, with `overlay` on top.
    pub fn build(
        &mut self,
        term: (u16, u16),
        scene: &mut dyn Playable,
        pixmap: &mut Pixmap,
        color: ColorMode,
        overlay: &Overlay<'_>,
    ) -> &Frame {
        let (cols, rows) = (usize::from(term.0), usize::from(term.1));
        self.frame.reset(cols, rows);
        // Room for the longest texts once (they grow as the figures do: `0 B/s` becomes
        // `1.23 MB/s`), so steady frames never reallocate them.
        self.rate.reserve(RATE_ROOM);
        self.detail.reserve(DETAIL_ROOM);
        self.line.reserve(4 * cols);
        if !big_enough(term) {
            ui::too_small(&mut self.frame);
            return &self.frame;
        }
        scene.render(pixmap);
        if !overlay.pixels_elsewhere {
            self.frame.draw_pixels(pixmap, color);
        }
        if let Some((x, y)) = overlay.aim {
            ui::aim_marker(&mut self.frame, x, y);
        }
        if let Some(lines) = overlay.help {
            ui::help_overlay(&mut self.frame, lines, color);
        }
        write_human_rate(&mut self.rate, overlay.bytes_per_second);
        if let Some(bandwidth) = overlay.bandwidth {
            // The rate in effect: what the link is found (or told) to carry.
            self.rate.push_str(" of ");
            write_human_bytes(&mut self.rate, bandwidth);
            self.rate.push_str("/s");
        }
        scene.status(&mut self.detail);
        let status = Status {
            scene: scene.kind().name(),
            fps: overlay.fps,
            rate: &self.rate,
            detail: &self.detail,
            stone: scene.takes_stones().then_some(overlay.stone),
            hints: scene.hints(),
            paused: overlay.paused,
            message: overlay.message,
        };
        ui::status_line(&mut self.frame, rows - 1, &status, color, &mut self.line);
        &self.frame
    }
}
