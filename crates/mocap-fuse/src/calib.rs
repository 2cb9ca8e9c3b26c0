//! Calibration: where each sensor is in the world frame, and the file that
//! stores it.
//!
//! # The calibration file (TOML, version 1)
//!
//! ```toml
//! version = 1
//!
//! [[sensor]]
//! id = 0
//! # world_from_sensor: a point p in the sensor's camera space is at
//! # rotation * p + translation in the world (metres).
//! rotation = [1.0, 0.0, 0.0, 0.0]     # unit quaternion, w x y z
//! translation = [0.0, 1.0, -3.0]
//! method = "body"                     # optional: how it was found
//! rms_residual = 0.031                # optional: metres
//! pairs = 5120                        # optional: point pairs used
//! ```
//!
//! The world frame is the frame of one reference sensor (its transform is
//! the identity) unless the calibration was made against known world points.

use std::path::Path;

use mocap_core::rotation::{Quat, Vec3};
use mocap_core::{Error, Result};
use serde::{Deserialize, Serialize};

/// A rotation followed by a translation: `p -> rotation * p + translation`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RigidTransform {
    pub rotation: Quat,
    pub translation: Vec3,
}

impl RigidTransform {
    pub const IDENTITY: RigidTransform = RigidTransform {
        rotation: Quat::IDENTITY,
        translation: Vec3::ZERO,
    };

    pub fn apply(&self, p: Vec3) -> Vec3 {
        self.rotation * p + self.translation
    }

    /// The inverse transform.
    pub fn inverse(&self) -> RigidTransform {
        let r = self.rotation.conjugate();
        RigidTransform {
            rotation: r,
            translation: -(r * self.translation),
        }
    }

    /// `self * other`: first `other`, then `self`.
    pub fn then_after(&self, other: &RigidTransform) -> RigidTransform {
        RigidTransform {
            rotation: (self.rotation * other.rotation).normalize(),
            translation: self.rotation * other.translation + self.translation,
        }
    }
}

/// One sensor's pose in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorPose {
    pub id: u16,
    /// `world_from_sensor`.
    pub transform: RigidTransform,
    pub method: Option<String>,
    pub rms_residual: Option<f64>,
    pub pairs: Option<usize>,
}

/// The poses of all sensors.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Calibration {
    pub sensors: Vec<SensorPose>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CalibrationFile {
    version: u32,
    #[serde(default)]
    sensor: Vec<SensorEntry>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SensorEntry {
    id: u16,
    rotation: [f64; 4],
    translation: [f64; 3],
    #[serde(default, skip_serializing_if = "Option::is_none")]
    method: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    rms_residual: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pairs: Option<usize>,
}

impl Calibration {
    /// The pose of sensor `id`, if calibrated.
    pub fn get(&self, id: u16) -> Option<&RigidTransform> {
        self.sensors
            .iter()
            .find(|s| s.id == id)
            .map(|s| &s.transform)
    }

    /// Sets (or adds) the pose of a sensor.
    pub fn set(&mut self, pose: SensorPose) {
        match self.sensors.iter_mut().find(|s| s.id == pose.id) {
            Some(s) => *s = pose,
            None => self.sensors.push(pose),
        }
        self.sensors.sort_by_key(|s| s.id);
    }

    /// Parses a calibration file's text; `path` is for messages.
    pub fn from_toml_str(text: &str, path: &Path) -> Result<Calibration> {
        let file: CalibrationFile = toml::from_str(text).map_err(|e| {
            let (line, column) = e
                .span()
                .map(|s| mocap_core::error::line_column(text, s.start))
                .unwrap_or((1, 1));
            Error::Parse(mocap_core::ParseError {
                location: mocap_core::error::Location {
                    path: path.to_path_buf(),
                    line,
                    column,
                },
                message: format!("expected a calibration file: {}", e.message()),
            })
        })?;
        if file.version != 1 {
            return Err(Error::Invalid(format!(
                "{}: calibration version {} is not supported (this reader knows 1)",
                path.display(),
                file.version
            )));
        }
        let mut calibration = Calibration::default();
        for s in file.sensor {
            let [w, x, y, z] = s.rotation;
            let norm = (w * w + x * x + y * y + z * z).sqrt();
            if !(norm.is_finite() && (norm - 1.0).abs() < 1e-3) {
                return Err(Error::Invalid(format!(
                    "{}: sensor {}: rotation must be a unit quaternion [w, x, y, z], its norm is {norm}",
                    path.display(),
                    s.id
                )));
            }
            if !s.translation.iter().all(|v| v.is_finite()) {
                return Err(Error::Invalid(format!(
                    "{}: sensor {}: translation must be finite",
                    path.display(),
                    s.id
                )));
            }
            if calibration.get(s.id).is_some() {
                return Err(Error::Invalid(format!(
                    "{}: sensor {} is listed twice",
                    path.display(),
                    s.id
                )));
            }
            calibration.set(SensorPose {
                id: s.id,
                transform: RigidTransform {
                    rotation: Quat::from_xyzw(x as f32, y as f32, z as f32, w as f32).normalize(),
                    translation: Vec3::new(
                        s.translation[0] as f32,
                        s.translation[1] as f32,
                        s.translation[2] as f32,
                    ),
                },
                method: s.method,
                rms_residual: s.rms_residual,
                pairs: s.pairs,
            });
        }
        Ok(calibration)
    }

    /// Reads a calibration file.
    pub fn read(path: &Path) -> Result<Calibration> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        Calibration::from_toml_str(&text, path)
    }

    /// The file's text.
    pub fn to_toml_string(&self) -> String {
        let file = CalibrationFile {
            version: 1,
            sensor: self
                .sensors
                .iter()
                .map(|s| {
                    let q = s.transform.rotation;
                    let t = s.transform.translation;
                    SensorEntry {
                        id: s.id,
                        rotation: [q.w as f64, q.x as f64, q.y as f64, q.z as f64],
                        translation: [t.x as f64, t.y as f64, t.z as f64],
                        method: s.method.clone(),
                        rms_residual: s.rms_residual,
                        pairs: s.pairs,
                    }
                })
                .collect(),
        };
        toml::to_string(&file).expect("a calibration always serializes")
    }

    /// Writes the file atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        mocap_core::io::atomic::write_bytes_atomically(path, self.to_toml_string().as_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn calibration_files_round_trip() {
        let mut c = Calibration::default();
        c.set(SensorPose {
            id: 3,
            transform: RigidTransform {
                rotation: Quat::from_rotation_y(0.7),
                translation: Vec3::new(1.0, 2.0, -3.0),
            },
            method: Some("body".into()),
            rms_residual: Some(0.02),
            pairs: Some(100),
        });
        let text = c.to_toml_string();
        let back = Calibration::from_toml_str(&text, Path::new("c.toml")).unwrap();
        let (a, b) = (c.get(3).unwrap(), back.get(3).unwrap());
        assert!(a.rotation.angle_between(b.rotation) < 1e-5);
        assert!((a.translation - b.translation).length() < 1e-6);
        assert_eq!(back.sensors[0].method.as_deref(), Some("body"));
    }

    #[test]
    fn bad_calibration_files_say_where_and_why() {
        let p = Path::new("c.toml");
        let err = Calibration::from_toml_str("version = 1\n[[sensor]]\nid = \"x\"\n", p)
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("c.toml:3:"), "{err}");
        let err = Calibration::from_toml_str(
            "version = 1\n[[sensor]]\nid = 1\nrotation = [2, 0, 0, 0]\ntranslation = [0, 0, 0]\n",
            p,
        )
        .unwrap_err()
        .to_string();
        assert!(err.contains("unit quaternion"), "{err}");
    }

    #[test]
    fn transforms_compose_and_invert() {
        let a = RigidTransform {
            rotation: Quat::from_rotation_z(0.3),
            translation: Vec3::new(1.0, 0.0, 2.0),
        };
        let p = Vec3::new(0.3, -0.2, 1.0);
        assert!((a.inverse().apply(a.apply(p)) - p).length() < 1e-6);
        let b = a.then_after(&a.inverse());
        assert!((b.apply(p) - p).length() < 1e-6);
    }
}
