//! The keypoint layouts of 2D pose estimators, and the canonical keypoints
//! they are all read into.
//!
//! Each estimator writes its keypoints in its own order, and two layouts of
//! the same length can differ in meaning (OpenPose's BODY_25 and BODY_25B both
//! have 25 keypoints: index 8 is the mid-hip in one and the right elbow in the
//! other). A [`Layout`] names its keypoints with the [`CANONICAL_NAMES`]
//! (OpenPose's spelling), so that the rest of the crate asks for `"LKnee"`
//! and never for an index.
//!
//! The orders were checked against:
//! - BODY_25: OpenPose's output documentation and `poseParameters.cpp`
//!   (`POSE_BODY_25_BODY_PARTS`);
//! - BODY_25B: OpenPose's `poseParameters.cpp` (`POSE_BODY_25B_BODY_PARTS`,
//!   where our `Neck` is its `UpperNeck` and our `Head` its `HeadTop`) and
//!   Pose2Sim's `skeletons.py`;
//! - COCO_17: the COCO keypoints (the first 17 of BODY_25B);
//! - HALPE_26: AlphaPose's Halpe-FullBody / MMPose's `halpe26` and Pose2Sim's
//!   `skeletons.py`;
//! - BLAZEPOSE: MediaPipe Pose's 33 landmarks.

use serde::{Deserialize, Serialize};

/// The keypoint layout of a 2D pose estimator's output.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Layout {
    /// OpenPose's default model: 25 keypoints with a mid-hip (index 8) and a
    /// neck at the base of the neck (index 1).
    Body25,
    /// OpenPose's experimental, more accurate model (Pose2Sim's default): the
    /// 17 COCO keypoints, the upper neck, the top of the head and the feet.
    Body25B,
    /// The 17 COCO keypoints (no neck, mid-hip or feet), as most estimators
    /// write them (YOLO-pose, MMPose, AlphaPose, OpenPifPaf).
    Coco17,
    /// AlphaPose's and MMPose's Halpe body: COCO_17 then the head, neck,
    /// mid-hip and feet.
    Halpe26,
    /// MediaPipe's BlazePose landmarks: face points, hands reduced to three
    /// points each, heels and toes, and no neck or mid-hip.
    BlazePose33,
}

/// The canonical keypoints every layout is read into, in OpenPose's spelling.
/// `Neck` is wherever the estimator puts it (the base of the neck in BODY_25,
/// the upper neck in BODY_25B and HALPE_26); `Head` is the top of the head;
/// the hand points (`LIndex`...) come from BlazePose only.
pub const CANONICAL_NAMES: [&str; 32] = [
    "Nose",      // 0
    "LEye",      // 1
    "REye",      // 2
    "LEar",      // 3
    "REar",      // 4
    "Neck",      // 5
    "Head",      // 6
    "LShoulder", // 7
    "RShoulder", // 8
    "LElbow",    // 9
    "RElbow",    // 10
    "LWrist",    // 11
    "RWrist",    // 12
    "MidHip",    // 13
    "LHip",      // 14
    "RHip",      // 15
    "LKnee",     // 16
    "RKnee",     // 17
    "LAnkle",    // 18
    "RAnkle",    // 19
    "LBigToe",   // 20
    "LSmallToe", // 21
    "LHeel",     // 22
    "RBigToe",   // 23
    "RSmallToe", // 24
    "RHeel",     // 25
    "LIndex",    // 26
    "RIndex",    // 27
    "LPinky",    // 28
    "RPinky",    // 29
    "LThumb",    // 30
    "RThumb",    // 31
];

/// The parent of each canonical keypoint (by index in [`CANONICAL_NAMES`]) in
/// a body tree rooted at `MidHip`, for bone-length confidence:
///
/// ```text
/// MidHip ─┬─ LHip ── LKnee ── LAnkle ─┬─ LHeel          (and the same on the right)
///         │                           ├─ LBigToe
///         │                           └─ LSmallToe
///         └─ Neck ─┬─ Head ── Nose ─┬─ LEye ── LEar     (and REye ── REar)
///                  ├─ LShoulder ── LElbow ── LWrist ─┬─ LIndex
///                  │                                 ├─ LPinky
///                  │                                 └─ LThumb
///                  └─ RShoulder ── ...                (the same on the right)
/// ```
///
/// Why this tree: the face points hang from the top of the head through the
/// nose, all on the skull, so their distances do not change as the head
/// nods (the neck is the one flexible link up there). The three foot points
/// hang straight from the ankle rather than chaining the small toe to the
/// big toe: the foot is near rigid, and a 3 cm toe-to-toe "bone" would be
/// swamped by the detector's noise. The same holds for the hand points on the
/// wrist.
///
/// A layout lacks some of these keypoints (BlazePose has no `Neck` or
/// `MidHip`, COCO_17 no `Neck`, `MidHip` or `Head`, BODY_25 no `Head`): a
/// bone whose parent is absent is skipped by whoever measures bones, or the
/// parent is synthesized (the mid-hip as the middle of the hips).
pub const CANONICAL_PARENTS: [Option<usize>; 32] = [
    Some(6),  // Nose ← Head
    Some(0),  // LEye ← Nose
    Some(0),  // REye ← Nose
    Some(1),  // LEar ← LEye
    Some(2),  // REar ← REye
    Some(13), // Neck ← MidHip
    Some(5),  // Head ← Neck
    Some(5),  // LShoulder ← Neck
    Some(5),  // RShoulder ← Neck
    Some(7),  // LElbow ← LShoulder
    Some(8),  // RElbow ← RShoulder
    Some(9),  // LWrist ← LElbow
    Some(10), // RWrist ← RElbow
    None,     // MidHip: the root
    Some(13), // LHip ← MidHip
    Some(13), // RHip ← MidHip
    Some(14), // LKnee ← LHip
    Some(15), // RKnee ← RHip
    Some(16), // LAnkle ← LKnee
    Some(17), // RAnkle ← RKnee
    Some(18), // LBigToe ← LAnkle
    Some(18), // LSmallToe ← LAnkle
    Some(18), // LHeel ← LAnkle
    Some(19), // RBigToe ← RAnkle
    Some(19), // RSmallToe ← RAnkle
    Some(19), // RHeel ← RAnkle
    Some(11), // LIndex ← LWrist
    Some(12), // RIndex ← RWrist
    Some(11), // LPinky ← LWrist
    Some(12), // RPinky ← RWrist
    Some(11), // LThumb ← LWrist
    Some(12), // RThumb ← RWrist
];

/// OpenPose BODY_25 (output documentation, `POSE_BODY_25_BODY_PARTS`).
const BODY_25: [&str; 25] = [
    "Nose",      // 0
    "Neck",      // 1
    "RShoulder", // 2
    "RElbow",    // 3
    "RWrist",    // 4
    "LShoulder", // 5
    "LElbow",    // 6
    "LWrist",    // 7
    "MidHip",    // 8
    "RHip",      // 9
    "RKnee",     // 10
    "RAnkle",    // 11
    "LHip",      // 12
    "LKnee",     // 13
    "LAnkle",    // 14
    "REye",      // 15
    "LEye",      // 16
    "REar",      // 17
    "LEar",      // 18
    "LBigToe",   // 19
    "LSmallToe", // 20
    "LHeel",     // 21
    "RBigToe",   // 22
    "RSmallToe", // 23
    "RHeel",     // 24
];

/// OpenPose BODY_25B (`POSE_BODY_25B_BODY_PARTS`): COCO's 17, then
/// `UpperNeck` (our `Neck`), `HeadTop` (our `Head`) and the feet.
const BODY_25B: [&str; 25] = [
    "Nose",      // 0
    "LEye",      // 1
    "REye",      // 2
    "LEar",      // 3
    "REar",      // 4
    "LShoulder", // 5
    "RShoulder", // 6
    "LElbow",    // 7
    "RElbow",    // 8
    "LWrist",    // 9
    "RWrist",    // 10
    "LHip",      // 11
    "RHip",      // 12
    "LKnee",     // 13
    "RKnee",     // 14
    "LAnkle",    // 15
    "RAnkle",    // 16
    "Neck",      // 17 (UpperNeck)
    "Head",      // 18 (HeadTop)
    "LBigToe",   // 19
    "LSmallToe", // 20
    "LHeel",     // 21
    "RBigToe",   // 22
    "RSmallToe", // 23
    "RHeel",     // 24
];

/// Halpe-FullBody's body: COCO's 17, then head, neck, hip (our `MidHip`) and
/// the feet, left and right interleaved (unlike BODY_25B).
const HALPE_26: [&str; 26] = [
    "Nose",      // 0
    "LEye",      // 1
    "REye",      // 2
    "LEar",      // 3
    "REar",      // 4
    "LShoulder", // 5
    "RShoulder", // 6
    "LElbow",    // 7
    "RElbow",    // 8
    "LWrist",    // 9
    "RWrist",    // 10
    "LHip",      // 11
    "RHip",      // 12
    "LKnee",     // 13
    "RKnee",     // 14
    "LAnkle",    // 15
    "RAnkle",    // 16
    "Head",      // 17
    "Neck",      // 18
    "MidHip",    // 19 (Hip)
    "LBigToe",   // 20
    "RBigToe",   // 21
    "LSmallToe", // 22
    "RSmallToe", // 23
    "LHeel",     // 24
    "RHeel",     // 25
];

/// MediaPipe Pose's landmarks. The eye corners and mouth corners have no
/// canonical name and keep their own; the foot index (the tip of the foot) is
/// our big toe.
const BLAZEPOSE_33: [&str; 33] = [
    "Nose",       // 0
    "LEyeInner",  // 1
    "LEye",       // 2
    "LEyeOuter",  // 3
    "REyeInner",  // 4
    "REye",       // 5
    "REyeOuter",  // 6
    "LEar",       // 7
    "REar",       // 8
    "MouthLeft",  // 9
    "MouthRight", // 10
    "LShoulder",  // 11
    "RShoulder",  // 12
    "LElbow",     // 13
    "RElbow",     // 14
    "LWrist",     // 15
    "RWrist",     // 16
    "LPinky",     // 17
    "RPinky",     // 18
    "LIndex",     // 19
    "RIndex",     // 20
    "LThumb",     // 21
    "RThumb",     // 22
    "LHip",       // 23
    "RHip",       // 24
    "LKnee",      // 25
    "RKnee",      // 26
    "LAnkle",     // 27
    "RAnkle",     // 28
    "LHeel",      // 29
    "RHeel",      // 30
    "LBigToe",    // 31 (left foot index)
    "RBigToe",    // 32 (right foot index)
];

impl Layout {
    /// Every layout, in declaration order.
    pub const ALL: [Layout; 5] = [
        Layout::Body25,
        Layout::Body25B,
        Layout::Coco17,
        Layout::Halpe26,
        Layout::BlazePose33,
    ];

    /// Keypoint names in the estimator's order, in canonical names; keypoints
    /// with no canonical name (BlazePose's eye corners and mouth corners) keep
    /// their own names and are never used.
    pub fn names(self) -> &'static [&'static str] {
        match self {
            Layout::Body25 => &BODY_25,
            Layout::Body25B => &BODY_25B,
            // The first 17 of BODY_25B.
            Layout::Coco17 => &BODY_25B[..17],
            Layout::Halpe26 => &HALPE_26,
            Layout::BlazePose33 => &BLAZEPOSE_33,
        }
    }

    /// The number of keypoints per person.
    // A layout is never empty: an `is_empty` would only ever say false.
    #[allow(clippy::len_without_is_empty)]
    pub fn len(self) -> usize {
        self.names().len()
    }

    /// The layout's name as Pose2Sim's `pose_model` spells it: "BODY_25",
    /// "BODY_25B", "COCO_17", "HALPE_26", "BLAZEPOSE".
    pub fn label(self) -> &'static str {
        match self {
            Layout::Body25 => "BODY_25",
            Layout::Body25B => "BODY_25B",
            Layout::Coco17 => "COCO_17",
            Layout::Halpe26 => "HALPE_26",
            Layout::BlazePose33 => "BLAZEPOSE",
        }
    }

    /// The layout a label names, case-insensitively: the [`Layout::label`]s
    /// and "COCO", "HALPE", "MEDIAPIPE", "BLAZEPOSE_33". `None` for anything
    /// else.
    ///
    /// "COCO" is read as COCO_17; Pose2Sim's `pose_model = 'COCO'` with
    /// OpenPose is OpenPose's older 18-keypoint model, whose files then fail
    /// the keypoint count check rather than being misread.
    pub fn parse(text: &str) -> Option<Layout> {
        let text = text.trim().to_ascii_uppercase();
        let layout = match text.as_str() {
            "BODY_25" => Layout::Body25,
            "BODY_25B" => Layout::Body25B,
            "COCO_17" | "COCO" => Layout::Coco17,
            "HALPE_26" | "HALPE" => Layout::Halpe26,
            "BLAZEPOSE" | "BLAZEPOSE_33" | "MEDIAPIPE" => Layout::BlazePose33,
            _ => return None,
        };
        Some(layout)
    }

    /// Index of a canonical keypoint in this layout; `None` when the layout
    /// lacks it (BODY_25 has no `Head`...).
    pub fn index_of(self, canonical: &str) -> Option<usize> {
        self.names().iter().position(|&name| name == canonical)
    }

    /// The bones of [`CANONICAL_PARENTS`]'s tree that this layout can
    /// measure, as `(child, parent)` indices in the layout: a parent the
    /// layout lacks is passed over for its nearest ancestor that it has
    /// (BODY_25's nose hangs from the neck, having no head top), and a
    /// keypoint with no such ancestor has no bone.
    pub(crate) fn bones(self) -> Vec<(usize, usize)> {
        let names = self.names();
        let mut bones = Vec::new();
        for (child, name) in names.iter().enumerate() {
            let Some(canonical) = CANONICAL_NAMES.iter().position(|n| n == name) else {
                continue;
            };
            let mut ancestor = CANONICAL_PARENTS[canonical];
            while let Some(a) = ancestor {
                if let Some(parent) = self.index_of(CANONICAL_NAMES[a]) {
                    bones.push((child, parent));
                    break;
                }
                ancestor = CANONICAL_PARENTS[a];
            }
        }
        bones
    }
}

impl std::fmt::Display for Layout {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.label())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The names of BlazePose keypoints that have no canonical name. Any
    /// other non-canonical name in a table is a typo ("Lknee") that would
    /// silently make the keypoint unusable.
    const OWN_NAMES: [&str; 6] = [
        "LEyeInner",
        "LEyeOuter",
        "REyeInner",
        "REyeOuter",
        "MouthLeft",
        "MouthRight",
    ];

    fn canonical_index(name: &str) -> Option<usize> {
        CANONICAL_NAMES.iter().position(|&n| n == name)
    }

    /// The name of the other side's keypoint: `LKnee` ⇄ `RKnee`; `None` for a
    /// keypoint on the midline.
    fn mirror(name: &str) -> Option<String> {
        let mut chars = name.chars();
        let side = chars.next()?;
        let rest = chars.as_str();
        // "LEye" is sided, "Nose" is not: the side letter is followed by a
        // capital.
        if !rest.starts_with(|c: char| c.is_ascii_uppercase()) {
            return None;
        }
        match side {
            'L' => Some(format!("R{rest}")),
            'R' => Some(format!("L{rest}")),
            _ => None,
        }
    }

    #[test]
    fn layouts_have_their_estimators_lengths() {
        let lengths: Vec<usize> = Layout::ALL.iter().map(|l| l.len()).collect();
        assert_eq!(lengths, [25, 25, 17, 26, 33]);
    }

    #[test]
    fn every_layout_names_each_canonical_keypoint_at_most_once_and_nothing_misspelt() {
        for layout in Layout::ALL {
            for (i, name) in layout.names().iter().enumerate() {
                if canonical_index(name).is_none() {
                    assert!(
                        layout == Layout::BlazePose33 && OWN_NAMES.contains(name),
                        "{layout}: keypoint {i} {name:?} is neither canonical nor one of BlazePose's own"
                    );
                }
                let count = layout.names().iter().filter(|n| *n == name).count();
                assert_eq!(count, 1, "{layout}: {name} appears {count} times");
                assert_eq!(layout.index_of(name), Some(i));
            }
        }
        // Every canonical keypoint is used by some layout.
        for name in CANONICAL_NAMES {
            assert!(
                Layout::ALL.iter().any(|l| l.index_of(name).is_some()),
                "{name} is in no layout"
            );
        }
    }

    #[test]
    fn every_parent_chain_reaches_the_mid_hip() {
        let root = canonical_index("MidHip").unwrap();
        for (i, name) in CANONICAL_NAMES.iter().enumerate() {
            let mut at = i;
            let mut steps = 0;
            while let Some(parent) = CANONICAL_PARENTS[at] {
                at = parent;
                steps += 1;
                assert!(steps <= CANONICAL_NAMES.len(), "{name}: a cycle");
            }
            assert_eq!(at, root, "{name}'s chain ends at {}", CANONICAL_NAMES[at]);
        }
        assert_eq!(CANONICAL_PARENTS[root], None);
    }

    #[test]
    fn sided_keypoints_come_in_mirror_pairs_with_mirrored_parents() {
        let mirror_index = |i: usize| {
            let name = CANONICAL_NAMES[i];
            mirror(name).map_or(Some(i), |m| canonical_index(&m))
        };
        for (i, name) in CANONICAL_NAMES.iter().enumerate() {
            let Some(other) = mirror(name) else { continue };
            let j = canonical_index(&other).unwrap_or_else(|| panic!("{name} has no {other}"));
            // The parents mirror too: the left knee's parent is the left hip
            // exactly when the right knee's is the right hip.
            assert_eq!(
                CANONICAL_PARENTS[i].map(|p| mirror_index(p).unwrap()),
                CANONICAL_PARENTS[j],
                "{name} and {other}"
            );
        }
        // And every layout holds both sides of each pair it holds one of.
        for layout in Layout::ALL {
            for name in layout.names() {
                if let Some(other) = mirror(name) {
                    assert!(
                        layout.index_of(&other).is_some(),
                        "{layout}: {name} without {other}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_orders_match_the_estimators() {
        // Spot checks straight from the sources, independent of the tables'
        // layout in this file.
        let at = |layout: Layout, name: &str| layout.index_of(name);
        assert_eq!(at(Layout::Body25, "Neck"), Some(1));
        assert_eq!(at(Layout::Body25, "MidHip"), Some(8));
        assert_eq!(at(Layout::Body25, "RHip"), Some(9));
        assert_eq!(at(Layout::Body25, "LHip"), Some(12));
        assert_eq!(at(Layout::Body25, "REye"), Some(15));
        assert_eq!(at(Layout::Body25, "RHeel"), Some(24));
        assert_eq!(at(Layout::Body25, "Head"), None);
        // BODY_25B's keypoint 8 is the right elbow: what tells it from BODY_25.
        assert_eq!(at(Layout::Body25B, "LEye"), Some(1));
        assert_eq!(at(Layout::Body25B, "REar"), Some(4));
        assert_eq!(at(Layout::Body25B, "LShoulder"), Some(5));
        assert_eq!(at(Layout::Body25B, "RElbow"), Some(8));
        assert_eq!(at(Layout::Body25B, "LKnee"), Some(13));
        assert_eq!(at(Layout::Body25B, "RAnkle"), Some(16));
        assert_eq!(at(Layout::Body25B, "RWrist"), Some(10));
        assert_eq!(at(Layout::Body25B, "Neck"), Some(17));
        assert_eq!(at(Layout::Body25B, "Head"), Some(18));
        assert_eq!(at(Layout::Body25B, "LBigToe"), Some(19));
        assert_eq!(at(Layout::Body25B, "MidHip"), None);
        assert_eq!(Layout::Body25B.names()[..17], *Layout::Coco17.names());
        assert_eq!(Layout::Halpe26.names()[..17], *Layout::Coco17.names());
        assert_eq!(at(Layout::Halpe26, "Head"), Some(17));
        assert_eq!(at(Layout::Halpe26, "Neck"), Some(18));
        assert_eq!(at(Layout::Halpe26, "MidHip"), Some(19));
        assert_eq!(at(Layout::Halpe26, "RBigToe"), Some(21));
        assert_eq!(at(Layout::Halpe26, "LSmallToe"), Some(22));
        assert_eq!(at(Layout::Halpe26, "LHeel"), Some(24));
        assert_eq!(at(Layout::BlazePose33, "LEye"), Some(2));
        assert_eq!(at(Layout::BlazePose33, "REye"), Some(5));
        assert_eq!(at(Layout::BlazePose33, "LEar"), Some(7));
        assert_eq!(at(Layout::BlazePose33, "RShoulder"), Some(12));
        assert_eq!(at(Layout::BlazePose33, "RWrist"), Some(16));
        assert_eq!(at(Layout::BlazePose33, "LIndex"), Some(19));
        assert_eq!(at(Layout::BlazePose33, "RThumb"), Some(22));
        assert_eq!(at(Layout::BlazePose33, "LHip"), Some(23));
        assert_eq!(at(Layout::BlazePose33, "RHeel"), Some(30));
        assert_eq!(at(Layout::BlazePose33, "RBigToe"), Some(32));
        assert_eq!(at(Layout::BlazePose33, "Neck"), None);
    }

    #[test]
    fn bones_skip_over_the_keypoints_a_layout_lacks() {
        let named = |layout: Layout| -> Vec<(&str, &str)> {
            let names = layout.names();
            layout
                .bones()
                .into_iter()
                .map(|(c, p)| (names[c], names[p]))
                .collect()
        };
        let body_25 = named(Layout::Body25);
        assert!(body_25.contains(&("LKnee", "LHip")));
        assert!(body_25.contains(&("LHip", "MidHip")));
        // No head top in BODY_25: the nose hangs from the neck.
        assert!(body_25.contains(&("Nose", "Neck")));
        assert!(body_25.contains(&("LSmallToe", "LAnkle")));
        // Every keypoint but the root has a bone in BODY_25.
        assert_eq!(body_25.len(), 24);
        let body_25b = named(Layout::Body25B);
        assert!(body_25b.contains(&("Nose", "Head")));
        assert!(body_25b.contains(&("REar", "REye")));
        // No mid-hip in BODY_25B: the hips and the neck are roots.
        assert!(!body_25b
            .iter()
            .any(|(c, _)| ["LHip", "RHip", "Neck"].contains(c)));
        let blazepose = named(Layout::BlazePose33);
        assert!(blazepose.contains(&("LThumb", "LWrist")));
        assert!(blazepose.contains(&("RBigToe", "RAnkle")));
        assert!(!blazepose.iter().any(|(c, _)| c.contains("Inner")));
    }

    #[test]
    fn labels_parse_back_and_aliases_are_accepted() {
        for layout in Layout::ALL {
            assert_eq!(Layout::parse(layout.label()), Some(layout));
            assert_eq!(Layout::parse(&layout.label().to_lowercase()), Some(layout));
        }
        assert_eq!(Layout::parse("coco"), Some(Layout::Coco17));
        assert_eq!(Layout::parse("Halpe"), Some(Layout::Halpe26));
        assert_eq!(Layout::parse("MediaPipe"), Some(Layout::BlazePose33));
        assert_eq!(Layout::parse("blazepose_33"), Some(Layout::BlazePose33));
        assert_eq!(Layout::parse(" BODY_25B "), Some(Layout::Body25B));
        assert_eq!(Layout::parse("BODY_135"), None);
        assert_eq!(Layout::parse(""), None);
    }

    #[test]
    fn layouts_serialize_by_variant_name() {
        let text = serde_json::to_string(&Layout::Body25B).unwrap();
        assert_eq!(text, "\"Body25B\"");
        let back: Layout = serde_json::from_str(&text).unwrap();
        assert_eq!(back, Layout::Body25B);
    }
}
