//! The sixel encoder's palette: the colours of its registers, as the percentages sixel defines
//! them with. Either an evenly spaced RGB cube ([`SixelPalette::for_registers`]: what is used
//! before a picture is seen) or colours fitted to a picture ([`SixelPalette::fit`]: median
//! cut and k-means in OKLab, see `fit.rs`).

use super::{MAX_REGISTERS, MIN_REGISTERS, fit};

/// The colours of the registers, in percent (what the stream defines), at most 256.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SixelPalette {
    percent: Vec<[u8; 3]>,
    /// The registers the terminal offers (clamped to 8..=256): what a refit may use.
    registers: u16,
}

impl SixelPalette {
    /// The largest RGB cube that fits in `registers` (clamped to 8..=256): levels are added
    /// green, red, blue in turn while they fit, so 256 registers give 6x7x6, 64 give 4x4x4,
    /// 16 give 2x4x2. Blue varies fastest (register `r * lg * lb + g * lb + b`).
    pub fn for_registers(registers: u16) -> SixelPalette {
        let registers = registers.clamp(MIN_REGISTERS, MAX_REGISTERS);
        let n = u32::from(registers);
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
        // Level i of n levels in percent, rounded half up.
        let level = |i: u32, n: u32| ((200 * i + n - 1) / (2 * (n - 1))) as u8;
        let [lr, lg, lb] = levels;
        let mut percent = Vec::with_capacity(n as usize);
        for r in 0..lr {
            for g in 0..lg {
                for b in 0..lb {
                    percent.push([level(r, lr), level(g, lg), level(b, lb)]);
                }
            }
        }
        SixelPalette { percent, registers }
    }

    /// At most `registers` (clamped to 8..=256) colours fitted to the picture `pixels` (`bpp`
    /// bytes a pixel, RGB first): see `fit.rs`. Colours that round to the same
    /// percentages are kept once.
    pub fn fit(pixels: &[u8], bpp: usize, registers: u16) -> SixelPalette {
        let registers = registers.clamp(MIN_REGISTERS, MAX_REGISTERS);
        let colours = fit::fit(&fit::subsample(pixels, bpp), usize::from(registers));
        let mut percent: Vec<[u8; 3]> = Vec::with_capacity(colours.len());
        for c in colours {
            let p = c.map(|v| ((u32::from(v) * 100 + 127) / 255) as u8);
            if !percent.contains(&p) {
                percent.push(p);
            }
        }
        if percent.is_empty() {
            percent.push([0, 0, 0]);
        }
        SixelPalette { percent, registers }
    }

    /// The registers the palette was made for (what a refit may use).
    pub fn registers(&self) -> u16 {
        self.registers
    }

    /// Number of colours.
    pub fn len(&self) -> usize {
        self.percent.len()
    }

    #[cfg(any(test, feature = "testing"))]
    /// Whether the palette is empty (never: at least one colour).
    pub fn is_empty(&self) -> bool {
        self.percent.is_empty()
    }

    /// The register's colour in percent (what the stream defines).
    pub fn percent_rgb(&self, index: u8) -> [u8; 3] {
        self.percent[usize::from(index)]
    }

    /// The register's colour as the terminal shows it: `(p * 255 + 50) / 100`, as xterm.
    pub fn rgb(&self, index: u8) -> [u8; 3] {
        self.percent_rgb(index).map(|p| ((u32::from(p) * 255 + 50) / 100) as u8)
    }
}
