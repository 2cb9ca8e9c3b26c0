//! Global joint positions as CSV or JSON, for spreadsheets, plotting and other
//! tools.
//!
//! CSV: a header `frame,time,<joint>.x,<joint>.y,<joint>.z,...` then one row
//! per frame. JSON: `{"frame_time": s, "joints": [names], "parents": [index or
//! null], "positions": [[[x, y, z], ...per joint], ...per frame]}`.

use std::io::Write;

use crate::kinematics::{forward_kinematics_range, frame_pieces};
use crate::motion::Motion;

/// Writes the positions of every frame as CSV (computed a piece of the take
/// at a time: memory does not grow with the take).
pub fn write_positions_csv(out: &mut dyn Write, motion: &Motion) -> std::io::Result<()> {
    check_finite(motion)?;
    write!(out, "frame,time")?;
    for joint in motion.skeleton().joints() {
        let name = csv_field(&joint.name);
        write!(out, ",{name}.x,{name}.y,{name}.z")?;
    }
    writeln!(out)?;
    for piece in frame_pieces(motion.frame_count()) {
        let poses = forward_kinematics_range(motion, piece.clone());
        for (k, f) in piece.enumerate() {
            write!(out, "{f},{}", f as f64 * motion.frame_time())?;
            for p in poses.frame_positions(k) {
                write!(out, ",{},{},{}", p.x, p.y, p.z)?;
            }
            writeln!(out)?;
        }
    }
    Ok(())
}

/// Writes the positions of every frame as one JSON object (a piece of the
/// take at a time, as [`write_positions_csv`]).
pub fn write_positions_json(out: &mut dyn Write, motion: &Motion) -> std::io::Result<()> {
    check_finite(motion)?;
    let skeleton = motion.skeleton();
    write!(out, "{{\"frame_time\":{},\"joints\":[", motion.frame_time())?;
    for (i, joint) in skeleton.joints().iter().enumerate() {
        let sep = if i == 0 { "" } else { "," };
        write!(out, "{sep}{}", json_string(&joint.name))?;
    }
    write!(out, "],\"parents\":[")?;
    for (i, joint) in skeleton.joints().iter().enumerate() {
        let sep = if i == 0 { "" } else { "," };
        match joint.parent {
            Some(p) => write!(out, "{sep}{p}")?,
            None => write!(out, "{sep}null")?,
        }
    }
    write!(out, "],\"positions\":[")?;
    for piece in frame_pieces(motion.frame_count()) {
        let poses = forward_kinematics_range(motion, piece.clone());
        for (k, f) in piece.enumerate() {
            write!(out, "{}[", if f == 0 { "" } else { "," })?;
            for (j, p) in poses.frame_positions(k).iter().enumerate() {
                let sep = if j == 0 { "" } else { "," };
                write!(out, "{sep}[{},{},{}]", p.x, p.y, p.z)?;
            }
            write!(out, "]")?;
        }
    }
    writeln!(out, "]}}")
}

/// Refuses positions that are not finite numbers (offsets and channel values
/// near the largest floats overflow in forward kinematics), which neither
/// CSV readers nor JSON could take, before anything is written. A first pass
/// over the take, a piece at a time like the writers.
fn check_finite(motion: &Motion) -> std::io::Result<()> {
    for piece in frame_pieces(motion.frame_count()) {
        let poses = forward_kinematics_range(motion, piece.clone());
        let Some(i) = poses.positions.iter().position(|p| !p.is_finite()) else {
            continue;
        };
        let joints = poses.joint_count.max(1);
        let joint = &motion.skeleton().joints()[i % joints].name;
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "the position of joint {joint} in frame {} is not a finite number ({}), \
                 so the positions cannot be written",
                piece.start + i / joints,
                poses.positions[i]
            ),
        ));
    }
    Ok(())
}

/// Quotes a CSV field when it holds a comma, quote or line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// A JSON string literal.
fn json_string(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::bvh::read_bvh_from;

    #[test]
    fn positions_that_overflow_are_refused_before_anything_is_written() {
        let text =
            "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Xposition Yposition Zposition\n\
                    JOINT Spine\n{\nOFFSET 0 3e38 0\nCHANNELS 0\n\
                    JOINT Head\n{\nOFFSET 0 3e38 0\nCHANNELS 0\n\
                    End Site\n{\nOFFSET 0 1 0\n}\n}\n}\n}\n\
                    MOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0\n";
        let motion = read_bvh_from(text.as_bytes(), std::path::Path::new("far.bvh")).unwrap();
        for write in [write_positions_csv, write_positions_json] {
            let mut out = Vec::new();
            let e = write(&mut out, &motion).unwrap_err().to_string();
            assert!(
                e.starts_with("the position of joint Head in frame 0 is not a finite number"),
                "{e}"
            );
            assert!(out.is_empty());
        }
    }
}
