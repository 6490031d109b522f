//! The integer ripple pool of the papers (`docs/ALGORITHMS.md` §1).
//!
//! Two `i16` amplitude buffers; every step replaces the older one with
//! `((N + S + E + W) >> 1) - previous`, then damps it by `v -= v >> shift`, and swaps them.
//! This is the explicit finite-difference wave equation with (c·dt/dx)² = 1/2: waves travel
//! about 0.7 cells per step, reflect at the walls and superpose, and the cost of a step does not
//! depend on how much water is moving.
//!
//! # Integer decisions
//! - The neighbour sum reaches ±131,068, so it is formed in `i32`; the new amplitude is clamped
//!   to the `i16` range *before* damping and stored back. Clamping (rather than wrapping like the
//!   papers' C, or wider storage) keeps the buffers at two bytes a cell, which is what makes the
//!   step fast (it is memory-bound), never panics in a debug build, and never turns a deep pile
//!   of stones into garbage: an over-deep spot simply saturates, and damping (which can only
//!   move a value towards zero) cannot leave the range again.
//! - `>>` on a negative number rounds towards minus infinity, so both the `>> 1` of the spread
//!   and the damping are biased downwards. Damped, a disturbed pool still returns to all-zero;
//!   **undamped ([`Damping::OFF`]) the mean level drifts slowly negative** after a disturbance,
//!   because every odd neighbour sum loses half a unit. That is the papers' arithmetic, kept on
//!   purpose so that tidepool matches them bit for bit.
//! - The outermost ring of cells is a fixed zero wall (the papers' 1-D loop reads across row
//!   ends instead; that defect is not reproduced). Stones are clipped to the interior.

mod damping;
mod stepper;
mod stone;

pub use damping::Damping;
pub use stone::Stone;

use crate::simd::Simd;

/// The ripple pool's state: the current and previous amplitude of every cell.
#[derive(Clone, Debug)]
pub struct RipplePool {
    width: usize,
    height: usize,
    current: Vec<i16>,
    previous: Vec<i16>,
    /// Per row, a bound of the magnitudes in `current` / `previous` (see
    /// [`stepper::RowMax`]): lets the step use 16-bit arithmetic where it is exact.
    current_max: stepper::RowMax,
    previous_max: stepper::RowMax,
    damping: Damping,
    steps: u64,
    scratch: stepper::Scratch,
    /// The instruction set the step runs with.
    simd: Simd,
}

impl RipplePool {
    /// A still pool of `width x height` cells.
    pub fn new(width: usize, height: usize, damping: Damping) -> RipplePool {
        let cells = width * height;
        RipplePool {
            width,
            height,
            current: vec![0; cells],
            previous: vec![0; cells],
            current_max: vec![0; height],
            previous_max: vec![0; height],
            damping,
            steps: 0,
            scratch: Default::default(),
            simd: Simd::detect(),
        }
    }

    /// Width in cells.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in cells.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The current amplitudes, row-major, row 0 at the top.
    pub fn heights(&self) -> &[i16] {
        &self.current
    }

    /// The amplitudes one step ago (the wave equation's second state).
    pub fn previous_heights(&self) -> &[i16] {
        &self.previous
    }

    /// How many steps have run since the pool was made.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The damping in effect.
    pub fn damping(&self) -> Damping {
        self.damping
    }

    /// Puts back the water a snapshot held (`scene/pool/state.rs`): both states and the step
    /// count. Returns `false`, changing nothing, when the sizes differ from this pool's.
    pub(crate) fn restore(&mut self, current: &[i16], previous: &[i16], steps: u64) -> bool {
        if current.len() != self.current.len() || previous.len() != self.previous.len() {
            return false;
        }
        self.current.copy_from_slice(current);
        self.previous.copy_from_slice(previous);
        // Each row's exact largest magnitude is a bound the step accepts (see `RowMax`).
        let bound = |cells: &[i16], row: usize| {
            cells[row * self.width..(row + 1) * self.width].iter().map(|v| v.unsigned_abs()).max().unwrap_or(0)
        };
        for row in 0..self.height {
            self.current_max[row] = bound(&self.current, row);
            self.previous_max[row] = bound(&self.previous, row);
        }
        self.steps = steps;
        true
    }

    /// Changes the damping from the next step on.
    pub fn set_damping(&mut self, damping: Damping) {
        self.damping = damping;
    }

    #[cfg(any(test, feature = "testing"))]
    /// Runs the step with another instruction set this CPU runs (every one gives the same
    /// water; the default is [`Simd::detect`]).
    pub fn set_simd(&mut self, simd: Simd) {
        self.simd = simd;
    }

    /// Stills the water (the step counter keeps counting).
    pub fn clear(&mut self) {
        self.current.fill(0);
        self.previous.fill(0);
        self.current_max.fill(0);
        self.previous_max.fill(0);
    }

    /// Drops a stone into the current buffer, clipped to the interior (the wall stays zero).
    pub fn drop_stone(&mut self, stone: Stone) {
        if self.width < 3 || self.height < 3 {
            return;
        }
        let r = i64::from(stone.radius);
        let r2 = r * r;
        let (cx, cy) = (i64::from(stone.x), i64::from(stone.y));
        let y0 = (cy - r + 1).max(1);
        let y1 = (cy + r - 1).min(self.height as i64 - 2);
        for y in y0..=y1 {
            let dy = y - cy;
            // The widest dx with dx² + dy² < r², found without floating point.
            let room = r2 - dy * dy;
            let mut half = (room as f64).sqrt() as i64;
            while half * half >= room {
                half -= 1;
            }
            while (half + 1) * (half + 1) < room {
                half += 1;
            }
            let x0 = (cx - half).max(1);
            let x1 = (cx + half).min(self.width as i64 - 2);
            if x0 > x1 {
                continue;
            }
            let row = y as usize * self.width;
            self.current[row + x0 as usize..=row + x1 as usize].fill(-stone.weight);
            let bound = &mut self.current_max[y as usize];
            *bound = (*bound).max(stone.weight.unsigned_abs());
        }
    }

    /// Adds a disturbance to the cells of the rectangle `x0..x1 x y0..y1` (clipped to the
    /// interior; the wall stays zero): `amount(x, y)` gives what is added to the current and to
    /// the previous amplitude of cell `(x, y)`, with saturation at the `i16` limits.
    ///
    /// Unlike [`RipplePool::drop_stone`], which sets a dent and so erases the waves under it,
    /// this adds to what is there. Setting the previous state too lets a caller launch waves
    /// that travel one way (the breeze of `PoolSettings::breeze` does).
    pub fn disturb(
        &mut self,
        (x0, y0): (i64, i64),
        (x1, y1): (i64, i64),
        mut amount: impl FnMut(i64, i64) -> (i16, i16),
    ) {
        if self.width < 3 || self.height < 3 {
            return;
        }
        let (x0, x1) = (x0.max(1), x1.min(self.width as i64 - 1));
        let (y0, y1) = (y0.max(1), y1.min(self.height as i64 - 1));
        for y in y0..y1 {
            let row = y as usize * self.width;
            let (mut cur_max, mut prev_max) = (0u16, 0u16);
            for x in x0..x1 {
                let (dc, dp) = amount(x, y);
                let i = row + x as usize;
                self.current[i] = self.current[i].saturating_add(dc);
                self.previous[i] = self.previous[i].saturating_add(dp);
                cur_max = cur_max.max(self.current[i].unsigned_abs());
                prev_max = prev_max.max(self.previous[i].unsigned_abs());
            }
            let y = y as usize;
            self.current_max[y] = self.current_max[y].max(cur_max);
            self.previous_max[y] = self.previous_max[y].max(prev_max);
        }
    }

    #[cfg(any(test, feature = "testing"))]
    /// Advances the water by one step.
    pub fn step(&mut self) {
        self.advance(1);
    }

    /// Advances the water by `steps` steps, as fast as this machine allows (SIMD, temporal
    /// blocking and all cores; see `stepper.rs`). The result is bit-identical to calling
    /// [`RipplePool::step`] `steps` times, on any number of threads.
    pub fn advance(&mut self, steps: u64) {
        stepper::advance(
            (&mut self.current, &mut self.current_max),
            (&mut self.previous, &mut self.previous_max),
            self.width,
            self.height,
            self.damping,
            steps,
            &mut self.scratch,
            self.simd,
        );
        self.steps += steps;
    }
}

#[cfg(test)]
mod tests;
