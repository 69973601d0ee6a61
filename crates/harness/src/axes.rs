//! Scene axes: a setting of a point's scene that a sweep varies beside the methods and α —
//! the twin of the raster registry's `OptionSpec` for the scene instead of the method.
//!
//! An [`AxisSpec`] says everything the harness needs of an axis: its name (in a record's
//! `axes` map and in the resume key, `|name=value`: frozen), its flag and bounds (parsed and
//! checked here for every axis alike), how a point's label, image names and truth name show a
//! value, and how a value is applied to the point's scene. The sweep, the worker, the resume
//! keys and the records read the [`AXES`] table; adding an axis is one entry here (and its
//! flag on `mirrorbox sweep`).

use crate::HarnessError;
use mirrorbox_scene::Scene;
use mirrorbox_scene::limits::SettingError;

/// One scene axis (see the module doc).
pub struct AxisSpec {
    /// The name in a record's `axes` map and in the resume key: frozen, earlier
    /// `results.jsonl` files resume by it.
    pub name: &'static str,
    /// The `mirrorbox sweep` flag that lists its values.
    pub flag: &'static str,
    /// What one value is, for errors: "symmetry plane counts".
    pub what: &'static str,
    /// Allowed values: `[min, max]` (`[min, max)` when `max_open`), whole numbers when
    /// `integer`.
    pub min: f64,
    pub max: f64,
    pub max_open: bool,
    pub integer: bool,
    /// The word a list may hold for "this axis not applied" (the stereo axis' `mono`).
    pub none_word: Option<&'static str>,
    /// A point's label shows a value as `{label}{value}{unit}` (` p=3`, ` bump=2.5°`).
    pub label: &'static str,
    pub unit: &'static str,
    /// Image and truth file names show it as `{slug}{value}`.
    pub slug: &'static str,
    /// Sets the value on a point's scene; `base` is the sweep's scene as loaded (an axis that
    /// rebuilds the scene from it, as the symmetry planes do, comes first in [`AXES`]).
    pub apply: fn(base: &Scene, scene: &mut Scene, value: f64) -> Result<(), HarnessError>,
}

/// Symmetry planes p (seed 001): the point's scene keeps the first p of the scene's
/// `symmetry_planes`.
pub const SYMMETRY_PLANES: AxisSpec = AxisSpec {
    name: "planes",
    flag: "--symmetry-planes",
    what: "symmetry plane counts",
    min: 0.0,
    max: mirrorbox_scene::symmetry::MAX_SYMMETRY_PLANES as f64,
    max_open: false,
    integer: true,
    none_word: None,
    label: " p=",
    unit: "",
    slug: "p",
    apply: |base, scene, p| {
        *scene = base.with_symmetry_planes(p as usize)?;
        Ok(())
    },
};

/// Mirrored-light depth k (issue 15, docs/shading.md): surfaces lit through chains of at most
/// k mirrors (`lighting.mirrored_lights`).
pub const MIRRORED_LIGHTS: AxisSpec = AxisSpec {
    name: "mirrored_lights",
    flag: "--mirrored-lights",
    what: "mirrored-light depths",
    min: 0.0,
    max: mirrorbox_scene::light_images::MAX_MIRRORED_LIGHTS as f64,
    max_open: false,
    integer: true,
    none_word: None,
    label: " k=",
    unit: "",
    slug: "k",
    apply: |_, scene, k| {
        scene.lighting.mirrored_lights = k as u32;
        Ok(())
    },
};

/// The uneven mirrors' steepest tilt, degrees (issue 16, docs/shading.md).
pub const BUMP_AMPLITUDE: AxisSpec = AxisSpec {
    name: "bump_deg",
    flag: "--bump-amplitude",
    what: "tilts in degrees",
    min: 0.0,
    max: mirrorbox_scene::bump::MAX_AMPLITUDE_DEG as f64,
    max_open: true,
    integer: false,
    none_word: None,
    label: " bump=",
    unit: "°",
    slug: "b",
    apply: |_, scene, a| {
        scene.set_bump_amplitude(a as f32);
        Ok(())
    },
};

/// A stereo pair's interpupillary distance, scene units (issue 17, seed 002): the point
/// renders both eyes of the scene's rig; `mono` is the plain frame.
pub const STEREO_IPD: AxisSpec = AxisSpec {
    name: "stereo_ipd",
    flag: "--ipd",
    what: "interpupillary distances in scene units",
    min: 0.0,
    max: 1.0,
    max_open: false,
    integer: false,
    none_word: Some("mono"),
    label: " stereo IPD ",
    unit: "",
    slug: "ipd",
    apply: |base, scene, d| {
        scene.stereo = Some(base.stereo_rig(d as f32));
        Ok(())
    },
};

/// The camera turned about the scene's up axis through its position, degrees, positive to
/// the left (issue 39): the same scene seen with more or less of what its mirrors reflect on
/// screen — the share screen-space reflections depend on.
pub const CAMERA_YAW: AxisSpec = AxisSpec {
    name: "yaw_deg",
    flag: "--camera-yaw",
    what: "camera turns in degrees",
    min: -180.0,
    max: 180.0,
    max_open: false,
    integer: false,
    none_word: None,
    label: " yaw=",
    unit: "°",
    slug: "yaw",
    apply: |_, scene, deg| {
        let c = &mut scene.camera;
        let turn = glam::Quat::from_axis_angle(c.up.normalize(), (deg as f32).to_radians());
        c.look_at = c.position + turn * (c.look_at - c.position);
        Ok(())
    },
};

/// Every scene axis, in the order a point's scene applies them and its key names them.
pub const AXES: [&AxisSpec; 5] = [
    &SYMMETRY_PLANES,
    &MIRRORED_LIGHTS,
    &BUMP_AMPLITUDE,
    &STEREO_IPD,
    &CAMERA_YAW,
];

/// The axis named `name`.
pub fn axis(name: &str) -> Option<&'static AxisSpec> {
    AXES.iter().copied().find(|a| a.name == name)
}

impl AxisSpec {
    /// A value as keys, labels and file names show it: a whole number, or the shortest
    /// decimal of its `f32` (as the keys of earlier sweeps, which held `f32`s).
    pub fn text(&self, v: f64) -> String {
        if self.integer {
            format!("{}", v as u64)
        } else {
            format!("{}", v as f32)
        }
    }

    /// The values' range in words: `each 0..=16, whole numbers`.
    pub fn allowed(&self) -> String {
        let close = if self.max_open { ")" } else { "]" };
        let kind = if self.integer { ", whole numbers" } else { "" };
        let none = self
            .none_word
            .map_or(String::new(), |w| format!(", or {w}"));
        format!(
            "{} each in [{}, {}{close}{kind}{none}",
            self.what,
            self.text(self.min),
            self.text(self.max)
        )
    }

    /// Whether `v` is an allowed value.
    pub fn allows(&self, v: f64) -> bool {
        v.is_finite()
            && v >= self.min
            && (v < self.max || (!self.max_open && v == self.max))
            && (!self.integer || v.fract() == 0.0)
    }

    /// Checks a list of values (`None`: the axis' none word).
    pub fn check(&self, values: &[Option<f64>]) -> Result<(), SettingError> {
        if values.is_empty() {
            return Err(SettingError::new(self.flag, self.allowed(), "none"));
        }
        for v in values {
            match v {
                None if self.none_word.is_none() => {
                    return Err(SettingError::new(self.flag, self.allowed(), "none"));
                }
                Some(x) if !self.allows(*x) => {
                    return Err(SettingError::new(self.flag, self.allowed(), x));
                }
                _ => {}
            }
        }
        Ok(())
    }

    /// Parses a flag's text: values comma separated, a whole-number axis also a range `a..=b`
    /// or `a..b` (both ends included, as the methods' `--n 0..4` reads), the none word where
    /// the axis has one; each checked.
    pub fn parse(&self, text: &str) -> Result<Vec<Option<f64>>, SettingError> {
        let bad = |got: &str| SettingError::new(self.flag, self.allowed(), format!("{got:?}"));
        let too_many = || {
            SettingError::new(
                self.flag,
                format!("at most {MAX_AXIS_VALUES} values in all"),
                "more",
            )
        };
        let mut out = Vec::new();
        for part in text.split(',').map(str::trim) {
            if Some(part) == self.none_word {
                out.push(None);
            } else if let Some((a, b)) = part.split_once("..").filter(|_| self.integer) {
                let b = b.strip_prefix('=').unwrap_or(b);
                let (a, b): (u64, u64) = (
                    a.trim().parse().map_err(|_| bad(part))?,
                    b.trim().parse().map_err(|_| bad(part))?,
                );
                if b < a || b - a > MAX_AXIS_VALUES as u64 {
                    return Err(bad(part));
                }
                // Each end checked before the range is spelled out.
                self.check(&[Some(a as f64), Some(b as f64)])?;
                if out.len() as u64 + (b - a + 1) > MAX_AXIS_VALUES as u64 {
                    return Err(too_many());
                }
                out.extend((a..=b).map(|v| Some(v as f64)));
            } else {
                out.push(Some(part.parse::<f64>().map_err(|_| bad(part))?));
            }
            if out.len() > MAX_AXIS_VALUES {
                return Err(too_many());
            }
        }
        self.check(&out)?;
        Ok(out)
    }
}

/// Most values one axis flag may list, ranges spelled out: bounded before a long list of
/// ranges is expanded (5 000 ranges of 10 000 had taken 790 MB before the first value was
/// refused).
pub const MAX_AXIS_VALUES: usize = 10_000;

/// One axis of a sweep and the values it takes (`None`: the axis not applied, e.g. `mono`).
#[derive(Clone)]
pub struct AxisValues {
    pub axis: &'static AxisSpec,
    pub values: Vec<Option<f64>>,
}

impl std::fmt::Debug for AxisValues {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}={:?}", self.axis.name, self.values)
    }
}

/// A point's setting of the axes it has, in [`AXES`] order.
pub type PointAxes = Vec<(&'static AxisSpec, f64)>;

/// The point's scene: the floor's without mirrors, or the base scene with each axis applied
/// in [`AXES`] order.
pub(crate) fn apply_axes(
    base: &Scene,
    floor: bool,
    axes: &[(&'static AxisSpec, f64)],
) -> Result<Scene, HarnessError> {
    let mut scene = if floor {
        base.without_mirrors()
    } else {
        base.clone()
    };
    // A mono point renders one frame, whatever the file's camera says.
    scene.stereo = None;
    for spec in AXES {
        if let Some((_, v)) = axes.iter().find(|(a, _)| a.name == spec.name) {
            (spec.apply)(base, &mut scene, *v)?;
        }
    }
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_parsed_and_bounded_alike_for_every_axis() {
        assert_eq!(
            SYMMETRY_PLANES.parse("0..=2,5").unwrap(),
            vec![Some(0.0), Some(1.0), Some(2.0), Some(5.0)]
        );
        // `a..b` reads as the methods' `--n 0..4` does: both ends included.
        assert_eq!(
            SYMMETRY_PLANES.parse("0..2").unwrap(),
            SYMMETRY_PLANES.parse("0..=2").unwrap()
        );
        assert!(SYMMETRY_PLANES.parse("17").is_err());
        assert!(SYMMETRY_PLANES.parse("1.5").is_err());
        assert!(
            BUMP_AMPLITUDE.parse("90").is_err(),
            "90° is outside [0, 90)"
        );
        assert_eq!(BUMP_AMPLITUDE.parse("2.5").unwrap(), vec![Some(2.5)]);
        assert_eq!(
            STEREO_IPD.parse("mono,0.05").unwrap(),
            vec![None, Some(0.05)]
        );
        assert!(MIRRORED_LIGHTS.parse("mono").is_err());
        let e = MIRRORED_LIGHTS.parse("x").unwrap_err().to_string();
        assert!(e.contains("--mirrored-lights"), "{e}");
        // A long list of ranges is bounded before it is spelled out: an end out of range is
        // refused by itself, and the values in all at MAX_AXIS_VALUES.
        let e = SYMMETRY_PLANES.parse("0..10000").unwrap_err().to_string();
        assert!(e.contains("got 10000"), "{e}");
        let k = MIRRORED_LIGHTS.max as u64;
        let many = vec![format!("0..{k}"); MAX_AXIS_VALUES / (k as usize + 1) + 1].join(",");
        let e = MIRRORED_LIGHTS.parse(&many).unwrap_err().to_string();
        assert!(
            e.contains(&format!("at most {MAX_AXIS_VALUES} values")),
            "{e}"
        );
        let fit = vec![format!("0..{k}"); MAX_AXIS_VALUES / (k as usize + 1)].join(",");
        assert!(MIRRORED_LIGHTS.parse(&fit).is_ok());
    }

    #[test]
    fn a_value_reads_as_the_keys_of_earlier_sweeps_did() {
        // Earlier keys formatted the f32 the flag parsed: `|bump_deg=2.5`, `|stereo_ipd=0.025`.
        assert_eq!(STEREO_IPD.text(0.025), "0.025");
        assert_eq!(BUMP_AMPLITUDE.text(2.5), "2.5");
        assert_eq!(SYMMETRY_PLANES.text(3.0), "3");
        let names: Vec<&str> = AXES.iter().map(|a| a.name).collect();
        // Frozen: an axis is appended, never renamed (issue 39 added `yaw_deg`).
        assert_eq!(
            names,
            [
                "planes",
                "mirrored_lights",
                "bump_deg",
                "stereo_ipd",
                "yaw_deg"
            ]
        );
        assert_eq!(CAMERA_YAW.text(-22.5), "-22.5");
        // The reports label each axis in words of their own (mirrorbox_report::axis::label):
        // an axis added here gets its words there, not the `name=value` of an unknown one.
        for a in AXES {
            let label = mirrorbox_report::axis::label(a.name, 1.0);
            assert!(!label.starts_with(a.name), "{}: {label}", a.name);
        }
    }

    #[test]
    fn a_camera_turn_looks_left_for_positive_degrees_and_keeps_the_position() {
        let base = mirrorbox_scene::load::bundled_scene("mirror_box.json");
        let mut scene = base.clone();
        (CAMERA_YAW.apply)(&base, &mut scene, 90.0).unwrap();
        let (c0, c1) = (&base.camera, &scene.camera);
        assert_eq!(c0.position, c1.position);
        let (f0, f1) = (c0.look_at - c0.position, c1.look_at - c1.position);
        assert!((f0.length() - f1.length()).abs() < 1e-4);
        // About the up axis: the part along it kept, the rest turned a quarter.
        let up = c0.up.normalize();
        let flat = |f: glam::Vec3| f - up * f.dot(up);
        assert!((f0.dot(up) - f1.dot(up)).abs() < 1e-4);
        assert!(
            flat(f0).dot(flat(f1)).abs() < 1e-4 * f0.length_squared(),
            "a quarter turn"
        );
        // Left of the old view: along −right = up × forward.
        let left = c0.up.cross(f0);
        assert!(f1.dot(left) > 0.0, "{f0} → {f1}");
    }
}
