//! Stones and raindrops: a round dent pressed into the water.

use std::ops::RangeInclusive;
use std::str::FromStr;

use crate::error::ValueError;

/// A stone (or raindrop): every cell with `dx² + dy² < radius²` is set to `-weight`.
///
/// Built only through [`Stone::new`] (or parsed from `X,Y[,R[,W]]`), so every stone has a
/// radius in [`Stone::RADII`] and a weight in [`Stone::WEIGHTS`]: a weight of `i16::MIN` would
/// overflow when negated, a radius of 0 would drop nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Stone {
    pub(crate) x: i32,
    pub(crate) y: i32,
    pub(crate) radius: u32,
    pub(crate) weight: i16,
}

impl Stone {
    /// Radii in cells a stone may have.
    pub const RADII: RangeInclusive<u32> = 1..=1000;
    /// Weights (depths of the dent) a stone may have; the papers' 32..128 looks natural.
    pub const WEIGHTS: RangeInclusive<i16> = 1..=i16::MAX;
    /// The radius of a stone given without one, in cells.
    pub const DEFAULT_RADIUS: u32 = 8;
    /// The weight of a stone given without one.
    pub const DEFAULT_WEIGHT: i16 = 64;

    /// A stone centred at (`x`, `y`) cells (outside the pool is allowed: it is clipped).
    ///
    /// Takes wide integers so that any number a person typed can be checked and named in the
    /// message. Fails when a coordinate does not fit an `i32` or the radius or weight is out of
    /// range.
    pub fn new(x: i64, y: i64, radius: i64, weight: i64) -> Result<Stone, ValueError> {
        let coordinate = |v: i64, name: &str| {
            i32::try_from(v).map_err(|_| {
                ValueError::new(
                    "stone position",
                    format!("the {name} {v} is too far away; stones outside the picture are clipped anyway"),
                )
            })
        };
        let (x, y) = (coordinate(x, "x")?, coordinate(y, "y")?);
        let (r0, r1) = (*Self::RADII.start(), *Self::RADII.end());
        if !(i64::from(r0)..=i64::from(r1)).contains(&radius) {
            return Err(ValueError::new("stone radius", format!("the radius {radius} is outside {r0}..={r1} pixels")));
        }
        let (w0, w1) = (*Self::WEIGHTS.start(), *Self::WEIGHTS.end());
        if !(i64::from(w0)..=i64::from(w1)).contains(&weight) {
            return Err(ValueError::new(
                "stone weight",
                format!("the weight {weight} is outside {w0}..={w1} (32..128 looks natural)"),
            ));
        }
        Ok(Stone { x, y, radius: radius as u32, weight: weight as i16 })
    }

    /// A stone whose radius and weight are brought into range (for sizes computed in code,
    /// such as a doubled stone for a right click).
    pub fn clamped(x: i32, y: i32, radius: u32, weight: i16) -> Stone {
        Stone {
            x,
            y,
            radius: radius.clamp(*Self::RADII.start(), *Self::RADII.end()),
            weight: weight.clamp(*Self::WEIGHTS.start(), *Self::WEIGHTS.end()),
        }
    }

    /// The papers' raindrop: radius 2, weight 64.
    pub fn raindrop(x: i32, y: i32) -> Stone {
        Stone { x, y, radius: 2, weight: 64 }
    }

    /// Centre column in cells; may lie outside the pool.
    pub fn x(&self) -> i32 {
        self.x
    }

    /// Centre row in cells, 0 at the top.
    pub fn y(&self) -> i32 {
        self.y
    }

    /// Radius in cells.
    pub fn radius(&self) -> u32 {
        self.radius
    }

    /// Depth of the dent.
    pub fn weight(&self) -> i16 {
        self.weight
    }
}

impl FromStr for Stone {
    type Err = ValueError;

    /// Parses `X,Y[,RADIUS[,WEIGHT]]` in pixels (defaults: radius 8, weight 64).
    fn from_str(text: &str) -> Result<Stone, ValueError> {
        let parts: Vec<&str> = text.split(',').map(str::trim).collect();
        if !(2..=4).contains(&parts.len()) {
            return Err(ValueError::new(
                "stone",
                "expected X,Y[,RADIUS[,WEIGHT]] in pixels, e.g. 120,80 or 120,80,12,96",
            ));
        }
        let number = |s: &str, name: &str| -> Result<i64, ValueError> {
            s.parse().map_err(|_| {
                ValueError::new("stone", format!("the {name} '{s}' is not a whole number; e.g. 120,80,12,96"))
            })
        };
        let x = number(parts[0], "x")?;
        let y = number(parts[1], "y")?;
        // The coordinates are checked before the radius and weight are parsed, as they read.
        Stone::new(x, y, 1, 1)?;
        let radius = parts.get(2).map_or(Ok(i64::from(Self::DEFAULT_RADIUS)), |s| number(s, "radius"))?;
        Stone::new(x, y, radius, 1)?;
        let weight = parts.get(3).map_or(Ok(i64::from(Self::DEFAULT_WEIGHT)), |s| number(s, "weight"))?;
        Stone::new(x, y, radius, weight)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parsing_and_ranges() {
        assert_eq!("1,2".parse(), Ok(Stone { x: 1, y: 2, radius: 8, weight: 64 }));
        assert_eq!("-5, 7, 3".parse(), Ok(Stone { x: -5, y: 7, radius: 3, weight: 64 }));
        assert_eq!("1,2,1000,32767".parse(), Ok(Stone { x: 1, y: 2, radius: 1000, weight: 32767 }));
        for bad in ["1", "1,2,3,4,5", "1,2,-3", "1,2,0", "1,2,1001", "1,2,3,0", "1,2,3,32768", "a,b", "1.5,2"] {
            assert!(bad.parse::<Stone>().is_err(), "{bad}");
        }
        assert_eq!("1,2,-3".parse::<Stone>().unwrap_err().to_string(), "the radius -3 is outside 1..=1000 pixels");
        assert_eq!(
            "1,2,3,-32768".parse::<Stone>().unwrap_err().to_string(),
            "the weight -32768 is outside 1..=32767 (32..128 looks natural)"
        );
        assert!("9999999999,1".parse::<Stone>().unwrap_err().to_string().contains("too far away"));
        assert_eq!(Stone::new(0, 0, 1, i64::from(i16::MIN)).unwrap_err().what(), "stone weight");
        assert_eq!(Stone::clamped(1, 2, 0, i16::MIN), Stone { x: 1, y: 2, radius: 1, weight: 1 });
    }

    mod properties {
        use super::*;
        use proptest::prelude::*;

        proptest! {
            /// Stones round-trip, with the documented defaults and ranges; no text panics.
            #[test]
            fn stones_round_trip(x in any::<i32>(), y in any::<i32>(), r in -5i64..1100, wt in -5i64..33_000) {
                let parsed = format!("{x},{y},{r},{wt}").parse::<Stone>();
                let valid = (1..=1000).contains(&r) && (1..=32767).contains(&wt);
                prop_assert_eq!(parsed.is_ok(), valid);
                if let Ok(stone) = parsed {
                    prop_assert_eq!(stone, Stone { x, y, radius: r as u32, weight: wt as i16 });
                }
                prop_assert_eq!(format!("{x},{y}").parse(), Ok(Stone { x, y, radius: 8, weight: 64 }));
            }

            #[test]
            fn no_text_panics(text in "\\PC{0,40}") {
                let _ = text.parse::<Stone>();
            }
        }
    }
}
