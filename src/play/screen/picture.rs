//! The player's picture in real pixels (kitty graphics, sixel, iTerm2), beside the cell frame
//! that still carries the status line.
//!
//! The player keeps its cell frame for every mode: in `cells` mode it holds the half-block
//! picture (today's output, unchanged); in a pixel mode its picture rows stay blank cells
//! (which, once sent, cost nothing) and this module sends the picture itself over them, at the
//! size [`geometry::layout`] gives for the protocol and the terminal's cell size. It owns the
//! encoder of the protocol chosen (each remembers what the terminal shows, so still water sends
//! no bytes) and the layout (mouse reports map to scene pixels through the seat's
//! [`crate::play::fit::Fit`]).

use std::io;

use tiny_skia::Pixmap;

use super::probe::{GraphicsChoice, GraphicsSupport};
use crate::output::bucket::ByteBucket;
use crate::output::diff::{SYNC_BEGIN, SYNC_END};
use crate::output::graphics::geometry::{self, Layout};
use crate::output::graphics::iterm2::Iterm2Encoder;
use crate::output::graphics::kitty::{self, KittyEncoder, KittyOptions, Medium};
use crate::output::graphics::sixel::{SixelEncoder, SixelPalette};
use crate::output::graphics::{GraphicsMode, push_rgb};

/// The largest picture a scene renders at in a pixel mode, in pixels. The pool's simulation
/// grid is its picture, and its breeze costs about 33 ns a cell a step (`tidepool render pool
/// --breeze 1 --stats`): at the full 1280x752 of a 160x48 window, 60 steps a second would need
/// two cores. Within this size the pool (simulation, picture, encoding) stays near half a core
/// (`scripts/measure_graphics.py`); kitty and iTerm2 scale the picture up to the cell area
/// themselves, sixel pictures are scaled up here.
pub const SCENE_CAP: (u32, u32) = (480, 300);

/// The kitty image's stacking order: under text glyphs, so the help overlay and the aim marker
/// (text cells over the picture) stay readable.
pub const KITTY_Z_INDEX: i32 = -1;

/// The picture of a pixel mode: its layout and encoder.
#[derive(Debug)]
pub struct Picture {
    choice: GraphicsChoice,
    support: GraphicsSupport,
    layout: Layout,
    encoder: Encoder,
    /// The picture as RGB, reused from frame to frame.
    rgb: Vec<u8>,
    /// The size the scene renders at: `layout.picture` within [`SCENE_CAP`].
    scene: (u32, u32),
    /// For sixel, the scene's picture scaled up to `layout.picture` (one pixel a pixel).
    scaled: Option<Pixmap>,
    /// This frame's picture bytes (reused).
    bytes: Vec<u8>,
    /// The help was open at the last frame (its text erases sixel and iTerm2 pixels, so the
    /// picture is sent whole when it closes).
    help_was_open: bool,
}

#[derive(Debug)]
enum Encoder {
    Kitty(Box<KittyEncoder>),
    Sixel(Box<SixelEncoder>),
    Iterm2(Iterm2Encoder),
}

impl Picture {
    /// The picture for `choice` in a terminal of `term` cells, or `None` for `cells` mode (the
    /// cell frame is the picture then).
    pub fn new(choice: &GraphicsChoice, support: &GraphicsSupport, term: (u16, u16)) -> Option<Picture> {
        let layout = layout_for(choice.mode, support, term);
        let encoder = match choice.mode {
            GraphicsMode::Cells => return None,
            GraphicsMode::Kitty => Encoder::Kitty(Box::new(KittyEncoder::new(kitty_options(choice, support, &layout)))),
            GraphicsMode::Sixel => {
                let registers = support.sixel_registers();
                Encoder::Sixel(Box::new(SixelEncoder::new(
                    SixelPalette::for_registers(registers),
                    layout.origin,
                    Some(layout.cell_px),
                )))
            }
            GraphicsMode::Iterm2 => Encoder::Iterm2(Iterm2Encoder::new(layout.origin, layout.cells, choice.tmux_wrap)),
        };
        let scene = fit(layout.picture, SCENE_CAP);
        Some(Picture {
            choice: choice.clone(),
            support: support.clone(),
            layout,
            encoder,
            rgb: Vec::new(),
            scene,
            scaled: None,
            bytes: Vec::new(),
            help_was_open: false,
        })
    }

    /// Where the picture goes and its size in pixels.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The size the scene renders at (the picture within [`SCENE_CAP`]).
    pub fn scene_size(&self) -> (u32, u32) {
        self.scene
    }

    /// A new terminal size: a new layout, and the next picture is sent whole (the caller clears
    /// the screen in the same frame).
    pub fn resize(&mut self, term: (u16, u16)) {
        self.layout = layout_for(self.choice.mode, &self.support, term);
        self.scene = fit(self.layout.picture, SCENE_CAP);
        match &mut self.encoder {
            Encoder::Kitty(k) => k.set_options(kitty_options(&self.choice, &self.support, &self.layout)),
            Encoder::Sixel(s) => {
                **s = SixelEncoder::new(s.palette().clone(), self.layout.origin, Some(self.layout.cell_px));
            }
            Encoder::Iterm2(i) => *i = Iterm2Encoder::new(self.layout.origin, self.layout.cells, self.choice.tmux_wrap),
        }
    }

    /// Forgets what the terminal shows: the next picture is sent whole (text was written over
    /// sixel or iTerm2 pixels, or the screen was cleared).
    pub fn invalidate(&mut self) {
        match &mut self.encoder {
            Encoder::Kitty(k) => k.invalidate(),
            Encoder::Sixel(s) => s.invalidate(),
            Encoder::Iterm2(i) => i.invalidate(),
        }
    }

    /// Whether text written over the picture erases its pixels (sixel, iTerm2), so the picture
    /// must be resent after the text goes; kitty draws its image under text and keeps it.
    pub fn text_erases_pixels(&self) -> bool {
        !matches!(self.encoder, Encoder::Kitty(_))
    }

    /// Appends the bytes that show `pixmap` (nothing when the terminal already shows it).
    /// Fails only when kitty's temporary file cannot be written; then nothing is appended.
    pub fn encode(&mut self, pixmap: &Pixmap, out: &mut Vec<u8>) -> io::Result<()> {
        let pixmap = match &self.encoder {
            // Sixel is drawn one pixel a pixel: the scene's picture is scaled up to the area.
            Encoder::Sixel(_) if (pixmap.width(), pixmap.height()) != self.layout.picture => {
                let (w, h) = self.layout.picture;
                let scaled = match self.scaled.take() {
                    Some(p) if (p.width(), p.height()) == (w, h) => p,
                    _ => Pixmap::new(w, h).ok_or_else(|| io::Error::other("cannot allocate the sixel picture"))?,
                };
                let scaled = self.scaled.insert(scaled);
                let transform = tiny_skia::Transform::from_scale(
                    w as f32 / pixmap.width() as f32,
                    h as f32 / pixmap.height() as f32,
                );
                let paint =
                    tiny_skia::PixmapPaint { quality: tiny_skia::FilterQuality::Bilinear, ..Default::default() };
                scaled.draw_pixmap(0, 0, pixmap.as_ref(), &paint, transform, None);
                &*scaled
            }
            _ => pixmap,
        };
        let (w, h) = (pixmap.width(), pixmap.height());
        match &mut self.encoder {
            Encoder::Kitty(k) => {
                self.rgb.clear();
                push_rgb(pixmap, &mut self.rgb);
                k.encode(&self.rgb, w, h, out)?;
            }
            Encoder::Sixel(s) => {
                self.rgb.clear();
                push_rgb(pixmap, &mut self.rgb);
                s.encode(&self.rgb, w, h, out);
            }
            Encoder::Iterm2(i) => {
                i.encode(pixmap, out);
            }
        }
        Ok(())
    }
}

/// What the player's frame is like, for [`Picture::add_to_frame`].
#[derive(Clone, Copy, Debug)]
pub struct Frame {
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
    /// Adds the picture to the frame's `bytes` (inside its synchronized update) when it is due,
    /// and says whether it did (then the terminal's cursor is somewhere unknown).
    ///
    /// The status line goes first: a picture is sent only once the cells are all shown, and
    /// only while the bucket is not in debt. A picture cannot be cut to a budget: it is sent
    /// whole and owed (see [`ByteBucket::owe`]), so the next one waits until the rate has paid
    /// for it; on a limited link the picture rate drops, and nothing queues. Sixel and iTerm2
    /// would paint over the help, so the picture waits while it is open.
    pub fn add_to_frame(
        &mut self,
        pixmap: &Pixmap,
        frame: &Frame,
        bucket: &mut ByteBucket,
        bytes: &mut Vec<u8>,
    ) -> io::Result<bool> {
        let erases = self.text_erases_pixels();
        if frame.resized || (self.help_was_open && !frame.help_open && erases) {
            self.invalidate();
        }
        self.help_was_open = frame.help_open;
        if (frame.help_open && erases) || !frame.cells_shown || bucket.in_debt() || !frame.drawable {
            return Ok(false);
        }
        let mut picture = std::mem::take(&mut self.bytes);
        picture.clear();
        let result = self.encode(pixmap, &mut picture);
        let sent = result.is_ok() && !picture.is_empty();
        if sent {
            bucket.owe(picture.len());
            splice_picture(bytes, &picture, frame.sync);
        }
        self.bytes = picture;
        result.map(|()| sent)
    }
}

/// Puts a picture's bytes into the frame's synchronized update (before its end marker), so the
/// picture and the status line change together; a frame without markers gets them.
fn splice_picture(frame: &mut Vec<u8>, picture: &[u8], sync: bool) {
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

fn kitty_options(choice: &GraphicsChoice, support: &GraphicsSupport, layout: &Layout) -> KittyOptions {
    KittyOptions {
        origin: layout.origin,
        tmux: choice.tmux_wrap,
        placeholders: choice.kitty_placeholders,
        frame_edits: support.kitty_frame_edits,
        medium: if support.kitty_temp_file { Medium::TempFile(kitty::temp_dir()) } else { Medium::Direct },
        z_index: KITTY_Z_INDEX,
        ..KittyOptions::new(layout.cells)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::graphics::kitty_decode;

    fn choice(mode: GraphicsMode) -> GraphicsChoice {
        GraphicsChoice { mode, tmux_wrap: false, kitty_placeholders: false, hint: None }
    }

    #[test]
    fn cells_mode_has_no_picture() {
        assert!(Picture::new(&choice(GraphicsMode::Cells), &GraphicsSupport::default(), (80, 24)).is_none());
    }

    #[test]
    fn kitty_pictures_decode_to_the_pixmap_and_still_pictures_send_nothing() {
        let support = GraphicsSupport { cell_px: Some((8, 16)), ..Default::default() };
        let mut p = Picture::new(&choice(GraphicsMode::Kitty), &support, (10, 5)).unwrap();
        assert_eq!(p.layout().picture, (80, 64));
        let mut pixmap = Pixmap::new(80, 64).unwrap();
        pixmap.fill(tiny_skia::Color::from_rgba8(10, 120, 200, 255));
        let mut out = Vec::new();
        p.encode(&pixmap, &mut out).unwrap();
        let image = &kitty_decode::decode(&out).unwrap().images[&kitty::IMAGE_ID];
        assert_eq!((image.width, image.height), (80, 64));
        assert_eq!(image.rgb, crate::output::graphics::rgb(&pixmap));
        let sent = out.len();
        p.encode(&pixmap, &mut out).unwrap();
        assert_eq!(out.len(), sent, "an unchanged picture sends nothing");
        let deleted = kitty_decode::decode(&restore_bytes(&choice(GraphicsMode::Kitty), false)).unwrap();
        assert!(deleted.images.is_empty() && deleted.commands[0][&'a'] == "d", "kitty's image is deleted on exit");
    }

    #[test]
    fn big_pictures_render_within_the_scene_cap_and_sixel_scales_them_up() {
        let support = GraphicsSupport { cell_px: Some((8, 16)), ..Default::default() };
        let mut p = Picture::new(&choice(GraphicsMode::Sixel), &support, (160, 48)).unwrap();
        assert_eq!((p.layout().picture, p.scene_size()), ((1280, 750), (480, 281)));
        let mut pixmap = Pixmap::new(480, 281).unwrap();
        pixmap.fill(tiny_skia::Color::from_rgba8(0, 0, 255, 255));
        let mut out = Vec::new();
        p.encode(&pixmap, &mut out).unwrap();
        let raster: &[u8] = b"\"1;1;1280;750";
        assert!(out.windows(raster.len()).any(|w| w == raster), "one pixel a screen pixel");
    }
}
