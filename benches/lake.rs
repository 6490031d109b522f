//! `render/lake`: one lake frame at terminal size (160x96, no supersampling) and at 1920x1080
//! with 2x2 supersampling, a 3 m/s breeze moving on 1/30 s per frame (the camera, shore,
//! sky and mirror stay, as in the player). `render/lake_new` adds building all of those.
//! Triangle counts are printed once.

use criterion::{Criterion, criterion_group, criterion_main};
use tiny_skia::Pixmap;

use tidepool::{LakeParams, LakeScene, LakeSettings, Scene};

fn scene(width: u32, height: u32, ssaa: u32) -> LakeScene {
    let settings =
        LakeSettings { lake: LakeParams { wind_m_s: 3.0, ..LakeParams::default() }, ssaa, ..LakeSettings::default() };
    LakeScene::new(settings, width, height).expect("valid size")
}

fn render_lake(c: &mut Criterion) {
    let mut group = c.benchmark_group("render/lake");
    group.sample_size(20);
    for (name, w, h, ssaa) in [("160x96_ssaa1", 160, 96, 1), ("1920x1080_ssaa2", 1920, 1080, 2)] {
        let mut s = scene(w, h, ssaa);
        let mut out = Pixmap::new(w, h).unwrap();
        s.render(&mut out);
        eprintln!("render/lake/{name}: {}", s.describe());
        group.bench_function(name, |b| {
            b.iter(|| {
                s.advance(1.0 / 30.0);
                s.render(&mut out);
            })
        });
    }
    group.finish();
    let mut group = c.benchmark_group("render/lake_new");
    group.sample_size(10);
    for (name, w, h, ssaa) in [("160x96_ssaa1", 160, 96, 1), ("1920x1080_ssaa2", 1920, 1080, 2)] {
        let mut out = Pixmap::new(w, h).unwrap();
        group.bench_function(name, |b| b.iter(|| scene(w, h, ssaa).render(&mut out)));
    }
    group.finish();
}

criterion_group!(benches, render_lake);
criterion_main!(benches);
