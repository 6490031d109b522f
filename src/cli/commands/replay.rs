//! `tidepool render pool --replay FILE`: re-simulate a recorded session headless.
//!
//! The replay's header fixes the size, seed and every pixel-changing flag; its events are
//! applied through [`crate::Scene::apply`], the same method the player used, at the same
//! steps, so the picture at step S is bit-identical to a screenshot the player took at step S.

use std::io::IsTerminal;
use std::path::Path;
use std::time::Instant;

use crate::SceneSpec;
use crate::replay::Replay;
use crate::size::Size;

use super::animate::{Animation, AnimationTarget, animate};
use super::output::{OutputPlan, terminal_pixels};
use super::stats::Stats;
use crate::cli::args::RenderPool;
use crate::cli::error::{Error, Result};
use crate::cli::progress::Progress;

/// Runs `tidepool render pool --replay FILE`.
pub fn render(args: &RenderPool, path: &Path) -> Result<()> {
    let replay = Replay::read(path)?;
    let spec = spec(&replay)?;
    if let Some(frames) = args.animation.frames {
        return animate_replay(args, &replay, &spec, frames);
    }
    let mut plan = OutputPlan::new(&args.output, "pool", std::io::stdout().is_terminal(), terminal_pixels())?;
    let end = replay.end_step();
    let target = args.steps.unwrap_or(end);
    if target > end {
        return Err(Error::arg("--steps", format!("the replay ends at step {end}; choose --steps {end} or fewer")));
    }
    let mut stats = Stats::default();
    let started = Instant::now();
    let mut progress = Progress::new("steps", target);
    let mut done = 0;
    let mut scene = replay.simulate(&spec, args.steps, &mut |step| {
        progress.advance(step.saturating_sub(std::mem::replace(&mut done, step)))
    })?;
    drop(progress);
    stats.record("sim", started, format!("{target} steps of {}", path.display()));
    let (width, height) = scene.size();
    plan.size = Size::of(width, height);
    let started = Instant::now();
    let picture = scene.snapshot()?;
    stats.record("render", started, format!("{width}x{height}"));
    let heights = plan.heightmap.is_some().then(|| scene.heightmap(width as usize, height as usize));
    drop(scene);
    plan.write_timed(&picture, heights.as_ref(), &mut stats)?;
    stats.print_if(args.output.stats);
    Ok(())
}

/// The scene at the replay's start: its options, with its background decoded.
fn spec(replay: &Replay) -> Result<SceneSpec> {
    let floor = match &replay.header.options.background {
        Some(file) => crate::render::background::load(file).map_err(Error::flag("--replay (its background)"))?,
        None => crate::PoolSettings::default_floor(),
    };
    Ok(replay.spec(floor))
}

/// `tidepool render pool --replay FILE --frames N`: the session as an animation, from step 0
/// (or `--steps`), each event at its step.
fn animate_replay(args: &RenderPool, replay: &Replay, spec: &SceneSpec, frames: u32) -> Result<()> {
    super::animate::check_animation_flags(&args.output)?;
    let target = AnimationTarget::from_out(args.output.out.as_deref(), "pool", args.animation.fps)?;
    let [w, h] = replay.header.size;
    let script = replay.script();
    let animation = Animation { frames, fps: args.animation.fps, start_step: args.steps.unwrap_or(0), script: &script };
    animate(spec, Size::of(w, h), &animation, &target, "", args.output.stats)
}
