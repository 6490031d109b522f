//! `tidepool render`: simulate headless and write a picture.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use tiny_skia::Pixmap;

use crate::cli::{Format, OutputArgs, RenderCommand, RenderPool, RenderScene, Size};
use crate::error::{Error, Result};
use crate::output::heightmap::{self, Heightmap};
use crate::output::{atomic, halfblock, png};
use crate::progress::Progress;
use crate::scene::pool::PoolScene;
use crate::sim::ripple::Stone;

/// The default PNG size.
pub const DEFAULT_PNG_SIZE: Size = Size { width: 640, height: 360 };
/// The default text size when not writing to a terminal (80 columns, 24 rows).
pub const DEFAULT_TEXT_SIZE: Size = Size { width: 80, height: 48 };

/// Runs `tidepool render <scene>`.
pub fn run(command: RenderCommand) -> Result<()> {
    match command.scene {
        RenderScene::Pool(args) => render_pool(args),
        RenderScene::Ocean(args) => super::ocean::render_ocean(args),
        RenderScene::Lake(args) => super::lake::render_lake(args),
    }
}

/// Where the picture goes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// Standard output.
    Stdout,
    /// A file, written atomically.
    File(PathBuf),
}

/// The validated output side of a render: where, in which format, at what size.
#[derive(Clone, Debug, PartialEq)]
pub struct OutputPlan {
    /// Where the picture goes.
    pub target: Target,
    /// Its format.
    pub format: Format,
    /// Its size in pixels.
    pub size: Size,
    /// Where the heightmap goes, and in which form.
    pub heightmap: Option<(PathBuf, HeightmapKind)>,
}

/// The heightmap formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeightmapKind {
    /// NPY float32.
    Npy,
    /// 16-bit grey PNG.
    Png16,
}

impl OutputPlan {
    /// Validates the output flags of scene `scene` (used for the default file name).
    /// `stdout_is_terminal` and `terminal_size` describe the environment (passed in for tests).
    pub fn new(
        args: &OutputArgs,
        scene: &str,
        stdout_is_terminal: bool,
        terminal_size: Option<Size>,
    ) -> Result<OutputPlan> {
        let (target, format) = match &args.out {
            None => {
                let format = args.format.unwrap_or(Format::Png);
                let ext = if format == Format::Png { "png" } else { "ans" };
                (Target::File(PathBuf::from(format!("{scene}.{ext}"))), format)
            }
            Some(path) if path.as_os_str() == "-" => (Target::Stdout, args.format.unwrap_or(Format::Ansi)),
            Some(path) => {
                let format = match (args.format, format_of(path)) {
                    (Some(format), _) => format,
                    (None, Some(format)) => format,
                    (None, None) => {
                        return Err(Error::arg(
                            "--out",
                            format!(
                                "cannot tell the format of '{}' from its extension; name it .png, .ans or .txt, or give --format png|ansi",
                                path.display()
                            ),
                        ));
                    }
                };
                (Target::File(path.clone()), format)
            }
        };
        if target == Target::Stdout && format == Format::Png && stdout_is_terminal {
            return Err(Error::arg(
                "--out",
                "refusing to write PNG bytes to a terminal; redirect standard output to a file, or use --format ansi",
            ));
        }
        let size = match args.size {
            Some(size) => size,
            None if format == Format::Png => DEFAULT_PNG_SIZE,
            None if target == Target::Stdout && stdout_is_terminal => terminal_size.unwrap_or(DEFAULT_TEXT_SIZE),
            None => DEFAULT_TEXT_SIZE,
        };
        let heightmap = match &args.heightmap {
            None => None,
            Some(path) => {
                let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
                let kind = match ext.as_deref() {
                    Some("npy") => HeightmapKind::Npy,
                    Some("png") => HeightmapKind::Png16,
                    _ => {
                        return Err(Error::arg(
                            "--heightmap",
                            format!("'{}' must end in .npy (float32) or .png (16-bit grey)", path.display()),
                        ));
                    }
                };
                Some((path.clone(), kind))
            }
        };
        Ok(OutputPlan { target, format, size, heightmap })
    }

    /// Samples the heightmap (when `--heightmap` asked for one) from `scene`, frees the scene
    /// (its buffers are the largest allocation) before encoding, writes everything and prints
    /// the stats when asked. The tail every rendered scene shares.
    pub fn sample_and_write<S>(
        &self,
        scene: S,
        picture: &Pixmap,
        sample: impl FnOnce(&S, usize, usize) -> Heightmap,
        png_scale: f32,
        mut stats: Stats,
        print_stats: bool,
    ) -> Result<()> {
        let (width, height) = (self.size.width as usize, self.size.height as usize);
        let started = Instant::now();
        let heights = self.heightmap.is_some().then(|| sample(&scene, width, height));
        if heights.is_some() {
            stats.record("sample", started, format!("heightmap {width}x{height}"));
        }
        drop(scene);
        self.write_timed(picture, heights.as_ref(), png_scale, &mut stats)?;
        stats.print_if(print_stats);
        Ok(())
    }

    /// Encodes and writes the picture, then the heightmap (heights in the scene's unit;
    /// `png_scale` converts them to PNG levels), recording how long each took.
    pub fn write_timed(
        &self,
        picture: &Pixmap,
        heights: Option<&Heightmap>,
        png_scale: f32,
        stats: &mut Stats,
    ) -> Result<()> {
        let started = Instant::now();
        let bytes = match self.format {
            Format::Png => png::encode(picture),
            Format::Ansi => halfblock::encode(picture),
        };
        let format = if self.format == Format::Png { "png" } else { "half-block text" };
        stats.record("encode", started, format!("{format}, {}", human_bytes(bytes.len())));
        let started = Instant::now();
        let target = match &self.target {
            Target::Stdout => {
                write_stdout(&bytes)?;
                "standard output".to_string()
            }
            Target::File(path) => {
                atomic::write_file(path, &bytes)?;
                path.display().to_string()
            }
        };
        stats.record("write", started, target);
        if let (Some((path, kind)), Some(map)) = (&self.heightmap, heights) {
            let started = Instant::now();
            let bytes = match kind {
                HeightmapKind::Npy => heightmap::encode_npy(map),
                HeightmapKind::Png16 => heightmap::encode_png16(map, png_scale),
            };
            atomic::write_file(path, &bytes)?;
            stats.record("heightmap", started, format!("{}, {}", path.display(), human_bytes(bytes.len())));
        }
        Ok(())
    }
}

/// Per-stage timings of one render, printed to standard error by `--stats`.
#[derive(Debug, Default)]
pub struct Stats {
    stages: Vec<(&'static str, Duration, String)>,
}

impl Stats {
    /// Records that `stage` ran from `started` until now; `detail` says what it did.
    pub fn record(&mut self, stage: &'static str, started: Instant, detail: String) {
        self.stages.push((stage, started.elapsed(), detail));
    }

    /// Prints [`Stats::report`] to standard error when `--stats` asked for it.
    pub fn print_if(&self, asked: bool) {
        if asked {
            eprint!("{}", self.report());
        }
    }

    /// The stages as aligned lines: name, milliseconds, detail.
    pub fn report(&self) -> String {
        let mut text = String::new();
        for (stage, took, detail) in &self.stages {
            text.push_str(&format!("{stage:<10} {:>9.2} ms   {detail}\n", took.as_secs_f64() * 1e3));
        }
        let total: Duration = self.stages.iter().map(|(_, took, _)| *took).sum();
        text.push_str(&format!("{:<10} {:>9.2} ms\n", "total", total.as_secs_f64() * 1e3));
        text
    }
}

/// `1234567` -> `1.2 MB`.
pub fn human_bytes(bytes: usize) -> String {
    match bytes {
        b if b >= 1 << 20 => format!("{:.1} MB", b as f64 / 1048576.0),
        b if b >= 1 << 10 => format!("{:.1} KB", b as f64 / 1024.0),
        b => format!("{b} B"),
    }
}

/// The format an output file name implies, if any.
fn format_of(path: &Path) -> Option<Format> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "png" => Some(Format::Png),
        "ans" | "txt" => Some(Format::Ansi),
        _ => None,
    }
}

fn write_stdout(bytes: &[u8]) -> Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(bytes).and_then(|()| out.flush()).map_err(Error::Stdout)
}

/// The terminal's size in half-block pixels (all columns, two pixels a row, one row left for
/// the shell prompt), when standard output is a terminal.
pub fn terminal_pixels() -> Option<Size> {
    let (cols, rows) = crossterm::terminal::size().ok()?;
    (cols > 0 && rows > 1).then(|| Size { width: u32::from(cols), height: 2 * (u32::from(rows) - 1) })
}

/// The stones of the default picture, as (step, stone): six stones falling one after another
/// in a cluster, so the picture shows young and old rings overlapping.
///
/// A ring lives about a hundred steps at the papers' damping whatever the picture's size, so
/// the cluster is laid out in pixels for a 360-pixel picture and shrunk (never enlarged) to fit
/// smaller ones; see [`default_pool_steps`].
pub fn default_stones(size: Size) -> Vec<(u64, Stone)> {
    let scale = default_scale(size);
    let (cx, cy) = (size.width as f32 / 2.0, size.height as f32 / 2.0);
    // (step at scale 1, x, y offsets from the centre and radius, in pixels at scale 1)
    let script: [(f32, f32, f32, f32); 6] = [
        (0.0, -70.0, -40.0, 4.0),
        (0.0, 30.0, -10.0, 4.0),
        (15.0, -20.0, 45.0, 3.0),
        (30.0, 95.0, -55.0, 3.0),
        (50.0, -120.0, 35.0, 3.0),
        (65.0, 70.0, 55.0, 2.0),
    ];
    script
        .iter()
        .map(|&(step, dx, dy, r)| {
            let stone = Stone {
                x: (cx + dx * scale) as i32,
                y: (cy + dy * scale) as i32,
                radius: (r * scale.sqrt()).round().max(2.0) as u32,
                weight: 160,
            };
            ((step * default_steps_scale(scale)) as u64, stone)
        })
        .collect()
}

/// Steps before the default picture (or one with explicit stones) is taken: 90 at 360 pixels
/// and above, fewer (at least 30) for smaller pictures, whose rings have less room.
pub fn default_pool_steps(size: Size) -> u64 {
    (90.0 * default_steps_scale(default_scale(size))).round() as u64
}

fn default_scale(size: Size) -> f32 {
    (size.width.min(size.height) as f32 / 360.0).min(1.0)
}

fn default_steps_scale(scale: f32) -> f32 {
    scale.max(1.0 / 3.0)
}

fn render_pool(args: RenderPool) -> Result<()> {
    if let Some(path) = &args.replay {
        return super::replay::render(&args, path);
    }
    if let Some(frames) = args.animation.frames {
        return animate_pool(&args, frames);
    }
    let plan = OutputPlan::new(&args.output, "pool", std::io::stdout().is_terminal(), terminal_pixels())?;
    let floor = args.pool.floor()?;
    let settings = args.pool.settings(args.output.seed, 0.0);
    let Size { width, height } = plan.size;
    let mut scene = PoolScene::new(width, height, floor, settings).ok_or_else(|| too_large(plan.size, ""))?;
    let mut script = if args.stones.is_empty() {
        default_stones(plan.size)
    } else {
        args.stones.iter().map(|&stone| (0, stone)).collect()
    };
    script.sort_by_key(|&(at, _)| at);
    let steps = args.steps.unwrap_or_else(|| default_pool_steps(plan.size));
    let mut stats = Stats::default();
    let started = Instant::now();
    let mut progress = Progress::new("steps", steps);
    let mut advance = |scene: &mut PoolScene, steps: u64| {
        // In slices, so a long run can show progress; slices of whole blocks cost nothing.
        let mut left = steps;
        while left > 0 {
            let slice = left.min(1024);
            scene.advance(slice);
            progress.advance(slice);
            left -= slice;
        }
    };
    let mut now = 0;
    for &(at, stone) in script.iter().filter(|(at, _)| *at <= steps) {
        advance(&mut scene, at - now);
        now = at;
        scene.drop_stone(stone);
    }
    advance(&mut scene, steps - now);
    drop(progress);
    let cells = f64::from(width) * f64::from(height) * steps as f64;
    let rate = cells / started.elapsed().as_secs_f64().max(1e-9) / 1e9;
    stats.record("sim", started, format!("{steps} steps, {rate:.2} G cell-updates/s"));
    let started = Instant::now();
    let picture = scene.snapshot();
    stats.record("render", started, format!("{width}x{height}"));
    plan.sample_and_write(scene, &picture, |scene, _, _| scene.heightmap(), 1.0, stats, args.output.stats)
}

/// The error when a picture of `size` cannot be allocated; `also` names another way out
/// (such as " or --ssaa").
pub fn too_large(size: Size, also: &str) -> Error {
    Error::arg("--size", format!("cannot allocate a {size} picture; choose a smaller size{also}"))
}

/// Refuses flags that mean nothing for an animation.
pub fn check_animation_flags(output: &OutputArgs) -> Result<()> {
    if output.format.is_some() {
        return Err(Error::arg(
            "--format",
            "an animation takes its format from --out (.gif, .png or a {frame} pattern)",
        ));
    }
    if output.heightmap.is_some() {
        return Err(Error::arg("--heightmap", "is written for single pictures; drop --frames or --heightmap"));
    }
    Ok(())
}

/// `tidepool render pool --frames N`: the stones (given or default) land at their steps, the
/// first frame after `--steps` steps (default 0, so the stones are seen falling).
fn animate_pool(args: &RenderPool, frames: u32) -> Result<()> {
    use super::animate::{Animation, AnimationTarget, animate};
    check_animation_flags(&args.output)?;
    let target = AnimationTarget::from_out(args.output.out.as_deref(), "pool", args.animation.fps)?;
    let size = args.output.size.unwrap_or(DEFAULT_PNG_SIZE);
    let floor = args.pool.floor()?;
    let settings = args.pool.settings(args.output.seed, 0.0);
    let mut script: Vec<(u64, crate::replay::Event)> = if args.stones.is_empty() {
        default_stones(size).into_iter().map(|(at, s)| (at, crate::replay::Event::Stone(s))).collect()
    } else {
        args.stones.iter().map(|&s| (0, crate::replay::Event::Stone(s))).collect()
    };
    script.sort_by_key(|(at, _)| *at);
    let mut make = || -> Result<Box<dyn crate::scene::playable::Playable>> {
        PoolScene::new(size.width, size.height, floor.clone(), settings)
            .map(|scene| Box::new(scene) as Box<dyn crate::scene::playable::Playable>)
            .ok_or_else(|| too_large(size, ""))
    };
    let animation = Animation { frames, fps: args.animation.fps, start_step: args.steps.unwrap_or(0), script: &script };
    animate(&mut make, &animation, &target, args.output.stats)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(out: Option<&str>, format: Option<Format>, size: Option<Size>) -> OutputArgs {
        OutputArgs { size, seed: 1, out: out.map(PathBuf::from), format, heightmap: None, stats: false }
    }

    #[test]
    fn format_follows_the_extension_and_the_flag_overrides_it() {
        let plan = |out, format| OutputPlan::new(&args(out, format, None), "pool", false, None);
        assert_eq!(plan(None, None).unwrap().target, Target::File("pool.png".into()));
        assert_eq!(plan(None, Some(Format::Ansi)).unwrap().target, Target::File("pool.ans".into()));
        assert_eq!(plan(Some("a.PNG"), None).unwrap().format, Format::Png);
        assert_eq!(plan(Some("a.txt"), None).unwrap().format, Format::Ansi);
        assert_eq!(plan(Some("a.ans"), Some(Format::Png)).unwrap().format, Format::Png);
        assert_eq!(plan(Some("a.bin"), Some(Format::Ansi)).unwrap().format, Format::Ansi);
        assert!(plan(Some("a.jpg"), None).unwrap_err().to_string().contains("--out"));
        assert_eq!(plan(Some("-"), None).unwrap().format, Format::Ansi);
    }

    #[test]
    fn png_to_a_terminal_is_refused() {
        let err = OutputPlan::new(&args(Some("-"), Some(Format::Png), None), "pool", true, None).unwrap_err();
        assert!(err.to_string().contains("terminal"));
        assert!(OutputPlan::new(&args(Some("-"), Some(Format::Png), None), "pool", false, None).is_ok());
    }

    #[test]
    fn default_sizes() {
        let term = Size { width: 120, height: 78 };
        let size = |out, format, tty| OutputPlan::new(&args(out, format, None), "pool", tty, Some(term)).unwrap().size;
        assert_eq!(size(None, None, false), DEFAULT_PNG_SIZE);
        assert_eq!(size(Some("-"), None, true), term);
        assert_eq!(size(Some("-"), None, false), DEFAULT_TEXT_SIZE);
        assert_eq!(size(Some("x.ans"), None, true), DEFAULT_TEXT_SIZE);
    }

    #[test]
    fn heightmap_extensions() {
        let mut a = args(None, None, None);
        a.heightmap = Some("h.npy".into());
        assert_eq!(OutputPlan::new(&a, "pool", false, None).unwrap().heightmap.unwrap().1, HeightmapKind::Npy);
        a.heightmap = Some("h.PNG".into());
        assert_eq!(OutputPlan::new(&a, "pool", false, None).unwrap().heightmap.unwrap().1, HeightmapKind::Png16);
        a.heightmap = Some("h.exr".into());
        assert!(OutputPlan::new(&a, "pool", false, None).unwrap_err().to_string().contains("--heightmap"));
    }

    #[test]
    fn default_stones_stay_inside_small_pictures() {
        for size in [Size { width: 1, height: 1 }, Size { width: 80, height: 48 }, Size { width: 4000, height: 300 }] {
            for (_, s) in default_stones(size) {
                assert!(s.x >= 0 && s.y >= 0 && s.x < size.width as i32 && s.y < size.height as i32);
                assert!((2..=1000).contains(&s.radius));
            }
        }
    }
}
