//! The host: the only owner of a scene. It holds the scene, its clock, the random source of
//! random stones, the list `tab` cycles through, and the recorder; [`Host::apply`] resolves a
//! person's [`Request`] and applies the events in one place, so a key's route is straight:
//! seat -> host -> scene, and a replay applies the same events through the same `Scene::apply`.
//!
//! The local player owns a host next to its seat and screen; `tidepool serve` runs one host on
//! its own thread for everyone. Time comes in as an argument, and files go out as data: a
//! screenshot is an [`Effect`] the door saves ([`Host::poll_effect`], then
//! [`Host::handle_saved`]), the recording is the text [`Host::finish`] hands out.

use std::path::PathBuf;
use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tiny_skia::Pixmap;

use super::clock::SimClock;
use super::request::Request;
use crate::error::{Result, ValueError};
use crate::replay::{FORMAT, Header, PoolOptions, Recorder};
#[cfg(any(feature = "testing", test))]
use crate::scene::SceneKind;
use crate::scene::{Action, Event, Playable, SceneSpec};

/// Random stones use their own generator, seeded from the seed xor this, so that pressing
/// `space` does not change the rain.
const STONE_SEED_MIX: u64 = 0x5354_4f4e_4553_0001;
/// Screenshot names tried before giving up on a free one.
const SCREENSHOT_NAMES: usize = 1000;

/// What the host runs.
#[derive(Clone)]
pub struct HostConfig {
    /// The scenes `tab` cycles through; the first is shown at the start.
    pub scenes: Vec<SceneSpec>,
    /// Seed of the random stones.
    pub seed: u64,
    /// Record the session (the pool only) to this file.
    pub record: Option<Recording>,
    /// Whether `s` takes screenshots (the door has somewhere to save them).
    pub screenshots: bool,
}

impl std::fmt::Debug for HostConfig {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("HostConfig")
            .field("scenes", &self.scenes.iter().map(SceneSpec::kind).collect::<Vec<_>>())
            .field("seed", &self.seed)
            .field("record", &self.record)
            .field("screenshots", &self.screenshots)
            .finish()
    }
}

/// What the host asks its door to do: the host writes no file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Effect {
    /// Save the scene's picture, a PNG, as `BASE.png` (or, when that is taken, the first free
    /// `BASE-N.png` for N up to 1000: [`Effect::names`]), then tell the host
    /// ([`Host::handle_saved`]).
    Screenshot {
        /// The name without its extension (`tidepool-pool-000120`).
        base: String,
        /// The PNG's bytes.
        png: Vec<u8>,
    },
}

impl Effect {
    /// The names a screenshot tries, in order.
    pub fn names(base: &str) -> impl Iterator<Item = String> + '_ {
        (1..=SCREENSHOT_NAMES).map(move |i| if i == 1 { format!("{base}.png") } else { format!("{base}-{i}.png") })
    }
}

/// Where a session is recorded.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Recording {
    /// The replay file.
    pub path: PathBuf,
    /// The floor image the pool was started with, for the header (`None`: the built-in one).
    pub background: Option<PathBuf>,
}

/// What the status line and the help say about the scene now.
#[derive(Clone, Debug, Default)]
pub struct SceneStatus {
    /// The scene's name (`pool`).
    pub name: &'static str,
    /// The scene's own summary (`rain 0.05 · damping 6`), plus whatever a server adds in front
    /// (`3 playing · `).
    pub detail: String,
    /// Whether the scene takes stones.
    pub takes_stones: bool,
    /// The status line's key hints, longest first.
    pub hints: &'static [&'static str],
    /// The scene's own keys for the help overlay.
    pub keys: Vec<(&'static str, &'static str)>,
    /// The simulation is paused.
    pub paused: bool,
}

/// The owner of a scene.
pub struct Host {
    scene: Box<dyn Playable>,
    scenes: Vec<SceneSpec>,
    current: usize,
    clock: SimClock,
    rng: ChaCha8Rng,
    recorder: Option<Recorder>,
    screenshots: bool,
    effects: Vec<Effect>,
    step: u64,
    status: SceneStatus,
}

impl std::fmt::Debug for Host {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Host")
            .field("scene", &self.scene.kind())
            .field("size", &self.scene.size())
            .field("step", &self.step)
            .finish_non_exhaustive()
    }
}

impl Host {
    /// The first scene of `config` at `size` pixels, its clock starting at `now`.
    ///
    /// Fails when there is no scene, the size cannot be allocated, or a recording is asked for
    /// a scene other than the pool.
    pub fn new(config: HostConfig, size: (u32, u32), now: Instant) -> Result<Host> {
        let first =
            config.scenes.first().ok_or_else(|| ValueError::new("scenes", "a host needs at least one scene"))?;
        let scene = first.build(size.0, size.1)?;
        let recorder = match (&config.record, first) {
            (Some(recording), SceneSpec::Pool(settings)) => {
                let header = Header {
                    format: FORMAT,
                    version: env!("CARGO_PKG_VERSION").into(),
                    scene: scene.kind(),
                    seed: config.seed,
                    size: [size.0, size.1],
                    options: PoolOptions::of(settings, recording.background.clone()),
                };
                Some(Recorder::new(&recording.path, &header))
            }
            (Some(_), _) => return Err(ValueError::new("record", "replays hold the pool only").into()),
            (None, _) => None,
        };
        let mut host = Host {
            clock: SimClock::new(scene.steps_per_second(), now),
            rng: ChaCha8Rng::seed_from_u64(config.seed ^ STONE_SEED_MIX),
            scene,
            scenes: config.scenes,
            current: 0,
            recorder,
            screenshots: config.screenshots,
            effects: Vec::new(),
            step: 0,
            status: SceneStatus::default(),
        };
        host.describe_scene();
        host.refresh_status();
        Ok(host)
    }

    /// The scene's picture size in pixels.
    pub fn size(&self) -> (u32, u32) {
        self.scene.size()
    }

    #[cfg(any(feature = "testing", test))]
    /// Which scene is shown.
    pub fn kind(&self) -> SceneKind {
        self.scene.kind()
    }

    #[cfg(any(feature = "testing", test))]
    /// Simulation steps run so far.
    pub fn step(&self) -> u64 {
        self.step
    }

    /// Resolves `request` with the scene, applies and records its events. Returns a message for
    /// the person who asked, when there is something to say (a screenshot's name, why `tab`
    /// did nothing).
    pub fn apply(&mut self, request: Request, now: Instant) -> Option<String> {
        match request {
            Request::Act(action) => self.act(action),
            Request::RandomStone { radius } => {
                let (w, h) = self.scene.size();
                let (x, y) = (self.rng.random_range(0..w) as i32, self.rng.random_range(0..h) as i32);
                self.act(Action::Stone { x, y, radius, big: false });
            }
            Request::TogglePause => {
                self.clock.set_paused(!self.clock.paused(), now);
                self.status.paused = self.clock.paused();
            }
            Request::NextScene => {
                let message = self.next_scene(now);
                self.refresh_status();
                return message;
            }
            Request::Screenshot => return self.screenshot(),
        }
        self.refresh_status();
        None
    }

    /// Draws at a new size (the local player's terminal was resized), through the same event
    /// a replay applies at the same step. A size the scene cannot take leaves it as it was.
    pub fn resize(&mut self, width: u32, height: u32) {
        if (width, height) != self.scene.size() {
            self.apply_event(Event::Resize([width, height]));
            self.refresh_status();
        }
    }

    /// Runs the steps due by `now` (none while paused); returns how many.
    pub fn advance(&mut self, now: Instant) -> u64 {
        let due = self.clock.due(now);
        self.scene.advance(due);
        self.step += due;
        if let Some(r) = &mut self.recorder {
            r.advance(self.step);
        }
        self.refresh_status();
        due
    }

    /// When the next step is due (`None` while paused).
    pub fn next_due(&self) -> Option<Instant> {
        self.clock.next_due()
    }

    /// Draws the scene into `out`, which has the scene's size.
    pub fn render(&mut self, out: &mut Pixmap) {
        self.scene.render(out);
        self.refresh_status();
    }

    /// What the status line and the help say now (kept current by every change the host
    /// makes to the scene).
    pub fn status(&self) -> &SceneStatus {
        &self.status
    }

    /// The scene's summary, refreshed in place (no allocation once its text has grown) after
    /// anything that may change it: the scene changes only through the host's own methods.
    fn refresh_status(&mut self) {
        self.status.detail.clear();
        self.scene.status(&mut self.status.detail);
    }

    /// What the door must do for the host (a screenshot to save), oldest first.
    pub fn poll_effect(&mut self) -> Option<Effect> {
        (!self.effects.is_empty()).then(|| self.effects.remove(0))
    }

    /// The door saved the screenshot as `name` (`Ok`), or could not (`Err`, why): recorded in
    /// the replay at the step it was asked at when saved. Returns the message for the person.
    pub fn handle_saved(&mut self, outcome: std::result::Result<String, String>) -> String {
        match outcome {
            Ok(name) => {
                let message = format!("saved {name}");
                self.apply_event(Event::Screenshot(name));
                self.refresh_status();
                message
            }
            Err(e) => format!("screenshot failed: {e}"),
        }
    }

    /// Ends the session: the recording's file (its path and its whole text) to save, once;
    /// `None` without a recording or on later calls.
    pub fn finish(&mut self) -> Option<(PathBuf, String)> {
        self.recorder.as_mut()?.finish(self.step)
    }

    fn act(&mut self, action: Action) {
        for event in self.scene.resolve(action) {
            self.apply_event(event);
        }
    }

    /// Applies an event and records it: the one way the scene changes.
    fn apply_event(&mut self, event: Event) {
        self.scene.apply(&event);
        if let Some(r) = &mut self.recorder {
            r.record(self.step, event);
        }
    }

    fn describe_scene(&mut self) {
        self.status = SceneStatus {
            name: self.scene.kind().name(),
            detail: String::with_capacity(128),
            takes_stones: self.scene.takes_stones(),
            hints: self.scene.hints(),
            keys: self.scene.help(),
            paused: self.clock.paused(),
        };
    }

    /// `tab`: the next scene, at the same size.
    fn next_scene(&mut self, now: Instant) -> Option<String> {
        let count = self.scenes.len();
        if count < 2 {
            return Some(format!("the {} is the only scene here", self.scene.kind()));
        }
        if self.recorder.is_some() {
            // A replay holds one scene; switching would make it lie.
            return Some("tab is off while recording (a replay holds one scene)".into());
        }
        let (w, h) = self.scene.size();
        let next = (self.current + 1) % count;
        match self.scenes[next].build(w, h) {
            Ok(scene) => {
                self.scene = scene;
                self.current = next;
                self.clock = SimClock::new(self.scene.steps_per_second(), now);
                self.describe_scene();
                None
            }
            Err(e) => Some(format!("cannot open the {}: {e}", self.scenes[next].kind())),
        }
    }

    /// Asks the door to save the scene's picture as `tidepool-SCENE-STEP.png` (a free name,
    /// recorded once saved); a message when it cannot be asked.
    fn screenshot(&mut self) -> Option<String> {
        if !self.screenshots {
            return Some("screenshots are off here".into());
        }
        let shot = match self.scene.snapshot() {
            Ok(shot) => shot,
            Err(e) => return Some(format!("screenshot failed: {e}")),
        };
        let base = format!("tidepool-{}-{:06}", self.scene.kind(), self.step);
        self.effects.push(Effect::Screenshot { base, png: crate::output::png::encode(&shot) });
        None
    }
}
