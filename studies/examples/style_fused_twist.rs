//! Why the style model cannot reproduce fused takes.
//!
//! The chain restyles its fused, cleaned take; the shipped style model gives
//! such a take back some 65 degrees off with no style, against 3-5 for the
//! walks it was trained on (`source_reconstruction_deg`). A Kinect skeleton
//! does not see the twist of a limb about its bone, so the fitted skeleton's
//! twists are the fitter's guess. This study splits each joint's local
//! rotation into its swing (where the bone to its only child points) and its
//! twist (about that bone), `q = swing * twist`, and measures the model on
//! the take with parts of the truth put in: its twists (in each joint's
//! frame, or in the world with the take's bones kept), its swings, its
//! pelvis and chest, its end joints (hands, head, toes); and on both with
//! every twist taken out. docs/research/style.md, "Fused takes".
//!
//! cargo run --release -p mocap-studies --example style_fused_twist -- MODEL TAKE.bvh TRUTH.bvh [TAKE TRUTH]...
//!
//! TAKE on the truth's rig (the demo's `fuse/fused-on-sample-rig.bvh` or
//! `clean/cleaned.bvh`), TRUTH the take it was captured from.

use mocap_core::io::bvh::read_bvh;
use mocap_core::rotation::{Quat, Vec3};
use mocap_core::{forward_kinematics, Motion};
use mocap_studies::frames::frame_shift;
use mocap_style::{load_model, source_reconstruction_deg};

type Error = Box<dyn std::error::Error>;

/// `q = swing * twist`, the twist about the unit `axis` (the joint's frame).
fn swing_twist(q: Quat, axis: Vec3) -> (Quat, Quat) {
    let v = Vec3::new(q.x, q.y, q.z);
    let p = axis * v.dot(axis);
    let twist = Quat::from_xyzw(p.x, p.y, p.z, q.w);
    let twist = if twist.length_squared() < 1e-12 {
        Quat::IDENTITY
    } else {
        twist.normalize()
    };
    (q * twist.inverse(), twist)
}

/// `take` with `truth`'s rotations on its joints with no child.
fn with_truth_ends(take: &Motion, truth: &Motion, shift: isize) -> Motion {
    mixed(take, truth, shift, Mix::TruthEnds)
}

/// Per joint, the unit bone to its only child (in the joint's frame);
/// `None` for a joint with no child or several.
fn bone_axes(motion: &Motion) -> Vec<Option<Vec3>> {
    let skeleton = motion.skeleton();
    (0..skeleton.joint_count())
        .map(|j| {
            let children: Vec<usize> = skeleton.children(j).collect();
            match children.as_slice() {
                [c] => Some(skeleton.joint(*c).offset).filter(|o| o.length() > 1e-6),
                _ => None,
            }
            .map(|o| o.normalize())
        })
        .collect()
}

/// Which part of the rotation `take` keeps of its own, the rest from `truth`.
#[derive(Clone, Copy)]
enum Mix {
    TruthTwist,
    TruthSwing,
    NoTwist,
    /// The truth's rotations on the joints with no single child (the root,
    /// the pelvis, the chest, the ends), the take's elsewhere.
    TruthBranches,
    /// The truth's rotations on the joints with no child (hands, head,
    /// toes: their rotations move no joint, so a capture cannot see them).
    TruthEnds,
}

/// `take` with every bone pointing where the take's points in the world
/// and turned about itself as the truth's is: each single-child joint's
/// global rotation is the truth's, swung the shortest way to the take's
/// bone; joints with several children keep the take's.
fn truth_twist_in_world(take: &Motion, truth: &Motion, shift: isize) -> Motion {
    let axes = bone_axes(take);
    let (take_poses, truth_poses) = (forward_kinematics(take), forward_kinematics(truth));
    let skeleton = take.skeleton();
    let mut out = take.clone();
    for f in 0..take.frame_count() {
        let g = (f as isize + shift).clamp(0, truth.frame_count() as isize - 1) as usize;
        let mut global = vec![Quat::IDENTITY; axes.len()];
        for (j, axis) in axes.iter().enumerate() {
            let mine = take_poses.rotation(f, j);
            global[j] = match *axis {
                Some(axis) => {
                    let theirs = truth_poses.rotation(g, j);
                    Quat::from_rotation_arc(theirs * axis, mine * axis) * theirs
                }
                None => mine,
            };
            let parent = skeleton
                .joint(j)
                .parent
                .map_or(Quat::IDENTITY, |p| global[p]);
            out.set_local_rotation(f, j, (parent.inverse() * global[j]).normalize());
        }
    }
    out
}

/// `take` with each twisting joint's rotation mixed with `truth`'s (frame
/// `f` of the take is the truth's `f + shift`).
fn mixed(take: &Motion, truth: &Motion, shift: isize, mix: Mix) -> Motion {
    let axes = bone_axes(take);
    let mut out = take.clone();
    for f in 0..take.frame_count() {
        let g = (f as isize + shift).clamp(0, truth.frame_count() as isize - 1) as usize;
        for (j, axis) in axes.iter().enumerate() {
            let leaf = take.skeleton().children(j).next().is_none();
            let Some(axis) = *axis else {
                if matches!(mix, Mix::TruthBranches) && !leaf
                    || matches!(mix, Mix::TruthEnds) && leaf
                {
                    out.set_local_rotation(f, j, truth.local_rotation(g, j));
                }
                continue;
            };
            if matches!(mix, Mix::TruthBranches | Mix::TruthEnds) {
                continue;
            }
            let (swing, twist) = swing_twist(take.local_rotation(f, j), axis);
            let (truth_swing, truth_twist) = swing_twist(truth.local_rotation(g, j), axis);
            let q = match mix {
                Mix::TruthTwist => swing * truth_twist,
                Mix::TruthSwing => truth_swing * twist,
                Mix::NoTwist | Mix::TruthBranches | Mix::TruthEnds => swing,
            };
            out.set_local_rotation(f, j, q.normalize());
        }
    }
    out
}

/// Mean over frames and twisting joints of the angle (degrees) between the
/// take's and the truth's twists, and between their swings.
fn twist_and_swing_error(take: &Motion, truth: &Motion, shift: isize) -> (f32, f32) {
    let axes = bone_axes(take);
    let (mut twist_sum, mut swing_sum, mut n) = (0.0f64, 0.0f64, 0usize);
    for f in 0..take.frame_count() {
        let g = f as isize + shift;
        if g < 0 || g >= truth.frame_count() as isize {
            continue;
        }
        for (j, axis) in axes.iter().enumerate() {
            let Some(axis) = *axis else { continue };
            let (s, t) = swing_twist(take.local_rotation(f, j), axis);
            let (ts, tt) = swing_twist(truth.local_rotation(g as usize, j), axis);
            twist_sum += t.angle_between(tt) as f64;
            swing_sum += s.angle_between(ts) as f64;
            n += 1;
        }
    }
    let n = n.max(1) as f64;
    (
        (twist_sum / n).to_degrees() as f32,
        (swing_sum / n).to_degrees() as f32,
    )
}

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 3 || !(args.len() - 1).is_multiple_of(2) {
        return Err("MODEL TAKE.bvh TRUTH.bvh [TAKE TRUTH]...".into());
    }
    let model = load_model(Some(args[0].as_ref()), Default::default())?;
    println!("| take | twist error (deg) | swing error (deg) | truth | take | take, the truth's twists | take, the truth's swings | take, no twist | truth, no twist | take, the truth's branching joints | take's bones, the truth's twists in the world | take, the truth's end joints | both |");
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for pair in args[1..].chunks(2) {
        let (take, truth) = (read_bvh(pair[0].as_ref())?, read_bvh(pair[1].as_ref())?);
        if take.skeleton().joint_count() != truth.skeleton().joint_count() {
            return Err(format!("{} and {} are not on one rig", pair[0], pair[1]).into());
        }
        let shift = frame_shift(&forward_kinematics(&take), &forward_kinematics(&truth));
        let (twist, swing) = twist_and_swing_error(&take, &truth, shift);
        let reconstruct = |m: &Motion| source_reconstruction_deg(&model, m);
        println!(
            "| {} | {twist:.1} | {swing:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} |",
            pair[0],
            reconstruct(&truth)?,
            reconstruct(&take)?,
            reconstruct(&mixed(&take, &truth, shift, Mix::TruthTwist))?,
            reconstruct(&mixed(&take, &truth, shift, Mix::TruthSwing))?,
            reconstruct(&mixed(&take, &truth, shift, Mix::NoTwist))?,
            reconstruct(&mixed(&truth, &truth, 0, Mix::NoTwist))?,
            reconstruct(&mixed(&take, &truth, shift, Mix::TruthBranches))?,
            reconstruct(&truth_twist_in_world(&take, &truth, shift))?,
            reconstruct(&with_truth_ends(&take, &truth, shift))?,
            reconstruct(&with_truth_ends(&truth_twist_in_world(&take, &truth, shift), &truth, shift))?,
        );
    }
    Ok(())
}
