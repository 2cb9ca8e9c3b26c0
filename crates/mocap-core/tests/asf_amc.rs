//! Tests of the ASF/AMC reader.
//!
//! The pose checks recompute global positions *independently* of the
//! reader: a few lines of text scanning read the ASF bones and one AMC frame,
//! and plain 3x3 matrices in double precision apply the ASF/AMC definitions
//! (`G_bone = G_parent C M C^-1`, `end = start + G_bone direction length`,
//! see the module documentation of `mocap_core::io::asf_amc`). The converted
//! `Motion` must give the same positions through `forward_kinematics`.

use mocap_testdata::shared_data;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use mocap_core::io::asf_amc::*;
use mocap_core::io::bvh::{read_bvh_from, write_bvh_to};
use mocap_core::kinematics::end_site_positions;
use mocap_core::rotation::{quat_to_euler, AngleUnit, EulerOrder, Quat, Vec3};
use mocap_core::skeleton::Channel;
use mocap_core::{forward_kinematics, Error, Motion};

// ---------------------------------------------------------------------------
// Data

fn hdm05() -> Option<(PathBuf, PathBuf)> {
    let dir = shared_data()?.join("hdm05-sample");
    Some((
        dir.join("HDM_bd.asf"),
        dir.join("HDM_bd_depositFloorR_001_120.amc"),
    ))
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/asf")
        .join(name)
}

fn read_text(path: &Path) -> String {
    String::from_utf8_lossy(&std::fs::read(path).unwrap()).into_owned()
}

// ---------------------------------------------------------------------------
// Independent ASF/AMC forward kinematics (f64, plain matrices)

type M3 = [[f64; 3]; 3];
type V3 = [f64; 3];

const IDENTITY: M3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// Rotation by `degrees` about axis `x`, `y` or `z` (column vectors).
fn rot(axis: char, degrees: f64) -> M3 {
    let (s, c) = degrees.to_radians().sin_cos();
    match axis {
        'x' => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        'y' => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        'z' => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
        _ => panic!("axis {axis}"),
    }
}

fn mul(a: M3, b: M3) -> M3 {
    let mut m = [[0.0; 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

fn transpose(a: M3) -> M3 {
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = a[j][i];
        }
    }
    m
}

fn apply(m: M3, v: V3) -> V3 {
    [0, 1, 2].map(|i| (0..3).map(|k| m[i][k] * v[k]).sum())
}

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn axis_index(c: char) -> usize {
    match c {
        'x' => 0,
        'y' => 1,
        'z' => 2,
        _ => panic!("axis {c}"),
    }
}

/// An ASF bone read by plain text scanning.
#[derive(Default, Debug)]
struct TestBone {
    direction: V3,
    length: f64,
    axis: V3,
    axis_order: String,
    dofs: Vec<String>,
    children: Vec<String>,
}

/// Bones by name, the root's children and the `:units length` scale.
fn scan_asf(text: &str) -> (HashMap<String, TestBone>, Vec<String>, f64) {
    let mut bones = HashMap::new();
    let mut root_children = Vec::new();
    let mut length_scale = 1.0;
    let mut section = String::new();
    let mut current: Option<(String, TestBone)> = None;
    let nums = |w: &[&str]| -> V3 { [0, 1, 2].map(|i| w[i].parse::<f64>().unwrap()) };
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.is_empty() || w[0].starts_with('#') {
            continue;
        }
        if w[0].starts_with(':') {
            section = w[0].to_string();
            continue;
        }
        match section.as_str() {
            ":units" if w[0] == "length" => length_scale = w[1].parse().unwrap(),
            ":bonedata" => match w[0] {
                "begin" => current = Some((String::new(), TestBone::default())),
                "end" => {
                    let (name, bone) = current.take().unwrap();
                    bones.insert(name, bone);
                }
                "name" => current.as_mut().unwrap().0 = w[1].to_string(),
                "direction" => current.as_mut().unwrap().1.direction = nums(&w[1..]),
                "length" => current.as_mut().unwrap().1.length = w[1].parse().unwrap(),
                "axis" => {
                    let b = &mut current.as_mut().unwrap().1;
                    b.axis = nums(&w[1..]);
                    b.axis_order = w[4].to_lowercase();
                }
                "dof" => {
                    current.as_mut().unwrap().1.dofs =
                        w[1..].iter().map(|s| s.to_string()).collect()
                }
                _ => {}
            },
            ":hierarchy" if w[0] != "begin" && w[0] != "end" => {
                let children: Vec<String> = w[1..].iter().map(|s| s.to_string()).collect();
                if w[0] == "root" {
                    root_children.extend(children);
                } else {
                    bones.get_mut(w[0]).unwrap().children.extend(children);
                }
            }
            _ => {}
        }
    }
    (bones, root_children, length_scale)
}

/// The values of one AMC frame by segment name.
fn scan_amc_frame(text: &str, frame_number: u32) -> HashMap<String, Vec<f64>> {
    let mut values = HashMap::new();
    let mut inside = false;
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.is_empty() || w[0].starts_with('#') || w[0].starts_with(':') {
            continue;
        }
        if w.len() == 1 && w[0].parse::<u32>().is_ok() {
            if inside {
                break;
            }
            inside = w[0].parse::<u32>().unwrap() == frame_number;
            continue;
        }
        if inside {
            let v = w[1..].iter().map(|s| s.parse::<f64>().unwrap()).collect();
            values.insert(w[0].to_string(), v);
        }
    }
    assert!(!values.is_empty(), "frame {frame_number} not found");
    values
}

/// Start and end of every bone (and the root position under "root") in
/// file units, from the ASF/AMC definitions. Expects the root order
/// `TX TY TZ RX RY RZ` with zero preset position and orientation.
fn expected_pose(asf: &str, frame: &HashMap<String, Vec<f64>>) -> HashMap<String, (V3, V3)> {
    assert!(asf.contains("order TX TY TZ RX RY RZ"));
    let (bones, root_children, _) = scan_asf(asf);
    let r = &frame["root"];
    // Root rotations about fixed axes, x first: M = Rz Ry Rx.
    let root_rotation = mul(rot('z', r[5]), mul(rot('y', r[4]), rot('x', r[3])));
    let root_position = [r[0], r[1], r[2]];
    let mut out = HashMap::new();
    out.insert("root".to_string(), (root_position, root_position));
    let mut stack: Vec<(String, M3, V3)> = root_children
        .iter()
        .map(|c| (c.clone(), root_rotation, root_position))
        .collect();
    while let Some((name, parent_rotation, parent_end)) = stack.pop() {
        let b = &bones[&name];
        // C from the axis angles, applied in the given order about fixed axes.
        let mut c = IDENTITY;
        for a in b.axis_order.chars() {
            c = mul(rot(a, b.axis[axis_index(a)]), c);
        }
        // M from the dof values in dof order; translations along C's axes.
        let mut m = IDENTITY;
        let mut t = [0.0; 3];
        let values = frame.get(&name).cloned().unwrap_or_default();
        for (dof, v) in b.dofs.iter().zip(values) {
            let axis = dof.chars().nth(1).unwrap();
            if dof.starts_with('r') {
                m = mul(rot(axis, v), m);
            } else {
                t[axis_index(axis)] = v;
            }
        }
        let start = add(parent_end, apply(mul(parent_rotation, c), t));
        let global = mul(parent_rotation, mul(c, mul(m, transpose(c))));
        let end = add(start, apply(global, b.direction.map(|d| d * b.length)));
        out.insert(name.clone(), (start, end));
        for child in &b.children {
            stack.push((child.clone(), global, end));
        }
    }
    out
}

/// Largest distance between the reader's FK and the independent positions
/// in `frame` (1-based AMC frame number), over every joint and leaf end.
fn max_pose_error(
    motion: &Motion,
    asf_text: &str,
    amc_text: &str,
    frame_number: u32,
    to_output: f64,
) -> f64 {
    let expected = expected_pose(asf_text, &scan_amc_frame(amc_text, frame_number));
    let poses = forward_kinematics(motion);
    let f = frame_number as usize - 1;
    let ends: HashMap<usize, Vec3> = end_site_positions(motion, &poses, f).into_iter().collect();
    let skeleton = motion.skeleton();
    let distance = |got: Vec3, want: V3| {
        let want = want.map(|w| w * to_output);
        ((got.x as f64 - want[0]).powi(2)
            + (got.y as f64 - want[1]).powi(2)
            + (got.z as f64 - want[2]).powi(2))
        .sqrt()
    };
    let mut worst = 0.0f64;
    assert_eq!(expected.len(), skeleton.joint_count());
    for (name, &(start, end)) in &expected {
        let j = skeleton
            .find(name)
            .unwrap_or_else(|| panic!("no joint {name}"));
        worst = worst.max(distance(poses.position(f, j), start));
        if let Some(&got_end) = ends.get(&j) {
            worst = worst.max(distance(got_end, end));
        }
    }
    worst
}

// ---------------------------------------------------------------------------
// HDM05 sample

#[test]
fn hdm05_skeleton_is_read_as_written() {
    let Some((asf_path, _)) = hdm05() else { return };
    let asf = read_asf(&asf_path).unwrap();
    assert_eq!(asf.units.length, 0.45);
    assert_eq!(asf.units.angle, AngleUnit::Degrees);
    assert_eq!(asf.name.as_deref(), Some("VICON"));
    assert_eq!(
        asf.root.order,
        vec![Dof::Tx, Dof::Ty, Dof::Tz, Dof::Rx, Dof::Ry, Dof::Rz]
    );
    let text = read_text(&asf_path);
    let (bones, root_children, _) = scan_asf(&text);
    assert_eq!(asf.bones.len(), bones.len());
    let names = |list: &[usize]| -> Vec<String> {
        list.iter().map(|&b| asf.bones[b].name.clone()).collect()
    };
    assert_eq!(names(&asf.root_children), root_children);
    for bone in &asf.bones {
        let want = &bones[&bone.name];
        assert_eq!(
            bone.length as f64, want.length as f32 as f64,
            "{}",
            bone.name
        );
        for i in 0..3 {
            assert_eq!(bone.direction[i], want.direction[i] as f32, "{}", bone.name);
            assert_eq!(bone.axis[i], want.axis[i] as f32, "{}", bone.name);
        }
        let dofs: Vec<String> = bone
            .dofs
            .iter()
            .map(|d| format!("{d:?}").to_lowercase())
            .collect();
        assert_eq!(dofs, want.dofs, "{}", bone.name);
        assert_eq!(names(&bone.children), want.children, "{}", bone.name);
        if !bone.dofs.is_empty() {
            assert_eq!(bone.limits.len(), bone.dofs.len(), "{}", bone.name);
        }
    }
    // `ltoes` has `axis -90 7.62852e-016 20 XYZ` and one limit.
    let ltoes = &asf.bones[asf.find_bone("ltoes").unwrap()];
    assert_eq!(ltoes.axis.y, 7.62852e-16);
    assert_eq!(ltoes.limits, vec![(-90.0, 20.0)]);
    // Parents come before children.
    let skeleton = asf.to_skeleton(LengthUnit::Centimetres).unwrap();
    assert_eq!(skeleton.joint_count(), bones.len() + 1);
    assert_eq!(skeleton.joint(0).name, "root");
}

#[test]
fn hdm05_motion_matches_the_asf_amc_definition() {
    let Some((asf_path, amc_path)) = hdm05() else {
        return;
    };
    let motion = read_asf_amc(&asf_path, &amc_path).unwrap();
    let asf_text = read_text(&asf_path);
    let amc_text = read_text(&amc_path);
    // Every line holding only a number starts a frame.
    let frames = amc_text
        .lines()
        .filter(|l| {
            let t = l.trim();
            !t.is_empty() && t.bytes().all(|c| c.is_ascii_digit())
        })
        .count();
    assert_eq!(motion.frame_count(), frames);
    assert!((motion.frame_time() - 1.0 / 120.0).abs() < 1e-12);
    let cm = 2.54 / 0.45;
    for frame_number in [1, frames as u32 / 2, frames as u32] {
        let error = max_pose_error(&motion, &asf_text, &amc_text, frame_number, cm);
        eprintln!("HDM05 frame {frame_number}: largest position difference {error:.2e} cm");
        assert!(error < 5e-3, "frame {frame_number}: {error} cm");
    }
}

#[test]
fn hdm05_root_channels_hold_the_file_values() {
    let Some((asf_path, amc_path)) = hdm05() else {
        return;
    };
    let motion = read_asf_amc(&asf_path, &amc_path).unwrap();
    let amc_text = read_text(&amc_path);
    let root = motion.skeleton().joint(0);
    assert_eq!(
        root.channels,
        vec![
            Channel::Xposition,
            Channel::Yposition,
            Channel::Zposition,
            Channel::Zrotation,
            Channel::Yrotation,
            Channel::Xrotation
        ]
    );
    let cm = 2.54 / 0.45;
    for frame_number in [1u32, 2, 100] {
        let r = &scan_amc_frame(&amc_text, frame_number)["root"];
        let got = motion.joint_values(frame_number as usize - 1, 0);
        let want = [r[0] * cm, r[1] * cm, r[2] * cm, r[5], r[4], r[3]];
        for (g, w) in got.iter().zip(want) {
            assert!(
                (*g as f64 - w).abs() < 1e-4 * w.abs().max(1.0),
                "{got:?} vs {want:?}"
            );
        }
    }
}

#[test]
fn hdm05_rotation_tracks_are_continuous() {
    let Some((asf_path, amc_path)) = hdm05() else {
        return;
    };
    let motion = read_asf_amc(&asf_path, &amc_path).unwrap();
    let skeleton = motion.skeleton();
    let mut worst = 0.0f32;
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let start = skeleton.channel_start(j);
        for (k, c) in joint.channels.iter().enumerate() {
            if !c.is_rotation() {
                continue;
            }
            for f in 1..motion.frame_count() {
                let step = (motion.frame(f)[start + k] - motion.frame(f - 1)[start + k]).abs();
                worst = worst.max(step);
                assert!(
                    step < 180.0,
                    "{} {}: {step} degrees at frame {f}",
                    joint.name,
                    c.name()
                );
            }
        }
    }
    eprintln!("largest rotation channel step between frames: {worst:.2} degrees");
}

#[test]
fn limits_hold_for_the_amc_angles_in_the_axis_frame() {
    let Some((asf_path, amc_path)) = hdm05() else {
        return;
    };
    let motion = read_asf_amc(&asf_path, &amc_path).unwrap();
    let amc_text = read_text(&amc_path);
    let j = motion.skeleton().find("lfemur").unwrap();
    let limits = motion.skeleton().joint(j).limits.clone().unwrap();
    // `dof rx ry rz` with limits (-160 20) (-70 70) (-60 70), listed in the
    // intrinsic decomposition order z, y, x.
    let channels: Vec<(Channel, f32, f32)> = limits
        .dofs
        .iter()
        .map(|d| (d.channel, d.min, d.max))
        .collect();
    assert_eq!(
        channels,
        vec![
            (Channel::Zrotation, -60.0, 70.0),
            (Channel::Yrotation, -70.0, 70.0),
            (Channel::Xrotation, -160.0, 20.0)
        ]
    );
    // The documented meaning: axis_frame^-1 q axis_frame, decomposed as
    // intrinsic Z Y X, gives back the AMC values.
    for frame_number in [1u32, 150, 300] {
        let want = &scan_amc_frame(&amc_text, frame_number)["lfemur"];
        let q = motion.local_rotation(frame_number as usize - 1, j);
        let m = limits.axis_frame.inverse() * q * limits.axis_frame;
        let zyx = quat_to_euler(EulerOrder::ZYX, m);
        let got = [zyx.z, zyx.y, zyx.x].map(|a| a.to_degrees() as f64);
        for i in 0..3 {
            assert!((got[i] - want[i]).abs() < 1e-3, "{got:?} vs {want:?}");
        }
    }
}

#[test]
fn hdm05_pose_is_physically_plausible() {
    // Independent of any matrix convention: with the lengths in centimetres
    // and Y up, the actor stands on the floor with the head at standing
    // height, and in this take reaches down to the floor.
    let Some((asf_path, amc_path)) = hdm05() else {
        return;
    };
    let motion = read_asf_amc(&asf_path, &amc_path).unwrap();
    let poses = forward_kinematics(&motion);
    let name = |j: usize| motion.skeleton().joint(j).name.as_str();
    let mut lowest_toe = f32::MAX;
    let mut lowest_hand = f32::MAX;
    for f in 0..motion.frame_count() {
        for (j, p) in end_site_positions(&motion, &poses, f) {
            match name(j) {
                "ltoes" | "rtoes" => lowest_toe = lowest_toe.min(p.y),
                "lfingers" | "rfingers" => lowest_hand = lowest_hand.min(p.y),
                _ => {}
            }
        }
    }
    let head = end_site_positions(&motion, &poses, 0)
        .into_iter()
        .find(|&(j, _)| name(j) == "head")
        .unwrap()
        .1;
    eprintln!(
        "lowest toe {lowest_toe:.1} cm, lowest hand {lowest_hand:.1} cm, head at frame 1 {:.1} cm",
        head.y
    );
    assert!((-5.0..10.0).contains(&lowest_toe), "{lowest_toe}");
    assert!((140.0..200.0).contains(&head.y), "{}", head.y);
    assert!(lowest_hand < 20.0, "{lowest_hand}");
}

#[test]
fn hdm05_written_as_bvh_plays_the_same() {
    let Some((asf_path, amc_path)) = hdm05() else {
        return;
    };
    let worst = bvh_round_trip_error(&read_asf_amc(&asf_path, &amc_path).unwrap());
    eprintln!("HDM05 through BVH: largest position difference {worst:.2e} cm");
    assert!(worst < 1e-3, "{worst} cm");
}

#[test]
fn fixture_written_as_bvh_plays_the_same() {
    // Position channels on a bone (translation dofs) and a joint without
    // channels go through BVH too.
    let motion = read_asf_amc(fixture("tiny.asf"), fixture("tiny.amc")).unwrap();
    let worst = bvh_round_trip_error(&motion);
    assert!(worst < 1e-3, "{worst} cm");
}

/// Largest distance between the joints and end sites of `motion` and of
/// `motion` written as BVH and read back.
fn bvh_round_trip_error(motion: &Motion) -> f32 {
    let mut bvh = Vec::new();
    write_bvh_to(&mut bvh, motion).unwrap();
    let back = read_bvh_from(bvh.as_slice(), Path::new("round-trip.bvh")).unwrap();
    assert_eq!(back.frame_count(), motion.frame_count());
    assert!((back.frame_time() - motion.frame_time()).abs() < 1e-9);
    let (a, b) = (forward_kinematics(motion), forward_kinematics(&back));
    let mut worst = 0.0f32;
    for f in 0..motion.frame_count() {
        for j in 0..a.joint_count {
            let j_back = back
                .skeleton()
                .find(&motion.skeleton().joint(j).name)
                .unwrap();
            worst = worst.max((a.position(f, j) - b.position(f, j_back)).length());
        }
        let ends_a = end_site_positions(motion, &a, f);
        let ends_b = end_site_positions(&back, &b, f);
        assert_eq!(ends_a.len(), ends_b.len());
        for ((_, p), (_, q)) in ends_a.iter().zip(&ends_b) {
            worst = worst.max((*p - *q).length());
        }
    }
    worst
}

// ---------------------------------------------------------------------------
// Hand-made fixture: axis orders, translation dofs, dofs out of order

#[test]
fn fixture_motion_matches_the_asf_amc_definition() {
    let motion = read_asf_amc(fixture("tiny.asf"), fixture("tiny.amc")).unwrap();
    assert_eq!(motion.frame_count(), 3);
    let asf_text = read_text(&fixture("tiny.asf"));
    let amc_text = read_text(&fixture("tiny.amc"));
    let cm = 2.54 / 0.5;
    for frame_number in 1..=3 {
        let error = max_pose_error(&motion, &asf_text, &amc_text, frame_number, cm);
        assert!(error < 1e-3, "frame {frame_number}: {error} cm");
    }
    let skeleton = motion.skeleton();
    // A bone without dofs has no channels; translation dofs give position
    // channels first.
    assert!(skeleton
        .joint(skeleton.find("hip").unwrap())
        .channels
        .is_empty());
    let arm = skeleton.joint(skeleton.find("arm").unwrap());
    assert_eq!(arm.channels.len(), 6);
    assert!(arm.channels[..3].iter().all(|c| c.is_position()));
    // Limits: translations first (scaled to cm), then rotations reversed.
    let limits = arm.limits.as_ref().unwrap();
    let channels: Vec<Channel> = limits.dofs.iter().map(|d| d.channel).collect();
    assert_eq!(
        channels,
        vec![
            Channel::Xposition,
            Channel::Yposition,
            Channel::Zposition,
            Channel::Xrotation,
            Channel::Zrotation
        ]
    );
    assert!((limits.dofs[0].max - cm as f32).abs() < 1e-5);
    let shin = skeleton.joint(skeleton.find("shin").unwrap());
    let shin_limits = &shin.limits.as_ref().unwrap().dofs;
    assert_eq!(shin_limits[0].channel, Channel::Zrotation);
    assert!(shin_limits[0].min == f32::NEG_INFINITY && shin_limits[0].max == f32::INFINITY);
}

#[test]
fn length_units_scale_every_position() {
    let asf = read_asf(fixture("tiny.asf")).unwrap();
    let read = |length_unit| {
        let options = AsfOptions {
            length_unit,
            frame_rate: 60.0,
        };
        read_amc_with(fixture("tiny.amc"), &asf, &options).unwrap()
    };
    let file = forward_kinematics(&read(LengthUnit::File));
    let cm = forward_kinematics(&read(LengthUnit::Centimetres));
    let m = forward_kinematics(&read(LengthUnit::Metres));
    assert!((read(LengthUnit::File).frame_time() - 1.0 / 60.0).abs() < 1e-12);
    for ((f, c), m) in file.positions.iter().zip(&cm.positions).zip(&m.positions) {
        assert!((*f * (2.54 / 0.5) - *c).length() < 1e-4);
        assert!((*c / 100.0 - *m).length() < 1e-6);
    }
}

#[test]
fn radians_read_the_same_as_degrees() {
    let asf = read_asf(fixture("tiny.asf")).unwrap();
    let degrees = read_amc(fixture("tiny.amc"), &asf).unwrap();
    // The same motion with every angle written in radians.
    let mut radians_text = String::from(":FULLY-SPECIFIED\n:RADIANS\n");
    for line in read_text(&fixture("tiny.amc")).lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        if w.is_empty() || w[0].starts_with('#') || w[0].starts_with(':') {
            continue;
        }
        if w.len() == 1 {
            radians_text += &format!("{}\n", w[0]);
            continue;
        }
        let translations = match w[0] {
            "root" => 3,
            "arm" => 3,
            _ => 0,
        };
        radians_text += w[0];
        for (k, v) in w[1..].iter().enumerate() {
            let v: f64 = v.parse().unwrap();
            let v = if k < translations { v } else { v.to_radians() };
            radians_text += &format!(" {v:e}");
        }
        radians_text += "\n";
    }
    let radians = parse_amc(
        radians_text.as_bytes(),
        Path::new("radians.amc"),
        &asf,
        &AsfOptions::default(),
    )
    .unwrap();
    let (a, b) = (forward_kinematics(&degrees), forward_kinematics(&radians));
    for (p, q) in a.positions.iter().zip(&b.positions) {
        assert!((*p - *q).length() < 1e-4, "{p} vs {q}");
    }
}

#[test]
fn root_orientation_turns_the_whole_body() {
    let text = read_text(&fixture("tiny.asf")).replace("orientation 0 0 0", "orientation 0 90 0");
    let turned = parse_asf(text.as_bytes(), Path::new("turned.asf")).unwrap();
    let plain = read_asf(fixture("tiny.asf")).unwrap();
    let amc = std::fs::read(fixture("tiny.amc")).unwrap();
    let options = AsfOptions::default();
    let a = parse_amc(&amc, Path::new("a.amc"), &plain, &options).unwrap();
    let b = parse_amc(&amc, Path::new("b.amc"), &turned, &options).unwrap();
    let (pa, pb) = (forward_kinematics(&a), forward_kinematics(&b));
    let turn = Quat::from_rotation_y(90f32.to_radians());
    for f in 0..a.frame_count() {
        let root = pa.position(f, 0);
        assert!((pa.position(f, 0) - pb.position(f, 0)).length() < 1e-5);
        for j in 1..pa.joint_count {
            let want = root + turn * (pa.position(f, j) - root);
            assert!((pb.position(f, j) - want).length() < 1e-3);
        }
    }
}

#[test]
fn mixed_line_endings_and_latin1_bytes_are_read() {
    let asf_text = read_text(&fixture("tiny.asf"));
    let amc_text = read_text(&fixture("tiny.amc"));
    // CRLF for every other line, a lone CR once, a Latin-1 byte in a comment.
    let mut asf_bytes = Vec::new();
    for (i, line) in asf_text.lines().enumerate() {
        asf_bytes.extend_from_slice(line.as_bytes());
        asf_bytes.extend_from_slice(if i % 2 == 0 { b"\r\n" } else { b"\n" });
    }
    let mut amc_bytes = b"#!OML:ASF X:\\f\xfcr Bonn\r\n".to_vec();
    for (i, line) in amc_text.lines().enumerate() {
        amc_bytes.extend_from_slice(line.as_bytes());
        amc_bytes.extend_from_slice(if i == 3 { b"\r" } else { b"\r\n" });
    }
    let asf = parse_asf(&asf_bytes, Path::new("mixed.asf")).unwrap();
    let mixed = parse_amc(
        &amc_bytes,
        Path::new("mixed.amc"),
        &asf,
        &AsfOptions::default(),
    )
    .unwrap();
    let plain = read_asf_amc(fixture("tiny.asf"), fixture("tiny.amc")).unwrap();
    assert_eq!(mixed.values(), plain.values());
}

// ---------------------------------------------------------------------------
// Errors: file, line, column and what was expected

/// Parses `asf` (and `amc` when given) and returns the parse error.
fn parse_error(asf: &str, amc: Option<&str>) -> (usize, usize, String) {
    let result = parse_asf(asf.as_bytes(), Path::new("bad.asf")).and_then(|skeleton| match amc {
        Some(amc) => parse_amc(
            amc.as_bytes(),
            Path::new("bad.amc"),
            &skeleton,
            &AsfOptions::default(),
        )
        .map(|_| ()),
        None => Ok(()),
    });
    match result {
        Err(Error::Parse(e)) => {
            let file = if amc.is_some() { "bad.amc" } else { "bad.asf" };
            assert_eq!(e.location.path, Path::new(file), "{e}");
            let shown = e.to_string();
            assert!(shown.starts_with(&format!(
                "{file}:{}:{}: ",
                e.location.line, e.location.column
            )));
            (e.location.line, e.location.column, e.message)
        }
        other => panic!("expected a parse error, got {other:?}"),
    }
}

fn tiny_asf() -> String {
    read_text(&fixture("tiny.asf"))
}

fn tiny_amc() -> String {
    read_text(&fixture("tiny.amc"))
}

/// 1-based line number of the first line containing `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

#[test]
fn error_unknown_bone_in_amc() {
    let amc = tiny_amc().replace("spine 20", "spline 20");
    let (line, column, message) = parse_error(&tiny_asf(), Some(&amc));
    assert_eq!((line, column), (line_of(&amc, "spline"), 1));
    assert!(message.contains("unknown bone `spline`"), "{message}");
}

#[test]
fn error_wrong_number_of_values() {
    let amc = tiny_amc().replace("thigh -35 20 45", "thigh -35 20");
    let (line, column, message) = parse_error(&tiny_asf(), Some(&amc));
    assert_eq!((line, column), (line_of(&amc, "thigh -35 20"), 13));
    assert!(
        message.contains("3 dofs (rx ry rz) but this line gives 2 values"),
        "{message}"
    );
    let amc = tiny_amc().replace("shin 95 -15", "shin 95 -15 7");
    let (_, column, message) = parse_error(&tiny_asf(), Some(&amc));
    assert_eq!(column, 13, "points at the first value too many");
    assert!(message.contains("gives 3 values"), "{message}");
}

#[test]
fn error_non_numeric_value() {
    let amc = tiny_amc().replace("shin 95 -15", "shin 95 1.#QNAN");
    let (line, column, message) = parse_error(&tiny_asf(), Some(&amc));
    assert_eq!((line, column), (line_of(&amc, "QNAN"), 9));
    assert!(
        message.contains("expected a number, found `1.#QNAN`"),
        "{message}"
    );
}

#[test]
fn error_frames_out_of_sequence() {
    let amc = tiny_amc().replace("\n3\n", "\n5\n");
    let (line, column, message) = parse_error(&tiny_asf(), Some(&amc));
    assert_eq!(
        (line, column),
        (amc.lines().position(|l| l == "5").unwrap() + 1, 1)
    );
    assert!(message.contains("expected 3, found 5"), "{message}");
}

#[test]
fn error_bone_missing_from_a_frame() {
    let amc = tiny_amc().replace("spine 20\n", "");
    let (line, _, message) = parse_error(&tiny_asf(), Some(&amc));
    assert_eq!(line, amc.lines().position(|l| l == "2").unwrap() + 1);
    assert!(
        message.contains("frame 2 has no line for `spine`"),
        "{message}"
    );
}

#[test]
fn error_values_before_the_first_frame_number() {
    let amc = tiny_amc().replace(":DEGREES\n1\n", ":DEGREES\n");
    let (line, _, message) = parse_error(&tiny_asf(), Some(&amc));
    assert_eq!(line, line_of(&amc, "root 1.5"));
    assert!(message.contains("expected a frame number"), "{message}");
}

#[test]
fn error_missing_bonedata() {
    let asf = tiny_asf();
    let cut = &asf[..asf.find(":bonedata").unwrap()];
    let (line, _, message) = parse_error(cut, None);
    assert_eq!(line, cut.lines().count());
    assert!(
        message.contains("expected a `:bonedata` section"),
        "{message}"
    );
}

#[test]
fn error_hierarchy_names_an_undefined_bone() {
    let asf = tiny_asf().replace("spine arm", "spine hand");
    let (line, column, message) = parse_error(&asf, None);
    assert_eq!((line, column), (line_of(&asf, "spine hand"), 11));
    assert!(
        message.contains("bone `hand` is used in :hierarchy but not defined"),
        "{message}"
    );
}

#[test]
fn error_bone_not_in_hierarchy() {
    let asf = tiny_asf().replace("    spine arm\n", "");
    let (line, _, message) = parse_error(&asf, None);
    assert_eq!(line, line_of(&asf, "name arm"));
    assert!(
        message.contains("`arm` is not connected to the root"),
        "{message}"
    );
}

#[test]
fn error_unknown_dof() {
    let asf = tiny_asf().replace("dof rx rz", "dof rx rw");
    let (line, column, message) = parse_error(&asf, None);
    assert_eq!((line, column), (line_of(&asf, "dof rx rw"), 12));
    assert!(message.contains("unknown dof `rw`"), "{message}");
}

#[test]
fn error_length_dof_is_refused() {
    let asf = tiny_asf().replace("dof ry\n", "dof ry l\n");
    let (line, _, message) = parse_error(&asf, None);
    assert_eq!(line, line_of(&asf, "dof ry l"));
    assert!(
        message.contains("dof `l`") && message.contains("not supported"),
        "{message}"
    );
}

#[test]
fn error_limits_do_not_match_dofs() {
    let asf = tiny_asf().replace("(-10 170) (-inf inf)", "(-10 170)");
    let (line, _, message) = parse_error(&asf, None);
    assert_eq!(line, line_of(&asf, "(-10 170)"));
    assert!(
        message.contains("`shin` has 2 dofs but 1 limits"),
        "{message}"
    );
}

#[test]
fn error_non_numeric_in_asf() {
    let asf = tiny_asf().replace("length 3\n", "length three\n");
    let (line, column, message) = parse_error(&asf, None);
    assert_eq!((line, column), (line_of(&asf, "length three"), 13));
    assert!(
        message.contains("expected a number, found `three`"),
        "{message}"
    );
}

#[test]
fn error_bone_block_without_end() {
    let asf = tiny_asf().replace("    dof ry\n  end\n", "    dof ry\n");
    let (_, _, message) = parse_error(&asf, None);
    assert!(
        message.contains("expected `end` of the bone block"),
        "{message}"
    );
}

#[test]
fn error_missing_file_is_an_io_error() {
    match read_asf("/nonexistent/skeleton.asf") {
        Err(Error::Io { path, .. }) => assert_eq!(path, Path::new("/nonexistent/skeleton.asf")),
        other => panic!("expected an I/O error, got {other:?}"),
    }
}

#[test]
fn an_amc_given_alone_takes_the_asf_beside_it() {
    use mocap_core::io::MotionSource;
    let Some(dir) = mocap_testdata::shared("hdm05-sample") else {
        return;
    };
    let amc = dir.join("HDM_bd_depositFloorR_001_120.amc");
    let sources = MotionSource::group(std::slice::from_ref(&amc)).unwrap();
    assert_eq!(
        sources,
        [MotionSource::AsfAmc {
            asf: dir.join("HDM_bd.asf"),
            amc: amc.clone(),
        }]
    );
    // Alone in a folder without an ASF: refused, saying what to give.
    let empty = tempfile::tempdir().unwrap();
    let lone = empty.path().join("HDM_bd_take.amc");
    std::fs::copy(&amc, &lone).unwrap();
    let err = MotionSource::group(&[lone]).unwrap_err().to_string();
    assert!(
        err.contains("no ASF skeleton file") && err.contains("HDM_bd_take.amc"),
        "{err}"
    );
}
