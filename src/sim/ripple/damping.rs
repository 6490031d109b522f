//! Damping: how fast the pool's waves lose energy.

use std::str::FromStr;

use crate::error::ValueError;

/// How fast waves lose energy: `v -= v >> shift` after every step, or no damping.
///
/// Built only from a shift in `1..=`[`Damping::MAX_SHIFT`] or as [`Damping::OFF`]: a shift of
/// 0 would flatten the water every step and one of 16 or more would damp nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Damping {
    /// The shift, or 0 for no damping.
    shift: u8,
}

impl Damping {
    /// No damping: waves ring until the walls' rounding eats them.
    pub const OFF: Damping = Damping { shift: 0 };
    /// The papers' damping, 1/32 per step.
    pub const PAPERS: Damping = Damping { shift: 5 };
    /// The largest shift; `v >> 16` would be 0 or -1 for every `i16`, i.e. no damping at all.
    pub const MAX_SHIFT: u8 = 15;

    /// Losing `1 / 2^shift` of the amplitude per step; fails outside `1..=15`.
    pub fn from_shift(shift: u8) -> Result<Damping, ValueError> {
        match shift {
            0 => Err(ValueError::new(
                "damping",
                "a shift of 0 would flatten the water every step; use 'off' for no damping",
            )),
            s if s > Self::MAX_SHIFT => Err(ValueError::new(
                "damping",
                format!(
                    "the shift {s} is outside 1..={} (5 is the papers'); use 'off' for no damping",
                    Self::MAX_SHIFT
                ),
            )),
            s => Ok(Damping { shift: s }),
        }
    }

    /// The shift, or `None` for no damping.
    pub fn shift(self) -> Option<u8> {
        (self.shift > 0).then_some(self.shift)
    }

    /// One step weaker (larger shift), saturating at [`Damping::OFF`].
    pub fn weaker(self) -> Damping {
        match self.shift() {
            Some(s) if s < Self::MAX_SHIFT => Damping { shift: s + 1 },
            _ => Damping::OFF,
        }
    }

    /// One step stronger (smaller shift), saturating at shift 1.
    pub fn stronger(self) -> Damping {
        match self.shift() {
            None => Damping { shift: Self::MAX_SHIFT },
            Some(s) => Damping { shift: s.saturating_sub(1).max(1) },
        }
    }
}

impl std::fmt::Display for Damping {
    /// `off`, or the shift (`5`): the form [`Damping::from_str`] reads back.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.shift() {
            None => f.write_str("off"),
            Some(s) => write!(f, "{s}"),
        }
    }
}

impl FromStr for Damping {
    type Err = ValueError;

    /// Parses `SHIFT` (1..=15) or `off` (also `none`).
    fn from_str(text: &str) -> Result<Damping, ValueError> {
        let text = text.trim();
        if text.eq_ignore_ascii_case("off") || text.eq_ignore_ascii_case("none") {
            return Ok(Damping::OFF);
        }
        let shift: i64 = text
            .parse()
            .map_err(|_| ValueError::new("damping", format!("'{text}' is neither a shift 1..=15 nor 'off'")))?;
        match u8::try_from(shift) {
            Ok(s) => Damping::from_shift(s),
            Err(_) => Err(ValueError::new(
                "damping",
                format!("the shift {shift} is outside 1..=15 (5 is the papers'); use 'off' for no damping"),
            )),
        }
    }
}

impl serde::Serialize for Damping {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

impl<'de> serde::Deserialize<'de> for Damping {
    /// The string form (`"5"`, `"off"`); a number is read as a shift too.
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Damping, D::Error> {
        let text = crate::numbers::text_or_number(deserializer)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shifts_parse_and_step() {
        assert_eq!("off".parse(), Ok(Damping::OFF));
        assert_eq!("5".parse(), Ok(Damping::PAPERS));
        assert_eq!("15".parse::<Damping>().map(Damping::shift), Ok(Some(15)));
        assert!("0".parse::<Damping>().unwrap_err().to_string().contains("use 'off'"));
        assert!("16".parse::<Damping>().is_err() && "-1".parse::<Damping>().is_err());
        assert_eq!("x".parse::<Damping>().unwrap_err().to_string(), "'x' is neither a shift 1..=15 nor 'off'");
        assert_eq!(Damping::from_shift(1).unwrap().stronger().shift(), Some(1));
        assert_eq!(Damping::from_shift(15).unwrap().weaker(), Damping::OFF);
        assert_eq!(Damping::OFF.weaker(), Damping::OFF);
        assert_eq!(Damping::OFF.stronger().shift(), Some(15));
        assert!(Damping::from_shift(0).is_err() && Damping::from_shift(16).is_err());
        for d in ["off", "1", "5", "15"] {
            assert_eq!(d.parse::<Damping>().unwrap().to_string(), d);
        }
    }
}
