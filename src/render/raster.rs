//! Watertight, non-anti-aliased triangle fills with tiny-skia.
//!
//! tiny-skia's non-AA scan converter fills two triangles that share an edge without a gap or
//! an overlap — as long as it sees the same edge twice. When a path crosses the pixmap's edge
//! it clips the path's lines itself, and the clipped end point depends on which way the line
//! runs (`x0 + (y - y0)·(x1 - x0)/(y1 - y0)`); two triangles run a shared edge in opposite
//! directions, so their clipped edges differ in the last bits and single pixels along the
//! picture's border stay unpainted (seen: one pixel in a 160x96 mesh). [`TriangleFiller`]
//! therefore clips triangles that stick out to the pixmap itself (Sutherland–Hodgman), with
//! every intersection computed from the edge's end points in a fixed order, so shared edges
//! clip identically and tiny-skia never has to clip.

use tiny_skia::{FillRule, Paint, PathBuilder, PixmapMut, Transform};

/// Up to 3 + 4 vertices: a triangle clipped by four sides.
const MAX: usize = 8;

type Polygon = ([(f32, f32); MAX], usize);

/// Fills triangles, reusing one path allocation.
#[derive(Debug)]
pub struct TriangleFiller {
    builder: Option<PathBuilder>,
}

impl Default for TriangleFiller {
    fn default() -> Self {
        TriangleFiller::new()
    }
}

impl TriangleFiller {
    /// A filler.
    pub fn new() -> TriangleFiller {
        TriangleFiller { builder: Some(PathBuilder::with_capacity(MAX, MAX)) }
    }

    /// Fills the triangle `points` (pixel coordinates, any orientation) with `paint`.
    pub fn fill(&mut self, out: &mut PixmapMut<'_>, paint: &Paint, points: [(f32, f32); 3]) {
        let (w, h) = (out.width() as f32, out.height() as f32);
        let mut poly: Polygon = ([(0.0, 0.0); MAX], 3);
        poly.0[..3].copy_from_slice(&points);
        let inside = points.iter().all(|&(x, y)| x >= 0.0 && x <= w && y >= 0.0 && y <= h);
        if !inside {
            poly = clip(poly, |p| p.0 >= 0.0, |a, b| cross_x(a, b, 0.0));
            poly = clip(poly, |p| p.0 <= w, |a, b| cross_x(a, b, w));
            poly = clip(poly, |p| p.1 >= 0.0, |a, b| cross_y(a, b, 0.0));
            poly = clip(poly, |p| p.1 <= h, |a, b| cross_y(a, b, h));
            if poly.1 < 3 {
                return;
            }
        }
        let mut builder = self.builder.take().unwrap_or_else(|| PathBuilder::with_capacity(MAX, MAX));
        builder.move_to(poly.0[0].0, poly.0[0].1);
        for &(x, y) in &poly.0[1..poly.1] {
            builder.line_to(x, y);
        }
        builder.close();
        self.builder = Some(match builder.finish() {
            Some(path) => {
                out.fill_path(&path, paint, FillRule::Winding, Transform::identity(), None);
                path.clear()
            }
            None => PathBuilder::with_capacity(MAX, MAX),
        });
    }
}

/// The end points of an edge in a fixed order, whichever way the edge runs.
fn ordered(a: (f32, f32), b: (f32, f32)) -> ((f64, f64), (f64, f64)) {
    let (a, b) = if (a.0, a.1) <= (b.0, b.1) { (a, b) } else { (b, a) };
    ((f64::from(a.0), f64::from(a.1)), (f64::from(b.0), f64::from(b.1)))
}

fn cross_x(a: (f32, f32), b: (f32, f32), x: f32) -> (f32, f32) {
    let (p, q) = ordered(a, b);
    let t = (f64::from(x) - p.0) / (q.0 - p.0);
    (x, (p.1 + t * (q.1 - p.1)) as f32)
}

fn cross_y(a: (f32, f32), b: (f32, f32), y: f32) -> (f32, f32) {
    let (p, q) = ordered(a, b);
    let t = (f64::from(y) - p.1) / (q.1 - p.1);
    ((p.0 + t * (q.0 - p.0)) as f32, y)
}

/// One Sutherland–Hodgman pass: keeps the part of `poly` where `inside` holds.
fn clip(
    poly: Polygon,
    inside: impl Fn((f32, f32)) -> bool,
    cross: impl Fn((f32, f32), (f32, f32)) -> (f32, f32),
) -> Polygon {
    let (pts, n) = poly;
    let mut out: Polygon = ([(0.0, 0.0); MAX], 0);
    let mut push = |p: (f32, f32)| {
        if out.1 < MAX {
            out.0[out.1] = p;
            out.1 += 1;
        }
    };
    for i in 0..n {
        let (cur, next) = (pts[i], pts[(i + 1) % n]);
        let (ci, ni) = (inside(cur), inside(next));
        if ci {
            push(cur);
        }
        if ci != ni {
            push(cross(cur, next));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use tiny_skia::{BlendMode, Color, Pixmap};

    #[test]
    fn shared_edges_across_the_border_leave_no_gap() {
        // The case that showed the gap: two triangles sharing an edge that crosses the bottom.
        let tris = [
            [(2.49337f32, 92.23555f32), (1.2973251, 96.24643), (-1.204956, 92.18538)],
            [(2.49337, 92.23555), (5.382126, 95.81636), (1.2973251, 96.24643)],
        ];
        let mut out = Pixmap::new(160, 96).unwrap();
        out.fill(Color::from_rgba8(255, 0, 255, 255));
        let mut paint = Paint { anti_alias: false, blend_mode: BlendMode::Source, ..Paint::default() };
        paint.set_color_rgba8(0, 100, 0, 255);
        let mut filler = TriangleFiller::new();
        for t in tris {
            filler.fill(&mut out.as_mut(), &paint, t);
        }
        // Pixel (1, 95) lies 0.02 px inside the shared edge; unclipped by us, neither got it.
        for x in 1..4 {
            assert_eq!(out.pixels()[95 * 160 + x].green(), 100, "pixel ({x}, 95)");
        }
    }

    #[test]
    fn clipping_keeps_the_inside() {
        let mut out = Pixmap::new(10, 10).unwrap();
        let mut paint = Paint { anti_alias: false, ..Paint::default() };
        paint.set_color_rgba8(10, 20, 30, 255);
        TriangleFiller::new().fill(&mut out.as_mut(), &paint, [(-100.0, -100.0), (300.0, -100.0), (-100.0, 300.0)]);
        assert!(out.pixels().iter().all(|p| p.alpha() == 255), "a huge triangle covers everything");
        let mut empty = Pixmap::new(10, 10).unwrap();
        TriangleFiller::new().fill(&mut empty.as_mut(), &paint, [(20.0, 20.0), (30.0, 20.0), (20.0, 30.0)]);
        assert!(empty.pixels().iter().all(|p| p.alpha() == 0));
    }
}
