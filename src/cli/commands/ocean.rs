//! `tidepool render ocean`: a wind-driven sea to a PNG, half-block text, a heightmap, an
//! animation (looping seamlessly with `--loop`) or tileable maps (`--maps`).

use std::io::IsTerminal;

use tiny_skia::Pixmap;

use crate::{CameraPose, Downsample, OceanScene, OceanSettings, OceanView, SceneSpec, SeaParams, SeaTexture};

use super::animate::{AnimationTarget, FrameSource, check_animation_flags, render_frames};
use super::output::{DEFAULT_PNG_SIZE, OutputPlan, default_ssaa, terminal_pixels, too_large};
use super::still::{self, Still};
use crate::cli::args::Format;
use crate::cli::args::ocean::{RenderOcean, default_shading, loop_period, wind_of};
use crate::cli::error::{Error, Result};

/// The sea of a `render ocean` command line, its loop checked against its own peak period.
fn sea_params(args: &RenderOcean) -> Result<SeaParams> {
    let (wind, from) = wind_of(args.preset, &args.wind, args.direction);
    let mut params = args.shape.params_or(args.preset, wind, from, args.output.seed)?;
    params.loop_period = match args.loop_seconds {
        Some(seconds) => Some(loop_period(seconds, &params)?),
        None => None,
    };
    Ok(params)
}

/// The validated settings of a `render ocean` command line.
fn settings(args: &RenderOcean, format: Format) -> Result<OceanSettings> {
    let sea = sea_params(args)?;
    let texture = match &args.texture {
        Some(path) => SeaTexture::from_pixmap(
            &crate::render::background::load(path).map_err(Error::flag("--texture"))?,
            SeaTexture::TILE_M,
        ),
        None => SeaTexture::builtin(),
    };
    Ok(OceanSettings {
        sea,
        view: OceanView {
            camera: args.camera.unwrap_or(CameraPose::DEFAULT),
            sun_azimuth_deg: args.sun.0 as f32,
            sun_elevation_deg: args.sun.1 as f32,
            ssaa: args.ssaa.unwrap_or_else(|| default_ssaa(format)),
            downsample: Downsample::Box,
            shading: args.shading.unwrap_or_else(|| default_shading(format)),
        },
        texture,
        start_time_s: args.time,
        heightmap_extent_m: args.extent,
    })
}

/// Runs `tidepool render ocean`.
pub fn render(args: RenderOcean) -> Result<()> {
    if let Some(dir) = &args.maps {
        return super::maps::write(&args, dir, sea_params(&args)?);
    }
    if let Some(frames) = args.animation.frames {
        return animate_ocean(&args, frames);
    }
    if args.loop_seconds.is_some() {
        return Err(Error::arg("--loop", "loops animations and maps; add --frames N or --maps DIR, or drop --loop"));
    }
    let plan = OutputPlan::new(&args.output, "ocean", std::io::stdout().is_terminal(), terminal_pixels())?;
    if args.extent.is_some() && plan.heightmap.is_none() {
        return Err(Error::arg(
            "--extent",
            "sizes the --heightmap or --maps patch; add --heightmap FILE.npy or --maps DIR, or drop --extent",
        ));
    }
    let ssaa = args.ssaa.unwrap_or_else(|| default_ssaa(plan.format));
    plan.size.check_supersampled(ssaa).map_err(|e| Error::arg("--size", format!("{e} (or lower --ssaa)")))?;
    let spec = SceneSpec::Ocean(settings(&args, plan.format)?);
    let still =
        Still { spec: &spec, script: &[], steps: 0, too_large_hint: " or --ssaa", print_stats: args.output.stats };
    still::render(&plan, still)
}

/// `tidepool render ocean --frames N`: frame k is the sea at `--time + k/fps`, the time since
/// `--time` counted apart from it, so that with `--loop T` frame T·fps is frame 0 again bit
/// for bit (foam included: its memory is the same steps of the same sea).
fn animate_ocean(args: &RenderOcean, frames: u32) -> Result<()> {
    check_animation_flags(&args.output)?;
    if args.extent.is_some() {
        return Err(Error::arg("--extent", "sizes the --heightmap or --maps patch, which animations do not write"));
    }
    let fps = args.animation.fps;
    let target = AnimationTarget::from_out(args.output.out.as_deref(), "ocean", fps)?;
    let size = args.output.size.unwrap_or(DEFAULT_PNG_SIZE);
    let ssaa = args.ssaa.unwrap_or_else(|| default_ssaa(Format::Png));
    size.check_supersampled(ssaa).map_err(|e| Error::arg("--size", format!("{e} (or lower --ssaa)")))?;
    let settings = settings(args, Format::Png)?;
    let make = || -> Result<Box<dyn FrameSource + '_>> {
        let scene = OceanScene::new(settings.clone(), size.width(), size.height())
            .ok_or_else(|| too_large(size, " or --ssaa"))?;
        Ok(Box::new(OceanFrames { scene, start_s: settings.start_time_s, fps }))
    };
    render_frames(&make, frames, fps, &target, args.output.stats)
}

/// The frames of an ocean animation: frame k is the sea `k/fps` seconds after the start.
struct OceanFrames {
    scene: OceanScene,
    start_s: f64,
    fps: u32,
}

impl FrameSource for OceanFrames {
    fn size(&self) -> (u32, u32) {
        (self.scene.width(), self.scene.height())
    }

    fn draw(&mut self, k: u32, out: &mut Pixmap) -> Result<()> {
        self.scene.set_clock(self.start_s, f64::from(k) / f64::from(self.fps));
        self.scene.render(out);
        Ok(())
    }
}
