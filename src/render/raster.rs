//! Exact, watertight triangle coverage in integers: which pixels' centres a triangle covers.
//!
//! The mesh renderers fill triangles themselves rather than through tiny-skia's path filler:
//! tiny-skia clips paths that cross the pixmap's edge with a formula that depends on which way
//! a line runs, so two triangles sharing an edge could leave single pixels along the border
//! unpainted (seen: one pixel in a 160x96 mesh), and the ocean's smooth shading computes every
//! pixel anyway. Here corners snap to 1/256 pixel and a centre on an edge belongs to one side.

/// Sub-pixel steps per pixel of [`fill_triangle_ids`]'s fixed-point coordinates.
const SUBPIXELS: f32 = 256.0;
/// Coordinates are clamped to ±this many pixels first, so every product fits an i64.
const FAR_PX: f32 = 1_048_576.0;

/// Writes `id` into every pixel of `ids` (`width` columns, `rows` rows, row-major) whose centre
/// lies inside the triangle `points` (pixel coordinates, either orientation).
///
/// Exact and watertight: the corners are snapped to 1/256 pixel, the edge functions are
/// evaluated in integers, and a centre exactly on an edge belongs to one side only (the edge
/// whose function has a positive x coefficient, or a zero one and a positive y coefficient).
/// So two triangles sharing an edge cover each pixel along it exactly once, whatever order
/// they come in. Degenerate triangles fill nothing. Allocates nothing.
pub fn fill_triangle_ids(ids: &mut [u32], width: usize, rows: usize, points: [(f32, f32); 3], id: u32) {
    for_each_span(width, rows, points, |y, x0, x1| ids[y * width + x0..=y * width + x1].fill(id));
}

/// Calls `span(y, x0, x1)` for every row `y` of a `width x rows` picture with the pixels
/// `x0..=x1` whose centres lie inside the triangle `points`: exactly the pixels
/// [`fill_triangle_ids`] fills (the same exact, watertight rule), for fills that compute each
/// pixel (the ocean's smooth shading).
pub fn for_each_span(width: usize, rows: usize, points: [(f32, f32); 3], mut span: impl FnMut(usize, usize, usize)) {
    // (A NaN coordinate snaps to 0: a wrong triangle, never a panic.)
    let snap = |v: f32| (v.clamp(-FAR_PX, FAR_PX) * SUBPIXELS).round() as i64;
    let mut p = points.map(|(x, y)| (snap(x), snap(y)));
    if width == 0 || rows == 0 {
        return;
    }
    let area = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[1].1 - p[0].1) * (p[2].0 - p[0].0);
    if area == 0 {
        return;
    }
    if area < 0 {
        p.swap(1, 2);
    }
    // Edge a -> b: E(q) = A·qx + B·qy + C, positive inside.
    let edges = [(p[0], p[1]), (p[1], p[2]), (p[2], p[0])].map(|(a, b)| {
        let (ea, eb) = (a.1 - b.1, b.0 - a.0);
        let c = -(ea * a.0 + eb * a.1);
        let inclusive = ea > 0 || (ea == 0 && eb > 0);
        (ea, eb, c, if inclusive { 0 } else { 1 })
    });
    let s = SUBPIXELS as i64;
    let half = s / 2;
    let (min_y, max_y) = (p.iter().map(|v| v.1).min().unwrap_or(0), p.iter().map(|v| v.1).max().unwrap_or(0));
    // Rows whose centre (y·s + s/2) lies within [min_y, max_y].
    let first = ceil_div(min_y - half, s).max(0);
    let last = (max_y - half).div_euclid(s).min(rows as i64 - 1);
    for y in first..=last {
        let cy = y * s + half;
        let (mut lo, mut hi) = (0i64, width as i64 - 1);
        for &(ea, eb, c, t) in &edges {
            // E at column x's centre = (A·s)·x + k.
            let k = ea * half + eb * cy + c;
            let step = ea * s;
            if step > 0 {
                lo = lo.max(ceil_div(t - k, step));
            } else if step < 0 {
                hi = hi.min((k - t).div_euclid(-step));
            } else if k < t {
                hi = -1;
            }
        }
        if lo <= hi {
            span(y as usize, lo as usize, hi as usize);
        }
    }
}

/// ⌈n / d⌉ for d > 0.
fn ceil_div(n: i64, d: i64) -> i64 {
    -((-n).div_euclid(d))
}

/// The end points of an edge in a fixed order, whichever way the edge runs.
/// Whether the screen triangle `a, b, c` can show on a `w` x `h` picture: its bounding box
/// meets the picture, and it faces the camera. spade's faces are counter-clockwise; one turned
/// over on the screen shows its underside (the far slope of a crest folded over by a tall wave
/// far away), and a nearer front face covers that spot.
pub fn shows_front(a: (f32, f32), b: (f32, f32), c: (f32, f32), w: f32, h: f32) -> bool {
    let (min_x, max_x) = (a.0.min(b.0).min(c.0), a.0.max(b.0).max(c.0));
    let (min_y, max_y) = (a.1.min(b.1).min(c.1), a.1.max(b.1).max(c.1));
    let on_screen = max_x >= 0.0 && max_y >= 0.0 && min_x <= w && min_y <= h;
    on_screen && (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0) > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn id_fills_are_watertight_and_exclusive() {
        // A fan of triangles around a centre, some edges through pixel centres exactly: every
        // pixel inside the fan is covered exactly once.
        let (w, h) = (40usize, 30usize);
        let centre = (20.5f32, 15.5f32);
        let ring: Vec<(f32, f32)> = (0..9)
            .map(|i| {
                let a = i as f32 * std::f32::consts::TAU / 9.0;
                (centre.0 + 18.0 * a.cos(), centre.1 + 13.3 * a.sin())
            })
            .collect();
        let mut counts = vec![0u32; w * h];
        for i in 0..9 {
            let mut ids = vec![0u32; w * h];
            let tri =
                if i % 2 == 0 { [centre, ring[i], ring[(i + 1) % 9]] } else { [ring[(i + 1) % 9], ring[i], centre] };
            fill_triangle_ids(&mut ids, w, h, tri, 7);
            for (c, v) in counts.iter_mut().zip(&ids) {
                *c += u32::from(*v == 7);
            }
        }
        assert!(counts.iter().all(|&c| c <= 1), "no pixel twice");
        for y in 8..23 {
            for x in 10..31 {
                assert_eq!(counts[y * w + x], 1, "({x}, {y}) covered once");
            }
        }
        // A grid of squares split into triangles, corners on pixel centres and off them.
        for offset in [0.0f32, 0.5, 0.25] {
            let mut counts = vec![0u32; w * h];
            for gy in 0..6 {
                for gx in 0..8 {
                    let p = |dx: usize, dy: usize| ((gx + dx) as f32 * 5.0 + offset, (gy + dy) as f32 * 5.0 + offset);
                    for tri in [[p(0, 0), p(1, 0), p(1, 1)], [p(0, 0), p(1, 1), p(0, 1)]] {
                        let mut ids = vec![0u32; w * h];
                        fill_triangle_ids(&mut ids, w, h, tri, 1);
                        for (c, v) in counts.iter_mut().zip(&ids) {
                            *c += *v;
                        }
                    }
                }
            }
            assert!(counts.iter().all(|&c| c == 1), "offset {offset}: every pixel exactly once");
        }
        // Clipped to the buffer, degenerate triangles fill nothing.
        let mut ids = vec![0u32; 4 * 3];
        fill_triangle_ids(&mut ids, 4, 3, [(-100.0, -100.0), (300.0, -100.0), (-100.0, 300.0)], 3);
        assert!(ids.iter().all(|&v| v == 3));
        let mut ids = vec![0u32; 4 * 3];
        fill_triangle_ids(&mut ids, 4, 3, [(0.0, 0.0), (2.0, 2.0), (4.0, 4.0)], 3);
        fill_triangle_ids(&mut ids, 4, 3, [(1.0, 1.0), (1.0, 1.0), (3.0, 2.0)], 3);
        assert!(ids.iter().all(|&v| v == 0));
        fill_triangle_ids(&mut ids, 4, 3, [(0.0, 0.0), (f32::NAN, 2.0), (f32::INFINITY, 1.0)], 3);
    }
}
