//! `render/ocean`: one ocean frame at terminal size (160x96 and the player's 160x94, no
//! supersampling) and at 1920x1080 with 2x2 supersampling, the camera still (the
//! triangulation is reused, as in the player), the sea moving on 1/30 s per frame: a linear
//! sea (choppiness 0) and `chop_foam` (the default, physical choppiness; foam is followed in
//! every case). `render/ocean_new_camera` adds building the triangulation. `still/`: a
//! picture from nothing, as `render ocean` makes one: the scene, the triangulation and the
//! foam's whole memory (a gale, Beaufort 8, and the default 10 m/s sea). `maps/1024`: the
//! tileable maps (height, displacement, normals, foam) of a 1024x1024 patch for one time step
//! of a series 1/30 s apart (foam continues) written over the step before's maps, as `tidepool
//! maps` does, encoding and writing not counted;
//! `maps/1024_surface` without foam; `maps/1024_cold` a set from nothing (the patch, the
//! foam's memory and the maps); `maps/256` one step of a 256x256 series 1/3 s apart. Scene
//! descriptions are printed once.

use criterion::{Criterion, criterion_group, criterion_main};
use tiny_skia::Pixmap;

use tidepool::sea::beaufort_speed_m_s;
use tidepool::testing::PatchSea;
use tidepool::{OceanScene, OceanSettings, OceanView, Scene, SeaParams};

fn scene(width: u32, height: u32, ssaa: u32, sea: SeaParams) -> OceanScene {
    let settings = OceanSettings { sea, view: OceanView { ssaa, ..OceanView::default() }, ..OceanSettings::default() };
    OceanScene::new(settings, width, height).expect("valid size")
}

fn render_ocean(c: &mut Criterion) {
    let mut group = c.benchmark_group("render/ocean");
    group.sample_size(20);
    let cases = [
        ("160x96_ssaa1", 160, 96, 1, 0.0),
        ("160x94_ssaa1_chop_foam", 160, 94, 1, SeaParams::DEFAULT_CHOPPINESS),
        ("1920x1080_ssaa2", 1920, 1080, 2, 0.0),
        ("1920x1080_ssaa2_chop_foam", 1920, 1080, 2, SeaParams::DEFAULT_CHOPPINESS),
    ];
    for (name, w, h, ssaa, choppiness) in cases {
        let mut s = scene(w, h, ssaa, SeaParams::default().with_choppiness(choppiness));
        let mut out = Pixmap::new(w, h).unwrap();
        s.render(&mut out);
        eprintln!("render/ocean/{name}: {}", s.describe());
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
        group.bench_function(name, |b| b.iter(|| scene(w, h, ssaa, SeaParams::default()).render(&mut out)));
    }
    group.finish();
    let mut group = c.benchmark_group("still");
    group.sample_size(10);
    let gale = SeaParams::default().with_wind_m_s(beaufort_speed_m_s(8).unwrap());
    for (name, sea) in [("1920x1080_ssaa2_beaufort8", gale), ("1920x1080_ssaa2_default", SeaParams::default())] {
        let mut out = Pixmap::new(1920, 1080).unwrap();
        group.bench_function(name, |b| b.iter(|| scene(1920, 1080, 2, sea).render(&mut out)));
    }
    group.finish();
}

fn maps(c: &mut Criterion) {
    let mut group = c.benchmark_group("maps");
    group.sample_size(10);
    let params = SeaParams::default().with_wind_m_s(12.0).with_choppiness(SeaParams::DEFAULT_CHOPPINESS);
    let mut patch = PatchSea::new(params, 1024, 1000.0).expect("valid patch");
    // A series' step, as `tidepool maps` takes it: into maps it wrote before.
    let mut maps = patch.maps(0.0);
    let mut t = 0.0;
    group.bench_function("1024", |b| {
        b.iter(|| {
            t += 1.0 / 30.0;
            patch.maps_after(0.0, t, &mut maps);
        })
    });
    group.bench_function("1024_surface", |b| b.iter(|| patch.surface(3.0)));
    group.bench_function("1024_cold", |b| {
        b.iter(|| PatchSea::new(params, 1024, 1000.0).expect("valid patch").maps(5.0))
    });
    let small = params.with_wind_m_s(beaufort_speed_m_s(5).unwrap());
    let mut patch = PatchSea::new(small, 256, 900.0).expect("valid patch");
    let mut maps = patch.maps(0.0);
    let mut t = 0.0;
    group.bench_function("256", |b| {
        b.iter(|| {
            t += 1.0 / 3.0;
            patch.maps_after(0.0, t, &mut maps);
        })
    });
    group.finish();
}

criterion_group!(benches, render_ocean, maps);
criterion_main!(benches);
