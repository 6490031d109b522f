//! The sea state a wind raises and what an engine needs from it: the spectra
//! (Pierson–Moskowitz, JONSWAP, TMA) and their directional spreading, swell from distant
//! storms, the Beaufort and WMO scales, choppiness, seamless loops, tileable maps and plots of
//! the spectrum.
//!
//! The sea is set on [`crate::SeaParams`] with its `with_*` builders, which take plain numbers
//! and check them (the spectra's, swells' and loop's checked types stay inside the crate); this
//! module holds what those builders and a caller's own numbers need besides.
//!
//! ```
//! use tidepool::{OceanScene, OceanSettings, Scene, SeaParams};
//!
//! // A JONSWAP sea (a fetch of 50 km) under a 12 m/s wind.
//! let sea = SeaParams::default().with_wind_m_s(12.0).with_choppiness(1.0).with_jonswap(None, Some(50.0))?;
//! let mut scene = OceanScene::new(OceanSettings { sea, ..OceanSettings::default() }, 64, 36).expect("a small sea");
//! let picture = scene.snapshot()?;
//! assert_eq!((picture.width(), picture.height()), (64, 36));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use crate::sim::sea_state::beaufort_speed_m_s;
pub use crate::sim::spectra::Spreading;
