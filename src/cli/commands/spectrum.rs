//! `tidepool spectrum`: the numbers of a sea's spectrum (Pierson–Moskowitz, JONSWAP or TMA,
//! spread by a named law, with its swells), and a plot of the sum.
//!
//! For a calm (wind 0) there is no peak: the peak lines print `none` (JSON `null`). The
//! JONSWAP lines (gamma, fetch, alpha) and the depth appear for the spectra that have them;
//! the peak and height lines are the wind sea's, each swell has its line, and the total
//! significant height and the sea state are the whole sea's.

use crate::SeaParams;
use crate::sim::sea_state::{beaufort_number, wmo_sea_state, wmo_sea_state_name};
use crate::sim::spectra::SpectrumChoice;

use crate::cli::args::ocean::{SpectrumCommand, wind_of};
use crate::cli::error::{Error, Result};
use crate::cli::files;

/// One line of the report: name, value (None = no value), unit, JSON key.
type Line = (&'static str, Option<f64>, &'static str, &'static str);

/// The report's lines for a sea.
pub fn report(params: &SeaParams) -> Vec<Line> {
    let sea = params.wind_spectrum();
    let hs = sea.significant_height_m();
    let total = params.significant_height_m();
    let mut lines = vec![("wind speed", Some(sea.wind_m_s()), "m/s", "wind_m_s")];
    if let SpectrumChoice::Jonswap(j) | SpectrumChoice::Tma(j, _) = sea.choice() {
        lines.push(("peak enhancement gamma", Some(j.gamma()), "", "gamma"));
        lines.push(("fetch", j.fetch_km(), "km", "fetch_km"));
        lines.push(("alpha", Some(sea.alpha()), "", "alpha"));
    }
    if let Some(depth) = sea.depth_m() {
        lines.push(("water depth", Some(depth), "m", "depth_m"));
    }
    lines.extend([
        ("peak frequency", sea.peak_hz(), "Hz", "peak_frequency_hz"),
        ("peak period", sea.peak_period_s(), "s", "peak_period_s"),
        ("peak wavelength", sea.peak_wavelength_m(), "m", "peak_wavelength_m"),
        ("significant wave height", Some(hs), "m", "significant_wave_height_m"),
    ]);
    if !params.swells.is_empty() {
        lines.push(("total significant wave height", Some(total), "m", "total_significant_wave_height_m"));
    }
    lines.extend([
        ("beaufort number", Some(f64::from(beaufort_number(sea.wind_m_s()))), "", "beaufort"),
        ("wmo sea state", Some(f64::from(wmo_sea_state(total))), "", "wmo_sea_state"),
    ]);
    lines
}

/// The spreading law and each swell, as text lines.
fn sea_lines(params: &SeaParams) -> String {
    let mut out = format!("spreading: {}\n", params.spreading.name());
    for (i, s) in params.swells.iter().enumerate() {
        out.push_str(&format!(
            "swell {}: {} m, {} s from {} degrees\n",
            i + 1,
            format_value(s.height_m()),
            format_value(s.period_s()),
            format_value(s.direction_from_deg())
        ));
    }
    out
}

/// Four significant digits, integers without decimals.
fn format_value(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e9 {
        return format!("{v:.0}");
    }
    let digits = (3 - v.abs().log10().floor() as i32).clamp(0, 8) as usize;
    format!("{v:.digits$}")
}

/// The text form: `name: value unit` lines.
pub fn text(params: &SeaParams) -> String {
    let mut out = format!("spectrum: {}\n", params.spectrum.kind().name());
    out.push_str(&sea_lines(params));
    for (name, value, unit, _) in report(params) {
        let line = match value {
            Some(v) if !unit.is_empty() => format!("{name}: {} {unit}", format_value(v)),
            Some(v) => format!("{name}: {}", format_value(v)),
            None if name == "fetch" => format!("{name}: unlimited"),
            None => format!("{name}: none"),
        };
        out.push_str(line.trim_end());
        out.push('\n');
    }
    let code = wmo_sea_state(params.significant_height_m());
    out.push_str(&format!("wmo sea state name: {}\n", wmo_sea_state_name(code)));
    out
}

/// The JSON form: one object, numbers or null; swells as a list of objects.
pub fn json(params: &SeaParams) -> String {
    let fields: Vec<String> = report(params)
        .into_iter()
        .map(|(_, value, _, key)| format!("\"{key}\": {}", value.map_or("null".to_string(), format_value)))
        .collect();
    let swells: Vec<String> = params
        .swells
        .iter()
        .map(|s| {
            format!(
                "{{\"height_m\": {}, \"period_s\": {}, \"from_deg\": {}}}",
                format_value(s.height_m()),
                format_value(s.period_s()),
                format_value(s.direction_from_deg())
            )
        })
        .collect();
    let code = wmo_sea_state(params.significant_height_m());
    format!(
        "{{\"spectrum\": \"{}\", \"spreading\": \"{}\", {}, \"swells\": [{}], \"wmo_sea_state_name\": \"{}\"}}\n",
        params.spectrum.kind().name(),
        params.spreading.name(),
        fields.join(", "),
        swells.join(", "),
        wmo_sea_state_name(code)
    )
}

/// Runs `tidepool spectrum`.
pub fn run(args: SpectrumCommand) -> Result<()> {
    let (wind, from) = wind_of(args.preset, &args.wind, args.direction);
    let sea = SeaParams {
        wind_m_s: wind,
        wind_from_deg: from,
        spectrum: args.spectrum.choice_or(args.preset)?,
        spreading: args.swell.spreading.unwrap_or_default(),
        swells: args.swell.swells_or(args.preset)?,
        ..SeaParams::default()
    };
    if let Some(path) = &args.out {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        if ext.as_deref() != Some("png") {
            return Err(Error::arg("--out", format!("'{}' must end in .png; the plot is a PNG", path.display())));
        }
        let picture = sea.spectrum_plot();
        files::write_file(path, &crate::encode::png(&picture))?;
    }
    let body = if args.json { json(&sea) } else { text(&sea) };
    super::output::write_stdout(body.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pm(wind: f64) -> SeaParams {
        SeaParams { wind_m_s: wind, ..SeaParams::default() }
    }

    fn sea(wind: f64, spectrum: SpectrumChoice) -> SeaParams {
        SeaParams { wind_m_s: wind, spectrum, ..SeaParams::default() }
    }

    #[test]
    fn the_report_of_a_10_m_s_wind() {
        let t = text(&pm(10.0));
        assert!(t.contains("peak frequency: 0.1275 Hz\n"), "{t}");
        assert!(t.contains("peak period: 7.841 s\n"), "{t}");
        assert!(t.contains("peak wavelength: 96.00 m\n"), "{t}");
        assert!(t.contains("significant wave height: 2.460 m\n"), "{t}");
        assert!(t.contains("beaufort number: 5\n") && t.contains("wmo sea state: 4\n"), "{t}");
    }

    #[test]
    fn json_and_calm() {
        let j = json(&pm(0.0));
        assert!(j.contains("\"peak_frequency_hz\": null") && j.contains("\"significant_wave_height_m\": 0"), "{j}");
        assert!(j.starts_with('{') && j.trim_end().ends_with('}'));
        assert!(text(&pm(0.0)).contains("peak period: none\n"));
        assert!(j.starts_with("{\"spectrum\": \"pm\", ") && !j.contains("gamma"), "{j}");
    }

    #[test]
    fn jonswap_and_tma_print_their_parameters() {
        use crate::sim::spectra::{SpectrumChoice as C, SpectrumKind};
        let fetch = sea(15.0, C::new(SpectrumKind::Jonswap, None, Some(15.0), None).unwrap());
        let t = text(&fetch);
        assert!(t.starts_with("spectrum: jonswap\n") && t.contains("peak enhancement gamma: 3.300\n"), "{t}");
        assert!(t.contains("fetch: 15 km\n") && t.contains("alpha: "), "{t}");
        let open = sea(15.0, C::new(SpectrumKind::Jonswap, None, None, None).unwrap());
        assert!(text(&open).contains("fetch: unlimited\n"));
        let shallow = sea(12.0, C::new(SpectrumKind::Tma, None, None, Some(4.0)).unwrap());
        let j = json(&shallow);
        assert!(j.contains("\"depth_m\": 4") && j.contains("\"fetch_km\": null"), "{j}");
        // The shallow sea's waves are shorter than the deep one's at the same wind.
        let deep = sea(12.0, C::new(SpectrumKind::Jonswap, None, None, None).unwrap());
        let wavelength = |p: &SeaParams| p.wind_spectrum().peak_wavelength_m().unwrap();
        assert!(wavelength(&shallow) < wavelength(&deep));
    }

    #[test]
    fn swells_add_lines_and_their_height() {
        use crate::sim::spectra::swell::{Swell, Swells};
        let swell = Swell::new(2.0, 12.0, 250.0).unwrap();
        let p = SeaParams { swells: Swells::new(&[swell]).unwrap(), ..pm(10.0) };
        let t = text(&p);
        assert!(t.contains("swell 1: 2 m, 12 s from 250 degrees\n"), "{t}");
        // sqrt(2.46² + 2²) = 3.1704 m.
        assert!(t.contains("total significant wave height: 3.170 m\n"), "{t}");
        assert!(t.contains("significant wave height: 2.460 m\n") && t.contains("spreading: paper\n"), "{t}");
        let j = json(&p);
        assert!(j.contains("\"swells\": [{\"height_m\": 2, \"period_s\": 12, \"from_deg\": 250}]"), "{j}");
    }
}
