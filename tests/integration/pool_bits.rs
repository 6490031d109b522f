//! The pool's pictures keep their bits: frames of many pools (the player's at pixel and cell
//! size, every grid, gusts, wavelets, each look, sizes down to one pixel) hashed and compared
//! with the hashes in `tests/golden/pool_frames.txt`, on every instruction set this CPU runs
//! and on one and two threads. A faster renderer must give exactly these bytes; a change of
//! picture that is meant rewrites them (`UPDATE_GOLDEN=1`, after looking at the pictures:
//! `tests/golden/pool_player.png` is the player's pool in pixels, in `goldens.rs`).

use std::fmt::Write as _;
use std::path::Path;

use tidepool::testing::Simd;
use tidepool::{BreezeStyle, Event, PoolLook, PoolScene, PoolSettings, Refraction, Scene, Stone, Sun};

/// One pool to hash: its name, size and settings.
struct Case {
    name: &'static str,
    size: (u32, u32),
    settings: PoolSettings,
}

/// The player's pool (`play`'s defaults: two cells a pixel, 30 steps a second, gusts, rain).
pub fn player(seed: u64) -> PoolSettings {
    PoolSettings {
        rain_rate: 0.01,
        breeze: 1.0,
        breeze_style: BreezeStyle::Gusts,
        grid: 2,
        steps_per_second: 30,
        seed,
        ..PoolSettings::default()
    }
}

fn cases() -> Vec<Case> {
    let gusts = |grid: u32| PoolSettings { grid, rain_rate: 0.2, ..player(3) };
    let wavelets = PoolSettings { breeze: 1.0, rain_rate: 0.3, ..PoolSettings::default() };
    let look = |look: PoolLook| PoolSettings { look, ..gusts(2) };
    let mut cases = vec![
        Case { name: "player-pixels", size: (480, 282), settings: player(1) },
        Case { name: "player-cells", size: (160, 94), settings: player(1) },
        Case { name: "grid1-wavelets", size: (160, 94), settings: wavelets.clone() },
        Case { name: "grid1-gusts", size: (161, 93), settings: gusts(1) },
        Case { name: "grid3-gusts", size: (101, 57), settings: gusts(3) },
        Case { name: "grid4-gusts", size: (64, 40), settings: gusts(4) },
        Case { name: "grid2-wavelets", size: (120, 70), settings: PoolSettings { grid: 2, ..wavelets.clone() } },
        Case {
            name: "grid1-large",
            size: (1024, 600),
            settings: PoolSettings { rain_rate: 2.0, ..Default::default() },
        },
        Case {
            name: "no-caustics",
            size: (200, 120),
            settings: look(PoolLook { caustics: None, ..PoolLook::default() }),
        },
        Case {
            name: "no-shading",
            size: (200, 120),
            settings: look(PoolLook { shading: false, ..PoolLook::default() }),
        },
        Case {
            name: "refraction-1",
            size: (200, 120),
            settings: look(PoolLook { refraction: Refraction::fixed(1.0).unwrap(), ..PoolLook::default() }),
        },
        Case {
            name: "refraction-1-grid1",
            size: (200, 120),
            settings: PoolSettings {
                look: PoolLook { refraction: Refraction::fixed(1.0).unwrap(), ..PoolLook::default() },
                ..gusts(1)
            },
        },
        Case {
            name: "refraction-0",
            size: (200, 120),
            settings: look(PoolLook { refraction: Refraction::fixed(0.0).unwrap(), ..PoolLook::default() }),
        },
        Case {
            name: "low-sun-bare",
            size: (200, 120),
            settings: look(PoolLook {
                sun: Sun::new(100.0, 30.0).unwrap(),
                shading: false,
                caustics: None,
                refraction: Refraction::fixed(2.5).unwrap(),
            }),
        },
        Case { name: "still-water", size: (90, 50), settings: PoolSettings { grid: 2, ..Default::default() } },
    ];
    for (w, h) in [(1, 1), (2, 3), (3, 2), (5, 4), (7, 6)] {
        for grid in [1, 2] {
            let name: &'static str = format!("tiny-{w}x{h}-grid{grid}").leak();
            cases.push(Case { name, size: (w, h), settings: gusts(grid) });
        }
    }
    cases
}

/// FNV-1a, 64 bits.
fn fnv(hash: &mut u64, bytes: &[u8]) {
    for &b in bytes {
        *hash ^= u64::from(b);
        *hash = hash.wrapping_mul(0x0000_0100_0000_01b3);
    }
}

/// The hash of three frames of `case` (stones dropped between them) and of its heightmap.
fn hash(case: &Case, simd: Simd) -> u64 {
    let (w, h) = case.size;
    let mut scene = PoolScene::new(w, h, case.settings.clone()).expect("a test-sized pool");
    scene.set_simd(simd);
    let mut hash = 0xcbf2_9ce4_8422_2325;
    for (k, steps) in [(0u32, 20u64), (1, 45), (2, 61)] {
        let stone = Stone::clamped((k * 7919 % w) as i32, (k * 104_729 % h) as i32, 4, 200);
        scene.apply(&Event::Stone(stone));
        Scene::advance(&mut scene, steps);
        fnv(&mut hash, scene.snapshot().expect("a picture").data());
    }
    for v in scene.heightmap().values {
        fnv(&mut hash, &v.to_le_bytes());
    }
    hash
}

fn reference() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/pool_frames.txt")
}

#[test]
fn pool_frames_keep_their_bits_on_every_tier_and_thread_count() {
    let cases = cases();
    let mut table = String::new();
    for case in &cases {
        let portable = hash(case, Simd::PORTABLE);
        writeln!(table, "{} {portable:016x}", case.name).unwrap();
        // Each tier once (the portable one again, on one thread), on 1, 2 and 3 threads in
        // turn. A thread count changes how rows are split, the same on every tier, so the
        // rotation meets each split and each tier; every pair took twice as long (9 frames a
        // case instead of 5, 25 s of CI's integration tests).
        for (i, simd) in Simd::supported().into_iter().enumerate() {
            let threads = 1 + i % 3;
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let got = pool.install(|| hash(case, simd));
            assert_eq!(got, portable, "{}: {simd} on {threads} threads differs from portable", case.name);
        }
    }
    if std::env::var_os("UPDATE_GOLDEN").is_some_and(|v| !v.is_empty() && v != "0") {
        std::fs::write(reference(), &table).unwrap();
        panic!("UPDATE_GOLDEN: wrote {}; look at the pictures, then run without UPDATE_GOLDEN", reference().display());
    }
    let expected = std::fs::read_to_string(reference())
        .unwrap_or_else(|e| panic!("cannot read {}: {e}; create it with UPDATE_GOLDEN=1", reference().display()));
    let differ: Vec<String> = table
        .lines()
        .zip(expected.lines())
        .filter(|(a, b)| a != b)
        .map(|(a, b)| format!("{a} (reference: {b})"))
        .collect();
    assert_eq!(table.lines().count(), expected.lines().count(), "the cases and the reference's lines");
    assert!(differ.is_empty(), "pictures changed: {}", differ.join("; "));
}
