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
//! RGB+D data set (several bodies per frame); [`ntu_sensor_frames`] keeps the
//! main body as a recording of one sensor.

use std::path::Path;

use mocap_core::error::Location;
use mocap_core::rotation::Vec3;
use mocap_core::{Error, ParseError, Result};
use serde::Deserialize;

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
/// of its name (`S001C002P003R001A001` is camera 2) or `default_sensor`.
pub fn read_any_recording(path: &Path, default_sensor: u16) -> Result<Vec<SensorFrame>> {
    let is_ntu = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("skeleton"));
    if is_ntu {
        let sensor = ntu_camera_of(path).unwrap_or(default_sensor);
        let frames = read_ntu_skeleton(path)?;
        Ok(ntu_sensor_frames(&frames, sensor, 30.0))
    } else {
        read_recording(path)
    }
}

/// Reads the sensor frames of several recordings ([`read_any_recording`];
/// the `i`th file's default sensor id is `i`). Fails when they hold no frame.
pub fn read_recordings(paths: &[std::path::PathBuf]) -> Result<Vec<SensorFrame>> {
    let mut frames = Vec::new();
    for (i, path) in paths.iter().enumerate() {
        frames.extend(read_any_recording(path, i as u16)?);
    }
    if frames.is_empty() {
        return Err(Error::Invalid(
            "the recordings hold no sensor frames".into(),
        ));
    }
    Ok(frames)
}

/// The camera number in an NTU file name (`...C002...` gives 2).
pub fn ntu_camera_of(path: &Path) -> Option<u16> {
    let name = path.file_stem()?.to_str()?;
    let at = name.find('C')?;
    let digits: String = name[at + 1..]
        .chars()
        .take_while(|c| c.is_ascii_digit())
        .collect();
    digits.parse().ok()
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

/// The main body of an NTU capture as frames of one sensor: the body id
/// present in the most frames (ties: the first seen). Frames without it are
/// dropped frames (a gap in `seq`). Timestamps are `frame / fps`.
pub fn ntu_sensor_frames(frames: &[Vec<NtuBody>], sensor: u16, fps: f64) -> Vec<SensorFrame> {
    let mut counts: Vec<(u64, usize)> = Vec::new();
    for bodies in frames {
        for b in bodies {
            match counts.iter_mut().find(|(id, _)| *id == b.body_id) {
                Some((_, c)) => *c += 1,
                None => counts.push((b.body_id, 1)),
            }
        }
    }
    let Some(&(main, _)) = counts
        .iter()
        .rev()
        .max_by_key(|(_, c)| *c)
        .or(counts.first())
    else {
        return Vec::new();
    };
    frames
        .iter()
        .enumerate()
        .filter_map(|(i, bodies)| {
            let body = bodies.iter().find(|b| b.body_id == main)?;
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
/// recordings do not (depth and colour pixel coordinates, joint
/// orientations, hand states, lean) are written as zeros. For test fixtures
/// and for tools that read NTU files.
pub fn write_ntu_skeleton(path: &Path, frames: &[SensorFrame], body_id: u64) -> Result<()> {
    use std::fmt::Write as _;
    let count = frames.iter().map(|f| f.seq + 1).max().unwrap_or(0) as usize;
    let mut by_seq: Vec<Option<&SensorFrame>> = vec![None; count];
    for f in frames {
        by_seq[f.seq as usize] = Some(f);
    }
    let mut text = String::with_capacity(count * 25 * 60 + 16);
    let _ = writeln!(text, "{count}");
    for frame in &by_seq {
        match frame {
            None => text.push_str("0\n"),
            Some(f) => {
                let _ = writeln!(text, "1\n{body_id} 0 0 0 0 0 0 0 0 2\n{JOINT_COUNT}");
                for j in &f.joints {
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
    }
    mocap_core::io::atomic::write_bytes_atomically(path, text.as_bytes())
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
}
