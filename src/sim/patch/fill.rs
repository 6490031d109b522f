//! The packed spectra of a moment's real fields: two real fields to a complex transform.

use super::*;

/// One row of each of a fill's buffers.
type Rows<'a> = Vec<&'a mut [Complex32]>;

impl Lattice {
    /// For each of `N` pairs of real fields, the spectrum one complex inverse transform turns
    /// into the pair, into `bufs` (resized to the lattice; old contents do not matter).
    /// `coefficients(i, w)` gives, for the travelling wave w = a·e^(iφ)·e^(-iωt) at lattice
    /// point i, the coefficients (c_f, c_g) of each pair's two fields f = re Σ c_f·e^(ik·x)
    /// and g = re Σ c_g·e^(ik·x). A real field's spectrum is the Hermitian
    /// S(k) = (c(k) + conj(c(-k)))/2, and the transform of S_f + i·S_g is f + i·g.
    ///
    /// Filled in the lattice's order, row by row (no index needs a division, and the reads
    /// run along rows: walking columns missed the cache at every point); the transform
    /// transposes it in tiles. A point and its mirror -k need each other's coefficients:
    /// rows r and n - r are filled together, so each point's coefficients are computed once
    /// (row 0 and, for even n, row n/2 are their own mirrors), and all `N` spectra in one pass
    /// over the waves. The same expressions as one point and one spectrum at a time, so the
    /// same bits.
    pub(super) fn fill_packed<const N: usize>(
        &self,
        waves: &[Complex32],
        coefficients: impl Fn(usize, Complex32) -> [(Complex32, Complex32); N] + Sync,
        bufs: [&mut Vec<Complex32>; N],
    ) {
        let n = self.n;
        let mirror_col = |c: usize| if c == 0 { 0 } else { n - c };
        let spectrum = |(f, g): (Complex32, Complex32), (fm, gm): (Complex32, Complex32)| {
            let sf = (f + fm.conj()) * 0.5;
            let sg = (g + gm.conj()) * 0.5;
            sf + Complex32::new(0.0, 1.0) * sg
        };
        let (pairs, even) = ((n - 1) / 2, n.is_multiple_of(2));
        let (mut row0, mut middle): (Rows, Rows) = (Vec::with_capacity(N), Vec::with_capacity(N));
        let mut pair_rows: Vec<(Rows, Rows)> =
            (0..pairs).map(|_| (Vec::with_capacity(N), Vec::with_capacity(N))).collect();
        for buf in bufs {
            buf.resize(n * n, Complex32::new(0.0, 0.0));
            let (first, rest) = buf.split_at_mut(n);
            let (top, rest) = rest.split_at_mut(pairs * n);
            let (mid, bottom) = rest.split_at_mut(if even { n } else { 0 });
            row0.push(first);
            middle.push(mid);
            for ((rows, row), row_m) in pair_rows.iter_mut().zip(top.chunks_mut(n)).zip(bottom.chunks_mut(n).rev()) {
                rows.0.push(row);
                rows.1.push(row_m);
            }
        }
        let own_mirror = |r: usize, rows: &mut Rows| {
            for c in 0..n {
                let (i, mirror) = (r * n + c, r * n + mirror_col(c));
                let (a, b) = (coefficients(i, waves[i]), coefficients(mirror, waves[mirror]));
                for (row, (a, b)) in rows.iter_mut().zip(a.into_iter().zip(b)) {
                    row[c] = spectrum(a, b);
                }
            }
        };
        own_mirror(0, &mut row0);
        if even {
            own_mirror(n / 2, &mut middle);
        }
        pair_rows.into_par_iter().enumerate().for_each(|(k, (mut rows, mut rows_m))| {
            let (r, r_m) = (k + 1, n - k - 1);
            for c in 0..n {
                let (i, mirror) = (r * n + c, r_m * n + mirror_col(c));
                let (a, b) = (coefficients(i, waves[i]), coefficients(mirror, waves[mirror]));
                for ((row, row_m), (a, b)) in rows.iter_mut().zip(rows_m.iter_mut()).zip(a.into_iter().zip(b)) {
                    row[c] = spectrum(a, b);
                    row_m[mirror_col(c)] = spectrum(b, a);
                }
            }
        });
    }
}
