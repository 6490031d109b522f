//! Playing: frames decode to the scene, players share one pool, requests beyond a pty and a
//! shell are refused, the authentication policy, and goodbyes.

use russh::ChannelMsg;
use russh::client::KeyboardInteractiveAuthResponse;
use russh::keys::{Algorithm, PrivateKey};

use crate::common::*;

#[tokio::test]
async fn a_pty_and_a_shell_get_frames_that_decode_to_the_pool() {
    let s = Server::start(TEST_FLAGS);
    assert!(s.first_line.starts_with("host key created: "), "{}", s.first_line);
    let h = connect_none(s.port).await;
    let mut ch = h.channel_open_session().await.unwrap();
    ch.request_pty(true, "xterm-256color", 100, 30, 0, 0, &[]).await.unwrap();
    assert!(matches!(reply(&mut ch).await, ChannelMsg::Success));
    ch.set_env(true, "COLORTERM", "truecolor").await.unwrap();
    assert!(matches!(reply(&mut ch).await, ChannelMsg::Success));
    ch.set_env(true, "LD_PRELOAD", "/tmp/x.so").await.unwrap();
    assert!(matches!(reply(&mut ch).await, ChannelMsg::Failure), "only COLORTERM is taken");
    ch.request_shell(true).await.unwrap();
    assert!(matches!(reply(&mut ch).await, ChannelMsg::Success));
    let mut t = Term::new(ch, 100, 30);
    t.read_until_status("1 playing").await;
    t.read_until_painted().await;
    assert!(contains(&t.raw, b"\x1b[?1049h"), "enters the alternate screen");
    assert!(contains(&t.raw, b"\x1b[?1006h"), "asks for SGR mouse reports");
    assert!(t.status().starts_with(" pool"), "{}", t.status());
    // 160x90 in a 100x58 picture: scale 0.625, the pool fills the width; the water is blue.
    let mut blue = 0;
    for y in 0..56 {
        for x in 0..100 {
            let p = t.screen.pixel(x, y).unwrap_or_else(|| panic!("pixel {x},{y} is not a half-block"));
            blue += usize::from(p[2] > p[0]);
        }
    }
    assert!(blue > 100 * 56 / 2, "mostly water: {blue}");
}

/// The cell of a terminal `cols x rows` showing scene pixel (x, y) of a 160x90 scene.
fn cell_of(x: f32, y: f32, cols: u32, rows: u32) -> (i32, i32) {
    let (pw, ph) = (cols as f32, (2 * (rows - 1)) as f32);
    let scale = (pw / 160.0).min(ph / 90.0);
    let (w, h) = ((160.0 * scale).round(), (90.0 * scale).round());
    let x0 = ((pw - w) / 2.0).floor();
    let y0 = (((ph - h) / 2.0).floor() as i32 & !1) as f32;
    (((x0 + (x + 0.5) * scale).floor()) as i32, ((y0 + (y + 0.5) * scale).floor() as i32) / 2)
}

/// The centre of the cells of `t` that look different from `before` (the first cells a stone
/// changed), in the pixels of a 160x90 scene shown in a `cols x rows` terminal; and how many.
fn changed_centre(t: &Term, before: &tidepool::testing::TerminalModel, cols: u32, rows: u32) -> ((f64, f64), usize) {
    let (pw, ph) = (cols as f64, (2 * (rows - 1)) as f64);
    let scale = (pw / 160.0).min(ph / 90.0);
    let (w, h) = ((160.0 * scale).round(), (90.0 * scale).round());
    let x0 = ((pw - w) / 2.0).floor();
    let y0 = (((ph - h) / 2.0).floor() as i32 & !1) as f64;
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0);
    for y in 0..rows as usize - 1 {
        for x in 0..cols as usize {
            if (2 * y..2 * y + 2).any(|py| before.pixel(x, py) != t.screen.pixel(x, py)) {
                sx += (x as f64 + 0.5 - x0) / scale;
                sy += (2.0 * y as f64 + 1.0 - y0) / scale;
                n += 1;
            }
        }
    }
    ((sx / n.max(1) as f64, sy / n.max(1) as f64), n)
}

#[tokio::test]
async fn a_stone_dropped_by_one_player_rings_at_the_same_spot_on_anothers_screen() {
    // A wide link: every frame is sent exactly and whole, so cells change only with the water.
    let mut args = TEST_FLAGS.to_vec();
    args.extend(["--client-bandwidth", "100M"]);
    let s = Server::start(&args);
    let a = connect_none(s.port).await;
    let b = connect_none(s.port).await;
    let mut ta = Term::new(open_shell(&a, "xterm", 80, 24).await, 80, 24);
    let mut tb = Term::new(open_shell(&b, "xterm-256color", 120, 40).await, 120, 40);
    ta.read_until_status("2 playing").await;
    tb.read_until_status("2 playing").await;
    ta.read_until_painted().await;
    tb.read_until_painted().await;
    // Still water and no rain: nothing changes until the stone.
    let (before_a, before_b) = (ta.screen.clone(), tb.screen.clone());
    // Player A clicks cell (30, 8): pixels (30, 16-17) of its 80x46 picture, about scene pixel
    // (61, 34).
    ta.ch.data(&b"\x1b[<0;31;9M\x1b[<0;31;9m"[..]).await.unwrap();
    let (ex, ey) = cell_of(61.0, 34.0, 120, 40);
    // The first frame in which the stone shows, on each screen (the same published picture).
    ta.read_until(|t| changed_centre(t, &before_a, 80, 24).1 >= 4).await;
    tb.read_until(|t| changed_centre(t, &before_b, 120, 40).1 >= 4).await;
    // Every changed cell of the water is near the stone: the rest of the pool is still.
    let changed =
        |t: &Term, x: usize, y: usize| (2 * y..2 * y + 2).any(|py| before_b.pixel(x, py) != t.screen.pixel(x, py));
    for y in 0..39 {
        for x in 0..120 {
            if changed(&tb, x, y) {
                let d = (x as i32 - ex).abs().max(2 * (y as i32 - ey).abs());
                assert!(d <= 24, "cell {x},{y} changed, {d} cells from the stone at {ex},{ey}");
            }
        }
    }
    // Both screens place the ring at the same scene pixels (measured: within half a pixel),
    // each mapping its cells back through its own letterbox (A's is 0 rows, B's 2). Every
    // letterbox two rows lower (the click maps through it too) puts them 1.9 pixels apart.
    let (((xa, ya), na), ((xb, yb), nb)) =
        (changed_centre(&ta, &before_a, 80, 24), changed_centre(&tb, &before_b, 120, 40));
    eprintln!(
        "the ring's centre in scene pixels: {xa:.2},{ya:.2} on A ({na} cells), {xb:.2},{yb:.2} on B ({nb} cells)"
    );
    assert!(nb >= 4, "a ring, not a dot: {nb} cells");
    assert!(
        (xa - xb).abs() <= 1.25 && (ya - yb).abs() <= 1.25,
        "A sees the ring at {xa:.2},{ya:.2}, B at {xb:.2},{yb:.2}"
    );
}

#[tokio::test]
async fn exec_sftp_x11_agent_and_forwarding_are_refused() {
    let s = Server::start(TEST_FLAGS);
    let h = connect_none(s.port).await;
    let mut ch = h.channel_open_session().await.unwrap();
    ch.exec(true, "cat /etc/passwd").await.unwrap();
    assert!(matches!(reply(&mut ch).await, ChannelMsg::Failure), "exec");
    ch.request_subsystem(true, "sftp").await.unwrap();
    assert!(matches!(reply(&mut ch).await, ChannelMsg::Failure), "sftp subsystem");
    ch.request_x11(true, false, "MIT-MAGIC-COOKIE-1", "00", 0).await.unwrap();
    assert!(matches!(reply(&mut ch).await, ChannelMsg::Failure), "x11-req");
    ch.agent_forward(true).await.unwrap();
    assert!(matches!(reply(&mut ch).await, ChannelMsg::Failure), "auth-agent-req");
    assert!(matches!(h.tcpip_forward("127.0.0.1", 0).await, Err(russh::Error::RequestDenied)), "remote forwarding");
    let direct = h.channel_open_direct_tcpip("127.0.0.1", 22, "127.0.0.1", 5555).await;
    assert!(matches!(direct, Err(russh::Error::ChannelOpenFailure(_))), "local forwarding");
    assert!(h.channel_open_session().await.is_err(), "a second session channel");
    // The refusals did not break the session: the game still starts on the same channel.
    ch.request_pty(true, "xterm", 80, 24, 0, 0, &[]).await.unwrap();
    assert!(matches!(reply(&mut ch).await, ChannelMsg::Success));
    ch.request_shell(true).await.unwrap();
    assert!(matches!(reply(&mut ch).await, ChannelMsg::Success));
    Term::new(ch, 80, 24).read_until_status("1 playing").await;
    let refused = s.log.lock().unwrap().iter().filter(|l| l.contains(" refused ")).count();
    assert!(refused >= 7, "each refusal is logged: {refused}");
}

#[tokio::test]
async fn a_public_pool_admits_none_keyboard_interactive_and_any_key_but_never_asks_a_password() {
    let s = Server::start(TEST_FLAGS);
    let (mut h, _) = connect(s.port).await;
    assert!(!h.authenticate_password("p", "hunter2").await.unwrap().success(), "password is not offered");
    assert!(h.authenticate_none("p").await.unwrap().success());
    let (mut h, _) = connect(s.port).await;
    let r = h.authenticate_keyboard_interactive_start("p", None).await.unwrap();
    assert!(matches!(r, KeyboardInteractiveAuthResponse::Success), "keyboard-interactive");
    let (mut h, _) = connect(s.port).await;
    let random = PrivateKey::random(&mut rand_keys::rng(), Algorithm::Ed25519).unwrap();
    assert!(auth_key(&mut h, &random).await, "any public key");
}

#[tokio::test]
async fn authorized_keys_admit_a_listed_key_and_refuse_another() {
    let listed = PrivateKey::random(&mut rand_keys::rng(), Algorithm::Ed25519).unwrap();
    let other = PrivateKey::random(&mut rand_keys::rng(), Algorithm::Ed25519).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("authorized_keys");
    std::fs::write(&file, format!("# players\n{} alice\n", listed.public_key().to_openssh().unwrap())).unwrap();
    let mut args = TEST_FLAGS.to_vec();
    args.extend(["--authorized-keys", file.to_str().unwrap()]);
    let s = Server::start(&args);
    let (mut h, _) = connect(s.port).await;
    assert!(!h.authenticate_none("p").await.unwrap().success(), "none is refused");
    assert!(!auth_key(&mut h, &other).await, "an unlisted key is refused");
    let r = h.authenticate_keyboard_interactive_start("p", None).await.unwrap();
    assert!(matches!(r, KeyboardInteractiveAuthResponse::Failure { .. }), "keyboard-interactive is refused");
    let (mut h, _) = connect(s.port).await;
    assert!(auth_key(&mut h, &listed).await, "the listed key is admitted");
    Term::new(open_shell(&h, "xterm", 80, 24).await, 80, 24).read_until_status("1 playing").await;
}

#[tokio::test]
async fn the_player_beyond_max_clients_is_told_the_pool_is_full_and_a_freed_place_is_taken() {
    let mut args = TEST_FLAGS.to_vec();
    args.extend(["--max-clients", "1"]);
    let s = Server::start(&args);
    let first = connect_none(s.port).await;
    let mut t1 = Term::new(open_shell(&first, "xterm", 80, 24).await, 80, 24);
    t1.read_until_status("1 playing").await;

    let second = connect_none(s.port).await;
    let mut c2 = open_shell(&second, "xterm", 80, 24).await;
    let (text, status) = read_to_close(&mut c2).await;
    assert_eq!(String::from_utf8_lossy(&text), "the pool is full, try again later\r\n");
    assert_eq!(status, Some(1));

    t1.ch.data(&b"q"[..]).await.unwrap();
    let (bye, status) = read_to_close(&mut t1.ch).await;
    assert!(contains(&bye, b"bye from the pool") && contains(&bye, b"\x1b[?1049l"), "told and restored");
    assert_eq!(status, Some(0));
    let third = connect_none(s.port).await;
    Term::new(open_shell(&third, "xterm", 80, 24).await, 80, 24).read_until_status("1 playing").await;
}

#[tokio::test]
async fn a_player_who_stops_reading_does_not_slow_another() {
    let mut args = TEST_FLAGS.to_vec();
    args.extend(["--stall-timeout-ms", "2000", "--fps", "20"]);
    let s = Server::start(&args);
    // The stalled player: a tiny window and buffer, a big terminal, and it never reads.
    let (mut stalled, _) = connect_with(s.port, client_config(4096, 2)).await;
    assert!(stalled.authenticate_none("p").await.unwrap().success());
    let _stalled_ch = open_shell(&stalled, "xterm", 200, 60).await;
    let reader = connect_none(s.port).await;
    let mut t = Term::new(open_shell(&reader, "xterm", 80, 24).await, 80, 24);
    t.read_until_status("2 playing").await;
    // Rain makes every frame differ, so every published picture is a frame worth sending.
    t.ch.data(&b"r"[..]).await.unwrap();
    t.read_frames(60).await;
    t.ch.data(&b"q"[..]).await.unwrap();
    let line = s.wait_for_log("left (quit)").await;
    let number = |after: &str| -> u64 {
        let before = line.split(after).next().unwrap();
        before.split_whitespace().last().unwrap().parse().unwrap()
    };
    let (sent, published) = (number(" frames sent"), number(" published"));
    eprintln!("{line}");
    assert!(2 * sent >= published, "the reader got most pictures: {sent} of {published}");
    let stalled_line = s.wait_for_log("left (stalled)").await;
    eprintln!("{stalled_line}");
    let _ = stalled.disconnect(russh::Disconnect::ByApplication, "", "").await;
}

#[tokio::test]
async fn sigterm_tells_every_player_restores_their_terminals_and_exits_0() {
    let s = Server::start(TEST_FLAGS);
    let a = connect_none(s.port).await;
    let b = connect_none(s.port).await;
    let mut ta = Term::new(open_shell(&a, "xterm", 80, 24).await, 80, 24);
    let mut tb = Term::new(open_shell(&b, "xterm", 80, 24).await, 80, 24);
    tb.read_until_status("2 playing").await;
    ta.read_until_status("2 playing").await;
    let _silent = tokio::net::TcpStream::connect(("127.0.0.1", s.port)).await.unwrap();
    let waiter = std::thread::spawn(move || s.stop(15));
    for t in [&mut ta, &mut tb] {
        let (text, status) = read_to_close(&mut t.ch).await;
        assert!(contains(&text, b"the pool is closing") && contains(&text, b"\x1b[?1049l"), "told and restored");
        assert_eq!(status, Some(0));
    }
    let (code, log) = waiter.join().unwrap();
    assert_eq!(code, Some(0), "{log:?}");
    let stopped = log.iter().find(|l| l.contains("stopped in")).expect("a summary line");
    eprintln!("{stopped}");
}

#[tokio::test]
async fn ctrl_c_does_the_same_with_status_130() {
    let s = Server::start(TEST_FLAGS);
    let a = connect_none(s.port).await;
    let mut ta = Term::new(open_shell(&a, "xterm", 80, 24).await, 80, 24);
    ta.read_until_status("1 playing").await;
    let waiter = std::thread::spawn(move || s.stop(2));
    let (text, _) = read_to_close(&mut ta.ch).await;
    assert!(contains(&text, b"the pool is closing"));
    assert_eq!(waiter.join().unwrap().0, Some(130));
}

/// A kitty terminal's answers to the graphics probe: the query's OK, then DA1 (no sixel).
const KITTY_ANSWERS: &[u8] = b"\x1b_Gi=31;OK\x1b\\\x1b[?62;22c";

#[tokio::test]
async fn a_remote_kitty_terminal_gets_kitty_pictures_and_a_silent_one_gets_cells() {
    let s = Server::start(TEST_FLAGS);
    let kitty = connect_none(s.port).await;
    let mut tk =
        Term::answering(open_shell(&kitty, "xterm-kitty", 100, 30).await, 100, 30, Answers::Probe(KITTY_ANSWERS));
    tk.read_until_status("kitty graphics").await;
    // The picture starts small and in parts while the link's rate is found (the ladder's lowest
    // rung), then climbs to the full size on this fast link: read until it has.
    let decoded = |t: &Term| {
        let from = tidepool::testing::SYNC_BEGIN;
        let start = t.raw.windows(from.len()).position(|w| w == from)?;
        let state = tidepool::testing::kitty_decode(&t.raw[start..]).ok()?;
        state.images.get(&tidepool::testing::KittyOptions::IMAGE_ID).cloned()
    };
    tk.read_until(|t| decoded(t).is_some_and(|i| i.width == 480)).await;
    let image = decoded(&tk).expect("the kitty image");
    // 100x30 cells of the assumed 8x16 pixels less the status row: 800x464, rendered within
    // the scene cap at 480x278; the 160x90 shared scene fills its width, 3 pixels a pixel.
    assert_eq!((image.width, image.height), (480, 278));
    let pixel = |x: u32, y: u32| {
        let i = 3 * (y * image.width + x) as usize;
        [image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]]
    };
    assert_eq!(pixel(240, 0), [8, 12, 20], "the letterbox's bar above the scene");
    let water = pixel(240, 139);
    assert!(water[2] > water[0], "water in the middle: {water:?}");
    if let Ok(dir) = std::env::var("TIDEPOOL_SHOT_DIR") {
        let path = std::path::Path::new(&dir).join("remote-kitty-player.png");
        image::save_buffer(&path, &image.rgb, image.width, image.height, image::ColorType::Rgb8).unwrap();
        eprintln!("the remote kitty player's picture: {}", path.display());
    }
    // A terminal that answers nothing gets half-block cells, and frames all the same.
    let silent = connect_none(s.port).await;
    let mut ts = Term::answering(open_shell(&silent, "xterm", 80, 24).await, 80, 24, Answers::Silent);
    ts.read_until_painted().await;
    ts.read_frames(10).await;
    assert!(!contains(&ts.raw, b"\x1b_Ga=T") && !contains(&ts.raw, b"\x1bPq"), "no picture protocol");
}

/// Reads `t` at no more than `rate` bytes a second (a slow link behind a deep buffer: the
/// client's SSH window is 2 MB, as OpenSSH's) until `done`; returns the bytes read.
async fn read_slowly(
    t: &mut Term,
    rate: f64,
    read: &mut usize,
    started: std::time::Instant,
    done: impl Fn(&Term) -> bool,
) {
    let guard = std::time::Instant::now();
    while !done(t) {
        assert!(guard.elapsed() < HANG_GUARD, "status line: {:?}", t.status());
        let before = t.raw.len();
        t.read_until(|t| t.raw.len() > before).await;
        *read += t.raw.len() - before;
        // Hold the pace: no faster than `rate` since the start.
        let due = started + std::time::Duration::from_secs_f64(*read as f64 / rate);
        tokio::time::sleep_until(due.into()).await;
    }
}

#[tokio::test]
async fn a_slow_client_gets_a_budget_of_its_own_and_no_long_backlog() {
    const RATE: f64 = 40_000.0;
    // Busy water: rain and the breeze change most cells every frame.
    let s = Server::start(&["--rain", "0.3", "--breeze", "1", "--handshake-timeout-ms", "5000"]);
    let (mut h, _) = connect_with(s.port, client_config(2 * 1024 * 1024, 100)).await;
    assert!(h.authenticate_none("slow").await.unwrap().success());
    let mut t = Term::new(open_shell(&h, "xterm-256color", 100, 30).await, 100, 30);
    let started = std::time::Instant::now();
    let mut read = 0;
    // Long enough for the rate to settle, and for the greeting to leave the status line (a
    // message covers the stone size on a 100-column line).
    let warm = started + std::time::Duration::from_secs(8);
    read_slowly(&mut t, RATE, &mut read, started, |t| {
        std::time::Instant::now() > warm && !t.status().contains("shared pool")
    })
    .await;
    let mut worst = 0;
    for (key, stone) in [(&b"+"[..], "stone 4"), (b"+", "stone 6"), (b"-", "stone 4")] {
        t.ch.data(&b" "[..]).await.unwrap();
        let at = read;
        t.ch.data(key).await.unwrap();
        read_slowly(&mut t, RATE, &mut read, started, |t| t.status().contains(stone)).await;
        // The bytes that had to be read after the key before its frame: the backlog ahead of it.
        worst = worst.max(read - at);
    }
    let rate = crate::fake_terminal::status_rate(&t.status()).expect("the status line shows the rate in effect");
    eprintln!("slow client: rate in effect {rate:.0} B/s, worst backlog {worst} bytes ({:.2} s)", worst as f64 / RATE);
    assert!(rate < 256_000.0, "below the old fixed budget: {rate}");
    assert!((worst as f64) < RATE / 2.0, "at most half a second queued: {worst} bytes at {RATE} B/s");
}
