//! Small synthetic motions for unit tests (the real-data tests live in
//! `tests/` and use the Bandai Namco takes).

use mocap_core::rotation::Vec3;
use mocap_core::skeleton::{Channel, Joint};
use mocap_core::{Motion, Skeleton};

/// A chain of `joints` joints with bones of length 10 along +Y, the root
/// with six channels, the others with `Zrotation Xrotation Yrotation`,
/// moving smoothly (sines of different frequencies) at 30 fps.
pub fn synthetic_motion(frames: usize, joints: usize) -> Motion {
    synthetic_motion_phase(frames, joints, 0.0)
}

/// Like [`synthetic_motion`], with the sines shifted by `phase` radians.
pub fn synthetic_motion_phase(frames: usize, joints: usize, phase: f32) -> Motion {
    use Channel::*;
    let mut list = Vec::new();
    for j in 0..joints {
        let (parent, offset) = if j == 0 {
            (None, Vec3::ZERO)
        } else {
            (Some(j - 1), Vec3::new(0.0, 10.0, 0.0))
        };
        let mut joint = Joint::new(format!("j{j}"), parent, offset);
        joint.channels = if j == 0 {
            vec![
                Xposition, Yposition, Zposition, Zrotation, Xrotation, Yrotation,
            ]
        } else {
            vec![Zrotation, Xrotation, Yrotation]
        };
        if j + 1 == joints {
            joint.end_sites.push(Vec3::new(0.0, 10.0, 0.0));
        }
        list.push(joint);
    }
    let skeleton = Skeleton::new(list).expect("valid chain");
    let mut values = Vec::new();
    for f in 0..frames {
        let t = f as f32 / 30.0;
        for j in 0..joints {
            let a = j as f32 + 1.0;
            if j == 0 {
                values.extend([t * 10.0, 90.0, 0.0]);
            }
            values.extend([
                25.0 * (1.3 * t + a + phase).sin(),
                20.0 * (0.7 * t * a + phase).cos(),
                30.0 * (0.5 * t + 2.0 * a + phase).sin(),
            ]);
        }
    }
    Motion::new(skeleton, 1.0 / 30.0, frames, values).expect("valid motion")
}

/// A small branching body: `root` (six channels) -> `pelvis` (three
/// rotation channels) with two chains below it, `spine` -> `head` and
/// `fixed` (no channels) -> `leg` -> `foot`, all moving smoothly.
pub fn branching_motion(frames: usize) -> Motion {
    use Channel::*;
    let rotation = || vec![Zrotation, Xrotation, Yrotation];
    let joint = |name: &str, parent: Option<usize>, offset: Vec3, channels: Vec<Channel>| {
        let mut j = Joint::new(name, parent, offset);
        j.channels = channels;
        j
    };
    let mut foot = joint("foot", Some(5), Vec3::new(0.0, -40.0, 0.0), rotation());
    foot.end_sites.push(Vec3::new(0.0, 0.0, 10.0));
    let mut head = joint("head", Some(2), Vec3::new(0.0, 20.0, 0.0), rotation());
    head.end_sites.push(Vec3::new(0.0, 10.0, 0.0));
    let list = vec![
        joint(
            "root",
            None,
            Vec3::ZERO,
            vec![
                Xposition, Yposition, Zposition, Zrotation, Xrotation, Yrotation,
            ],
        ),
        joint("pelvis", Some(0), Vec3::new(0.0, 90.0, 0.0), rotation()),
        joint("spine", Some(1), Vec3::new(0.0, 15.0, 0.0), rotation()),
        head,
        joint("fixed", Some(1), Vec3::new(10.0, -5.0, 0.0), Vec::new()),
        joint("leg", Some(4), Vec3::new(0.0, -40.0, 0.0), rotation()),
        foot,
    ];
    let skeleton = Skeleton::new(list).expect("valid body");
    let mut values = Vec::new();
    for f in 0..frames {
        let t = f as f32 / 30.0;
        values.extend([t * 10.0, 0.0, 0.0, 5.0 * t.sin(), 0.0, 40.0 * t]);
        for a in 1..=5 {
            let a = a as f32;
            values.extend([
                25.0 * (1.3 * t + a).sin(),
                20.0 * (0.7 * t * a).cos(),
                30.0 * (0.5 * t + 2.0 * a).sin(),
            ]);
        }
    }
    Motion::new(skeleton, 1.0 / 30.0, frames, values).expect("valid motion")
}
