//! The lake through the binary as a user would run it: the library's pictures, determinism and
//! motion, heightmaps, and the errors of bad flags.

use crate::common::{read_npy, read_png, run_in, scratch, stderr};
use tidepool::LakeParams;

fn render(dir: &std::path::Path, args: &[&str]) -> Vec<u8> {
    let out = run_in(dir, &[&["render", "lake"][..], args].concat());
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    out.stdout
}

/// What `render lake` writes equals the library's picture of the same lake, bit for bit, in a
/// file and on standard output.
#[test]
fn the_command_line_draws_the_librarys_lakes() {
    use crate::goldens::{picture, rgba};
    use tidepool::{LakeSettings, SceneSpec};
    let dir = scratch("lake_cli_is_the_library");
    render(&dir, &["--wind", "6", "--time", "2.5", "--size", "192x108", "--out", "lake.png"]);
    let spec = |ssaa, time| {
        SceneSpec::Lake(LakeSettings {
            lake: LakeParams { wind_m_s: 6.0, ..LakeParams::default() },
            ssaa,
            start_time_s: time,
        })
    };
    assert!(read_png(&dir.join("lake.png")) == rgba(&picture(&spec(2, 2.5), 192, 108, &[], 0)));
    render(&dir, &["--wind", "6", "--time", "1", "--size", "80x48", "--out", "lake.ans"]);
    let text = tidepool::encode::halfblock(&picture(&spec(1, 1.0), 80, 48, &[], 0));
    assert_eq!(std::fs::read(dir.join("lake.ans")).unwrap(), text);
    let stdout = render(&dir, &["--wind", "6", "--time", "1", "--size", "80x48", "--out", "-"]);
    assert_eq!(stdout, text, "standard output gets the same text");
}

#[test]
fn same_flags_same_bytes_time_moves_the_water_and_flags_matter() {
    let dir = scratch("lake_determinism");
    let picture = |name: &str, extra: &[&str]| {
        render(&dir, &[&["--size", "96x54", "--out", name][..], extra].concat());
        std::fs::read(dir.join(name)).unwrap()
    };
    let base = picture("a.png", &["--wind", "5", "--time", "2"]);
    assert_eq!(base, picture("b.png", &["--wind", "5", "--time", "2"]));
    for (name, extra) in [
        ("t.png", &["--wind", "5", "--time", "2.2"][..]),
        ("g.png", &["--wind", "5", "--time", "2", "--noise", "gradient"]),
        ("o.png", &["--wind", "5", "--time", "2", "--octaves", "2"]),
        ("p.png", &["--wind", "5", "--time", "2", "--persistence", "0.8"]),
        ("s.png", &["--wind", "5", "--time", "2", "--seed", "9"]),
        ("w.png", &["--wind", "4", "--time", "2"]),
    ] {
        assert_ne!(base, picture(name, extra), "{extra:?} changes the picture");
    }
    // Negative times are values, not flags.
    render(&dir, &["--size", "32x18", "--time", "-5", "--out", "n.png"]);
    // A calm lake does not move.
    assert_eq!(picture("c1.png", &["--wind", "0", "--time", "0"]), picture("c2.png", &["--wind", "0", "--time", "9"]));
}

#[test]
fn animations_move_the_water() {
    let dir = scratch("lake_animation");
    render(&dir, &["--wind", "5", "--frames", "3", "--fps", "10", "--size", "48x27", "--out", "f_{frame}.png"]);
    let frames: Vec<Vec<u8>> = (0..3).map(|k| std::fs::read(dir.join(format!("f_{k}.png"))).unwrap()).collect();
    assert!(frames[0] != frames[1] && frames[1] != frames[2], "each frame a tenth of a second on");
    // The first frame is the picture at --time; animations take no heightmap.
    render(&dir, &["--wind", "5", "--size", "48x27", "--ssaa", "2", "--out", "still.png"]);
    assert_eq!(read_png(&dir.join("still.png")), read_png(&dir.join("f_0.png")));
    let out = run_in(&dir, &["render", "lake", "--frames", "2", "--heightmap", "h.npy", "--out", "a.gif"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--heightmap"));
}

#[test]
fn heightmaps_hold_the_water_in_metres_and_millimetres() {
    let dir = scratch("lake_heightmap");
    render(&dir, &["--wind", "8", "--size", "120x60", "--ssaa", "1", "--heightmap", "h.npy", "--out", "l.png"]);
    let (rows, cols, values) = read_npy(&std::fs::read(dir.join("h.npy")).unwrap());
    assert_eq!((rows, cols, values.len()), (60, 120, 7200));
    let rms = (values.iter().map(|&v| f64::from(v).powi(2)).sum::<f64>() / values.len() as f64).sqrt();
    let want = LakeParams { wind_m_s: 8.0, ..LakeParams::default() }.significant_height_m() / 4.0;
    assert!((rms / want - 1.0).abs() < 0.25, "rms {rms:.4} m vs Hs/4 {want:.4} m");
    // The PNG form is millimetres around 32768; a calm lake is exactly flat.
    render(&dir, &["--wind", "8", "--size", "64x32", "--heightmap", "h.png", "--out", "l.png"]);
    let grey = image::open(dir.join("h.png")).unwrap().into_luma16();
    assert_eq!(grey.dimensions(), (64, 32));
    assert!(grey.pixels().all(|p| (32768 - 500..32768 + 500).contains(&p.0[0])), "within ±0.5 m");
    assert!(grey.pixels().any(|p| p.0[0] != 32768));
    render(&dir, &["--wind", "0", "--size", "16x8", "--heightmap", "c.npy", "--out", "c.png"]);
    assert!(read_npy(&std::fs::read(dir.join("c.npy")).unwrap()).2.iter().all(|&v| v == 0.0));
}

#[test]
fn bad_flags_are_one_line_errors_with_status_2() {
    let dir = scratch("lake_errors");
    let cases: &[(&[&str], &str)] = &[
        (&["--wind", "31"], "--wind"),
        (&["--wind", "-1"], "0..=30 m/s"),
        (&["--wind", "gale"], "not a number"),
        (&["--octaves", "0"], "--octaves"),
        (&["--octaves", "13"], "1..=12"),
        (&["--persistence", "1.5"], "--persistence"),
        (&["--persistence", "nan"], "finite"),
        (&["--noise", "perlin"], "--noise"),
        (&["--ssaa", "5"], "--ssaa"),
        (&["--time", "1e9"], "--time"),
        (&["--size", "8000x8000", "--ssaa", "2"], "megapixels"),
        (&["--heightmap", "h.txt"], ".npy"),
        (&["--out", "lake.jpg"], "--out"),
    ];
    for (args, needle) in cases {
        let out = run_in(&dir, &[&["render", "lake"][..], args].concat());
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = stderr(&out);
        let first = err.lines().next().unwrap_or("");
        assert!(first.contains(needle), "{args:?}: the first line names it: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    assert!(std::fs::read_dir(&dir).unwrap().next().is_none(), "no file written by a refused command");
}
