//! The sequencer's role on a thread of its own: a players' runtime whose every worker is busy
//! does not stop the lease's renewal. Needs a real nats-server: ignored by the README's test
//! command (a fresh machine has none); `scripts/bus_tests.sh` installs it and runs this.

use std::process::{Child, Command, Stdio};
use std::sync::Barrier;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use async_nats::jetstream;

use super::*;
use crate::serve::bus::protocol::Names;

/// How long the players' runtime is kept busy: three times the lease's expiry.
const STALL: Duration = Duration::from_secs(3);
/// The players' runtime's workers.
const WORKERS: usize = 2;
/// The longest any wait here may take.
const HANG_GUARD: Duration = Duration::from_secs(30);

/// A nats-server with JetStream on a loopback port; killed when dropped.
struct NatsServer {
    child: Child,
    port: u16,
    _dir: tempfile::TempDir,
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
        let offset = std::process::id() as u16 % (last - first + 1);
        let port = (0..=last - first)
            .map(|i| first + (offset + i) % (last - first + 1))
            .find(|&p| std::net::TcpListener::bind(("127.0.0.1", p)).is_ok())
            .expect("a free port for nats-server");
        let dir = tempfile::tempdir().unwrap();
        let child = Command::new("nats-server")
            .args(["-js", "-a", "127.0.0.1", "-p", &port.to_string(), "-sd"])
            .arg(dir.path())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap_or_else(|e| panic!("cannot run nats-server ({e}): this test needs it; run scripts/bus_tests.sh"));
        let server = NatsServer { child, port, _dir: dir };
        wait_until("nats-server to listen", || std::net::TcpStream::connect(("127.0.0.1", port)).is_ok());
        server
    }
}

impl Drop for NatsServer {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
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
    let limits =
        SequencerLimits { actions_per_second: 30.0, scene_keys_per_second: 4.0, pool_scene_keys_per_second: 8.0 };
    let options = BusOptions {
        url: url.clone(),
        pool: pool.clone(),
        edge: "a".into(),
        credentials: None,
        ca: None,
        shots: None,
        limits,
    };
    // The server's runtime, where the players' tasks (their frames' encoding) run.
    let players = tokio::runtime::Builder::new_multi_thread().worker_threads(WORKERS).enable_all().build().unwrap();
    let state = Arc::new(BusState::default());
    let (snapshots, _never_answered) = mpsc::channel(4);
    let role = Role {
        me: "a".into(),
        size: (160, 90),
        steps_per_second: 60.0,
        seed: 1,
        limits,
        snapshots,
        state: state.clone(),
    };
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
