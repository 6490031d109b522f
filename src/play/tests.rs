//! The play session with no terminal and no socket: bytes in, bytes out, time passed in.

use std::time::{Duration, Instant};

use super::*;
use crate::PoolSettings;
use crate::output::vt::TerminalModel as Vt;
use crate::scene::SceneSpec;

pub(crate) const FRAME: Duration = Duration::from_nanos(1_000_000_000 / 30);

/// The screen every test session uses: 30 fps, 60 kB/s, no probe.
pub(crate) fn screen_config() -> ScreenConfig {
    ScreenConfig {
        fps: 30,
        bandwidth: Bandwidth::Fixed(60_000),
        color: Default::default(),
        color_auto: false,
        colour_hint: false,
        encode: Default::default(),
        graphics: GraphicsRequest::Auto,
        probe: None,
        link_path: crate::play::LinkPath::Direct,
    }
}

/// The host every test session uses: a rainy, breezy pool, seed 3.
pub(crate) fn host_config() -> HostConfig {
    let pool = PoolSettings { rain_rate: 0.05, breeze: 1.0, seed: 3, ..PoolSettings::default() };
    HostConfig { scenes: vec![SceneSpec::Pool(pool)], seed: 3, record: None, screenshots: false }
}

/// Plays `script` (bytes the terminal sends, at frame numbers) for `frames` frames of a 30 fps
/// clock from `t0` on a 100x20 terminal, one turn a frame, the writer always free; returns
/// every byte the session handed out. The test harness of the canonical turn.
pub(crate) fn session(t0: Instant, script: &[(u32, &[u8])], frames: u32) -> Vec<u8> {
    let mut session = Session::new(screen_config(), host_config(), (100, 20), None, t0);
    let mut out = Transmit::default();
    for k in 0..frames {
        let now = t0 + FRAME * k;
        for (_, bytes) in script.iter().filter(|(at, _)| *at == k) {
            session.handle_bytes(bytes, now);
        }
        session.handle_resize((100, 20));
        session.handle_timeout(now).unwrap();
        while let Some(event) = session.poll_event() {
            assert!(!matches!(event, SessionEvent::Quit), "no one quits");
        }
        session.poll_transmit(now, true, &mut out).unwrap();
    }
    out.bytes
}

/// One step of a session whose pictures come from elsewhere (`tidepool serve`'s pacing).
#[cfg(feature = "serve")]
#[derive(Clone, Copy, Debug)]
pub(crate) enum Step {
    /// The terminal sends these bytes.
    Bytes(&'static [u8]),
    /// The next picture (with its scene's status) is there.
    Picture,
}

/// The instant a door whose timers count whole milliseconds from `t0` (tokio's) wakes for a
/// deadline at `t`: the next whole millisecond.
#[cfg(feature = "serve")]
fn on_the_millisecond(t0: Instant, t: Instant) -> Instant {
    let nanos = t.saturating_duration_since(t0).as_nanos().div_ceil(1_000_000);
    t0 + Duration::from_millis(u64::try_from(nanos).unwrap_or(u64::MAX))
}

/// Plays `player` paced by pictures from elsewhere: `pictures[0]` is there from `t0` on, and
/// each [`Step::Picture`] of `script` (steps at whole milliseconds from `t0`) brings the next.
/// A turn for every step and for every deadline of the driver's (woken on the millisecond, as
/// a door's timers are): the canonical turn of a door whose pictures are shared, the writer
/// always free. Returns every byte handed out (the screen's farewell last, once the person
/// quits) and the requests for the host. A deadline at a step's very millisecond would leave
/// the order to the door's scheduling: the script must not put one there (checked).
#[cfg(feature = "serve")]
pub(crate) fn pictured_session(
    t0: Instant,
    player: Player,
    scene: (u32, u32),
    pictures: &[(tiny_skia::Pixmap, SceneStatus)],
    script: &[(u64, Step)],
) -> (Vec<u8>, Vec<Request>) {
    let mut driver = Driver::new(player, Pacing::Pictures);
    let (mut out, mut requests) = (Transmit::default(), Vec::new());
    driver.start(t0, &mut out.bytes);
    let (mut shown, mut steps) = (0, script.iter().peekable());
    loop {
        let tick = driver.poll_timeout().map(|t| on_the_millisecond(t0, t));
        let step = steps.peek().map(|(at, step)| (t0 + Duration::from_millis(*at), *step));
        let now = match (tick, step) {
            (Some(tick), Some((at, _))) if tick == at => panic!("a deadline at the step at {at:?}: move the step"),
            (Some(tick), None) => tick,
            (Some(tick), Some((at, _))) if tick < at => tick,
            (_, Some((at, step))) => {
                steps.next();
                match step {
                    Step::Bytes(bytes) => _ = driver.handle_bytes(bytes, at),
                    Step::Picture => {
                        shown += 1;
                        driver.handle_picture();
                    }
                }
                at
            }
            (None, None) => panic!("the script ended before the person quit"),
        };
        let (picture, status) = &pictures[shown];
        driver.handle_timeout(now, status);
        while let Some(event) = driver.poll_event() {
            match event {
                DriverEvent::Request(request) => requests.push(request),
                DriverEvent::Layout => driver.refit(scene),
                DriverEvent::Quit => {
                    driver.player().screen.farewell(&mut out.bytes);
                    return (out.bytes, requests);
                }
            }
        }
        if driver.poll_frame(now, true) {
            driver.transmit(now, picture, status, &mut out);
        }
    }
}

/// What a 100x20 terminal shows after `bytes`.
fn shown(bytes: &[u8]) -> Vt {
    let mut vt = Vt::new(100, 20);
    vt.feed(bytes);
    vt
}

#[test]
fn the_same_script_at_the_same_times_gives_the_same_bytes() {
    let script: &[(u32, &[u8])] = &[(5, b" "), (20, b"+"), (40, b"\x1b[<0;30;8M"), (45, b"?")];
    let t0 = Instant::now();
    let first = session(t0, script, 60);
    let again = session(t0 + Duration::from_secs(7), script, 60);
    assert!(first == again, "deterministic: the clock is passed in, nothing else is read");
    let vt = shown(&first);
    assert!(vt.row_text(19).contains("stone 4"), "`+` stepped the stone: {}", vt.row_text(19));
    assert!((0..19).any(|y| vt.row_text(y).contains("tidepool keys")), "`?` opened the help");
}

#[test]
fn a_click_changes_the_water_as_the_host_applied_it() {
    let t0 = Instant::now();
    let with = session(t0, &[(10, b"\x1b[<0;30;8M")], 30);
    let without = session(t0, &[], 30);
    let (a, b) = (shown(&with), shown(&without));
    let changed =
        (0..38).flat_map(|y| (0..100).map(move |x| (x, y))).filter(|&(x, y)| a.pixel(x, y) != b.pixel(x, y)).count();
    assert!(changed > 20, "the stone's ring: {changed} pixels differ");
}
