//! The sea state a wind raises and what an engine needs from it: the spectra
//! (Pierson–Moskowitz, JONSWAP, TMA) and their directional spreading, swell from distant
//! storms, the Beaufort and WMO scales, choppiness, seamless loops, tileable maps and plots of
//! the spectrum.
//!
//! ```
//! use tidepool::sea::{PatchSea, SeaSpectrum, SpectrumChoice, SpectrumKind};
//! use tidepool::SeaParams;
//!
//! let choice = SpectrumChoice::new(SpectrumKind::Jonswap, None, Some(50.0), None)?;
//! let spectrum = SeaSpectrum::new(12.0, choice);
//! assert!(spectrum.significant_height_m() > 1.0);
//! let params = SeaParams { wind_m_s: 12.0, spectrum: choice, choppiness: 1.0, ..SeaParams::default() };
//! let maps = PatchSea::new(params, 64, 300.0)?.maps(0.0);
//! assert_eq!(maps.height.len(), 64 * 64);
//! let files = maps.files(None);
//! assert_eq!(files[0].0, "height.npy");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use crate::sim::looping::LoopPeriod;
pub use crate::sim::patch::{PatchMaps, PatchSea};
pub use crate::sim::sea_state::beaufort_speed_m_s;
pub use crate::sim::spectra::swell::{Swell, Swells};
pub use crate::sim::spectra::{
    Depth, Jonswap, SeaSpectrum, SpectrumChoice, SpectrumChoiceError, SpectrumKind, Spreading,
};
