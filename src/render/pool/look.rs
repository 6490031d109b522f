//! How the pool is drawn: how far the slope displaces the floor, where the sun is, light and
//! caustics on or off. Each value checks itself ([`Refraction::fixed`], [`Sun::new`], and
//! `FromStr` for both), so the command line and the replay reader share the checks.

use std::str::FromStr;

use crate::error::ValueError;
use crate::render::caustics::CausticsLook;

/// How strongly the surface slope displaces the background: a fixed factor (1.0 is the papers'
/// displacement, 0 shows the floor undistorted) or [`Refraction::AUTO`], which scales with the
/// picture. Fixed factors are finite and within [`Refraction::MAX_FACTOR`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refraction {
    /// The fixed factor, or `None` for automatic.
    fixed: Option<f32>,
}

impl Refraction {
    /// Scale with the picture: `min(width, height) / 720`, between 0.15 and 1.
    pub const AUTO: Refraction = Refraction { fixed: None };
    /// The side (in pixels) at which `AUTO` gives the papers' factor of 1.
    pub const AUTO_REFERENCE_SIDE: f32 = 720.0;
    /// The largest fixed factor.
    pub const MAX_FACTOR: f32 = 100.0;

    /// A fixed factor, `0..=`[`Refraction::MAX_FACTOR`].
    pub fn fixed(factor: f32) -> Result<Refraction, ValueError> {
        Self::checked(factor, &factor.to_string())
    }

    fn checked(factor: f32, shown: &str) -> Result<Refraction, ValueError> {
        if !factor.is_finite() || !(0.0..=Self::MAX_FACTOR).contains(&factor) {
            return Err(ValueError::new(
                "refraction",
                format!("'{shown}' must be between 0 and 100 (1.0 is the papers' factor), or 'auto'"),
            ));
        }
        Ok(Refraction { fixed: Some(factor) })
    }

    /// The fixed factor, or `None` for automatic.
    pub fn fixed_factor(self) -> Option<f32> {
        self.fixed
    }

    /// The factor used for a `width x height` picture.
    pub fn factor(self, width: u32, height: u32) -> f32 {
        match self.fixed {
            Some(f) => f,
            None => (width.min(height) as f32 / Self::AUTO_REFERENCE_SIDE).clamp(0.15, 1.0),
        }
    }
}

impl std::fmt::Display for Refraction {
    /// `auto` or the factor: the form [`Refraction::from_str`] reads back.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.fixed {
            None => f.write_str("auto"),
            Some(v) => write!(f, "{v}"),
        }
    }
}

impl FromStr for Refraction {
    type Err = ValueError;

    /// Parses a factor (finite, `0..=100`) or `auto`.
    fn from_str(text: &str) -> Result<Refraction, ValueError> {
        let text = text.trim();
        if text.eq_ignore_ascii_case("auto") {
            return Ok(Refraction::AUTO);
        }
        let v: f32 = text
            .parse()
            .map_err(|_| ValueError::new("refraction", format!("'{text}' is neither a number nor 'auto'")))?;
        Self::checked(v, text)
    }
}

/// Where the sun is: azimuth clockwise from north (the top of the picture), elevation above
/// the horizon, both in degrees. The azimuth is kept in `0..360`, the elevation in `0..=90`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sun {
    azimuth_deg: f32,
    elevation_deg: f32,
}

impl Default for Sun {
    /// High in the north-west: light from the upper left, as pictures are usually lit.
    fn default() -> Self {
        Sun { azimuth_deg: 315.0, elevation_deg: 60.0 }
    }
}

impl Sun {
    /// A sun at any finite azimuth (wrapped to `0..360`) and an elevation in `0..=90` degrees.
    pub fn new(azimuth_deg: f32, elevation_deg: f32) -> Result<Sun, ValueError> {
        let hint = SUN_HINT;
        if !azimuth_deg.is_finite() {
            return Err(ValueError::new("sun", format!("the azimuth must be finite; {hint}")));
        }
        if !elevation_deg.is_finite() {
            return Err(ValueError::new("sun", format!("the elevation must be finite; {hint}")));
        }
        if !(0.0..=90.0).contains(&elevation_deg) {
            return Err(ValueError::new(
                "sun",
                format!("the elevation {elevation_deg} is outside 0..=90 degrees; {hint}"),
            ));
        }
        Ok(Sun { azimuth_deg: azimuth_deg.rem_euclid(360.0), elevation_deg })
    }

    /// Degrees clockwise from north (0 = top of the picture, 90 = right).
    pub fn azimuth_deg(self) -> f32 {
        self.azimuth_deg
    }

    /// Degrees above the horizon.
    pub fn elevation_deg(self) -> f32 {
        self.elevation_deg
    }

    /// The unit vector towards the sun in picture coordinates (x right, y down, z up).
    pub fn direction(self) -> [f32; 3] {
        let (az, el) = (self.azimuth_deg.to_radians(), self.elevation_deg.to_radians());
        [az.sin() * el.cos(), -az.cos() * el.cos(), el.sin()]
    }
}

const SUN_HINT: &str = "write it as AZIMUTH,ELEVATION in degrees, e.g. 315,60";

impl std::fmt::Display for Sun {
    /// `AZIMUTH,ELEVATION`: the form [`Sun::from_str`] reads back.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{},{}", self.azimuth_deg, self.elevation_deg)
    }
}

impl FromStr for Sun {
    type Err = ValueError;

    /// Parses `AZIMUTH,ELEVATION` in degrees.
    fn from_str(text: &str) -> Result<Sun, ValueError> {
        let hint = SUN_HINT;
        let (az, el) =
            text.split_once(',').ok_or_else(|| ValueError::new("sun", format!("expected two numbers; {hint}")))?;
        let number = |s: &str, name: &str| -> Result<f32, ValueError> {
            s.trim()
                .parse()
                .map_err(|_| ValueError::new("sun", format!("the {name} '{}' is not a number; {hint}", s.trim())))
        };
        let azimuth = number(az, "azimuth")?;
        if !azimuth.is_finite() {
            return Err(ValueError::new("sun", format!("the azimuth must be finite; {hint}")));
        }
        Sun::new(azimuth, number(el, "elevation")?)
    }
}

/// How the pool is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoolLook {
    /// Background displacement per unit of slope.
    pub refraction: Refraction,
    /// Light the slopes from the sun, with glints on crests facing it.
    pub shading: bool,
    /// Caustics on the floor; `None` for none.
    pub caustics: Option<CausticsLook>,
    /// Where the light comes from.
    pub sun: Sun,
}

impl Default for PoolLook {
    fn default() -> Self {
        PoolLook {
            refraction: Refraction::AUTO,
            shading: true,
            caustics: Some(CausticsLook::default()),
            sun: Sun::default(),
        }
    }
}
