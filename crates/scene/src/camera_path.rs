//! Camera paths (`camera.path`): keyframes of position, look-at point, up and field of view
//! with times in seconds, so that every method and the truth can be rendered along the same
//! motion, frame by frame, deterministically (issue 22; `--time T` on `trace` and `render`).
//!
//! Between keys the position and the look-at point follow a cubic Hermite curve in time
//! whose tangents are Catmull–Rom's, weighted by the keys' times
//! (`m_i = (p_{i+1} − p_{i−1}) / (t_{i+1} − t_{i−1})`, one-sided at the ends): the curve passes
//! through every key and its velocity is continuous. The field of view is interpolated
//! linearly, the up direction by normalised linear interpolation. Before the first key and
//! after the last the camera holds still. One key is a still camera.

use crate::camera::Camera;
use glam::Vec3;

/// Most keys a path may hold.
pub const MAX_KEYS: usize = 10_000;

/// One validated key.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraKey {
    pub time: f64,
    pub position: Vec3,
    pub look_at: Vec3,
    /// Unit up hint.
    pub up: Vec3,
    pub fov_y_deg: f32,
}

/// A validated path: at least one key, times strictly increasing.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraPath {
    keys: Vec<CameraKey>,
}

/// A time at which the interpolated camera is degenerate (it looks at its own position, or
/// along its up direction).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("at time {time} s the camera path {what}; add a key near that time")]
pub struct DegenerateView {
    pub time: f64,
    pub what: &'static str,
}

impl CameraPath {
    /// A path of `keys` (checked by the loader: non-empty, strictly increasing times).
    pub fn new(keys: Vec<CameraKey>) -> Self {
        assert!(!keys.is_empty(), "a camera path has at least one key");
        assert!(
            keys.windows(2).all(|w| w[0].time < w[1].time),
            "camera path times increase strictly"
        );
        CameraPath { keys }
    }

    pub fn keys(&self) -> &[CameraKey] {
        &self.keys
    }

    /// First and last key times.
    pub fn span(&self) -> (f64, f64) {
        (self.keys[0].time, self.keys[self.keys.len() - 1].time)
    }

    /// Position and look-at tangent of key `i` (units per second).
    fn tangents(&self, i: usize) -> (Vec3, Vec3) {
        let k = &self.keys;
        let (a, b) = (i.saturating_sub(1), (i + 1).min(k.len() - 1));
        if a == b {
            return (Vec3::ZERO, Vec3::ZERO);
        }
        let dt = (k[b].time - k[a].time) as f32;
        (
            (k[b].position - k[a].position) / dt,
            (k[b].look_at - k[a].look_at) / dt,
        )
    }

    /// The key values at `time` (held outside the path's span).
    pub fn key_at(&self, time: f64) -> CameraKey {
        let k = &self.keys;
        let (t0, t1) = self.span();
        // NaN holds the first key too (callers check their times; this never panics).
        if time <= t0 || time.is_nan() {
            return k[0];
        }
        if time >= t1 {
            return k[k.len() - 1];
        }
        // The segment [k[i], k[i + 1]] holding `time`.
        let i = k.partition_point(|key| key.time <= time) - 1;
        let (a, b) = (&k[i], &k[i + 1]);
        let h = (b.time - a.time) as f32;
        let s = ((time - a.time) / (b.time - a.time)) as f32;
        let (s2, s3) = (s * s, s * s * s);
        let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
        let h10 = s3 - 2.0 * s2 + s;
        let h01 = -2.0 * s3 + 3.0 * s2;
        let h11 = s3 - s2;
        let (ma_p, ma_l) = self.tangents(i);
        let (mb_p, mb_l) = self.tangents(i + 1);
        let hermite = |p0: Vec3, m0: Vec3, p1: Vec3, m1: Vec3| {
            h00 * p0 + h10 * h * m0 + h01 * p1 + h11 * h * m1
        };
        CameraKey {
            time,
            position: hermite(a.position, ma_p, b.position, mb_p),
            look_at: hermite(a.look_at, ma_l, b.look_at, mb_l),
            up: a.up.lerp(b.up, s).normalize_or(a.up),
            fov_y_deg: a.fov_y_deg + (b.fov_y_deg - a.fov_y_deg) * s,
        }
    }

    /// `base` (its size, exposure and lens kept) placed as the path says at `time`.
    pub fn camera_at(&self, base: &Camera, time: f64) -> Result<Camera, DegenerateView> {
        let key = self.key_at(time);
        let forward = (key.look_at - key.position)
            .try_normalize()
            .ok_or(DegenerateView {
                time,
                what: "looks at its own position",
            })?;
        if forward.cross(key.up).length() < 1e-4 {
            return Err(DegenerateView {
                time,
                what: "looks along its up direction",
            });
        }
        Ok(Camera {
            position: key.position,
            look_at: key.look_at,
            up: key.up,
            fov_y_deg: key.fov_y_deg,
            ..base.clone()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time: f64, x: f32) -> CameraKey {
        CameraKey {
            time,
            position: Vec3::new(x, 1.0, 3.0),
            look_at: Vec3::new(x, 1.0, 0.0),
            up: Vec3::Y,
            fov_y_deg: 40.0 + x,
        }
    }

    #[test]
    fn the_path_passes_through_its_keys_and_holds_at_the_ends() {
        let path = CameraPath::new(vec![key(0.0, 0.0), key(1.0, 2.0), key(3.0, 1.0)]);
        for k in path.keys() {
            let at = path.key_at(k.time);
            assert!(at.position.distance(k.position) < 1e-5, "{at:?} vs {k:?}");
            assert!((at.fov_y_deg - k.fov_y_deg).abs() < 1e-5);
        }
        assert_eq!(path.key_at(-5.0).position, path.keys()[0].position);
        assert_eq!(path.key_at(9.0).position, path.keys()[2].position);
        // Between keys: on the way, fov linear.
        let mid = path.key_at(0.5);
        assert!(mid.position.x > 0.0 && mid.position.x < 2.0);
        assert!((mid.fov_y_deg - 41.0).abs() < 1e-5);
    }

    #[test]
    fn motion_is_smooth_across_keys() {
        let path = CameraPath::new(vec![key(0.0, 0.0), key(1.0, 2.0), key(3.0, 1.0)]);
        // Velocity just before and just after the middle key agree (C1).
        let v = |t0: f64, t1: f64| {
            (path.key_at(t1).position - path.key_at(t0).position) / (t1 - t0) as f32
        };
        let (before, after) = (v(1.0 - 2e-3, 1.0 - 1e-3), v(1.0 + 1e-3, 1.0 + 2e-3));
        assert!((before - after).length() < 0.02, "{before} vs {after}");
        // Catmull–Rom's tangent at the middle key: (p2 − p0) / (t2 − t0) = 1/3 along x.
        assert!((before.x - 1.0 / 3.0).abs() < 0.02, "{before}");
    }

    #[test]
    fn one_key_is_a_still_camera_and_degenerate_views_are_refused() {
        let base = Camera {
            position: Vec3::ZERO,
            look_at: Vec3::NEG_Z,
            up: Vec3::Y,
            fov_y_deg: 45.0,
            width: 64,
            height: 32,
            exposure: 1.5,
            shift_x: 0.0,
        };
        let still = CameraPath::new(vec![key(2.0, 0.5)]);
        for t in [0.0, 2.0, 7.0] {
            let c = still.camera_at(&base, t).unwrap();
            assert_eq!(c.position, Vec3::new(0.5, 1.0, 3.0));
            assert_eq!((c.width, c.height, c.exposure), (64, 32, 1.5));
        }
        let mut k = key(0.0, 0.0);
        k.look_at = k.position;
        let bad = CameraPath::new(vec![k]);
        assert!(bad.camera_at(&base, 0.0).is_err());
    }
}
