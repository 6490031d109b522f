//! The contract between a water simulation and the mesh renderer: "one renderer, two height
//! sources". The ocean ([`crate::sim::ocean::SeaSurface`]) and the lake implement [`Surface`];
//! [`crate::render::mesh::MeshRenderer`] samples it at its mesh vertices, one footprint each.

/// The patch of sea one mesh sample stands for: the ground vectors (east, north metres) of one
/// sample step along the screen's x axis (`across`) and y axis (`along`, towards the viewer).
///
/// Far from the camera `along` grows much longer than `across` (the plane is seen at a grazing
/// angle), so a surface can keep waves whose crests run across the view while dropping those
/// that would alias. A zero footprint asks for the full surface.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Footprint {
    /// One sample step along the screen's x axis, on the ground, metres (east, north).
    pub across: [f32; 2],
    /// One sample step along the screen's y axis, on the ground, metres (east, north).
    pub along: [f32; 2],
}

impl Footprint {
    #[cfg(test)]
    /// A square footprint of `size_m` metres (axis-aligned); 0 is the full surface.
    pub fn isotropic(size_m: f32) -> Footprint {
        Footprint { across: [size_m, 0.0], along: [0.0, size_m] }
    }

    /// The shorter side, metres: nothing shorter than twice this can be drawn.
    pub fn min_m(&self) -> f32 {
        len(self.across).min(len(self.along))
    }

    /// The longer side, metres.
    pub fn max_m(&self) -> f32 {
        len(self.across).max(len(self.along))
    }

    /// The geometric mean of the two sides, metres: the scale for isotropic detail.
    pub fn mean_m(&self) -> f32 {
        (len(self.across) * len(self.along)).sqrt()
    }

    /// The largest phase change (radians) of a wave with wavenumber vector (kx, ky) over one
    /// sample step: above π/2 it starts to alias, at π it is noise.
    #[inline(always)]
    pub fn phase_step(&self, kx: f32, ky: f32) -> f32 {
        let a = (kx * self.across[0] + ky * self.across[1]).abs();
        let b = (kx * self.along[0] + ky * self.along[1]).abs();
        a.max(b)
    }
}

fn len(v: [f32; 2]) -> f32 {
    (v[0] * v[0] + v[1] * v[1]).sqrt()
}

/// What a surface looks like at one point, seen with a footprint.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfaceSample {
    /// Height above the mean level, m (only what the footprint resolves).
    pub height_m: f32,
    /// How far the water that rests at the sampled point is carried across the plane (east,
    /// north metres): the horizontal displacement of a choppy sea (zero for other surfaces).
    /// The renderer draws the point at (x, y) + this, at `height_m`.
    pub displacement_m: [f32; 2],
    /// Foam (whitecap) cover at the point, 0..=1.
    pub foam: f32,
    /// Slope variance (per axis) of the waves too short for the footprint; the renderer
    /// spreads the sun's glint by it.
    pub unresolved_slope_variance: f32,
    /// Σ a²/2·k²·φ² over the waves the footprint keeps (both axes), φ each wave's phase step
    /// between neighbouring samples: a mesh between the samples loses part of their slope
    /// (flat triangles about φ²/12 of each wave's, smooth shading about φ²/2), which the
    /// renderer adds back to the unresolved slope variance. 0 for surfaces that do not say.
    pub mesh_slope_loss: f32,
}

/// A water surface a renderer can sample: heights in metres over the (east, north) plane.
///
/// `Sync` so the renderer can sample on several threads.
pub trait Surface: Sync {
    /// The surface at (east, north) metres for a sample standing for `footprint`.
    fn sample(&self, x: f32, y: f32, footprint: &Footprint) -> SurfaceSample;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn footprints() {
        let f = Footprint { across: [3.0, 4.0], along: [0.0, 20.0] };
        assert_eq!(f.min_m(), 5.0);
        assert_eq!(f.mean_m(), 10.0);
        assert_eq!(f.max_m(), 20.0);
        // A wave travelling north (ky) changes phase fast along the view, slowly across it.
        assert_eq!(f.phase_step(0.0, 0.1), 2.0);
        assert_eq!(Footprint::isotropic(0.0).phase_step(5.0, 5.0), 0.0);
    }
}
