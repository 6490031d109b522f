//! Renders the ocean pictures of the guide's gallery (docs/GUIDE.md) through the library's public API:
//!
//! ```sh
//! cargo run --release --example ocean_gallery -- docs/gallery
//! ```
//!
//! Beaufort 3, 6, 9 and 10 with the physical choppiness and foam, a wind sea with swell, a
//! fetch-limited JONSWAP sea, a shallow TMA sea, the far crests of a 1920x1080 gale
//! (cropped), the player's terminal frame (160x94, magnified), and a 2x2 tiling of a periodic
//! map. Each is shaded as its command draws it: pictures flat (`render ocean`'s default for
//! pictures), the player's frame smooth (`play`'s default). (The presets' pictures are `render ocean --preset NAME`: `scripts/gallery.sh`.)

use std::path::{Path, PathBuf};

use tiny_skia::{Pixmap, PixmapPaint, Transform};

use tidepool::sea::beaufort_speed_m_s;
use tidepool::testing::PatchSea;
use tidepool::{CameraPose, OceanScene, OceanSettings, OceanView, Scene, SeaParams, SeaShading};

struct Shot {
    name: &'static str,
    params: SeaParams,
    sun: (f32, f32),
    size: (u32, u32),
    ssaa: u32,
    shading: SeaShading,
    time_s: f64,
}

/// A gallery picture: 640x360, two samples a pixel, at time 0.
fn gallery(name: &'static str, params: SeaParams, sun: (f32, f32)) -> Shot {
    Shot { name, params, sun, size: (640, 360), ssaa: 2, shading: SeaShading::Flat, time_s: 0.0 }
}

fn render(shot: &Shot) -> Pixmap {
    let view = OceanView {
        camera: CameraPose::DEFAULT,
        sun_azimuth_deg: shot.sun.0,
        sun_elevation_deg: shot.sun.1,
        ssaa: shot.ssaa,
        shading: shot.shading,
        ..OceanView::default()
    };
    let settings = OceanSettings { sea: shot.params, view, start_time_s: shot.time_s, ..OceanSettings::default() };
    let mut scene = OceanScene::new(settings, shot.size.0, shot.size.1).expect("valid size");
    scene.snapshot().expect("a picture of a valid size")
}

fn crop(p: &Pixmap, x: u32, y: u32, w: u32, h: u32) -> Pixmap {
    let mut out = Pixmap::new(w, h).expect("valid size");
    out.draw_pixmap(-(x as i32), -(y as i32), p.as_ref(), &PixmapPaint::default(), Transform::identity(), None);
    out
}

fn magnify(p: &Pixmap, k: u32) -> Pixmap {
    let mut out = Pixmap::new(p.width() * k, p.height() * k).expect("valid size");
    let w = out.width();
    for y in 0..out.height() {
        for x in 0..w {
            out.pixels_mut()[(y * w + x) as usize] = p.pixels()[((y / k) * p.width() + x / k) as usize];
        }
    }
    out
}

fn save(dir: &Path, name: &str, p: &Pixmap) {
    let path = dir.join(name);
    std::fs::write(&path, tidepool::encode::png(p)).expect("writable gallery folder");
    println!("{}", path.display());
}

fn main() {
    let dir = PathBuf::from(std::env::args().nth(1).unwrap_or_else(|| "docs/gallery".into()));
    std::fs::create_dir_all(&dir).expect("gallery folder");
    let chop = |wind: f64, from: f64| {
        SeaParams::default().with_wind_m_s(wind).with_wind_from_deg(from).with_choppiness(SeaParams::DEFAULT_CHOPPINESS)
    };
    let b = |n: u8| beaufort_speed_m_s(n).expect("a Beaufort number");
    let shots = [
        gallery("sea-beaufort-3.png", chop(b(3), 330.0), (15.0, 22.0)),
        gallery("sea-beaufort-6.png", chop(b(6), 60.0), (15.0, 22.0)),
        gallery("sea-beaufort-9.png", chop(b(9), 330.0), (200.0, 12.0)),
        gallery("sea-beaufort-10.png", chop(b(10), 330.0), (15.0, 22.0)),
        gallery("sea-swell.png", chop(b(4), 330.0).with_swell(1.5, 12.0, 250.0).expect("one swell"), (15.0, 22.0)),
        gallery(
            "sea-jonswap-fetch-15km.png",
            chop(15.0, 330.0).with_jonswap(Some(3.3), Some(15.0)).expect("a 15 km fetch"),
            (15.0, 22.0),
        ),
        gallery("sea-tma-4m.png", chop(12.0, 330.0).with_tma(None, None, 4.0).expect("4 m of water"), (15.0, 22.0)),
    ];
    for shot in &shots {
        save(&dir, shot.name, &render(shot));
    }
    // The far crests of a 1920x1080 gale (the default look: no choppiness, flat faces, two
    // samples a pixel), cropped.
    let gale = Shot {
        name: "",
        params: SeaParams::default().with_wind_m_s(b(9)),
        sun: (200.0, 12.0),
        size: (1920, 1080),
        ssaa: 2,
        shading: SeaShading::Flat,
        time_s: 0.0,
    };
    save(&dir, "far-crests-after.png", &crop(&render(&gale), 480, 180, 960, 300));
    // The player's frame: 160x48 cells = 160x94 pixels at one sample per pixel, smooth as
    // `play` draws it, magnified.
    let term = Shot {
        name: "",
        params: SeaParams::default().with_wind_m_s(b(6)),
        sun: (15.0, 22.0),
        size: (160, 94),
        ssaa: 1,
        shading: SeaShading::Smooth,
        time_s: 0.0,
    };
    save(&dir, "terminal-after.png", &magnify(&render(&term), 4));
    // A periodic patch's foam and normal map, tiled 2x2: no seam.
    let mut patch = PatchSea::new(chop(b(7), 330.0), 256, 300.0).expect("valid patch");
    let maps = patch.maps(20.0);
    let mut tiled = Pixmap::new(512, 512).expect("valid size");
    for y in 0..512usize {
        for x in 0..512usize {
            let i = (y % 256) * 256 + x % 256;
            let n = maps.normal[i];
            let shade = (0.35 + 0.65 * (0.4 * n[0] + 0.3 * n[1] + 0.87 * n[2]).max(0.0)).min(1.0);
            let f = maps.foam[i];
            let c = |base: f32| ((base * shade * (1.0 - f) + f) * 255.0) as u8;
            tiled.pixels_mut()[y * 512 + x] =
                tiny_skia::PremultipliedColorU8::from_rgba(c(0.12), c(0.32), c(0.45), 255).expect("opaque");
        }
    }
    save(&dir, "maps-tiled-2x2.png", &tiled);
}
