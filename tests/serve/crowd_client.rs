//! A crowd of players as a process of its own (not a CI test): `scripts/bus_scale.sh` starts
//! one per edge, so the players' SSH work is not in the edges' processes nor in one another's.
//!
//! `CROWD_PORT` (the server), `CROWD_PLAYERS`, `CROWD_SECONDS` (the measured window, after
//! everyone is in and `CROWD_WARM_UP` seconds more), `CROWD_STONE_MS` (each player drops a
//! stone this often, staggered), `CROWD_COLS`x`CROWD_ROWS`. Each player is an in-process russh
//! client that answers the terminal's questions as a text terminal does. Prints one line of
//! figures at the end (`crowd:`), which the script reads.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use russh::ChannelMsg;

use crate::common::*;

fn env(key: &str, default: u64) -> u64 {
    std::env::var(key).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 1)]
#[ignore = "a load client, not a test: scripts/bus_scale.sh runs it, one process per edge"]
async fn crowd_client() {
    let port = env("CROWD_PORT", 0) as u16;
    assert!(port != 0, "set CROWD_PORT to the server's port");
    let players = env("CROWD_PLAYERS", 100) as usize;
    let window = Duration::from_secs(env("CROWD_SECONDS", 60));
    let warm_up = Duration::from_secs(env("CROWD_WARM_UP", 10));
    let stone_every = Duration::from_millis(env("CROWD_STONE_MS", 4000));
    let size = (env("CROWD_COLS", 80) as u32, env("CROWD_ROWS", 24) as u32);
    let gate = Arc::new(tokio::sync::Semaphore::new(16));
    let ready = Arc::new(AtomicUsize::new(0));
    let start = Arc::new(std::sync::OnceLock::<Instant>::new());
    let started = Instant::now();
    let mut tasks = Vec::new();
    for i in 0..players {
        let (gate, ready, start) = (gate.clone(), ready.clone(), start.clone());
        let offset = stone_every.mul_f64(i as f64 / players as f64);
        tasks.push(tokio::spawn(async move {
            let permit = gate.acquire_owned().await.unwrap();
            let h = connect_none(port).await;
            let mut ch = open_shell(&h, "xterm-256color", size.0, size.1).await;
            drop(permit);
            ready.fetch_add(1, Ordering::Relaxed);
            let (mut frames, mut bytes) = (0u64, 0u64);
            let mut next_stone = Instant::now() + offset;
            let mut carry = Vec::new();
            loop {
                let now = Instant::now();
                let window_start = start.get().copied();
                if window_start.is_some_and(|s| now >= s + window) {
                    break;
                }
                let wake = next_stone.min(window_start.map_or(now + Duration::from_secs(1), |s| s + window));
                match tokio::time::timeout_at(wake.into(), ch.wait()).await {
                    Ok(Some(ChannelMsg::Data { data })) => {
                        carry.extend_from_slice(&data);
                        let questions = carry.windows(DA1_QUESTION.len()).filter(|w| *w == DA1_QUESTION).count();
                        carry.drain(..carry.len().saturating_sub(DA1_QUESTION.len() - 1));
                        for _ in 0..questions {
                            let _ = ch.data(DA1_ANSWER).await;
                        }
                        if window_start.is_some_and(|s| Instant::now() >= s) {
                            frames += data.windows(SYNC_BEGIN.len()).filter(|w| *w == SYNC_BEGIN).count() as u64;
                            bytes += data.len() as u64;
                        }
                    }
                    Ok(Some(_)) | Err(_) => {}
                    Ok(None) => return (frames, bytes, false),
                }
                if Instant::now() >= next_stone {
                    let _ = ch.data(&b" "[..]).await;
                    next_stone += stone_every;
                }
            }
            let _ = ch.data(&b"q"[..]).await;
            (frames, bytes, true)
        }));
    }
    while ready.load(Ordering::Relaxed) < players {
        assert!(started.elapsed() < Duration::from_secs(900), "the players could not all connect in 15 minutes");
        tokio::time::sleep(Duration::from_millis(250)).await;
    }
    let connecting = started.elapsed();
    tokio::time::sleep(warm_up).await;
    let t0 = Instant::now();
    start.set(t0).unwrap();
    eprintln!("crowd: all {players} in after {:.0} s; window starts", connecting.as_secs_f64());
    let mut results = Vec::new();
    for t in tasks {
        results.push(t.await.unwrap());
    }
    let secs = window.as_secs_f64();
    let mut fps: Vec<f64> = results.iter().map(|r| r.0 as f64 / secs).collect();
    fps.sort_by(f64::total_cmp);
    let at = |p: f64| fps[((fps.len() - 1) as f64 * p).round() as usize];
    let bytes: f64 = results.iter().map(|r| r.1 as f64).sum::<f64>() / secs / players as f64;
    let cut = results.iter().filter(|r| !r.2).count();
    println!(
        "crowd: port {port} players {players} connect_s {:.0} window_s {secs:.0} fps_median {:.2} fps_p5 {:.2} fps_min {:.2} bytes_per_s_per_player {bytes:.0} cut {cut}",
        connecting.as_secs_f64(),
        at(0.5),
        at(0.05),
        fps[0]
    );
}
