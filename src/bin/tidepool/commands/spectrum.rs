//! `tidepool spectrum`: the numbers of a sea's spectrum (Pierson–Moskowitz, JONSWAP or TMA),
//! and a plot of it.
//!
//! For a calm (wind 0) there is no peak: the peak lines print `none` (JSON `null`). The
//! JONSWAP lines (gamma, fetch, alpha) and the depth appear for the spectra that have them.

use tidepool::sea::{
    SeaSpectrum, SpectrumChoice, beaufort_number, sea_spectrum_plot, wmo_sea_state, wmo_sea_state_name,
};

use crate::cli::ocean::SpectrumCommand;
use crate::error::{Error, Result};
use crate::files;

/// One line of the report: name, value (None = no value), unit, JSON key.
type Line = (&'static str, Option<f64>, &'static str, &'static str);

/// The report's lines for a sea.
pub fn report(sea: &SeaSpectrum) -> Vec<Line> {
    let hs = sea.significant_height_m();
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
        ("beaufort number", Some(f64::from(beaufort_number(sea.wind_m_s()))), "", "beaufort"),
        ("wmo sea state", Some(f64::from(wmo_sea_state(hs))), "", "wmo_sea_state"),
    ]);
    lines
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
pub fn text(sea: &SeaSpectrum) -> String {
    let mut out = format!("spectrum: {}\n", sea.choice().kind().name());
    for (name, value, unit, _) in report(sea) {
        let line = match value {
            Some(v) if !unit.is_empty() => format!("{name}: {} {unit}", format_value(v)),
            Some(v) => format!("{name}: {}", format_value(v)),
            None if name == "fetch" => format!("{name}: unlimited"),
            None => format!("{name}: none"),
        };
        out.push_str(line.trim_end());
        out.push('\n');
    }
    let code = wmo_sea_state(sea.significant_height_m());
    out.push_str(&format!("wmo sea state name: {}\n", wmo_sea_state_name(code)));
    out
}

/// The JSON form: one object, numbers or null.
pub fn json(sea: &SeaSpectrum) -> String {
    let fields: Vec<String> = report(sea)
        .into_iter()
        .map(|(_, value, _, key)| format!("\"{key}\": {}", value.map_or("null".to_string(), format_value)))
        .collect();
    let code = wmo_sea_state(sea.significant_height_m());
    format!(
        "{{\"spectrum\": \"{}\", {}, \"wmo_sea_state_name\": \"{}\"}}\n",
        sea.choice().kind().name(),
        fields.join(", "),
        wmo_sea_state_name(code)
    )
}

/// Runs `tidepool spectrum`.
pub fn run(args: SpectrumCommand) -> Result<()> {
    let sea = SeaSpectrum::new(args.wind.speed_m_s(), args.spectrum.choice()?);
    if let Some(path) = &args.out {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        if ext.as_deref() != Some("png") {
            return Err(Error::arg("--out", format!("'{}' must end in .png; the plot is a PNG", path.display())));
        }
        let picture = sea_spectrum_plot(&sea);
        files::write_file(path, &tidepool::encode::png(&picture))?;
    }
    let body = if args.json { json(&sea) } else { text(&sea) };
    super::output::write_stdout(body.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pm(wind: f64) -> SeaSpectrum {
        SeaSpectrum::new(wind, SpectrumChoice::PiersonMoskowitz)
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
        use tidepool::sea::{SpectrumChoice as C, SpectrumKind};
        let fetch = SeaSpectrum::new(15.0, C::new(SpectrumKind::Jonswap, None, Some(15.0), None).unwrap());
        let t = text(&fetch);
        assert!(t.starts_with("spectrum: jonswap\n") && t.contains("peak enhancement gamma: 3.300\n"), "{t}");
        assert!(t.contains("fetch: 15 km\n") && t.contains("alpha: "), "{t}");
        let open = SeaSpectrum::new(15.0, C::new(SpectrumKind::Jonswap, None, None, None).unwrap());
        assert!(text(&open).contains("fetch: unlimited\n"));
        let shallow = SeaSpectrum::new(12.0, C::new(SpectrumKind::Tma, None, None, Some(4.0)).unwrap());
        let j = json(&shallow);
        assert!(j.contains("\"depth_m\": 4") && j.contains("\"fetch_km\": null"), "{j}");
        // The shallow sea's waves are shorter than the deep one's at the same wind.
        let deep = SeaSpectrum::new(12.0, C::new(SpectrumKind::Jonswap, None, None, None).unwrap());
        assert!(shallow.peak_wavelength_m().unwrap() < deep.peak_wavelength_m().unwrap());
    }
}
