//! Biovision Hierarchy (BVH) files: read and write.
//!
//! # The format
//!
//! A BVH file has two parts. The `HIERARCHY` part describes the skeleton as
//! nested blocks, one per joint:
//!
//! ```text
//! HIERARCHY
//! ROOT Hips
//! {
//!     OFFSET 0 0 0
//!     CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
//!     JOINT Spine
//!     {
//!         OFFSET 0 10.5 0
//!         CHANNELS 3 Zrotation Xrotation Yrotation
//!         End Site
//!         {
//!             OFFSET 0 8 0
//!         }
//!     }
//! }
//! MOTION
//! Frames: 2
//! Frame Time: 0.0333333
//! 0 90 0 0 0 0 5 0 0
//! 0 91 0 0 0 0 6 0 0
//! ```
//!
//! `OFFSET` is the joint's rest translation from its parent, `CHANNELS` the
//! columns the joint owns in every frame line, in that order. Rotations are
//! in degrees and intrinsic in the listed order (see [`crate::rotation`]).
//! `End Site` blocks mark the tip of a chain and have only an offset. The
//! `MOTION` part gives the frame count, the seconds between frames, then one
//! line per frame with the values of every joint's channels, joints in the
//! order they appear in the hierarchy. A file may hold several `ROOT` blocks
//! one after the other; their channels follow each other in the frame lines.
//!
//! # What the reader tolerates
//!
//! Real exporters differ in many small ways, all of which are read:
//!
//! - any subset or permutation of the six channels on any joint, including
//!   none (`CHANNELS 0`, or no `CHANNELS` line at all), and a missing `OFFSET`
//!   (taken as zero);
//! - tabs or spaces anywhere between words, `\n`, `\r\n` or a mix of both as
//!   line ends, a UTF-8 byte order mark, blank lines anywhere;
//! - keywords in any case (`ROOT`, `Root`, `End Site`, `END SITE`,
//!   `EndSite`, `Frame time:`), `{` on the `ROOT`/`JOINT`/`End Site` line,
//!   `}}` for two closing braces, a name after `End Site`;
//! - joint names with spaces or any bytes: the rest of the `ROOT`/`JOINT`
//!   line (up to a `{`) is the name, and bytes that are not UTF-8 (Latin-1 names from old
//!   tools) are decoded lossily, never refused;
//! - `Frames:` and `Frame Time:` in either order, followed by spaces or tabs,
//!   with or without the colon; numbers such as `.0083333`, `-0.0000`,
//!   `8.09E-05`, `1e-015`;
//! - lines whose first word starts with `#` or `//` in the header (comments,
//!   in any encoding);
//! - blank lines between or after the frame lines.
//!
//! It refuses, with a [`ParseError`](crate::ParseError) naming the file, the 1-based line and
//! column (counted in bytes) and what was expected: a frame line with the
//! wrong number of values, fewer or more frame lines than `Frames:` announced,
//! an unknown channel name, a `CHANNELS n` line that lists another number of
//! names, a value that is not a number, a missing `MOTION`, `Frames:` or
//! `Frame Time:`, unbalanced braces, two joints of the same name, and an
//! empty file. Old Mac line ends (`\r` alone) are not supported.
//!
//! # Speed and memory
//!
//! The reader streams: it reads one line at a time from a [`BufRead`] into
//! one reused buffer and parses numbers straight into the motion's `Vec<f32>`,
//! reserved once from `Frames:` times the channel count. Memory is therefore
//! the values (4 bytes each, about half the size of the text) plus one line.
//!
//! # Writing
//!
//! The writer uses tabs for indentation and writes every number in the
//! shortest form that reads back to the same `f32` (the frame time as the
//! shortest `f64`), so reading a written motion gives bit-identical values.
//! Joints are written depth first from each root, children in skeleton
//! order; for a skeleton read from a BVH file this is the file's own order.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, BufRead, BufReader, Write};
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::io::atomic::write_atomically;
use crate::motion::{Motion, FRAME_TIME_RANGE};
use crate::rotation::Vec3;
use crate::skeleton::{Channel, Joint, Skeleton};

/// Reads a BVH file.
///
/// Errors: [`Error::Io`] when the file cannot be read, [`Error::Parse`] with
/// the line and column when it does not follow the format.
pub fn read_bvh(path: &Path) -> Result<Motion> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let file_size = file.metadata().ok().map(|m| m.len());
    let reader = BufReader::with_capacity(1 << 16, file);
    Parser::new(reader, path, file_size).parse()
}

/// What the header of a BVH file says, read without its frame lines: the
/// skeleton, the number of frames `Frames:` announces and the frame time
/// (a file with another number of frame lines is refused by [`read_bvh`]).
/// For judging the size of a take before reading it.
pub fn read_bvh_header(path: &Path) -> Result<(Skeleton, usize, f64)> {
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let mut parser = Parser::new(BufReader::with_capacity(1 << 16, file), path, None);
    let (skeleton, header) = parser.parse_header()?;
    Ok((skeleton, header.frames, header.frame_time))
}

/// Reads BVH text from `reader`; `path_for_errors` is the name that errors
/// give for the source.
pub fn read_bvh_from<R: BufRead>(reader: R, path_for_errors: &Path) -> Result<Motion> {
    Parser::new(reader, path_for_errors, None).parse()
}

/// Writes `motion` as a BVH file, atomically (the file is either whole or
/// not there at all).
pub fn write_bvh(path: &Path, motion: &Motion) -> Result<()> {
    write_atomically(path, |w| write_bvh_to(w, motion))
}

/// Writes `motion` as BVH text.
///
/// Fails with [`io::ErrorKind::InvalidInput`], before writing anything, when
/// the file would not read back the same: a joint name that is empty, has a
/// line break or a `{`, or spaces at either end; an offset or a channel value
/// that is not a finite number.
pub fn write_bvh_to(writer: &mut dyn Write, motion: &Motion) -> io::Result<()> {
    let skeleton = motion.skeleton();
    let joints = skeleton.joints();
    for joint in joints {
        check_writable_name(&joint.name)?;
    }
    check_finite(motion)?;

    // Children of every joint, and the roots, in skeleton order. Parents come
    // before children, so one pass gives every joint's depth too.
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); joints.len()];
    let mut roots = Vec::new();
    let mut depth = vec![0usize; joints.len()];
    for (i, joint) in joints.iter().enumerate() {
        match joint.parent {
            Some(p) => {
                children[p].push(i);
                depth[i] = depth[p] + 1;
            }
            None => roots.push(i),
        }
    }

    // Depth-first walk with an explicit stack (no recursion, so a very deep
    // chain cannot overflow the call stack). `order` collects the joints in
    // the order they are written, which is the column order of the frames.
    enum Step {
        Open(usize),
        Close(usize),
    }
    let mut order = Vec::with_capacity(joints.len());
    let mut stack: Vec<Step> = roots.iter().rev().map(|&r| Step::Open(r)).collect();
    writer.write_all(b"HIERARCHY\n")?;
    while let Some(step) = stack.pop() {
        match step {
            Step::Open(j) => {
                let joint = &joints[j];
                let tabs = depth[j];
                let keyword = if joint.parent.is_none() {
                    "ROOT"
                } else {
                    "JOINT"
                };
                indent(writer, tabs)?;
                writeln!(writer, "{keyword} {}", joint.name)?;
                indent(writer, tabs)?;
                writer.write_all(b"{\n")?;
                write_offset(writer, tabs + 1, joint.offset)?;
                indent(writer, tabs + 1)?;
                write!(writer, "CHANNELS {}", joint.channels.len())?;
                for channel in &joint.channels {
                    write!(writer, " {}", channel.name())?;
                }
                writer.write_all(b"\n")?;
                order.push(j);
                stack.push(Step::Close(j));
                stack.extend(children[j].iter().rev().map(|&c| Step::Open(c)));
            }
            Step::Close(j) => {
                let tabs = depth[j];
                for &end_site in &joints[j].end_sites {
                    indent(writer, tabs + 1)?;
                    writer.write_all(b"End Site\n")?;
                    indent(writer, tabs + 1)?;
                    writer.write_all(b"{\n")?;
                    write_offset(writer, tabs + 2, end_site)?;
                    indent(writer, tabs + 1)?;
                    writer.write_all(b"}\n")?;
                }
                indent(writer, tabs)?;
                writer.write_all(b"}\n")?;
            }
        }
    }

    writeln!(writer, "MOTION")?;
    writeln!(writer, "Frames: {}", motion.frame_count())?;
    writeln!(writer, "Frame Time: {}", motion.frame_time())?;

    // Column ranges of the joints in written order.
    let columns: Vec<(usize, usize)> = order
        .iter()
        .map(|&j| {
            let start = skeleton.channel_start(j);
            (start, start + joints[j].channels.len())
        })
        .collect();
    // One reused line buffer: `{}` on f32 is the shortest text that parses
    // back to the same value.
    let mut line = String::new();
    for f in 0..motion.frame_count() {
        line.clear();
        let frame = motion.frame(f);
        for &(start, end) in &columns {
            for value in &frame[start..end] {
                if !line.is_empty() {
                    line.push(' ');
                }
                // Writing to a String cannot fail.
                let _ = write!(line, "{value}");
            }
        }
        line.push('\n');
        writer.write_all(line.as_bytes())?;
    }
    Ok(())
}

fn check_writable_name(name: &str) -> io::Result<()> {
    let bad = name.is_empty()
        || name.chars().any(|c| c.is_control() && c != '\t')
        || name.trim() != name
        || name.contains('{');
    if bad {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("joint name {name:?} cannot be written to BVH"),
        ));
    }
    Ok(())
}

/// Every offset and channel value is a finite number: a NaN or an infinity
/// (from `--scale NaN`, or an overflow) would write a file no reader takes.
fn check_finite(motion: &Motion) -> io::Result<()> {
    let refuse = |what: String| {
        Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("{what} is not a finite number, so the motion cannot be written"),
        ))
    };
    for joint in motion.skeleton().joints() {
        let offsets = std::iter::once(joint.offset).chain(joint.end_sites.iter().copied());
        if let Some(bad) = offsets.into_iter().find(|o| !o.is_finite()) {
            return refuse(format!("an offset of joint {} ({bad})", joint.name));
        }
    }
    let channels = motion.skeleton().channel_count().max(1);
    if let Some(i) = motion.values().iter().position(|v| !v.is_finite()) {
        let value = motion.values()[i];
        return refuse(format!("channel value {value} of frame {}", i / channels));
    }
    Ok(())
}

/// The deepest indentation written, in tabs: deeper than any real rig (a
/// Mixamo finger tip is about 12 deep), and a cap so that a chain nested
/// 10,000 deep writes a file that grows with its joints, not their square.
/// Readers go by the braces, not the tabs.
const MAX_INDENT: usize = 32;

fn indent(writer: &mut dyn Write, tabs: usize) -> io::Result<()> {
    const TABS: [u8; MAX_INDENT] = [b'\t'; MAX_INDENT];
    writer.write_all(&TABS[..tabs.min(MAX_INDENT)])
}

fn write_offset(writer: &mut dyn Write, tabs: usize, offset: Vec3) -> io::Result<()> {
    indent(writer, tabs)?;
    writeln!(writer, "OFFSET {} {} {}", offset.x, offset.y, offset.z)
}

// ---------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------

/// The source read line by line into one reused buffer, with the position
/// of the current line for error messages.
struct Lines<R> {
    reader: R,
    path: PathBuf,
    /// The current line without its line end.
    line: Vec<u8>,
    /// 1-based number of the current line; 0 before the first.
    number: usize,
    /// Whether the last line read ended with `\n` (for end-of-file errors).
    ended_with_newline: bool,
    /// Length of the last line read (kept after end of file).
    last_len: usize,
    /// Next byte of `line` to scan for header tokens.
    cursor: usize,
}

/// A word of the header: where it is on the current line.
#[derive(Debug, Clone, Copy)]
struct Token {
    line: usize,
    start: usize,
    end: usize,
}

impl Token {
    fn column(self) -> usize {
        self.start + 1
    }
}

impl<R: BufRead> Lines<R> {
    fn new(reader: R, path: &Path) -> Self {
        Lines {
            reader,
            path: path.to_path_buf(),
            line: Vec::with_capacity(4096),
            number: 0,
            ended_with_newline: true,
            last_len: 0,
            cursor: 0,
        }
    }

    /// Reads the next line into `self.line`; `false` at the end of the file.
    fn advance(&mut self) -> Result<bool> {
        self.line.clear();
        self.cursor = 0;
        let read = self
            .reader
            .read_until(b'\n', &mut self.line)
            .map_err(|e| Error::io(&self.path, e))?;
        if read == 0 {
            return Ok(false);
        }
        self.number += 1;
        self.ended_with_newline = self.line.last() == Some(&b'\n');
        if self.ended_with_newline {
            self.line.pop();
        }
        if self.line.last() == Some(&b'\r') {
            self.line.pop();
        }
        if self.number == 1 && self.line.starts_with(b"\xEF\xBB\xBF") {
            self.line.drain(..3);
        }
        self.last_len = self.line.len();
        Ok(true)
    }

    /// The next word of the header, reading lines as needed and skipping
    /// comment lines; `None` at the end of the file.
    fn next_token(&mut self) -> Result<Option<Token>> {
        loop {
            if let Some((start, word)) = Fields::new(&self.line, self.cursor).next() {
                if word.starts_with(b"#") || word.starts_with(b"//") {
                    self.cursor = self.line.len();
                    continue;
                }
                let end = start + word.len();
                self.cursor = end;
                return Ok(Some(Token {
                    line: self.number,
                    start,
                    end,
                }));
            }
            if !self.advance()? {
                return Ok(None);
            }
        }
    }

    fn text(&self, token: Token) -> &[u8] {
        self.line.get(token.start..token.end).unwrap_or_default()
    }

    /// The text after a `ROOT`/`JOINT`/`End` keyword up to the end of the
    /// line or to a `{`, trimmed; whether a `{` ended it; and the column where
    /// the text starts. Moves the cursor after the `{` (the rest of the line,
    /// such as `OFFSET ...`, is read as usual) or to the end of the line.
    fn name_until_brace(&mut self) -> (String, bool, usize) {
        let rest = self.line.get(self.cursor..).unwrap_or_default();
        let column = self.cursor + 1 + (rest.len() - rest.trim_ascii_start().len());
        let (name, brace, consumed) = match rest.iter().position(|&b| b == b'{') {
            Some(at) => (&rest[..at], true, at + 1),
            None => (rest, false, rest.len()),
        };
        let text = String::from_utf8_lossy(name.trim_ascii()).into_owned();
        self.cursor += consumed;
        (text, brace, column)
    }

    /// Where the file ends: after the last line's text, or at the start of
    /// the line after it when the file ends with a line break.
    fn end_of_file(&self) -> (usize, usize) {
        if self.ended_with_newline {
            (self.number + 1, 1)
        } else {
            (self.number, self.last_len + 1)
        }
    }

    fn error(&self, line: usize, column: usize, message: impl Into<String>) -> Error {
        Error::parse(&self.path, line, column, message)
    }

    /// An error at a column of the current line.
    fn error_here(&self, column: usize, message: impl Into<String>) -> Error {
        self.error(self.number, column, message)
    }

    fn error_at(&self, token: Token, message: impl Into<String>) -> Error {
        self.error(token.line, token.column(), message)
    }

    fn error_at_end(&self, message: impl Into<String>) -> Error {
        let (line, column) = self.end_of_file();
        self.error(line, column, message)
    }
}

/// The words of a line separated by ASCII whitespace, each with its byte
/// offset. No allocation: this is the inner loop of the frame parser.
struct Fields<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Fields<'a> {
    fn new(bytes: &'a [u8], from: usize) -> Self {
        Fields { bytes, pos: from }
    }
}

impl<'a> Iterator for Fields<'a> {
    type Item = (usize, &'a [u8]);

    #[inline]
    fn next(&mut self) -> Option<Self::Item> {
        let bytes = self.bytes;
        let mut start = self.pos;
        while start < bytes.len() && bytes[start].is_ascii_whitespace() {
            start += 1;
        }
        if start >= bytes.len() {
            self.pos = start;
            return None;
        }
        let mut end = start + 1;
        while end < bytes.len() && !bytes[end].is_ascii_whitespace() {
            end += 1;
        }
        self.pos = end;
        Some((start, &bytes[start..end]))
    }
}

/// A value of a frame line or an offset. `fast-float2` is correctly rounded
/// (the same bits as `str::parse`, checked on all Bandai frames) and about 2.5
/// times faster, which is most of the reader's time. It takes every spelling
/// exporters write (`.5`, `-0.0000`, `8.09E-05`, `1e-015`). `nan` and `inf`
/// are refused: a BVH holding them is broken, and every later computation
/// would silently inherit them.
#[inline]
fn parse_f32(word: &[u8]) -> Option<f32> {
    fast_float2::parse::<f32, _>(word)
        .ok()
        .filter(|v: &f32| v.is_finite())
}

fn parse_f64(word: &[u8]) -> Option<f64> {
    std::str::from_utf8(word).ok()?.parse().ok()
}

fn parse_count(word: &[u8]) -> Option<usize> {
    std::str::from_utf8(word).ok()?.parse().ok()
}

/// A word of the file as shown in an error message (lossy, shortened).
fn show(word: &[u8]) -> String {
    let text = String::from_utf8_lossy(word);
    match text.char_indices().nth(40) {
        Some((cut, _)) => format!("\"{}...\"", &text[..cut]),
        None => format!("\"{text}\""),
    }
}

fn is_keyword(word: &[u8], keyword: &str) -> bool {
    word.eq_ignore_ascii_case(keyword.as_bytes())
}

/// A joint whose block is open, and the line of its `ROOT`/`JOINT`.
struct OpenJoint {
    index: usize,
    line: usize,
}

/// What `Frames:` and `Frame Time:` say.
struct MotionHeader {
    frames: usize,
    frames_line: usize,
    frame_time: f64,
}

struct Parser<R> {
    lines: Lines<R>,
    /// Size of the file in bytes when known: bounds the memory reserved from
    /// the `Frames:` line, so that a wrong header cannot reserve more than the
    /// file could hold.
    file_size: Option<u64>,
}

impl<R: BufRead> Parser<R> {
    fn new(reader: R, path: &Path, file_size: Option<u64>) -> Self {
        Parser {
            lines: Lines::new(reader, path),
            file_size,
        }
    }

    fn parse(mut self) -> Result<Motion> {
        let (skeleton, header) = self.parse_header()?;
        let values = self.parse_frames(skeleton.channel_count(), &header)?;
        Motion::new(skeleton, header.frame_time, header.frames, values)
    }

    /// The hierarchy and the `Frames:` and `Frame Time:` lines.
    fn parse_header(&mut self) -> Result<(Skeleton, MotionHeader)> {
        let joints = self.parse_hierarchy()?;
        let motion_line = self.lines.number;
        let header = self.parse_motion_header()?;
        // Names are unique and parents come first (checked while parsing), so
        // this only fails on a bug; the error still names the file.
        let skeleton = Skeleton::new(joints).map_err(|e| {
            self.lines
                .error(motion_line, 1, format!("invalid hierarchy: {e}"))
        })?;
        Ok((skeleton, header))
    }

    /// Reads from `HIERARCHY` up to and including `MOTION`; joints in file
    /// order, so every parent comes before its children.
    fn parse_hierarchy(&mut self) -> Result<Vec<Joint>> {
        match self.lines.next_token()? {
            None => return Err(self.lines.error(1, 1, "empty file: expected HIERARCHY")),
            Some(t) if is_keyword(self.lines.text(t), "HIERARCHY") => {}
            Some(t) => {
                let text = self.lines.text(t);
                let found = show(text);
                // An AMC motion or an ASF skeleton given where a BVH file
                // goes: say how to make one.
                let hint = if text.starts_with(b":") || text.starts_with(b"#") {
                    " (an ASF/AMC file? make a BVH of it first: `mocap convert SKELETON.asf \
                     MOTION.amc take.bvh`)"
                } else {
                    ""
                };
                return Err(self
                    .lines
                    .error_at(t, format!("expected HIERARCHY, found {found}{hint}")));
            }
        }
        let mut joints: Vec<Joint> = Vec::new();
        let mut open: Vec<OpenJoint> = Vec::new();
        // Line of each joint name, to report duplicates.
        let mut name_lines: HashMap<String, usize> = HashMap::new();
        loop {
            let Some(token) = self.lines.next_token()? else {
                let message = match open.last() {
                    Some(o) => format!(
                        "file ends inside joint {:?} (opened at line {}): expected `}}`",
                        joints[o.index].name, o.line
                    ),
                    None if joints.is_empty() => "file ends in the hierarchy: expected ROOT".into(),
                    None => "file ends after the hierarchy: expected MOTION".into(),
                };
                return Err(self.lines.error_at_end(message));
            };
            let word = self.lines.text(token);
            if is_keyword(word, "ROOT") || is_keyword(word, "JOINT") {
                let is_root = is_keyword(word, "ROOT");
                let keyword = if is_root { "ROOT" } else { "JOINT" };
                if is_root {
                    if let Some(o) = open.last() {
                        return Err(self.lines.error_at(
                            token,
                            format!(
                                "ROOT inside joint {:?} (opened at line {}): expected `}}` to close it first",
                                joints[o.index].name, o.line
                            ),
                        ));
                    }
                } else if open.is_empty() {
                    return Err(self.lines.error_at(
                        token,
                        "JOINT outside of any ROOT block: expected ROOT or MOTION",
                    ));
                }
                let (name, brace, name_column) = self.lines.name_until_brace();
                if name.is_empty() {
                    return Err(self.lines.error_here(
                        self.lines.line.len() + 1,
                        format!("expected a joint name after {keyword}"),
                    ));
                }
                if let Some(bad) = name.chars().find(|&c| c.is_control() && c != '\t') {
                    return Err(self.lines.error_here(
                        name_column,
                        format!(
                            "joint name {name:?} holds the control character {bad:?}: expected printable text"
                        ),
                    ));
                }
                if let Some(first) = name_lines.get(&name) {
                    return Err(self.lines.error_here(
                        name_column,
                        format!(
                            "a second joint named {name:?} (the first is at line {first}): joint names must be unique"
                        ),
                    ));
                }
                name_lines.insert(name.clone(), token.line);
                let parent = open.last().map(|o| o.index);
                joints.push(Joint::new(name, parent, Vec3::ZERO));
                if !brace {
                    self.expect_open_brace(keyword)?;
                }
                open.push(OpenJoint {
                    index: joints.len() - 1,
                    line: token.line,
                });
            } else if is_keyword(word, "End") || is_keyword(word, "EndSite") {
                let glued = is_keyword(word, "EndSite");
                let Some(o) = open.last() else {
                    return Err(self.lines.error_at(token, "End Site outside of any joint"));
                };
                let joint = o.index;
                let (rest, brace, _) = self.lines.name_until_brace();
                let says_site = glued
                    || rest
                        .split_ascii_whitespace()
                        .next()
                        .is_some_and(|w| w.eq_ignore_ascii_case("Site"));
                if !says_site {
                    return Err(self.lines.error_at(token, "expected `End Site`"));
                }
                if !brace {
                    self.expect_open_brace("End Site")?;
                }
                let offset = self.parse_end_site()?;
                joints[joint].end_sites.push(offset);
            } else if is_keyword(word, "OFFSET") {
                let Some(o) = open.last() else {
                    return Err(self.lines.error_at(token, "OFFSET outside of any joint"));
                };
                let joint = o.index;
                joints[joint].offset = self.parse_offset()?;
            } else if is_keyword(word, "CHANNELS") {
                let Some(o) = open.last() else {
                    return Err(self.lines.error_at(token, "CHANNELS outside of any joint"));
                };
                let joint = o.index;
                if !joints[joint].channels.is_empty() {
                    return Err(self.lines.error_at(
                        token,
                        format!("a second CHANNELS line for joint {:?}", joints[joint].name),
                    ));
                }
                joints[joint].channels = self.parse_channels(token)?;
            } else if !word.is_empty() && word.iter().all(|&b| b == b'}') {
                // `}}` closes two joints.
                for k in 0..word.len() {
                    if open.pop().is_none() {
                        return Err(self.lines.error_here(
                            token.column() + k,
                            "unbalanced `}`: no joint is open here",
                        ));
                    }
                }
            } else if is_keyword(word, "MOTION") {
                if let Some(o) = open.last() {
                    return Err(self.lines.error_at(
                        token,
                        format!(
                            "expected `}}` to close joint {:?} (opened at line {}) before MOTION",
                            joints[o.index].name, o.line
                        ),
                    ));
                }
                if joints.is_empty() {
                    return Err(self
                        .lines
                        .error_at(token, "expected ROOT: the hierarchy has no joint"));
                }
                if let Some((start, extra)) = Fields::new(&self.lines.line, token.end).next() {
                    return Err(self.lines.error_here(
                        start + 1,
                        format!(
                            "expected the end of the line after MOTION, found {}",
                            show(extra)
                        ),
                    ));
                }
                return Ok(joints);
            } else {
                let found = show(word);
                let message = if open.is_empty() && !joints.is_empty() {
                    format!("expected MOTION (or another ROOT) after the hierarchy, found {found}")
                } else if open.is_empty() {
                    format!("expected ROOT, found {found}")
                } else {
                    format!("expected OFFSET, CHANNELS, JOINT, End Site or `}}`, found {found}")
                };
                return Err(self.lines.error_at(token, message));
            }
        }
    }

    fn expect_open_brace(&mut self, after: &str) -> Result<()> {
        match self.lines.next_token()? {
            Some(t) if self.lines.text(t) == b"{" => Ok(()),
            Some(t) => {
                let found = show(self.lines.text(t));
                Err(self
                    .lines
                    .error_at(t, format!("expected `{{` after {after}, found {found}")))
            }
            None => Err(self
                .lines
                .error_at_end(format!("file ends: expected `{{` after {after}"))),
        }
    }

    /// The inside of an `End Site` block, after its `{`.
    fn parse_end_site(&mut self) -> Result<Vec3> {
        let mut offset = Vec3::ZERO;
        loop {
            let Some(token) = self.lines.next_token()? else {
                return Err(self
                    .lines
                    .error_at_end("file ends inside End Site: expected `}`"));
            };
            let word = self.lines.text(token);
            if is_keyword(word, "OFFSET") {
                offset = self.parse_offset()?;
            } else if word.first() == Some(&b'}') && word.iter().all(|&b| b == b'}') {
                // In `}}` the first brace closes the End Site; the next token
                // starts at the second, which closes its joint.
                self.lines.cursor = token.start + 1;
                return Ok(offset);
            } else {
                let found = show(word);
                return Err(self.lines.error_at(
                    token,
                    format!("expected OFFSET or `}}` in End Site, found {found}"),
                ));
            }
        }
    }

    /// The three numbers after `OFFSET`, on the same line.
    fn parse_offset(&mut self) -> Result<Vec3> {
        let lines = &self.lines;
        let mut xyz = [0.0f32; 3];
        let mut count = 0;
        for (start, word) in Fields::new(&lines.line, lines.cursor) {
            if count == 3 {
                return Err(
                    lines.error_here(start + 1, "OFFSET takes 3 numbers (x y z), found more")
                );
            }
            xyz[count] = parse_f32(word).ok_or_else(|| {
                lines.error_here(
                    start + 1,
                    format!("expected a number for OFFSET, found {}", show(word)),
                )
            })?;
            count += 1;
        }
        if count < 3 {
            return Err(lines.error_here(
                lines.line.len() + 1,
                format!("OFFSET takes 3 numbers (x y z), found {count}"),
            ));
        }
        self.lines.cursor = self.lines.line.len();
        Ok(Vec3::from_array(xyz))
    }

    /// The count and channel names after `CHANNELS`, on the same line.
    fn parse_channels(&mut self, keyword: Token) -> Result<Vec<Channel>> {
        let lines = &self.lines;
        let mut words = Fields::new(&lines.line, lines.cursor);
        let Some((start, word)) = words.next() else {
            return Err(lines.error_here(
                lines.line.len() + 1,
                "expected the number of channels after CHANNELS",
            ));
        };
        let count = parse_count(word).ok_or_else(|| {
            lines.error_here(
                start + 1,
                format!(
                    "expected the number of channels after CHANNELS, found {}",
                    show(word)
                ),
            )
        })?;
        let mut channels: Vec<Channel> = Vec::with_capacity(count.min(6));
        for (start, word) in words {
            let channel = std::str::from_utf8(word)
                .ok()
                .and_then(Channel::parse)
                .ok_or_else(|| {
                    lines.error_here(
                        start + 1,
                        format!(
                            "unknown channel {}: expected Xposition, Yposition, Zposition, \
                             Xrotation, Yrotation or Zrotation",
                            show(word)
                        ),
                    )
                })?;
            if channels.len() == count {
                return Err(lines.error_here(
                    start + 1,
                    format!("CHANNELS {count} lists more than {count} channel names"),
                ));
            }
            if channels.contains(&channel) {
                return Err(lines.error_here(
                    start + 1,
                    format!("channel {} is listed twice", channel.name()),
                ));
            }
            channels.push(channel);
        }
        if channels.len() < count {
            return Err(lines.error_here(
                lines.line.len() + 1,
                format!(
                    "CHANNELS {count} lists {} channel names: expected {count} (CHANNELS at column {})",
                    channels.len(),
                    keyword.column()
                ),
            ));
        }
        self.lines.cursor = self.lines.line.len();
        Ok(channels)
    }

    /// The `Frames:` and `Frame Time:` lines after `MOTION`, in either order.
    fn parse_motion_header(&mut self) -> Result<MotionHeader> {
        let mut frames: Option<(usize, usize)> = None;
        let mut frame_time: Option<f64> = None;
        while frames.is_none() || frame_time.is_none() {
            let missing = if frames.is_none() {
                "`Frames:`"
            } else {
                "`Frame Time:`"
            };
            if !self.lines.advance()? {
                return Err(self
                    .lines
                    .error_at_end(format!("file ends after MOTION: expected {missing}")));
            }
            let lines = &self.lines;
            let Some((start, first)) = Fields::new(&lines.line, 0).next() else {
                continue;
            };
            if first.starts_with(b"#") || first.starts_with(b"//") {
                continue;
            }
            if let Some(after) = strip_label(&lines.line, start, &["Frames"]) {
                let (start, word) =
                    single_word(lines, after, "the number of frames after `Frames:`")?;
                let count = parse_count(word).ok_or_else(|| {
                    lines.error_here(
                        start + 1,
                        format!(
                            "expected the number of frames after `Frames:`, found {}",
                            show(word)
                        ),
                    )
                })?;
                frames = Some((count, lines.number));
            } else if let Some(after) = strip_label(&lines.line, start, &["Frame", "Time"]) {
                let what = "a frame time of 0.000001 to 10 seconds after `Frame Time:`";
                let (start, word) = single_word(lines, after, what)?;
                let seconds = parse_f64(word)
                    .filter(|t| FRAME_TIME_RANGE.contains(t))
                    .ok_or_else(|| {
                        lines
                            .error_here(start + 1, format!("expected {what}, found {}", show(word)))
                    })?;
                frame_time = Some(seconds);
            } else {
                return Err(lines.error_here(
                    start + 1,
                    format!("expected {missing} after MOTION, found {}", show(first)),
                ));
            }
        }
        match (frames, frame_time) {
            (Some((frames, frames_line)), Some(frame_time)) => Ok(MotionHeader {
                frames,
                frames_line,
                frame_time,
            }),
            // The loop above runs until both are set.
            _ => Err(self
                .lines
                .error_here(1, "expected `Frames:` and `Frame Time:`")),
        }
    }

    /// The frame lines: `header.frames` lines of `channels` numbers each.
    fn parse_frames(&mut self, channels: usize, header: &MotionHeader) -> Result<Vec<f32>> {
        let frames = header.frames;
        let too_large = || {
            self.lines.error(
                header.frames_line,
                1,
                format!("`Frames: {frames}` with {channels} channels is more than memory can hold"),
            )
        };
        let total = frames.checked_mul(channels).ok_or_else(too_large)?;
        // Reserve once for the whole take so that the values are never copied
        // while growing. A wrong header must not reserve more than the file
        // can hold: every value takes at least two bytes of text (a digit and
        // a separator). When the size is unknown (a stream), reserve at most
        // 1 GiB up front and let the vector grow past it if needed.
        let reserve = match self.file_size {
            Some(size) => total.min(usize::try_from(size / 2 + 1).unwrap_or(usize::MAX)),
            None => total.min(1 << 28),
        };
        let mut values: Vec<f32> = Vec::new();
        values.try_reserve_exact(reserve).map_err(|_| too_large())?;

        let mut read = 0usize;
        while self.lines.advance()? {
            let lines = &self.lines;
            let mut count = 0usize;
            for (start, word) in Fields::new(&lines.line, 0) {
                if count == 0 && read == frames {
                    return Err(lines.error_here(
                        start + 1,
                        format!(
                            "more frame lines than the {frames} announced by `Frames:` at line {}",
                            header.frames_line
                        ),
                    ));
                }
                if count == channels {
                    return Err(lines.error_here(
                        start + 1,
                        format!("too many values on frame {}: expected {channels}", read + 1),
                    ));
                }
                let value = parse_f32(word).ok_or_else(|| {
                    lines.error_here(
                        start + 1,
                        format!("expected a number, found {}", show(word)),
                    )
                })?;
                values.push(value);
                count += 1;
            }
            if count == 0 {
                continue; // a blank line
            }
            if count < channels {
                return Err(lines.error_here(
                    lines.line.len() + 1,
                    format!(
                        "frame {} has {count} values: expected {channels} (one per channel)",
                        read + 1
                    ),
                ));
            }
            read += 1;
        }
        // With no channels, frame lines are empty and may all be missing.
        if read < frames && channels > 0 {
            return Err(self.lines.error_at_end(format!(
                "file ends after {read} frame lines: `Frames:` at line {} announced {frames} (truncated file?)",
                header.frames_line
            )));
        }
        Ok(values)
    }
}

/// Matches `words` (case-insensitive, separated by whitespace) at `start`,
/// then an optional `:`; returns the offset after them.
fn strip_label(line: &[u8], start: usize, words: &[&str]) -> Option<usize> {
    let mut pos = start;
    for (k, word) in words.iter().enumerate() {
        if k > 0 {
            while line.get(pos).is_some_and(u8::is_ascii_whitespace) {
                pos += 1;
            }
        }
        let end = pos + word.len();
        if !line.get(pos..end)?.eq_ignore_ascii_case(word.as_bytes()) {
            return None;
        }
        pos = end;
    }
    // The label must end here: `Frames` is not `FramesPerSecond`.
    match line.get(pos) {
        None => Some(pos),
        Some(b':') => Some(pos + 1),
        Some(b) if b.is_ascii_whitespace() => {
            let mut after = pos;
            while line.get(after).is_some_and(u8::is_ascii_whitespace) {
                after += 1;
            }
            Some(if line.get(after) == Some(&b':') {
                after + 1
            } else {
                pos
            })
        }
        Some(_) => None,
    }
}

/// The one word after a label, and nothing after it.
fn single_word<'a, R: BufRead>(
    lines: &'a Lines<R>,
    from: usize,
    what: &str,
) -> Result<(usize, &'a [u8])> {
    let mut words = Fields::new(&lines.line, from);
    let Some((start, word)) = words.next() else {
        return Err(lines.error_here(lines.line.len() + 1, format!("expected {what}")));
    };
    if let Some((extra, word)) = words.next() {
        return Err(lines.error_here(
            extra + 1,
            format!(
                "expected the end of the line after {what}, found {}",
                show(word)
            ),
        ));
    }
    Ok((start, word))
}
