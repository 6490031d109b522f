//! The SSH viewer is a shim: its own loop ([`run`], the task `tidepool serve` spawns for a
//! player), on tokio's paused clock and writing to memory, hands out exactly the bytes the test
//! harness gets from the canonical turn ([`pictured_session`]) on the same pictures, keys and
//! times (the terminal door's twin is `term::door::tests`).

use std::collections::HashMap;
use std::net::SocketAddr;
use std::sync::atomic::AtomicU64;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use super::*;
use crate::cli::serve::game::REQUEST_QUEUE;
use crate::cli::serve::limits::{ConnTracker, Limits, PlayerSlots};
use crate::play::Request;
use crate::play::host::SceneStatus;
use crate::play::tests::{Step, host_config, pictured_session, screen_config};
use crate::play::{Fit, Host};
use tiny_skia::Pixmap;
use tokio_util::task::TaskTracker;

/// The player's terminal, in cells.
const TERM: (u16, u16) = (100, 20);
/// The shared scene, in pixels.
const SCENE: (u32, u32) = (200, 76);
/// A new shared picture every 33 ms (the game's 30 fps, on whole milliseconds).
const PICTURE_MS: u64 = 33;
/// Pictures published after the first.
const PICTURES: u64 = 60;
/// What the player types, at milliseconds from the start: a space, `+`, a click, `?`, a lone
/// Escape (which closes the help once its wait is over: a deadline of the driver's own), `q`.
/// None falls on a picture's millisecond.
const KEYS: &[(u64, &[u8])] =
    &[(170, b" "), (605, b"+"), (1210, b"\x1b[<0;30;8M"), (1402, b"?"), (1801, b"\x1b"), (1905, b"q")];

/// The script: the keys and the pictures, in time order.
fn script() -> Vec<(u64, Step)> {
    let mut script: Vec<(u64, Step)> = KEYS.iter().map(|&(at, bytes)| (at, Step::Bytes(bytes))).collect();
    script.extend((1..=PICTURES).map(|k| (k * PICTURE_MS, Step::Picture)));
    script.sort_by_key(|&(at, _)| at);
    script
}

/// The game's ends of a hub's channels: where pictures are published, where requests arrive.
type GameEnds = (watch::Sender<Arc<SharedFrame>>, mpsc::Receiver<(u64, Request)>);

/// A server's shared state for one player, with rates that never get in the way (the test is
/// about the turn, not the limits), and the game's ends of its channels.
fn hub(first: SharedFrame) -> (Arc<Hub>, GameEnds) {
    let limits = Limits {
        idle_timeout: Duration::from_secs(3600),
        outbound_bytes_per_second: 1 << 40,
        actions_per_second: 1000,
        scene_keys_per_second: 1000,
        ..Limits::default()
    };
    let (frames_tx, frames) = watch::channel(Arc::new(first));
    let (requests, requests_rx) = mpsc::channel(REQUEST_QUEUE);
    let hub = Hub {
        outbound: Mutex::new(limits.outbound_bucket()),
        scene_keys: Mutex::new(limits.all_scene_keys_bucket()),
        tracker: ConnTracker::new(&limits),
        limits,
        allow: None,
        config: Arc::new(russh::server::Config::default()),
        players: PlayerSlots::new(1),
        shutdown: CancellationToken::new(),
        cut_all: CancellationToken::new(),
        frames,
        fits: Arc::new(Mutex::new(HashMap::new())),
        requests,
        stats: Arc::default(),
        tasks: TaskTracker::new(),
        next_id: AtomicU64::new(1),
        scene_size: SCENE,
        fps: 30,
        screenshots: false,
    };
    (Arc::new(hub), (frames_tx, requests_rx))
}

/// The shared scene's pictures at 0, 33, 66, ... ms as the game makes them (the host stepped to
/// each time, rendered, fitted to the player's picture), with its status.
fn pictures(t0: Instant, target: &Fit) -> Vec<(Pixmap, SceneStatus)> {
    let mut host = Host::new(host_config(), SCENE, t0).unwrap();
    let mut scene = Pixmap::new(SCENE.0, SCENE.1).unwrap();
    (0..=PICTURES)
        .map(|k| {
            host.advance(t0 + Duration::from_millis(k * PICTURE_MS));
            host.render(&mut scene);
            (target.fitted(&scene, None).unwrap(), host.status().clone())
        })
        .collect()
}

/// The shared frame of picture `k`.
fn shared(k: usize, pictures: &[(Pixmap, SceneStatus)], target: (u32, u32)) -> SharedFrame {
    let (picture, status) = &pictures[k];
    SharedFrame {
        number: k as u64 + 1,
        status: Arc::new(status.clone()),
        pictures: HashMap::from([(target, Arc::new(picture.clone()))]),
        groups: HashMap::new(),
    }
}

/// A channel that keeps what it is sent.
#[derive(Clone, Default)]
struct Memory(Arc<Mutex<Vec<u8>>>);

impl Channel for Memory {
    async fn data(&self, bytes: Bytes) -> Result<(), ()> {
        self.0.lock().unwrap().extend_from_slice(&bytes);
        Ok(())
    }
    async fn exit_status(&self, _status: u32) -> Result<(), ()> {
        Ok(())
    }
    async fn eof(&self) -> Result<(), ()> {
        Ok(())
    }
    async fn close(&self) -> Result<(), ()> {
        Ok(())
    }
}

#[tokio::test(start_paused = true)]
async fn the_viewer_hands_out_the_bytes_of_the_canonical_turn() {
    let t0 = clock();
    let script = script();
    let (probe_hub, ..) = hub(SharedFrame::default());
    let fit = *new_player(&probe_hub, screen_config(), TERM, t0).fit();
    let pictures = pictures(t0, &fit);
    let (hub, (frames, mut requests)) = hub(shared(0, &pictures, fit.target()));

    // The viewer's own task, and the script feeding it at its times.
    let memory = Memory::default();
    let (_terminal_tx, terminal) = watch::channel(TerminalState { size: TERM, closed: false });
    let (input_tx, input) = mpsc::channel(16);
    let ctx = ViewerCtx {
        hub: hub.clone(),
        id: 1,
        peer: SocketAddr::from(([127, 0, 0, 1], 22)),
        write: memory.clone(),
        terminal,
        input,
        screen: screen_config(),
        kill: CancellationToken::new(),
        slot: hub.players.try_take().unwrap(),
    };
    let feed = async {
        let mut shown = 0;
        for &(at, step) in &script {
            tokio::time::sleep_until((t0 + Duration::from_millis(at)).into()).await;
            match step {
                Step::Bytes(bytes) => input_tx.send((clock(), bytes.to_vec())).await.unwrap(),
                Step::Picture => {
                    shown += 1;
                    frames.send_replace(Arc::new(shared(shown, &pictures, fit.target())));
                }
            }
        }
    };
    tokio::join!(run(ctx), feed);
    let viewer = std::mem::take(&mut *memory.0.lock().unwrap());
    let sent: Vec<Request> = std::iter::from_fn(|| requests.try_recv().ok()).map(|(_, r)| r).collect();

    // The harness: the same player, pictures, keys and times, turn by turn.
    let player = new_player(&hub, screen_config(), TERM, t0);
    let (mut harness, asked) = pictured_session(t0, player, SCENE, &pictures, &script);
    assert!(harness.len() > 10_000, "frames were drawn: {} bytes", harness.len());
    assert!(!asked.is_empty(), "the click asked the host for a stone");
    // The viewer then says goodbye as the server does (`leave.rs`).
    harness.extend_from_slice(format!("bye from the {}\r\n", pictures[0].1.name).as_bytes());
    assert!(viewer == harness, "the viewer's bytes ({}) are the harness's ({})", viewer.len(), harness.len());
    assert_eq!(sent, asked, "the viewer sent the host the harness's requests");
}

/// A channel that holds what it is handed, as russh's queue does, until the test lets it go;
/// for every handing over: when, the bytes it already held, and how many came.
#[derive(Clone, Default)]
struct Queue(Arc<Mutex<(Vec<Bytes>, Vec<Handed>)>>);

/// A handing over: when, the bytes already held, the bytes handed.
type Handed = (Instant, usize, usize);

impl Queue {
    /// Lets everything held go (russh took it into its write buffer).
    fn release(&self) {
        self.0.lock().unwrap().0.clear();
    }
}

impl Channel for Queue {
    async fn data(&self, bytes: Bytes) -> Result<(), ()> {
        let (held, handed) = &mut *self.0.lock().unwrap();
        handed.push((clock(), held.iter().map(Bytes::len).sum(), bytes.len()));
        held.push(bytes);
        Ok(())
    }
    async fn exit_status(&self, _status: u32) -> Result<(), ()> {
        Ok(())
    }
    async fn eof(&self) -> Result<(), ()> {
        Ok(())
    }
    async fn close(&self) -> Result<(), ()> {
        Ok(())
    }
}

/// Issue 31 (bus.md round 9): while russh has not taken a player's frames, the player hands it
/// no new one once they hold the byte budget (the pictures meanwhile are skipped, not queued),
/// and the frame a key owes goes the moment the bytes land, not at the next picture.
#[tokio::test(start_paused = true)]
async fn a_player_holds_its_byte_budget_in_flight_and_a_keys_frame_goes_when_it_lands() {
    use crate::cli::serve::flight::FLIGHT_BUDGET_BYTES;
    let t0 = clock();
    let (probe_hub, ..) = hub(SharedFrame::default());
    let fit = *new_player(&probe_hub, screen_config(), TERM, t0).fit();
    let pictures = pictures(t0, &fit);
    let (hub, (frames, _requests)) = hub(shared(0, &pictures, fit.target()));
    let queue = Queue::default();
    let (_terminal_tx, terminal) = watch::channel(TerminalState { size: TERM, closed: false });
    let (input_tx, input) = mpsc::channel(16);
    let ctx = ViewerCtx {
        hub: hub.clone(),
        id: 1,
        peer: SocketAddr::from(([127, 0, 0, 1], 22)),
        write: queue.clone(),
        terminal,
        input,
        screen: screen_config(),
        kill: CancellationToken::new(),
        slot: hub.players.try_take().unwrap(),
    };
    let at = |ms: u64| tokio::time::sleep_until((t0 + Duration::from_millis(ms)).into());
    let feed = async {
        // Every picture for two seconds while russh takes nothing.
        for k in 1..=PICTURES as usize {
            at(k as u64 * PICTURE_MS).await;
            frames.send_replace(Arc::new(shared(k, &pictures, fit.target())));
        }
        // No more pictures: a key's frame waits behind the held bytes, then they land.
        at(2_010).await;
        input_tx.send((clock(), b"?".to_vec())).await.unwrap();
        at(2_050).await;
        queue.release();
        at(2_100).await;
        input_tx.send((clock(), b"q".to_vec())).await.unwrap();
    };
    tokio::join!(run(ctx), feed);
    let handed = std::mem::take(&mut queue.0.lock().unwrap().1);
    let most = handed.iter().map(|&(_, held, len)| held + len).max().unwrap();
    assert!(most >= FLIGHT_BUDGET_BYTES, "the frames reached the budget ({most} bytes held at most): the test binds");
    for &(when, held, len) in &handed {
        let ms = (when - t0).as_millis();
        assert!(held < FLIGHT_BUDGET_BYTES, "at {ms} ms a frame of {len} bytes was handed over with {held} bytes held");
    }
    let during = handed.iter().filter(|&&(when, ..)| when < t0 + Duration::from_millis(2_050));
    assert!(
        during.count() < PICTURES as usize / 2,
        "most pictures were skipped while russh held the budget: {handed:?}"
    );
    let landed = t0 + Duration::from_millis(2_050);
    assert!(
        handed.iter().any(|&(when, _, len)| when == landed && len > 0),
        "the help's frame went when the bytes landed: {:?}",
        handed.iter().map(|&(when, held, len)| ((when - t0).as_millis(), held, len)).collect::<Vec<_>>()
    );
}
