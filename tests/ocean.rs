//! The ocean and `tidepool spectrum`, run through the binary as a user would: golden images of
//! two sea states and a half-block frame, heightmaps, and the errors of bad flags.

mod common;

use common::golden::{self, Tolerance};
use common::{read_npy, read_png, run, run_in, scratch, stderr};

fn sea_golden(beaufort: &str, direction: &str) {
    let dir = scratch(&format!("ocean_golden_b{beaufort}"));
    let out = run_in(
        &dir,
        &["render", "ocean", "--beaufort", beaufort, "--direction", direction, "--size", "192x108", "--out", "sea.png"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let picture = read_png(&dir.join("sea.png"));
    assert_eq!(picture.dimensions(), (192, 108));
    golden::check_png(&format!("ocean_b{beaufort}"), &picture, Tolerance::default());
}

#[test]
fn beaufort_3_golden() {
    sea_golden("3", "330");
}

#[test]
fn beaufort_8_golden() {
    sea_golden("8", "200");
}

#[test]
fn half_block_ocean_golden() {
    let dir = scratch("ocean_ansi");
    let out =
        run_in(&dir, &["render", "ocean", "--beaufort", "6", "--size", "80x48", "--time", "4", "--out", "sea.ans"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read(dir.join("sea.ans")).unwrap();
    assert_eq!(String::from_utf8_lossy(&text).lines().count(), 24, "two pixel rows per line");
    golden::check_ansi("ocean_small", &text, Tolerance::default());
}

#[test]
fn same_flags_same_bytes_and_time_moves_the_sea() {
    let dir = scratch("ocean_determinism");
    let render = |name: &str, time: &str| {
        let out = run_in(&dir, &["render", "ocean", "--size", "96x54", "--time", time, "--out", name]);
        assert!(out.status.success(), "{}", stderr(&out));
        std::fs::read(dir.join(name)).unwrap()
    };
    assert_eq!(render("a.png", "2"), render("b.png", "2"));
    assert_ne!(render("a.png", "2"), render("c.png", "3"));
    // Negative values are values, not flags: the sea before t = 0, a wind from -90° (west).
    let out =
        run_in(&dir, &["render", "ocean", "--size", "32x18", "--time", "-5", "--direction", "-90", "--out", "n.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
}

#[test]
fn the_heightmap_of_a_10_m_s_sea_has_its_significant_height() {
    let dir = scratch("ocean_heightmap");
    let out = run_in(
        &dir,
        &[
            "render",
            "ocean",
            "--wind",
            "10",
            "--size",
            "128x128",
            "--ssaa",
            "1",
            "--heightmap",
            "h.npy",
            "--out",
            "o.png",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let (rows, cols, values) = read_npy(&std::fs::read(dir.join("h.npy")).unwrap());
    assert_eq!((rows, cols, values.len()), (128, 128, 128 * 128));
    let mean = values.iter().map(|&v| f64::from(v)).sum::<f64>() / values.len() as f64;
    let var = values.iter().map(|&v| (f64::from(v) - mean).powi(2)).sum::<f64>() / values.len() as f64;
    let hs = 4.0 * var.sqrt();
    let want = 0.2413 * 100.0 / 9.81;
    // One patch of 8 x 8 peak wavelengths holds few independent waves: allow 20 %.
    assert!((hs / want - 1.0).abs() < 0.2, "Hs {hs:.3} m vs {want:.3} m");
    // The PNG form is centimetres around 32768.
    let out = run_in(&dir, &["render", "ocean", "--size", "64x32", "--heightmap", "h.png", "--extent", "500"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let png = image::open(dir.join("h.png")).unwrap();
    let grey = png.as_luma16().expect("16-bit grey");
    assert_eq!(grey.dimensions(), (64, 32));
    assert!(grey.pixels().all(|p| (32768 - 800..32768 + 800).contains(&p.0[0])), "within ±8 m");
    assert!(grey.pixels().any(|p| p.0[0] != 32768));
}

#[test]
fn spectrum_prints_lines_json_and_a_plot() {
    let out = run(&["spectrum", "--wind", "4"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    for line in [
        "peak frequency: 0.3188 Hz",
        "peak wavelength: 15.36 m",
        "significant wave height: 0.3936 m",
        "beaufort number: 3",
    ] {
        assert!(text.lines().any(|l| l == line), "missing '{line}' in:\n{text}");
    }
    let out = run(&["spectrum", "--beaufort", "8", "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    assert_eq!(json["wind_m_s"], 18.95);
    assert_eq!(json["beaufort"], 8);
    assert_eq!(json["wmo_sea_state"], 7);
    let dir = scratch("spectrum_plot");
    let out = run_in(&dir, &["spectrum", "--wind", "12", "--out", "plot.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(read_png(&dir.join("plot.png")).dimensions(), (1000, 440));
}

#[test]
fn bad_flags_are_one_line_errors_with_status_2() {
    let dir = scratch("ocean_errors");
    let cases: &[(&[&str], &str)] = &[
        (&["render", "ocean", "--wind", "61"], "--wind"),
        (&["render", "ocean", "--beaufort", "13"], "--beaufort"),
        (&["render", "ocean", "--wind", "5", "--beaufort", "3"], "--beaufort"),
        (&["render", "ocean", "--camera", "0,8,70"], "camera height"),
        (&["render", "ocean", "--sun", "10,-4"], "above the horizon"),
        (&["render", "ocean", "--ssaa", "5"], "--ssaa"),
        (&["render", "ocean", "--size", "8000x8000", "--ssaa", "2"], "megapixels"),
        (&["render", "ocean", "--extent", "300"], "--heightmap"),
        (&["render", "ocean", "--texture", "missing.png"], "no such file"),
        (&["spectrum", "--out", "plot.jpg"], ".png"),
    ];
    for (args, needle) in cases {
        let out = run_in(&dir, args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = stderr(&out);
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    assert!(std::fs::read_dir(&dir).unwrap().next().is_none(), "no file written by a refused command");
}
