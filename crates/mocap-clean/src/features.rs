//! What the network sees: the local rotations of a skeleton's joints, frame
//! after frame, in a chosen rotation representation. Root translation is not
//! a feature; it is copied through unchanged.
//!
//! Representations ([`Representation`]):
//! - [`Representation::Rot6d`] (default): the first two columns of each
//!   rotation matrix (Zhou et al. 2019). Continuous: a small change of the
//!   rotation is a small change of the features, with no wrap-around at
//!   +-180 degrees and no gimbal lock, so finite differences along time (the
//!   velocity and acceleration terms of the loss) are meaningful everywhere.
//! - [`Representation::ExpMap`]: rotation vectors, 3 numbers per joint; the
//!   quaternion sign is kept consistent along time, but the vector still
//!   jumps when the rotation angle crosses 180 degrees.
//! - [`Representation::Euler`]: the BVH Euler angles (radians), unwrapped
//!   along time (`unwrap_track`), then each window shifted by whole turns so
//!   that its first frame lies in (-180, 180]; this is what the report feeds,
//!   and it keeps gimbal-lock discontinuities.

use mocap_core::rotation::{
    euler_to_quat, expmap_to_quat, quat_to_6d, quat_to_expmap, rot6d_to_quat, unwrap_track,
    AngleUnit, EulerOrder, Quat, Vec3,
};
use mocap_core::{Motion, Skeleton};
use serde::{Deserialize, Serialize};

use crate::{CleanError, Result};

/// Rotation representation of the network's input and output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Representation {
    #[default]
    Rot6d,
    ExpMap,
    Euler,
}

impl Representation {
    /// Numbers per joint.
    pub fn dim(self) -> usize {
        match self {
            Representation::Rot6d => 6,
            Representation::ExpMap | Representation::Euler => 3,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Representation::Rot6d => "rot6d",
            Representation::ExpMap => "expmap",
            Representation::Euler => "euler",
        }
    }
}

impl std::str::FromStr for Representation {
    type Err = CleanError;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "rot6d" | "6d" => Ok(Representation::Rot6d),
            "expmap" | "exp" => Ok(Representation::ExpMap),
            "euler" => Ok(Representation::Euler),
            _ => Err(CleanError::Invalid(format!(
                "unknown rotation representation `{s}`: expected rot6d, expmap or euler"
            ))),
        }
    }
}

/// Which joints are features and how: the joints with three rotation
/// channels, in skeleton order.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureLayout {
    pub representation: Representation,
    /// Joint indices with features.
    pub joints: Vec<usize>,
    /// Euler order of each of those joints.
    orders: Vec<EulerOrder>,
}

impl FeatureLayout {
    /// The layout of `skeleton`. Joints with one or two rotation channels are
    /// not supported by the denoiser (they are rare in BVH); joints without
    /// rotation channels are left out.
    pub fn new(skeleton: &Skeleton, representation: Representation) -> Result<FeatureLayout> {
        let mut joints = Vec::new();
        let mut orders = Vec::new();
        for (j, joint) in skeleton.joints().iter().enumerate() {
            let rotations = joint.channels.iter().filter(|c| c.is_rotation()).count();
            match (rotations, joint.euler_order()) {
                (0, _) => {}
                (3, Some(order)) => {
                    joints.push(j);
                    orders.push(order);
                }
                _ => {
                    return Err(CleanError::Invalid(format!(
                        "joint `{}` has {rotations} rotation channels; the denoiser needs 0 or 3",
                        joint.name
                    )))
                }
            }
        }
        if joints.is_empty() {
            return Err(CleanError::Invalid(
                "the skeleton has no rotation channels".into(),
            ));
        }
        Ok(FeatureLayout {
            representation,
            joints,
            orders,
        })
    }

    /// Features per frame.
    pub fn channels(&self) -> usize {
        self.joints.len() * self.representation.dim()
    }

    /// Features of every frame of `motion`, frame after frame.
    pub fn encode(&self, motion: &Motion) -> Vec<f32> {
        let frames = motion.frame_count();
        let dim = self.representation.dim();
        let c = self.channels();
        let mut out = vec![0.0; frames * c];
        match self.representation {
            Representation::Rot6d => {
                for f in 0..frames {
                    for (k, &j) in self.joints.iter().enumerate() {
                        let r = quat_to_6d(motion.local_rotation(f, j));
                        out[f * c + k * dim..f * c + (k + 1) * dim].copy_from_slice(&r);
                    }
                }
            }
            Representation::ExpMap => {
                for (k, &j) in self.joints.iter().enumerate() {
                    let mut previous = Quat::IDENTITY;
                    for f in 0..frames {
                        // Keep the quaternion on the hemisphere of the previous
                        // frame's, so the rotation vector does not flip needlessly.
                        let mut q = motion.local_rotation(f, j);
                        if q.dot(previous) < 0.0 {
                            q = -q;
                        }
                        previous = q;
                        let v = quat_to_expmap(q);
                        // quat_to_expmap takes w >= 0; for w < 0 write the
                        // equivalent longer vector to stay continuous.
                        let v = if q.w < 0.0 && v.length() > 0.0 {
                            v - v.normalize() * std::f32::consts::TAU
                        } else {
                            v
                        };
                        out[f * c + k * dim..f * c + (k + 1) * dim].copy_from_slice(&v.to_array());
                    }
                }
            }
            Representation::Euler => {
                let deg = std::f32::consts::PI / 180.0;
                for (k, &j) in self.joints.iter().enumerate() {
                    let start = motion.skeleton().channel_start(j);
                    let rot_slots: Vec<usize> = motion
                        .skeleton()
                        .joint(j)
                        .channels
                        .iter()
                        .enumerate()
                        .filter(|(_, ch)| ch.is_rotation())
                        .map(|(i, _)| i)
                        .collect();
                    for (a, &slot) in rot_slots.iter().enumerate() {
                        let mut track: Vec<f32> = (0..frames)
                            .map(|f| motion.frame(f)[start + slot] * deg)
                            .collect();
                        unwrap_track(&mut track, AngleUnit::Radians);
                        for (f, v) in track.into_iter().enumerate() {
                            out[f * c + k * dim + a] = v;
                        }
                    }
                }
            }
        }
        out
    }

    /// Brings a window of features to a canonical range before it is fed to
    /// the network, and returns what to add back afterwards. Only Euler
    /// angles need it: whole turns are taken off so the first frame of each
    /// channel lies in (-pi, pi].
    pub fn recenter(&self, window: &mut [f32]) -> Vec<f32> {
        let c = self.channels();
        let mut offsets = vec![0.0; c];
        if self.representation == Representation::Euler && window.len() >= c {
            let tau = std::f32::consts::TAU;
            for (ch, offset) in offsets.iter_mut().enumerate() {
                *offset = (window[ch] / tau).round() * tau;
            }
            for frame in window.chunks_mut(c) {
                for (v, o) in frame.iter_mut().zip(&offsets) {
                    *v -= o;
                }
            }
        }
        offsets
    }

    /// The local rotation of feature joint `k` from one frame's features.
    pub fn rotation(&self, frame_features: &[f32], k: usize) -> Quat {
        let dim = self.representation.dim();
        let v = &frame_features[k * dim..(k + 1) * dim];
        match self.representation {
            Representation::Rot6d => rot6d_to_quat([v[0], v[1], v[2], v[3], v[4], v[5]]),
            Representation::ExpMap => expmap_to_quat(Vec3::new(v[0], v[1], v[2])),
            Representation::Euler => euler_to_quat(self.orders[k], Vec3::new(v[0], v[1], v[2])),
        }
    }

    /// Writes the rotations in `features` (frame after frame) into `motion`'s
    /// rotation channels; position channels are left as they are.
    pub fn decode_into(&self, features: &[f32], motion: &mut Motion) {
        let c = self.channels();
        for f in 0..motion.frame_count() {
            let frame = &features[f * c..(f + 1) * c];
            for (k, &j) in self.joints.iter().enumerate() {
                let q = self.rotation(frame, k);
                motion.set_local_rotation(f, j, q);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::synthetic_motion;

    #[test]
    fn every_representation_round_trips() {
        let motion = synthetic_motion(40, 7);
        for repr in [
            Representation::Rot6d,
            Representation::ExpMap,
            Representation::Euler,
        ] {
            let layout = FeatureLayout::new(motion.skeleton(), repr).unwrap();
            let features = layout.encode(&motion);
            let mut back = motion.clone();
            layout.decode_into(&features, &mut back);
            for f in 0..motion.frame_count() {
                for &j in &layout.joints {
                    let a = motion.local_rotation(f, j);
                    let b = back.local_rotation(f, j);
                    let angle = mocap_core::rotation::angle_between(a, b).to_degrees();
                    assert!(
                        angle < 0.05,
                        "{repr:?} frame {f} joint {j}: {angle} degrees"
                    );
                }
            }
        }
    }

    #[test]
    fn euler_windows_are_recentered_by_whole_turns() {
        let motion = synthetic_motion(10, 3);
        let layout = FeatureLayout::new(motion.skeleton(), Representation::Euler).unwrap();
        let mut window = layout.encode(&motion);
        window[0] += 4.0 * std::f32::consts::PI;
        let original = window.clone();
        let offsets = layout.recenter(&mut window);
        assert!(window[0].abs() <= std::f32::consts::PI + 1e-5);
        for (i, v) in window.iter().enumerate() {
            let o = offsets[i % layout.channels()];
            assert!((v + o - original[i]).abs() < 1e-4);
        }
    }
}
