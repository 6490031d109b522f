//! iTerm2 inline images (also WezTerm): OSC 1337 `File=` with a base64 PNG, scaled by the
//! terminal to a cell area.
//!
//! `width` and `height` are given in cells and `preserveAspectRatio=0`, so the picture fills
//! exactly the area the player reserved (its aspect already matches: see
//! [`crate::output::graphics::geometry`]). `doNotMoveCursor=1` keeps the cursor where it was
//! (terminals that do not know the key ignore it; the picture ends above the last row, so even
//! a moved cursor does not scroll). The PNG comes from [`crate::encode::png`], whose bytes depend
//! only on the pixels; an unchanged picture sends nothing. The protocol has no partial update:
//! each frame is a whole new image.

use base64::Engine;
use base64::engine::general_purpose::STANDARD as BASE64;
use tiny_skia::Pixmap;

use std::io::Write;

use crate::output::graphics::pack::{Packing, pack};
use crate::output::graphics::tmux;

/// The encoder, with the picture the terminal shows.
#[derive(Debug)]
pub struct Iterm2Encoder {
    /// The picture's top-left cell (column, row), 0-based.
    origin: (u16, u16),
    /// The cell area the picture fills (columns, rows).
    cells: (u16, u16),
    /// Wrap for tmux passthrough.
    tmux: bool,
    shown: Option<(u32, u32, Vec<u8>)>,
}

impl Iterm2Encoder {
    /// An encoder for a picture over `cells` from cell `origin`.
    pub fn new(origin: (u16, u16), cells: (u16, u16), tmux: bool) -> Iterm2Encoder {
        Iterm2Encoder { origin, cells, tmux, shown: None }
    }

    #[cfg(any(test, feature = "testing"))]
    /// Forgets what the terminal shows: the next picture is sent.
    pub fn invalidate(&mut self) {
        self.shown = None;
    }

    /// Appends the bytes that show `pixmap`; returns false (and appends nothing) when it is the
    /// picture already shown.
    pub fn encode(&mut self, pixmap: &Pixmap, out: &mut Vec<u8>) -> bool {
        let (w, h) = (pixmap.width(), pixmap.height());
        if matches!(&self.shown, Some((sw, sh, data)) if (*sw, *sh) == (w, h) && data == pixmap.data()) {
            return false;
        }
        let mut rgb = Vec::with_capacity(w as usize * h as usize * 3);
        crate::output::graphics::push_rgb(pixmap, &mut rgb);
        let mut png = Vec::new();
        pack(Packing::Png, &rgb, w, h, &mut png);
        push_file(out, self.origin, self.cells, self.tmux, &png);
        match &mut self.shown {
            Some((sw, sh, data)) if (*sw, *sh) == (w, h) => data.copy_from_slice(pixmap.data()),
            shown => *shown = Some((w, h, pixmap.data().to_vec())),
        }
        true
    }
}

/// Appends a cursor move to cell `origin` and the inline file `file` (a PNG or JPEG) filling
/// `cells` (columns, rows), wrapped for tmux when asked. The base64 goes straight into `out`.
pub fn push_file(out: &mut Vec<u8>, origin: (u16, u16), cells: (u16, u16), tmux: bool, file: &[u8]) {
    let _ = write!(out, "\x1b[{};{}H", u32::from(origin.1) + 1, u32::from(origin.0) + 1);
    let mut command = Vec::new();
    let to: &mut Vec<u8> = if tmux { &mut command } else { &mut *out };
    let _ = write!(
        to,
        "\x1b]1337;File=inline=1;size={};width={};height={};preserveAspectRatio=0;doNotMoveCursor=1:",
        file.len(),
        cells.0,
        cells.1
    );
    let start = to.len();
    to.resize(start + file.len().div_ceil(3) * 4, 0);
    let n = BASE64.encode_slice(file, &mut to[start..]).expect("sized for the base64");
    to.truncate(start + n);
    to.push(0x07);
    if tmux {
        tmux::push_wrapped(out, &command);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tiny_skia::ColorU8;

    #[test]
    fn an_inline_png_of_the_picture_scaled_to_the_cells() {
        let mut p = Pixmap::new(7, 5).unwrap();
        for (i, px) in p.pixels_mut().iter_mut().enumerate() {
            *px = ColorU8::from_rgba(i as u8 * 7, 255 - i as u8, 3, 255).premultiply();
        }
        let mut enc = Iterm2Encoder::new((1, 2), (30, 9), false);
        let mut out = Vec::new();
        assert!(enc.encode(&p, &mut out));
        let text = String::from_utf8(out.clone()).unwrap();
        let head = "\x1b[3;2H\x1b]1337;File=inline=1;size=";
        assert!(text.starts_with(head), "{text:?}");
        let (args, payload) = text[head.len()..].split_once(':').unwrap();
        assert!(args.ends_with(";width=30;height=9;preserveAspectRatio=0;doNotMoveCursor=1"), "{args}");
        let payload = payload.strip_suffix('\x07').expect("ends with BEL");
        let png = BASE64.decode(payload).unwrap();
        assert_eq!(args.split(';').next().unwrap(), png.len().to_string(), "size= is the PNG's byte count");
        let decoded = image::load_from_memory(&png).unwrap().to_rgb8();
        assert_eq!(decoded.into_raw(), crate::output::graphics::rgb(&p));

        // Unchanged: nothing; changed: sent again; tmux: wrapped.
        let mut again = Vec::new();
        assert!(!enc.encode(&p, &mut again) && again.is_empty());
        p.pixels_mut()[0] = ColorU8::from_rgba(1, 1, 1, 255).premultiply();
        assert!(enc.encode(&p, &mut again));
        let mut wrapped = Vec::new();
        Iterm2Encoder::new((0, 0), (30, 9), true).encode(&p, &mut wrapped);
        assert!(wrapped.starts_with(b"\x1b[1;1H\x1bPtmux;\x1b\x1b]1337;File="));
    }
}
