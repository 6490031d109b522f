//! The scenes a live session cycles through with `tab`, built from the scene flags that
//! `play` and `serve` share, so both start the same water from the same flags.

use crate::scene::SceneKind;
use crate::{LakeParams, LakeSettings, OceanSettings, OceanView, SceneSpec, SeaParams};

use crate::cli::args::{LiveSceneArgs, PlayScene};
use crate::cli::error::Result;

/// The lake the player starts with: the default breeze and noise, no supersampling (a
/// terminal cell is two pixels; the frame budget goes to the water instead).
pub fn lake_settings(seed: u64) -> LakeSettings {
    LakeSettings { lake: LakeParams { seed, ..LakeParams::default() }, ..LakeSettings::default() }
}

/// Every scene, in `tab` order, starting from `first`.
pub fn specs(first: PlayScene, flags: &LiveSceneArgs) -> Result<Vec<SceneSpec>> {
    let pool = flags.pool.settings(flags.seed, crate::cli::args::PoolDefaults::PLAYER)?;
    let default_view = OceanView::default();
    let ocean = OceanSettings {
        sea: flags.sea.shape().params(
            flags.wind.speed_m_s(),
            flags.direction.unwrap_or(SeaParams::DEFAULT_WIND_FROM_DEG),
            flags.seed,
        )?,
        view: OceanView {
            sun_azimuth_deg: flags.pool.sun.map_or(default_view.sun_azimuth_deg, |s| s.azimuth_deg()),
            sun_elevation_deg: flags.pool.sun.map_or(default_view.sun_elevation_deg, |s| s.elevation_deg()),
            ssaa: 1,
            shading: flags.sea.shading,
            ..default_view
        },
        ..OceanSettings::default()
    };
    let mut lake = lake_settings(flags.seed);
    if flags.wind.wind.is_some() || flags.wind.beaufort.is_some() {
        lake.lake.wind_m_s = flags.wind.speed_m_s().min(LakeParams::MAX_WIND_M_S);
    }
    // Tab goes through the scenes in their order, starting from the one asked for.
    let all = [SceneSpec::Pool(pool), SceneSpec::Ocean(ocean), SceneSpec::Lake(lake)];
    let first = SceneKind::from(first);
    let start = all.iter().position(|s| s.kind() == first).unwrap_or(0);
    Ok(all.iter().cycle().skip(start).take(all.len()).cloned().collect())
}
