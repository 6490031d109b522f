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
            seed: args.seed,
            octaves: args.octaves,
            persistence: args.persistence,
            noise: args.noise.into(),
        },
        ssaa,
    }
}

/// Runs `tidepool render lake`.
pub fn render_lake(args: RenderLake) -> Result<()> {
    let plan = OutputPlan::new(&args.output_args(), "lake", std::io::stdout().is_terminal(), terminal_pixels())?;
    let ssaa = args.ssaa.unwrap_or_else(|| default_ssaa(plan.format));
    check_pixels(plan.size, ssaa).map_err(|e| Error::arg("--size", format!("{e} (or lower --ssaa)")))?;
    let (width, height) = (plan.size.width, plan.size.height);
    let mut stats = Stats::default();
    let started = Instant::now();
    let mut scene = LakeScene::new(settings(&args, ssaa), width, height).ok_or_else(|| {
        Error::arg("--size", format!("cannot allocate a {width}x{height} picture; choose a smaller size or --ssaa"))
    })?;
    scene.set_time(args.time);
    stats.record("setup", started, "sky, shore and mirror".into());
    let started = Instant::now();
    let picture = scene.snapshot();
    let triangles = scene.renderer().triangle_count();
    stats.record("render", started, format!("{width}x{height}, ssaa {ssaa}, {triangles} triangles"));
    let started = Instant::now();
    let heights = plan.heightmap.is_some().then(|| scene.heightmap(width as usize, height as usize));
    if heights.is_some() {
        stats.record("sample", started, format!("heightmap {width}x{height}"));
    }
    // The supersampled buffers are the largest allocations; free them before encoding.
    drop(scene);
    plan.write_timed(&picture, heights.as_ref(), HEIGHTMAP_PNG_SCALE, &mut stats)?;
    if args.stats {
        eprint!("{}", stats.report());
    }
    Ok(())
}
