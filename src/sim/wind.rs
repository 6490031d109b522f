//! Wind speeds: the limits of the sea's and the lake's winds, checked where they enter.

use crate::error::ValueError;

/// The strongest wind the sea takes, m/s.
pub const MAX_SEA_WIND_M_S: f64 = 60.0;
/// The sea's wind when none is given, m/s (Beaufort 5, Hs 2.46 m).
pub const DEFAULT_SEA_WIND_M_S: f64 = 10.0;
/// Where the sea's default wind comes from, degrees clockwise from north (north-north-west: the
/// waves run towards the camera's right, across the default view).
pub const DEFAULT_WIND_FROM_DEG: f64 = 330.0;
/// The strongest wind the lake takes, m/s (a storm; beyond it a lake is all spray).
pub const MAX_LAKE_WIND_M_S: f64 = 30.0;

/// Checks the sea's wind speed.
pub fn check_sea_wind(v: f64) -> Result<f64, ValueError> {
    if !(0.0..=MAX_SEA_WIND_M_S).contains(&v) {
        return Err(ValueError::new(
            "wind speed",
            format!("the wind speed {v} is outside 0..={MAX_SEA_WIND_M_S} m/s (use --beaufort 0..=12 for named winds)"),
        ));
    }
    Ok(v)
}

/// Checks the lake's wind speed, `0..=`[`MAX_LAKE_WIND_M_S`] m/s.
pub fn check_lake_wind(v: f64) -> Result<f64, ValueError> {
    if !(0.0..=MAX_LAKE_WIND_M_S).contains(&v) {
        return Err(ValueError::new(
            "wind speed",
            format!(
                "the wind speed {v} is outside 0..={MAX_LAKE_WIND_M_S} m/s; use 0 for a mirror calm, 3 for a breeze, 10 for a strong wind"
            ),
        ));
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn winds() {
        assert_eq!(check_sea_wind(0.0), Ok(0.0));
        assert_eq!(check_sea_wind(60.0), Ok(60.0));
        for bad in [-1.0, 60.5, f64::NAN, f64::INFINITY] {
            assert!(check_sea_wind(bad).is_err(), "{bad}");
        }
        assert_eq!(check_lake_wind(30.0), Ok(30.0));
        for bad in [-1.0, 30.5, f64::NAN, f64::INFINITY] {
            assert!(check_lake_wind(bad).is_err(), "{bad}");
        }
        assert!(check_lake_wind(31.0).unwrap_err().to_string().contains("0..=30 m/s"));
    }
}
