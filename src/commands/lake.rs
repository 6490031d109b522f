//! `tidepool render lake`: Perlin-noise water and its mirrored shore to a PNG, half-block text
//! and a heightmap.

use std::io::IsTerminal;
use std::time::Instant;

use crate::cli::check_pixels;
use crate::cli::lake::RenderLake;
use crate::commands::ocean::default_ssaa;
use crate::commands::render::{OutputPlan, Stats, terminal_pixels};
use crate::error::{Error, Result};
use crate::scene::lake::{LakeScene, LakeSettings};
use crate::sim::lake::LakeParams;

/// Heightmap PNG levels per metre: millimetres (lake ripples are millimetres to centimetres).
pub const HEIGHTMAP_PNG_SCALE: f32 = 1000.0;

/// The validated settings of a `render lake` command line.
pub fn settings(args: &RenderLake, ssaa: u32) -> LakeSettings {
    LakeSettings {
        lake: LakeParams {
            wind_m_s: args.wind,
            seed: args.output.seed,
            octaves: args.octaves,
            persistence: args.persistence,
            noise: args.noise.into(),
        },
        ssaa,
    }
}

/// Runs `tidepool render lake`.
pub fn render_lake(args: RenderLake) -> Result<()> {
    if let Some(frames) = args.animation.frames {
        return animate_lake(&args, frames);
    }
    let plan = OutputPlan::new(&args.output, "lake", std::io::stdout().is_terminal(), terminal_pixels())?;
    let ssaa = args.ssaa.unwrap_or_else(|| default_ssaa(plan.format));
    check_pixels(plan.size, ssaa).map_err(|e| Error::arg("--size", format!("{e} (or lower --ssaa)")))?;
    let (width, height) = (plan.size.width, plan.size.height);
    let mut stats = Stats::default();
    let started = Instant::now();
    let mut scene = LakeScene::new(settings(&args, ssaa), width, height)
        .ok_or_else(|| super::render::too_large(plan.size, " or --ssaa"))?;
    scene.set_time(args.time);
    stats.record("setup", started, "sky, shore and mirror".into());
    let started = Instant::now();
    let picture = scene.snapshot();
    let triangles = scene.renderer().triangle_count();
    stats.record("render", started, format!("{width}x{height}, ssaa {ssaa}, {triangles} triangles"));
    let sample = |scene: &LakeScene, w, h| scene.heightmap(w, h);
    plan.sample_and_write(scene, &picture, sample, HEIGHTMAP_PNG_SCALE, stats, args.output.stats)
}

/// `tidepool render lake --frames N`: the lake from `--time` on, 1/30 s a step as in the player.
fn animate_lake(args: &RenderLake, frames: u32) -> Result<()> {
    use super::animate::{Animation, AnimationTarget, animate};
    super::render::check_animation_flags(&args.output)?;
    let target = AnimationTarget::from_out(args.output.out.as_deref(), "lake", args.animation.fps)?;
    let size = args.output.size.unwrap_or(super::render::DEFAULT_PNG_SIZE);
    let ssaa = args.ssaa.unwrap_or_else(|| default_ssaa(crate::cli::Format::Png));
    check_pixels(size, ssaa).map_err(|e| Error::arg("--size", format!("{e} (or lower --ssaa)")))?;
    let settings = settings(args, ssaa);
    let time = args.time;
    let mut make = || -> Result<Box<dyn crate::scene::playable::Playable>> {
        let mut scene = LakeScene::new(settings, size.width, size.height)
            .ok_or_else(|| super::render::too_large(size, " or --ssaa"))?;
        scene.set_time(time);
        Ok(Box::new(scene))
    };
    animate(&mut make, &Animation::plain(frames, args.animation.fps), &target, args.output.stats)
}
