//! `tidepool render ocean`: a wind-driven sea to a PNG, half-block text, a heightmap, an
//! animation (looping seamlessly with `--loop`) or tileable maps (`--maps`).

use std::io::IsTerminal;

use tiny_skia::Pixmap;

use tidepool::sea::{LoopPeriod, SEA_TEXTURE_TILE_M};
use tidepool::{CameraPose, Downsample, OceanScene, OceanSettings, OceanView, SceneSpec, SeaParams, SeaTexture};

use super::animate::{Animation, AnimationTarget, FrameSource, animate, check_animation_flags, render_frames};
use super::output::{DEFAULT_PNG_SIZE, OutputPlan, default_ssaa, terminal_pixels, too_large};
use super::still::{self, Still};
use crate::cli::Format;
use crate::cli::ocean::{RenderOcean, loop_period};
use crate::error::{Error, Result};

/// The sea of a `render ocean` command line, its loop checked against its own peak period.
fn sea_params(args: &RenderOcean) -> Result<SeaParams> {
    let mut params = args.shape.params(args.wind.speed_m_s(), args.direction, args.output.seed)?;
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
        Some(path) => {
            SeaTexture::from_pixmap(&tidepool::load_image(path).map_err(Error::flag("--texture"))?, SEA_TEXTURE_TILE_M)
        }
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

/// `tidepool render ocean --frames N`: the sea from `--time` on, 1/60 s a step as in the
/// player; with `--loop T`, N frames spread evenly over one loop.
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
    let Some(period) = settings.sea.loop_period else {
        let spec = SceneSpec::Ocean(settings);
        return animate(&spec, size, &Animation::plain(frames, fps), &target, " or --ssaa", args.output.stats);
    };
    let make = || -> Result<Box<dyn FrameSource + '_>> {
        let scene = OceanScene::new(settings.clone(), size.width(), size.height())
            .ok_or_else(|| too_large(size, " or --ssaa"))?;
        Ok(Box::new(LoopFrames { scene, start_s: settings.start_time_s, period, frames }))
    };
    render_frames(&make, frames, fps, &target, args.output.stats)
}

/// The frames of one loop: frame k is the sea at `start + k·T/N`, so frame N would be frame 0
/// again and the animation wraps without a jump.
struct LoopFrames {
    scene: OceanScene,
    start_s: f64,
    period: LoopPeriod,
    frames: u32,
}

impl FrameSource for LoopFrames {
    fn size(&self) -> (u32, u32) {
        (self.scene.width(), self.scene.height())
    }

    fn draw(&mut self, k: u32, out: &mut Pixmap) -> Result<()> {
        self.scene.set_time(self.start_s + self.period.frame_time(k, self.frames));
        self.scene.render(out);
        Ok(())
    }
}
