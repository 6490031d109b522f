//! The ocean and `tidepool spectrum`, run through the binary as a user would: the library's
//! pictures, heightmaps, and the errors of bad flags.

use crate::common::{read_npy, read_png, run, run_in, scratch, stderr};

/// What `render ocean` writes equals the library's picture of the same sea, bit for bit.
#[test]
fn the_command_line_draws_the_librarys_seas() {
    use crate::goldens::{picture, rgba};
    use tidepool::sea::beaufort_speed_m_s;
    use tidepool::{OceanSettings, OceanView, SceneSpec, SeaParams};
    let dir = scratch("ocean_cli_is_the_library");
    let out = run_in(
        &dir,
        &["render", "ocean", "--beaufort", "8", "--direction", "200", "--size", "192x108", "--out", "sea.png"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let spec = |ssaa, time| {
        SceneSpec::Ocean(OceanSettings {
            sea: SeaParams { wind_m_s: beaufort_speed_m_s(8).unwrap(), wind_from_deg: 200.0, seed: 1 },
            view: OceanView { ssaa, ..OceanView::default() },
            start_time_s: time,
            ..OceanSettings::default()
        })
    };
    assert!(read_png(&dir.join("sea.png")) == rgba(&picture(&spec(2, 0.0), 192, 108, &[], 0)));
    let out = run_in(
        &dir,
        &[
            "render",
            "ocean",
            "--beaufort",
            "8",
            "--direction",
            "200",
            "--size",
            "80x48",
            "--time",
            "4",
            "--out",
            "sea.ans",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let text = tidepool::encode::halfblock(&picture(&spec(1, 4.0), 80, 48, &[], 0));
    assert_eq!(std::fs::read(dir.join("sea.ans")).unwrap(), text);
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
    // The PNG form is the same heights in centimetres around 32768: exactly the .npy of a run
    // with the same flags, rounded.
    let args = ["render", "ocean", "--size", "64x32", "--extent", "500", "--out", "o.png"];
    for map in ["h.png", "h2.npy"] {
        let out = run_in(&dir, &[&args[..], &["--heightmap", map]].concat());
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let png = image::open(dir.join("h.png")).unwrap();
    let grey = png.as_luma16().expect("16-bit grey");
    assert_eq!(grey.dimensions(), (64, 32));
    let (_, _, metres) = read_npy(&std::fs::read(dir.join("h2.npy")).unwrap());
    for (p, m) in grey.pixels().zip(&metres) {
        let want = ((m * 100.0).round() + 32768.0).clamp(0.0, 65535.0) as u16;
        assert_eq!(p.0[0], want, "{m} m");
    }
    assert!(grey.pixels().any(|p| p.0[0] != 32768), "the sea is not flat");
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
