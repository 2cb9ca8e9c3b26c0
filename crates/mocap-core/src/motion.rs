//! A motion: a skeleton, a frame time and the channel values of every frame.
//!
//! The channel values are kept exactly as read (rotations in degrees,
//! positions in file units, columns in file order), so writing a motion back
//! loses nothing. Root translation, local rotations and local translations are
//! views computed from them.

use crate::error::{Error, Result};
use crate::rotation::{quat_to_euler_near, Axis, EulerOrder, Quat, Vec3};
use crate::skeleton::{Channel, Joint, Skeleton};

/// The frame times a motion may have, in seconds: a million frames per
/// second to one frame every ten seconds. Outside it a take is a broken file
/// (`Frame Time: 1e300` makes every duration infinite, `1e-300` every speed),
/// not a capture.
pub const FRAME_TIME_RANGE: std::ops::RangeInclusive<f64> = 1e-6..=10.0;

/// The most channel values one motion may hold (frames × channels): 2^28, a
/// gigabyte of `f32`, above the largest real takes (a 1 GB BVH file holds
/// about 113 million). An edit whose output would be larger (resampling a
/// take to a billion frames per second) is refused before it allocates.
pub const MAX_VALUES: usize = 1 << 28;

const DEG: f32 = std::f32::consts::PI / 180.0;

#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    skeleton: Skeleton,
    frame_time: f64,
    frame_count: usize,
    /// `frame_count * skeleton.channel_count()` values, frame after frame.
    values: Vec<f32>,
}

impl Motion {
    /// A motion from channel values laid out frame after frame. The frame
    /// time is in seconds, within [`FRAME_TIME_RANGE`].
    pub fn new(
        skeleton: Skeleton,
        frame_time: f64,
        frame_count: usize,
        values: Vec<f32>,
    ) -> Result<Motion> {
        if !FRAME_TIME_RANGE.contains(&frame_time) {
            return Err(Error::Invalid(format!(
                "frame time must be {} to {} seconds, got {frame_time}",
                FRAME_TIME_RANGE.start(),
                FRAME_TIME_RANGE.end()
            )));
        }
        let expected = frame_count * skeleton.channel_count();
        if values.len() != expected {
            return Err(Error::Invalid(format!(
                "{frame_count} frames of {} channels need {expected} values, got {}",
                skeleton.channel_count(),
                values.len()
            )));
        }
        Ok(Motion {
            skeleton,
            frame_time,
            frame_count,
            values,
        })
    }

    /// A motion of `frame_count` frames in which every joint is at its rest
    /// offset with no rotation.
    pub fn rest(skeleton: Skeleton, frame_time: f64, frame_count: usize) -> Result<Motion> {
        let mut frame = vec![0.0; skeleton.channel_count()];
        for (j, joint) in skeleton.joints().iter().enumerate() {
            let start = skeleton.channel_start(j);
            for (k, c) in joint.channels.iter().enumerate() {
                if c.is_position() {
                    frame[start + k] = joint.offset[c.axis() as usize];
                }
            }
        }
        let values = frame.repeat(frame_count);
        Motion::new(skeleton, frame_time, frame_count, values)
    }

    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// Seconds between frames, as written in the file.
    pub fn frame_time(&self) -> f64 {
        self.frame_time
    }

    /// Frames per second.
    pub fn fps(&self) -> f64 {
        1.0 / self.frame_time
    }

    pub fn frame_count(&self) -> usize {
        self.frame_count
    }

    /// Length of the take in seconds (`frame_count * frame_time`).
    pub fn duration(&self) -> f64 {
        self.frame_count as f64 * self.frame_time
    }

    /// All channel values, frame after frame.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The channel values of one frame.
    pub fn frame(&self, frame: usize) -> &[f32] {
        let n = self.skeleton.channel_count();
        &self.values[frame * n..(frame + 1) * n]
    }

    pub fn frame_mut(&mut self, frame: usize) -> &mut [f32] {
        let n = self.skeleton.channel_count();
        &mut self.values[frame * n..(frame + 1) * n]
    }

    /// Splits into skeleton, frame time, frame count and values.
    pub fn into_parts(self) -> (Skeleton, f64, usize, Vec<f32>) {
        (
            self.skeleton,
            self.frame_time,
            self.frame_count,
            self.values,
        )
    }

    /// The channel values of `joint` in `frame`, in the joint's channel order.
    pub fn joint_values(&self, frame: usize, joint: usize) -> &[f32] {
        let start = self.skeleton.channel_start(joint);
        let len = self.skeleton.joint(joint).channels.len();
        &self.frame(frame)[start..start + len]
    }

    /// Appends the frames of `other`, which must have the same skeleton and
    /// frame time (for joining takes of one recording).
    pub fn append(&mut self, other: &Motion) -> Result<()> {
        if other.skeleton != self.skeleton {
            return Err(Error::Invalid(
                "cannot join motions with different skeletons".to_string(),
            ));
        }
        if other.frame_time != self.frame_time {
            return Err(Error::Invalid(format!(
                "cannot join motions with different frame times ({} s and {} s)",
                self.frame_time, other.frame_time
            )));
        }
        self.values.extend_from_slice(&other.values);
        self.frame_count += other.frame_count;
        Ok(())
    }

    /// Local rotation of `joint` in `frame`: the product of its rotation
    /// channels in the order listed (BVH rotations are intrinsic).
    pub fn local_rotation(&self, frame: usize, joint: usize) -> Quat {
        local_rotation_of(
            &self.skeleton.joint(joint).channels,
            self.joint_values(frame, joint),
        )
    }

    /// Local translation of `joint` in `frame`: its position channels where it
    /// has them (they replace the rest offset, as in BVH), else its offset.
    pub fn local_translation(&self, frame: usize, joint: usize) -> Vec3 {
        local_translation_of(self.skeleton.joint(joint), self.joint_values(frame, joint))
    }

    /// Translation of the first root joint in `frame`.
    pub fn root_translation(&self, frame: usize) -> Vec3 {
        self.local_translation(frame, 0)
    }

    /// Sets the local rotation of `joint` in `frame` by rewriting its rotation
    /// channels. The Euler angles are chosen nearest to the previous frame's so
    /// that tracks stay continuous (no jumps of 360 degrees).
    ///
    /// A joint with fewer than three rotation channels can only hold rotations
    /// about those axes: the rotation is decomposed with the missing axes last
    /// and only the listed angles are kept. A joint without rotation channels
    /// is left unchanged.
    pub fn set_local_rotation(&mut self, frame: usize, joint: usize, rotation: Quat) {
        let reference = (frame > 0).then(|| self.rotation_angles(frame - 1, joint));
        self.set_local_rotation_near(frame, joint, rotation, reference);
    }

    /// Like [`Motion::set_local_rotation`], but the Euler angles are chosen
    /// nearest to `reference` (radians, in the joint's rotation channel order;
    /// `None` means zero), e.g. the angles of the same frame before an edit.
    pub fn set_local_rotation_near(
        &mut self,
        frame: usize,
        joint: usize,
        rotation: Quat,
        reference: Option<Vec3>,
    ) {
        let Some((columns, order)) = self.rotation_columns(joint) else {
            return;
        };
        let angles = quat_to_euler_near(order, rotation, reference.unwrap_or(Vec3::ZERO));
        let values = self.frame_mut(frame);
        for (slot, column) in columns.into_iter().enumerate() {
            if let Some(c) = column {
                values[c] = angles[slot] / DEG;
            }
        }
    }

    /// The rotation channel values of `joint` in `frame`, in radians, in the
    /// order of its rotation channels (missing channels are zero).
    pub fn rotation_angles(&self, frame: usize, joint: usize) -> Vec3 {
        let mut angles = Vec3::ZERO;
        if let Some((columns, _)) = self.rotation_columns(joint) {
            let values = self.frame(frame);
            for (slot, column) in columns.into_iter().enumerate() {
                if let Some(c) = column {
                    angles[slot] = values[c] * DEG;
                }
            }
        }
        angles
    }

    /// Columns of the joint's rotation channels in frame order, and the Euler
    /// order they form, with axes the joint lacks appended last (their
    /// column is `None`). `None` for a joint without rotation channels.
    fn rotation_columns(&self, joint: usize) -> Option<([Option<usize>; 3], EulerOrder)> {
        let start = self.skeleton.channel_start(joint);
        let mut columns = [None; 3];
        let mut axes = [Axis::X; 3];
        let mut count = 0;
        for (k, c) in self.skeleton.joint(joint).channels.iter().enumerate() {
            if c.is_rotation() && count < 3 {
                columns[count] = Some(start + k);
                axes[count] = c.axis();
                count += 1;
            }
        }
        if count == 0 {
            return None;
        }
        for a in [Axis::X, Axis::Y, Axis::Z] {
            if count < 3 && !axes[..count].contains(&a) {
                axes[count] = a;
                count += 1;
            }
        }
        let order = EulerOrder::from_axes(axes).expect("three distinct axes form an Euler order");
        Some((columns, order))
    }

    /// Sets the position channels of `joint` in `frame`. A joint without
    /// position channels keeps its offset.
    pub fn set_local_translation(&mut self, frame: usize, joint: usize, translation: Vec3) {
        let start = self.skeleton.channel_start(joint);
        let channels = self.skeleton.joint(joint).channels.clone();
        let values = self.frame_mut(frame);
        for (k, c) in channels.iter().enumerate() {
            if c.is_position() {
                values[start + k] = translation[c.axis() as usize];
            }
        }
    }
}

/// Translation of a joint from its channel values: position channels replace
/// the matching coordinates of the rest offset.
#[inline]
pub(crate) fn local_translation_of(joint: &Joint, values: &[f32]) -> Vec3 {
    let mut t = joint.offset;
    for (c, &v) in joint.channels.iter().zip(values) {
        if c.is_position() {
            t[c.axis() as usize] = v;
        }
    }
    t
}

/// Rotation of a joint's channel values (degrees) in the order listed.
#[inline]
pub(crate) fn local_rotation_of(channels: &[Channel], values: &[f32]) -> Quat {
    let mut q = Quat::IDENTITY;
    for (c, &v) in channels.iter().zip(values) {
        if c.is_rotation() {
            q *= c.axis().rotation(v * DEG);
        }
    }
    q
}
