//! Flags of the ocean: `tidepool render ocean` and `tidepool spectrum`.

use std::path::PathBuf;

use clap::Args;

use crate::sim::looping::LoopPeriod;
use crate::sim::sea_state::beaufort_speed_m_s;
use crate::sim::spectra::swell::{Swell, Swells};
use crate::sim::spectra::{Jonswap, SpectrumChoice, SpectrumChoiceError, SpectrumKind, Spreading};
use crate::{CameraPose, SeaParams, SeaShading};

use crate::cli::error::{Error, Result};

use super::OutputArgs;
use super::values::number;

const OCEAN_EXAMPLES: &str = "\
Examples:
  tidepool render ocean                              # ocean.png, 640x360, a 10 m/s breeze
  tidepool render ocean --beaufort 8 --direction 200 --size 1280x720 --out gale.png
  tidepool render ocean --shading smooth --out smooth.png   # no facets
  tidepool render ocean --out - --size 160x96        # in this terminal
  tidepool render ocean --wind 10 --heightmap sea.npy --size 512x512
  tidepool render ocean --spectrum jonswap --fetch 20 --wind 15 --out fetch.png
  tidepool render ocean --spectrum tma --depth 6 --beaufort 6 --out shallow.png
  tidepool render ocean --beaufort 4 --swell 1.5,12,250 --swell 0.6,16,200
  tidepool render ocean --preset north-atlantic-gale --size 1280x720 --out gale.png
  tidepool render ocean --beaufort 6 --spreading donelan-banner --out db.png
  tidepool render ocean --beaufort 5 --loop 80 --frames 800 --fps 10 --out loop.gif
  tidepool render ocean --beaufort 7 --maps maps/ --size 1024x1024 --extent 500";

const OCEAN_HEIGHTMAP_HELP: &str = "Also write the sea surface height on the --extent patch, sampled at the \
picture's size: FILE.npy (float32 metres, numpy's format) or FILE.png (16-bit grey, value = round(height*100) + \
32768, i.e. centimetres, clamped). Columns run east, row 0 is the north edge.";

/// The wind: a speed or a Beaufort number.
#[derive(Args, Debug, Clone)]
pub struct WindArgs {
    /// Wind speed at 10 m, m/s (0..=60; 0 is a flat calm). [default: 10]
    #[arg(long, value_name = "M/S", value_parser = parse_wind, conflicts_with = "beaufort", allow_negative_numbers = true)]
    pub wind: Option<f64>,

    /// Wind as a Beaufort number 0..=12 (0.15, 0.9, 2.45, 4.4, 6.7, 9.35, 12.3, 15.5, 18.95,
    /// 22.6, 26.45, 30.55, 35 m/s).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u8).range(0..=12))]
    pub beaufort: Option<u8>,
}

impl WindArgs {
    /// The wind speed, m/s.
    pub fn speed_m_s(&self) -> f64 {
        self.given_m_s().unwrap_or(SeaParams::DEFAULT_WIND_M_S)
    }

    /// The wind speed given by `--wind` or `--beaufort`, if any.
    pub fn given_m_s(&self) -> Option<f64> {
        match (self.wind, self.beaufort) {
            (Some(w), _) => Some(w),
            (None, Some(b)) => beaufort_speed_m_s(b),
            (None, None) => None,
        }
    }
}

/// A named sea: the wind, its direction, the wind sea's spectrum and the swells, each
/// documented with its numbers (docs/GUIDE.md, `render ocean --help`). Any flag given as well wins
/// over the preset's value for it (`--swell` replaces the preset's swells).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Preset {
    /// A light air of 2 m/s from 330° over the remains of yesterday's sea: swell 0.4 m,
    /// 9 s from 240°. Glassy crests, no whitecaps.
    CalmMorning,
    /// The north-east trades: 8 m/s from 60° over an unlimited fetch (Pierson-Moskowitz, Hs
    /// 1.57 m), with a 1.2 m, 11 s swell from 30°; scattered whitecaps.
    TradeWind,
    /// A south-westerly gale, 22 m/s from 240° over 500 km of fetch (JONSWAP, gamma 3.3, Hs
    /// about 8 m), with a 3 m, 14 s swell from 270°: streaks and patches of foam.
    NorthAtlanticGale,
    /// A long-period swell on a calm day: 1.5 m/s from 180°, a 1.8 m, 16 s swell from 250°.
    LongSwell,
}

impl Preset {
    /// The wind speed (m/s) and where it comes from (degrees).
    pub fn wind(self) -> (f64, f64) {
        match self {
            Preset::CalmMorning => (2.0, 330.0),
            Preset::TradeWind => (8.0, 60.0),
            Preset::NorthAtlanticGale => (22.0, 240.0),
            Preset::LongSwell => (1.5, 180.0),
        }
    }

    /// The wind sea's spectrum.
    pub fn spectrum(self) -> SpectrumChoice {
        match self {
            Preset::NorthAtlanticGale => {
                SpectrumChoice::Jonswap(Jonswap::new(3.3, Some(500.0)).expect("a valid fetch"))
            }
            _ => SpectrumChoice::PiersonMoskowitz,
        }
    }

    /// The swells as (height m, period s, from degrees).
    pub fn swells(self) -> &'static [(f64, f64, f64)] {
        match self {
            Preset::CalmMorning => &[(0.4, 9.0, 240.0)],
            Preset::TradeWind => &[(1.2, 11.0, 30.0)],
            Preset::NorthAtlanticGale => &[(3.0, 14.0, 270.0)],
            Preset::LongSwell => &[(1.8, 16.0, 250.0)],
        }
    }
}

/// The spectrum's kind and JONSWAP's parameters (`render ocean`, `spectrum` and `play` alike).
#[derive(Args, Debug, Clone)]
pub struct SpectrumKindArgs {
    /// The wave spectrum: pm (Pierson-Moskowitz, fully developed: the papers'), jonswap
    /// (fetch-limited, peak-enhanced) or tma (JONSWAP in shallow water; needs the depth:
    /// --depth, or --sea-depth in play). [default: pm]
    #[arg(long, value_name = "KIND", value_parser = parse_spectrum)]
    pub spectrum: Option<SpectrumKind>,

    /// JONSWAP's peak enhancement gamma, 1..=10 (jonswap and tma). [default: 3.3]
    #[arg(long, value_name = "G", value_parser = parse_plain_number, allow_negative_numbers = true)]
    pub gamma: Option<f64>,

    /// The fetch: how far the wind has blown over open water, km (jonswap and tma; 0.01..=10000).
    /// [default: unlimited, a fully developed peak]
    #[arg(long, value_name = "KM", value_parser = parse_plain_number, allow_negative_numbers = true)]
    pub fetch: Option<f64>,
}

/// Which spectrum the sea follows.
#[derive(Args, Debug, Clone)]
pub struct SpectrumArgs {
    /// The spectrum's kind, gamma and fetch.
    #[command(flatten)]
    pub kind: SpectrumKindArgs,

    /// The water depth for tma, metres (0.5..=10000): shallow water shortens the waves.
    #[arg(long, value_name = "M", value_parser = parse_plain_number, allow_negative_numbers = true)]
    pub depth: Option<f64>,

    /// The flag errors about the depth name (`play` calls it `--sea-depth`).
    #[arg(skip = "--depth")]
    pub depth_flag: &'static str,
}

impl SpectrumArgs {
    /// The checked spectrum (the preset's when no spectrum flag is given); an impossible
    /// combination names the flag to change.
    pub fn choice_or(&self, preset: Option<Preset>) -> Result<SpectrumChoice> {
        let SpectrumKindArgs { spectrum, gamma, fetch } = self.kind;
        match preset {
            Some(p) if spectrum.is_none() && gamma.is_none() && fetch.is_none() && self.depth.is_none() => {
                Ok(p.spectrum())
            }
            _ => self.choice(),
        }
    }

    /// The checked spectrum; an impossible combination names the flag to change.
    pub fn choice(&self) -> Result<SpectrumChoice> {
        let SpectrumKindArgs { spectrum, gamma, fetch } = self.kind;
        SpectrumChoice::new(spectrum.unwrap_or_default(), gamma, fetch, self.depth).map_err(|e| {
            let flag = match &e {
                SpectrumChoiceError::JonswapParameterWithPm if gamma.is_some() => "--gamma",
                SpectrumChoiceError::JonswapParameterWithPm => "--fetch",
                SpectrumChoiceError::DepthWithoutTma | SpectrumChoiceError::TmaWithoutDepth => self.depth_flag,
                SpectrumChoiceError::Value(v) => match v.what() {
                    "peak enhancement gamma" => "--gamma",
                    "fetch" => "--fetch",
                    _ => self.depth_flag,
                },
            };
            Error::arg(flag, e.to_string())
        })
    }
}

/// Swell and the wind sea's spreading (`render ocean`, `spectrum` and `play` alike).
#[derive(Args, Debug, Clone)]
pub struct SwellArgs {
    /// A swell from a distant storm, summed with the wind sea: its significant height (m,
    /// 0.01..=20), peak period (s, 2..=30) and where it comes FROM (degrees clockwise from
    /// north). Repeat for up to 4 swells.
    #[arg(long, value_name = "HEIGHT,PERIOD,DIRECTION", value_parser = parse_swell, allow_hyphen_values = true)]
    pub swell: Vec<Swell>,

    /// How the wind sea spreads over directions: paper (the seed paper's Mitsuyasu mix),
    /// mitsuyasu, hasselmann (cos-2s with the published s(f) laws) or donelan-banner (sech²).
    /// [default: paper]
    #[arg(long, value_name = "LAW", value_parser = parse_spreading)]
    pub spreading: Option<Spreading>,
}

impl SwellArgs {
    /// The swells given, or the preset's when none is.
    pub fn swells_or(&self, preset: Option<Preset>) -> Result<Swells> {
        let list: Vec<Swell> = match preset {
            Some(p) if self.swell.is_empty() => {
                p.swells().iter().map(|&(h, t, d)| Swell::new(h, t, d).expect("a preset's swells are valid")).collect()
            }
            _ => self.swell.clone(),
        };
        Swells::new(&list).map_err(|e| Error::arg("--swell", e.to_string()))
    }
}

/// The sea's shape beyond the wind: spectrum, swell, spreading and choppiness.
#[derive(Args, Debug, Clone)]
pub struct SeaShapeArgs {
    /// The spectrum.
    #[command(flatten)]
    pub spectrum: SpectrumArgs,

    /// Swell and spreading.
    #[command(flatten)]
    pub swell: SwellArgs,

    /// Horizontal displacement of the water, 0..=4: 0 moves it only up and down (round crests),
    /// 1 is the physical displacement (sharp crests, foam where waves fold). [default: 1]
    #[arg(long, value_name = "L", value_parser = parse_choppiness, allow_negative_numbers = true)]
    pub choppiness: Option<f64>,
}

impl SeaShapeArgs {
    /// The sea of these flags under `wind_m_s` from `wind_from_deg`, seeded with `seed`.
    pub fn params(&self, wind_m_s: f64, wind_from_deg: f64, seed: u64) -> Result<SeaParams> {
        self.params_or(None, wind_m_s, wind_from_deg, seed)
    }

    /// [`SeaShapeArgs::params`] with a preset's spectrum and swells where no flag gives them.
    pub fn params_or(&self, preset: Option<Preset>, wind_m_s: f64, wind_from_deg: f64, seed: u64) -> Result<SeaParams> {
        Ok(SeaParams {
            wind_m_s,
            wind_from_deg,
            seed,
            spectrum: self.spectrum.choice_or(preset)?,
            spreading: self.swell.spreading.unwrap_or_default(),
            swells: self.swell.swells_or(preset)?,
            choppiness: self.choppiness.unwrap_or(SeaParams::DEFAULT_CHOPPINESS),
            loop_period: None,
        })
    }
}

/// The ocean's spectrum and choppiness in `play`, where `--depth` is the pool's caustics depth:
/// the sea's depth for tma is `--sea-depth` there.
#[derive(Args, Debug, Clone)]
pub struct PlaySeaArgs {
    /// The ocean's spectrum, gamma and fetch.
    #[command(flatten)]
    pub kind: SpectrumKindArgs,

    /// The ocean's water depth for tma, metres (0.5..=10000).
    #[arg(long = "sea-depth", value_name = "M", value_parser = parse_plain_number, allow_negative_numbers = true)]
    pub sea_depth: Option<f64>,

    /// The ocean's swell and spreading.
    #[command(flatten)]
    pub swell: SwellArgs,

    /// The ocean's horizontal displacement, 0..=4 (0 round crests, 1 physical). [default: 1]
    #[arg(long, value_name = "L", value_parser = parse_choppiness, allow_negative_numbers = true)]
    pub choppiness: Option<f64>,

    /// How the ocean's mesh is lit: smooth (shaded at the vertices and blended across each
    /// triangle) or flat (one colour per spade triangle, the faceted sea of the design; at a
    /// terminal's few pixels, without supersampling, its triangles are a mosaic of blocks).
    #[arg(long, value_name = "MODE", value_parser = parse_shading, default_value_t = PLAY_SHADING)]
    pub shading: SeaShading,
}

impl PlaySeaArgs {
    /// The same flags in `render ocean`'s shape.
    pub fn shape(&self) -> SeaShapeArgs {
        SeaShapeArgs {
            spectrum: SpectrumArgs { kind: self.kind.clone(), depth: self.sea_depth, depth_flag: "--sea-depth" },
            swell: self.swell.clone(),
            choppiness: self.choppiness,
        }
    }
}

/// Checks `--loop SECONDS` for the sea `params` (the shortest loop depends on its longest
/// peak period, the wind sea's or a swell's).
pub fn loop_period(seconds: f64, params: &SeaParams) -> Result<LoopPeriod> {
    LoopPeriod::new(seconds, params.longest_peak_period_s()).map_err(|e| Error::arg("--loop", e.to_string()))
}

/// `tidepool render ocean`.
#[derive(Args, Debug)]
#[command(after_help = OCEAN_EXAMPLES)]
#[command(mut_arg("heightmap", |arg| arg.help(OCEAN_HEIGHTMAP_HELP)))]
pub struct RenderOcean {
    /// A named sea (wind, direction, spectrum and swell; the flags given as well win):
    /// calm-morning (2 m/s from 330°, swell 0.4 m 9 s from 240°), trade-wind (8 m/s from
    /// 60°, swell 1.2 m 11 s from 30°), north-atlantic-gale (22 m/s from 240°, JONSWAP over
    /// 500 km, swell 3 m 14 s from 270°), long-swell (1.5 m/s from 180°, swell 1.8 m 16 s
    /// from 250°).
    #[arg(long, value_name = "NAME", value_enum)]
    pub preset: Option<Preset>,

    /// The wind.
    #[command(flatten)]
    pub wind: WindArgs,

    /// Where the wind comes FROM, degrees clockwise from north (meteorological convention);
    /// the waves travel downwind. [default: 330]
    #[arg(long, value_name = "DEG", value_parser = parse_degrees, allow_hyphen_values = true)]
    pub direction: Option<f64>,

    /// Spectrum and choppiness.
    #[command(flatten)]
    pub shape: SeaShapeArgs,

    /// Repeat exactly every SECONDS (at least 10 of the longest peak period, at most 3600):
    /// frame k of an animation or a map series shows --time + k/--fps, and frame
    /// SECONDS*fps is frame 0 again, bit for bit. A GIF, animated PNG or series of
    /// SECONDS*fps frames loops without a jump.
    #[arg(long = "loop", value_name = "SECONDS", value_parser = parse_plain_number, allow_negative_numbers = true)]
    pub loop_seconds: Option<f64>,

    /// Write tileable maps for game engines into this folder (created if missing) instead of a
    /// picture: height.npy/.png, displacement.npy/.png, normal.png, foam.png of a periodic
    /// patch --extent metres across at --size (square); with --frames, a numbered series.
    #[arg(long, value_name = "DIR")]
    pub maps: Option<PathBuf>,

    /// The maps' files: png (the .npy and PNG files above) or exr (those, and beside them
    /// height.exr, displacement.exr, normal.exr and foam.exr in half floats: metres and unit
    /// vectors as Blender bakes and Unreal and Unity import them). [default: png]
    #[arg(long, value_name = "FORMAT", value_enum, requires = "maps")]
    pub map_format: Option<MapFormat>,

    /// The sun: azimuth (degrees clockwise from north) and elevation (0..=90 degrees).
    #[arg(long, value_name = "AZ,EL", default_value = "15,22", value_parser = parse_sun, allow_hyphen_values = true)]
    pub sun: (f64, f64),

    /// How the mesh is lit: flat (one colour per spade triangle, the faceted sea of the design;
    /// --ssaa averages its far crests) or smooth (shaded at the vertices and blended across
    /// each triangle). The sun's glitter and the foam are drawn per pixel in both.
    /// [default: flat for pictures, smooth for text]
    #[arg(long, value_name = "MODE", value_parser = parse_shading)]
    pub shading: Option<SeaShading>,

    /// The camera: height above the sea in metres (0.5..=10000), tilt below the horizontal in
    /// degrees (-45..=89), horizontal field of view in degrees (5..=150) and heading in
    /// degrees clockwise from north. [default: 25,8,70,0]
    #[arg(long, value_name = "H,PITCH,HFOV[,HEADING]", value_parser = parse_camera, allow_hyphen_values = true)]
    pub camera: Option<CameraPose>,

    /// Physical time in seconds: the sea at t and t + 1 is one second apart.
    #[arg(long, value_name = "SECONDS", default_value_t = 0.0, value_parser = parse_time, allow_hyphen_values = true)]
    pub time: f64,

    /// A PNG or JPEG stretched over the sea, one copy every 48 m. [default: the built-in one]
    #[arg(long, value_name = "FILE")]
    pub texture: Option<PathBuf>,

    /// Supersampling: render N times larger in each direction and average down (1..=4).
    /// [default: 2 for PNG, 1 for text]
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4))]
    pub ssaa: Option<u32>,

    /// East-west size of the --heightmap patch in metres (it spans extent·H/W north-south,
    /// centred under the camera) [default: 8 peak wavelengths], or the side of the --maps
    /// patch (1..=100000) [default: 10 peak wavelengths].
    #[arg(long, value_name = "METRES", value_parser = parse_extent)]
    pub extent: Option<f64>,

    /// Size, seed, output file and format, heightmap, stats.
    #[command(flatten)]
    pub output: OutputArgs,

    /// An animation instead of one picture (it starts at --time).
    #[command(flatten)]
    pub animation: super::AnimationArgs,
}

/// The files `--maps` writes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum MapFormat {
    /// Float .npy and 16-bit and 8-bit PNG.
    #[default]
    Png,
    /// Those, and half-float OpenEXR.
    Exr,
}

/// `tidepool spectrum`.
#[derive(Args, Debug)]
pub struct SpectrumCommand {
    /// A named sea, as for `render ocean`.
    #[arg(long, value_name = "NAME", value_enum)]
    pub preset: Option<Preset>,

    /// The wind.
    #[command(flatten)]
    pub wind: WindArgs,

    /// Where the wind comes FROM, degrees (the swells' directions are plotted against it).
    /// [default: 330]
    #[arg(long, value_name = "DEG", value_parser = parse_degrees, allow_hyphen_values = true)]
    pub direction: Option<f64>,

    /// The spectrum.
    #[command(flatten)]
    pub spectrum: SpectrumArgs,

    /// Swell and spreading.
    #[command(flatten)]
    pub swell: SwellArgs,

    /// Print JSON instead of `name: value unit` lines.
    #[arg(long)]
    pub json: bool,

    /// Also plot E(f) and the spreading D(theta) at the peak into this PNG file.
    #[arg(long, value_name = "FILE.png")]
    pub out: Option<PathBuf>,
}

/// Parses `pm`, `jonswap` or `tma`.
pub fn parse_spectrum(text: &str) -> Result<SpectrumKind, String> {
    text.parse().map_err(|e: crate::ValueError| e.to_string())
}

/// `play`'s shading: its frames are a terminal's few pixels without supersampling, where flat
/// triangles are a mosaic of blocks (docs/sea/README.md).
pub const PLAY_SHADING: SeaShading = SeaShading::Smooth;

/// `render ocean`'s shading for an output `format`: flat (the design's faceted sea) for
/// pictures, which are supersampled, smooth for text, which is not.
pub fn default_shading(format: super::Format) -> SeaShading {
    if format == super::Format::Png { SeaShading::Flat } else { SeaShading::Smooth }
}

/// Parses `flat` or `smooth`.
pub fn parse_shading(text: &str) -> Result<SeaShading, String> {
    text.parse().map_err(|e: crate::ValueError| e.to_string())
}

/// Parses a spreading law.
pub fn parse_spreading(text: &str) -> Result<Spreading, String> {
    text.parse().map_err(|e: crate::ValueError| e.to_string())
}

/// Parses `HEIGHT,PERIOD,DIRECTION`.
pub fn parse_swell(text: &str) -> Result<Swell, String> {
    text.parse().map_err(|e: crate::ValueError| e.to_string())
}

/// The wind speed and direction of a command line with an optional preset: each flag given
/// wins over the preset's value, the preset's over the defaults.
pub fn wind_of(preset: Option<Preset>, wind: &WindArgs, direction: Option<f64>) -> (f64, f64) {
    let (preset_speed, preset_from) =
        preset.map_or((SeaParams::DEFAULT_WIND_M_S, SeaParams::DEFAULT_WIND_FROM_DEG), Preset::wind);
    (wind.given_m_s().unwrap_or(preset_speed), direction.unwrap_or(preset_from))
}

/// Parses any number, `inf` and `nan` included: the library's checks word the refusal.
fn parse_plain_number(text: &str) -> Result<f64, String> {
    text.trim().parse::<f64>().map_err(|_| format!("'{text}' is not a number"))
}

/// Parses a choppiness, 0..=4.
pub fn parse_choppiness(text: &str) -> Result<f64, String> {
    SeaParams::check_choppiness(parse_plain_number(text)?).map_err(|e| e.to_string())
}

fn in_range(v: f64, lo: f64, hi: f64, what: &str, unit: &str) -> Result<f64, String> {
    if v < lo || v > hi {
        return Err(format!("the {what} {v} is outside {lo}..={hi} {unit}"));
    }
    Ok(v)
}

/// Parses a wind speed 0..=60 m/s.
pub fn parse_wind(text: &str) -> Result<f64, String> {
    super::values::parse_sea_wind(text)
}

/// Parses an angle in degrees, wrapped into 0..360.
pub fn parse_degrees(text: &str) -> Result<f64, String> {
    Ok(number(text, "direction", "270 (a west wind)")?.rem_euclid(360.0))
}

/// Parses `AZ,EL`.
pub fn parse_sun(text: &str) -> Result<(f64, f64), String> {
    let parts: Vec<&str> = text.split(',').collect();
    let [az, el] = parts.as_slice() else {
        return Err("expected AZIMUTH,ELEVATION in degrees, e.g. 15,22".into());
    };
    let az = number(az, "sun azimuth", "15,22")?.rem_euclid(360.0);
    let el = number(el, "sun elevation", "15,22")?;
    let el = in_range(el, 0.0, 90.0, "sun elevation", "degrees (the sun must be above the horizon)")?;
    Ok((az, el))
}

/// Parses `H,PITCH,HFOV[,HEADING]`.
pub fn parse_camera(text: &str) -> Result<CameraPose, String> {
    let parts: Vec<&str> = text.split(',').collect();
    if !(3..=4).contains(&parts.len()) {
        return Err("expected HEIGHT_M,PITCH_DEG_DOWN,HFOV_DEG[,HEADING_DEG], e.g. 25,8,70 or 25,8,70,180".into());
    }
    let ex = "25,8,70,180";
    let height = in_range(number(parts[0], "camera height", ex)?, 0.5, 10_000.0, "camera height", "m")?;
    let pitch = in_range(number(parts[1], "camera pitch", ex)?, -45.0, 89.0, "camera pitch", "degrees down")?;
    let hfov = in_range(number(parts[2], "field of view", ex)?, 5.0, 150.0, "field of view", "degrees")?;
    let heading = match parts.get(3) {
        Some(h) => number(h, "camera heading", ex)?.rem_euclid(360.0),
        None => CameraPose::DEFAULT.heading_deg,
    };
    Ok(CameraPose {
        height_m: height,
        pitch_down_deg: pitch,
        hfov_deg: hfov,
        heading_deg: heading,
        ..CameraPose::DEFAULT
    })
}

/// Parses a time in seconds (|t| <= 1e7, about four months).
pub fn parse_time(text: &str) -> Result<f64, String> {
    let v = number(text, "time", "12.5")?;
    in_range(v, -1e7, 1e7, "time", "seconds")
}

/// Parses a heightmap extent, 0.01..=1e6 m.
pub fn parse_extent(text: &str) -> Result<f64, String> {
    let v = number(text, "extent", "800")?;
    in_range(v, 0.01, 1e6, "extent", "metres")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn winds() {
        assert_eq!(parse_wind("0"), Ok(0.0));
        assert_eq!(parse_wind(" 60 "), Ok(60.0));
        for bad in ["-1", "60.5", "nan", "inf", "fast"] {
            assert!(parse_wind(bad).is_err(), "{bad}");
        }
        let w = WindArgs { wind: None, beaufort: Some(8) };
        assert_eq!(w.speed_m_s(), 18.95);
        assert_eq!(WindArgs { wind: None, beaufort: None }.speed_m_s(), SeaParams::DEFAULT_WIND_M_S);
    }

    #[test]
    fn angles_sun_and_camera() {
        assert_eq!(parse_degrees("-90"), Ok(270.0));
        assert_eq!(parse_degrees("720"), Ok(0.0));
        assert_eq!(parse_sun("370,10"), Ok((10.0, 10.0)));
        for bad in ["10", "10,-5", "10,91", "a,b", "1,2,3"] {
            assert!(parse_sun(bad).is_err(), "{bad}");
        }
        let c = parse_camera("40,10,60").unwrap();
        assert_eq!((c.height_m, c.pitch_down_deg, c.hfov_deg, c.heading_deg), (40.0, 10.0, 60.0, 0.0));
        assert_eq!(parse_camera("40,10,60,-90").unwrap().heading_deg, 270.0);
        for bad in ["0,10,60", "40,90,60", "40,10,170", "40,10", "40,10,60,1,2", "x,1,2"] {
            assert!(parse_camera(bad).is_err(), "{bad}");
        }
        assert!(parse_camera("0,10,60").unwrap_err().contains("camera height"));
    }

    #[test]
    fn times_and_extents() {
        assert_eq!(parse_time("-3.5"), Ok(-3.5));
        assert!(parse_time("1e9").is_err());
        assert!(parse_extent("0").is_err());
        assert_eq!(parse_extent("800"), Ok(800.0));
    }
}
