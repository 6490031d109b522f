//! The WMO tables that name a sea: Beaufort numbers for wind speeds and sea-state codes for
//! significant wave heights.

/// The wind speed tidepool uses for each Beaufort number, m/s (the middle of the WMO range;
/// 0.15 for calm and 35 for hurricane force, whose range has no top).
pub const BEAUFORT_SPEEDS_M_S: [f64; 13] =
    [0.15, 0.9, 2.45, 4.4, 6.7, 9.35, 12.3, 15.5, 18.95, 22.6, 26.45, 30.55, 35.0];

/// The lower bound of each Beaufort number's wind range at 10 m, m/s (WMO).
pub const BEAUFORT_LOWER_M_S: [f64; 13] = [0.0, 0.3, 1.6, 3.4, 5.5, 8.0, 10.8, 13.9, 17.2, 20.8, 24.5, 28.5, 32.7];

#[cfg(any(feature = "cli", test))]
/// The upper bound of significant wave height (m) for WMO sea-state codes 0..=8; code 9 is
/// everything above 14 m.
pub const WMO_UPPER_HS_M: [f64; 9] = [0.0, 0.1, 0.5, 1.25, 2.5, 4.0, 6.0, 9.0, 14.0];

/// The wind speed of Beaufort number `b`, or `None` above 12.
pub fn beaufort_speed_m_s(b: u8) -> Option<f64> {
    BEAUFORT_SPEEDS_M_S.get(usize::from(b)).copied()
}

/// The Beaufort number of a wind speed: the largest number whose lower bound is <= `wind_m_s`.
pub fn beaufort_number(wind_m_s: f64) -> u8 {
    BEAUFORT_LOWER_M_S.iter().rposition(|&lower| lower <= wind_m_s).unwrap_or(0) as u8
}

#[cfg(any(feature = "cli", test))]
/// The WMO sea-state code (0 = calm, glassy .. 9 = phenomenal) of a significant wave height.
pub fn wmo_sea_state(hs_m: f64) -> u8 {
    WMO_UPPER_HS_M.iter().position(|&upper| hs_m <= upper).unwrap_or(9) as u8
}

#[cfg(any(feature = "cli", test))]
/// The WMO name of a sea-state code.
pub fn wmo_sea_state_name(code: u8) -> &'static str {
    const NAMES: [&str; 10] = [
        "calm (glassy)",
        "calm (rippled)",
        "smooth",
        "slight",
        "moderate",
        "rough",
        "very rough",
        "high",
        "very high",
        "phenomenal",
    ];
    NAMES[usize::from(code.min(9))]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::spectrum::PiersonMoskowitz;

    #[test]
    fn every_beaufort_speed_maps_back_to_its_number() {
        for b in 0..=12u8 {
            assert_eq!(beaufort_number(beaufort_speed_m_s(b).unwrap()), b);
        }
        assert_eq!(beaufort_speed_m_s(13), None);
        assert_eq!(beaufort_number(0.0), 0);
        assert_eq!(beaufort_number(3.39), 2);
        assert_eq!(beaufort_number(3.4), 3);
        assert_eq!(beaufort_number(60.0), 12);
    }

    #[test]
    fn sea_state_codes() {
        assert_eq!(wmo_sea_state(0.0), 0);
        assert_eq!(wmo_sea_state(0.05), 1);
        assert_eq!(wmo_sea_state(0.1), 1);
        assert_eq!(wmo_sea_state(2.46), 4);
        assert_eq!(wmo_sea_state(14.0), 8);
        assert_eq!(wmo_sea_state(14.01), 9);
        // A 10 m/s PM sea (Hs 2.46 m) is "moderate".
        let hs = PiersonMoskowitz::new(10.0).significant_height_m();
        assert_eq!(wmo_sea_state_name(wmo_sea_state(hs)), "moderate");
    }
}
