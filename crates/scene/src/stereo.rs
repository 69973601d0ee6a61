//! Stereo cameras (seed 002: per-eye mirror cameras for stereoscopic views). A camera may
//! carry a `stereo` (`docs/scene-format.md`): the eyes sit `±ipd/2` along the camera's right
//! axis from its position (the head's centre); each eye is a pinhole camera with the
//! project's pixel convention ([`crate::camera`]).
//!
//! - `off-axis` (the default, as VR headsets do): both eyes look along the centre's view
//!   direction with asymmetric frusta, shifted so that the plane at `convergence_distance`
//!   has zero parallax: `shift_x = ±(ipd/2)/(d·tan(fov/2)·aspect)` (left eye −, right +).
//! - `parallel`: both look along the centre's direction, no shift (zero parallax at infinity).
//! - `toe-in`: each eye turns to the point at `convergence_distance` straight ahead of the
//!   centre (vertical parallax at the image's corners: the classic artefact).
//!
//! With `ipd = 0` both eyes are the centre camera exactly.

use crate::Camera;

/// How the eyes converge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Convergence {
    OffAxis,
    Parallel,
    ToeIn,
}

impl Convergence {
    pub fn name(self) -> &'static str {
        match self {
            Convergence::OffAxis => "off-axis",
            Convergence::Parallel => "parallel",
            Convergence::ToeIn => "toe-in",
        }
    }
}

/// One eye.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Eye {
    Left,
    Right,
}

impl Eye {
    pub const BOTH: [Eye; 2] = [Eye::Left, Eye::Right];

    pub fn name(self) -> &'static str {
        match self {
            Eye::Left => "left",
            Eye::Right => "right",
        }
    }

    /// −1 for the left eye, +1 for the right.
    fn sign(self) -> f32 {
        match self {
            Eye::Left => -1.0,
            Eye::Right => 1.0,
        }
    }
}

/// A validated stereo rig.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stereo {
    /// Interpupillary distance, scene units (≥ 0).
    pub ipd: f32,
    pub convergence: Convergence,
    /// Distance of the zero-parallax plane (`off-axis`) or the fixation point (`toe-in`)
    /// from the head's centre along its view direction.
    pub convergence_distance: f32,
}

impl Stereo {
    /// The camera of eye `eye` for the head camera `centre` (module docs).
    pub fn eye(&self, centre: &Camera, eye: Eye) -> Camera {
        if self.ipd == 0.0 {
            return centre.clone();
        }
        let forward = (centre.look_at - centre.position).normalize();
        let right = forward.cross(centre.up).normalize();
        let offset = right * (0.5 * self.ipd * eye.sign());
        let position = centre.position + offset;
        let tan_half = (0.5 * centre.fov_y_deg.to_radians()).tan();
        match self.convergence {
            Convergence::Parallel | Convergence::OffAxis => {
                let shift_x = if self.convergence == Convergence::OffAxis {
                    eye.sign() * 0.5 * self.ipd
                        / (self.convergence_distance * tan_half * centre.aspect())
                } else {
                    0.0
                };
                Camera {
                    position,
                    look_at: centre.look_at + offset,
                    shift_x,
                    ..centre.clone()
                }
            }
            Convergence::ToeIn => Camera {
                position,
                look_at: centre.position + forward * self.convergence_distance,
                ..centre.clone()
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn centre() -> Camera {
        Camera {
            position: Vec3::new(0.0, 1.0, 3.0),
            look_at: Vec3::new(0.2, 1.0, 0.0),
            up: Vec3::Y,
            fov_y_deg: 50.0,
            width: 64,
            height: 36,
            exposure: 1.0,
            shift_x: 0.0,
        }
    }

    fn rig(convergence: Convergence) -> Stereo {
        Stereo {
            ipd: 0.064,
            convergence,
            convergence_distance: 2.0,
        }
    }

    #[test]
    fn a_zero_ipd_gives_the_centre_camera_to_both_eyes() {
        let s = Stereo {
            ipd: 0.0,
            ..rig(Convergence::OffAxis)
        };
        for eye in Eye::BOTH {
            assert_eq!(s.eye(&centre(), eye), centre());
        }
    }

    #[test]
    fn off_axis_eyes_see_the_convergence_plane_at_the_same_pixel() {
        let c = centre();
        let forward = (c.look_at - c.position).normalize();
        let s = rig(Convergence::OffAxis);
        // A point on the zero-parallax plane, off the axis: the same pixel in both eyes.
        let right = forward.cross(c.up).normalize();
        let p = c.position + forward * 2.0 + right * 0.3 + Vec3::Y * 0.2;
        let l = s.eye(&c, Eye::Left).project_to_pixel(p).unwrap();
        let r = s.eye(&c, Eye::Right).project_to_pixel(p).unwrap();
        assert!((l - r).length() < 1e-3, "{l} vs {r}");
        // A farther point has positive (uncrossed) disparity: further right in the right eye.
        let far = c.position + forward * 6.0;
        let (l, r) = (
            s.eye(&c, Eye::Left).project_to_pixel(far).unwrap(),
            s.eye(&c, Eye::Right).project_to_pixel(far).unwrap(),
        );
        assert!(r.x > l.x + 0.1 && (r.y - l.y).abs() < 1e-3, "{l} {r}");
        // The ray generator inverts the shifted projection.
        let eye = s.eye(&c, Eye::Left);
        let px = eye.project_to_pixel(p).unwrap();
        let ray = eye.primary_ray(px.x, px.y);
        let to_p = (p - ray.origin).normalize();
        assert!(ray.dir.dot(to_p) > 1.0 - 1e-6);
    }

    #[test]
    fn parallel_and_toe_in_eyes() {
        let c = centre();
        let forward = (c.look_at - c.position).normalize();
        let p = c.position + forward * 2.0;
        let par = rig(Convergence::Parallel);
        let (l, r) = (
            par.eye(&c, Eye::Left).project_to_pixel(p).unwrap(),
            par.eye(&c, Eye::Right).project_to_pixel(p).unwrap(),
        );
        assert!(l.x > r.x, "parallel: crossed disparity at finite distance");
        let toe = rig(Convergence::ToeIn);
        let (l, r) = (
            toe.eye(&c, Eye::Left).project_to_pixel(p).unwrap(),
            toe.eye(&c, Eye::Right).project_to_pixel(p).unwrap(),
        );
        assert!(
            (l - r).length() < 1e-3 && (l.x - 32.0).abs() < 1e-3,
            "toe-in fixates: {l} {r}"
        );
    }
}
