//! What travels on the bus, and the names it travels under. Sans-IO: plain types, their JSON
//! forms and their checks, so the sequencer, the edges and the tests share one definition.
//!
//! - An edge sends a [`Submit`] (one player's request) on `tidepool.POOL.in` and a
//!   [`Presence`] (its player count) on `tidepool.POOL.edges`, both plain NATS messages.
//! - The sequencer publishes a [`Tick`] to the pool's JetStream stream (`tidepool.POOL.log`):
//!   a step every edge may run to, and the events every edge applies at that step, in order.
//!
//! Every message has a byte bound checked before it is parsed, and every value a bound checked
//! after; what fails is a [`Refusal`] naming the problem.

use crate::Action;
use crate::play::Request;
use serde::{Deserialize, Serialize};

/// The largest [`Submit`] accepted, in bytes.
pub const MAX_SUBMIT_BYTES: usize = 512;
/// The largest [`Presence`] accepted, in bytes.
pub const MAX_PRESENCE_BYTES: usize = 256;
/// The largest [`Tick`] an edge accepts (and the stream's largest message), in bytes.
pub const MAX_TICK_BYTES: usize = 64 * 1024;
/// The most events one tick carries (the pool's event rate is bounded below this).
pub const MAX_EVENTS_PER_TICK: usize = 256;
/// The most settled requests one tick names (more are not named: their edges give them up
/// by age, and the sequencer ignores them meanwhile).
pub const MAX_SETTLED_PER_TICK: usize = 256;
/// The longest pool name: letters, digits, `-` and `_` (it is part of subjects and bucket names).
pub const MAX_POOL_NAME: usize = 32;
/// The longest edge name, same characters.
pub const MAX_EDGE_NAME: usize = 64;
/// The largest stone radius a request may ask for, in pixels (the seat's largest).
pub const MAX_RADIUS: u32 = 32;
/// Keys other than letters, digits and punctuation are refused.
const KEY_RANGE: std::ops::RangeInclusive<char> = '!'..='~';

/// A player's request as it travels: the scene's actions in pixels, plus what only the
/// sequencer may decide (where a random stone lands, pause) or every edge does (a screenshot).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Wire {
    /// A stone at `(x, y)`.
    Stone {
        /// Column in pixels.
        x: i32,
        /// Row in pixels.
        y: i32,
        /// Radius in pixels.
        radius: u32,
        /// A right click's big stone.
        big: bool,
    },
    /// A drag stirring the water.
    Stir {
        /// Where the drag was.
        from: [i32; 2],
        /// Where it is now.
        to: [i32; 2],
    },
    /// A stone at a spot the sequencer picks (only in a [`Submit`]; a tick holds the stone).
    RandomStone {
        /// Radius in pixels.
        radius: u32,
    },
    /// `r`.
    Rain,
    /// `c`.
    Clear,
    /// `[` (stronger) and `]`.
    Damping {
        /// Damp more.
        stronger: bool,
    },
    /// A scene key (`b`).
    Key {
        /// The key.
        key: char,
    },
    /// `p`: the sequencer pauses the pool's clock (only in a [`Submit`]).
    Pause,
    /// `s`: every edge that keeps screenshots saves this step's picture.
    Shot,
}

/// One player's request, from an edge to the sequencer. `(edge, run, n)` names it: the edge
/// keeps it until that id is in the log (stamped or refused) and sends it again meanwhile, and
/// the sequencer stamps an id once (`bus/pending.rs`, `bus/handled.rs`).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Submit {
    /// The edge's name.
    pub edge: String,
    /// The edge's run (a number the process picked when it started): a restarted edge of the
    /// same name counts its requests anew.
    #[serde(default)]
    pub run: u64,
    /// The player's number on that edge.
    pub player: u64,
    /// The edge's count of submits so far in this run (a key's latency is measured by it).
    pub n: u64,
    /// Every request of this run below this count is settled for the edge (in the log or
    /// given up): the sequencer forgets what it remembers of them.
    #[serde(default)]
    pub floor: u64,
    /// The last log entry the edge had read when it sent this.
    #[serde(default)]
    pub seen: u64,
    /// Sent before: a sequencer whose term began after entry `seen` cannot know whether an
    /// earlier term stamped it, and leaves it for the edge to send again once it read on.
    #[serde(default)]
    pub again: bool,
    /// What was asked.
    pub what: Wire,
}

impl Submit {
    /// A first send of request `n` of `edge`'s run 0 (for the tests).
    #[cfg(test)]
    pub fn new(edge: &str, player: u64, n: u64, what: Wire) -> Submit {
        Submit { edge: edge.into(), run: 0, player, n, floor: 0, seen: 0, again: false, what }
    }

    /// Its id.
    pub fn id(&self) -> RequestId {
        RequestId { edge: self.edge.clone(), run: self.run, n: self.n }
    }
}

/// The id of a request: its edge, the edge's run and its count there.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RequestId {
    /// The edge's name.
    pub edge: String,
    /// The edge's run.
    #[serde(default)]
    pub run: u64,
    /// Its count there.
    pub n: u64,
}

/// An edge's players, every second.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Presence {
    /// The edge's name.
    pub edge: String,
    /// Players on it now.
    pub players: u32,
}

/// An event in the log: what, and who asked (edge and submit count, for the logs and the
/// latency measure; it changes nothing in the scene).
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stamped {
    /// The request, resolved (never `RandomStone` or `Pause`).
    pub what: Wire,
    /// The edge that sent it.
    pub edge: String,
    /// The edge's run.
    #[serde(default)]
    pub run: u64,
    /// Its submit count there.
    pub n: u64,
}

/// One entry of the pool's log.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Tick {
    /// Every edge may run its scene up to this step; `events` apply at it, in order, before
    /// the step after it.
    pub step: u64,
    /// The sequencer's lease revision (a new sequencer has a larger one).
    pub term: u64,
    /// The pool's clock is paused.
    pub paused: bool,
    /// Players on the whole pool (every edge's last presence).
    pub players: u32,
    /// The events at `step`.
    pub events: Vec<Stamped>,
    /// Requests the sequencer handled since the last tick without an event (refused over a
    /// rate or a bound, or a pause): their edges stop sending them. At most
    /// [`MAX_SETTLED_PER_TICK`].
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub settled: Vec<RequestId>,
}

/// Why a message was refused.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Refusal(pub String);

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

fn refuse<T>(why: impl Into<String>) -> Result<T, Refusal> {
    Err(Refusal(why.into()))
}

/// Whether `name` is a pool or edge name: 1 to `max` letters, digits, `-` or `_`.
pub fn valid_name(name: &str, max: usize) -> bool {
    (1..=max).contains(&name.len()) && name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_')
}

/// The subjects and bucket names of one pool.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Names {
    /// Players' requests to the sequencer.
    pub submit: String,
    /// Edges' presence.
    pub presence: String,
    /// The log's subject.
    pub log: String,
    /// The log's stream.
    pub stream: String,
    /// The key-value bucket (the sequencer's lease, the pool's settings).
    pub bucket: String,
    /// The object store of snapshots.
    pub snapshots: String,
}

impl Names {
    /// The names of pool `pool` (checked with [`valid_name`]).
    pub fn of(pool: &str) -> Result<Names, Refusal> {
        if !valid_name(pool, MAX_POOL_NAME) {
            return refuse(format!(
                "'{pool}' is not a pool name; use 1 to {MAX_POOL_NAME} letters, digits, '-' or '_'"
            ));
        }
        Ok(Names {
            submit: format!("tidepool.{pool}.in"),
            presence: format!("tidepool.{pool}.edges"),
            log: format!("tidepool.{pool}.log"),
            stream: format!("tidepool_{pool}_log"),
            bucket: format!("tidepool_{pool}"),
            snapshots: format!("tidepool_{pool}_snap"),
        })
    }
}

/// The request a player's seat made, as it travels; `None` for what the bus does not carry
/// (`tab`: a bus pool has one scene).
pub fn wire_of(request: Request) -> Option<Wire> {
    Some(match request {
        Request::Act(Action::Stone { x, y, radius, big }) => Wire::Stone { x, y, radius, big },
        Request::Act(Action::Stir { from, to }) => Wire::Stir { from: [from.0, from.1], to: [to.0, to.1] },
        Request::Act(Action::ToggleRain) => Wire::Rain,
        Request::Act(Action::Clear) => Wire::Clear,
        Request::Act(Action::Damping(stronger)) => Wire::Damping { stronger },
        Request::Act(Action::Key(key)) => Wire::Key { key },
        Request::RandomStone { radius } => Wire::RandomStone { radius },
        Request::TogglePause => Wire::Pause,
        Request::Screenshot => Wire::Shot,
        Request::NextScene => return None,
    })
}

impl Wire {
    /// The scene's action, for what the scene resolves itself.
    pub fn action(self) -> Option<Action> {
        Some(match self {
            Wire::Stone { x, y, radius, big } => Action::Stone { x, y, radius, big },
            Wire::Stir { from, to } => Action::Stir { from: (from[0], from[1]), to: (to[0], to[1]) },
            Wire::Rain => Action::ToggleRain,
            Wire::Clear => Action::Clear,
            Wire::Damping { stronger } => Action::Damping(stronger),
            Wire::Key { key } => Action::Key(key),
            Wire::RandomStone { .. } | Wire::Pause | Wire::Shot => return None,
        })
    }

    /// Whether it costs every edge more than a stone (the scene keys' own, lower rate).
    pub fn is_scene_key(self) -> bool {
        !matches!(self, Wire::Stone { .. } | Wire::Stir { .. } | Wire::RandomStone { .. })
    }

    /// Checks the values against a scene of `size` pixels: points inside it, a radius the seat
    /// can have, a printable key.
    pub fn check(self, size: (u32, u32)) -> Result<(), Refusal> {
        let inside = |x: i32, y: i32| x >= 0 && y >= 0 && (x as u32) < size.0 && (y as u32) < size.1;
        let radius_ok = |r: u32| (1..=MAX_RADIUS).contains(&r);
        match self {
            Wire::Stone { x, y, radius, .. } if !inside(x, y) || !radius_ok(radius) => refuse(format!(
                "stone at ({x}, {y}) radius {radius} is outside the {}x{} pool or radii 1..={MAX_RADIUS}",
                size.0, size.1
            )),
            Wire::Stir { from, to } if !inside(from[0], from[1]) || !inside(to[0], to[1]) => {
                refuse(format!("stir {from:?} to {to:?} leaves the {}x{} pool", size.0, size.1))
            }
            Wire::RandomStone { radius } if !radius_ok(radius) => {
                refuse(format!("random stone radius {radius} is outside 1..={MAX_RADIUS}"))
            }
            Wire::Key { key } if !KEY_RANGE.contains(&key) => refuse(format!("key {key:?} is not a scene key")),
            _ => Ok(()),
        }
    }

    /// A stone, for the sequencer's choice of a random spot.
    pub fn stone_at(x: i32, y: i32, radius: u32) -> Wire {
        Wire::Stone { x, y, radius, big: false }
    }
}

/// Reads a [`Submit`]: within [`MAX_SUBMIT_BYTES`], well-formed, a valid edge name, its
/// values within a scene of `size`.
#[cfg(test)]
pub fn read_submit(bytes: &[u8], size: (u32, u32)) -> Result<Submit, Refusal> {
    let submit = parse_submit(bytes)?;
    submit.what.check(size)?;
    Ok(submit)
}

/// Reads a [`Submit`] within [`MAX_SUBMIT_BYTES`], well-formed, with a valid edge name; its
/// values are left to [`Wire::check`] (a refusal of them names the request's id).
pub fn parse_submit(bytes: &[u8]) -> Result<Submit, Refusal> {
    if bytes.len() > MAX_SUBMIT_BYTES {
        return refuse(format!("{} bytes, at most {MAX_SUBMIT_BYTES}", bytes.len()));
    }
    let submit: Submit = serde_json::from_slice(bytes).map_err(|e| Refusal(format!("malformed: {e}")))?;
    if !valid_name(&submit.edge, MAX_EDGE_NAME) {
        return refuse("bad edge name");
    }
    Ok(submit)
}

/// Reads a [`Presence`] within [`MAX_PRESENCE_BYTES`].
pub fn read_presence(bytes: &[u8]) -> Result<Presence, Refusal> {
    if bytes.len() > MAX_PRESENCE_BYTES {
        return refuse(format!("{} bytes, at most {MAX_PRESENCE_BYTES}", bytes.len()));
    }
    let presence: Presence = serde_json::from_slice(bytes).map_err(|e| Refusal(format!("malformed: {e}")))?;
    if !valid_name(&presence.edge, MAX_EDGE_NAME) {
        return refuse("bad edge name");
    }
    Ok(presence)
}

/// Reads a [`Tick`] from the log: within [`MAX_TICK_BYTES`] and [`MAX_EVENTS_PER_TICK`],
/// each event checked against a scene of `size`, none of the sequencer's own.
pub fn read_tick(bytes: &[u8], size: (u32, u32)) -> Result<Tick, Refusal> {
    if bytes.len() > MAX_TICK_BYTES {
        return refuse(format!("{} bytes, at most {MAX_TICK_BYTES}", bytes.len()));
    }
    let tick: Tick = serde_json::from_slice(bytes).map_err(|e| Refusal(format!("malformed: {e}")))?;
    if tick.events.len() > MAX_EVENTS_PER_TICK {
        return refuse(format!("{} events, at most {MAX_EVENTS_PER_TICK}", tick.events.len()));
    }
    if tick.settled.len() > MAX_SETTLED_PER_TICK {
        return refuse(format!("{} settled requests, at most {MAX_SETTLED_PER_TICK}", tick.settled.len()));
    }
    for e in &tick.events {
        if matches!(e.what, Wire::RandomStone { .. } | Wire::Pause) {
            return refuse("an unresolved request in the log");
        }
        e.what.check(size)?;
    }
    Ok(tick)
}

/// JSON bytes of any message (they cannot fail: plain structs of numbers and names).
pub fn bytes_of<T: Serialize>(message: &T) -> Vec<u8> {
    serde_json::to_vec(message).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    const SIZE: (u32, u32) = (160, 90);

    fn submit(what: Wire) -> Vec<u8> {
        bytes_of(&Submit::new("a", 1, 1, what))
    }

    #[test]
    fn every_request_travels_and_comes_back() {
        let requests = [
            Request::Act(Action::Stone { x: 3, y: 4, radius: 2, big: true }),
            Request::Act(Action::Stir { from: (1, 2), to: (3, 4) }),
            Request::Act(Action::ToggleRain),
            Request::Act(Action::Clear),
            Request::Act(Action::Damping(false)),
            Request::Act(Action::Key('b')),
        ];
        for r in requests {
            let wire = wire_of(r).unwrap();
            let back = read_submit(&submit(wire), SIZE).unwrap();
            assert_eq!(Request::Act(back.what.action().unwrap()), r);
        }
        assert_eq!(wire_of(Request::NextScene), None);
        assert_eq!(wire_of(Request::RandomStone { radius: 4 }), Some(Wire::RandomStone { radius: 4 }));
    }

    #[test]
    fn out_of_bounds_and_malformed_submits_are_refused() {
        let bad = [
            submit(Wire::Stone { x: 160, y: 0, radius: 2, big: false }),
            submit(Wire::Stone { x: -1, y: 0, radius: 2, big: false }),
            submit(Wire::Stone { x: 1, y: 1, radius: 0, big: false }),
            submit(Wire::Stone { x: 1, y: 1, radius: MAX_RADIUS + 1, big: false }),
            submit(Wire::Stir { from: [0, 0], to: [0, 90] }),
            submit(Wire::RandomStone { radius: 1000 }),
            submit(Wire::Key { key: '\u{7}' }),
            b"{\"edge\":\"a\"}".to_vec(),
            b"not json".to_vec(),
            br#"{"edge":"a b","player":1,"n":1,"what":"clear"}"#.to_vec(),
            br#"{"edge":"a","player":1,"n":1,"what":"clear","extra":1}"#.to_vec(),
            vec![b' '; MAX_SUBMIT_BYTES + 1],
        ];
        for b in bad {
            assert!(read_submit(&b, SIZE).is_err(), "{}", String::from_utf8_lossy(&b));
        }
        assert!(read_submit(&submit(Wire::Stone { x: 159, y: 89, radius: MAX_RADIUS, big: true }), SIZE).is_ok());
    }

    #[test]
    fn ticks_are_bounded_and_hold_resolved_events_only() {
        let event = |what| Stamped { what, edge: "a".into(), run: 0, n: 0 };
        let good = Tick { step: 9, events: vec![event(Wire::Clear), event(Wire::Shot)], ..Tick::default() };
        assert_eq!(read_tick(&bytes_of(&good), SIZE).unwrap(), good);
        let unresolved = Tick { events: vec![event(Wire::RandomStone { radius: 2 })], ..Tick::default() };
        assert!(read_tick(&bytes_of(&unresolved), SIZE).is_err());
        let many = Tick { events: vec![event(Wire::Clear); MAX_EVENTS_PER_TICK + 1], ..Tick::default() };
        assert!(read_tick(&bytes_of(&many), SIZE).is_err());
    }

    #[test]
    fn names_are_checked() {
        assert_eq!(Names::of("main").unwrap().stream, "tidepool_main_log");
        for bad in ["", "a.b", "a b", "a*", &"x".repeat(MAX_POOL_NAME + 1)] {
            assert!(Names::of(bad).is_err(), "{bad}");
        }
    }
}
