//! A glTF 2.0 file read as a take: the skeleton is the first skin's joints,
//! the motion one animation of them, resampled onto a uniform frame time.
//!
//! glTF poses a joint by its node's translation, rotation and scale under
//! its parent node; a take has offsets and channel values under its parent
//! joint, with no scale. So:
//! - a joint's parent is its nearest ancestor node that is a joint; a joint
//!   with none is a root. Nodes between (an armature above the roots, with
//!   the rotation and the 0.01 scale Mixamo and Blender exports have) are
//!   folded into the joint below them: their rotation into its rotation,
//!   their translation and scale into its offset and position channels;
//! - a uniform scale scales every offset below it; a non-uniform one, or a
//!   scale the animation changes, cannot be held and is refused;
//! - a joint's offset is its rest translation; its channel values are its
//!   whole local rotation (the rest rotation where the animation does not
//!   turn it) and, for joints the animation moves, its translation.
//!
//! Files this crate wrote carry a record ([`crate::record`]) that restores
//! the take's units, turn, channel layouts and end sites; other files are
//! read in metres with the root's channels `Xposition Yposition Zposition
//! Zrotation Xrotation Yrotation` and `Zrotation Xrotation Yrotation` below
//! it (with positions first on joints the animation moves).

use std::borrow::Cow;
use std::collections::{HashMap, HashSet};
use std::ops::{Add, Mul};
use std::path::Path;

use base64::Engine;
use gltf::animation::util::ReadOutputs;
use gltf::animation::Interpolation;
use mocap_core::rotation::{slerp, Quat, Vec3};
use mocap_core::{
    ops, Channel, Error, Joint, Motion, Result, Skeleton, FRAME_TIME_RANGE, MAX_VALUES,
};

use crate::record::{from_extras, AnimationRecord, SkeletonRecord};

/// The frame time of a take whose animation has a single key: glTF keeps
/// times, not a rate, and one key gives none.
pub const SINGLE_KEY_FRAME_TIME: f64 = 1.0 / 30.0;

/// How far a scale's components may be apart, or from the rest scale, as a
/// share of it, and still be one uniform, unmoving scale (exporters write
/// 0.99999994 for 1).
const SCALE_TOLERANCE: f32 = 1e-4;

/// How far an animated translation may stray from the rest translation, as
/// a share of it (plus this much absolutely), and still not move the joint:
/// exporters key every joint's translation, mostly at rest.
const STILL_TOLERANCE: f32 = 1e-5;

/// The BVH layout of a joint that moves, in files without our record.
const MOVING_CHANNELS: [Channel; 6] = [
    Channel::Xposition,
    Channel::Yposition,
    Channel::Zposition,
    Channel::Zrotation,
    Channel::Xrotation,
    Channel::Yrotation,
];

/// Reads the animation named `animation` (the first where `None`) of the
/// glTF file `path` (`.glb`, or `.gltf` with its buffers embedded or
/// beside it) as a take of its first skin's joints (module docs). Errors
/// name the file and what is missing: no skin, no such animation, an
/// animation that moves none of the skin's joints, a scale that cannot be
/// held, a buffer file that is not there, a damaged file.
pub fn read_gltf(path: &Path, animation: Option<&str>) -> Result<Motion> {
    let invalid = |why: String| Error::Invalid(format!("{}: {why}", path.display()));
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    let gltf = gltf::Gltf::from_slice(&bytes)
        .map_err(|e| invalid(format!("not a readable glTF 2.0 file: {e}")))?;
    let buffers = load_buffers(path, &gltf)?;
    let document = &gltf.document;

    let skin = document.skins().next().ok_or_else(|| {
        invalid("it has no skin (the skeleton is read from the first skin's joints)".into())
    })?;
    let clip = choose_animation(document, animation).map_err(invalid)?;
    let record: Option<SkeletonRecord> =
        from_extras(&document.as_json().asset.extras).map_err(invalid)?;
    let timing: Option<AnimationRecord> = from_extras(clip.extras()).map_err(invalid)?;

    let rig = Rig::new(document, &skin).map_err(invalid)?;
    let tracks = read_tracks(&clip, &buffers, &rig).map_err(invalid)?;
    let skeleton = skeleton(&rig, &tracks, record.as_ref()).map_err(invalid)?;
    let times = Timing::new(&tracks, timing, skeleton.channel_count()).map_err(invalid)?;

    let frames = times.frames;
    let values = vec![0.0; frames * skeleton.channel_count()];
    let mut motion = Motion::new(skeleton, times.frame_time, frames, values)
        .map_err(|e| invalid(e.to_string()))?;
    for f in 0..frames {
        let t = (times.start + f as f64 * times.frame_time) as f32;
        for (j, joint) in rig.joints.iter().enumerate() {
            let rotation = tracks[j]
                .rotation
                .as_ref()
                .map_or(joint.rest_rotation, |track| track.sample(t));
            let translation = tracks[j]
                .translation
                .as_ref()
                .map_or(joint.rest_translation, |track| track.sample(t));
            let (rotation, translation) = joint.local(rotation, translation);
            motion.set_local_rotation(f, j, rotation);
            motion.set_local_translation(f, j, translation);
        }
    }

    if let Some(record) = &record {
        if let Some(turn) = record.turned() {
            motion = ops::turn(&motion, turn.inverse())
                .map_err(|e| invalid(format!("undoing the turn to Y-up it records: {e}")))?;
        }
        let units = record.units_per_metre;
        if !(units.is_finite() && units > 0.0) {
            return Err(invalid(format!(
                "its record gives {units} units per metre, not a positive number"
            )));
        }
        if units != 1.0 {
            motion = ops::scale(&motion, units);
        }
    }
    Ok(motion)
}

/// The bytes of every buffer: the GLB's binary chunk, a base64 data URI,
/// or a file beside the glTF.
fn load_buffers<'a>(path: &Path, gltf: &'a gltf::Gltf) -> Result<Vec<Cow<'a, [u8]>>> {
    let invalid = |why: String| Error::Invalid(format!("{}: {why}", path.display()));
    let mut buffers = Vec::new();
    for buffer in gltf.document.buffers() {
        let i = buffer.index();
        let data: Cow<[u8]> = match buffer.source() {
            gltf::buffer::Source::Bin => match gltf.blob.as_deref() {
                Some(blob) => Cow::Borrowed(blob),
                None => {
                    return Err(invalid(format!(
                        "buffer {i} is the GLB's binary chunk, which the file lacks"
                    )))
                }
            },
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => Cow::Owned(
                decode_data_uri(uri).map_err(|why| invalid(format!("buffer {i}: {why}")))?,
            ),
            gltf::buffer::Source::Uri(uri) => {
                let name = percent_encoding::percent_decode_str(uri).decode_utf8_lossy();
                let file = path.parent().unwrap_or(Path::new("")).join(name.as_ref());
                Cow::Owned(std::fs::read(&file).map_err(|e| {
                    invalid(format!(
                        "its buffer file {} cannot be read ({e})",
                        file.display()
                    ))
                })?)
            }
        };
        if data.len() < buffer.length() {
            return Err(invalid(format!(
                "buffer {i} holds {} bytes where the file says {} (truncated?)",
                data.len(),
                buffer.length()
            )));
        }
        buffers.push(data);
    }
    Ok(buffers)
}

/// The bytes of a `data:...;base64,...` URI.
fn decode_data_uri(uri: &str) -> std::result::Result<Vec<u8>, String> {
    let (header, data) = uri
        .split_once(',')
        .ok_or("a data URI without a comma before its data")?;
    if !header.ends_with(";base64") {
        return Err(format!("a data URI that is not base64 ({header})"));
    }
    base64::engine::general_purpose::STANDARD
        .decode(data)
        .map_err(|e| format!("a data URI that is not valid base64 ({e})"))
}

/// The animation named `name`, or the first.
fn choose_animation<'a>(
    document: &'a gltf::Document,
    name: Option<&str>,
) -> std::result::Result<gltf::Animation<'a>, String> {
    let mut animations = document.animations();
    match name {
        None => animations
            .next()
            .ok_or_else(|| "it has no animation (a take is read from the first one)".to_string()),
        Some(name) => {
            let found = animations.clone().find(|a| a.name() == Some(name));
            found.ok_or_else(|| {
                let names: Vec<String> = animations
                    .map(|a| match a.name() {
                        Some(n) => format!("{n:?}"),
                        None => format!("#{} (unnamed)", a.index()),
                    })
                    .collect();
                match names.is_empty() {
                    true => format!("it has no animation named {name:?} (it has none)"),
                    false => format!(
                        "it has no animation named {name:?} (it has {})",
                        names.join(", ")
                    ),
                }
            })
        }
    }
}

/// A uniform, unmoving translation, rotation and scale: what nodes above a
/// joint may be, folded into it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Similarity {
    translation: Vec3,
    rotation: Quat,
    scale: f32,
}

impl Similarity {
    const IDENTITY: Similarity = Similarity {
        translation: Vec3::ZERO,
        rotation: Quat::IDENTITY,
        scale: 1.0,
    };

    /// `self` then `inner` below it.
    fn then(self, inner: Similarity) -> Similarity {
        Similarity {
            translation: self.translation + self.rotation * (self.scale * inner.translation),
            rotation: (self.rotation * inner.rotation).normalize(),
            scale: self.scale * inner.scale,
        }
    }
}

/// A node's rest transform, or why a skeleton cannot hold it.
fn rest_of(node: &gltf::Node) -> std::result::Result<Similarity, String> {
    let (translation, rotation, scale) = node.transform().decomposed();
    let scale = uniform(scale).ok_or_else(|| {
        format!(
            "node {} has the scale {scale:?}, which is not uniform (a skeleton's bones cannot \
             stretch one way only)",
            node_name(node)
        )
    })?;
    Ok(Similarity {
        translation: Vec3::from_array(translation),
        rotation: Quat::from_array(rotation).normalize(),
        scale,
    })
}

/// The one value of a uniform, positive scale.
fn uniform(scale: [f32; 3]) -> Option<f32> {
    let [x, y, z] = scale;
    let (min, max) = (x.min(y).min(z), x.max(y).max(z));
    (min > 0.0 && max.is_finite() && max - min <= SCALE_TOLERANCE * max)
        .then_some((x + y + z) / 3.0)
}

fn node_name(node: &gltf::Node) -> String {
    match node.name() {
        Some(name) => format!("{name:?}"),
        None => format!("#{}", node.index()),
    }
}

/// One skin joint as a joint of the take.
#[derive(Debug, Clone)]
struct RigJoint {
    name: String,
    parent: Option<usize>,
    /// The nodes between the parent joint (or the scene) and this joint.
    between: Similarity,
    /// The uniform scale of the parent joint's frame (1 for a root).
    parent_scale: f32,
    rest_translation: Vec3,
    rest_rotation: Quat,
    rest_scale: f32,
    /// Leaf nodes below this joint that are not joints (exporters' bone
    /// ends), in this joint's frame.
    end_sites: Vec<Vec3>,
}

impl RigJoint {
    /// The take's local rotation and translation of the joint posed with
    /// its node's `rotation` and `translation`: what lies between folded in,
    /// scales applied.
    fn local(&self, rotation: Quat, translation: Vec3) -> (Quat, Vec3) {
        let posed = self.between.then(Similarity {
            translation,
            rotation,
            scale: 1.0,
        });
        (posed.rotation, self.parent_scale * posed.translation)
    }

    /// The uniform scale of this joint's own frame.
    fn scale(&self) -> f32 {
        self.parent_scale * self.between.scale * self.rest_scale
    }
}

/// The skin's joints in an order with parents first, and the nodes above
/// them.
struct Rig {
    joints: Vec<RigJoint>,
    /// Joint index of each joint node.
    joint_of_node: HashMap<usize, usize>,
    /// Nodes above a joint that are not joints, with their rest transform:
    /// the animation may not move them.
    above: HashMap<usize, Similarity>,
}

impl Rig {
    fn new(document: &gltf::Document, skin: &gltf::Skin) -> std::result::Result<Rig, String> {
        let nodes: Vec<gltf::Node> = document.nodes().collect();
        let mut parent_of = vec![None; nodes.len()];
        for node in &nodes {
            for child in node.children() {
                parent_of[child.index()] = Some(node.index());
            }
        }
        let skin_nodes: Vec<usize> = skin.joints().map(|n| n.index()).collect();
        if skin_nodes.is_empty() {
            return Err("its first skin has no joints".into());
        }
        let is_joint: HashSet<usize> = skin_nodes.iter().copied().collect();
        // Each joint node's nearest joint ancestor, and the nodes between.
        let mut parent_node = HashMap::new();
        let mut between_nodes = HashMap::new();
        for &node in &skin_nodes {
            let mut chain = Vec::new();
            let mut at = parent_of[node];
            while let Some(n) = at.filter(|n| !is_joint.contains(n)) {
                chain.push(n);
                at = parent_of[n];
            }
            chain.reverse();
            parent_node.insert(node, at);
            between_nodes.insert(node, chain);
        }
        let order = parents_first(&skin_nodes, &parent_node);
        let joint_of_node: HashMap<usize, usize> =
            order.iter().enumerate().map(|(j, &n)| (n, j)).collect();

        let mut joints: Vec<RigJoint> = Vec::with_capacity(order.len());
        let mut above = HashMap::new();
        for &n in &order {
            let node = &nodes[n];
            let mut between = Similarity::IDENTITY;
            for &b in &between_nodes[&n] {
                let rest = rest_of(&nodes[b])?;
                above.insert(b, rest);
                between = between.then(rest);
            }
            let rest = rest_of(node)?;
            let parent = parent_node[&n].map(|p| joint_of_node[&p]);
            let end_sites = node
                .children()
                .filter(|c| !is_joint.contains(&c.index()))
                .filter(|c| c.children().next().is_none() && c.mesh().is_none())
                .map(|c| Vec3::from_array(c.transform().decomposed().0))
                .collect();
            let joint = RigJoint {
                name: node
                    .name()
                    .map_or_else(|| format!("joint{n}"), str::to_string),
                parent,
                between,
                parent_scale: parent.map_or(1.0, |p: usize| joints[p].scale()),
                rest_translation: rest.translation,
                rest_rotation: rest.rotation,
                rest_scale: rest.scale,
                end_sites,
            };
            joints.push(joint);
        }
        // End sites hang in the joint's own (scaled) frame.
        for joint in &mut joints {
            let scale = joint.scale();
            for end in &mut joint.end_sites {
                *end *= scale;
            }
        }
        Ok(Rig {
            joints,
            joint_of_node,
            above,
        })
    }
}

/// The skin's order where every joint comes after its parent joint (most
/// exporters write it so, and so does this crate), else the joints depth
/// first from each root, children in the skin's order.
fn parents_first(skin_nodes: &[usize], parent_node: &HashMap<usize, Option<usize>>) -> Vec<usize> {
    let position: HashMap<usize, usize> = skin_nodes
        .iter()
        .enumerate()
        .map(|(i, &n)| (n, i))
        .collect();
    let ordered = skin_nodes
        .iter()
        .enumerate()
        .all(|(i, n)| parent_node[n].is_none_or(|p| position[&p] < i));
    if ordered {
        return skin_nodes.to_vec();
    }
    fn visit(
        n: usize,
        skin_nodes: &[usize],
        parent_node: &HashMap<usize, Option<usize>>,
        out: &mut Vec<usize>,
    ) {
        out.push(n);
        for &c in skin_nodes {
            if parent_node[&c] == Some(n) {
                visit(c, skin_nodes, parent_node, out);
            }
        }
    }
    let mut out = Vec::with_capacity(skin_nodes.len());
    for &n in skin_nodes.iter().filter(|n| parent_node[n].is_none()) {
        visit(n, skin_nodes, parent_node, &mut out);
    }
    out
}

/// Values an animation can interpolate.
trait Key: Copy + Add<Output = Self> + Mul<f32, Output = Self> {
    fn lerp(self, other: Self, t: f32) -> Self;
    fn normalized(self) -> Self;
}

impl Key for Vec3 {
    fn lerp(self, other: Vec3, t: f32) -> Vec3 {
        Vec3::lerp(self, other, t)
    }
    fn normalized(self) -> Vec3 {
        self
    }
}

impl Key for Quat {
    fn lerp(self, other: Quat, t: f32) -> Quat {
        slerp(self, other, t)
    }
    fn normalized(self) -> Quat {
        self.normalize()
    }
}

/// One animated property of one node: key times and values (for
/// CUBICSPLINE, three a key: in-tangent, value, out-tangent).
#[derive(Debug, Clone)]
struct Track<T> {
    times: Vec<f32>,
    values: Vec<T>,
    interpolation: Interpolation,
}

impl<T: Key> Track<T> {
    fn value(&self, key: usize) -> T {
        match self.interpolation {
            Interpolation::CubicSpline => self.values[3 * key + 1],
            _ => self.values[key],
        }
    }

    /// The value at time `t`, as the glTF specification interpolates it;
    /// held at the first and last keys outside them.
    fn sample(&self, t: f32) -> T {
        let last = self.times.len() - 1;
        if t <= self.times[0] {
            return self.value(0);
        }
        if t >= self.times[last] {
            return self.value(last);
        }
        let i = self.times.partition_point(|&k| k <= t) - 1;
        let span = self.times[i + 1] - self.times[i];
        let u = (t - self.times[i]) / span;
        match self.interpolation {
            Interpolation::Step => self.value(i),
            Interpolation::Linear => self.value(i).lerp(self.value(i + 1), u),
            Interpolation::CubicSpline => {
                // The cubic Hermite spline of the specification's appendix.
                let (u2, u3) = (u * u, u * u * u);
                let out_tangent = self.values[3 * i + 2] * span;
                let in_tangent = self.values[3 * (i + 1)] * span;
                (self.value(i) * (2.0 * u3 - 3.0 * u2 + 1.0)
                    + out_tangent * (u3 - 2.0 * u2 + u)
                    + self.value(i + 1) * (-2.0 * u3 + 3.0 * u2)
                    + in_tangent * (u3 - u2))
                    .normalized()
            }
        }
    }

    /// The values at the keys (tangents left out).
    fn key_values(&self) -> impl Iterator<Item = T> + '_ {
        (0..self.times.len()).map(|k| self.value(k))
    }
}

/// A joint's rotation and translation tracks, where the animation has them.
#[derive(Debug, Clone, Default)]
struct JointTracks {
    rotation: Option<Track<Quat>>,
    translation: Option<Track<Vec3>>,
}

/// The tracks of `clip` for each joint of `rig`; refuses animations of the
/// nodes above the joints and of scale.
fn read_tracks(
    clip: &gltf::Animation,
    buffers: &[Cow<[u8]>],
    rig: &Rig,
) -> std::result::Result<Vec<JointTracks>, String> {
    let mut tracks = vec![JointTracks::default(); rig.joints.len()];
    let mut any = false;
    for channel in clip.channels() {
        let node = channel.target().node();
        let joint = rig.joint_of_node.get(&node.index()).copied();
        let above = rig.above.get(&node.index());
        if joint.is_none() && above.is_none() {
            // A prop, a camera, the mesh: not the skeleton.
            continue;
        }
        let what = format!("channel {} (node {})", channel.index(), node_name(&node));
        let reader = channel.reader(|b| buffers.get(b.index()).map(|d| &d[..]));
        let times: Vec<f32> = reader
            .read_inputs()
            .ok_or_else(|| format!("{what}: its key times cannot be read"))?
            .collect();
        if times.is_empty() || times.iter().any(|t| !t.is_finite()) {
            return Err(format!(
                "{what}: its key times are empty or not finite numbers"
            ));
        }
        if times.windows(2).any(|w| w[1] < w[0]) {
            return Err(format!("{what}: its key times go backwards"));
        }
        let interpolation = channel.sampler().interpolation();
        let per_key = if interpolation == Interpolation::CubicSpline {
            3
        } else {
            1
        };
        let outputs = reader
            .read_outputs()
            .ok_or_else(|| format!("{what}: its values cannot be read"))?;
        let check = |values: usize| {
            if values == per_key * times.len() {
                Ok(())
            } else {
                Err(format!(
                    "{what}: {} keys but {values} values ({per_key} a key expected)",
                    times.len()
                ))
            }
        };
        match outputs {
            ReadOutputs::Translations(values) => {
                let values: Vec<Vec3> = values.map(Vec3::from_array).collect();
                check(values.len())?;
                let track = Track {
                    times,
                    values,
                    interpolation,
                };
                match joint {
                    Some(j) => tracks[j].translation = Some(track),
                    None => still(&what, track.key_values(), above.unwrap().translation)?,
                }
            }
            ReadOutputs::Rotations(values) => {
                let values: Vec<Quat> = values
                    .into_f32()
                    .map(|q| Quat::from_array(q).normalize())
                    .collect();
                check(values.len())?;
                if values.iter().any(|q| !q.is_finite()) {
                    return Err(format!(
                        "{what}: a rotation that is not a finite quaternion"
                    ));
                }
                let track = Track {
                    times,
                    values,
                    interpolation,
                };
                match joint {
                    Some(j) => tracks[j].rotation = Some(track),
                    None => {
                        let rest = above.unwrap().rotation;
                        if track.key_values().any(|q| q.dot(rest).abs() < 1.0 - 1e-6) {
                            return Err(format!(
                                "{what}: the animation turns this node above the skin's joints; \
                                 only the joints' own animation is read"
                            ));
                        }
                    }
                }
            }
            ReadOutputs::Scales(values) => {
                let values: Vec<Vec3> = values.map(Vec3::from_array).collect();
                check(values.len())?;
                let track = Track {
                    times,
                    values,
                    interpolation,
                };
                let rest = match joint {
                    Some(j) => rig.joints[j].rest_scale,
                    None => above.unwrap().scale,
                };
                if let Some(s) = track
                    .key_values()
                    .find(|s| (*s - Vec3::splat(rest)).abs().max_element() > SCALE_TOLERANCE * rest)
                {
                    return Err(format!(
                        "{what}: the animation scales it (to {s} from {rest}); a take's bones \
                         keep their lengths, so animated scale is not read"
                    ));
                }
                continue;
            }
            ReadOutputs::MorphTargetWeights(_) => continue,
        }
        any |= joint.is_some();
    }
    if !any {
        return Err(format!(
            "animation {} moves none of the skin's joints (no rotation or translation channel \
             targets a joint)",
            match clip.name() {
                Some(n) => format!("{n:?}"),
                None => format!("#{}", clip.index()),
            }
        ));
    }
    Ok(tracks)
}

/// Refuses a translation track of a node above the joints that moves it.
fn still(
    what: &str,
    mut values: impl Iterator<Item = Vec3>,
    rest: Vec3,
) -> std::result::Result<(), String> {
    if values.any(|v| moved(v, rest)) {
        return Err(format!(
            "{what}: the animation moves this node above the skin's joints; only the joints' \
             own animation is read"
        ));
    }
    Ok(())
}

fn moved(v: Vec3, rest: Vec3) -> bool {
    (v - rest).abs().max_element() > STILL_TOLERANCE * (1.0 + rest.abs().max_element())
}

/// The take's skeleton: joints, offsets, channels and end sites, from the
/// record where the file has one.
fn skeleton(
    rig: &Rig,
    tracks: &[JointTracks],
    record: Option<&SkeletonRecord>,
) -> std::result::Result<Skeleton, String> {
    let mut joints = Vec::with_capacity(rig.joints.len());
    for (j, rig_joint) in rig.joints.iter().enumerate() {
        let (_, offset) = rig_joint.local(rig_joint.rest_rotation, rig_joint.rest_translation);
        let mut joint = Joint::new(rig_joint.name.clone(), rig_joint.parent, offset);
        match record.and_then(|r| r.joint(&rig_joint.name)) {
            Some(recorded) => {
                joint.channels = recorded.channels().map_err(|name| {
                    format!(
                        "its record gives joint {:?} the channel {name:?}, which is not a BVH channel",
                        rig_joint.name
                    )
                })?;
                joint.end_sites = recorded.end_sites();
            }
            None => {
                let moves = rig_joint.parent.is_none()
                    || tracks[j].translation.as_ref().is_some_and(|t| {
                        t.key_values().any(|v| moved(v, rig_joint.rest_translation))
                    });
                joint.channels = if moves {
                    MOVING_CHANNELS.to_vec()
                } else {
                    MOVING_CHANNELS[3..].to_vec()
                };
                joint.end_sites = rig_joint.end_sites.clone();
            }
        }
        joints.push(joint);
    }
    Skeleton::new(joints).map_err(|e| format!("its skin's joints do not form a skeleton: {e}"))
}

/// The frames the take samples the animation at.
#[derive(Debug, Clone, Copy)]
struct Timing {
    /// The first key's time, in seconds: frame 0.
    start: f64,
    frame_time: f64,
    frames: usize,
}

impl Timing {
    /// From the first to the last key of every joint track, a frame every
    /// recorded frame time, else every median step between the keys of the
    /// track with the most keys.
    fn new(
        tracks: &[JointTracks],
        record: Option<AnimationRecord>,
        channels: usize,
    ) -> std::result::Result<Timing, String> {
        let all_times = tracks.iter().flat_map(|t| {
            let rotation = t.rotation.as_ref().map(|t| &t.times);
            let translation = t.translation.as_ref().map(|t| &t.times);
            rotation.into_iter().chain(translation)
        });
        let (mut start, mut end) = (f32::INFINITY, f32::NEG_INFINITY);
        let mut densest: &[f32] = &[];
        for times in all_times {
            start = start.min(times[0]);
            end = end.max(times[times.len() - 1]);
            if times.len() > densest.len() {
                densest = times;
            }
        }
        let frame_time = match record {
            Some(record) => record.frame_time,
            None => {
                let mut steps: Vec<f32> = densest
                    .windows(2)
                    .map(|w| w[1] - w[0])
                    .filter(|s| *s > 0.0)
                    .collect();
                steps.sort_by(f32::total_cmp);
                steps
                    .get(steps.len() / 2)
                    .map_or(SINGLE_KEY_FRAME_TIME, |&s| f64::from(s))
            }
        };
        if !FRAME_TIME_RANGE.contains(&frame_time) {
            return Err(format!(
                "its keys are {frame_time} s apart, not a frame time ({} to {} s)",
                FRAME_TIME_RANGE.start(),
                FRAME_TIME_RANGE.end()
            ));
        }
        let span = f64::from(end) - f64::from(start);
        let frames = (span / frame_time).round() as usize + 1;
        if frames.saturating_mul(channels.max(1)) > MAX_VALUES {
            return Err(format!(
                "its animation of {span:.1} s at a frame every {frame_time} s is {frames} frames, \
                 more than a take may hold"
            ));
        }
        Ok(Timing {
            start: f64::from(start),
            frame_time,
            frames,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn track<T: Key>(values: Vec<T>, interpolation: Interpolation) -> Track<T> {
        let keys = if interpolation == Interpolation::CubicSpline {
            values.len() / 3
        } else {
            values.len()
        };
        Track {
            times: (0..keys).map(|k| k as f32).collect(),
            values,
            interpolation,
        }
    }

    #[test]
    fn tracks_interpolate_as_the_specification_says() {
        let (a, b) = (Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0));
        let linear = track(vec![a, b], Interpolation::Linear);
        assert_eq!(linear.sample(0.25), Vec3::new(0.5, 0.0, 0.0));
        assert_eq!(linear.sample(-1.0), a);
        assert_eq!(linear.sample(5.0), b);
        let step = track(vec![a, b], Interpolation::Step);
        assert_eq!(step.sample(0.99), a);
        assert_eq!(step.sample(1.0), b);
        // Zero tangents: the smoothstep between the values.
        let cubic = track(vec![a, a, a, a, b, a], Interpolation::CubicSpline);
        assert!((cubic.sample(0.5) - Vec3::new(1.0, 0.0, 0.0)).length() < 1e-6);
        assert!((cubic.sample(0.25).x - 2.0 * (3.0 * 0.0625 - 2.0 * 0.015625)).abs() < 1e-6);
        // Rotations: slerp, the short way.
        let half = Quat::from_rotation_y(1.0);
        let turn = track(
            vec![Quat::IDENTITY, -Quat::from_rotation_y(2.0)],
            Interpolation::Linear,
        );
        assert!(turn.sample(0.5).angle_between(half) < 1e-5);
    }

    #[test]
    fn similarities_compose_as_matrices_do() {
        let outer = Similarity {
            translation: Vec3::new(1.0, 2.0, 3.0),
            rotation: Quat::from_rotation_x(-1.2),
            scale: 0.01,
        };
        let inner = Similarity {
            translation: Vec3::new(-4.0, 50.0, 6.0),
            rotation: Quat::from_rotation_z(0.3),
            scale: 2.0,
        };
        let matrix = |s: Similarity| {
            glam::Mat4::from_scale_rotation_translation(
                Vec3::splat(s.scale),
                s.rotation,
                s.translation,
            )
        };
        let composed = matrix(outer.then(inner));
        let product = matrix(outer) * matrix(inner);
        assert!(composed.abs_diff_eq(product, 1e-5), "{composed} {product}");
    }

    #[test]
    fn data_uris_decode_and_other_uris_are_refused() {
        assert_eq!(
            decode_data_uri("data:application/octet-stream;base64,AAEC").unwrap(),
            [0, 1, 2]
        );
        assert!(decode_data_uri("data:text/plain,hello")
            .unwrap_err()
            .contains("not base64"));
    }
}
