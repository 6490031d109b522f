//! The play session with no terminal and no socket: bytes in, bytes out, time passed in.

use std::time::{Duration, Instant};

use tiny_skia::Pixmap;

use super::*;
use crate::PoolSettings;
use crate::output::vt::TerminalModel as Vt;
use crate::scene::SceneSpec;

const FRAME: Duration = Duration::from_nanos(1_000_000_000 / 30);

/// Plays `script` (bytes the terminal sends, at frame numbers) for `frames` frames of a 30 fps
/// clock from `t0` on a 100x20 terminal; returns every byte the screen produced.
fn session(t0: Instant, script: &[(u32, &[u8])], frames: u32) -> Vec<u8> {
    let config = ScreenConfig {
        fps: 30,
        bandwidth: Bandwidth::Fixed(60_000),
        color: Default::default(),
        color_auto: false,
        encode: Default::default(),
        graphics: GraphicsRequest::Auto,
        probe: None,
        link_path: crate::play::LinkPath::Direct,
    };
    let mut screen = Screen::new(config, (100, 20), t0);
    let pool = PoolSettings { rain_rate: 0.05, breeze: 1.0, seed: 3, ..PoolSettings::default() };
    let host_config = HostConfig { scenes: vec![SceneSpec::Pool(pool)], seed: 3, record: None, storage: None };
    let mut host = Host::new(host_config, screen.picture_size(), t0).unwrap();
    let mut seat = Seat::new(screen.fit(host.size()));
    let mut picture = Pixmap::new(host.size().0, host.size().1).unwrap();
    let (mut inputs, mut requests, mut out) = (Vec::new(), Vec::new(), Vec::new());
    for k in 0..frames {
        let now = t0 + FRAME * k;
        for (_, bytes) in script.iter().filter(|(at, _)| *at == k) {
            screen.feed(bytes, now, &mut inputs);
        }
        screen.tick(now, &mut inputs);
        for input in inputs.drain(..) {
            assert_eq!(seat.handle(input, now, host.status(), &mut requests), Flow::Continue);
            for request in requests.drain(..) {
                host.apply(request, now);
            }
        }
        host.advance(now);
        if screen.ready(now, false) {
            host.render(&mut picture);
            let status = host.status();
            let view = seat.view(now, status);
            screen.frame(now, &picture, status, &view, &mut out).unwrap();
        }
    }
    out
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
