//! One six-row band of a sixel image: every register the band uses gets one colour pass
//! (`#n`, its sixels from its first to its last column, `$` back to the band's start), in
//! register order, runs of [`MIN_RUN`] or more equal sixels written `!n`.
//!
//! **One pass over the pixels.** Each column's (at most six) registers and the bits of the
//! rows each covers are found by comparing the column's six registers with each other (no
//! search per pixel), and every (register, column, bits) entry goes to one flat list in column
//! order, counted by register; a counting sort then lays the entries out register by register,
//! each register's columns still ascending. The colour passes read that list in order. The
//! cost grows with the pixels and the entries, never with pixels x colours, and no list per
//! register is touched (256 of them, one push each per entry, was a fifth of the encoder).

/// A run of this many equal sixels or more is written `!n` (`!4x` is shorter than `xxxx`).
const MIN_RUN: usize = 4;

/// The band writer's scratch, kept between bands and pictures.
#[derive(Debug, Default)]
pub struct Band {
    /// The band's entries in column order: `register << 32 | column << 8 | bits`.
    entries: Vec<u64>,
    /// The same entries by register, then column: `column << 8 | bits`.
    sorted: Vec<u32>,
}

/// What the band's registers need from the image: each register's definition (`;2;r;g;b`)
/// and whether it is defined already (in this image, or in this session).
pub struct Definitions<'a> {
    pub definitions: &'a [Vec<u8>],
    pub defined: &'a mut [bool],
}

impl Band {
    /// Appends the band `(x0, y, w, rows)` (at most six rows) of `pixels` (`stride` registers
    /// a row), each register defined where first used when it is not defined yet, then the
    /// band's end (`-`).
    pub fn push(
        &mut self,
        out: &mut Vec<u8>,
        pixels: &[u8],
        stride: usize,
        (x0, y, w, rows): (usize, usize, usize, usize),
        registers: Definitions<'_>,
    ) {
        let mut lines: [&[u8]; 6] = [&[]; 6];
        for (dy, line) in lines.iter_mut().enumerate().take(rows.min(6)) {
            let start = (y + dy) * stride + x0;
            *line = &pixels[start..start + w];
        }
        let mut counts = [0u32; 256];
        self.collect(&lines, rows.min(6), w, &mut counts);
        // Where each register's entries start, in register order.
        let mut starts = [0u32; 256];
        let mut sum = 0;
        for (start, &n) in starts.iter_mut().zip(&counts) {
            *start = sum;
            sum += n;
        }
        self.sorted.resize(self.entries.len(), 0);
        let mut at = starts;
        for &e in &self.entries {
            let r = (e >> 32) as usize;
            self.sorted[at[r] as usize] = e as u32;
            at[r] += 1;
        }
        let mut first = true;
        for (c, (&start, &n)) in starts.iter().zip(&counts).enumerate().filter(|(_, (_, n))| **n > 0) {
            if !first {
                out.push(b'$');
            }
            first = false;
            out.push(b'#');
            push_decimal(out, c);
            if !registers.defined[c] {
                // Defined, then selected: xterm's `#Pc;2;...` only defines (DEC's selects
                // too), and the band would be drawn in the register selected before.
                out.extend_from_slice(&registers.definitions[c]);
                out.push(b'#');
                push_decimal(out, c);
                registers.defined[c] = true;
            }
            push_colour_pass(out, &self.sorted[start as usize..(start + n) as usize]);
        }
        out.push(b'-');
    }

    /// Fills `entries` with the band's (register, column, bits), columns ascending and within a
    /// column in the order of each register's first row, and counts them by register.
    fn collect(&mut self, lines: &[&[u8]; 6], rows: usize, w: usize, counts: &mut [u32; 256]) {
        self.entries.clear();
        for x in 0..w {
            // The column's registers (a short band's missing rows are never read: `left`
            // holds only the rows it has).
            let mut px = [0u8; 6];
            for (p, line) in px.iter_mut().zip(&lines[..rows]) {
                *p = line[x];
            }
            let mut left = (1u8 << rows) - 1;
            while left != 0 {
                let c = px[left.trailing_zeros() as usize];
                let same = px.iter().enumerate().fold(0u8, |m, (dy, &p)| m | u8::from(p == c) << dy);
                let bits = same & left;
                left &= !bits;
                counts[usize::from(c)] += 1;
                self.entries.push(u64::from(c) << 32 | (x as u64) << 8 | u64::from(bits));
            }
        }
    }
}

/// Appends one colour's pass over a band from its covered columns (`column << 8 | sixel bits`,
/// ascending): empty sixels (`?`) up to each covered column, runs of equal sixels as `!n`.
fn push_colour_pass(out: &mut Vec<u8>, cols: &[u32]) {
    let mut next = 0usize; // the column the pass has reached
    let mut i = 0;
    while i < cols.len() {
        let (x, sixel) = ((cols[i] >> 8) as usize, cols[i] as u8);
        push_run(out, b'?', x - next);
        let mut run = 1;
        while i + run < cols.len() && cols[i + run] == cols[i] + ((run as u32) << 8) {
            run += 1;
        }
        push_run(out, 63 + sixel, run);
        next = x + run;
        i += run;
    }
}

/// Appends `n` copies of the sixel character `ch`.
#[inline]
fn push_run(out: &mut Vec<u8>, ch: u8, n: usize) {
    if n >= MIN_RUN {
        out.push(b'!');
        push_decimal(out, n);
        out.push(ch);
    } else {
        // Byte by byte: a slice of variable length is a call to memcpy.
        for _ in 0..n {
            out.push(ch);
        }
    }
}

/// Appends `v` in decimal.
pub fn push_decimal(out: &mut Vec<u8>, v: usize) {
    // Run lengths and registers are mostly one or two digits.
    if v < 10 {
        out.push(b'0' + v as u8);
        return;
    }
    if v < 100 {
        out.push(b'0' + (v / 10) as u8);
        out.push(b'0' + (v % 10) as u8);
        return;
    }
    let mut digits = [0u8; 20];
    let mut n = v;
    let mut i = digits.len();
    loop {
        i -= 1;
        digits[i] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    out.extend_from_slice(&digits[i..]);
}
