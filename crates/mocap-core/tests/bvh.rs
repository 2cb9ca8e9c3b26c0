//! BVH reader and writer on real files (the Bandai Namco takes and the
//! parser cases from other exporters) and on small hand-made fixtures.

use mocap_testdata::{bvh_files, shared_data};
use std::io::Cursor;
use std::path::{Path, PathBuf};

use mocap_core::io::bvh::{read_bvh, read_bvh_from, write_bvh, write_bvh_to};
use mocap_core::rotation::Vec3;
use mocap_core::{Channel, Joint, Motion, Skeleton};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/bvh")
        .join(name)
}

/// What the file says, found without the reader: the number after
/// `Frames:`, the number of non-blank lines after `Frame Time:`, and the
/// last of those lines split into numbers.
struct TextFacts {
    joints: usize,
    channels: usize,
    frames_in_header: usize,
    frame_lines: usize,
    last_frame: Vec<f32>,
}

fn text_facts(path: &Path) -> TextFacts {
    let bytes = std::fs::read(path).unwrap();
    let text = String::from_utf8_lossy(&bytes);
    let mut frames_in_header = None;
    let mut in_frames = false;
    let mut frame_lines = 0;
    let mut last = "";
    let (mut joints, mut channels) = (0, 0);
    for line in text.lines() {
        let t = line.trim();
        let first_word = t.split_whitespace().next().unwrap_or("");
        if !in_frames && (first_word == "ROOT" || first_word == "JOINT") {
            joints += 1;
        }
        if !in_frames && first_word == "CHANNELS" {
            channels += t
                .split_whitespace()
                .nth(1)
                .unwrap()
                .parse::<usize>()
                .unwrap();
        }
        if in_frames {
            if !t.is_empty() {
                frame_lines += 1;
                last = t;
            }
        } else if let Some(rest) = t.strip_prefix("Frames:") {
            frames_in_header = Some(rest.trim().parse().unwrap());
        } else if t.starts_with("Frame Time:") {
            in_frames = true;
        }
    }
    TextFacts {
        joints,
        channels,
        frames_in_header: frames_in_header.expect("a Frames: line"),
        frame_lines,
        last_frame: last
            .split_whitespace()
            .map(|w| w.parse().unwrap())
            .collect(),
    }
}

fn check_against_text(path: &Path, motion: &Motion) {
    let facts = text_facts(path);
    let name = path.display();
    assert_eq!(motion.skeleton().joint_count(), facts.joints, "{name}");
    assert_eq!(motion.skeleton().channel_count(), facts.channels, "{name}");
    assert_eq!(motion.frame_count(), facts.frames_in_header, "{name}");
    assert_eq!(motion.frame_count(), facts.frame_lines, "{name}");
    if motion.frame_count() > 0 {
        let last = motion.frame(motion.frame_count() - 1);
        assert_eq!(last, &facts.last_frame[..], "{name}: last frame");
    }
}

/// Parents come before their children, and the frame has one column per
/// listed channel.
fn check_structure(motion: &Motion) {
    let skeleton = motion.skeleton();
    for (i, joint) in skeleton.joints().iter().enumerate() {
        if let Some(p) = joint.parent {
            assert!(p < i);
        }
    }
    let channels: usize = skeleton.joints().iter().map(|j| j.channels.len()).sum();
    assert_eq!(
        motion.values().len(),
        motion.frame_count() * channels,
        "values"
    );
}

#[test]
fn every_bandai_file_loads_with_the_frame_count_of_its_header() {
    let Some(data) = shared_data() else { return };
    let mut loaded = 0;
    for dataset in ["dataset-1", "dataset-2"] {
        for path in bvh_files(&data.join("bandai").join(dataset)) {
            let motion = read_bvh(&path).unwrap_or_else(|e| panic!("{e}"));
            check_against_text(&path, &motion);
            check_structure(&motion);
            // Every take has the same rig: 22 joints counting the root (the
            // README's "22 joints plus a root" counts one too many), 6
            // channels each, 30 frames per second.
            let skeleton = motion.skeleton();
            assert_eq!(skeleton.joint_count(), 22, "{}", path.display());
            assert_eq!(skeleton.channel_count(), 22 * 6, "{}", path.display());
            assert!((motion.fps() - 30.0).abs() < 1e-3, "{}", path.display());
            loaded += 1;
        }
    }
    // dataset-1 has 174 takes, the dataset-2 subset 991 (see the README).
    assert_eq!(loaded, 174 + 991);
}

#[test]
fn bandai_hierarchy_and_channel_order_are_as_in_the_file() {
    let Some(data) = shared_data() else { return };
    let path = data.join("bandai/dataset-1/dataset-1_bow_active_001.bvh");
    let motion = read_bvh(&path).unwrap();
    let skeleton = motion.skeleton();
    let names: Vec<&str> = skeleton.joints()[..6]
        .iter()
        .map(|j| j.name.as_str())
        .collect();
    assert_eq!(
        names,
        ["joint_Root", "Hips", "Spine", "Chest", "Neck", "Head"]
    );
    let hips = skeleton.joint(1);
    assert_eq!(hips.parent, Some(0));
    assert_eq!(hips.offset, Vec3::new(0.847027, 93.984, -452.225));
    use Channel::*;
    assert_eq!(
        hips.channels,
        [Xposition, Yposition, Zposition, Zrotation, Xrotation, Yrotation]
    );
    let head = skeleton.find("Head").unwrap();
    assert_eq!(skeleton.joint(head).end_sites, [Vec3::ZERO]);
    assert_eq!(skeleton.joint(head).parent, skeleton.find("Neck"));
    assert_eq!(motion.frame_time(), 0.0333333);
}

#[test]
fn every_parser_case_loads_with_the_frame_count_of_its_header() {
    let Some(data) = shared_data() else { return };
    let files = bvh_files(&data.join("parser-cases"));
    assert!(files.len() >= 5, "{} parser cases", files.len());
    for path in &files {
        let motion = read_bvh(path).unwrap_or_else(|e| panic!("{e}"));
        check_against_text(path, &motion);
        check_structure(&motion);
    }
}

#[test]
fn parser_cases_read_the_right_rigs() {
    let Some(data) = shared_data() else { return };
    let cases = data.join("parser-cases");

    let simple = read_bvh(&cases.join("bvhanim_test_simple.bvh")).unwrap();
    let s = simple.skeleton();
    assert_eq!(s.joint_count(), 2);
    assert_eq!(s.joint(1).name, "End");
    assert_eq!(s.joint(1).offset, Vec3::new(0.0, 0.0, 15.0));
    assert_eq!(s.joint(1).end_sites, [Vec3::new(0.0, 0.0, 30.0)]);
    assert_eq!(simple.frame(0), [0.0; 9]);
    assert_eq!(simple.frame(1), [1.0; 9]);
    assert_eq!(simple.frame_time(), 0.033333333);

    // The same take with LF and with CRLF + tab after `Frames:`.
    let lf = read_bvh(&cases.join("bvhanim_test_mocapbank.bvh")).unwrap();
    let crlf = read_bvh(&cases.join("bvhpython_test_mocapbank.bvh")).unwrap();
    assert_eq!(lf, crlf);
    assert_eq!(lf.frame_count(), 455);
    let chest = lf.skeleton().find("Chest").unwrap();
    use Channel::*;
    assert_eq!(
        lf.skeleton().joint(chest).channels,
        [Zrotation, Xrotation, Yrotation]
    );

    let mixamo = read_bvh(&cases.join("bvhpython_test_freebvh.bvh")).unwrap();
    assert_eq!(mixamo.skeleton().joint_count(), 55);
    assert!(mixamo
        .skeleton()
        .joints()
        .iter()
        .all(|j| j.name.starts_with("mixamorig:")));
    assert_eq!(
        mixamo.skeleton().joint(2).offset,
        Vec3::new(-0.0001, 11.6455, -1.4224)
    );

    let cmu = read_bvh(&cases.join("dme_example_crlf_leadingdot_frametime.bvh")).unwrap();
    assert_eq!(cmu.frame_time(), 0.0083333);
    assert_eq!(cmu.skeleton().joint_count(), 31);
    assert_eq!(cmu.frame_count(), 278);
}

/// Reads, writes to memory, reads again: same skeleton (bit for bit),
/// channel order, frame time and values.
fn assert_round_trip(motion: &Motion, label: &str) -> Vec<u8> {
    let mut text = Vec::new();
    write_bvh_to(&mut text, motion).unwrap();
    let again = read_bvh_from(Cursor::new(&text), Path::new(label))
        .unwrap_or_else(|e| panic!("{label}: written text does not read back: {e}"));
    assert_same_bits(motion, &again, label);
    text
}

fn assert_same_bits(a: &Motion, b: &Motion, label: &str) {
    let (sa, sb) = (a.skeleton(), b.skeleton());
    assert_eq!(sa.joint_count(), sb.joint_count(), "{label}");
    for (ja, jb) in sa.joints().iter().zip(sb.joints()) {
        assert_eq!(ja.name, jb.name, "{label}");
        assert_eq!(ja.parent, jb.parent, "{label} {}", ja.name);
        assert_eq!(ja.channels, jb.channels, "{label} {}", ja.name);
        assert_eq!(
            ja.offset.to_array().map(f32::to_bits),
            jb.offset.to_array().map(f32::to_bits),
            "{label} {} offset",
            ja.name
        );
        let ends = |j: &Joint| -> Vec<[u32; 3]> {
            j.end_sites
                .iter()
                .map(|e| e.to_array().map(f32::to_bits))
                .collect()
        };
        assert_eq!(ends(ja), ends(jb), "{label} {} end sites", ja.name);
    }
    assert_eq!(
        a.frame_time().to_bits(),
        b.frame_time().to_bits(),
        "{label}"
    );
    assert_eq!(a.frame_count(), b.frame_count(), "{label}");
    let differing = a
        .values()
        .iter()
        .zip(b.values())
        .position(|(x, y)| x.to_bits() != y.to_bits());
    assert_eq!(differing, None, "{label}: first value that differs");
}

#[test]
fn round_trip_of_every_parser_case_is_bit_identical() {
    let Some(data) = shared_data() else { return };
    for path in bvh_files(&data.join("parser-cases")) {
        let motion = read_bvh(&path).unwrap();
        assert_round_trip(&motion, &path.display().to_string());
    }
}

#[test]
fn round_trip_of_a_sample_of_bandai_files_is_bit_identical() {
    let Some(data) = shared_data() else { return };
    let mut tried = 0;
    for dataset in ["dataset-1", "dataset-2"] {
        for path in bvh_files(&data.join("bandai").join(dataset))
            .iter()
            .step_by(40)
        {
            let motion = read_bvh(path).unwrap();
            assert_round_trip(&motion, &path.display().to_string());
            tried += 1;
        }
    }
    assert!(tried >= 25, "{tried} files");
}

#[test]
fn write_bvh_writes_a_file_that_reads_back() {
    let motion = read_bvh(&fixture("two_roots.bvh")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.bvh");
    write_bvh(&path, &motion).unwrap();
    let again = read_bvh(&path).unwrap();
    assert_same_bits(&motion, &again, "out.bvh");
    // Nothing but the file is left in the folder (no temporary file).
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn two_roots_are_read_and_written() {
    let motion = read_bvh(&fixture("two_roots.bvh")).unwrap();
    let s = motion.skeleton();
    let names: Vec<&str> = s.joints().iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, ["Body", "Head", "Prop"]);
    assert_eq!(s.joint(2).parent, None);
    assert_eq!(s.joint(2).offset, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(s.joint(2).end_sites, [Vec3::Z]);
    use Channel::*;
    assert_eq!(s.joint(2).channels, [Xposition, Zposition, Yposition]);
    assert_eq!(motion.joint_values(1, 2), [10.0, 11.0, 12.0]);
    // Position channels replace the offset, in their listed order.
    assert_eq!(motion.local_translation(1, 2), Vec3::new(10.0, 12.0, 11.0));
    assert_eq!(motion.frame_time(), 0.04);

    let text = assert_round_trip(&motion, "two_roots");
    let text = String::from_utf8(text).unwrap();
    assert_eq!(text.matches("ROOT ").count(), 2);
}

#[test]
fn quirks_of_real_exporters_are_tolerated() {
    // The fixture has: a UTF-8 byte order mark; `hierarchy`, `Root`,
    // `Offset`, `Channels`, `END SITE tip`, `Motion`, `Frame time:`, `FRAMES:`;
    // CRLF mixed with LF; tabs between numbers; `{` on the ROOT line; a name
    // with a space and one with a Latin-1 byte (0xE9); a comment line with a
    // Latin-1 byte; channel subsets (`CHANNELS 2 Yrotation Xposition`,
    // `CHANNELS 0`, no CHANNELS line); `Frame time` before `Frames` and a tab
    // after `FRAMES:`; `.0083333`, `8.09E-05`, `1e-015`, `-0.0000`; and blank
    // lines after the last frame.
    let motion = read_bvh(&fixture("quirks.bvh")).unwrap();
    let s = motion.skeleton();
    let names: Vec<&str> = s.joints().iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, ["Hips Bone", "Caf\u{FFFD}", "NoChannels", "Zero"]);
    assert_eq!(s.joint(0).offset, Vec3::new(0.5, -12.5, 8.09e-5));
    assert_eq!(s.joint(1).offset.y, 1e-15);
    assert_eq!(s.joint(1).offset.z.to_bits(), (-0.0f32).to_bits());
    use Channel::*;
    assert_eq!(
        s.joint(0).channels,
        [Xposition, Yposition, Zposition, Zrotation, Xrotation, Yrotation]
    );
    assert_eq!(s.joint(1).channels, [Yrotation, Xposition]);
    assert!(s.joint(2).channels.is_empty());
    assert!(s.joint(3).channels.is_empty());
    assert_eq!(s.joint(2).parent, Some(1));
    assert_eq!(s.joint(3).parent, Some(1));
    assert_eq!(s.joint(2).end_sites, [Vec3::new(0.5, 0.0, 0.0)]);
    assert_eq!(s.joint(3).end_sites, [Vec3::new(0.0, 0.0, 2.0)]);
    assert_eq!(motion.frame_time(), 0.0083333);
    assert_eq!(motion.frame_count(), 2);
    assert_eq!(motion.frame(0), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
    let f = motion.frame(1);
    assert_eq!(f[..5], [-150.0, 2.5e-3, 0.0, 0.25, -0.75]);
    assert_eq!(f[2].to_bits(), (-0.0f32).to_bits());
    assert_eq!(f[5], 1e-45); // the smallest subnormal f32
    assert_eq!(f[6], f32::MAX);
    assert_round_trip(&motion, "quirks");
}

/// A small motion built in code: two joints, two frames.
fn small_motion() -> Motion {
    use Channel::*;
    let mut root = Joint::new("Hips", None, Vec3::new(0.0, 90.0, 0.0));
    root.channels = vec![
        Xposition, Yposition, Zposition, Zrotation, Xrotation, Yrotation,
    ];
    let mut spine = Joint::new("Spine", Some(0), Vec3::new(0.0, 10.5, -0.0));
    spine.channels = vec![Zrotation, Xrotation, Yrotation];
    spine.end_sites.push(Vec3::new(0.0, 8.0, 0.0));
    let skeleton = Skeleton::new(vec![root, spine]).unwrap();
    let values = vec![
        0.0,
        90.0,
        0.1,
        0.0,
        0.0,
        0.0,
        5.0,
        -0.0,
        1e-7, //
        0.5,
        91.0,
        0.2,
        1.0,
        2.0,
        3.0,
        6.0,
        7.25,
        1.0 / 3.0,
    ];
    Motion::new(skeleton, 1.0 / 30.0, 2, values).unwrap()
}

#[test]
fn writer_output_is_the_expected_text() {
    let mut text = Vec::new();
    write_bvh_to(&mut text, &small_motion()).unwrap();
    let expected = "HIERARCHY\n\
        ROOT Hips\n\
        {\n\
        \tOFFSET 0 90 0\n\
        \tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n\
        \tJOINT Spine\n\
        \t{\n\
        \t\tOFFSET 0 10.5 -0\n\
        \t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\
        \t\tEnd Site\n\
        \t\t{\n\
        \t\t\tOFFSET 0 8 0\n\
        \t\t}\n\
        \t}\n\
        }\n\
        MOTION\n\
        Frames: 2\n\
        Frame Time: 0.03333333333333333\n\
        0 90 0.1 0 0 0 5 -0 0.0000001\n\
        0.5 91 0.2 1 2 3 6 7.25 0.33333334\n";
    assert_eq!(String::from_utf8(text).unwrap(), expected);
}

#[test]
fn joints_not_in_depth_first_order_are_written_with_their_own_values() {
    // Breadth-first order (as an ASF skeleton may give): Root, A, B, A1.
    // The file must list A1 inside A, before B, and its columns with it.
    let mut root = Joint::new("Root", None, Vec3::ZERO);
    root.channels = vec![Channel::Xposition];
    let mut a = Joint::new("A", Some(0), Vec3::X);
    a.channels = vec![Channel::Xrotation];
    let mut b = Joint::new("B", Some(0), Vec3::Y);
    b.channels = vec![Channel::Yrotation];
    let mut a1 = Joint::new("A1", Some(1), Vec3::Z);
    a1.channels = vec![Channel::Zrotation];
    let skeleton = Skeleton::new(vec![root, a, b, a1]).unwrap();
    let motion = Motion::new(skeleton, 0.01, 1, vec![1.0, 2.0, 3.0, 4.0]).unwrap();

    let mut text = Vec::new();
    write_bvh_to(&mut text, &motion).unwrap();
    let again = read_bvh_from(Cursor::new(&text), Path::new("bfs")).unwrap();
    let names: Vec<&str> = again
        .skeleton()
        .joints()
        .iter()
        .map(|j| j.name.as_str())
        .collect();
    assert_eq!(names, ["Root", "A", "A1", "B"]);
    for name in ["Root", "A", "B", "A1"] {
        let before = motion.skeleton().find(name).unwrap();
        let after = again.skeleton().find(name).unwrap();
        assert_eq!(
            motion.joint_values(0, before),
            again.joint_values(0, after),
            "{name}"
        );
        let parent_name = |m: &Motion, j: usize| {
            m.skeleton()
                .joint(j)
                .parent
                .map(|p| m.skeleton().joint(p).name.clone())
        };
        assert_eq!(parent_name(&motion, before), parent_name(&again, after));
    }
}

#[test]
fn names_that_cannot_be_written_are_refused() {
    for bad in ["", " Hips", "Hips\nJOINT", "Hips {", "A{B"] {
        let skeleton = Skeleton::new(vec![Joint::new(bad, None, Vec3::ZERO)]).unwrap();
        let motion = Motion::new(skeleton, 0.1, 0, vec![]).unwrap();
        let err = write_bvh_to(&mut Vec::new(), &motion).unwrap_err();
        assert_eq!(err.kind(), std::io::ErrorKind::InvalidInput, "{bad:?}");
    }
}

#[test]
fn a_very_deep_chain_reads_and_writes_without_recursion() {
    let depth = 5000;
    let mut text = String::from("HIERARCHY\n");
    for i in 0..depth {
        let keyword = if i == 0 { "ROOT" } else { "JOINT" };
        text.push_str(&format!(
            "{keyword} j{i}\n{{\nOFFSET 0 1 0\nCHANNELS 1 Zrotation\n"
        ));
    }
    text.push_str(&"}\n".repeat(depth));
    text.push_str("MOTION\nFrames: 1\nFrame Time: 0.1\n");
    text.push_str(&vec!["1"; depth].join(" "));
    let motion = read_bvh_from(Cursor::new(text.as_bytes()), Path::new("deep")).unwrap();
    assert_eq!(motion.skeleton().joint_count(), depth);
    assert_eq!(motion.skeleton().joint(depth - 1).parent, Some(depth - 2));
    let written = assert_round_trip(&motion, "deep");
    // Indentation is capped: the file grows with the joints, not with the
    // square of the depth (one tab a level writes about 62 million tabs here;
    // capped, about 210 bytes a joint).
    assert!(
        written.len() < 300 * depth,
        "{} bytes for {depth} joints",
        written.len()
    );
}

#[test]
fn zero_frames_read_and_write() {
    let text = "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 1 Xrotation\n}\nMOTION\nFrames: 0\nFrame Time: 0.5\n";
    let motion = read_bvh_from(Cursor::new(text), Path::new("empty-take")).unwrap();
    assert_eq!(motion.frame_count(), 0);
    assert_round_trip(&motion, "empty-take");
}

#[test]
fn end_site_spellings_and_braces_on_the_same_line() {
    for end_site in [
        "End Site",
        "END SITE",
        "end site",
        "EndSite",
        "End Site {",
        "End Site Hand_end",
    ] {
        let brace = if end_site.ends_with('{') { "" } else { "{" };
        let text = format!(
            "HIERARCHY\nROOT Hips {{\n OFFSET 0 0 0\n CHANNELS 1 Yrotation\n JOINT Hand {{ OFFSET 1 0 0\n  {end_site}\n  {brace} OFFSET 0 2 0\n  }}}}\n}}\nMOTION\nFrames: 1\nFrame Time: 0.1\n45\n"
        );
        let motion = read_bvh_from(Cursor::new(text), Path::new("end-site"))
            .unwrap_or_else(|e| panic!("{end_site:?}: {e}"));
        let hand = motion.skeleton().joint(1);
        assert_eq!(hand.offset, Vec3::X, "{end_site:?}");
        assert_eq!(hand.end_sites, [Vec3::new(0.0, 2.0, 0.0)], "{end_site:?}");
        assert_eq!(motion.frame(0), [45.0]);
    }
}

#[test]
fn the_first_branching_joint_is_the_pelvis_of_real_rigs() {
    let name = |m: &Motion| {
        let s = m.skeleton();
        s.joint(s.first_branching_joint()).name.clone()
    };
    // Bandai: a helper `joint_Root` on the floor above `Hips`.
    let bandai = read_bvh(&mocap_testdata::sample_walk()).unwrap();
    assert_eq!(bandai.skeleton().joint(0).name, "joint_Root");
    assert_eq!(name(&bandai), "Hips");
    let Some(data) = shared_data() else { return };
    let cases = data.join("parser-cases");
    let mixamo = read_bvh(&cases.join("bvhpython_test_freebvh.bvh")).unwrap();
    assert_eq!(name(&mixamo), "mixamorig:Hips");
    let cmu = read_bvh(&cases.join("dme_example_crlf_leadingdot_frametime.bvh")).unwrap();
    assert_eq!(name(&cmu), "Hips");
    // A two-joint chain has no branch: its last joint.
    let simple = read_bvh(&cases.join("bvhanim_test_simple.bvh")).unwrap();
    assert_eq!(simple.skeleton().first_branching_joint(), 1);
}
