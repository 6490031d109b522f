//! The sea state a wind raises: the Pierson–Moskowitz spectrum, the Beaufort and WMO scales,
//! and a plot of the spectrum.

pub use crate::render::plot::spectrum_plot;
pub use crate::render::texture::SEA_TEXTURE_TILE_M;
pub use crate::sim::sea_state::{beaufort_number, beaufort_speed_m_s, wmo_sea_state, wmo_sea_state_name};
pub use crate::sim::spectrum::PiersonMoskowitz;
pub use crate::sim::wind::{DEFAULT_SEA_WIND_M_S, DEFAULT_WIND_FROM_DEG, MAX_LAKE_WIND_M_S, MAX_SEA_WIND_M_S};
