//! Where a rendered picture goes: the validated output flags ([`OutputPlan`]), standard output,
//! and the error for a picture too large to allocate.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::Heightmap;
use crate::size::Size;

use tiny_skia::Pixmap;

use super::stats::Stats;
use crate::cli::args::{Format, OutputArgs};
use crate::cli::error::{Error, Result};
use crate::cli::files;

/// The default PNG size.
pub const DEFAULT_PNG_SIZE: Size = Size::of(640, 360);
/// The default text size when not writing to a terminal (80 columns, 24 rows).
pub const DEFAULT_TEXT_SIZE: Size = Size::of(80, 48);

/// Where the picture goes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Destination {
    /// Standard output.
    Stdout,
    /// A file, written atomically.
    File(PathBuf),
}

/// The validated output side of a render: where, in which format, at what size.
#[derive(Clone, Debug, PartialEq)]
pub struct OutputPlan {
    /// Where the picture goes.
    pub target: Destination,
    /// Its format.
    pub format: Format,
    /// Its size in pixels.
    pub size: Size,
    /// Where the heightmap goes, and in which form.
    pub heightmap: Option<(PathBuf, HeightmapKind)>,
    /// Standard output is a terminal that shows real pixels: the picture goes as one image.
    pub inline: Option<super::inline::Inline>,
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
                (Destination::File(PathBuf::from(format!("{scene}.{ext}"))), format)
            }
            Some(path) if path.as_os_str() == "-" => (Destination::Stdout, args.format.unwrap_or(Format::Ansi)),
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
                (Destination::File(path.clone()), format)
            }
        };
        if target == Destination::Stdout && format == Format::Png && stdout_is_terminal {
            return Err(Error::arg(
                "--out",
                "refusing to write PNG bytes to a terminal; redirect standard output to a file, or use --format ansi",
            ));
        }
        // Half-block text to a terminal may be real pixels instead (the terminal is asked here,
        // before the picture's size is chosen: pixels have the size of the terminal's cells).
        let inline = (target == Destination::Stdout && format == Format::Ansi && stdout_is_terminal)
            .then(|| super::inline::Inline::probe(args.graphics))
            .flatten();
        let size = match args.size {
            Some(size) => size,
            None if inline.is_some() => inline.as_ref().map_or(DEFAULT_TEXT_SIZE, |i| i.size(DEFAULT_TEXT_SIZE)),
            None if format == Format::Png => DEFAULT_PNG_SIZE,
            None if target == Destination::Stdout && stdout_is_terminal => terminal_size.unwrap_or(DEFAULT_TEXT_SIZE),
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
        Ok(OutputPlan { target, format, size, heightmap, inline })
    }

    /// Encodes and writes the picture, then the heightmap, recording how long each took.
    pub fn write_timed(&self, picture: &Pixmap, heights: Option<&Heightmap>, stats: &mut Stats) -> Result<()> {
        let started = Instant::now();
        let bytes = match (self.format, &self.inline) {
            (Format::Png, _) => crate::encode::png(picture),
            (Format::Ansi, Some(inline)) => inline.encode(picture),
            (Format::Ansi, None) => crate::encode::halfblock(picture),
        };
        let format = match (self.format, &self.inline) {
            (Format::Png, _) => "png",
            (Format::Ansi, Some(inline)) => inline.name(),
            (Format::Ansi, None) => "half-block text",
        };
        stats.record("encode", started, format!("{format}, {}", crate::output::units::human_bytes(bytes.len() as u64)));
        let started = Instant::now();
        let target = match &self.target {
            Destination::Stdout => {
                write_stdout(&bytes)?;
                "standard output".to_string()
            }
            Destination::File(path) => {
                files::write_file(path, &bytes)?;
                path.display().to_string()
            }
        };
        stats.record("write", started, target);
        if let (Some((path, kind)), Some(map)) = (&self.heightmap, heights) {
            let started = Instant::now();
            let bytes = match kind {
                HeightmapKind::Npy => map.to_npy(),
                HeightmapKind::Png16 => map.to_png16(),
            };
            files::write_file(path, &bytes)?;
            let size = crate::output::units::human_bytes(bytes.len() as u64);
            stats.record("heightmap", started, format!("{}, {size}", path.display()));
        }
        Ok(())
    }
}

/// The supersampling used when `--ssaa` is not given: 2 for PNG, 1 for text.
pub fn default_ssaa(format: Format) -> u32 {
    if format == Format::Png { 2 } else { 1 }
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

/// Writes all of `bytes` to standard output.
pub fn write_stdout(bytes: &[u8]) -> Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(bytes).and_then(|()| out.flush()).map_err(Error::Stdout)
}

/// The terminal's size in half-block pixels (all columns, two pixels a row, one row left for
/// the shell prompt), when standard output is a terminal.
pub fn terminal_pixels() -> Option<Size> {
    let (cols, rows) = crossterm::terminal::size().ok()?;
    (cols > 0 && rows > 1).then(|| Size::new(i64::from(cols), 2 * (i64::from(rows) - 1)).ok()).flatten()
}

/// The error for a picture of `size` that cannot be allocated; `also` names another way out
/// (such as " or --ssaa").
pub fn too_large(size: Size, also: &str) -> Error {
    Error::arg("--size", format!("cannot allocate a {size} picture; choose a smaller size{also}"))
}

/// Turns the library's allocation failure into the `--size` error; passes other errors on.
pub fn size_error(size: Size, also: &'static str) -> impl FnOnce(crate::Error) -> Error {
    move |e| match e {
        crate::Error::TooLarge { .. } => too_large(size, also),
        other => Error::Lib(other),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(out: Option<&str>, format: Option<Format>, size: Option<Size>) -> OutputArgs {
        OutputArgs {
            size,
            seed: 1,
            out: out.map(PathBuf::from),
            format,
            heightmap: None,
            stats: false,
            graphics: crate::cli::args::GraphicsFlag::Cells,
        }
    }

    #[test]
    fn format_follows_the_extension_and_the_flag_overrides_it() {
        let plan = |out, format| OutputPlan::new(&args(out, format, None), "pool", false, None);
        assert_eq!(plan(None, None).unwrap().target, Destination::File("pool.png".into()));
        assert_eq!(plan(None, Some(Format::Ansi)).unwrap().target, Destination::File("pool.ans".into()));
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
        let term = Size::of(120, 78);
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
}
