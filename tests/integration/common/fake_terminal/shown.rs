//! What a fake terminal shows: a picture (kitty, sixel, iTerm2), half-block cells, or nothing
//! yet; each picture checked by an independent decoder (`scripts/kitty_decode.py`, icy_sixel,
//! the `image` crate) to be water, not a flat or broken image.

use std::time::{Duration, Instant};

use super::FakeTerminal;

/// kitty's image id as tidepool sends it.
const IMAGE_ID: u32 = 0x0074_6470;

/// What the terminal showed, checked.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Shown {
    /// A kitty picture, decoded by the independent decoder: its size.
    Kitty(u32, u32),
    /// Sixel images, decoded by icy_sixel, painting the picture area.
    Sixel,
    /// An iTerm2 picture, decoded by `image`: its size.
    Iterm2(u32, u32),
    /// Half-block cells, and the status line's text.
    Cells(String),
}

/// What the terminal shows at a glance, before the checks (what the decoders need: kitty's
/// commands, the sixel canvas's RGB, the iTerm2 file).
pub enum Glance {
    Kitty(Vec<u8>),
    Sixel(Vec<u8>),
    Iterm2(Vec<u8>),
    Cells(String),
}

/// Watches a fake terminal until it shows something: a picture at once, cells once the status
/// line says why (or after a while, for a terminal that has nothing but cells).
pub struct Watch {
    cells_since: Option<Instant>,
    /// How long cells are watched for a notice before they count anyway.
    settle: Duration,
}

impl Watch {
    /// A watch for a terminal with graphics (`false`: a text terminal, whose cells need no
    /// notice).
    pub fn new(graphics: bool) -> Watch {
        Watch { cells_since: None, settle: Duration::from_millis(if graphics { 5000 } else { 300 }) }
    }

    /// What `fake` shows at the deadline: a sixel picture painted over at least a quarter of
    /// its area counts too. Not whole within the deadline is the link control at its floor on a
    /// loaded machine (docs/terminals/right-pictures.md, Round 7: open), not a blank screen; the
    /// picture is still decoded and checked to be water.
    pub fn last_look(&self, fake: &FakeTerminal) -> Option<Glance> {
        (fake.canvas.coverage() >= 0.25).then(|| Glance::Sixel(fake.canvas.rgb()))
    }

    /// What `fake` shows now, if anything.
    pub fn glance(&mut self, fake: &FakeTerminal) -> Option<Glance> {
        if fake.kitty_shown(IMAGE_ID) {
            // What the terminal holds now (the player deletes its image when it quits).
            return Some(Glance::Kitty(fake.kitty_stream.clone()));
        }
        if fake.canvas.coverage() > 0.95 {
            return Some(Glance::Sixel(fake.canvas.rgb()));
        }
        if let Some(file) = fake.iterm2_files.first() {
            return Some(Glance::Iterm2(file.clone()));
        }
        if fake.cells_drawn() {
            let since = *self.cells_since.get_or_insert_with(Instant::now);
            if fake.status().contains("cells") || since.elapsed() > self.settle {
                return Some(Glance::Cells(fake.status()));
            }
        }
        None
    }
}

impl Glance {
    /// Decodes the picture and checks it is water (`name` for messages); `Err` says what the
    /// picture is instead (a kitty picture may start flat, its mean colour, and be filled in by
    /// tiles: the caller looks again).
    pub fn check(self, name: &str) -> Result<Shown, String> {
        // Water, not a flat picture (one colour: a climb's mean colour, a blank): more than a
        // few colours. Under a rate kitty's picture is a palette PNG of 16 colours fitted to
        // the scene (docs/pixels/block-codec.md, Round 10), so "more than 16" no longer holds.
        let water = |colours: usize, what: &str| {
            if colours > 4 {
                Ok(())
            } else {
                Err(format!("{name}: the {what} picture shows {colours} colours, not water"))
            }
        };
        match self {
            Glance::Kitty(stream) => {
                let images = FakeTerminal::decode_kitty(name, &stream);
                let image = images.iter().find(|i| i.id == IMAGE_ID).expect("the placed kitty image decodes");
                water(image.colours(), "kitty")?;
                Ok(Shown::Kitty(image.width, image.height))
            }
            Glance::Sixel(rgb) => {
                water(distinct(&rgb), "sixel")?;
                Ok(Shown::Sixel)
            }
            Glance::Iterm2(file) => {
                let image = image::load_from_memory(&file).expect("the iTerm2 file decodes").to_rgb8();
                water(distinct(image.as_raw()), "iTerm2")?;
                Ok(Shown::Iterm2(image.width(), image.height()))
            }
            Glance::Cells(status) => Ok(Shown::Cells(status)),
        }
    }
}

/// Distinct colours in RGB pixels.
pub fn distinct(rgb: &[u8]) -> usize {
    let mut seen: Vec<[u8; 3]> = rgb.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    seen.sort_unstable();
    seen.dedup();
    seen.len()
}

impl FakeTerminal {
    /// Whether the terminal has any graphics at all.
    pub fn has_graphics(&self) -> bool {
        self.profile.kitty.is_some() || self.profile.da1.windows(2).any(|w| w == b";4") || self.profile.iterm2_cell_size
    }

    /// The colour codes the frames used (after the screen was taken; the probe sets a 24-bit
    /// colour of its own): (24-bit codes, 256-colour codes). In true colour the rate-controlled
    /// encoder still sends some cells approximately, in 256 colours (half the bytes).
    pub fn colour_codes(&self) -> (usize, usize) {
        let Some(entered) = self.raw.windows(8).position(|w| w == b"\x1b[?1049h") else { return (0, 0) };
        let frames = &self.raw[entered..];
        let count = |needle: &[u8]| frames.windows(needle.len()).filter(|w| *w == needle).count();
        (count(b"8;2;"), count(b"8;5;"))
    }
}
