//! One pool across machines: real `tidepool serve --bus` processes (the edges) and a real
//! `nats-server -js` the test starts. Ignored by the README's test command (a fresh machine has
//! no nats-server, and that command must pass there; its output lists them as ignored, naming
//! the script): `scripts/bus_tests.sh` installs Debian's nats-server when it is missing and runs
//! them, and `.ci/run` runs that script. Run without nats-server they fail, saying so.
//!
//! Pictures are compared through the edges' screenshots (`--bus-shots`): a player's `s` goes
//! through the log like a stone, so every edge saves the same step, and the same step must be
//! the same bytes everywhere.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{Shutdown, TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicU16, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use tokio::sync::mpsc;

use crate::common::*;

/// An edge's memory stays flat under players (issue 31, item 4, at CI's scale).
mod memory;
/// Requests kept until the log has them: none lost while the role moves, none applied twice.
mod requests;

/// The tests' ports: `TIDEPOOL_BUS_TEST_PORTS` (`FIRST-LAST`), the bus tests' 42000-42999 when
/// unset (the binary's own bus test reads the same).
fn ports() -> std::ops::Range<u16> {
    let range = std::env::var("TIDEPOOL_BUS_TEST_PORTS").unwrap_or_else(|_| "42000-42999".into());
    let (first, last) = range
        .split_once('-')
        .and_then(|(a, b)| Some((a.parse::<u16>().ok()?, b.parse::<u16>().ok()?)))
        .expect("TIDEPOOL_BUS_TEST_PORTS is FIRST-LAST, e.g. 42000-42999");
    first..last
}
static NEXT_PORT: AtomicU16 = AtomicU16::new(0);
/// Water that moves by itself (rain, gusts): a step's picture depends on every step before.
const WATER: &[&str] = &[
    "--rain",
    "0.05",
    "--handshake-timeout-ms",
    "5000",
    "--size",
    "120x60",
    "--max-per-address",
    "1000",
    "--max-clients",
    "1000",
];

/// A free loopback port in [`ports`], never the same twice in this process.
pub fn free_port() -> u16 {
    let range = ports();
    let span = range.end - range.start;
    let offset = (std::process::id() % u32::from(span)) as u16;
    for _ in 0..span {
        let i = NEXT_PORT.fetch_add(1, Ordering::Relaxed);
        let port = range.start + (offset + i) % span;
        if TcpListener::bind(("127.0.0.1", port)).is_ok() {
            return port;
        }
    }
    panic!("no free port in {range:?}");
}

/// Waits (bounded) until `ok` holds.
pub fn wait_until(what: &str, mut ok: impl FnMut() -> bool) {
    let until = Instant::now() + HANG_GUARD;
    while !ok() {
        assert!(Instant::now() < until, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A nats-server with JetStream on a loopback port, its data in a temporary folder.
pub struct Nats {
    child: Child,
    pub port: u16,
    dir: PathBuf,
}

impl Nats {
    pub fn start() -> Nats {
        let dir = tempfile::tempdir().unwrap().keep();
        Nats::start_at(free_port(), dir)
    }

    fn start_at(port: u16, dir: PathBuf) -> Nats {
        let child = Command::new("nats-server")
            .args(["-js", "-a", "127.0.0.1", "-p", &port.to_string(), "-sd"])
            .arg(&dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| {
                panic!("cannot run nats-server ({e}): these tests need it; run scripts/bus_tests.sh, which installs it")
            });
        wait_until("nats-server to listen", || TcpStream::connect(("127.0.0.1", port)).is_ok());
        Nats { child, port, dir }
    }

    pub fn url(&self) -> String {
        format!("nats://127.0.0.1:{}", self.port)
    }

    /// Stops the server (SIGTERM, as a service manager does); returns when it has exited.
    pub fn stop(&mut self) -> Instant {
        let _ = Command::new("kill").arg(self.child.id().to_string()).status();
        let _ = self.child.wait();
        Instant::now()
    }

    /// Starts it again on the same port with the same data, once it has been down `down`
    /// since `stopped`.
    pub fn start_again(&mut self, stopped: Instant, down: Duration) {
        std::thread::sleep(down.saturating_sub(stopped.elapsed()));
        // The old one's drop kills and reaps nothing more: it has exited.
        *self = Nats::start_at(self.port, self.dir.clone());
    }

    /// Publishes `payload` on `subject` as a plain NATS client (no tidepool in it).
    pub fn publish_raw(&self, subject: &str, payloads: &[Vec<u8>]) {
        let mut s = TcpStream::connect(("127.0.0.1", self.port)).unwrap();
        s.set_read_timeout(Some(HANG_GUARD)).unwrap();
        let mut info = String::new();
        BufReader::new(s.try_clone().unwrap()).read_line(&mut info).unwrap();
        assert!(info.starts_with("INFO"), "{info}");
        let mut out = b"CONNECT {\"verbose\":false,\"pedantic\":false}\r\n".to_vec();
        for p in payloads {
            out.extend_from_slice(format!("PUB {subject} {}\r\n", p.len()).as_bytes());
            out.extend_from_slice(p);
            out.extend_from_slice(b"\r\n");
        }
        out.extend_from_slice(b"PING\r\n");
        s.write_all(&out).unwrap();
        let mut seen = Vec::new();
        let mut buf = [0u8; 4096];
        while !contains(&seen, b"PONG") {
            let n = s.read(&mut buf).unwrap();
            assert!(n > 0, "nats-server closed: {}", String::from_utf8_lossy(&seen));
            seen.extend_from_slice(&buf[..n]);
        }
        assert!(!contains(&seen, b"-ERR"), "{}", String::from_utf8_lossy(&seen));
    }
}

impl Drop for Nats {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A TCP relay between an edge and nats-server that the test can cut and mend: the edge cut
/// off from the bus while everything else runs.
pub struct Relay {
    pub port: u16,
    cut: Arc<AtomicBool>,
    open: Arc<Mutex<Vec<TcpStream>>>,
}

impl Relay {
    pub fn start(to: u16) -> Relay {
        let port = free_port();
        let listener = TcpListener::bind(("127.0.0.1", port)).unwrap();
        listener.set_nonblocking(true).unwrap();
        let (cut, open) = (Arc::new(AtomicBool::new(false)), Arc::new(Mutex::new(Vec::new())));
        let (c, o) = (cut.clone(), open.clone());
        std::thread::spawn(move || {
            loop {
                match listener.accept() {
                    Ok((inner, _)) if !c.load(Ordering::Relaxed) => {
                        inner.set_nonblocking(false).unwrap();
                        let Ok(outer) = TcpStream::connect(("127.0.0.1", to)) else { continue };
                        o.lock().unwrap().extend([inner.try_clone().unwrap(), outer.try_clone().unwrap()]);
                        for (mut from, mut to) in
                            [(inner.try_clone().unwrap(), outer.try_clone().unwrap()), (outer, inner)]
                        {
                            std::thread::spawn(move || {
                                let _ = std::io::copy(&mut from, &mut to);
                                let _ = to.shutdown(Shutdown::Both);
                            });
                        }
                    }
                    Ok((refused, _)) => drop(refused),
                    Err(_) => std::thread::sleep(Duration::from_millis(10)),
                }
            }
        });
        Relay { port, cut, open }
    }

    pub fn url(&self) -> String {
        format!("nats://127.0.0.1:{}", self.port)
    }

    /// Cuts every connection and refuses new ones.
    pub fn cut(&self) {
        self.cut.store(true, Ordering::Relaxed);
        for s in self.open.lock().unwrap().drain(..) {
            let _ = s.shutdown(Shutdown::Both);
        }
    }

    /// Lets connections through again.
    pub fn mend(&self) {
        self.cut.store(false, Ordering::Relaxed);
    }
}

/// An edge: `tidepool serve --bus` with its screenshots in a folder of its own.
pub struct Edge {
    pub server: Server,
    pub shots: PathBuf,
    pub name: String,
}

impl Edge {
    pub fn start(url: &str, pool: &str, name: &str) -> Edge {
        Edge::start_env(url, pool, name, &[])
    }

    /// As [`Edge::start`], with `env` added to the edge's environment.
    pub fn start_env(url: &str, pool: &str, name: &str, env: &[(&str, &str)]) -> Edge {
        let shots = tempfile::tempdir().unwrap().keep();
        let mut args: Vec<&str> = WATER.to_vec();
        let shots_arg = shots.to_str().unwrap().to_owned();
        args.extend(["--bus", url, "--pool", pool, "--bus-edge", name, "--bus-shots", &shots_arg]);
        let server = Server::start_env(&args, env);
        Edge { server, shots, name: name.into() }
    }

    /// Edge "a", the pool's first: it takes the sequencer's role.
    pub fn first(url: &str, pool: &str) -> Edge {
        let a = Edge::start(url, pool, "a");
        a.wait_log("this edge is the sequencer");
        a
    }

    pub fn log_has(&self, needle: &str) -> bool {
        self.server.log.lock().unwrap().iter().any(|l| l.contains(needle))
    }

    pub fn log(&self) -> Vec<String> {
        self.server.log.lock().unwrap().clone()
    }

    pub fn count_log(&self, needle: &str) -> usize {
        self.server.log.lock().unwrap().iter().filter(|l| l.contains(needle)).count()
    }

    pub fn wait_log(&self, needle: &str) {
        wait_until(&format!("{needle:?} in {}'s log ({:?})", self.name, self.log()), || self.log_has(needle));
    }

    /// The screenshots saved so far, by step.
    pub fn shots(&self) -> Vec<(u64, Vec<u8>)> {
        shots_in(&self.shots)
    }

    /// Kills the process at once (SIGKILL: no goodbye, no lease given back).
    pub fn kill(mut self) {
        let _ = self.server.child.kill();
        let _ = self.server.child.wait();
    }
}

fn shots_in(dir: &Path) -> Vec<(u64, Vec<u8>)> {
    let mut shots: Vec<(u64, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| {
            let name = e.ok()?.file_name().into_string().ok()?;
            let step = name.strip_prefix("tidepool-pool-")?.strip_suffix(".png")?.parse().ok()?;
            Some((step, std::fs::read(dir.join(&name)).ok()?))
        })
        .collect();
    shots.sort();
    shots
}

/// A player on an edge: an SSH client with an 80x24 terminal, read all the time by a task
/// of its own (a terminal that stops reading would stall its edge's frames to it).
pub struct Player {
    keys: mpsc::UnboundedSender<Vec<u8>>,
    status: Arc<Mutex<String>>,
}

impl Player {
    pub async fn join(edge: &Edge) -> Player {
        Player::join_port(edge.server.port).await
    }

    /// As [`Player::join`], by the edge's port (for a task of its own).
    pub async fn join_port(port: u16) -> Player {
        let h = connect_none(port).await;
        let ch = open_shell(&h, "xterm-256color", 80, 24).await;
        let mut t = Term::new(ch, 80, 24);
        t.read_until_status("playing").await;
        let (keys, mut rx) = mpsc::unbounded_channel::<Vec<u8>>();
        let status = Arc::new(Mutex::new(t.status()));
        let shown = status.clone();
        tokio::spawn(async move {
            let _session = h; // lives as long as the task
            loop {
                tokio::select! {
                    k = rx.recv() => match k {
                        Some(bytes) => { let _ = t.ch.data(&bytes[..]).await; }
                        None => return,
                    },
                    _ = tokio::time::timeout(Duration::from_millis(50), t.read_frames(1)) => {
                        *shown.lock().unwrap() = t.status();
                    }
                }
            }
        });
        Player { keys, status }
    }

    pub fn send(&self, bytes: &[u8]) {
        let _ = self.keys.send(bytes.to_vec());
    }

    pub fn status(&self) -> String {
        self.status.lock().unwrap().clone()
    }

    /// Waits (bounded) until the status line satisfies `ok`.
    pub async fn wait_status(&self, what: &str, ok: impl Fn(&str) -> bool) {
        let until = Instant::now() + HANG_GUARD;
        while !ok(&self.status()) {
            assert!(Instant::now() < until, "timed out waiting for {what}; status line {:?}", self.status());
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    }
}

/// A left click at cell (col, row), 1-based.
pub fn click(col: u32, row: u32) -> Vec<u8> {
    format!("\x1b[<0;{col};{row}M\x1b[<0;{col};{row}m").into_bytes()
}

/// Presses `s` on `t` and waits until every edge of `edges` saved a new screenshot; returns
/// the step and each edge's bytes.
pub async fn shoot(p: &Player, edges: &[&Edge]) -> (u64, Vec<Vec<u8>>) {
    let before: Vec<usize> = edges.iter().map(|e| e.shots().len()).collect();
    p.send(b"s");
    let until = Instant::now() + HANG_GUARD;
    loop {
        let shots: Vec<Vec<(u64, Vec<u8>)>> = edges.iter().map(|e| e.shots()).collect();
        if shots.iter().zip(&before).all(|(s, b)| s.len() > *b) {
            // The newest step every edge has (a PNG is written whole: an atomic rename).
            let step = shots.iter().map(|s| s.last().unwrap().0).min().unwrap();
            let pictures = shots
                .iter()
                .map(|s| s.iter().find(|(k, _)| *k == step).map(|(_, b)| b.clone()).unwrap_or_default())
                .collect();
            return (step, pictures);
        }
        assert!(
            Instant::now() < until,
            "no screenshot on every edge: {:?}",
            edges.iter().map(|e| e.log()).collect::<Vec<_>>()
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

fn assert_same(step: u64, pictures: &[Vec<u8>], what: &str) {
    assert!(!pictures[0].is_empty(), "{what}: no picture at step {step}");
    for (i, p) in pictures.iter().enumerate().skip(1) {
        assert!(p == &pictures[0], "{what}: edge {i}'s picture of step {step} differs from edge 0's");
    }
}

pub fn pool_name(test: &str) -> String {
    format!("{test}-{}", std::process::id())
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "needs nats-server: scripts/bus_tests.sh installs it and runs these (.ci/run does)"]
async fn two_edges_show_the_same_step_bit_for_bit_and_a_late_edge_joins_from_a_snapshot() {
    let nats = Nats::start();
    let pool = pool_name("same");
    let a = Edge::first(&nats.url(), &pool);
    let b = Edge::start(&nats.url(), &pool, "b");
    let (pa, pb) = (Player::join(&a).await, Player::join(&b).await);
    // Both edges' players, together on the pool's count.
    pa.wait_status("2 playing", |s| s.contains("2 playing")).await;
    let (still, pictures) = shoot(&pa, &[&a, &b]).await;
    assert_same(still, &pictures, "before the stones");
    // Stones from players on both edges, clicks and random ones.
    pa.send(&click(20, 6));
    pb.send(&click(60, 15));
    pb.send(b"  ");
    a.wait_log("bus: saved");
    let (step, stones) = shoot(&pb, &[&a, &b]).await;
    assert!(step > still);
    assert_same(step, &stones, "with stones from both edges");
    assert_ne!(stones[0], pictures[0], "the stones show");
    // A third edge, started after the first snapshot (every 5 s), joins from it.
    tokio::time::sleep(Duration::from_secs(6)).await;
    let c = Edge::start(&nats.url(), &pool, "c");
    c.wait_log("joined from a snapshot");
    pb.send(&click(40, 10));
    let (step, all) = shoot(&pa, &[&a, &b, &c]).await;
    assert_same(step, &all, "with an edge that joined late");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "needs nats-server: scripts/bus_tests.sh installs it and runs these (.ci/run does)"]
async fn malformed_and_out_of_bounds_events_are_refused_and_the_others_go_on() {
    let nats = Nats::start();
    let pool = pool_name("wall");
    let a = Edge::first(&nats.url(), &pool);
    let b = Edge::start(&nats.url(), &pool, "b");
    let pb = Player::join(&b).await;
    let subject = format!("tidepool.{pool}.in");
    let mut hostile: Vec<Vec<u8>> = vec![
        b"not json".to_vec(),
        br#"{"edge":"x","player":1,"n":1,"what":{"stone":{"x":5000,"y":1,"radius":2,"big":false}}}"#.to_vec(),
        br#"{"edge":"x","player":1,"n":2,"what":{"stone":{"x":1,"y":1,"radius":100000,"big":false}}}"#.to_vec(),
        br#"{"edge":"x","player":1,"n":3,"what":{"random_stone":{"radius":0}}}"#.to_vec(),
        vec![b'{'; 4000],
    ];
    // And a flood of well-formed stones from one player: over the player's rate.
    for n in 0..200 {
        hostile.push(
            format!(r#"{{"edge":"x","player":1,"n":{n},"what":{{"stone":{{"x":1,"y":1,"radius":2,"big":false}}}}}}"#)
                .into_bytes(),
        );
    }
    nats.publish_raw(&subject, &hostile);
    // Each refused and logged (a flood summed up once a second).
    for why in ["malformed", "outside", "over a rate", "bytes, at most"] {
        wait_until(&format!("a refusal for {why:?}: {:?}", a.log()), || {
            a.log().iter().any(|l| l.contains("refused") && l.contains(why))
        });
    }
    // A tick written straight into the log (not by the sequencer) is skipped by every edge
    // alike, and the sequencer, fenced out by it, takes its role back.
    nats.publish_raw(&format!("tidepool.{pool}.log"), &[b"{\"step\":\"no\"}".to_vec()]);
    b.wait_log("skipped (every edge skips it)");
    a.wait_log("skipped (every edge skips it)");
    // Requests sent while the role changes hands are lost (never acknowledged): wait for it.
    wait_until("the sequencer back", || a.count_log("this edge is the sequencer") >= 2);
    // The others go on: stones and pictures still agree.
    pb.send(&click(30, 8));
    let (step, pictures) = shoot(&pb, &[&a, &b]).await;
    assert_same(step, &pictures, "after the hostile edge");
    // Nothing the hostile edge sent reached the log: the only entry skipped is the one written
    // straight into it.
    for edge in [&a, &b] {
        assert_eq!(edge.count_log("skipped"), 1, "{:?}", edge.log());
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "needs nats-server: scripts/bus_tests.sh installs it and runs these (.ci/run does)"]
async fn edges_killed_the_sequencer_moves_and_no_acknowledged_event_is_lost() {
    let nats = Nats::start();
    let pool = pool_name("kill");
    let a = Edge::first(&nats.url(), &pool);
    let b = Edge::start(&nats.url(), &pool, "b");
    let c = Edge::start(&nats.url(), &pool, "c");
    let (pb, _pc) = (Player::join(&b).await, Player::join(&c).await);
    // An edge that is not the sequencer is killed: the others go on.
    c.kill();
    pb.send(&click(10, 5));
    let (_, alone) = shoot(&pb, &[&a, &b]).await;
    assert!(!alone[0].is_empty());
    // Stones the sequencer acknowledged (they reached the log: the edges saw their ticks).
    pb.send(&click(50, 12));
    pb.send(&click(55, 14));
    let (before, pictures) = shoot(&pb, &[&a, &b]).await;
    assert_same(before, &pictures, "before the sequencer dies");
    // The sequencer's edge is killed: b takes the role over.
    let killed = Instant::now();
    a.kill();
    b.wait_log("this edge is the sequencer");
    eprintln!("takeover: {} ms after the kill", killed.elapsed().as_millis());
    // A new edge joins after the takeover: the log and snapshot it joins from hold every
    // acknowledged stone, so its picture of a later step is b's.
    let d = Edge::start(&nats.url(), &pool, "d");
    d.wait_log("joined");
    pb.send(&click(30, 9));
    let (after, pictures) = shoot(&pb, &[&b, &d]).await;
    assert!(after > before);
    assert_same(after, &pictures, "after the takeover");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "needs nats-server: scripts/bus_tests.sh installs it and runs these (.ci/run does)"]
async fn the_bus_restarted_or_an_edge_cut_off_players_stay_told_why_and_resume_in_step() {
    let mut nats = Nats::start();
    let pool = pool_name("fault");
    let a = Edge::first(&nats.url(), &pool);
    let relay = Relay::start(nats.port);
    let b = Edge::start(&relay.url(), &pool, "b");
    let (pa, pb) = (Player::join(&a).await, Player::join(&b).await);
    pa.wait_status("2 playing", |s| s.contains("2 playing")).await;

    // b cut off from the bus: its player stays, is told, and its stones are not taken.
    relay.cut();
    pb.wait_status("bus lost", |s| s.contains("bus lost")).await;
    pb.send(b"    ");
    relay.mend();
    wait_until("b to connect again", || b.count_log("bus: connected") >= 2);
    pb.wait_status("the bus back", |s| !s.contains("bus lost")).await;
    pb.send(&click(25, 7));
    let (step, pictures) = shoot(&pa, &[&a, &b]).await;
    assert_same(step, &pictures, "after b came back");
    assert!(b.log_has("disconnected"), "{:?}", b.log());

    // nats-server restarted: both edges keep their players, say so, and resume in step.
    // (Told while it is down: an edge may be back a moment after the server.)
    let stopped = nats.stop();
    pa.wait_status("bus lost", |s| s.contains("bus lost")).await;
    pb.wait_status("bus lost", |s| s.contains("bus lost")).await;
    nats.start_again(stopped, Duration::from_millis(1500));
    pa.wait_status("the bus back", |s| !s.contains("bus lost")).await;
    pb.wait_status("the bus back", |s| !s.contains("bus lost")).await;
    pa.send(&click(45, 11));
    let (after, pictures) = shoot(&pb, &[&a, &b]).await;
    assert!(after > step);
    assert_same(after, &pictures, "after the bus's restart");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "needs nats-server: scripts/bus_tests.sh installs it and runs these (.ci/run does)"]
async fn the_sequencers_edge_cut_off_another_takes_over_and_it_stands_down_when_back() {
    let nats = Nats::start();
    let pool = pool_name("cutlead");
    let relay = Relay::start(nats.port);
    let a = Edge::first(&relay.url(), &pool);
    let b = Edge::start(&nats.url(), &pool, "b");
    let (pa, pb) = (Player::join(&a).await, Player::join(&b).await);
    pa.wait_status("2 playing", |s| s.contains("2 playing")).await;
    pb.send(&click(20, 6));
    let (step, pictures) = shoot(&pb, &[&a, &b]).await;
    assert_same(step, &pictures, "before the cut");

    // The sequencer's edge cut off: its player is told; b takes the role over, and orders
    // b's stones meanwhile.
    relay.cut();
    pa.wait_status("bus lost", |s| s.contains("bus lost")).await;
    b.wait_log("this edge is the sequencer");
    pb.send(&click(40, 10));
    // Back: a learns that b holds the role (its lease's compare-and-set, or its tick fenced
    // out of the log) and stands down; it does not write after b, and follows b's log.
    relay.mend();
    a.wait_log("no longer the sequencer");
    pa.wait_status("the bus back", |s| !s.contains("bus lost")).await;
    pa.send(&click(30, 9));
    let (after, pictures) = shoot(&pa, &[&a, &b]).await;
    assert!(after > step);
    assert_same(after, &pictures, "after a came back");
    // Exactly one sequencer after the cut: b, once; a never took the role back.
    assert_eq!(b.count_log("this edge is the sequencer"), 1, "{:?}", b.log());
    assert_eq!(a.count_log("this edge is the sequencer"), 1, "{:?}", a.log());
    assert_eq!(a.count_log("skipped"), 0, "{:?}", a.log());
}
