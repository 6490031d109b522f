//! A pinhole camera above a water plane: world metres (east, north, up) to screen pixels.
//!
//! The pose is what a person on a ship's bridge or a cliff would give: height above the mean
//! water level, how far the view is tilted down, the horizontal field of view and the heading
//! (clockwise from north). There is no roll, so the horizon of the flat plane is a horizontal
//! line at `y = cy - focal·tan(pitch)`. Earth's curvature is ignored except that the sea is
//! sampled only out to the distance of the real horizon ([`Camera::horizon_distance_m`]).

use super::vec3::{Vec3, add, cross, dot, normalize, scale, sub};

/// The mean radius of the Earth, m.
pub const EARTH_RADIUS_M: f64 = 6_371_000.0;
/// Points closer than this in front of the camera are not drawn, m.
pub const NEAR_M: f32 = 0.05;

/// Where the camera is and where it looks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraPose {
    /// Height of the eye above the mean water level, m (> 0).
    pub height_m: f64,
    /// How far the view is tilted below the horizontal, degrees (negative looks up).
    pub pitch_down_deg: f64,
    /// Horizontal field of view, degrees.
    pub hfov_deg: f64,
    /// Where the view points, degrees clockwise from north.
    pub heading_deg: f64,
    /// Position east of the world origin, m.
    pub east_m: f64,
    /// Position north of the world origin, m.
    pub north_m: f64,
}

impl CameraPose {
    /// The default view: 25 m up (a ship's bridge), 8° down, 70° wide, looking north. Storm
    /// crests of Beaufort 12 stay below it, and the horizon sits in the upper third.
    pub const DEFAULT: CameraPose =
        CameraPose { height_m: 25.0, pitch_down_deg: 8.0, hfov_deg: 70.0, heading_deg: 0.0, east_m: 0.0, north_m: 0.0 };
}

impl Default for CameraPose {
    fn default() -> Self {
        CameraPose::DEFAULT
    }
}

/// A camera with its picture size: projects world points to pixels and pixels to rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pose: CameraPose,
    width: u32,
    height: u32,
    focal_px: f32,
    eye: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
}

impl Camera {
    /// A camera with `pose` drawing a `width x height` picture.
    pub fn new(pose: CameraPose, width: u32, height: u32) -> Camera {
        let heading = pose.heading_deg.to_radians() as f32;
        let pitch = pose.pitch_down_deg.to_radians() as f32;
        let forward = [heading.sin() * pitch.cos(), heading.cos() * pitch.cos(), -pitch.sin()];
        let right = [heading.cos(), -heading.sin(), 0.0];
        let up = cross(right, forward);
        let focal_px = (width as f64 / 2.0 / (pose.hfov_deg.to_radians() / 2.0).tan()) as f32;
        let eye = [pose.east_m as f32, pose.north_m as f32, pose.height_m as f32];
        Camera { pose, width, height, focal_px, eye, right, up, forward }
    }

    /// The camera of the mirror image in the still water plane (z = 0): the eye as far below
    /// the water as this one is above it, looking up as much as this one looks down.
    ///
    /// What it sees, turned upside down (row y to row `height - 1 - y`), is exactly what a
    /// calm surface shows this camera at the same pixel: the paper's stencil-buffer reflection.
    pub fn mirrored(&self) -> Camera {
        let pose = CameraPose { height_m: -self.pose.height_m, pitch_down_deg: -self.pose.pitch_down_deg, ..self.pose };
        Camera {
            pose,
            forward: [self.forward[0], self.forward[1], -self.forward[2]],
            up: cross(self.right, [self.forward[0], self.forward[1], -self.forward[2]]),
            eye: [self.eye[0], self.eye[1], -self.eye[2]],
            ..*self
        }
    }

    /// The same camera drawing a picture `pad_x` pixels wider on each side and `pad_y` taller
    /// at the top and bottom: same eye, direction, focal length and centre, so pixel (x, y)
    /// here is pixel (x - pad_x, y - pad_y) of this camera.
    pub fn padded(&self, pad_x: u32, pad_y: u32) -> Camera {
        let width = self.width + 2 * pad_x;
        let hfov_deg = 2.0 * (f64::from(width) / 2.0 / f64::from(self.focal_px)).atan().to_degrees();
        Camera { pose: CameraPose { hfov_deg, ..self.pose }, width, height: self.height + 2 * pad_y, ..*self }
    }

    /// The pose.
    pub fn pose(&self) -> CameraPose {
        self.pose
    }

    /// Picture width, px.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Picture height, px.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The focal length in pixels.
    pub fn focal_px(&self) -> f32 {
        self.focal_px
    }

    /// The eye position, world metres.
    pub fn eye(&self) -> Vec3 {
        self.eye
    }

    /// The unit view direction.
    pub fn forward(&self) -> Vec3 {
        self.forward
    }

    /// The unit direction of the picture's x axis (level: the camera has no roll).
    pub fn right(&self) -> Vec3 {
        self.right
    }

    /// The unit direction of the picture's upward axis.
    pub fn up(&self) -> Vec3 {
        self.up
    }

    /// The screen row of the flat sea's horizon (may lie outside the picture).
    pub fn horizon_y(&self) -> f32 {
        self.height as f32 / 2.0 - self.focal_px * (self.pose.pitch_down_deg.to_radians() as f32).tan()
    }

    /// How far the real horizon is for this eye height, m: √(2·R·h).
    pub fn horizon_distance_m(&self) -> f32 {
        (2.0 * EARTH_RADIUS_M * self.pose.height_m.max(0.0)).sqrt() as f32
    }

    /// A world point in pixels `(x, y)` and its depth along the view (m), or `None` when it
    /// is closer than [`NEAR_M`] or behind the camera.
    #[inline(always)]
    pub fn project(&self, p: Vec3) -> Option<(f32, f32, f32)> {
        let d = sub(p, self.eye);
        let depth = dot(d, self.forward);
        if depth.is_nan() || depth < NEAR_M {
            return None;
        }
        let inv = self.focal_px / depth;
        let x = self.width as f32 / 2.0 + dot(d, self.right) * inv;
        let y = self.height as f32 / 2.0 - dot(d, self.up) * inv;
        Some((x, y, depth))
    }

    /// The unit world direction of the ray through pixel position (x, y).
    pub fn ray(&self, x: f32, y: f32) -> Vec3 {
        let a = (x - self.width as f32 / 2.0) / self.focal_px;
        let b = (self.height as f32 / 2.0 - y) / self.focal_px;
        normalize(add(self.forward, add(scale(self.right, a), scale(self.up, b))))
    }

    /// Where the ray through (x, y) meets the mean water level (east, north), or `None` when
    /// it does not point down.
    pub fn ground_point(&self, x: f32, y: f32) -> Option<[f32; 2]> {
        let r = self.ray(x, y);
        if r[2] >= -1e-6 {
            return None;
        }
        let t = -self.eye[2] / r[2];
        Some([self.eye[0] + r[0] * t, self.eye[1] + r[1] * t])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera::new(CameraPose { heading_deg: 30.0, ..CameraPose::DEFAULT }, 320, 180)
    }

    #[test]
    fn ground_points_project_back_to_their_pixel() {
        let c = camera();
        for (x, y) in [(10.0, 170.0), (160.0, 90.0), (300.0, 60.0)] {
            let g = c.ground_point(x, y).unwrap();
            let (px, py, depth) = c.project([g[0], g[1], 0.0]).unwrap();
            assert!((px - x).abs() < 0.01 && (py - y).abs() < 0.01, "({x}, {y}) -> ({px}, {py})");
            assert!(depth > 0.0);
        }
    }

    #[test]
    fn the_horizon_is_where_rays_turn_level() {
        let c = camera();
        let h = c.horizon_y();
        assert!(h > 0.0 && h < 90.0, "8° down puts the horizon above the centre: {h}");
        assert!(c.ground_point(100.0, h - 1.0).is_none());
        assert!(c.ground_point(100.0, h + 1.0).is_some());
        assert!(c.ray(5.0, h)[2].abs() < 1e-5);
    }

    #[test]
    fn heading_is_clockwise_from_north() {
        let east = Camera::new(CameraPose { heading_deg: 90.0, pitch_down_deg: 0.0, ..CameraPose::DEFAULT }, 100, 100);
        let f = east.forward();
        assert!((f[0] - 1.0).abs() < 1e-6 && f[1].abs() < 1e-6);
        // A point to the south is on the right when looking east.
        let (x, _, _) = east.project([100.0, -10.0, 25.0]).unwrap();
        assert!(x > 50.0);
        assert!(east.project([-100.0, 0.0, 25.0]).is_none(), "behind the camera");
    }

    #[test]
    fn the_mirror_camera_sees_reflections_upside_down() {
        let c = Camera::new(
            CameraPose { height_m: 3.0, pitch_down_deg: 3.0, hfov_deg: 60.0, ..CameraPose::DEFAULT },
            200,
            120,
        );
        let m = c.mirrored();
        // A point on a hill: its reflection, seen by c, is where m sees the point, flipped.
        let p = [14.0, 300.0, 40.0];
        let (rx, ry, _) = c.project([p[0], p[1], -p[2]]).unwrap();
        let (mx, my, _) = m.project(p).unwrap();
        assert!((rx - mx).abs() < 1e-3 && (ry - (120.0 - my)).abs() < 1e-3, "({rx}, {ry}) vs ({mx}, {})", 120.0 - my);
        assert_eq!(m.mirrored(), c);
        // Padding keeps every point where it was, shifted by the padding.
        let big = c.padded(10, 7);
        assert_eq!((big.width(), big.height()), (220, 134));
        let (x, y, _) = c.project(p).unwrap();
        let (bx, by, _) = big.project(p).unwrap();
        assert!((bx - x - 10.0).abs() < 1e-3 && (by - y - 7.0).abs() < 1e-3);
        assert!((big.focal_px() - c.focal_px()).abs() < 1e-3);
    }

    #[test]
    fn horizon_distance() {
        assert!((camera().horizon_distance_m() - 17_847.0).abs() < 5.0);
    }
}
