//! What goes through a whole take a piece at a time (forward kinematics for
//! the bounding box and the positions writers) gives the numbers of the
//! whole take at once; a BVH header tells a take's length without its frames.

use std::io::Write;

use mocap_core::info::MotionInfo;
use mocap_core::io::bvh::{read_bvh, read_bvh_header};
use mocap_core::io::positions::{write_positions_csv, write_positions_json};
use mocap_core::io::MotionSource;
use mocap_core::kinematics::{
    bounding_box, forward_kinematics_range, frame_pieces, FRAMES_AT_A_TIME,
};
use mocap_core::{forward_kinematics, Motion};

/// The sample walk played 7 times: 1,365 frames, two pieces.
fn long_walk() -> Motion {
    let walk = read_bvh(&mocap_testdata::sample_walk()).unwrap();
    let mut take = walk.clone();
    for _ in 1..7 {
        take.append(&walk).unwrap();
    }
    assert!(take.frame_count() > FRAMES_AT_A_TIME);
    take
}

#[test]
fn pieces_give_the_bits_of_the_whole_take() {
    let take = long_walk();
    let whole = forward_kinematics(&take);
    let mut positions = Vec::new();
    let mut rotations = Vec::new();
    for piece in frame_pieces(take.frame_count()) {
        let poses = forward_kinematics_range(&take, piece);
        positions.extend(poses.positions);
        rotations.extend(poses.rotations);
    }
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<u32>>();
    let flat = |p: &[mocap_core::rotation::Vec3]| {
        p.iter().flat_map(|v| v.to_array()).collect::<Vec<f32>>()
    };
    assert_eq!(bits(&flat(&positions)), bits(&flat(&whole.positions)));
    let flat_q = |q: &[mocap_core::rotation::Quat]| {
        q.iter().flat_map(|v| v.to_array()).collect::<Vec<f32>>()
    };
    assert_eq!(bits(&flat_q(&rotations)), bits(&flat_q(&whole.rotations)));
    assert_eq!(bounding_box(&take), whole.bounding_box());
    let info = MotionInfo::of("take", &take);
    let (lo, hi) = whole.bounding_box().unwrap();
    assert_eq!(info.bounding_box, Some([lo.to_array(), hi.to_array()]));
}

#[test]
fn positions_are_written_as_from_the_whole_take() {
    let take = long_walk();
    let poses = forward_kinematics(&take);
    // CSV rows as they were written from the poses of the whole take.
    let mut expected = Vec::new();
    write!(expected, "frame,time").unwrap();
    for joint in take.skeleton().joints() {
        let name = &joint.name;
        write!(expected, ",{name}.x,{name}.y,{name}.z").unwrap();
    }
    writeln!(expected).unwrap();
    for f in 0..take.frame_count() {
        write!(expected, "{f},{}", f as f64 * take.frame_time()).unwrap();
        for p in poses.frame_positions(f) {
            write!(expected, ",{},{},{}", p.x, p.y, p.z).unwrap();
        }
        writeln!(expected).unwrap();
    }
    let mut csv = Vec::new();
    write_positions_csv(&mut csv, &take).unwrap();
    assert!(csv == expected, "the CSV differs from the whole take's");
    // JSON: the positions part as written from the whole take's poses.
    let mut expected = Vec::new();
    for f in 0..take.frame_count() {
        write!(expected, "{}[", if f == 0 { "" } else { "," }).unwrap();
        for (j, p) in poses.frame_positions(f).iter().enumerate() {
            let sep = if j == 0 { "" } else { "," };
            write!(expected, "{sep}[{},{},{}]", p.x, p.y, p.z).unwrap();
        }
        write!(expected, "]").unwrap();
    }
    let mut json = Vec::new();
    write_positions_json(&mut json, &take).unwrap();
    let json = String::from_utf8(json).unwrap();
    let positions = json
        .split_once("\"positions\":[")
        .and_then(|(_, rest)| rest.strip_suffix("]}\n"))
        .expect("a positions array");
    assert!(
        positions.as_bytes() == expected,
        "the JSON differs from the whole take's"
    );
}

#[test]
fn a_header_tells_the_length_without_the_frames() {
    let walk = mocap_testdata::sample_walk();
    let (skeleton, frames, frame_time) = read_bvh_header(&walk).unwrap();
    let motion = read_bvh(&walk).unwrap();
    assert_eq!(&skeleton, motion.skeleton());
    assert_eq!(
        (frames, frame_time),
        (motion.frame_count(), motion.frame_time())
    );
    let source = MotionSource::Bvh(walk.clone());
    assert_eq!(
        source.announced_length().unwrap(),
        Some((frames, frame_time))
    );

    // A header announcing a billion frames, and none of them: the header is
    // read, the frames are not.
    let text = std::fs::read_to_string(&walk).unwrap();
    let header_end = text.find("Frame Time").unwrap();
    let line_end = header_end + text[header_end..].find('\n').unwrap() + 1;
    let header = text[..line_end].replace(&format!("Frames:\t{frames}"), "Frames:\t1000000000");
    assert!(
        header.contains("1000000000"),
        "the sample's `Frames:` line changed"
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.bvh");
    std::fs::write(&path, header).unwrap();
    let (_, frames, _) = read_bvh_header(&path).unwrap();
    assert_eq!(frames, 1_000_000_000);
    // Reading it is an error naming the file, not an allocation of 500 GB.
    let e = read_bvh(&path).unwrap_err().to_string();
    assert!(e.contains("huge.bvh"), "{e}");
}
