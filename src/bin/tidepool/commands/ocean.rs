//! `tidepool render ocean`: a wind-driven sea to a PNG, half-block text, a heightmap or an
//! animation.

use std::io::IsTerminal;

use tidepool::sea::SEA_TEXTURE_TILE_M;
use tidepool::{CameraPose, Downsample, OceanSettings, OceanView, SceneSpec, SeaParams, SeaTexture};

use super::animate::{Animation, AnimationTarget, animate};
use super::output::{DEFAULT_PNG_SIZE, OutputPlan, default_ssaa, terminal_pixels};
use super::still::{self, Still};
use crate::cli::Format;
use crate::cli::ocean::RenderOcean;
use crate::error::{Error, Result};

/// The validated settings of a `render ocean` command line.
fn settings(args: &RenderOcean, format: Format) -> Result<OceanSettings> {
    let texture = match &args.texture {
        Some(path) => {
            SeaTexture::from_pixmap(&tidepool::load_image(path).map_err(Error::flag("--texture"))?, SEA_TEXTURE_TILE_M)
        }
        None => SeaTexture::builtin(),
    };
    Ok(OceanSettings {
        sea: SeaParams { wind_m_s: args.wind.speed_m_s(), wind_from_deg: args.direction, seed: args.output.seed },
        view: OceanView {
            camera: args.camera.unwrap_or(CameraPose::DEFAULT),
            sun_azimuth_deg: args.sun.0 as f32,
            sun_elevation_deg: args.sun.1 as f32,
            ssaa: args.ssaa.unwrap_or_else(|| default_ssaa(format)),
            downsample: Downsample::Box,
        },
        texture,
        start_time_s: args.time,
        heightmap_extent_m: args.extent,
    })
}

/// Runs `tidepool render ocean`.
pub fn render(args: RenderOcean) -> Result<()> {
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
    let ssaa = args.ssaa.unwrap_or_else(|| default_ssaa(plan.format));
    plan.size.check_supersampled(ssaa).map_err(|e| Error::arg("--size", format!("{e} (or lower --ssaa)")))?;
    let spec = SceneSpec::Ocean(settings(&args, plan.format)?);
    let still =
        Still { spec: &spec, script: &[], steps: 0, too_large_hint: " or --ssaa", print_stats: args.output.stats };
    still::render(&plan, still)
}

/// `tidepool render ocean --frames N`: the sea from `--time` on, 1/60 s a step as in the player.
fn animate_ocean(args: &RenderOcean, frames: u32) -> Result<()> {
    super::animate::check_animation_flags(&args.output)?;
    if args.extent.is_some() {
        return Err(Error::arg("--extent", "only sizes the --heightmap patch, which animations do not write"));
    }
    let target = AnimationTarget::from_out(args.output.out.as_deref(), "ocean", args.animation.fps)?;
    let size = args.output.size.unwrap_or(DEFAULT_PNG_SIZE);
    let ssaa = args.ssaa.unwrap_or_else(|| default_ssaa(Format::Png));
    size.check_supersampled(ssaa).map_err(|e| Error::arg("--size", format!("{e} (or lower --ssaa)")))?;
    let spec = SceneSpec::Ocean(settings(args, Format::Png)?);
    animate(&spec, size, &Animation::plain(frames, args.animation.fps), &target, " or --ssaa", args.output.stats)
}
