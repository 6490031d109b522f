//! The pool alive at rest: a [`PoolScene`] with a [`Breeze`], rain and (optionally) a stone a
//! second, stepped at the player's 60 steps a second, written as a PNG sequence and a contact
//! sheet (every saved frame, scaled up 3x, in a grid) to look at.
//!
//!     cargo run --release --example alive_pool -- OUT_DIR [key=value ...]
//!
//! Keys (defaults in brackets): `size=WxH` [160x94], `breeze=LEVEL` [1], `damping=SHIFT|off`
//! [6], `rain=RATE` [0.05], `seed=N` [1], `seconds=S` [6], `every=STEPS` (one PNG every this
//! many steps) [30], `stones=0|1` (a stone a second, like the codec fixture) [1], `weight=W` (the
//! stones' weight) [128]; to try other
//! breeze shapes ([`BreezeShape`]): `packets=`, `amplitude=`, `wavelength=MIN..MAX`, `length=`,
//! `width=`, `heading=`, `spread=`.
//!
//! The stepping order is the one the scene integration will use: per step the breeze excites
//! the water, then the scene steps (its raindrops land, then the water moves).

use std::path::PathBuf;

use tidepool::output::png;
use tidepool::render::background;
use tidepool::render::pool::PoolLook;
use tidepool::scene::pool::{PoolScene, PoolSettings};
use tidepool::sim::breeze::{Breeze, BreezeShape};
use tidepool::sim::ripple::{Damping, Stone};
use tiny_skia::{Pixmap, PixmapPaint, Transform};

/// The stone weight proposed for the player (today's `PLAYER_STONE_WEIGHT` is 48): lighter
/// rings are flattened by the papers' integer damping within a second, before they cross the
/// pool, and drown in the breeze.
const PROPOSED_STONE_WEIGHT: i16 = 128;
/// The player's simulation rate.
const STEPS_PER_SECOND: u64 = 60;
/// The contact sheet's scale and columns.
const SHEET_SCALE: f32 = 3.0;
const SHEET_COLUMNS: u32 = 4;

struct Options {
    out: PathBuf,
    size: (u32, u32),
    breeze: f64,
    damping: Damping,
    rain: f64,
    seed: u64,
    seconds: u64,
    every: u64,
    stones: bool,
    weight: i16,
    shape: BreezeShape,
}

fn parse() -> Result<Options, String> {
    let mut args = std::env::args().skip(1);
    let out = PathBuf::from(args.next().ok_or("usage: alive_pool OUT_DIR [key=value ...]")?);
    let mut o = Options {
        out,
        size: (160, 94),
        breeze: 1.0,
        damping: Damping::Shift(6),
        rain: 0.05,
        seed: 1,
        seconds: 6,
        every: 30,
        stones: true,
        weight: PROPOSED_STONE_WEIGHT,
        shape: BreezeShape::default(),
    };
    for arg in args {
        let (key, value) = arg.split_once('=').ok_or(format!("expected key=value, got {arg:?}"))?;
        let bad = |e: &dyn std::fmt::Display| format!("{key}={value}: {e}");
        match key {
            "size" => {
                let (w, h) = value.split_once('x').ok_or("size=WxH")?;
                o.size = (w.parse().map_err(|e| bad(&e))?, h.parse().map_err(|e| bad(&e))?);
            }
            "breeze" => o.breeze = value.parse().map_err(|e| bad(&e))?,
            "damping" if value == "off" => o.damping = Damping::Off,
            "damping" => o.damping = Damping::shift(value.parse().map_err(|e| bad(&e))?).ok_or("damping 1..=15")?,
            "rain" => o.rain = value.parse().map_err(|e| bad(&e))?,
            "seed" => o.seed = value.parse().map_err(|e| bad(&e))?,
            "seconds" => o.seconds = value.parse().map_err(|e| bad(&e))?,
            "every" => o.every = value.parse::<u64>().map_err(|e| bad(&e))?.max(1),
            "stones" => o.stones = value != "0",
            "weight" => o.weight = value.parse().map_err(|e| bad(&e))?,
            "packets" => o.shape.packets_per_10k_cells = value.parse().map_err(|e| bad(&e))?,
            "amplitude" => o.shape.amplitude_at_level_1 = value.parse().map_err(|e| bad(&e))?,
            "wavelength" => {
                let (a, b) = value.split_once("..").ok_or("wavelength=MIN..MAX")?;
                o.shape.wavelength_cells = (a.parse().map_err(|e| bad(&e))?, b.parse().map_err(|e| bad(&e))?);
            }
            "length" => o.shape.packet_length_waves = value.parse().map_err(|e| bad(&e))?,
            "width" => o.shape.packet_width_waves = value.parse().map_err(|e| bad(&e))?,
            "heading" => o.shape.heading_deg = value.parse().map_err(|e| bad(&e))?,
            "spread" => o.shape.gust_spread_deg = value.parse().map_err(|e| bad(&e))?,
            _ => return Err(format!("unknown key {key:?}")),
        }
    }
    Ok(o)
}

fn main() {
    let o = match parse() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("alive_pool: {e}");
            std::process::exit(2);
        }
    };
    std::fs::create_dir_all(&o.out).expect("the output directory can be made");
    let settings = PoolSettings { damping: o.damping, rain_rate: o.rain, seed: o.seed, look: PoolLook::default() };
    let mut scene = PoolScene::new(o.size.0, o.size.1, background::pool_floor(), settings).expect("a valid size");
    let mut breeze = Breeze::with_shape(o.breeze, o.seed, o.shape);
    let mut pixmap = Pixmap::new(o.size.0, o.size.1).expect("a valid size");
    let mut saved = Vec::new();
    for step in 0..=o.seconds * STEPS_PER_SECOND {
        if o.stones && step > 0 && step % STEPS_PER_SECOND == 0 {
            // A stone a second at a deterministic spot, like a player's space bar.
            let k = step / STEPS_PER_SECOND;
            let (x, y) = ((k * 53 % u64::from(o.size.0)) as i32, (k * 31 % u64::from(o.size.1)) as i32);
            scene.drop_stone(Stone { x, y, radius: 3, weight: o.weight });
        }
        if step % o.every == 0 {
            scene.render(&mut pixmap);
            let path = o.out.join(format!("frame_{step:05}.png"));
            std::fs::write(&path, png::encode(&pixmap)).expect("the frame can be written");
            saved.push(pixmap.clone());
        }
        breeze.excite(scene.pool_mut());
        scene.step();
    }
    let rows = (saved.len() as u32).div_ceil(SHEET_COLUMNS);
    let (tw, th) = ((o.size.0 as f32 * SHEET_SCALE) as u32, (o.size.1 as f32 * SHEET_SCALE) as u32);
    let mut sheet = Pixmap::new(tw * SHEET_COLUMNS.min(saved.len() as u32), th * rows).expect("a sheet");
    for (i, frame) in saved.iter().enumerate() {
        let (col, row) = (i as u32 % SHEET_COLUMNS, i as u32 / SHEET_COLUMNS);
        let transform =
            Transform::from_scale(SHEET_SCALE, SHEET_SCALE).post_translate((col * tw) as f32, (row * th) as f32);
        let paint = PixmapPaint { quality: tiny_skia::FilterQuality::Nearest, ..Default::default() };
        sheet.draw_pixmap(0, 0, frame.as_ref(), &paint, transform, None);
    }
    std::fs::write(o.out.join("sheet.png"), png::encode(&sheet)).expect("the sheet can be written");
    println!("{} frames and sheet.png in {}", saved.len(), o.out.display());
}
