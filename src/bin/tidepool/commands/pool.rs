//! `tidepool render pool`: the ripple pool after some steps, with stones (or the default
//! cluster of six), to a PNG, half-block text, a heightmap or an animation.

use std::io::IsTerminal;

use tidepool::{Event, SceneSpec, Size, Stone};

use super::animate::{Animation, AnimationTarget, animate};
use super::output::{DEFAULT_PNG_SIZE, OutputPlan, terminal_pixels};
use super::still::{self, Still};
use crate::cli::{OutputArgs, RenderPool};
use crate::error::{Error, Result};

/// Runs `tidepool render pool`.
pub fn render(args: RenderPool) -> Result<()> {
    if let Some(path) = &args.replay {
        return super::replay::render(&args, path);
    }
    if let Some(frames) = args.animation.frames {
        return animate_pool(&args, frames);
    }
    let plan = OutputPlan::new(&args.output, "pool", std::io::stdout().is_terminal(), terminal_pixels())?;
    let spec = SceneSpec::Pool(args.pool.settings(args.output.seed, 0.0)?);
    let script = script(&args, plan.size);
    let steps = args.steps.unwrap_or_else(|| default_pool_steps(plan.size));
    let still = Still { spec: &spec, script: &script, steps, too_large_hint: "", print_stats: args.output.stats };
    still::render(&plan, still)
}

/// The stones as events at their steps: the flags' stones at step 0, or the default cluster.
fn script(args: &RenderPool, size: Size) -> Vec<(u64, Event)> {
    let mut script: Vec<(u64, Event)> = if args.stones.is_empty() {
        default_stones(size).into_iter().map(|(at, s)| (at, Event::Stone(s))).collect()
    } else {
        args.stones.iter().map(|&s| (0, Event::Stone(s))).collect()
    };
    script.sort_by_key(|(at, _)| *at);
    script
}

/// The stones of the default picture, as (step, stone): six stones falling one after another
/// in a cluster, so the picture shows young and old rings overlapping.
///
/// A ring lives about a hundred steps at the papers' damping whatever the picture's size, so
/// the cluster is laid out in pixels for a 360-pixel picture and shrunk (never enlarged) to fit
/// smaller ones; see [`default_pool_steps`].
pub fn default_stones(size: Size) -> Vec<(u64, Stone)> {
    let scale = default_scale(size);
    let (cx, cy) = (size.width() as f32 / 2.0, size.height() as f32 / 2.0);
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
            let stone = Stone::clamped(
                (cx + dx * scale) as i32,
                (cy + dy * scale) as i32,
                (r * scale.sqrt()).round().max(2.0) as u32,
                160,
            );
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
    (size.width().min(size.height()) as f32 / 360.0).min(1.0)
}

fn default_steps_scale(scale: f32) -> f32 {
    scale.max(1.0 / 3.0)
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
    check_animation_flags(&args.output)?;
    let target = AnimationTarget::from_out(args.output.out.as_deref(), "pool", args.animation.fps)?;
    let size = args.output.size.unwrap_or(DEFAULT_PNG_SIZE);
    let spec = SceneSpec::Pool(args.pool.settings(args.output.seed, 0.0)?);
    let script = script(args, size);
    let animation = Animation { frames, fps: args.animation.fps, start_step: args.steps.unwrap_or(0), script: &script };
    animate(&spec, size, &animation, &target, "", args.output.stats)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_stones_stay_inside_small_pictures() {
        for size in [Size::of(1, 1), Size::of(80, 48), Size::of(4000, 300)] {
            for (_, s) in default_stones(size) {
                assert!(s.x() >= 0 && s.y() >= 0 && s.x() < size.width() as i32 && s.y() < size.height() as i32);
                assert!((2..=1000).contains(&s.radius()));
            }
        }
    }
}
