//! How well retargeting keeps real takes: every Bandai take of a folder
//! played by other rigs (their BVH files give the hierarchy and offsets) and
//! back. Per rig: the largest angle between a limb bone of the take and the
//! same bone on the other rig, the error of every joint after the round
//! trip (the pelvis and the joints below it), and the time per frame. Writes markdown to stdout.
//!
//! cargo run --release -p mocap-core --example retarget_check -- DATA_FOLDER RIG.bvh...

use std::path::PathBuf;
use std::time::Instant;

use mocap_core::bodymap::{BodyMap, BodyPart};
use mocap_core::io::bvh::read_bvh;
use mocap_core::io::find_bvh_files;
use mocap_core::retarget::Retargeting;
use mocap_core::{forward_kinematics, Motion};

const LIMBS: [(BodyPart, BodyPart); 10] = [
    (BodyPart::LeftShoulder, BodyPart::LeftElbow),
    (BodyPart::LeftElbow, BodyPart::LeftWrist),
    (BodyPart::RightShoulder, BodyPart::RightElbow),
    (BodyPart::RightElbow, BodyPart::RightWrist),
    (BodyPart::LeftHip, BodyPart::LeftKnee),
    (BodyPart::LeftKnee, BodyPart::LeftAnkle),
    (BodyPart::RightHip, BodyPart::RightKnee),
    (BodyPart::RightKnee, BodyPart::RightAnkle),
    (BodyPart::LeftAnkle, BodyPart::LeftToe),
    (BodyPart::RightAnkle, BodyPart::RightToe),
];

fn worst_limb_angle(a: &Motion, b: &Motion) -> f32 {
    let (ma, mb) = (
        BodyMap::detect(a.skeleton()).unwrap(),
        BodyMap::detect(b.skeleton()).unwrap(),
    );
    let (pa, pb) = (forward_kinematics(a), forward_kinematics(b));
    let mut worst = 0.0f32;
    for f in 0..a.frame_count() {
        for (u, l) in LIMBS {
            let (Some(ua), Some(la), Some(ub), Some(lb)) =
                (ma.joint(u), ma.joint(l), mb.joint(u), mb.joint(l))
            else {
                continue;
            };
            let da = (pa.position(f, la) - pa.position(f, ua)).normalize();
            let db = (pb.position(f, lb) - pb.position(f, ub)).normalize();
            worst = worst.max(da.angle_between(db).to_degrees());
        }
    }
    worst
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
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
    println!("| rig | joints | scale | worst limb bone angle there (deg) | round trip: mean joint error (cm) | worst (cm), joint | ms per 1000 frames there and back |");
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: |");
    for rig in rigs {
        let other = read_bvh(rig)?;
        let (mut angle, mut sum, mut count, mut worst, mut seconds) =
            (0.0f32, 0.0f64, 0usize, (0.0f32, String::new()), 0.0f64);
        let mut scale = 0.0;
        for take in &takes {
            let t = Instant::now();
            let there = Retargeting::detect(take.skeleton(), other.skeleton())?;
            let back = Retargeting::detect(other.skeleton(), take.skeleton())?;
            let moved = there.apply(take)?;
            let returned = back.apply(&moved)?;
            seconds += t.elapsed().as_secs_f64();
            scale = there.scale();
            angle = angle.max(worst_limb_angle(take, &moved));
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
        println!(
            "| {} | {} | {scale:.3} | {angle:.3} | {:.3} | {:.2}, {} | {:.1} |",
            rig.file_name().unwrap().to_string_lossy(),
            other.skeleton().joint_count(),
            sum / count as f64,
            worst.0,
            worst.1,
            1000.0 * seconds * 1000.0 / frames as f64
        );
    }
    Ok(())
}
