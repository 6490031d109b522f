//! `tidepool render pool`: the ripple pool after some steps, with stones (or the default
//! cluster of six), to a PNG, half-block text, a heightmap or an animation.

use std::io::IsTerminal;

use crate::size::Size;
use crate::{Event, SceneSpec};

use super::animate::{Animation, AnimationTarget, animate};
use super::output::{DEFAULT_PNG_SIZE, OutputPlan, terminal_pixels};
use super::still::{self, Still};
use crate::cli::args::RenderPool;
use crate::cli::error::Result;

/// Runs `tidepool render pool`.
pub fn render(args: RenderPool) -> Result<()> {
    if let Some(frames) = args.animation.frames {
        return animate_pool(&args, frames);
    }
    let plan = OutputPlan::new(&args.output, "pool", std::io::stdout().is_terminal(), terminal_pixels())?;
    let spec = SceneSpec::Pool(args.pool.settings(args.output.seed, crate::cli::args::PoolDefaults::RENDER)?);
    let script = script(&args, plan.size);
    let steps = args.steps.unwrap_or_else(|| default_pool_steps(plan.size));
    let still = Still { spec: &spec, script: &script, steps, too_large_hint: "", print_stats: args.output.stats };
    still::render(&plan, still)
}

/// The stones as events at their steps: the flags' stones at step 0, or the default cluster
/// ([`crate::pool_showcase`]).
fn script(args: &RenderPool, size: Size) -> Vec<(u64, Event)> {
    if args.stones.is_empty() {
        crate::PoolScene::showcase(size.width(), size.height()).0
    } else {
        args.stones.iter().map(|&s| (0, Event::Stone(s))).collect()
    }
}

/// Steps before the picture is taken when `--steps` is not given (see [`crate::pool_showcase`]).
fn default_pool_steps(size: Size) -> u64 {
    crate::PoolScene::showcase(size.width(), size.height()).1
}

/// `tidepool render pool --frames N`: the stones (given or default) land at their steps, the
/// first frame after `--steps` steps (default 0, so the stones are seen falling).
fn animate_pool(args: &RenderPool, frames: u32) -> Result<()> {
    super::animate::check_animation_flags(&args.output)?;
    let target = AnimationTarget::from_out(args.output.out.as_deref(), "pool", args.animation.fps)?;
    let size = args.output.size.unwrap_or(DEFAULT_PNG_SIZE);
    let spec = SceneSpec::Pool(args.pool.settings(args.output.seed, crate::cli::args::PoolDefaults::RENDER)?);
    let script = script(args, size);
    let animation = Animation { frames, fps: args.animation.fps, start_step: args.steps.unwrap_or(0), script: &script };
    animate(&spec, size, &animation, &target, "", args.output.stats)
}
