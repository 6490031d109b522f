//! Picture sizes and the limits every picture, simulation and replay is held to.

use std::str::FromStr;

use crate::error::ValueError;

/// The largest picture side tidepool renders, in pixels.
pub const MAX_SIDE: u32 = 16_384;
/// The most pixels tidepool renders in one picture (including any supersampling).
pub const MAX_PIXELS: u64 = 64 * 1024 * 1024;

/// A picture size in pixels, within `MAX_SIDE` and `MAX_PIXELS`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Size {
    width: u32,
    height: u32,
}

impl Size {
    /// A size, checked against the limits (each side at least 1).
    pub fn new(width: i64, height: i64) -> Result<Size, ValueError> {
        let side = |v: i64, name: &str| -> Result<u32, ValueError> {
            if v < 1 {
                return Err(ValueError::new("size", format!("the {name} must be at least 1 pixel; {HINT}")));
            }
            if v > i64::from(MAX_SIDE) {
                return Err(ValueError::new(
                    "size",
                    format!("the {name} {v} is larger than the limit of {MAX_SIDE} pixels; choose a smaller size"),
                ));
            }
            Ok(v as u32)
        };
        let size = Size { width: side(width, "width")?, height: side(height, "height")? };
        size.check_supersampled(1)?;
        Ok(size)
    }

    #[cfg(any(test, feature = "cli", feature = "testing"))]
    /// A size known at compile time; panics (at compile time in a `const`) when it is invalid.
    pub const fn of(width: u32, height: u32) -> Size {
        assert!(width >= 1 && height >= 1 && width <= MAX_SIDE && height <= MAX_SIDE);
        assert!(width as u64 * height as u64 <= MAX_PIXELS);
        Size { width, height }
    }

    /// Width in pixels.
    pub fn width(self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(self) -> u32 {
        self.height
    }

    /// Pixels in the picture.
    pub fn pixels(self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }

    /// Refuses pictures over `MAX_PIXELS` once supersampled `ssaa x ssaa`.
    pub fn check_supersampled(self, ssaa: u32) -> Result<(), ValueError> {
        let pixels = self.pixels() * u64::from(ssaa) * u64::from(ssaa);
        if pixels > MAX_PIXELS {
            let sampled = if ssaa > 1 { format!(" at {ssaa}x{ssaa} supersampling") } else { String::new() };
            return Err(ValueError::new(
                "size",
                format!(
                    "{self}{sampled} is {:.1} megapixels, over the limit of {} megapixels; choose a smaller size",
                    pixels as f64 / 1048576.0,
                    MAX_PIXELS / 1048576
                ),
            ));
        }
        Ok(())
    }
}

const HINT: &str = "write it as WIDTHxHEIGHT, e.g. 640x360";

impl std::fmt::Display for Size {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}x{}", self.width, self.height)
    }
}

impl FromStr for Size {
    type Err = ValueError;

    /// Parses `WIDTHxHEIGHT` (or `WxH` with a capital X).
    fn from_str(text: &str) -> Result<Size, ValueError> {
        let (w, h) = text
            .trim()
            .split_once(['x', 'X'])
            .ok_or_else(|| ValueError::new("size", format!("expected WIDTHxHEIGHT; {HINT}")))?;
        let number = |s: &str, name: &str| -> Result<i64, ValueError> {
            s.trim()
                .parse()
                .map_err(|_| ValueError::new("size", format!("the {name} '{s}' is not a whole number; {HINT}")))
        };
        // Each side is checked as soon as it is read, so the message names the first problem.
        let width = number(w, "width")?;
        Size::new(width, 1)?;
        Size::new(width, number(h, "height")?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes() {
        assert_eq!("640x360".parse(), Ok(Size::of(640, 360)));
        assert_eq!(" 1X1 ".parse(), Ok(Size::of(1, 1)));
        for bad in ["0x0", "640", "-5x10", "ax3", "16385x1", "100000x100000", "8193x8193", ""] {
            assert!(bad.parse::<Size>().is_err(), "{bad}");
        }
        assert!("16384x4096".parse::<Size>().is_ok());
        assert!("9000x9000".parse::<Size>().unwrap_err().to_string().contains("megapixels"));
        assert_eq!(
            "0x0".parse::<Size>().unwrap_err().to_string(),
            "the width must be at least 1 pixel; write it as WIDTHxHEIGHT, e.g. 640x360"
        );
        assert!(Size::of(4096, 4096).check_supersampled(3).unwrap_err().to_string().contains("supersampling"));
    }

    mod properties {
        use super::*;
        use proptest::prelude::*;

        proptest! {
            /// Sizes within the limits round-trip; anything past a limit is refused.
            #[test]
            fn sizes_round_trip_within_the_limits(w in 1u32..=20_000, h in 1u32..=20_000) {
                let parsed = format!("{w}x{h}").parse::<Size>();
                let fits = w <= MAX_SIDE && h <= MAX_SIDE && u64::from(w) * u64::from(h) <= MAX_PIXELS;
                prop_assert_eq!(parsed.is_ok(), fits);
                if let Ok(size) = parsed {
                    prop_assert_eq!((size.width(), size.height()), (w, h));
                }
            }

            #[test]
            fn no_text_panics(text in "\\PC{0,40}") {
                let _ = text.parse::<Size>();
            }
        }
    }
}
