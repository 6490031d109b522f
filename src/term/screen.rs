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
        if big_enough(term) {
            scene.render(pixmap);
        }
        self.detail.clear();
        self.detail.reserve(DETAIL_ROOM);
        scene.status(&mut self.detail);
        let about = About { name: scene.kind().name(), takes_stones: scene.takes_stones(), hints: scene.hints() };
        self.finish(term, pixmap, color, overlay, &about)
    }

    /// The frame for a `term` terminal showing a picture drawn elsewhere: `picture` (the size
    /// [`picture_size`](super::player::picture_size) gives for `term`) with `overlay` and the
    /// status line of `scene`. A server that shares one scene among many viewers renders the
    /// scene once per picture size and calls this for each viewer, so the viewers need no
    /// access to the scene itself.
    pub fn compose(
        &mut self,
        term: (u16, u16),
        picture: &Pixmap,
        color: ColorMode,
        overlay: &Overlay<'_>,
        scene: &SceneInfo,
    ) -> &Frame {
        self.detail.clear();
        self.detail.push_str(&scene.detail);
        let about = About { name: scene.name, takes_stones: scene.takes_stones, hints: scene.hints };
        self.finish(term, picture, color, overlay, &about)
    }

    fn finish(
        &mut self,
        term: (u16, u16),
        pixmap: &Pixmap,
        color: ColorMode,
        overlay: &Overlay<'_>,
        about: &About,
    ) -> &Frame {
        let (cols, rows) = (usize::from(term.0), usize::from(term.1));
        self.frame.reset(cols, rows);
        // Room for the longest texts once (they grow as the figures do: `0 B/s` becomes
        // `1.23 MB/s`), so steady frames never reallocate them.
        self.rate.reserve(RATE_ROOM);
        self.line.reserve(4 * cols);
        if !big_enough(term) {
            ui::too_small(&mut self.frame);
            return &self.frame;
        }
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
        let status = Status {
            scene: about.name,
            fps: overlay.fps,
            rate: &self.rate,
            detail: &self.detail,
            stone: about.takes_stones.then_some(overlay.stone),
            hints: about.hints,
            paused: overlay.paused,
            message: overlay.message,
        };
        ui::status_line(&mut self.frame, rows - 1, &status, color, &mut self.line);
        &self.frame
    }
}

/// What the status line and the help say about a scene, taken from it once so that viewers of
/// a scene shared among many (`tidepool serve`) can draw their frames without touching it.
#[derive(Clone, Debug)]
pub struct SceneInfo {
    /// The scene's name (`pool`).
    pub name: &'static str,
    /// The scene's status summary, plus whatever the caller adds (`3 playing`).
    pub detail: String,
    /// Whether the scene takes stones.
    pub takes_stones: bool,
    /// The status line's key hints, longest first.
    pub hints: &'static [&'static str],
    /// The help overlay's lines: the player's keys and the scene's own.
    pub help: Vec<(&'static str, &'static str)>,
}

impl SceneInfo {
    /// Takes what the status line and the help say about `scene` now.
    pub fn of(scene: &dyn Playable) -> SceneInfo {
        let mut detail = String::new();
        scene.status(&mut detail);
        SceneInfo {
            name: scene.kind().name(),
            detail,
            takes_stones: scene.takes_stones(),
            hints: scene.hints(),
            help: ui::help_lines(&scene.help(), scene.takes_stones()),
        }
    }
}

/// The scene's part of the status line.
struct About {
    name: &'static str,
    takes_stones: bool,
    hints: &'static [&'static str],
}
