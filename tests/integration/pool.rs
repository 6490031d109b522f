//! The ripple pool through the binary as a user runs it: the same pictures as the library's, in
//! every output format.

use crate::common::golden::{self, Tolerance};
use crate::common::{read_png, run_in, scratch, stderr};

/// What `render pool` writes equals the library's picture of the same scene, bit for bit.
#[test]
fn the_command_line_draws_the_librarys_pictures() {
    use crate::goldens::{picture, rgba};
    use tidepool::{Event, PoolSettings, SceneSpec, Stone};
    let dir = scratch("pool_cli_is_the_library");
    let out = run_in(&dir, &["render", "pool"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let file = read_png(&dir.join("pool.png"));
    assert_eq!(file.dimensions(), (640, 360), "the default size");
    let (script, steps) = tidepool::PoolScene::showcase(640, 360);
    let spec = SceneSpec::Pool(PoolSettings::default());
    assert!(file == rgba(&picture(&spec, 640, 360, &script, steps)), "the default picture");
    let out = run_in(
        &dir,
        &[
            "render",
            "pool",
            "--size",
            "64x40",
            "--stone",
            "20,14,4,128",
            "--stone",
            "44,26,3,128",
            "--steps",
            "30",
            "--out",
            "small.ans",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let script: Vec<(u64, Event)> = [(20, 14, 4, 128), (44, 26, 3, 128)]
        .iter()
        .map(|&(x, y, r, w)| (0, Event::Stone(Stone::new(x, y, r, w).unwrap())))
        .collect();
    let text = tidepool::encode::halfblock(&picture(&spec, 64, 40, &script, 30));
    assert_eq!(std::fs::read(dir.join("small.ans")).unwrap(), text, "the half-block text");
}

#[test]
fn ansi_output_matches_the_png_pixel_for_pixel() {
    let dir = scratch("ansi_matches_png");
    let args = ["render", "pool", "--size", "50x30", "--stone", "25,15,5,200", "--steps", "20"];
    for out in ["same.png", "same.ans"] {
        let status = run_in(&dir, &[&args[..], &["--out", out]].concat());
        assert!(status.status.success(), "{}", stderr(&status));
    }
    let png = read_png(&dir.join("same.png"));
    let text = golden::decode_ansi(&std::fs::read(dir.join("same.ans")).unwrap());
    golden::compare("ansi_matches_png", &png, &text, Tolerance { channel: 0, max_fraction: 0.0 });
}

/// The player's pool flags as a user gives them to `render pool` (a finer grid, the pace, gusts)
/// reach the scene: the picture is the library's with those settings, bit for bit, and not the
/// default pool's.
#[test]
fn grid_pace_and_gusts_given_on_the_command_line_reach_the_scene() {
    use crate::goldens::{picture, rgba};
    use tidepool::{BreezeStyle, PoolSettings, SceneSpec};
    let dir = scratch("pool_cli_grid_pace_gusts");
    let flags = ["--size", "96x64", "--steps", "40", "--breeze", "1"];
    let coherent = ["--grid", "2", "--steps-per-second", "30", "--breeze-style", "gusts", "--out", "coherent.png"];
    let out = run_in(&dir, &[&["render", "pool"][..], &flags, &coherent].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let (script, _) = tidepool::PoolScene::showcase(96, 64);
    let settings = PoolSettings {
        breeze: 1.0,
        breeze_style: BreezeStyle::Gusts,
        grid: 2,
        steps_per_second: 30,
        ..PoolSettings::default()
    };
    let file = read_png(&dir.join("coherent.png"));
    assert!(file == rgba(&picture(&SceneSpec::Pool(settings), 96, 64, &script, 40)), "the flags' pool");
    let plain = run_in(&dir, &[&["render", "pool"][..], &flags, &["--out", "plain.png"]].concat());
    assert!(plain.status.success(), "{}", stderr(&plain));
    assert!(read_png(&dir.join("plain.png")) != file, "the flags changed the picture");
}
