//! The buffers a frame is encoded in, shared by every screen of the process.
//!
//! The rate encoder's per-cell buffers (about 200 bytes a cell: its candidates, measures,
//! colour memos and layouts; 1.3 MB at 160x48), the composed frame and the frame's bytes are
//! scratch: nothing in them changes what the next frame sends (`RateEncoder` says so of its
//! own). A screen that kept its own would hold them as long as it lives, and a crowd's players
//! (`tidepool serve`) that leave their group's step held about a megabyte each for it
//! (issue 31). So a screen borrows a [`Scratch`] for the length of one frame and gives it back:
//! the process holds as many as frames are encoded at once (its threads), each grown to the
//! largest frame it met, and never more than [`MAX_SPARE`] spare ones.

use std::sync::Mutex;

use super::compose::{CellsPicture, FrameBuilder};
use crate::output::rate::RateEncoder;

/// Spare scratches kept at most (more than the threads that encode at once on any machine
/// this serves from; one given back beyond it is freed).
const MAX_SPARE: usize = 16;

/// One frame's buffers.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    /// The rate encoder (scratch buffers only).
    pub encoder: RateEncoder,
    /// The composed frame.
    pub builder: FrameBuilder,
    /// The frame's bytes before they are handed out.
    pub bytes: Vec<u8>,
    /// The picture resampled to the cells' size when a frame brings another size.
    pub cells_picture: CellsPicture,
}

static SPARE: Mutex<Vec<Scratch>> = Mutex::new(Vec::new());

/// A scratch for one frame: a spare one, or a new one (empty: it grows as it is used).
pub(crate) fn take() -> Scratch {
    SPARE.lock().unwrap_or_else(|p| p.into_inner()).pop().unwrap_or_default()
}

/// Gives `scratch` back for the next frame (of any screen).
pub(crate) fn give(scratch: Scratch) {
    let mut spare = SPARE.lock().unwrap_or_else(|p| p.into_inner());
    if spare.len() < MAX_SPARE {
        spare.push(scratch);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scratch_given_back_is_taken_again_and_the_spares_are_bounded() {
        // Other tests of this binary take and give scratches concurrently: look for the
        // marked buffer among all the spares.
        let mut marked = take();
        marked.bytes = Vec::with_capacity(12_345);
        give(marked);
        let mut taken: Vec<Scratch> = (0..MAX_SPARE + 4).map(|_| take()).collect();
        assert!(taken.iter().any(|s| s.bytes.capacity() == 12_345), "the buffer given back came back");
        taken.iter_mut().for_each(|s| s.bytes = Vec::with_capacity(1));
        taken.into_iter().for_each(give);
        let spare = SPARE.lock().unwrap().len();
        assert!(spare <= MAX_SPARE, "{spare} spares kept, at most {MAX_SPARE}");
    }
}
