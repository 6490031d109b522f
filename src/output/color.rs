//! Terminal colours: what the terminal understands, and how a pixel becomes one of its colours.
//!
//! - Detection follows the usual signals: `COLORTERM=truecolor|24bit`, a `TERM` ending in
//!   `-direct`, or the `TERM` of a terminal that always draws 24-bit colour
//!   ([`TRUE_COLOR_TERMS`]: kitty, Ghostty, WezTerm, foot, Alacritty, ...) means 24-bit colour;
//!   a `TERM` naming 256 colours (or any other modern `TERM`) means the xterm 256-colour
//!   palette; `linux`, `vt100`/`vt220`, `ansi` and `dumb` mean 16. SSH does not forward
//!   `COLORTERM` (and Debian's sshd accepts only `LANG`/`LC_*`) while `TERM` does cross, so the
//!   names matter there; the player then also asks the terminal (`play::screen::probe`), and
//!   `--color` always overrides the guess.
//! - The 256-colour palette is matched against the real xterm levels (0, 95, 135, 175, 215, 255
//!   for the cube; 8..=238 step 10 for the grey ramp), with the midpoints as thresholds, not the
//!   divide-by-43 shortcut, which picks the wrong level for a third of the values.
//! - 256 colours are not dithered: looked at in tmux, a Bayer dither turned the pool's flat
//!   tiles into checkerboards and hid the ripples, while the plain nearest colour keeps tiles
//!   flat and ripples readable. 16 colours are too few for that, so there an ordered (Bayer
//!   4x4) dither mixes neighbouring colours. It depends only on the pixel's colour and position,
//!   so still water dithers the same way every frame and the frame-to-frame diff stays empty
//!   (error diffusion would shimmer and defeat the diff).

use crate::output::halfblock::Rgb;

/// How many colours the terminal shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ColorMode {
    /// 24-bit colour: `ESC[38;2;r;g;bm` (what most terminals show today).
    #[default]
    TrueColor,
    /// The xterm 256-colour palette: `ESC[38;5;nm`.
    Palette256,
    /// The 16 basic colours, which users theme: hues are not promised.
    Palette16,
}

/// A colour as sent to the terminal.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Color {
    /// A 24-bit colour.
    Rgb(Rgb),
    /// An entry of the 256-colour palette (0-15 are the basic colours).
    Index(u8),
    /// The terminal's default foreground or background.
    Default,
}

impl Color {
    /// The colour's RGB (xterm's values for palette entries); `None` for the default colour.
    pub fn rgb(self) -> Option<Rgb> {
        match self {
            Color::Rgb(c) => Some(c),
            Color::Index(i) => Some(xterm_256(i)),
            Color::Default => None,
        }
    }

    /// Whether the two colours differ by at most `threshold` in every channel. The default
    /// colour is only close to itself.
    pub fn close_to(self, other: Color, threshold: u8) -> bool {
        if self == other {
            return true;
        }
        if threshold == 0 {
            return false;
        }
        match (self.rgb(), other.rgb()) {
            (Some(a), Some(b)) => a.iter().zip(b).all(|(&x, y)| x.abs_diff(y) <= threshold),
            _ => false,
        }
    }
}

/// `TERM` names of terminals that always draw 24-bit colour (each sets its own name and has
/// no palette-only mode): kitty, Ghostty, WezTerm (with its terminfo installed), foot,
/// Alacritty, Contour, Rio, iTerm2's own entry.
///
/// Not mlterm (`TERM=mlterm`, no `COLORTERM`), though it takes 24-bit colours: it keeps each
/// one that is not near a palette colour in a table of 240 (`MAX_EXT_COLORS` in its
/// `vt_color.c`) and, when the table is full, gives the oldest entry to the new colour, so
/// every cell still showing the old colour changes with it. A grey ramp of 16 steps drew finer
/// than the palette (round 8), but water in 24-bit cells brings thousands of colours a second:
/// Debian's mlterm 3.9 under Xvfb showed patches of lane navy and bright cyan over the tiles
/// and the lanes within 4 s, over the shaped link and through `tidepool serve`, while the same
/// bytes replayed into pyte drew a clean pool. Its probe reads the player's 24-bit colour back
/// as the palette's `38;5;16`, so it gets 256 colours, which it draws exactly;
/// `--color truecolor` still forces 24 bits.
pub const TRUE_COLOR_TERMS: &[&str] = &[
    "xterm-kitty",
    "xterm-ghostty",
    "ghostty",
    "wezterm",
    "foot",
    "foot-extra",
    "alacritty",
    "contour",
    "contour-latest",
    "rio",
    "iterm2",
];

/// `TERM` names of terminals that take 24-bit colours but draw water in them wrongly, so the
/// status line does not suggest `--color truecolor` to them: mlterm (see [`TRUE_COLOR_TERMS`]).
pub const RECYCLED_COLOR_TERMS: &[&str] = &["mlterm", "mlterm-256color"];

/// Bayer 4x4 thresholds, 0..16.
const BAYER4: [[u8; 4]; 4] = [[0, 8, 2, 10], [12, 4, 14, 6], [3, 11, 1, 9], [15, 7, 13, 5]];

/// The xterm cube levels.
const CUBE_LEVELS: [u8; 6] = [0, 95, 135, 175, 215, 255];

impl ColorMode {
    /// The terminal colour for pixel `rgb` at `(x, y)` (the position only steers the dither).
    #[inline]
    pub(crate) fn quantize(self, rgb: Rgb, x: u32, y: u32) -> Color {
        match self {
            ColorMode::TrueColor => Color::Rgb(rgb),
            ColorMode::Palette256 => Color::Index(nearest_256(rgb)),
            ColorMode::Palette16 => Color::Index(nearest_16(dither(rgb, x, y, 64))),
        }
    }

    /// The colour mode the environment suggests (`COLORTERM`, `TERM`), for `--color auto`.
    pub fn detect(colorterm: Option<&str>, term: Option<&str>) -> ColorMode {
        let colorterm = colorterm.unwrap_or("").to_ascii_lowercase();
        let term = term.unwrap_or("").to_ascii_lowercase();
        if colorterm == "truecolor"
            || colorterm == "24bit"
            || term.ends_with("-direct")
            || TRUE_COLOR_TERMS.contains(&term.as_str())
        {
            return ColorMode::TrueColor;
        }
        let basic = ["linux", "vt100", "vt102", "vt220", "ansi", "dumb", "cons25", "xterm-color", "xterm-16color"];
        if term.is_empty() || basic.contains(&term.as_str()) { ColorMode::Palette16 } else { ColorMode::Palette256 }
    }

    /// Whether `--color truecolor` would draw better than what `--color auto` found for `term`:
    /// not for a terminal that recycles its 24-bit colours (`RECYCLED_COLOR_TERMS`: mlterm).
    pub fn truecolor_helps(term: Option<&str>) -> bool {
        !RECYCLED_COLOR_TERMS.contains(&term.unwrap_or("").to_ascii_lowercase().as_str())
    }

    /// The mode's name as `--color` spells it.
    pub fn name(self) -> &'static str {
        match self {
            ColorMode::TrueColor => "truecolor",
            ColorMode::Palette256 => "256",
            ColorMode::Palette16 => "16",
        }
    }
}

/// Adds an ordered-dither offset of up to ±`amplitude`/2 to each channel.
#[inline]
fn dither(rgb: Rgb, x: u32, y: u32, amplitude: i32) -> Rgb {
    let t = i32::from(BAYER4[(y & 3) as usize][(x & 3) as usize]);
    // (t + 0.5) / 16 - 0.5, scaled by the amplitude, in integers.
    let offset = ((2 * t + 1 - 16) * amplitude) / 32;
    rgb.map(|c| (i32::from(c) + offset).clamp(0, 255) as u8)
}

/// The index of the nearest cube level (thresholds at the midpoints between levels).
#[inline]
fn cube_level(v: u8) -> usize {
    match v {
        0..=47 => 0,
        48..=114 => 1,
        115..=154 => 2,
        155..=194 => 3,
        195..=234 => 4,
        _ => 5,
    }
}

fn distance2(a: Rgb, b: Rgb) -> i32 {
    a.iter().zip(b).map(|(&x, y)| (i32::from(x) - i32::from(y)).pow(2)).sum()
}

/// The 256-colour palette entry (16..=255) nearest to `rgb`: the nearest cube colour or the
/// nearest grey of the ramp, whichever is closer.
pub fn nearest_256(rgb: Rgb) -> u8 {
    let [r, g, b] = rgb.map(cube_level);
    let cube = [CUBE_LEVELS[r], CUBE_LEVELS[g], CUBE_LEVELS[b]];
    let cube_index = 16 + 36 * r as u8 + 6 * g as u8 + b as u8;
    let mean = (u32::from(rgb[0]) + u32::from(rgb[1]) + u32::from(rgb[2])) / 3;
    // Grey ramp 232..=255 is 8 + 10k; round to the nearest step.
    let k = ((mean as i32 - 8 + 5) / 10).clamp(0, 23) as u8;
    let grey = 8 + 10 * k;
    if distance2(rgb, [grey; 3]) < distance2(rgb, cube) { 232 + k } else { cube_index }
}

/// The basic colour (0..=15, xterm's default values) nearest to `rgb`.
pub fn nearest_16(rgb: Rgb) -> u8 {
    (0..16u8).min_by_key(|&i| distance2(rgb, xterm_256(i))).unwrap_or(0)
}

/// The RGB of xterm's 256-colour palette entry `index` (the cube levels are 0, 95, 135, 175,
/// 215, 255; the grey ramp runs 8..=238 in steps of 10; 0-15 are xterm's defaults).
pub fn xterm_256(index: u8) -> Rgb {
    const BASIC: [Rgb; 16] = [
        [0, 0, 0],
        [205, 0, 0],
        [0, 205, 0],
        [205, 205, 0],
        [0, 0, 238],
        [205, 0, 205],
        [0, 205, 205],
        [229, 229, 229],
        [127, 127, 127],
        [255, 0, 0],
        [0, 255, 0],
        [255, 255, 0],
        [92, 92, 255],
        [255, 0, 255],
        [0, 255, 255],
        [255, 255, 255],
    ];
    const LEVELS: [u8; 6] = [0, 95, 135, 175, 215, 255];
    match index {
        0..=15 => BASIC[index as usize],
        16..=231 => {
            let i = index - 16;
            [LEVELS[(i / 36) as usize], LEVELS[(i / 6 % 6) as usize], LEVELS[(i % 6) as usize]]
        }
        _ => {
            let v = 8 + 10 * (index - 232);
            [v, v, v]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detection() {
        use ColorMode::*;
        assert_eq!(ColorMode::detect(Some("truecolor"), Some("xterm-256color")), TrueColor);
        assert_eq!(ColorMode::detect(Some("24bit"), None), TrueColor);
        assert_eq!(ColorMode::detect(None, Some("xterm-direct")), TrueColor);
        assert_eq!(ColorMode::detect(None, Some("tmux-256color")), Palette256);
        // Terminals that always draw 24-bit colour, by their own TERM (over SSH COLORTERM is
        // gone, TERM is not).
        assert_eq!(ColorMode::detect(Some(""), Some("xterm-kitty")), TrueColor);
        assert_eq!(ColorMode::detect(None, Some("xterm-ghostty")), TrueColor);
        assert_eq!(ColorMode::detect(None, Some("foot")), TrueColor);
        // mlterm recycles its 24-bit colours (TRUE_COLOR_TERMS): the palette, unless the
        // terminal's answers say otherwise.
        assert_eq!(ColorMode::detect(None, Some("mlterm")), Palette256);
        assert!(!ColorMode::truecolor_helps(Some("mlterm")), "no --color truecolor hint for mlterm");
        assert!(ColorMode::truecolor_helps(Some("xterm-256color")) && ColorMode::truecolor_helps(None));
        assert_eq!(ColorMode::detect(None, Some("xterm-256color")), Palette256);
        assert_eq!(ColorMode::detect(None, Some("linux")), Palette16);
        assert_eq!(ColorMode::detect(None, None), Palette16);
    }

    #[test]
    fn cube_uses_the_real_levels() {
        // 100 is nearer 95 than 135: level 1. The divide-by-43 shortcut would say 2.
        assert_eq!(nearest_256([100, 0, 0]), 16 + 36);
        assert_eq!(nearest_256([114, 0, 0]), 16 + 36);
        assert_eq!(nearest_256([116, 0, 0]), 16 + 72);
        assert_eq!(nearest_256([255, 255, 255]), 231);
        assert_eq!(nearest_256([0, 0, 0]), 16);
        // Every cube colour maps to itself.
        for i in 16..=231u8 {
            assert_eq!(nearest_256(xterm_256(i)), i);
        }
    }

    #[test]
    fn greys_use_the_ramp() {
        assert_eq!(nearest_256([128, 128, 128]), 244, "128 is grey 8 + 10*12");
        assert_eq!(xterm_256(nearest_256([50, 50, 50])), [48, 48, 48]);
        for i in 232..=255u8 {
            assert_eq!(nearest_256(xterm_256(i)), i);
        }
    }

    #[test]
    fn basic_colours_map_to_themselves() {
        for i in 0..16u8 {
            assert_eq!(nearest_16(xterm_256(i)), i);
        }
    }

    #[test]
    fn dither_is_stable_and_bounded() {
        let c = [120, 60, 200];
        for y in 0..8 {
            for x in 0..8 {
                assert_eq!(dither(c, x, y, 24), dither(c, x + 4, y + 4, 24));
                let d = dither(c, x, y, 24);
                assert!(d.iter().zip(c).all(|(&a, b)| a.abs_diff(b) <= 12));
            }
        }
        // A flat colour between two levels dithers to a mix of both.
        let picks: std::collections::BTreeSet<u8> =
            (0..16).map(|i| nearest_256(dither([155, 0, 0], i % 4, i / 4, 24))).collect();
        assert_eq!(picks.len(), 2, "{picks:?}");
    }

    #[test]
    fn closeness() {
        let a = Color::Rgb([10, 20, 30]);
        assert!(a.close_to(Color::Rgb([13, 17, 30]), 3));
        assert!(!a.close_to(Color::Rgb([14, 20, 30]), 3));
        assert!(!a.close_to(Color::Rgb([11, 20, 30]), 0));
        assert!(!a.close_to(Color::Default, 255));
        assert!(Color::Default.close_to(Color::Default, 0));
    }
}
