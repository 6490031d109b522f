//! Golden-image comparison in the manner of resvg's harness.
//!
//! - References live in `tests/golden/<name>.png` (or `.ans` for half-block text, compared
//!   after decoding it with the terminal model).
//! - Tolerance: a pixel differs when any channel is off by more than [`Tolerance::channel`];
//!   the test fails when more than [`Tolerance::max_fraction`] of the pixels differ. The
//!   defaults (2 levels, 0.1 %) absorb floating-point differences between CPUs and nothing
//!   a person would see; tidepool itself is byte-deterministic on one machine.
//! - `UPDATE_GOLDEN=1 cargo test` writes the references, prints their paths and FAILS, so an
//!   update run never passes silently. A missing reference fails and says how to create it.
//! - On a mismatch an `expected | changed pixels | actual` strip is written to
//!   `target/golden-failures/<name>.png` and its path is printed.

use std::path::{Path, PathBuf};

use image::{Rgba, RgbaImage};

/// How different two pictures may be and still match.
#[derive(Clone, Copy, Debug)]
pub struct Tolerance {
    /// Largest per-channel difference that is not a difference.
    pub channel: u8,
    /// Largest fraction of differing pixels (0.001 = 0.1 %).
    pub max_fraction: f64,
}

impl Default for Tolerance {
    fn default() -> Self {
        Tolerance { channel: 2, max_fraction: 0.001 }
    }
}

fn reference_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

fn updating() -> bool {
    std::env::var_os("UPDATE_GOLDEN").is_some_and(|v| !v.is_empty() && v != "0")
}

/// A test's golden checks. In an update run (`UPDATE_GOLDEN=1`) every reference is written,
/// and when the value is dropped at the end of the test it fails, listing them: a test with
/// several references rewrites them all in one run, and an update run never passes.
#[derive(Default)]
pub struct Goldens {
    updated: Vec<PathBuf>,
}

impl Goldens {
    /// Checks for one test.
    pub fn new() -> Goldens {
        Goldens::default()
    }

    /// Compares a picture with `tests/golden/<name>.png`.
    pub fn png(&mut self, name: &str, actual: &RgbaImage, tolerance: Tolerance) {
        let path = reference_dir().join(format!("{name}.png"));
        if updating() {
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            actual.save(&path).unwrap();
            println!("UPDATE_GOLDEN: wrote {}", path.display());
            self.updated.push(path);
            return;
        }
        let expected = load_reference(&path, |p| image::open(p).map(|i| i.to_rgba8()).map_err(|e| e.to_string()));
        compare(name, &expected, actual, tolerance);
    }

    /// Compares half-block text with `tests/golden/<name>.ans`, by the pixels a terminal
    /// shows. Default-background halves decode as transparent black.
    pub fn ansi(&mut self, name: &str, actual: &[u8], tolerance: Tolerance) {
        let path = reference_dir().join(format!("{name}.ans"));
        if updating() {
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(&path, actual).unwrap();
            println!("UPDATE_GOLDEN: wrote {} (cat it to look at it)", path.display());
            self.updated.push(path);
            return;
        }
        let expected = load_reference(&path, |p| std::fs::read(p).map_err(|e| e.to_string()));
        compare(name, &decode_ansi(&expected), &decode_ansi(actual), tolerance);
    }
}

impl Drop for Goldens {
    fn drop(&mut self) {
        if !self.updated.is_empty() && !std::thread::panicking() {
            let list: Vec<String> = self.updated.iter().map(|p| p.display().to_string()).collect();
            panic!("UPDATE_GOLDEN: wrote {}; look at each, then run the tests without UPDATE_GOLDEN", list.join(", "));
        }
    }
}

/// Compares a picture with `tests/golden/<name>.png` (one reference; see [`Goldens`]).
pub fn check_png(name: &str, actual: &RgbaImage, tolerance: Tolerance) {
    Goldens::new().png(name, actual, tolerance);
}

/// Compares half-block text with `tests/golden/<name>.ans` (one reference; see [`Goldens`]).
pub fn check_ansi(name: &str, actual: &[u8], tolerance: Tolerance) {
    Goldens::new().ansi(name, actual, tolerance);
}

/// Decodes half-block text (as written by `tidepool --format ansi`) into pixels.
pub fn decode_ansi(text: &[u8]) -> RgbaImage {
    let lines = text.split(|&b| b == b'\n').filter(|l| !l.is_empty()).count();
    let cols = String::from_utf8_lossy(text).lines().map(|l| l.matches('\u{2580}').count()).max().unwrap_or(0);
    // One spare row so the final newline does not scroll the picture away.
    let mut screen = tidepool::testing::TerminalModel::new(cols, lines + 1);
    screen.feed(text);
    let mut image = RgbaImage::new(cols as u32, 2 * lines as u32);
    for (x, y, pixel) in image.enumerate_pixels_mut() {
        *pixel = match screen.pixel(x as usize, y as usize) {
            Some([r, g, b]) => Rgba([r, g, b, 255]),
            None => Rgba([0, 0, 0, 0]),
        };
    }
    image
}

fn load_reference<T>(path: &Path, read: impl Fn(&Path) -> Result<T, String>) -> T {
    if !path.exists() {
        panic!(
            "missing golden reference {}; create it with `UPDATE_GOLDEN=1 cargo test`, look at it, and commit it",
            path.display()
        );
    }
    read(path).unwrap_or_else(|e| panic!("cannot read golden reference {}: {e}", path.display()))
}

/// Compares two pictures; on failure writes the strip and panics with the figures.
pub fn compare(name: &str, expected: &RgbaImage, actual: &RgbaImage, tolerance: Tolerance) {
    if expected.dimensions() != actual.dimensions() {
        let strip = write_strip(name, expected, actual, &RgbaImage::new(1, 1));
        panic!(
            "{name}: size {:?} differs from the reference's {:?}; see {}",
            actual.dimensions(),
            expected.dimensions(),
            strip.display()
        );
    }
    let (w, h) = expected.dimensions();
    let mut mask = RgbaImage::new(w, h);
    let mut differing = 0u64;
    let mut worst = 0u8;
    for ((e, a), m) in expected.pixels().zip(actual.pixels()).zip(mask.pixels_mut()) {
        let diff = e.0.iter().zip(a.0).map(|(x, y)| x.abs_diff(y)).max().unwrap_or(0);
        worst = worst.max(diff);
        *m = if diff > tolerance.channel {
            differing += 1;
            Rgba([255, 0, 255, 255])
        } else {
            let [r, g, b, _] = e.0;
            Rgba([r / 4, g / 4, b / 4, 255])
        };
    }
    let total = u64::from(w) * u64::from(h);
    let allowed = (total as f64 * tolerance.max_fraction).floor() as u64;
    if differing > allowed {
        let strip = write_strip(name, expected, actual, &mask);
        panic!(
            "{name}: {differing} of {total} pixels differ by more than {} (worst {worst}); at most {allowed} may. \
             expected | changed pixels | actual: {}",
            tolerance.channel,
            strip.display()
        );
    }
}

fn write_strip(name: &str, expected: &RgbaImage, actual: &RgbaImage, mask: &RgbaImage) -> PathBuf {
    let (ew, eh) = expected.dimensions();
    let (aw, ah) = actual.dimensions();
    let (mw, mh) = mask.dimensions();
    let gap = 4;
    let mut strip = RgbaImage::from_pixel(ew + mw + aw + 2 * gap, eh.max(ah).max(mh), Rgba([40, 40, 40, 255]));
    image::imageops::overlay(&mut strip, expected, 0, 0);
    image::imageops::overlay(&mut strip, mask, i64::from(ew + gap), 0);
    image::imageops::overlay(&mut strip, actual, i64::from(ew + mw + 2 * gap), 0);
    let path = super::target_dir().join("golden-failures").join(format!("{name}.png"));
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    strip.save(&path).unwrap();
    path
}
