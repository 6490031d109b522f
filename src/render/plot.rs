//! The plot of `tidepool spectrum --out`: E(f) and the spreading D(theta) at the peak (or,
//! with swell, the directions the whole sea's energy travels in), side by side, with axes,
//! ticks and labels in an embedded 8x8 bitmap font (`font8x8`, drawn at twice its size so it
//! reads at a glance).

use font8x8::UnicodeFonts;
use tiny_skia::{Color, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use crate::sim::ocean::SeaParams;
use crate::sim::spectra::swell::SwellSpectrum;
use crate::sim::spectra::{SeaSpectrum, SpectrumChoice};
#[cfg(any(test, feature = "testing"))]
use crate::sim::spectrum::PiersonMoskowitz;

/// Plot width, px.
pub const WIDTH: u32 = 1000;
/// Plot height, px.
pub const HEIGHT: u32 = 440;
const SCALE: i32 = 2;
const INK: [u8; 3] = [30, 34, 40];
const GRID: [u8; 3] = [222, 226, 232];
const CURVE: [u8; 3] = [20, 96, 170];
const PART: [u8; 3] = [150, 156, 166];

/// Draws `text` with its top-left corner at (x, y), `SCALE` pixels per font pixel.
pub fn draw_text(out: &mut Pixmap, x: i32, y: i32, text: &str, [r, g, b]: [u8; 3]) {
    let (w, h) = (out.width() as i32, out.height() as i32);
    let colour = tiny_skia::PremultipliedColorU8::from_rgba(r, g, b, 255).expect("opaque");
    let pixels = out.pixels_mut();
    for (i, ch) in text.chars().enumerate() {
        let glyph = font8x8::BASIC_FONTS.get(ch).unwrap_or([0; 8]);
        for (row, bits) in glyph.iter().enumerate() {
            for col in 0..8 {
                if bits >> col & 1 == 1 {
                    for dy in 0..SCALE {
                        for dx in 0..SCALE {
                            let px = x + (i as i32 * 8 + col) * SCALE + dx;
                            let py = y + row as i32 * SCALE + dy;
                            if px >= 0 && py >= 0 && px < w && py < h {
                                pixels[(py * w + px) as usize] = colour;
                            }
                        }
                    }
                }
            }
        }
    }
}

/// The pixel width of `text`.
pub fn text_width(text: &str) -> i32 {
    text.chars().count() as i32 * 8 * SCALE
}

/// About five round tick values covering `lo..=hi`.
pub fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return vec![lo];
    }
    let raw = (hi - lo) / 5.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 2.5, 5.0, 10.0].iter().map(|m| m * mag).find(|&s| s >= raw).unwrap_or(10.0 * mag);
    let mut v = (lo / step).ceil() * step;
    let mut out = Vec::new();
    while v <= hi + step * 1e-9 {
        out.push(if v.abs() < step * 1e-9 { 0.0 } else { v });
        v += step;
    }
    out
}

fn label(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

fn paint(rgb: [u8; 3]) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color_rgba8(rgb[0], rgb[1], rgb[2], 255);
    p
}

/// One panel: a frame at `rect`, ticks on both axes, the curve `points` (data units).
struct Panel {
    rect: Rect,
    x: (f64, f64),
    y: (f64, f64),
    x_ticks: Option<Vec<f64>>,
}

impl Panel {
    fn to_px(&self, x: f64, y: f64) -> (f32, f32) {
        let fx = ((x - self.x.0) / (self.x.1 - self.x.0)) as f32;
        let fy = ((y - self.y.0) / (self.y.1 - self.y.0)) as f32;
        (self.rect.left() + fx * self.rect.width(), self.rect.bottom() - fy * self.rect.height())
    }

    /// Draws the frame, the labels, the grey `parts` and the curve `points` over them.
    fn draw(
        &self,
        out: &mut Pixmap,
        (title, x_label, y_label): (&str, &str, &str),
        points: &[(f64, f64)],
        parts: &[Vec<(f64, f64)>],
    ) {
        let stroke = Stroke { width: 1.0, ..Stroke::default() };
        let r = self.rect;
        for tx in self.x_ticks.clone().unwrap_or_else(|| ticks(self.x.0, self.x.1)) {
            let (px, _) = self.to_px(tx, 0.0);
            line(out, (px, r.top()), (px, r.bottom()), GRID, &stroke);
            line(out, (px, r.bottom()), (px, r.bottom() + 5.0), INK, &stroke);
            let text = label(tx);
            draw_text(out, px as i32 - text_width(&text) / 2, r.bottom() as i32 + 9, &text, INK);
        }
        for ty in ticks(self.y.0, self.y.1) {
            let (_, py) = self.to_px(0.0, ty);
            line(out, (r.left(), py), (r.right(), py), GRID, &stroke);
            line(out, (r.left() - 5.0, py), (r.left(), py), INK, &stroke);
            let text = label(ty);
            draw_text(out, r.left() as i32 - 8 - text_width(&text), py as i32 - 8, &text, INK);
        }
        if let Some(path) = PathBuilder::from_rect(r).into() {
            out.stroke_path(&path, &paint(INK), &stroke, Transform::identity(), None);
        }
        for (curve, colour, width) in
            parts.iter().map(|p| (p.as_slice(), PART, 1.5)).chain(std::iter::once((points, CURVE, 2.5)))
        {
            let mut pb = PathBuilder::new();
            for (i, &(x, y)) in curve.iter().enumerate() {
                let (px, py) = self.to_px(x, y);
                if i == 0 { pb.move_to(px, py) } else { pb.line_to(px, py) }
            }
            if let Some(path) = pb.finish() {
                out.stroke_path(
                    &path,
                    &paint(colour),
                    &Stroke { width, ..Stroke::default() },
                    Transform::identity(),
                    None,
                );
            }
        }
        draw_text(out, r.left() as i32, r.top() as i32 - 44, title, INK);
        draw_text(
            out,
            (r.left() + r.width() / 2.0) as i32 - text_width(x_label) / 2,
            r.bottom() as i32 + 32,
            x_label,
            INK,
        );
        draw_text(out, r.left() as i32, r.top() as i32 - 22, y_label, INK);
    }
}

fn line(out: &mut Pixmap, a: (f32, f32), b: (f32, f32), rgb: [u8; 3], stroke: &Stroke) {
    let mut pb = PathBuilder::new();
    pb.move_to(a.0, a.1);
    pb.line_to(b.0, b.1);
    if let Some(path) = pb.finish() {
        out.stroke_path(&path, &paint(rgb), stroke, Transform::identity(), None);
    }
}

#[cfg(any(test, feature = "testing"))]
/// The plot of `sea`: E(f) from 0 to 3·fm, and D(theta) at fm over -180..180 degrees.
pub fn spectrum_plot(sea: &PiersonMoskowitz) -> Pixmap {
    sea_spectrum_plot(&SeaParams { wind_m_s: sea.wind_m_s(), ..SeaParams::default() })
}

impl SeaParams {
    /// A plot of this sea's spectrum, what `tidepool spectrum --out` draws: the wind sea's
    /// spectrum (its name, γ, fetch and depth and the spreading law in the heading) summed with
    /// its swells; left E(f), right the directions.
    pub fn spectrum_plot(&self) -> Pixmap {
        sea_spectrum_plot(self)
    }
}

/// The plot of any sea: the wind sea's spectrum (its name, γ, fetch and depth and the
/// spreading law in the heading) summed with its swells. Left, E(f) from 0 to 3 times the
/// highest peak frequency (each part in grey under the sum); right, D(theta) at the wind
/// sea's peak, or with swell the direction the whole sea's energy travels in,
/// ∫E(f, θ)df/m0 against θ from downwind (a Pierson–Moskowitz sea plots exactly as
/// [`spectrum_plot`]).
pub fn sea_spectrum_plot(params: &SeaParams) -> Pixmap {
    let mut out = Pixmap::new(WIDTH, HEIGHT).expect("a fixed, valid size");
    out.fill(Color::WHITE);
    let sea = params.wind_spectrum();
    let swells = params.swell_spectra();
    let (heading, swell_line) = sea_heading(params, &sea, &swells);
    draw_text(&mut out, 20, 12, &heading, INK);
    if let Some(line) = swell_line {
        draw_text(&mut out, 20, 34, &line, INK);
    }
    let peaks = sea.peak_hz().into_iter().chain(swells.iter().map(|s| s.peak_hz()));
    let Some(f_top) = peaks.reduce(f64::max) else {
        draw_text(&mut out, 20, 200, "calm: no wind, no waves (E = 0 everywhere)", INK);
        return out;
    };
    let (energy, parts) = energy_curves(&sea, &swells, f_top);
    let e_max = energy.iter().map(|p| p.1).fold(0.0, f64::max);
    let (spread, title) = spread_curve(params, &sea, &swells, f_top);
    let d_max = spread.iter().map(|p| p.1).fold(0.0, f64::max);
    let left = Panel {
        rect: Rect::from_ltrb(120.0, 110.0, 470.0, 360.0).unwrap(),
        x: (0.0, 3.0 * f_top),
        y: (0.0, e_max * 1.1),
        x_ticks: None,
    };
    left.draw(&mut out, ("E(f)", "frequency f, Hz", "m^2/Hz"), &energy, &parts);
    let right = Panel {
        rect: Rect::from_ltrb(590.0, 110.0, 940.0, 360.0).unwrap(),
        x: (-180.0, 180.0),
        y: (0.0, d_max * 1.1),
        x_ticks: Some(vec![-180.0, -90.0, 0.0, 90.0, 180.0]),
    };
    right.draw(&mut out, (&title, "theta to the wind, degrees", "1/rad"), &spread, &[]);
    out
}

/// Points on each curve of the sea's plots.
const CURVE_POINTS: usize = 400;

/// The plot's heading (spectrum, wind, JONSWAP's parameters, Hs) and its swell line, if any.
fn sea_heading(params: &SeaParams, sea: &SeaSpectrum, swells: &[SwellSpectrum]) -> (String, Option<String>) {
    let (u, hs) = (label(sea.wind_m_s()), params.significant_height_m());
    let mut heading = match sea.choice() {
        SpectrumChoice::PiersonMoskowitz => format!("Pierson-Moskowitz sea, U = {u} m/s, Hs = {hs:.2} m"),
        SpectrumChoice::Jonswap(j) | SpectrumChoice::Tma(j, _) => {
            let fetch = j.fetch_km().map_or("unlimited".to_string(), |f| format!("{} km", label(f)));
            let depth = sea.depth_m().map_or(String::new(), |d| format!(", h = {} m", label(d)));
            let name = if sea.depth_m().is_some() { "TMA" } else { "JONSWAP" };
            format!("{name}, U = {u} m/s, gamma {}, fetch {fetch}{depth}, Hs = {hs:.2} m", label(j.gamma()))
        }
    };
    if swells.is_empty() {
        return (heading, None);
    }
    heading = heading.replace(", Hs", " + swell, Hs");
    let swell_text: Vec<String> = swells
        .iter()
        .map(|s| {
            let w = s.swell();
            format!("{} m {} s from {}", label(w.height_m()), label(w.period_s()), label(w.direction_from_deg()))
        })
        .collect();
    (heading, Some(format!("swell {}", swell_text.join(", "))))
}

/// E(f) of the whole sea over 0..3 times the highest peak, and with swell each system's own.
#[allow(clippy::type_complexity)]
fn energy_curves(sea: &SeaSpectrum, swells: &[SwellSpectrum], f_top: f64) -> (Vec<(f64, f64)>, Vec<Vec<(f64, f64)>>) {
    let n = CURVE_POINTS;
    let f_at = |i: usize| 3.0 * f_top * i as f64 / n as f64;
    let energy = (0..=n)
        .map(|i| (f_at(i), sea.energy(f_at(i)) + swells.iter().map(|s| s.energy(f_at(i))).sum::<f64>()))
        .collect();
    let parts = if swells.is_empty() {
        Vec::new()
    } else {
        std::iter::once((0..=n).map(|i| (f_at(i), sea.energy(f_at(i)))).collect())
            .chain(swells.iter().map(|s| (0..=n).map(|i| (f_at(i), s.energy(f_at(i)))).collect()))
            .collect()
    };
    (energy, parts)
}

/// The right panel's curve and title: the wind sea's spreading at its peak, or with swell the
/// energy by direction of the whole sea.
fn spread_curve(
    params: &SeaParams,
    sea: &SeaSpectrum,
    swells: &[SwellSpectrum],
    f_top: f64,
) -> (Vec<(f64, f64)>, String) {
    let n = CURVE_POINTS;
    let degrees = |i: usize| -180.0 + 360.0 * i as f64 / n as f64;
    match (sea.peak_hz(), swells.is_empty()) {
        (Some(fm), true) => {
            let law = match sea.spreading_exponent(fm) {
                Some(s) => format!("s = {s:.2}"),
                None => "sech2".to_string(),
            };
            let curve = (0..=n).map(|i| (degrees(i), sea.spread(fm, degrees(i).to_radians()))).collect();
            (curve, format!("D(theta) at fm, {} {law}", sea.spreading().name()))
        }
        _ => {
            // ∫E(f, θ)df/m0 by the midpoint rule over 0..6 times the highest peak.
            let downwind = (params.wind_from_deg + 180.0).to_radians();
            let (steps, df) = (600, 6.0 * f_top / 600.0);
            let m0 = params.m0().max(1e-300);
            let curve = (0..=n)
                .map(|i| {
                    let theta = degrees(i).to_radians();
                    let e: f64 = (0..steps)
                        .map(|j| {
                            let f = (j as f64 + 0.5) * df;
                            let bearing = downwind + theta;
                            sea.directional_energy(f, theta)
                                + swells.iter().map(|s| s.directional_energy(f, bearing - s.bearing_rad())).sum::<f64>()
                        })
                        .sum::<f64>()
                        * df;
                    (degrees(i), e / m0)
                })
                .collect();
            (curve, "energy by direction (sum)".to_string())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round() {
        assert_eq!(ticks(0.0, 10.0), vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0]);
        assert_eq!(ticks(-1.0, 1.5), vec![-1.0, -0.5, 0.0, 0.5, 1.0, 1.5]);
        assert_eq!(label(0.25), "0.25");
        assert_eq!(label(3.0), "3");
    }

    #[test]
    fn the_plot_has_ink_and_a_curve() {
        let p = spectrum_plot(&PiersonMoskowitz::new(10.0));
        assert_eq!((p.width(), p.height()), (WIDTH, HEIGHT));
        let curve = p.pixels().iter().filter(|c| c.red() < 60 && c.blue() > 140).count();
        let ink = p.pixels().iter().filter(|c| c.red() < 60 && c.blue() < 60).count();
        assert!(curve > 500 && ink > 2000, "curve {curve}, ink {ink}");
        let calm = spectrum_plot(&PiersonMoskowitz::new(0.0));
        assert!(calm.pixels().iter().all(|c| !(c.red() < 60 && c.blue() > 140)));
    }
}
