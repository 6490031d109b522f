//! The light of one point of water: its body, the sky it reflects, the sun's glint, foam and
//! haze. The ocean evaluates it once per mesh face (flat shading) or per vertex (smooth
//! shading) without the glint, which it evaluates per pixel (`render::ocean`'s glitter); the
//! lake takes [`fresnel`] and [`glint`] for its per-pixel mirror.
//!
//! The paper lights its sea mesh with ambient + diffuse + specular and stretches a sea photo
//! over it; tidepool keeps those terms and adds what makes water read as water:
//!
//! ```text
//! body    = albedo · (ambient·sky + diffuse·sun·max(n·l, 0))     light scattered up from below
//! colour  = (1 - F)·body + F·env(reflect(v, n')) + glint          F: Schlick, F0 = 0.02
//! n'      = n tilted towards the eye by σ (the unresolved facets that face the eye)
//! glint   = E_sun · F(v·h) · p(h) / (4 · (n·v) · (n·h)⁴)           Cox–Munk glitter
//! p(h)    = exp(-tan²θh / 2σ²) / (2πσ²)                           σ²: slope variance per axis
//! colour  = mix(colour, foam·(ambient·sky + sun·max(n·l,0)), foam cover)
//! colour  = mix(colour, haze(view), 1 - exp(-distance / haze_m))
//! ```
//!
//! σ² is the slope variance the mesh cannot show (small near the camera, where facets carry the
//! waves; large far away, where they are filtered out), so the sun makes sharp sparkles on near
//! facets and a broad glitter path towards the horizon, as on a real sea. Colours are linear
//! RGB floats; [`to_srgb8`](super::light::to_srgb8) tone-maps and encodes them.

use super::light::{Light, Rgb, mix};
use super::sky::Environment;
use super::vec3::{Vec3, dot, normalize, reflect};

/// Water's reflectance at normal incidence (refractive index 1.33).
pub const WATER_F0: f32 = 0.02;

/// Schlick's Fresnel reflectance for a cosine of incidence `cos`.
#[inline(always)]
pub fn fresnel(cos: f32) -> f32 {
    let m = (1.0 - cos.clamp(0.0, 1.0)).powi(5);
    WATER_F0 + (1.0 - WATER_F0) * m
}

/// How water is lit and coloured.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WaterLook {
    /// Weight of the sky's light on the water body.
    pub ambient: f32,
    /// Weight of the sun's light on the water body.
    pub diffuse: f32,
    /// The sun's irradiance relative to the sky's radiance (the glint's strength).
    pub sun_irradiance: f32,
    /// Slope variance (per axis) always added to [`glint`]'s: the capillary waves the lake's
    /// noise does not carry (the ocean's unresolved slope variance already holds Cox–Munk's
    /// whole total, so its glitter adds none).
    pub base_slope_variance: f32,
    /// Foam's albedo.
    pub foam: Rgb,
    /// Distance over which haze takes 63 % of the colour, m.
    pub haze_m: f32,
}

impl Default for WaterLook {
    fn default() -> Self {
        WaterLook {
            ambient: 1.0,
            diffuse: 0.6,
            sun_irradiance: 0.9,
            base_slope_variance: 0.0008,
            foam: [0.74, 0.79, 0.82],
            haze_m: 20_000.0,
        }
    }
}

/// Everything about one facet the shading needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Facet {
    /// Unit face normal (pointing up).
    pub normal: Vec3,
    /// Unit vector from the facet to the eye.
    pub to_eye: Vec3,
    /// Distance from the eye, m.
    pub distance_m: f32,
    /// The water body's albedo here (from the texture), linear.
    pub albedo: Rgb,
    /// Foam cover 0..=1.
    pub foam: f32,
    /// Unresolved slope variance per axis.
    pub slope_variance: f32,
    /// Mean height of the facet above the still water level, m (the lake colours by it).
    pub height_m: f32,
}

/// The sun's glint on a facet with unit normal `n` seen from the unit direction `v` (towards
/// the eye), as a multiple of the sun's colour: Cox–Munk glitter with the facet's unresolved
/// `slope_variance` plus [`WaterLook::base_slope_variance`], at most 50. 0 when the sun is down.
#[inline]
pub fn glint(look: &WaterLook, light: &Light, n: Vec3, v: Vec3, slope_variance: f32) -> f32 {
    let l = light.sun_dir;
    if l[2] <= 0.0 {
        return 0.0;
    }
    let n_dot_v = dot(n, v).max(0.02);
    let h = normalize([l[0] + v[0], l[1] + v[1], l[2] + v[2]]);
    let n_dot_h = dot(n, h).max(1e-3);
    let s2 = slope_variance + look.base_slope_variance;
    let tan2 = (1.0 - n_dot_h * n_dot_h) / (n_dot_h * n_dot_h);
    let p = (-tan2 / (2.0 * s2)).exp() / (2.0 * std::f32::consts::PI * s2);
    let g = look.sun_irradiance * fresnel(dot(v, h)) * p / (4.0 * n_dot_v * n_dot_h.powi(4));
    g.min(50.0)
}

/// A facet's colour without the sun's glint, and the share of a glint the haze would leave.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WaterShade {
    /// Linear RGB, everything but the glint.
    pub colour: Rgb,
    /// 1 - haze: a glint adds `glint·sun·keep` to `colour` (on water without foam).
    pub keep: f32,
}

/// The colour of one facet without the sun's glint, linear RGB.
#[inline]
pub fn shade_water<E: Environment + ?Sized>(look: &WaterLook, light: &Light, env: &E, f: &Facet) -> WaterShade {
    let n = f.normal;
    let v = f.to_eye;
    let n_dot_l = dot(n, light.sun_dir).max(0.0);
    // Unresolved roughness: of the small facets inside this one, those tilted towards the eye
    // are seen most, so reflect with the normal tilted that way by one standard deviation.
    // This is what keeps a rough sea darker than the sky at the horizon.
    let sigma = f.slope_variance.sqrt();
    let toward = normalize([v[0], v[1], 0.0]);
    let rough_n = normalize([n[0] + sigma * toward[0], n[1] + sigma * toward[1], n[2]]);
    let fr = fresnel(dot(rough_n, v).max(0.02));
    let mut r = reflect(v, rough_n);
    if r[2] < 0.0 {
        // A facet tilted away from the eye reflects the sea; show the horizon instead.
        r = normalize([r[0], r[1], 0.0]);
    }
    let sky = env.radiance(r);
    let lit = |c: f32, i: usize| c * (look.ambient * light.sky[i] + look.diffuse * light.sun[i] * n_dot_l);
    let body = [lit(f.albedo[0], 0), lit(f.albedo[1], 1), lit(f.albedo[2], 2)];
    let mut colour = mix(body, sky, fr);
    if f.foam > 0.0 {
        let foam = [0, 1, 2].map(|i| look.foam[i] * (look.ambient * light.sky[i] + light.sun[i] * n_dot_l));
        // Foam is a froth of bubbles over water, never a solid sheet: at most 85 % cover.
        colour = mix(colour, foam, 0.85 * f.foam.min(1.0));
    }
    let keep = (-f.distance_m / look.haze_m).exp();
    let away = normalize([-v[0], -v[1], 0.0]);
    WaterShade { colour: mix(env.radiance(away), colour, keep), keep }
}

/// The colour of one facet, linear RGB: [`shade_water`] with the glint of its normal and its
/// unresolved slope variance (under foam, dimmed by the foam's cover).
#[inline]
pub fn shade_facet<E: Environment + ?Sized>(look: &WaterLook, light: &Light, env: &E, f: &Facet) -> Rgb {
    let WaterShade { colour, keep } = shade_water(look, light, env, f);
    let g = glint(look, light, f.normal, f.to_eye, f.slope_variance) * keep * (1.0 - 0.85 * f.foam.clamp(0.0, 1.0));
    [colour[0] + g * light.sun[0], colour[1] + g * light.sun[1], colour[2] + g * light.sun[2]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::sky::Sky;

    fn facet(normal: Vec3, to_eye: Vec3) -> Facet {
        Facet {
            normal,
            to_eye,
            distance_m: 100.0,
            albedo: [0.01, 0.04, 0.06],
            foam: 0.0,
            slope_variance: 0.001,
            height_m: 0.0,
        }
    }

    #[test]
    fn fresnel_rises_to_one_at_grazing_angles() {
        assert!((fresnel(1.0) - WATER_F0).abs() < 1e-6);
        assert!((fresnel(0.0) - 1.0).abs() < 1e-6);
        assert!(fresnel(0.2) > fresnel(0.6));
    }

    #[test]
    fn the_sun_glints_where_the_facet_mirrors_it() {
        let sky = Sky::new(0.0, 20.0);
        let light = sky.light();
        let look = WaterLook::default();
        let up = [0.0, 0.0, 1.0];
        // Looking north-down at 20°, the level sea mirrors the sun (north, 20° up).
        let mirror = normalize([0.0, -(20f32.to_radians().cos()), 20f32.to_radians().sin()]);
        let aside = normalize([0.7, -0.7, 0.36]);
        let glint = shade_facet(&look, &light, &sky, &facet(up, mirror));
        let plain = shade_facet(&look, &light, &sky, &facet(up, aside));
        assert!(glint[0] > 1.0 && glint[0] > 5.0 * plain[0], "{glint:?} vs {plain:?}");
        // Grazing views reflect more sky than steep ones.
        let steep = shade_facet(&look, &light, &sky, &facet(up, normalize([0.0, 0.2, 1.0])));
        let grazing = shade_facet(&look, &light, &sky, &facet(up, normalize([0.0, 0.95, 0.05])));
        assert!(grazing[2] > steep[2]);
    }

    #[test]
    fn foam_is_white_and_haze_takes_over_far_away() {
        let sky = Sky::new(90.0, 40.0);
        let (light, look) = (sky.light(), WaterLook::default());
        let mut f = facet([0.0, 0.0, 1.0], normalize([0.0, -0.5, 0.3]));
        let water = shade_facet(&look, &light, &sky, &f);
        f.foam = 1.0;
        let foam = shade_facet(&look, &light, &sky, &f);
        assert!(foam[0] > 3.0 * water[0]);
        f.distance_m = 1e7;
        let far = shade_facet(&look, &light, &sky, &f);
        let horizon = sky.radiance(normalize([0.0, 0.5, 0.0]));
        assert!((0..3).all(|i| (far[i] - horizon[i]).abs() < 1e-3));
    }
}
