//! How well retargeting keeps real takes: every Bandai take of a folder
//! played by other rigs (their BVH files give the hierarchy and offsets) and
//! back. Per rig: the largest angle between a limb bone of the take and the
//! same bone on the other rig, the error of every joint after the round
//! trip (the pelvis and the joints below it) and of the local rotations
//! (what a model of the rig reads), and the time per frame. Writes markdown to stdout.
//!
//! cargo run --release -p mocap-core --example retarget_check -- DATA_FOLDER RIG.bvh...
//!
//! With `--plausibility REFERENCE.bvh CLIP.bvh...`: clips of other rigs
//! played by the reference's rig (reference poses: both canonical T-poses,
//! both first frames, and both rest poses), and for each clip the mean angle between every joint's
//! local rotation and the reference's mean local rotation of that joint;
//! clips of the reference's own rig are measured as they are, for scale.

use std::path::{Path, PathBuf};
use std::time::Instant;

use mocap_core::bodymap::{BodyMap, BodyPart};
use mocap_core::io::bvh::read_bvh;
use mocap_core::io::find_bvh_files;
use mocap_core::metrics::largest_bone_angle_degrees;
use mocap_core::retarget::Retargeting;
use mocap_core::rotation::{angle_between, mean_of_close, Quat};
use mocap_core::{forward_kinematics, Motion};

/// A retargeting with the first frames of `source` and `target` as the
/// reference poses.
fn by_references(source: &Motion, target: &Motion) -> mocap_core::Result<Retargeting> {
    Retargeting::with_reference_poses(
        source,
        &BodyMap::detect(source.skeleton())?,
        target,
        &BodyMap::detect(target.skeleton())?,
    )
}

/// See the module docs (`--plausibility`).
fn plausibility(reference: &Path, clips: &[PathBuf]) -> Result<(), Box<dyn std::error::Error>> {
    let reference = read_bvh(reference)?;
    let skeleton = reference.skeleton();
    let joints: Vec<usize> = (0..skeleton.joint_count())
        .filter(|&j| {
            skeleton.joint(j).has_rotation_channels() && skeleton.joint(j).parent.is_some()
        })
        .collect();
    let means: Vec<Quat> = joints
        .iter()
        .map(|&j| {
            mean_of_close((0..reference.frame_count()).map(|f| reference.local_rotation(f, j)))
        })
        .collect();
    let rest = |m: &Motion| Motion::rest(m.skeleton().clone(), m.frame_time(), 1);
    println!("| clip | reference poses | mean angle to the reference's mean local rotations (deg) | largest joint's (deg) |");
    println!("| --- | --- | ---: | ---: |");
    for path in clips {
        let clip = read_bvh(path)?;
        // The same joint names and hierarchy (bone lengths may differ).
        let own = clip.skeleton().joint_count() == skeleton.joint_count()
            && clip
                .skeleton()
                .joints()
                .iter()
                .zip(skeleton.joints())
                .all(|(a, b)| a.name == b.name && a.parent == b.parent);
        let versions: Vec<(&str, Motion)> = if own {
            vec![
                ("(same rig, as captured)", clip.clone()),
                (
                    "canonical poses",
                    Retargeting::detect(clip.skeleton(), reference.skeleton())?.apply(&clip)?,
                ),
            ]
        } else {
            vec![
                (
                    "canonical poses",
                    Retargeting::detect(clip.skeleton(), reference.skeleton())?.apply(&clip)?,
                ),
                (
                    "first frames",
                    by_references(&clip, &reference)?.apply(&clip)?,
                ),
                (
                    "rest poses",
                    by_references(&rest(&clip)?, &rest(&reference)?)?.apply(&clip)?,
                ),
            ]
        };
        for (how, motion) in versions {
            let angles: Vec<(f32, usize)> = joints
                .iter()
                .zip(&means)
                .map(|(&j, &mean)| {
                    let sum: f32 = (0..motion.frame_count())
                        .map(|f| angle_between(mean, motion.local_rotation(f, j)).to_degrees())
                        .sum();
                    (sum / motion.frame_count() as f32, j)
                })
                .collect();
            let mean = angles.iter().map(|a| a.0).sum::<f32>() / angles.len() as f32;
            let worst = angles
                .iter()
                .fold((0.0f32, 0), |a, &b| if b.0 > a.0 { b } else { a });
            println!(
                "| {} | {how} | {mean:.1} | {:.0}, {} |",
                path.file_name().unwrap().to_string_lossy(),
                worst.0,
                skeleton.joint(worst.1).name
            );
        }
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if args
        .first()
        .is_some_and(|a| a.as_os_str() == "--plausibility")
    {
        let (reference, clips) = args[1..]
            .split_first()
            .ok_or("--plausibility REFERENCE.bvh CLIP.bvh... needed")?;
        return plausibility(reference, clips);
    }
    let (data, rigs) = args.split_first().ok_or("DATA_FOLDER RIG.bvh... needed")?;
    let files = find_bvh_files(std::slice::from_ref(data))?;
    let takes: Vec<Motion> = files
        .iter()
        .map(|f| read_bvh(f))
        .collect::<Result<_, _>>()?;
    let frames: usize = takes.iter().map(Motion::frame_count).sum();
    println!(
        "{} takes, {frames} frames, from {}\n",
        takes.len(),
        data.display()
    );
    println!("| rig | joints | scale | worst limb bone angle there (deg) | round trip: mean joint error (cm) | worst (cm), joint | round trip: mean local rotation error (deg) | worst joint's (deg) | ms per 1000 frames there and back |");
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for rig in rigs {
        let other = read_bvh(rig)?;
        let (mut angle, mut sum, mut count, mut worst, mut seconds) =
            (0.0f32, 0.0f64, 0usize, (0.0f32, String::new()), 0.0f64);
        let mut scale = 0.0;
        // Local rotations (what a model of the rig reads): per joint, summed
        // over takes weighted by frames.
        let mut rotation_sums: Vec<f64> = Vec::new();
        for take in &takes {
            let t = Instant::now();
            let there = Retargeting::detect(take.skeleton(), other.skeleton())?;
            let back = Retargeting::detect(other.skeleton(), take.skeleton())?;
            let moved = there.apply(take)?;
            let returned = back.apply(&moved)?;
            seconds += t.elapsed().as_secs_f64();
            scale = there.scale();
            angle = angle.max(largest_bone_angle_degrees(take, &moved)?);
            let per_joint = mocap_core::metrics::joint_rotation_errors_degrees(take, &returned)?;
            rotation_sums.resize(per_joint.len(), 0.0);
            for (sum, e) in rotation_sums.iter_mut().zip(&per_joint) {
                *sum += *e as f64 * take.frame_count() as f64;
            }
            let (a, b) = (forward_kinematics(take), forward_kinematics(&returned));
            // The body: the pelvis and below (a helper root above it, as
            // Bandai's `joint_Root`, is placed differently and shows nothing).
            let pelvis = BodyMap::detect(take.skeleton())?.require(BodyPart::Pelvis)?;
            let body = take.skeleton().subtree(pelvis);
            for f in 0..take.frame_count() {
                for &j in &body {
                    let d = a.position(f, j).distance(b.position(f, j));
                    sum += d as f64;
                    count += 1;
                    if d > worst.0 {
                        worst = (d, take.skeleton().joint(j).name.clone());
                    }
                }
            }
        }
        let skeleton = takes[0].skeleton();
        let rotating: Vec<usize> = (0..rotation_sums.len())
            .filter(|&j| skeleton.joint(j).has_rotation_channels())
            .collect();
        let (worst_rotation, worst_joint) = rotating
            .iter()
            .map(|&j| (rotation_sums[j] / frames as f64, j))
            .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a });
        let mean_rotation = rotating.iter().map(|&j| rotation_sums[j]).sum::<f64>()
            / (frames * rotating.len()) as f64;
        println!(
            "| {} | {} | {scale:.3} | {angle:.3} | {:.3} | {:.2}, {} | {mean_rotation:.3} | {worst_rotation:.2}, {} | {:.1} |",
            rig.file_name().unwrap().to_string_lossy(),
            other.skeleton().joint_count(),
            sum / count as f64,
            worst.0,
            worst.1,
            skeleton.joint(worst_joint).name,
            1000.0 * seconds * 1000.0 / frames as f64
        );
    }
    Ok(())
}
