//! Sensor recordings: what one depth sensor saw, frame after frame.
//!
//! # The recording format (`.jsonl`, version 1)
//!
//! One JSON object per line, one line per frame per sensor:
//!
//! ```json
//! {"v":1,"sensor":2,"seq":17,"t":0.5667,"arrival":0.6301,"joints":[[0.01,0.32,2.51,2], ...]}
//! ```
//!
//! | key | type | meaning |
//! | --- | --- | --- |
//! | `v` | integer | format version, `1` (optional, 1 when absent) |
//! | `sensor` | integer | sensor id, `0..=65535` |
//! | `seq` | integer | the sensor's frame counter; gaps are dropped frames |
//! | `t` | number | capture time in seconds on the shared clock |
//! | `arrival` | number | optional: when the frame reached the sensor's computer (seconds, same clock); `t` plus the sensor's latency. `send --realtime` sends each frame at this time |
//! | `joints` | array of 25 `[x, y, z, state]` | joint positions in metres in the sensor's camera space (Kinect convention: z forward out of the lens, y up, x to the sensor's left) and tracking state 0 NotTracked, 1 Inferred, 2 Tracked, in Kinect v2 SDK joint order ([`crate::kinect::JOINT_NAMES`]) |
//!
//! Several sensors may share one file; lines need not be sorted.
//!
//! # NTU RGB+D `.skeleton` files
//!
//! [`read_ntu_skeleton`] reads the plain-text Kinect v2 captures of the NTU
//! RGB+D data set (several bodies per frame, no times); [`choose_ntu_body`]
//! finds the performer among the bodies (the track that moves most among
//! those in view most of the take, with a body id that changes mid-take
//! stitched back into one track) and [`ntu_sensor_frames`] keeps them as a
//! recording of one sensor: frame `i` of the file is frame `seq = i` at
//! `i / fps` seconds (30 frames per second unless told otherwise), and a
//! frame without the performer is a dropped frame.
//!
//! # Several files: sensor ids and clocks
//!
//! [`read_recordings_with`] reads the files of one capture (what `mocap
//! fuse calibrate`, `measure` and `run` are given) and says what it did
//! ([`RecordingsReport::notes`]). Each file's sensor id:
//!
//! | file | sensor id |
//! | --- | --- |
//! | `.jsonl` | the `sensor` field of its lines (several sensors may share a file) |
//! | NTU `.skeleton` named `S...C...P...R...A...` | its camera number: `S001C002P003R001A001` is sensor 2 (NTU numbers cameras from 1; the simulator's NTU files from 0, like its sensors) |
//! | another `.skeleton` | the next id after the highest of all the other files, in the order given |
//!
//! Two files with the same sensor id (two takes of one camera, or one
//! file given twice) are an error that names both: a sensor's frames must
//! come from one file.
//!
//! `.jsonl` times are on the clock shared by the sensors and are kept. NTU
//! files have none: frame `i` is at `i / input_fps`, so cameras that started
//! a few frames apart would be fused out of step. Each NTU file's offset
//! against the NTU file of the lowest sensor id is estimated from the
//! motion ([`estimate_time_offset`]) and added to its times when the motions
//! correlate well enough ([`TimeOffsets`]; they can also be given, or
//! switched off).

use std::path::{Path, PathBuf};

use mocap_core::error::Location;
use mocap_core::rotation::Vec3;
use mocap_core::{Error, ParseError, Result};
use serde::{Deserialize, Serialize};

use crate::kinect::{TrackingState, JOINT_COUNT};

/// Version of the recording format this crate writes.
pub const RECORDING_VERSION: u32 = 1;

/// One joint as a sensor reported it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointObservation {
    /// Metres, in the sensor's camera space (or world space after calibration).
    pub position: Vec3,
    pub state: TrackingState,
}

impl JointObservation {
    pub const NOT_TRACKED: JointObservation = JointObservation {
        position: Vec3::ZERO,
        state: TrackingState::NotTracked,
    };
}

/// The farthest a joint may be from the sensor that saw it, in metres.
/// Kinect v2 tracks bodies 0.5 to 4.5 m away; ten metres leaves room for
/// other depth sensors of its kind and for any calibration error, and
/// nothing a sensor reports beyond it is part of the person it watches. A
/// joint farther away (an absurd coordinate, such as 1e30 m) is an outlier,
/// not an observation ([`SensorFrame::screen_implausible_joints`]).
pub const MAX_JOINT_DISTANCE: f32 = 10.0;

/// One skeleton frame of one sensor.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorFrame {
    pub sensor: u16,
    pub seq: u64,
    /// Capture time, seconds on the shared clock.
    pub timestamp: f64,
    /// When the frame reached the sensor's computer (seconds), if known.
    pub arrival: Option<f64>,
    /// The 25 joints in Kinect v2 order.
    pub joints: [JointObservation; JOINT_COUNT],
}

/// The JSON shape of a frame (see the module documentation).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FrameRecord {
    #[serde(default = "default_version")]
    v: u32,
    sensor: u16,
    seq: u64,
    t: f64,
    #[serde(default)]
    arrival: Option<f64>,
    joints: Vec<[f64; 4]>,
}

fn default_version() -> u32 {
    1
}

impl SensorFrame {
    /// Treats the joints farther than [`MAX_JOINT_DISTANCE`] from the sensor
    /// (camera space, before calibration) as outliers: each becomes
    /// NotTracked, so that it has no weight in the fusion, and is put at the
    /// mean of the frame's plausible joints (at the sensor when there is
    /// none), so that no guess, bone-length term or facing computed from
    /// the frame's positions sees the absurd position. Returns how many
    /// joints were outliers; all [`JOINT_COUNT`] means the frame holds no
    /// observation at all. The fusion server and the offline fusion
    /// ([`crate::offline::SensorStreams::new`]) both screen every frame so.
    pub fn screen_implausible_joints(&mut self) -> usize {
        let plausible = |j: &JointObservation| j.position.length() <= MAX_JOINT_DISTANCE;
        let (sum, kept) = self
            .joints
            .iter()
            .filter(|j| plausible(j))
            .fold((Vec3::ZERO, 0usize), |(sum, n), j| {
                (sum + j.position, n + 1)
            });
        let outliers = JOINT_COUNT - kept;
        if outliers == 0 {
            return 0;
        }
        let stand_in = if kept > 0 {
            sum / kept as f32
        } else {
            Vec3::ZERO
        };
        for j in self.joints.iter_mut().filter(|j| !plausible(j)) {
            *j = JointObservation {
                position: stand_in,
                state: TrackingState::NotTracked,
            };
        }
        outliers
    }

    /// The frame as one line of JSON (no newline). Written by hand rather
    /// than through serde: the server and the sender do this for every
    /// datagram, and positions rounded to 0.1 mm (more than any depth sensor
    /// resolves) keep lines short.
    pub fn to_json(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::with_capacity(1200);
        let _ = write!(
            s,
            "{{\"v\":{RECORDING_VERSION},\"sensor\":{},\"seq\":{},\"t\":{}",
            self.sensor, self.seq, self.timestamp
        );
        if let Some(a) = self.arrival {
            let _ = write!(s, ",\"arrival\":{a}");
        }
        s.push_str(",\"joints\":[");
        for (n, j) in self.joints.iter().enumerate() {
            if n > 0 {
                s.push(',');
            }
            let p = j.position;
            let _ = write!(s, "[{:.4},{:.4},{:.4},{}]", p.x, p.y, p.z, j.state.code());
        }
        s.push_str("]}");
        s
    }

    /// Parses one frame from JSON, checking every field. The error message
    /// says what is wrong; the caller adds where.
    pub fn from_json(text: &str) -> std::result::Result<SensorFrame, String> {
        SensorFrame::from_json_at(text).map_err(|(_, message)| message)
    }

    /// [`SensorFrame::from_json`], with the 1-based column of the problem
    /// when the JSON itself is at fault (1 otherwise).
    fn from_json_at(text: &str) -> std::result::Result<SensorFrame, (usize, String)> {
        let record: FrameRecord = serde_json::from_str(text).map_err(|e| {
            // serde_json says "... at line 1 column 17"; the column goes to
            // the location, the rest is the message.
            let column = e.column().max(1);
            let message = e.to_string();
            let message = match message.rfind(" at line ") {
                Some(at) => message[..at].to_string(),
                None => message,
            };
            (column, message)
        })?;
        SensorFrame::from_record(record).map_err(|message| (1, message))
    }

    fn from_record(record: FrameRecord) -> std::result::Result<SensorFrame, String> {
        if record.v != RECORDING_VERSION {
            return Err(format!(
                "recording format version {} is not supported (this reader knows {RECORDING_VERSION})",
                record.v
            ));
        }
        if !record.t.is_finite() {
            return Err("timestamp `t` must be a finite number".into());
        }
        if let Some(a) = record.arrival {
            if !a.is_finite() {
                return Err("`arrival` must be a finite number".into());
            }
        }
        if record.joints.len() != JOINT_COUNT {
            return Err(format!(
                "expected {JOINT_COUNT} joints, found {}",
                record.joints.len()
            ));
        }
        let mut joints = [JointObservation::NOT_TRACKED; JOINT_COUNT];
        for (n, [x, y, z, s]) in record.joints.into_iter().enumerate() {
            if !(x.is_finite() && y.is_finite() && z.is_finite()) {
                return Err(format!("joint {n}: position is not finite"));
            }
            // Positions are kept as f32: a coordinate beyond its range
            // (about 3.4e38) would become infinite.
            if [x, y, z].iter().any(|c| c.abs() > f32::MAX as f64) {
                return Err(format!(
                    "joint {n}: position [{x}, {y}, {z}] is out of range"
                ));
            }
            let state = if s.fract() == 0.0 {
                TrackingState::from_code(s as i64)
            } else {
                None
            }
            .ok_or_else(|| format!("joint {n}: tracking state must be 0, 1 or 2, got {s}"))?;
            joints[n] = JointObservation {
                position: Vec3::new(x as f32, y as f32, z as f32),
                state,
            };
        }
        Ok(SensorFrame {
            sensor: record.sensor,
            seq: record.seq,
            timestamp: record.t,
            arrival: record.arrival,
            joints,
        })
    }
}

fn parse_error(path: &Path, line: usize, column: usize, message: impl Into<String>) -> Error {
    Error::Parse(ParseError {
        location: Location {
            path: path.to_path_buf(),
            line,
            column,
        },
        message: message.into(),
    })
}

/// Reads a `.jsonl` recording (blank lines are skipped).
pub fn read_recording(path: &Path) -> Result<Vec<SensorFrame>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let mut frames = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let frame = SensorFrame::from_json_at(line).map_err(|(column, message)| {
            parse_error(
                path,
                i + 1,
                column,
                format!("expected a sensor frame object: {message}"),
            )
        })?;
        frames.push(frame);
    }
    Ok(frames)
}

/// Writes frames as a `.jsonl` recording, atomically.
pub fn write_recording(path: &Path, frames: &[SensorFrame]) -> Result<()> {
    mocap_core::io::atomic::write_atomically(path, |w| {
        for f in frames {
            writeln!(w, "{}", f.to_json())?;
        }
        Ok(())
    })
}

/// Reads sensor frames from a `.jsonl` recording or an NTU `.skeleton` file
/// (chosen by extension). For an NTU file the sensor id is the camera number
/// of its name (`S001C002P003R001A001` is camera 2) or `default_sensor`,
/// frame `i` is at `i / 30` s and the performer is chosen and followed as
/// [`choose_ntu_body`] says. [`read_recordings_with`] reads several files,
/// with their ids kept apart and their clocks matched.
pub fn read_any_recording(path: &Path, default_sensor: u16) -> Result<Vec<SensorFrame>> {
    if is_ntu_file(path) {
        let sensor = ntu_camera_of(path).unwrap_or(default_sensor);
        let frames = read_ntu_skeleton(path)?;
        Ok(ntu_sensor_frames(&frames, sensor, NTU_FPS))
    } else {
        read_recording(path)
    }
}

/// Whether `path` is read as an NTU `.skeleton` file (by its extension).
fn is_ntu_file(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("skeleton"))
}

/// Reads the sensor frames of several recordings with the default
/// [`ReadOptions`] ([`read_recordings_with`], whose report this drops).
/// Fails when they hold no frame.
pub fn read_recordings(paths: &[PathBuf]) -> Result<Vec<SensorFrame>> {
    Ok(read_recordings_with(paths, &ReadOptions::default())?.frames)
}

/// The camera number in an NTU RGB+D file name: `S001C002P003R001A001`
/// (setup, camera, performer, replication, action, each a number; anywhere
/// in the name) is camera 2. `None` when the name does not follow the
/// pattern.
pub fn ntu_camera_of(path: &Path) -> Option<u16> {
    let name = path.file_stem()?.to_str()?.as_bytes();
    // Each field: its letter, then at least one digit.
    let field = |at: usize, letter: u8| -> Option<(u64, usize)> {
        if name.get(at) != Some(&letter) {
            return None;
        }
        let digits = name[at + 1..]
            .iter()
            .take_while(|c| c.is_ascii_digit())
            .count();
        if digits == 0 {
            return None;
        }
        let text = std::str::from_utf8(&name[at + 1..at + 1 + digits]).ok()?;
        Some((text.parse().ok()?, at + 1 + digits))
    };
    (0..name.len()).find_map(|start| {
        let (_, at) = field(start, b'S')?;
        let (camera, mut at) = field(at, b'C')?;
        for letter in [b'P', b'R', b'A'] {
            at = field(at, letter)?.1;
        }
        u16::try_from(camera).ok()
    })
}

/// One body of an NTU frame.
#[derive(Debug, Clone, PartialEq)]
pub struct NtuBody {
    /// The Kinect tracking id, stable while the body stays in view.
    pub body_id: u64,
    /// The 25 joints (camera space, metres) with their tracking states.
    pub joints: [JointObservation; JOINT_COUNT],
}

/// Reads an NTU RGB+D `.skeleton` file: per frame, the bodies in it.
///
/// Layout (whitespace-separated, one record per line): the frame count; per
/// frame the body count; per body a line of 10 values (`bodyID clippedEdges
/// handLeftConfidence handLeftState handRightConfidence handRightState
/// isRestricted leanX leanY trackingState`), the joint count (25), and per
/// joint a line `x y z depthX depthY colorX colorY orientationW orientationX
/// orientationY orientationZ trackingState`.
pub fn read_ntu_skeleton(path: &Path) -> Result<Vec<Vec<NtuBody>>> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    read_ntu_skeleton_from(&text, path)
}

/// [`read_ntu_skeleton`] on the text of a file; `path` names it in errors.
pub fn read_ntu_skeleton_from(text: &str, path: &Path) -> Result<Vec<Vec<NtuBody>>> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let mut last_line = 0;
    let mut next = |what: &str| -> Result<(usize, Vec<&str>)> {
        match lines.next() {
            Some((i, l)) => {
                last_line = i + 1;
                Ok((i + 1, l.split_whitespace().collect()))
            }
            None => Err(parse_error(
                path,
                last_line + 1,
                1,
                format!("unexpected end of file, expected {what}"),
            )),
        }
    };
    let count = |(line, fields): (usize, Vec<&str>), what: &str| -> Result<usize> {
        match fields[..] {
            [one] => one
                .parse::<usize>()
                .map_err(|_| parse_error(path, line, 1, format!("expected {what}, found {one:?}"))),
            _ => Err(parse_error(
                path,
                line,
                1,
                format!(
                    "expected {what} alone on the line, found {} values",
                    fields.len()
                ),
            )),
        }
    };
    let frame_count = count(next("the frame count")?, "the frame count")?;
    // No room reserved from the counts: they are the file's word, and a
    // frame or a body takes at least a line, so the file's length bounds
    // what is really there.
    let mut frames = Vec::new();
    for f in 0..frame_count {
        let body_count = count(
            next(&format!("the body count of frame {}", f + 1))?,
            "a body count",
        )?;
        let mut bodies = Vec::new();
        for _ in 0..body_count {
            let (line, header) = next("a body line of 10 values")?;
            if header.len() != 10 {
                return Err(parse_error(
                    path,
                    line,
                    1,
                    format!(
                        "expected a body line of 10 values (bodyID clippedEdges handLeftConfidence handLeftState handRightConfidence handRightState isRestricted leanX leanY trackingState), found {}",
                        header.len()
                    ),
                ));
            }
            let body_id = header[0].parse::<u64>().map_err(|_| {
                parse_error(
                    path,
                    line,
                    1,
                    format!("expected a body id, found {:?}", header[0]),
                )
            })?;
            let joint_count_line = next("the joint count (25)")?;
            let joint_count_at = joint_count_line.0;
            let joint_count = count(joint_count_line, "the joint count")?;
            if joint_count != JOINT_COUNT {
                return Err(parse_error(
                    path,
                    joint_count_at,
                    1,
                    format!("expected {JOINT_COUNT} joints (Kinect v2), found {joint_count}"),
                ));
            }
            let mut joints = [JointObservation::NOT_TRACKED; JOINT_COUNT];
            for joint in joints.iter_mut() {
                let (line, v) = next("a joint line of 12 values")?;
                if v.len() != 12 {
                    return Err(parse_error(
                        path,
                        line,
                        1,
                        format!("expected a joint line of 12 values (x y z depthX depthY colorX colorY orientationW orientationX orientationY orientationZ trackingState), found {}", v.len()),
                    ));
                }
                let mut xyz = [0.0f32; 3];
                for (k, slot) in xyz.iter_mut().enumerate() {
                    *slot = v[k]
                        .parse::<f32>()
                        .ok()
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| {
                            parse_error(
                                path,
                                line,
                                column_of_field(text, line, k),
                                format!(
                                    "expected a number for the joint coordinate, found {:?}",
                                    v[k]
                                ),
                            )
                        })?;
                }
                let state = v[11]
                    .parse::<i64>()
                    .ok()
                    .and_then(TrackingState::from_code)
                    .ok_or_else(|| {
                        parse_error(
                            path,
                            line,
                            column_of_field(text, line, 11),
                            format!("expected a tracking state 0, 1 or 2, found {:?}", v[11]),
                        )
                    })?;
                *joint = JointObservation {
                    position: Vec3::from(xyz),
                    state,
                };
            }
            bodies.push(NtuBody { body_id, joints });
        }
        frames.push(bodies);
    }
    Ok(frames)
}

/// 1-based column of the `field`-th whitespace-separated value on `line`.
fn column_of_field(text: &str, line: usize, field: usize) -> usize {
    let Some(l) = text.lines().nth(line - 1) else {
        return 1;
    };
    let mut seen = 0;
    let mut in_field = false;
    for (i, c) in l.char_indices() {
        if c.is_whitespace() {
            in_field = false;
        } else if !in_field {
            if seen == field {
                return i + 1;
            }
            seen += 1;
            in_field = true;
        }
    }
    1
}

/// Body ids that vanish and appear within this many seconds of each other
/// may be one person the sensor lost and found again ([`choose_ntu_body`]).
pub const STITCH_MAX_GAP_SECONDS: f64 = 0.5;

/// How far (metres) the pelvis may have gone per frame between a body id
/// vanishing and a new one appearing for the two to count as one person.
pub const STITCH_METRES_PER_FRAME: f64 = 0.3;

/// A track must cover at least this share of the frames of the longest one
/// to be a candidate for the performer ([`choose_ntu_body`]).
pub const PERFORMER_MIN_COVERAGE: f64 = 0.5;

/// One person's track through an NTU file: one body id, or several stitched
/// together.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NtuTrack {
    /// The Kinect body ids of the track, in the order they appear.
    pub ids: Vec<u64>,
    /// Frames in which the track has a body.
    pub frames: usize,
    /// Its first and last frame (0-based).
    pub first_frame: usize,
    pub last_frame: usize,
    /// Motion energy: the sum over the joints of the variance of their
    /// positions over the track's frames (m², x, y and z summed), as NTU
    /// RGB+D's own tools rank bodies.
    pub motion: f64,
    /// Tracked joints per frame, on average.
    pub tracked_joints: f64,
}

/// Two body ids followed as one person: `from` vanished after frame
/// `last_frame`, `to` appeared at frame `first_frame`, its pelvis
/// `distance` metres from where `from`'s was.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NtuStitch {
    pub from: u64,
    pub to: u64,
    pub last_frame: usize,
    pub first_frame: usize,
    pub distance: f64,
}

/// A run of frames (0-based, `count` of them from `first`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct FrameRun {
    pub first: usize,
    pub count: usize,
}

impl FrameRun {
    /// `12-19`, or `12` for one frame.
    pub fn describe(&self) -> String {
        match self.count {
            1 => format!("{}", self.first),
            _ => format!("{}-{}", self.first, self.first + self.count - 1),
        }
    }
}

/// Which body of an NTU file is the performer ([`choose_ntu_body`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NtuBodyChoice {
    /// Frames in the file.
    pub frames: usize,
    /// The performer's track.
    pub performer: NtuTrack,
    /// The other tracks (other people, or noise), dropped.
    pub dropped: Vec<NtuTrack>,
    /// The body ids followed as one person, the performer's and others'.
    pub stitches: Vec<NtuStitch>,
    /// The frames without the performer: they are gaps (dropped frames) of
    /// the recording. A run from frame 0 is a performer who appears late,
    /// one to the end a performer who vanishes early.
    pub gaps: Vec<FrameRun>,
    /// The performer's body id at each frame of the file (`None`: not
    /// there): what the recording holds, frame by frame. Left out of the
    /// JSON reports, which `frames`, `stitches` and `gaps` sum up.
    #[serde(skip)]
    pub per_frame: Vec<Option<u64>>,
}

impl NtuBodyChoice {
    /// Frames without the performer.
    pub fn missing_frames(&self) -> usize {
        self.gaps.iter().map(|g| g.count).sum()
    }
}

/// Chooses the performer among the bodies of an NTU capture (`fps` frames
/// per second) and follows them through the take.
///
/// 1. **Tracks.** Each body id is a track. When an id vanishes and a new
///    one appears within [`STITCH_MAX_GAP_SECONDS`], with its pelvis (the
///    `SpineBase` joint) less than [`STITCH_METRES_PER_FRAME`] per elapsed
///    frame from where the old one was last seen, the sensor lost the
///    person and found them again: the two ids are stitched into one track
///    (the closest such track when several qualify; ids seen at the same
///    time are never stitched).
/// 2. **The performer.** Among the tracks that cover at least
///    [`PERFORMER_MIN_COVERAGE`] of the frames of the longest one, the one
///    that moves most (the motion energy of NTU RGB+D's tools, the sum of
///    the variances of the joints' positions: the actor moves, a bystander
///    or a piece of furniture taken for a body barely does); on equal
///    motion the one with more tracked joints per frame, then the one
///    listed first.
///
/// `None` when the file holds no body at all.
pub fn choose_ntu_body(frames: &[Vec<NtuBody>], fps: f64) -> Option<NtuBodyChoice> {
    // Each id's bodies, in the order the ids are first listed.
    let mut by_id: Vec<(u64, Vec<(usize, &NtuBody)>)> = Vec::new();
    for (i, bodies) in frames.iter().enumerate() {
        for b in bodies {
            match by_id.iter_mut().find(|(id, _)| *id == b.body_id) {
                Some((_, seen)) => {
                    // One body per id and frame: a repeated id is a fault of
                    // the file, and its first listing is kept.
                    if seen.last().is_none_or(|(f, _)| *f != i) {
                        seen.push((i, b));
                    }
                }
                None => by_id.push((b.body_id, vec![(i, b)])),
            }
        }
    }
    if by_id.is_empty() {
        return None;
    }
    // Stitching, in the order the ids appear (stable: listing order on ties).
    by_id.sort_by_key(|(_, seen)| seen[0].0);
    let pelvis = |b: &NtuBody| b.joints[crate::kinect::joint::SPINE_BASE].position;
    let max_elapsed = (STITCH_MAX_GAP_SECONDS * fps).round().max(0.0) as usize + 1;
    // Each track: its ids, and its bodies by frame.
    type Track<'a> = (Vec<u64>, Vec<(usize, &'a NtuBody)>);
    let mut chains: Vec<Track> = Vec::new();
    let mut stitches = Vec::new();
    for (id, seen) in by_id {
        let (first, first_body) = seen[0];
        let joined = chains
            .iter()
            .enumerate()
            .filter_map(|(c, (_, chain))| {
                let &(last, last_body) = chain.last()?;
                let elapsed = first.checked_sub(last).filter(|e| *e >= 1)?;
                let distance = pelvis(last_body).distance(pelvis(first_body)) as f64;
                (elapsed <= max_elapsed && distance < STITCH_METRES_PER_FRAME * elapsed as f64)
                    .then_some((c, distance))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match joined {
            Some((c, distance)) => {
                let (ids, chain) = &mut chains[c];
                stitches.push(NtuStitch {
                    from: *ids.last().unwrap_or(&id),
                    to: id,
                    last_frame: chain.last().map_or(0, |(f, _)| *f),
                    first_frame: first,
                    distance,
                });
                ids.push(id);
                chain.extend(seen);
            }
            None => chains.push((vec![id], seen)),
        }
    }
    let tracks: Vec<NtuTrack> = chains
        .iter()
        .map(|(ids, seen)| track_of(ids, seen))
        .collect();
    let longest = tracks.iter().map(|t| t.frames).max().unwrap_or(0);
    let performer = (0..tracks.len())
        .filter(|&k| tracks[k].frames as f64 >= PERFORMER_MIN_COVERAGE * longest as f64)
        .reduce(|best, k| {
            let (a, b) = (&tracks[best], &tracks[k]);
            let better = b
                .motion
                .total_cmp(&a.motion)
                .then(b.tracked_joints.total_cmp(&a.tracked_joints));
            if better.is_gt() {
                k
            } else {
                best
            }
        })?;
    let mut per_frame = vec![None; frames.len()];
    for (f, b) in &chains[performer].1 {
        per_frame[*f] = Some(b.body_id);
    }
    let mut gaps: Vec<FrameRun> = Vec::new();
    for (f, id) in per_frame.iter().enumerate() {
        if id.is_some() {
            continue;
        }
        match gaps.last_mut() {
            Some(run) if run.first + run.count == f => run.count += 1,
            _ => gaps.push(FrameRun { first: f, count: 1 }),
        }
    }
    let mut tracks = tracks;
    let performer_track = tracks.remove(performer);
    Some(NtuBodyChoice {
        frames: frames.len(),
        performer: performer_track,
        dropped: tracks,
        stitches,
        gaps,
        per_frame,
    })
}

/// The summary of one track's bodies (in frame order).
fn track_of(ids: &[u64], seen: &[(usize, &NtuBody)]) -> NtuTrack {
    let n = seen.len() as f64;
    let mut motion = 0.0;
    for j in 0..JOINT_COUNT {
        let mean = seen
            .iter()
            .map(|(_, b)| b.joints[j].position.as_dvec3())
            .sum::<glam::DVec3>()
            / n;
        motion += seen
            .iter()
            .map(|(_, b)| (b.joints[j].position.as_dvec3() - mean).length_squared())
            .sum::<f64>()
            / n;
    }
    let tracked = seen
        .iter()
        .map(|(_, b)| {
            b.joints
                .iter()
                .filter(|j| j.state == TrackingState::Tracked)
                .count()
        })
        .sum::<usize>() as f64;
    NtuTrack {
        ids: ids.to_vec(),
        frames: seen.len(),
        first_frame: seen.first().map_or(0, |(f, _)| *f),
        last_frame: seen.last().map_or(0, |(f, _)| *f),
        motion,
        tracked_joints: tracked / n,
    }
}

/// The performer of an NTU capture ([`choose_ntu_body`]) as frames of one
/// sensor: frame `i` of the file is frame `seq = i` at `i / fps` seconds;
/// frames without the performer are dropped frames (a gap in `seq`).
pub fn ntu_sensor_frames(frames: &[Vec<NtuBody>], sensor: u16, fps: f64) -> Vec<SensorFrame> {
    match choose_ntu_body(frames, fps) {
        Some(choice) => ntu_performer_frames(frames, &choice, sensor, fps),
        None => Vec::new(),
    }
}

/// The bodies `choice` picked, frame by frame, as frames of `sensor`.
pub fn ntu_performer_frames(
    frames: &[Vec<NtuBody>],
    choice: &NtuBodyChoice,
    sensor: u16,
    fps: f64,
) -> Vec<SensorFrame> {
    frames
        .iter()
        .zip(&choice.per_frame)
        .enumerate()
        .filter_map(|(i, (bodies, id))| {
            let body = bodies.iter().find(|b| Some(b.body_id) == *id)?;
            Some(SensorFrame {
                sensor,
                seq: i as u64,
                timestamp: i as f64 / fps,
                arrival: None,
                joints: body.joints,
            })
        })
        .collect()
}

/// Writes one sensor's frames as an NTU RGB+D `.skeleton` file (one body,
/// id `body_id`), atomically: frame `seq` of the recording is frame `seq` of
/// the file, and frames the sensor dropped have no body. Fields NTU has and
/// recordings do not are written as zeros ([`write_ntu_bodies`]). For test
/// fixtures and for tools that read NTU files.
pub fn write_ntu_skeleton(path: &Path, frames: &[SensorFrame], body_id: u64) -> Result<()> {
    let count = frames.iter().map(|f| f.seq + 1).max().unwrap_or(0) as usize;
    let mut bodies: Vec<Vec<NtuBody>> = vec![Vec::new(); count];
    for f in frames {
        bodies[f.seq as usize] = vec![NtuBody {
            body_id,
            joints: f.joints,
        }];
    }
    write_ntu_bodies(path, &bodies)
}

/// Writes the bodies of each frame as an NTU RGB+D `.skeleton` file,
/// atomically: what [`read_ntu_skeleton`] reads back. Fields NTU has and
/// [`NtuBody`] does not (depth and colour pixel coordinates, joint
/// orientations, hand states, lean) are written as zeros, every body as
/// tracked.
pub fn write_ntu_bodies(path: &Path, frames: &[Vec<NtuBody>]) -> Result<()> {
    use std::fmt::Write as _;
    let bodies: usize = frames.iter().map(Vec::len).sum();
    let mut text = String::with_capacity(bodies * 25 * 60 + frames.len() * 4 + 16);
    let _ = writeln!(text, "{}", frames.len());
    for frame in frames {
        let _ = writeln!(text, "{}", frame.len());
        for body in frame {
            let _ = writeln!(text, "{} 0 0 0 0 0 0 0 0 2\n{JOINT_COUNT}", body.body_id);
            for j in &body.joints {
                let p = j.position;
                let _ = writeln!(
                    text,
                    "{:.6} {:.6} {:.6} 0 0 0 0 0 0 0 0 {}",
                    p.x,
                    p.y,
                    p.z,
                    j.state.code()
                );
            }
        }
    }
    mocap_core::io::atomic::write_bytes_atomically(path, text.as_bytes())
}

// ------------------------------------------------------- several recordings

/// Frames per second of NTU RGB+D captures (Kinect v2): the default of
/// [`ReadOptions::input_fps`].
pub const NTU_FPS: f64 = 30.0;

/// Correlation of two sensors' motion below which an estimated time offset
/// is not applied ([`TimeOffsets::Estimate`]).
pub const MIN_OFFSET_CORRELATION: f64 = 0.3;

/// The largest time offset estimated, in frames either way.
pub const MAX_OFFSET_FRAMES: usize = 15;

/// What a frame of shift costs an estimate's correlation
/// ([`estimate_time_offset`]): the cameras of one take start within a few
/// frames of each other far more often than half a second apart, and a
/// repeated motion (walking) matches itself a step later almost as well.
const LAG_PRIOR_PER_FRAME: f64 = 0.01;

/// An estimate's runner-up this close in correlation makes it doubtful
/// (noted).
const AMBIGUOUS_CORRELATION: f64 = 0.05;

/// Pairs of frames two sensors must have in common at a lag for their
/// motion to be compared there.
const MIN_OFFSET_PAIRS: usize = 10;

/// How the files' clocks are matched ([`ReadOptions::time_offsets`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TimeOffsets {
    /// For the files without times of their own (NTU `.skeleton`: frame
    /// `i` is at `i / input_fps`), an offset is estimated from the motion
    /// against the NTU file of the lowest sensor id ([`estimate_time_offset`])
    /// and added to the file's times when the correlation is at least
    /// `min_correlation`. `.jsonl` times are on the shared clock and kept.
    Estimate { min_correlation: f64 },
    /// Every file's times as read.
    Off,
    /// One offset per file, in the order of the files, in frames at
    /// [`ReadOptions::input_fps`], added to its times (`.jsonl` too).
    Frames(Vec<f64>),
}

impl Default for TimeOffsets {
    fn default() -> Self {
        TimeOffsets::Estimate {
            min_correlation: MIN_OFFSET_CORRELATION,
        }
    }
}

impl std::str::FromStr for TimeOffsets {
    type Err = String;

    /// `auto` (estimated, [`MIN_OFFSET_CORRELATION`]), `off`, or one number
    /// of frames per file separated by commas (`0,2,-1.5`).
    fn from_str(text: &str) -> std::result::Result<Self, String> {
        match text.trim() {
            "auto" => Ok(TimeOffsets::default()),
            "off" => Ok(TimeOffsets::Off),
            list => list
                .split(',')
                .map(|v| {
                    v.trim()
                        .parse::<f64>()
                        .ok()
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| {
                            format!(
                                "expected auto, off or frames per file such as 0,2,-1.5; {:?} is not a number",
                                v.trim()
                            )
                        })
                })
                .collect::<std::result::Result<Vec<f64>, String>>()
                .map(TimeOffsets::Frames),
        }
    }
}

impl std::fmt::Display for TimeOffsets {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            TimeOffsets::Estimate { .. } => write!(f, "auto"),
            TimeOffsets::Off => write!(f, "off"),
            TimeOffsets::Frames(v) => {
                let list: Vec<String> = v.iter().map(|x| x.to_string()).collect();
                write!(f, "{}", list.join(","))
            }
        }
    }
}

/// How recordings are read ([`read_recordings_with`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ReadOptions {
    /// Frames per second of the files without times (NTU `.skeleton`):
    /// frame `i` is at `i / input_fps` seconds.
    pub input_fps: f64,
    pub time_offsets: TimeOffsets,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            input_fps: NTU_FPS,
            time_offsets: TimeOffsets::default(),
        }
    }
}

/// Recordings read ([`read_recordings_with`]): every file's frames, and
/// what was done to them.
#[derive(Debug, Clone)]
pub struct Recordings {
    pub frames: Vec<SensorFrame>,
    pub report: RecordingsReport,
}

/// Where a file's sensor id comes from (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SensorIdSource {
    /// The `sensor` field of a `.jsonl` recording's lines.
    Recorded,
    /// The camera number of an NTU file name (`S001C002...`: 2).
    NtuCamera,
    /// An NTU `.skeleton` file without a camera number in its name: the
    /// next id after the highest of the other files.
    AfterOthers,
}

/// One file read.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordingFile {
    pub path: PathBuf,
    /// How messages name it: `C002` for a camera of an NTU name, else the
    /// file name.
    pub label: String,
    pub sensors: Vec<u16>,
    pub sensor_id: SensorIdSource,
    /// Frames read (of an NTU file: those with the performer).
    pub frames: usize,
    /// Frames in an NTU file, with the performer or not.
    pub file_frames: Option<usize>,
    /// Which body of an NTU file is the performer (`None` for `.jsonl`
    /// files and NTU files without any body).
    pub ntu: Option<NtuBodyChoice>,
}

/// How a time offset was set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OffsetSource {
    Estimated,
    Given,
}

/// A file's time offset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TimeOffsetReport {
    pub sensor: u16,
    pub label: String,
    pub source: OffsetSource,
    /// The file matched against (estimated offsets).
    pub reference: Option<String>,
    /// The offset in input frames (estimated: the estimate, applied or
    /// not; `None` when the motions have no clear match) and in seconds.
    pub frames: Option<f64>,
    pub seconds: Option<f64>,
    /// Correlation of the two files' motion at the estimate.
    pub correlation: Option<f64>,
    /// The correlation an estimate needs to be applied.
    pub min_correlation: Option<f64>,
    /// The next best match of an estimate: whole frames and correlation
    /// ([`OffsetEstimate::runner_up`]).
    pub runner_up: Option<(i64, f64)>,
    /// Whether it was added to the file's times.
    pub applied: bool,
}

/// What [`read_recordings_with`] did, file by file.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct RecordingsReport {
    pub files: Vec<RecordingFile>,
    pub time_offsets: Vec<TimeOffsetReport>,
}

impl RecordingsReport {
    /// Whether the NTU files differ in their number of frames.
    pub fn frame_counts_differ(&self) -> bool {
        let mut counts = self.files.iter().filter_map(|f| f.file_frames);
        let first = counts.next();
        counts.any(|c| Some(c) != first)
    }

    /// What a person should know, one sentence each: the bodies dropped
    /// and the ids stitched in NTU files, frames without the performer,
    /// different frame counts, sensor ids given to unnamed files, time
    /// offsets. Empty when there is nothing to say.
    pub fn notes(&self) -> Vec<String> {
        let mut notes = Vec::new();
        for f in &self.files {
            if f.sensor_id == SensorIdSource::AfterOthers {
                notes.push(format!(
                    "{}: no NTU camera number in its name (S001C002P001R001A001): sensor {}",
                    f.label,
                    f.sensors.first().copied().unwrap_or_default()
                ));
            }
            let Some(file_frames) = f.file_frames else {
                continue;
            };
            let Some(choice) = &f.ntu else {
                notes.push(format!(
                    "{}: no body in any of its {file_frames} frames",
                    f.label
                ));
                continue;
            };
            if !choice.dropped.is_empty() {
                let dropped: Vec<String> = choice
                    .dropped
                    .iter()
                    .map(|t| {
                        format!(
                            "{} ({} frames, motion {:.3})",
                            ids_text(&t.ids),
                            t.frames,
                            t.motion
                        )
                    })
                    .collect();
                notes.push(format!(
                    "{}: {} people in view; kept body {} as the performer ({} frames, motion {:.3}: the most among those in view most of the take), dropped {}",
                    f.label,
                    choice.dropped.len() + 1,
                    ids_text(&choice.performer.ids),
                    choice.performer.frames,
                    choice.performer.motion,
                    dropped.join(", ")
                ));
            }
            for s in &choice.stitches {
                notes.push(format!(
                    "{}: body {} vanished after frame {} and body {} appeared at frame {}, {:.2} m away: followed as one person",
                    f.label, s.from, s.last_frame, s.to, s.first_frame, s.distance
                ));
            }
            if !choice.gaps.is_empty() {
                const LISTED: usize = 8;
                let mut runs: Vec<String> = choice
                    .gaps
                    .iter()
                    .take(LISTED)
                    .map(|g| {
                        let mut text = g.describe();
                        if g.first == 0 {
                            text += &format!(" (appears at frame {})", g.count);
                        } else if g.first + g.count == choice.frames {
                            text += &format!(" (gone after frame {})", g.first - 1);
                        }
                        text
                    })
                    .collect();
                if let Some(last) = choice.gaps.last().filter(|_| choice.gaps.len() > LISTED) {
                    runs.push(format!(
                        "... ({} runs in all, the last {})",
                        choice.gaps.len(),
                        last.describe()
                    ));
                }
                notes.push(format!(
                    "{}: no performer in {} of {} frames: {}",
                    f.label,
                    choice.missing_frames(),
                    choice.frames,
                    runs.join(", ")
                ));
            }
        }
        if self.frame_counts_differ() {
            let counts: Vec<String> = self
                .files
                .iter()
                .filter_map(|f| Some(format!("{} {}", f.label, f.file_frames?)))
                .collect();
            notes.push(format!(
                "the NTU files have different frame counts: {}",
                counts.join(", ")
            ));
        }
        for o in &self.time_offsets {
            let reference = o.reference.as_deref().unwrap_or("the others");
            let shift = |frames: f64, seconds: f64| {
                format!("{frames:+.1} frames ({:.1} ms)", seconds * 1000.0)
            };
            notes.push(match (o.source, o.frames, o.seconds, o.correlation) {
                (OffsetSource::Given, Some(frames), Some(seconds), _) => {
                    format!("{} shifted {} as given", o.label, shift(frames, seconds))
                }
                (OffsetSource::Estimated, Some(frames), Some(seconds), Some(r)) if o.applied => {
                    let doubt = match o.runner_up {
                        Some((lag, other)) if other > r - AMBIGUOUS_CORRELATION => format!(
                            " (it also matches at {lag:+} frames, correlation {other:.2}: \
                             a repeated motion? check, and give the offsets if need be)"
                        ),
                        _ => String::new(),
                    };
                    format!(
                        "{} shifted {} to match {reference}, correlation {r:.2}{doubt}",
                        o.label,
                        shift(frames, seconds)
                    )
                }
                (OffsetSource::Estimated, Some(frames), Some(seconds), Some(r)) => format!(
                    "{} not shifted: its motion matches {reference} best at {}, but with correlation {r:.2} (below {})",
                    o.label,
                    shift(frames, seconds),
                    o.min_correlation.unwrap_or(MIN_OFFSET_CORRELATION)
                ),
                _ => format!(
                    "{} not shifted: its motion has no clear match with {reference}'s within {MAX_OFFSET_FRAMES} frames",
                    o.label
                ),
            });
        }
        notes
    }
}

/// `72057594037931101` or `1+2` (stitched ids).
fn ids_text(ids: &[u64]) -> String {
    let ids: Vec<String> = ids.iter().map(|i| i.to_string()).collect();
    ids.join("+")
}

/// Reads the sensor frames of several recordings (`.jsonl`, NTU
/// `.skeleton`), with their sensor ids kept apart and their clocks
/// matched:
/// - each file's sensor id as the module documentation says; a file given
///   twice, or two files with the same sensor id (two takes of one NTU
///   camera), is an error naming both;
/// - in an NTU file the performer is chosen and followed
///   ([`choose_ntu_body`]), and frame `i` is at `i / input_fps`;
/// - time offsets estimated, given or none ([`TimeOffsets`]) added to the
///   files' times.
///
/// Fails when the files hold no frame. The report says what was done.
pub fn read_recordings_with(paths: &[PathBuf], options: &ReadOptions) -> Result<Recordings> {
    let fps = options.input_fps;
    if !(fps.is_finite() && fps > 0.0) {
        return Err(Error::Invalid(format!(
            "the input frame rate must be positive, got {fps}"
        )));
    }
    if let TimeOffsets::Frames(given) = &options.time_offsets {
        if given.len() != paths.len() {
            return Err(Error::Invalid(format!(
                "{} time offsets given for {} recordings: give one per file, in their order",
                given.len(),
                paths.len()
            )));
        }
        if let Some(x) = given.iter().find(|x| !x.is_finite()) {
            return Err(Error::Invalid(format!(
                "time offset {x} is not a number of frames"
            )));
        }
    }
    // The same file given twice (under one name or two).
    let keys: Vec<PathBuf> = paths
        .iter()
        .map(|p| std::fs::canonicalize(p).unwrap_or_else(|_| p.clone()))
        .collect();
    for (j, key) in keys.iter().enumerate() {
        if let Some(i) = keys[..j].iter().position(|k| k == key) {
            let also = if paths[i].as_os_str() != paths[j].as_os_str() {
                format!(" (also as {})", paths[i].display())
            } else {
                String::new()
            };
            return Err(Error::Invalid(format!(
                "{} is given twice{also}: give each sensor's recording once",
                paths[j].display()
            )));
        }
    }
    let mut files: Vec<RecordingFile> = Vec::with_capacity(paths.len());
    let mut frames_of: Vec<Vec<SensorFrame>> = Vec::with_capacity(paths.len());
    for path in paths {
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        if is_ntu_file(path) {
            let bodies = read_ntu_skeleton(path)?;
            let camera = ntu_camera_of(path);
            let sensor = camera.unwrap_or(0);
            let choice = choose_ntu_body(&bodies, fps);
            let frames = choice
                .as_ref()
                .map_or_else(Vec::new, |c| ntu_performer_frames(&bodies, c, sensor, fps));
            files.push(RecordingFile {
                path: path.clone(),
                label: camera.map_or(name, |c| format!("C{c:03}")),
                sensors: vec![sensor],
                sensor_id: if camera.is_some() {
                    SensorIdSource::NtuCamera
                } else {
                    SensorIdSource::AfterOthers
                },
                frames: frames.len(),
                file_frames: Some(bodies.len()),
                ntu: choice,
            });
            frames_of.push(frames);
        } else {
            let frames = read_recording(path)?;
            let mut sensors: Vec<u16> = frames.iter().map(|f| f.sensor).collect();
            sensors.sort_unstable();
            sensors.dedup();
            files.push(RecordingFile {
                path: path.clone(),
                label: name,
                sensors,
                sensor_id: SensorIdSource::Recorded,
                frames: frames.len(),
                file_frames: None,
                ntu: None,
            });
            frames_of.push(frames);
        }
    }
    // Files without an id of their own continue after the others' ids.
    let mut next = files
        .iter()
        .filter(|f| f.sensor_id != SensorIdSource::AfterOthers)
        .flat_map(|f| f.sensors.iter().map(|s| *s as u32 + 1))
        .max()
        .unwrap_or(0);
    for (file, frames) in files.iter_mut().zip(frames_of.iter_mut()) {
        if file.sensor_id != SensorIdSource::AfterOthers {
            continue;
        }
        let id = u16::try_from(next).map_err(|_| {
            Error::Invalid(format!(
                "{}: no sensor id is left after 65535 for it",
                file.path.display()
            ))
        })?;
        next += 1;
        file.sensors = vec![id];
        for f in frames.iter_mut() {
            f.sensor = id;
        }
    }
    check_distinct_sensors(&files)?;
    let time_offsets = match &options.time_offsets {
        TimeOffsets::Off => Vec::new(),
        TimeOffsets::Frames(given) => given_offsets(&files, &mut frames_of, given, fps),
        TimeOffsets::Estimate { min_correlation } => {
            estimated_offsets(&files, &mut frames_of, *min_correlation, fps)
        }
    };
    let frames: Vec<SensorFrame> = frames_of.into_iter().flatten().collect();
    if frames.is_empty() {
        return Err(Error::Invalid(
            "the recordings hold no sensor frames".into(),
        ));
    }
    Ok(Recordings {
        frames,
        report: RecordingsReport {
            files,
            time_offsets,
        },
    })
}

/// Fails, naming both files, when two files hold the same sensor.
fn check_distinct_sensors(files: &[RecordingFile]) -> Result<()> {
    let why = |f: &RecordingFile, id: u16| match f.sensor_id {
        SensorIdSource::NtuCamera => format!("camera {id} of its NTU name"),
        SensorIdSource::Recorded => "its lines' `sensor` field".to_string(),
        SensorIdSource::AfterOthers => "the next free id".to_string(),
    };
    for (j, b) in files.iter().enumerate() {
        for a in &files[..j] {
            if let Some(&id) = b.sensors.iter().find(|s| a.sensors.contains(s)) {
                return Err(Error::Invalid(format!(
                    "{} and {} are both sensor {id} ({}; {}): one sensor's frames come from one file; \
                     give the files of one take, one per camera",
                    a.path.display(),
                    b.path.display(),
                    why(a, id),
                    why(b, id)
                )));
            }
        }
    }
    Ok(())
}

/// Adds the given offsets (frames at `fps`, one per file) to the files'
/// times.
fn given_offsets(
    files: &[RecordingFile],
    frames_of: &mut [Vec<SensorFrame>],
    given: &[f64],
    fps: f64,
) -> Vec<TimeOffsetReport> {
    let mut reports = Vec::new();
    for ((file, frames), &offset) in files.iter().zip(frames_of.iter_mut()).zip(given) {
        if offset == 0.0 {
            continue;
        }
        shift_times(frames, offset / fps);
        for &sensor in &file.sensors {
            reports.push(TimeOffsetReport {
                sensor,
                label: file.label.clone(),
                source: OffsetSource::Given,
                reference: None,
                frames: Some(offset),
                seconds: Some(offset / fps),
                correlation: None,
                min_correlation: None,
                runner_up: None,
                applied: true,
            });
        }
    }
    reports
}

/// Estimates the offset of each NTU file against the NTU file of the lowest
/// sensor id ([`estimate_time_offset`]) and adds it to the file's times
/// when the correlation reaches `min_correlation`.
fn estimated_offsets(
    files: &[RecordingFile],
    frames_of: &mut [Vec<SensorFrame>],
    min_correlation: f64,
    fps: f64,
) -> Vec<TimeOffsetReport> {
    let untimed: Vec<usize> = (0..files.len())
        .filter(|&k| files[k].file_frames.is_some() && !frames_of[k].is_empty())
        .collect();
    let Some(&reference) = untimed.iter().min_by_key(|&&k| files[k].sensors[0]) else {
        return Vec::new();
    };
    if untimed.len() < 2 {
        return Vec::new();
    }
    let mut reports = Vec::new();
    // The reference's shapes, once for every camera compared with it.
    let reference_shapes = shape_features(&frames_of[reference], fps);
    for &k in untimed.iter().filter(|&&k| k != reference) {
        let shapes = shape_features(&frames_of[k], fps);
        let estimate = offset_between_shapes(&reference_shapes, &shapes, MAX_OFFSET_FRAMES);
        let applied = estimate
            .as_ref()
            .is_some_and(|e| e.correlation >= min_correlation);
        if let (true, Some(e)) = (applied, &estimate) {
            shift_times(&mut frames_of[k], e.frames / fps);
        }
        reports.push(TimeOffsetReport {
            sensor: files[k].sensors[0],
            label: files[k].label.clone(),
            source: OffsetSource::Estimated,
            reference: Some(files[reference].label.clone()),
            frames: estimate.as_ref().map(|e| e.frames),
            seconds: estimate.as_ref().map(|e| e.frames / fps),
            correlation: estimate.as_ref().map(|e| e.correlation),
            min_correlation: Some(min_correlation),
            runner_up: estimate.as_ref().and_then(|e| e.runner_up),
            applied,
        });
    }
    reports
}

fn shift_times(frames: &mut [SensorFrame], seconds: f64) {
    for f in frames {
        f.timestamp += seconds;
        if let Some(a) = f.arrival.as_mut() {
            *a += seconds;
        }
    }
}

/// A time offset between two recordings of one take
/// ([`estimate_time_offset`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OffsetEstimate {
    /// Frames to add to the second recording's frame times (at the `fps`
    /// of the estimate) for its motion to match the first's.
    pub frames: f64,
    /// Correlation of the two motions at the best whole-frame lag.
    pub correlation: f64,
    /// Frames compared there.
    pub pairs: usize,
    /// The next best match (another peak of the correlation, in whole
    /// frames) and its correlation: a repeated motion (steps) matches
    /// itself a period later too.
    pub runner_up: Option<(i64, f64)>,
}

/// Estimates how many frames (at `fps`) to add to `other`'s times for its
/// motion to line up with `reference`'s, within `max_lag` frames either
/// way; the sensors need not be calibrated.
///
/// Each frame is described by the distances between its joints (those not
/// NotTracked), every pair of joints: the body's shape, the same in every
/// sensor's camera space. Each distance is averaged with its mirror image
/// (left hand to head with right hand to head), so that a sensor that sees
/// the person from behind and swaps left and right describes the same
/// shape. The two series are correlated at every whole-frame lag on the
/// frames both have (the Pearson correlation of all the distances at once:
/// the sum of their covariances over the square root of the product of the
/// sums of their variances); the best lag is refined to a fraction of a
/// frame by the parabola through it and its neighbours. Frames are placed
/// by their times (`round(t * fps)`). `None` when the correlation has no
/// peak (lags with fewer than 10 frames in common, or fewer than two thirds
/// of the shorter recording's, are left out).
///
/// The match chosen is the peak of the correlation (a lag better than both
/// its neighbours: a maximum at the edge of the window is the slope of a
/// peak beyond it) with the best correlation less 0.01 per frame of lag:
/// the cameras of one take start within a few frames of each other far
/// more often than half a second apart, and a repeated motion matches
/// itself a step later almost as well (a walker's steps are 15 frames
/// apart, and a sensor that sees them from behind swaps left and right).
/// The next best peak is kept as [`OffsetEstimate::runner_up`].
///
/// The speed of the joints, also the same in every camera space, was tried
/// first and lost to the shape on simulated Kinect takes: the sensor noise
/// of a difference of positions drowns the small changes of a walker's
/// speed (docs/research/fuse.md).
pub fn estimate_time_offset(
    reference: &[SensorFrame],
    other: &[SensorFrame],
    fps: f64,
    max_lag: usize,
) -> Option<OffsetEstimate> {
    offset_between_shapes(
        &shape_features(reference, fps),
        &shape_features(other, fps),
        max_lag,
    )
}

/// Frame shapes by frame number ([`shape_features`]).
type Shapes = std::collections::BTreeMap<i64, Vec<f64>>;

/// [`estimate_time_offset`] on the two recordings' shapes.
fn offset_between_shapes(a: &Shapes, b: &Shapes, max_lag: usize) -> Option<OffsetEstimate> {
    let max_lag = max_lag as i64;
    // Correlations over few frames are noisy, and the noisier the likelier
    // to be the highest: a lag counts only where the two share at least two
    // thirds of the shorter recording's frames (on a 23-frame take a lag of
    // 11 frames matched better than the true 0).
    let min_pairs = (2 * a.len().min(b.len())).div_ceil(3);
    let scores: Vec<(i64, f64, usize)> = (-max_lag..=max_lag)
        .filter_map(|lag| shape_correlation(a, b, lag).map(|(r, n)| (lag, r, n)))
        .filter(|&(_, _, n)| n >= min_pairs)
        .collect();
    // The peaks: lags better than both neighbours. A maximum at the edge of
    // the window is a slope towards a peak beyond it, not a match.
    let peaks: Vec<usize> = (1..scores.len().saturating_sub(1))
        .filter(|&i| {
            let (before, at, after) = (scores[i - 1], scores[i], scores[i + 1]);
            before.0 + 1 == at.0 && at.0 + 1 == after.0 && before.1 < at.1 && after.1 < at.1
        })
        .collect();
    let score = |i: usize| scores[i].1 - LAG_PRIOR_PER_FRAME * scores[i].0.abs() as f64;
    let best = peaks
        .iter()
        .copied()
        .max_by(|&i, &j| score(i).total_cmp(&score(j)))?;
    let (lag, r, pairs) = scores[best];
    let (before, after) = (scores[best - 1].1, scores[best + 1].1);
    let curvature = before - 2.0 * r + after;
    let fraction = (0.5 * (before - after) / curvature).clamp(-0.5, 0.5);
    let runner_up = peaks
        .iter()
        .copied()
        .filter(|&i| i != best)
        .max_by(|&i, &j| score(i).total_cmp(&score(j)))
        .map(|i| (scores[i].0, scores[i].1));
    Some(OffsetEstimate {
        frames: lag as f64 + fraction,
        correlation: r,
        pairs,
        runner_up,
    })
}

/// Each frame's shape by frame number `round(t * fps)`: the distance of
/// every pair of joints averaged with its mirror image (each such class
/// once), NaN where a joint is NotTracked.
fn shape_features(frames: &[SensorFrame], fps: f64) -> Shapes {
    use crate::kinect::MIRROR;
    let classes: Vec<((usize, usize), (usize, usize))> = (0..JOINT_COUNT)
        .flat_map(|i| ((i + 1)..JOINT_COUNT).map(move |j| (i, j)))
        .filter_map(|(i, j)| {
            let (mi, mj) = (MIRROR[i], MIRROR[j]);
            let mirror = (mi.min(mj), mi.max(mj));
            (mirror >= (i, j)).then_some(((i, j), mirror))
        })
        .collect();
    let seen = |j: &JointObservation| j.state != TrackingState::NotTracked;
    frames
        .iter()
        .map(|f| {
            let d = |(a, b): (usize, usize)| {
                let (p, q) = (&f.joints[a], &f.joints[b]);
                if seen(p) && seen(q) {
                    p.position.distance(q.position) as f64
                } else {
                    f64::NAN
                }
            };
            let values = classes
                .iter()
                .map(|&(pair, mirror)| {
                    if pair == mirror {
                        d(pair)
                    } else {
                        0.5 * (d(pair) + d(mirror))
                    }
                })
                .collect();
            ((f.timestamp * fps).round() as i64, values)
        })
        .collect()
}

/// The correlation of two shape series with `b` `lag` frames later (all
/// distances at once, each centred on its own mean over the frames
/// compared) and how many frames were compared; `None` under 10.
fn shape_correlation(a: &Shapes, b: &Shapes, lag: i64) -> Option<(f64, usize)> {
    #[derive(Clone, Copy, Default)]
    struct Sums {
        n: usize,
        x: f64,
        y: f64,
        xx: f64,
        yy: f64,
        xy: f64,
    }
    let features = a.values().next()?.len();
    let mut sums = vec![Sums::default(); features];
    let mut pairs = 0;
    for (k, xs) in a {
        let Some(ys) = b.get(&(k - lag)) else {
            continue;
        };
        pairs += 1;
        for ((s, &x), &y) in sums.iter_mut().zip(xs).zip(ys) {
            if x.is_nan() || y.is_nan() {
                continue;
            }
            s.n += 1;
            s.x += x;
            s.y += y;
            s.xx += x * x;
            s.yy += y * y;
            s.xy += x * y;
        }
    }
    if pairs < MIN_OFFSET_PAIRS {
        return None;
    }
    let (mut cov, mut vx, mut vy) = (0.0, 0.0, 0.0);
    for s in sums.iter().filter(|s| s.n >= MIN_OFFSET_PAIRS) {
        let n = s.n as f64;
        cov += s.xy - s.x * s.y / n;
        vx += s.xx - s.x * s.x / n;
        vy += s.yy - s.y * s.y / n;
    }
    (vx > 0.0 && vy > 0.0).then(|| (cov / (vx * vy).sqrt(), pairs))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ntu_files_written_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("S001C003P001R001A001.skeleton");
        let frame = |seq: u64, x: f32| SensorFrame {
            sensor: 3,
            seq,
            timestamp: seq as f64 / 30.0,
            arrival: None,
            joints: [JointObservation {
                position: Vec3::new(x, 0.5, 2.5),
                state: TrackingState::Tracked,
            }; JOINT_COUNT],
        };
        write_ntu_skeleton(&path, &[frame(0, 0.1), frame(2, 0.3)], 72057594037927936).unwrap();
        let back = read_any_recording(&path, 0).unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!(back[1].seq, 2);
        assert_eq!(back[1].sensor, 3);
        assert!((back[1].joints[5].position.x - 0.3).abs() < 1e-6);
    }

    fn frame() -> SensorFrame {
        let mut joints = [JointObservation::NOT_TRACKED; JOINT_COUNT];
        for (n, j) in joints.iter_mut().enumerate() {
            *j = JointObservation {
                position: Vec3::new(n as f32 * 0.1, 1.0, 2.5),
                state: if n % 3 == 0 {
                    TrackingState::Inferred
                } else {
                    TrackingState::Tracked
                },
            };
        }
        SensorFrame {
            sensor: 3,
            seq: 42,
            timestamp: 1.25,
            arrival: Some(1.31),
            joints,
        }
    }

    #[test]
    fn frames_round_trip_through_json() {
        let f = frame();
        let back = SensorFrame::from_json(&f.to_json()).unwrap();
        assert_eq!(back.sensor, 3);
        assert_eq!(back.seq, 42);
        assert_eq!(back.arrival, Some(1.31));
        for (a, b) in f.joints.iter().zip(&back.joints) {
            assert!((a.position - b.position).length() < 1e-4);
            assert_eq!(a.state, b.state);
        }
    }

    #[test]
    fn bad_frames_are_refused_with_a_reason() {
        let good = frame().to_json();
        let cases = [
            (good.replace("\"v\":1", "\"v\":7"), "version"),
            (good.replace(",2]", ",5]"), "tracking state"),
            (good.replacen("[0.0000,", "[1e39,", 1), "out of range"),
            (
                good.replacen("[0.0000,", "[1e999,", 1),
                "number out of range",
            ),
            (good.replacen("[0.0000,", "[NaN,", 1), "expected value"),
            ("{\"sensor\":1}".to_string(), "missing field"),
            ("not json".to_string(), "expected"),
            (
                good.replacen("[0.0000,1.0000,2.5000,1],", "", 1),
                "expected 25 joints",
            ),
        ];
        for (text, expected) in cases {
            let err = SensorFrame::from_json(&text).unwrap_err();
            assert!(
                err.contains(expected),
                "{err:?} should mention {expected:?}"
            );
        }
    }

    #[test]
    fn recording_errors_name_the_line() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("rec.jsonl");
        std::fs::write(
            &path,
            format!("{}\n\n{{\"sensor\": 1}}\n", frame().to_json()),
        )
        .unwrap();
        let err = read_recording(&path).unwrap_err().to_string();
        // The column is where the JSON reader found the problem: the end
        // of the object that lacks fields.
        assert!(err.contains("rec.jsonl:3:13:"), "{err}");
        assert!(err.contains("missing field `seq`"), "{err}");
        assert!(!err.contains("at line"), "{err}");
    }

    fn ntu_text(frames: &[&[u64]]) -> String {
        let mut s = format!("{}\n", frames.len());
        for bodies in frames {
            s += &format!("{}\n", bodies.len());
            for id in *bodies {
                s += &format!("{id} 0 1 1 1 1 0 0.1 0.2 2\n25\n");
                for n in 0..25 {
                    s += &format!(
                        "{} 0.5 3.1 250 200 900 500 0.9 0 0.1 0 {}\n",
                        n as f32 * 0.01,
                        if n == 7 { 1 } else { 2 }
                    );
                }
            }
        }
        s
    }

    #[test]
    fn ntu_files_are_read_and_the_main_body_kept() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("S001C002P003R001A001.skeleton");
        std::fs::write(
            &path,
            ntu_text(&[&[72057594037931101], &[5, 72057594037931101], &[], &[5]]),
        )
        .unwrap();
        let frames = read_ntu_skeleton(&path).unwrap();
        assert_eq!(frames.len(), 4);
        assert_eq!(frames[1].len(), 2);
        assert_eq!(frames[0][0].joints[7].state, TrackingState::Inferred);
        let rec = read_any_recording(&path, 0).unwrap();
        assert_eq!(rec.len(), 2, "the main body is in frames 0 and 1");
        assert_eq!(rec[0].sensor, 2);
        assert_eq!(rec[1].seq, 1);
        assert!((rec[0].joints[1].position.x - 0.01).abs() < 1e-6);
    }

    #[test]
    fn ntu_errors_name_line_and_column() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.skeleton");
        let text = ntu_text(&[&[1]]).replacen("0.5 3.1", "0.5 x3.1", 1);
        std::fs::write(&path, text).unwrap();
        let err = read_ntu_skeleton(&path).unwrap_err().to_string();
        assert!(err.contains("bad.skeleton:5:"), "{err}");
        assert!(err.contains("x3.1"), "{err}");
        std::fs::write(&path, "2\n1\n1 0 1 1 1 1 0 0.1 0.2 2\n25\n").unwrap();
        let err = read_ntu_skeleton(&path).unwrap_err().to_string();
        assert!(err.contains("unexpected end of file"), "{err}");
    }

    fn body_of(bodies: &[NtuBody], id: u64) -> Option<&NtuBody> {
        bodies.iter().find(|b| b.body_id == id)
    }

    #[test]
    fn a_second_person_listed_first_is_not_followed() {
        let (_dir, files) = crate::sim::simulated_walk_files();
        let path = &files.ntu[1];
        let mut frames = read_ntu_skeleton(path).unwrap();
        let first = frames.iter().flatten().next().unwrap().clone();
        let performer = first.body_id;
        // A bystander stands still 1.5 m to the side, in every frame (the
        // performer is in fewer: the sensor drops some), listed first.
        let bystander = NtuBody {
            body_id: 7,
            joints: first.joints.map(|j| JointObservation {
                position: j.position + Vec3::new(1.5, 0.0, 0.3),
                ..j
            }),
        };
        for bodies in frames.iter_mut() {
            bodies.insert(0, bystander.clone());
        }
        write_ntu_bodies(path, &frames).unwrap();
        let frames = read_ntu_skeleton(path).unwrap();
        let read = read_recordings_with(&files.ntu, &ReadOptions::default()).unwrap();
        let choice = read.report.files[1].ntu.as_ref().unwrap();
        assert_eq!(choice.performer.ids, vec![performer]);
        let dropped: Vec<Vec<u64>> = choice.dropped.iter().map(|t| t.ids.clone()).collect();
        assert_eq!(dropped, vec![vec![7]]);
        assert!(choice.dropped[0].frames > choice.performer.frames);
        assert!(choice.performer.motion > 10.0 * choice.dropped[0].motion);
        let camera: Vec<&SensorFrame> = read.frames.iter().filter(|f| f.sensor == 1).collect();
        assert_eq!(camera.len(), choice.performer.frames);
        for f in camera {
            let body = body_of(&frames[f.seq as usize], performer).unwrap();
            assert_eq!(f.joints, body.joints, "frame {}", f.seq);
        }
        let notes = read.report.notes().join("\n");
        assert!(
            notes.contains(&format!("C001: 2 people in view; kept body {performer}")),
            "{notes}"
        );
        assert!(
            notes.contains(&format!("dropped 7 ({} frames", frames.len())),
            "{notes}"
        );
    }

    #[test]
    fn a_body_id_changing_mid_take_is_stitched() {
        let (_dir, files) = crate::sim::simulated_walk_files();
        let path = &files.ntu[0];
        let mut frames = read_ntu_skeleton(path).unwrap();
        let old = frames.iter().flatten().next().unwrap().body_id;
        let new = old + 1000;
        for bodies in frames[40..].iter_mut() {
            for b in bodies.iter_mut() {
                b.body_id = new;
            }
        }
        write_ntu_bodies(path, &frames).unwrap();
        let with_body = frames.iter().filter(|b| !b.is_empty()).count();
        let read =
            read_recordings_with(std::slice::from_ref(path), &ReadOptions::default()).unwrap();
        let choice = read.report.files[0].ntu.as_ref().unwrap();
        assert_eq!(choice.performer.ids, vec![old, new]);
        assert!(choice.dropped.is_empty());
        assert_eq!(
            read.frames.len(),
            with_body,
            "every frame with a body is kept"
        );
        let stitch = &choice.stitches[..];
        assert_eq!(stitch.len(), 1);
        let first_new = (40..).find(|&i| !frames[i].is_empty()).unwrap();
        let last_old = (0..40).rev().find(|&i| !frames[i].is_empty()).unwrap();
        assert_eq!(
            (stitch[0].last_frame, stitch[0].first_frame),
            (last_old, first_new)
        );
        assert!(stitch[0].distance < 0.3);
        let notes = read.report.notes().join("\n");
        assert!(
            notes.contains(&format!(
                "C000: body {old} vanished after frame {last_old} and body {new} appeared at frame {first_new}"
            )),
            "{notes}"
        );
    }

    /// A body `id` in frames `frames`, its pelvis at `x` (+1 cm a frame).
    fn walker(frames: std::ops::Range<usize>, id: u64, x: f32) -> Vec<(usize, NtuBody)> {
        frames
            .map(|i| {
                let mut joints = [JointObservation::NOT_TRACKED; JOINT_COUNT];
                for (n, j) in joints.iter_mut().enumerate() {
                    *j = JointObservation {
                        position: Vec3::new(x + 0.01 * i as f32, 0.05 * n as f32, 3.0),
                        state: TrackingState::Tracked,
                    };
                }
                (
                    i,
                    NtuBody {
                        body_id: id,
                        joints,
                    },
                )
            })
            .collect()
    }

    fn ntu_frames(count: usize, bodies: &[Vec<(usize, NtuBody)>]) -> Vec<Vec<NtuBody>> {
        let mut frames = vec![Vec::new(); count];
        for (i, b) in bodies.iter().flatten() {
            frames[*i].push(b.clone());
        }
        frames
    }

    #[test]
    fn only_nearby_ids_soon_after_are_stitched() {
        // Body 1 vanishes after frame 9; body 2 appears 2 frames later 4 cm
        // away (stitched), body 3 at once but 2 m away (another person), body
        // 4 a second later (too late).
        let frames = ntu_frames(
            60,
            &[
                walker(0..10, 1, 0.0),
                walker(12..30, 2, 0.0),
                walker(10..20, 3, 2.0),
            ],
        );
        let choice = choose_ntu_body(&frames, 30.0).unwrap();
        assert_eq!(choice.performer.ids, vec![1, 2]);
        assert_eq!(choice.stitches.len(), 1);
        assert_eq!(choice.dropped[0].ids, vec![3]);
        let mut late = frames.clone();
        for (i, b) in walker(0..10, 1, 0.0)
            .into_iter()
            .chain(walker(40..60, 4, 0.0))
        {
            late[i] = vec![b];
        }
        for bodies in late[10..40].iter_mut() {
            bodies.clear();
        }
        let choice = choose_ntu_body(&late, 30.0).unwrap();
        assert!(choice.stitches.is_empty(), "{:?}", choice.stitches);
        assert_eq!(choice.performer.ids, vec![4], "the longer track");
        assert_eq!(
            choice.gaps,
            vec![FrameRun {
                first: 0,
                count: 40
            }]
        );
    }

    #[test]
    fn frames_without_the_performer_and_frame_counts_are_reported() {
        let (_dir, files) = crate::sim::simulated_walk_files();
        // 194 frames each (a sensor that dropped its last frames wrote
        // fewer); then C001 loses the performer in frames 30-39, C002
        // starts with 5 empty frames and is one frame shorter.
        let read = |k: usize| {
            let mut frames = read_ntu_skeleton(&files.ntu[k]).unwrap();
            frames.resize(194, Vec::new());
            frames
        };
        write_ntu_bodies(&files.ntu[0], &read(0)).unwrap();
        let mut one = read(1);
        for bodies in one[30..40].iter_mut() {
            bodies.clear();
        }
        write_ntu_bodies(&files.ntu[1], &one).unwrap();
        let mut two = read(2);
        for bodies in two[..5].iter_mut() {
            bodies.clear();
        }
        two.pop();
        write_ntu_bodies(&files.ntu[2], &two).unwrap();
        let read = read_recordings_with(&files.ntu, &ReadOptions::default()).unwrap();
        let report = &read.report;
        let gaps = |k: usize| report.files[k].ntu.as_ref().unwrap().gaps.clone();
        let run = gaps(1)
            .into_iter()
            .find(|g| g.first <= 30 && g.first + g.count >= 40)
            .expect("frames 30-39 are a gap");
        let start = gaps(2)[0];
        assert_eq!(start.first, 0);
        assert!(start.count >= 5);
        assert!(report.frame_counts_differ());
        assert_eq!(report.files[2].file_frames, Some(193));
        let notes = report.notes().join("\n");
        assert!(notes.contains(&run.describe()), "{notes}");
        assert!(
            notes.contains(&format!(
                "{} (appears at frame {})",
                start.describe(),
                start.count
            )),
            "{notes}"
        );
        assert!(
            notes.contains(
                "the NTU files have different frame counts: C000 194, C001 194, C002 193"
            ),
            "{notes}"
        );
    }

    /// The time (s) at which sensor `k`'s frame 0 was captured, from its
    /// `.jsonl` recording: the phase NTU files lose.
    fn phase(files: &crate::sim::SimulationFiles, k: usize) -> f64 {
        let f = &read_recording(&files.recordings[k]).unwrap()[0];
        f.timestamp - f.seq as f64 / 30.0
    }

    #[test]
    fn a_camera_started_late_is_shifted_back_by_its_motion() {
        let (_dir, files) = crate::sim::simulated_walk_files();
        // C001 started 2 frames late: its frame i is the others' frame i + 2.
        let mut one = read_ntu_skeleton(&files.ntu[1]).unwrap();
        one.drain(..2);
        write_ntu_bodies(&files.ntu[1], &one).unwrap();
        let expected = 2.0 + (phase(&files, 1) - phase(&files, 0)) * 30.0;
        let read = read_recordings_with(&files.ntu, &ReadOptions::default()).unwrap();
        let offset = &read.report.time_offsets[0];
        assert_eq!(
            (offset.sensor, offset.reference.as_deref()),
            (1, Some("C000"))
        );
        let frames = offset.frames.unwrap();
        eprintln!(
            "C001 2 frames late: estimated {frames:+.2} frames, truly {expected:+.2}, correlation {:.2}",
            offset.correlation.unwrap()
        );
        assert!(offset.applied);
        assert!(
            (frames - expected).abs() < 0.5,
            "estimated {frames:+.2} frames, truly {expected:+.2}"
        );
        assert!(offset.correlation.unwrap() > MIN_OFFSET_CORRELATION);
        let shifted = read.frames.iter().find(|f| f.sensor == 1).unwrap();
        let want = shifted.seq as f64 / 30.0 + frames / 30.0;
        assert!((shifted.timestamp - want).abs() < 1e-9);
        let notes = read.report.notes().join("\n");
        assert!(
            notes.contains(&format!(
                "C001 shifted {frames:+.1} frames ({:.1} ms) to match C000, correlation",
                frames / 30.0 * 1000.0
            )),
            "{notes}"
        );
        // Switched off, or given.
        let off = ReadOptions {
            time_offsets: TimeOffsets::Off,
            ..Default::default()
        };
        let read = read_recordings_with(&files.ntu, &off).unwrap();
        assert!(read.report.time_offsets.is_empty());
        assert!(read
            .frames
            .iter()
            .all(|f| f.timestamp == f.seq as f64 / 30.0));
        let given = ReadOptions {
            input_fps: 15.0,
            time_offsets: "0, 2, 0".parse().unwrap(),
        };
        let read = read_recordings_with(&files.ntu, &given).unwrap();
        let f = read.frames.iter().find(|f| f.sensor == 1).unwrap();
        assert_eq!(f.timestamp, (f.seq as f64 + 2.0) / 15.0);
        let g = read.frames.iter().find(|f| f.sensor == 2).unwrap();
        assert_eq!(g.timestamp, g.seq as f64 / 15.0);
        let shifts: Vec<String> = read
            .report
            .notes()
            .into_iter()
            .filter(|n| n.contains("shifted"))
            .collect();
        assert_eq!(shifts, vec!["C001 shifted +2.0 frames (133.3 ms) as given"]);
        let wrong = ReadOptions {
            time_offsets: TimeOffsets::Frames(vec![0.0, 2.0]),
            ..Default::default()
        };
        let err = read_recordings_with(&files.ntu, &wrong)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("2 time offsets given for 3 recordings"),
            "{err}"
        );
    }

    #[test]
    fn time_offsets_are_parsed_and_written() {
        assert_eq!("auto".parse::<TimeOffsets>(), Ok(TimeOffsets::default()));
        assert_eq!("off".parse::<TimeOffsets>(), Ok(TimeOffsets::Off));
        let given: TimeOffsets = "0,+2,-1.5".parse().unwrap();
        assert_eq!(given, TimeOffsets::Frames(vec![0.0, 2.0, -1.5]));
        assert_eq!(given.to_string(), "0,2,-1.5");
        let err = "0,two".parse::<TimeOffsets>().unwrap_err();
        assert!(err.contains("\"two\" is not a number"), "{err}");
        assert!("0,inf".parse::<TimeOffsets>().is_err());
    }

    #[test]
    fn the_same_camera_or_file_twice_is_an_error_naming_both() {
        let (dir, files) = crate::sim::simulated_walk_files();
        let other_take = dir.path().join("S001C001P001R002A001.skeleton");
        std::fs::copy(&files.ntu[1], &other_take).unwrap();
        let paths = [files.ntu[0].clone(), files.ntu[1].clone(), other_take];
        let err = read_recordings(&paths).unwrap_err().to_string();
        assert!(
            err.contains("S001C001P001R001A001.skeleton and")
                && err.contains(
                    "S001C001P001R002A001.skeleton are both sensor 1 (camera 1 of its NTU name"
                ),
            "{err}"
        );
        let twice = [files.ntu[0].clone(), files.ntu[0].clone()];
        let err = read_recordings(&twice).unwrap_err().to_string();
        assert!(
            err.contains("S001C000P001R001A001.skeleton is given twice"),
            "{err}"
        );
        let also = [
            files.ntu[0].clone(),
            dir.path().join(".").join(files.ntu[0].file_name().unwrap()),
        ];
        let err = read_recordings(&also).unwrap_err().to_string();
        assert!(err.contains("given twice (also as"), "{err}");
        let copy = dir.path().join("copy.jsonl");
        std::fs::copy(&files.recordings[2], &copy).unwrap();
        let err = read_recordings(&[files.recordings[2].clone(), copy])
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("sensor-2.jsonl and") && err.contains("copy.jsonl are both sensor 2"),
            "{err}"
        );
    }

    #[test]
    fn files_without_a_camera_number_get_the_next_free_ids() {
        let (dir, files) = crate::sim::simulated_walk_files();
        // Real NTU cameras are numbered from 1.
        let c1 = dir.path().join("S001C001P001R001A001.skeleton");
        let c2 = dir.path().join("S001C002P001R001A001.skeleton");
        let extra = dir.path().join("extra-camera.skeleton");
        std::fs::copy(&files.ntu[1], &c2).unwrap();
        std::fs::copy(&files.ntu[2], &extra).unwrap();
        // (files.ntu[1] is S001C001P001R001A001.skeleton: c1.)
        assert_eq!(files.ntu[1], c1);
        let read = read_recordings_with(&[c1, c2, extra], &ReadOptions::default()).unwrap();
        let ids: Vec<(Vec<u16>, SensorIdSource)> = read
            .report
            .files
            .iter()
            .map(|f| (f.sensors.clone(), f.sensor_id))
            .collect();
        assert_eq!(
            ids,
            vec![
                (vec![1], SensorIdSource::NtuCamera),
                (vec![2], SensorIdSource::NtuCamera),
                (vec![3], SensorIdSource::AfterOthers),
            ]
        );
        let mut sensors: Vec<u16> = read.frames.iter().map(|f| f.sensor).collect();
        sensors.dedup();
        assert_eq!(sensors, vec![1, 2, 3]);
        assert!(read
            .report
            .notes()
            .contains(&"extra-camera.skeleton: no NTU camera number in its name (S001C002P001R001A001): sensor 3".to_string()));
    }

    #[test]
    fn camera_numbers_come_from_ntu_names_only() {
        let camera = |name: &str| ntu_camera_of(Path::new(name));
        assert_eq!(camera("S001C002P003R001A001.skeleton"), Some(2));
        assert_eq!(camera("take_S017C003P020R002A060_x.skeleton"), Some(3));
        assert_eq!(camera("Capture3.skeleton"), None);
        assert_eq!(camera("C2.skeleton"), None);
        assert_eq!(camera("S001C002P003.skeleton"), None);
    }
}
