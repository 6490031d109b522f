//! `render/ocean`: one ocean frame at terminal size (160x96, no supersampling) and at
//! 1920x1080 with 2x2 supersampling, the camera still (the triangulation is reused, as in the
//! player), the sea moving on 1/30 s per frame. `render/ocean_new_camera` adds building the
//! triangulation. Triangle counts are printed once.

use criterion::{Criterion, criterion_group, criterion_main};
use tiny_skia::Pixmap;

use tidepool::render::ocean::OceanView;
use tidepool::render::texture::SeaTexture;
use tidepool::scene::ocean::{OceanScene, OceanSettings};
use tidepool::sim::ocean::SeaParams;

fn scene(width: u32, height: u32, ssaa: u32) -> OceanScene {
    let settings = OceanSettings {
        sea: SeaParams { wind_m_s: 10.0, wind_from_deg: 330.0, seed: 1, ..SeaParams::default() },
        view: OceanView { ssaa, ..OceanView::default() },
    };
    OceanScene::new(settings, width, height, SeaTexture::builtin()).expect("valid size")
}

fn render_ocean(c: &mut Criterion) {
    let mut group = c.benchmark_group("render/ocean");
    group.sample_size(20);
    for (name, w, h, ssaa) in [("160x96_ssaa1", 160, 96, 1), ("1920x1080_ssaa2", 1920, 1080, 2)] {
        let mut s = scene(w, h, ssaa);
        let mut out = Pixmap::new(w, h).unwrap();
        s.render(&mut out);
        eprintln!("render/ocean/{name}: {} triangles", s.renderer().triangle_count());
        group.bench_function(name, |b| {
            b.iter(|| {
                s.advance(1.0 / 30.0);
                s.render(&mut out);
            })
        });
    }
    group.finish();
    let mut group = c.benchmark_group("render/ocean_new_camera");
    group.sample_size(10);
    for (name, w, h, ssaa) in [("160x96_ssaa1", 160, 96, 1), ("1920x1080_ssaa2", 1920, 1080, 2)] {
        let mut out = Pixmap::new(w, h).unwrap();
        group.bench_function(name, |b| b.iter(|| scene(w, h, ssaa).render(&mut out)));
    }
    group.finish();
}

criterion_group!(benches, render_ocean);
criterion_main!(benches);
