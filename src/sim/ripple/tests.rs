//! The ripple pool's tests: the fast paths against the plain rule, by hand and by proptest.

use super::*;

/// The rule written as plainly as possible, to check the fast paths against.
pub(crate) fn reference_step(pool: &mut RipplePool) {
    let (w, h) = (pool.width, pool.height);
    if w >= 3 && h >= 3 {
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                let i = y * w + x;
                let c = &pool.current;
                let sum = i32::from(c[i - 1]) + i32::from(c[i + 1]) + i32::from(c[i - w]) + i32::from(c[i + w]);
                let mut v = ((sum >> 1) - i32::from(pool.previous[i])).clamp(-32768, 32767);
                if let Some(s) = pool.damping.shift() {
                    v -= v >> s;
                }
                pool.previous[i] = v as i16;
            }
        }
    }
    std::mem::swap(&mut pool.current, &mut pool.previous);
    pool.recompute_row_max();
    pool.steps += 1;
}

/// A pool with deterministic pseudo-random water (including saturated cells).
fn rough_pool(width: usize, height: usize, damping: Damping, seed: u64) -> RipplePool {
    let mut pool = RipplePool::new(width, height, damping);
    let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
    for k in 0..(width * height / 40).max(3) {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let x = (state >> 33) as i32 % width.max(1) as i32;
        let y = (state >> 13) as i32 % height.max(1) as i32;
        let weight = if k % 7 == 0 { 32767 } else { ((state >> 50) % 3000) as i16 + 1 };
        pool.drop_stone(Stone { x, y, radius: 1 + (k % 5) as u32, weight });
    }
    pool
}

/// Every instruction set this CPU runs (portable, SSE4.1, AVX2, AVX-512), each against the
/// plain scalar rule, in one process: `Simd::detect` alone would test only the widest.
#[test]
fn fast_paths_match_the_plain_rule_bit_for_bit_on_every_simd_tier() {
    for simd in Simd::supported() {
        fast_paths_match_the_plain_rule(simd);
    }
}

fn fast_paths_match_the_plain_rule(simd: Simd) {
    for (w, h) in [(3, 3), (4, 7), (17, 5), (33, 40), (64, 64), (130, 97), (300, 520)] {
        for damping in
            [Damping::OFF, Damping::from_shift(1).unwrap(), Damping::PAPERS, Damping::from_shift(15).unwrap()]
        {
            let mut fast = rough_pool(w, h, damping, (w * h) as u64);
            fast.set_simd(simd);
            let mut slow = fast.clone();
            for steps in [1u64, 2, 3, 16, 17, 40] {
                fast.advance(steps);
                for _ in 0..steps {
                    reference_step(&mut slow);
                }
                assert_eq!(fast.heights(), slow.heights(), "{simd} {w}x{h} {damping:?} after {steps}");
                assert_eq!(fast.previous_heights(), slow.previous_heights(), "{simd} {w}x{h} {damping:?}");
                assert_eq!(fast.steps(), slow.steps());
                fast.assert_row_max_holds();
            }
        }
    }
}

#[test]
fn thread_count_does_not_change_a_bit() {
    // Large enough for several bands (the parallel path starts at 2^17 cells).
    let (w, h) = (300, 600);
    let start = rough_pool(w, h, Damping::PAPERS, 99);
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let mut water = start.clone();
        pool.install(|| water.advance(53));
        water
    };
    let one = run(1);
    let mut reference = start.clone();
    for _ in 0..53 {
        reference_step(&mut reference);
    }
    assert_eq!(one.heights(), reference.heights());
    for threads in [2, 3, 5] {
        let many = run(threads);
        assert_eq!(many.heights(), one.heights(), "{threads} threads");
        assert_eq!(many.previous_heights(), one.previous_heights(), "{threads} threads");
        many.assert_row_max_holds();
    }
}

fn pool_with(width: usize, height: usize, current: &[i16], previous: &[i16], damping: Damping) -> RipplePool {
    let mut pool = RipplePool::new(width, height, damping);
    pool.current.copy_from_slice(current);
    pool.previous.copy_from_slice(previous);
    pool.recompute_row_max();
    pool
}

impl RipplePool {
    /// After writing the buffers directly: the exact row maxima.
    fn recompute_row_max(&mut self) {
        let w = self.width;
        let max_of = |cells: &[i16], row: usize| {
            cells[row * w..(row + 1) * w].iter().map(|v| v.unsigned_abs()).max().unwrap_or(0)
        };
        for row in 0..self.height {
            self.current_max[row] = max_of(&self.current, row);
            self.previous_max[row] = max_of(&self.previous, row);
        }
    }

    /// The row maxima bound every row (the invariant the 16-bit path relies on).
    fn assert_row_max_holds(&self) {
        let w = self.width;
        for row in 0..self.height {
            for (cells, bounds, name) in
                [(&self.current, &self.current_max, "current"), (&self.previous, &self.previous_max, "previous")]
            {
                let actual = cells[row * w..(row + 1) * w].iter().map(|v| v.unsigned_abs()).max().unwrap_or(0);
                assert!(actual <= bounds[row], "{name} row {row}: |v| {actual} over its bound {}", bounds[row]);
            }
        }
    }
}

#[test]
fn step_matches_hand_computed_grid() {
    // 4x4 grid: interior cells (1,1) (2,1) (1,2) (2,2).
    #[rustfmt::skip]
    let cur = [
        0, 0, 0, 0,
        0, 10, 3, 0,
        0, -7, 0, 0,
        0, 0, 0, 0,
    ];
    #[rustfmt::skip]
    let prev = [
        0, 0, 0, 0,
        0, 2, 0, 0,
        0, 0, -5, 0,
        0, 0, 0, 0,
    ];
    let mut pool = pool_with(4, 4, &cur, &prev, Damping::OFF);
    pool.step();
    // (1,1): N0+S-7+W0+E3 = -4 >> 1 = -2; -2 - 2 = -4
    // (2,1): N0+S0+W10+E0 = 10 >> 1 = 5; 5 - 0 = 5
    // (1,2): N10+S0+W0+E0 = 10 >> 1 = 5; 5 - 0 = 5
    // (2,2): N3+S0+W-7+E0 = -4 >> 1 = -2; -2 - (-5) = 3
    #[rustfmt::skip]
    let expected = [
        0, 0, 0, 0,
        0, -4, 5, 0,
        0, 5, 3, 0,
        0, 0, 0, 0,
    ];
    assert_eq!(pool.heights(), &expected);
    assert_eq!(pool.previous_heights(), &cur);
    assert_eq!(pool.steps(), 1);
}

#[test]
fn odd_sums_round_towards_minus_infinity() {
    // Centre (2, 2) of a 5x5 pool whose only disturbance is its northern neighbour:
    // (-3 >> 1) = -2, not -1.
    let mut pool = RipplePool::new(5, 5, Damping::OFF);
    pool.current[5 + 2] = -3;
    pool.recompute_row_max();
    pool.step();
    assert_eq!(pool.heights()[2 * 5 + 2], -2);
}

#[test]
fn damping_applies_after_the_spread() {
    // Centre (2, 2) of a 5x5 pool with its west and east neighbours at 200.
    let mut cur = [0i16; 25];
    cur[2 * 5 + 1] = 200;
    cur[2 * 5 + 3] = 200;
    let prev = [0i16; 25];
    let mut pool = pool_with(5, 5, &cur, &prev, Damping::PAPERS);
    pool.step();
    // spread: 400 >> 1 = 200; damping: 200 - (200 >> 5) = 200 - 6 = 194
    assert_eq!(pool.heights()[12], 194);
    let mut negative = pool_with(5, 5, &cur.map(|v| -v), &prev, Damping::PAPERS);
    negative.step();
    // -200 - (-200 >> 5) = -200 - (-7) = -193: the papers' asymmetric rounding.
    assert_eq!(negative.heights()[12], -193);
}

#[test]
fn damping_off_keeps_energy_in_a_closed_pool() {
    let mut off = RipplePool::new(64, 64, Damping::OFF);
    let mut damped = RipplePool::new(64, 64, Damping::PAPERS);
    for pool in [&mut off, &mut damped] {
        pool.drop_stone(Stone { x: 32, y: 32, radius: 4, weight: 100 });
        for _ in 0..400 {
            pool.step();
        }
    }
    let energy = |p: &RipplePool| p.heights().iter().map(|&v| i64::from(v).abs()).sum::<i64>();
    assert!(energy(&off) > 10_000, "undamped water keeps moving: {}", energy(&off));
    assert!(energy(&damped) < energy(&off) / 20, "damped water calms down");
}

#[test]
fn damped_pool_returns_to_rest() {
    let mut pool = RipplePool::new(48, 32, Damping::PAPERS);
    pool.drop_stone(Stone { x: 20, y: 10, radius: 5, weight: 128 });
    for _ in 0..3000 {
        pool.step();
    }
    assert!(pool.heights().iter().all(|&v| v == 0));
}

#[test]
fn stone_covers_exactly_the_open_disc() {
    let mut pool = RipplePool::new(21, 21, Damping::PAPERS);
    pool.drop_stone(Stone { x: 10, y: 10, radius: 3, weight: 50 });
    for y in 0..21i32 {
        for x in 0..21i32 {
            let inside = (x - 10).pow(2) + (y - 10).pow(2) < 9;
            let v = pool.heights()[(y * 21 + x) as usize];
            assert_eq!(v, if inside { -50 } else { 0 }, "cell ({x}, {y})");
        }
    }
    // Radius 3 covers the whole 5x5 square (its corners are at 2² + 2² = 8 < 9) and nothing
    // at distance 3 (3² = 9 is not < 9).
    assert_eq!(pool.heights().iter().filter(|&&v| v != 0).count(), 25);
}

#[test]
fn radius_one_is_a_single_cell() {
    let mut pool = RipplePool::new(5, 5, Damping::PAPERS);
    pool.drop_stone(Stone { x: 2, y: 2, radius: 1, weight: 7 });
    assert_eq!(pool.heights().iter().filter(|&&v| v != 0).count(), 1);
    assert_eq!(pool.heights()[12], -7);
}

#[test]
fn stones_crossing_the_border_are_clipped_not_rejected() {
    let mut pool = RipplePool::new(16, 12, Damping::PAPERS);
    pool.drop_stone(Stone { x: 0, y: 0, radius: 4, weight: 64 });
    pool.drop_stone(Stone { x: 100, y: -100, radius: 3, weight: 64 }); // far outside: nothing
    pool.drop_stone(Stone { x: 15, y: 11, radius: 1000, weight: 9 }); // covers everything
    let (w, h) = (16, 12);
    for y in 0..h {
        for x in 0..w {
            let v = pool.heights()[y * w + x];
            let wall = x == 0 || y == 0 || x == w - 1 || y == h - 1;
            assert_eq!(v, if wall { 0 } else { -9 }, "cell ({x}, {y})");
        }
    }
}

#[test]
fn walls_stay_zero() {
    let mut pool = RipplePool::new(30, 20, Damping::OFF);
    pool.drop_stone(Stone { x: 1, y: 1, radius: 6, weight: 32767 });
    for _ in 0..200 {
        pool.step();
        let (w, h) = (30, 20);
        for x in 0..w {
            assert_eq!(pool.heights()[x], 0);
            assert_eq!(pool.heights()[(h - 1) * w + x], 0);
        }
        for y in 0..h {
            assert_eq!(pool.heights()[y * w], 0);
            assert_eq!(pool.heights()[y * w + w - 1], 0);
        }
    }
}

#[test]
fn piled_stones_saturate_instead_of_wrapping() {
    // Runs in the dev profile with overflow checks: any wrap would panic here.
    let mut pool = RipplePool::new(40, 40, Damping::OFF);
    for round in 0..50 {
        pool.drop_stone(Stone { x: 20, y: 20, radius: 6, weight: 32767 });
        pool.drop_stone(Stone { x: 20 + round % 3, y: 19, radius: 9, weight: 32767 });
        for _ in 0..7 {
            pool.step();
        }
    }
    let hit_limit = pool.heights().iter().any(|&v| v == i16::MAX || v == i16::MIN)
        || pool.previous_heights().iter().any(|&v| v == i16::MAX || v == i16::MIN);
    assert!(hit_limit, "this pile is deep enough to reach the i16 limits");
}

#[test]
fn disturbances_add_clip_to_the_interior_and_saturate() {
    let mut pool = RipplePool::new(6, 5, Damping::PAPERS);
    pool.drop_stone(Stone { x: 2, y: 2, radius: 1, weight: 10 });
    pool.disturb((-5, -5), (50, 50), |x, y| if (x, y) == (3, 3) { (i16::MAX, -7) } else { (4, -3) });
    let (w, h) = (6, 5);
    for y in 0..h {
        for x in 0..w {
            let (cur, prev) = (pool.heights()[y * w + x], pool.previous_heights()[y * w + x]);
            let wall = x == 0 || y == 0 || x == w - 1 || y == h - 1;
            let expected = match (x, y) {
                _ if wall => (0, 0),
                (2, 2) => (-6, -3),
                (3, 3) => (i16::MAX, -7),
                _ => (4, -3),
            };
            assert_eq!((cur, prev), expected, "cell ({x}, {y})");
        }
    }
    pool.assert_row_max_holds();
    // The stepper's 16-bit path relies on the row bounds: stepping stays exact.
    let mut slow = pool.clone();
    pool.advance(5);
    for _ in 0..5 {
        reference_step(&mut slow);
    }
    assert_eq!(pool.heights(), slow.heights());
}

#[test]
fn tiny_pools_are_all_wall_and_a_single_cell_still_follows_the_rule() {
    // No interior: a stone and a step change nothing, and the step still counts.
    for (w, h) in [(0, 0), (1, 1), (2, 5), (5, 2)] {
        let mut pool = RipplePool::new(w, h, Damping::PAPERS);
        pool.drop_stone(Stone { x: 1, y: 1, radius: 5, weight: 100 });
        pool.step();
        assert_eq!(pool.heights(), vec![0; w * h], "{w}x{h}");
        assert_eq!(pool.previous_heights(), vec![0; w * h], "{w}x{h}");
        assert_eq!(pool.steps(), 1, "{w}x{h}");
    }
    // 3x3: one interior cell. The stone covers only it (the wall stays zero); the step moves
    // it to the previous state (its neighbours are all wall), and the next step reflects it:
    // 0 >> 1 - (-100) = 100, damped by 100 >> 5 to 97.
    let mut pool = RipplePool::new(3, 3, Damping::PAPERS);
    pool.drop_stone(Stone { x: 1, y: 1, radius: 5, weight: 100 });
    let dent = [0, 0, 0, 0, -100, 0, 0, 0, 0];
    assert_eq!(pool.heights(), dent);
    pool.step();
    assert_eq!((pool.heights(), pool.previous_heights()), (&[0; 9][..], &dent[..]));
    pool.step();
    assert_eq!(pool.heights(), [0, 0, 0, 0, 97, 0, 0, 0, 0]);
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    fn damping() -> impl Strategy<Value = Damping> {
        prop_oneof![Just(Damping::OFF), (1u8..=15).prop_map(|s| Damping::from_shift(s).unwrap())]
    }

    fn stone(w: usize, h: usize) -> impl Strategy<Value = Stone> {
        (-20i32..w as i32 + 20, -20i32..h as i32 + 20, 1u32..40, 1i16..=i16::MAX)
            .prop_map(|(x, y, radius, weight)| Stone { x, y, radius, weight })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Any stones, any damping, any number of steps: the fast paths compute exactly
        /// the plain rule (which clamps to i16, so nothing ever wraps), and the walls stay
        /// zero. Runs with overflow checks in the dev profile.
        #[test]
        fn any_stones_match_the_plain_rule(
            (w, h, stones) in (3usize..70, 3usize..70).prop_flat_map(|(w, h)| {
                (Just(w), Just(h), proptest::collection::vec((stone(w, h), 0u64..40), 1..12))
            }),
            damping in damping(),
        ) {
            let mut fast = RipplePool::new(w, h, damping);
            let mut slow = fast.clone();
            for (stone, steps) in stones {
                fast.drop_stone(stone);
                slow.drop_stone(stone);
                fast.advance(steps);
                for _ in 0..steps {
                    reference_step(&mut slow);
                }
                prop_assert_eq!(fast.heights(), slow.heights());
                fast.assert_row_max_holds();
            }
            for x in 0..w {
                prop_assert_eq!(fast.heights()[x], 0);
                prop_assert_eq!(fast.heights()[(h - 1) * w + x], 0);
            }
            for y in 0..h {
                prop_assert_eq!(fast.heights()[y * w], 0);
                prop_assert_eq!(fast.heights()[y * w + w - 1], 0);
            }
        }

        /// A stone in the centre of a square pool keeps the pool's 8-fold symmetry
        /// exactly, damped or not: the rule, its rounding and the walls are all symmetric.
        #[test]
        fn a_centred_stone_keeps_eight_fold_symmetry(
            half in 2usize..30,
            radius in 1u32..20,
            weight in 1i16..=i16::MAX,
            steps in 0u64..120,
            damping in damping(),
        ) {
            let n = 2 * half + 1;
            let mut pool = RipplePool::new(n, n, damping);
            pool.drop_stone(Stone { x: half as i32, y: half as i32, radius, weight });
            pool.advance(steps);
            let at = |x: usize, y: usize| pool.heights()[y * n + x];
            for y in 0..n {
                for x in 0..n {
                    let v = at(x, y);
                    let (mx, my) = (n - 1 - x, n - 1 - y);
                    prop_assert_eq!(v, at(mx, y));
                    prop_assert_eq!(v, at(x, my));
                    prop_assert_eq!(v, at(y, x), "diagonal mirror at ({}, {})", x, y);
                }
            }
        }
    }
}
