//! Replays: an interactive session as JSON lines, so it can be re-simulated headless
//! (`tidepool render pool --replay FILE`) for bug reports and golden tests.
//!
//! ```text
//! {"tidepool_replay":1,"version":"0.1.0","scene":"pool","seed":1,"size":[160,94],"options":{...}}
//! {"step":12,"stone":[80,40,4,160]}
//! {"step":30,"rain":0.0}
//! {"step":31,"damping":"6"}
//! {"step":40,"clear":true}
//! {"step":41,"resize":[120,70]}
//! {"step":90,"screenshot":"tidepool-pool-000090.png"}
//! {"step":95,"end":true}
//! ```
//!
//! An event with step S happened after S simulation steps had run (steps count from the start
//! of the session, across resizes): re-simulating means, for each step, applying that step's
//! events in file order and then stepping ([`crate::scene::Script`]). Events are *resolved*: a
//! random stone is recorded where it landed, so a replay never needs the player's random
//! choices. The format is serde's form of a header and [`Event`]s; every value is checked by
//! the constructor the command line uses, and every count is bounded ([`Limits`]).
//!
//! The player keeps the file in memory while playing and saves it whole when the session ends
//! (its recorder), so a replay on disk is always complete; a file without its `end` line is
//! reported as truncated.

#[cfg(feature = "player")]
mod recorder;

#[cfg(feature = "player")]
pub(crate) use recorder::Recorder;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::Value;
use tiny_skia::Pixmap;

use crate::error::{Error, Result};
use crate::render::caustics::CausticsLook;
use crate::render::pool::{PoolLook, Refraction, Sun};
use crate::scene::pool::PoolSettings;
use crate::scene::{Event, Playable, SceneKind, SceneSpec, Script};
use crate::sim::breeze::BreezeStyle;
use crate::sim::ripple::Damping;
use crate::size::Size;

/// The replay format this tidepool writes and reads.
pub(crate) const FORMAT: u64 = 1;

/// What a replay may hold. Hostile or damaged files are refused by these limits at once,
/// instead of allocating gigabytes or simulating for ever.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// The last step a replay may reach.
    pub max_steps: u64,
    /// The most events (lines) a replay may hold.
    pub max_events: usize,
    /// The most pixels of the picture, at the start or after a resize.
    pub max_pixels: u64,
    /// The largest file, in bytes.
    pub max_bytes: u64,
}

impl Limits {
    /// 10 million steps: 46 hours of play at 60 steps a second.
    pub const MAX_STEPS: u64 = 10_000_000;
    /// A million events: a stone every step for four and a half hours.
    pub const MAX_EVENTS: usize = 1_000_000;
    /// 64 MB: a million events take about 40.
    pub const MAX_BYTES: u64 = 64 << 20;
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_steps: Limits::MAX_STEPS,
            max_events: Limits::MAX_EVENTS,
            max_pixels: crate::size::MAX_PIXELS,
            max_bytes: Limits::MAX_BYTES,
        }
    }
}

/// The first line of a replay.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub(crate) struct Header {
    /// The format number (1 today).
    #[serde(rename = "tidepool_replay")]
    pub format: u64,
    /// The tidepool version that recorded it (informational).
    #[serde(default)]
    pub version: String,
    /// The scene (replays hold the pool).
    #[serde(with = "scene_name")]
    pub scene: SceneKind,
    /// The seed of everything random.
    pub seed: u64,
    /// The picture size at step 0, in pixels.
    pub size: [u32; 2],
    /// Every flag that changes pixels.
    pub options: PoolOptions,
}

/// The pool's pixel-changing settings, as a replay header records them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub(crate) struct PoolOptions {
    /// Damping (`"5"`, `"off"`).
    pub damping: Damping,
    /// Raindrops per step.
    #[serde(deserialize_with = "rain")]
    pub rain: f64,
    /// Refraction (`"auto"` or a factor).
    #[serde(with = "display_from_str")]
    pub refraction: Refraction,
    /// Slope lighting and glints.
    pub shading: bool,
    /// Caustics on the floor.
    pub caustics: bool,
    /// Water depth for the caustics, pixels.
    #[serde(deserialize_with = "depth")]
    pub depth: f32,
    /// The sun (`"AZIMUTH,ELEVATION"`).
    #[serde(with = "display_from_str")]
    pub sun: Sun,
    /// The floor image, or `null` for the built-in tiles.
    pub background: Option<PathBuf>,
    /// The breeze's level; a header without it (recorded before the breeze existed) means 0.
    #[serde(default, deserialize_with = "breeze")]
    pub breeze: f64,
    /// How the breeze moves the water (`"gusts"`, `"wavelets"`); a header without it
    /// (recorded before the gusts existed) means the first breeze's wavelets.
    #[serde(default, with = "display_from_str")]
    pub breeze_style: BreezeStyle,
    /// Simulation cells per pixel along each axis; a header without it means 1, the papers'
    /// pool.
    #[serde(default = "one_cell_a_pixel", deserialize_with = "grid")]
    pub grid: u32,
    /// Simulation steps a second (how animations of the replay pace it); a header without it
    /// means the papers' 60.
    #[serde(default = "papers_pace", deserialize_with = "steps_per_second")]
    pub steps_per_second: u32,
}

impl PoolOptions {
    #[cfg(any(test, feature = "player"))]
    /// The options of pool `settings` whose floor came from `background` (`None`: built in).
    pub fn of(settings: &PoolSettings, background: Option<PathBuf>) -> PoolOptions {
        let caustics = settings.look.caustics;
        PoolOptions {
            damping: settings.damping,
            rain: settings.rain_rate,
            refraction: settings.look.refraction,
            shading: settings.look.shading,
            caustics: caustics.is_some(),
            depth: caustics.unwrap_or_default().depth_px(),
            sun: settings.look.sun,
            background,
            breeze: settings.breeze,
            breeze_style: settings.breeze_style,
            grid: settings.grid,
            steps_per_second: settings.steps_per_second,
        }
    }

    /// The pool these options describe, with `seed` and its `floor` (decoded from
    /// [`PoolOptions::background`], or the built-in one).
    pub fn settings(&self, seed: u64, floor: Pixmap) -> PoolSettings {
        let caustics = self.caustics.then(|| CausticsLook::with_depth(self.depth).unwrap_or_default());
        PoolSettings {
            damping: self.damping,
            rain_rate: self.rain,
            breeze: self.breeze,
            breeze_style: self.breeze_style,
            grid: self.grid,
            steps_per_second: self.steps_per_second,
            seed,
            look: PoolLook { refraction: self.refraction, shading: self.shading, caustics, sun: self.sun },
            floor,
        }
    }
}

/// An event and the step it happened at.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub(crate) struct Entry {
    /// Simulation steps run before the event.
    pub step: u64,
    /// What happened.
    #[serde(flatten)]
    pub event: Event,
}

/// A whole replay file.
#[derive(Clone, Debug, PartialEq)]
pub struct Replay {
    /// The header.
    pub(crate) header: Header,
    /// The events in order, the `end` event last.
    pub(crate) entries: Vec<Entry>,
}

impl Replay {
    /// Reads and checks a replay file.
    pub fn read(path: &Path) -> Result<Replay> {
        read_with(path, &Limits::default())
    }

    /// Parses replay text; `path` only names the file in errors.
    pub fn parse(path: &Path, text: &str) -> Result<Replay> {
        parse_with(path, text, &Limits::default())
    }

    /// [`Replay::parse`] with other limits (the fuzz target uses small ones, so every input is
    /// answered quickly).
    pub fn parse_with(path: &Path, text: &str, limits: &Limits) -> Result<Replay> {
        parse_with(path, text, limits)
    }

    /// The picture's size at the start, in pixels (width, height).
    pub fn size(&self) -> [u32; 2] {
        self.header.size
    }

    /// The replay as a file holds it: the header line, then one line an event (what
    /// [`Replay::parse`] reads back to an equal replay).
    pub fn to_text(&self) -> String {
        let mut text = header_line(&self.header) + "\n";
        for entry in &self.entries {
            text += &(event_line(entry) + "\n");
        }
        text
    }

    /// The step of the `end` line.
    pub fn end_step(&self) -> u64 {
        self.entries.last().map_or(0, |e| e.step)
    }

    /// The events with their steps, for a [`Script`].
    pub fn script(&self) -> Vec<(u64, Event)> {
        self.entries.iter().map(|e| (e.step, e.event.clone())).collect()
    }

    /// The scene at step 0, its floor being `floor`.
    pub fn spec(&self, floor: Pixmap) -> SceneSpec {
        SceneSpec::Pool(self.header.options.settings(self.header.seed, floor))
    }

    /// Re-simulates the session from `spec` (see [`Replay::spec`]) up to `steps` (its end when
    /// `None`). At an explicit step that holds a screenshot, the events recorded after that
    /// screenshot at that step are left out, so the result is exactly what the screenshot shows.
    /// `progress` is told the steps run so far, now and then.
    pub fn simulate(
        &self,
        spec: &SceneSpec,
        steps: Option<u64>,
        progress: &mut dyn FnMut(u64),
    ) -> Result<Box<dyn Playable>> {
        let [w, h] = self.header.size;
        let mut scene = spec.build(w, h)?;
        let script = self.script();
        let mut runner = Script::new(&script);
        let target = steps.unwrap_or(self.end_step());
        // In slices, so a long replay can show its progress; slices cost nothing.
        const SLICE: u64 = 4096;
        while runner.step() + SLICE < target {
            let next = runner.step() + SLICE;
            runner.run_to(scene.as_mut(), next);
            progress(next);
        }
        match steps {
            Some(_) => runner.run_to_screenshot(scene.as_mut(), target),
            None => runner.run_to(scene.as_mut(), target),
        }
        progress(target);
        Ok(scene)
    }
}

/// One header line, as written.
pub(crate) fn header_line(header: &Header) -> String {
    serde_json::to_string(header).expect("a header always serializes")
}

/// One event line, as written.
pub(crate) fn event_line(entry: &Entry) -> String {
    serde_json::to_string(entry).expect("an event always serializes")
}

/// [`Replay::read`] with other limits.
pub(crate) fn read_with(path: &Path, limits: &Limits) -> Result<Replay> {
    let fail = |line: usize, message: String| Error::Replay { path: path.to_owned(), line, message };
    let size = std::fs::metadata(path).map_err(|e| Error::io("cannot read", path, e))?.len();
    if size > limits.max_bytes {
        return Err(fail(
            1,
            format!(
                "the file is {:.0} MB, over the limit of {} MB for a replay; the file is damaged or not a tidepool replay",
                size as f64 / 1048576.0,
                limits.max_bytes >> 20
            ),
        ));
    }
    let text = std::fs::read_to_string(path).map_err(|e| Error::io("cannot read", path, e))?;
    parse_with(path, &text, limits)
}

/// [`Replay::parse_with`].
pub(crate) fn parse_with(path: &Path, text: &str, limits: &Limits) -> Result<Replay> {
    let fail = |line: usize, message: String| Error::Replay { path: path.to_owned(), line, message };
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l)).filter(|(_, l)| !l.trim().is_empty());
    let Some((first, line)) = lines.next() else {
        return Err(fail(1, "the file is empty; record one with `tidepool play --record FILE`".into()));
    };
    let header = parse_header(line, limits).map_err(|m| fail(first, m))?;
    let mut entries: Vec<Entry> = Vec::new();
    let mut last_line = first;
    for (number, line) in lines {
        last_line = number;
        if entries.last().is_some_and(|e| e.event == Event::End) {
            return Err(fail(number, "text after the end line; a replay ends with {\"end\": true}".into()));
        }
        if entries.len() >= limits.max_events {
            return Err(fail(
                number,
                format!(
                    "more than {} events, the limit for a replay; the file is damaged or not a tidepool replay",
                    limits.max_events
                ),
            ));
        }
        let entry = parse_event(line, limits).map_err(|m| fail(number, m))?;
        if let Some(previous) = entries.last()
            && entry.step < previous.step
        {
            return Err(fail(
                number,
                format!("step {} comes after step {}; events must be in step order", entry.step, previous.step),
            ));
        }
        entries.push(entry);
    }
    if entries.last().is_none_or(|e| e.event != Event::End) {
        return Err(fail(
            last_line + 1,
            "the replay stops without its {\"end\": true} line: the file is truncated; record it again".into(),
        ));
    }
    Ok(Replay { header, entries })
}

fn parse_json(line: &str) -> Result<serde_json::Map<String, Value>, String> {
    match serde_json::from_str::<Value>(line) {
        Ok(Value::Object(map)) => Ok(map),
        Ok(_) => Err("expected a JSON object {...}".into()),
        Err(e) if e.is_eof() => Err(format!("the line is cut short ({e}): the file is truncated; record it again")),
        Err(e) => Err(format!("not valid JSON: {e}")),
    }
}

fn parse_header(line: &str, limits: &Limits) -> Result<Header, String> {
    let map = parse_json(line)?;
    let format = map.get("tidepool_replay").ok_or(
        "not a tidepool replay: the first line has no \"tidepool_replay\" field; record one with `tidepool play --record FILE`",
    )?;
    match format.as_u64() {
        Some(FORMAT) => {}
        Some(n) if n > FORMAT => {
            let version = map.get("version").and_then(Value::as_str).unwrap_or("a newer tidepool");
            return Err(format!(
                "replay format {n} (recorded by {version}) is newer than this tidepool reads ({FORMAT}); update tidepool"
            ));
        }
        _ => return Err(format!("unknown replay format {format}; this tidepool reads format {FORMAT}")),
    }
    for name in ["scene", "seed", "size", "options"] {
        if !map.contains_key(name) {
            return Err(format!("the header has no \"{name}\" field"));
        }
    }
    check_size("size", &map["size"], limits)?;
    let header: Header = serde_json::from_value(Value::Object(map)).map_err(|e| format!("the header: {e}"))?;
    if header.scene != SceneKind::Pool {
        return Err(format!("this is a replay of the {0}; tidepool replays only the pool", header.scene));
    }
    Ok(header)
}

/// Checks a `[WIDTH, HEIGHT]` value against the picture limits and `limits.max_pixels`.
fn check_size(name: &str, value: &Value, limits: &Limits) -> Result<(), String> {
    let shape = || format!("\"{name}\" must be [WIDTH, HEIGHT] in pixels, each at least 1");
    let pair = value.as_array().filter(|a| a.len() == 2).ok_or_else(shape)?;
    let side = |v: &Value| v.as_i64().ok_or_else(shape);
    let (w, h) = (side(&pair[0])?, side(&pair[1])?);
    if w < 1 || h < 1 {
        return Err(shape());
    }
    let size = Size::new(w, h).map_err(|_| {
        format!(
            "\"{name}\" is {w}x{h}, over the picture limits ({} pixels a side, {} megapixels); the file is damaged or not a tidepool replay",
            crate::size::MAX_SIDE,
            crate::size::MAX_PIXELS >> 20
        )
    })?;
    if size.pixels() > limits.max_pixels {
        return Err(format!(
            "\"{name}\" is {size}, over the limit of {} pixels for a replay; the file is damaged or not a tidepool replay",
            limits.max_pixels
        ));
    }
    Ok(())
}

fn parse_event(line: &str, limits: &Limits) -> Result<Entry, String> {
    let mut map = parse_json(line)?;
    let step = map
        .remove("step")
        .ok_or("an event needs a \"step\" field")?
        .as_u64()
        .ok_or("\"step\" must be a whole number >= 0")?;
    if step > limits.max_steps {
        return Err(format!(
            "step {step} is past the limit of {} steps (46 hours at 60 steps a second); the file is damaged or not a tidepool replay",
            limits.max_steps
        ));
    }
    if map.len() != 1 {
        let keys: Vec<&String> = map.keys().collect();
        return Err(format!("expected exactly one event besides \"step\", found {keys:?}"));
    }
    let name = map.keys().next().expect("one entry").clone();
    if !Event::NAMES.contains(&name.as_str()) {
        return Err(format!(
            "unknown event \"{name}\"; this tidepool knows stone, rain, damping, breeze, clear, resize, screenshot, wind, noise and end"
        ));
    }
    if name == "resize" {
        check_size("resize", &map["resize"], limits)?;
    }
    if let Some(Value::String(file)) = map.get("screenshot")
        && file.len() > MAX_NAME_BYTES
    {
        return Err(format!("the screenshot's name is longer than {MAX_NAME_BYTES} bytes"));
    }
    let event = serde_json::from_value::<Event>(Value::Object(map)).map_err(|e| {
        let message = e.to_string();
        if message.starts_with("bad ") { message } else { format!("\"{name}\": {message}") }
    })?;
    Ok(Entry { step, event })
}

/// The longest screenshot name a replay may hold.
const MAX_NAME_BYTES: usize = 4096;

/// The scene's name as a string.
mod scene_name {
    use super::*;

    pub fn serialize<S: serde::Serializer>(kind: &SceneKind, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(kind.name())
    }

    pub fn deserialize<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<SceneKind, D::Error> {
        let text = String::deserialize(deserializer)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

/// Values written with `Display` and read with `FromStr` (a number is read as its text).
mod display_from_str {
    pub fn serialize<T: std::fmt::Display, S: serde::Serializer>(v: &T, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(v)
    }

    pub fn deserialize<'de, T, D>(deserializer: D) -> Result<T, D::Error>
    where
        T: std::str::FromStr<Err = crate::error::ValueError>,
        D: serde::Deserializer<'de>,
    {
        let text = crate::numbers::text_or_number(deserializer)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

fn rain<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
    let text = crate::numbers::text_or_number(deserializer)?;
    crate::sim::rain::parse_rate(&text).map_err(|e| serde::de::Error::custom(format!("rain: {e}")))
}

fn breeze<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<f64, D::Error> {
    let text = crate::numbers::text_or_number(deserializer)?;
    crate::sim::breeze::parse_level(&text).map_err(|e| serde::de::Error::custom(format!("breeze: {e}")))
}

fn one_cell_a_pixel() -> u32 {
    1
}

fn grid<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<u32, D::Error> {
    let text = crate::numbers::text_or_number(deserializer)?;
    crate::scene::pool::parse_grid(&text).map_err(|e| serde::de::Error::custom(format!("grid: {e}")))
}

fn papers_pace() -> u32 {
    crate::scene::pool::POOL_STEPS_PER_SECOND as u32
}

fn steps_per_second<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<u32, D::Error> {
    let text = crate::numbers::text_or_number(deserializer)?;
    crate::scene::pool::parse_steps_per_second(&text)
        .map_err(|e| serde::de::Error::custom(format!("steps_per_second: {e}")))
}

fn depth<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<f32, D::Error> {
    let text = crate::numbers::text_or_number(deserializer)?;
    CausticsLook::parse_depth(&text).map(|c| c.depth_px()).map_err(|e| serde::de::Error::custom(format!("depth: {e}")))
}

#[cfg(test)]
mod tests;
