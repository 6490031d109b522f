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
    /// One colour pass's bytes, written by position ([`colour_pass`]); grown, never cleared.
    pass: Vec<u8>,
    /// For each of the band's six rows, a column's mask of the rows with the same register
    /// when the row is the first of them, otherwise 0 (see [`Band::collect`]).
    masks: Vec<u8>,
    /// The bytes that skip `n` columns (`?` to `???`, then `!n?`), eight bytes and the
    /// length used, for every `n` up to the widest band seen: written as eight bytes and cut,
    /// with no branch on the length.
    skips: Vec<([u8; 8], u8)>,
}

/// The most columns a skip in the table may cover (`!999999?` is eight bytes).
const MAX_SKIP: usize = 999_999;

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
        // A short band's missing rows repeat its last (never used: the mask of rows leaves
        // them out), so every column reads six.
        let rows = rows.clamp(1, 6);
        for dy in rows..6 {
            lines[dy] = lines[rows - 1];
        }
        let mut counts = [0u32; 256];
        let n = self.collect(&lines, rows, w, &mut counts);
        while self.skips.len() <= w.min(MAX_SKIP) {
            let mut code = Vec::with_capacity(8);
            push_run(&mut code, b'?', self.skips.len());
            let mut bytes = [0u8; 8];
            bytes[..code.len()].copy_from_slice(&code);
            self.skips.push((bytes, code.len() as u8));
        }
        // Where each register's entries start, in register order.
        let mut starts = [0u32; 256];
        let mut sum = 0;
        for (start, &n) in starts.iter_mut().zip(&counts) {
            *start = sum;
            sum += n;
        }
        self.sorted.resize(n, 0);
        let mut at = starts;
        for &e in &self.entries[..n] {
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
            let len = colour_pass(&mut self.pass, &self.sorted[start as usize..(start + n) as usize], &self.skips);
            out.extend_from_slice(&self.pass[..len]);
        }
        out.push(b'-');
    }

    /// Writes the band's (register, column, bits) to `entries`, counts them by register in
    /// `counts` and says how many: columns ascending, within a column in the order of each
    /// register's first row.
    ///
    /// In two passes, neither with a branch on the pixels: the first compares, for each row,
    /// every column's register with the five others of its column (a loop along the row, over
    /// bytes, that the compiler vectorizes) and keeps the row's mask of equal rows where the
    /// row is the first of its register (0 elsewhere: a first row's mask holds its own bit);
    /// the second writes each column's six entries always and keeps those with a mask (the
    /// count moved on). One pass doing both a column at a time was scalar, six by six
    /// comparisons a column.
    fn collect(&mut self, lines: &[&[u8]; 6], rows: usize, w: usize, counts: &mut [u32; 256]) -> usize {
        if self.entries.len() < 6 * w {
            self.entries.resize(6 * w, 0);
        }
        self.masks.resize(6 * w, 0);
        let lines: [&[u8]; 6] = lines.map(|line| &line[..w]);
        let valid = (1u8 << rows) - 1;
        for (dy, masks) in self.masks.chunks_exact_mut(w).enumerate() {
            if valid >> dy & 1 == 0 {
                masks.fill(0);
                continue;
            }
            let earlier = (1u8 << dy) - 1;
            // Every slice exactly `w` long, so the loop carries no bounds checks.
            let (masks, line) = (&mut masks[..w], &lines[dy][..w]);
            let [l0, l1, l2, l3, l4, l5] = lines.map(|line| &line[..w]);
            for x in 0..w {
                let c = line[x];
                let same = (u8::from(l0[x] == c)
                    | u8::from(l1[x] == c) << 1
                    | u8::from(l2[x] == c) << 2
                    | u8::from(l3[x] == c) << 3
                    | u8::from(l4[x] == c) << 4
                    | u8::from(l5[x] == c) << 5)
                    & valid;
                masks[x] = if same & earlier == 0 { same } else { 0 };
            }
        }
        // Each row and its masks as a slice of its own, exactly `w` long: indexed through an
        // array of slices, every read was checked against a length loaded from the stack.
        let [l0, l1, l2, l3, l4, l5] = lines;
        let [m0, m1, m2, m3, m4, m5]: [&[u8]; 6] = std::array::from_fn(|dy| &self.masks[dy * w..(dy + 1) * w]);
        let entries = &mut self.entries[..6 * w];
        let mut n = 0;
        for x in 0..w {
            let column =
                [(l0[x], m0[x]), (l1[x], m1[x]), (l2[x], m2[x]), (l3[x], m3[x]), (l4[x], m4[x]), (l5[x], m5[x])];
            for (c, same) in column {
                let kept = u32::from(same != 0);
                entries[n] = u64::from(c) << 32 | (x as u64) << 8 | u64::from(same);
                counts[usize::from(c)] += kept;
                n += kept as usize;
            }
        }
        n
    }
}

/// The most bytes one entry of a colour pass writes: a skip (`!n?`) and a run (`!nx`), each
/// at most `!`, 20 digits and a character.
const MAX_ENTRY_BYTES: usize = 2 * 22;

/// Writes one colour's pass over a band from its covered columns (`column << 8 | sixel bits`,
/// ascending) to the start of `buf` and says how long it is: empty sixels (`?`) up to each
/// covered column, runs of equal sixels as `!n`. `skips`: the bytes of each skip (see
/// [`Band`]). Written by position into a buffer long enough for the worst case, so the loop
/// keeps its length in a register (a `Vec` that grows checked and stored its length at every
/// push).
fn colour_pass(buf: &mut Vec<u8>, cols: &[u32], skips: &[([u8; 8], u8)]) -> usize {
    let most = MAX_ENTRY_BYTES * cols.len() + 8;
    if buf.len() < most {
        buf.resize(most, 0);
    }
    let buf = &mut buf[..most];
    let mut at = 0;
    let mut next = 0usize; // the column the pass has reached
    let mut i = 0;
    while i < cols.len() {
        let (x, sixel) = ((cols[i] >> 8) as usize, cols[i] as u8);
        match skips.get(x - next) {
            Some((bytes, len)) => {
                buf[at..at + 8].copy_from_slice(bytes);
                at += usize::from(*len);
            }
            None => at += write_run(&mut buf[at..], b'?', x - next),
        }
        let mut run = 1;
        while i + run < cols.len() && cols[i + run] == cols[i] + ((run as u32) << 8) {
            run += 1;
        }
        if run < MIN_RUN {
            buf[at..at + MIN_RUN].copy_from_slice(&[63 + sixel; MIN_RUN]);
            at += run;
        } else {
            at += write_run(&mut buf[at..], 63 + sixel, run);
        }
        next = x + run;
        i += run;
    }
    at
}

/// Writes `!n` and `ch` (a run of `n`, at least [`MIN_RUN`]) to the start of `buf` and says
/// how many bytes.
fn write_run(buf: &mut [u8], ch: u8, n: usize) -> usize {
    let (digits, first) = decimal(n);
    let len = digits.len() - first;
    buf[0] = b'!';
    buf[1..1 + len].copy_from_slice(&digits[first..]);
    buf[1 + len] = ch;
    len + 2
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
    let (digits, first) = decimal(v);
    out.extend_from_slice(&digits[first..]);
}

/// The decimal digits of `v`, right-aligned, and where the first is.
fn decimal(v: usize) -> ([u8; 20], usize) {
    let mut digits = [0u8; 20];
    let mut n = v;
    let mut first = digits.len();
    loop {
        first -= 1;
        digits[first] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    (digits, first)
}
