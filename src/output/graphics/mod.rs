//! Real pixels in terminals that can show them: the kitty graphics protocol, sixel and iTerm2
//! inline images. Pixels in, bytes out; nothing here touches a terminal.
//!
//! - [`kitty`]: one image id replaced in place, zlib-compressed RGB in base64 chunks (or a
//!   temporary file when the terminal is on this machine), optional changed-rectangle updates,
//!   Unicode placeholders for tmux; [`kitty_decode`] parses such a stream back into pixels.
//! - [`sixel`]: a palette fitted to the scene with ordered dithering by position, so still
//!   water encodes to the same bytes every frame.
//! - [`iterm2`]: OSC 1337 inline PNG.
//! - [`tmux`]: the passthrough wrapper every protocol needs inside tmux.
//! - [`geometry`]: which resolution to render for each protocol, and which picture pixel a
//!   click lands on.
//!
//! The player drives these through `crate::term::picture`, `render --out -` through the
//! binary's `commands/inline.rs`; detection lives in [`crate::term::probe`].
// The standalone encoders (`KittyEncoder`, `SixelEncoder`, `Iterm2Encoder`: a picture written
// once, `tidepool render --out -`) are the command line's and the tests'; the play session
// drives the protocols through its picture stream. Without `cli` or `testing` their parts that
// only the standalone encoders use are unused: allowed here rather than a `cfg` on each field.
#![cfg_attr(not(any(test, feature = "cli", feature = "testing")), allow(dead_code))]

pub mod deflate;
pub mod geometry;
pub mod iterm2;
pub mod kitty;
#[cfg(any(test, feature = "testing"))]
pub mod kitty_decode;
pub mod kitty_placeholder;
pub mod lossy_png;
pub mod pack;
pub mod palette_png;
pub mod scan;
pub mod sixel;
#[cfg(any(test, feature = "player", feature = "testing"))]
pub mod stream;
pub mod tmux;

use tiny_skia::Pixmap;

#[cfg(test)]
pub(crate) mod test_pictures;

/// How the player draws its picture.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GraphicsMode {
    /// The kitty graphics protocol.
    Kitty,
    /// DEC sixel graphics.
    Sixel,
    /// iTerm2's OSC 1337 inline images.
    Iterm2,
    /// Half-block text cells, two pixels a cell: works everywhere.
    Cells,
}

impl GraphicsMode {
    /// The mode's name as `--graphics` spells it.
    pub fn name(self) -> &'static str {
        match self {
            GraphicsMode::Kitty => "kitty",
            GraphicsMode::Sixel => "sixel",
            GraphicsMode::Iterm2 => "iterm2",
            GraphicsMode::Cells => "cells",
        }
    }
}

/// What a call to an encoder's `encode` sent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Update {
    /// The picture is what the terminal already shows: no bytes.
    Unchanged,
    /// The whole picture.
    Full,
    /// Only this rectangle (x, y, width, height in pixels): an edit of the shown image
    /// (kitty) or a block of whole cells (sixel).
    Rect(u32, u32, u32, u32),
}

/// Appends the pixmap's pixels as straight (un-premultiplied) RGB, 3 bytes a pixel, row-major.
/// Alpha is dropped: the player's pictures are opaque.
pub fn push_rgb(pixmap: &Pixmap, out: &mut Vec<u8>) {
    let start = out.len();
    out.resize(start + pixmap.pixels().len() * 3, 0);
    // Premultiplied and straight colour agree where alpha is 255 (every pixel of a rendered
    // scene): copy those bytes as they are, and demultiply only the others.
    for (p, to) in pixmap.data().chunks_exact(4).zip(out[start..].chunks_exact_mut(3)) {
        if p[3] == 255 {
            to.copy_from_slice(&p[..3]);
        } else {
            let c = tiny_skia::PremultipliedColorU8::from_rgba(p[0], p[1], p[2], p[3])
                .map_or(tiny_skia::ColorU8::from_rgba(0, 0, 0, 0), |c| c.demultiply());
            to.copy_from_slice(&[c.red(), c.green(), c.blue()]);
        }
    }
}

/// The pixmap's pixels as straight RGB (see [`push_rgb`]).
#[cfg(test)]
pub fn rgb(pixmap: &Pixmap) -> Vec<u8> {
    let mut out = Vec::new();
    push_rgb(pixmap, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use tiny_skia::ColorU8;

    #[test]
    fn rgb_is_straight_and_row_major() {
        let mut p = Pixmap::new(2, 1).unwrap();
        p.pixels_mut()[0] = ColorU8::from_rgba(10, 20, 30, 255).premultiply();
        p.pixels_mut()[1] = ColorU8::from_rgba(200, 100, 50, 128).premultiply();
        let bytes = rgb(&p);
        assert_eq!(&bytes[..3], &[10, 20, 30]);
        for (got, want) in bytes[3..].iter().zip([200u8, 100, 50]) {
            assert!(got.abs_diff(want) <= 1, "{bytes:?}");
        }
    }
}
