//! What a viewer needs to draw motions: for each motion its skeleton topology
//! (point names and parents), the global position of every point in every
//! frame, optional per-joint confidence, a label and a colour.
//!
//! Positions come from `mocap_core`'s forward kinematics for BVH and ASF/AMC
//! motions, or are given directly for captures that are only joint positions
//! (sensor and fused recordings). They are stored in **metres**: each motion's
//! length unit is guessed from the size of its figure (see
//! [`guess_metres_per_unit`]) so that a BVH in centimetres and a Kinect
//! recording in metres can be overlaid and the floor grid has metre cells.
//!
//! A motion's *points* are its joints followed by the end sites of the file
//! (the tips of the head, fingers and toes): drawing bones to them makes the
//! figure complete, as in Blender. Confidence is per joint only.

use std::path::{Path, PathBuf};

use mocap_core::io::read_motions;
use mocap_core::kinematics::{end_site_positions, forward_kinematics_range, frame_pieces};
use mocap_core::rotation::Vec3;
use mocap_core::{Error, Motion, Result};
use serde::Serialize;

/// Distinct colours for motions shown together (Tableau 10, which stays
/// distinguishable for the common colour-vision deficiencies).
pub const PALETTE: [[u8; 3]; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];

/// One motion ready to be drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewMotion {
    /// Shown in the legend (file name, "noisy", "cleaned", ...).
    pub label: String,
    /// Where the motion came from (a path), if anywhere.
    pub source: Option<String>,
    /// Names of the points: joints first, then end sites (`"<joint> end"`).
    pub names: Vec<String>,
    /// Parent point of each point (`None` for roots). Joints from files are
    /// in parent-before-child order; captures given as positions may not be
    /// (Kinect v2); end sites always follow their joint.
    pub parents: Vec<Option<usize>>,
    /// How many of the points are joints (the rest are end sites).
    pub joint_count: usize,
    /// Whether the bone from each point's parent to it is drawn. A joint
    /// whose position channels move it about its parent is not held by a
    /// rigid bone (Bandai's `Hips` carries the walk under a `joint_Root`
    /// that stays at the origin): a line there would be no bone, so it is
    /// left out.
    pub bones: Vec<bool>,
    /// Seconds between frames.
    pub frame_time: f64,
    pub frame_count: usize,
    /// Positions in metres, `frame * point_count + point`.
    pub positions: Vec<Vec3>,
    /// Confidence of each joint in each frame (`frame * joint_count + joint`),
    /// from 0 (not trusted) to 1 (fully trusted).
    pub confidence: Option<Vec<f32>>,
    /// Drawing colour; `None` takes the next colour of [`PALETTE`].
    pub colour: Option<[u8; 3]>,
    /// The factor that turned the file's length unit into metres.
    pub metres_per_unit: f32,
}

impl ViewMotion {
    /// A motion's skeleton and global positions (by forward kinematics),
    /// with its end sites, converted to metres.
    pub fn from_motion(label: impl Into<String>, motion: &Motion) -> ViewMotion {
        let skeleton = motion.skeleton();
        let joint_count = skeleton.joint_count();
        let mut names: Vec<String> = skeleton.joints().iter().map(|j| j.name.clone()).collect();
        let mut parents = skeleton.parents();
        for (j, joint) in skeleton.joints().iter().enumerate() {
            for k in 0..joint.end_sites.len() {
                let suffix = if joint.end_sites.len() > 1 {
                    format!(" end {}", k + 1)
                } else {
                    " end".to_string()
                };
                names.push(format!("{}{suffix}", joint.name));
                parents.push(Some(j));
            }
        }
        let point_count = names.len();
        let mut positions = Vec::with_capacity(point_count * motion.frame_count());
        // A piece of the take at a time: the full global poses (rotations
        // too) of a long take would take more memory than its positions.
        for piece in frame_pieces(motion.frame_count()) {
            let poses = forward_kinematics_range(motion, piece);
            for f in 0..poses.frame_count {
                positions.extend_from_slice(poses.frame_positions(f));
                positions.extend(
                    end_site_positions(motion, &poses, f)
                        .into_iter()
                        .map(|(_, p)| p),
                );
            }
        }
        let bones: Vec<bool> = (0..point_count)
            .map(|p| p >= joint_count || (parents[p].is_some() && !translates(motion, p)))
            .collect();
        let metres_per_unit = guess_metres_per_unit(figure_extent(&positions, &parents, &bones));
        for p in &mut positions {
            *p *= metres_per_unit;
        }
        ViewMotion {
            label: label.into(),
            source: None,
            names,
            parents,
            joint_count,
            bones,
            frame_time: motion.frame_time(),
            frame_count: motion.frame_count(),
            positions,
            confidence: None,
            colour: None,
            metres_per_unit,
        }
    }

    /// A capture given as joint positions only (a sensor or fused
    /// recording): `positions` holds `frame_count * names.len()` points,
    /// frame after frame, in the capture's length unit. With
    /// `metres_per_unit = None` the unit is guessed from the figure's size.
    pub fn from_positions(
        label: impl Into<String>,
        names: Vec<String>,
        parents: Vec<Option<usize>>,
        frame_time: f64,
        positions: Vec<Vec3>,
        metres_per_unit: Option<f32>,
    ) -> Result<ViewMotion> {
        let label = label.into();
        let n = names.len();
        if parents.len() != n {
            return Err(Error::Invalid(format!(
                "{label}: {n} joint names but {} parents",
                parents.len()
            )));
        }
        // Any order will do for drawing (Kinect's is not parent-before-child).
        if let Some((j, p)) = parents
            .iter()
            .enumerate()
            .find_map(|(j, p)| p.filter(|&p| p >= n || p == j).map(|p| (j, p)))
        {
            return Err(Error::Invalid(format!(
                "{label}: joint {j} ({}) has parent {p}, which is not another joint",
                names[j]
            )));
        }
        if !(frame_time.is_finite() && frame_time > 0.0) {
            return Err(Error::Invalid(format!(
                "{label}: frame time must be a positive number of seconds, got {frame_time}"
            )));
        }
        if n == 0 || !positions.len().is_multiple_of(n) {
            return Err(Error::Invalid(format!(
                "{label}: {} positions is not a whole number of frames of {n} joints",
                positions.len()
            )));
        }
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::Invalid(format!(
                "{label}: joint {} ({}) of frame {} has a position that is not a finite number",
                i % n,
                names[i % n],
                i / n
            )));
        }
        let frame_count = positions.len() / n;
        let bones: Vec<bool> = parents.iter().map(Option::is_some).collect();
        let metres_per_unit = match metres_per_unit {
            Some(m) if m.is_finite() && m > 0.0 => m,
            Some(m) => {
                return Err(Error::Invalid(format!(
                    "{label}: metres per unit must be a positive number, got {m}"
                )))
            }
            None => guess_metres_per_unit(figure_extent(&positions, &parents, &bones)),
        };
        let positions = positions.into_iter().map(|p| p * metres_per_unit).collect();
        Ok(ViewMotion {
            label,
            source: None,
            names,
            parents,
            joint_count: n,
            bones,
            frame_time,
            frame_count,
            positions,
            confidence: None,
            colour: None,
            metres_per_unit,
        })
    }

    /// Adds per-joint confidence, `frame_count * joint_count` values frame
    /// after frame, 0 = not trusted, 1 = fully trusted (values outside are
    /// clamped; callers with another scale divide first).
    pub fn with_confidence(mut self, confidence: Vec<f32>) -> Result<ViewMotion> {
        let expected = self.frame_count * self.joint_count;
        if confidence.len() != expected {
            return Err(Error::Invalid(format!(
                "{}: {} frames of {} joints need {expected} confidence values, got {}",
                self.label,
                self.frame_count,
                self.joint_count,
                confidence.len()
            )));
        }
        if let Some(i) = confidence.iter().position(|c| !c.is_finite()) {
            return Err(Error::Invalid(format!(
                "{}: the confidence of joint {} in frame {} is not a finite number",
                self.label,
                i % self.joint_count,
                i / self.joint_count
            )));
        }
        self.confidence = Some(confidence.into_iter().map(|c| c.clamp(0.0, 1.0)).collect());
        Ok(self)
    }

    /// Sets the drawing colour.
    pub fn with_colour(mut self, colour: [u8; 3]) -> ViewMotion {
        self.colour = Some(colour);
        self
    }

    /// Sets the source shown under the label.
    pub fn with_source(mut self, source: impl Into<String>) -> ViewMotion {
        self.source = Some(source.into());
        self
    }

    /// Whether a point is drawn: it ends or starts a drawn bone, or stands
    /// alone. (Bandai's `joint_Root`, joined to nothing by a bone, is not.)
    pub fn point_shown(&self, point: usize) -> bool {
        point_shown(point, &self.parents, &self.bones)
    }

    /// The point a camera follows: the first shown point not held by a bone
    /// (the hips, for Bandai as for most rigs).
    pub fn body_root(&self) -> usize {
        (0..self.point_count())
            .find(|&p| self.point_shown(p) && !self.bones[p])
            .unwrap_or(0)
    }

    /// The farthest any shown point gets horizontally from the body root
    /// over the take (half the figure's widest horizontal span).
    pub fn horizontal_reach(&self) -> f32 {
        let root = self.body_root();
        let shown: Vec<bool> = (0..self.point_count())
            .map(|p| self.point_shown(p))
            .collect();
        let mut reach: f32 = 0.0;
        for f in 0..self.frame_count {
            let points = self.frame_positions(f);
            for (p, &q) in points.iter().enumerate() {
                if shown[p] {
                    let d = q - points[root];
                    reach = reach.max(d.x.hypot(d.z));
                }
            }
        }
        reach
    }

    /// Number of points (joints and end sites).
    pub fn point_count(&self) -> usize {
        self.names.len()
    }

    /// The positions of all points in one frame.
    pub fn frame_positions(&self, frame: usize) -> &[Vec3] {
        let n = self.point_count();
        &self.positions[frame * n..(frame + 1) * n]
    }

    /// The confidence of one joint in one frame, if the motion has any. End
    /// sites take their joint's confidence.
    pub fn joint_confidence(&self, frame: usize, point: usize) -> Option<f32> {
        let confidence = self.confidence.as_ref()?;
        let mut joint = point;
        while joint >= self.joint_count {
            joint = self.parents[joint]?;
        }
        Some(confidence[frame * self.joint_count + joint])
    }

    /// Smallest and largest position over all points and frames.
    pub fn bounding_box(&self) -> Option<(Vec3, Vec3)> {
        bounding_box(&self.positions)
    }
}

/// Several motions shown together, each with its colour.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scene {
    pub motions: Vec<ViewMotion>,
}

impl Scene {
    /// A scene of the given motions; those without a colour get the palette's
    /// colours in turn.
    pub fn new(motions: Vec<ViewMotion>) -> Scene {
        let mut scene = Scene { motions };
        for (i, m) in scene.motions.iter_mut().enumerate() {
            m.colour.get_or_insert(PALETTE[i % PALETTE.len()]);
        }
        scene
    }

    /// Reads motion files (`.bvh`, or `.asf` followed by its `.amc` files,
    /// as [`mocap_core::io::MotionSource::group`] pairs them) and captures
    /// (`.jsonl`, see [`read_capture`]), labelled by file name.
    pub fn from_files(paths: &[PathBuf]) -> Result<Scene> {
        if paths.is_empty() {
            return Err(Error::Invalid("no motion files given".to_string()));
        }
        let mut motions = Vec::new();
        // Runs of motion files go to mocap_core's reader (which pairs ASF
        // and AMC files); each capture file is read on its own, in order.
        let mut run: Vec<PathBuf> = Vec::new();
        let flush = |run: &mut Vec<PathBuf>, motions: &mut Vec<ViewMotion>| -> Result<()> {
            if !run.is_empty() {
                for (source, motion) in read_motions(run)? {
                    let name = source.display_name();
                    motions.push(
                        ViewMotion::from_motion(file_label(Path::new(&name)), &motion)
                            .with_source(name),
                    );
                }
                run.clear();
            }
            Ok(())
        };
        for path in paths {
            if is_capture(path) {
                flush(&mut run, &mut motions)?;
                motions.extend(read_capture(path)?);
            } else {
                run.push(path.clone());
            }
        }
        flush(&mut run, &mut motions)?;
        Ok(Scene::new(motions))
    }

    /// The scene as compact JSON for the web viewer:
    /// `{"version": 1, "up": "y", "unit": "m", "motions": [...]}` where each
    /// motion has `label`, `source`, `colour` (`#rrggbb`), `frame_time` (s),
    /// `frame_count`, `joint_count`, `names` and `parents` of its points
    /// (joints, then end sites), `bones` (per point: draw the bone from its
    /// parent), `shown` (per point: draw it), `metres_per_unit` (the factor
    /// applied to the file's numbers), `positions` (metres, `[x, y, z]` of
    /// every point of frame 0, then frame 1, ... flattened) and `confidence`
    /// (`null`, or one value in 0..1 per joint per frame).
    pub fn to_json(&self) -> String {
        let motions = self
            .motions
            .iter()
            .enumerate()
            .map(|(i, m)| MotionJson {
                label: &m.label,
                source: m.source.as_deref(),
                colour: hex_colour(m.colour.unwrap_or(PALETTE[i % PALETTE.len()])),
                frame_time: m.frame_time,
                frame_count: m.frame_count,
                joint_count: m.joint_count,
                names: &m.names,
                bones: &m.bones,
                shown: (0..m.point_count()).map(|p| m.point_shown(p)).collect(),
                parents: &m.parents,
                metres_per_unit: m.metres_per_unit,
                // 0.1 mm is finer than any capture resolves and keeps the
                // numbers short.
                positions: m
                    .positions
                    .iter()
                    .flat_map(|p| [p.x, p.y, p.z])
                    .map(|v| round_to(v, 1e4))
                    .collect(),
                confidence: m
                    .confidence
                    .as_ref()
                    .map(|c| c.iter().map(|&v| round_to(v, 1e3)).collect()),
            })
            .collect();
        serde_json::to_string(&SceneJson {
            version: 1,
            up: "y",
            unit: "m",
            motions,
        })
        .expect("a scene of finite numbers always serialises")
    }
}

#[derive(Serialize)]
struct SceneJson<'a> {
    version: u32,
    up: &'static str,
    unit: &'static str,
    motions: Vec<MotionJson<'a>>,
}

#[derive(Serialize)]
struct MotionJson<'a> {
    label: &'a str,
    source: Option<&'a str>,
    colour: String,
    frame_time: f64,
    frame_count: usize,
    joint_count: usize,
    names: &'a [String],
    bones: &'a [bool],
    shown: Vec<bool>,
    parents: &'a [Option<usize>],
    metres_per_unit: f32,
    positions: Vec<f32>,
    confidence: Option<Vec<f32>>,
}

fn round_to(v: f32, scale: f32) -> f32 {
    (v * scale).round() / scale
}

/// `#rrggbb`.
pub(crate) fn hex_colour([r, g, b]: [u8; 3]) -> String {
    format!("#{r:02x}{g:02x}{b:02x}")
}

/// The file name without its extension, for legends.
pub(crate) fn file_label(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// Smallest and largest coordinates of `points`.
pub(crate) fn bounding_box(points: &[Vec3]) -> Option<(Vec3, Vec3)> {
    let first = *points.first()?;
    Some(
        points
            .iter()
            .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
    )
}

/// Whether `joint` moves relative to its parent: its local translation
/// changes during the take by more than rounding (a thousandth of the
/// skeleton's median bone length). Bandai gives every joint position
/// channels; all hold constants except those of the hips, which carry the
/// body's translation even when the actor barely steps.
fn translates(motion: &Motion, joint: usize) -> bool {
    let skeleton = motion.skeleton();
    if !skeleton.joint(joint).has_position_channels() || motion.frame_count() == 0 {
        return false;
    }
    let mut lengths: Vec<f32> = skeleton
        .joints()
        .iter()
        .filter(|j| j.parent.is_some())
        .map(|j| j.offset.length())
        .filter(|&l| l > 0.0)
        .collect();
    lengths.sort_by(f32::total_cmp);
    let Some(&median) = lengths.get(lengths.len() / 2) else {
        return true;
    };
    let first = motion.local_translation(0, joint);
    (0..motion.frame_count())
        .any(|f| (motion.local_translation(f, joint) - first).length() > 1e-3 * median)
}

fn point_shown(point: usize, parents: &[Option<usize>], bones: &[bool]) -> bool {
    let has_bone_child = (0..parents.len()).any(|c| parents[c] == Some(point) && bones[c]);
    let has_child = parents.contains(&Some(point));
    bones[point] || has_bone_child || (parents[point].is_none() && !has_child)
}

/// The diagonal of the bounding box of the shown points of the first frame
/// (`positions` starts with it): about the figure's height for a standing
/// person, and its length for a lying one.
fn figure_extent(positions: &[Vec3], parents: &[Option<usize>], bones: &[bool]) -> f32 {
    let shown: Vec<Vec3> = (0..parents.len().min(positions.len()))
        .filter(|&p| point_shown(p, parents, bones))
        .map(|p| positions[p])
        .collect();
    bounding_box(&shown).map_or(0.0, |(lo, hi)| (hi - lo).length())
}

/// Metres per length unit of a human figure whose first frame spans
/// `extent` units (the diagonal of its bounding box, 1 to 2.5 m for an
/// adult): metres, the units of the CMU data converted to BVH (1/0.45 inch,
/// 5.64 cm: its ASF files say `length 0.45`; an adult spans 25 to 45 with
/// arms and legs apart),
/// centimetres (Bandai, and ASF as read by `mocap_core`) or millimetres.
/// Inches (60 to 100 for an adult) fall in the centimetre range and are
/// taken as centimetres: the figure is then drawn 2.5 times too small but
/// whole. An extent outside every range keeps the file's unit.
pub fn guess_metres_per_unit(extent: f32) -> f32 {
    match extent {
        e if (0.3..=4.0).contains(&e) => 1.0,
        e if (8.0..50.0).contains(&e) => 0.0254 / 0.45,
        e if (50.0..=400.0).contains(&e) => 0.01,
        e if (300.0..=4000.0).contains(&e) => 0.001,
        _ => 1.0,
    }
}

fn is_capture(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("jsonl"))
}

/// Reads a Kinect v2 capture written by `mocap-fuse` (JSON lines, 25 joints
/// in Kinect v2 order, metres, y up):
///
/// - a **fused** capture, one line per frame:
///   `{"t": s, "joints": [[x, y, z], ...], "confidence": [c, ...]}`; the
///   confidence of a joint is the sum of the confidences of the sensors
///   that saw it, shown as `min(c, 1)` (at least one fully trusted view is
///   green);
/// - a **sensor recording**, one line per frame per sensor:
///   `{"v": 1, "sensor": k, "seq": n, "t": s, "joints": [[x, y, z, state], ...]}`;
///   one motion per sensor, its confidence the tracking state (tracked 1,
///   inferred 0.5, not tracked 0).
///
/// Frames are put in time order and played at the median interval between
/// them.
pub fn read_capture(path: &Path) -> Result<Vec<ViewMotion>> {
    use mocap_core::bodymap::KINECT_V2_JOINTS;
    use std::collections::BTreeMap;

    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let at = |line: usize, message: String| Error::parse(path, line, 1, message);
    let joint_count = KINECT_V2_JOINTS.len();
    // Per stream (a sensor id, or None for fused frames): (time, points, confidence).
    type Frame = (f64, Vec<Vec3>, Vec<f32>);
    let mut streams: BTreeMap<Option<u64>, Vec<Frame>> = BTreeMap::new();
    for (index, line) in text.lines().enumerate() {
        let number = index + 1;
        if line.trim().is_empty() {
            continue;
        }
        let value: serde_json::Value = serde_json::from_str(line)
            .map_err(|e| at(number, format!("not a JSON object: {e}")))?;
        let time = value["t"]
            .as_f64()
            .filter(|t| t.is_finite())
            .ok_or_else(|| at(number, "expected a time `t` in seconds".to_string()))?;
        let sensor = match &value["sensor"] {
            serde_json::Value::Null => None,
            v => Some(
                v.as_u64()
                    .ok_or_else(|| at(number, "`sensor` must be a whole number".to_string()))?,
            ),
        };
        let joints = value["joints"]
            .as_array()
            .filter(|j| j.len() == joint_count)
            .ok_or_else(|| {
                at(
                    number,
                    format!("expected `joints`: {joint_count} Kinect v2 joints"),
                )
            })?;
        let width = if sensor.is_some() { 4 } else { 3 };
        let mut points = Vec::with_capacity(joint_count);
        let mut confidence = Vec::with_capacity(joint_count);
        for (j, joint) in joints.iter().enumerate() {
            let numbers: Vec<f64> = joint
                .as_array()
                .filter(|a| a.len() == width)
                .map(|a| a.iter().filter_map(|v| v.as_f64()).collect())
                .filter(|n: &Vec<f64>| n.len() == width && n.iter().all(|v| v.is_finite()))
                .ok_or_else(|| {
                    at(
                        number,
                        format!(
                            "joint {j} ({}): expected {}",
                            KINECT_V2_JOINTS[j].0,
                            if width == 4 {
                                "[x, y, z, state]"
                            } else {
                                "[x, y, z]"
                            }
                        ),
                    )
                })?;
            points.push(Vec3::new(
                numbers[0] as f32,
                numbers[1] as f32,
                numbers[2] as f32,
            ));
            if width == 4 {
                confidence.push(match numbers[3] as i64 {
                    2 => 1.0,
                    1 => 0.5,
                    _ => 0.0,
                });
            }
        }
        if sensor.is_none() {
            if let Some(c) = value["confidence"].as_array() {
                let values: Vec<f32> = c
                    .iter()
                    .filter_map(|v| v.as_f64())
                    .map(|v| v as f32)
                    .collect();
                if values.len() != joint_count || values.iter().any(|v| !v.is_finite()) {
                    return Err(at(
                        number,
                        format!("expected `confidence`: {joint_count} numbers"),
                    ));
                }
                confidence = values;
            }
        }
        streams
            .entry(sensor)
            .or_default()
            .push((time, points, confidence));
    }
    if streams.is_empty() {
        return Err(at(1, "no frame in this capture".to_string()));
    }
    let names: Vec<String> = KINECT_V2_JOINTS
        .iter()
        .map(|(n, _)| n.to_string())
        .collect();
    let parents: Vec<Option<usize>> = KINECT_V2_JOINTS.iter().map(|&(_, p)| p).collect();
    let stem = file_label(path);
    let mut motions = Vec::new();
    for (sensor, mut frames) in streams {
        frames.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut steps: Vec<f64> = frames
            .windows(2)
            .map(|w| w[1].0 - w[0].0)
            .filter(|d| *d > 0.0)
            .collect();
        steps.sort_by(f64::total_cmp);
        let frame_time = steps.get(steps.len() / 2).copied().unwrap_or(1.0 / 30.0);
        let has_confidence = frames.iter().all(|f| f.2.len() == joint_count);
        let positions: Vec<Vec3> = frames.iter().flat_map(|f| f.1.iter().copied()).collect();
        let label = match sensor {
            Some(k) => format!("{stem} sensor {k}"),
            None => stem.clone(),
        };
        let mut motion = ViewMotion::from_positions(
            label,
            names.clone(),
            parents.clone(),
            frame_time,
            positions,
            Some(1.0),
        )?
        .with_source(path.display().to_string());
        if has_confidence {
            motion = motion
                .with_confidence(frames.iter().flat_map(|f| f.2.iter().copied()).collect())?;
        }
        motions.push(motion);
    }
    Ok(motions)
}
