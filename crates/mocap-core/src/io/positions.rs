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
