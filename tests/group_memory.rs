//! What a crowd's player holds of its own while it is out of its group's step (issue 31: at
//! most 0.3 MB; it was about 1 MB, its own rate encoder's and frame buffers, and a crowd's
//! memory grew by that much for every player that slipped out of step).
//!
//! Live heap bytes are counted by a counting allocator (every thread: rayon's too). Twenty
//! players of the largest common terminal (160x48) play in one group on a real pool host;
//! the heap is read with none of them, with all in step, with all out of step for an overlay
//! of their own (a message: they compose and encode their own frames), and once more in step
//! after falling behind (their frames missed, they encoded towards the group's model and
//! caught up). Each reading, less the one without them, divided by twenty, is a player's own
//! state. This binary holds a single
//! test so no other test's allocations are counted.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicIsize, Ordering};
use std::time::{Duration, Instant};

use tidepool::play::{Bandwidth, GraphicsRequest, HostConfig, LinkPath, ScreenConfig};
use tidepool::play::{ColorMode, EncodeOptions};
use tidepool::testing::{GroupKey, Groups, Host, Membership, Player, Screen, Source};
use tidepool::{PoolSettings, SceneSpec};
use tiny_skia::Pixmap;

struct Counting;

/// Bytes allocated and not freed, over every thread.
static LIVE: AtomicIsize = AtomicIsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LIVE.fetch_add(layout.size() as isize, Ordering::Relaxed);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size() as isize, Ordering::Relaxed);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LIVE.fetch_add(new_size as isize - layout.size() as isize, Ordering::Relaxed);
        // SAFETY: forwarded unchanged to the system allocator.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// The bound on an out-of-step player's own state, bytes.
const OWN_STATE_AT_MOST: isize = 300_000;
const PLAYERS: usize = 20;
/// The largest terminal of the crowd's load test.
const TERM: (u16, u16) = (160, 48);
const FRAME: Duration = Duration::from_nanos(1_000_000_000 / 15);

fn player(t0: Instant) -> Player {
    let config = ScreenConfig {
        fps: 15,
        // A link that takes a whole frame at once: members take every group frame.
        bandwidth: Bandwidth::Fixed(8_000_000),
        color: ColorMode::Palette256,
        color_auto: false,
        colour_hint: false,
        encode: EncodeOptions::default(),
        graphics: GraphicsRequest::Force(tidepool::play::GraphicsMode::Cells),
        probe: None,
        link_path: LinkPath::Direct,
    };
    let screen = Screen::new(config, TERM, t0);
    let picture = screen.picture_size();
    Player::new(screen, picture, None)
}

/// A pool host, its group and the frames they made, stepped by hand.
struct Crowd {
    t0: Instant,
    frame: u32,
    host: Host,
    picture: Pixmap,
    groups: Groups,
    key: GroupKey,
}

/// What the players did in one frame.
#[derive(Debug, Default)]
struct Sources {
    group: usize,
    own: usize,
}

impl Crowd {
    fn new(t0: Instant) -> Crowd {
        let pool = PoolSettings { rain_rate: 0.5, seed: 9, ..PoolSettings::default() };
        let config = HostConfig { scenes: vec![SceneSpec::Pool(pool)], seed: 9, record: None, screenshots: false };
        let probe = player(t0);
        let size = probe.screen.picture_size();
        let key = Membership::new().key(&probe.screen).expect("a cell screen has a group");
        let host = Host::new(config, size, t0).unwrap();
        Crowd { t0, frame: 0, host, picture: Pixmap::new(size.0, size.1).unwrap(), groups: Groups::default(), key }
    }

    /// One frame: the host steps and draws, the group encodes, the `playing` players take
    /// their frames (the others' writers are busy: they skip it).
    fn step(&mut self, players: &mut [(Player, Membership)], playing: bool) -> Sources {
        self.frame += 1;
        let now = self.t0 + FRAME * self.frame;
        if self.frame.is_multiple_of(8) {
            self.host.apply(tidepool::testing::Request::RandomStone { radius: 3 }, now);
        }
        self.host.advance(now);
        self.host.render(&mut self.picture);
        let status = self.host.status().clone();
        self.groups.keep([(self.key, None), (self.key, None)], now);
        let pictures = [(self.picture.width(), self.picture.height())]
            .into_iter()
            .map(|size| (size, std::sync::Arc::new(self.picture.clone())))
            .collect();
        self.groups.encode(&pictures, &status, now);
        let feeds = self.groups.feeds();
        let feed = feeds.get(&self.key);
        let mut sources = Sources::default();
        if !playing {
            return sources;
        }
        let mut out = Vec::new();
        for (player, membership) in players.iter_mut() {
            out.clear();
            match membership.frame(player, now, &self.picture, &status, feed, &mut out).1 {
                Source::Group => sources.group += 1,
                Source::Own => sources.own += 1,
                Source::Nothing => {}
            }
        }
        sources
    }

    fn now(&self) -> Instant {
        self.t0 + FRAME * self.frame
    }
}

fn live() -> isize {
    LIVE.load(Ordering::Relaxed)
}

#[test]
fn an_out_of_step_player_holds_at_most_0_3_mb_of_its_own() {
    rayon::broadcast(|_| ());
    let t0 = Instant::now();
    let mut crowd = Crowd::new(t0);
    // Warm-up: a player that encodes alone, in step and out, so every buffer the process
    // shares (the group's, the encoding scratch) has its working size before the count.
    let mut warm = vec![(player(t0), Membership::new())];
    for k in 0..60 {
        if k == 20 {
            warm[0].0.say("warming up".into(), crowd.now());
        }
        crowd.step(&mut warm, true);
    }
    drop(warm);
    crowd.step(&mut [], false);
    let without = live();

    let mut players: Vec<(Player, Membership)> = (0..PLAYERS).map(|_| (player(t0), Membership::new())).collect();
    let mut last = Sources::default();
    for _ in 0..30 {
        last = crowd.step(&mut players, true);
    }
    assert_eq!(last.group, PLAYERS, "all in step after a second: {last:?}");
    let in_step = (live() - without) / PLAYERS as isize;

    // An overlay of their own: each composes and encodes its frames.
    let now = crowd.now();
    players.iter_mut().for_each(|(p, _)| p.say("a message of its own".into(), now));
    for _ in 0..15 {
        last = crowd.step(&mut players, true);
    }
    assert_eq!(last.own, PLAYERS, "all out of step for their messages: {last:?}");
    let overlay = (live() - without) / PLAYERS as isize;

    // Behind: the message gone, then more frames missed than the feed holds (its last 8);
    // each encodes towards the group's model until it catches up (on this fast link, in the
    // frame it comes back), and in step again it frees its model.
    for _ in 0..60 {
        crowd.step(&mut players, true);
    }
    for _ in 0..20 {
        crowd.step(&mut players, false);
    }
    let first_back = crowd.step(&mut players, true);
    assert_eq!(first_back.own, PLAYERS, "all behind, encoding for themselves: {first_back:?}");
    let rejoined = (0..30).map(|_| crowd.step(&mut players, true)).last().unwrap();
    let after = (live() - without) / PLAYERS as isize;

    eprintln!(
        "a player's own heap at {}x{} ({PLAYERS} players, 256 colours): in step {in_step} B, out of step for an overlay {overlay} B, back in step after falling behind ({} of {PLAYERS}) {after} B",
        TERM.0, TERM.1, rejoined.group
    );
    for (what, bytes) in [("in step", in_step), ("out of step for an overlay", overlay)] {
        assert!(bytes <= OWN_STATE_AT_MOST, "{what}: {bytes} bytes of its own, at most {OWN_STATE_AT_MOST}");
    }
    assert_eq!(rejoined.group, PLAYERS, "all back in step: {rejoined:?}");
    assert!(after <= in_step + 4096, "back in step, its own state freed again: {after} B, {in_step} B before");
}
