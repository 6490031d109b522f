//! Gives the memory an edge freed back to the system when malloc keeps much of it: checked every
//! [`TRIM_PERIOD`], done when the arenas' free bytes exceed [`TRIM_FREE_SHARE`] of those in use.
//!
//! Why: an edge's live heap is flat (heaptrack over 150 s, 100 to 150 players: 33 to 36 MB),
//! but its resident memory grew in steps with the machine's load and stayed at each new high
//! (docs/serve/bus.md, round 6): glibc's malloc keeps what a thread freed in that thread's
//! arena for the next allocation, and an edge has more threads allocating than the single
//! machine's serve (the bus's runtime on the sequencer's thread, the log's follower, the game
//! thread, the players' workers), each with an arena of its own. `malloc_trim(0)` returns the
//! free pages of every arena (measured: 83.5 MB to 55.9 MB on an edge with 150 players).
//! Since round 8 the edge asks for one arena ([`one_arena`]): its free list stops growing, and
//! the trim still returns the free pages in it.
//!
//! Round 9: with one arena the arena's size (in use + free) did not move by 20 kB in five
//! minutes on any edge of the scale run, while a trim every 5 s made the resident size swing 2
//! to 5 %: each trim gave back the free pages of the moment (3 to 10 MB, as the bytes in use
//! moved by about 5 MB), and the next seconds' allocations touched them again. So the trim now
//! runs only when the free bytes are a large share of the live ones (players left, a burst):
//! between those, the resident size is the arena's, which does not move.
//!
//! The bound this gives: an edge's resident memory, at each check, is at most its live heap
//! (its players, the pool, the bus's bounded queues) plus [`TRIM_FREE_SHARE`] of it, plus what
//! it freed in the last [`TRIM_PERIOD`]; not the highest it ever used. A no-op where the C
//! library is not glibc (musl returns free memory by itself).

use std::time::{Duration, Instant};

/// How often the freed memory is given back (the snapshot's period). A trim walks the arenas'
/// free blocks once: the test's 63 MB of freed 4 kB blocks took 7.8 ms in the debug build (at
/// load 7), an edge frees a few MB between trims.
pub const TRIM_PERIOD: Duration = Duration::from_secs(5);

/// A trim is done when malloc's free bytes exceed this share of its bytes in use (a half: one
/// arena kept 5 to 21 % free while the players played, round 9; 48 MB free against 10 MB in use
/// once they left; the many arenas of round 6 kept 62 %).
pub const TRIM_FREE_SHARE: f64 = 0.5;

/// Whether malloc keeps enough free (`free` bytes against `used` in use) to give it back.
pub fn worth_trimming(used: usize, free: usize) -> bool {
    free as f64 > used as f64 * TRIM_FREE_SHARE
}

/// What one check found: malloc's bytes in use and free (before a trim), and how long the trim
/// took if one was done.
pub struct Check {
    pub used: usize,
    pub free: usize,
    pub trimmed: Option<Duration>,
}

/// Checks the heap every [`TRIM_PERIOD`], trims it when [`worth_trimming`].
pub struct Trim {
    next: Instant,
}

impl Trim {
    /// The first trim a period after `now`.
    pub fn new(now: Instant) -> Trim {
        Trim { next: now + TRIM_PERIOD }
    }

    /// Checks when a period has passed since the last check (and trims if it is worth it);
    /// what it found, if it checked.
    pub fn due(&mut self, now: Instant) -> Option<Check> {
        if now < self.next {
            return None;
        }
        self.next = now + TRIM_PERIOD;
        let (used, free) = held();
        // Where `held` knows nothing (not glibc), trim as before: it is a no-op there.
        let trimmed = ((used, free) == (0, 0) || worth_trimming(used, free)).then(|| {
            let started = Instant::now();
            trim();
            started.elapsed()
        });
        Some(Check { used, free, trimmed })
    }
}

/// glibc's `mallopt` parameter for the most arenas (`malloc.h`).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const M_ARENA_MAX: std::ffi::c_int = -8;

/// glibc's `struct mallinfo2` (`malloc.h`, glibc 2.33 and later): every field a `size_t`.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[repr(C)]
#[allow(dead_code)] // the C layout: every field is there, two are read
struct Mallinfo2 {
    arena: usize,
    ordblks: usize,
    smblks: usize,
    hblks: usize,
    hblkhd: usize,
    usmblks: usize,
    fsmblks: usize,
    /// Bytes in use.
    uordblks: usize,
    /// Bytes free in the arenas.
    fordblks: usize,
    keepcost: usize,
}

#[cfg(all(target_os = "linux", target_env = "gnu"))]
unsafe extern "C" {
    /// glibc's `malloc_trim(3)`: releases free memory from the top of every arena and, with
    /// `madvise`, the free pages inside them; returns 1 when it released any.
    fn malloc_trim(pad: usize) -> std::ffi::c_int;
    /// glibc's `mallopt(3)`: sets one of malloc's parameters; returns 1 on success.
    fn mallopt(param: std::ffi::c_int, value: std::ffi::c_int) -> std::ffi::c_int;
    /// glibc's `mallinfo2(3)`: what malloc holds, summed over its arenas.
    fn mallinfo2() -> Mallinfo2;
}

/// What malloc holds: bytes in use and bytes free in its arenas (glibc's `mallinfo2`; zeros
/// elsewhere). The edge's trace prints them at every trim: an RSS that moves with "in use" is
/// the edge's live data (frames in flight), one that moves with "free" is the allocator's.
pub fn held() -> (usize, usize) {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: mallinfo2 takes no pointer and returns a plain struct by value.
        let m = unsafe { mallinfo2() };
        (m.uordblks, m.fordblks)
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    (0, 0)
}

/// One malloc arena for the whole process, asked for before the edge's threads start (glibc;
/// nothing elsewhere).
///
/// Why: glibc gives each thread that allocates while another holds an arena's lock an arena of
/// its own (up to 8 a core); an edge's tokio workers, its game thread and the bus's thread
/// then each keep what was freed in them, and a block freed in one arena cannot serve another
/// thread's next allocation. Measured with `mallinfo2` (round 8): 150 players on an edge, free
/// bytes held in the arenas 28 MB and growing by about 3.6 MB over 90 s with the default
/// arenas, 0.7 to 4.2 MB with one, the players' frame rates alike. The periodic [`trim`]
/// returns free pages, not the partly used ones a scattered free list leaves behind.
pub fn one_arena() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt takes two integers; called before the runtime's threads exist.
    unsafe {
        mallopt(M_ARENA_MAX, 1);
    }
}

/// Gives the free pages of every malloc arena back to the system (glibc); nothing elsewhere.
pub fn trim() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim takes no pointer and is thread-safe (it locks each arena in turn).
    unsafe {
        malloc_trim(0);
    }
}

#[cfg(all(test, target_os = "linux", target_env = "gnu"))]
mod tests {
    use super::*;

    /// The edges of round 9's scale run while their players played (one arena: 49 to 59 MB in
    /// use, 2.6 to 10.2 MB free) are not trimmed, so their resident size stays the arena's; an
    /// edge whose players left (10 MB in use, 48 MB free) is, and so is round 6's many arenas'.
    #[test]
    fn a_trim_waits_until_the_free_bytes_are_half_those_in_use() {
        const MB: usize = 1 << 20;
        for (used, free) in [(50 * MB, 10 * MB), (56 * MB, 400 << 10), (40 * MB, 20 * MB)] {
            assert!(!worth_trimming(used, free), "{used} in use, {free} free: no trim");
        }
        for (used, free) in [(10 * MB, 48 * MB), (45 * MB, 28 * MB), (40 * MB, 21 * MB), (0, 1)] {
            assert!(worth_trimming(used, free), "{used} in use, {free} free: a trim");
        }
    }

    /// This process's resident memory in kB.
    fn rss_kb() -> u64 {
        let status = std::fs::read_to_string("/proc/self/status").unwrap();
        let line = status.lines().find(|l| l.starts_with("VmRSS:")).unwrap();
        line.split_whitespace().nth(1).unwrap().parse().unwrap()
    }

    /// A thread fills its arena with 64 MB of small blocks and frees all but every 64th (as
    /// an edge's threads free most of what a busy minute allocated), then returns what it
    /// kept; the resident memory (and what the trim gave back) in kB.
    fn freed_by_a_thread_then_trimmed() -> (u64, u64, Duration) {
        const BLOCK: usize = 4096;
        const BLOCKS: usize = (64 << 20) / BLOCK;
        let kept = std::thread::spawn(|| {
            let mut blocks: Vec<Vec<u8>> = (0..BLOCKS).map(|i| vec![i as u8 | 1; BLOCK]).collect();
            let mut kept = Vec::new();
            for (i, b) in blocks.drain(..).enumerate() {
                if i % 64 == 0 {
                    kept.push(b);
                }
            }
            kept
        })
        .join()
        .unwrap();
        let before = rss_kb();
        let mut t = Trim::new(Instant::now() - TRIM_PERIOD);
        let started = Instant::now();
        assert!(t.due(Instant::now()).is_some_and(|c| c.trimmed.is_some()), "63 MB free: worth a trim");
        let took = started.elapsed();
        assert!(t.due(Instant::now()).is_none(), "once a period");
        let after = rss_kb();
        drop(kept);
        (before, after, took)
    }

    /// The arena keeps the freed pages, so the resident memory stays up until [`trim`] gives
    /// them back: at least half of the 63 MB freed must leave. The resident memory is the
    /// whole test process's, and other tests run beside this one: a test allocating 32 MB
    /// between the two reads could hide the drop, so up to three tries are made (a trim that
    /// does nothing fails all three).
    #[test]
    fn a_trim_gives_back_what_a_thread_freed() {
        let mut tries = Vec::new();
        for _ in 0..3 {
            let (before, after, took) = freed_by_a_thread_then_trimmed();
            eprintln!("resident: {before} kB before the trim, {after} kB after, in {took:?}");
            if before.saturating_sub(after) >= 32 << 10 {
                return;
            }
            tries.push(before as i64 - after as i64);
        }
        panic!("the trim gave back {tries:?} kB of 63 MB freed, in three tries");
    }
}
