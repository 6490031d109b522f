//! Three-component f32 vectors for the mesh renderer: world space is east, north, up, metres.

/// A vector or point: `[east, north, up]`.
pub type Vec3 = [f32; 3];

/// a + b.
#[inline(always)]
pub fn add(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// a - b.
#[inline(always)]
pub fn sub(a: Vec3, b: Vec3) -> Vec3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// a · s.
#[inline(always)]
pub fn scale(a: Vec3, s: f32) -> Vec3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// The dot product.
#[inline(always)]
pub fn dot(a: Vec3, b: Vec3) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The cross product.
#[inline(always)]
pub fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// The length.
#[inline(always)]
pub fn length(a: Vec3) -> f32 {
    dot(a, a).sqrt()
}

/// `a` scaled to length 1 (straight up for a zero vector, the safe answer for a normal).
#[inline(always)]
pub fn normalize(a: Vec3) -> Vec3 {
    let l = length(a);
    if l > 0.0 && l.is_finite() { scale(a, 1.0 / l) } else { [0.0, 0.0, 1.0] }
}

/// `v` mirrored about the unit normal `n` (both pointing away from the surface).
#[inline(always)]
pub fn reflect(v: Vec3, n: Vec3) -> Vec3 {
    sub(scale(n, 2.0 * dot(n, v)), v)
}
