//! The command line as a user meets it: exit statuses, messages, files written or left alone.

use crate::common::{run, run_in, scratch, stderr, tidepool};

#[test]
fn help_and_version_exit_zero_and_explain_the_flags() {
    let help = run(&["render", "pool", "--help"]);
    assert!(help.status.success());
    let text = String::from_utf8_lossy(&help.stdout);
    for flag in [
        "--size",
        "--seed",
        "--steps",
        "--stone",
        "--rain",
        "--damping",
        "--refraction",
        "--grid",
        "--steps-per-second",
        "--breeze-style",
        "--no-shading",
        "--background",
        "--heightmap",
        "--out",
        "--format",
    ] {
        assert!(text.contains(flag), "render pool --help mentions {flag}");
    }
    assert!(text.contains("default"), "defaults are shown");
    let version = run(&["--version"]);
    assert!(version.status.success());
    assert!(String::from_utf8_lossy(&version.stdout).starts_with("tidepool "));
}

#[test]
fn bad_values_name_the_flag_and_exit_two() {
    let cases: &[(&[&str], &str)] = &[
        (&["--size", "0x0"], "--size"),
        (&["--size", "100000x100000"], "--size"),
        (&["--size", "abc"], "--size"),
        (&["--size", "-5x10"], "at least 1 pixel"),
        (&["--stone", "10,10,-3"], "--stone"),
        (&["--stone", "10"], "--stone"),
        (&["--stone", "-5,-5,0"], "--stone"),
        (&["--steps", "-3"], "--steps"),
        (&["--seed", "-1"], "--seed"),
        (&["--damping", "0"], "use 'off'"),
        (&["--rain", "-1"], "--rain"),
        (&["--rain", "NaN"], "--rain"),
        (&["--refraction", "inf"], "--refraction"),
        (&["--grid", "5"], "--grid"),
        (&["--grid", "0"], "outside 1..=4"),
        (&["--steps-per-second", "0"], "--steps-per-second"),
        (&["--steps-per-second", "241"], "outside 1..=240"),
        (&["--breeze-style", "storm"], "'gusts'"),
        (&["--out", "picture.jpg"], "--out"),
        (&["--heightmap", "h.exr"], "--heightmap"),
        (&["--background", "/nonexistent/floor.png"], "--background"),
        (&["--frobnicate"], "--frobnicate"),
    ];
    let dir = scratch("bad_values");
    for (args, needle) in cases {
        let out = run_in(&dir, &[&["render", "pool"], *args].concat());
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = stderr(&out);
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing was written");
}

#[test]
fn corrupt_backgrounds_are_refused_cleanly() {
    let dir = scratch("corrupt_backgrounds");
    std::fs::write(dir.join("empty.png"), b"").unwrap();
    std::fs::write(dir.join("text.png"), b"this is not a picture").unwrap();
    let mut png = Vec::new();
    image::RgbImage::new(64, 64).write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).unwrap();
    std::fs::write(dir.join("truncated.png"), &png[..png.len() / 2]).unwrap();
    std::fs::create_dir(dir.join("folder.png")).unwrap();
    for (file, needle) in
        [("empty.png", "empty"), ("text.png", "format"), ("truncated.png", "decode"), ("folder.png", "directory")]
    {
        let out = run_in(&dir, &["render", "pool", "--background", file, "--out", "x.png"]);
        assert_eq!(out.status.code(), Some(2), "{file}");
        let err = stderr(&out);
        assert!(err.starts_with("tidepool: --background") && err.contains(needle), "{file}: {err}");
        assert_eq!(err.lines().count(), 1, "one line: {err}");
    }
    assert!(!dir.join("x.png").exists());
}

/// Every scene, and an animation, gives the same bytes whatever the number of threads: work is
/// split into fixed bands, never into per-thread pieces, and nothing is summed in thread order.
#[test]
fn every_scene_is_the_same_on_one_thread_and_on_three() {
    let dir = scratch("thread_counts");
    let cases: [&[&str]; 4] = [
        &["render", "ocean", "--size", "160x90", "--heightmap", "{}.npy", "--out", "{}.png"],
        &["render", "lake", "--wind", "5", "--size", "160x90", "--out", "{}.png"],
        &["render", "pool", "--size", "1000x520", "--rain", "0.3", "--out", "{}.png"],
        &["render", "pool", "--size", "120x80", "--frames", "6", "--out", "{}.gif"],
    ];
    for (i, case) in cases.iter().enumerate() {
        let mut outputs = Vec::new();
        for threads in ["1", "3"] {
            let name = format!("case{i}-{threads}");
            let args: Vec<String> = case.iter().map(|a| a.replace("{}", &name)).collect();
            let out = tidepool().current_dir(&dir).env("RAYON_NUM_THREADS", threads).args(&args).output().unwrap();
            assert!(out.status.success(), "{case:?}: {}", stderr(&out));
            let files: Vec<Vec<u8>> =
                args.iter().filter(|a| a.starts_with(&name)).map(|f| std::fs::read(dir.join(f)).unwrap()).collect();
            outputs.push(files);
        }
        assert!(outputs[0] == outputs[1], "{case:?}: one thread and three threads differ");
    }
}

#[test]
fn same_arguments_give_identical_bytes() {
    let dir = scratch("deterministic");
    for name in ["a", "b"] {
        for ext in ["png", "ans"] {
            let out = run_in(
                &dir,
                &[
                    "render",
                    "pool",
                    "--size",
                    "120x80",
                    "--rain",
                    "0.5",
                    "--seed",
                    "42",
                    "--steps",
                    "60",
                    "--out",
                    &format!("{name}.{ext}"),
                    "--heightmap",
                    &format!("{name}-{ext}.npy"),
                ],
            );
            assert!(out.status.success(), "{}", stderr(&out));
        }
    }
    for file in ["{}.png", "{}.ans", "{}-png.npy"] {
        let a = std::fs::read(dir.join(file.replace("{}", "a"))).unwrap();
        let b = std::fs::read(dir.join(file.replace("{}", "b"))).unwrap();
        assert!(a == b, "{file} differs between identical runs");
    }
    let other_seed = run_in(
        &dir,
        &["render", "pool", "--size", "120x80", "--rain", "0.5", "--seed", "43", "--steps", "60", "--out", "c.png"],
    );
    assert!(other_seed.status.success());
    assert_ne!(std::fs::read(dir.join("a.png")).unwrap(), std::fs::read(dir.join("c.png")).unwrap());
}

#[test]
fn heightmaps_hold_the_raw_amplitudes() {
    let dir = scratch("heightmaps");
    let args = ["render", "pool", "--size", "40x30", "--stone", "20,15,3,77", "--steps", "0", "--out", "p.png"];
    assert!(run_in(&dir, &[&args[..], &["--heightmap", "h.npy"]].concat()).status.success());
    assert!(run_in(&dir, &[&args[..], &["--heightmap", "h.png"]].concat()).status.success());
    let npy = std::fs::read(dir.join("h.npy")).unwrap();
    let header_len = u16::from_le_bytes([npy[8], npy[9]]) as usize;
    assert!(String::from_utf8_lossy(&npy[10..10 + header_len]).contains("'shape': (30, 40)"));
    let values: Vec<f32> =
        npy[10 + header_len..].chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect();
    assert_eq!(values.len(), 1200);
    assert_eq!(values[15 * 40 + 20], -77.0, "the stone's centre, row 0 at the top");
    assert_eq!(values[0], 0.0);
    let png = image::open(dir.join("h.png")).unwrap();
    let grey = png.as_luma16().expect("16-bit grey");
    assert_eq!(grey.get_pixel(20, 15).0[0], 32768 - 77);
    assert_eq!(grey.get_pixel(0, 0).0[0], 32768);
}

#[test]
fn stdout_gets_half_block_text_and_a_closed_pipe_is_quiet() {
    let out = run(&["render", "pool", "--out", "-", "--size", "30x20"]);
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text.lines().count(), 10);
    assert!(text.lines().all(|l| l.ends_with("\x1b[0m") && l.contains('\u{2580}')));

    let mut child = tidepool()
        .args(["render", "pool", "--out", "-", "--size", "400x400"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = [0u8; 100];
    std::io::Read::read_exact(child.stdout.as_mut().unwrap(), &mut first).unwrap();
    drop(child.stdout.take()); // like `| head -c 100`
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "broken pipe is not an error: {:?} {}", out.status, stderr(&out));
    assert!(stderr(&out).is_empty());
}

#[test]
fn failed_writes_keep_the_existing_file() {
    let dir = scratch("failed_writes");
    std::fs::write(dir.join("keep.png"), b"precious").unwrap();
    // The picture is written first, then the heightmap into a missing folder fails: the error
    // names the folder, and nothing half-written is left behind.
    let out = run_in(&dir, &["render", "pool", "--size", "20x20", "--out", "new.png", "--heightmap", "missing/h.npy"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("missing"), "{}", stderr(&out));
    let out = run_in(&dir, &["render", "pool", "--size", "20x20", "--out", "nowhere/keep.png"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("does not exist"), "{}", stderr(&out));
    assert_eq!(std::fs::read(dir.join("keep.png")).unwrap(), b"precious");
    let leftovers: Vec<_> = std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name()).collect();
    assert!(leftovers.iter().all(|n| !n.to_string_lossy().ends_with(".tmp")), "{leftovers:?}");
}

#[test]
fn ctrl_c_exits_130_and_leaves_no_file() {
    /// Kills the render if the test fails before it ends (it would run for hours).
    struct KillOnDrop(std::process::Child);
    impl Drop for KillOnDrop {
        fn drop(&mut self) {
            let _ = self.0.kill();
            let _ = self.0.wait();
        }
    }
    let dir = scratch("ctrl_c");
    let child = tidepool()
        .current_dir(&dir)
        .args(["render", "pool", "--size", "512x512", "--steps", "100000000", "--out", "never.png"])
        .spawn()
        .unwrap();
    let mut child = KillOnDrop(child);
    // Ready when the process catches SIGINT (its handler is installed): before that, the
    // default action would kill it with another status.
    crate::common::wait_until_catches(child.0.id(), 2);
    // Send SIGINT through the kill command, as a terminal's Ctrl-C would.
    let killed = std::process::Command::new("kill").args(["-INT", &child.0.id().to_string()]).status().unwrap();
    assert!(killed.success());
    let status = child.0.wait().unwrap();
    assert_eq!(status.code(), Some(130));
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "no file, no temporary file");
}

/// `tidepool` alone plays the pool full-screen (issue 3); without a terminal it says so in one
/// line, points to `tidepool render`, and exits 2.
#[test]
fn no_subcommand_without_a_terminal_points_to_render() {
    let out = run(&[]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("not a terminal") && err.contains("tidepool render pool"), "{err}");
}

#[test]
fn completions_and_man_pages_come_from_the_real_flags() {
    for shell in ["bash", "zsh", "fish"] {
        let out = run(&["completions", shell]);
        assert!(out.status.success(), "{shell}");
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains("render") && text.contains("refraction"), "{shell}");
    }
    let page = run(&["man"]);
    assert!(page.status.success());
    assert!(String::from_utf8_lossy(&page.stdout).contains(".TH tidepool 1"));
    let dir = scratch("man_pages");
    let out = run_in(&dir, &["man", "--out-dir", "."]);
    assert!(out.status.success(), "{}", stderr(&out));
    for page in ["tidepool.1", "tidepool-render.1", "tidepool-render-pool.1", "tidepool-play.1"] {
        let text = std::fs::read_to_string(dir.join(page)).unwrap();
        assert!(text.contains(".TH"), "{page}");
    }
    assert!(std::fs::read_to_string(dir.join("tidepool-render-pool.1")).unwrap().contains("caustics"));
    assert_eq!(run_in(&dir, &["man", "--out-dir", "nope"]).status.code(), Some(2));
}

/// The README's test command builds `serve`: its tests (`tests/serve/`, a test binary cargo
/// leaves out without the feature) and the docs' `tidepool serve` flags are checked only
/// then. A plain `cargo test` fails here, saying so, instead of passing without them.
#[cfg(not(feature = "serve"))]
#[test]
fn the_tests_run_with_the_server_built() {
    panic!(
        "tidepool serve is not built, so its tests (tests/serve/) did not run: use the README's test command, `cargo test --all-features`"
    );
}

/// Without the feature, `tidepool serve` says how to get a build with the server, in one line,
/// with status 2 (not clap's "unrecognized subcommand").
#[cfg(not(feature = "serve"))]
#[test]
fn serve_without_the_feature_says_how_to_build_it() {
    let output = run(&["serve", "--listen", "0.0.0.0:2222"]);
    assert_eq!(output.status.code(), Some(2));
    let text = stderr(&output);
    assert!(text.contains("cargo run --release --features serve -- serve"), "{text}");
    assert_eq!(text.lines().count(), 1, "{text}");
}
