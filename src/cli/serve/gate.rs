//! Which of a player's requests reach the shared game. Stones and stirs pass under the player's
//! actions bucket; scene keys (rain, clear, damping, pause, wind, `tab`), which cost the one game
//! thread more, under a bucket of their own per player and one for all players together; then
//! the game's bounded queue. Whatever is refused is dropped, never queued.

use std::sync::atomic::Ordering;
use std::time::Instant;

use crate::Action;
use crate::output::bucket::ByteBucket;
use crate::play::Request;

use super::hub::Hub;
use super::limits::Limits;

/// What became of a request.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Gated {
    /// Sent to the game; `scene_key` when it was one.
    Sent { scene_key: bool },
    /// Refused by a rate limit or a full queue.
    Dropped,
}

/// One player's buckets.
pub struct RequestGate {
    player: u64,
    actions: ByteBucket,
    scene_keys: ByteBucket,
}

/// Whether a request costs the game thread more than a stone.
fn costs_the_game(request: &Request) -> bool {
    !matches!(request, Request::RandomStone { .. } | Request::Act(Action::Stone { .. } | Action::Stir { .. }))
}

impl RequestGate {
    /// Player `player`'s full buckets at `limits`.
    pub fn new(limits: &Limits, player: u64) -> RequestGate {
        RequestGate { player, actions: limits.actions_bucket(), scene_keys: limits.scene_keys_bucket() }
    }

    /// Sends `request` to `hub`'s game if the limits allow it now; counts what is dropped.
    pub fn send(&mut self, request: Request, hub: &Hub, now: Instant) -> Gated {
        let scene_key = costs_the_game(&request);
        let allowed = if scene_key {
            let ok = self.scene_keys.try_take(1.0, now)
                && hub.scene_keys.lock().unwrap_or_else(|p| p.into_inner()).try_take(1.0, now);
            if !ok {
                hub.stats.scene_keys_dropped.fetch_add(1, Ordering::Relaxed);
            }
            ok
        } else {
            let ok = self.actions.try_take(1.0, now);
            if !ok {
                hub.stats.actions_dropped.fetch_add(1, Ordering::Relaxed);
            }
            ok
        };
        if !allowed {
            return Gated::Dropped;
        }
        if hub.requests.try_send((self.player, request)).is_err() {
            hub.stats.actions_dropped.fetch_add(1, Ordering::Relaxed);
            return Gated::Dropped;
        }
        Gated::Sent { scene_key }
    }
}
