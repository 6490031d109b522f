//! `tidepool render lake`: Perlin-noise water and its mirrored shore to a PNG, half-block text,
//! a heightmap or an animation.

use std::io::IsTerminal;

use crate::{LakeParams, LakeSettings, SceneSpec};

use super::animate::{Animation, AnimationTarget, animate};
use super::output::{DEFAULT_PNG_SIZE, OutputPlan, default_ssaa, terminal_pixels};
use super::still::{self, Still};
use crate::cli::args::Format;
use crate::cli::args::lake::RenderLake;
use crate::cli::error::{Error, Result};

/// The validated settings of a `render lake` command line.
fn settings(args: &RenderLake, ssaa: u32) -> LakeSettings {
    LakeSettings {
        lake: LakeParams {
            wind_m_s: args.wind,
            seed: args.output.seed,
            octaves: args.octaves,
            persistence: args.persistence,
            noise: args.noise.into(),
        },
        ssaa,
        start_time_s: args.time,
    }
}

/// Runs `tidepool render lake`.
pub fn render(args: RenderLake) -> Result<()> {
    if let Some(frames) = args.animation.frames {
        return animate_lake(&args, frames);
    }
    let plan = OutputPlan::new(&args.output, "lake", std::io::stdout().is_terminal(), terminal_pixels())?;
    let ssaa = args.ssaa.unwrap_or_else(|| default_ssaa(plan.format));
    plan.size.check_supersampled(ssaa).map_err(|e| Error::arg("--size", format!("{e} (or lower --ssaa)")))?;
    let spec = SceneSpec::Lake(settings(&args, ssaa));
    let still =
        Still { spec: &spec, script: &[], steps: 0, too_large_hint: " or --ssaa", print_stats: args.output.stats };
    still::render(&plan, still)
}

/// `tidepool render lake --frames N`: the lake from `--time` on, 1/30 s a step as in the player.
fn animate_lake(args: &RenderLake, frames: u32) -> Result<()> {
    super::animate::check_animation_flags(&args.output)?;
    let target = AnimationTarget::from_out(args.output.out.as_deref(), "lake", args.animation.fps)?;
    let size = args.output.size.unwrap_or(DEFAULT_PNG_SIZE);
    let ssaa = args.ssaa.unwrap_or_else(|| default_ssaa(Format::Png));
    size.check_supersampled(ssaa).map_err(|e| Error::arg("--size", format!("{e} (or lower --ssaa)")))?;
    let spec = SceneSpec::Lake(settings(args, ssaa));
    animate(&spec, size, &Animation::plain(frames, args.animation.fps), &target, " or --ssaa", args.output.stats)
}
