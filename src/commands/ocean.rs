//! `tidepool render ocean`: a wind-driven sea to a PNG, half-block text and a heightmap.

use std::io::IsTerminal;
use std::time::Instant;

use crate::cli::ocean::RenderOcean;
use crate::cli::{Format, check_pixels};
use crate::commands::render::{OutputPlan, Stats, terminal_pixels};
use crate::error::{Error, Result};
use crate::render::background;
use crate::render::camera::CameraPose;
use crate::render::ocean::OceanView;
use crate::render::supersample::Downsample;
use crate::render::texture::{SEA_TEXTURE_TILE_M, SeaTexture};
use crate::scene::ocean::{OceanScene, OceanSettings, default_extent_m};
use crate::sim::ocean::SeaParams;

/// Heightmap PNG levels per metre: centimetres.
pub const HEIGHTMAP_PNG_SCALE: f32 = 100.0;

/// The supersampling used when `--ssaa` is not given: 2 for PNG, 1 for text.
pub fn default_ssaa(format: Format) -> u32 {
    if format == Format::Png { 2 } else { 1 }
}

/// The validated settings of a `render ocean` command line.
pub fn settings(args: &RenderOcean, format: Format) -> OceanSettings {
    OceanSettings {
        sea: SeaParams {
            wind_m_s: args.wind.speed_m_s(),
            wind_from_deg: args.direction,
            seed: args.output.seed,
            ..SeaParams::default()
        },
        view: OceanView {
            camera: args.camera.unwrap_or(CameraPose::DEFAULT),
            sun_azimuth_deg: args.sun.0 as f32,
            sun_elevation_deg: args.sun.1 as f32,
            ssaa: args.ssaa.unwrap_or_else(|| default_ssaa(format)),
            downsample: Downsample::Box,
        },
    }
}

/// Runs `tidepool render ocean`.
pub fn render_ocean(args: RenderOcean) -> Result<()> {
    if let Some(frames) = args.animation.frames {
        return animate_ocean(&args, frames);
    }
    let plan = OutputPlan::new(&args.output, "ocean", std::io::stdout().is_terminal(), terminal_pixels())?;
    if args.extent.is_some() && plan.heightmap.is_none() {
        return Err(Error::arg(
            "--extent",
            "only sizes the --heightmap patch; add --heightmap FILE.npy or drop --extent",
        ));
    }
    let settings = settings(&args, plan.format);
    check_pixels(plan.size, settings.view.ssaa).map_err(|e| Error::arg("--size", format!("{e} (or lower --ssaa)")))?;
    let texture = match &args.texture {
        Some(path) => SeaTexture::from_pixmap(&background::load("--texture", path)?, SEA_TEXTURE_TILE_M),
        None => SeaTexture::builtin(),
    };
    let (width, height) = (plan.size.width, plan.size.height);
    let mut scene = OceanScene::new(settings, width, height, texture)
        .ok_or_else(|| super::render::too_large(plan.size, " or --ssaa"))?;
    scene.set_time(args.time);
    let mut stats = Stats::default();
    let started = Instant::now();
    let picture = scene.snapshot();
    let ssaa = scene.renderer().view().ssaa;
    let triangles = scene.renderer().triangle_count();
    stats.record("render", started, format!("{width}x{height}, ssaa {ssaa}, {triangles} triangles"));
    let extent = args.extent;
    let sample =
        |scene: &OceanScene, w, h| scene.heightmap(extent.unwrap_or_else(|| default_extent_m(scene.sea())), w, h);
    plan.sample_and_write(scene, &picture, sample, HEIGHTMAP_PNG_SCALE, stats, args.output.stats)
}

/// `tidepool render ocean --frames N`: the sea from `--time` on, 1/60 s a step as in the player.
fn animate_ocean(args: &RenderOcean, frames: u32) -> Result<()> {
    use super::animate::{Animation, AnimationTarget, animate};
    super::render::check_animation_flags(&args.output)?;
    if args.extent.is_some() {
        return Err(Error::arg("--extent", "only sizes the --heightmap patch, which animations do not write"));
    }
    let target = AnimationTarget::from_out(args.output.out.as_deref(), "ocean", args.animation.fps)?;
    let size = args.output.size.unwrap_or(super::render::DEFAULT_PNG_SIZE);
    let settings = settings(args, crate::cli::Format::Png);
    check_pixels(size, settings.view.ssaa).map_err(|e| Error::arg("--size", format!("{e} (or lower --ssaa)")))?;
    let texture = match &args.texture {
        Some(path) => SeaTexture::from_pixmap(&background::load("--texture", path)?, SEA_TEXTURE_TILE_M),
        None => SeaTexture::builtin(),
    };
    let time = args.time;
    let mut make = || -> Result<Box<dyn crate::scene::playable::Playable>> {
        let mut scene = OceanScene::new(settings, size.width, size.height, texture.clone())
            .ok_or_else(|| super::render::too_large(size, " or --ssaa"))?;
        scene.set_time(time);
        Ok(Box::new(scene))
    };
    animate(&mut make, &Animation::plain(frames, args.animation.fps), &target, args.output.stats)
}
