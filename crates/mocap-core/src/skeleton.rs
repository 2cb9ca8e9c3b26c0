//! The skeleton: joints in parent-before-child order with their rest offsets
//! and the channels their animation is stored in.

use crate::error::{Error, Result};
use crate::rotation::{Axis, EulerOrder, Quat, Vec3};

/// One animation channel of a joint, as named in BVH files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Channel {
    Xposition,
    Yposition,
    Zposition,
    Xrotation,
    Yrotation,
    Zrotation,
}

impl Channel {
    /// The BVH spelling of the channel.
    pub fn name(self) -> &'static str {
        match self {
            Channel::Xposition => "Xposition",
            Channel::Yposition => "Yposition",
            Channel::Zposition => "Zposition",
            Channel::Xrotation => "Xrotation",
            Channel::Yrotation => "Yrotation",
            Channel::Zrotation => "Zrotation",
        }
    }

    /// Parses a BVH channel name (case-insensitive, as some exporters write
    /// `XPOSITION` or `xrotation`).
    pub fn parse(name: &str) -> Option<Channel> {
        const ALL: [Channel; 6] = [
            Channel::Xposition,
            Channel::Yposition,
            Channel::Zposition,
            Channel::Xrotation,
            Channel::Yrotation,
            Channel::Zrotation,
        ];
        ALL.into_iter()
            .find(|c| c.name().eq_ignore_ascii_case(name))
    }

    pub fn is_rotation(self) -> bool {
        matches!(
            self,
            Channel::Xrotation | Channel::Yrotation | Channel::Zrotation
        )
    }

    pub fn is_position(self) -> bool {
        !self.is_rotation()
    }

    pub fn axis(self) -> Axis {
        match self {
            Channel::Xposition | Channel::Xrotation => Axis::X,
            Channel::Yposition | Channel::Yrotation => Axis::Y,
            Channel::Zposition | Channel::Zrotation => Axis::Z,
        }
    }

    pub fn rotation(axis: Axis) -> Channel {
        match axis {
            Axis::X => Channel::Xrotation,
            Axis::Y => Channel::Yrotation,
            Axis::Z => Channel::Zrotation,
        }
    }

    pub fn position(axis: Axis) -> Channel {
        match axis {
            Axis::X => Channel::Xposition,
            Axis::Y => Channel::Yposition,
            Axis::Z => Channel::Zposition,
        }
    }
}

/// Range of motion of one degree of freedom: `min..=max` in degrees for a
/// rotation, in file length units for a translation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DofLimit {
    pub channel: Channel,
    pub min: f32,
    pub max: f32,
}

/// Measured range of motion of a joint (ASF `limits`).
///
/// The limits hold for the Euler angles of the joint's local rotation
/// expressed in its `axis_frame`: with `q` the joint's local rotation in this
/// skeleton, the constrained rotation is `axis_frame^-1 * q * axis_frame`,
/// decomposed as *intrinsic* Euler angles in the order of `dofs` (the same
/// convention as BVH channels; the ASF reader lists `dof rx ry rz` as
/// `rz ry rx` for this reason). Translation limits are in the motion's length
/// unit.
#[derive(Debug, Clone, PartialEq)]
pub struct RangeOfMotion {
    pub axis_frame: Quat,
    pub dofs: Vec<DofLimit>,
}

/// A joint of a skeleton.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    pub name: String,
    /// Index of the parent joint; `None` for a root. Always smaller than this
    /// joint's own index.
    pub parent: Option<usize>,
    /// Rest translation from the parent joint, in the parent's frame.
    pub offset: Vec3,
    /// The joint's channels in file order.
    pub channels: Vec<Channel>,
    /// Offsets of the `End Site` children of this joint.
    pub end_sites: Vec<Vec3>,
    /// Range of motion, when the file gives one.
    pub limits: Option<RangeOfMotion>,
}

impl Joint {
    /// A joint with no channels, end sites or limits.
    pub fn new(name: impl Into<String>, parent: Option<usize>, offset: Vec3) -> Joint {
        Joint {
            name: name.into(),
            parent,
            offset,
            channels: Vec::new(),
            end_sites: Vec::new(),
            limits: None,
        }
    }

    /// The Euler order of the rotation channels when there are exactly three
    /// distinct ones.
    pub fn euler_order(&self) -> Option<EulerOrder> {
        let axes: Vec<Axis> = self
            .channels
            .iter()
            .filter(|c| c.is_rotation())
            .map(|c| c.axis())
            .collect();
        match axes[..] {
            [a, b, c] => EulerOrder::from_axes([a, b, c]),
            _ => None,
        }
    }

    pub fn has_position_channels(&self) -> bool {
        self.channels.iter().any(|c| c.is_position())
    }

    pub fn has_rotation_channels(&self) -> bool {
        self.channels.iter().any(|c| c.is_rotation())
    }
}

/// Joints in parent-before-child order, with each joint's first column in a
/// frame of channel values.
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    joints: Vec<Joint>,
    channel_starts: Vec<usize>,
    channel_count: usize,
}

impl Skeleton {
    /// Checks the joint order (every parent before its children), unique
    /// names, and that no joint lists a channel twice.
    pub fn new(joints: Vec<Joint>) -> Result<Skeleton> {
        let mut channel_starts = Vec::with_capacity(joints.len());
        let mut channel_count = 0;
        let mut names = std::collections::HashSet::new();
        for (i, joint) in joints.iter().enumerate() {
            if let Some(p) = joint.parent {
                if p >= i {
                    return Err(Error::Invalid(format!(
                        "joint {:?} (index {i}) comes before its parent (index {p})",
                        joint.name
                    )));
                }
            }
            if !names.insert(joint.name.as_str()) {
                return Err(Error::Invalid(format!(
                    "two joints are named {:?}",
                    joint.name
                )));
            }
            for (k, c) in joint.channels.iter().enumerate() {
                if joint.channels[..k].contains(c) {
                    return Err(Error::Invalid(format!(
                        "joint {:?} lists channel {} twice",
                        joint.name,
                        c.name()
                    )));
                }
            }
            channel_starts.push(channel_count);
            channel_count += joint.channels.len();
        }
        Ok(Skeleton {
            joints,
            channel_starts,
            channel_count,
        })
    }

    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    pub fn joint(&self, index: usize) -> &Joint {
        &self.joints[index]
    }

    pub fn joint_count(&self) -> usize {
        self.joints.len()
    }

    /// The parent of every joint (`None` for roots), in joint order.
    pub fn parents(&self) -> Vec<Option<usize>> {
        self.joints.iter().map(|j| j.parent).collect()
    }

    /// Number of channel values in one frame.
    pub fn channel_count(&self) -> usize {
        self.channel_count
    }

    /// Column of the joint's first channel in a frame of values.
    pub fn channel_start(&self, joint: usize) -> usize {
        self.channel_starts[joint]
    }

    /// Index of the joint with this exact name.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Indices of the joints whose parent is `joint`.
    pub fn children(&self, joint: usize) -> impl Iterator<Item = usize> + '_ {
        self.joints
            .iter()
            .enumerate()
            .filter(move |(_, j)| j.parent == Some(joint))
            .map(|(i, _)| i)
    }

    /// The first joint, walking down from the first root, that has other
    /// than exactly one child: the pelvis of a body (`Hips` in Bandai Namco
    /// and CMU BVH, `root` in ASF), below any helper joints that some rigs
    /// put above it (Bandai's `joint_Root` on the floor). Found from the
    /// hierarchy alone, so it works for rigs with any joint names; a rig that
    /// is a single chain gives its last joint.
    pub fn first_branching_joint(&self) -> usize {
        let mut joint = 0;
        loop {
            let mut children = self.children(joint);
            match (children.next(), children.next()) {
                (Some(only), None) => joint = only,
                _ => return joint,
            }
        }
    }

    /// `joint` and every joint below it, in skeleton order.
    pub fn subtree(&self, joint: usize) -> Vec<usize> {
        let mut inside = vec![false; self.joints.len()];
        inside[joint] = true;
        let mut out = vec![joint];
        for i in joint + 1..self.joints.len() {
            if let Some(p) = self.joints[i].parent {
                if inside[p] {
                    inside[i] = true;
                    out.push(i);
                }
            }
        }
        out
    }

    /// Rest length of the bone chain from `joint` up to its ancestor
    /// `ancestor`: the sum of the offsets' lengths of `joint` and every joint
    /// between them (not of `ancestor` itself). `None` when `ancestor` is not
    /// above `joint`; 0 when they are the same joint.
    pub fn chain_length(&self, joint: usize, ancestor: usize) -> Option<f32> {
        let mut length = 0.0;
        let mut at = joint;
        while at != ancestor {
            length += self.joints[at].offset.length();
            at = self.joints[at].parent?;
        }
        Some(length)
    }

    /// Consumes the skeleton and returns its joints (to edit and rebuild).
    pub fn into_joints(self) -> Vec<Joint> {
        self.joints
    }
}
