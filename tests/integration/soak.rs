//! The long run (ignored by default; about a minute in the dev profile):
//!
//!     cargo test --test integration soak -- --ignored --nocapture
//!
//! A million steps of the player's pool in the dev profile (overflow checks on), driven by a
//! scripted input stream: heavy rain, a stone every step, drags, rain toggles, damping changes
//! (including off), clears and resizes, with frames built and diff-encoded as the player does.
//! It checks that nothing panics or overflows, that the water stays in range, and that memory
//! stays flat.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use tidepool::play::{ColorMode, EncodeOptions};
use tidepool::testing::{Frame, Shown, encode_into};
use tidepool::{Action, Controls, Damping, Event, PoolScene, PoolSettings, Scene};

/// Resident memory of this process in KiB (Linux), for the "memory stays flat" check.
fn resident_kib() -> u64 {
    let statm = std::fs::read_to_string("/proc/self/statm").unwrap_or_default();
    let pages: u64 = statm.split_whitespace().nth(1).and_then(|v| v.parse().ok()).unwrap_or(0);
    pages * 4
}

#[test]
#[ignore = "a million steps: cargo test --test integration soak -- --ignored --nocapture"]
fn a_million_steps_of_heavy_weather() {
    const STEPS: u64 = 1_000_000;
    let started = std::time::Instant::now();
    let damping = Damping::from_shift(4).unwrap();
    let settings = PoolSettings { damping, rain_rate: 2.0, seed: 11, ..PoolSettings::default() };
    let (mut w, mut h) = (160u32, 94u32);
    let mut scene = PoolScene::new(w, h, settings).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    let mut frame = Frame::new(0, 0);
    let mut pixmap = tiny_skia::Pixmap::new(w, h).unwrap();
    let mut shown = Shown::UNKNOWN;
    let mut bytes = Vec::new();
    let mut baseline = None;
    let mut peak = 0;
    for step in 0..STEPS {
        // The input stream: a stone every step (big ones too), drags, and now and then the
        // keys that change the water.
        let (x, y) = (rng.random_range(-10..w as i32 + 10), rng.random_range(-10..h as i32 + 10));
        let mut actions = vec![Action::Stone { x, y, radius: rng.random_range(1..=32), big: rng.random_bool(0.1) }];
        if step % 7 == 0 {
            actions.push(Action::Stir {
                from: (x, y),
                to: (x + rng.random_range(-40..40), y + rng.random_range(-20..20)),
            });
        }
        match step % 20_011 {
            0 => actions.push(Action::ToggleRain),
            5_000 => actions.extend([Action::Damping(false); 16]), // all the way to "off"
            15_000 => actions.extend([Action::Damping(true); 12]),
            19_999 => actions.push(Action::Clear),
            _ => {}
        }
        for action in actions {
            for event in scene.resolve(action) {
                scene.apply(&event);
            }
        }
        if step % 250_003 == 250_000 {
            // A resize, as the terminal would send.
            (w, h) = if w == 160 { (97, 61) } else { (160, 94) };
            scene.apply(&Event::Resize([w, h]));
            pixmap = tiny_skia::Pixmap::new(w, h).unwrap();
            shown = Shown::UNKNOWN;
        }
        Scene::advance(&mut scene, 1);
        if step % 97 == 0 {
            frame.reset(w as usize, (h / 2 + 1) as usize);
            scene.render(&mut pixmap);
            frame.draw_pixels(&pixmap, ColorMode::TrueColor);
            bytes.clear();
            encode_into(&mut shown, &frame, EncodeOptions::default(), &mut bytes);
        }
        if step % 100_000 == 99_999 {
            let heights = scene.pool().heights();
            let busy = heights.iter().filter(|&&v| v != 0).count();
            let rss = resident_kib();
            peak = peak.max(rss);
            let base = *baseline.get_or_insert(rss);
            println!(
                "step {:>7}: {busy} moving cells of {}, damping {}, resident {rss} KiB, {:.0} s",
                step + 1,
                heights.len(),
                scene.pool().damping(),
                started.elapsed().as_secs_f64()
            );
            assert!(rss < base + 8 * 1024, "memory grew from {base} KiB to {rss} KiB");
        }
    }
    println!("{STEPS} steps in {:.0} s, peak resident {peak} KiB", started.elapsed().as_secs_f64());
}
