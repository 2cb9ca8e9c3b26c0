//! Body parts found without a rig file on every rig of the given folders
//! (`bench/body-parts.sh` writes `bench/results/body-parts.md`).
//!
//!     body_parts_report DIR...
//!
//! Every BVH file under each folder (subfolders included) is read; one row
//! per folder that holds files: the rig and how its parts were found, the
//! parts found, the same skeleton with its joints renamed `joint_0..N`
//! (found by shape? the same joints as by name?), and, on the motion, in
//! how many frames the left hip and shoulder are on the body's left (up,
//! pelvis to head, × forward, where the feet point).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use mocap_core::bodymap::{BodyMap, BodyPart};
use mocap_core::io::bvh::read_bvh;
use mocap_core::kinematics::end_site_positions;
use mocap_core::rotation::Vec3;
use mocap_core::{forward_kinematics, Joint, Motion, Skeleton};

fn bvh_tree(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            bvh_tree(&path, out);
        } else if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("bvh"))
        {
            out.push(path);
        }
    }
}

fn scrambled(s: &Skeleton) -> Skeleton {
    let joints = s
        .joints()
        .iter()
        .enumerate()
        .map(|(i, j)| Joint {
            name: format!("joint_{i}"),
            ..j.clone()
        })
        .collect();
    Skeleton::new(joints).unwrap()
}

/// Frames checked and, of them, those with the left hip and the left
/// shoulder on the body's left.
fn left_on_left(m: &Motion, map: &BodyMap) -> (usize, usize, usize) {
    use BodyPart::*;
    let p = forward_kinematics(m);
    let j = |part: BodyPart| map.joint(part).unwrap();
    let (mut frames, mut hips, mut shoulders) = (0, 0, 0);
    for f in 0..m.frame_count() {
        let at = |part: BodyPart| p.position(f, j(part));
        let up = (at(Head) - at(Pelvis)).normalize();
        let ends = end_site_positions(m, &p, f);
        let mut forward = Vec3::ZERO;
        for (toe, ankle) in [(LeftToe, LeftAnkle), (RightToe, RightAnkle)] {
            let tip = match map.joint(toe) {
                Some(t) => p.position(f, t),
                None => {
                    let below = m.skeleton().subtree(j(ankle));
                    ends.iter()
                        .filter(|(k, _)| below.contains(k))
                        .map(|&(_, e)| e)
                        .max_by(|a, b| a.distance(at(ankle)).total_cmp(&b.distance(at(ankle))))
                        .unwrap_or(at(ankle))
                }
            };
            let foot = tip - at(ankle);
            forward += foot - up * foot.dot(up);
        }
        let left = up.cross(forward.normalize_or_zero());
        frames += 1;
        hips += usize::from((at(LeftHip) - at(RightHip)).dot(left) > 0.0);
        shoulders += usize::from((at(LeftShoulder) - at(RightShoulder)).dot(left) > 0.0);
    }
    (frames, hips, shoulders)
}

#[derive(Default)]
struct Row {
    clips: usize,
    joints: Vec<usize>,
    rigs: BTreeMap<String, usize>,
    parts: Vec<usize>,
    refused: Vec<String>,
    by_shape: usize,
    same_joints: Vec<usize>,
    frames: usize,
    hips_left: usize,
    shoulders_left: usize,
}

fn range(values: &[usize]) -> String {
    match (values.iter().min(), values.iter().max()) {
        (Some(lo), Some(hi)) if lo == hi => lo.to_string(),
        (Some(lo), Some(hi)) => format!("{lo}-{hi}"),
        _ => "-".into(),
    }
}

fn main() {
    let dirs: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    assert!(!dirs.is_empty(), "usage: body_parts_report DIR...");
    let mut rows: BTreeMap<String, Row> = BTreeMap::new();
    for dir in &dirs {
        let mut files = Vec::new();
        bvh_tree(dir, &mut files);
        for path in files {
            let folder = path.parent().unwrap();
            // CMU-Daz subjects (NN/) are one rig.
            let folder = match folder.parent() {
                Some(up) if up.ends_with("cmu-daz") => up,
                _ => folder,
            };
            let key = folder
                .strip_prefix(dir.parent().unwrap_or(dir))
                .unwrap_or(folder)
                .display()
                .to_string();
            let row = rows.entry(key).or_default();
            let m = read_bvh(&path).unwrap_or_else(|e| panic!("{e}"));
            row.clips += 1;
            row.joints.push(m.skeleton().joint_count());
            let map = match BodyMap::detect(m.skeleton()) {
                Ok(map) => map,
                Err(e) => {
                    let what = e.to_string();
                    let first = what.split(". ").next().unwrap_or(&what).to_string();
                    row.refused.push(format!(
                        "{}: {}",
                        path.file_name().unwrap().to_string_lossy(),
                        first.split(": ").last().unwrap_or(&first)
                    ));
                    continue;
                }
            };
            *row.rigs
                .entry(format!("{} ({})", map.rig(), map.found_by()))
                .or_default() += 1;
            row.parts.push(map.parts().count());
            if let Ok(shape) = BodyMap::detect(&scrambled(m.skeleton())) {
                row.by_shape += 1;
                row.same_joints.push(
                    BodyPart::ALL
                        .iter()
                        .filter(|&&p| map.joint(p).is_some() && shape.joint(p) == map.joint(p))
                        .count(),
                );
            }
            let (frames, hips, shoulders) = left_on_left(&m, &map);
            row.frames += frames;
            row.hips_left += hips;
            row.shoulders_left += shoulders;
        }
    }
    println!("| folder | clips | joints | rig (how found) | parts found | renamed `joint_0..N`: found by shape | of the parts by name, same joint by shape | frames with left hip / left shoulder on the body's left | refused |");
    println!("| --- | ---: | ---: | --- | ---: | ---: | ---: | ---: | --- |");
    for (folder, row) in &rows {
        let rigs: Vec<String> = row
            .rigs
            .iter()
            .map(|(rig, n)| {
                if *n == row.clips {
                    rig.clone()
                } else {
                    format!("{rig}: {n}")
                }
            })
            .collect();
        let pct = |n: usize| 100.0 * n as f64 / row.frames.max(1) as f64;
        println!(
            "| {folder} | {} | {} | {} | {} | {} of {} | {} | {:.1}% / {:.1}% of {} | {} |",
            row.clips,
            range(&row.joints),
            rigs.join("; "),
            range(&row.parts),
            row.by_shape,
            row.clips - row.refused.len(),
            range(&row.same_joints),
            pct(row.hips_left),
            pct(row.shoulders_left),
            row.frames,
            if row.refused.is_empty() {
                "-".to_string()
            } else {
                row.refused.join("; ")
            }
        );
    }
}
