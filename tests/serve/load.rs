//! Load: 100 players for 60 s (ignored by default; run it with
//! `cargo test --release --test serve -- --ignored --nocapture load`). Reports the server's
//! CPU, its memory per player, and each player's frames and bytes a second.

use std::time::{Duration, Instant};

use russh::ChannelMsg;

use crate::common::*;

/// Players connected.
const PLAYERS: usize = 100;
/// How long they play.
const PLAY: Duration = Duration::from_secs(60);

fn proc_stat(pid: u32) -> (u64, u64) {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap();
    let fields: Vec<&str> = stat.rsplit(')').next().unwrap().split_whitespace().collect();
    let ticks = fields[11].parse::<u64>().unwrap() + fields[12].parse::<u64>().unwrap();
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let rss_kb = status.lines().find(|l| l.starts_with("VmRSS:")).unwrap().split_whitespace().nth(1).unwrap();
    (ticks, rss_kb.parse().unwrap())
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "a minute of load; run by hand and record the figures in the README"]
async fn load_100_players_for_a_minute() {
    let s = Server::start(&["--max-clients", "128", "--max-per-address", "128", "--handshake-timeout-ms", "60000"]);
    let pid = s.child.id();
    tokio::time::sleep(Duration::from_secs(1)).await;
    let (_, rss_alone) = proc_stat(pid);
    let mut tasks = Vec::new();
    for i in 0..PLAYERS {
        let port = s.port;
        // Three terminal sizes: the server draws one picture per distinct size.
        let (cols, rows) = [(80, 24), (120, 40), (100, 30)][i % 3];
        tasks.push(tokio::spawn(async move {
            let h = connect_none(port).await;
            let mut ch = open_shell(&h, "xterm-256color", cols, rows).await;
            let until = Instant::now() + PLAY;
            let (mut frames, mut bytes, mut keys) = (0u64, 0u64, 0u64);
            let mut last_key = Instant::now();
            let start = Instant::now();
            while let Ok(Some(msg)) = tokio::time::timeout_at(until.into(), ch.wait()).await {
                if let ChannelMsg::Data { data } = msg {
                    frames += data.windows(SYNC_BEGIN.len()).filter(|w| *w == SYNC_BEGIN).count() as u64;
                    bytes += data.len() as u64;
                }
                // A stone every two seconds per player: 50 stones a second in all.
                if last_key.elapsed() >= Duration::from_secs(2) {
                    let _ = ch.data(&b" "[..]).await;
                    last_key = Instant::now();
                    keys += 1;
                }
            }
            let secs = start.elapsed().as_secs_f64();
            let _ = ch.data(&b"q"[..]).await;
            (frames as f64 / secs, bytes as f64 / secs, keys, h)
        }));
    }
    tokio::time::sleep(Duration::from_secs(5)).await;
    let (cpu0, rss0) = proc_stat(pid);
    let t0 = Instant::now();
    let mut rss_samples = vec![rss0];
    while t0.elapsed() < PLAY - Duration::from_secs(10) {
        tokio::time::sleep(Duration::from_secs(10)).await;
        rss_samples.push(proc_stat(pid).1);
    }
    let (cpu1, rss1) = proc_stat(pid);
    let clk = 100.0; // USER_HZ
    let cpu = (cpu1 - cpu0) as f64 / clk / t0.elapsed().as_secs_f64();
    let mut results = Vec::new();
    for t in tasks {
        results.push(t.await.unwrap());
    }
    let mut fps: Vec<f64> = results.iter().map(|r| r.0).collect();
    let mut bps: Vec<f64> = results.iter().map(|r| r.1).collect();
    fps.sort_by(f64::total_cmp);
    bps.sort_by(f64::total_cmp);
    let per_player_kb = (rss1 as f64 - rss_alone as f64) / PLAYERS as f64;
    println!("load: {PLAYERS} players, {:?}", PLAY);
    println!("server CPU: {:.2} cores (of 2) over {:.0} s", cpu, t0.elapsed().as_secs_f64());
    println!(
        "server RSS: {rss_alone} kB alone, samples every 10 s with players: {rss_samples:?} kB; per player {per_player_kb:.0} kB"
    );
    println!("fps per player: min {:.1}, median {:.1}, max {:.1}", fps[0], fps[PLAYERS / 2], fps[PLAYERS - 1]);
    println!("bytes/s per player: min {:.0}, median {:.0}, max {:.0}", bps[0], bps[PLAYERS / 2], bps[PLAYERS - 1]);
    println!("fps of every player: {:?}", fps.iter().map(|f| (f * 10.0).round() / 10.0).collect::<Vec<_>>());
    assert!(fps[0] > 1.0, "no player starved");
}
