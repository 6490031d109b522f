//! A still picture: frame `steps` of the same run an animation, a replay or the player makes,
//! through the library's one scene contract.

use std::time::Instant;

use crate::scene::SceneKind;
use crate::scene::Script;
use crate::{Event, SceneSpec};

use super::output::{OutputPlan, size_error};
use super::stats::Stats;
use crate::cli::error::Result;
use crate::cli::progress::Progress;

/// What to render.
pub struct Still<'a> {
    /// The scene.
    pub spec: &'a SceneSpec,
    /// Events at steps (the pool's stones).
    pub script: &'a [(u64, Event)],
    /// Steps before the picture is taken.
    pub steps: u64,
    /// Another way out of a too-large picture, for its error (" or --ssaa").
    pub too_large_hint: &'static str,
    /// Print the stage timings (`--stats`).
    pub print_stats: bool,
}

/// Renders `still` and writes it (and its heightmap) where `plan` says.
pub fn render(plan: &OutputPlan, still: Still<'_>) -> Result<()> {
    let (width, height) = (plan.size.width(), plan.size.height());
    let mut stats = Stats::default();
    let started = Instant::now();
    let mut scene = still.spec.build(width, height).map_err(size_error(plan.size, still.too_large_hint))?;
    stats.record("setup", started, format!("{} {width}x{height}", scene.kind()));
    if still.steps > 0 {
        let started = Instant::now();
        let mut script = Script::new(still.script);
        let mut progress = Progress::new("steps", still.steps);
        // In slices, so a long run can show progress; slices of whole blocks cost nothing.
        while script.step() < still.steps {
            let next = (script.step() + 1024).min(still.steps);
            progress.advance(next - script.step());
            script.run_to(scene.as_mut(), next);
        }
        drop(progress);
        let detail = match scene.kind() {
            SceneKind::Pool => {
                let cells = f64::from(width) * f64::from(height) * still.steps as f64;
                let rate = cells / started.elapsed().as_secs_f64().max(1e-9) / 1e9;
                format!("{} steps, {rate:.2} G cell-updates/s", still.steps)
            }
            _ => format!("{} steps", still.steps),
        };
        stats.record("sim", started, detail);
    } else {
        Script::new(still.script).run_to(scene.as_mut(), 0);
    }
    let started = Instant::now();
    let picture = scene.snapshot().map_err(size_error(plan.size, still.too_large_hint))?;
    let describe = scene.describe();
    let detail =
        if describe.is_empty() { format!("{width}x{height}") } else { format!("{width}x{height}, {describe}") };
    stats.record("render", started, detail);
    let heights = plan.heightmap.is_some().then(|| {
        let started = Instant::now();
        let map = scene.heightmap(width as usize, height as usize);
        stats.record("sample", started, format!("heightmap {}x{}", map.width, map.height));
        map
    });
    // The scene's buffers are the largest allocation: free them before encoding.
    drop(scene);
    plan.write_timed(&picture, heights.as_ref(), &mut stats)?;
    stats.print_if(still.print_stats);
    Ok(())
}
