//! Fusing the sensors' skeletons of one instant into one skeleton.
//!
//! The paper's fusion is the confidence-weighted mean of each joint,
//! `J_n = sum_k C_kn J_kn / sum_k C_kn` ([`crate::confidence`]). On top of it
//! [`FusionOptions`] can switch on additions that help (each measured
//! separately in the evaluation):
//! - **left/right swap repair**: a Kinect that sees the person from behind
//!   still believes it sees them from the front and swaps left and right. The
//!   person's facing is found from cues that do not depend on the labels (the
//!   feet point forward), plus the previous fused skeleton's facing; a sensor
//!   whose labelled skeleton faces the other way has its left and right
//!   labels swapped back before fusing;
//! - **robust rejection**: iteratively reweighted mean with Cauchy weights
//!   `C_kn / (1 + (r_kn / c)^2)`, `r_kn` the distance of the sensor's joint to
//!   the current fused joint, so one sensor that disagrees with the others
//!   loses its say;
//! - **temporal filtering**: a One Euro filter (Casiez, Roussel, Vogel, CHI
//!   2012) per joint: strong smoothing when the joint is slow, little lag
//!   when it is fast.

use mocap_core::rotation::Vec3;
use serde::{Deserialize, Serialize};

use crate::body::BodyModel;
use crate::confidence::{confidences, ConfidenceModel};
use crate::kinect::{joint::*, TrackingState, JOINT_COUNT, MIRROR};
use crate::recording::JointObservation;

/// Parameters of the One Euro filter.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OneEuroParams {
    /// Cutoff frequency (Hz) when the joint is still.
    pub min_cutoff: f32,
    /// How fast the cutoff rises with speed (Hz per m/s).
    pub beta: f32,
    /// Cutoff (Hz) of the speed estimate.
    pub derivative_cutoff: f32,
}

impl Default for OneEuroParams {
    fn default() -> Self {
        OneEuroParams {
            min_cutoff: 2.0,
            beta: 1.5,
            derivative_cutoff: 1.0,
        }
    }
}

/// Everything the fusion does, beyond the confidence terms.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FusionOptions {
    pub confidence: ConfidenceModel,
    /// Swap a sensor's left and right back when it saw the person from behind.
    pub swap_repair: bool,
    /// Scale `c` (metres) of the Cauchy reweighting; `None` for the plain mean.
    pub robust_scale: Option<f32>,
    /// One Euro filtering of the fused joints; `None` for none.
    pub smoothing: Option<OneEuroParams>,
    /// Depth at which a Tracked joint's error is twice that of a joint right
    /// in front of the sensor (m): weights are multiplied by
    /// `1 / (1 + (d / d0)^2)^2`, the inverse variance of an error growing
    /// with the square of the depth `d` (time-of-flight depth noise).
    /// `None`: no depth weighting.
    #[serde(default)]
    pub depth_reference: Option<f32>,
    /// Swap repair also reads bent knees as a label-free cue to facing
    /// (`label_free_forward`), not only the feet.
    #[serde(default)]
    pub knee_cue: bool,
    /// Learn each sensor's reliability: per sensor, joint and tracking
    /// state, a running mean (this rate per frame) of the squared distance
    /// between the sensor's joint and the fused joint of the other sensors;
    /// weights are divided by it. `None`: off.
    #[serde(default)]
    pub adaptive_rate: Option<f32>,
    /// Offline only ([`crate::offline::fuse_streams`]): Savitzky-Golay
    /// smoothing (quadratic, this many frames on either side) of the fused
    /// joints, which removes jitter without the lag of a causal filter.
    #[serde(default)]
    pub centered_smoothing: Option<usize>,
}

impl FusionOptions {
    /// The report's baseline: tracking-state weights only.
    pub fn state_only() -> FusionOptions {
        FusionOptions {
            confidence: ConfidenceModel {
                bone_length: None,
                range_of_motion: None,
                ..ConfidenceModel::default()
            },
            swap_repair: false,
            robust_scale: None,
            smoothing: None,
            depth_reference: None,
            knee_cue: false,
            adaptive_rate: None,
            centered_smoothing: None,
        }
    }

    /// The report's method: state weights and the bone-length term
    /// propagated down the chain.
    pub fn bone_length(function: crate::confidence::BoneLengthFunction) -> FusionOptions {
        let mut o = FusionOptions::state_only();
        o.confidence.bone_length = Some(function);
        o
    }

    /// State, bone length and range of motion (the full report).
    pub fn report() -> FusionOptions {
        FusionOptions {
            confidence: ConfidenceModel::default(),
            ..FusionOptions::state_only()
        }
    }

    /// Our best version: state weights, a wider bone-length term applied to
    /// each joint alone (not propagated: the evaluation shows propagation
    /// turns ordinary noise into frame-to-frame weight swings), the
    /// range-of-motion term, swap repair reading the feet and the bent knees
    /// (the largest gain: a sensor seeing the back with its labels left
    /// swapped is the dominant error) and robust reweighting of gross
    /// outliers. No temporal filter: the One Euro filter lowers jitter but
    /// its lag raises the position error (see `bench/results/fuse.md`);
    /// offline, `best-smooth` adds Savitzky-Golay smoothing, which has no
    /// lag.
    pub fn best() -> FusionOptions {
        FusionOptions {
            confidence: ConfidenceModel {
                bone_length: Some(crate::confidence::BoneLengthFunction::Gaussian { sigma: 0.08 }),
                propagate: false,
                ..ConfidenceModel::default()
            },
            swap_repair: true,
            robust_scale: Some(0.25),
            smoothing: None,
            depth_reference: None,
            knee_cue: true,
            adaptive_rate: None,
            centered_smoothing: None,
        }
    }
}

/// The named fusion methods of `mocap fuse run|serve --method`.
pub const METHOD_NAMES: [&str; 5] = ["best", "best-smooth", "report", "bone", "state"];

impl FusionOptions {
    /// The options of a named method: `best` ([`FusionOptions::best`]),
    /// `best-smooth` (the same with Savitzky-Golay smoothing offline; a
    /// server cannot look ahead and uses the One Euro filter instead, see
    /// [`FusionOptions::online`]), `report` (the
    /// report's method, all terms), `bone` (state weights and the bone-length
    /// term) or `state` (tracking-state weights only).
    pub fn preset(name: &str) -> mocap_core::Result<FusionOptions> {
        Ok(match name {
            "best" => FusionOptions::best(),
            "best-smooth" => FusionOptions {
                centered_smoothing: Some(3),
                ..FusionOptions::best()
            },
            "report" => FusionOptions::report(),
            "bone" => FusionOptions::bone_length(crate::confidence::BoneLengthFunction::Gaussian {
                sigma: 0.04,
            }),
            "state" => FusionOptions::state_only(),
            other => {
                return Err(mocap_core::Error::Invalid(format!(
                    "unknown fusion method {other:?}; expected one of {}",
                    METHOD_NAMES.join(", ")
                )))
            }
        })
    }
}

impl FusionOptions {
    /// The options for fusing live (the server): smoothing that needs
    /// future frames ([`FusionOptions::centered_smoothing`]) becomes the
    /// causal One Euro filter.
    pub fn online(self) -> FusionOptions {
        match self.centered_smoothing {
            Some(_) => FusionOptions {
                centered_smoothing: None,
                smoothing: self.smoothing.or(Some(OneEuroParams::default())),
                ..self
            },
            None => self,
        }
    }
}

/// One sensor's skeleton of this instant, in world space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorView {
    pub sensor: u16,
    /// Where the sensor is (world space), for depth weighting.
    pub origin: Vec3,
    pub joints: [JointObservation; JOINT_COUNT],
}

/// The fused skeleton of one instant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FusedFrame {
    /// Seconds on the shared clock.
    pub time: f64,
    /// World-space joint positions (metres), Kinect v2 order.
    pub joints: [Vec3; JOINT_COUNT],
    /// Sum of the confidences that went into each joint (0: no sensor saw
    /// it; the position is held from the previous frame).
    pub confidence: [f32; JOINT_COUNT],
    /// The sensors that contributed.
    pub sensors: Vec<u16>,
    /// The sensors whose left and right were swapped back.
    pub swapped: Vec<u16>,
}

/// Vector One Euro filter state of one joint.
#[derive(Debug, Clone, Copy)]
struct OneEuro {
    value: Vec3,
    speed: Vec3,
}

fn smoothing_factor(cutoff: f32, dt: f32) -> f32 {
    let tau = 1.0 / (std::f32::consts::TAU * cutoff);
    1.0 / (1.0 + tau / dt)
}

/// Fuses frame after frame; keeps what the options need from the past (the
/// previous skeleton for swap repair and holding unseen joints, the filters).
#[derive(Debug, Clone)]
pub struct Fuser {
    options: FusionOptions,
    body: BodyModel,
    previous: Option<(f64, [Vec3; JOINT_COUNT])>,
    filters: Option<[OneEuro; JOINT_COUNT]>,
    /// Learnt squared error (m^2) per sensor, joint and tracking state.
    reliability: std::collections::HashMap<(u16, usize, TrackingState), f32>,
}

/// The side-to-side direction of a skeleton as labelled: from the left
/// shoulder and hip to the right ones.
fn lateral(p: &[Vec3; JOINT_COUNT]) -> Vec3 {
    (p[SHOULDER_RIGHT] - p[SHOULDER_LEFT]) + (p[HIP_RIGHT] - p[HIP_LEFT])
}

/// The horizontal direction a skeleton faces according to its left/right
/// labels (up cross left-to-right), unit length or zero.
pub fn facing_of(p: &[Vec3; JOINT_COUNT]) -> Vec3 {
    Vec3::Y.cross(lateral(p)).with_y(0.0).normalize_or_zero()
}

/// The skeleton with left and right labels exchanged.
pub fn swap_left_right(
    joints: &[JointObservation; JOINT_COUNT],
) -> [JointObservation; JOINT_COUNT] {
    std::array::from_fn(|n| joints[MIRROR[n]])
}

/// Which way a skeleton really faces, from cues that do not depend on its
/// left/right labels (horizontal, camera or world space, y up): the feet
/// point forward (ankle to foot) and bent knees stick out forward (knee
/// ahead of the line from hip to ankle). Each leg counts when its joints
/// are Tracked, whatever its label; the vector's length grows with how much
/// the cues say (metres), zero when they say nothing.
pub fn label_free_forward(joints: &[JointObservation; JOINT_COUNT]) -> Vec3 {
    let tracked = |n: usize| joints[n].state == TrackingState::Tracked;
    let at = |n: usize| joints[n].position;
    let mut forward = Vec3::ZERO;
    for (hip, knee, ankle, foot) in [
        (HIP_LEFT, KNEE_LEFT, ANKLE_LEFT, FOOT_LEFT),
        (HIP_RIGHT, KNEE_RIGHT, ANKLE_RIGHT, FOOT_RIGHT),
    ] {
        if tracked(ankle) && tracked(foot) {
            forward += (at(foot) - at(ankle)).with_y(0.0);
        }
        if tracked(hip) && tracked(knee) && tracked(ankle) {
            // Twice the knee's offset: a knee bent by 30 degrees sticks out
            // about 10 cm, as long as a foot.
            forward += 2.0 * (at(knee) - (at(hip) + at(ankle)) * 0.5).with_y(0.0);
        }
    }
    forward
}

impl Fuser {
    pub fn new(options: FusionOptions, body: BodyModel) -> Fuser {
        Fuser {
            options,
            body,
            previous: None,
            filters: None,
            reliability: std::collections::HashMap::new(),
        }
    }

    pub fn options(&self) -> &FusionOptions {
        &self.options
    }

    pub fn body(&self) -> &BodyModel {
        &self.body
    }

    /// Fuses the sensors' views of the instant `time`. With no view at all,
    /// returns `None` (nothing to write for this instant).
    pub fn fuse(&mut self, time: f64, views: &[SensorView]) -> Option<FusedFrame> {
        if views.is_empty() {
            return None;
        }
        let mut swapped = Vec::new();
        let views: Vec<SensorView> = if self.options.swap_repair {
            self.repair_swaps(views, &mut swapped)
        } else {
            views.to_vec()
        };
        let mut weights: Vec<[f32; JOINT_COUNT]> = views
            .iter()
            .map(|v| confidences(&self.options.confidence, &self.body, &v.joints))
            .collect();
        if let Some(d0) = self.options.depth_reference {
            for (v, w) in views.iter().zip(weights.iter_mut()) {
                for (w, j) in w.iter_mut().zip(&v.joints) {
                    let d = j.position.distance(v.origin) / d0;
                    *w /= (1.0 + d * d).powi(2);
                }
            }
        }
        if self.options.adaptive_rate.is_some() {
            for (v, w) in views.iter().zip(weights.iter_mut()) {
                for (n, (w, j)) in w.iter_mut().zip(&v.joints).enumerate() {
                    *w /= match self.reliability.get(&(v.sensor, n, j.state)) {
                        Some(e2) => e2.max(1e-6),
                        None => prior_squared_error(j.state),
                    };
                }
            }
        }
        let mut joints = [Vec3::ZERO; JOINT_COUNT];
        let mut confidence = [0.0f32; JOINT_COUNT];
        for n in 0..JOINT_COUNT {
            let total: f32 = weights.iter().map(|w| w[n]).sum();
            confidence[n] = total;
            if total > 0.0 {
                let mut mean = weighted_mean(&views, &weights, n, &|_, _| 1.0);
                if let Some(c) = self.options.robust_scale {
                    // Iteratively reweighted mean, Cauchy weights.
                    for _ in 0..4 {
                        let center = mean;
                        mean = weighted_mean(&views, &weights, n, &|_, p| {
                            let r = (p - center).length() / c;
                            1.0 / (1.0 + r * r)
                        });
                    }
                }
                joints[n] = mean;
            } else if let Some((_, prev)) = self.previous {
                joints[n] = prev[n];
            } else {
                // Nobody sees it and there is no past: the sensors' guesses.
                let sum: Vec3 = views.iter().map(|v| v.joints[n].position).sum();
                joints[n] = sum / views.len() as f32;
            }
        }
        if let Some(rate) = self.options.adaptive_rate {
            self.learn_reliability(&views, &weights, rate);
        }
        if let Some(params) = self.options.smoothing {
            joints = self.smooth(time, joints, params);
        }
        self.previous = Some((time, joints));
        Some(FusedFrame {
            time,
            joints,
            confidence,
            sensors: views.iter().map(|v| v.sensor).collect(),
            swapped,
        })
    }

    /// Updates the running squared error of each sensor's joints against
    /// the fused joint of the other sensors (leave one out, so that a sensor
    /// does not vouch for itself).
    fn learn_reliability(
        &mut self,
        views: &[SensorView],
        weights: &[[f32; JOINT_COUNT]],
        rate: f32,
    ) {
        for n in 0..JOINT_COUNT {
            let total: f32 = weights.iter().map(|w| w[n]).sum();
            let sum: Vec3 = views
                .iter()
                .zip(weights)
                .map(|(v, w)| v.joints[n].position * w[n])
                .sum();
            for (v, w) in views.iter().zip(weights) {
                let state = v.joints[n].state;
                if state == TrackingState::NotTracked {
                    continue;
                }
                let others = total - w[n];
                if others <= total * 1e-3 {
                    continue;
                }
                let reference = (sum - v.joints[n].position * w[n]) / others;
                let e2 = v.joints[n].position.distance_squared(reference);
                let entry = self
                    .reliability
                    .entry((v.sensor, n, state))
                    .or_insert(prior_squared_error(state));
                *entry += rate * (e2 - *entry);
            }
        }
    }

    fn repair_swaps(&self, views: &[SensorView], swapped: &mut Vec<u16>) -> Vec<SensorView> {
        // Which way the person faces, from cues that do not depend on the
        // left/right labels: the feet point forward (ankle to foot, both
        // feet, every sensor that sees them) and, with `knee_cue`, bent
        // knees stick out forward; plus the previous fused skeleton's facing
        // for continuity when the cues say little.
        let mut forward = Vec3::ZERO;
        for v in views {
            if self.options.knee_cue {
                forward += label_free_forward(&v.joints).normalize_or_zero();
                continue;
            }
            for (ankle, foot) in [(ANKLE_LEFT, FOOT_LEFT), (ANKLE_RIGHT, FOOT_RIGHT)] {
                let (a, f) = (v.joints[ankle], v.joints[foot]);
                if a.state == TrackingState::Tracked && f.state == TrackingState::Tracked {
                    forward +=
                        ((f.position - a.position) * Vec3::new(1.0, 0.0, 1.0)).normalize_or_zero();
                }
            }
        }
        let forward = forward.normalize_or_zero()
            + self
                .previous
                .map_or(Vec3::ZERO, |(_, p)| facing_of(&p) * 0.5);
        views
            .iter()
            .map(|v| {
                let labelled = facing_of(&v.joints.map(|j| j.position));
                if labelled.dot(forward) < 0.0 {
                    swapped.push(v.sensor);
                    SensorView {
                        joints: swap_left_right(&v.joints),
                        ..*v
                    }
                } else {
                    *v
                }
            })
            .collect()
    }

    fn smooth(
        &mut self,
        time: f64,
        joints: [Vec3; JOINT_COUNT],
        params: OneEuroParams,
    ) -> [Vec3; JOINT_COUNT] {
        let dt = match self.previous {
            Some((t, _)) if time > t => (time - t) as f32,
            _ => {
                self.filters = None;
                0.0
            }
        };
        let Some(filters) = self.filters.as_mut().filter(|_| dt > 0.0 && dt < 0.5) else {
            self.filters = Some(joints.map(|value| OneEuro {
                value,
                speed: Vec3::ZERO,
            }));
            return joints;
        };
        let mut out = joints;
        for (n, f) in filters.iter_mut().enumerate() {
            let raw_speed = (joints[n] - f.value) / dt;
            let a_d = smoothing_factor(params.derivative_cutoff, dt);
            f.speed = f.speed.lerp(raw_speed, a_d);
            let cutoff = params.min_cutoff + params.beta * f.speed.length();
            let a = smoothing_factor(cutoff, dt);
            f.value = f.value.lerp(joints[n], a);
            out[n] = f.value;
        }
        out
    }
}

/// The squared error (m^2) a joint of this state is assumed to have before
/// any is learnt: a few centimetres when Tracked, about 15 cm when Inferred
/// (Kinect v2 against marker-based capture, see [`crate::sim`]).
fn prior_squared_error(state: TrackingState) -> f32 {
    match state {
        TrackingState::Tracked => 0.04 * 0.04,
        TrackingState::Inferred => 0.15 * 0.15,
        TrackingState::NotTracked => 0.5 * 0.5,
    }
}

/// `sum_k C_kn g_k J_kn / sum_k C_kn g_k` for joint `n`, with `g` an extra
/// per-observation factor (1 for the paper's mean).
fn weighted_mean(
    views: &[SensorView],
    weights: &[[f32; JOINT_COUNT]],
    n: usize,
    extra: &dyn Fn(usize, Vec3) -> f32,
) -> Vec3 {
    let mut sum = Vec3::ZERO;
    let mut total = 0.0;
    for (k, (v, w)) in views.iter().zip(weights).enumerate() {
        let p = v.joints[n].position;
        let c = w[n] * extra(k, p);
        sum += p * c;
        total += c;
    }
    if total > 0.0 {
        sum / total
    } else {
        // Every observation was reweighted to nothing (far outliers all):
        // fall back to the plain confidence-weighted mean.
        weighted_mean(views, weights, n, &|_, _| 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::MeasureOptions;

    fn view(sensor: u16, pose: [Vec3; JOINT_COUNT], state: TrackingState) -> SensorView {
        SensorView {
            sensor,
            origin: Vec3::new(0.0, 1.0, 3.0),
            joints: pose.map(|position| JointObservation { position, state }),
        }
    }

    fn body() -> BodyModel {
        let pose = crate::body::tests::standing_pose();
        BodyModel::from_positions([&pose; 20], MeasureOptions::default())
    }

    #[test]
    fn fused_joint_is_the_confidence_weighted_mean() {
        let pose = crate::body::tests::standing_pose();
        let shifted = pose.map(|p| p + Vec3::new(0.1, 0.0, 0.0));
        let mut fuser = Fuser::new(FusionOptions::state_only(), body());
        let views = [
            view(0, pose, TrackingState::Tracked),
            view(1, shifted, TrackingState::Inferred),
        ];
        let fused = fuser.fuse(0.0, &views).unwrap();
        // 0.7 * x + 0.3 * (x + 0.1) = x + 0.03
        let d = fused.joints[HEAD] - pose[HEAD];
        assert!((d.x - 0.03).abs() < 1e-5, "{d}");
        assert!((fused.confidence[HEAD] - 1.0).abs() < 1e-6);
    }

    #[test]
    fn bone_length_term_pulls_towards_the_sensor_with_the_right_bones() {
        let pose = crate::body::tests::standing_pose();
        let mut bad = pose;
        bad[ELBOW_LEFT] += Vec3::new(0.0, 0.0, 0.2);
        let views = [
            view(0, pose, TrackingState::Tracked),
            view(1, bad, TrackingState::Tracked),
        ];
        let err = |options| {
            let mut fuser = Fuser::new(options, body());
            let f = fuser.fuse(0.0, &views).unwrap();
            (f.joints[ELBOW_LEFT] - pose[ELBOW_LEFT]).length()
        };
        let state = err(FusionOptions::state_only());
        let bone = err(FusionOptions::bone_length(
            crate::confidence::BoneLengthFunction::Gaussian { sigma: 0.04 },
        ));
        assert!((state - 0.1).abs() < 1e-4);
        assert!(bone < 0.5 * state, "{bone} vs {state}");
    }

    #[test]
    fn swap_repair_fixes_a_sensor_behind_the_person() {
        let pose = crate::body::tests::standing_pose();
        let behind = swap_left_right(&pose.map(|position| JointObservation {
            position,
            state: TrackingState::Tracked,
        }));
        let views = [
            view(0, pose, TrackingState::Tracked),
            view(1, pose, TrackingState::Tracked),
            SensorView {
                sensor: 2,
                origin: Vec3::new(0.0, 1.0, -3.0),
                joints: behind,
            },
        ];
        let mut plain = Fuser::new(FusionOptions::report(), body());
        let f = plain.fuse(0.0, &views).unwrap();
        assert!((f.joints[HAND_LEFT] - pose[HAND_LEFT]).length() > 0.05);
        let mut options = FusionOptions::report();
        options.swap_repair = true;
        let mut repaired = Fuser::new(options, body());
        let f = repaired.fuse(0.0, &views).unwrap();
        assert_eq!(f.swapped, vec![2]);
        assert!((f.joints[HAND_LEFT] - pose[HAND_LEFT]).length() < 1e-5);
    }

    #[test]
    fn unseen_joints_hold_their_last_position() {
        let pose = crate::body::tests::standing_pose();
        let mut fuser = Fuser::new(FusionOptions::report(), body());
        fuser.fuse(0.0, &[view(0, pose, TrackingState::Tracked)]);
        let moved = pose.map(|p| p + Vec3::ONE);
        let mut v = view(0, moved, TrackingState::Tracked);
        v.joints[HEAD].state = TrackingState::NotTracked;
        let f = fuser.fuse(0.033, &[v]).unwrap();
        assert_eq!(f.joints[HEAD], pose[HEAD]);
        assert_eq!(f.confidence[HEAD], 0.0);
        assert!(fuser.fuse(0.066, &[]).is_none());
    }

    #[test]
    fn robust_reweighting_rejects_one_disagreeing_sensor() {
        let pose = crate::body::tests::standing_pose();
        let far = pose.map(|p| p + Vec3::new(0.5, 0.0, 0.0));
        let views = [
            view(0, pose, TrackingState::Tracked),
            view(1, pose, TrackingState::Tracked),
            view(2, far, TrackingState::Tracked),
        ];
        let mut options = FusionOptions::state_only();
        options.robust_scale = Some(0.08);
        let f = Fuser::new(options, body()).fuse(0.0, &views).unwrap();
        assert!((f.joints[HEAD] - pose[HEAD]).length() < 0.01);
    }
}
