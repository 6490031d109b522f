//! Flags of the lake: `tidepool render lake`.

use clap::{Args, ValueEnum};

use crate::NoiseKind;

use super::OutputArgs;
use super::values::{parse_lake_wind, parse_octaves, parse_persistence};

const LAKE_EXAMPLES: &str = "\
Examples:
  tidepool render lake                                 # lake.png, 640x360, a 3 m/s breeze
  tidepool render lake --wind 0 --size 1280x720 --out calm.png     # a mirror
  tidepool render lake --wind 7 --time 2.5 --out windy.png
  tidepool render lake --noise gradient --octaves 7 --persistence 0.6 --out rough.png
  tidepool render lake --out - --size 160x96           # in this terminal
  tidepool render lake --wind 5 --heightmap lake.npy --size 600x300
  tidepool render lake --wind 4 --frames 90 --fps 30 --size 480x270 --out breeze.gif";

const LAKE_HEIGHTMAP_HELP: &str = "Also write the water's height, sampled at the picture's size on square \
cells over the lake from the far shore (row 0, 300 m north) to the near shore, centred on the camera: FILE.npy \
(float32 metres) or FILE.png (16-bit grey, value = round(height*1000) + 32768, i.e. millimetres).";

/// `--noise`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum NoiseArg {
    /// Hashed lattice values, smoothed 3x3 and cosine-interpolated (the paper's).
    Value,
    /// Hashed lattice gradients (the paper's figure 1).
    Gradient,
}

impl From<NoiseArg> for NoiseKind {
    fn from(arg: NoiseArg) -> NoiseKind {
        match arg {
            NoiseArg::Value => NoiseKind::Value,
            NoiseArg::Gradient => NoiseKind::Gradient,
        }
    }
}

/// `tidepool render lake`.
#[derive(Args, Debug)]
#[command(after_help = LAKE_EXAMPLES)]
#[command(mut_arg("heightmap", |arg| arg.help(LAKE_HEIGHTMAP_HELP)))]
pub struct RenderLake {
    /// Wind speed at 10 m, m/s (0..=30): 0 is a mirror calm; the ripples' height and length
    /// follow the wind over the lake's 300 m fetch.
    #[arg(long, value_name = "M/S", default_value = "3", value_parser = parse_lake_wind, allow_hyphen_values = true)]
    pub wind: f64,

    /// Octaves of noise summed (1..=12), each half the size of the one before.
    #[arg(long, value_name = "N", default_value = "5", value_parser = parse_octaves, allow_hyphen_values = true)]
    pub octaves: u32,

    /// Amplitude ratio from one octave to the next (0..=1): higher is rougher, 0.5 follows the
    /// k^-3 slope of real wind ripples.
    #[arg(long, value_name = "P", default_value = "0.5", value_parser = parse_persistence, allow_hyphen_values = true)]
    pub persistence: f64,

    /// The lattice noise: hashed values (smoothed, cosine-interpolated) or hashed gradients.
    #[arg(long, value_enum, value_name = "KIND", default_value = "value")]
    pub noise: NoiseArg,

    /// Time in seconds: the water at t and t + 1 is one second apart.
    #[arg(long, value_name = "SECONDS", default_value_t = 0.0, value_parser = super::ocean::parse_time, allow_hyphen_values = true)]
    pub time: f64,

    /// Supersampling: render N times larger in each direction and average down (1..=4).
    /// [default: 2 for PNG, 1 for text]
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=4))]
    pub ssaa: Option<u32>,

    /// Size, seed, output file and format, heightmap, stats.
    #[command(flatten)]
    pub output: OutputArgs,

    /// An animation instead of one picture (it starts at --time).
    #[command(flatten)]
    pub animation: super::AnimationArgs,
}
