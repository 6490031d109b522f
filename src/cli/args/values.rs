//! The parsers of the plain numbers people type for the scenes' settings: each reads the text,
//! saying what is wrong with text that is not a number, then calls the library's check of the
//! setting it is for (`PoolSettings::check_rain`, ...), which says what is wrong with the
//! number. clap puts the flag in front of either message.

use crate::{LakeSettings, OceanSettings, PoolSettings};

/// Parses a finite number; `what` names it in the message (`"wind speed"`), `example` shows a
/// good value.
pub fn number(text: &str, what: &str, example: &str) -> Result<f64, String> {
    let v: f64 =
        text.trim().parse().map_err(|_| format!("the {what} '{}' is not a number; e.g. {example}", text.trim()))?;
    if !v.is_finite() {
        return Err(format!("the {what} must be a finite number; e.g. {example}"));
    }
    Ok(v)
}

/// Parses a rain rate, drops per step.
pub fn parse_rate(text: &str) -> Result<f64, String> {
    let v: f64 = text.trim().parse().map_err(|_| format!("'{text}' is not a number; e.g. 0.05"))?;
    PoolSettings::check_rain(v).map_err(|e| e.to_string())
}

/// Parses a breeze level, 0..=4.
pub fn parse_breeze(text: &str) -> Result<f64, String> {
    PoolSettings::check_breeze(number(text, "breeze", "1")?).map_err(|e| e.to_string())
}

/// Parses a pace, 1..=240 simulation steps a second.
pub fn parse_steps_per_second(text: &str) -> Result<u32, String> {
    let steps: u64 = text.trim().parse().map_err(|_| format!("'{text}' is not a whole number of steps, e.g. 30"))?;
    PoolSettings::check_steps_per_second(steps).map_err(|e| e.to_string())
}

/// Parses a grid, 1..=4 simulation cells per pixel.
pub fn parse_grid(text: &str) -> Result<u32, String> {
    let grid: u64 =
        text.trim().parse().map_err(|_| format!("'{text}' is not a whole number of cells per pixel, e.g. 2"))?;
    PoolSettings::check_grid(grid).map_err(|e| e.to_string())
}

/// Parses the sea's wind speed, 0..=60 m/s.
pub fn parse_sea_wind(text: &str) -> Result<f64, String> {
    OceanSettings::check_wind(number(text, "wind speed", "10")?).map_err(|e| e.to_string())
}

/// Parses the lake's wind speed, 0..=30 m/s.
pub fn parse_lake_wind(text: &str) -> Result<f64, String> {
    LakeSettings::check_wind(number(text, "wind speed", "3")?).map_err(|e| e.to_string())
}

/// Parses an octave count, 1..=12.
pub fn parse_octaves(text: &str) -> Result<u32, String> {
    let v: i64 =
        text.trim().parse().map_err(|_| format!("the octave count '{}' is not a whole number; e.g. 5", text.trim()))?;
    LakeSettings::check_octaves(v).map_err(|e| e.to_string())
}

/// Parses a persistence, 0..=1.
pub fn parse_persistence(text: &str) -> Result<f64, String> {
    LakeSettings::check_persistence(number(text, "persistence", "0.5")?).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_that_is_not_a_number_is_named_and_numbers_go_to_the_librarys_checks() {
        assert_eq!(number(" 2.5 ", "wind speed", "10"), Ok(2.5));
        assert_eq!(number("fast", "wind speed", "10").unwrap_err(), "the wind speed 'fast' is not a number; e.g. 10");
        assert_eq!(number("inf", "breeze", "1").unwrap_err(), "the breeze must be a finite number; e.g. 1");
        assert_eq!(parse_rate("0.02"), Ok(0.02));
        assert_eq!(parse_rate("lots").unwrap_err(), "'lots' is not a number; e.g. 0.05");
        assert!(parse_rate("-1").unwrap_err().contains("'-1' must be a finite number >= 0"));
        assert_eq!(parse_rate("1e9").unwrap_err(), "1000000000 drops per step would boil the pool; use at most 10000");
        assert_eq!(parse_breeze("4"), Ok(4.0));
        assert!(parse_breeze("5").unwrap_err().contains("outside 0..=4"));
        assert_eq!(parse_grid(" 2 "), Ok(2));
        assert!(parse_grid("5").unwrap_err().contains("outside 1..=4"));
        assert!(parse_grid("1.5").unwrap_err().contains("whole number"));
        assert_eq!(parse_steps_per_second("30"), Ok(30));
        assert!(parse_steps_per_second("0").unwrap_err().contains("outside 1..=240"));
        assert_eq!(parse_sea_wind(" 60 "), Ok(60.0));
        for bad in ["-1", "60.5", "nan", "inf", "fast"] {
            assert!(parse_sea_wind(bad).is_err(), "{bad}");
        }
        assert_eq!(parse_lake_wind(" 30 "), Ok(30.0));
        for bad in ["-1", "30.5", "nan", "inf", "calm", ""] {
            assert!(parse_lake_wind(bad).is_err(), "{bad}");
        }
        assert!(parse_lake_wind("31").unwrap_err().contains("0..=30 m/s"));
        assert_eq!(parse_octaves("12"), Ok(12));
        assert!(parse_octaves("0").unwrap_err().contains("outside 1..=12"));
        assert!(parse_octaves("many").unwrap_err().contains("is not a whole number"));
        assert_eq!(parse_persistence("0"), Ok(0.0));
        assert!(parse_persistence("2").unwrap_err().contains("rougher"));
    }
}
