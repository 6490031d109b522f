use super::*;

fn settings(rain_rate: f64) -> PoolSettings {
    PoolSettings { rain_rate, seed: 7, ..PoolSettings::default() }
}

#[test]
fn rain_moves_the_water_deterministically() {
    let run = || {
        let mut scene = PoolScene::new(64, 48, settings(0.5)).unwrap();
        for _ in 0..40 {
            scene.advance(1);
        }
        scene.snapshot().unwrap().data().to_vec()
    };
    let still = PoolScene::new(64, 48, settings(0.0)).unwrap().snapshot().unwrap();
    assert_eq!(run(), run());
    assert_ne!(run(), still.data());
}

/// The stepper, the refraction rows and the caustics give the same bytes on every
/// instruction set this CPU runs, at terminal size and at a size whose caustics are
/// computed at half resolution on several threads.
#[test]
fn every_simd_tier_draws_the_same_pixels() {
    for (w, h, pool) in [(160u32, 94u32, settings(0.4)), (1024, 600, settings(0.4)), (160, 94, coherent(2))] {
        let run = |simd: Simd| {
            let mut scene = PoolScene::new(w, h, pool.clone()).unwrap();
            scene.set_simd(simd);
            for k in 0..12 {
                scene.drop_stone(Stone::clamped((k * 37 % w) as i32, (k * 53 % h) as i32, 5, 300));
                scene.advance(7);
            }
            (scene.pool().heights().to_vec(), scene.snapshot().unwrap().data().to_vec())
        };
        let portable = run(Simd::PORTABLE);
        for simd in Simd::supported() {
            let (heights, pixels) = run(simd);
            assert!(heights == portable.0, "{w}x{h}: the water on {simd} differs from portable");
            assert!(pixels == portable.1, "{w}x{h}: the picture on {simd} differs from portable");
        }
    }
}

fn coherent(grid: u32) -> PoolSettings {
    PoolSettings {
        grid,
        steps_per_second: 30,
        breeze: 1.0,
        breeze_style: BreezeStyle::Gusts,
        rain_rate: 0.3,
        ..settings(0.0)
    }
}

#[test]
fn a_finer_grid_takes_stones_in_pixels_and_moves_their_rings_slower() {
    // The same stone in pixels on one and on two cells a pixel: the dent covers the same
    // pixels, and after the same steps the ring has travelled the same cells, half the
    // pixels.
    let ring_radius = |grid: u32| {
        let mut scene = PoolScene::new(80, 60, PoolSettings { grid, ..settings(0.0) }).unwrap();
        scene.drop_stone(Stone::new(40, 30, 3, 128).unwrap());
        let dent = scene.pool().heights().iter().filter(|&&v| v < 0).count() as f32;
        let disc = std::f32::consts::PI * (3 * grid * 3 * grid) as f32;
        assert!((dent / disc - 1.0).abs() < 0.25, "a disc of radius 3 pixels: {dent} cells on grid {grid}");
        scene.advance(40);
        // The ring's front: the farthest cell the wave has moved by a few units.
        let (w, pool) = (scene.pool().width(), scene.pool());
        let centre = (40.0 * grid as f32 + (grid / 2) as f32, 30.0 * grid as f32 + (grid / 2) as f32);
        let front = pool.heights().iter().enumerate().filter(|&(_, &v)| v.abs() >= 4).map(|(i, _)| {
            let (x, y) = ((i % w) as f32, (i / w) as f32);
            (x - centre.0).hypot(y - centre.1)
        });
        front.fold(0f32, f32::max) / grid as f32
    };
    // 0.7 cells a step: 28 cells past the dent's edge (3 pixels = 3 or 6 cells).
    let (one, two) = (ring_radius(1), ring_radius(2));
    assert!((one - 31.0).abs() < 4.0, "{one} pixels after 40 steps on one cell a pixel");
    assert!((two - 17.0).abs() < 3.0, "{two} pixels after 40 steps on two cells a pixel");
    assert_eq!(PoolScene::new(10, 10, PoolSettings { grid: 5, ..settings(0.0) }).map(|s| s.grid()), None);
}

#[test]
fn gusts_move_the_water_at_rest_and_clearing_stills_them() {
    let mut scene = PoolScene::new(80, 48, PoolSettings { rain_rate: 0.0, ..coherent(2) }).unwrap();
    let calm = PoolSettings { rain_rate: 0.0, breeze: 0.0, ..coherent(2) };
    let still = PoolScene::new(80, 48, calm).unwrap().snapshot().unwrap();
    scene.advance(30);
    assert!(scene.pool().heights().iter().all(|&v| v == 0), "the gusts are drawn, not put into the pool");
    let breezy = scene.snapshot().unwrap();
    let moved = breezy.pixels().iter().zip(still.pixels()).filter(|(a, b)| a != b).count();
    assert!(moved > 80 * 48 / 10, "the gusts light the floor: {moved} pixels moved");
    scene.apply(&Event::Clear);
    assert!(scene.snapshot().unwrap().data() == still.data(), "clear stills the gusts too");
    assert_eq!(scene.steps_per_second(), 30.0);
}

#[test]
fn grids_paces_and_styles_are_checked() {
    assert_eq!(parse_grid(" 2 "), Ok(2));
    assert!(parse_grid("5").unwrap_err().to_string().contains("outside 1..=4"));
    assert!(parse_grid("1.5").unwrap_err().to_string().contains("whole number"));
    assert_eq!(parse_steps_per_second("30"), Ok(30));
    assert!(parse_steps_per_second("0").unwrap_err().to_string().contains("outside 1..=240"));
    assert_eq!("gusts".parse(), Ok(BreezeStyle::Gusts));
    assert_eq!("wavelets".parse(), Ok(BreezeStyle::Wavelets));
    assert!("storm".parse::<BreezeStyle>().unwrap_err().to_string().contains("'gusts'"));
}

#[test]
fn advance_equals_single_steps() {
    let mut stepped = PoolScene::new(80, 60, settings(0.3)).unwrap();
    let mut advanced = stepped.clone();
    for _ in 0..77 {
        stepped.advance(1);
    }
    advanced.advance(77);
    assert_eq!(stepped.pool().heights(), advanced.pool().heights());
    assert_eq!(stepped.pool().steps(), 77);
    assert_eq!(advanced.pool().steps(), 77);
}

#[test]
fn resize_reallocates() {
    let mut scene = PoolScene::new(64, 48, settings(0.0)).unwrap();
    scene.drop_stone(Stone { x: 10, y: 10, radius: 4, weight: 64 });
    assert!(PoolScene::resize(&mut scene, 30, 20));
    assert_eq!((scene.width(), scene.height()), (30, 20));
    assert!(scene.pool().heights().iter().all(|&v| v == 0));
    assert_eq!(scene.snapshot().unwrap().width(), 30);
    assert!(Scene::resize(&mut scene, 0, 10).is_err());
    assert_eq!(scene.width(), 30);
}

#[test]
fn actions_resolve_to_events_that_apply() {
    let mut scene = PoolScene::new(40, 30, settings(0.0)).unwrap();
    let events = scene.resolve(Action::Stone { x: 10, y: 12, radius: 3, big: true });
    assert_eq!(events, vec![Event::Stone(Stone::new(10, 12, 6, 256).unwrap())]);
    scene.apply(&events[0]);
    assert!(scene.pool().heights()[12 * 40 + 10] < 0);
    let stir = scene.resolve(Action::Stir { from: (5, 5), to: (15, 5) });
    assert_eq!(stir.len(), 5);
    assert_eq!(stir[4], Event::Stone(Stone::clamped(15, 5, 2, STIR_WEIGHT)));
    let rain = scene.resolve(Action::ToggleRain);
    assert_eq!(rain, vec![Event::Rain(DEFAULT_TOGGLE_RAIN)]);
    scene.apply(&rain[0]);
    assert_eq!(scene.resolve(Action::ToggleRain), vec![Event::Rain(0.0)]);
    let damping = scene.resolve(Action::Damping(true));
    assert_eq!(damping, vec![Event::Damping(Damping::from_shift(4).unwrap())]);
    scene.apply(&Event::Clear);
    assert!(scene.pool().heights().iter().all(|&v| v == 0));
    scene.apply(&Event::Resize([20, 10]));
    assert_eq!(Scene::size(&scene), (20, 10));
    assert!(scene.resolve(Action::Key('w')).is_empty());
    let mut status = String::new();
    scene.status(&mut status);
    assert!(status.contains("rain 0.02"));
}

#[test]
fn the_showcase_stays_inside_small_pictures() {
    for (w, h) in [(1, 1), (80, 48), (4000, 300)] {
        let (stones, steps) = PoolScene::showcase(w, h);
        assert!((30..=90).contains(&steps));
        for (at, event) in stones {
            let Event::Stone(s) = event else { panic!("stones only") };
            assert!(s.x() >= 0 && s.y() >= 0 && s.x() < w as i32 && s.y() < h as i32);
            assert!((2..=1000).contains(&s.radius()) && at < steps);
        }
    }
}

#[test]
fn heightmap_mirrors_the_amplitudes() {
    let mut scene = PoolScene::new(10, 8, settings(0.0)).unwrap();
    scene.drop_stone(Stone { x: 4, y: 3, radius: 1, weight: 99 });
    let map = scene.heightmap();
    assert_eq!((map.width, map.height), (10, 8));
    assert_eq!(map.values[3 * 10 + 4], -99.0);
}
