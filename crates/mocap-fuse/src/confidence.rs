//! The confidence `C_kn` of sensor `k` for joint `n`.
//!
//! ```text
//! C_kn = w(s_kn) * S_kn
//! S_kn = b(|l_pre,n - l_kn|) * r_kn * S_k,parent(n)        (S of the root: b * r)
//! ```
//!
//! - `w(s)`: the tracking-state weight (paper: NotTracked 0, Inferred 0.3,
//!   Tracked 0.7);
//! - `b(d)`: the bone-length term, a *decreasing* function of the difference
//!   `d` between the length of the bone into joint `n` as sensor `k` sees it
//!   this frame, `l_kn`, and the length measured beforehand, `l_pre,n`. The
//!   report writes this term as `a |l_pre - l_f|`, which read literally would
//!   *grow* with the error; a confidence must fall as the error grows, so we
//!   implement decreasing functions of `a |l_pre - l_f|` ([`BoneLengthFunction`])
//!   and compare them in the evaluation;
//! - `r_kn`: the range-of-motion term: 1 inside the measured range of the
//!   angle whose bone ends at joint `n`, falling off outside it with separate
//!   rates below the lower and above the upper limit;
//! - the product runs down the kinematic chain (`S_k,parent(n)`), so a bad
//!   elbow also discounts the wrist and the hand.

use mocap_core::rotation::Vec3;
use serde::{Deserialize, Serialize};

use crate::body::{joint_angle, BodyModel, ANGLES};
use crate::kinect::{TrackingState, JOINT_COUNT, PARENTS, TOPOLOGICAL_ORDER};
use crate::recording::JointObservation;

/// Weight of each tracking state.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StateWeights {
    pub not_tracked: f32,
    pub inferred: f32,
    pub tracked: f32,
}

impl Default for StateWeights {
    /// The paper's weights: NotTracked 0, Inferred 0.3, Tracked 0.7.
    fn default() -> Self {
        StateWeights {
            not_tracked: 0.0,
            inferred: 0.3,
            tracked: 0.7,
        }
    }
}

impl StateWeights {
    pub fn weight(&self, state: TrackingState) -> f32 {
        match state {
            TrackingState::NotTracked => self.not_tracked,
            TrackingState::Inferred => self.inferred,
            TrackingState::Tracked => self.tracked,
        }
    }
}

/// A decreasing function of the bone-length difference `d` (metres).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum BoneLengthFunction {
    /// `max(0, 1 - a d)`: the report's `a |l_pre - l_f|` turned into a
    /// penalty; zero confidence from `d = 1/a` on.
    Linear { a: f32 },
    /// `1 / (1 + a d)`: falls like the report's term grows, never reaches 0.
    Inverse { a: f32 },
    /// `exp(-d^2 / (2 sigma^2))`: a Gaussian likelihood of the length error.
    Gaussian { sigma: f32 },
}

impl BoneLengthFunction {
    /// The term for a length difference of `d` metres.
    pub fn eval(&self, d: f32) -> f32 {
        let d = d.abs();
        match *self {
            BoneLengthFunction::Linear { a } => (1.0 - a * d).max(0.0),
            BoneLengthFunction::Inverse { a } => 1.0 / (1.0 + a * d),
            BoneLengthFunction::Gaussian { sigma } => (-(d * d) / (2.0 * sigma * sigma)).exp(),
        }
    }

    /// A short name for tables.
    pub fn label(&self) -> String {
        match *self {
            BoneLengthFunction::Linear { a } => format!("linear 1-{a}d"),
            BoneLengthFunction::Inverse { a } => format!("inverse 1/(1+{a}d)"),
            BoneLengthFunction::Gaussian { sigma } => {
                format!("gaussian sigma={}cm", sigma * 100.0)
            }
        }
    }
}

/// The range-of-motion term: outside the measured range by `e` degrees the
/// factor is `exp(-e / lower_scale)` below the lower limit and
/// `exp(-e / upper_scale)` above the upper one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RangeOfMotionTerm {
    /// Degrees past the lower limit for the factor to fall by `e`.
    pub lower_scale: f32,
    /// Degrees past the upper limit for the factor to fall by `e`.
    pub upper_scale: f32,
}

impl Default for RangeOfMotionTerm {
    fn default() -> Self {
        // The lower limit of the knees and hips is hyperextension, which a
        // real joint does not do: fall faster there than past the upper limit
        // (deep flexion, which a short measuring capture may not have seen).
        RangeOfMotionTerm {
            lower_scale: 10.0,
            upper_scale: 20.0,
        }
    }
}

/// Which terms make up the confidence.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ConfidenceModel {
    pub state_weights: StateWeights,
    /// `None`: no bone-length term (the state-only baseline).
    pub bone_length: Option<BoneLengthFunction>,
    pub range_of_motion: Option<RangeOfMotionTerm>,
    /// Multiply each joint's structural term by its parent's.
    pub propagate: bool,
    /// Smallest structural term, so that a joint whose every sensor is
    /// discounted still gets the state-weighted mean rather than nothing.
    pub floor: f32,
}

impl Default for ConfidenceModel {
    fn default() -> Self {
        ConfidenceModel {
            state_weights: StateWeights::default(),
            bone_length: Some(BoneLengthFunction::Gaussian { sigma: 0.04 }),
            range_of_motion: Some(RangeOfMotionTerm::default()),
            propagate: true,
            floor: 1e-4,
        }
    }
}

/// The confidences `C_kn` of one sensor's skeleton (world or camera space).
pub fn confidences(
    model: &ConfidenceModel,
    body: &BodyModel,
    joints: &[JointObservation; JOINT_COUNT],
) -> [f32; JOINT_COUNT] {
    let positions: [Vec3; JOINT_COUNT] = joints.map(|j| j.position);
    // The per-joint factor of this frame, before propagation.
    let mut local = [1.0f32; JOINT_COUNT];
    if let Some(f) = model.bone_length {
        for n in 0..JOINT_COUNT {
            if let (Some(p), Some(l_pre)) = (PARENTS[n], body.bone_lengths[n]) {
                let l_seen = positions[n].distance(positions[p]);
                local[n] *= f.eval(l_seen - l_pre);
            }
        }
    }
    if let Some(rom) = model.range_of_motion {
        for (def, range) in ANGLES.iter().zip(&body.ranges) {
            let (Some(range), Some(angle)) = (range, joint_angle(def, &positions)) else {
                continue;
            };
            let factor = if angle < range.min {
                (-(range.min - angle) / rom.lower_scale).exp()
            } else if angle > range.max {
                (-(angle - range.max) / rom.upper_scale).exp()
            } else {
                1.0
            };
            local[def.bone.1] *= factor;
        }
    }
    let mut structural = [1.0f32; JOINT_COUNT];
    for &n in &TOPOLOGICAL_ORDER {
        let inherited = match PARENTS[n] {
            Some(p) if model.propagate => structural[p],
            _ => 1.0,
        };
        structural[n] = local[n] * inherited;
    }
    let mut c = [0.0f32; JOINT_COUNT];
    for n in 0..JOINT_COUNT {
        c[n] = model.state_weights.weight(joints[n].state) * structural[n].max(model.floor);
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::MeasureOptions;
    use crate::kinect::joint::*;

    fn tracked(p: [Vec3; JOINT_COUNT]) -> [JointObservation; JOINT_COUNT] {
        p.map(|position| JointObservation {
            position,
            state: TrackingState::Tracked,
        })
    }

    fn body() -> BodyModel {
        let pose = crate::body::tests::standing_pose();
        BodyModel::from_positions([&pose; 20], MeasureOptions::default())
    }

    #[test]
    fn every_bone_length_function_decreases_from_one() {
        for f in [
            BoneLengthFunction::Linear { a: 5.0 },
            BoneLengthFunction::Inverse { a: 20.0 },
            BoneLengthFunction::Gaussian { sigma: 0.04 },
        ] {
            assert_eq!(f.eval(0.0), 1.0);
            let mut last = 1.0;
            for i in 1..40 {
                let v = f.eval(i as f32 * 0.01);
                assert!(v <= last && v >= 0.0, "{f:?} at {i} cm");
                last = v;
            }
            assert!(last < 0.5, "{f:?} must fall well below 1 at 40 cm");
            assert_eq!(f.eval(-0.1), f.eval(0.1));
        }
    }

    #[test]
    fn state_weights_alone_are_the_papers() {
        let model = ConfidenceModel {
            bone_length: None,
            range_of_motion: None,
            ..ConfidenceModel::default()
        };
        let mut joints = tracked(crate::body::tests::standing_pose());
        joints[HEAD].state = TrackingState::Inferred;
        joints[FOOT_LEFT].state = TrackingState::NotTracked;
        let c = confidences(&model, &body(), &joints);
        assert!((c[SPINE_BASE] - 0.7).abs() < 1e-6);
        assert!((c[HEAD] - 0.3).abs() < 1e-6);
        assert_eq!(c[FOOT_LEFT], 0.0);
    }

    #[test]
    fn a_bad_elbow_discounts_the_wrist_below_it_but_not_the_other_arm() {
        let model = ConfidenceModel {
            range_of_motion: None,
            ..ConfidenceModel::default()
        };
        let body = body();
        let good = tracked(crate::body::tests::standing_pose());
        let mut bad = good;
        bad[ELBOW_LEFT].position += Vec3::new(0.0, -0.15, 0.1);
        let (cg, cb) = (
            confidences(&model, &body, &good),
            confidences(&model, &body, &bad),
        );
        assert!((cg[WRIST_LEFT] - 0.7).abs() < 1e-5);
        assert!(cb[ELBOW_LEFT] < 0.5 * cg[ELBOW_LEFT]);
        assert!(
            cb[WRIST_LEFT] < 0.5 * cg[WRIST_LEFT],
            "propagated down the chain"
        );
        assert!(cb[HAND_TIP_LEFT] < 0.5 * cg[HAND_TIP_LEFT]);
        assert_eq!(cb[WRIST_RIGHT], cg[WRIST_RIGHT]);
        assert_eq!(cb[SHOULDER_LEFT], cg[SHOULDER_LEFT]);
    }

    #[test]
    fn a_knee_bent_forward_lowers_the_ankle_confidence() {
        let model = ConfidenceModel {
            bone_length: None,
            ..ConfidenceModel::default()
        };
        let mut body = body();
        let pose = crate::body::tests::standing_pose();
        // A person whose knees flex, measured over a squat.
        let mut flexed = pose;
        let shank = pose[ANKLE_LEFT].distance(pose[KNEE_LEFT]);
        flexed[ANKLE_LEFT] = pose[KNEE_LEFT] + Vec3::new(0.0, -0.7, -0.7).normalize() * shank;
        let squat =
            BodyModel::from_positions([&pose, &flexed].repeat(10), MeasureOptions::default());
        body.ranges = squat.ranges;
        let mut forward = tracked(pose);
        forward[ANKLE_LEFT].position =
            pose[KNEE_LEFT] + Vec3::new(0.0, -0.7, 0.7).normalize() * shank;
        let c = confidences(&model, &body, &forward);
        assert!(c[ANKLE_LEFT] < 0.1, "{}", c[ANKLE_LEFT]);
        assert!(c[FOOT_LEFT] < 0.1, "propagated to the foot");
        assert!((c[KNEE_LEFT] - 0.7).abs() < 1e-5);
        let normal = confidences(&model, &body, &tracked(flexed));
        assert!((normal[ANKLE_LEFT] - 0.7).abs() < 1e-5);
    }
}
