//! The bus's figures (not a CI test): `scripts/bus_tests.sh load`. Beside `bus.rs` to keep
//! each file short; it uses that file's nats-server, edges and players.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::bus::{Edge, Player, free_port, pool_name, wait_until};

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
