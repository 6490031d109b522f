//! Where two pictures differ: one pass over the rows, each byte compared at most once.
//!
//! The kitty and sixel encoders both need the box around the changed pixels (kitty for a frame
//! edit, sixel for the changed cells) and the stream needs it per strip. Rows are compared in
//! 64-byte blocks (a slice comparison is a `memcmp`), and only the block that differs is read
//! byte by byte, from the front for the first difference and from the back for the last, so a
//! row costs one comparison of its bytes whatever changed in it.

/// The bytes compared at once before looking inside a block.
const BLOCK: usize = 64;

/// The index of the first byte where `a` and `b` differ (same length), if any.
pub fn first_difference(a: &[u8], b: &[u8]) -> Option<usize> {
    debug_assert_eq!(a.len(), b.len());
    let mut start = 0;
    for (x, y) in a.chunks(BLOCK).zip(b.chunks(BLOCK)) {
        if x != y {
            return x.iter().zip(y).position(|(p, q)| p != q).map(|i| start + i);
        }
        start += x.len();
    }
    None
}

/// The index of the last byte where `a` and `b` differ (same length), if any.
pub fn last_difference(a: &[u8], b: &[u8]) -> Option<usize> {
    debug_assert_eq!(a.len(), b.len());
    let mut end = a.len();
    while end > 0 {
        let start = end.saturating_sub(BLOCK);
        let (x, y) = (&a[start..end], &b[start..end]);
        if x != y {
            return x.iter().zip(y).rposition(|(p, q)| p != q).map(|i| start + i);
        }
        end = start;
    }
    None
}

/// The box `(x, y, width, height)` in pixels around every pixel that differs between `old` and
/// `new` (`width x height` pixels of `bpp` bytes, row-major) within rows `rows`, or `None` when
/// they are equal there. One pass: each row's bytes are compared once.
pub fn changed_box(
    old: &[u8],
    new: &[u8],
    width: u32,
    bpp: usize,
    rows: std::ops::Range<u32>,
) -> Option<(u32, u32, u32, u32)> {
    changed_in(old, new, width as usize * bpp, bpp, (0, rows.start, width, rows.end.saturating_sub(rows.start)))
}

/// [`changed_box`] within `area` `(x, y, w, h)` of pictures `stride` bytes a row.
pub fn changed_in(
    old: &[u8],
    new: &[u8],
    stride: usize,
    bpp: usize,
    area: (u32, u32, u32, u32),
) -> Option<(u32, u32, u32, u32)> {
    let (x, y, w, h) = area;
    let (mut top, mut bottom, mut left, mut right) = (u32::MAX, 0, u32::MAX, 0);
    for row in y..y + h {
        let a = row as usize * stride + x as usize * bpp;
        let b = a + w as usize * bpp;
        let (p, q) = (&old[a..b], &new[a..b]);
        let Some(first) = first_difference(p, q) else { continue };
        // Only the part after the first difference is left to search from the back.
        let last = first + last_difference(&p[first..], &q[first..]).unwrap_or(0);
        top = top.min(row);
        bottom = row;
        left = left.min(x + (first / bpp) as u32);
        right = right.max(x + (last / bpp) as u32);
    }
    (top != u32::MAX).then(|| (left, top, right - left + 1, bottom - top + 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_and_last_differences_across_blocks() {
        let a = vec![7u8; 200];
        let mut b = a.clone();
        assert_eq!((first_difference(&a, &b), last_difference(&a, &b)), (None, None));
        b[3] = 0;
        b[130] = 0;
        assert_eq!((first_difference(&a, &b), last_difference(&a, &b)), (Some(3), Some(130)));
        b[199] = 1;
        assert_eq!(last_difference(&a, &b), Some(199));
        assert_eq!(first_difference(&a[..5], &b[..5]), Some(3));
    }

    #[test]
    fn the_box_holds_every_changed_pixel_and_nothing_else() {
        let (w, h) = (70u32, 9u32);
        let old = vec![0u8; (w * h * 3) as usize];
        let mut new = old.clone();
        assert_eq!(changed_box(&old, &new, w, 3, 0..h), None);
        let set = |new: &mut Vec<u8>, x: u32, y: u32, c: usize| new[((y * w + x) * 3) as usize + c] = 9;
        set(&mut new, 66, 2, 2);
        set(&mut new, 5, 6, 0);
        set(&mut new, 30, 4, 1);
        assert_eq!(changed_box(&old, &new, w, 3, 0..h), Some((5, 2, 62, 5)));
        assert_eq!(
            changed_box(&old, &new, w, 3, 3..h),
            Some((5, 4, 26, 3)),
            "rows outside the range are not looked at"
        );
        assert_eq!(changed_box(&old, &new, w, 3, 7..h), None);
        let one = vec![1u8; (w * h) as usize];
        let mut two = one.clone();
        two[(8 * w + 69) as usize] = 2;
        assert_eq!(changed_box(&one, &two, w, 1, 0..h), Some((69, 8, 1, 1)), "one byte a pixel");
    }
}
