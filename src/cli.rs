//! The command line: clap definitions (raw flags) and the parsers that validate each value.
//!
//! Every value parser returns a message that names what is wrong and how to fix it; clap puts
//! the flag in front (`invalid value '0x0' for '--size <WxH>': ...`) and exits with status 2.
//! Checks that involve several flags live in [`crate::commands`].

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

pub mod ocean;

use crate::sim::ripple::{Damping, Stone};

/// The largest picture side tidepool renders.
pub const MAX_SIDE: u32 = 16_384;
/// The most pixels tidepool renders in one picture (including any supersampling).
pub const MAX_PIXELS: u64 = 64 * 1024 * 1024;

const ABOUT: &str = "Water you can play with in any terminal: a ripple pool, an ocean and a lake, \
simulated and drawn on the CPU.";

const EXAMPLES: &str = "\
Examples:
  tidepool render pool                          # pool.png, 640x360, the default stones
  tidepool render pool --out pool.ans           # half-block text; `cat pool.ans` shows it
  tidepool render pool --out - --size 120x60    # straight to this terminal
  tidepool render pool --stone 100,80,12,96 --stone 300,200 --steps 150 --out two.png";

/// tidepool's command line.
#[derive(Parser, Debug)]
#[command(name = "tidepool", version, about = ABOUT, after_help = EXAMPLES)]
pub struct Cli {
    /// What to do; without one, tidepool shows how to get started.
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a scene headless to a PNG file or half-block text (no terminal needed).
    Render(RenderCommand),
    /// Print the Pierson–Moskowitz sea state of a wind (peak, Hs, Beaufort, WMO code), or plot it.
    Spectrum(ocean::SpectrumCommand),
    /// Measure how fast this machine runs tidepool, stage by stage (a few seconds).
    Bench(BenchArgs),
}

/// `tidepool bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Seconds to spend on each workload (the median of the runs is reported).
    #[arg(long, value_name = "S", default_value_t = 0.4, value_parser = parse_seconds)]
    pub seconds: f64,

    /// The terminal picture to measure, in pixels (columns x 2 per row).
    #[arg(long, value_name = "WxH", default_value = "160x94", value_parser = parse_size)]
    pub terminal: Size,
}

/// `tidepool render <scene>`.
#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct RenderCommand {
    /// The scene to render.
    #[command(subcommand)]
    pub scene: RenderScene,
}

/// The scenes `render` knows.
#[derive(Subcommand, Debug)]
pub enum RenderScene {
    /// The ripple pool: stones and rain on water over a tiled floor.
    Pool(RenderPool),
    /// The ocean: a wind-driven Pierson–Moskowitz sea under a sky, as a flat-shaded mesh.
    Ocean(ocean::RenderOcean),
}

/// `tidepool render pool`.
#[derive(Args, Debug)]
#[command(after_help = EXAMPLES)]
pub struct RenderPool {
    /// Simulation steps before the picture is taken; waves travel about 0.7 px per step.
    /// [default: 90; fewer (at least 30) when the smaller side is under 360 pixels]
    #[arg(long, value_name = "N", allow_negative_numbers = true)]
    pub steps: Option<u64>,

    /// Drop a stone at step 0: centre X,Y in pixels (outside the picture is clipped), radius R
    /// in pixels (1..=1000, default 8) and weight W (1..=32767, default 64). Repeat the flag for
    /// more stones; any explicit stone replaces the default ones.
    #[arg(long = "stone", value_name = "X,Y[,R[,W]]", value_parser = parse_stone, allow_hyphen_values = true)]
    pub stones: Vec<Stone>,

    /// The water.
    #[command(flatten)]
    pub pool: PoolArgs,

    /// The picture and where it goes.
    #[command(flatten)]
    pub output: OutputArgs,
}

/// Flags every rendered scene takes.
#[derive(Args, Debug, Clone)]
pub struct OutputArgs {
    /// Picture size in pixels, WIDTHxHEIGHT (each side 1..=16384, at most 64 megapixels).
    /// [default: 640x360 for PNG; for text, the terminal's size when writing to it, else 80x48]
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    pub size: Option<Size>,

    /// Seed for everything random (rain, phases); the same seed and flags give the same bytes.
    #[arg(long, value_name = "N", default_value_t = 1, allow_negative_numbers = true)]
    pub seed: u64,

    /// Output file, or - for standard output. The format follows the extension: .png, or
    /// .ans/.txt for half-block text. [default: <scene>.png, or <scene>.ans with --format ansi]
    #[arg(long, value_name = "FILE|-")]
    pub out: Option<PathBuf>,

    /// Output format; overrides the extension. Standard output defaults to ansi.
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub format: Option<Format>,

    /// Also write the height field: FILE.npy (float32, numpy's format) or FILE.png (16-bit grey,
    /// value = height + 32768; pool heights are raw amplitudes). Row 0 is the top of the picture.
    #[arg(long, value_name = "FILE")]
    pub heightmap: Option<PathBuf>,

    /// Print how long each stage took (simulation, picture, encoding, writing) to standard
    /// error, with throughput.
    #[arg(long)]
    pub stats: bool,
}

/// Flags of the ripple pool, shared by `render pool` and the player.
#[derive(Args, Debug, Clone)]
pub struct PoolArgs {
    /// Raindrops per simulation step on average (radius 2, weight 64), a number >= 0.
    /// [default: 0 for render]
    #[arg(long, value_name = "RATE", value_parser = parse_rate, allow_negative_numbers = true)]
    pub rain: Option<f64>,

    /// Damping: each step the water loses 1/2^SHIFT of its amplitude (SHIFT 1..=15; higher
    /// calms more slowly), or `off` for none.
    #[arg(long, value_name = "SHIFT|off", default_value = "5", value_parser = parse_damping, allow_negative_numbers = true)]
    pub damping: Damping,

    /// How far the surface slope displaces the floor: 1.0 is the papers' factor, 0 shows the
    /// floor undistorted, `auto` scales with the picture (its smaller side / 720, between 0.15
    /// and 1) so ripples read as ripples at every size.
    #[arg(long, value_name = "F|auto", default_value = "auto", value_parser = parse_refraction, allow_negative_numbers = true)]
    pub refraction: crate::render::pool::Refraction,

    /// Do not light the slopes (by default slopes facing the upper left are brightened).
    #[arg(long)]
    pub no_shading: bool,

    /// The pool floor: a PNG or JPEG, scaled to cover the picture (aspect kept, centred).
    /// [default: the built-in tiled floor]
    #[arg(long, value_name = "FILE")]
    pub background: Option<PathBuf>,
}

/// A picture size in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Size {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

impl std::fmt::Display for Size {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}x{}", self.width, self.height)
    }
}

/// What kind of bytes to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// A PNG image.
    Png,
    /// Truecolor half-block text (`▀`), one text row per two pixel rows.
    Ansi,
}

/// Parses `WxH` and checks it against the size limits.
pub fn parse_size(text: &str) -> Result<Size, String> {
    let hint = "write it as WIDTHxHEIGHT, e.g. 640x360";
    let (w, h) = text.trim().split_once(['x', 'X']).ok_or_else(|| format!("expected WIDTHxHEIGHT; {hint}"))?;
    let side = |s: &str, name: &str| -> Result<u32, String> {
        let v: i64 = s.trim().parse().map_err(|_| format!("the {name} '{s}' is not a whole number; {hint}"))?;
        if v < 1 {
            return Err(format!("the {name} must be at least 1 pixel; {hint}"));
        }
        if v > i64::from(MAX_SIDE) {
            return Err(format!("the {name} {v} is larger than the limit of {MAX_SIDE} pixels; choose a smaller size"));
        }
        Ok(v as u32)
    };
    let size = Size { width: side(w, "width")?, height: side(h, "height")? };
    check_pixels(size, 1).map(|_| size)
}

/// Refuses pictures over [`MAX_PIXELS`] once supersampled `ssaa x ssaa`.
pub fn check_pixels(size: Size, ssaa: u32) -> Result<(), String> {
    let pixels = u64::from(size.width) * u64::from(size.height) * u64::from(ssaa * ssaa);
    if pixels > MAX_PIXELS {
        let sampled = if ssaa > 1 { format!(" at {ssaa}x{ssaa} supersampling") } else { String::new() };
        return Err(format!(
            "{size}{sampled} is {:.1} megapixels, over the limit of {} megapixels; choose a smaller size",
            pixels as f64 / 1048576.0,
            MAX_PIXELS / 1048576
        ));
    }
    Ok(())
}

/// Parses `X,Y[,R[,W]]`.
pub fn parse_stone(text: &str) -> Result<Stone, String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    if !(2..=4).contains(&parts.len()) {
        return Err("expected X,Y[,RADIUS[,WEIGHT]] in pixels, e.g. 120,80 or 120,80,12,96".into());
    }
    let number = |s: &str, name: &str| -> Result<i64, String> {
        s.parse().map_err(|_| format!("the {name} '{s}' is not a whole number; e.g. 120,80,12,96"))
    };
    let coordinate = |s: &str, name: &str| -> Result<i32, String> {
        let v = number(s, name)?;
        i32::try_from(v)
            .map_err(|_| format!("the {name} {v} is too far away; stones outside the picture are clipped anyway"))
    };
    let x = coordinate(parts[0], "x")?;
    let y = coordinate(parts[1], "y")?;
    let radius = match parts.get(2) {
        Some(s) => number(s, "radius")?,
        None => 8,
    };
    if !(1..=1000).contains(&radius) {
        return Err(format!("the radius {radius} is outside 1..=1000 pixels"));
    }
    let weight = match parts.get(3) {
        Some(s) => number(s, "weight")?,
        None => 64,
    };
    if !(1..=32767).contains(&weight) {
        return Err(format!("the weight {weight} is outside 1..=32767 (32..128 looks natural)"));
    }
    Ok(Stone { x, y, radius: radius as u32, weight: weight as i16 })
}

/// Parses `SHIFT` (1..=15) or `off`.
pub fn parse_damping(text: &str) -> Result<Damping, String> {
    let text = text.trim();
    if text.eq_ignore_ascii_case("off") || text.eq_ignore_ascii_case("none") {
        return Ok(Damping::Off);
    }
    let shift: i64 = text.parse().map_err(|_| format!("'{text}' is neither a shift 1..=15 nor 'off'"))?;
    if shift == 0 {
        return Err("a shift of 0 would flatten the water every step; use 'off' for no damping".into());
    }
    u8::try_from(shift)
        .ok()
        .and_then(Damping::shift)
        .ok_or_else(|| format!("the shift {shift} is outside 1..=15 (5 is the papers'); use 'off' for no damping"))
}

/// Parses a duration in seconds, 0.01..=60.
pub fn parse_seconds(text: &str) -> Result<f64, String> {
    let v: f64 = text.trim().parse().map_err(|_| format!("'{text}' is not a number of seconds; e.g. 0.5"))?;
    if !v.is_finite() || !(0.01..=60.0).contains(&v) {
        return Err(format!("'{text}' must be between 0.01 and 60 seconds"));
    }
    Ok(v)
}

/// Parses a finite number >= 0.
pub fn parse_rate(text: &str) -> Result<f64, String> {
    let v: f64 = text.trim().parse().map_err(|_| format!("'{text}' is not a number; e.g. 0.05"))?;
    if !v.is_finite() || v < 0.0 {
        return Err(format!("'{text}' must be a finite number >= 0 (drops per step), e.g. 0.05"));
    }
    if v > 10_000.0 {
        return Err(format!("{v} drops per step would boil the pool; use at most 10000"));
    }
    Ok(v)
}

/// Parses a refraction factor (finite, 0..=100) or `auto`.
pub fn parse_refraction(text: &str) -> Result<crate::render::pool::Refraction, String> {
    use crate::render::pool::Refraction;
    let text = text.trim();
    if text.eq_ignore_ascii_case("auto") {
        return Ok(Refraction::Auto);
    }
    let v: f32 = text.parse().map_err(|_| format!("'{text}' is neither a number nor 'auto'"))?;
    if !v.is_finite() || !(0.0..=100.0).contains(&v) {
        return Err(format!("'{text}' must be between 0 and 100 (1.0 is the papers' factor), or 'auto'"));
    }
    Ok(Refraction::Factor(v))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn clap_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn sizes() {
        assert_eq!(parse_size("640x360"), Ok(Size { width: 640, height: 360 }));
        assert_eq!(parse_size(" 1X1 "), Ok(Size { width: 1, height: 1 }));
        for bad in ["0x0", "640", "-5x10", "ax3", "16385x1", "100000x100000", "8193x8193", ""] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
        assert!(parse_size("16384x4096").is_ok());
        assert!(parse_size("9000x9000").unwrap_err().contains("megapixels"));
        assert!(check_pixels(Size { width: 4096, height: 4096 }, 3).unwrap_err().contains("supersampling"));
    }

    #[test]
    fn stones() {
        assert_eq!(parse_stone("1,2"), Ok(Stone { x: 1, y: 2, radius: 8, weight: 64 }));
        assert_eq!(parse_stone("-5, 7, 3"), Ok(Stone { x: -5, y: 7, radius: 3, weight: 64 }));
        assert_eq!(parse_stone("1,2,1000,32767"), Ok(Stone { x: 1, y: 2, radius: 1000, weight: 32767 }));
        for bad in ["1", "1,2,3,4,5", "1,2,-3", "1,2,0", "1,2,1001", "1,2,3,0", "1,2,3,32768", "a,b", "1.5,2"] {
            assert!(parse_stone(bad).is_err(), "{bad}");
        }
        assert!(parse_stone("1,2,-3").unwrap_err().contains("radius"));
    }

    #[test]
    fn damping() {
        assert_eq!(parse_damping("off"), Ok(Damping::Off));
        assert_eq!(parse_damping("5"), Ok(Damping::Shift(5)));
        assert_eq!(parse_damping("15"), Ok(Damping::Shift(15)));
        assert!(parse_damping("0").unwrap_err().contains("use 'off'"));
        assert!(parse_damping("16").is_err());
        assert!(parse_damping("-1").is_err());
    }

    #[test]
    fn rates_and_factors() {
        assert_eq!(parse_rate("0.02"), Ok(0.02));
        for bad in ["-1", "NaN", "inf", "x", "1e9"] {
            assert!(parse_rate(bad).is_err(), "{bad}");
        }
        assert!(parse_refraction("auto").is_ok());
        assert!(parse_refraction("0").is_ok());
        for bad in ["-0.5", "nan", "1e9", "fast"] {
            assert!(parse_refraction(bad).is_err(), "{bad}");
        }
    }
}
