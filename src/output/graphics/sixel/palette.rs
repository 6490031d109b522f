//! The sixel encoder's fixed palette: an evenly spaced RGB cube of colour registers, and the
//! tables that dither each channel between its two nearest levels (see the encoder's module
//! documentation for why the palette is fixed and the dither ordered).

use super::{MAX_REGISTERS, MIN_REGISTERS};

/// An RGB cube of colour registers.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SixelPalette {
    /// Levels of red, green and blue.
    levels: [u8; 3],
}

impl SixelPalette {
    /// The largest cube that fits in `registers` (clamped to 8..=
    /// 256): levels are added green, red, blue in turn while they fit, so 256
    /// registers give 6x7x6, 64 give 4x4x4, 16 give 2x4x2.
    pub fn for_registers(registers: u16) -> SixelPalette {
        let n = u32::from(registers.clamp(MIN_REGISTERS, MAX_REGISTERS));
        let mut levels = [2u32; 3];
        loop {
            let mut grew = false;
            for channel in [1, 0, 2] {
                let mut bigger = levels;
                bigger[channel] += 1;
                if bigger.iter().product::<u32>() <= n {
                    levels = bigger;
                    grew = true;
                }
            }
            if !grew {
                break;
            }
        }
        SixelPalette { levels: levels.map(|l| l as u8) }
    }

    /// Levels of red, green and blue.
    pub fn levels(&self) -> [u8; 3] {
        self.levels
    }

    /// Number of colours.
    pub fn len(&self) -> usize {
        self.levels.iter().map(|&l| usize::from(l)).product()
    }

    /// Whether the palette is empty (never: at least 2 levels a channel).
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Level `i` of a channel with `levels` levels, in percent as sixel colour registers take it.
    fn percent(i: u8, levels: u8) -> u8 {
        ((200 * u32::from(i) + u32::from(levels) - 1) / (2 * (u32::from(levels) - 1))) as u8
    }

    /// The 0..=255 value a terminal makes of a percentage: `(p * 255 + 50) / 100`, as xterm.
    fn value(percent: u8) -> u8 {
        ((u32::from(percent) * 255 + 50) / 100) as u8
    }

    /// The register's colour in percent (what the stream defines).
    pub fn percent_rgb(&self, index: u8) -> [u8; 3] {
        let [lr, lg, lb] = self.levels;
        let i = index as usize;
        let (r, g, b) =
            (i / (usize::from(lg) * usize::from(lb)), i / usize::from(lb) % usize::from(lg), i % usize::from(lb));
        [Self::percent(r as u8, lr), Self::percent(g as u8, lg), Self::percent(b as u8, lb)]
    }

    /// The register's colour as the terminal shows it.
    pub fn rgb(&self, index: u8) -> [u8; 3] {
        self.percent_rgb(index).map(Self::value)
    }

    /// For each channel, Bayer threshold and value: the channel's share of the register index.
    pub(super) fn tables(&self) -> Vec<[[u8; 256]; 64]> {
        let [_, lg, lb] = self.levels.map(u16::from);
        let strides = [lg * lb, lb, 1];
        (0..3)
            .map(|c| {
                let levels = self.levels[c];
                let values: Vec<u16> = (0..levels).map(|i| u16::from(Self::value(Self::percent(i, levels)))).collect();
                let mut table = [[0u8; 256]; 64];
                for (t, row) in table.iter_mut().enumerate() {
                    for (v, entry) in row.iter_mut().enumerate() {
                        let v = v as u16;
                        // The level just below (or at) v, and whether v rounds up at threshold t:
                        // up when the fraction of the step exceeds (t + 0.5) / 64.
                        let lo = values.iter().rposition(|&l| l <= v).unwrap_or(0);
                        let level = if lo + 1 < values.len() {
                            let (a, b) = (values[lo], values[lo + 1]);
                            let up = 128 * (v - a) > (2 * t as u16 + 1) * (b - a);
                            lo + usize::from(up)
                        } else {
                            lo
                        };
                        *entry = (level as u16 * strides[c]) as u8;
                    }
                }
                table
            })
            .collect()
    }
}
