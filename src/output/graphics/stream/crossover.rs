//! `auto`'s choice between real pixels and half-block cells as the link changes.
//!
//! The figures come from `cargo bench --bench pictures` (the fixture pool at 160x48 cells of
//! 8x16 pixels, SSIM over time at the cell area's pixel size; README "Pictures at a rate"):
//! below a protocol's crossover rate the cell codec shows the truer moving picture, above it
//! the protocol does. [`crossover`] is the pure function; [`AutoSwitch`] adds the hysteresis
//! the Screen needs so that a link hovering at the crossover does not flip the mode back and
//! forth: the rate must stay beyond a margin for a while, and switches are spaced.

use std::time::{Duration, Instant};

use super::encode::FULL_PALETTE_RATE;
use crate::output::graphics::GraphicsMode;

/// The link rate (bytes per second) above which each protocol's pictures score a higher SSIM
/// over time than the cell codec's, measured by `cargo bench --bench pictures` (see the module
/// documentation). `None`: the protocol never won below unlimited there.
pub fn crossover(mode: GraphicsMode) -> Option<f64> {
    match mode {
        GraphicsMode::Kitty => Some(KITTY_CROSSOVER),
        GraphicsMode::Sixel => SIXEL_CROSSOVER,
        GraphicsMode::Iterm2 => Some(ITERM2_CROSSOVER),
        GraphicsMode::Cells => None,
    }
}

/// kitty's crossover, bytes per second (see [`crossover`]): at 50 kB/s, the lowest rate
/// measured, kitty already scored SSIM 0.583 against the cells' 0.519 (250 kB/s: 0.603), so the
/// crossover is at or below it; 50 kB/s is taken until lower rates are measured.
const KITTY_CROSSOVER: f64 = 50_000.0;
/// sixel's crossover, bytes per second: it wins only where its pictures are the screen's own
/// size with the terminal's whole palette, as without a rate (SSIM over time 0.706 against the
/// cells' 0.671 unlimited, the mean of the frames it draws, 0.894, and the frames between,
/// 0.518), which it fits from [`FULL_PALETTE_RATE`] on. Below it cells: 0.58 against 0.63 at 2
/// MB/s, 0.61/0.66 at 4 MB/s, 0.57/0.67 at 8 MB/s, 0.64/0.67 at 16-24 MB/s (32 colours; the
/// pictures cost more bytes a pixel than cells' half blocks); docs/pixels/cpu.md, Round 5.
const SIXEL_CROSSOVER: Option<f64> = Some(FULL_PALETTE_RATE);
/// iTerm2's crossover, bytes per second: JPEG won at 50 kB/s (0.604 against 0.519) and at
/// 250 kB/s (0.664).
const ITERM2_CROSSOVER: f64 = 50_000.0;

/// The mode that shows the truer moving picture at `rate` (bytes per second; `None`: no limit,
/// the terminal is local) when the terminal can show `pixels`: pictures at or above the
/// crossover, cells below it.
pub fn truer_mode(pixels: GraphicsMode, rate: Option<f64>) -> GraphicsMode {
    match (rate, crossover(pixels)) {
        (None, _) => pixels,
        (Some(_), None) => GraphicsMode::Cells,
        (Some(rate), Some(at)) if rate >= at => pixels,
        _ => GraphicsMode::Cells,
    }
}

/// `auto`'s mode over time: `truer_mode` with hysteresis. Clock-injected, so tests run on
/// made-up time.
#[derive(Clone, Debug)]
pub struct AutoSwitch {
    pixels: GraphicsMode,
    current: GraphicsMode,
    /// Since when the rate has been beyond the margin towards the other mode.
    leaning: Option<Instant>,
    last_switch: Option<Instant>,
    /// The pictures do not cross the link (see [`AutoSwitch::local`]): never leave them.
    local: bool,
}

impl AutoSwitch {
    /// How far past the crossover the rate must go before the mode switches (a ratio).
    pub const MARGIN: f64 = 1.25;
    /// How long the rate must stay past the margin before the mode switches.
    pub const HOLD: Duration = Duration::from_secs(3);
    /// The least time between two switches.
    pub const MIN_BETWEEN: Duration = Duration::from_secs(10);

    /// Starts in the truer mode at `rate` when the rate is known (a fixed `--bandwidth`),
    /// else in `pixels` (the protocol the probe found): a local terminal keeps it, and a slow
    /// link is measured before it is left.
    pub fn new(pixels: GraphicsMode, rate: Option<f64>) -> AutoSwitch {
        let current = rate.map_or(pixels, |r| truer_mode(pixels, Some(r)));
        AutoSwitch { pixels, current, leaning: None, last_switch: None, local: false }
    }

    /// Pixels whatever the link's rate, for a terminal whose pictures do not cross the link:
    /// kitty reading them from temporary files on this machine sends about 130 bytes a picture
    /// down the pty, so no rate makes cells truer. The rate a local terminal is measured at
    /// says how fast it reads and draws, not what a picture costs: kitty 0.26 under Xvfb with
    /// software OpenGL answered late while drawing and was measured at the link's floor
    /// (2 kB/s), and the plain switch then left its full-size pictures for half-block cells
    /// crawling in at 2 kB/s (`docs/terminals/pictures-at-a-rate.md`).
    pub fn local(pixels: GraphicsMode) -> AutoSwitch {
        AutoSwitch { local: true, ..AutoSwitch::new(pixels, None) }
    }

    /// The mode in force.
    pub fn mode(&self) -> GraphicsMode {
        self.current
    }

    /// The mode after the link was measured at `rate` at `now` (`None`: unlimited): it changes
    /// only when the rate has stayed [`AutoSwitch::MARGIN`] beyond the crossover for
    /// [`AutoSwitch::HOLD`] and the last switch is [`AutoSwitch::MIN_BETWEEN`] ago. Returns the mode and whether it just changed (the Screen
    /// says so on the status line for a few seconds).
    pub fn update(&mut self, rate: Option<f64>, now: Instant) -> (GraphicsMode, bool) {
        if self.local {
            return (self.current, false);
        }
        // No crossover: cells win at any limited rate, pixels only without a limit.
        let at = crossover(self.pixels).unwrap_or(f64::INFINITY);
        let other = if self.current == self.pixels { GraphicsMode::Cells } else { self.pixels };
        let beyond = match (other == self.pixels, rate) {
            (true, None) => true,
            (true, Some(r)) => r >= at * Self::MARGIN,
            (false, None) => false,
            (false, Some(r)) => r < at / Self::MARGIN,
        };
        if !beyond {
            self.leaning = None;
            return (self.current, false);
        }
        let since = *self.leaning.get_or_insert(now);
        let spaced = self.last_switch.is_none_or(|t| now.saturating_duration_since(t) >= Self::MIN_BETWEEN);
        // Back to a local terminal's pixels at once: nothing to wait for.
        let held = rate.is_none() || now.saturating_duration_since(since) >= Self::HOLD;
        if held && spaced {
            self.current = other;
            self.leaning = None;
            self.last_switch = Some(now);
            return (self.current, true);
        }
        (self.current, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locally_pixels_and_on_a_slow_link_cells() {
        assert_eq!(truer_mode(GraphicsMode::Sixel, None), GraphicsMode::Sixel, "locally pixels");
        for mode in [GraphicsMode::Kitty, GraphicsMode::Iterm2, GraphicsMode::Sixel] {
            let at = crossover(mode).unwrap();
            assert_eq!(truer_mode(mode, None), mode);
            assert_eq!(truer_mode(mode, Some(at * 2.0)), mode);
            assert_eq!(truer_mode(mode, Some(at / 2.0)), GraphicsMode::Cells);
        }
        assert_eq!(truer_mode(GraphicsMode::Cells, None), GraphicsMode::Cells);
    }

    /// The pictures bench's table (docs/pixels/cpu.md, Round 5): sixel loses to cells at every
    /// rate it was measured at below 32 MB/s and wins from there (its whole palette, as
    /// unlimited).
    #[test]
    fn sixel_wins_where_the_pictures_bench_measured_it_winning() {
        for rate in [50e3, 250e3, 2e6, 4e6, 8e6, 16e6, 24e6] {
            assert_eq!(truer_mode(GraphicsMode::Sixel, Some(rate)), GraphicsMode::Cells, "{rate} B/s");
        }
        for rate in [32e6, 48e6] {
            assert_eq!(truer_mode(GraphicsMode::Sixel, Some(rate)), GraphicsMode::Sixel, "{rate} B/s");
        }
        // A link measured past the crossover (with the margin) leaves cells for sixel.
        let t0 = Instant::now();
        let mut auto = AutoSwitch::new(GraphicsMode::Sixel, Some(2e6));
        assert_eq!(auto.mode(), GraphicsMode::Cells);
        assert_eq!(auto.update(Some(48e6), t0).0, GraphicsMode::Cells, "not before HOLD");
        assert_eq!(auto.update(Some(48e6), t0 + AutoSwitch::HOLD), (GraphicsMode::Sixel, true));
    }

    #[test]
    fn the_switch_waits_for_a_steady_rate_and_does_not_flap() {
        let t0 = Instant::now();
        let at = crossover(GraphicsMode::Kitty).unwrap();
        let mut auto = AutoSwitch::new(GraphicsMode::Kitty, None);
        let s = |secs: f64| t0 + Duration::from_secs_f64(secs);
        // A rate hovering around the crossover (within the margin) never switches.
        for i in 0..100 {
            let rate = if i % 2 == 0 { at * 1.1 } else { at * 0.9 };
            assert_eq!(auto.update(Some(rate), s(f64::from(i) * 0.5)), (GraphicsMode::Kitty, false), "step {i}");
        }
        // A slow link: cells after HOLD, not before.
        let slow = Some(at / 4.0);
        assert_eq!(auto.update(slow, s(60.0)).0, GraphicsMode::Kitty);
        assert_eq!(auto.update(slow, s(62.0)).0, GraphicsMode::Kitty);
        assert_eq!(auto.update(slow, s(63.0)), (GraphicsMode::Cells, true));
        // The link recovers at once, but the switch back waits MIN_BETWEEN after the last.
        let fast = Some(at * 4.0);
        assert_eq!(auto.update(fast, s(64.0)).0, GraphicsMode::Cells);
        assert_eq!(auto.update(fast, s(67.5)).0, GraphicsMode::Cells, "held, but too soon after a switch");
        assert_eq!(auto.update(fast, s(73.0)), (GraphicsMode::Kitty, true));
        // A dip shorter than HOLD does not switch.
        assert_eq!(auto.update(slow, s(90.0)).0, GraphicsMode::Kitty);
        assert_eq!(auto.update(fast, s(92.0)).0, GraphicsMode::Kitty);
        assert_eq!(auto.update(slow, s(93.0)).0, GraphicsMode::Kitty, "the dip's clock started over");
    }

    #[test]
    fn a_local_terminal_keeps_its_pixels_at_any_rate() {
        let t0 = Instant::now();
        let mut auto = AutoSwitch::local(GraphicsMode::Kitty);
        for i in 0..100u32 {
            let now = t0 + Duration::from_millis(500) * i;
            assert_eq!(auto.update(Some(2_000.0), now), (GraphicsMode::Kitty, false), "step {i}");
        }
    }
}
