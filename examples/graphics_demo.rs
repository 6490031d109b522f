//! Shows the pool's golden picture with the graphics protocol the terminal answers for: the
//! detection and the encoders of issue 15 against a real terminal, before the player is wired.
//! `scripts/real_terminals.sh` runs it in kitty and xterm under Xvfb and takes screenshots.
//!
//!     cargo run --example graphics_demo -- [auto|kitty|sixel|iterm2|cells] [REPORT] [SECONDS]
//!
//! It probes (150 ms at most), writes what it found to `REPORT` (default
//! `graphics_demo.txt`), draws the picture over every row but the last (the status line says
//! which mode), waits half of `SECONDS` (default 4), paints a red square into the picture and
//! sends only that change (a kitty frame edit or a sixel cell block where the terminal allows),
//! writes the picture the terminal should show to `REPORT.png` (for sixel the dithered one), waits the other half and restores the
//! terminal (kitty's image deleted). The terminal is asked with `tidepool::testing::probe_for_picture`,
//! as `render --out -` asks it.

use std::io::{self, Write};
use std::time::{Duration, Instant};

use tidepool::play::GraphicsMode;
use tidepool::play::GraphicsRequest;
use tidepool::testing::Iterm2Encoder;
use tidepool::testing::dithered_rgb;
use tidepool::testing::push_rgb;
use tidepool::testing::{KittyEncoder, KittyOptions, Medium, kitty_temp_dir};
use tidepool::testing::{Layout, layout};
use tidepool::testing::{SixelEncoder, SixelPalette};
use tiny_skia::{Color, FilterQuality, Pixmap, PixmapPaint, Rect, Transform};

const GOLDEN: &[u8] = include_bytes!("../tests/golden/pool_default.png");

fn main() -> io::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let request = match args.first().map(String::as_str).unwrap_or("auto") {
        "auto" => GraphicsRequest::Auto,
        "kitty" => GraphicsRequest::Force(GraphicsMode::Kitty),
        "sixel" => GraphicsRequest::Force(GraphicsMode::Sixel),
        "iterm2" => GraphicsRequest::Force(GraphicsMode::Iterm2),
        "cells" => GraphicsRequest::Force(GraphicsMode::Cells),
        other => {
            eprintln!("graphics_demo: unknown mode {other}: use auto, kitty, sixel, iterm2 or cells");
            std::process::exit(2);
        }
    };
    let report = args.get(1).cloned().unwrap_or_else(|| "graphics_demo.txt".into());
    let seconds: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(4.0);
    crossterm::terminal::enable_raw_mode()?;
    let result = run(request, &report, seconds);
    let _ = crossterm::terminal::disable_raw_mode();
    result
}

fn run(request: GraphicsRequest, report: &str, seconds: f64) -> io::Result<()> {
    // The same question and the same rules as `tidepool render --out -` (at most
    // 150 ms; the file medium is not offered).
    let started = Instant::now();
    let (choice, support) = tidepool::testing::probe_for_picture(request);
    let took = started.elapsed();
    let support = &support;
    let mut text = format!("probe took {took:?}\n{support:#?}\n{choice:#?}\n");
    let (cols, rows) = crossterm::terminal::size()?;
    let mut stdout = io::stdout().lock();
    let mut write = |bytes: &[u8]| {
        stdout.write_all(bytes)?;
        stdout.flush()
    };
    let sixel_max = support.sixel.and_then(|s| Some((s.max_w?, s.max_h?)));
    let l = layout(choice.mode, (cols, rows), support.cell_px, sixel_max, Layout::SCALED_CAP);
    text.push_str(&format!("{l:#?}\n"));
    let mut picture = Pixmap::new(l.picture.0, l.picture.1).expect("a picture of at least 1x1");
    let golden = image::load_from_memory(GOLDEN).expect("the golden picture decodes").to_rgba8();
    let size = tiny_skia::IntSize::from_wh(golden.width(), golden.height()).expect("a non-empty picture");
    let golden =
        Pixmap::from_vec(golden.into_raw(), size).expect("RGBA of the right size (opaque: premultiplied as is)");
    let scale =
        Transform::from_scale(l.picture.0 as f32 / golden.width() as f32, l.picture.1 as f32 / golden.height() as f32);
    let paint = PixmapPaint { quality: FilterQuality::Bilinear, ..PixmapPaint::default() };
    picture.draw_pixmap(0, 0, golden.as_ref(), &paint, scale, None);

    let mut out = b"\x1b[?1049h\x1b[?25l\x1b[2J".to_vec();
    // GRAPHICS_DEMO_LABEL: a text label in the picture's top-left cells, drawn before the
    // picture (kitty at z=-1 keeps it readable; sixel paints over it).
    if let Ok(label) = std::env::var("GRAPHICS_DEMO_LABEL") {
        out.extend_from_slice(format!("\x1b[2;3H\x1b[1;33m{label}\x1b[0m").as_bytes());
    }
    let status = format!(" graphics_demo: {} ", choice.mode.name());
    out.extend_from_slice(format!("\x1b[{rows};1H\x1b[7m{status}\x1b[0m").as_bytes());
    let mut kitty_enc = KittyEncoder::new(KittyOptions {
        tmux: choice.tmux_wrap,
        placeholders: choice.kitty_placeholders,
        frame_edits: support.kitty_frame_edits,
        medium: if support.kitty_temp_file { Medium::TempFile(kitty_temp_dir()) } else { Medium::Direct },
        // Under text glyphs, as the player places it (src/term/picture.rs).
        z_index: -1,
        ..KittyOptions::new(l.cells)
    });
    let registers = support.sixel_registers();
    let mut sixel_enc = SixelEncoder::new(SixelPalette::for_registers(registers), (0, 0), Some(l.cell_px));
    let mut iterm2_enc = Iterm2Encoder::new((0, 0), l.cells, choice.tmux_wrap);
    let mut draw = |picture: &Pixmap, out: &mut Vec<u8>, text: &mut String| -> io::Result<()> {
        let mut rgb = Vec::new();
        push_rgb(picture, &mut rgb);
        let (w, h) = (picture.width(), picture.height());
        let what = match choice.mode {
            GraphicsMode::Kitty => format!("{:?}", kitty_enc.encode(&rgb, w, h, out)?),
            GraphicsMode::Sixel => {
                // The palette fitted to the scene (the first picture; again if its colours drift).
                sixel_enc.fit_to(&rgb, 3, 256);
                format!("{:?}", sixel_enc.encode(&rgb, w, h, out))
            }
            GraphicsMode::Iterm2 => format!("{}", iterm2_enc.encode(picture, out)),
            GraphicsMode::Cells => {
                let mut frame = tidepool::testing::Frame::new(usize::from(cols), usize::from(rows) - 1);
                frame.draw_pixels(picture, tidepool::play::ColorMode::TrueColor);
                let mut shown = tidepool::testing::Shown::UNKNOWN;
                tidepool::testing::encode_into(&mut shown, &frame, Default::default(), out);
                "cells".into()
            }
        };
        text.push_str(&format!("frame: {what}, {} bytes\n", out.len()));
        Ok(())
    };
    draw(&picture, &mut out, &mut text)?;
    write(&out)?;
    std::thread::sleep(Duration::from_secs_f64(seconds / 2.0));

    // A red square in the middle: only it should be sent.
    let (w, h) = (picture.width() as f32, picture.height() as f32);
    let square = Rect::from_xywh(w * 0.45, h * 0.4, w * 0.1, h * 0.2).expect("a square inside the picture");
    picture.fill_rect(
        square,
        &tiny_skia::Paint {
            shader: tiny_skia::Shader::SolidColor(Color::from_rgba8(220, 30, 30, 255)),
            ..Default::default()
        },
        Transform::identity(),
        None,
    );
    let mut out = Vec::new();
    draw(&picture, &mut out, &mut text)?;
    write(&out)?;
    // What the terminal should show: the picture, or for sixel the dithered picture.
    let expected = if choice.mode == GraphicsMode::Sixel {
        let mut rgb = Vec::new();
        push_rgb(&picture, &mut rgb);
        let shown = dithered_rgb(sixel_enc.palette(), &rgb, picture.width(), picture.height());
        let image = image::RgbImage::from_raw(picture.width(), picture.height(), shown).expect("RGB of the size");
        let mut png = Vec::new();
        image.write_to(&mut io::Cursor::new(&mut png), image::ImageFormat::Png).map_err(io::Error::other)?;
        png
    } else {
        tidepool::encode::png(&picture)
    };
    std::fs::write(format!("{report}.png"), expected)?;
    std::thread::sleep(Duration::from_secs_f64(seconds / 2.0));

    let mut restore = Vec::new();
    if choice.mode == GraphicsMode::Kitty {
        kitty_enc.push_delete(&mut restore);
    }
    restore.extend_from_slice(b"\x1b[0m\x1b[?25h\x1b[?1049l");
    write(&restore)?;
    std::fs::write(report, text)
}
