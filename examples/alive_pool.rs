//! The pool alive at rest, as the player shows it: the breeze, rain and (optionally) a stone a
//! second, stepped at the player's 60 steps a second, written as a PNG sequence and a contact
//! sheet (every saved frame, scaled up 3x, in a grid) to look at.
//!
//!     cargo run --release --example alive_pool -- OUT_DIR [key=value ...]
//!
//! Keys (defaults in brackets): `size=WxH` [160x94], `breeze=LEVEL` [1], `damping=SHIFT|off`
//! [6], `rain=RATE` [0.05], `seed=N` [1], `seconds=S` [6], `every=STEPS` (one PNG every this
//! many steps) [30], `stones=0|1` (a stone a second, like the codec fixture) [1], `weight=W` (the
//! stones' weight) [128].

use std::path::PathBuf;

use tidepool::testing::Size;
use tidepool::{Damping, PoolScene, PoolSettings, Scene, Stone};
use tiny_skia::{Pixmap, PixmapPaint, Transform};

/// The player's simulation rate.
const STEPS_PER_SECOND: u64 = 60;
/// The contact sheet's scale and columns.
const SHEET_SCALE: f32 = 3.0;
const SHEET_COLUMNS: u32 = 4;

struct Options {
    out: PathBuf,
    size: Size,
    settings: PoolSettings,
    seconds: u64,
    every: u64,
    stones: bool,
    weight: i64,
}

fn parse() -> Result<Options, String> {
    let mut args = std::env::args().skip(1);
    let out = PathBuf::from(args.next().ok_or("usage: alive_pool OUT_DIR [key=value ...]")?);
    let mut o = Options {
        out,
        size: Size::of(160, 94),
        settings: PoolSettings {
            breeze: 1.0,
            damping: Damping::from_shift(6).expect("a valid shift"),
            rain_rate: 0.05,
            ..PoolSettings::default()
        },
        seconds: 6,
        every: 30,
        stones: true,
        weight: 128,
    };
    for arg in args {
        let (key, value) = arg.split_once('=').ok_or(format!("'{arg}' is not key=value"))?;
        let number = |v: &str| v.parse::<f64>().map_err(|e| format!("{key}: {e}"));
        match key {
            "size" => o.size = value.parse().map_err(|e| format!("size: {e}"))?,
            "breeze" => o.settings.breeze = PoolSettings::check_breeze(number(value)?).map_err(|e| e.to_string())?,
            "damping" => o.settings.damping = value.parse().map_err(|e| format!("damping: {e}"))?,
            "rain" => o.settings.rain_rate = PoolSettings::check_rain(number(value)?).map_err(|e| e.to_string())?,
            "seed" => o.settings.seed = number(value)? as u64,
            "seconds" => o.seconds = number(value)? as u64,
            "every" => o.every = (number(value)? as u64).max(1),
            "stones" => o.stones = value == "1",
            "weight" => o.weight = number(value)? as i64,
            _ => return Err(format!("unknown key '{key}'")),
        }
    }
    Ok(o)
}

fn main() -> Result<(), String> {
    let o = parse()?;
    std::fs::create_dir_all(&o.out).map_err(|e| format!("{}: {e}", o.out.display()))?;
    let (w, h) = (o.size.width(), o.size.height());
    let mut scene = PoolScene::new(w, h, o.settings.clone()).ok_or("the picture is too large")?;
    let mut frames = Vec::new();
    for step in 1..=o.seconds * STEPS_PER_SECOND {
        if o.stones && step % STEPS_PER_SECOND == 0 {
            let k = step / STEPS_PER_SECOND;
            let stone = Stone::new((k * 53 % u64::from(w)) as i64, (k * 31 % u64::from(h)) as i64, 3, o.weight)
                .map_err(|e| e.to_string())?;
            scene.drop_stone(stone);
        }
        scene.advance(1);
        if step % o.every == 0 {
            let picture = scene.snapshot().map_err(|e| e.to_string())?;
            let path = o.out.join(format!("alive_{step:05}.png"));
            std::fs::write(&path, tidepool::encode::png(&picture)).map_err(|e| format!("{}: {e}", path.display()))?;
            frames.push(picture);
        }
    }
    // The contact sheet.
    let rows = (frames.len() as u32).div_ceil(SHEET_COLUMNS).max(1);
    let (cw, ch) = ((w as f32 * SHEET_SCALE) as u32, (h as f32 * SHEET_SCALE) as u32);
    let mut sheet = Pixmap::new(cw * SHEET_COLUMNS, ch * rows).ok_or("the sheet is too large")?;
    for (i, frame) in frames.iter().enumerate() {
        let (col, row) = (i as u32 % SHEET_COLUMNS, i as u32 / SHEET_COLUMNS);
        let transform = Transform::from_row(SHEET_SCALE, 0.0, 0.0, SHEET_SCALE, (col * cw) as f32, (row * ch) as f32);
        sheet.draw_pixmap(0, 0, frame.as_ref(), &PixmapPaint::default(), transform, None);
    }
    let path = o.out.join("sheet.png");
    std::fs::write(&path, tidepool::encode::png(&sheet)).map_err(|e| format!("{}: {e}", path.display()))?;
    println!("{} frames and {}", frames.len(), path.display());
    Ok(())
}
