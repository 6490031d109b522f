//! Whatever file a user points tidepool at: odd but valid images work, broken or hostile ones
//! get a one-line error, exit status 2, and nothing is written.

use std::io::Cursor;
use std::path::Path;

use crate::common::{run_in, scratch, stderr};

/// Renders a tiny pool on `background` and returns (exit code, stderr).
fn render_on(dir: &Path, background: &str) -> (Option<i32>, String) {
    let out = run_in(
        dir,
        &["render", "pool", "--size", "32x24", "--steps", "5", "--background", background, "--out", "out.png"],
    );
    (out.status.code(), stderr(&out))
}

fn png_bytes(info: impl FnOnce(&mut png::Encoder<&mut Vec<u8>>), data: &[u8]) -> Vec<u8> {
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, 4, 3);
        info(&mut encoder);
        let mut writer = encoder.write_header().unwrap();
        writer.write_image_data(data).unwrap();
    }
    bytes
}

#[test]
fn unusual_but_valid_images_simply_work() {
    let dir = scratch("unusual_images");
    // 16-bit RGBA.
    let deep = png_bytes(
        |e| {
            e.set_color(png::ColorType::Rgba);
            e.set_depth(png::BitDepth::Sixteen);
        },
        &[0x80; 4 * 3 * 8],
    );
    // 8-bit grey.
    let grey = png_bytes(
        |e| {
            e.set_color(png::ColorType::Grayscale);
            e.set_depth(png::BitDepth::Eight);
        },
        &[10, 60, 110, 160, 20, 70, 120, 170, 30, 80, 130, 180],
    );
    // A palette of two colours, one bit per pixel.
    let palette = png_bytes(
        |e| {
            e.set_color(png::ColorType::Indexed);
            e.set_depth(png::BitDepth::One);
            e.set_palette(vec![255, 0, 0, 0, 0, 255]);
        },
        &[0b1010_0000, 0b0101_0000, 0b1010_0000],
    );
    // An animated PNG with two frames: the first frame is used.
    let mut animated = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut animated, 4, 3);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_animated(2, 0).unwrap();
        let mut writer = encoder.write_header().unwrap();
        writer.write_image_data(&[200; 4 * 3 * 3]).unwrap();
        writer.write_image_data(&[20; 4 * 3 * 3]).unwrap();
        writer.finish().unwrap();
    }
    // A JPEG.
    let mut jpeg = Vec::new();
    image::RgbImage::from_fn(16, 16, |x, y| image::Rgb([x as u8 * 16, y as u8 * 16, 90]))
        .write_to(&mut Cursor::new(&mut jpeg), image::ImageFormat::Jpeg)
        .unwrap();
    for (name, bytes) in [
        ("deep.png", &deep),
        ("grey.png", &grey),
        ("palette.png", &palette),
        ("animated.png", &animated),
        ("photo.jpg", &jpeg),
    ] {
        std::fs::write(dir.join(name), bytes).unwrap();
        let (code, err) = render_on(&dir, name);
        assert_eq!(code, Some(0), "{name}: {err}");
        let picture = image::open(dir.join("out.png")).unwrap().to_rgba8();
        assert_eq!(picture.dimensions(), (32, 24), "{name}");
    }
}

#[test]
fn broken_and_hostile_images_are_refused_cleanly() {
    let dir = scratch("hostile_images");
    // A PNG header that claims 100000x100000 pixels: refused before any pixel memory exists.
    let mut huge = Vec::new();
    huge.extend_from_slice(b"\x89PNG\r\n\x1a\n");
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(b"IHDR");
    ihdr.extend_from_slice(&100_000u32.to_be_bytes());
    ihdr.extend_from_slice(&100_000u32.to_be_bytes());
    ihdr.extend_from_slice(&[8, 6, 0, 0, 0]);
    huge.extend_from_slice(&13u32.to_be_bytes());
    huge.extend_from_slice(&ihdr);
    huge.extend_from_slice(&crc32(&ihdr).to_be_bytes());
    std::fs::write(dir.join("huge.png"), &huge).unwrap();
    // A well-formed PNG (valid CRCs) whose palette is 10 bytes, not whole RGB entries: png
    // 0.18.1 panics on it (found by fuzzing); tidepool checks the palette first.
    let mut palette = b"\x89PNG\r\n\x1a\n".to_vec();
    for (kind, data) in [
        (&b"IHDR"[..], vec![0, 0, 0, 4, 0, 0, 0, 4, 8, 3, 0, 0, 0]),
        (b"PLTE", (0..10).collect()),
        (b"IDAT", vec![0x78, 0x9c, 0x63, 0x60, 0x00, 0x00, 0x00, 0x02, 0x00, 0x01]),
        (b"IEND", vec![]),
    ] {
        let typed: Vec<u8> = kind.iter().chain(&data).copied().collect();
        palette.extend_from_slice(&(data.len() as u32).to_be_bytes());
        palette.extend_from_slice(&typed);
        palette.extend_from_slice(&crc32(&typed).to_be_bytes());
    }
    std::fs::write(dir.join("palette.png"), &palette).unwrap();
    // A JPEG with its entropy-coded data scrambled, and one cut short.
    let mut jpeg = Vec::new();
    image::RgbImage::from_fn(64, 64, |x, y| image::Rgb([x as u8 * 4, y as u8 * 4, 90]))
        .write_to(&mut Cursor::new(&mut jpeg), image::ImageFormat::Jpeg)
        .unwrap();
    let mut scrambled = jpeg.clone();
    let middle = scrambled.len() / 2;
    for b in &mut scrambled[middle - 40..middle + 40] {
        *b = 0xFF;
    }
    std::fs::write(dir.join("scrambled.jpg"), &scrambled).unwrap();
    std::fs::write(dir.join("cut.jpg"), &jpeg[..jpeg.len() / 3]).unwrap();
    // Cut inside the scan data: the decoder alone would fill the rest with grey.
    std::fs::write(dir.join("half.jpg"), &jpeg[..jpeg.len() * 3 / 4]).unwrap();
    std::fs::write(dir.join("empty.png"), b"").unwrap();
    std::fs::write(dir.join("notes.png"), b"remember to buy milk\n").unwrap();
    std::fs::create_dir(dir.join("folder.png")).unwrap();
    let cases = [
        ("huge.png", "too large to decode"),
        ("palette.png", "palette is malformed"),
        ("scrambled.jpg", "decode"),
        ("cut.jpg", "decode"),
        ("half.jpg", "cut short"),
        ("empty.png", "empty"),
        ("notes.png", "format could not be determined"),
        ("folder.png", "directory"),
        ("missing.png", "no such file"),
    ];
    for (name, needle) in cases {
        let (code, err) = render_on(&dir, name);
        assert_eq!(code, Some(2), "{name}: {err}");
        assert!(err.starts_with("tidepool: --background") && err.contains(needle), "{name}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: one line: {err}");
    }
    assert!(!dir.join("out.png").exists(), "nothing was written");
}

#[test]
fn outputs_that_cannot_be_written_keep_what_was_there() {
    let dir = scratch("unwritable_outputs");
    std::fs::write(dir.join("plain.txt"), b"a regular file").unwrap();
    std::fs::write(dir.join("keep.png"), b"precious").unwrap();
    let cases: [(&str, &str); 3] = [
        ("plain.txt/x.png", "is not a directory"),
        ("no/such/folder/x.png", "does not exist"),
        ("keep.png/", "Not a directory"),
    ];
    for (out, needle) in cases {
        let result = run_in(&dir, &["render", "pool", "--size", "16x16", "--out", out]);
        assert_eq!(result.status.code(), Some(2), "{out}");
        assert!(stderr(&result).contains(needle), "{out}: {}", stderr(&result));
    }
    assert_eq!(std::fs::read(dir.join("keep.png")).unwrap(), b"precious");
    assert_eq!(std::fs::read(dir.join("plain.txt")).unwrap(), b"a regular file");
    // /dev/full stands in for a full disk: the error says so, exit 2.
    let full = run_in(&dir, &["render", "pool", "--size", "16x16", "--format", "png", "--out", "/dev/full"]);
    assert_eq!(full.status.code(), Some(2));
    assert!(stderr(&full).contains("no space left on the device; free some space"), "{}", stderr(&full));
}

/// CRC-32 as PNG chunks use it.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 == 1 { (crc >> 1) ^ 0xEDB8_8320 } else { crc >> 1 };
        }
    }
    !crc
}
