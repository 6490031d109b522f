//! Every request an edge sends reaches the log once: stones pressed on one edge while the
//! sequencer's edge is killed (the role moves) and while nats-server restarts are each in the
//! log exactly once afterwards. The edges' trace (`TIDEPOOL_BUS_TRACE=1`) names what an edge
//! sent (`bus-trace sent EDGE N`) and what another read from the log (`bus-trace taken EDGE N`).

use super::*;

const TRACE: &[(&str, &str)] = &[("TIDEPOOL_BUS_TRACE", "1")];

/// The counts of the requests `edge` sent (first sends; sends again are not traced).
fn sent(edge: &Edge) -> Vec<u64> {
    let prefix = format!("bus-trace sent {} ", edge.name);
    edge.log().iter().filter_map(|l| l.strip_prefix(&prefix)?.split(' ').next()?.parse().ok()).collect()
}

/// The counts of `from`'s requests that `observer` read from the log, once per log entry.
fn taken(observer: &Edge, from: &str) -> Vec<u64> {
    let prefix = format!("bus-trace taken {from} ");
    observer.log().iter().filter_map(|l| l.strip_prefix(&prefix)?.split(' ').next()?.parse().ok()).collect()
}

/// Clicks `count` stones on `p`, 70 ms apart (within a player's 30 actions a second).
async fn press(p: &Player, count: u32, first: u32) {
    for i in first..first + count {
        p.send(&click(5 + i % 70, 3 + i % 18));
        tokio::time::sleep(Duration::from_millis(70)).await;
    }
}

/// Waits (bounded) until `observer` read every request `edge` sent so far, then long enough
/// for any request sent twice to show twice (twice the time after which an edge sends again),
/// and asserts each is in the log once.
async fn each_once(edge: &Edge, observer: &Edge, what: &str) -> usize {
    let until = Instant::now() + HANG_GUARD;
    loop {
        let (s, t) = (sent(edge), taken(observer, &edge.name));
        if s.iter().all(|n| t.contains(n)) {
            break;
        }
        let missing: Vec<&u64> = s.iter().filter(|n| !t.contains(n)).collect();
        assert!(
            Instant::now() < until,
            "{what}: requests {missing:?} of {} never reached the log; {}'s log {:?}",
            s.len(),
            edge.name,
            edge.log().iter().filter(|l| !l.starts_with("bus-trace")).collect::<Vec<_>>()
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    tokio::time::sleep(Duration::from_secs(4)).await;
    let (s, t) = (sent(edge), taken(observer, &edge.name));
    for n in &s {
        let times = t.iter().filter(|m| *m == n).count();
        assert_eq!(times, 1, "{what}: request {n} is in the log {times} times");
    }
    s.len()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
#[ignore = "needs nats-server: scripts/bus_tests.sh installs it and runs these (.ci/run does)"]
async fn stones_pressed_while_the_role_moves_or_the_bus_restarts_are_each_in_the_log_once() {
    let mut nats = Nats::start();
    let pool = pool_name("once");
    let a = Edge::first(&nats.url(), &pool);
    let b = Edge::start_env(&nats.url(), &pool, "b", TRACE);
    let c = Edge::start_env(&nats.url(), &pool, "c", TRACE);
    let pb = Player::join(&b).await;
    b.wait_log("joined");
    c.wait_log("joined");
    press(&pb, 10, 0).await;

    // The sequencer's edge killed while b's player keeps pressing: what b sends before a
    // standby takes the role over reaches nobody, and is sent again on the new term.
    a.kill();
    press(&pb, 30, 10).await;
    wait_until("a new sequencer", || {
        b.log_has("this edge is the sequencer") || c.log_has("this edge is the sequencer")
    });
    press(&pb, 10, 40).await;
    let n = each_once(&b, &c, "after the takeover").await;
    assert!(n >= 50, "b sent {n} requests of the 50 stones");
    assert!(b.log_has("requests again"), "nothing was sent again: the test missed the takeover; {:?}", b.log());

    // nats-server restarted while b's player presses: stones pressed while the bus is away are
    // not taken (the status line says so); those sent before, and their ticks, are not lost.
    let restart = tokio::task::spawn_blocking(move || {
        std::thread::sleep(Duration::from_millis(700));
        let stopped = nats.stop();
        nats.start_again(stopped, Duration::from_millis(1500));
        nats
    });
    press(&pb, 30, 50).await;
    let _nats = restart.await.unwrap();
    pb.wait_status("the bus back", |s| !s.contains("bus lost")).await;
    press(&pb, 10, 80).await;
    let m = each_once(&b, &c, "after the restart").await;
    assert!(m > n, "b sent nothing after the restart");
}
