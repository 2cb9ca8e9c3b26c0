//! Triangulated keypoints as the Kinect v2 joints that mocap-fuse's BVH
//! fitter and confidence model know.
//!
//! A 2D pose estimator sees fewer joints than the fitter wants (no spine
//! between pelvis and neck, no hand beyond the wrist unless the layout has
//! fingers), so some Kinect joints are made from others. Each is marked
//! `seen` only when it comes from keypoints straight away; the made ones are
//! placed where a person's are on average:
//!
//! - `SpineBase`: the layout's mid-hip, else the middle of the two hips;
//! - `SpineShoulder`: the middle of the shoulders; `SpineMid` halfway
//!   between it and `SpineBase`;
//! - `Head`: the middle of the ears (else the eyes, the nose, the top of the
//!   head); `Neck`: 40% of the way from `SpineShoulder` to it;
//! - a hand: the middle of index and pinky when the layout has them, else
//!   30% of a forearm beyond the wrist; the hand tip 65% of a forearm beyond
//!   it (or the index); the thumb (or 4 cm off the hand, across the arm's
//!   bend);
//! - a foot: the middle of the big and small toes (else the big toe, else
//!   12 cm ahead of the ankle).

use glam::DVec3;
use mocap_core::rotation::Vec3;
use mocap_fuse::{joint::*, JOINT_COUNT};

use crate::layout::Layout;

/// The Kinect joint each canonical keypoint stands for, in the confidence
/// model (the face and the feet's keypoints share their joint).
pub(crate) fn kinect_joint_of(canonical: &str) -> Option<usize> {
    Some(match canonical {
        "MidHip" => SPINE_BASE,
        "Neck" => NECK,
        "Nose" | "LEye" | "REye" | "LEar" | "REar" | "Head" => HEAD,
        "LShoulder" => SHOULDER_LEFT,
        "LElbow" => ELBOW_LEFT,
        "LWrist" => WRIST_LEFT,
        "LIndex" | "LPinky" => HAND_LEFT,
        "LThumb" => THUMB_LEFT,
        "RShoulder" => SHOULDER_RIGHT,
        "RElbow" => ELBOW_RIGHT,
        "RWrist" => WRIST_RIGHT,
        "RIndex" | "RPinky" => HAND_RIGHT,
        "RThumb" => THUMB_RIGHT,
        "LHip" => HIP_LEFT,
        "LKnee" => KNEE_LEFT,
        "LAnkle" => ANKLE_LEFT,
        "LBigToe" | "LSmallToe" | "LHeel" => FOOT_LEFT,
        "RHip" => HIP_RIGHT,
        "RKnee" => KNEE_RIGHT,
        "RAnkle" => ANKLE_RIGHT,
        "RBigToe" | "RSmallToe" | "RHeel" => FOOT_RIGHT,
        _ => return None,
    })
}

/// The Kinect joints of one pose, and which came straight from keypoints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct KinectPose {
    /// Metres, in the cameras' world.
    pub joints: [Vec3; JOINT_COUNT],
    pub seen: [bool; JOINT_COUNT],
}

/// The limb keypoints the fitter cannot do without, and their Kinect
/// joints (besides something of the head).
pub(crate) const REQUIRED: [(usize, &str); 12] = [
    (SHOULDER_LEFT, "LShoulder"),
    (ELBOW_LEFT, "LElbow"),
    (WRIST_LEFT, "LWrist"),
    (SHOULDER_RIGHT, "RShoulder"),
    (ELBOW_RIGHT, "RElbow"),
    (WRIST_RIGHT, "RWrist"),
    (HIP_LEFT, "LHip"),
    (KNEE_LEFT, "LKnee"),
    (ANKLE_LEFT, "LAnkle"),
    (HIP_RIGHT, "RHip"),
    (KNEE_RIGHT, "RKnee"),
    (ANKLE_RIGHT, "RAnkle"),
];

/// The Kinect pose of one frame's keypoints (in `layout`'s order), or `None`
/// when a keypoint of [`REQUIRED`] or every keypoint of the head is
/// missing.
pub(crate) fn kinect_pose(layout: Layout, points: &[Option<DVec3>]) -> Option<KinectPose> {
    let get = |name: &str| layout.index_of(name).and_then(|i| points.get(i).copied()?);
    let mid = |a: &str, b: &str| Some(0.5 * (get(a)? + get(b)?));
    let mut joints = [DVec3::ZERO; JOINT_COUNT];
    let mut seen = [true; JOINT_COUNT];
    for (joint, name) in REQUIRED {
        joints[joint] = get(name)?;
    }
    joints[SPINE_BASE] = get("MidHip").unwrap_or(0.5 * (joints[HIP_LEFT] + joints[HIP_RIGHT]));
    joints[SPINE_SHOULDER] = 0.5 * (joints[SHOULDER_LEFT] + joints[SHOULDER_RIGHT]);
    joints[SPINE_MID] = 0.5 * (joints[SPINE_BASE] + joints[SPINE_SHOULDER]);
    seen[SPINE_MID] = false;
    joints[HEAD] = mid("LEar", "REar")
        .or_else(|| mid("LEye", "REye"))
        .or_else(|| get("Nose"))
        .or_else(|| get("Head"))?;
    joints[NECK] = joints[SPINE_SHOULDER].lerp(joints[HEAD], 0.4);
    seen[NECK] = false;
    let up = (joints[SPINE_SHOULDER] - joints[SPINE_BASE]).normalize_or(DVec3::Z);
    for (side, shoulder, elbow, wrist, hand, tip, thumb) in [
        (
            "L",
            SHOULDER_LEFT,
            ELBOW_LEFT,
            WRIST_LEFT,
            HAND_LEFT,
            HAND_TIP_LEFT,
            THUMB_LEFT,
        ),
        (
            "R",
            SHOULDER_RIGHT,
            ELBOW_RIGHT,
            WRIST_RIGHT,
            HAND_RIGHT,
            HAND_TIP_RIGHT,
            THUMB_RIGHT,
        ),
    ] {
        let forearm = joints[wrist] - joints[elbow];
        let fingers = mid(&format!("{side}Index"), &format!("{side}Pinky"));
        joints[hand] = fingers.unwrap_or(joints[wrist] + 0.3 * forearm);
        seen[hand] = fingers.is_some();
        let index = get(&format!("{side}Index"));
        joints[tip] = index.unwrap_or(joints[hand] + 0.65 * forearm);
        seen[tip] = index.is_some();
        let across = forearm
            .cross(joints[elbow] - joints[shoulder])
            .try_normalize()
            .unwrap_or_else(|| forearm.cross(up).normalize_or(DVec3::X));
        let given = get(&format!("{side}Thumb"));
        joints[thumb] = given.unwrap_or(joints[hand] + 0.04 * across);
        seen[thumb] = given.is_some();
    }
    let left = joints[HIP_LEFT] - joints[HIP_RIGHT];
    let forward = left.cross(up).normalize_or(DVec3::X);
    for (side, ankle, foot) in [("L", ANKLE_LEFT, FOOT_LEFT), ("R", ANKLE_RIGHT, FOOT_RIGHT)] {
        let toes = mid(&format!("{side}BigToe"), &format!("{side}SmallToe"))
            .or_else(|| get(&format!("{side}BigToe")));
        joints[foot] = toes.unwrap_or(joints[ankle] + 0.12 * forward);
        seen[foot] = toes.is_some();
    }
    Some(KinectPose {
        joints: joints.map(|p| p.as_vec3()),
        seen,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_layout_without_feet_or_hands_gets_them_made_and_marked_unseen() {
        let layout = Layout::Coco17;
        let mut points = vec![None; layout.len()];
        let put = |points: &mut Vec<Option<DVec3>>, name: &str, p: [f64; 3]| {
            points[layout.index_of(name).unwrap()] = Some(DVec3::from(p));
        };
        // A person facing +y, z up, left at -x... as a Z-up world has it.
        put(&mut points, "LShoulder", [-0.2, 0.0, 1.4]);
        put(&mut points, "RShoulder", [0.2, 0.0, 1.4]);
        put(&mut points, "LElbow", [-0.2, 0.0, 1.1]);
        put(&mut points, "RElbow", [0.2, 0.0, 1.1]);
        put(&mut points, "LWrist", [-0.2, 0.1, 0.85]);
        put(&mut points, "RWrist", [0.2, 0.1, 0.85]);
        put(&mut points, "LHip", [-0.1, 0.0, 0.9]);
        put(&mut points, "RHip", [0.1, 0.0, 0.9]);
        put(&mut points, "LKnee", [-0.1, 0.0, 0.5]);
        put(&mut points, "RKnee", [0.1, 0.0, 0.5]);
        put(&mut points, "LAnkle", [-0.1, 0.0, 0.1]);
        put(&mut points, "RAnkle", [0.1, 0.0, 0.1]);
        let without_head = kinect_pose(layout, &points);
        assert!(without_head.is_none(), "no head: no pose");
        put(&mut points, "Nose", [0.0, 0.1, 1.6]);
        let pose = kinect_pose(layout, &points).unwrap();
        assert_eq!(pose.joints[SPINE_BASE], Vec3::new(0.0, 0.0, 0.9));
        assert_eq!(pose.joints[HEAD], Vec3::new(0.0, 0.1, 1.6));
        assert!(pose.seen[KNEE_LEFT] && pose.seen[HEAD]);
        assert!(!pose.seen[FOOT_LEFT] && !pose.seen[HAND_LEFT] && !pose.seen[NECK]);
        // The made feet point the way the person faces: left × up.
        let forward = (pose.joints[FOOT_LEFT] - pose.joints[ANKLE_LEFT]).normalize();
        let facing = Vec3::new(-1.0, 0.0, 0.0).cross(Vec3::Z);
        assert!(forward.dot(facing) > 0.99, "{forward}");
        assert!(pose.joints.iter().all(|p| p.is_finite()));
    }
}
