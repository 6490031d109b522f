//! The ocean and `tidepool spectrum`, run through the binary as a user would: the library's
//! pictures, heightmaps, and the errors of bad flags.

use crate::common::{read_npy, read_png, run, run_in, scratch, stderr};

/// What `render ocean` writes equals the library's picture of the same sea, bit for bit.
#[test]
fn the_command_line_draws_the_librarys_seas() {
    use crate::goldens::{picture, rgba};
    use tidepool::sea::beaufort_speed_m_s;
    use tidepool::{OceanSettings, OceanView, SceneSpec, SeaParams, SeaShading};
    let dir = scratch("ocean_cli_is_the_library");
    let out = run_in(
        &dir,
        &["render", "ocean", "--beaufort", "8", "--direction", "200", "--size", "192x108", "--out", "sea.png"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    // Pictures are flat-shaded by default, text smooth (see `the_help_names_the_shading_it_draws`).
    let spec = |ssaa, time, shading| {
        SceneSpec::Ocean(OceanSettings {
            sea: SeaParams::default()
                .with_wind_m_s(beaufort_speed_m_s(8).unwrap())
                .with_wind_from_deg(200.0)
                .with_seed(1),
            view: OceanView { ssaa, shading, ..OceanView::default() },
            start_time_s: time,
            ..OceanSettings::default()
        })
    };
    let flat = picture(&spec(2, 0.0, SeaShading::Flat), 192, 108, &[], 0);
    assert!(read_png(&dir.join("sea.png")) == rgba(&flat));
    assert!(flat != picture(&spec(2, 0.0, SeaShading::Smooth), 192, 108, &[], 0), "the shadings differ");
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
    let text = tidepool::encode::halfblock(&picture(&spec(1, 4.0, SeaShading::Smooth), 80, 48, &[], 0));
    assert_eq!(std::fs::read(dir.join("sea.ans")).unwrap(), text);
}

/// The shading's help text names the defaults the commands draw: `render ocean --help` says
/// which shading pictures and text get, and a picture and a text drawn without `--shading`
/// are the same bytes as with the word the help printed (and not the other).
#[test]
fn the_help_names_the_shading_it_draws() {
    let help = run(&["render", "ocean", "--help"]);
    assert!(help.status.success(), "{}", stderr(&help));
    let words = String::from_utf8_lossy(&help.stdout).split_whitespace().collect::<Vec<_>>().join(" ");
    let at = words.find("--shading <MODE>").expect("render ocean --help lists --shading");
    let entry = &words[at..];
    let default = &entry[entry.find("[default: ").expect("--shading shows its default") + 10..];
    let default = &default[..default.find(']').expect("a closed [default: ...]")];
    // "[default: flat for pictures, smooth for text]"
    let word_for = |medium: &str| -> String {
        let part = default.split(',').find(|p| p.contains(medium)).unwrap_or_else(|| panic!("{default}: {medium}"));
        part.split_whitespace().next().expect("a word").to_string()
    };
    let dir = scratch("ocean_shading_help");
    for (medium, file) in [("pictures", "sea.png"), ("text", "sea.ans")] {
        let word = word_for(medium);
        assert!(word == "flat" || word == "smooth", "{medium}: '{word}'");
        let draw = |name: &str, shading: Option<&str>| {
            let mut args = vec!["render", "ocean", "--size", "96x54", "--beaufort", "7", "--out", name];
            if let Some(s) = shading {
                args.extend(["--shading", s]);
            }
            let out = run_in(&dir, &args);
            assert!(out.status.success(), "{}", stderr(&out));
            std::fs::read(dir.join(name)).unwrap()
        };
        let ext = file.rsplit('.').next().unwrap();
        let plain = draw(file, None);
        assert!(plain == draw(&format!("named.{ext}"), Some(&word)), "{medium}: the default is not '{word}'");
        let opposite = if word == "flat" { "smooth" } else { "flat" };
        assert!(plain != draw(&format!("opposite.{ext}"), Some(opposite)), "{medium}: '{opposite}' draws the same");
    }
    let play = run(&["play", "--help"]);
    let play_text = String::from_utf8_lossy(&play.stdout).split_whitespace().collect::<Vec<_>>().join(" ");
    let at = play_text.find("--shading <MODE>").expect("play --help lists --shading");
    assert!(play_text[at..].contains("[default: smooth]"), "play draws the ocean smooth");
    let bad = run(&["render", "ocean", "--shading", "gouraud"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(stderr(&bad).contains("--shading") && stderr(&bad).contains("flat"), "{}", stderr(&bad));
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
        (&["render", "ocean", "--spectrum", "jonswap", "--fetch", "0"], "--fetch: a fetch of 0 km"),
        (&["render", "ocean", "--spectrum", "tma", "--depth", "-1"], "--depth: a water depth of -1 m"),
        (&["render", "ocean", "--spectrum", "jonswap", "--gamma", "0"], "--gamma"),
        (&["render", "ocean", "--loop", "0", "--frames", "3", "--out", "a.gif"], "--loop: a loop of 0 s"),
        (&["render", "ocean", "--loop", "inf", "--frames", "3", "--out", "a.gif"], "--loop"),
        (&["render", "ocean", "--loop", "1", "--frames", "3", "--out", "a.gif"], "at least 10 peak periods"),
        (&["render", "ocean", "--loop", "30"], "add --frames N or --maps DIR"),
        (&["render", "ocean", "--choppiness", "NaN"], "--choppiness"),
        (&["render", "ocean", "--spectrum", "pm", "--gamma", "3"], "--gamma: the peak enhancement"),
        (&["render", "ocean", "--spectrum", "pm", "--fetch", "100"], "--fetch: the peak enhancement"),
        (&["render", "ocean", "--depth", "4"], "only the tma spectrum feels the bottom"),
        (&["render", "ocean", "--size", "300x200", "--maps", "m"], "maps are square"),
        (&["render", "ocean", "--maps", "m", "--out", "-"], "cannot go to standard output"),
        (&["render", "ocean", "--swell", "1,12"], "'1,12' is not HEIGHT,PERIOD,DIRECTION"),
        (&["render", "ocean", "--swell", "0,12,250"], "the swell height 0 m is outside"),
        (&["render", "ocean", "--swell", "1,40,250"], "the swell period 40 s is outside 2..=30 s"),
        (&["render", "ocean", "--swell", "1,12,west"], "'west' is not a number"),
        (
            &[
                "render", "ocean", "--swell", "1,9,0", "--swell", "1,9,0", "--swell", "1,9,0", "--swell", "1,9,0",
                "--swell", "1,9,0",
            ],
            "--swell: 5 swells are more than the 4 a sea takes",
        ),
        (&["render", "ocean", "--spreading", "cosine"], "--spreading"),
        (&["render", "ocean", "--preset", "doldrums"], "--preset"),
        (
            &[
                "render",
                "ocean",
                "--beaufort",
                "4",
                "--swell",
                "1,16,0",
                "--loop",
                "100",
                "--frames",
                "2",
                "--out",
                "a.gif",
            ],
            "peak period is 16.00 s",
        ),
        (&["spectrum", "--swell", "1,1,1"], "the swell period 1 s is outside"),
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

/// The little-endian f32 payload of a 2-D `.npy` file: (rows, columns, values).
fn read_npy_2d(bytes: &[u8]) -> (usize, usize, Vec<f32>) {
    assert_eq!(&bytes[..6], b"\x93NUMPY", "an .npy file");
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
    assert!(header.contains("'descr': '<f4'"), "{header}");
    let shape = header.split("'shape': (").nth(1).unwrap().split(')').next().unwrap();
    let dims: Vec<usize> = shape.split(',').filter_map(|d| d.trim().parse().ok()).collect();
    let values =
        bytes[10 + header_len..].chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect::<Vec<_>>();
    assert_eq!(values.len(), dims.iter().product::<usize>());
    (dims[0], dims[1], values)
}

/// `--maps` writes a tileable patch: the step across the seam (last column to first, last row
/// to first) is no bigger than the steps inside it; with `--loop`, the maps a whole loop later
/// are the same bytes; a file where the folder should be is refused and left alone.
#[test]
fn maps_tile_across_their_edges_and_loop_in_time() {
    let dir = scratch("ocean_maps");
    let out = run_in(&dir, &["render", "ocean", "--maps", "m", "--size", "64x64", "--wind", "12"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let mut names: Vec<String> =
        std::fs::read_dir(dir.join("m")).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    assert_eq!(names, ["displacement.npy", "displacement.png", "foam.png", "height.npy", "height.png", "normal.png"]);
    let (rows, cols, h) = read_npy_2d(&std::fs::read(dir.join("m/height.npy")).unwrap());
    assert_eq!((rows, cols), (64, 64));
    let at = |r: usize, c: usize| h[r * cols + c];
    let (mut inside, mut seam) = (0.0f32, 0.0f32);
    for r in 0..rows {
        for c in 0..cols - 1 {
            inside = inside.max((at(r, c + 1) - at(r, c)).abs()).max((at(c + 1, r) - at(c, r)).abs());
        }
        seam = seam.max((at(r, 0) - at(r, cols - 1)).abs()).max((at(0, r) - at(rows - 1, r)).abs());
    }
    assert!(inside > 0.05, "a sea with waves: largest step {inside} m");
    assert!(seam <= inside, "the seam steps {seam} m, more than any step inside ({inside} m)");

    // A loop of 80 s: the maps at --time 80 are the maps at --time 0.
    for (folder, time) in [("t0", "0"), ("t80", "80")] {
        let out =
            run_in(&dir, &["render", "ocean", "--maps", folder, "--size", "32x32", "--loop", "80", "--time", time]);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    for name in ["height.npy", "displacement.npy", "normal.png", "foam.png"] {
        let a = std::fs::read(dir.join("t0").join(name)).unwrap();
        assert_eq!(a, std::fs::read(dir.join("t80").join(name)).unwrap(), "{name} a loop later");
    }
    let out = run_in(&dir, &["render", "ocean", "--maps", "t0", "--size", "32x32", "--time", "7"]);
    assert!(out.status.success());
    assert_ne!(
        std::fs::read(dir.join("t0/height.npy")).unwrap(),
        std::fs::read(dir.join("t80/height.npy")).unwrap(),
        "time moves the maps"
    );

    std::fs::write(dir.join("afile"), b"keep me").unwrap();
    let out = run_in(&dir, &["render", "ocean", "--maps", "afile", "--size", "32x32"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--maps: 'afile' is a file"), "{}", stderr(&out));
    assert_eq!(std::fs::read(dir.join("afile")).unwrap(), b"keep me");
}

/// Runs `scripts/check_exr_maps.py` (the OpenEXR Python bindings reading the maps) on `args`;
/// fails loudly when python3 or the reader is missing.
fn independent_exr_check(args: &[&std::path::Path]) -> String {
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/check_exr_maps.py");
    let out = std::process::Command::new("python3")
        .arg(&script)
        .args(args)
        .output()
        .unwrap_or_else(|e| panic!("python3 is needed to read the EXR maps independently: {e}"));
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert_ne!(out.status.code(), Some(2), "the independent EXR reader is missing: {text}");
    assert!(out.status.success(), "{text}");
    text
}

/// `--map-format exr` writes half-float OpenEXR maps beside the .npy and PNG files; read back
/// by an independent reader (OpenEXR's Python bindings) they equal the .npy fields within
/// half precision and the PNGs within their 8-bit step, they tile, and a loop later they are
/// the same bytes. Ignored by the README's test command (a fresh machine has no OpenEXR reader):
/// `scripts/exr_tests.sh` installs the reader and runs it, and `.ci/run` runs that script.
#[test]
#[ignore = "needs OpenEXR's Python reader: scripts/exr_tests.sh installs it and runs this test"]
fn exr_maps_read_back_by_an_independent_reader() {
    let dir = scratch("ocean_maps_exr");
    let out =
        run_in(&dir, &["render", "ocean", "--maps", "m", "--size", "64x64", "--wind", "12", "--map-format", "exr"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let mut names: Vec<String> =
        std::fs::read_dir(dir.join("m")).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    let want = [
        "displacement.exr",
        "displacement.npy",
        "displacement.png",
        "foam.exr",
        "foam.png",
        "height.exr",
        "height.npy",
        "height.png",
        "normal.exr",
        "normal.png",
    ];
    assert_eq!(names, want);
    let text = independent_exr_check(&[&dir.join("m")]);
    assert!(text.contains("within half precision"), "{text}");
    // A loop of 100 s (Beaufort 6, foam included): the maps at --time 100 are those at 0.
    for (folder, time) in [("t0", "0"), ("t100", "100")] {
        let args = ["render", "ocean", "--maps", folder, "--size", "32x32", "--loop", "100", "--time", time];
        let out = run_in(&dir, &[&args[..], &["--map-format", "exr", "--beaufort", "6"]].concat());
        assert!(out.status.success(), "{}", stderr(&out));
    }
    independent_exr_check(&[&dir.join("t0"), std::path::Path::new("--same"), &dir.join("t100")]);
    let out = run_in(&dir, &["render", "ocean", "--size", "32x32", "--map-format", "exr", "--out", "x.png"]);
    assert_eq!(out.status.code(), Some(2), "--map-format without --maps is refused");
}

/// The maps (EXR, .npy and PNG) and a picture of the sea are the same bytes on the portable
/// path with one thread and on the widest SIMD tier this CPU has with three: the patch's FFT is
/// rustfft's scalar planner and its sine tidepool's own, so no tier changes a bit.
#[test]
fn maps_and_pictures_are_the_same_bytes_on_every_simd_tier() {
    let dir = scratch("ocean_simd_tiers");
    let mut outputs = Vec::new();
    for (tier, threads) in [("portable", "1"), ("", "3")] {
        let name = format!("t{threads}");
        let args = ["render", "ocean", "--maps", &name, "--size", "64x64", "--beaufort", "8", "--map-format", "exr"];
        let picture = format!("{name}.png");
        let shot = ["render", "ocean", "--beaufort", "8", "--size", "96x54", "--out", &picture];
        let mut files = Vec::new();
        for command in [&args[..], &shot[..]] {
            let out = crate::common::tidepool()
                .current_dir(&dir)
                .env("TIDEPOOL_SIMD", tier)
                .env("RAYON_NUM_THREADS", threads)
                .args(command)
                .output()
                .unwrap();
            assert!(out.status.success(), "{command:?}: {}", stderr(&out));
        }
        let mut names: Vec<_> = std::fs::read_dir(dir.join(&name)).unwrap().map(|e| e.unwrap().path()).collect();
        names.sort();
        for path in names {
            files.push((path.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read(&path).unwrap()));
        }
        files.push(("the picture".to_string(), std::fs::read(dir.join(&picture)).unwrap()));
        outputs.push(files);
    }
    assert_eq!(outputs[0].len(), 11, "ten maps and a picture");
    for (a, b) in outputs[0].iter().zip(&outputs[1]) {
        assert!(a == b, "{:?} differs between the portable path on one thread and the widest tier on three", a.0);
    }
}

/// The frames of `render ocean ARGS --size 64x36 --ssaa 1 --frames N+1 --fps F --loop T` in
/// `dir` (N = T·F), as pictures.
fn loop_frames(dir: &std::path::Path, args: &[&str], period: u32, fps: u32) -> Vec<image::RgbaImage> {
    let frames = period * fps + 1;
    let (frames_text, fps_text, period_text) = (frames.to_string(), fps.to_string(), period.to_string());
    let mut all = vec!["render", "ocean", "--size", "64x36", "--ssaa", "1", "--frames", &frames_text];
    all.extend(["--fps", &fps_text, "--loop", &period_text, "--out", "f_{frame:04}.png"]);
    all.extend(args);
    let out = run_in(dir, &all);
    assert!(out.status.success(), "{args:?}: {}", stderr(&out));
    (0..frames).map(|k| read_png(&dir.join(format!("f_{k:04}.png")))).collect()
}

fn mean_difference(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    a.as_raw().iter().zip(b.as_raw()).map(|(x, y)| f64::from(x.abs_diff(*y))).sum::<f64>() / a.as_raw().len() as f64
}

/// `render ocean --frames N+1 --loop T` as a user runs it, at several frame rates and winds
/// (foam included, from a start that is not a whole second): frame N, one loop after frame 0,
/// is frame 0 byte for byte, and the step into it is an ordinary step.
#[test]
fn the_loop_closes_through_the_command_line() {
    let cases: &[(&str, &[&str], u32, u32)] = &[
        ("b4_fps1", &["--beaufort", "4"], 60, 1),
        ("b4_fps2_late", &["--beaufort", "4", "--time", "0.3"], 60, 2),
        ("b8_fps1", &["--beaufort", "8", "--direction", "200"], 150, 1),
        ("b2_no_foam", &["--beaufort", "2"], 20, 1),
        ("swell", &["--beaufort", "5", "--swell", "1.2,10,250"], 100, 1),
    ];
    for (name, args, period, fps) in cases {
        let dir = scratch(&format!("ocean_loop_{name}"));
        let frames = loop_frames(&dir, args, *period, *fps);
        let n = frames.len() - 1;
        let bytes = |k: usize| std::fs::read(dir.join(format!("f_{k:04}.png"))).unwrap();
        assert!(bytes(n) == bytes(0), "{name}: frame {n} is not frame 0");
        assert_ne!(bytes(n / 2), bytes(0), "{name}: the sea moves");
        let into_loop = mean_difference(&frames[n - 1], &frames[n]);
        let before = mean_difference(&frames[n - 2], &frames[n - 1]);
        let after = mean_difference(&frames[0], &frames[1]);
        assert!(into_loop <= 1.5 * before.max(after), "{name}: a jump of {into_loop} levels; steps {before}, {after}");
    }
}

/// A series of maps `--frames N+1 --loop T` closes too: frame N's files are frame 0's (the
/// foam of frame N continued through the series, frame 0's computed from its memory).
#[test]
fn a_looping_series_of_maps_closes() {
    let dir = scratch("ocean_maps_series_loop");
    let args = ["render", "ocean", "--beaufort", "4", "--maps", "m", "--size", "32x32", "--loop", "53"];
    let out = run_in(&dir, &[&args[..], &["--frames", "54", "--fps", "1", "--time", "2.5"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    for stem in ["height.npy", "displacement.npy", "normal.png", "foam.png", "height.png"] {
        let (name, ext) = stem.split_once('.').unwrap();
        let read = |k: u32| std::fs::read(dir.join("m").join(format!("{name}_{k:04}.{ext}"))).unwrap();
        assert_eq!(read(53), read(0), "{stem}: frame 53 is frame 0");
        assert_ne!(read(20), read(0), "{stem}: the maps move");
    }
}

/// Swell and presets as a user gives them: `spectrum` reports each swell and the total
/// height, and plots their sum; a preset renders and its numbers are printed.
#[test]
fn swell_and_presets_through_the_command_line() {
    let out = run(&["spectrum", "--beaufort", "4", "--swell", "1.5,12,250", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    assert_eq!(json["swells"][0]["period_s"], 12);
    let (sea, total) = (
        json["significant_wave_height_m"].as_f64().unwrap(),
        json["total_significant_wave_height_m"].as_f64().unwrap(),
    );
    assert!((total - sea.hypot(1.5)).abs() < 0.002, "{sea} {total}");
    let out = run(&["spectrum", "--preset", "trade-wind", "--spreading", "donelan-banner"]);
    let text = String::from_utf8(out.stdout).unwrap();
    for line in ["wind speed: 8 m/s", "spreading: donelan-banner", "swell 1: 1.200 m, 11 s from 30 degrees"] {
        assert!(text.lines().any(|l| l == line), "missing '{line}' in:\n{text}");
    }
    let dir = scratch("ocean_presets");
    let out = run_in(&dir, &["spectrum", "--beaufort", "4", "--swell", "1.5,12,250", "--out", "sum.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(read_png(&dir.join("sum.png")).dimensions(), (1000, 440));
    for preset in ["calm-morning", "north-atlantic-gale"] {
        let out = run_in(&dir, &["render", "ocean", "--preset", preset, "--size", "64x36", "--out", "p.png"]);
        assert!(out.status.success(), "{preset}: {}", stderr(&out));
    }
}
