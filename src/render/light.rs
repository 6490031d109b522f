//! Linear colour and light: the colour type every renderer shares, sRGB encoding and decoding,
//! and the light falling on a scene. A leaf module (it imports only [`super::vec3`]), so the
//! sky, the shading, the shore and the textures can all use it without importing each other.

use super::vec3::Vec3;

/// A linear RGB colour (1.0 = white paper in full light; highlights go above 1).
pub type Rgb = [f32; 3];

/// Colour `a` mixed towards `b` by `t` (0 = a, 1 = b).
#[inline(always)]
pub fn mix(a: Rgb, b: Rgb, t: f32) -> Rgb {
    [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, a[2] + (b[2] - a[2]) * t]
}

/// The sRGB encoding of a linear value in 0..=1.
#[inline(always)]
pub fn srgb_encode(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 }
}

/// The linear value of an sRGB level 0..=255.
pub fn srgb_decode(level: u8) -> f32 {
    let v = f32::from(level) / 255.0;
    if v <= 0.040_45 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
}

/// Linear colour to 8-bit sRGB: values up to 0.8 pass unchanged, brighter ones roll off
/// smoothly towards 1 (so a glint saturates to white without a hard edge).
#[inline(always)]
pub fn to_srgb8(c: Rgb) -> [u8; 3] {
    let tone = |v: f32| {
        let v = v.max(0.0);
        if v <= 0.8 { v } else { 0.8 + 0.2 * (1.0 - (-(v - 0.8) / 0.2).exp()) }
    };
    c.map(|v| (srgb_encode(tone(v)) * 255.0 + 0.5) as u8)
}

/// The light falling on the water.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Unit direction towards the sun.
    pub sun_dir: Vec3,
    /// The sun's colour (times `WaterLook::sun_irradiance` for the glint).
    pub sun: Rgb,
    /// The average sky light on a level surface.
    pub sky: Rgb,
}

/// [`to_srgb8`] for one channel through a table, for per-pixel work: 16,384 steps per unit of linear light up to 4
/// (fine enough that the darkest water has no bands: one step is under 0.1 of an 8-bit level).
pub struct SrgbTable {
    levels: Vec<u8>,
}

impl SrgbTable {
    const STEPS: f32 = 16_384.0;

    /// The table, built on first use.
    pub fn shared() -> &'static SrgbTable {
        static TABLE: std::sync::OnceLock<SrgbTable> = std::sync::OnceLock::new();
        TABLE.get_or_init(|| SrgbTable {
            levels: (0..65_536).map(|i| to_srgb8([(i as f32 + 0.5) / Self::STEPS, 0.0, 0.0])[0]).collect(),
        })
    }

    /// The 8-bit sRGB level of a linear value (NaN and negatives give 0).
    #[inline(always)]
    pub fn encode(&self, v: f32) -> u8 {
        // `as usize` sends NaN and negatives to 0.
        self.levels[((v * Self::STEPS) as usize).min(self.levels.len() - 1)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tone_mapping_is_monotonic_and_saturates() {
        assert_eq!(to_srgb8([0.0, 0.5, 100.0]), [0, 188, 255]);
        assert!(to_srgb8([1.0; 3])[0] > 240);
        let mut last = 0;
        for i in 0..200 {
            let v = to_srgb8([i as f32 / 50.0; 3])[0];
            assert!(v >= last);
            last = v;
        }
        assert_eq!(srgb_encode(srgb_decode(128)), 128.0 / 255.0);
    }

    #[test]
    fn the_table_matches_to_srgb8() {
        let t = SrgbTable::shared();
        for v in [0.0f32, 0.0004, 0.01, 0.2, 0.79, 0.81, 1.5, 3.9, 10.0] {
            let want = to_srgb8([v, 0.0, 0.0])[0];
            assert!(t.encode(v).abs_diff(want) <= 1, "{v}: {} vs {want}", t.encode(v));
        }
        assert_eq!(t.encode(f32::NAN), 0);
        assert_eq!(t.encode(-1.0), 0);
    }
}
