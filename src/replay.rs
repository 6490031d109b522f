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
//! events in file order and then stepping. Events are *resolved*: a random stone is recorded
//! where it landed, so a replay never needs the player's random choices.
//!
//! The file is kept in memory while playing and written atomically when the session ends (on
//! `q`, a signal or a panic), so a replay on disk is always complete; a file without its `end`
//! line is reported as truncated.

use std::path::{Path, PathBuf};

use serde_json::{Value, json};

use crate::error::{Error, Result};
use crate::sim::noise::NoiseKind;
use crate::sim::ripple::{Damping, Stone};

/// The replay format this tidepool writes and reads.
pub const FORMAT: u64 = 1;

/// The first line of a replay.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// The tidepool version that recorded it (informational).
    pub version: String,
    /// The scene's name, e.g. `pool`.
    pub scene: String,
    /// The seed of everything random.
    pub seed: u64,
    /// The picture size at step 0, in pixels.
    pub size: [u32; 2],
    /// Every flag that changes pixels, as the scene defines them.
    pub options: serde_json::Map<String, Value>,
}

/// Something that happened during a session.
#[derive(Clone, Debug, PartialEq)]
pub enum Event {
    /// A stone (or a stir of the water) landed, in pixels.
    Stone(Stone),
    /// The rain rate changed (drops per step; 0 is off).
    Rain(f64),
    /// The damping changed.
    Damping(Damping),
    /// The water was stilled.
    Clear,
    /// The picture was resized to `[width, height]` pixels: still water at the new size.
    Resize([u32; 2]),
    /// A screenshot was saved to this file.
    Screenshot(String),
    /// The ocean's wind changed: speed in m/s and where it comes from, degrees clockwise from
    /// north.
    Wind([f64; 2]),
    /// The session ended.
    End,
    /// The lake's noise changed.
    Noise {
        /// Octaves summed.
        octaves: u32,
        /// Amplitude ratio between octaves.
        persistence: f64,
        /// Value or gradient noise.
        kind: NoiseKind,
    },
}

/// An event and the step it happened at.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    /// Simulation steps run before the event.
    pub step: u64,
    /// What happened.
    pub event: Event,
}

/// A whole replay file.
#[derive(Clone, Debug, PartialEq)]
pub struct Replay {
    /// The header.
    pub header: Header,
    /// The events in order, the `end` event last.
    pub entries: Vec<Entry>,
}

impl Replay {
    /// The step of the `end` line.
    pub fn end_step(&self) -> u64 {
        self.entries.last().map_or(0, |e| e.step)
    }
}

/// One header line, as written.
pub fn header_line(header: &Header) -> String {
    json!({
        "tidepool_replay": FORMAT,
        "version": header.version,
        "scene": header.scene,
        "seed": header.seed,
        "size": header.size,
        "options": header.options,
    })
    .to_string()
}

/// One event line, as written.
pub fn event_line(entry: &Entry) -> String {
    let step = entry.step;
    match &entry.event {
        Event::Stone(s) => json!({"step": step, "stone": [s.x, s.y, s.radius, s.weight]}),
        Event::Rain(rate) => json!({"step": step, "rain": rate}),
        Event::Damping(d) => json!({"step": step, "damping": d.to_string()}),
        Event::Clear => json!({"step": step, "clear": true}),
        Event::Resize(size) => json!({"step": step, "resize": size}),
        Event::Screenshot(file) => json!({"step": step, "screenshot": file}),
        Event::Wind(wind) => json!({"step": step, "wind": wind}),
        Event::End => json!({"step": step, "end": true}),
        Event::Noise { octaves, persistence, kind } => {
            json!({"step": step, "noise": {"octaves": octaves, "persistence": persistence, "kind": kind.name()}})
        }
    }
    .to_string()
}

/// Reads and checks a replay file.
pub fn read(path: &Path) -> Result<Replay> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io("cannot read", path, e))?;
    parse(path, &text)
}

/// Parses replay text; `path` only names the file in errors.
pub fn parse(path: &Path, text: &str) -> Result<Replay> {
    let fail = |line: usize, message: String| Error::Replay { path: path.to_owned(), line, message };
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l)).filter(|(_, l)| !l.trim().is_empty());
    let Some((first, line)) = lines.next() else {
        return Err(fail(1, "the file is empty; record one with `tidepool play --record FILE`".into()));
    };
    let header = parse_header(line).map_err(|m| fail(first, m))?;
    let mut entries: Vec<Entry> = Vec::new();
    let mut last_line = first;
    for (number, line) in lines {
        last_line = number;
        if entries.last().is_some_and(|e| e.event == Event::End) {
            return Err(fail(number, "text after the end line; a replay ends with {\"end\": true}".into()));
        }
        let entry = parse_event(line).map_err(|m| fail(number, m))?;
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

fn parse_header(line: &str) -> Result<Header, String> {
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
    let field = |name: &str| map.get(name).ok_or_else(|| format!("the header has no \"{name}\" field"));
    let scene = field("scene")?.as_str().ok_or("\"scene\" must be a string such as \"pool\"")?.to_owned();
    let seed = field("seed")?.as_u64().ok_or("\"seed\" must be a whole number >= 0")?;
    let size = parse_size(field("size")?).ok_or("\"size\" must be [WIDTH, HEIGHT] in pixels, each at least 1")?;
    let options = match field("options")? {
        Value::Object(o) => o.clone(),
        _ => return Err("\"options\" must be an object".into()),
    };
    let version = map.get("version").and_then(Value::as_str).unwrap_or("").to_owned();
    Ok(Header { version, scene, seed, size, options })
}

fn parse_size(v: &Value) -> Option<[u32; 2]> {
    let a = v.as_array()?;
    let side = |i: usize| a.get(i)?.as_u64().and_then(|n| u32::try_from(n).ok()).filter(|&n| n >= 1);
    (a.len() == 2).then_some(())?;
    Some([side(0)?, side(1)?])
}

fn parse_event(line: &str) -> Result<Entry, String> {
    let mut map = parse_json(line)?;
    let step = map
        .remove("step")
        .ok_or("an event needs a \"step\" field")?
        .as_u64()
        .ok_or("\"step\" must be a whole number >= 0")?;
    if map.len() != 1 {
        let keys: Vec<&String> = map.keys().collect();
        return Err(format!("expected exactly one event besides \"step\", found {keys:?}"));
    }
    let (name, value) = map.into_iter().next().expect("one entry");
    let event = match name.as_str() {
        "stone" => {
            let text = value
                .as_array()
                .filter(|a| a.len() == 4)
                .map(|a| a.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(","))
                .ok_or("\"stone\" must be [X, Y, RADIUS, WEIGHT]")?;
            Event::Stone(crate::cli::parse_stone(&text).map_err(|e| format!("bad stone: {e}"))?)
        }
        "rain" => {
            let rate = value.as_f64().ok_or("\"rain\" must be a number of drops per step")?;
            Event::Rain(crate::cli::parse_rate(&rate.to_string()).map_err(|e| format!("bad rain: {e}"))?)
        }
        "damping" => {
            let text = value.as_str().ok_or("\"damping\" must be a string: a shift \"1\"..\"15\" or \"off\"")?;
            Event::Damping(crate::cli::parse_damping(text).map_err(|e| format!("bad damping: {e}"))?)
        }
        "clear" => Event::Clear,
        "end" => Event::End,
        "resize" => Event::Resize(parse_size(&value).ok_or("\"resize\" must be [WIDTH, HEIGHT], each at least 1")?),
        "screenshot" => Event::Screenshot(value.as_str().ok_or("\"screenshot\" must be a file name")?.to_owned()),
        "wind" => {
            let pair = value.as_array().filter(|a| a.len() == 2).and_then(|a| Some([a[0].as_f64()?, a[1].as_f64()?]));
            let [speed, from] = pair.ok_or("\"wind\" must be [SPEED_M_S, FROM_DEG]")?;
            if !(0.0..=crate::cli::ocean::MAX_WIND_M_S).contains(&speed) || !from.is_finite() {
                return Err(format!("bad wind: {speed} m/s from {from} degrees"));
            }
            Event::Wind([speed, from])
        }
        "noise" => {
            let field = |name: &str| value.get(name).ok_or(format!("\"noise\" needs \"{name}\""));
            let octaves = field("octaves")?.to_string();
            let persistence = field("persistence")?.to_string();
            let kind = field("kind")?.as_str().ok_or("\"kind\" must be \"value\" or \"gradient\"")?;
            let kind = match kind {
                "value" => NoiseKind::Value,
                "gradient" => NoiseKind::Gradient,
                other => return Err(format!("bad noise: unknown kind \"{other}\"; use \"value\" or \"gradient\"")),
            };
            Event::Noise {
                octaves: crate::cli::lake::parse_octaves(&octaves).map_err(|e| format!("bad noise: {e}"))?,
                persistence: crate::cli::lake::parse_persistence(&persistence)
                    .map_err(|e| format!("bad noise: {e}"))?,
                kind,
            }
        }
        other => {
            return Err(format!(
                "unknown event \"{other}\"; this tidepool knows stone, rain, damping, clear, resize, screenshot, wind, noise and end"
            ));
        }
    };
    Ok(Entry { step, event })
}

/// Collects a session's events and writes them (atomically) when the session ends.
#[derive(Debug)]
pub struct Recorder {
    path: PathBuf,
    text: String,
    finished: bool,
    step: u64,
}

impl Recorder {
    /// A recorder that will write to `path`; fails now (before the session starts) when the
    /// file could never be written there.
    pub fn new(path: &Path, header: &Header) -> Result<Recorder> {
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        if path.is_dir() || !dir.is_dir() {
            return Err(Error::arg(
                "--record",
                format!("cannot write {}: give a file in an existing folder", path.display()),
            ));
        }
        let mut text = header_line(header);
        text.push('\n');
        Ok(Recorder { path: path.to_owned(), text, finished: false, step: 0 })
    }

    /// Records `event` at `step`.
    pub fn record(&mut self, step: u64, event: Event) {
        self.advance(step);
        if !self.finished {
            self.text.push_str(&event_line(&Entry { step, event }));
            self.text.push('\n');
        }
    }

    /// Notes that the session has reached `step` (where an interrupted session ends).
    pub fn advance(&mut self, step: u64) {
        self.step = self.step.max(step);
    }

    /// The latest step seen.
    pub fn step(&self) -> u64 {
        self.step
    }

    /// Adds the end line and writes the file (once; later calls do nothing).
    pub fn finish(&mut self, step: u64) -> Result<()> {
        if self.finished {
            return Ok(());
        }
        self.record(step, Event::End);
        self.finished = true;
        crate::output::atomic::write_file(&self.path, self.text.as_bytes())
    }

    /// The file it writes.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for Recorder {
    /// A session cut short by a panic still leaves a complete replay of what happened.
    fn drop(&mut self) {
        let _ = self.finish(self.step);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header() -> Header {
        let mut options = serde_json::Map::new();
        options.insert("damping".into(), json!("5"));
        Header { version: "0.1.0".into(), scene: "pool".into(), seed: 7, size: [20, 10], options }
    }

    fn text(entries: &[Entry]) -> String {
        let mut t = header_line(&header()) + "\n";
        for e in entries {
            t += &(event_line(e) + "\n");
        }
        t
    }

    fn err(text: &str) -> String {
        parse(Path::new("r.jsonl"), text).unwrap_err().to_string()
    }

    #[test]
    fn round_trip() {
        let entries = vec![
            Entry { step: 0, event: Event::Stone(Stone { x: -3, y: 4, radius: 5, weight: 160 }) },
            Entry { step: 3, event: Event::Rain(0.25) },
            Entry { step: 3, event: Event::Damping(Damping::Off) },
            Entry { step: 4, event: Event::Clear },
            Entry { step: 9, event: Event::Resize([30, 12]) },
            Entry { step: 9, event: Event::Screenshot("a b.png".into()) },
            Entry { step: 10, event: Event::Wind([4.5, 0.0]) },
            Entry { step: 11, event: Event::Noise { octaves: 6, persistence: 0.55, kind: NoiseKind::Gradient } },
            Entry { step: 12, event: Event::End },
        ];
        let replay = parse(Path::new("r"), &text(&entries)).unwrap();
        assert_eq!(replay, Replay { header: header(), entries });
        assert_eq!(replay.end_step(), 12);
    }

    #[test]
    fn errors_name_the_line() {
        let end = Entry { step: 5, event: Event::End };
        let good = text(&[Entry { step: 1, event: Event::Clear }, end.clone()]);
        let truncated = &good[..good.len() - 10];
        assert!(err(truncated).starts_with("r.jsonl, line 3: the line is cut short"), "{}", err(truncated));
        let lines: Vec<&str> = good.lines().collect();
        let missing_end = format!("{}\n{}\n", lines[0], lines[1]);
        assert!(err(&missing_end).contains("line 3: the replay stops without"), "{}", err(&missing_end));
        assert!(err("").contains("line 1: the file is empty"));
        assert!(err("{\"a\":1}").contains("line 1: not a tidepool replay"));
        let newer = good.replacen("\"tidepool_replay\":1", "\"tidepool_replay\":2", 1);
        assert!(err(&newer).contains("line 1: replay format 2 (recorded by 0.1.0) is newer"), "{}", err(&newer));
        let bad_event = good.replacen("\"clear\":true", "\"splash\":true", 1);
        assert!(err(&bad_event).contains("line 2: unknown event \"splash\""));
        let bad_stone = good.replacen("\"clear\":true", "\"stone\":[1,2,0,3]", 1);
        assert!(err(&bad_stone).contains("line 2: bad stone: the radius 0"), "{}", err(&bad_stone));
        let bad_noise =
            good.replacen("\"clear\":true", "\"noise\":{\"octaves\":0,\"persistence\":0.5,\"kind\":\"value\"}", 1);
        assert!(err(&bad_noise).contains("line 2: bad noise: the octave count 0"), "{}", err(&bad_noise));
        let backwards = good.replacen("\"step\":5", "\"step\":0", 1);
        assert!(err(&backwards).contains("line 3: step 0 comes after step 1"));
        let after_end = good.clone() + &event_line(&end) + "\n";
        assert!(err(&after_end).contains("line 4: text after the end line"));
        let no_size = good.replacen("\"size\":[20,10]", "\"size\":[0,10]", 1);
        assert!(err(&no_size).contains("line 1: \"size\""));
    }

    #[test]
    fn recorder_writes_only_when_finished() {
        let dir = std::env::temp_dir().join(format!("tidepool-rec-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("s.jsonl");
        let mut rec = Recorder::new(&path, &header()).unwrap();
        rec.record(2, Event::Clear);
        assert!(!path.exists());
        rec.finish(7).unwrap();
        rec.finish(9).unwrap();
        let replay = read(&path).unwrap();
        assert_eq!(replay.entries, vec![Entry { step: 2, event: Event::Clear }, Entry { step: 7, event: Event::End }]);
        assert!(Recorder::new(&dir.join("no/such/dir/x.jsonl"), &header()).is_err());
        assert!(Recorder::new(&dir, &header()).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
