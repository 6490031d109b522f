//! The sea state a wind raises and what an engine needs from it: the spectra
//! (Pierson–Moskowitz, JONSWAP, TMA) and their directional spreading, swell from distant
//! storms, the Beaufort and WMO scales, choppiness, seamless loops, tileable maps and plots of
//! the spectrum.
//!
//! ```
//! use tidepool::sea::{SpectrumChoice, SpectrumKind};
//! use tidepool::{OceanScene, OceanSettings, Scene, SeaParams};
//!
//! // A JONSWAP sea (a fetch of 50 km) under a 12 m/s wind.
//! let choice = SpectrumChoice::new(SpectrumKind::Jonswap, None, Some(50.0), None)?;
//! let sea = SeaParams { wind_m_s: 12.0, spectrum: choice, choppiness: 1.0, ..SeaParams::default() };
//! let mut scene = OceanScene::new(OceanSettings { sea, ..OceanSettings::default() }, 64, 36).expect("a small sea");
//! let picture = scene.snapshot()?;
//! assert_eq!((picture.width(), picture.height()), (64, 36));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use crate::sim::looping::LoopPeriod;
pub use crate::sim::sea_state::beaufort_speed_m_s;
pub use crate::sim::spectra::swell::{Swell, Swells};
pub use crate::sim::spectra::{Depth, Jonswap, SpectrumChoice, SpectrumChoiceError, SpectrumKind, Spreading};
