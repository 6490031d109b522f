//! The command line: clap definitions (raw flags) and the parsers that validate each value.
//!
//! Every value parser returns a message that names what is wrong and how to fix it; clap puts
//! the flag in front (`invalid value '0x0' for '--size <WxH>': ...`) and exits with status 2.
//! Checks that involve several flags live in [`crate::commands`].

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

pub mod lake;
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
    /// What to do; without one, tidepool plays the pool in this terminal (`tidepool play`).
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
    /// Play with the water full-screen in this terminal: keys and the mouse drop stones.
    Play(PlayCommand),
    /// Measure how fast this machine runs tidepool, stage by stage (a few seconds).
    Bench(BenchArgs),
    /// Print shell completions: `tidepool completions bash > ~/.local/share/bash-completion/completions/tidepool`.
    Completions(CompletionsArgs),
    /// Print the manual page (roff), or write one page per command into a folder.
    Man(ManArgs),
}

/// `tidepool completions`.
#[derive(Args, Debug)]
pub struct CompletionsArgs {
    /// The shell to complete for.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}

/// `tidepool man`.
#[derive(Args, Debug)]
pub struct ManArgs {
    /// Write tidepool.1, tidepool-render.1, tidepool-render-pool.1... into this folder instead
    /// of printing the main page (e.g. `tidepool man --out-dir ~/.local/share/man/man1`).
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
}

/// `tidepool bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Seconds to spend on each workload (the median of the runs is reported).
    #[arg(long, value_name = "S", default_value_t = 0.4, value_parser = parse_seconds)]
    pub seconds: f64,

    /// The terminal picture to measure, in pixels (columns x 2 per row).
    #[arg(long, value_name = "WxH", default_value = "160x94", value_parser = parse_size, allow_hyphen_values = true)]
    pub terminal: Size,
}

const PLAY_KEYS: &str = "\
Keys: space stone at random · arrows/hjkl aim, enter drop · r rain · c clear · +/- stone size ·
[/] damping · p pause · s screenshot (PNG) · tab next scene · ? help · q, Esc, Ctrl-C quit.
Mouse: left click drops a stone, drag stirs the water, right click drops a big stone.
The lake: 0-9 wind by Beaufort number · [/] less/more wind · c calm · o/O octaves ·
</> persistence · n value/gradient noise.

Examples:
  tidepool                                      # the pool, full screen
  tidepool play pool --rain 0.1 --damping 6     # more rain, longer ripples
  tidepool play --max-bps 200k                  # a slow SSH link: cap the output rate
  tidepool play --record s.jsonl                # then: tidepool render pool --replay s.jsonl
  tidepool play lake --wind 0                   # a calm lake mirroring its shore";

/// `tidepool play [scene]`.
///
/// The player damps more than `render` (shift 4, not 5): a terminal pool is a few hundred
/// pixels at most, and at the papers' damping a ring crosses it twice before it fades, so the
/// water never settles, looks busy and costs every cell's bytes on every frame.
#[derive(Args, Debug, Clone)]
#[command(after_help = PLAY_KEYS, mut_arg("damping", |a| a.default_value(PLAYER_DAMPING)))]
pub struct PlayCommand {
    /// The scene to start with (`tab` switches while playing).
    #[arg(value_enum, default_value = "pool")]
    pub scene: PlayScene,

    /// The water of the pool. [--rain default: 0.02 drops per step]
    #[command(flatten)]
    pub pool: PoolArgs,

    /// The wind: the ocean's (default 10 m/s), and the lake's when given (its default is
    /// 3 m/s; it takes at most 30).
    #[command(flatten)]
    pub wind: ocean::WindArgs,

    /// Where the ocean's wind comes FROM, degrees clockwise from north. [default: 330]
    #[arg(long, value_name = "DEG", value_parser = ocean::parse_degrees, allow_hyphen_values = true)]
    pub direction: Option<f64>,

    /// Seed for everything random (rain, random stones); the same seed and the same inputs
    /// give the same water.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = parse_seed, allow_negative_numbers = true)]
    pub seed: u64,

    /// Display frames per second (1..=240); the simulation runs at its own fixed rate.
    #[arg(long, value_name = "N", default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..=240))]
    pub fps: u32,

    /// Colours: truecolor (24-bit), 256 (xterm palette), 16, or auto (from COLORTERM and
    /// TERM; SSH and tmux may hide truecolor support, see the README).
    #[arg(long, value_enum, value_name = "MODE", default_value = "auto")]
    pub color: ColorChoice,

    /// Treat a colour change of at most N (0..=255, per channel) as no change, to save bytes.
    /// Screenshots always use exact pixels. [default: 0, or 3 when SSH_CONNECTION is set]
    #[arg(long, value_name = "N")]
    pub color_threshold: Option<u8>,

    /// Do not wrap frames in synchronized output (ESC[?2026h/l), for terminals that mishandle it.
    #[arg(long)]
    pub no_sync: bool,

    /// Cap the output at N bytes per second (suffixes k and M: 200k, 1.5M) by lowering the
    /// frame rate, for slow links.
    #[arg(long, value_name = "N", value_parser = parse_bps)]
    pub max_bps: Option<u64>,

    /// Record the session as JSON lines, for `tidepool render pool --replay FILE` (the pool only).
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,
}

/// The player's default `--damping`.
pub const PLAYER_DAMPING: &str = "4";

/// The scenes `play` knows; `tab` cycles through them in this order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PlayScene {
    /// The ripple pool.
    Pool,
    /// The open sea under the wind.
    Ocean,
    /// The lake under a breeze, mirroring its shore.
    Lake,
}

/// `--color`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ColorChoice {
    /// Guess from COLORTERM and TERM.
    Auto,
    /// 24-bit colour.
    Truecolor,
    /// The xterm 256-colour palette.
    #[value(name = "256")]
    Palette256,
    /// The 16 basic colours.
    #[value(name = "16")]
    Palette16,
}

/// Parses a byte rate: a whole number with an optional `k` (1000) or `M` (1,000,000) suffix.
pub fn parse_bps(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let (number, unit) = match t.char_indices().last() {
        Some((i, 'k' | 'K')) => (&t[..i], 1e3),
        Some((i, 'm' | 'M')) => (&t[..i], 1e6),
        _ => (t, 1.0),
    };
    let v: f64 = number.trim().parse().map_err(|_| format!("'{text}' is not a byte rate; e.g. 200k or 1.5M"))?;
    let bytes = v * unit;
    if !bytes.is_finite() || bytes < 1000.0 {
        return Err(format!("'{text}' is below 1k bytes per second, too little to draw a frame; e.g. 200k"));
    }
    if bytes > 1e12 {
        return Err(format!("'{text}' is beyond any link; leave --max-bps out for no cap"));
    }
    Ok(bytes as u64)
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
    /// The lake: Perlin-noise water mirroring its wooded shore; wind breaks the mirror.
    Lake(lake::RenderLake),
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

    /// Re-simulate a session recorded with `tidepool play --record FILE` and render its last
    /// step (or --steps N): identical to a screenshot taken at that step. The replay fixes the
    /// size, seed, stones and water flags.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["size", "seed", "stones", "rain", "damping", "refraction", "no_shading", "no_caustics", "depth", "sun", "background"])]
    pub replay: Option<PathBuf>,

    /// An animation instead of one picture.
    #[command(flatten)]
    pub animation: AnimationArgs,
}

/// Flags of animations, taken by every rendered scene.
#[derive(Args, Debug, Clone, Copy)]
pub struct AnimationArgs {
    /// Render an animation of N frames (1..=100000) instead of one picture, to --out NAME.gif,
    /// NAME.png (animated PNG) or a pattern such as frames/pool_{frame:04}.png (one PNG a frame).
    /// The scene advances between frames as the player's does at --fps; for the pool, --steps
    /// is where the first frame is taken. [default: one picture]
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub frames: Option<u32>,

    /// Frames per second of the animation (1..=240; a GIF shows at most 50).
    #[arg(long, value_name = "F", default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..=240))]
    pub fps: u32,
}

/// Flags every rendered scene takes.
#[derive(Args, Debug, Clone)]
pub struct OutputArgs {
    /// Picture size in pixels, WIDTHxHEIGHT (each side 1..=16384, at most 64 megapixels including
    /// any supersampling). [default: 640x360 for PNG; for text, the terminal's size when writing
    /// to it, else 80x48]
    #[arg(long, value_name = "WxH", value_parser = parse_size, allow_hyphen_values = true)]
    pub size: Option<Size>,

    /// Seed for everything random (rain, wave phases, noise, the shore); the same seed and flags
    /// give the same bytes.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = parse_seed, allow_negative_numbers = true)]
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

    /// Print how long each stage took (simulation or mesh, picture, encoding, writing) to
    /// standard error, with throughput or triangle counts.
    #[arg(long)]
    pub stats: bool,
}

/// Flags of the ripple pool, shared by `render pool` and the player.
#[derive(Args, Debug, Clone)]
pub struct PoolArgs {
    /// Raindrops per simulation step on average (radius 2, weight 64), a number >= 0.
    /// [default: 0 for render, 0.02 for play]
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

    /// Do not light the surface (by default flanks facing the sun are brightened, the others
    /// darkened, and crests tilted towards the sun glint).
    #[arg(long)]
    pub no_shading: bool,

    /// Do not draw caustics (the moving lines of focused sunlight on the floor).
    #[arg(long)]
    pub no_caustics: bool,

    /// Water depth in pixels: deeper water focuses the caustics into sharper, brighter lines
    /// and moves them further from the ripples that cast them (0..=10000).
    #[arg(long, value_name = "PIXELS", default_value_t = 24.0, value_parser = parse_depth)]
    pub depth: f32,

    /// Where the sun is: azimuth in degrees clockwise from north (the top of the picture) and
    /// elevation in degrees above the horizon (0..=90). [default: 315,60 for the pool, the upper
    /// left; 15,22 for the ocean, ahead and low]
    #[arg(long, value_name = "AZ_DEG,EL_DEG", value_parser = parse_sun, allow_hyphen_values = true)]
    pub sun: Option<crate::render::pool::Sun>,

    /// The pool floor: a PNG or JPEG, scaled to cover the picture (aspect kept, centred).
    /// [default: the built-in tiled floor]
    #[arg(long, value_name = "FILE")]
    pub background: Option<PathBuf>,
}

impl PoolArgs {
    /// The look these flags ask for.
    pub fn look(&self) -> crate::render::pool::PoolLook {
        use crate::render::caustics::CausticsLook;
        crate::render::pool::PoolLook {
            refraction: self.refraction,
            shading: !self.no_shading,
            caustics: (!self.no_caustics).then(|| CausticsLook { depth_px: self.depth, ..CausticsLook::default() }),
            sun: self.sun(),
        }
    }

    /// The pool's settings from these flags, with `seed` and the rain when `--rain` is not given.
    pub fn settings(&self, seed: u64, default_rain: f64) -> crate::scene::pool::PoolSettings {
        crate::scene::pool::PoolSettings {
            damping: self.damping,
            rain_rate: self.rain.unwrap_or(default_rain),
            seed,
            look: self.look(),
        }
    }

    /// The pool floor: `--background` decoded, or the built-in tiles.
    pub fn floor(&self) -> crate::error::Result<tiny_skia::Pixmap> {
        match &self.background {
            Some(path) => crate::render::background::load("--background", path),
            None => Ok(crate::render::background::pool_floor()),
        }
    }

    /// The pool's sun: `--sun`, or the default in the upper left.
    pub fn sun(&self) -> crate::render::pool::Sun {
        self.sun.unwrap_or_default()
    }
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

/// Parses a seed: any whole number 0..=2^64-1.
pub fn parse_seed(text: &str) -> Result<u64, String> {
    text.trim()
        .parse()
        .map_err(|_| format!("the seed '{}' is not a whole number 0..={}; e.g. 42", text.trim(), u64::MAX))
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

/// Parses a water depth in pixels, 0..=10000.
pub fn parse_depth(text: &str) -> Result<f32, String> {
    let v: f32 = text.trim().parse().map_err(|_| format!("'{text}' is not a number of pixels; e.g. 48"))?;
    if !v.is_finite() || !(0.0..=10_000.0).contains(&v) {
        return Err(format!("'{text}' must be between 0 and 10000 pixels"));
    }
    Ok(v)
}

/// Parses `AZIMUTH,ELEVATION` in degrees: any finite azimuth (wrapped to 0..360), elevation
/// 0..=90.
pub fn parse_sun(text: &str) -> Result<crate::render::pool::Sun, String> {
    let hint = "write it as AZIMUTH,ELEVATION in degrees, e.g. 315,60";
    let (az, el) = text.split_once(',').ok_or_else(|| format!("expected two numbers; {hint}"))?;
    let number = |s: &str, name: &str| -> Result<f32, String> {
        let v: f32 = s.trim().parse().map_err(|_| format!("the {name} '{}' is not a number; {hint}", s.trim()))?;
        if v.is_finite() { Ok(v) } else { Err(format!("the {name} must be finite; {hint}")) }
    };
    let azimuth = number(az, "azimuth")?.rem_euclid(360.0);
    let elevation = number(el, "elevation")?;
    if !(0.0..=90.0).contains(&elevation) {
        return Err(format!("the elevation {elevation} is outside 0..=90 degrees; {hint}"));
    }
    Ok(crate::render::pool::Sun { azimuth_deg: azimuth, elevation_deg: elevation })
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
    fn byte_rates() {
        assert_eq!(parse_bps("200k"), Ok(200_000));
        assert_eq!(parse_bps("1.5M"), Ok(1_500_000));
        assert_eq!(parse_bps("5000"), Ok(5000));
        for bad in ["", "k", "-5k", "10", "fast", "1e20"] {
            assert!(parse_bps(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn replay_conflicts_with_what_it_fixes() {
        let parse = |args: &[&str]| Cli::try_parse_from(["tidepool", "render", "pool"].iter().chain(args));
        assert!(parse(&["--replay", "r.jsonl", "--out", "x.png", "--steps", "5"]).is_ok());
        for bad in ["-1", "1.5", "", "18446744073709551616"] {
            assert!(parse_seed(bad).unwrap_err().contains("whole number"), "{bad}");
        }
        assert_eq!(parse_seed(" 42 "), Ok(42));
        for flag in [&["--size", "10x10"][..], &["--seed", "3"], &["--stone", "1,2"], &["--damping", "4"]] {
            let err = parse(&[&["--replay", "r.jsonl"][..], flag].concat()).unwrap_err();
            assert_eq!(err.kind(), clap::error::ErrorKind::ArgumentConflict, "{flag:?}");
        }
    }

    #[test]
    fn play_is_the_default_scene_pool() {
        let cli = Cli::try_parse_from(["tidepool", "play"]).unwrap();
        let Some(Command::Play(play)) = cli.command else { panic!("not play") };
        assert_eq!((play.scene, play.fps, play.color, play.pool.rain), (PlayScene::Pool, 30, ColorChoice::Auto, None));
        assert_eq!(play.pool.damping, Damping::Shift(4), "the player damps more than render");
        let cli = Cli::try_parse_from(["tidepool", "render", "pool"]).unwrap();
        let Some(Command::Render(RenderCommand { scene: RenderScene::Pool(pool) })) = cli.command else { panic!() };
        assert_eq!(pool.pool.damping, Damping::PAPERS);
        assert!(Cli::try_parse_from(["tidepool", "play", "--fps", "0"]).is_err());
        assert!(Cli::try_parse_from(["tidepool", "play", "--color", "256"]).is_ok());
    }

    #[test]
    fn rates_and_factors() {
        assert_eq!(parse_rate("0.02"), Ok(0.02));
        for bad in ["-1", "NaN", "inf", "x", "1e9"] {
            assert!(parse_rate(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_sun("-45, 30").map(|s| (s.azimuth_deg, s.elevation_deg)), Ok((315.0, 30.0)));
        for bad in ["45", "45,91", "45,-1", "x,30", "inf,30", "45,30,1"] {
            assert!(parse_sun(bad).is_err(), "{bad}");
        }
        assert!(parse_depth("-1").is_err() && parse_depth("nan").is_err() && parse_depth("48").is_ok());
        assert!(parse_refraction("auto").is_ok());
        assert!(parse_refraction("0").is_ok());
        for bad in ["-0.5", "nan", "1e9", "fast"] {
            assert!(parse_refraction(bad).is_err(), "{bad}");
        }
    }

    mod properties {
        use super::*;
        use proptest::prelude::*;

        proptest! {
            /// No text makes a parser panic; every answer is a value or a message.
            #[test]
            fn parsers_never_panic(text in "\\PC{0,40}") {
                let _ = parse_size(&text);
                let _ = parse_stone(&text);
                let _ = parse_damping(&text);
                let _ = parse_rate(&text);
                let _ = parse_refraction(&text);
                let _ = parse_sun(&text);
                let _ = parse_depth(&text);
                let _ = parse_seconds(&text);
            }

            /// Sizes within the limits round-trip; anything past a limit is refused.
            #[test]
            fn sizes_round_trip_within_the_limits(w in 1u32..=20_000, h in 1u32..=20_000) {
                let parsed = parse_size(&format!("{w}x{h}"));
                let fits = w <= MAX_SIDE && h <= MAX_SIDE && u64::from(w) * u64::from(h) <= MAX_PIXELS;
                prop_assert_eq!(parsed.is_ok(), fits);
                if let Ok(size) = parsed {
                    prop_assert_eq!((size.width, size.height), (w, h));
                }
            }

            /// Stones round-trip, with the documented defaults and ranges.
            #[test]
            fn stones_round_trip(x in any::<i32>(), y in any::<i32>(), r in -5i64..1100, wt in -5i64..33_000) {
                let parsed = parse_stone(&format!("{x},{y},{r},{wt}"));
                let valid = (1..=1000).contains(&r) && (1..=32767).contains(&wt);
                prop_assert_eq!(parsed.is_ok(), valid);
                if let Ok(stone) = parsed {
                    prop_assert_eq!(stone, Stone { x, y, radius: r as u32, weight: wt as i16 });
                }
                prop_assert_eq!(parse_stone(&format!("{x},{y}")), Ok(Stone { x, y, radius: 8, weight: 64 }));
            }
        }
    }
}
