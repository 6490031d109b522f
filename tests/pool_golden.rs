//! Golden images of the ripple pool, rendered by the binary as a user would.

mod common;

use common::golden::{self, Tolerance};
use common::{read_png, run_in, scratch, stderr};

#[test]
fn default_pool_png() {
    let dir = scratch("default_pool_png");
    let out = run_in(&dir, &["render", "pool"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let picture = read_png(&dir.join("pool.png"));
    assert_eq!(picture.dimensions(), (640, 360), "the default size");
    golden::check_png("pool_default", &picture, Tolerance::default());
}

#[test]
fn small_pool_as_half_block_text() {
    let dir = scratch("small_pool_ansi");
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
    let text = std::fs::read(dir.join("small.ans")).unwrap();
    assert_eq!(String::from_utf8_lossy(&text).lines().count(), 20, "two pixel rows per line");
    golden::check_ansi("pool_small", &text, Tolerance::default());
}

#[test]
fn pool_on_a_user_background() {
    let dir = scratch("pool_user_background");
    // A colourful background made here, so the test needs no binary input: diagonal stripes
    // that show every displacement.
    let background = image::RgbImage::from_fn(300, 200, |x, y| {
        let band = ((x + y) / 12) % 3;
        match band {
            0 => image::Rgb([220, 90, 40]),
            1 => image::Rgb([250, 230, 120]),
            _ => image::Rgb([30, 60, 160]),
        }
    });
    background.save(dir.join("stripes.png")).unwrap();
    let out = run_in(
        &dir,
        &[
            "render",
            "pool",
            "--size",
            "240x160",
            "--background",
            "stripes.png",
            "--stone",
            "120,80,6,160",
            "--steps",
            "45",
            "--refraction",
            "1",
            "--out",
            "striped.png",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    golden::check_png("pool_user_background", &read_png(&dir.join("striped.png")), Tolerance::default());
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
