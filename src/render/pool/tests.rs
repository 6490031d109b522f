use super::*;
use crate::sim::ripple::{Damping, Stone};

fn striped_background(w: u32, h: u32) -> Pixmap {
    let mut bg = Pixmap::new(w, h).unwrap();
    for (i, p) in bg.pixels_mut().iter_mut().enumerate() {
        let (x, y) = ((i as u32 % w) as u8, (i as u32 / w) as u8);
        *p = tiny_skia::PremultipliedColorU8::from_rgba(x, y, 7, 255).unwrap();
    }
    bg
}

#[test]
fn still_water_shows_the_floor_unchanged() {
    let bg = striped_background(20, 10);
    let mut renderer = PoolRenderer::new(bg.clone(), PoolLook::default());
    let pool = RipplePool::new(20, 10, Damping::PAPERS);
    let mut out = Pixmap::new(20, 10).unwrap();
    renderer.render(&pool, &mut out);
    assert_eq!(out.data(), bg.data());
}

#[test]
fn offsets_follow_the_papers_formula() {
    let bg = striped_background(30, 30);
    let look =
        PoolLook { refraction: Refraction::fixed(1.0).unwrap(), shading: false, caustics: None, ..PoolLook::default() };
    let mut renderer = PoolRenderer::new(bg, look);
    let mut pool = RipplePool::new(30, 30, Damping::OFF);
    // A single deep cell at (10, 10): its neighbours see a slope of ±5.
    pool.drop_stone(Stone { x: 10, y: 10, radius: 1, weight: 5 });
    let mut out = Pixmap::new(30, 30).unwrap();
    renderer.render(&pool, &mut out);
    let at = |x: usize, y: usize| {
        let p = out.pixels()[y * 30 + x];
        (p.red(), p.green())
    };
    // Left of the dent: xoff = h[x-1] - h[x+1] = 0 - (-5) = 5, so it shows x + 5.
    assert_eq!(at(9, 10), (14, 10));
    // Right of it: xoff = -5 - 0 = -5.
    assert_eq!(at(11, 10), (6, 10));
    // Above: yoff = 0 - (-5) = 5; below: -5.
    assert_eq!(at(10, 9), (10, 14));
    assert_eq!(at(10, 11), (10, 6));
    // The dent itself is flat around it.
    assert_eq!(at(10, 10), (10, 10));
}

#[test]
fn offsets_clamp_at_the_edges() {
    let bg = striped_background(8, 8);
    let look = PoolLook {
        refraction: Refraction::fixed(10.0).unwrap(),
        shading: false,
        caustics: None,
        ..PoolLook::default()
    };
    let mut renderer = PoolRenderer::new(bg, look);
    let mut pool = RipplePool::new(8, 8, Damping::OFF);
    pool.drop_stone(Stone { x: 3, y: 3, radius: 1, weight: 100 });
    let mut out = Pixmap::new(8, 8).unwrap();
    renderer.render(&pool, &mut out);
    let p = out.pixels()[3 * 8 + 2];
    assert_eq!((p.red(), p.green()), (7, 3), "pushed past the right edge, clamped to it");
    let p = out.pixels()[3 * 8 + 4];
    assert_eq!((p.red(), p.green()), (0, 3), "pushed past the left edge");
}

#[test]
fn shading_lights_slopes_facing_the_sun() {
    let renderer = PoolRenderer::new(striped_background(4, 4), PoolLook::default());
    let grey = u32::from_ne_bytes([100, 100, 100, 255]);
    let red = |p: u32| p.to_ne_bytes()[0];
    let renderer = Shader(renderer);
    // The default sun is in the upper left: a surface rising to the right (across < 0)
    // faces it.
    assert!(red(renderer.light_surface(grey, -10, -10)) > 100);
    assert!(red(renderer.light_surface(grey, 10, 10)) < 100);
    assert_eq!(renderer.light_surface(grey, 0, 0), grey, "flat water, sun off the glint angle");
    assert_eq!(renderer.light_surface(grey, -30000, -30000).to_ne_bytes()[3], 255, "alpha untouched");
    let west = Shader(PoolRenderer::new(
        striped_background(4, 4),
        PoolLook { sun: Sun::new(270.0, 45.0).unwrap(), ..PoolLook::default() },
    ));
    assert!(red(west.light_surface(grey, -10, 0)) > 100);
    assert_eq!(red(west.light_surface(grey, 0, -10)), 100, "a slope across the light is not shaded");
}

#[test]
fn crests_tilted_towards_the_sun_glint() {
    let renderer = Shader(PoolRenderer::new(striped_background(4, 4), PoolLook::default()));
    let dark = u32::from_ne_bytes([20, 40, 80, 255]);
    // The default sun is 30° off the vertical in the north-west: the half vector is 15°
    // off, so a slope of tan 15° ≈ 0.27 towards the upper left mirrors the sun at the eye.
    let slope = (0.268 * STENCIL_SPAN * AMPLITUDE_PER_PIXEL / 2f32.sqrt()) as i32;
    let glint = renderer.light_surface(dark, -slope, -slope).to_ne_bytes();
    assert!(glint[0] > 200 && glint[2] > 200, "{glint:?}");
    let off = renderer.light_surface(dark, slope, slope).to_ne_bytes();
    assert!(off[0] < 20, "{off:?}");
    let flat_enough = renderer.light_surface(dark, -1, -1).to_ne_bytes();
    assert!(flat_enough[0] < 25, "nearly flat water does not glint: {flat_enough:?}");
}

#[test]
fn the_glint_pre_test_never_misses_a_glint() {
    for (az, el) in [(315.0, 60.0), (90.0, 20.0), (0.0, 85.0), (200.0, 45.0), (10.0, 5.0)] {
        let look = PoolLook { sun: Sun::new(az, el).unwrap(), ..PoolLook::default() };
        let renderer = PoolRenderer::new(striped_background(4, 4), look);
        let (mut glints, mut candidates) = (0, 0);
        for across in (-3000..=3000).step_by(7) {
            for along in (-3000..=3000).step_by(7) {
                let may = renderer.may_glint(across, along);
                candidates += usize::from(may);
                if renderer.glint_exact(across, along) > 0 {
                    glints += 1;
                    assert!(may, "sun {az},{el}: slope ({across}, {along}) glints but was skipped");
                }
            }
        }
        assert!(candidates < 4 * glints + 50, "sun {az},{el}: {candidates} candidates for {glints} glints");
    }
}

#[test]
fn caustic_gain_scales_colour_and_saturates() {
    let p = u32::from_ne_bytes([100, 200, 10, 255]);
    assert_eq!(light_pixel(p, 64, 0), p);
    assert_eq!(light_pixel(p, 128, 0).to_ne_bytes(), [200, 255, 20, 255]);
    assert_eq!(light_pixel(p, 32, 0).to_ne_bytes(), [50, 100, 5, 255]);
    assert_eq!(light_pixel(p, 32, 10).to_ne_bytes(), [60, 110, 15, 255]);
    assert_eq!(light_pixel(p, 64, -20).to_ne_bytes(), [80, 180, 0, 255]);
}

/// The renderer's surface light applied to one colour, as the tests want it.
struct Shader(PoolRenderer);

impl Shader {
    fn light_surface(&self, colour: u32, across: i32, along: i32) -> u32 {
        light_pixel(colour, caustics::UNIT_GAIN, self.0.surface_light(across, along))
    }
}

#[test]
fn the_sun_shifts_the_caustics_away_from_it() {
    let look = PoolLook { sun: Sun::new(90.0, 45.0).unwrap(), ..PoolLook::default() };
    let renderer = PoolRenderer::new(striped_background(4, 4), look);
    // Sun in the east: light travels west (negative x), by depth · tan(asin(cos 45° / 1.33))
    // = 24 · 0.628 ≈ 15 pixels.
    assert_eq!(renderer.light_shift, (-15, 0));
    let overhead = PoolLook { sun: Sun::new(0.0, 90.0).unwrap(), ..PoolLook::default() };
    assert_eq!(PoolRenderer::new(striped_background(4, 4), overhead).light_shift, (0, 0));
}

#[test]
fn staged_spans_compute_exactly_what_single_pixels_do() {
    let (w, h) = (150u32, 90u32);
    for look in [
        PoolLook::default(),
        PoolLook {
            refraction: Refraction::fixed(1.0).unwrap(),
            sun: Sun::new(100.0, 30.0).unwrap(),
            ..PoolLook::default()
        },
        PoolLook { caustics: None, shading: false, ..PoolLook::default() },
    ] {
        let mut renderer = PoolRenderer::new(striped_background(w, h), look);
        let mut pool = RipplePool::new(w as usize, h as usize, Damping::PAPERS);
        for k in 0..30 {
            pool.drop_stone(Stone { x: (k * 37 % w) as i32, y: (k * 23 % h) as i32, radius: 3, weight: 400 });
            pool.advance(2);
        }
        let mut out = Pixmap::new(w, h).unwrap();
        renderer.render(&pool, &mut out);
        let heights = pool.heights();
        let (wu, hu) = (w as usize, h as usize);
        for y in 0..hu {
            let row = |dy: isize| {
                let r = (y as isize + dy).clamp(0, hu as isize - 1) as usize;
                &heights[r * wu..(r + 1) * wu]
            };
            let around = [row(-2), row(-1), row(0), row(1), row(2)];
            let rows = Rows { refraction: around, light: around };
            for x in 0..wu {
                let near = [x.saturating_sub(2), x.saturating_sub(1), (x + 1).min(wu - 1), (x + 2).min(wu - 1)];
                let expected = renderer.pixel(&rows, x, y, near).to_ne_bytes();
                let got = &out.data()[(y * wu + x) * 4..(y * wu + x) * 4 + 4];
                assert_eq!(got, expected, "({x}, {y}) with {look:?}");
            }
        }
    }
}

#[test]
fn packed_lerp_is_exact_per_channel() {
    let a = u32::from_ne_bytes([0, 255, 10, 255]);
    let b = u32::from_ne_bytes([255, 0, 30, 255]);
    assert_eq!(lerp_packed(a, b, 0), a);
    assert_eq!(lerp_packed(a, b, 256), b);
    assert_eq!(lerp_packed(a, b, 128).to_ne_bytes(), [127, 127, 20, 255]);
}

#[test]
fn parallel_rows_equal_single_thread_rows() {
    let (w, h) = (400u32, 300u32);
    let mut renderer = PoolRenderer::new(striped_background(w, h), PoolLook::default());
    let mut pool = RipplePool::new(w as usize, h as usize, Damping::PAPERS);
    for k in 0..9 {
        pool.drop_stone(Stone { x: 40 * k, y: 30 * k, radius: 7, weight: 300 });
    }
    pool.advance(25);
    let mut parallel = Pixmap::new(w, h).unwrap();
    renderer.render(&pool, &mut parallel);
    let mut single = Pixmap::new(w, h).unwrap();
    let fields = Fields { refraction: pool.heights(), light: pool.heights() };
    renderer.render_rows(fields, 0, single.data_mut(), &mut RowScratch::default());
    assert_eq!(parallel.data(), single.data());
}

#[test]
fn auto_refraction_scales_with_size() {
    assert_eq!(Refraction::AUTO.factor(1920, 1080), 1.0);
    assert!((Refraction::AUTO.factor(640, 360) - 0.5).abs() < 1e-6);
    assert_eq!(Refraction::AUTO.factor(160, 94), 0.15);
    assert_eq!(Refraction::fixed(2.5).unwrap().factor(10, 10), 2.5);
}
