//! What an edge keeps while a pool runs for long: the sequencer's tables (players, edges, the
//! runs' ids) and every edge's requests not yet in the log, counted over ten simulated minutes
//! of the scale run's load (3 edges of 300 players, a stone each every 4 s) where every player
//! leaves after a minute and another comes (new ids). Sans-IO: no NATS, the sequencer's ticks
//! handed to every edge's queue as the log would.

use std::time::{Duration, Instant};

use super::pending::Pending;
use super::protocol::{self, Wire};
use super::sequencer::{Sequencer, SequencerLimits, TICK_PERIOD};

const EDGES: usize = 3;
const PLAYERS: u64 = 300;
const STONE_EVERY: Duration = Duration::from_secs(4);
const STAY: Duration = Duration::from_secs(60);
const MINUTES: u64 = 10;

#[test]
fn the_sequencer_and_the_edges_keep_the_last_seconds_not_everyone_who_came() {
    let t0 = Instant::now();
    let limits =
        SequencerLimits { actions_per_second: 30.0, scene_keys_per_second: 4.0, pool_scene_keys_per_second: 8.0 };
    let mut seq = Sequencer::new((160, 90), 60.0, limits, 1, None, (1, 0), t0);
    let mut edges: Vec<Pending> = (0..EDGES).map(|e| Pending::new(&format!("e{e}"), 7)).collect();
    // Each player's next stone, as an offset from the start in ms (staggered over 4 s).
    let every = STONE_EVERY.as_millis() as u64;
    let mut next: Vec<u64> = (0..PLAYERS).map(|p| p * every / PLAYERS).collect();
    let (mut seq_no, mut kept) = (0u64, Vec::new());
    let period = TICK_PERIOD.as_millis() as u64;
    for ms in (0..MINUTES * 60_000).step_by(period as usize) {
        let now = t0 + Duration::from_millis(ms);
        // The players of this minute: ids no earlier minute used.
        let generation = ms / STAY.as_millis() as u64;
        for (p, due) in next.iter_mut().enumerate() {
            if *due > ms {
                continue;
            }
            *due += every;
            let player = generation * PLAYERS + p as u64;
            for edge in &mut edges {
                let bytes = edge.send(player, Wire::RandomStone { radius: 3 }, now);
                seq.submit(&bytes, now).expect("taken");
            }
        }
        let tick = protocol::bytes_of(&seq.tick(now));
        seq_no += 1;
        let tick: protocol::Tick = serde_json::from_slice(&tick).unwrap();
        for edge in &mut edges {
            edge.taken(seq_no, &tick);
        }
        if (ms + period) % 60_000 < period {
            let (players, seen_edges, runs, ids) = seq.kept();
            let waiting: usize = edges.iter().map(Pending::len).sum();
            kept.push((players, seen_edges, runs, ids, waiting));
        }
    }
    eprintln!("kept at the end of each minute (players, edges, runs, ids, requests waiting): {kept:?}");
    assert_eq!(kept.len(), MINUTES as usize);
    // Every player of the last 10 s at most: this minute's and, at its start, the last one's.
    let bound = 2 * EDGES * PLAYERS as usize;
    for (minute, &(players, seen_edges, runs, ids, waiting)) in kept.iter().enumerate() {
        assert!(players <= bound, "minute {}: {players} players remembered (at most {bound})", minute + 1);
        assert_eq!((seen_edges, runs), (EDGES, EDGES), "minute {}", minute + 1);
        assert!(ids <= EDGES * 64, "minute {}: {ids} ids remembered", minute + 1);
        // Every request is in a tick its edge read: none waits (the queue's own bound is 512).
        assert_eq!(waiting, 0, "minute {}: requests waiting", minute + 1);
    }
    // And the same at minute 10 as at minute 2: nothing piles up with the time run.
    assert!(kept[9].0 <= kept[1].0, "players remembered grew from {} to {}", kept[1].0, kept[9].0);
    // An hour's quiet later (one last tick), nothing is left of them.
    let later = t0 + Duration::from_secs(MINUTES * 60 + 120);
    seq.tick(later);
    assert_eq!(seq.kept(), (0, 0, 0, 0), "after two quiet minutes");
}
