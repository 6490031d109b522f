//! `--frames N`: an animation of any scene, as the player would show it at `--fps`.
//!
//! Frame k shows the scene after `floor(k·steps_per_second/fps)` simulation steps (plus the
//! steps before the first frame), exactly the steps the player has run when it draws a frame
//! at that rate: stones, rain and time advance between frames as they do on screen.
//! Scripted events (the pool's stones, a replay's events) land at their steps.
//!
//! Targets, from `--out`: `NAME.gif` (animated GIF, at most 50 fps), `NAME.png` (animated PNG),
//! or a pattern with `{frame}` / `{frame:0N}` such as `frames/pool_{frame:04}.png` (one PNG per
//! frame). Every file is written atomically; an interrupted animation leaves no partial file.

use std::path::{Path, PathBuf};
use std::time::Instant;

use tiny_skia::Pixmap;

use crate::encode::{ApngWriter, GifPalette, GifWriter};
use crate::output::units::human_bytes;
use crate::scene::Script;
use crate::size::Size;
use crate::{Event, SceneSpec};

use super::output::size_error;
use super::stats::Stats;
use crate::cli::args::OutputArgs;
use crate::cli::error::{Error, Result};
use crate::cli::files::{self, AtomicFile};
use crate::cli::progress::Progress;

/// GIF delays are whole hundredths of a second, and viewers slow anything under 2 cs down.
pub const MAX_GIF_FPS: u32 = 50;
/// Frames the GIF palette is learned from, spread over the animation.
const PALETTE_SAMPLES: u32 = 5;

/// Where an animation goes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum AnimationTarget {
    /// An animated GIF.
    Gif(PathBuf),
    /// An animated PNG.
    Apng(PathBuf),
    /// One PNG per frame, named by the pattern.
    Sequence(FramePattern),
}

impl AnimationTarget {
    /// The target `--out` names for an animation of `scene` at `fps` (default `SCENE.gif`).
    pub fn from_out(out: Option<&Path>, scene: &str, fps: u32) -> Result<AnimationTarget> {
        let hint =
            "write the animation to NAME.gif, NAME.png (animated PNG) or a pattern such as frames/pool_{frame:04}.png";
        let path = match out {
            None => PathBuf::from(format!("{scene}.gif")),
            Some(p) if p.as_os_str() == "-" => {
                return Err(Error::arg(
                    "--out",
                    format!("animations are written to files, not standard output; {hint}"),
                ));
            }
            Some(p) => p.to_owned(),
        };
        let text = path.to_string_lossy();
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        if text.contains("{frame") {
            if ext.as_deref() != Some("png") {
                return Err(Error::arg("--out", format!("a frame pattern must end in .png; {hint}")));
            }
            return FramePattern::parse(&text).map(AnimationTarget::Sequence).map_err(|e| Error::arg("--out", e));
        }
        match ext.as_deref() {
            Some("gif") if fps > MAX_GIF_FPS => Err(Error::arg(
                "--fps",
                format!(
                    "a GIF shows at most {MAX_GIF_FPS} frames per second (its delays are in 1/100 s); use --fps {MAX_GIF_FPS} or less, or write an animated .png"
                ),
            )),
            Some("gif") => Ok(AnimationTarget::Gif(path)),
            Some("png") => Ok(AnimationTarget::Apng(path)),
            _ => Err(Error::arg("--out", format!("cannot tell the animation format of '{text}'; {hint}"))),
        }
    }
}

/// A file name with a `{frame}` or `{frame:0N}` placeholder.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FramePattern {
    before: String,
    width: usize,
    after: String,
}

impl FramePattern {
    /// Parses `before{frame}after` or `before{frame:0N}after` (N = 1..=9 digits).
    pub fn parse(text: &str) -> Result<FramePattern, String> {
        let start = text.find("{frame").ok_or("no {frame} placeholder")?;
        let end = start + text[start..].find('}').ok_or("the {frame placeholder has no closing }")?;
        let spec = &text[start + "{frame".len()..end];
        let width = match spec {
            "" => 0,
            s if s.starts_with(":0") && s.len() == 3 && s.as_bytes()[2].is_ascii_digit() && s.as_bytes()[2] != b'0' => {
                usize::from(s.as_bytes()[2] - b'0')
            }
            s => return Err(format!("'{{frame{s}}}' is not understood; use {{frame}} or {{frame:04}}")),
        };
        let after = &text[end + 1..];
        if after.contains("{frame") {
            return Err("use the {frame} placeholder once".into());
        }
        Ok(FramePattern { before: text[..start].to_owned(), width, after: after.to_owned() })
    }

    /// The file name of frame `k`.
    pub fn name(&self, k: u32) -> PathBuf {
        PathBuf::from(format!("{}{:0width$}{}", self.before, k, self.after, width = self.width))
    }
}

/// What to animate: `frames` frames at `fps`, the first after `start_step` steps, with
/// `script` events (sorted by step) landing at their steps.
pub struct Animation<'a> {
    /// Number of frames.
    pub frames: u32,
    /// Frames per second.
    pub fps: u32,
    /// Simulation steps before the first frame.
    pub start_step: u64,
    /// Events at steps, in step order.
    pub script: &'a [(u64, Event)],
}

impl Animation<'_> {
    /// An animation without scripted events, from the scene's own start.
    pub fn plain(frames: u32, fps: u32) -> Animation<'static> {
        Animation { frames, fps, start_step: 0, script: &[] }
    }

    /// The simulation step of frame `k`.
    pub fn frame_step(&self, k: u32, steps_per_second: f64) -> u64 {
        self.start_step + (f64::from(k) * steps_per_second / f64::from(self.fps)).floor() as u64
    }
}

/// Renders the animation of scene `spec` at `size` to `target` (a GIF takes two runs: the
/// first learns the palette from sample frames); prints the stage timings when `print_stats`
/// (`--stats`). `too_large_hint` names another way out of a too-large picture (" or --ssaa").
pub fn animate(
    spec: &SceneSpec,
    size: Size,
    animation: &Animation<'_>,
    target: &AnimationTarget,
    too_large_hint: &'static str,
    print_stats: bool,
) -> Result<()> {
    let make = || -> Result<Box<dyn FrameSource + '_>> {
        let scene = spec.build(size.width(), size.height()).map_err(size_error(size, too_large_hint))?;
        Ok(Box::new(Stepped { scene, script: Script::new(animation.script), animation }))
    };
    render_frames(&make, animation.frames, animation.fps, target, print_stats)
}

/// Renders `frames` frames from the sources `make` builds (fresh for each pass) to `target` at
/// `fps`.
pub fn render_frames<'a>(
    make: &dyn Fn() -> Result<Box<dyn FrameSource + 'a>>,
    frames: u32,
    fps: u32,
    target: &AnimationTarget,
    print_stats: bool,
) -> Result<()> {
    let mut stats = Stats::default();
    let started = Instant::now();
    let palette = match target {
        AnimationTarget::Gif(_) => {
            let mut source = make()?;
            let (width, height) = source.size();
            let mut samples = Vec::new();
            for i in 0..PALETTE_SAMPLES.min(frames) {
                let k = (u64::from(i) * u64::from(frames - 1) / u64::from((PALETTE_SAMPLES - 1).max(1))) as u32;
                let mut pixmap =
                    Pixmap::new(width, height).ok_or_else(|| Error::arg("--size", "cannot allocate the frames"))?;
                source.draw(k, &mut pixmap)?;
                samples.push(pixmap);
            }
            let palette = GifPalette::learn(&samples.iter().collect::<Vec<_>>());
            stats.record("palette", started, format!("{} sample frames", samples.len()));
            Some(palette)
        }
        _ => None,
    };
    let started = Instant::now();
    let mut source = make()?;
    let (width, height) = source.size();
    let mut pixmap = Pixmap::new(width, height).ok_or_else(|| Error::arg("--size", "cannot allocate the frames"))?;
    let mut sink = Sink::open(target, width, height, frames, fps, palette)?;
    let mut progress = Progress::new("frames", u64::from(frames));
    for k in 0..frames {
        source.draw(k, &mut pixmap)?;
        sink.write(k, &pixmap)?;
        progress.advance(1);
    }
    drop(progress);
    let (what, bytes) = sink.finish()?;
    stats.record(
        "animation",
        started,
        format!("{frames} frames of {width}x{height} at {fps} fps, {what}, {}", human_bytes(bytes as u64)),
    );
    stats.print_if(print_stats);
    Ok(())
}

/// Where an animation's frames come from: frame `k` drawn into a picture of `size()`. Frames
/// are asked for in increasing order (the GIF palette's samples skip some).
pub trait FrameSource {
    /// The picture size, pixels.
    fn size(&self) -> (u32, u32);
    /// Draws frame `k` into `out`.
    fn draw(&mut self, k: u32, out: &mut Pixmap) -> Result<()>;
}

/// A scene stepped as the player steps it, with scripted events at their steps.
struct Stepped<'a> {
    scene: Box<dyn crate::Playable>,
    script: Script<'a>,
    animation: &'a Animation<'a>,
}

impl FrameSource for Stepped<'_> {
    fn size(&self) -> (u32, u32) {
        self.scene.size()
    }

    fn draw(&mut self, k: u32, out: &mut Pixmap) -> Result<()> {
        let step = self.animation.frame_step(k, self.scene.steps_per_second());
        self.script.run_to(self.scene.as_mut(), step);
        if self.scene.size() != (out.width(), out.height()) {
            return Err(Error::Usage(format!(
                "the scene changed size at step {} (a replay's resize); animate the part before or after it with --steps and --frames",
                self.script.step()
            )));
        }
        self.scene.render(out);
        Ok(())
    }
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

/// An [`AtomicFile`] an encoder can write to and still be committed after the encoder is done
/// with it (the `png` encoder keeps its writer until it is dropped).
#[derive(Clone)]
struct SharedFile(std::rc::Rc<std::cell::RefCell<Option<AtomicFile>>>);

impl SharedFile {
    fn new(file: AtomicFile) -> SharedFile {
        SharedFile(std::rc::Rc::new(std::cell::RefCell::new(Some(file))))
    }

    fn commit(self) -> Result<()> {
        let file = self.0.borrow_mut().take().expect("committed once");
        file.commit()
    }
}

impl std::io::Write for SharedFile {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.borrow_mut().as_mut().ok_or_else(|| std::io::Error::other("the file was closed"))?.write(buf)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.borrow_mut().as_mut().ok_or_else(|| std::io::Error::other("the file was closed"))?.flush()
    }
}

/// The open output of an animation.
enum Sink {
    Gif(Box<GifWriter<AtomicFile>>, PathBuf),
    Apng(ApngWriter<SharedFile>, SharedFile, PathBuf),
    Sequence(FramePattern, usize),
}

impl Sink {
    fn open(
        target: &AnimationTarget,
        width: u32,
        height: u32,
        frames: u32,
        fps: u32,
        palette: Option<GifPalette>,
    ) -> Result<Sink> {
        Ok(match target {
            AnimationTarget::Gif(path) => {
                let file = AtomicFile::create(path)?;
                let palette = palette.expect("a GIF's palette is learned first");
                let writer = GifWriter::new(file, width, height, palette, fps)
                    .map_err(|e| Error::io("cannot write", path, e))?;
                Sink::Gif(Box::new(writer), path.clone())
            }
            AnimationTarget::Apng(path) => {
                let file = SharedFile::new(AtomicFile::create(path)?);
                let writer = ApngWriter::new(file.clone(), width, height, frames, fps)
                    .map_err(|e| Error::io("cannot write", path, e))?;
                Sink::Apng(writer, file, path.clone())
            }
            AnimationTarget::Sequence(pattern) => Sink::Sequence(pattern.clone(), 0),
        })
    }

    fn write(&mut self, k: u32, pixmap: &Pixmap) -> Result<()> {
        match self {
            Sink::Gif(writer, path) => writer.write(pixmap).map_err(|e| Error::io("cannot write", path.as_path(), e)),
            Sink::Apng(writer, _, path) => {
                writer.write(pixmap).map_err(|e| Error::io("cannot write", path.as_path(), e))
            }
            Sink::Sequence(pattern, bytes) => {
                let png = crate::encode::png(pixmap);
                *bytes += png.len();
                files::write_file(&pattern.name(k), &png)
            }
        }
    }

    /// Closes the output: (what was written, bytes).
    fn finish(self) -> Result<(String, usize)> {
        match self {
            Sink::Gif(writer, path) => {
                let file = writer.finish().map_err(|e| Error::io("cannot write", &path, e))?;
                file.commit()?;
                Ok((path.display().to_string(), file_size(&path)))
            }
            Sink::Apng(writer, file, path) => {
                writer.finish().map_err(|e| Error::io("cannot write", &path, e))?;
                file.commit()?;
                Ok((path.display().to_string(), file_size(&path)))
            }
            Sink::Sequence(pattern, bytes) => Ok((pattern.name(0).display().to_string() + " ...", bytes)),
        }
    }
}

fn file_size(path: &Path) -> usize {
    std::fs::metadata(path).map_or(0, |m| m.len() as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_follow_the_name() {
        let target = |out: &str, fps| AnimationTarget::from_out(Some(Path::new(out)), "pool", fps);
        assert_eq!(target("a.gif", 30).unwrap(), AnimationTarget::Gif("a.gif".into()));
        assert_eq!(target("a.PNG", 60).unwrap(), AnimationTarget::Apng("a.PNG".into()));
        assert!(matches!(target("f/p_{frame:04}.png", 60).unwrap(), AnimationTarget::Sequence(_)));
        assert!(target("a.gif", 60).unwrap_err().to_string().contains("--fps"));
        assert!(target("a.mp4", 30).unwrap_err().to_string().contains("--out"));
        assert!(target("-", 30).unwrap_err().to_string().contains("standard output"));
        assert!(target("f/{frame}.gif", 30).is_err());
        assert_eq!(AnimationTarget::from_out(None, "ocean", 30).unwrap(), AnimationTarget::Gif("ocean.gif".into()));
    }

    #[test]
    fn frame_patterns() {
        let p = FramePattern::parse("frames/pool_{frame:04}.png").unwrap();
        assert_eq!(p.name(7), PathBuf::from("frames/pool_0007.png"));
        assert_eq!(p.name(12345), PathBuf::from("frames/pool_12345.png"));
        assert_eq!(FramePattern::parse("{frame}.png").unwrap().name(3), PathBuf::from("3.png"));
        for bad in ["{frame:4}.png", "{frame:00}.png", "{frame.png", "{frame}{frame}.png", "{frame:x}.png"] {
            assert!(FramePattern::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn frames_fall_on_the_players_steps() {
        let a = Animation { frames: 4, fps: 25, start_step: 10, script: &[] };
        // 60 steps a second at 25 fps: 2.4 steps a frame.
        assert_eq!((0..4).map(|k| a.frame_step(k, 60.0)).collect::<Vec<_>>(), vec![10, 12, 14, 17]);
    }
}
