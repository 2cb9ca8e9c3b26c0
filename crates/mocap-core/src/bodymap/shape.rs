//! Body parts from the skeleton's shape, for rigs whose joint names no
//! convention knows.
//!
//! On the rest pose (the offsets summed down the hierarchy):
//! - **pelvis**: walking down from the root, the first joint with three or
//!   more long branches (each at least [`BIG`] of the joint's reach): the
//!   one that forks again further down is the spine, the two that do not are
//!   the legs;
//! - **chest**: walking up the spine, the first joint with two branches of
//!   at least [`FORK`] of the spine branch's reach: the two longest are the
//!   arms, the longest other child leads to the neck and head (the first
//!   and second joint past the chest on it; the head alone when there is
//!   one); **spine**: the first joint past the pelvis below the chest;
//! - **limbs**: along each arm and leg (following the child of longest
//!   reach), the two long bones are the two consecutive bones of greatest
//!   length whose end (wrist, ankle) has less beyond it than the first bone
//!   is long (a hand or a foot, not a forearm and hand): they give the
//!   shoulder, elbow and wrist, or hip, knee and ankle. The joint before the
//!   shoulder, if it is not the chest, is the clavicle; the first joint past
//!   the wrist or ankle is the hand or toe.
//!
//! Joints at the same place (zero offsets, as CMU's `LHipJoint` under
//! `Hips`) count as one point, the one highest in the hierarchy standing
//! for it. Fingers, eyes, twist and helper joints are short side branches
//! and are never followed.
//!
//! Left and right come from the rest pose: up is from the pelvis to the
//! head, forward is where the feet point (ankle to toe tip), and the left
//! side is up × forward. A rest pose whose legs do not hang down or whose
//! feet point nowhere (Bandai's has every bone along x) cannot tell; then
//! joint names that differ only by a side marker (`_L`/`_R`, `Left`/
//! `Right`...) decide. A first frame is not used: the body map is the
//! rig's, the same for every take of it. When neither tells, or they
//! disagree, nothing is guessed: the parts are refused.

use super::names::name_pattern_pairs;
use super::{BodyPart, SideEvidence};
use crate::rotation::Vec3;
use crate::skeleton::Skeleton;

/// A branch is long at a joint when it reaches at least this part of the
/// joint's own reach.
const BIG: f32 = 0.3;
/// The spine forks (at the chest) into branches of at least this part of
/// the spine branch's reach; the legs never do.
const FORK: f32 = 0.25;
/// Joints closer than this part of the pelvis's reach are one point.
const SAME_POINT: f32 = 0.01;
/// The cosine between the two limbs' offset and the body's left direction
/// below which the rest pose does not tell left from right.
const SIDE_COSINE: f32 = 0.5;

/// What the shape of a skeleton gives.
pub(super) struct ShapeOutcome {
    /// The parts found; when `sides` is `None`, the limbs found are put on
    /// an arbitrary side.
    pub(super) joints: [Option<usize>; BodyPart::COUNT],
    /// How left and right were told, `None` when they were not.
    pub(super) sides: Option<SideEvidence>,
    /// Why the shape does not give every required part, `None` when it does.
    pub(super) failure: Option<String>,
}

/// Finds the body parts of `skeleton` from its shape (module
/// documentation).
pub(super) fn find(skeleton: &Skeleton) -> ShapeOutcome {
    let mut out = ShapeOutcome {
        joints: [None; BodyPart::COUNT],
        sides: None,
        failure: None,
    };
    if let Err(reason) = find_into(skeleton, &mut out) {
        out.failure = Some(reason);
    }
    out
}

/// The rest pose and the reach of every joint.
struct Rest<'a> {
    skeleton: &'a Skeleton,
    position: Vec<Vec3>,
    children: Vec<Vec<usize>>,
    /// Longest path from the joint down through its children and end sites.
    reach: Vec<f32>,
    /// Distance under which two joints are one point.
    same_point: f32,
}

impl<'a> Rest<'a> {
    fn new(skeleton: &'a Skeleton) -> Rest<'a> {
        let n = skeleton.joint_count();
        let mut position = vec![Vec3::ZERO; n];
        let mut children = vec![Vec::new(); n];
        for (j, joint) in skeleton.joints().iter().enumerate() {
            let base = joint.parent.map_or(Vec3::ZERO, |p| position[p]);
            position[j] = base + joint.offset;
            if let Some(p) = joint.parent {
                children[p].push(j);
            }
        }
        let mut reach = vec![0.0f32; n];
        for j in (0..n).rev() {
            let ends = skeleton.joint(j).end_sites.iter().map(|e| e.length());
            let kids = children[j]
                .iter()
                .map(|&c| skeleton.joint(c).offset.length() + reach[c]);
            reach[j] = ends.chain(kids).fold(0.0, f32::max);
        }
        Rest {
            skeleton,
            position,
            children,
            reach,
            same_point: 0.0,
        }
    }

    fn name(&self, joint: usize) -> &str {
        &self.skeleton.joint(joint).name
    }

    /// Length of the branch that starts with the bone to `child`.
    fn branch(&self, child: usize) -> f32 {
        self.skeleton.joint(child).offset.length() + self.reach[child]
    }

    fn distance(&self, a: usize, b: usize) -> f32 {
        self.position[a].distance(self.position[b])
    }

    /// The children of `joint` whose branch is at least `least` long,
    /// longest first.
    fn long_children(&self, joint: usize, least: f32) -> Vec<usize> {
        let mut out: Vec<usize> = self.children[joint]
            .iter()
            .copied()
            .filter(|&c| self.branch(c) >= least)
            .collect();
        out.sort_by(|&a, &b| self.branch(b).total_cmp(&self.branch(a)));
        out
    }

    /// The child of `joint` with the longest branch.
    fn longest_child(&self, joint: usize) -> Option<usize> {
        self.children[joint]
            .iter()
            .copied()
            .max_by(|&a, &b| self.branch(a).total_cmp(&self.branch(b)))
    }

    /// Whether some joint of the branch starting at `child` forks into two
    /// branches of at least [`FORK`] of its length (the spine does at the
    /// chest; a leg does not).
    fn forks(&self, child: usize) -> bool {
        let least = FORK * self.branch(child);
        self.skeleton
            .subtree(child)
            .into_iter()
            .any(|k| self.long_children(k, least).len() >= 2)
    }

    /// `from`, `first`, then the child of longest branch down to a leaf.
    fn chain(&self, from: usize, first: usize) -> Vec<usize> {
        let mut chain = vec![from, first];
        let mut at = first;
        while let Some(next) = self.longest_child(at) {
            chain.push(next);
            at = next;
        }
        chain
    }

    /// The chain's joints grouped into points: consecutive joints at the
    /// same place are one point, named by its first joint.
    fn points(&self, chain: &[usize]) -> Vec<usize> {
        let mut points: Vec<usize> = Vec::new();
        for &j in chain {
            match points.last() {
                Some(&p) if self.distance(p, j) < self.same_point => {}
                _ => points.push(j),
            }
        }
        points
    }

    /// The farthest point of the branch below `joint`, down the children of
    /// longest branch and the longest end site.
    fn tip(&self, joint: usize) -> Vec3 {
        let mut at = joint;
        while let Some(next) = self.longest_child(at) {
            at = next;
        }
        let end = self
            .skeleton
            .joint(at)
            .end_sites
            .iter()
            .copied()
            .max_by(|a, b| a.length().total_cmp(&b.length()))
            .unwrap_or(Vec3::ZERO);
        self.position[at] + end
    }
}

/// An arm or a leg.
struct Limb {
    /// The first joint of the limb's branch (below the chest or pelvis).
    root: usize,
    /// Clavicle (arms only).
    girdle: Option<usize>,
    /// Shoulder or hip, elbow or knee, wrist or ankle.
    upper: usize,
    middle: usize,
    lower: usize,
    /// Hand or toe.
    end: Option<usize>,
}

impl Limb {
    /// Finds the limb whose branch starts at `root`, below `from`.
    fn find(rest: &Rest, from: usize, root: usize) -> Option<Limb> {
        let chain = rest.chain(from, root);
        let points = rest.points(&chain);
        let mut best: Option<(f32, usize)> = None;
        for i in 1..points.len().saturating_sub(2) {
            let (a, b, c) = (points[i], points[i + 1], points[i + 2]);
            let (first, second) = (rest.distance(a, b), rest.distance(b, c));
            if rest.reach[c] < first && best.is_none_or(|(s, _)| first + second > s) {
                best = Some((first + second, i));
            }
        }
        let (_, i) = best?;
        let upper = points[i];
        let at = chain.iter().position(|&j| j == upper)?;
        Some(Limb {
            root,
            girdle: (at >= 2).then(|| chain[at - 1]),
            upper,
            middle: points[i + 1],
            lower: points[i + 2],
            end: points.get(i + 3).copied(),
        })
    }

    fn points(&self) -> [usize; 3] {
        [self.upper, self.middle, self.lower]
    }

    /// Puts the limb's joints at `parts` (`[girdle, upper, middle, lower,
    /// end]`; legs have no girdle part).
    fn place(&self, joints: &mut [Option<usize>; BodyPart::COUNT], parts: LimbParts) {
        let found = [
            self.girdle,
            Some(self.upper),
            Some(self.middle),
            Some(self.lower),
            self.end,
        ];
        for (part, joint) in parts.into_iter().zip(found) {
            if let Some(part) = part {
                joints[part.index()] = joint;
            }
        }
    }
}

/// The parts of a limb's girdle, upper, middle and lower joint and end.
type LimbParts = [Option<BodyPart>; 5];

const LEFT_LEG: LimbParts = [
    None,
    Some(BodyPart::LeftHip),
    Some(BodyPart::LeftKnee),
    Some(BodyPart::LeftAnkle),
    Some(BodyPart::LeftToe),
];
const LEFT_ARM: LimbParts = [
    Some(BodyPart::LeftClavicle),
    Some(BodyPart::LeftShoulder),
    Some(BodyPart::LeftElbow),
    Some(BodyPart::LeftWrist),
    Some(BodyPart::LeftHand),
];

fn find_into(skeleton: &Skeleton, out: &mut ShapeOutcome) -> Result<(), String> {
    let mut rest = Rest::new(skeleton);
    if skeleton.joint_count() == 0 {
        return Err("the skeleton has no joint".into());
    }

    // The pelvis: where two legs and a spine branch off.
    let mut node = 0;
    let (pelvis, spine, legs) = loop {
        let long = rest.long_children(node, BIG * rest.reach[node]);
        match long.len() {
            0 => {
                return Err(format!(
                    "no joint where two legs and a spine branch off (the hierarchy from the \
                     root ends at {})",
                    rest.name(node)
                ))
            }
            1 => node = long[0],
            _ => {
                let (forked, plain): (Vec<usize>, Vec<usize>) =
                    long.iter().partition(|&&c| rest.forks(c));
                if forked.len() == 1 && plain.len() == 2 {
                    break (node, forked[0], [plain[0], plain[1]]);
                }
                return Err(format!(
                    "no joint where two legs and a spine branch off: {} has {} long \
                     branches, {} of which fork again (a pelvis has two legs that do not \
                     and a spine that does, at the chest)",
                    rest.name(node),
                    long.len(),
                    forked.len()
                ));
            }
        }
    };
    rest.same_point = SAME_POINT * rest.reach[pelvis];
    out.joints[BodyPart::Pelvis.index()] = Some(pelvis);

    // The chest: up the spine to where the arms branch off.
    let least = FORK * rest.branch(spine);
    let mut spine_chain = vec![pelvis, spine];
    let mut at = spine;
    let (chest, arms) = loop {
        let long = rest.long_children(at, least);
        if long.len() >= 2 {
            break (at, [long[0], long[1]]);
        }
        match rest.longest_child(at) {
            Some(next) => {
                spine_chain.push(next);
                at = next;
            }
            None => {
                return Err(format!(
                    "no joint of the spine above {} where two arms branch off",
                    rest.name(pelvis)
                ))
            }
        }
    };
    let spine_points = rest.points(&spine_chain);
    if spine_points.len() >= 3 {
        out.joints[BodyPart::Spine.index()] = Some(spine_points[1]);
    }
    let chest_point = match spine_points.last() {
        Some(&p) if p != pelvis => p,
        _ => chest,
    };
    out.joints[BodyPart::Chest.index()] = Some(chest_point);

    // Neck and head: the longest other branch of the chest.
    let head_branch = rest.children[chest]
        .iter()
        .copied()
        .filter(|c| !arms.contains(c))
        .max_by(|&a, &b| rest.branch(a).total_cmp(&rest.branch(b)));
    let Some(head_branch) = head_branch else {
        return Err(format!(
            "no head: {}, where the arms branch off, has no other branch",
            rest.name(chest)
        ));
    };
    let head_points = rest.points(&rest.chain(chest, head_branch));
    match head_points[1..] {
        [] => {
            return Err(format!(
                "no head: the branch of {} past the arms has no joint away from it",
                rest.name(chest)
            ))
        }
        [head] => out.joints[BodyPart::Head.index()] = Some(head),
        [neck, head, ..] => {
            out.joints[BodyPart::Neck.index()] = Some(neck);
            out.joints[BodyPart::Head.index()] = Some(head);
        }
    }

    // The limbs, on a side to be told.
    let limb = |from: usize, root: usize, what: &str| {
        Limb::find(&rest, from, root).ok_or_else(|| {
            format!(
                "the {what} from {} has no two long bones (an upper and a lower {what} \
                 ending in a shorter {})",
                rest.name(root),
                if what == "arm" { "hand" } else { "foot" }
            )
        })
    };
    let legs = [limb(pelvis, legs[0], "leg")?, limb(pelvis, legs[1], "leg")?];
    let arms = [limb(chest, arms[0], "arm")?, limb(chest, arms[1], "arm")?];
    let place = |joints: &mut [Option<usize>; BodyPart::COUNT], first_left: [bool; 2]| {
        for (pair, left_parts, first_is_left) in [
            (&legs, LEFT_LEG, first_left[0]),
            (&arms, LEFT_ARM, first_left[1]),
        ] {
            let (left, right) = if first_is_left {
                (&pair[0], &pair[1])
            } else {
                (&pair[1], &pair[0])
            };
            left.place(joints, left_parts);
            right.place(joints, left_parts.map(|p| p.map(BodyPart::mirror)));
        }
    };
    place(&mut out.joints, [true, true]);

    // Left and right.
    let up = (rest.position[out.joints[BodyPart::Head.index()].unwrap()] - rest.position[pelvis])
        .normalize_or_zero();
    let forward = facing(&rest, up, &legs);
    let pairs = name_pattern_pairs(skeleton);
    let mut by_names = false;
    let mut first_left = [true; 2];
    for (k, (pair, what)) in [(&legs, "legs"), (&arms, "arms")].into_iter().enumerate() {
        let geometry = forward.and_then(|f| rest_pose_side(&rest, up, f, pair));
        let names = name_side(skeleton, &pairs, pair);
        first_left[k] = match (geometry, names) {
            (Some(g), Some(n)) if g != n => {
                return Err(format!(
                    "the rest pose puts {} on the left, but the joint names say it is on \
                     the right",
                    rest.name(pair[if g { 0 } else { 1 }].upper)
                ))
            }
            (Some(g), _) => g,
            (None, Some(n)) => {
                by_names = true;
                n
            }
            (None, None) => {
                return Err(format!(
                    "left and right cannot be told for the {what} ({} and {}): the rest pose \
                     does not show it ({}), and the joint names carry no left/right marker",
                    rest.name(pair[0].upper),
                    rest.name(pair[1].upper),
                    match forward {
                        None => "its legs do not hang down or its feet point nowhere",
                        Some(_) => "its two limbs are not apart across the body",
                    }
                ))
            }
        };
    }
    place(&mut out.joints, first_left);
    out.sides = Some(if by_names {
        SideEvidence::Names
    } else {
        SideEvidence::RestPose
    });
    Ok(())
}

/// Where the body faces in the rest pose: the mean direction from the
/// ankles to the tips of the feet, across `up`. `None` when the legs do not
/// hang down from the hips or the feet point nowhere across `up`.
fn facing(rest: &Rest, up: Vec3, legs: &[Limb; 2]) -> Option<Vec3> {
    let mut forward = Vec3::ZERO;
    let mut leg_length = 0.0;
    for leg in legs {
        let down = rest.position[leg.lower] - rest.position[leg.upper];
        if down.dot(up) > -0.5 * down.length() {
            return None;
        }
        leg_length += down.length();
        let foot = rest.tip(leg.lower) - rest.position[leg.lower];
        forward += foot - up * foot.dot(up);
    }
    (forward.length() > 0.05 * leg_length).then(|| forward.normalize())
}

/// Whether the first of two limbs is the left one, from the rest pose:
/// their joints' offset across `up`, against the body's left (up ×
/// forward). `None` when the offset is not clearly to one side.
fn rest_pose_side(rest: &Rest, up: Vec3, forward: Vec3, pair: &[Limb; 2]) -> Option<bool> {
    let mut apart = Vec3::ZERO;
    for (a, b) in pair[0].points().into_iter().zip(pair[1].points()) {
        apart += rest.position[a] - rest.position[b];
    }
    apart -= up * apart.dot(up);
    let left = up.cross(forward).normalize_or_zero();
    let length = apart.length();
    if length < rest.same_point || left == Vec3::ZERO {
        return None;
    }
    let cosine = apart.dot(left) / length;
    (cosine.abs() >= SIDE_COSINE).then_some(cosine > 0.0)
}

/// Whether the first of two limbs is the left one, from joint names that
/// differ only by a side marker (`pairs`, `(left, right)`): `None` when no
/// such pair joins them, or as many say one way as the other.
fn name_side(skeleton: &Skeleton, pairs: &[(usize, usize)], limbs: &[Limb; 2]) -> Option<bool> {
    let mut inside = [
        vec![false; skeleton.joint_count()],
        vec![false; skeleton.joint_count()],
    ];
    for (k, limb) in limbs.iter().enumerate() {
        for j in skeleton.subtree(limb.root) {
            inside[k][j] = true;
        }
    }
    let mut votes = 0i32;
    for &(left, right) in pairs {
        if inside[0][left] && inside[1][right] {
            votes += 1;
        } else if inside[1][left] && inside[0][right] {
            votes -= 1;
        }
    }
    (votes != 0).then_some(votes > 0)
}
