//! Bad BVH input gives a `ParseError` naming the file, the 1-based line and
//! column, and what was expected; never a panic. One test per kind of error.

use std::io::Cursor;
use std::path::{Path, PathBuf};

use mocap_core::io::bvh::{read_bvh, read_bvh_from};
use mocap_core::{Error, ParseError};
use proptest::prelude::*;

/// A valid file; each test breaks one thing in it. Line numbers:
///  1 HIERARCHY, 2 ROOT, 6 JOINT Spine, 9 its CHANNELS, 10 End Site,
/// 15 the root's `}`, 16 MOTION, 17 Frames, 18 Frame Time, 19-20 frames.
const VALID: &str = "\
HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0 10 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 5 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0333333
0 90 0 0 0 0 1 2 3
0 91 0 0 0 0 4 5 6
";

/// `VALID` with line `line` (1-based) replaced by `text` (`None` removes it).
fn with_line(line: usize, text: Option<&str>) -> String {
    let mut lines: Vec<&str> = VALID.lines().collect();
    match text {
        Some(t) => lines[line - 1] = t,
        None => {
            lines.remove(line - 1);
        }
    }
    lines.join("\n") + "\n"
}

fn parse_error(text: &str) -> ParseError {
    match read_bvh_from(Cursor::new(text.as_bytes()), Path::new("take.bvh")) {
        Err(Error::Parse(e)) => e,
        Err(other) => panic!("expected a parse error, got {other}"),
        Ok(_) => panic!("expected a parse error, the text was read"),
    }
}

#[track_caller]
fn assert_error(text: &str, line: usize, column: usize, phrase: &str) {
    let e = parse_error(text);
    assert_eq!(e.location.path, Path::new("take.bvh"));
    assert_eq!(
        (e.location.line, e.location.column),
        (line, column),
        "wrong place for: {e}"
    );
    assert!(
        e.message.contains(phrase),
        "message {:?} lacks {phrase:?}",
        e.message
    );
}

#[test]
fn the_valid_base_file_reads() {
    let motion = read_bvh_from(Cursor::new(VALID), Path::new("take.bvh")).unwrap();
    assert_eq!(motion.frame_count(), 2);
}

#[test]
fn empty_file() {
    assert_error("", 1, 1, "empty file");
    assert_error(" \r\n\t\n", 1, 1, "empty file");
}

#[test]
fn missing_hierarchy_keyword() {
    assert_error(
        &with_line(1, Some("HIERARCHIE")),
        1,
        1,
        "expected HIERARCHY",
    );
}

#[test]
fn too_few_values_on_a_frame_line() {
    // "0 91 0 0 0 0 4 5" is 16 bytes: the missing value is at column 17.
    let text = with_line(20, Some("0 91 0 0 0 0 4 5"));
    assert_error(&text, 20, 17, "frame 2 has 8 values: expected 9");
}

#[test]
fn too_many_values_on_a_frame_line() {
    // The tenth value starts at column 20.
    let text = with_line(19, Some("0 90 0 0 0 0 1 2 3 7"));
    assert_error(&text, 19, 20, "too many values on frame 1: expected 9");
}

#[test]
fn truncated_file_with_fewer_frame_lines_than_announced() {
    let text = with_line(17, Some("Frames: 3"));
    assert_error(&text, 21, 1, "file ends after 2 frame lines");
    assert_error(&text, 21, 1, "announced 3");
    // Cut in the middle of the last frame line: that line lacks values.
    let cut = &VALID[..VALID.len() - 5];
    assert!(cut.ends_with("0 91 0 0 0 0 4"));
    assert_error(cut, 20, 15, "frame 2 has 7 values: expected 9");
}

#[test]
fn more_frame_lines_than_announced() {
    let text = with_line(17, Some("Frames: 1"));
    assert_error(&text, 20, 1, "more frame lines than the 1 announced");
}

#[test]
fn unknown_channel() {
    let text = with_line(9, Some("    CHANNELS 3 Zrotation Xrotation Wrotation"));
    assert_error(&text, 9, 36, "unknown channel \"Wrotation\"");
}

#[test]
fn channel_count_differs_from_the_names_listed() {
    let fewer = with_line(9, Some("    CHANNELS 3 Zrotation Xrotation"));
    assert_error(
        &fewer,
        9,
        35,
        "CHANNELS 3 lists 2 channel names: expected 3",
    );
    let more = with_line(9, Some("    CHANNELS 2 Zrotation Xrotation Yrotation"));
    assert_error(&more, 9, 36, "CHANNELS 2 lists more than 2");
    let not_a_count = with_line(9, Some("    CHANNELS Zrotation"));
    assert_error(&not_a_count, 9, 14, "expected the number of channels");
}

#[test]
fn channel_listed_twice() {
    let text = with_line(9, Some("    CHANNELS 3 Zrotation Xrotation Zrotation"));
    assert_error(&text, 9, 36, "listed twice");
}

#[test]
fn non_numeric_value() {
    assert_error(
        &with_line(19, Some("0 90 0 0 abc 0 1 2 3")),
        19,
        10,
        "expected a number, found \"abc\"",
    );
    // A decimal comma, as some localized exporters write.
    assert_error(
        &with_line(20, Some("0 91,5 0 0 0 0 4 5 6")),
        20,
        3,
        "expected a number, found \"91,5\"",
    );
    // Bytes that are not text at all.
    let mut bytes = with_line(20, Some("0 91 0 0 0 0 4 5 \u{1}")).into_bytes();
    let at = bytes.iter().position(|&b| b == 1).unwrap();
    bytes[at] = 0xFF;
    let e = match read_bvh_from(Cursor::new(bytes), Path::new("take.bvh")) {
        Err(Error::Parse(e)) => e,
        other => panic!("{other:?}"),
    };
    assert_eq!((e.location.line, e.location.column), (20, 18));
    assert!(e.message.contains("expected a number"), "{}", e.message);
}

#[test]
fn non_finite_value() {
    assert_error(
        &with_line(19, Some("0 90 0 0 nan 0 1 2 3")),
        19,
        10,
        "expected a number, found \"nan\"",
    );
    assert_error(
        &with_line(19, Some("0 90 0 0 0 -inf 1 2 3")),
        19,
        12,
        "expected a number, found \"-inf\"",
    );
}

#[test]
fn non_numeric_offset() {
    let text = with_line(8, Some("    OFFSET 0 ten 0"));
    assert_error(&text, 8, 14, "expected a number for OFFSET");
    let short = with_line(8, Some("    OFFSET 0 10"));
    assert_error(&short, 8, 16, "OFFSET takes 3 numbers (x y z), found 2");
}

#[test]
fn missing_motion() {
    let text = with_line(16, None);
    assert_error(&text, 16, 1, "expected MOTION");
    let ends = VALID.split("MOTION").next().unwrap();
    assert_error(
        ends,
        16,
        1,
        "file ends after the hierarchy: expected MOTION",
    );
}

#[test]
fn missing_frame_time() {
    let text = with_line(18, None);
    assert_error(
        &text,
        18,
        1,
        "expected `Frame Time:` after MOTION, found \"0\"",
    );
    let ends = VALID.split("Frame Time").next().unwrap();
    assert_error(ends, 18, 1, "expected `Frame Time:`");
}

#[test]
fn missing_frames() {
    let text = with_line(17, None);
    assert_error(&text, 18, 1, "expected `Frames:` after MOTION");
    assert_error(
        "HIERARCHY\nROOT a\n{\n}\nMOTION\n",
        6,
        1,
        "expected `Frames:`",
    );
}

#[test]
fn bad_frame_count_or_frame_time() {
    assert_error(
        &with_line(17, Some("Frames: -2")),
        17,
        9,
        "expected the number of frames",
    );
    assert_error(
        &with_line(18, Some("Frame Time: 0")),
        18,
        13,
        "a frame time of 0.000001 to 10 seconds",
    );
    // Frame times no capture has: every duration infinite, every speed NaN.
    for absurd in ["1e300", "1e-300", "11", "0.0000009"] {
        assert_error(
            &with_line(18, Some(&format!("Frame Time: {absurd}"))),
            18,
            13,
            &format!(
                "a frame time of 0.000001 to 10 seconds after `Frame Time:`, found \"{absurd}\""
            ),
        );
    }
    for sane in ["0.000001", "10", "0.008333"] {
        let text = with_line(18, Some(&format!("Frame Time: {sane}")));
        read_bvh_from(Cursor::new(text.as_bytes()), Path::new("take.bvh")).unwrap();
    }
    assert_error(
        &with_line(18, Some("Frame Time: 0.03 0.04")),
        18,
        18,
        "expected the end of the line",
    );
    // 10^19 frames of 9 channels overflow any memory.
    assert_error(
        &with_line(17, Some("Frames: 10000000000000000000")),
        17,
        1,
        "more than memory can hold",
    );
}

#[test]
fn unbalanced_braces() {
    // One `}` too many after the root.
    let extra = VALID.replace("}\nMOTION", "}\n}\nMOTION");
    assert_error(&extra, 16, 1, "unbalanced `}`");
    // The root is never closed.
    let missing = with_line(15, None);
    assert_error(&missing, 15, 1, "expected `}` to close joint \"Hips\"");
    // The file ends inside a joint.
    let cut: String = VALID.lines().take(12).map(|l| format!("{l}\n")).collect();
    assert_error(&cut, 13, 1, "file ends inside End Site");
    let cut: String = VALID.lines().take(9).map(|l| format!("{l}\n")).collect();
    assert_error(
        &cut,
        10,
        1,
        "file ends inside joint \"Spine\" (opened at line 6)",
    );
    // A second ROOT before the first is closed.
    let nested_root = with_line(6, Some("  ROOT Spine"));
    assert_error(
        &nested_root,
        6,
        3,
        "ROOT inside joint \"Hips\" (opened at line 2)",
    );
    // A JOINT without `{`.
    let no_brace = with_line(7, Some("    OFFSET 1 1 1"));
    assert_error(&no_brace, 7, 5, "expected `{` after JOINT");
}

#[test]
fn two_joints_with_one_name() {
    let text = with_line(6, Some("  JOINT Hips"));
    assert_error(
        &text,
        6,
        9,
        "a second joint named \"Hips\" (the first is at line 2)",
    );
}

#[test]
fn unexpected_word_in_a_joint() {
    let text = with_line(8, Some("    OFSET 0 10 0"));
    assert_error(
        &text,
        8,
        5,
        "expected OFFSET, CHANNELS, JOINT, End Site or `}`",
    );
}

#[test]
fn error_from_a_file_names_the_file() {
    let path: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bvh/truncated.bvh");
    let e = match read_bvh(&path) {
        Err(Error::Parse(e)) => e,
        other => panic!("{other:?}"),
    };
    assert_eq!(e.location.path, path);
    assert_eq!((e.location.line, e.location.column), (16, 1));
    assert!(e.message.contains("announced 4"), "{}", e.message);
    let shown = e.to_string();
    assert!(
        shown.starts_with(&format!("{}:16:1: ", path.display())),
        "{shown}"
    );
}

#[test]
fn missing_file_is_an_io_error_naming_it() {
    let path = Path::new("/nonexistent/take.bvh");
    match read_bvh(path) {
        Err(Error::Io { path: p, .. }) => assert_eq!(p, path),
        other => panic!("{other:?}"),
    }
}

#[test]
fn every_truncation_of_a_file_is_read_or_refused_without_panic() {
    for end in 0..VALID.len() {
        let _ = read_bvh_from(Cursor::new(&VALID.as_bytes()[..end]), Path::new("cut.bvh"));
    }
    let quirks =
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bvh/quirks.bvh"))
            .unwrap();
    for end in 0..quirks.len() {
        let _ = read_bvh_from(Cursor::new(&quirks[..end]), Path::new("cut.bvh"));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    /// Random edits with the bytes that matter to the grammar never panic.
    #[test]
    fn random_edits_never_panic(
        edits in prop::collection::vec(
            (any::<prop::sample::Index>(), 0u8..3, prop::sample::select(
                b" \t\r\n{}-.eE09:#\xFF\xC3".to_vec())),
            1..6)
    ) {
        let mut bytes = VALID.as_bytes().to_vec();
        for (at, kind, byte) in edits {
            let i = at.index(bytes.len() + 1);
            match kind {
                0 => bytes.insert(i, byte),
                1 if i < bytes.len() => bytes[i] = byte,
                _ if i < bytes.len() => { bytes.remove(i); }
                _ => {}
            }
        }
        let _ = read_bvh_from(Cursor::new(bytes), Path::new("edited.bvh"));
    }
}

/// A file that starts with a terminal escape (one that retitles the
/// terminal) gets an error whose text escapes it: printing the error must not
/// hand the file's control characters to the user's terminal.
#[test]
fn control_characters_of_the_file_are_escaped_in_the_message() {
    let text = "\u{1b}]0;owned\u{7}HIERARCHY\n";
    let e = parse_error(text);
    let shown = Error::Parse(e).to_string();
    assert!(!shown.chars().any(|c| c.is_control()), "{shown:?}");
    assert!(shown.contains("\\u{1b}]0;owned\\u{7}"), "{shown}");
    assert!(shown.starts_with("take.bvh:1:1: "), "{shown}");
}
