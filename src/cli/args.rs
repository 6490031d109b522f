//! The command line: clap definitions (raw flags) and the parsers that validate each value.
//!
//! The value parsers are the library's own checks (`Stone::from_str`, `Damping::from_str`,
//! `PoolSettings::check_rain`, ...; the plain numbers are read in [`values`]): each returns a
//! message that names what is wrong and how to fix it;
//! clap puts the flag in front (`invalid value '0x0' for '--size <WxH>': ...`) and exits with
//! status 2. Checks that involve several flags live in [`crate::cli::commands`].

use std::path::PathBuf;
use std::str::FromStr;

use crate::scene::SceneKind;
use crate::size::Size;
use crate::{BreezeStyle, CausticsLook, Damping, Refraction, Stone, Sun, ValueError};
use clap::{Args, Parser, Subcommand, ValueEnum};

pub mod lake;
pub mod ocean;
pub mod pool;
pub mod values;

pub use pool::{PoolArgs, PoolDefaults};
pub use values::{parse_breeze, parse_grid, parse_rate, parse_steps_per_second};
#[cfg(feature = "serve")]
pub mod serve;
#[cfg(feature = "bus")]
pub mod serve_bus;

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
    /// Host one shared pool over SSH: everyone who connects plays in the same water.
    #[cfg(feature = "serve")]
    Serve(serve::ServeCommand),
    /// Host one shared pool over SSH (not in this build: it needs `--features serve`).
    #[cfg(not(feature = "serve"))]
    Serve(ServeNotBuilt),
    /// Measure how fast this machine runs tidepool, stage by stage (a few seconds).
    Bench(BenchArgs),
    /// Print shell completions: `tidepool completions bash > ~/.local/share/bash-completion/completions/tidepool`.
    Completions(CompletionsArgs),
    /// Print the manual page (roff), or write one page per command into a folder.
    Man(ManArgs),
}

/// `tidepool serve` in a build without the feature: whatever follows is taken, and the command
/// says how to get a build with the server (rather than clap's "unrecognized subcommand").
#[cfg(not(feature = "serve"))]
#[derive(Args, Debug)]
pub struct ServeNotBuilt {
    /// The server's flags (not read: there is no server in this build).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
    pub flags: Vec<String>,
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
Keys: space stone at random · arrows/hjkl aim, enter drop · r rain · b breeze · c clear ·
+/- stone size · [/] damping · p pause · s screenshot (PNG) · tab next scene · ? help ·
q, Esc, Ctrl-C quit.
Mouse: left click drops a stone, drag stirs the water, right click drops a big stone.
The lake: 0-9 wind by Beaufort number · [/] less/more wind · c calm · o/O octaves ·
</> persistence · n value/gradient noise.

Examples:
  tidepool                                      # the pool, full screen
  tidepool play pool --rain 0.1 --damping 6     # more rain, longer ripples
  tidepool play --bandwidth 200k                # a fixed link rate (default: found by itself)
  tidepool play --breeze 0 --rain 0             # the papers' still water
  tidepool play --record s.jsonl                # then: tidepool render pool --replay s.jsonl
  tidepool play lake --wind 0                   # a calm lake mirroring its shore";

/// `tidepool play [scene]`.
///
/// The scene flags a live session takes (`play` and `serve`): every scene is built from them,
/// so `tab` switches between waters set up by the same command line.
#[derive(Args, Debug, Clone)]
pub struct LiveSceneArgs {
    /// The water of the pool.
    #[command(flatten)]
    pub pool: PoolArgs,

    /// The wind: the ocean's (default 10 m/s), and the lake's when given (its default is
    /// 3 m/s; it takes at most 30).
    #[command(flatten)]
    pub wind: ocean::WindArgs,

    /// Where the ocean's wind comes FROM, degrees clockwise from north. [default: 330]
    #[arg(long, value_name = "DEG", value_parser = ocean::parse_degrees, allow_hyphen_values = true)]
    pub direction: Option<f64>,

    /// The ocean's spectrum and choppiness.
    #[command(flatten)]
    pub sea: ocean::PlaySeaArgs,

    /// Seed for everything random (rain, random stones); the same seed and the same inputs
    /// give the same water.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = parse_seed, allow_negative_numbers = true)]
    pub seed: u64,
}

/// The player's water is alive at rest and coherent from frame to frame: gusts of broad swells
/// of light, a few raindrops, stones whose rings spread crisp at a third of a pixel a frame (a
/// grid of two cells a pixel, 30 steps a second; see [`PoolDefaults::PLAYER`]), the papers'
/// damping.
#[derive(Args, Debug, Clone)]
#[command(after_help = PLAY_KEYS)]
pub struct PlayCommand {
    /// The scene to start with (`tab` switches while playing).
    #[arg(value_enum, default_value = "pool")]
    pub scene: PlayScene,

    /// The scenes' water, wind and seed.
    #[command(flatten)]
    pub water: LiveSceneArgs,

    /// Display frames per second (1..=240); the simulation runs at its own fixed rate.
    #[arg(long, value_name = "N", default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..=240))]
    pub fps: u32,

    /// Colours: truecolor (24-bit), 256 (xterm palette), 16, or auto (from COLORTERM and
    /// TERM; SSH and tmux may hide truecolor support, see docs/GUIDE.md).
    #[arg(long, value_enum, value_name = "MODE", default_value = "auto")]
    pub color: ColorChoice,

    /// Treat a colour change of at most N (0..=255, per channel) as no change, to save bytes.
    /// Screenshots always use exact pixels. [default: 0, or 3 when SSH_CONNECTION is set]
    #[arg(long, value_name = "N")]
    pub color_threshold: Option<u8>,

    /// Do not wrap frames in synchronized output (ESC[?2026h/l), for terminals that mishandle it.
    #[arg(long)]
    pub no_sync: bool,

    /// Bytes per second the link carries: `auto` finds it by itself from the terminal's
    /// answers (and adapts as it changes), a number (suffixes k and M: 200k, 1.5M) fixes it,
    /// `unlimited` sends every change whole. On a slow link the picture is sent approximately
    /// and refined as the budget allows; frames never queue up.
    #[arg(long, value_name = "BYTES/s|auto|unlimited", default_value = "auto", value_parser = parse_bandwidth)]
    pub bandwidth: crate::play::Bandwidth,

    /// The same as --bandwidth N (kept for scripts written before --bandwidth).
    #[arg(long, value_name = "N", value_parser = parse_bps, conflicts_with = "bandwidth", hide = true)]
    pub max_bps: Option<u64>,

    /// Record the session as JSON lines, for `tidepool render pool --replay FILE` (the pool only).
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,

    /// How the picture is drawn: real pixels with the kitty graphics protocol, sixel or iTerm2
    /// inline images, or half-block cells (two pixels a cell, any terminal). `auto` asks the
    /// terminal what it can show (500 ms at most) and falls back to cells.
    #[arg(long, value_enum, value_name = "MODE", default_value = "auto")]
    pub graphics: GraphicsFlag,
}

/// `--graphics`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum GraphicsFlag {
    /// The best the terminal answers for: kitty, then sixel, then iTerm2, else cells.
    Auto,
    /// The kitty graphics protocol (kitty, WezTerm, Ghostty, Konsole).
    Kitty,
    /// DEC sixel (xterm -ti vt340, foot, mlterm, WezTerm, Windows Terminal).
    Sixel,
    /// iTerm2's inline images (iTerm2, WezTerm).
    Iterm2,
    /// Half-block text cells, as before real pixels.
    Cells,
}

impl From<GraphicsFlag> for crate::play::GraphicsRequest {
    fn from(choice: GraphicsFlag) -> Self {
        use crate::play::GraphicsMode;
        use crate::play::GraphicsRequest::{Auto, Force};
        match choice {
            GraphicsFlag::Auto => Auto,
            GraphicsFlag::Kitty => Force(GraphicsMode::Kitty),
            GraphicsFlag::Sixel => Force(GraphicsMode::Sixel),
            GraphicsFlag::Iterm2 => Force(GraphicsMode::Iterm2),
            GraphicsFlag::Cells => Force(GraphicsMode::Cells),
        }
    }
}

/// The scenes `play` knows; `tab` cycles through them in this order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub(crate) enum PlayScene {
    /// The ripple pool.
    Pool,
    /// The open sea under the wind.
    Ocean,
    /// The lake under a breeze, mirroring its shore.
    Lake,
}

impl From<PlayScene> for SceneKind {
    fn from(scene: PlayScene) -> SceneKind {
        match scene {
            PlayScene::Pool => SceneKind::Pool,
            PlayScene::Ocean => SceneKind::Ocean,
            PlayScene::Lake => SceneKind::Lake,
        }
    }
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

/// Parses `--bandwidth`: `auto`, `unlimited` or a byte rate.
pub fn parse_bandwidth(text: &str) -> Result<crate::play::Bandwidth, String> {
    use crate::play::Bandwidth;
    match text.trim() {
        t if t.eq_ignore_ascii_case("auto") => Ok(Bandwidth::Auto),
        t if t.eq_ignore_ascii_case("unlimited") || t.eq_ignore_ascii_case("off") => Ok(Bandwidth::Unlimited),
        t => parse_bps(t).map(Bandwidth::Fixed).map_err(|e| format!("{e}, or auto or unlimited")),
    }
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
        return Err(format!("'{text}' is beyond any link; use unlimited for no cap"));
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
    /// The ocean: a wind-driven Pierson–Moskowitz sea under a sky, a spade-triangulated mesh,
    /// flat- or smooth-shaded (--shading).
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
    #[arg(long, value_name = "FILE", conflicts_with_all = ["size", "seed", "stones", "rain", "damping", "breeze", "grid", "breeze_style", "steps_per_second", "refraction", "no_shading", "no_caustics", "depth", "sun", "background"])]
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

    /// With --out - to a terminal: draw the picture in real pixels (kitty graphics, sixel,
    /// iTerm2) or half-block cells. `auto` asks the terminal (500 ms at most); into a pipe or a
    /// file it means cells and nothing is asked.
    #[arg(long, value_enum, value_name = "MODE", default_value = "auto")]
    pub graphics: GraphicsFlag,
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

/// The library's check of a value, as clap wants it: the message is the library's.
fn check<T: FromStr<Err = ValueError>>(text: &str) -> Result<T, String> {
    text.parse().map_err(|e: ValueError| e.to_string())
}

/// Parses `WxH` and checks it against the size limits.
pub fn parse_size(text: &str) -> Result<Size, String> {
    check(text)
}

/// Parses `X,Y[,R[,W]]`.
pub fn parse_stone(text: &str) -> Result<Stone, String> {
    check(text)
}

/// Parses `SHIFT` (1..=15) or `off`.
pub fn parse_damping(text: &str) -> Result<Damping, String> {
    check(text)
}

/// Parses a water depth in pixels, 0..=10000.
pub fn parse_depth(text: &str) -> Result<CausticsLook, String> {
    CausticsLook::parse_depth(text).map_err(|e| e.to_string())
}

/// Parses the pool's `AZIMUTH,ELEVATION` in degrees.
pub fn parse_sun(text: &str) -> Result<Sun, String> {
    check(text)
}

/// Parses a breeze style: `gusts` or `wavelets`.
pub fn parse_breeze_style(text: &str) -> Result<BreezeStyle, String> {
    check(text)
}

/// Parses a refraction factor (finite, 0..=100) or `auto`.
pub fn parse_refraction(text: &str) -> Result<Refraction, String> {
    check(text)
}

/// Parses a duration in seconds, 0.01..=60.
pub fn parse_seconds(text: &str) -> Result<f64, String> {
    let v: f64 = text.trim().parse().map_err(|_| format!("'{text}' is not a number of seconds; e.g. 0.5"))?;
    if !v.is_finite() || !(0.01..=60.0).contains(&v) {
        return Err(format!("'{text}' must be between 0.01 and 60 seconds"));
    }
    Ok(v)
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
    fn value_parsers_are_the_librarys_checks() {
        assert_eq!(parse_size("640x360"), Ok(Size::of(640, 360)));
        assert!(parse_size("9000x9000").unwrap_err().contains("megapixels"));
        assert!(parse_stone("1,2,-3").unwrap_err().contains("radius"));
        assert!(parse_damping("0").unwrap_err().contains("use 'off'"));
        assert_eq!(parse_rate("0.02"), Ok(0.02));
        assert_eq!(parse_sun("-45, 30").map(|s| (s.azimuth_deg(), s.elevation_deg())), Ok((315.0, 30.0)));
        assert!(parse_depth("-1").is_err() && parse_depth("48").is_ok());
        assert!(parse_refraction("auto").is_ok() && parse_refraction("1e9").is_err());
    }

    #[test]
    fn bandwidths() {
        use crate::play::Bandwidth;
        assert_eq!(parse_bandwidth("auto"), Ok(Bandwidth::Auto));
        assert_eq!(parse_bandwidth("unlimited"), Ok(Bandwidth::Unlimited));
        assert_eq!(parse_bandwidth("250k"), Ok(Bandwidth::Fixed(250_000)));
        for bad in ["0", "-5k", "fast", ""] {
            assert!(parse_bandwidth(bad).unwrap_err().contains("auto or unlimited"), "{bad}");
        }
        assert!(Cli::try_parse_from(["tidepool", "play", "--bandwidth", "1k", "--max-bps", "2k"]).is_err());
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
        for flag in [
            &["--size", "10x10"][..],
            &["--seed", "3"],
            &["--stone", "1,2"],
            &["--damping", "4"],
            &["--grid", "2"],
            &["--steps-per-second", "30"],
            &["--breeze-style", "gusts"],
            &["--breeze", "3"],
        ] {
            let err = parse(&[&["--replay", "r.jsonl"][..], flag].concat()).unwrap_err();
            assert_eq!(err.kind(), clap::error::ErrorKind::ArgumentConflict, "{flag:?}");
        }
    }

    #[test]
    fn play_is_the_default_scene_pool() {
        let cli = Cli::try_parse_from(["tidepool", "play"]).unwrap();
        let Some(Command::Play(play)) = cli.command else { panic!("not play") };
        assert_eq!(
            (play.scene, play.fps, play.color, play.water.pool.rain),
            (PlayScene::Pool, 30, ColorChoice::Auto, None)
        );
        assert_eq!(play.water.pool.damping.shift(), Some(5), "the player's damping");
        let pool = play.water.pool.settings(1, PoolDefaults::PLAYER).unwrap();
        assert_eq!(
            (pool.grid, pool.steps_per_second, pool.breeze_style, pool.breeze, pool.rain_rate),
            (2, 30, BreezeStyle::Gusts, 1.0, 0.01),
            "the player's coherent pool"
        );
        assert_eq!(play.bandwidth, crate::play::Bandwidth::Auto);
        assert_eq!(play.graphics, GraphicsFlag::Auto, "pictures in real pixels where the terminal answers");
        for (flag, want) in
            [("kitty", GraphicsFlag::Kitty), ("sixel", GraphicsFlag::Sixel), ("cells", GraphicsFlag::Cells)]
        {
            let cli = Cli::try_parse_from(["tidepool", "play", "--graphics", flag]).unwrap();
            let Some(Command::Play(play)) = cli.command else { panic!("not play") };
            assert_eq!(play.graphics, want);
        }
        assert!(Cli::try_parse_from(["tidepool", "play", "--graphics", "png"]).is_err());
        let cli = Cli::try_parse_from(["tidepool", "render", "pool"]).unwrap();
        let Some(Command::Render(RenderCommand { scene: RenderScene::Pool(pool) })) = cli.command else { panic!() };
        assert_eq!(pool.pool.damping, Damping::PAPERS);
        let render = pool.pool.settings(1, PoolDefaults::RENDER).unwrap();
        assert_eq!(
            (render.grid, render.steps_per_second, render.breeze_style, render.breeze, render.rain_rate),
            (1, 60, BreezeStyle::Wavelets, 0.0, 0.0),
            "render draws the papers' pool"
        );
        assert!(Cli::try_parse_from(["tidepool", "play", "--fps", "0"]).is_err());
        assert!(Cli::try_parse_from(["tidepool", "play", "--color", "256"]).is_ok());
    }

    mod properties {
        use super::*;
        use proptest::prelude::*;

        proptest! {
            /// No text makes a parser panic; every answer is a value or a message.
            #[test]
            fn parsers_never_panic(text in "\\PC{0,40}") {
                let _ = parse_bps(&text);
                let _ = parse_seed(&text);
                let _ = parse_seconds(&text);
            }
        }
    }
}
