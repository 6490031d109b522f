//! Animations and caustics, rendered by the binary: GIF frames and timing, APNG and PNG
//! sequences, replays turned into animations, and golden pictures of both.

use crate::common::{read_png, run_in, scratch, stderr};

/// Decodes a GIF into its frames as composited RGBA pictures, with their delays (1/100 s).
fn gif_frames(bytes: &[u8]) -> (u32, u32, Vec<(image::RgbaImage, u16)>) {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options.read_info(std::io::Cursor::new(bytes)).unwrap();
    let (w, h) = (u32::from(decoder.width()), u32::from(decoder.height()));
    let mut screen = image::RgbaImage::new(w, h);
    let mut frames = Vec::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        for y in 0..u32::from(frame.height) {
            for x in 0..u32::from(frame.width) {
                let i = ((y * u32::from(frame.width) + x) * 4) as usize;
                let px = &frame.buffer[i..i + 4];
                if px[3] != 0 {
                    screen.put_pixel(
                        x + u32::from(frame.left),
                        y + u32::from(frame.top),
                        image::Rgba([px[0], px[1], px[2], 255]),
                    );
                }
            }
        }
        frames.push((screen.clone(), frame.delay));
    }
    (w, h, frames)
}

/// How far a GIF frame is from the exact frame, as the eye sees a dithered picture: per 4x4
/// cell of the Bayer pattern (aligned to it), the largest channel difference of the cells'
/// means. Returns the mean over the cells and the 98th percentile.
fn dithered_distance(gif: &image::RgbaImage, exact: &image::RgbaImage) -> (f64, f64) {
    let (w, h) = exact.dimensions();
    let mut cells = Vec::new();
    for by in (0..h - h % 4).step_by(4) {
        for bx in (0..w - w % 4).step_by(4) {
            let mean = |img: &image::RgbaImage, c: usize| {
                (0..16).map(|i| f64::from(img.get_pixel(bx + i % 4, by + i / 4)[c])).sum::<f64>() / 16.0
            };
            cells.push((0..3).map(|c| (mean(gif, c) - mean(exact, c)).abs()).fold(0.0, f64::max));
        }
    }
    cells.sort_by(f64::total_cmp);
    (cells.iter().sum::<f64>() / cells.len() as f64, cells[cells.len() * 98 / 100])
}

/// The tolerance of a GIF frame against the exact frame, in levels of [`dithered_distance`].
/// The GIF's 4x4 Bayer dither spreads each colour over a cell to within about half a step of
/// its 255-colour palette; measured on the falling-stones animation below, a frame's mean cell
/// error is 1.6 to 2.6 levels and its 98th percentile 5.8 to 9.6. The same GIF against the
/// frame one simulation step later measures 2.5 to 13 (mean) and 20 to 57 (98th percentile);
/// against the exact frame shifted by 10 levels, a mean of 10.3 or more. So a frame passes
/// with a mean of at most 4 levels and a 98th percentile of at most 12: a one-step shift in
/// time fails the percentile, a 10-level colour shift fails the mean.
const MEAN_LEVELS: f64 = 4.0;
/// See [`MEAN_LEVELS`].
const P98_LEVELS: f64 = 12.0;

fn assert_gif_frame(what: &str, gif: &image::RgbaImage, exact: &image::RgbaImage) {
    let (mean, p98) = dithered_distance(gif, exact);
    assert!(
        mean <= MEAN_LEVELS && p98 <= P98_LEVELS,
        "{what}: cells off by {mean:.1} levels on average, {p98:.1} at the 98th percentile (at most {MEAN_LEVELS} and {P98_LEVELS})"
    );
}

#[test]
fn a_gif_of_falling_stones() {
    use crate::goldens::{picture, rgba};
    use tidepool::{PoolSettings, SceneSpec};
    let dir = scratch("gif_stones");
    let out =
        run_in(&dir, &["render", "pool", "--size", "96x64", "--frames", "12", "--fps", "20", "--out", "drops.gif"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (w, h, frames) = gif_frames(&std::fs::read(dir.join("drops.gif")).unwrap());
    assert_eq!((w, h, frames.len()), (96, 64, 12));
    assert!(frames.iter().all(|(_, delay)| *delay == 5), "20 fps = 5 cs a frame");
    // Frame k is the pool after k · 60 / 20 = 3k steps, with the default stones.
    let (script, _) = tidepool::PoolScene::showcase(96, 64);
    let spec = SceneSpec::Pool(PoolSettings::default());
    let exact = |step: u64| rgba(&picture(&spec, 96, 64, &script, step));
    for (k, (frame, _)) in frames.iter().enumerate() {
        assert_gif_frame(&format!("frame {k}"), frame, &exact(3 * k as u64));
    }
}

#[test]
fn apng_and_png_sequences_hold_every_frame() {
    let dir = scratch("apng_sequence");
    std::fs::create_dir(dir.join("frames")).unwrap();
    let args = ["render", "pool", "--size", "40x30", "--frames", "5", "--fps", "60", "--rain", "1"];
    for out in ["anim.png", "frames/f_{frame:03}.png"] {
        let result = run_in(&dir, &[&args[..], &["--out", out]].concat());
        assert!(result.status.success(), "{out}: {}", stderr(&result));
    }
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(dir.join("anim.png")).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    assert_eq!(reader.info().animation_control().unwrap().num_frames, 5);
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    for k in 0..5 {
        reader.next_frame(&mut buf).unwrap();
        // The same frame as the sequence's PNG, to the byte.
        let file = read_png(&dir.join(format!("frames/f_{k:03}.png")));
        let rgb: Vec<u8> = file.pixels().flat_map(|p| [p[0], p[1], p[2]]).collect();
        assert_eq!(&buf[..rgb.len()], &rgb[..], "frame {k}");
    }
    assert!(!dir.join("frames/f_005.png").exists());
}

#[test]
fn animation_flags_are_checked() {
    let dir = scratch("anim_flags");
    let cases: &[(&[&str], &str)] = &[
        (&["--frames", "3", "--out", "a.gif", "--fps", "60"], "--fps"),
        (&["--frames", "3", "--out", "a.mp4"], "--out"),
        (&["--frames", "3", "--out", "-"], "standard output"),
        (&["--frames", "3", "--out", "a.gif", "--heightmap", "h.npy"], "--heightmap"),
        (&["--frames", "3", "--out", "a.gif", "--format", "png"], "--format"),
        (&["--frames", "0", "--out", "a.gif"], "--frames"),
        (&["--frames", "3", "--out", "f_{frame:4}.png"], "--out"),
    ];
    for (args, needle) in cases {
        let out = run_in(&dir, &[&["render", "pool", "--size", "20x20"], *args].concat());
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
    }
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 0, "nothing written");
}

#[test]
fn the_ocean_animates_in_physical_time() {
    let dir = scratch("ocean_gif");
    let out = run_in(&dir, &["render", "ocean", "--size", "64x36", "--frames", "4", "--fps", "10", "--out", "sea.gif"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (_, _, frames) = gif_frames(&std::fs::read(dir.join("sea.gif")).unwrap());
    assert_eq!(frames.len(), 4);
    assert_ne!(frames[0].0, frames[3].0, "the sea moved");
    // Frame 3 at 10 fps is 0.3 s of sea: the same as a still picture at --time 0.3.
    let still = run_in(&dir, &["render", "ocean", "--size", "64x36", "--time", "0.3", "--ssaa", "2", "--out", "t.png"]);
    assert!(still.status.success());
    assert_gif_frame("frame 3, the still at 0.3 s", &frames[3].0, &read_png(&dir.join("t.png")));
}
