//! The sequencer's role on a thread of its own: a players' runtime whose every worker is busy
//! does not stop the lease's renewal, and a restart of nats-server does not move the role.
//! Needs a real nats-server: ignored by the README's test command (a fresh machine has none);
//! `scripts/bus_tests.sh` installs it and runs these.

use std::process::{Child, Command, Stdio};
use std::sync::Barrier;
use std::sync::atomic::{AtomicU16, Ordering};
use std::time::{Duration, Instant};

use async_nats::jetstream;

use super::*;
use crate::cli::serve::bus::protocol::Names;

/// How long the players' runtime is kept busy: three times the lease's expiry.
const STALL: Duration = Duration::from_secs(3);
/// The players' runtime's workers.
const WORKERS: usize = 2;
/// The pool's size.
const SIZE: (u32, u32) = (160, 90);
/// The longest any wait here may take.
const HANG_GUARD: Duration = Duration::from_secs(30);

/// A nats-server with JetStream on a loopback port; killed when dropped.
struct NatsServer {
    child: Child,
    port: u16,
    dir: tempfile::TempDir,
}

impl NatsServer {
    /// On a free port of `TIDEPOOL_BUS_TEST_PORTS` (`FIRST-LAST`; the bus tests' 42000-42999
    /// when unset).
    fn start() -> NatsServer {
        let range = std::env::var("TIDEPOOL_BUS_TEST_PORTS").unwrap_or_else(|_| "42000-42999".into());
        let (first, last) = range
            .split_once('-')
            .and_then(|(a, b)| Some((a.parse::<u16>().ok()?, b.parse::<u16>().ok()?)))
            .expect("TIDEPOOL_BUS_TEST_PORTS is FIRST-LAST, e.g. 42000-42999");
        // Never the same port twice in this process: the tests run side by side, and one
        // port is free while its server restarts.
        static NEXT: AtomicU16 = AtomicU16::new(0);
        let offset = std::process::id() as u16 % (last - first + 1);
        let port = (0..=last - first)
            .map(|_| first + offset.wrapping_add(NEXT.fetch_add(1, Ordering::Relaxed)) % (last - first + 1))
            .find(|&p| std::net::TcpListener::bind(("127.0.0.1", p)).is_ok())
            .expect("a free port for nats-server");
        let dir = tempfile::tempdir().unwrap();
        let child = NatsServer::spawn(port, dir.path());
        NatsServer { child, port, dir }
    }

    fn spawn(port: u16, dir: &std::path::Path) -> Child {
        let child = Command::new("nats-server")
            .args(["-js", "-a", "127.0.0.1", "-p", &port.to_string(), "-sd"])
            .arg(dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot run nats-server ({e}): this test needs it; run scripts/bus_tests.sh"));
        wait_until("nats-server to listen", || std::net::TcpStream::connect(("127.0.0.1", port)).is_ok());
        child
    }

    /// Stops it as a service manager does (SIGTERM) and waits for it to exit.
    fn stop(&mut self) -> Instant {
        let _ = Command::new("kill").arg(self.child.id().to_string()).status();
        let _ = self.child.wait();
        Instant::now()
    }

    /// Starts it again on the same port with the same data.
    fn start_again(&mut self) {
        self.child = NatsServer::spawn(self.port, self.dir.path());
    }
}

impl Drop for NatsServer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// An edge's options, its part in the role and its bus state (the snapshots it is asked for
/// are never answered: it never joins, so it never offers one).
fn edge(url: &str, pool: &str, me: &str) -> (BusOptions, Role, Arc<BusState>) {
    let limits =
        SequencerLimits { actions_per_second: 30.0, scene_keys_per_second: 4.0, pool_scene_keys_per_second: 8.0 };
    let options = BusOptions {
        url: url.into(),
        pool: pool.into(),
        edge: me.into(),
        credentials: None,
        ca: None,
        shots: None,
        limits,
    };
    let state = Arc::new(BusState::default());
    let (snapshots, _) = mpsc::channel(4);
    let role =
        Role { me: me.into(), size: SIZE, steps_per_second: 60.0, seed: 1, limits, snapshots, state: state.clone() };
    (options, role, state)
}

fn wait_until(what: &str, mut ok: impl FnMut() -> bool) {
    let until = Instant::now() + HANG_GUARD;
    while !ok() {
        assert!(Instant::now() < until, "timed out waiting for {what}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
#[ignore = "needs nats-server: scripts/bus_tests.sh installs it and runs this (.ci/run does)"]
fn the_lease_is_renewed_while_every_worker_of_the_players_runtime_is_busy() {
    let nats = NatsServer::start();
    let url = format!("nats://127.0.0.1:{}", nats.port);
    let pool = format!("starved-{}", std::process::id());
    // The server's runtime, where the players' tasks (their frames' encoding) run.
    let players = tokio::runtime::Builder::new_multi_thread().worker_threads(WORKERS).enable_all().build().unwrap();
    let (options, role, state) = edge(&url, &pool, "a");
    let stop = CancellationToken::new();
    players.block_on(start(&options, "a test pool".into(), role, stop.clone())).expect("the sequencer's role starts");
    wait_until("the sequencer's role", || state.leading.load(Ordering::Relaxed));

    // The lease as another machine sees it: a connection and a runtime of the test's own.
    let watcher = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    let bucket = Names::of(&pool).unwrap().bucket;
    let kv = watcher.block_on(async {
        let client = async_nats::connect(&url).await.expect("the watcher connects");
        jetstream::new(client).get_key_value(bucket).await.expect("the pool's bucket")
    });
    let lease = || {
        let entry = watcher.block_on(kv.entry(LEASE_KEY)).expect("the lease reads").expect("a lease");
        (String::from_utf8_lossy(&entry.value).into_owned(), entry.revision)
    };

    // Every worker of the players' runtime blocked for STALL (as by encoding at full load):
    // the barrier is passed only when each worker runs one of these.
    let busy = Arc::new(Barrier::new(WORKERS + 1));
    for _ in 0..WORKERS {
        let busy = busy.clone();
        players.spawn(async move {
            busy.wait();
            std::thread::sleep(STALL);
        });
    }
    busy.wait();
    let (_, before) = lease();
    std::thread::sleep(STALL - Duration::from_millis(500));
    let (holder, after) = lease();
    // A refresh every 250 ms: about ten in the window; a lease on the blocked runtime, none.
    assert_eq!(holder, "a");
    assert!(
        after >= before + 2,
        "the lease went from revision {before} to {after} while every worker of the players' runtime was busy \
         (a standby takes a lease unchanged for {} ms)",
        lease::EXPIRY.as_millis()
    );
    assert!(state.leading.load(Ordering::Relaxed), "the role was given up");
    stop.cancel();
    drop(players);
}

/// The pool's log as another machine reads it: its last entry's sequence and every tick from
/// entry `from` on. A connection of its own each time (the server restarts under the test).
fn read_log(url: &str, pool: &str, from: u64) -> (u64, Vec<Tick>) {
    let names = Names::of(pool).unwrap();
    let reader = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    reader.block_on(async {
        let client = async_nats::connect(url).await.expect("the reader connects");
        let log = jetstream::new(client).get_stream(&names.stream).await.expect("the pool's log");
        let end = log.get_last_raw_message_by_subject(&names.log).await.expect("a tick in the log").sequence;
        let mut ticks = Vec::new();
        for seq in from..=end {
            let entry = log.get_raw_message(seq).await.expect("the log's entry");
            ticks.push(protocol::read_tick(&entry.payload, SIZE).expect("a tick"));
        }
        (end, ticks)
    })
}

/// Publishes a player's random stone from edge `w` as another machine would.
fn submit(url: &str, pool: &str, n: u64) {
    let subject = Names::of(pool).unwrap().submit;
    let sender = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    sender.block_on(async {
        let client = async_nats::connect(url).await.expect("the sender connects");
        let bytes = format!(r#"{{"edge":"w","player":1,"n":{n},"what":{{"random_stone":{{"radius":3}}}}}}"#);
        client.publish(subject, bytes.into()).await.unwrap();
        client.flush().await.unwrap();
    });
}

#[test]
#[ignore = "needs nats-server: scripts/bus_tests.sh installs it and runs this (.ci/run does)"]
fn a_restart_of_nats_server_leaves_the_role_with_its_holder_and_its_term() {
    let mut nats = NatsServer::start();
    let url = format!("nats://127.0.0.1:{}", nats.port);
    let pool = format!("restart-{}", std::process::id());
    let players = tokio::runtime::Builder::new_multi_thread().worker_threads(WORKERS).enable_all().build().unwrap();
    let stop = CancellationToken::new();
    let (options, role, a) = edge(&url, &pool, "a");
    players.block_on(start(&options, "a test pool".into(), role, stop.clone())).expect("a starts");
    wait_until("a to be the sequencer", || a.leading.load(Ordering::Relaxed));
    let (options, role, b) = edge(&url, &pool, "b");
    players.block_on(start(&options, "a test pool".into(), role, stop.clone())).expect("b starts");
    submit(&url, &pool, 1);
    wait_until("the first stone in the log", || read_log(&url, &pool, 1).1.iter().any(|t| !t.events.is_empty()));
    let (before, ticks) = read_log(&url, &pool, 1);
    let term = ticks.last().unwrap().term;

    // Down for 1.5 s (the edges' fault test's outage), then back with the same data: exactly
    // one sequencer all along, a, and b never takes over, neither while the bus is away nor
    // once both see it again (three lease expiries after both are back).
    let stopped = nats.stop();
    let watch = |what: &str| {
        assert!(a.leading.load(Ordering::Relaxed), "a gave the role up {what}");
        assert!(!b.leading.load(Ordering::Relaxed), "b took the role over {what}");
        std::thread::sleep(Duration::from_millis(10));
    };
    while stopped.elapsed() < Duration::from_millis(1500) {
        watch("while nats-server was down");
    }
    nats.start_again();
    wait_until("both edges connected again", || {
        [&a, &b].iter().all(|s| s.connected.load(Ordering::Relaxed) && s.lost_once.load(Ordering::Relaxed))
    });
    // A stone sent the moment both are back: a sequencer takes it.
    submit(&url, &pool, 2);
    let back = Instant::now();
    while back.elapsed() < 3 * lease::EXPIRY {
        watch("after nats-server came back");
    }

    // Ordered by a in the same term: ten ticks at least after the restart (bounded, not
    // timed: a loaded machine may take its time), every one of them of a's term, and the
    // stone sent once the bus was back in one.
    wait_until("ten ticks after the restart", || {
        watch("while the log was read");
        read_log(&url, &pool, 1).0 > before + 10
    });
    let (_, ticks) = read_log(&url, &pool, before + 1);
    let terms: std::collections::BTreeSet<u64> = ticks.iter().map(|t| t.term).collect();
    assert_eq!(terms, [term].into(), "the terms of the ticks after the restart (a's was {term})");
    let taken = ticks.iter().flat_map(|t| &t.events).filter(|e| e.edge == "w" && e.n == 2).count();
    assert_eq!(taken, 1, "the stone sent once the bus was back, in the ticks after the restart");
    stop.cancel();
    drop(players);
}
