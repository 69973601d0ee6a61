//! The viewer's free camera: a position and a heading (yaw about the scene camera's up,
//! pitch towards it), turned back into the scene's [`Camera`] that both renderers use.
//!
//! Until it moves, it gives back the scene's camera exactly (bit for bit), so the first
//! frames of `mirrorbox view` are the offline `render` and `trace` of the scene file.

use glam::Vec3;
use mirrorbox_scene::Camera;

/// Pitch stays this far from straight up or down, where yaw would be undefined.
const MAX_PITCH_DEG: f32 = 89.0;

#[derive(Clone, Debug)]
pub struct FlyCamera {
    /// The scene's camera, the reset target; its size and exposure are kept.
    home: Camera,
    /// Unit up, and the horizontal frame yaw turns in: `front` ⟂ `up`, `right` = front × up.
    up: Vec3,
    front: Vec3,
    right: Vec3,
    position: Vec3,
    yaw_deg: f32,
    pitch_deg: f32,
    fov_y_deg: f32,
    /// False until the camera moves: then [`FlyCamera::camera`] is the home camera itself.
    moved: bool,
}

impl FlyCamera {
    pub fn new(home: Camera) -> Self {
        let up = home.up.normalize();
        let forward = (home.look_at - home.position).normalize();
        // A view straight along `up` has no horizontal heading: pick any perpendicular.
        let horizontal = forward - up * forward.dot(up);
        let front = if horizontal.length_squared() > 1e-12 {
            horizontal.normalize()
        } else {
            up.any_orthonormal_vector()
        };
        let right = front.cross(up);
        let pitch_deg = forward.dot(up).clamp(-1.0, 1.0).asin().to_degrees();
        FlyCamera {
            up,
            front,
            right,
            position: home.position,
            yaw_deg: 0.0,
            pitch_deg: pitch_deg.clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG),
            fov_y_deg: home.fov_y_deg,
            home,
            moved: false,
        }
    }

    /// Back to the scene's camera.
    pub fn reset(&mut self) {
        *self = FlyCamera::new(self.home.clone());
    }

    /// Unit view direction: `cos p (cos y front + sin y right) + sin p up`.
    pub fn forward(&self) -> Vec3 {
        let (sy, cy) = self.yaw_deg.to_radians().sin_cos();
        let (sp, cp) = self.pitch_deg.to_radians().sin_cos();
        (cp * (cy * self.front + sy * self.right) + sp * self.up).normalize()
    }

    /// Unit right of the view, horizontal.
    pub fn right(&self) -> Vec3 {
        self.forward().cross(self.up).normalize_or(self.right)
    }

    pub fn up(&self) -> Vec3 {
        self.up
    }

    pub fn position(&self) -> Vec3 {
        self.position
    }

    pub fn fov_y_deg(&self) -> f32 {
        self.fov_y_deg
    }

    /// Turns by `yaw` degrees (positive: to the right) and `pitch` degrees (positive: up).
    pub fn turn(&mut self, yaw_deg: f32, pitch_deg: f32) {
        if yaw_deg == 0.0 && pitch_deg == 0.0 {
            return;
        }
        self.yaw_deg = (self.yaw_deg + yaw_deg).rem_euclid(360.0);
        self.pitch_deg = (self.pitch_deg + pitch_deg).clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG);
        self.moved = true;
    }

    /// Moves by `forward`, `right` and `up` scene units along the view's axes (`up` along the
    /// scene camera's up).
    pub fn walk(&mut self, forward: f32, right: f32, up: f32) {
        if forward == 0.0 && right == 0.0 && up == 0.0 {
            return;
        }
        self.position += forward * self.forward() + right * self.right() + up * self.up;
        self.moved = true;
    }

    /// Sets the vertical field of view, within (1°, 170°).
    pub fn set_fov(&mut self, fov_y_deg: f32) {
        let fov = fov_y_deg.clamp(1.0, 170.0);
        if fov != self.fov_y_deg {
            self.fov_y_deg = fov;
            self.moved = true;
        }
    }

    /// Places the camera at `position` looking at `look_at` (the scene's up kept).
    pub fn look(&mut self, position: Vec3, look_at: Vec3) {
        let mut home = self.home.clone();
        home.position = position;
        home.look_at = look_at;
        let keep = self.home.clone();
        *self = FlyCamera::new(home);
        self.home = keep;
        self.moved = true;
    }

    /// The scene camera at this position and heading, at `width × height` pixels.
    pub fn camera(&self, width: u32, height: u32) -> Camera {
        let mut camera = self.home.clone();
        if self.moved {
            camera.position = self.position;
            camera.look_at = self.position + self.forward();
            camera.up = self.up;
            camera.fov_y_deg = self.fov_y_deg;
        }
        camera.width = width;
        camera.height = height;
        camera
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn home() -> Camera {
        Camera {
            position: Vec3::new(0.8, 1.8, 1.7),
            look_at: Vec3::new(-0.25, 1.15, -2.0),
            up: Vec3::Y,
            fov_y_deg: 45.0,
            width: 640,
            height: 360,
            exposure: 1.0,
            shift_x: 0.0,
        }
    }

    #[test]
    fn an_unmoved_camera_is_the_scene_camera_bit_for_bit() {
        let fly = FlyCamera::new(home());
        let c = fly.camera(640, 360);
        assert_eq!(format!("{c:?}"), format!("{:?}", home()));
        let forward = (home().look_at - home().position).normalize();
        assert!(fly.forward().distance(forward) < 1e-6, "{}", fly.forward());
    }

    #[test]
    fn turning_right_looks_right_and_walking_follows_the_view() {
        let mut fly = FlyCamera::new(home());
        let before = fly.forward();
        fly.turn(90.0, 0.0);
        // Seen from above (up = +Y), a right turn is clockwise: the new view is old × up.
        let expected = before.cross(Vec3::Y);
        assert!(
            fly.forward().dot(expected.normalize()) > 0.98,
            "{}",
            fly.forward()
        );
        let p0 = fly.position();
        fly.walk(2.0, 0.0, 0.0);
        assert!((fly.position() - p0 - 2.0 * fly.forward()).length() < 1e-5);
        fly.walk(0.0, 0.0, 1.0);
        assert!((fly.position().y - p0.y - 1.0 - 2.0 * fly.forward().y).abs() < 1e-5);
        let c = fly.camera(320, 180);
        assert_eq!((c.width, c.height), (320, 180));
        assert!((c.look_at - c.position - fly.forward()).length() < 1e-6);
    }

    #[test]
    fn pitch_is_clamped_short_of_the_pole_and_reset_goes_home() {
        let mut fly = FlyCamera::new(home());
        fly.turn(0.0, 500.0);
        assert!(fly.forward().dot(Vec3::Y) < 1.0 && fly.forward().dot(Vec3::Y) > 0.99);
        assert!(fly.forward().is_finite());
        fly.reset();
        assert_eq!(
            format!("{:?}", fly.camera(640, 360)),
            format!("{:?}", home())
        );
    }
}
