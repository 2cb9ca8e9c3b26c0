//! TRC marker files, as OpenSim reads them and Pose2Sim writes its
//! triangulated keypoints (`pose-3d/*.trc`).
//!
//! A TRC file is tab-separated text:
//!
//! ```text
//! PathFileType  4  (X/Y/Z)  walk.trc
//! DataRate  CameraRate  NumFrames  NumMarkers  Units  OrigDataRate  OrigDataStartFrame  OrigNumFrames
//! 60        60          100        21          m      60            1                   100
//! Frame#  Time  RHip        RKnee ...
//!               X1  Y1  Z1  X2  Y2  Z2 ...
//! 1       0     x   y   z   x   y   z ...
//! ```
//!
//! Each marker's name stands above its X column, followed by two empty cells;
//! a missing marker is written as empty cells. [`read_trc`] and [`write_trc`]
//! keep the positions on the file's axes: Pose2Sim writes them Y up
//! (OpenSim's convention), rotated from its calibration's Z-up world by its
//! `zup2yup`, and [`trc_to_zup`] and [`zup_to_trc`] go between the two.

use std::fs::File;
use std::io::{BufRead, BufReader, Write};
use std::path::Path;

use glam::DVec3;
use mocap_core::{Error, Result};

/// Marker positions over time.
#[derive(Debug, Clone, PartialEq)]
pub struct Markers {
    /// The markers' names, in the file's column order.
    pub names: Vec<String>,
    /// Frames per second (the header's `DataRate`).
    pub fps: f64,
    /// Metres, frame-major: `positions[frame][marker]`; NaN (all three
    /// coordinates) where a marker is missing (empty cells).
    pub positions: Vec<Vec<DVec3>>,
}

/// The most coordinates (frames × markers × 3) a header may announce: a
/// header that asks for more is refused before anything is allocated. 50
/// million values are more than an hour of 100 markers at 60 Hz (21.6
/// million).
const MAX_VALUES: usize = 50_000_000;

/// A point of a Pose2Sim TRC file (Y up) in the Z-up world of its
/// calibration: the inverse of Pose2Sim's `zup2yup`, `(X, Y, Z)` of the TRC
/// being `(y, z, x)` of the world.
///
/// A proper rotation (a cyclic permutation of the axes), so handedness and
/// left and right are kept. Checked on Pose2Sim's demo: the markers of
/// `S00_P00_T01_BalancingTrial_0-100.trc` turned by this and projected through
/// `Calib_qualisys.toml` land within a few pixels of the 2D keypoints they
/// were triangulated from, where the other axis orders miss by hundreds.
pub fn trc_to_zup(p: DVec3) -> DVec3 {
    DVec3::new(p.z, p.x, p.y)
}

/// A point of the calibration's Z-up world as Pose2Sim writes it to TRC
/// (Y up): its `zup2yup`, which takes the columns `Y, Z, X` of the Z-up
/// points as the TRC's `X, Y, Z`. The inverse of [`trc_to_zup`].
pub fn zup_to_trc(p: DVec3) -> DVec3 {
    DVec3::new(p.y, p.z, p.x)
}

/// Reads a TRC file. Positions are converted to metres (units `m`, `cm` or
/// `mm`) and kept on the file's axes (see [`trc_to_zup`]). Errors name the
/// file, line and column.
pub fn read_trc(path: &Path) -> Result<Markers> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    read_trc_from(BufReader::new(file), path)
}

/// The lines of a file, numbered from 1, without their line ends.
struct Lines<R> {
    reader: R,
    number: usize,
    buffer: Vec<u8>,
}

impl<R: BufRead> Lines<R> {
    /// The next line and its number; `None` at the end of the file.
    fn next(&mut self, path: &Path) -> Result<Option<(usize, String)>> {
        self.buffer.clear();
        let read = self
            .reader
            .read_until(b'\n', &mut self.buffer)
            .map_err(|e| Error::io(path, e))?;
        if read == 0 {
            return Ok(None);
        }
        self.number += 1;
        while matches!(self.buffer.last(), Some(b'\n' | b'\r')) {
            self.buffer.pop();
        }
        let line = String::from_utf8(std::mem::take(&mut self.buffer)).map_err(|e| {
            let column = String::from_utf8_lossy(&e.as_bytes()[..e.utf8_error().valid_up_to()])
                .chars()
                .count()
                + 1;
            Error::parse(path, self.number, column, "not UTF-8 text")
        })?;
        Ok(Some((self.number, line)))
    }

    /// The next line, which the format requires: `what` names it in the error
    /// when the file ends before it.
    fn expect(&mut self, path: &Path, what: &str) -> Result<(usize, String)> {
        match self.next(path)? {
            Some(line) => Ok(line),
            None => Err(Error::parse(
                path,
                self.number + 1,
                1,
                format!("the file ends before {what}"),
            )),
        }
    }
}

/// The tab-separated cells of a line, each with its 1-based column (in
/// characters) for error messages. Cells are trimmed of spaces.
fn cells(line: &str) -> Vec<(usize, &str)> {
    let mut column = 1;
    line.split('\t')
        .map(|cell| {
            let at = column;
            column += cell.chars().count() + 1;
            let leading = cell.len() - cell.trim_start().len();
            (at + cell[..leading].chars().count(), cell.trim())
        })
        .collect()
}

fn read_trc_from(reader: impl BufRead, path: &Path) -> Result<Markers> {
    let mut lines = Lines {
        reader,
        number: 0,
        buffer: Vec::new(),
    };

    let (n, first) = lines.expect(path, "its header")?;
    let first_cells = cells(&first);
    if !first_cells[0].1.eq_ignore_ascii_case("PathFileType") {
        return Err(Error::parse(
            path,
            n,
            1,
            "not a TRC file: expected `PathFileType` to begin the first line",
        ));
    }

    // Line 2 names the header values of line 3; the order is OpenSim's, but
    // look each key up rather than trust it.
    let (keys_line, keys) = lines.expect(path, "the header's keys (DataRate...)")?;
    let (values_line, values) = lines.expect(path, "the header's values")?;
    let keys = cells(&keys);
    let values = cells(&values);
    let value = |key: &str| -> Result<(usize, &str)> {
        let index = keys
            .iter()
            .position(|(_, k)| k.eq_ignore_ascii_case(key))
            .ok_or_else(|| {
                Error::parse(path, keys_line, 1, format!("the header has no `{key}`"))
            })?;
        values.get(index).copied().ok_or_else(|| {
            Error::parse(
                path,
                values_line,
                values.last().map_or(1, |(c, v)| c + v.chars().count()),
                format!("no value for `{key}`"),
            )
        })
    };
    let count = |key: &str| -> Result<usize> {
        let (column, text) = value(key)?;
        text.parse::<usize>().map_err(|_| {
            Error::parse(
                path,
                values_line,
                column,
                format!("`{key}` should be a whole number, not `{text}`"),
            )
        })
    };
    let fps = {
        let (column, text) = value("DataRate")?;
        match text.parse::<f64>() {
            Ok(fps) if fps.is_finite() && fps > 0.0 => fps,
            _ => {
                let message = format!("`DataRate` should be a positive frame rate, not `{text}`");
                return Err(Error::parse(path, values_line, column, message));
            }
        }
    };
    let frames = count("NumFrames")?;
    let marker_count = count("NumMarkers")?;
    let scale = {
        let (column, text) = value("Units")?;
        match text {
            "m" => 1.0,
            "cm" => 0.01,
            "mm" => 0.001,
            _ => {
                return Err(Error::parse(
                    path,
                    values_line,
                    column,
                    format!("`Units` should be m, cm or mm, not `{text}`"),
                ))
            }
        }
    };
    let too_many = frames
        .checked_mul(marker_count)
        .and_then(|n| n.checked_mul(3))
        .is_none_or(|n| n > MAX_VALUES);
    if too_many {
        return Err(Error::parse(
            path,
            values_line,
            1,
            format!(
                "{frames} frames of {marker_count} markers is more than this reader takes \
                 ({MAX_VALUES} coordinates)"
            ),
        ));
    }

    // Line 4: each marker's name above its X column, two empty cells after.
    let (names_line, names_text) = lines.expect(path, "the marker names (Frame#, Time, ...)")?;
    let name_cells = cells(&names_text);
    let mut names = Vec::with_capacity(marker_count);
    for (i, &(column, name)) in name_cells.iter().enumerate().skip(2) {
        if name.is_empty() {
            continue;
        }
        if (i - 2) % 3 != 0 || names.len() == marker_count {
            return Err(Error::parse(
                path,
                names_line,
                column,
                format!(
                    "`{name}` is not where a marker name goes: the header announces \
                     {marker_count} markers, each name above its X column"
                ),
            ));
        }
        names.push(name.to_string());
    }
    if names.len() != marker_count {
        // A name cell left empty where one was expected.
        let i = 2 + 3 * names.len();
        let column = name_cells
            .get(i)
            .map_or(names_text.chars().count() + 1, |(c, _)| *c);
        return Err(Error::parse(
            path,
            names_line,
            column,
            format!(
                "the header announces {marker_count} markers, this line names {}",
                names.len()
            ),
        ));
    }
    // Line 5: X1 Y1 Z1 ..., which says nothing the names do not.
    lines.expect(path, "the coordinate labels (X1, Y1, Z1, ...)")?;

    let columns = 2 + 3 * marker_count;
    // Trust the header's frame count for the allocation only as far as a
    // plausible file goes; the rows themselves decide.
    let mut positions: Vec<Vec<DVec3>> = Vec::with_capacity(frames.min(1 << 16));
    let mut last_line = lines.number;
    while let Some((n, line)) = lines.next(path)? {
        last_line = n;
        let row = cells(&line);
        // OpenSim's own files have a blank line before the data.
        if row.iter().all(|(_, c)| c.is_empty()) {
            continue;
        }
        if positions.len() == frames {
            return Err(Error::parse(
                path,
                n,
                1,
                format!("more frames than the header's NumFrames ({frames})"),
            ));
        }
        if row.len() < columns {
            let column = line.chars().count() + 1;
            return Err(Error::parse(
                path,
                n,
                column,
                format!(
                    "the row ends after {} of its {columns} cells (Frame#, Time and 3 per \
                     marker): a truncated file?",
                    row.len()
                ),
            ));
        }
        if let Some(&(column, extra)) = row[columns..].iter().find(|(_, c)| !c.is_empty()) {
            return Err(Error::parse(
                path,
                n,
                column,
                format!("`{extra}` beyond the {marker_count} markers the header announces"),
            ));
        }
        for &(column, text) in &row[..2] {
            if !text.parse::<f64>().is_ok_and(f64::is_finite) {
                return Err(Error::parse(
                    path,
                    n,
                    column,
                    format!("expected a frame number or time, found `{text}`"),
                ));
            }
        }
        let mut frame = Vec::with_capacity(marker_count);
        for marker in row[2..columns].chunks_exact(3) {
            let mut p = [0.0; 3];
            let mut missing = false;
            for (value, &(column, text)) in p.iter_mut().zip(marker) {
                if text.is_empty() || text.eq_ignore_ascii_case("nan") {
                    missing = true;
                    continue;
                }
                match text.parse::<f64>() {
                    Ok(v) if v.is_finite() => *value = v * scale,
                    _ => {
                        return Err(Error::parse(
                            path,
                            n,
                            column,
                            format!("expected a coordinate, found `{text}`"),
                        ))
                    }
                }
            }
            // A marker with any coordinate missing is missing whole: callers
            // check one coordinate, or `is_finite`.
            frame.push(if missing {
                DVec3::NAN
            } else {
                DVec3::from_array(p)
            });
        }
        positions.push(frame);
    }
    if positions.len() < frames {
        return Err(Error::parse(
            path,
            last_line + 1,
            1,
            format!(
                "the file ends after {} of the header's {frames} frames: a truncated file?",
                positions.len()
            ),
        ));
    }
    Ok(Markers {
        names,
        fps,
        positions,
    })
}

/// Writes `markers` as a TRC file (units `m`, positions as given: see
/// [`zup_to_trc`]), atomically. Frames are numbered from 1, at times
/// `frame / fps` from 0; a NaN marker is written as empty cells.
pub fn write_trc(path: &Path, markers: &Markers) -> Result<()> {
    if !(markers.fps.is_finite() && markers.fps > 0.0) {
        return Err(Error::Invalid(format!(
            "{}: a TRC needs a positive frame rate, not {}",
            path.display(),
            markers.fps
        )));
    }
    if let Some(name) = markers
        .names
        .iter()
        .find(|n| n.trim().is_empty() || n.trim() != n.as_str() || n.contains(['\t', '\n', '\r']))
    {
        return Err(Error::Invalid(format!(
            "{}: the marker name {name:?} cannot be written to a TRC (empty, or with tabs, \
             line breaks or surrounding spaces)",
            path.display()
        )));
    }
    for (f, frame) in markers.positions.iter().enumerate() {
        if frame.len() != markers.names.len() {
            return Err(Error::Invalid(format!(
                "{}: frame {f} has {} positions for {} markers",
                path.display(),
                frame.len(),
                markers.names.len()
            )));
        }
        if frame
            .iter()
            .any(|p| p.to_array().iter().any(|v| v.is_infinite()))
        {
            return Err(Error::Invalid(format!(
                "{}: frame {f} has an infinite position",
                path.display()
            )));
        }
    }
    let file_name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    mocap_core::io::atomic::write_atomically(path, |w| write_trc_to(w, &file_name, markers))
}

fn write_trc_to(w: &mut dyn Write, file_name: &str, markers: &Markers) -> std::io::Result<()> {
    let fps = markers.fps;
    let frames = markers.positions.len();
    let count = markers.names.len();
    writeln!(w, "PathFileType\t4\t(X/Y/Z)\t{file_name}")?;
    writeln!(
        w,
        "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame\tOrigNumFrames"
    )?;
    writeln!(w, "{fps}\t{fps}\t{frames}\t{count}\tm\t{fps}\t1\t{frames}")?;
    write!(w, "Frame#\tTime")?;
    for name in &markers.names {
        write!(w, "\t{name}\t\t")?;
    }
    writeln!(w)?;
    write!(w, "\t")?;
    for i in 1..=count {
        write!(w, "\tX{i}\tY{i}\tZ{i}")?;
    }
    writeln!(w)?;
    for (f, frame) in markers.positions.iter().enumerate() {
        // `{}` writes the shortest text that reads back to the same f64.
        write!(w, "{}\t{}", f + 1, f as f64 / fps)?;
        for p in frame {
            if p.is_nan() {
                write!(w, "\t\t\t")?;
            } else {
                write!(w, "\t{}\t{}\t{}", p.x, p.y, p.z)?;
            }
        }
        writeln!(w)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const DEMO_TRC: &str = "pose2sim-demo/S00_P00_SingleParticipant/S00_P00_T01_BalancingTrial/\
                            pose-3d/S00_P00_T01_BalancingTrial_0-100.trc";

    fn sample() -> Markers {
        Markers {
            names: vec!["RHip".into(), "LHip".into(), "Nose".into()],
            fps: 60.0,
            positions: (0..5)
                .map(|f| {
                    let t = f as f64;
                    vec![
                        DVec3::new(0.1 * t, 0.9, -1.4 + 1e-9 * t),
                        if f == 2 {
                            DVec3::NAN
                        } else {
                            DVec3::new(-0.1, 0.91, 1.0 / 3.0)
                        },
                        DVec3::new(0.0, 1.6 + t / 7.0, -0.2),
                    ]
                })
                .collect(),
        }
    }

    fn read_text(text: &str) -> Result<Markers> {
        read_trc_from(text.as_bytes(), Path::new("test.trc"))
    }

    /// The error's line and column, and its message.
    fn parse_error(text: &str) -> (usize, usize, String) {
        match read_text(text) {
            Err(Error::Parse(e)) => (e.location.line, e.location.column, e.message),
            other => panic!("expected a parse error, got {other:?}"),
        }
    }

    fn written(markers: &Markers) -> String {
        let mut out = Vec::new();
        write_trc_to(&mut out, "test.trc", markers).unwrap();
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn reads_pose2sims_demo_trc() {
        let Some(path) = mocap_testdata::shared(DEMO_TRC) else {
            return;
        };
        let m = read_trc(&path).unwrap();
        assert_eq!(m.fps, 60.0);
        assert_eq!(m.names.len(), 21);
        assert_eq!(m.names[0], "RHip");
        assert_eq!(m.names[20], "LWrist");
        assert_eq!(m.positions.len(), 100);
        assert!(m.positions.iter().all(|f| f.len() == 21));
        // First row, first marker, as in the file.
        assert_eq!(
            m.positions[0][0],
            DVec3::new(
                -0.06497214796810755,
                0.9015045550714222,
                -1.4005886926185436
            )
        );
        // Y up in the file: the hips about 0.9 m up, the nose above them;
        // in the calibration's world that height is z.
        let hip = m.positions[0][m.names.iter().position(|n| n == "RHip").unwrap()];
        let nose = m.positions[0][m.names.iter().position(|n| n == "Nose").unwrap()];
        assert!(nose.y > hip.y + 0.5, "{hip} {nose}");
        assert!((trc_to_zup(hip).z - hip.y).abs() < 1e-12);
    }

    /// The axis convention on real data: Pose2Sim's triangulated markers,
    /// turned by `trc_to_zup`, project through its calibration onto the 2D
    /// keypoints they came from; read as they are, they land far off.
    #[test]
    fn pose2sims_markers_turned_z_up_reproject_onto_their_keypoints() {
        let Some(demo) = mocap_testdata::shared("pose2sim-demo") else {
            return;
        };
        let rig =
            crate::camera::read_calibration(&demo.join("S00_Calibration/Calib_qualisys.toml"))
                .unwrap();
        let m = read_trc(&demo.join(DEMO_TRC.trim_start_matches("pose2sim-demo/"))).unwrap();
        let trial = demo.join("S00_P00_SingleParticipant/S00_P00_T01_BalancingTrial");
        let layout = crate::layout::Layout::Body25B;
        let median = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let mut pooled = Vec::new();
        for (c, camera) in rig.cameras.iter().enumerate() {
            let folder = trial.join(format!("pose-associated/cam{:02}_json", c + 1));
            let views = crate::keypoints::read_openpose_folder(&folder, Some(layout)).unwrap();
            let (mut turned, mut raw) = (Vec::new(), Vec::new());
            // TRC row f is the camera's frame f.
            for (f, frame) in views.frames.iter().enumerate().step_by(10) {
                let Some(person) = frame
                    .people
                    .iter()
                    .find(|p| p.keypoints.iter().any(|k| k[2] > 0.0))
                else {
                    continue;
                };
                for (name, &p) in m.names.iter().zip(&m.positions[f]) {
                    let [x, y, s] = person.keypoints[layout.index_of(name).unwrap()];
                    if s < 0.5 || p.is_nan() {
                        continue;
                    }
                    let seen = glam::DVec2::new(x as f64, y as f64);
                    let off = |q: DVec3| {
                        camera
                            .project(q)
                            .map_or(f64::INFINITY, |q| q.distance(seen))
                    };
                    turned.push(off(trc_to_zup(p)));
                    raw.push(off(p));
                }
            }
            assert!(turned.len() > 50, "{}", turned.len());
            pooled.extend_from_slice(&turned);
            let (turned, raw) = (median(turned), median(raw));
            eprintln!("camera {c}: median {turned:.1} px");
            // Measured on every tenth frame: 7.3-17.1 px per camera (cam_03,
            // the highest, has a few right joints 50 px off that Pose2Sim
            // left out of its triangulation).
            assert!(turned < 20.0, "camera {c}: {turned} px turned");
            assert!(raw > 300.0, "camera {c}: {raw} px as read");
        }
        let pooled = median(pooled);
        assert!(pooled < 12.0, "all cameras: {pooled} px");
    }

    #[test]
    fn write_then_read_gives_the_markers_back() {
        let markers = sample();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("round.trc");
        write_trc(&path, &markers).unwrap();
        let back = read_trc(&path).unwrap();
        assert_eq!(back.names, markers.names);
        assert_eq!(back.fps, markers.fps);
        assert_eq!(back.positions.len(), markers.positions.len());
        for (a, b) in back.positions.iter().zip(&markers.positions) {
            for (p, q) in a.iter().zip(b) {
                // NaN is missing on both sides; everything else bit-exact.
                assert!(p == q || (p.is_nan() && q.is_nan()), "{p} against {q}");
            }
        }
        assert!(back.positions[2][1].is_nan());
        // The layout OpenSim expects.
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "PathFileType\t4\t(X/Y/Z)\tround.trc");
        assert_eq!(lines[2], "60\t60\t5\t3\tm\t60\t1\t5");
        assert_eq!(lines[3], "Frame#\tTime\tRHip\t\t\tLHip\t\t\tNose\t\t");
        assert_eq!(lines[4], "\t\tX1\tY1\tZ1\tX2\tY2\tZ2\tX3\tY3\tZ3");
        assert!(lines[7].starts_with("3\t0.03333333333333333\t0.2\t0.9\t"));
        assert!(lines[7].contains("\t\t\t\t0\t"), "{}", lines[7]);
    }

    #[test]
    fn millimetres_are_read_as_metres_and_blank_lines_are_skipped() {
        let text = "PathFileType\t4\t(X/Y/Z)\tx.trc\n\
                    DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\n\
                    100\t100\t2\t1\tmm\n\
                    Frame#\tTime\tA\t\t\n\
                    \t\tX1\tY1\tZ1\n\
                    \n\
                    1\t0\t1000\t-250\t5\r\n\
                    2\t0.01\t\t\t\n";
        let m = read_text(text).unwrap();
        assert_eq!(m.fps, 100.0);
        assert_eq!(m.positions[0][0], DVec3::new(1.0, -0.25, 0.005));
        assert!(m.positions[1][0].is_nan());
    }

    #[test]
    fn a_truncated_file_is_an_error_at_its_end() {
        let text = written(&sample());
        // Cut in the middle of the fourth frame's row, after `4\t0.05`.
        let cut = text.match_indices('\n').nth(7).unwrap().0 + 7;
        let (line, column, message) = parse_error(&text[..cut]);
        assert_eq!((line, column), (9, 7), "{message}");
        assert!(message.contains("truncated"), "{message}");
        // Cut after a whole row: frames missing.
        let cut = text.match_indices('\n').nth(7).unwrap().0 + 1;
        let (line, column, message) = parse_error(&text[..cut]);
        assert_eq!((line, column), (9, 1), "{message}");
        assert!(message.contains("3 of the header's 5 frames"), "{message}");
        // Cut inside the header.
        let (line, _, message) = parse_error("PathFileType\t4\t(X/Y/Z)\tx.trc\n");
        assert_eq!(line, 2, "{message}");
    }

    #[test]
    fn a_bad_number_is_an_error_at_its_cell() {
        let text = written(&sample()).replacen("\t0.9\t", "\t0.9x\t", 1);
        let (line, column, message) = parse_error(&text);
        // Row of frame 1 (line 6): "1\t0\t0\t0.9x": the fourth cell, column 7.
        assert_eq!((line, column), (6, 7), "{message}");
        assert!(message.contains("`0.9x`"), "{message}");

        let text = written(&sample()).replacen("\tm\t", "\tinches\t", 1);
        let (line, column, message) = parse_error(&text);
        assert_eq!((line, column), (3, 11), "{message}");
        assert!(message.contains("inches"), "{message}");
    }

    #[test]
    fn absurd_headers_are_refused_before_allocating() {
        let text = "PathFileType\t4\t(X/Y/Z)\tx.trc\n\
                    DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\n\
                    60\t60\t99999999999\t400\tm\n";
        let (line, _, message) = parse_error(text);
        assert_eq!(line, 3);
        assert!(message.contains("more than this reader takes"), "{message}");
        let text = text.replace(
            "99999999999\t400",
            "18446744073709551615\t18446744073709551615",
        );
        assert!(parse_error(&text).2.contains("more than"));
        // A header whose marker count disagrees with the names.
        let text = written(&sample()).replacen("\t5\t3\t", "\t5\t4\t", 1);
        let (line, _, message) = parse_error(&text);
        assert_eq!(line, 4, "{message}");
        // Not a TRC at all.
        assert_eq!(parse_error("Frame,Time\n1,0\n").0, 1);
    }

    #[test]
    fn the_axis_conversions_are_inverse_proper_rotations() {
        let p = DVec3::new(0.3, -1.2, 1.7);
        assert_eq!(trc_to_zup(zup_to_trc(p)), p);
        assert_eq!(zup_to_trc(trc_to_zup(p)), p);
        // The world's up (z) is the TRC's up (y).
        assert_eq!(zup_to_trc(DVec3::Z), DVec3::Y);
        // Pose2Sim's zup2yup: TRC columns are the world's Y, Z, X.
        assert_eq!(
            zup_to_trc(DVec3::new(1.0, 2.0, 3.0)),
            DVec3::new(2.0, 3.0, 1.0)
        );
        // A rotation, not a mirror: right-handed axes stay right-handed.
        let m = glam::DMat3::from_cols(
            zup_to_trc(DVec3::X),
            zup_to_trc(DVec3::Y),
            zup_to_trc(DVec3::Z),
        );
        assert_eq!(m.determinant(), 1.0);
    }

    #[test]
    fn unwritable_markers_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.trc");
        let mut m = sample();
        m.positions[1].pop();
        assert!(write_trc(&path, &m).is_err());
        let mut m = sample();
        m.names[0] = "R\tHip".into();
        assert!(write_trc(&path, &m).is_err());
        let mut m = sample();
        m.positions[0][0].x = f64::INFINITY;
        assert!(write_trc(&path, &m).is_err());
        assert!(!path.exists());
    }
}
