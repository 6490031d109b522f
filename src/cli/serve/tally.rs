//! What one player's game did, counted as it plays and written as one log line when it leaves.

use std::net::SocketAddr;

use crate::play::group::Membership;

use super::game::SharedFrame;
use super::gate::Gated;
use super::leave::Leave;

/// One player's counts.
#[derive(Default)]
pub struct Tally {
    first: Option<u64>,
    last: u64,
    /// Frames sent, and of them the group's bytes.
    pub sent: u64,
    pub from_group: u64,
    skipped: u64,
    /// Bytes sent.
    pub bytes: u64,
    /// Requests sent to the game, and dropped by a rate limit or a full queue.
    actions: u64,
    dropped: u64,
    /// Of the requests sent, scene keys.
    scene_keys: u64,
    /// New terminal sizes taken.
    pub resizes: u64,
}

impl Tally {
    /// A frame of `shared` is being drawn: pictures published since the last one were skipped.
    pub fn count(&mut self, shared: &SharedFrame) {
        self.first.get_or_insert(shared.number);
        if self.last != 0 && shared.number > self.last + 1 {
            self.skipped += shared.number - self.last - 1;
        }
        self.last = self.last.max(shared.number);
    }

    /// A request went through the gate.
    pub fn request(&mut self, gated: Gated) {
        match gated {
            Gated::Sent { scene_key } => {
                self.actions += 1;
                self.scene_keys += u64::from(scene_key);
            }
            Gated::Dropped => self.dropped += 1,
        }
    }

    /// The pictures skipped in all, with those published after the last one drawn.
    pub fn skipped(&self, published: u64) -> u64 {
        self.skipped + if self.last != 0 { published.saturating_sub(self.last) } else { 0 }
    }

    /// The closing log line of player `id` from `peer`, `published` frames having been
    /// published when it left; `rate` is its link's rate in bytes a second, if found.
    pub fn report(
        &self,
        peer: SocketAddr,
        id: u64,
        reason: Leave,
        published: u64,
        rate: Option<f64>,
        membership: &Membership,
    ) -> String {
        let group = membership.stats();
        let skipped = self.skipped(published);
        let seen = self.first.map_or(0, |first| published.saturating_sub(first) + 1);
        format!(
            "serve: {peer} #{id} left ({}): {} frames sent ({} from its group), {skipped} skipped of {seen} published, {} bytes, \
             {} actions taken, {} dropped, {} scene keys taken, {} new sizes; link {} B/s; joined its group {} times, \
             left it {} times for an overlay, {} behind, {} for another group",
            reason.name(),
            self.sent,
            self.from_group,
            self.bytes,
            self.actions - self.scene_keys,
            self.dropped,
            self.scene_keys,
            self.resizes,
            rate.map_or(-1, |r| r as i64),
            group.joined,
            group.left_for_overlay,
            group.left_behind,
            group.left_for_key,
        )
    }
}
