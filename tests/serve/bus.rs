//! One pool across machines: real `tidepool serve --bus` processes (the edges) and a real
//! `nats-server -js` the test starts. Run by `scripts/bus_tests.sh`, which installs Debian's
//! nats-server when it is missing; without it these tests fail, saying so.
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

/// The test's ports, within the range this project's bus tests use.
const PORTS: std::ops::Range<u16> = 42000..42999;
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

/// A free loopback port in [`PORTS`], never the same twice in this process.
fn free_port() -> u16 {
    let span = PORTS.end - PORTS.start;
    let offset = (std::process::id() % u32::from(span)) as u16;
    for _ in 0..span {
        let i = NEXT_PORT.fetch_add(1, Ordering::Relaxed);
        let port = PORTS.start + (offset + i) % span;
        if TcpListener::bind(("127.0.0.1", port)).is_ok() {
            return port;
        }
    }
    panic!("no free port in {PORTS:?}");
}

/// Waits (bounded) until `ok` holds.
fn wait_until(what: &str, mut ok: impl FnMut() -> bool) {
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

    /// Stops the server (SIGTERM, as a service manager does), waits `down`, starts it again
    /// on the same port with the same data.
    pub fn restart(&mut self, down: Duration) {
        let _ = Command::new("kill").arg(self.child.id().to_string()).status();
        let _ = self.child.wait();
        std::thread::sleep(down);
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
        let shots = tempfile::tempdir().unwrap().keep();
        let mut args: Vec<&str> = WATER.to_vec();
        let shots_arg = shots.to_str().unwrap().to_owned();
        args.extend(["--bus", url, "--pool", pool, "--bus-edge", name, "--bus-shots", &shots_arg]);
        let server = Server::start(&args);
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
        let h = connect_none(edge.server.port).await;
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

fn pool_name(test: &str) -> String {
    format!("{test}-{}", std::process::id())
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
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
    nats.restart(Duration::from_millis(1500));
    pa.wait_status("bus lost", |s| s.contains("bus lost")).await;
    pa.wait_status("the bus back", |s| !s.contains("bus lost")).await;
    pb.wait_status("the bus back", |s| !s.contains("bus lost")).await;
    pa.send(&click(45, 11));
    let (after, pictures) = shoot(&pb, &[&a, &b]).await;
    assert!(after > step);
    assert_same(after, &pictures, "after the bus's restart");
}

/// CPU time (user + system, clock ticks) of a process.
fn cpu_ticks(pid: u32) -> u64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
    let fields: Vec<&str> = stat.rsplit(')').next().unwrap_or("").split_whitespace().collect();
    fields.get(11).and_then(|u| u.parse::<u64>().ok()).unwrap_or(0)
        + fields.get(12).and_then(|s| s.parse::<u64>().ok()).unwrap_or(0)
}

/// nats-server's counters (`/varz` of its monitoring port).
fn varz(port: u16) -> serde_json::Value {
    let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    s.write_all(b"GET /varz HTTP/1.0\r\n\r\n").unwrap();
    let mut body = String::new();
    s.read_to_string(&mut body).unwrap();
    serde_json::from_str(body.split("\r\n\r\n").nth(1).unwrap_or("{}")).unwrap()
}

/// The bus's figures (not a CI test): `BUS_EDGES` edges with `BUS_PLAYERS` players each for
/// `BUS_SECONDS`, every player dropping a stone every `BUS_STONE_MS`; prints the bus's
/// messages and bytes a second, the edges' CPU per player, and a key's latency from one edge's
/// player to the other edges' logs. Run with `TIDEPOOL_BUS_TRACE=1` (the edges then print when
/// they sent and took each event): scripts/bus_tests.sh load.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore]
async fn bus_load() {
    let env = |k: &str, d: u64| std::env::var(k).ok().and_then(|v| v.parse().ok()).unwrap_or(d);
    let (edges_n, players_n, seconds, stone_ms) =
        (env("BUS_EDGES", 3), env("BUS_PLAYERS", 20), env("BUS_SECONDS", 60), env("BUS_STONE_MS", 2000));
    assert!(std::env::var("TIDEPOOL_BUS_TRACE").is_ok_and(|v| v == "1"), "run with TIDEPOOL_BUS_TRACE=1");
    let (port, monitor) = (free_port(), free_port());
    let dir = tempfile::tempdir().unwrap().keep();
    let mut nats = Command::new("nats-server")
        .args(["-js", "-a", "127.0.0.1", "-p", &port.to_string(), "-m", &monitor.to_string(), "-sd"])
        .arg(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("nats-server");
    wait_until("nats-server", || TcpStream::connect(("127.0.0.1", monitor)).is_ok());
    let url = format!("nats://127.0.0.1:{port}");
    let pool = pool_name("load");
    let mut edges = Vec::new();
    for i in 0..edges_n {
        let e = Edge::start(&url, &pool, &format!("e{i}"));
        e.wait_log("joined");
        edges.push(e);
    }
    let mut players = Vec::new();
    for e in &edges {
        for _ in 0..players_n {
            players.push(Player::join(e).await);
        }
    }
    tokio::time::sleep(Duration::from_secs(3)).await;
    let cpu0: Vec<u64> = edges.iter().map(|e| cpu_ticks(e.server.child.id())).collect();
    let nats_cpu0 = cpu_ticks(nats.id());
    let v0 = varz(monitor);
    let started = Instant::now();
    let mut k = 0usize;
    while started.elapsed() < Duration::from_secs(seconds) {
        // One player at a time, round the crowd: every player a stone per `stone_ms`.
        players[k % players.len()].send(b" ");
        k += 1;
        tokio::time::sleep(Duration::from_millis(stone_ms) / players.len() as u32).await;
    }
    let wall = started.elapsed().as_secs_f64();
    let v1 = varz(monitor);
    let hz = 100.0; // USER_HZ
    let cpu: Vec<f64> =
        edges.iter().zip(&cpu0).map(|(e, c)| (cpu_ticks(e.server.child.id()) - c) as f64 / hz / wall).collect();
    let nats_cpu = (cpu_ticks(nats.id()) - nats_cpu0) as f64 / hz / wall;
    let d = |k: &str| (v1[k].as_f64().unwrap_or(0.0) - v0[k].as_f64().unwrap_or(0.0)) / wall;
    println!(
        "bus load: {edges_n} edges x {players_n} players, {wall:.0} s, {:.1} stones/s offered",
        1000.0 * players.len() as f64 / stone_ms as f64
    );
    println!(
        "nats-server: in {:.0} msgs/s {:.0} B/s, out {:.0} msgs/s {:.0} B/s, CPU {:.3} cores",
        d("in_msgs"),
        d("in_bytes"),
        d("out_msgs"),
        d("out_bytes"),
        nats_cpu
    );
    for (e, c) in edges.iter().zip(&cpu) {
        println!("edge {}: CPU {c:.3} cores, {:.2} ms of CPU per player-second", e.name, 1000.0 * c / players_n as f64);
    }
    // A key's latency: sent on one edge, taken from the log on another (same machine clock).
    let mut sent = std::collections::HashMap::new();
    for e in &edges {
        for l in e.log() {
            let w: Vec<&str> = l.split_whitespace().collect();
            if w.get(1) == Some(&"sent") {
                sent.insert((w[2].to_owned(), w[3].to_owned()), w[4].parse::<f64>().unwrap_or(0.0));
            }
        }
    }
    let (mut to_log, mut to_screen, mut sizes) = (Vec::new(), Vec::new(), Vec::new());
    for e in &edges {
        for l in e.log() {
            // bus-trace taken EDGE N at STEP for STAMP TIME BYTES
            let w: Vec<&str> = l.split_whitespace().collect();
            if w.get(1) != Some(&"taken") || w.len() < 10 {
                continue;
            }
            let Some(t0) = sent.get(&(w[2].to_owned(), w[3].to_owned())) else { continue };
            let (step, stamp, t1) = (
                w[5].parse::<f64>().unwrap_or(0.0),
                w[7].parse::<f64>().unwrap_or(0.0),
                w[8].parse::<f64>().unwrap_or(0.0),
            );
            sizes.push(w[9].parse::<f64>().unwrap_or(0.0));
            to_log.push((t1 - t0) / 1000.0);
            // The ring is drawn at the first frame (30 fps) after the edge reaches the stamp.
            to_screen.push((t1 - t0) / 1000.0 + ((stamp - step).max(0.0) / 60.0) * 1000.0 + 1000.0 / 30.0 / 2.0);
        }
    }
    for v in [&mut to_log, &mut to_screen, &mut sizes] {
        v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    }
    let pct = |v: &Vec<f64>, p: f64| v.get(((v.len() as f64 - 1.0) * p) as usize).copied().unwrap_or(f64::NAN);
    println!(
        "key -> other edge's log: n {} median {:.1} ms p95 {:.1} ms; -> its screen (modelled: + lead to the stamp + half a frame): median {:.1} ms p95 {:.1} ms",
        to_log.len(),
        pct(&to_log, 0.5),
        pct(&to_log, 0.95),
        pct(&to_screen, 0.5),
        pct(&to_screen, 0.95)
    );
    println!(
        "tick sizes with events: median {:.0} B, p95 {:.0} B, max {:.0} B",
        pct(&sizes, 0.5),
        pct(&sizes, 0.95),
        sizes.last().copied().unwrap_or(0.0)
    );
    let _ = nats.kill();
    let _ = nats.wait();
}
