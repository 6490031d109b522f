//! The cell frame a screen shows: the picture as half-block cells (or blank cells under real
//! pixels), with the aim marker, the help overlay and the status line on top. Every buffer is
//! kept from frame to frame, so a steady stream of frames allocates nothing.

use tiny_skia::Pixmap;

use super::ui::{self, MIN_SIZE, Status};
use crate::output::color::ColorMode;
use crate::output::frame::Frame;
use crate::output::graphics::stream::ladder::Resampler;
use crate::output::units::{write_human_bytes, write_human_rate};
use crate::play::host::SceneStatus;
use crate::play::seat::SeatView;

/// What the screen itself adds to the status line.
#[derive(Clone, Copy, Debug, Default)]
pub struct Figures {
    /// Frames drawn per second.
    pub fps: u32,
    /// Bytes sent per second.
    pub bytes_per_second: u64,
    /// The link's rate in effect, bytes per second (`None`: no limit).
    pub bandwidth: Option<u64>,
    /// The picture goes to the terminal in real pixels (kitty, sixel, iTerm2), not in these
    /// cells: the picture's rows stay blank cells under it.
    pub pixels_elsewhere: bool,
    /// A standing note of the screen's (how to set the link's rate where it cannot be
    /// measured), shown when the seat has no message.
    pub note: Option<&'static str>,
}

/// Bytes reserved for the formatted byte rate.
const RATE_ROOM: usize = 40;

/// Whether a `cols x rows` terminal is big enough for the picture and the status line.
pub fn big_enough((cols, rows): (u16, u16)) -> bool {
    cols >= MIN_SIZE.0 && rows >= MIN_SIZE.1
}

/// The half-block picture of a `cols x rows` terminal, in pixels: a pixel a column, two a row,
/// above the status line (at least 3x3, so a scene always has an inside). Screens and groups
/// both size their pictures by it, so a group's frame is a member's.
pub fn half_block_picture((cols, rows): (u16, u16)) -> (u32, u32) {
    let (width, height) = crate::output::halfblock::picture_size(cols, rows.saturating_sub(1));
    (width.max(3), height.max(3))
}

/// The scene's picture at the cells' size, for the frames whose picture is another size.
///
/// The picture a frame brings was drawn for the screen's mode when the frame began: the frame
/// in which `auto` leaves pixels for cells (and the first after a resize) brings one of the
/// old size, and the cells, a pixel a column, would take its top-left corner (`tidepool serve`
/// in xterm showed the pool magnified four times for a frame when it left sixel). Such a
/// picture is resampled to the cells' size; one of their size is used as it is, so steady
/// frames copy nothing.
#[derive(Debug, Default)]
pub struct CellsPicture {
    resampler: Resampler,
    rgb: Vec<u8>,
    fitted: Option<Pixmap>,
}

impl CellsPicture {
    /// `picture` at `size` (the cells' [`half_block_picture`]).
    pub fn fit<'a>(&'a mut self, picture: &'a Pixmap, size: (u32, u32)) -> &'a Pixmap {
        let from = (picture.width(), picture.height());
        if from == size {
            return picture;
        }
        self.resampler.resample(picture.data(), 4, from, size, &mut self.rgb);
        let fitted = match self.fitted.take() {
            Some(p) if (p.width(), p.height()) == size => p,
            _ => Pixmap::new(size.0, size.1).expect("the cells' picture is at least 3x3"),
        };
        let fitted = self.fitted.insert(fitted);
        // The scenes' pictures are opaque: premultiplied RGB is RGB.
        for (px, rgb) in fitted.data_mut().chunks_exact_mut(4).zip(self.rgb.chunks_exact(3)) {
            px.copy_from_slice(&[rgb[0], rgb[1], rgb[2], 255]);
        }
        fitted
    }
}

/// Builds frames, reusing its buffers.
#[derive(Debug)]
pub struct FrameBuilder {
    frame: Frame,
    rate: String,
    line: String,
}

impl Default for FrameBuilder {
    fn default() -> Self {
        FrameBuilder { frame: Frame::new(0, 0), rate: String::new(), line: String::new() }
    }
}

impl FrameBuilder {
    /// The frame composed last, to change before it is encoded (a switch keeps cells).
    pub fn last_mut(&mut self) -> &mut Frame {
        &mut self.frame
    }

    /// The frame composed last.
    pub fn last(&self) -> &Frame {
        &self.frame
    }

    /// The frame for a `term` (columns, rows) terminal: `picture` (the cells' pixel size: one
    /// pixel a column, two a row, above the status line) with the seat's marker, help and
    /// message, and the status line of `status` with the screen's `figures`.
    pub fn compose(
        &mut self,
        term: (u16, u16),
        picture: &Pixmap,
        color: ColorMode,
        status: &SceneStatus,
        seat: &SeatView<'_>,
        figures: &Figures,
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
        if !figures.pixels_elsewhere {
            self.frame.draw_pixels(picture, color);
        }
        if let Some((col, row)) = seat.aim {
            ui::aim_marker(&mut self.frame, usize::from(col), usize::from(row));
        }
        if let Some(lines) = seat.help {
            ui::help_overlay(&mut self.frame, lines, color);
        }
        write_human_rate(&mut self.rate, figures.bytes_per_second);
        if let Some(bandwidth) = figures.bandwidth {
            // The rate in effect: what the link is found (or told) to carry.
            self.rate.push_str(" of ");
            write_human_bytes(&mut self.rate, bandwidth);
            self.rate.push_str("/s");
        }
        let line = Status {
            scene: status.name,
            fps: figures.fps,
            rate: &self.rate,
            detail: &status.detail,
            stone: status.takes_stones.then_some(seat.stone),
            hints: status.hints,
            paused: status.paused,
            message: seat.message.or(figures.note),
        };
        ui::status_line(&mut self.frame, rows - 1, &line, color, &mut self.line);
        &self.frame
    }
}
