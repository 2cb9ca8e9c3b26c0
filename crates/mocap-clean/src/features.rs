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
//!
//! Frames ([`RotationFrame`]): each joint's rotation is either its local
//! rotation (relative to its parent, what BVH stores) or, for the joints
//! below the pelvis, its rotation relative to the pelvis (the product of the
//! local rotations from the pelvis down to the joint). See
//! [`RotationFrame::Pelvis`] for why the second suits capture noise.

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

/// Which rotation of each joint is a feature.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RotationFrame {
    /// The local rotation of each joint, relative to its parent (what BVH
    /// stores).
    #[default]
    Local,
    /// For the joints below the pelvis, the rotation relative to the pelvis
    /// `P^-1 G_j` (`G` global rotations); the pelvis and the joints above it
    /// keep their local rotations (so the heading stays where it was and the
    /// features do not depend on which way the performer faces). The pelvis
    /// is found from the hierarchy alone
    /// ([`Skeleton::first_branching_joint`]: `Hips` in Bandai and CMU BVH,
    /// `root` in ASF).
    ///
    /// Why: markerless capture errs on each keypoint on its own, so its
    /// rotation errors are independent per joint in *global* terms, and the
    /// chain-corrected noise ([`crate::RandomNoise`]) is built that way. In local
    /// terms each joint's error also carries its parent's error, undone: the
    /// errors of parent and child compensate each other, and a network that
    /// reduces them one joint at a time breaks the compensation, so the
    /// positions get worse while the rotations get better. Relative to the
    /// pelvis the errors stay independent per joint (plus the pelvis's own,
    /// which all joints share).
    Pelvis,
}

impl RotationFrame {
    pub fn name(self) -> &'static str {
        match self {
            RotationFrame::Local => "local",
            RotationFrame::Pelvis => "pelvis",
        }
    }
}

impl std::str::FromStr for RotationFrame {
    type Err = CleanError;
    fn from_str(s: &str) -> Result<Self> {
        match s {
            "local" => Ok(RotationFrame::Local),
            "pelvis" => Ok(RotationFrame::Pelvis),
            _ => Err(CleanError::Invalid(format!(
                "unknown rotation frame `{s}`: expected local or pelvis"
            ))),
        }
    }
}

/// Which joints are features and how: the joints with three rotation
/// channels, in skeleton order.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureLayout {
    pub representation: Representation,
    pub frame: RotationFrame,
    /// Joint indices with features.
    pub joints: Vec<usize>,
    /// Euler order of each of those joints.
    orders: Vec<EulerOrder>,
    /// The pelvis (see [`RotationFrame::Pelvis`]).
    pelvis: usize,
    /// Per skeleton joint: whether it lies below the pelvis.
    below_pelvis: Vec<bool>,
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
        let pelvis = skeleton.first_branching_joint();
        let mut below_pelvis = vec![false; skeleton.joint_count()];
        for (j, joint) in skeleton.joints().iter().enumerate() {
            if let Some(p) = joint.parent {
                // Parents come before their children (checked by `Skeleton`).
                below_pelvis[j] = p == pelvis || below_pelvis[p];
            }
        }
        Ok(FeatureLayout {
            representation,
            frame: RotationFrame::Local,
            joints,
            orders,
            pelvis,
            below_pelvis,
        })
    }

    /// The names of the joints with features, in feature order: what a
    /// model or filter fitted to one rig checks another take's rig against.
    pub fn joint_names(&self, skeleton: &Skeleton) -> Vec<String> {
        self.joints
            .iter()
            .map(|&j| skeleton.joint(j).name.clone())
            .collect()
    }

    /// The same layout with rotations in `frame`. Euler angles only come in
    /// the local frame: their channel order is the joint's own.
    pub fn in_frame(mut self, frame: RotationFrame) -> Result<FeatureLayout> {
        if frame != RotationFrame::Local && self.representation == Representation::Euler {
            return Err(CleanError::Invalid(format!(
                "Euler angles are local rotations; rotations in the {} frame need rot6d or expmap",
                frame.name()
            )));
        }
        self.frame = frame;
        Ok(self)
    }

    /// The rotation of every feature joint in frame `f`, in the layout's
    /// frame, into `out`; `globals` is room for the global rotations the
    /// pelvis frame needs (forward kinematics of that frame alone).
    fn frame_rotations(
        &self,
        motion: &Motion,
        f: usize,
        globals: &mut Vec<Quat>,
        out: &mut Vec<Quat>,
    ) {
        out.clear();
        match self.frame {
            RotationFrame::Local => {
                out.extend(self.joints.iter().map(|&j| motion.local_rotation(f, j)));
            }
            RotationFrame::Pelvis => {
                // As `forward_kinematics`: R_j = R_parent * q_j.
                globals.clear();
                for (j, joint) in motion.skeleton().joints().iter().enumerate() {
                    let local = motion.local_rotation(f, j);
                    let global = match joint.parent {
                        Some(p) => globals[p] * local,
                        None => local,
                    };
                    globals.push(global);
                }
                let pelvis = globals[self.pelvis].conjugate();
                out.extend(self.joints.iter().map(|&j| {
                    if self.below_pelvis[j] {
                        (pelvis * globals[j]).normalize()
                    } else {
                        motion.local_rotation(f, j)
                    }
                }));
            }
        }
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
        let n = self.joints.len();
        match self.representation {
            Representation::Rot6d => {
                let (mut globals, mut rotations) = (Vec::new(), Vec::with_capacity(n));
                for f in 0..frames {
                    self.frame_rotations(motion, f, &mut globals, &mut rotations);
                    for (k, &q) in rotations.iter().enumerate() {
                        let r = quat_to_6d(q);
                        out[f * c + k * dim..f * c + (k + 1) * dim].copy_from_slice(&r);
                    }
                }
            }
            Representation::ExpMap => {
                let (mut globals, mut rotations) = (Vec::new(), Vec::with_capacity(n));
                let mut previous = vec![Quat::IDENTITY; n];
                for f in 0..frames {
                    self.frame_rotations(motion, f, &mut globals, &mut rotations);
                    for (k, (&q, previous)) in rotations.iter().zip(&mut previous).enumerate() {
                        // Keep the quaternion on the hemisphere of the previous
                        // frame's, so the rotation vector does not flip needlessly.
                        let q = if q.dot(*previous) < 0.0 { -q } else { q };
                        *previous = q;
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

    /// The features of the frames `frames` of `motion`, one after the other,
    /// when every frame's features are its own (6D rotations): the numbers
    /// those frames have in [`FeatureLayout::encode`]'s features of the whole
    /// take, computed without them. `None` for exponential maps and Euler
    /// angles, which are kept continuous from the take's first frame.
    pub fn encode_frames(
        &self,
        motion: &Motion,
        frames: impl Iterator<Item = usize>,
    ) -> Option<Vec<f32>> {
        if self.representation != Representation::Rot6d {
            return None;
        }
        let (mut globals, mut rotations) = (Vec::new(), Vec::with_capacity(self.joints.len()));
        let mut out = Vec::new();
        for f in frames {
            self.frame_rotations(motion, f, &mut globals, &mut rotations);
            for &q in &rotations {
                out.extend_from_slice(&quat_to_6d(q));
            }
        }
        Some(out)
    }

    /// The 6D features of feature joint `k` alone in every frame of `motion`
    /// (6 per frame), for a layout of local 6D rotations: the same numbers as
    /// that joint's in [`FeatureLayout::encode`]. `None` for other layouts.
    pub(crate) fn encode_joint(&self, motion: &Motion, k: usize) -> Option<Vec<f32>> {
        if (self.representation, self.frame) != (Representation::Rot6d, RotationFrame::Local) {
            return None;
        }
        let j = self.joints[k];
        let mut out = Vec::with_capacity(motion.frame_count() * 6);
        for f in 0..motion.frame_count() {
            out.extend_from_slice(&quat_to_6d(motion.local_rotation(f, j)));
        }
        Some(out)
    }

    /// Writes the rotations of feature joint `k` from `features` (6 per
    /// frame, as [`FeatureLayout::encode_joint`] gives them) into `motion`,
    /// as [`FeatureLayout::decode_into`] writes that joint: in the local
    /// frame every joint is decoded on its own.
    pub(crate) fn decode_joint_into(&self, features: &[f32], k: usize, motion: &mut Motion) {
        debug_assert_eq!(self.frame, RotationFrame::Local);
        let j = self.joints[k];
        for (f, v) in features
            .chunks_exact(6)
            .enumerate()
            .take(motion.frame_count())
        {
            let q = rot6d_to_quat([v[0], v[1], v[2], v[3], v[4], v[5]]);
            set_rotation_keeping_branch(motion, f, j, q);
        }
    }

    /// Brings a window of features to a canonical range before it is fed to
    /// the network, and returns what was done, to undo it on the output
    /// ([`Recentering::undo`]) or do the same to the target
    /// ([`Recentering::apply`]).
    ///
    /// - Euler angles: whole turns are taken off so that the first frame of
    ///   each channel lies in (-pi, pi].
    /// - Exponential maps: a joint whose first vector is longer than pi (the
    ///   take-level encoding is sign-continuous, so a joint that turned
    ///   through 180 degrees earlier in the take carries vectors up to 2 pi
    ///   long) is switched to the other branch (`v - 2 pi v/|v|`, the same
    ///   rotation) in the whole window. Training windows are encoded on
    ///   their own and always start within pi; without this, inference
    ///   would feed vectors the network never saw.
    /// - 6D: nothing.
    pub fn recenter(&self, window: &mut [f32]) -> Recentering {
        let c = self.channels();
        if window.len() < c {
            return Recentering::None;
        }
        let recentering = match self.representation {
            Representation::Rot6d => Recentering::None,
            Representation::Euler => {
                let tau = std::f32::consts::TAU;
                Recentering::Offsets(
                    window[..c]
                        .iter()
                        .map(|v| (v / tau).round() * tau)
                        .collect(),
                )
            }
            Representation::ExpMap => Recentering::Flipped(
                window[..c]
                    .chunks(3)
                    .map(|v| Vec3::new(v[0], v[1], v[2]).length() > std::f32::consts::PI)
                    .collect(),
            ),
        };
        recentering.apply(window);
        recentering
    }

    /// Puts the target window `target` on the same branch as the input window
    /// `input` (both frame after frame, encoded from the clean and the noisy
    /// copy of the same frames).
    ///
    /// Euler angles and exponential maps name one rotation with several
    /// vectors (whole turns; `v` and `v - 2 pi v/|v|`). The clean and the noisy
    /// window are encoded separately, so near 180 degrees they can land on
    /// different branches: a joint at 179 degrees in the clean take and 181
    /// in the noisy copy gives a target 358 degrees away from the input for
    /// a 2 degree error. Training on such pairs asks the network for a jump
    /// that has nothing to do with the noise. Here each Euler channel of the
    /// target is shifted by the whole number of turns closest to its mean
    /// difference from the input, and each exponential-map joint of the
    /// target is switched to the other branch over the whole window when
    /// that brings it closer to the input (the window stays continuous
    /// along time: switching all frames of a sign-continuous track is
    /// negating all its quaternions).
    pub fn align_target(&self, input: &[f32], target: &mut [f32]) {
        let c = self.channels();
        if c == 0 || input.len() != target.len() {
            return;
        }
        let frames = input.len() / c;
        match self.representation {
            Representation::Rot6d => {}
            Representation::Euler => {
                let tau = std::f32::consts::TAU;
                for ch in 0..c {
                    let mean = (0..frames)
                        .map(|f| input[f * c + ch] - target[f * c + ch])
                        .sum::<f32>()
                        / frames.max(1) as f32;
                    let shift = (mean / tau).round() * tau;
                    if shift != 0.0 {
                        for f in 0..frames {
                            target[f * c + ch] += shift;
                        }
                    }
                }
            }
            Representation::ExpMap => {
                for k in 0..self.joints.len() {
                    let (mut same, mut flipped) = (0.0f32, 0.0f32);
                    for f in 0..frames {
                        let at = f * c + 3 * k;
                        let x = Vec3::from_slice(&input[at..at + 3]);
                        let y = Vec3::from_slice(&target[at..at + 3]);
                        same += (x - y).length_squared();
                        flipped += (x - other_branch(y)).length_squared();
                    }
                    if flipped < same {
                        for f in 0..frames {
                            let at = f * c + 3 * k;
                            let y = other_branch(Vec3::from_slice(&target[at..at + 3]));
                            target[at..at + 3].copy_from_slice(&y.to_array());
                        }
                    }
                }
            }
        }
    }

    /// The rotation of feature joint `k` from one frame's features, in the
    /// layout's frame.
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
        let frames = motion.frame_count();
        self.decode_frames_into(&features[..frames * self.channels()], 0, motion);
    }

    /// [`FeatureLayout::decode_into`] for the frames `first..` of `motion`
    /// that `features` holds: every frame is decoded on its own, so a take
    /// may be decoded piece by piece.
    pub fn decode_frames_into(&self, features: &[f32], first: usize, motion: &mut Motion) {
        let c = self.channels();
        let joint_count = motion.skeleton().joint_count();
        let mut feature_of = vec![None; joint_count];
        for (k, &j) in self.joints.iter().enumerate() {
            feature_of[j] = Some(k);
        }
        // Rotations relative to the pelvis of the frame being decoded.
        let mut relative = vec![Quat::IDENTITY; joint_count];
        for (frame, f) in features.chunks_exact(c).zip(first..) {
            for j in 0..joint_count {
                let decoded = feature_of[j].map(|k| self.rotation(frame, k));
                let parent = motion.skeleton().joint(j).parent;
                match (self.frame, parent) {
                    (RotationFrame::Pelvis, Some(p)) if self.below_pelvis[j] => {
                        // `relative[pelvis]` stays the identity.
                        let r =
                            decoded.unwrap_or_else(|| relative[p] * motion.local_rotation(f, j));
                        relative[j] = r;
                        if decoded.is_some() {
                            let local = (relative[p].conjugate() * r).normalize();
                            set_rotation_keeping_branch(motion, f, j, local);
                        }
                    }
                    _ => {
                        if let Some(q) = decoded {
                            set_rotation_keeping_branch(motion, f, j, q);
                        }
                    }
                }
            }
        }
    }
}

/// Writes `rotation` as `joint`'s Euler angles in `frame`, choosing of the
/// equivalent angle triples the one nearest to the angles there before: a
/// take whose channels use the other Tait-Bryan solution, or angles past
/// +-180 degrees, keeps them where the rotation barely changed, so the
/// cleaned file's channels stay comparable to the input's, value by value.
fn set_rotation_keeping_branch(motion: &mut Motion, frame: usize, joint: usize, rotation: Quat) {
    let before = motion.rotation_angles(frame, joint);
    motion.set_local_rotation_near(frame, joint, rotation, Some(before));
}

/// The other exponential-map vector of the same rotation: `v - 2 pi v/|v|`
/// (a rotation by `theta` about `n` is one by `theta - 2 pi` about `n`). For
/// lengths in (0, 2 pi) applying it twice gives `v` back.
fn other_branch(v: Vec3) -> Vec3 {
    let length = v.length();
    if length < 1e-6 {
        // Near the identity the other branch is a full turn about an
        // undefined axis; keep the short vector.
        v
    } else {
        v * (1.0 - std::f32::consts::TAU / length)
    }
}

/// What [`FeatureLayout::recenter`] did to a window.
#[derive(Debug, Clone, PartialEq)]
pub enum Recentering {
    /// Nothing (6D features).
    None,
    /// Whole turns taken off each Euler channel.
    Offsets(Vec<f32>),
    /// Exponential-map joints switched to their other branch.
    Flipped(Vec<bool>),
}

impl Recentering {
    /// Does the same to another window of the same layout (frame after frame).
    pub fn apply(&self, window: &mut [f32]) {
        match self {
            Recentering::None => {}
            Recentering::Offsets(offsets) => add_per_frame(window, offsets, -1.0),
            Recentering::Flipped(flipped) => flip(flipped, window),
        }
    }

    /// Undoes it on a window (the network's output): the features are back
    /// on the branch of the take they came from, so overlapping windows
    /// blend on one branch.
    pub fn undo(&self, window: &mut [f32]) {
        match self {
            Recentering::None => {}
            Recentering::Offsets(offsets) => add_per_frame(window, offsets, 1.0),
            // Switching branch is its own inverse.
            Recentering::Flipped(flipped) => flip(flipped, window),
        }
    }
}

/// Adds `sign * offsets` to every frame of `window` (frames of
/// `offsets.len()` channels).
fn add_per_frame(window: &mut [f32], offsets: &[f32], sign: f32) {
    for frame in window.chunks_mut(offsets.len()) {
        for (v, o) in frame.iter_mut().zip(offsets) {
            *v += sign * o;
        }
    }
}

fn flip(flipped: &[bool], window: &mut [f32]) {
    if !flipped.iter().any(|&f| f) {
        return;
    }
    for frame in window.chunks_mut(3 * flipped.len()) {
        for (k, _) in flipped.iter().enumerate().filter(|(_, &f)| f) {
            let v = other_branch(Vec3::from_slice(&frame[3 * k..3 * k + 3]));
            frame[3 * k..3 * k + 3].copy_from_slice(&v.to_array());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::synthetic_motion;
    use mocap_core::forward_kinematics;

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
    fn decoding_keeps_the_inputs_euler_branch() {
        use std::f32::consts::PI;
        // Joint 1's channels on the other Tait-Bryan solution, joint 2's
        // first angle a whole turn up: the same rotations, other values,
        // as exporters write them.
        let mut motion = synthetic_motion(40, 7);
        for f in 0..motion.frame_count() {
            let (q1, a1) = (motion.local_rotation(f, 1), motion.rotation_angles(f, 1));
            let other = Vec3::new(a1.x + PI, PI - a1.y, a1.z + PI);
            motion.set_local_rotation_near(f, 1, q1, Some(other));
            let (q2, a2) = (motion.local_rotation(f, 2), motion.rotation_angles(f, 2));
            let turned = Vec3::new(a2.x + std::f32::consts::TAU, a2.y, a2.z);
            motion.set_local_rotation_near(f, 2, q2, Some(turned));
        }
        assert!(motion.rotation_angles(0, 1).y.abs() > PI / 2.0);
        for representation in [
            Representation::Rot6d,
            Representation::ExpMap,
            Representation::Euler,
        ] {
            let layout = FeatureLayout::new(motion.skeleton(), representation).unwrap();
            let mut back = motion.clone();
            layout.decode_into(&layout.encode(&motion), &mut back);
            let most = motion
                .values()
                .iter()
                .zip(back.values())
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f32::max);
            assert!(
                most < 0.05,
                "{representation:?}: a channel moved by {most} degrees"
            );
        }
    }

    #[test]
    fn pelvis_frame_round_trips_and_ignores_the_heading() {
        use crate::test_support::branching_motion;
        let motion = branching_motion(30);
        let mut turned = motion.clone();
        for f in 0..turned.frame_count() {
            // Turn the whole body about the vertical at the pelvis.
            let yaw = Quat::from_rotation_y((70.0 + f as f32).to_radians());
            let q = yaw * turned.local_rotation(f, 1);
            turned.set_local_rotation(f, 1, q);
        }
        for repr in [Representation::Rot6d, Representation::ExpMap] {
            let layout = FeatureLayout::new(motion.skeleton(), repr)
                .unwrap()
                .in_frame(RotationFrame::Pelvis)
                .unwrap();
            assert_eq!(layout.pelvis, 1);
            assert_eq!(layout.joints, vec![0, 1, 2, 3, 5, 6]);
            let features = layout.encode(&motion);
            // Below the pelvis the features are P^-1 G_j.
            let poses = forward_kinematics(&motion);
            let c = layout.channels();
            // Frame by frame, the bits of the whole take's kinematics.
            if repr == Representation::Rot6d {
                for f in 0..motion.frame_count() {
                    for (k, &j) in layout.joints.iter().enumerate() {
                        let q = if layout.below_pelvis[j] {
                            (poses.rotation(f, 1).conjugate() * poses.rotation(f, j)).normalize()
                        } else {
                            motion.local_rotation(f, j)
                        };
                        let got = &features[f * c + 6 * k..f * c + 6 * k + 6];
                        assert_eq!(got, &quat_to_6d(q)[..], "frame {f} joint {j}");
                    }
                }
            }
            for f in [0, 17] {
                let expected = poses.rotation(f, 1).conjugate() * poses.rotation(f, 6);
                let got = layout.rotation(&features[f * c..(f + 1) * c], 5);
                assert!(mocap_core::rotation::angle_between(expected, got) < 1e-3);
            }
            // Joints below the pelvis do not see the heading.
            let turned_features = layout.encode(&turned);
            let d = repr.dim();
            for f in 0..motion.frame_count() {
                for ch in 2 * d..c {
                    let (a, b) = (features[f * c + ch], turned_features[f * c + ch]);
                    assert!((a - b).abs() < 1e-4, "{repr:?} frame {f} channel {ch}");
                }
            }
            // Decoding gives the local rotations back.
            let mut back = turned.clone();
            for f in 0..back.frame_count() {
                for j in [2, 3, 5, 6] {
                    back.set_local_rotation(f, j, Quat::IDENTITY);
                }
            }
            layout.decode_into(&turned_features, &mut back);
            for f in 0..motion.frame_count() {
                for &j in &layout.joints {
                    let angle = mocap_core::rotation::angle_between(
                        turned.local_rotation(f, j),
                        back.local_rotation(f, j),
                    );
                    assert!(angle.to_degrees() < 0.05, "{repr:?} frame {f} joint {j}");
                }
            }
        }
        let euler = FeatureLayout::new(motion.skeleton(), Representation::Euler).unwrap();
        assert!(euler.in_frame(RotationFrame::Pelvis).is_err());
    }

    #[test]
    fn euler_windows_are_recentered_by_whole_turns() {
        let motion = synthetic_motion(10, 3);
        let layout = FeatureLayout::new(motion.skeleton(), Representation::Euler).unwrap();
        let mut window = layout.encode(&motion);
        window[0] += 4.0 * std::f32::consts::PI;
        let original = window.clone();
        let recentering = layout.recenter(&mut window);
        assert!(window[0].abs() <= std::f32::consts::PI + 1e-5);
        let mut back = window.clone();
        recentering.undo(&mut back);
        for (v, o) in back.iter().zip(&original) {
            assert!((v - o).abs() < 1e-4);
        }
    }

    /// Largest feature distance and largest rotation change of joint 1
    /// between two feature windows.
    fn joint1_gap(layout: &FeatureLayout, a: &[f32], b: &[f32]) -> (f32, f32) {
        let (c, dim) = (layout.channels(), layout.representation.dim());
        let (mut feature, mut angle) = (0.0f32, 0.0f32);
        for f in 0..a.len() / c {
            for i in dim..2 * dim {
                feature = feature.max((a[f * c + i] - b[f * c + i]).abs());
            }
            let qa = layout.rotation(&a[f * c..(f + 1) * c], 1);
            let qb = layout.rotation(&b[f * c..(f + 1) * c], 1);
            angle = angle.max(mocap_core::rotation::angle_between(qa, qb).to_degrees());
        }
        (feature, angle)
    }

    #[test]
    fn euler_targets_are_put_on_the_inputs_turn() {
        // Joint 1 (Z X Y channels) at Y = 179 degrees in the clean take and
        // -179 (= 181) in the noisy one: 2 degrees apart as rotations.
        let clean = synthetic_motion(8, 3);
        let mut noisy = clean.clone();
        let mut clean = clean;
        let y_slot = clean.skeleton().channel_start(1) + 2;
        for f in 0..8 {
            clean.frame_mut(f)[y_slot] = 179.0;
            noisy.frame_mut(f)[y_slot] = -179.0;
        }
        let layout = FeatureLayout::new(clean.skeleton(), Representation::Euler).unwrap();
        let x = layout.encode(&noisy);
        let mut y = layout.encode(&clean);
        let original = y.clone();
        layout.align_target(&x, &mut y);
        let (feature, angle) = joint1_gap(&layout, &x, &y);
        assert!(feature < 0.04, "target still {feature} rad from the input");
        assert!((angle - 2.0).abs() < 0.01, "{angle}");
        // The aligned target is the same rotation as the clean take.
        assert!(joint1_gap(&layout, &original, &y).1 < 0.01);
    }

    #[test]
    fn expmap_targets_are_put_on_the_inputs_branch() {
        let y_axis = Vec3::new(0.0, 1.0, 0.0);
        let mut clean = synthetic_motion(8, 3);
        let mut noisy = clean.clone();
        for f in 0..8 {
            clean.set_local_rotation(f, 1, Quat::from_axis_angle(y_axis, 179f32.to_radians()));
            noisy.set_local_rotation(f, 1, Quat::from_axis_angle(y_axis, 181f32.to_radians()));
        }
        let layout = FeatureLayout::new(clean.skeleton(), Representation::ExpMap).unwrap();
        let x = layout.encode(&noisy);
        let mut y = layout.encode(&clean);
        let original = y.clone();
        // Encoded on their own, the two land on opposite branches.
        assert!(joint1_gap(&layout, &x, &original).0 > 6.0);
        layout.align_target(&x, &mut y);
        let (feature, angle) = joint1_gap(&layout, &x, &y);
        assert!(feature < 0.04, "target still {feature} rad from the input");
        assert!((angle - 2.0).abs() < 0.01, "{angle}");
        assert!(joint1_gap(&layout, &original, &y).1 < 0.01);
    }

    #[test]
    fn expmap_windows_past_half_a_turn_are_recentered_and_restored() {
        // Joint 1 turns about Y from 150 to 240 degrees over the take: the
        // take-level encoding is continuous, so its vectors pass pi.
        let mut motion = synthetic_motion(16, 3);
        let y_axis = Vec3::new(0.0, 1.0, 0.0);
        for f in 0..16 {
            let angle = (150.0 + 6.0 * f as f32).to_radians();
            motion.set_local_rotation(f, 1, Quat::from_axis_angle(y_axis, angle));
        }
        let layout = FeatureLayout::new(motion.skeleton(), Representation::ExpMap).unwrap();
        let features = layout.encode(&motion);
        let c = layout.channels();
        let length = |w: &[f32], f: usize| Vec3::from_slice(&w[f * c + 3..f * c + 6]).length();
        // A window starting at frame 8 (198 degrees).
        let original = features[8 * c..].to_vec();
        assert!(length(&original, 0) > std::f32::consts::PI);
        let mut window = original.clone();
        let recentering = layout.recenter(&mut window);
        assert_eq!(recentering, Recentering::Flipped(vec![false, true, false]));
        assert!(length(&window, 0) <= std::f32::consts::PI);
        // Same rotations, and still continuous along time.
        assert!(joint1_gap(&layout, &original, &window).1 < 0.01);
        for f in 1..8 {
            let step = Vec3::from_slice(&window[f * c + 3..f * c + 6])
                - Vec3::from_slice(&window[(f - 1) * c + 3..(f - 1) * c + 6]);
            assert!(step.length() < 0.2, "frame {f}: step {}", step.length());
        }
        recentering.undo(&mut window);
        for (a, b) in window.iter().zip(&original) {
            assert!((a - b).abs() < 1e-4);
        }
    }
}
