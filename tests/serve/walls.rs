//! The walls a player meets while playing: authorized_keys options, the action and scene-key
//! buckets, the bandwidth for all players, and the resize rate, each through a real session.

use std::time::{Duration, Instant};

use russh::ChannelMsg;
use russh::keys::{Algorithm, PrivateKey};

use crate::common::*;

/// Connects from `source` (a loopback address of this machine) to the server's port.
async fn connect_from(source: &str, port: u16) -> russh::client::Handle<TestClient> {
    let socket = tokio::net::TcpSocket::new_v4().unwrap();
    socket.bind(format!("{source}:0").parse().unwrap()).unwrap();
    let stream = socket.connect(([127, 0, 0, 1], port).into()).await.unwrap();
    russh::client::connect_stream(client_config(2 * 1024 * 1024, 100), stream, TestClient::default()).await.unwrap()
}

#[tokio::test]
async fn from_in_authorized_keys_confines_a_key_to_its_addresses_and_restrict_takes_the_pty() {
    let keys: Vec<PrivateKey> =
        (0..4).map(|_| PrivateKey::random(&mut rand_keys::rng(), Algorithm::Ed25519).unwrap()).collect();
    let line = |k: &PrivateKey| k.public_key().to_openssh().unwrap();
    let text = format!(
        "from=\"127.0.0.2\" {}\nfrom=\"!127.0.0.1,127.0.0.0/8\" {}\nfrom=\"127.0.0.0/8\" {}\nrestrict {}\n",
        line(&keys[0]),
        line(&keys[1]),
        line(&keys[2]),
        line(&keys[3])
    );
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("authorized_keys");
    std::fs::write(&file, text).unwrap();
    let mut args = TEST_FLAGS.to_vec();
    args.extend(["--authorized-keys", file.to_str().unwrap()]);
    let s = Server::start(&args);
    let mut h = connect_from("127.0.0.1", s.port).await;
    assert!(!auth_key(&mut h, &keys[0]).await, "from=\"127.0.0.2\" refuses a client at 127.0.0.1");
    assert!(!auth_key(&mut h, &keys[1]).await, "a negated address refuses whatever else matches");
    s.wait_for_log("from= of line 1 does not admit 127.0.0.1").await;
    let mut elsewhere = connect_from("127.0.0.2", s.port).await;
    assert!(auth_key(&mut elsewhere, &keys[0]).await, "the same key from 127.0.0.2 is admitted");
    assert!(auth_key(&mut h, &keys[2]).await, "a network that holds the client admits it");
    Term::new(open_shell(&h, "xterm", 80, 24).await, 80, 24).read_until_status("1 playing").await;
    // `restrict` without `pty`: no terminal, as sshd; the game itself still starts.
    let mut r = connect_from("127.0.0.1", s.port).await;
    assert!(auth_key(&mut r, &keys[3]).await);
    let mut ch = r.channel_open_session().await.unwrap();
    ch.request_pty(true, "xterm", 80, 24, 0, 0, &[]).await.unwrap();
    assert!(matches!(reply(&mut ch).await, ChannelMsg::Failure), "restrict takes the pty away");
    ch.request_shell(true).await.unwrap();
    assert!(matches!(reply(&mut ch).await, ChannelMsg::Success));
}

/// The number in a log line just before `after` (`12 actions taken` → 12).
fn number_before(line: &str, after: &str) -> u64 {
    let before = line.split(after).next().unwrap();
    before.split_whitespace().last().unwrap().parse().unwrap_or_else(|_| panic!("no number before {after:?} in {line}"))
}

#[tokio::test]
async fn a_client_that_floods_stones_and_scene_keys_gets_its_limits_and_the_others_keep_their_frame_rate() {
    let mut args = TEST_FLAGS.to_vec();
    args.extend(["--actions-per-second", "10", "--scene-keys-per-second", "2", "--fps", "20"]);
    let s = Server::start(&args);
    let (flood, watch) = (connect_none(s.port).await, connect_none(s.port).await);
    let mut tf = Term::new(open_shell(&flood, "xterm", 80, 24).await, 80, 24);
    let mut tw = Term::new(open_shell(&watch, "xterm", 80, 24).await, 80, 24);
    tw.read_until_status("2 playing").await;
    tf.read_until_status("2 playing").await;
    // Rain (the watcher's one scene key) keeps every frame different.
    tw.ch.data(&b"r"[..]).await.unwrap();
    tw.read_frames(5).await;
    let flooding = Duration::from_secs(3);
    let started = Instant::now();
    let (mut stones, mut keys) = (0, 0);
    while started.elapsed() < flooding {
        // 50 stones and 10 scene keys (`x`: a key the scene may bind) every 50 ms: 1,000 and 200 a second.
        tf.ch.data(&[b' '; 50][..]).await.unwrap();
        tf.ch.data(&[b'x'; 10][..]).await.unwrap();
        (stones, keys) = (stones + 50, keys + 10);
        tw.read_frames(1).await;
        // The flooder reads its frames too, as an ssh client does: one that never reads (its
        // channel's window shut) is held by the server in a frame's write, and its `q` waited
        // there for the stall timeout (the test's flood then timed out on an idle machine, 3 of
        // 4 runs at c9fd94d+; a non-reading player's quit is an open defect of its own,
        // docs/terminals/right-pictures.md, Round 7).
        tf.read_frames(1).await;
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let elapsed = started.elapsed().as_secs_f64();
    tf.ch.data(&b"q"[..]).await.unwrap();
    let line = s.wait_for_log("#1 left (quit)").await;
    eprintln!("flooder: {line}; sent {stones} stones and {keys} scene keys in {elapsed:.1} s");
    let (taken, scene_taken) = (number_before(&line, " actions taken"), number_before(&line, " scene keys taken"));
    // A second's burst, then the rate (and the first frames' greeting before the flood).
    let most = |rate: f64| (rate * (elapsed + 1.0)).ceil() as u64 + 1;
    assert!(taken <= most(10.0), "stones taken {taken}: no more than the limit");
    assert!(taken as f64 >= 10.0 * elapsed * 0.8, "stones taken {taken}: the limit, not less");
    assert!(scene_taken <= most(2.0), "scene keys taken {scene_taken}: their own, lower limit");
    assert!(scene_taken >= 2, "scene keys taken {scene_taken}: some got through");
    tw.ch.data(&b"q"[..]).await.unwrap();
    let _ = read_to_close(&mut tw.ch).await;
    // Connected one after the other: the flooder is #1, the watcher #2.
    let watcher = s.wait_for_log("#2 left (quit)").await;
    let (sent, published) = (number_before(&watcher, " frames sent"), number_before(&watcher, " published"));
    eprintln!("watcher: {watcher}");
    assert!(2 * sent >= published, "the watcher kept its frame rate: {sent} frames of {published} published");
}

#[tokio::test]
async fn the_bandwidth_for_all_players_is_shared_and_not_exceeded() {
    const RATE: f64 = 20_000.0;
    let mut args = TEST_FLAGS.to_vec();
    args.extend(["--total-bandwidth", "20k", "--client-bandwidth", "unlimited"]);
    let s = Server::start(&args);
    let (a, b) = (connect_none(s.port).await, connect_none(s.port).await);
    let mut ta = Term::new(open_shell(&a, "xterm-256color", 100, 30).await, 100, 30);
    let mut tb = Term::new(open_shell(&b, "xterm-256color", 100, 30).await, 100, 30);
    ta.read_until_status("2 playing").await;
    tb.read_until_status("2 playing").await;
    ta.ch.data(&b"r"[..]).await.unwrap();
    ta.read_frames(2).await;
    let (a0, b0) = (ta.raw.len(), tb.raw.len());
    let (fa, fb) = (ta.frames, tb.frames);
    let started = Instant::now();
    while started.elapsed() < Duration::from_secs(4) {
        ta.read_frames(1).await;
        tb.read_frames(1).await;
    }
    let elapsed = started.elapsed().as_secs_f64();
    let bytes = (ta.raw.len() - a0 + tb.raw.len() - b0) as f64;
    eprintln!(
        "two players under {RATE} B/s in all: {:.0} B/s, {} and {} frames in {elapsed:.1} s",
        bytes / elapsed,
        ta.frames - fa,
        tb.frames - fb
    );
    // The rate, a second's burst, and the debt of at most a second a frame bigger than the
    // budget may leave.
    assert!(bytes <= RATE * (elapsed + 2.0), "{bytes} bytes in {elapsed:.1} s");
    assert!(bytes >= RATE * elapsed * 0.5, "the rate is used: {bytes} bytes in {elapsed:.1} s");
}

#[tokio::test]
async fn a_flood_of_window_changes_waits_for_the_resize_rate_and_the_last_size_wins() {
    let s = Server::start(TEST_FLAGS);
    let h = connect_none(s.port).await;
    let mut t = Term::new(open_shell(&h, "xterm", 80, 24).await, 80, 24);
    t.read_until_status("1 playing").await;
    // 50 new sizes a second for two seconds, while the frames are read.
    let started = Instant::now();
    for cols in 81..=180 {
        t.ch.window_change(cols, 24, 0, 0).await.unwrap();
        let until = Instant::now() + Duration::from_millis(20);
        let _ = tokio::time::timeout_at(until.into(), t.ch.wait()).await;
    }
    let elapsed = started.elapsed().as_secs_f64();
    // Read on in a terminal of the last size: it is painted whole only at that size.
    let mut t = Term::new(t.ch, 180, 24);
    t.read_until_painted().await;
    t.ch.data(&b"q"[..]).await.unwrap();
    let line = s.wait_for_log("left (quit)").await;
    eprintln!("{line}; 100 sizes sent in {elapsed:.1} s");
    let taken = number_before(&line, " new sizes");
    assert!(taken as f64 <= 4.0 * (elapsed + 1.5) + 1.0, "{taken} new sizes taken in {elapsed:.1} s");
    assert!(taken >= 2, "{taken} new sizes taken");
}
