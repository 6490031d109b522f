//! Load (ignored by default: measurements, not tests; run them by hand with `--release`):
//!
//! - `load_100_players_for_a_minute`: 100 players for 60 s, clients in the same process.
//! - `load_1000_players_for_five_minutes`: 1,000 players for 5 minutes. Run it alone:
//!   `ulimit -n 20000; cargo test --release --test serve -- --ignored --nocapture load_1000`
//!   (`scripts/serve_load.sh` does that and keeps the report).
//!
//! Each player is an in-process russh client that answers the terminal's questions as a text
//! terminal does (so each link finds its own rate), drops a stone every few seconds, and counts
//! the frames and bytes it receives in the measured window. The server is the real binary in
//! its own process; its CPU and memory come from `/proc`. What shares the 2 cores: the server
//! and this process (every client's decryption and bookkeeping), nothing else of ours.
//!
//! Each run asserts the figures `docs/serve/crowd.md` quotes for it (see [`Quoted`]), within
//! tolerances wide enough for a shared machine and narrow enough to catch a regression: the
//! server's CPU per player, the players' frame rates, and for the long run its memory.

use std::sync::Arc;
use std::time::{Duration, Instant};

use russh::ChannelMsg;

use crate::common::*;

fn proc_stat(pid: u32) -> (u64, u64) {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    let fields: Vec<&str> = stat.rsplit(')').next().unwrap().split_whitespace().collect();
    let ticks = fields[11].parse::<u64>().unwrap() + fields[12].parse::<u64>().unwrap();
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let rss_kb = status.lines().find(|l| l.starts_with("VmRSS:")).unwrap().split_whitespace().nth(1).unwrap();
    (ticks, rss_kb.parse().unwrap())
}

/// Open file descriptors of a process.
pub fn fds(pid: u32) -> usize {
    std::fs::read_dir(format!("/proc/{pid}/fd")).map(|d| d.count()).unwrap_or(0)
}

/// CPU ticks a second (USER_HZ).
const TICKS: f64 = 100.0;

/// What one load run is.
struct Load {
    players: usize,
    /// Terminal sizes, taken in turn.
    sizes: &'static [(u32, u32)],
    /// From the last connection to the start of the measured window.
    warm_up: Duration,
    /// The measured window.
    window: Duration,
    /// Each player drops a stone this often (staggered).
    stone_every: Duration,
    /// Connections opened at once while connecting.
    connect_batch: usize,
    server_flags: Vec<&'static str>,
    /// How often the server's memory is read in the window.
    sample_every: Duration,
}

/// The figures a run is quoted for (`docs/serve/crowd.md`), each with its tolerance.
struct Quoted {
    /// Server CPU per player at 15 fps, cores (its cost scaled to the frame rate it reached):
    /// the run fails above twice this (a busier machine slows the clients before the server).
    cores_per_player_at_15_fps: f64,
    /// The players' median frame rate: the run fails below 80 % of it.
    median_fps: f64,
    /// The server's resident memory at the end of the window, MB, when the window is long
    /// enough to say (five minutes): the run fails above 130 % of it.
    memory_at_end_mb: Option<f64>,
}

/// What one run measured.
struct Measured {
    cores_per_player_at_15_fps: f64,
    median_fps: f64,
    min_fps: f64,
    memory_at_end_mb: f64,
    cut: usize,
    /// The server's resident memory in the window: (seconds into it, kB).
    memory: Vec<(u64, u64)>,
}

impl Measured {
    /// Fails when a player was cut or starved.
    fn no_one_cut_or_starved(&self) {
        assert_eq!(self.cut, 0, "no player was cut");
        assert!(self.min_fps > 1.0, "no player starved: the slowest got {:.2} fps", self.min_fps);
    }

    /// Fails unless the server's memory from `from` seconds into the window to its end stays
    /// within `percent` of what it was at `from` (issue 31: flat within 2 % from minute 1 to
    /// 5 at 1,000 players); prints the readings either way.
    fn memory_flat(&self, from: u64, percent: f64) {
        let start = self.memory.iter().find(|(t, _)| *t >= from).expect("a reading at or after the start");
        let highest = self.memory.iter().filter(|(t, _)| *t >= from).map(|&(_, kb)| kb).max().unwrap();
        let growth = (highest as f64 - start.1 as f64) / start.1 as f64 * 100.0;
        println!(
            "memory from {} s: {} kB, at most {highest} kB after ({growth:+.2} %; flat within {percent} % asked)",
            start.0, start.1
        );
        assert!(
            growth <= percent,
            "memory grew {growth:+.2} % from {} kB at {} s to {highest} kB (flat within {percent} % asked): {:?}",
            start.1,
            start.0,
            self.memory
        );
    }

    /// Fails unless the run holds the figures it is quoted for.
    fn holds(&self, quoted: &Quoted) {
        self.no_one_cut_or_starved();
        let cores = self.cores_per_player_at_15_fps;
        let most = 2.0 * quoted.cores_per_player_at_15_fps;
        assert!(
            cores <= most,
            "server CPU {cores:.5} cores a player at 15 fps, quoted {} (at most {most:.5})",
            quoted.cores_per_player_at_15_fps
        );
        let least = 0.8 * quoted.median_fps;
        assert!(
            self.median_fps >= least,
            "median {:.1} fps, quoted {} (at least {least:.1})",
            self.median_fps,
            quoted.median_fps
        );
        if let Some(mb) = quoted.memory_at_end_mb {
            let at_most = 1.3 * mb;
            assert!(
                self.memory_at_end_mb <= at_most,
                "{:.0} MB at the end, quoted {mb} (at most {at_most:.0})",
                self.memory_at_end_mb
            );
        }
    }
}

/// What one player saw in the window.
#[derive(Clone, Copy, Debug, Default)]
struct Seen {
    frames: u64,
    bytes: u64,
    stones: u64,
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

async fn run(load: Load) -> Measured {
    let s = Server::start(&load.server_flags);
    let pid = s.child.id();
    tokio::time::sleep(Duration::from_secs(1)).await;
    let (_, rss_alone) = proc_stat(pid);
    let connected = Arc::new(tokio::sync::Semaphore::new(load.connect_batch));
    let started = Instant::now();
    // The window's start is set once everyone is in.
    let window_start = Arc::new(std::sync::OnceLock::<Instant>::new());
    let ready = Arc::new(std::sync::atomic::AtomicUsize::new(0));
    let mut tasks = Vec::new();
    for i in 0..load.players {
        let port = s.port;
        let (cols, rows) = load.sizes[i % load.sizes.len()];
        let (gate, window_start, ready) = (connected.clone(), window_start.clone(), ready.clone());
        let (stone_every, window) = (load.stone_every, load.window);
        let offset = stone_every.mul_f64(i as f64 / load.players as f64);
        tasks.push(tokio::spawn(async move {
            let permit = gate.acquire_owned().await.unwrap();
            let h = connect_none(port).await;
            let mut ch = open_shell(&h, "xterm-256color", cols, rows).await;
            drop(permit);
            ready.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            let mut seen = Seen::default();
            let mut next_stone = Instant::now() + offset;
            let mut carry = Vec::new();
            loop {
                let now = Instant::now();
                let (start, end) = match window_start.get() {
                    Some(&start) => (Some(start), Some(start + window)),
                    None => (None, None),
                };
                if end.is_some_and(|e| now >= e) {
                    break;
                }
                let wake = next_stone.min(end.unwrap_or(now + Duration::from_secs(1)));
                match tokio::time::timeout_at(wake.into(), ch.wait()).await {
                    Ok(Some(ChannelMsg::Data { data })) => {
                        // Answer the device-attributes questions, as a terminal does once it
                        // has read what came before them (a question may straddle packets).
                        carry.extend_from_slice(&data);
                        let questions = carry.windows(DA1_QUESTION.len()).filter(|w| *w == DA1_QUESTION).count();
                        let keep = carry.len().saturating_sub(DA1_QUESTION.len() - 1);
                        carry.drain(..keep);
                        for _ in 0..questions {
                            let _ = ch.data(DA1_ANSWER).await;
                        }
                        if start.is_some_and(|s| Instant::now() >= s) {
                            seen.frames += data.windows(SYNC_BEGIN.len()).filter(|w| *w == SYNC_BEGIN).count() as u64;
                            seen.bytes += data.len() as u64;
                        }
                    }
                    Ok(Some(_)) => {}
                    Ok(None) => return (seen, false, h),
                    Err(_) => {}
                }
                if Instant::now() >= next_stone {
                    let _ = ch.data(&b" "[..]).await;
                    next_stone += stone_every;
                    if start.is_some_and(|s| Instant::now() >= s) {
                        seen.stones += 1;
                    }
                }
            }
            let _ = ch.data(&b"q"[..]).await;
            (seen, true, h)
        }));
    }
    // Everyone in.
    while ready.load(std::sync::atomic::Ordering::Relaxed) < load.players {
        assert!(started.elapsed() < Duration::from_secs(600), "the players could not all connect in 10 minutes");
        tokio::time::sleep(Duration::from_millis(500)).await;
    }
    let connect_time = started.elapsed();
    tokio::time::sleep(load.warm_up).await;
    let t0 = Instant::now();
    window_start.set(t0).unwrap();
    let (cpu0, rss0) = proc_stat(pid);
    let client0 = proc_stat(std::process::id()).0;
    let mut samples = vec![(0u64, rss0)];
    let mut k = 1;
    while load.sample_every * k <= load.window {
        tokio::time::sleep_until((t0 + load.sample_every * k).into()).await;
        samples.push(((load.sample_every * k).as_secs(), proc_stat(pid).1));
        k += 1;
    }
    tokio::time::sleep_until((t0 + load.window).into()).await;
    let secs = t0.elapsed().as_secs_f64();
    let (cpu1, rss1) = proc_stat(pid);
    let client1 = proc_stat(std::process::id()).0;
    let mut results = Vec::new();
    for t in tasks {
        results.push(t.await.unwrap());
    }
    let cut = results.iter().filter(|r| !r.1).count();
    let cores = (cpu1 - cpu0) as f64 / TICKS / secs;
    let client_cores = (client1 - client0) as f64 / TICKS / secs;
    let mut fps: Vec<f64> = results.iter().map(|r| r.0.frames as f64 / secs).collect();
    let mut bps: Vec<f64> = results.iter().map(|r| r.0.bytes as f64 / secs).collect();
    fps.sort_by(f64::total_cmp);
    bps.sort_by(f64::total_cmp);
    let stones: u64 = results.iter().map(|r| r.0.stones).sum();
    let n = load.players as f64;
    let median_fps = percentile(&fps, 0.5);
    let rss_minute_1 = samples.iter().find(|(t, _)| *t >= 60).map_or(rss0, |s| s.1);
    println!("load: {} players of {:?}, a stone each every {:?}", load.players, load.sizes, load.stone_every);
    println!("server flags: {}", load.server_flags.join(" "));
    println!(
        "connecting took {:.0} s; warm-up {:?}; measured for {secs:.0} s",
        connect_time.as_secs_f64(),
        load.warm_up
    );
    println!(
        "server CPU: {cores:.2} cores; per player {:.5} cores at a median {median_fps:.1} fps: {:.5} cores per player at 15 fps",
        cores / n,
        cores / n * 15.0 / median_fps.max(0.01)
    );
    println!("client process CPU (the other user of the 2 cores): {client_cores:.2} cores");
    println!(
        "server memory: {} kB alone, {rss0} kB at the window's start, {:.0} kB per player; samples (s, kB): {samples:?}",
        rss_alone,
        (rss0 as f64 - rss_alone as f64) / n
    );
    if load.window >= Duration::from_secs(240) {
        let growth = (rss1 as f64 - rss_minute_1 as f64) / rss_minute_1 as f64 * 100.0;
        println!("memory at minute 1: {rss_minute_1} kB, at the end: {rss1} kB ({growth:+.2} %)");
    }
    println!(
        "fps per player: 5th percentile {:.1}, median {median_fps:.1}, min {:.1}, max {:.1}",
        percentile(&fps, 0.05),
        fps[0],
        fps[fps.len() - 1]
    );
    println!(
        "bytes/s per player: 5th percentile {:.0}, median {:.0}, min {:.0}, max {:.0}; all together {:.1} MB/s",
        percentile(&bps, 0.05),
        percentile(&bps, 0.5),
        bps[0],
        bps[bps.len() - 1],
        bps.iter().sum::<f64>() / 1e6
    );
    println!(
        "stones sent in the window: {stones} ({:.0} a second); players cut before the end: {cut}",
        stones as f64 / secs
    );
    let (_, log) = s.stop(15);
    if let Some(summary) = log.iter().find(|l| l.contains("stopped in")) {
        println!("{summary}");
    }
    let from_group: Vec<&String> = log.iter().filter(|l| l.contains(" left (")).collect();
    let (mut sent, mut grouped) = (0u64, 0u64);
    let (mut joined, mut overlay, mut behind, mut other) = (0u64, 0u64, 0u64, 0u64);
    let mut links = Vec::new();
    for line in &from_group {
        let number = |after: &str| -> u64 {
            let before = line.split(after).next().unwrap();
            before.split_whitespace().last().unwrap().trim_start_matches('(').parse().unwrap_or(0)
        };
        sent += number(" frames sent");
        grouped += number(" from its group");
        joined += number(" times, left it");
        overlay += number(" times for an overlay");
        behind += number(" behind");
        other += number(" for another group");
        links.push(number(" B/s; joined") as f64);
    }
    links.sort_by(f64::total_cmp);
    if !links.is_empty() {
        println!(
            "link rates found (B/s): 5th percentile {:.0}, median {:.0}, 95th {:.0}",
            percentile(&links, 0.05),
            percentile(&links, 0.5),
            percentile(&links, 0.95)
        );
    }
    println!(
        "joined a group {joined} times; left it {overlay} times for an overlay, {behind} behind, {other} for another group"
    );
    for line in from_group.iter().take(3) {
        println!("{line}");
    }
    println!(
        "frames sent {sent}, of them the group's bytes {grouped} ({:.0} %)",
        grouped as f64 / sent.max(1) as f64 * 100.0
    );
    Measured {
        cores_per_player_at_15_fps: cores / n * 15.0 / median_fps.max(0.01),
        median_fps,
        min_fps: fps[0],
        memory_at_end_mb: rss1 as f64 / 1000.0,
        cut,
        memory: samples,
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "a minute of load; run by hand: it checks the figures of docs/serve/crowd.md"]
async fn load_100_players_for_a_minute() {
    run(Load {
        players: 100,
        sizes: &[(80, 24), (120, 40), (100, 30)],
        warm_up: Duration::from_secs(5),
        window: Duration::from_secs(55),
        stone_every: Duration::from_secs(2),
        connect_batch: 100,
        server_flags: vec!["--max-clients", "128", "--max-per-address", "128", "--handshake-timeout-ms", "60000"],
        sample_every: Duration::from_secs(30),
    })
    .await
    .holds(&Quoted { cores_per_player_at_15_fps: 0.0091, median_fps: 9.3, memory_at_end_mb: None });
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "five minutes of 1,000 players; run alone by hand (scripts/serve_load.sh)"]
async fn load_1000_players_for_five_minutes() {
    let players = std::env::var("LOAD_PLAYERS").ok().and_then(|v| v.parse().ok()).unwrap_or(1000);
    let minutes = std::env::var("LOAD_MINUTES").ok().and_then(|v| v.parse().ok()).unwrap_or(5u64);
    // Each player's link: `auto` (the default: found from its own round trips) or a rate.
    let bandwidth: &'static str =
        Box::leak(std::env::var("LOAD_BANDWIDTH").unwrap_or_else(|_| "auto".into()).into_boxed_str());
    let measured = run(Load {
        players,
        sizes: &[(80, 24), (120, 40), (160, 48)],
        warm_up: Duration::from_secs(20),
        window: Duration::from_secs(60 * minutes),
        stone_every: Duration::from_secs(4),
        connect_batch: 16,
        server_flags: vec![
            "--max-clients",
            "1000",
            "--max-per-address",
            "1000",
            "--handshake-timeout-ms",
            "120000",
            "--fps",
            "15",
            "--total-bandwidth",
            "256M",
            "--client-bandwidth",
            bandwidth,
        ],
        sample_every: Duration::from_secs(30),
    })
    .await;
    // The quoted run: 1,000 players for five minutes with links found by themselves.
    if (players, minutes, bandwidth) == (1000, 5, "auto") {
        measured.holds(&Quoted { cores_per_player_at_15_fps: 0.00196, median_fps: 12.5, memory_at_end_mb: None });
    } else {
        measured.no_one_cut_or_starved();
    }
    if minutes >= 2 {
        // Issue 31: flat within 2 % from minute 1 to the end.
        measured.memory_flat(60, 2.0);
    }
}

/// The crowd's memory stays flat at a scale a CI machine affords (issue 31): 200 players of
/// three sizes for two minutes, links found by themselves, a stone each every 4 s. Players
/// slip out of their group's step and back all the while (an overlay, a missed frame, a new
/// link class); what each holds of its own meanwhile must not pile up. The server's memory is
/// read every 10 s; from 30 s into the window to its end it stays within 2 % of the reading
/// at 30 s.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "two and a half minutes of 200 players: scripts/serve_load.sh flat runs it (in release)"]
async fn load_200_players_for_two_minutes_memory_stays_flat() {
    let measured = run(Load {
        players: 200,
        sizes: &[(80, 24), (120, 40), (160, 48)],
        warm_up: Duration::from_secs(20),
        window: Duration::from_secs(120),
        stone_every: Duration::from_secs(4),
        connect_batch: 16,
        server_flags: vec![
            "--max-clients",
            "256",
            "--max-per-address",
            "256",
            "--handshake-timeout-ms",
            "120000",
            "--fps",
            "15",
            "--total-bandwidth",
            "256M",
        ],
        sample_every: Duration::from_secs(10),
    })
    .await;
    measured.no_one_cut_or_starved();
    measured.memory_flat(30, 2.0);
}

/// One short session: in, a frame, out (by `q`, by closing the channel, or by dropping the
/// connection, in turn).
async fn visit(port: u16, i: usize) {
    let h = connect_none(port).await;
    let mut ch = open_shell(&h, "xterm-256color", 80, 24).await;
    let until = Instant::now() + HANG_GUARD;
    let mut seen = Vec::new();
    while !contains(&seen, SYNC_BEGIN) && Instant::now() < until {
        match tokio::time::timeout_at(until.into(), ch.wait()).await {
            Ok(Some(ChannelMsg::Data { data })) => {
                if contains(&data, DA1_QUESTION) {
                    let _ = ch.data(DA1_ANSWER).await;
                }
                seen.extend_from_slice(&data);
            }
            Ok(Some(_)) => {}
            _ => break,
        }
    }
    match i % 3 {
        0 => {
            let _ = ch.data(&b"q"[..]).await;
            let _ = read_to_close(&mut ch).await;
        }
        1 => {
            let _ = ch.close().await;
        }
        _ => {}
    }
    let _ = h.disconnect(russh::Disconnect::ByApplication, "", "").await;
}

/// `n` sessions, `at_once` at a time.
async fn visits(port: u16, n: usize, at_once: usize, first: usize) {
    let gate = Arc::new(tokio::sync::Semaphore::new(at_once));
    let mut tasks = Vec::new();
    for i in 0..n {
        let permit = gate.clone().acquire_owned().await.unwrap();
        tasks.push(tokio::spawn(async move {
            visit(port, first + i).await;
            drop(permit);
        }));
    }
    for t in tasks {
        t.await.unwrap();
    }
}

/// Waits until the server has no connection left (its log says each one closed or ended).
async fn settle(s: &Server, connections: usize) {
    let until = Instant::now() + Duration::from_secs(120);
    loop {
        let done = s.log.lock().unwrap().iter().filter(|l| l.contains(" on the socket")).count();
        if done >= connections || Instant::now() > until {
            break;
        }
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
    // Lingering tasks (a goodbye's second) and the allocator's trim.
    tokio::time::sleep(Duration::from_secs(3)).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "10,000 sessions (a few minutes); run by hand (scripts/serve_load.sh churn)"]
async fn churn_10000_connects_and_disconnects_leave_memory_and_descriptors_where_they_were() {
    // The allocator's pools reach their working size within about 6,000 sessions of 50 at once
    // (measured: 91 MB after 500, 101.7 MB after 6,500, then within 0.1 MB for 4,000 more,
    // with glibc's default arenas or two): the first 5,000 bring them there, so what the next
    // 10,000 add is what sessions leave behind (the 5 % below is 450 bytes a session).
    const WARM: usize = 5_000;
    const VISITS: usize = 10_000;
    let s = Server::start(&["--max-clients", "256", "--max-per-address", "256", "--handshake-timeout-ms", "60000"]);
    let pid = s.child.id();
    tokio::time::sleep(Duration::from_secs(1)).await;
    let (_, rss_start) = proc_stat(pid);
    let fds_start = fds(pid);
    visits(s.port, WARM, 50, 0).await;
    settle(&s, WARM).await;
    let (_, rss_warm) = proc_stat(pid);
    let fds_warm = fds(pid);
    let started = Instant::now();
    let mut samples = Vec::new();
    for round in 0..10 {
        visits(s.port, VISITS / 10, 50, WARM + round * VISITS / 10).await;
        samples.push((WARM + (round + 1) * VISITS / 10, proc_stat(pid).1, fds(pid)));
    }
    settle(&s, WARM + VISITS).await;
    let (_, rss_end) = proc_stat(pid);
    let fds_end = fds(pid);
    println!(
        "churn: {VISITS} sessions (q, channel close, dropped connection in turn), 50 at once, in {:.0} s",
        started.elapsed().as_secs_f64()
    );
    println!(
        "server memory: {rss_start} kB at start, {rss_warm} kB after {WARM} warm-up sessions, {rss_end} kB after {VISITS} more ({:+.2} %)",
        (rss_end as f64 - rss_warm as f64) / rss_warm as f64 * 100.0
    );
    println!("server file descriptors: {fds_start} at start, {fds_warm} after the warm-up, {fds_end} at the end");
    println!("during (sessions, kB, descriptors): {samples:?}");
    let (_, log) = s.stop(15);
    if let Some(summary) = log.iter().find(|l| l.contains("stopped in")) {
        println!("{summary}");
    }
    assert_eq!(fds_end, fds_start, "every socket closed");
    assert!(rss_end as f64 <= rss_warm as f64 * 1.05, "memory where it was: {rss_warm} kB -> {rss_end} kB");
}
