//! Acclaim skeleton (ASF) and motion (AMC) files, as written by Vicon
//! BodyBuilder for the CMU Graphics Lab database and for HDM05.
//!
//! [`read_asf`] gives the skeleton as written ([`AsfSkeleton`]: bones, units,
//! root, joint limits); [`read_amc`] and [`read_asf_amc`] give the same
//! [`Motion`] as a BVH file would, so that writing it as BVH plays the same.
//!
//! # What the files mean
//!
//! Sources: the Acclaim format description of the University of Wisconsin
//! (CS 838, 1999, `research.cs.wisc.edu/graphics/Courses/cs-838-1999/Jeff/ASF-AMC.html`),
//! "Acclaim Format - ASF line details" of CMU
//! (`graphics.cs.cmu.edu/nsp/course/cs229/info/ACCLAIMdef.html`), the CMU
//! motion capture FAQ (`mocap.cs.cmu.edu/faqs.php`), the CMU 15-464 notes on
//! the ASF fields (`graphics.cs.cmu.edu/nsp/course/15-464/Fall05/assignments/StartupCodeDescription.html`)
//! and the CMU/USC ASF/AMC viewer (Lin, Safonova, Bhat, Barbic, Zhao;
//! `skeleton.cpp` `compute_rotation_parent_child`, `displaySkeleton.cpp`
//! `DrawBone`).
//!
//! - **Units.** `:units length L`: lengths and root translations are in
//!   inches times `L`; the CMU FAQ converts them to metres with
//!   `(1.0/0.45)*2.54/100.0` for `L = 0.45`. This reader writes
//!   **centimetres** by default (`value / L * 2.54`); [`LengthUnit`] asks for
//!   metres or the file's own numbers. `angle deg|rad` is the unit of `axis`,
//!   `limits`, `orientation` and of the AMC angles, unless the AMC header says
//!   `:DEGREES` or `:RADIANS`. A file without `:units` means `length 1`,
//!   `angle deg`.
//! - **Bones.** `direction` (a unit vector in world coordinates, rest pose)
//!   times `length` goes from the bone's start to its end; a bone starts
//!   where its parent ends, and the root's children start at the root.
//! - **`axis ax ay az XYZ`**: the bone's local frame `C` relative to the world.
//!   The numbers are the angles about x, y and z; the letters are the order in
//!   which they are applied about the fixed world axes, so `XYZ` gives
//!   `C = Rz(az) Ry(ay) Rx(ax)` (column vectors), as the CMU viewer builds it.
//! - **`dof rx ry rz`**: the order of the bone's values in each AMC frame, and
//!   the order of its rotations about the axes of `C`, first listed first:
//!   `M = Rz(rz) Ry(ry) Rx(rx)` for `rx ry rz` (the CMU viewer always applies
//!   x, then y, then z; CMU and HDM05 files always list them in that order).
//! - **Pose.** With `G` a bone's global rotation,
//!   `G_bone = G_parent C M C^-1` and `end = start + G_bone (direction length)`
//!   (the Wisconsin text writes the same as `L = C^-1 M C B` for row
//!   vectors).
//! - **Root.** `order TX TY TZ RX RY RZ` is the order of the root's AMC values
//!   and the sequence of its rotations about fixed global axes (CMU's
//!   "ASF line details"): `M_root = Rz Ry Rx`. `position` and `orientation`
//!   (angles about x, y, z, applied in `axis` order) are presets:
//!   `G_root = O M_root` and the root sits at `position + (TX, TY, TZ)`. Vicon
//!   BodyBuilder (CMU, HDM05) always writes them as zero because packages
//!   disagree on how to apply them, so this choice only matters for other
//!   writers' files.
//! - **Translation dofs** `tx ty tz` move the bone's start along the axes of
//!   `C` before its rotation, as the CMU viewer draws them:
//!   `start = parent end + G_parent C t`. The dof `l` (bone stretch) is
//!   refused with a clear error.
//!
//! # The converted skeleton
//!
//! One joint per ASF segment: `root` first, then the bones depth first in
//! `:hierarchy` order. The root has the channels
//! `Xposition Yposition Zposition Zrotation Yrotation Xrotation`. A bone's
//! joint sits at the bone's start: its offset is its parent's
//! `direction * length` (zero under the root), and a bone without children
//! gets an end site at its own `direction * length`. A bone with rotation
//! dofs gets `Zrotation Yrotation Xrotation` holding its local rotation
//! `C M C^-1` (chosen continuous from frame to frame by
//! [`Motion::set_local_rotation`]); where `C` is the identity and the dofs
//! are listed x before y before z, as for the root and spine of CMU/HDM05
//! skeletons, these channels hold the file's angles unchanged. A bone with
//! translation dofs also gets `Xposition Yposition Zposition`; a bone without
//! dofs gets no channels. The bone's `limits` are kept in [`Joint::limits`]
//! (see [`AsfSkeleton::to_skeleton`]).
//!
//! AMC files do not store their frame rate: CMU and HDM05 record at 120 Hz,
//! which is the default of [`AsfOptions::frame_rate`]. (HDM05 names a file's
//! rate at the end of its name, as in `..._120.amc`.)

use std::borrow::Cow;
use std::collections::HashMap;
use std::io::BufRead;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::motion::Motion;
use crate::rotation::{AngleUnit, Axis, Quat, Vec3};
use crate::skeleton::{Channel, DofLimit, Joint, RangeOfMotion, Skeleton};

/// Unit of the lengths in a converted [`Motion`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LengthUnit {
    /// Centimetres, from the ASF convention that lengths are inches times
    /// the `:units length` scale.
    #[default]
    Centimetres,
    /// Metres, by the same convention.
    Metres,
    /// The numbers as written in the files.
    File,
}

/// How to convert ASF/AMC into a [`Motion`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AsfOptions {
    /// Unit of the output lengths (offsets, root positions).
    pub length_unit: LengthUnit,
    /// Frames per second of the AMC file, which does not store it.
    pub frame_rate: f64,
}

impl Default for AsfOptions {
    /// Centimetres and 120 frames per second (CMU and HDM05).
    fn default() -> Self {
        AsfOptions {
            length_unit: LengthUnit::Centimetres,
            frame_rate: 120.0,
        }
    }
}

/// A degree of freedom of an ASF bone or of the root.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dof {
    Tx,
    Ty,
    Tz,
    Rx,
    Ry,
    Rz,
}

impl Dof {
    /// Parses `rx`, `TX`, ... (case-insensitive).
    pub fn parse(token: &str) -> Option<Dof> {
        match token.to_ascii_lowercase().as_str() {
            "tx" => Some(Dof::Tx),
            "ty" => Some(Dof::Ty),
            "tz" => Some(Dof::Tz),
            "rx" => Some(Dof::Rx),
            "ry" => Some(Dof::Ry),
            "rz" => Some(Dof::Rz),
            _ => None,
        }
    }

    pub fn axis(self) -> Axis {
        match self {
            Dof::Tx | Dof::Rx => Axis::X,
            Dof::Ty | Dof::Ry => Axis::Y,
            Dof::Tz | Dof::Rz => Axis::Z,
        }
    }

    pub fn is_rotation(self) -> bool {
        matches!(self, Dof::Rx | Dof::Ry | Dof::Rz)
    }

    /// The channel of a converted joint that this dof drives.
    pub fn channel(self) -> Channel {
        if self.is_rotation() {
            Channel::rotation(self.axis())
        } else {
            Channel::position(self.axis())
        }
    }
}

/// The `:units` section.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AsfUnits {
    pub mass: f32,
    /// Lengths in the files are inches times this scale.
    pub length: f32,
    /// Unit of `axis`, `limits`, `orientation` and (by default) AMC angles.
    pub angle: AngleUnit,
}

impl Default for AsfUnits {
    fn default() -> Self {
        AsfUnits {
            mass: 1.0,
            length: 1.0,
            angle: AngleUnit::Degrees,
        }
    }
}

/// The `:root` section.
#[derive(Debug, Clone, PartialEq)]
pub struct AsfRoot {
    /// The root's values in each AMC frame, in order; the rotations among
    /// them are applied in this order about fixed global axes.
    pub order: Vec<Dof>,
    /// Order in which the `orientation` angles are applied (about fixed axes).
    pub axis_order: [Axis; 3],
    /// Preset position, in file length units.
    pub position: Vec3,
    /// Preset orientation: angles about x, y, z in the ASF angle unit.
    pub orientation: Vec3,
}

impl Default for AsfRoot {
    fn default() -> Self {
        AsfRoot {
            order: vec![Dof::Tx, Dof::Ty, Dof::Tz, Dof::Rx, Dof::Ry, Dof::Rz],
            axis_order: [Axis::X, Axis::Y, Axis::Z],
            position: Vec3::ZERO,
            orientation: Vec3::ZERO,
        }
    }
}

/// One bone of the `:bonedata` section, as written (file units).
#[derive(Debug, Clone, PartialEq)]
pub struct AsfBone {
    pub name: String,
    /// Direction from the bone's start to its end in world coordinates at
    /// rest.
    pub direction: Vec3,
    /// Length in file units.
    pub length: f32,
    /// Angles about x, y, z of the bone's local frame, in the ASF angle unit.
    pub axis: Vec3,
    /// Order in which the `axis` angles are applied (about fixed axes).
    pub axis_order: [Axis; 3],
    /// The bone's values in each AMC frame, in order.
    pub dofs: Vec<Dof>,
    /// `(min, max)` for each dof, in the file's units; empty when the file
    /// gives no limits.
    pub limits: Vec<(f32, f32)>,
    /// Index of the parent bone in [`AsfSkeleton::bones`]; `None` for a bone
    /// attached to the root.
    pub parent: Option<usize>,
    /// Child bones in `:hierarchy` order.
    pub children: Vec<usize>,
}

impl AsfBone {
    pub fn has_rotation(&self) -> bool {
        self.dofs.iter().any(|d| d.is_rotation())
    }

    pub fn has_translation(&self) -> bool {
        self.dofs.iter().any(|d| !d.is_rotation())
    }
}

/// An ASF skeleton as written in the file.
#[derive(Debug, Clone, PartialEq)]
pub struct AsfSkeleton {
    /// The `:name` of the skeleton, if any.
    pub name: Option<String>,
    pub units: AsfUnits,
    pub root: AsfRoot,
    /// Bones in file order.
    pub bones: Vec<AsfBone>,
    /// Bones attached to the root, in `:hierarchy` order.
    pub root_children: Vec<usize>,
    /// All bones, depth first from the root in `:hierarchy` order: every
    /// parent before its children. The converted skeleton has the root
    /// joint, then one joint per bone in this order.
    pub joint_order: Vec<usize>,
}

impl AsfSkeleton {
    /// Index of the bone with this exact name.
    pub fn find_bone(&self, name: &str) -> Option<usize> {
        self.bones.iter().position(|b| b.name == name)
    }

    /// Factor from file lengths to `unit`.
    pub fn length_factor(&self, unit: LengthUnit) -> f32 {
        match unit {
            LengthUnit::Centimetres => 2.54 / self.units.length,
            LengthUnit::Metres => 0.0254 / self.units.length,
            LengthUnit::File => 1.0,
        }
    }

    /// The local frame `C` of a bone (its `axis` line) as a rotation.
    pub fn axis_frame(&self, bone: usize) -> Quat {
        let b = &self.bones[bone];
        fixed_axes_rotation(
            b.axis_order
                .iter()
                .map(|&a| (a, b.axis[a as usize] * self.units.angle.to_radians_factor())),
        )
    }

    /// The root's preset `orientation` as a rotation.
    pub fn root_orientation(&self) -> Quat {
        let r = &self.root;
        fixed_axes_rotation(r.axis_order.iter().map(|&a| {
            (
                a,
                r.orientation[a as usize] * self.units.angle.to_radians_factor(),
            )
        }))
    }

    /// The skeleton of the converted motion (see the module documentation),
    /// with lengths in `unit`.
    ///
    /// Limits: a bone with `limits` gets `Joint::limits = RangeOfMotion {
    /// axis_frame: C, dofs }`. `C^-1 q C` of the joint's local rotation `q`
    /// is the bone's `M`; its angles, read as intrinsic Euler angles in the
    /// order of the rotation [`DofLimit`]s, are the AMC values. Since `M`
    /// applies the file's dofs first listed first about fixed axes, the
    /// rotation limits are listed in the reverse of the file's order (`rz`,
    /// `ry`, `rx` for `dof rx ry rz`), after any translation limits (in file
    /// order). Rotation limits are in degrees, translation limits in `unit`.
    pub fn to_skeleton(&self, unit: LengthUnit) -> Result<Skeleton> {
        let scale = self.length_factor(unit);
        let to_degrees = |v: f32| match self.units.angle {
            AngleUnit::Degrees => v,
            AngleUnit::Radians => v.to_degrees(),
        };
        let mut joints = Vec::with_capacity(self.bones.len() + 1);
        let mut root = Joint::new("root", None, self.root.position * scale);
        root.channels = [POSITION_CHANNELS, ROTATION_CHANNELS].concat();
        joints.push(root);
        let mut joint_of_bone = vec![0; self.bones.len()];
        for &b in &self.joint_order {
            let bone = &self.bones[b];
            let (parent, offset) = match bone.parent {
                None => (0, Vec3::ZERO),
                Some(p) => {
                    let pb = &self.bones[p];
                    (joint_of_bone[p], pb.direction * pb.length * scale)
                }
            };
            let mut joint = Joint::new(bone.name.clone(), Some(parent), offset);
            if bone.has_translation() {
                joint.channels.extend(POSITION_CHANNELS);
            }
            if bone.has_rotation() {
                joint.channels.extend(ROTATION_CHANNELS);
            }
            if bone.children.is_empty() {
                joint.end_sites.push(bone.direction * bone.length * scale);
            }
            if !bone.limits.is_empty() {
                let limit = |(d, &(min, max)): (&Dof, &(f32, f32))| {
                    let (min, max) = if d.is_rotation() {
                        (to_degrees(min), to_degrees(max))
                    } else {
                        (min * scale, max * scale)
                    };
                    DofLimit {
                        channel: d.channel(),
                        min,
                        max,
                    }
                };
                let pairs = bone.dofs.iter().zip(&bone.limits);
                let mut dofs: Vec<DofLimit> = pairs
                    .clone()
                    .filter(|(d, _)| !d.is_rotation())
                    .map(limit)
                    .collect();
                dofs.extend(pairs.rev().filter(|(d, _)| d.is_rotation()).map(limit));
                joint.limits = Some(RangeOfMotion {
                    axis_frame: self.axis_frame(b),
                    dofs,
                });
            }
            joint_of_bone[b] = joints.len();
            joints.push(joint);
        }
        Skeleton::new(joints)
    }

    /// Number of values in one AMC frame (root and all bones).
    pub fn dof_count(&self) -> usize {
        self.root.order.len() + self.bones.iter().map(|b| b.dofs.len()).sum::<usize>()
    }
}

const POSITION_CHANNELS: [Channel; 3] =
    [Channel::Xposition, Channel::Yposition, Channel::Zposition];
/// Rotation channels of every converted joint: intrinsic Z, Y, X, which is
/// the file's `M` unchanged for dofs listed x before y before z.
const ROTATION_CHANNELS: [Channel; 3] =
    [Channel::Zrotation, Channel::Yrotation, Channel::Xrotation];

/// Rotations about fixed axes applied in sequence, first listed first:
/// `R = R_n ... R_2 R_1` (angles in radians).
fn fixed_axes_rotation(sequence: impl Iterator<Item = (Axis, f32)>) -> Quat {
    sequence.fold(Quat::IDENTITY, |q, (axis, angle)| axis.rotation(angle) * q)
}

/// The ASF skeleton of an AMC motion given alone: in the same folder, the
/// `.asf` file whose name (without extension) is the longest prefix of the
/// AMC's name (`HDM_bd.asf` for `HDM_bd_walk4StepsLstart_001_120.amc`,
/// `01.asf` for `01_02.amc`), or the only `.asf` file there.
pub fn skeleton_file_for(amc: &Path) -> Result<PathBuf> {
    let dir = match amc.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let stem = amc
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    let mut skeletons: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| e.eq_ignore_ascii_case("asf"))
        })
        .collect();
    skeletons.sort();
    let prefix_len = |p: &PathBuf| {
        let s = p
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        stem.starts_with(&s).then_some(s.len())
    };
    if let Some((_, best)) = skeletons
        .iter()
        .filter_map(|p| prefix_len(p).map(|n| (n, p)))
        .max_by_key(|(n, _)| *n)
    {
        return Ok(best.clone());
    }
    if skeletons.len() == 1 {
        return Ok(skeletons.remove(0));
    }
    Err(Error::Invalid(format!(
        "{}: no ASF skeleton file for this AMC motion in {} (give it before the AMC, or put one \
         whose name starts the AMC's name beside it, e.g. `HDM_bd.asf` for `HDM_bd_*.amc`)",
        amc.display(),
        dir.display()
    )))
}

/// Reads an ASF skeleton file.
pub fn read_asf(path: impl AsRef<Path>) -> Result<AsfSkeleton> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    parse_asf(&bytes, path)
}

/// Reads an AMC motion of `skeleton` with the default options
/// (centimetres, 120 frames per second).
pub fn read_amc(path: impl AsRef<Path>, skeleton: &AsfSkeleton) -> Result<Motion> {
    read_amc_with(path, skeleton, &AsfOptions::default())
}

/// Reads an AMC motion of `skeleton`.
pub fn read_amc_with(
    path: impl AsRef<Path>,
    skeleton: &AsfSkeleton,
    options: &AsfOptions,
) -> Result<Motion> {
    let path = path.as_ref();
    check_frame_rate(options)?;
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    // Line by line: memory holds the values, not the file's text too.
    let lines = StreamedLines::new(std::io::BufReader::with_capacity(1 << 16, file), path);
    let (values, frame_count, angle) = read_amc_values(lines, path, skeleton)?;
    build_motion(skeleton, &values, frame_count, angle, options)
}

/// Reads an ASF skeleton and an AMC motion of it with the default options
/// (centimetres, 120 frames per second).
pub fn read_asf_amc(asf: impl AsRef<Path>, amc: impl AsRef<Path>) -> Result<Motion> {
    read_asf_amc_with(asf, amc, &AsfOptions::default())
}

/// Reads an ASF skeleton and an AMC motion of it.
pub fn read_asf_amc_with(
    asf: impl AsRef<Path>,
    amc: impl AsRef<Path>,
    options: &AsfOptions,
) -> Result<Motion> {
    let skeleton = read_asf(asf)?;
    read_amc_with(amc, &skeleton, options)
}

// ---------------------------------------------------------------------------
// Lines and tokens

/// The lines of a file with their 1-based numbers; `#` comment lines are
/// given as empty lines.
/// Lines end at `\r\n`, `\n` or a lone `\r`, so files with mixed endings
/// read the same.
fn lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let mut rest = text;
    let mut number = 0;
    std::iter::from_fn(move || {
        if rest.is_empty() {
            return None;
        }
        number += 1;
        let (line, next) = match rest.find(['\n', '\r']) {
            Some(i) => {
                let skip = if rest[i..].starts_with("\r\n") { 2 } else { 1 };
                (&rest[..i], &rest[i + skip..])
            }
            None => (rest, ""),
        };
        rest = next;
        Some((number, without_comment(line)))
    })
}

/// Comments are whole lines. A `#` inside a line is kept: Vicon writes a
/// missing value as `1.#QNAN`, which must be an error, not 1.
fn without_comment(line: &str) -> &str {
    if line.trim_start().starts_with('#') {
        ""
    } else {
        line
    }
}

/// [`lines`] read from a file one at a time (each decoded lossily, as the
/// whole text would be: no UTF-8 sequence holds a line end), so that a long
/// motion is not held as text beside its values.
struct StreamedLines<'p, R> {
    reader: R,
    path: &'p Path,
    number: usize,
    line: Vec<u8>,
}

impl<'p, R: BufRead> StreamedLines<'p, R> {
    fn new(reader: R, path: &'p Path) -> Self {
        StreamedLines {
            reader,
            path,
            number: 0,
            line: Vec::new(),
        }
    }

    /// The next line's bytes into `self.line`; `false` at the end.
    fn advance(&mut self) -> std::io::Result<bool> {
        self.line.clear();
        let mut started = false;
        loop {
            let available = self.reader.fill_buf()?;
            if available.is_empty() {
                return Ok(started);
            }
            started = true;
            match available.iter().position(|&b| b == b'\n' || b == b'\r') {
                Some(i) => {
                    let cr = available[i] == b'\r';
                    self.line.extend_from_slice(&available[..i]);
                    self.reader.consume(i + 1);
                    if cr && self.reader.fill_buf()?.first() == Some(&b'\n') {
                        self.reader.consume(1);
                    }
                    return Ok(true);
                }
                None => {
                    let n = available.len();
                    self.line.extend_from_slice(available);
                    self.reader.consume(n);
                }
            }
        }
    }
}

impl<R: BufRead> Iterator for StreamedLines<'_, R> {
    type Item = Result<(usize, Cow<'static, str>)>;

    fn next(&mut self) -> Option<Self::Item> {
        match self.advance() {
            Ok(false) => None,
            Ok(true) => {
                self.number += 1;
                let text = String::from_utf8_lossy(&self.line);
                Some(Ok((
                    self.number,
                    Cow::Owned(without_comment(&text).to_string()),
                )))
            }
            Err(e) => Some(Err(Error::io(self.path, e))),
        }
    }
}

/// The lines of a text in memory, as [`read_amc_values`] takes them.
fn text_lines(text: &str) -> impl Iterator<Item = Result<(usize, Cow<'_, str>)>> {
    lines(text).map(|(number, line)| Ok((number, Cow::Borrowed(line))))
}

/// A word of a line and its byte offset in the line.
#[derive(Debug, Clone, Copy)]
struct Token<'a> {
    text: &'a str,
    offset: usize,
}

fn tokens(line: &str) -> Vec<Token<'_>> {
    line.split_whitespace()
        .map(|text| Token {
            text,
            offset: text.as_ptr() as usize - line.as_ptr() as usize,
        })
        .collect()
}

/// Builds parse errors that point into one file.
struct Errors<'p> {
    path: &'p Path,
}

impl Errors<'_> {
    /// An error at byte `offset` of `line` (column counted in characters).
    fn at(&self, number: usize, line: &str, offset: usize, message: impl Into<String>) -> Error {
        let column = line[..offset.min(line.len())].chars().count() + 1;
        Error::parse(self.path, number, column, message)
    }

    fn at_token(
        &self,
        number: usize,
        line: &str,
        token: Token,
        message: impl Into<String>,
    ) -> Error {
        self.at(number, line, token.offset, message)
    }

    /// A number; `allow_infinite` for limits such as `(-inf inf)`.
    fn number(&self, number: usize, line: &str, token: Token, allow_infinite: bool) -> Result<f32> {
        match token.text.parse::<f32>() {
            Ok(v) if v.is_finite() || (allow_infinite && v.is_infinite()) => Ok(v),
            _ => Err(self.at_token(
                number,
                line,
                token,
                format!("expected a number, found `{}`", token.text),
            )),
        }
    }

    /// Three numbers after the keyword token.
    fn vec3(&self, number: usize, line: &str, tokens: &[Token], what: &str) -> Result<Vec3> {
        if tokens.len() < 4 {
            return Err(self.at(
                number,
                line,
                line.trim_end().len(),
                format!("expected three numbers for `{what}`"),
            ));
        }
        Ok(Vec3::new(
            self.number(number, line, tokens[1], false)?,
            self.number(number, line, tokens[2], false)?,
            self.number(number, line, tokens[3], false)?,
        ))
    }

    /// An axis order such as `XYZ` (three distinct letters).
    fn axis_order(&self, number: usize, line: &str, token: Token) -> Result<[Axis; 3]> {
        let axes: Vec<Option<Axis>> = token
            .text
            .chars()
            .map(|c| match c.to_ascii_uppercase() {
                'X' => Some(Axis::X),
                'Y' => Some(Axis::Y),
                'Z' => Some(Axis::Z),
                _ => None,
            })
            .collect();
        match axes[..] {
            [Some(a), Some(b), Some(c)] if a != b && b != c && a != c => Ok([a, b, c]),
            _ => Err(self.at_token(
                number,
                line,
                token,
                format!("expected an axis order such as XYZ, found `{}`", token.text),
            )),
        }
    }
}

// ---------------------------------------------------------------------------
// ASF

/// Parses an ASF skeleton from the bytes of a file (decoded lossily, so a
/// stray Latin-1 byte in a comment does no harm). `path` is used in errors.
pub fn parse_asf(bytes: &[u8], path: &Path) -> Result<AsfSkeleton> {
    let text = String::from_utf8_lossy(bytes);
    AsfParser::new(path).parse(&text)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Section {
    Header,
    Units,
    Root,
    BoneData,
    Hierarchy,
    /// `:version`, `:documentation` and sections this reader does not use.
    Other,
}

/// A bone block being read, with where its fields were written.
struct BoneBlock {
    begin_line: usize,
    name: Option<(String, usize)>,
    direction: Option<Vec3>,
    length: Option<f32>,
    axis: Vec3,
    axis_order: [Axis; 3],
    dofs: Vec<Dof>,
    limits: Vec<(f32, f32)>,
    limits_line: usize,
}

struct AsfParser<'p> {
    errors: Errors<'p>,
    name: Option<String>,
    units: AsfUnits,
    root: AsfRoot,
    bones: Vec<AsfBone>,
    /// Line of each bone's `name`, for errors found after the block.
    bone_lines: Vec<usize>,
    bone_index: HashMap<String, usize>,
}

impl<'p> AsfParser<'p> {
    fn new(path: &'p Path) -> Self {
        AsfParser {
            errors: Errors { path },
            name: None,
            units: AsfUnits::default(),
            root: AsfRoot::default(),
            bones: Vec::new(),
            bone_lines: Vec::new(),
            bone_index: HashMap::new(),
        }
    }

    fn parse(mut self, text: &str) -> Result<AsfSkeleton> {
        let mut section = Section::Header;
        let mut seen_bonedata = false;
        let mut seen_hierarchy = false;
        let mut block: Option<BoneBlock> = None;
        // The last bone field read was `limits`: lines starting with `(`
        // continue it.
        let mut in_limits = false;
        let mut hierarchy: Vec<(usize, &str)> = Vec::new();
        let mut last_line = (0, "");
        for (number, line) in lines(text) {
            last_line = (number, line);
            let words = tokens(line);
            let Some(&first) = words.first() else {
                continue;
            };
            if first.text.starts_with(':') {
                if let Some(b) = &block {
                    return Err(self.errors.at_token(
                        number,
                        line,
                        first,
                        format!(
                            "expected `end` of the bone block that starts at line {}",
                            b.begin_line
                        ),
                    ));
                }
                section = match first.text.to_ascii_lowercase().as_str() {
                    ":units" => Section::Units,
                    ":root" => Section::Root,
                    ":bonedata" => {
                        seen_bonedata = true;
                        Section::BoneData
                    }
                    ":hierarchy" => {
                        seen_hierarchy = true;
                        Section::Hierarchy
                    }
                    ":name" => {
                        self.name = words.get(1).map(|t| t.text.to_string());
                        Section::Other
                    }
                    _ => Section::Other,
                };
                continue;
            }
            match section {
                Section::Units => self.units_line(number, line, &words)?,
                Section::Root => self.root_line(number, line, &words)?,
                Section::BoneData => {
                    self.bone_line(number, line, &words, &mut block, &mut in_limits)?
                }
                Section::Hierarchy => hierarchy.push((number, line)),
                Section::Header | Section::Other => {}
            }
        }
        let (last_number, last_text) = last_line;
        let end_of_file = |message: &str| {
            self.errors
                .at(last_number.max(1), last_text, last_text.len(), message)
        };
        if let Some(b) = &block {
            return Err(end_of_file(&format!(
                "expected `end` of the bone block that starts at line {}",
                b.begin_line
            )));
        }
        if !seen_bonedata {
            return Err(end_of_file("expected a `:bonedata` section"));
        }
        if !seen_hierarchy && !self.bones.is_empty() {
            return Err(end_of_file("expected a `:hierarchy` section"));
        }
        let root_children = self.hierarchy(&hierarchy)?;
        let joint_order = self.joint_order(&root_children)?;
        Ok(AsfSkeleton {
            name: self.name,
            units: self.units,
            root: self.root,
            bones: self.bones,
            root_children,
            joint_order,
        })
    }

    fn units_line(&mut self, number: usize, line: &str, words: &[Token]) -> Result<()> {
        let e = &self.errors;
        let key = words[0].text.to_ascii_lowercase();
        let value = || {
            words.get(1).copied().ok_or_else(|| {
                e.at(
                    number,
                    line,
                    line.trim_end().len(),
                    format!("expected a value for `{key}`"),
                )
            })
        };
        match key.as_str() {
            "mass" => self.units.mass = e.number(number, line, value()?, false)?,
            "length" => {
                let token = value()?;
                let length = e.number(number, line, token, false)?;
                if length <= 0.0 {
                    return Err(e.at_token(
                        number,
                        line,
                        token,
                        format!("expected a positive length scale, found `{}`", token.text),
                    ));
                }
                self.units.length = length;
            }
            "angle" => {
                let token = value()?;
                self.units.angle = match token.text.to_ascii_lowercase().as_str() {
                    "deg" | "degree" | "degrees" => AngleUnit::Degrees,
                    "rad" | "radian" | "radians" => AngleUnit::Radians,
                    _ => {
                        return Err(e.at_token(
                            number,
                            line,
                            token,
                            format!("expected `deg` or `rad`, found `{}`", token.text),
                        ))
                    }
                };
            }
            _ => {}
        }
        Ok(())
    }

    fn root_line(&mut self, number: usize, line: &str, words: &[Token]) -> Result<()> {
        let e = &self.errors;
        match words[0].text.to_ascii_lowercase().as_str() {
            "order" => {
                let mut order = Vec::new();
                for &token in &words[1..] {
                    let dof = Dof::parse(token.text).ok_or_else(|| {
                        e.at_token(
                            number,
                            line,
                            token,
                            format!(
                                "expected one of TX TY TZ RX RY RZ in the root order, found `{}`",
                                token.text
                            ),
                        )
                    })?;
                    if order.contains(&dof) {
                        return Err(e.at_token(
                            number,
                            line,
                            token,
                            format!("`{}` is listed twice in the root order", token.text),
                        ));
                    }
                    order.push(dof);
                }
                self.root.order = order;
            }
            "axis" => {
                let token = words.get(1).copied().ok_or_else(|| {
                    e.at(
                        number,
                        line,
                        line.trim_end().len(),
                        "expected an axis order such as XYZ",
                    )
                })?;
                self.root.axis_order = e.axis_order(number, line, token)?;
            }
            "position" => self.root.position = e.vec3(number, line, words, "position")?,
            "orientation" => self.root.orientation = e.vec3(number, line, words, "orientation")?,
            _ => {}
        }
        Ok(())
    }

    fn bone_line(
        &mut self,
        number: usize,
        line: &str,
        words: &[Token],
        block: &mut Option<BoneBlock>,
        in_limits: &mut bool,
    ) -> Result<()> {
        let e = &self.errors;
        let first = words[0];
        let key = first.text.to_ascii_lowercase();
        let Some(b) = block else {
            if key == "begin" {
                *block = Some(BoneBlock {
                    begin_line: number,
                    name: None,
                    direction: None,
                    length: None,
                    axis: Vec3::ZERO,
                    axis_order: [Axis::X, Axis::Y, Axis::Z],
                    dofs: Vec::new(),
                    limits: Vec::new(),
                    limits_line: 0,
                });
                return Ok(());
            }
            return Err(e.at_token(
                number,
                line,
                first,
                format!("expected `begin` of a bone, found `{}`", first.text),
            ));
        };
        let continues_limits = *in_limits && first.text.starts_with('(');
        *in_limits = false;
        if continues_limits || key == "limits" || key.starts_with("limits(") {
            *in_limits = true;
            if b.limits.is_empty() {
                b.limits_line = number;
            }
            // Parentheses become spaces; offsets stay the same.
            let cleaned = line.replace(['(', ')'], " ");
            let skip = usize::from(!continues_limits);
            let numbers: Vec<Token> = tokens(&cleaned).into_iter().skip(skip).collect();
            if numbers.len() % 2 == 1 {
                return Err(e.at(
                    number,
                    line,
                    line.trim_end().len(),
                    "expected limits as pairs `(min max)`",
                ));
            }
            for pair in numbers.chunks(2) {
                let min = e.number(number, &cleaned, pair[0], true)?;
                let max = e.number(number, &cleaned, pair[1], true)?;
                b.limits.push((min, max));
            }
            return Ok(());
        }
        match key.as_str() {
            "begin" => {
                return Err(e.at_token(
                    number,
                    line,
                    first,
                    format!(
                        "expected `end` of the bone block that starts at line {}",
                        b.begin_line
                    ),
                ))
            }
            "end" => {
                let b = block.take().expect("inside a bone block");
                self.finish_bone(b)?;
            }
            "name" => {
                let token = words.get(1).ok_or_else(|| {
                    e.at(number, line, line.trim_end().len(), "expected a bone name")
                })?;
                b.name = Some((token.text.to_string(), number));
            }
            "direction" => b.direction = Some(e.vec3(number, line, words, "direction")?),
            "length" => {
                let token = words.get(1).copied().ok_or_else(|| {
                    e.at(
                        number,
                        line,
                        line.trim_end().len(),
                        "expected a bone length",
                    )
                })?;
                b.length = Some(e.number(number, line, token, false)?);
            }
            "axis" => {
                b.axis = e.vec3(number, line, words, "axis")?;
                if let Some(&token) = words.get(4) {
                    b.axis_order = e.axis_order(number, line, token)?;
                }
            }
            "dof" => {
                b.dofs.clear();
                for &token in &words[1..] {
                    if token.text.eq_ignore_ascii_case("l") {
                        return Err(e.at_token(
                            number,
                            line,
                            token,
                            "dof `l` (bone length change over time) is not supported",
                        ));
                    }
                    let dof = Dof::parse(token.text).ok_or_else(|| {
                        e.at_token(
                            number,
                            line,
                            token,
                            format!(
                                "unknown dof `{}`, expected rx, ry, rz, tx, ty or tz",
                                token.text
                            ),
                        )
                    })?;
                    if b.dofs.contains(&dof) {
                        return Err(e.at_token(
                            number,
                            line,
                            token,
                            format!("dof `{}` is listed twice", token.text),
                        ));
                    }
                    b.dofs.push(dof);
                }
            }
            // `id`, `bodymass`, `cofmass` and other fields are not needed.
            _ => {}
        }
        Ok(())
    }

    fn finish_bone(&mut self, b: BoneBlock) -> Result<()> {
        let e = &self.errors;
        let missing = |what: &str| {
            let named = match &b.name {
                Some((name, _)) => format!("bone `{name}`"),
                None => "bone".to_string(),
            };
            e.at(
                b.begin_line,
                "",
                0,
                format!("the {named} that starts here has no `{what}`"),
            )
        };
        let Some((name, name_line)) = b.name.clone() else {
            return Err(missing("name"));
        };
        let direction = b.direction.ok_or_else(|| missing("direction"))?;
        let length = b.length.ok_or_else(|| missing("length"))?;
        if !b.limits.is_empty() && b.limits.len() != b.dofs.len() {
            return Err(e.at(
                b.limits_line,
                "",
                0,
                format!(
                    "bone `{name}` has {} dofs but {} limits",
                    b.dofs.len(),
                    b.limits.len()
                ),
            ));
        }
        if name.eq_ignore_ascii_case("root") {
            return Err(e.at(
                name_line,
                "",
                0,
                "a bone cannot be named `root`: the name is kept for the root",
            ));
        }
        if let Some(&other) = self.bone_index.get(&name) {
            return Err(e.at(
                name_line,
                "",
                0,
                format!(
                    "bone `{name}` is defined twice (first at line {})",
                    self.bone_lines[other]
                ),
            ));
        }
        self.bone_index.insert(name.clone(), self.bones.len());
        self.bone_lines.push(name_line);
        self.bones.push(AsfBone {
            name,
            direction,
            length,
            axis: b.axis,
            axis_order: b.axis_order,
            dofs: b.dofs,
            limits: b.limits,
            parent: None,
            children: Vec::new(),
        });
        Ok(())
    }

    /// Links parents and children from the `:hierarchy` lines; returns the
    /// bones attached to the root.
    fn hierarchy(&mut self, lines: &[(usize, &str)]) -> Result<Vec<usize>> {
        let e = &self.errors;
        let mut root_children = Vec::new();
        let mut has_parent = vec![false; self.bones.len()];
        let mut inside = false;
        for &(number, line) in lines {
            let words = tokens(line);
            let Some(&first) = words.first() else {
                continue;
            };
            if first.text.eq_ignore_ascii_case("begin") {
                inside = true;
                continue;
            }
            if first.text.eq_ignore_ascii_case("end") {
                break;
            }
            if !inside {
                return Err(e.at_token(
                    number,
                    line,
                    first,
                    format!("expected `begin` of the hierarchy, found `{}`", first.text),
                ));
            }
            let lookup = |token: Token| {
                self.bone_index.get(token.text).copied().ok_or_else(|| {
                    e.at_token(
                        number,
                        line,
                        token,
                        format!(
                            "bone `{}` is used in :hierarchy but not defined in :bonedata",
                            token.text
                        ),
                    )
                })
            };
            let parent = if first.text.eq_ignore_ascii_case("root") {
                None
            } else {
                Some(lookup(first)?)
            };
            for &token in &words[1..] {
                if token.text.eq_ignore_ascii_case("root") {
                    return Err(e.at_token(number, line, token, "the root cannot be a child"));
                }
                let child = lookup(token)?;
                if has_parent[child] {
                    return Err(e.at_token(
                        number,
                        line,
                        token,
                        format!("bone `{}` is given a second parent", token.text),
                    ));
                }
                has_parent[child] = true;
                self.bones[child].parent = parent;
                match parent {
                    None => root_children.push(child),
                    Some(p) => self.bones[p].children.push(child),
                }
            }
        }
        Ok(root_children)
    }

    /// Bones depth first from the root; every bone must be reached.
    fn joint_order(&self, root_children: &[usize]) -> Result<Vec<usize>> {
        let mut order = Vec::with_capacity(self.bones.len());
        let mut stack: Vec<usize> = root_children.iter().rev().copied().collect();
        let mut visited = vec![false; self.bones.len()];
        while let Some(b) = stack.pop() {
            if visited[b] {
                continue;
            }
            visited[b] = true;
            order.push(b);
            stack.extend(self.bones[b].children.iter().rev());
        }
        if let Some(b) = visited.iter().position(|&v| !v) {
            return Err(self.errors.at(
                self.bone_lines[b],
                "",
                0,
                format!(
                    "bone `{}` is not connected to the root in :hierarchy",
                    self.bones[b].name
                ),
            ));
        }
        Ok(order)
    }
}

// ---------------------------------------------------------------------------
// AMC

/// Parses an AMC motion of `skeleton` from the bytes of a file (decoded
/// lossily). `path` is used in errors.
pub fn parse_amc(
    bytes: &[u8],
    path: &Path,
    skeleton: &AsfSkeleton,
    options: &AsfOptions,
) -> Result<Motion> {
    check_frame_rate(options)?;
    let text = String::from_utf8_lossy(bytes);
    let (values, frame_count, angle) = read_amc_values(text_lines(&text), path, skeleton)?;
    build_motion(skeleton, &values, frame_count, angle, options)
}

fn check_frame_rate(options: &AsfOptions) -> Result<()> {
    if !(options.frame_rate.is_finite() && options.frame_rate > 0.0) {
        return Err(Error::Invalid(format!(
            "the frame rate must be a positive number of frames per second, got {}",
            options.frame_rate
        )));
    }
    Ok(())
}

/// Segment names of an AMC line: the root or a bone.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Segment {
    Root,
    Bone(usize),
}

/// The values of every frame, laid out as the root's then each bone's in
/// file order ([`AsfSkeleton::dof_count`] per frame), the frame count and
/// the angle unit.
fn read_amc_values<'t>(
    lines: impl Iterator<Item = Result<(usize, Cow<'t, str>)>>,
    path: &Path,
    skeleton: &AsfSkeleton,
) -> Result<(Vec<f32>, usize, AngleUnit)> {
    let e = Errors { path };
    let per_frame = skeleton.dof_count();
    let mut starts = Vec::with_capacity(skeleton.bones.len());
    let mut start = skeleton.root.order.len();
    for bone in &skeleton.bones {
        starts.push(start);
        start += bone.dofs.len();
    }
    let mut names: HashMap<&str, Segment> = HashMap::new();
    names.insert("root", Segment::Root);
    for (i, bone) in skeleton.bones.iter().enumerate() {
        names.insert(bone.name.as_str(), Segment::Bone(i));
    }
    let find = |name: &str| {
        names.get(name).copied().or_else(|| {
            // Vicon matches names case-insensitively.
            if name.eq_ignore_ascii_case("root") {
                return Some(Segment::Root);
            }
            skeleton
                .bones
                .iter()
                .position(|b| b.name.eq_ignore_ascii_case(name))
                .map(Segment::Bone)
        })
    };

    let mut angle = skeleton.units.angle;
    let mut values: Vec<f32> = Vec::new();
    let mut frame_count = 0;
    // Number and line of the frame being read, and which segments it gave
    // (index 0 the root, then the bones).
    let mut frame: Option<(u64, usize)> = None;
    let mut given = vec![false; skeleton.bones.len() + 1];
    let check_frame = |frame: Option<(u64, usize)>, given: &[bool]| -> Result<()> {
        let Some((frame_number, frame_line)) = frame else {
            return Ok(());
        };
        let missing = if !given[0] && !skeleton.root.order.is_empty() {
            Some("root")
        } else {
            skeleton
                .bones
                .iter()
                .zip(&given[1..])
                .find(|(b, &g)| !g && !b.dofs.is_empty())
                .map(|(b, _)| b.name.as_str())
        };
        match missing {
            Some(name) => Err(e.at(
                frame_line,
                "",
                0,
                format!("frame {frame_number} has no line for `{name}`"),
            )),
            None => Ok(()),
        }
    };
    for item in lines {
        let (number, line) = item?;
        let line: &str = &line;
        let words = tokens(line);
        let Some(&first) = words.first() else {
            continue;
        };
        if first.text.starts_with(':') {
            if first.text.eq_ignore_ascii_case(":degrees") {
                angle = AngleUnit::Degrees;
            } else if first.text.eq_ignore_ascii_case(":radians") {
                angle = AngleUnit::Radians;
            }
            continue;
        }
        if words.len() == 1 && first.text.bytes().all(|c| c.is_ascii_digit()) {
            let frame_number: u64 = first.text.parse().map_err(|_| {
                e.at_token(
                    number,
                    line,
                    first,
                    format!("frame number `{}` is too large", first.text),
                )
            })?;
            check_frame(frame, &given)?;
            if let Some((previous, _)) = frame {
                let expected = previous.saturating_add(1);
                if frame_number != expected {
                    return Err(e.at_token(
                        number,
                        line,
                        first,
                        format!(
                            "frame numbers out of sequence: expected {expected}, found {frame_number}"
                        ),
                    ));
                }
            }
            frame = Some((frame_number, number));
            given.fill(false);
            values.resize(values.len() + per_frame, 0.0);
            frame_count += 1;
            continue;
        }
        if frame.is_none() {
            return Err(e.at_token(
                number,
                line,
                first,
                format!("expected a frame number, found `{}`", first.text),
            ));
        }
        let segment = find(first.text).ok_or_else(|| {
            e.at_token(
                number,
                line,
                first,
                format!(
                    "unknown bone `{}`: the ASF skeleton has no such bone",
                    first.text
                ),
            )
        })?;
        let (slot, dofs, start) = match segment {
            Segment::Root => (0, &skeleton.root.order, 0),
            Segment::Bone(b) => (b + 1, &skeleton.bones[b].dofs, starts[b]),
        };
        if given[slot] {
            return Err(e.at_token(
                number,
                line,
                first,
                format!("`{}` is given twice in this frame", first.text),
            ));
        }
        given[slot] = true;
        let found = &words[1..];
        if found.len() != dofs.len() {
            let names: Vec<String> = dofs
                .iter()
                .map(|d| format!("{d:?}").to_lowercase())
                .collect();
            let offset = found
                .get(dofs.len())
                .map_or(line.trim_end().len(), |t| t.offset);
            return Err(e.at(
                number,
                line,
                offset,
                format!(
                    "`{}` has {} dofs ({}) but this line gives {} values",
                    first.text,
                    dofs.len(),
                    names.join(" "),
                    found.len()
                ),
            ));
        }
        let base = values.len() - per_frame + start;
        for (k, &token) in found.iter().enumerate() {
            values[base + k] = e.number(number, line, token, false)?;
        }
    }
    check_frame(frame, &given)?;
    Ok((values, frame_count, angle))
}

/// How one ASF segment's AMC values become its joint's channels.
struct JointPlan<'a> {
    joint: usize,
    /// The segment's values in an AMC frame.
    value_start: usize,
    dofs: &'a [Dof],
    /// `C` of a bone; the preset orientation `O` of the root.
    frame: Quat,
    is_root: bool,
    /// Rest offset in output units (for translation dofs of bones).
    offset: Vec3,
    /// Columns of the joint's Zrotation, Yrotation, Xrotation channels.
    rotation_columns: Option<[usize; 3]>,
    /// The rotation channels can hold the file's angles unchanged: `frame`
    /// is the identity and the rotation dofs come x before y before z.
    copy_angles: bool,
}

fn build_motion(
    asf: &AsfSkeleton,
    values: &[f32],
    frame_count: usize,
    angle: AngleUnit,
    options: &AsfOptions,
) -> Result<Motion> {
    let scale = asf.length_factor(options.length_unit);
    let skeleton = asf.to_skeleton(options.length_unit)?;
    let plans = joint_plans(asf, &skeleton);
    let mut motion = Motion::rest(skeleton, 1.0 / options.frame_rate, frame_count)?;
    let radians = angle.to_radians_factor();
    let per_frame = asf.dof_count();
    for f in 0..frame_count {
        let frame_values = &values[f * per_frame..(f + 1) * per_frame];
        for plan in &plans {
            let own = &frame_values[plan.value_start..plan.value_start + plan.dofs.len()];
            let mut translation = Vec3::ZERO;
            let mut has_translation = false;
            for (d, &v) in plan.dofs.iter().zip(own) {
                if !d.is_rotation() {
                    translation[d.axis() as usize] = v * scale;
                    has_translation = true;
                }
            }
            if plan.is_root {
                let position = asf.root.position * scale + translation;
                motion.set_local_translation(f, plan.joint, position);
            } else if has_translation {
                motion.set_local_translation(f, plan.joint, plan.offset + plan.frame * translation);
            }
            let Some(columns) = plan.rotation_columns else {
                continue;
            };
            if plan.copy_angles {
                let mut zyx = [0.0; 3];
                for (d, &v) in plan.dofs.iter().zip(own) {
                    if d.is_rotation() {
                        let degrees = match angle {
                            AngleUnit::Degrees => v,
                            AngleUnit::Radians => v.to_degrees(),
                        };
                        zyx[2 - d.axis() as usize] = degrees;
                    }
                }
                let row = motion.frame_mut(f);
                for (column, value) in columns.into_iter().zip(zyx) {
                    row[column] = value;
                }
                continue;
            }
            let m = fixed_axes_rotation(
                plan.dofs
                    .iter()
                    .zip(own)
                    .filter(|(d, _)| d.is_rotation())
                    .map(|(d, &v)| (d.axis(), v * radians)),
            );
            let local = if plan.is_root {
                plan.frame * m
            } else {
                plan.frame * m * plan.frame.inverse()
            };
            motion.set_local_rotation(f, plan.joint, local);
        }
    }
    Ok(motion)
}

fn joint_plans<'a>(asf: &'a AsfSkeleton, skeleton: &Skeleton) -> Vec<JointPlan<'a>> {
    let rotation_columns = |joint: usize| {
        let channels = &skeleton.joint(joint).channels;
        let start = skeleton.channel_start(joint);
        let column = |c: Channel| channels.iter().position(|&x| x == c).map(|k| start + k);
        Some([
            column(Channel::Zrotation)?,
            column(Channel::Yrotation)?,
            column(Channel::Xrotation)?,
        ])
    };
    let in_xyz_order = |dofs: &[Dof]| {
        let axes: Vec<usize> = dofs
            .iter()
            .filter(|d| d.is_rotation())
            .map(|d| d.axis() as usize)
            .collect();
        axes.windows(2).all(|w| w[0] < w[1])
    };
    let mut plans = Vec::with_capacity(asf.bones.len() + 1);
    let root_frame = asf.root_orientation();
    plans.push(JointPlan {
        joint: 0,
        value_start: 0,
        dofs: &asf.root.order,
        frame: root_frame,
        is_root: true,
        offset: Vec3::ZERO,
        rotation_columns: rotation_columns(0),
        copy_angles: asf.root.orientation == Vec3::ZERO && in_xyz_order(&asf.root.order),
    });
    let mut value_starts = Vec::with_capacity(asf.bones.len());
    let mut start = asf.root.order.len();
    for bone in &asf.bones {
        value_starts.push(start);
        start += bone.dofs.len();
    }
    for (k, &b) in asf.joint_order.iter().enumerate() {
        let bone = &asf.bones[b];
        let joint = k + 1;
        plans.push(JointPlan {
            joint,
            value_start: value_starts[b],
            dofs: &bone.dofs,
            frame: asf.axis_frame(b),
            is_root: false,
            offset: skeleton.joint(joint).offset,
            rotation_columns: rotation_columns(joint),
            copy_angles: bone.axis == Vec3::ZERO && in_xyz_order(&bone.dofs),
        });
    }
    plans
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Lines read from a file one at a time are the lines of its whole
    /// text, whatever the reader's buffer cuts (a `\r\n` split between two
    /// fills, a UTF-8 sequence cut, a line longer than the buffer).
    #[test]
    fn streamed_lines_are_the_lines_of_the_whole_text() {
        let texts: [&[u8]; 6] = [
            b"a\r\nb\nc\r  # note\n\n1.#QNAN",
            b"\r\n\r\r\n\n\n",
            b"root 1 2 3\r\nlfemur 4\xff 5\xc3\xa9 6\r\n",
            b"no ending",
            b"",
            b"a long line that no buffer of a few bytes holds at once\rx\n",
        ];
        for bytes in texts {
            let text = String::from_utf8_lossy(bytes);
            let expected: Vec<(usize, String)> =
                lines(&text).map(|(n, l)| (n, l.to_string())).collect();
            for capacity in [1, 2, 3, 7, 64] {
                let reader = std::io::BufReader::with_capacity(capacity, bytes);
                let got: Vec<(usize, String)> = StreamedLines::new(reader, Path::new("x.amc"))
                    .map(|item| item.map(|(n, l)| (n, l.into_owned())).unwrap())
                    .collect();
                assert_eq!(got, expected, "{bytes:?} read {capacity} bytes at a time");
            }
        }
    }

    /// A real AMC motion read from its file line by line is the motion
    /// parsed from its bytes.
    #[test]
    fn an_amc_file_reads_as_its_bytes_parse() {
        let Some(dir) = mocap_testdata::shared("hdm05-sample") else {
            eprintln!("note: ../shared/data/hdm05-sample is absent; skipped");
            return;
        };
        let skeleton = read_asf(dir.join("HDM_bd.asf")).unwrap();
        let amc = dir.join("HDM_bd_depositFloorR_001_120.amc");
        let read = read_amc(&amc, &skeleton).unwrap();
        let bytes = std::fs::read(&amc).unwrap();
        let parsed = parse_amc(&bytes, &amc, &skeleton, &AsfOptions::default()).unwrap();
        assert_eq!(read, parsed);
    }

    #[test]
    fn lines_split_at_every_ending_and_drop_comments() {
        let text = "a\r\nb\nc\r  # note\n\n1.#QNAN";
        let got: Vec<(usize, &str)> = lines(text).collect();
        assert_eq!(
            got,
            vec![
                (1, "a"),
                (2, "b"),
                (3, "c"),
                (4, ""),
                (5, ""),
                (6, "1.#QNAN")
            ]
        );
    }

    #[test]
    fn token_offsets_point_into_the_line() {
        let line = "  dof rx\try";
        let t = tokens(line);
        assert_eq!(t.len(), 3);
        assert_eq!((t[0].text, t[0].offset), ("dof", 2));
        assert_eq!((t[2].text, t[2].offset), ("ry", 9));
    }

    #[test]
    fn fixed_axes_apply_first_listed_first() {
        let (a, b) = (0.3, -1.1);
        let q = fixed_axes_rotation([(Axis::X, a), (Axis::Z, b)].into_iter());
        let expected = Quat::from_rotation_z(b) * Quat::from_rotation_x(a);
        assert!(q.angle_between(expected) < 1e-6);
    }
}
