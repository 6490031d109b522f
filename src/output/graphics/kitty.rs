//! The kitty graphics protocol encoder: one image id, replaced in place every frame.
//!
//! A frame is one transmit-and-display command (`a=T`) for the same image id and placement id:
//! the terminal replaces the old image and its placement with the new one, so nothing piles up
//! and nothing flickers (inside synchronized output). The pixels go as 24-bit RGB (`f=24`):
//! - **direct** (any terminal, also over SSH): zlib-compressed (`o=z`) and base64-encoded, in
//!   chunks of at most [`CHUNK_BASE64`] bytes, `m=1` on all but the last;
//! - **temporary file** (`t=t`, the terminal on this machine, as the probe found out): the raw
//!   RGB is written to a file whose name contains `tty-graphics-protocol` in `/dev/shm` (memory,
//!   not disk) or the temp directory; the command carries only the path. The terminal reads the
//!   file and deletes it. No base64, no compression: the cheapest route by far. POSIX shared
//!   memory (`t=s`) would save one copy more but needs `shm_open` through `unsafe` FFI; a file
//!   in `/dev/shm` is the same memory without it.
//!
//! Responses are suppressed (`q=2`): a reply arriving during play would otherwise reach the
//! input as keys. The placement is scaled to a cell area (`c=`, `r=`), and the cursor is not
//! moved (`C=1`), so the caller's idea of the cursor stays right.
//!
//! **Changed rectangle.** When only part of the picture changed and the terminal answered the
//! probe's frame-edit test (`play::screen::probe`), the frame is sent as an edit of the image's
//! root frame (`a=f,r=1,x=,y=,s=,v=,X=1`): the animation part of the protocol, which composes a
//! rectangle of new pixels onto an existing frame with plain replacement. The bounding box of
//! the changed pixels is sent if it is at most [`EDIT_MAX_FRACTION`] of the picture; otherwise
//! the whole image. Terminals that implement the protocol without animation (Ghostty, Konsole)
//! answer the probe's edit with an error or not at all, and get whole frames.
//!
//! **tmux.** Every command can be wrapped for passthrough ([`crate::output::graphics::tmux`]),
//! chunk by chunk. A placement made by a passed-through command is not known to tmux and would
//! stay put when panes move, so in tmux the image gets a *virtual* placement (`U=1`) and is
//! shown through Unicode placeholder text ([`push_placeholders`]).

pub use super::Update;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

pub use crate::output::graphics::kitty_placeholder::push_placeholders;
use crate::output::graphics::pack::{Packing, zlib};
use crate::output::graphics::{scan, tmux};
use base64::Engine;
use base64::engine::general_purpose::STANDARD as BASE64;

/// The most base64 bytes in one chunk (the protocol's limit).
pub const CHUNK_BASE64: usize = 4096;
/// Raw bytes per chunk: base64 turns 3 bytes into 4.
const CHUNK_RAW: usize = CHUNK_BASE64 / 4 * 3;
/// tidepool's image id: arbitrary, below 2^24 so Unicode placeholders carry it in one colour.
pub const IMAGE_ID: u32 = 0x0074_6470;
/// The one placement of [`IMAGE_ID`].
pub const PLACEMENT_ID: u32 = 1;
/// zlib level for direct transmission: 1 is the fastest; higher levels cost several times the
/// CPU for a few percent fewer bytes on rendered water.
pub const ZLIB_LEVEL: u32 = 1;
/// A changed rectangle is sent as a frame edit only if its area is at most this fraction of the
/// picture's; above it, the whole picture costs about the same and is simpler for the terminal.
pub const EDIT_MAX_FRACTION: f64 = 0.5;
/// The marker kitty requires in a temporary file's path before it deletes the file.
pub const TEMP_FILE_MARKER: &str = "tty-graphics-protocol";

/// How the pixels reach the terminal.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Medium {
    /// In the escape codes, zlib-compressed and base64-encoded.
    Direct,
    /// Through temporary files in this directory (see [`temp_dir`]).
    TempFile(PathBuf),
}

/// Where and how the image is shown.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct KittyOptions {
    /// The image id ([`KittyOptions::IMAGE_ID`]).
    pub image_id: u32,
    /// The top-left cell of the picture, 0-based (column, row).
    pub origin: (u16, u16),
    /// The cell area the picture is scaled to (columns, rows).
    pub cells: (u16, u16),
    /// Wrap every command for tmux passthrough.
    pub tmux: bool,
    /// Show the image through Unicode placeholders (a virtual placement, `U=1`).
    pub placeholders: bool,
    /// Send changed rectangles as frame edits (only when the probe saw them work).
    pub frame_edits: bool,
    /// How the pixels travel.
    pub medium: Medium,
    /// Stacking order: 0 draws over text; negative values draw under text glyphs.
    pub z_index: i32,
}

impl KittyOptions {
    /// The image id tidepool's pictures use unless told otherwise (`new` sets it).
    #[cfg(any(test, feature = "testing"))]
    pub const IMAGE_ID: u32 = IMAGE_ID;

    /// Direct transmission of [`KittyOptions::IMAGE_ID`] over `cells` at the top-left corner; no tmux, no
    /// placeholders, no frame edits.
    pub fn new(cells: (u16, u16)) -> KittyOptions {
        KittyOptions {
            image_id: IMAGE_ID,
            origin: (0, 0),
            cells,
            tmux: false,
            placeholders: false,
            frame_edits: false,
            medium: Medium::Direct,
            z_index: 0,
        }
    }
}

/// The encoder, with what the terminal shows (for "no change, no bytes" and changed rectangles).
#[derive(Debug)]
pub struct KittyEncoder {
    options: KittyOptions,
    /// The picture the terminal has: (width, height, RGB); `None` before the first frame and
    /// after [`KittyEncoder::invalidate`].
    shown: Option<(u32, u32, Vec<u8>)>,
    /// Reused buffers: the rectangle's pixels, the compressed data.
    rect: Vec<u8>,
    zlib: Vec<u8>,
    /// Counts temporary files, so each has its own name.
    files: u64,
    /// Placeholder text must be (re)printed before the next frame.
    placeholders_due: bool,
}

impl KittyEncoder {
    /// An encoder with nothing shown yet.
    pub fn new(options: KittyOptions) -> KittyEncoder {
        KittyEncoder { options, shown: None, rect: Vec::new(), zlib: Vec::new(), files: 0, placeholders_due: true }
    }

    #[cfg(any(test, feature = "testing"))]
    /// The options in force.
    pub fn options(&self) -> &KittyOptions {
        &self.options
    }

    #[cfg(any(test, feature = "testing"))]
    /// Changes the options (after a resize: a new cell area); the next frame is sent whole.
    pub fn set_options(&mut self, options: KittyOptions) {
        self.options = options;
        self.invalidate();
    }

    #[cfg(any(test, feature = "testing"))]
    /// Forgets what the terminal shows (the screen was cleared): the next frame is sent whole.
    pub fn invalidate(&mut self) {
        self.shown = None;
        self.placeholders_due = true;
    }

    /// Appends the bytes that make the terminal show `rgb` (`width x height`, 3 bytes a pixel,
    /// row-major), and says what was sent. Nothing is appended when the picture is unchanged.
    /// Fails only when a temporary file cannot be written (then nothing is appended).
    pub fn encode(&mut self, rgb: &[u8], width: u32, height: u32, out: &mut Vec<u8>) -> io::Result<Update> {
        assert_eq!(rgb.len(), width as usize * height as usize * 3, "RGB buffer does not match {width}x{height}");
        let update = match &self.shown {
            Some((w, h, old)) if (*w, *h) == (width, height) => match changed_rect(old, rgb, width, height) {
                None => return Ok(Update::Unchanged),
                Some((x, y, rw, rh))
                    if self.options.frame_edits
                        && f64::from(rw) * f64::from(rh)
                            <= EDIT_MAX_FRACTION * f64::from(width) * f64::from(height) =>
                {
                    Update::Rect(x, y, rw, rh)
                }
                Some(_) => Update::Full,
            },
            _ => Update::Full,
        };
        let start = out.len();
        let result = match update {
            Update::Rect(x, y, w, h) => {
                self.rect.clear();
                for row in y..y + h {
                    let from = (row as usize * width as usize + x as usize) * 3;
                    self.rect.extend_from_slice(&rgb[from..from + w as usize * 3]);
                }
                let rect = std::mem::take(&mut self.rect);
                let r = self.push_edit(out, &rect, (x, y, w, h));
                self.rect = rect;
                r
            }
            _ => self.push_full(out, rgb, width, height),
        };
        if let Err(e) = result {
            out.truncate(start);
            return Err(e);
        }
        match &mut self.shown {
            Some((w, h, old)) if (*w, *h) == (width, height) => old.copy_from_slice(rgb),
            shown => *shown = Some((width, height, rgb.to_vec())),
        }
        Ok(update)
    }

    fn push_full(&mut self, out: &mut Vec<u8>, rgb: &[u8], width: u32, height: u32) -> io::Result<()> {
        let mut keys = Vec::with_capacity(96);
        image_keys(&mut keys, &self.options, (width, height));
        if !self.options.placeholders {
            push_cursor_to(out, self.options.origin);
        }
        self.push_pixels(out, &keys, b"", rgb)?;
        if self.options.placeholders && self.placeholders_due {
            let o = &self.options;
            push_placeholders(out, o.image_id, o.origin.0, o.origin.1, o.cells.0, o.cells.1);
            self.placeholders_due = false;
        }
        Ok(())
    }

    fn push_edit(&mut self, out: &mut Vec<u8>, rect: &[u8], r: (u32, u32, u32, u32)) -> io::Result<()> {
        let mut keys = Vec::with_capacity(64);
        edit_keys(&mut keys, self.options.image_id, r);
        self.push_pixels(out, &keys, b"a=f,", rect)
    }

    /// Appends the command(s) carrying `data` by the configured medium. `more_keys` go on
    /// continuation chunks before `m=` (`a=f,` for frame edits, as the protocol requires).
    fn push_pixels(&mut self, out: &mut Vec<u8>, keys: &[u8], more_keys: &[u8], data: &[u8]) -> io::Result<()> {
        match &self.options.medium {
            Medium::TempFile(dir) => {
                self.files += 1;
                let path = write_temp_file(dir, self.files, data)?;
                let command = temp_file_command(keys, &path);
                push_command(out, &command, self.options.tmux);
            }
            Medium::Direct => {
                zlib(data, ZLIB_LEVEL as u8, &mut self.zlib);
                push_chunks(out, keys, more_keys, Packing::Zlib(ZLIB_LEVEL as u8), &self.zlib, self.options.tmux);
            }
        }
        Ok(())
    }

    #[cfg(any(test, feature = "testing"))]
    /// Appends the bytes that delete the image and its data (for the restore; also after a
    /// switch to another mode). Harmless when nothing was shown.
    pub fn push_delete(&self, out: &mut Vec<u8>) {
        push_delete(out, self.options.image_id, self.options.tmux);
    }
}

/// Appends a delete of image `image_id` with its data (`a=d,d=I`), responses suppressed.
pub fn push_delete(out: &mut Vec<u8>, image_id: u32, tmux: bool) {
    push_command(out, format!("\x1b_Ga=d,d=I,i={image_id},q=2\x1b\\").as_bytes(), tmux);
}

/// Appends one escape sequence, wrapped for tmux if asked.
fn push_command(out: &mut Vec<u8>, command: &[u8], tmux: bool) {
    if tmux {
        tmux::push_wrapped(out, command);
    } else {
        out.extend_from_slice(command);
    }
}

/// Appends `data` base64-encoded in chunks: the first with `keys`, the rest with
/// `more_keys` and `q=2`; `m=1` on all but the last. Without tmux every chunk is written in place (the
/// base64 straight into `out`); inside tmux each chunk is built once and wrapped.
fn push_chunked_bytes(out: &mut Vec<u8>, keys: &[u8], more_keys: &[u8], data: &[u8], tmux: bool) {
    let chunks = data.len().div_ceil(CHUNK_RAW).max(1);
    out.reserve(data.len().div_ceil(3) * 4 + chunks * (16 + more_keys.len()) + keys.len() + 16);
    let mut command = Vec::new();
    for i in 0..chunks {
        let part = &data[(i * CHUNK_RAW).min(data.len())..((i + 1) * CHUNK_RAW).min(data.len())];
        let more = i + 1 < chunks;
        let to: &mut Vec<u8> = if tmux {
            command.clear();
            &mut command
        } else {
            &mut *out
        };
        to.extend_from_slice(b"\x1b_G");
        if i == 0 {
            to.extend_from_slice(keys);
            to.extend_from_slice(if more { b",m=1;" } else { b",m=0;" });
        } else {
            to.extend_from_slice(more_keys);
            to.extend_from_slice(if more { b"m=1,q=2;" } else { b"m=0,q=2;" });
        }
        let at = to.len();
        to.resize(at + part.len().div_ceil(3) * 4, 0);
        let n = BASE64.encode_slice(part, &mut to[at..]).expect("a chunk's base64 fits its buffer");
        to.truncate(at + n);
        to.extend_from_slice(b"\x1b\\");
        if tmux {
            tmux::push_wrapped(out, &command);
        }
    }
}

/// Appends the chunked command(s) carrying packed pixels: `keys` (without format or
/// compression) plus the packing's keys (`f=24,o=z` or `f=100`).
pub fn push_chunks(out: &mut Vec<u8>, keys: &[u8], more_keys: &[u8], packing: Packing, packed: &[u8], tmux: bool) {
    let mut all = Vec::with_capacity(keys.len() + 12);
    all.extend_from_slice(keys);
    all.extend_from_slice(match packing {
        Packing::Zlib(_) => b",f=24,o=z".as_slice(),
        Packing::Png | Packing::LossyPng(_) | Packing::PalettePng(_) => b",f=100".as_slice(),
        Packing::Jpeg(_) => panic!("kitty decodes no JPEG"),
    });
    push_chunked_bytes(out, &all, more_keys, packed, tmux);
}

/// The keys of a whole-image transmission and display (`a=T`) of a `size` picture under
/// `options`, without the pixel format: the placement, the cell area, responses off.
pub fn image_keys(keys: &mut Vec<u8>, o: &KittyOptions, (width, height): (u32, u32)) {
    let (cols, rows) = o.cells;
    let _ = write!(keys, "a=T,i={},s={width},v={height},c={cols},r={rows},q=2", o.image_id);
    if o.placeholders {
        keys.extend_from_slice(b",U=1");
    } else {
        let _ = write!(keys, ",p={PLACEMENT_ID},C=1");
        if o.z_index != 0 {
            let _ = write!(keys, ",z={}", o.z_index);
        }
    }
}

/// The keys of an edit of image `id`'s root frame: the rectangle `(x, y, w, h)` replaced.
pub fn edit_keys(keys: &mut Vec<u8>, id: u32, (x, y, w, h): (u32, u32, u32, u32)) {
    let _ = write!(keys, "a=f,r=1,i={id},x={x},y={y},s={w},v={h},X=1,q=2");
}

/// Appends a cursor move to cell `origin` (0-based column, row): a placement is made where
/// the cursor is.
pub fn push_cursor_to(out: &mut Vec<u8>, (col, row): (u16, u16)) {
    let _ = write!(out, "\x1b[{};{}H", u32::from(row) + 1, u32::from(col) + 1);
}

/// Appends the command that makes the terminal read raw RGB pixels from the temporary file
/// `path` (`t=t`, `f=24`) under `keys`, wrapped for tmux if asked.
#[cfg(any(test, feature = "player", feature = "testing"))]
pub(crate) fn push_temp_file_command(out: &mut Vec<u8>, keys: &[u8], path: &Path, tmux: bool) {
    push_command(out, &temp_file_command(keys, path), tmux);
}

/// The command that makes the terminal read pixels from `path` (`t=t`): `keys` plus the
/// medium, the base64-encoded path as payload.
fn temp_file_command(keys: &[u8], path: &Path) -> Vec<u8> {
    let path = path.as_os_str().as_encoded_bytes();
    let mut command = b"\x1b_G".to_vec();
    command.extend_from_slice(keys);
    command.extend_from_slice(b",f=24,t=t;");
    command.extend_from_slice(BASE64.encode(path).as_bytes());
    command.extend_from_slice(b"\x1b\\");
    command
}

/// The name of temporary file `n` of this process: it carries [`TEMP_FILE_MARKER`], which the
/// terminal needs before it deletes a file.
pub fn temp_file_path(dir: &Path, n: u64) -> PathBuf {
    dir.join(format!("tidepool-{}-{n}-{TEMP_FILE_MARKER}.rgb", std::process::id()))
}

/// The bounding box (x, y, width, height) of the pixels that differ between two RGB pictures of
/// the same size, or `None` when they are equal (one pass: `scan::changed_box`).
pub fn changed_rect(old: &[u8], new: &[u8], width: u32, height: u32) -> Option<(u32, u32, u32, u32)> {
    scan::changed_box(old, new, width, 3, 0..height)
}

mod files;
pub use files::write_temp_file;
// The door's (the command line's terminal door) and the tests'.
#[cfg(any(test, feature = "cli", feature = "testing"))]
pub use files::temp_dir;
#[cfg(any(feature = "cli", feature = "testing"))]
pub use files::write_new_file;

#[cfg(test)]
mod tests;
