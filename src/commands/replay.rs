//! `tidepool render pool --replay FILE`: re-simulate a recorded session headless.
//!
//! The replay's header fixes the size, seed and every pixel-changing flag; its events are
//! applied through [`Playable::apply`], the same method the player used, at the same steps, so
//! the picture at step S is bit-identical to a screenshot the player took at step S.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use serde_json::{Map, Value, json};

use crate::cli::{PoolArgs, RenderPool, Size};
use crate::commands::render::{OutputPlan, terminal_pixels};
use crate::error::{Error, Result};
use crate::render::background;
use crate::render::caustics::CausticsLook;
use crate::render::pool::{PoolLook, Refraction};
use crate::replay::{self, Event, Replay};
use crate::scene::playable::Playable;
use crate::scene::pool::{PoolScene, PoolSettings};

/// The pool's pixel-changing flags as a replay header's `options`.
pub fn pool_options(args: &PoolArgs, rain: f64) -> Map<String, Value> {
    let refraction = match args.refraction {
        Refraction::Auto => "auto".to_string(),
        Refraction::Factor(f) => f.to_string(),
    };
    let background = args.background.as_ref().map(|p| p.display().to_string());
    let value = json!({
        "damping": args.damping.to_string(),
        "rain": rain,
        "refraction": refraction,
        "shading": !args.no_shading,
        "caustics": !args.no_caustics,
        "depth": args.depth,
        "sun": format!("{},{}", args.sun().azimuth_deg, args.sun().elevation_deg),
        "background": background,
    });
    match value {
        Value::Object(map) => map,
        _ => unreachable!("json! of an object literal is an object"),
    }
}

/// The pool settings (and background file) a replay header's `options` describe.
fn pool_settings(path: &Path, replay: &Replay) -> Result<(PoolSettings, Option<PathBuf>)> {
    let fail = |message: String| Error::Replay { path: path.to_owned(), line: 1, message };
    let options = &replay.header.options;
    let text = |name: &str| -> Result<String> {
        match options.get(name) {
            Some(Value::String(s)) => Ok(s.clone()),
            Some(Value::Number(n)) => Ok(n.to_string()),
            _ => Err(fail(format!("the options have no \"{name}\""))),
        }
    };
    let damping = crate::cli::parse_damping(&text("damping")?).map_err(|e| fail(format!("damping: {e}")))?;
    let rain = crate::cli::parse_rate(&text("rain")?).map_err(|e| fail(format!("rain: {e}")))?;
    let refraction =
        crate::cli::parse_refraction(&text("refraction")?).map_err(|e| fail(format!("refraction: {e}")))?;
    let flag = |name: &str| {
        options.get(name).and_then(Value::as_bool).ok_or_else(|| fail(format!("\"{name}\" must be true or false")))
    };
    let shading = flag("shading")?;
    let caustics = flag("caustics")?;
    let depth = crate::cli::parse_depth(&text("depth")?).map_err(|e| fail(format!("depth: {e}")))?;
    let sun = crate::cli::parse_sun(&text("sun")?).map_err(|e| fail(format!("sun: {e}")))?;
    let background = match options.get("background") {
        None | Some(Value::Null) => None,
        Some(Value::String(s)) => Some(PathBuf::from(s)),
        Some(_) => return Err(fail("\"background\" must be a file name or null".into())),
    };
    let look = PoolLook {
        refraction,
        shading,
        caustics: caustics.then(|| CausticsLook { depth_px: depth, ..CausticsLook::default() }),
        sun,
    };
    let settings = PoolSettings { damping, rain_rate: rain, seed: replay.header.seed, look };
    Ok((settings, background))
}

/// Re-simulates `replay` up to `steps` (default: its end). With an explicit step that holds a
/// screenshot, the events recorded after that screenshot at that step are left out, so the
/// result is exactly what the screenshot shows.
pub fn simulate(path: &Path, replay: &Replay, steps: Option<u64>) -> Result<PoolScene> {
    if replay.header.scene != "pool" {
        return Err(Error::Replay {
            path: path.to_owned(),
            line: 1,
            message: format!("this is a replay of the {0}; use `tidepool render {0} --replay`", replay.header.scene),
        });
    }
    let end = replay.end_step();
    let target = steps.unwrap_or(end);
    if target > end {
        return Err(Error::arg("--steps", format!("the replay ends at step {end}; choose --steps {end} or fewer")));
    }
    let (settings, background) = pool_settings(path, replay)?;
    let floor = match &background {
        Some(file) => background::load("--replay (its background)", file)?,
        None => background::pool_floor(),
    };
    let [w, h] = replay.header.size;
    let mut scene = PoolScene::new(w, h, floor, settings).ok_or_else(|| Error::Replay {
        path: path.to_owned(),
        line: 1,
        message: format!("cannot allocate a {w}x{h} pool"),
    })?;
    // Calm stretches between events go to `advance`, which is identical to stepping one by
    // one and much faster.
    let mut at = 0;
    for entry in replay.entries.iter().take_while(|e| e.step <= target) {
        scene.advance(entry.step - at);
        at = entry.step;
        if let Event::Resize([w, h]) = entry.event
            && (w.max(h) > crate::cli::MAX_SIDE || u64::from(w) * u64::from(h) > crate::cli::MAX_PIXELS)
        {
            return Err(Error::Replay {
                path: path.to_owned(),
                line: 1,
                message: format!("a resize to {w}x{h} is over the size limits"),
            });
        }
        if steps.is_some() && at == target && matches!(entry.event, Event::Screenshot(_)) {
            return Ok(scene);
        }
        Playable::apply(&mut scene, &entry.event);
    }
    scene.advance(target - at);
    Ok(scene)
}

/// Runs `tidepool render pool --replay FILE`.
pub fn render(args: &RenderPool, path: &Path) -> Result<()> {
    let replay = replay::read(path)?;
    if let Some(frames) = args.animation.frames {
        return animate(args, path, &replay, frames);
    }
    let mut plan = OutputPlan::new(&args.output, "pool", std::io::stdout().is_terminal(), terminal_pixels())?;
    let mut scene = simulate(path, &replay, args.steps)?;
    plan.size = Size { width: scene.width(), height: scene.height() };
    let picture = scene.snapshot();
    let stats = super::render::Stats::default();
    plan.sample_and_write(scene, &picture, |scene, _, _| scene.heightmap(), 1.0, stats, args.output.stats)
}

/// `tidepool render pool --replay FILE --frames N`: the session as an animation, from step 0
/// (or `--steps`), each event at its step.
fn animate(args: &RenderPool, path: &Path, replay: &Replay, frames: u32) -> Result<()> {
    use super::animate::{Animation, AnimationTarget};
    super::render::check_animation_flags(&args.output)?;
    if replay.header.scene != "pool" {
        return Err(Error::Replay {
            path: path.to_owned(),
            line: 1,
            message: format!("this is a replay of the {0}; use `tidepool render {0} --replay`", replay.header.scene),
        });
    }
    let target = AnimationTarget::from_out(args.output.out.as_deref(), "pool", args.animation.fps)?;
    let (settings, background) = pool_settings(path, replay)?;
    let floor = match &background {
        Some(file) => background::load("--replay (its background)", file)?,
        None => background::pool_floor(),
    };
    let [w, h] = replay.header.size;
    let script: Vec<(u64, Event)> = replay.entries.iter().map(|e| (e.step, e.event.clone())).collect();
    let mut make = || -> Result<Box<dyn Playable>> {
        PoolScene::new(w, h, floor.clone(), settings).map(|s| Box::new(s) as Box<dyn Playable>).ok_or_else(|| {
            Error::Replay { path: path.to_owned(), line: 1, message: format!("cannot allocate a {w}x{h} pool") }
        })
    };
    let animation = Animation { frames, fps: args.animation.fps, start_step: args.steps.unwrap_or(0), script: &script };
    super::animate::animate(&mut make, &animation, &target, args.output.stats)
}
