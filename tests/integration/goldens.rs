//! Golden images, rendered in-process through the library's scene contract (resvg's harness:
//! a reference PNG per case, a failure strip under `target/golden-failures/`). The command line
//! is tested to produce the same pictures in `pool.rs`, `ocean.rs` and `lake.rs`.

use tidepool::sea::beaufort_speed_m_s;
use tidepool::testing::Script;
use tidepool::{
    Event, LakeParams, LakeSettings, OceanSettings, OceanView, PoolLook, PoolSettings, Refraction, SceneSpec,
    SeaParams, SeaShading, Stone, Sun,
};
use tiny_skia::Pixmap;

use crate::common::golden::{self, Goldens, Tolerance};

/// Frame `steps` of `spec` at `width x height`, with `script`'s events.
pub fn picture(spec: &SceneSpec, width: u32, height: u32, script: &[(u64, Event)], steps: u64) -> Pixmap {
    let mut scene = spec.build(width, height).expect("a small scene");
    Script::new(script).run_to(scene.as_mut(), steps);
    scene.snapshot().expect("a small picture")
}

/// A pixmap as straight RGBA.
pub fn rgba(pixmap: &Pixmap) -> image::RgbaImage {
    let pixels = pixmap.pixels().iter().flat_map(|p| {
        let c = p.demultiply();
        [c.red(), c.green(), c.blue(), c.alpha()]
    });
    image::RgbaImage::from_raw(pixmap.width(), pixmap.height(), pixels.collect()).unwrap()
}

fn stones(list: &[(i64, i64, i64, i64)]) -> Vec<(u64, Event)> {
    list.iter().map(|&(x, y, r, w)| (0, Event::Stone(Stone::new(x, y, r, w).unwrap()))).collect()
}

#[test]
fn the_default_pool() {
    let (script, steps) = tidepool::PoolScene::showcase(640, 360);
    let p = picture(&SceneSpec::Pool(PoolSettings::default()), 640, 360, &script, steps);
    golden::check_png("pool_default", &rgba(&p), Tolerance::default());
}

#[test]
fn the_players_pool_in_pixels() {
    // What kitty, sixel and iTerm2 show at 160x48 cells: 480x282 pixels of the player's pool
    // (two cells a pixel, gusts, rain), three stones' rings on it.
    let script = stones(&[(120, 80, 4, 128), (330, 200, 4, 128), (240, 141, 3, 160)]);
    let p = picture(&SceneSpec::Pool(crate::pool_bits::player(1)), 480, 282, &script, 90);
    golden::check_png("pool_player", &rgba(&p), Tolerance::default());
}

#[test]
fn a_small_pool_as_half_block_text() {
    let script = stones(&[(20, 14, 4, 128), (44, 26, 3, 128)]);
    let p = picture(&SceneSpec::Pool(PoolSettings::default()), 64, 40, &script, 30);
    let text = tidepool::encode::halfblock(&p);
    assert_eq!(String::from_utf8_lossy(&text).lines().count(), 20, "two pixel rows per line");
    golden::check_ansi("pool_small", &text, Tolerance::default());
}

#[test]
fn a_pool_on_a_user_background() {
    // Diagonal stripes that show every displacement, made here so the test needs no file.
    let stripes = image::RgbImage::from_fn(300, 200, |x, y| match ((x + y) / 12) % 3 {
        0 => image::Rgb([220, 90, 40]),
        1 => image::Rgb([250, 230, 120]),
        _ => image::Rgb([30, 60, 160]),
    });
    let mut png = Vec::new();
    stripes.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).unwrap();
    let floor = tidepool::encode::decode_image(&png).unwrap();
    let look = PoolLook { refraction: Refraction::fixed(1.0).unwrap(), ..PoolLook::default() };
    let spec = SceneSpec::Pool(PoolSettings { look, floor, ..PoolSettings::default() });
    let p = picture(&spec, 240, 160, &stones(&[(120, 80, 6, 160)]), 45);
    golden::check_png("pool_user_background", &rgba(&p), Tolerance::default());
}

#[test]
fn caustics_throw_rings_of_light_on_the_floor() {
    let sun = Sun::new(90.0, 50.0).unwrap();
    let lit_look = PoolLook { sun, ..PoolLook::default() };
    let dark_look = PoolLook { caustics: None, ..lit_look };
    let script = stones(&[(80, 60, 5, 200)]);
    let render =
        |look| picture(&SceneSpec::Pool(PoolSettings { look, ..PoolSettings::default() }), 160, 120, &script, 40);
    let (lit, dark) = (rgba(&render(lit_look)), rgba(&render(dark_look)));
    golden::check_png("pool_caustics", &lit, Tolerance::default());
    // Brighter than the floor somewhere on a ring (the focused light), darker elsewhere.
    let luma = |p: &image::Rgba<u8>| u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2]);
    let (mut brighter, mut darker) = (0, 0);
    for (a, b) in lit.pixels().zip(dark.pixels()) {
        brighter += usize::from(luma(a) > luma(b) + 60);
        darker += usize::from(luma(a) + 30 < luma(b));
    }
    assert!(brighter > 100 && darker > 100, "brighter {brighter}, darker {darker}");
}

/// The sea of `render ocean --beaufort B --direction D --shading S` (seed 1, the default
/// camera and sun).
fn sea(beaufort: u8, direction: f64, ssaa: u32, time_s: f64, shading: SeaShading) -> SceneSpec {
    let wind = beaufort_speed_m_s(beaufort).unwrap();
    SceneSpec::Ocean(OceanSettings {
        sea: SeaParams::default().with_wind_m_s(wind).with_wind_from_deg(direction).with_seed(1),
        view: OceanView { ssaa, shading, ..OceanView::default() },
        start_time_s: time_s,
        ..OceanSettings::default()
    })
}

/// Beaufort 3 and 8, flat (the pictures' default) and smooth.
#[test]
fn seas_at_beaufort_3_and_8_flat_and_smooth() {
    let mut goldens = Goldens::new();
    for shading in [SeaShading::Flat, SeaShading::Smooth] {
        for (beaufort, direction) in [(3, 330.0), (8, 200.0)] {
            let p = picture(&sea(beaufort, direction, 2, 0.0, shading), 192, 108, &[], 0);
            goldens.png(&format!("ocean_b{beaufort}_{shading}"), &rgba(&p), Tolerance::default());
        }
    }
}

/// Beaufort 6 as half-block text, smooth (the text's default) and flat.
#[test]
fn a_sea_as_half_block_text() {
    let mut goldens = Goldens::new();
    for (name, shading) in [("ocean_small", SeaShading::Smooth), ("ocean_small_flat", SeaShading::Flat)] {
        let text = tidepool::encode::halfblock(&picture(&sea(6, 330.0, 1, 4.0, shading), 80, 48, &[], 0));
        assert_eq!(String::from_utf8_lossy(&text).lines().count(), 24, "two pixel rows per line");
        goldens.ansi(name, &text, Tolerance::default());
    }
}

/// The lake of `render lake --wind W --time T` (seed 1, default noise).
fn lake(wind: f64, time_s: f64, ssaa: u32) -> SceneSpec {
    SceneSpec::Lake(LakeSettings {
        lake: LakeParams { wind_m_s: wind, ..LakeParams::default() },
        ssaa,
        start_time_s: time_s,
    })
}

#[test]
fn a_calm_and_a_windy_lake() {
    let mut goldens = Goldens::new();
    for (name, wind, time) in [("lake_calm", 0.0, 0.0), ("lake_windy", 6.0, 2.5)] {
        let p = picture(&lake(wind, time, 2), 192, 108, &[], 0);
        goldens.png(name, &rgba(&p), Tolerance::default());
    }
    for (name, wind) in [("lake_calm_small", 0.0), ("lake_windy_small", 6.0)] {
        let text = tidepool::encode::halfblock(&picture(&lake(wind, 1.0, 1), 80, 48, &[], 0));
        assert_eq!(String::from_utf8_lossy(&text).lines().count(), 24, "two pixel rows per line");
        goldens.ansi(name, &text, Tolerance::default());
    }
}
