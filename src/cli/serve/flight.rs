//! A player's frames in flight, counted in bytes: handed to russh and not yet taken into its
//! write buffer.
//!
//! Why: russh's `data_bytes` returns once a frame sits in the session's queue
//! (`SESSION_EVENT_QUEUE` messages), not once it is written. A player's task that built its next
//! frame as soon as that call returned could leave up to four frames waiting there, and on a
//! busy machine (the sessions' tasks behind) hundreds of players did: the edge's bytes in use
//! moved 50 to 54 MB with the machine's load (issue 31, bus.md rounds 8 and 9). Each frame's
//! bytes are therefore carried in a [`Bytes`] that counts them until russh lets the last slice
//! go (it drops a chunk once it has encrypted it into its write buffer, or when the session
//! ends), and the player builds a frame only while its earlier frames hold fewer than
//! [`FLIGHT_BUDGET_BYTES`]. A picture that comes meanwhile is not queued: the player takes the
//! newest one when its bytes have landed. A key's frame waits behind at most the budget (and the
//! one frame that may exceed it), never behind more than russh's queue held before.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use bytes::Bytes;
use tokio::sync::Notify;

/// A player builds a new frame only while its earlier frames hold fewer bytes than this in
/// russh. Small frames (a key's echo, a cursor) still go back to back; a frame of the water at
/// 80x24 (7 to 30 kB at the scale run's rates) goes when the one before it has been taken. So a
/// player holds at most this plus one frame.
pub const FLIGHT_BUDGET_BYTES: usize = 16 * 1024;

/// Every player's bytes in flight in this process, for the bus's trace (`bus-trace trim`).
static ALL: AtomicUsize = AtomicUsize::new(0);

/// The bytes in flight of all players of this process (the bus's trace reads it).
#[cfg(feature = "bus")]
pub fn all_in_flight() -> usize {
    ALL.load(Ordering::Relaxed)
}

/// One player's count of bytes in flight and the wake-up when some land.
#[derive(Default)]
struct Count {
    bytes: AtomicUsize,
    landed: Notify,
}

/// One player's frames in flight (cheap to clone: the count is shared with its frames).
#[derive(Clone, Default)]
pub(crate) struct Flight(Arc<Count>);

impl Flight {
    /// `frame` copied out at its own size, counted until russh lets it go.
    pub fn carry(&self, frame: &[u8]) -> Bytes {
        if frame.is_empty() {
            return Bytes::new();
        }
        self.0.bytes.fetch_add(frame.len(), Ordering::Relaxed);
        ALL.fetch_add(frame.len(), Ordering::Relaxed);
        Bytes::from_owner(Carried { frame: frame.into(), count: self.0.clone() })
    }

    /// This player's bytes handed over and not yet let go.
    pub fn bytes(&self) -> usize {
        self.0.bytes.load(Ordering::Relaxed)
    }

    /// Whether a new frame may be built now (its earlier frames hold less than the budget).
    pub fn has_room(&self) -> bool {
        self.bytes() < FLIGHT_BUDGET_BYTES
    }

    /// Resolves when some of the bytes have landed since the last call (or at once if they did
    /// before it: the wake-up is kept).
    pub async fn landed(&self) {
        self.0.landed.notified().await;
    }
}

/// A frame's bytes and the count they leave when the last slice of them is dropped.
struct Carried {
    frame: Box<[u8]>,
    count: Arc<Count>,
}

impl AsRef<[u8]> for Carried {
    fn as_ref(&self) -> &[u8] {
        &self.frame
    }
}

impl Drop for Carried {
    fn drop(&mut self) {
        self.count.bytes.fetch_sub(self.frame.len(), Ordering::Relaxed);
        ALL.fetch_sub(self.frame.len(), Ordering::Relaxed);
        self.count.landed.notify_one();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_counts_until_its_last_slice_is_dropped() {
        let flight = Flight::default();
        let frame = flight.carry(&[7; 20_000]);
        assert_eq!(flight.bytes(), 20_000);
        assert!(!flight.has_room());
        // russh splits a frame into packets: slices of the same bytes.
        let (head, tail) = (frame.slice(..10_000), frame.slice(10_000..));
        drop(frame);
        drop(head);
        assert_eq!(flight.bytes(), 20_000, "a slice still holds the frame");
        drop(tail);
        assert_eq!(flight.bytes(), 0);
        assert!(flight.has_room());
        assert!(flight.carry(&[]).is_empty());
        assert_eq!(flight.bytes(), 0);
    }
}
