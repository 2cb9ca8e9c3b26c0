//! Per-camera 2D keypoint files: OpenPose's JSON, one file per frame, which
//! Pose2Sim converts every estimator's output to.
//!
//! A file holds `{"version": 1.3, "people": [{"person_id": [-1],
//! "pose_keypoints_2d": [x, y, score, ...]}, ...]}`; other keys (face and
//! hand keypoints, 3D keypoints) are ignored. A camera's files sit in one
//! folder, named so that the last run of digits in the name is the frame
//! number (`cam01.0012.json`, `video_000012_keypoints.json`).
//!
//! Every number is checked as it is read, so that an error names the file,
//! the line and the column: a count that is not (x, y, score) triples or
//! that disagrees with the layout, a negative score, a number out of range.

use std::cell::Cell;
use std::cmp::Ordering;
use std::fmt;
use std::io::Read;
use std::path::{Path, PathBuf};

use mocap_core::{Error, Result};
use serde::de::{self, DeserializeSeed, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};

use crate::layout::Layout;

/// One detected person in one image.
#[derive(Debug, Clone, PartialEq)]
pub struct Person2d {
    /// The estimator's or the tracker's id of the person; `None` for
    /// OpenPose's `-1` (not tracked).
    pub id: Option<i64>,
    /// (x px, y px, score 0..1) per keypoint in the layout's order; a
    /// keypoint not detected has score 0.
    pub keypoints: Vec<[f32; 3]>,
}

/// The people one camera saw in one frame.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ViewFrame {
    /// In the file's order. Pose2Sim's associated files keep one place per
    /// tracked participant and write `{}` for one not seen: such a place is
    /// kept, as a person with every keypoint undetected.
    pub people: Vec<Person2d>,
}

/// One camera's keypoints over a trial.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraKeypoints {
    /// The folder read.
    pub folder: PathBuf,
    /// The layout of every person's keypoints: the one asked for, else the
    /// one detected from the files.
    pub layout: Layout,
    /// The frame number of `frames[0]` (from the file names).
    pub first_frame: usize,
    /// One entry per frame number from `first_frame`; a missing file is an
    /// empty frame (and counted in `missing_files`).
    pub frames: Vec<ViewFrame>,
    /// Frame numbers between the first and the last with no file.
    pub missing_files: usize,
}

/// The largest keypoint file read: a frame of a few people is a few kB, so
/// anything near this is not a keypoint file, and reading it whole would
/// only cost memory.
const MAX_FILE_BYTES: u64 = 64 << 20;

/// The most frames a folder may span from its first file to its last: frame
/// numbers far apart (`cam.0001.json` beside `cam.99999999.json`) would
/// otherwise have us allocate an empty frame for each number in between.
const MAX_FRAME_SPAN: usize = 1_000_000;

/// The score from which a keypoint counts as seen when telling layouts apart.
const CONFIDENT: f32 = 0.3;

/// Reads a folder of OpenPose JSON files, one per frame, in frame order.
///
/// `layout`: the layout of the files, else detected from the keypoint count
/// (17: COCO_17, 26: HALPE_26, 33: BLAZEPOSE) and, for 25, from the
/// keypoints themselves: the body tree's bones
/// ([`CANONICAL_PARENTS`](crate::CANONICAL_PARENTS)) are clearly shorter
/// read in the right one of BODY_25 and BODY_25B, over the people with
/// enough confident keypoints (at least 3); when they are not, the error
/// asks for the layout. The result's `layout` says which was chosen. Every
/// person of every file must have the layout's count. A person written
/// with no keypoints (`{}`, `[]`) gets the layout's count of undetected
/// keypoints.
///
/// Errors: the folder cannot be read, holds no `.json` file, two files have
/// the same frame number or a file has none; a file is not such JSON (the
/// error gives its line and column), is over 64 MiB, holds a non-finite
/// number, a negative score, or a count of numbers that is not (x, y, score)
/// triples or not the layout's; the layout cannot be detected.
pub fn read_openpose_folder(folder: &Path, layout: Option<Layout>) -> Result<CameraKeypoints> {
    let files = keypoint_files(folder)?;
    let (Some((first_frame, _)), Some((last_frame, _))) = (files.first(), files.last()) else {
        return Err(Error::Invalid(format!(
            "{}: no .json keypoint files",
            folder.display()
        )));
    };
    let (first_frame, last_frame) = (*first_frame, *last_frame);
    let span = last_frame - first_frame + 1;
    if span > MAX_FRAME_SPAN {
        return Err(Error::Invalid(format!(
            "{}: frame numbers from {first_frame} to {last_frame} in {} files: over the {MAX_FRAME_SPAN} frames a folder may span",
            folder.display(),
            files.len()
        )));
    }

    let expect = Expect {
        layout,
        count: Cell::new(layout.map(Layout::len)),
    };
    let mut frames = vec![ViewFrame::default(); span];
    for (frame, path) in &files {
        frames[frame - first_frame] = read_frame(path, &expect)?;
    }

    let layout = match layout {
        Some(layout) => layout,
        None => detect_layout(folder, expect.count.get(), &frames)?,
    };
    for person in frames.iter_mut().flat_map(|f| f.people.iter_mut()) {
        if person.keypoints.is_empty() {
            person.keypoints = vec![[0.0; 3]; layout.len()];
        }
    }
    Ok(CameraKeypoints {
        folder: folder.to_path_buf(),
        layout,
        first_frame,
        frames,
        missing_files: span - files.len(),
    })
}

/// The per-camera keypoint folders of a trial, in camera order:
/// `<trial>/pose-associated/*` if it holds any, else `<trial>/pose/*`, else
/// the trial's own subfolders; only folders holding `.json` files; sorted by
/// name in natural order (`cam2` before `cam10`).
pub fn find_camera_folders(trial: &Path) -> Result<Vec<PathBuf>> {
    // An unreadable trial is an I/O error naming it, not "no folders".
    std::fs::metadata(trial).map_err(|e| Error::io(trial, e))?;
    for place in [
        trial.join("pose-associated"),
        trial.join("pose"),
        trial.to_path_buf(),
    ] {
        if !place.is_dir() {
            continue;
        }
        let mut folders = Vec::new();
        for entry in read_dir(&place)? {
            if entry.is_dir() && !is_hidden(&entry) && holds_json(&entry)? {
                folders.push(entry);
            }
        }
        if !folders.is_empty() {
            folders.sort_by(|a, b| natural_cmp(&file_name(a), &file_name(b)));
            return Ok(folders);
        }
    }
    Err(Error::Invalid(format!(
        "{}: no folder of .json keypoint files in pose-associated/, pose/ or the trial itself",
        trial.display()
    )))
}

/// Writes one frame as OpenPose JSON, atomically, for the camera simulator:
/// `person_id` is `[-1]` for a person with no id (so an id of -1 reads back
/// as none), and the face, hand and 3D arrays are written empty as OpenPose
/// does.
///
/// Refused (nothing written): a non-finite number or a negative score, which
/// the reader would refuse, and people with different keypoint counts.
pub fn write_openpose_frame(path: &Path, people: &[Person2d]) -> Result<()> {
    let invalid = |what: String| Error::Invalid(format!("{}: {what}", path.display()));
    let count = people.iter().map(|p| p.keypoints.len()).find(|&n| n > 0);
    let mut text = String::from("{\"version\":1.3,\"people\":[");
    for (i, person) in people.iter().enumerate() {
        if let Some(count) = count {
            let n = person.keypoints.len();
            if n != 0 && n != count {
                return Err(invalid(format!(
                    "person {i} has {n} keypoints where the people before have {count}"
                )));
            }
        }
        if i > 0 {
            text.push(',');
        }
        let id = person.id.unwrap_or(-1);
        text.push_str(&format!("{{\"person_id\":[{id}],\"pose_keypoints_2d\":["));
        for (k, point) in person.keypoints.iter().enumerate() {
            if !point.iter().all(|v| v.is_finite()) {
                return Err(invalid(format!(
                    "person {i}, keypoint {k}: {point:?} is not finite"
                )));
            }
            if point[2] < 0.0 {
                return Err(invalid(format!(
                    "person {i}, keypoint {k}: negative score {}",
                    point[2]
                )));
            }
            for (c, &value) in point.iter().enumerate() {
                if k > 0 || c > 0 {
                    text.push(',');
                }
                text.push_str(&json_number(value));
            }
        }
        text.push_str(
            "],\"face_keypoints_2d\":[],\"hand_left_keypoints_2d\":[],\
             \"hand_right_keypoints_2d\":[],\"pose_keypoints_3d\":[],\
             \"face_keypoints_3d\":[],\"hand_left_keypoints_3d\":[],\
             \"hand_right_keypoints_3d\":[]}",
        );
    }
    text.push_str("]}\n");
    mocap_core::io::atomic::write_bytes_atomically(path, text.as_bytes())
}

/// `value` as the shortest decimal that reads back to it. The reader parses
/// numbers as f64 and rounds them to f32; in rare cases that double rounding
/// misses the f32 that the shortest f32 decimal stands for, and then the
/// f64's exact digits are written instead.
fn json_number(value: f32) -> String {
    let short = value.to_string();
    if short.parse::<f64>().is_ok_and(|v| v as f32 == value) {
        short
    } else {
        f64::from(value).to_string()
    }
}

// ---------------------------------------------------------------------------
// Files and frame numbers

/// The `.json` files of `folder` with their frame numbers, sorted by frame.
fn keypoint_files(folder: &Path) -> Result<Vec<(usize, PathBuf)>> {
    let mut files = Vec::new();
    for path in read_dir(folder)? {
        if is_hidden(&path) || !is_json(&path) || !path.is_file() {
            continue;
        }
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let frame = frame_number(&stem)
            .map_err(|why| Error::Invalid(format!("{}: {why}", path.display())))?;
        files.push((frame, path));
    }
    files.sort();
    for pair in files.windows(2) {
        if pair[0].0 == pair[1].0 {
            return Err(Error::Invalid(format!(
                "{} and {}: both are frame {}",
                pair[0].1.display(),
                pair[1].1.display(),
                pair[0].0
            )));
        }
    }
    Ok(files)
}

/// The frame number in a file stem: its last run of digits
/// (`cam01.0012` → 12, `video_000012_keypoints` → 12).
fn frame_number(stem: &str) -> std::result::Result<usize, String> {
    let bytes = stem.as_bytes();
    let Some(end) = bytes.iter().rposition(u8::is_ascii_digit) else {
        return Err("no frame number (a run of digits) in the file name".into());
    };
    let start = bytes[..end]
        .iter()
        .rposition(|b| !b.is_ascii_digit())
        .map_or(0, |i| i + 1);
    let digits = &stem[start..=end];
    digits
        .parse()
        .map_err(|_| format!("frame number {digits} is too large"))
}

/// The entries of a folder, as paths.
fn read_dir(folder: &Path) -> Result<Vec<PathBuf>> {
    let io = |e| Error::io(folder, e);
    let mut paths = Vec::new();
    for entry in std::fs::read_dir(folder).map_err(io)? {
        paths.push(entry.map_err(io)?.path());
    }
    Ok(paths)
}

/// Whether a folder holds a `.json` file.
fn holds_json(folder: &Path) -> Result<bool> {
    Ok(read_dir(folder)?
        .iter()
        .any(|p| !is_hidden(p) && is_json(p) && p.is_file()))
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Dot files are skipped: editors' and our own atomic writes' temporary
/// files (`.cam01.0012.json.PID.tmp`) live beside the data.
fn is_hidden(path: &Path) -> bool {
    file_name(path).starts_with('.')
}

fn is_json(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
}

/// Names compared with their runs of digits as numbers: `cam2` < `cam10`.
/// Names that differ only in leading zeros (`cam01`, `cam1`) fall back on
/// plain order, so that the order is total.
fn natural_cmp(a: &str, b: &str) -> Ordering {
    fn digit_run(s: &[u8]) -> (&[u8], &[u8]) {
        let n = s.iter().take_while(|b| b.is_ascii_digit()).count();
        s.split_at(n)
    }
    let (mut x, mut y) = (a.as_bytes(), b.as_bytes());
    loop {
        match (x.first(), y.first()) {
            (None, None) => return a.cmp(b),
            (None, Some(_)) => return Ordering::Less,
            (Some(_), None) => return Ordering::Greater,
            (Some(c), Some(d)) if c.is_ascii_digit() && d.is_ascii_digit() => {
                let ((m, rest_x), (n, rest_y)) = (digit_run(x), digit_run(y));
                let m = &m[m.iter().take_while(|&&b| b == b'0').count()..];
                let n = &n[n.iter().take_while(|&&b| b == b'0').count()..];
                // Without leading zeros, the longer run is the larger number.
                let order = m.len().cmp(&n.len()).then_with(|| m.cmp(n));
                if order != Ordering::Equal {
                    return order;
                }
                (x, y) = (rest_x, rest_y);
            }
            (Some(c), Some(d)) => {
                if c != d {
                    return c.cmp(d);
                }
                (x, y) = (&x[1..], &y[1..]);
            }
        }
    }
}

// ---------------------------------------------------------------------------
// One file

/// Reads one frame's file, checking every person against `expect`.
fn read_frame(path: &Path, expect: &Expect) -> Result<ViewFrame> {
    let too_big = |size: u64| {
        Error::Invalid(format!(
            "{}: {size} bytes: over the {} MiB a keypoint file may have",
            path.display(),
            MAX_FILE_BYTES >> 20
        ))
    };
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let size = file.metadata().map_err(|e| Error::io(path, e))?.len();
    if size > MAX_FILE_BYTES {
        return Err(too_big(size));
    }
    // The size was checked, but the file can grow while it is read.
    let mut bytes = Vec::with_capacity(size as usize);
    file.take(MAX_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Error::io(path, e))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(too_big(bytes.len() as u64));
    }
    // A byte-order mark, as some Windows tools write, is not JSON. (Columns
    // on the first line then count from after it.)
    let text = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes);

    let mut deserializer = serde_json::Deserializer::from_slice(text);
    FrameSeed(expect)
        .deserialize(&mut deserializer)
        .and_then(|frame| deserializer.end().map(|()| frame))
        .map_err(|e| json_error(path, &e, ""))
}

/// A serde_json error as a parse error at its line and column, its message
/// after `prefix` (for the calibration's JSON reader too).
pub(crate) fn json_error(path: &Path, error: &serde_json::Error, prefix: &str) -> Error {
    let (line, column) = (error.line(), error.column());
    // serde_json's message ends with " at line L column C"; the location is
    // given apart.
    let message = error.to_string();
    let message = message
        .strip_suffix(&format!(" at line {line} column {column}"))
        .unwrap_or(&message);
    Error::parse(
        path,
        line.max(1),
        column.max(1),
        format!("{prefix}{message}"),
    )
}

/// The keypoint count every person must have: the layout's, else the count
/// of the first person read in the folder (which must be some layout's).
struct Expect {
    layout: Option<Layout>,
    count: Cell<Option<usize>>,
}

impl Expect {
    fn check(&self, count: usize) -> std::result::Result<(), String> {
        match (self.count.get(), self.layout) {
            (Some(expected), _) if expected == count => Ok(()),
            (Some(expected), Some(layout)) => {
                Err(format!("{count} keypoints, where {layout} has {expected}"))
            }
            (Some(expected), None) => Err(format!(
                "{count} keypoints, where the people before have {expected}"
            )),
            (None, _) if Layout::ALL.iter().any(|l| l.len() == count) => {
                self.count.set(Some(count));
                Ok(())
            }
            (None, _) => Err(format!(
                "{count} keypoints: no known layout has that many (COCO_17: 17, \
                 BODY_25 and BODY_25B: 25, HALPE_26: 26, BLAZEPOSE: 33)"
            )),
        }
    }
}

/// The file's top-level object.
struct FrameSeed<'a>(&'a Expect);

impl<'de> DeserializeSeed<'de> for FrameSeed<'_> {
    type Value = ViewFrame;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<ViewFrame, D::Error> {
        deserializer.deserialize_map(self)
    }
}

impl<'de> Visitor<'de> for FrameSeed<'_> {
    type Value = ViewFrame;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an OpenPose keypoint object with a \"people\" list")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<ViewFrame, A::Error> {
        let mut people = None;
        while let Some(key) = map.next_key::<String>()? {
            if key == "people" {
                if people.is_some() {
                    return Err(de::Error::duplicate_field("people"));
                }
                people = Some(map.next_value_seed(PeopleSeed(self.0))?);
            } else {
                map.next_value::<IgnoredAny>()?;
            }
        }
        let people = people.ok_or_else(|| de::Error::missing_field("people"))?;
        Ok(ViewFrame { people })
    }
}

/// The `people` list.
struct PeopleSeed<'a>(&'a Expect);

impl<'de> DeserializeSeed<'de> for PeopleSeed<'_> {
    type Value = Vec<Person2d>;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<Self::Value, D::Error> {
        deserializer.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for PeopleSeed<'_> {
    type Value = Vec<Person2d>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a list of people")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut people = Vec::new();
        while let Some(person) = seq.next_element_seed(PersonSeed(self.0))? {
            people.push(person);
        }
        Ok(people)
    }
}

/// One person: `person_id` and `pose_keypoints_2d`; either may be absent
/// (Pose2Sim writes `{}` for a participant not seen).
struct PersonSeed<'a>(&'a Expect);

impl<'de> DeserializeSeed<'de> for PersonSeed<'_> {
    type Value = Person2d;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<Person2d, D::Error> {
        deserializer.deserialize_map(self)
    }
}

impl<'de> Visitor<'de> for PersonSeed<'_> {
    type Value = Person2d;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a person: an object with \"pose_keypoints_2d\"")
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Person2d, A::Error> {
        let mut id = None;
        let mut keypoints = None;
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "person_id" => {
                    if id.is_some() {
                        return Err(de::Error::duplicate_field("person_id"));
                    }
                    id = Some(map.next_value::<PersonId>()?.0);
                }
                "pose_keypoints_2d" => {
                    if keypoints.is_some() {
                        return Err(de::Error::duplicate_field("pose_keypoints_2d"));
                    }
                    keypoints = Some(map.next_value_seed(KeypointsSeed(self.0))?);
                }
                _ => {
                    map.next_value::<IgnoredAny>()?;
                }
            }
        }
        Ok(Person2d {
            id: id.flatten(),
            keypoints: keypoints.unwrap_or_default(),
        })
    }
}

/// `pose_keypoints_2d`: x, y, score triples, checked as they come.
struct KeypointsSeed<'a>(&'a Expect);

impl<'de> DeserializeSeed<'de> for KeypointsSeed<'_> {
    type Value = Vec<[f32; 3]>;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<Self::Value, D::Error> {
        deserializer.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for KeypointsSeed<'_> {
    type Value = Vec<[f32; 3]>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a list of numbers: x, y, score per keypoint")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut keypoints = Vec::new();
        let mut point = [0.0f32; 3];
        let mut n = 0usize;
        while let Some(value) = seq.next_element::<f64>()? {
            let (k, c) = (n / 3, n % 3);
            let narrow = value as f32;
            if !narrow.is_finite() {
                return Err(de::Error::custom(format!(
                    "keypoint {k}: {value} does not fit a 32-bit float"
                )));
            }
            if c == 2 && narrow < 0.0 {
                return Err(de::Error::custom(format!(
                    "keypoint {k}: negative score {value}"
                )));
            }
            // Scores are 0..1; OpenPose's heat-map peaks can top 1 a little.
            point[c] = if c == 2 { narrow.min(1.0) } else { narrow };
            if c == 2 {
                keypoints.push(point);
            }
            n += 1;
        }
        if n != keypoints.len() * 3 {
            return Err(de::Error::custom(format!(
                "{n} numbers: not (x, y, score) triples"
            )));
        }
        // No numbers at all is a person with nothing detected, in any layout.
        if n > 0 {
            self.0.check(keypoints.len()).map_err(de::Error::custom)?;
        }
        Ok(keypoints)
    }
}

/// `person_id`: OpenPose writes `[-1]` (no id); a bare number or `null` is
/// taken too. -1 is no id.
struct PersonId(Option<i64>);

impl<'de> de::Deserialize<'de> for PersonId {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<PersonId, D::Error> {
        deserializer.deserialize_any(PersonIdVisitor)
    }
}

struct PersonIdVisitor;

impl<'de> Visitor<'de> for PersonIdVisitor {
    type Value = PersonId;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a person id: an integer or a list holding one")
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<PersonId, E> {
        Ok(PersonId((v != -1).then_some(v)))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<PersonId, E> {
        let v = i64::try_from(v).map_err(|_| E::custom(format!("person id {v} is too large")))?;
        self.visit_i64(v)
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<PersonId, E> {
        // Python writers give `[1.0]` from float arrays.
        if v.fract() == 0.0 && v.abs() < 2f64.powi(53) {
            self.visit_i64(v as i64)
        } else {
            Err(E::custom(format!("person id {v} is not an integer")))
        }
    }

    fn visit_unit<E: de::Error>(self) -> Result<PersonId, E> {
        Ok(PersonId(None))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<PersonId, A::Error> {
        let first = seq.next_element::<PersonId>()?;
        while seq.next_element::<IgnoredAny>()?.is_some() {}
        Ok(first.unwrap_or(PersonId(None)))
    }
}

// ---------------------------------------------------------------------------
// Layout detection

/// The layout of a folder read without one, from the keypoint count of its
/// people (`count`; `None` when no file holds a person).
fn detect_layout(folder: &Path, count: Option<usize>, frames: &[ViewFrame]) -> Result<Layout> {
    let Some(count) = count else {
        return Err(Error::Invalid(format!(
            "{}: no person in any file, so the keypoint layout cannot be detected: give it",
            folder.display()
        )));
    };
    let candidates: Vec<Layout> = Layout::ALL
        .into_iter()
        .filter(|l| l.len() == count)
        .collect();
    match candidates[..] {
        [layout] => Ok(layout),
        _ => detect_body_25(folder, frames),
    }
}

/// Tells BODY_25 from BODY_25B, which both have 25 keypoints, from the
/// keypoints themselves: read in the right layout, the bones of the body tree
/// ([`crate::layout::CANONICAL_PARENTS`]) join neighbouring points (a knee to
/// its hip, a heel to its ankle); read in the wrong one, they join points
/// across the body (BODY_25B's keypoint 8, the right elbow, would be
/// BODY_25's mid-hip; its 14, a knee, BODY_25's left ankle). So for each
/// person with enough confident keypoints, the median bone is measured under
/// both layouts, and the layout whose bones are shorter over the folder's
/// people (the median of the log ratios) is chosen, when it is clearly so.
///
/// The mid-hip alone (BODY_25's keypoint 8 lies midway between its 9 and 12,
/// BODY_25B's does not) was not enough: in side views of real BODY_25B
/// captures keypoint 8 often lies near that middle too.
fn detect_body_25(folder: &Path, frames: &[ViewFrame]) -> Result<Layout> {
    /// People measured below this are too few to trust.
    const MIN_PEOPLE: usize = 3;
    /// The median bone must be this much shorter in one layout: real
    /// captures give a factor of 1.7 to 3.5 (log 0.5 to 1.3).
    const MARGIN: f32 = 0.4; // ln 1.5

    let body_25 = Layout::Body25.bones();
    let body_25b = Layout::Body25B.bones();
    let mut log_ratios: Vec<f32> = frames
        .iter()
        .flat_map(|f| &f.people)
        .filter_map(|person| {
            let a = median_bone(&person.keypoints, &body_25)?;
            let b = median_bone(&person.keypoints, &body_25b)?;
            (a > 0.0 && b > 0.0).then(|| (a / b).ln())
        })
        .collect();
    let undecided = |why: String| {
        Error::Invalid(format!(
            "{}: 25 keypoints per person, but {why}: cannot tell BODY_25 from BODY_25B; give the layout",
            folder.display()
        ))
    };
    if log_ratios.len() < MIN_PEOPLE {
        return Err(undecided(format!(
            "only {} people with enough confident keypoints",
            log_ratios.len()
        )));
    }
    log_ratios.sort_by(f32::total_cmp);
    let median = log_ratios[log_ratios.len() / 2];
    if median < -MARGIN {
        Ok(Layout::Body25)
    } else if median > MARGIN {
        Ok(Layout::Body25B)
    } else {
        Err(undecided(format!(
            "the body's bones are about as long read either way (median ratio {:.2})",
            median.exp()
        )))
    }
}

/// The median length of the `bones` whose both ends are confident; `None`
/// when the person has too few confident keypoints to say.
fn median_bone(keypoints: &[[f32; 3]], bones: &[(usize, usize)]) -> Option<f32> {
    let confident = |i: usize| keypoints.get(i).filter(|p| p[2] >= CONFIDENT);
    if keypoints.iter().filter(|p| p[2] >= CONFIDENT).count() < 8 {
        return None;
    }
    let mut lengths: Vec<f32> = bones
        .iter()
        .filter_map(|&(a, b)| {
            let (p, q) = (confident(a)?, confident(b)?);
            Some((p[0] - q[0]).hypot(p[1] - q[1]))
        })
        .collect();
    if lengths.len() < 5 {
        return None;
    }
    lengths.sort_by(f32::total_cmp);
    Some(lengths[lengths.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;

    const BALANCING: &str = "pose2sim-demo/S00_P00_SingleParticipant/S00_P00_T01_BalancingTrial";
    const TWO_PEOPLE: &str = "pose2sim-demo/S00_P01_MultiParticipants/S00_P01_T02_Participants1-2";

    /// A folder of the shared data, or `None` (with a note) without it.
    fn shared_dir(relative: &str) -> Option<PathBuf> {
        let dir = mocap_testdata::shared(relative)?;
        if dir.is_dir() {
            Some(dir)
        } else {
            eprintln!("note: {} not found; skipping", dir.display());
            None
        }
    }

    fn parse_error(e: &Error) -> &mocap_core::ParseError {
        match e {
            Error::Parse(p) => p,
            other => panic!("expected a parse error, got {other}"),
        }
    }

    /// A person of `n` keypoints at made-up places, all seen.
    fn person(n: usize, id: Option<i64>) -> Person2d {
        Person2d {
            id,
            keypoints: (0..n)
                .map(|k| [10.0 + k as f32, 200.0 - k as f32 * 0.5, 0.75])
                .collect(),
        }
    }

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    /// The checks of image geometry on a person standing upright: pairs
    /// (above, below) in image y (which grows downward).
    const UPRIGHT: [(&str, &str); 12] = [
        ("Head", "Nose"),
        ("Head", "Neck"),
        ("Neck", "LHip"),
        ("Neck", "RHip"),
        ("LHip", "LKnee"),
        ("RHip", "RKnee"),
        ("LKnee", "LAnkle"),
        ("RKnee", "RAnkle"),
        ("LKnee", "LHeel"),
        ("RKnee", "RHeel"),
        ("LKnee", "LBigToe"),
        ("RKnee", "RBigToe"),
    ];

    #[test]
    fn the_balancing_trial_reads_as_body_25b_with_an_upright_body() {
        let Some(trial) = shared_dir(BALANCING) else {
            return;
        };
        let associated = find_camera_folders(&trial).unwrap();
        let names: Vec<String> = associated.iter().map(|p| file_name(p)).collect();
        assert_eq!(
            names,
            ["cam01_json", "cam02_json", "cam03_json", "cam04_json"]
        );
        assert!(associated
            .iter()
            .all(|p| p.parent().unwrap().ends_with("pose-associated")));
        let raw: Vec<PathBuf> = names.iter().map(|n| trial.join("pose").join(n)).collect();

        for folder in associated.iter().chain(&raw) {
            let camera = read_openpose_folder(folder, None).unwrap();
            let layout = camera.layout;
            assert_eq!(layout, Layout::Body25B, "{}", folder.display());
            assert_eq!(camera.frames.len(), 100);
            assert_eq!((camera.first_frame, camera.missing_files), (0, 0));
            assert!(camera.frames.iter().any(|f| !f.people.is_empty()));

            // Every confident pair of the upright checks, on every person: a
            // wrong order (BODY_25's, or a mixed-up table) puts the feet or
            // the hips out of place.
            let (mut held, mut failed) = (0, 0);
            for person in camera.frames.iter().flat_map(|f| &f.people) {
                assert_eq!(person.keypoints.len(), 25);
                for (above, below) in UPRIGHT {
                    let p = person.keypoints[layout.index_of(above).unwrap()];
                    let q = person.keypoints[layout.index_of(below).unwrap()];
                    if p[2] < 0.5 || q[2] < 0.5 {
                        continue;
                    }
                    if p[1] < q[1] {
                        held += 1;
                    } else {
                        failed += 1;
                    }
                }
            }
            assert!(held >= 500, "{}: {held} checks", folder.display());
            assert!(
                failed * 50 <= held,
                "{}: {failed} of {} upright checks failed",
                folder.display(),
                held + failed
            );
        }
    }

    #[test]
    fn the_two_person_trial_has_frames_with_two_people() {
        let Some(trial) = shared_dir(TWO_PEOPLE) else {
            return;
        };
        let pose = trial.join("pose");
        for camera in ["cam01_json", "cam02_json", "cam03_json", "cam04_json"] {
            let keypoints = read_openpose_folder(&pose.join(camera), None).unwrap();
            assert_eq!(keypoints.layout, Layout::Body25B);
            assert_eq!(keypoints.frames.len(), 100);
            let two = keypoints
                .frames
                .iter()
                .filter(|f| f.people.len() >= 2)
                .count();
            assert!(two >= 90, "{camera}: {two} frames with two people or more");
        }
        // cam01's frame 1 holds a person written with no keypoints: kept, as
        // nothing detected.
        let cam01 = read_openpose_folder(&pose.join("cam01_json"), None).unwrap();
        let empty = &cam01.frames[1].people[0];
        assert_eq!(empty.keypoints, vec![[0.0; 3]; 25]);
        assert_eq!(empty.id, None);

        // The associated files keep a place per participant, `{}` when one
        // is not seen.
        let associated = find_camera_folders(&trial).unwrap();
        let cam01 = read_openpose_folder(&associated[0], Some(Layout::Body25B)).unwrap();
        let frame = &cam01.frames[0].people;
        assert_eq!(frame.len(), 2);
        assert!(frame[0].keypoints.iter().any(|p| p[2] > 0.0));
        assert_eq!(frame[1].keypoints, vec![[0.0; 3]; 25]);
    }

    /// A BODY_25B person in BODY_25's order, as OpenPose's BODY_25 model
    /// would have written it: the mid-hip, which BODY_25B lacks, midway
    /// between the hips.
    fn as_body_25(person: &Person2d) -> Person2d {
        let from = |name: &str| person.keypoints[Layout::Body25B.index_of(name).unwrap()];
        let keypoints = Layout::Body25
            .names()
            .iter()
            .map(|&name| match name {
                "MidHip" => {
                    let (l, r) = (from("LHip"), from("RHip"));
                    [(l[0] + r[0]) / 2.0, (l[1] + r[1]) / 2.0, l[2].min(r[2])]
                }
                _ => from(name),
            })
            .collect();
        Person2d {
            id: person.id,
            keypoints,
        }
    }

    #[test]
    fn detection_tells_body_25_from_body_25b() {
        let Some(trial) = shared_dir(BALANCING) else {
            return;
        };
        let dir = tempfile::tempdir().unwrap();
        let (b25, b25b) = (dir.path().join("b25"), dir.path().join("b25b"));
        std::fs::create_dir(&b25).unwrap();
        std::fs::create_dir(&b25b).unwrap();
        // A few frames of two views, one clip after the other: enough, as in
        // a short capture.
        for (c, camera) in ["cam01_json", "cam03_json"].into_iter().enumerate() {
            let real = read_openpose_folder(&trial.join("pose").join(camera), None).unwrap();
            for (n, frame) in real.frames.iter().enumerate().step_by(20) {
                let name = format!("clip.{:04}.json", c * 100 + n);
                write_openpose_frame(&b25b.join(&name), &frame.people).unwrap();
                let permuted: Vec<Person2d> = frame.people.iter().map(as_body_25).collect();
                write_openpose_frame(&b25.join(&name), &permuted).unwrap();
            }
        }
        assert_eq!(
            read_openpose_folder(&b25b, None).unwrap().layout,
            Layout::Body25B
        );
        assert_eq!(
            read_openpose_folder(&b25, None).unwrap().layout,
            Layout::Body25
        );
        // Given, the layout is taken as is.
        assert_eq!(
            read_openpose_folder(&b25, Some(Layout::Body25B))
                .unwrap()
                .layout,
            Layout::Body25B
        );
    }

    #[test]
    fn detection_by_count_and_when_undecidable() {
        let dir = tempfile::tempdir().unwrap();
        for (n, layout) in [
            (17, Layout::Coco17),
            (26, Layout::Halpe26),
            (33, Layout::BlazePose33),
        ] {
            let folder = dir.path().join(format!("n{n}"));
            std::fs::create_dir(&folder).unwrap();
            write_openpose_frame(&folder.join("f_0.json"), &[person(n, None)]).unwrap();
            assert_eq!(read_openpose_folder(&folder, None).unwrap().layout, layout);
        }

        // 25 keypoints none of which is confident: no way to tell.
        let folder = dir.path().join("unsure");
        std::fs::create_dir(&folder).unwrap();
        let mut unsure = person(25, None);
        unsure.keypoints.iter_mut().for_each(|p| p[2] = 0.1);
        for frame in 0..5 {
            write_openpose_frame(&folder.join(format!("f_{frame}.json")), &[unsure.clone()])
                .unwrap();
        }
        let e = read_openpose_folder(&folder, None).unwrap_err().to_string();
        assert!(
            e.contains("BODY_25B") && e.contains("give the layout"),
            "{e}"
        );
        let read = read_openpose_folder(&folder, Some(Layout::Body25)).unwrap();
        assert_eq!(read.frames.len(), 5);

        // No person anywhere: nothing to detect from.
        let folder = dir.path().join("nobody");
        std::fs::create_dir(&folder).unwrap();
        write(&folder, "f_0.json", r#"{"version":1.3,"people":[]}"#);
        let e = read_openpose_folder(&folder, None).unwrap_err().to_string();
        assert!(e.contains("no person"), "{e}");
        let read = read_openpose_folder(&folder, Some(Layout::Coco17)).unwrap();
        assert_eq!(read.frames, [ViewFrame::default()]);
    }

    #[test]
    fn a_truncated_file_is_named_with_its_line_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let text = "{\n  \"version\": 1.3,\n  \"people\": [\n    {\"person_id\": [-1],\n     \"pose_keypoints_2d\": [1.5, 2.5, 0.9, 3.5, 4";
        let path = write(dir.path(), "cam.0007.json", text);
        let e = read_openpose_folder(dir.path(), None).unwrap_err();
        let p = parse_error(&e);
        assert_eq!(p.location.path, path);
        // The end of the text: line 5, after its last character.
        let last_line = text.lines().last().unwrap();
        assert_eq!(p.location.line, 5);
        assert_eq!(p.location.column, last_line.len());
        assert!(p.message.contains("EOF"), "{}", p.message);
        let shown = e.to_string();
        assert!(
            shown.contains(&format!("cam.0007.json:5:{}", last_line.len())),
            "{shown}"
        );
    }

    #[test]
    fn bad_keypoint_lists_are_refused_with_their_place() {
        let dir = tempfile::tempdir().unwrap();
        // One person's `pose_keypoints_2d` holding `list`.
        let one = |list: &str| format!("{{\"people\":[{{\"pose_keypoints_2d\":[{list}]}}]}}");
        let ones = |n: usize| vec!["1.0"; n].join(",");
        let (coco, body) = (ones(51), ones(75));
        // (file, layout given, words of the message)
        let cases = [
            (one(&ones(74)), None, "not (x, y, score) triples"),
            (one(&ones(60)), None, "no known layout"),
            (one(&coco), Some(Layout::Body25B), "where BODY_25B has 25"),
            (one("1, 2, -0.5"), None, "negative score"),
            (one("1e39, 2, 0.5"), None, "32-bit float"),
            (one("1e999, 2, 0.5"), None, "out of range"),
            (one("NaN, 2, 0.5"), None, "expected value"),
            (one("null, 2, 0.5"), None, "invalid type"),
            (
                r#"{"people":[{"person_id":"seven"}]}"#.into(),
                None,
                "person id",
            ),
            (r#"{"version":1.3}"#.into(), None, "missing field `people`"),
            ("[1, 2, 3]".into(), None, "invalid type"),
            (
                r#"{"people":[]} trailing"#.into(),
                None,
                "trailing characters",
            ),
        ];
        for (i, (text, layout, expected)) in cases.iter().enumerate() {
            let folder = dir.path().join(format!("case{i}"));
            std::fs::create_dir(&folder).unwrap();
            let path = write(&folder, "x_0001.json", text);
            let e = read_openpose_folder(&folder, *layout).unwrap_err();
            let p = parse_error(&e);
            assert_eq!(p.location.path, path, "case {i}");
            assert_eq!(p.location.line, 1, "case {i}: {e}");
            assert!(p.location.column >= 1, "case {i}: {e}");
            assert!(p.message.contains(expected), "case {i}: {e}");
        }

        // People of two layouts in one folder: the second is refused, at the
        // end of its list on line 3 of the second file.
        let folder = dir.path().join("mixed");
        std::fs::create_dir(&folder).unwrap();
        write(&folder, "x_1.json", &one(&coco));
        let text = format!(
            "{{\"people\":[\n{{\"pose_keypoints_2d\":[{coco}]}},\n{{\"pose_keypoints_2d\":[{body}]}}]}}"
        );
        let path = write(&folder, "x_2.json", &text);
        let e = read_openpose_folder(&folder, None).unwrap_err();
        let p = parse_error(&e);
        assert_eq!((&p.location.path, p.location.line), (&path, 3), "{e}");
        // At the list's closing bracket, after `{"pose_keypoints_2d":[` and
        // the list.
        assert_eq!(p.location.column, 22 + body.len() + 1, "{e}");
        assert!(p.message.contains("where the people before have 17"), "{e}");
    }

    #[test]
    fn folders_without_usable_files_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        // No JSON at all (a dot file and another extension do not count).
        write(dir.path(), "notes.txt", "hello");
        write(dir.path(), ".cam.0001.json.123.tmp", "{}");
        write(dir.path(), ".hidden_0001.json", "{}");
        let e = read_openpose_folder(dir.path(), None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no .json keypoint files"), "{e}");

        let e = read_openpose_folder(&dir.path().join("absent"), None).unwrap_err();
        assert!(matches!(e, Error::Io { .. }), "{e}");

        // Two files of one frame.
        let empty = r#"{"people":[]}"#;
        let twice = dir.path().join("twice");
        std::fs::create_dir(&twice).unwrap();
        write(&twice, "a_12.json", empty);
        write(&twice, "b_0012.json", empty);
        let e = read_openpose_folder(&twice, None).unwrap_err().to_string();
        assert!(e.contains("both are frame 12"), "{e}");

        // A file with no frame number.
        let unnumbered = dir.path().join("unnumbered");
        std::fs::create_dir(&unnumbered).unwrap();
        write(&unnumbered, "keypoints.json", empty);
        let e = read_openpose_folder(&unnumbered, None)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no frame number"), "{e}");

        // Frame numbers too far apart to hold as frames.
        let far = dir.path().join("far");
        std::fs::create_dir(&far).unwrap();
        write(&far, "f_0.json", empty);
        write(&far, "f_99999999999.json", empty);
        let e = read_openpose_folder(&far, None).unwrap_err().to_string();
        assert!(e.contains("may span"), "{e}");
        write(&far, "f_99999999999999999999999.json", empty);
        let e = read_openpose_folder(&far, None).unwrap_err().to_string();
        assert!(e.contains("too large"), "{e}");

        // A file over the size limit is refused unread (a sparse file).
        let big = dir.path().join("big");
        std::fs::create_dir(&big).unwrap();
        let file = std::fs::File::create(big.join("f_1.json")).unwrap();
        file.set_len(MAX_FILE_BYTES + 1).unwrap();
        let e = read_openpose_folder(&big, None).unwrap_err().to_string();
        assert!(e.contains("64 MiB"), "{e}");
    }

    #[test]
    fn frame_numbers_are_the_last_run_of_digits_and_gaps_are_empty_frames() {
        assert_eq!(frame_number("anything_000012_keypoints"), Ok(12));
        assert_eq!(frame_number("cam01.0012"), Ok(12));
        assert_eq!(frame_number("Static_cam_01.00003"), Ok(3));
        assert_eq!(frame_number("7"), Ok(7));
        assert!(frame_number("keypoints").is_err());

        let dir = tempfile::tempdir().unwrap();
        let one = [person(17, Some(4))];
        for frame in [5, 6, 9] {
            write_openpose_frame(
                &dir.path().join(format!("v_{frame:06}_keypoints.json")),
                &one,
            )
            .unwrap();
        }
        let read = read_openpose_folder(dir.path(), None).unwrap();
        assert_eq!(read.folder, dir.path());
        assert_eq!(
            (read.first_frame, read.frames.len(), read.missing_files),
            (5, 5, 2)
        );
        let seen: Vec<usize> = read.frames.iter().map(|f| f.people.len()).collect();
        assert_eq!(seen, [1, 1, 0, 0, 1]);
    }

    #[test]
    fn a_written_frame_reads_back_equal() {
        let dir = tempfile::tempdir().unwrap();
        // Awkward numbers: thirds, tiny, large, negative (off-image) pixels.
        let mut first = person(26, Some(3));
        first.keypoints[0] = [1.0 / 3.0, -42.369_86, 0.0];
        first.keypoints[1] = [1e-7, 123_456.79, 1.0];
        first.keypoints[2] = [f32::MAX, f32::MIN_POSITIVE, 0.1];
        let people = vec![
            first,
            person(26, None),
            Person2d {
                id: Some(0),
                keypoints: vec![],
            },
        ];
        write_openpose_frame(&dir.path().join("cam.0000.json"), &people).unwrap();
        write_openpose_frame(&dir.path().join("cam.0001.json"), &[]).unwrap();

        let read = read_openpose_folder(dir.path(), None).unwrap();
        assert_eq!(read.layout, Layout::Halpe26);
        let mut expected = people.clone();
        // The person with no keypoints reads back as 26 undetected ones.
        expected[2].keypoints = vec![[0.0; 3]; 26];
        assert_eq!(read.frames[0].people, expected);
        assert_eq!(read.frames[1], ViewFrame::default());

        // Exactly the same numbers, for many values, not just close ones.
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let values: Vec<[f32; 3]> = (0..2000)
            .map(|_| {
                let mut next = || {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    f32::from_bits((state >> 32) as u32 & 0x7f7f_ffff)
                };
                let x = next();
                [x, -next(), (next() / f32::MAX).abs()]
            })
            .filter(|p| p.iter().all(|v| v.is_finite()))
            .collect();
        let chunks: Vec<Person2d> = values[..33 * 40]
            .chunks(33)
            .map(|c| Person2d {
                id: None,
                keypoints: c.to_vec(),
            })
            .collect();
        let folder = dir.path().join("many");
        std::fs::create_dir(&folder).unwrap();
        write_openpose_frame(&folder.join("m_1.json"), &chunks).unwrap();
        let read = read_openpose_folder(&folder, None).unwrap();
        assert_eq!(read.frames[0].people, chunks);
    }

    #[test]
    fn writing_refuses_what_reading_would() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x_1.json");
        let mut bad = person(17, None);
        bad.keypoints[3][0] = f32::NAN;
        assert!(write_openpose_frame(&path, &[bad]).is_err());
        let mut bad = person(17, None);
        bad.keypoints[3][2] = -0.1;
        assert!(write_openpose_frame(&path, &[bad]).is_err());
        assert!(write_openpose_frame(&path, &[person(17, None), person(25, None)]).is_err());
        assert!(!path.exists());
    }

    #[test]
    fn scores_above_one_are_capped_and_ids_take_several_forms() {
        let dir = tempfile::tempdir().unwrap();
        let points = vec!["1, 2, 1.02"; 17].join(",");
        let text = format!(
            "\u{feff}{{\"people\":[{{\"person_id\":[5],\"pose_keypoints_2d\":[{points}]}},\
             {{\"person_id\":7}},{{\"person_id\":null}},{{\"person_id\":[2.0, 9]}},{{\"person_id\":[]}}]}}"
        );
        write(dir.path(), "f_3.json", &text);
        let read = read_openpose_folder(dir.path(), None).unwrap();
        let people = &read.frames[0].people;
        assert_eq!(people[0].keypoints[16], [1.0, 2.0, 1.0]);
        let ids: Vec<Option<i64>> = people.iter().map(|p| p.id).collect();
        assert_eq!(ids, [Some(5), Some(7), None, Some(2), None]);
    }

    #[test]
    fn damaged_files_give_errors_never_panics() {
        let Some(trial) = shared_dir(BALANCING) else {
            return;
        };
        let original = std::fs::read(trial.join("pose/cam01_json/cam01.0000.json")).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f_0.json");
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut refused = 0;
        for _ in 0..300 {
            let mut bytes = original.clone();
            for _ in 0..1 + next() % 4 {
                if bytes.is_empty() {
                    break;
                }
                let at = (next() % bytes.len() as u64) as usize;
                match next() % 3 {
                    0 => bytes[at] = b"{}[],:-.0123456789eE\"x "[(next() % 23) as usize],
                    1 => {
                        bytes.remove(at);
                    }
                    _ => bytes.truncate(at),
                }
            }
            std::fs::write(&path, &bytes).unwrap();
            if read_openpose_folder(dir.path(), Some(Layout::Body25B)).is_err() {
                refused += 1;
            }
        }
        assert!(refused > 100, "{refused}");
    }

    #[test]
    fn camera_folders_come_from_pose_associated_then_pose_then_the_trial() {
        let trial = tempfile::tempdir().unwrap();
        let t = trial.path();
        let empty = r#"{"people":[]}"#;
        for cam in ["cam10", "cam2", "cam1"] {
            std::fs::create_dir_all(t.join("pose").join(cam)).unwrap();
            write(&t.join("pose").join(cam), "f_0.json", empty);
        }
        // Not cameras: a folder with no JSON, a dot folder.
        std::fs::create_dir_all(t.join("pose/videos")).unwrap();
        std::fs::create_dir_all(t.join("pose/.cache")).unwrap();
        write(&t.join("pose/.cache"), "f_0.json", empty);
        // pose-associated without cameras does not hide pose.
        std::fs::create_dir_all(t.join("pose-associated")).unwrap();
        let names = |folders: Vec<PathBuf>| -> Vec<String> {
            folders.iter().map(|p| file_name(p)).collect()
        };
        assert_eq!(
            names(find_camera_folders(t).unwrap()),
            ["cam1", "cam2", "cam10"]
        );
        std::fs::create_dir_all(t.join("pose-associated/camB")).unwrap();
        write(&t.join("pose-associated/camB"), "f_0.json", empty);
        assert_eq!(names(find_camera_folders(t).unwrap()), ["camB"]);

        let flat = tempfile::tempdir().unwrap();
        for cam in ["c_json_3", "c_json_1"] {
            std::fs::create_dir(flat.path().join(cam)).unwrap();
            write(&flat.path().join(cam), "f_0.json", empty);
        }
        assert_eq!(
            names(find_camera_folders(flat.path()).unwrap()),
            ["c_json_1", "c_json_3"]
        );

        let bare = tempfile::tempdir().unwrap();
        let e = find_camera_folders(bare.path()).unwrap_err().to_string();
        assert!(e.contains("no folder of .json"), "{e}");
        assert!(find_camera_folders(&bare.path().join("absent")).is_err());
    }

    #[test]
    fn natural_order_compares_numbers_as_numbers() {
        let mut names = vec!["cam10", "cam2", "cam1", "cam01", "Cam3", "cam2b", "cam"];
        names.sort_by(|a, b| natural_cmp(a, b));
        assert_eq!(
            names,
            ["Cam3", "cam", "cam01", "cam1", "cam2", "cam2b", "cam10"]
        );
    }
}
