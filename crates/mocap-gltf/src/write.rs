//! A take written as glTF 2.0: the skeleton as a skin whose joints are
//! nodes (rest offsets as their translations, no rest rotation, as a BVH
//! rest pose), one animation sampled at the take's frames, and a simple
//! body ([`crate::mesh`]) bound to it; in metres, +Y up. `.glb` is the
//! binary container; `.gltf` is JSON with the buffer inside it as a base64
//! data URI, so that either is one file.

use std::borrow::Cow;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

use base64::Engine;
use glam::Mat4;
use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;
use mocap_core::io::atomic::AtomicFile;
use mocap_core::rotation::{Quat, Vec3};
use mocap_core::{ops, Error, Motion, Result};

use crate::mesh::{body_mesh, BodyMesh};
use crate::record::{to_extras, AnimationRecord, SkeletonRecord};
use crate::units::{axis_name, take_units, turn_to_y_up};

/// The two spellings of glTF, by the file's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Container {
    /// `.glb`: JSON and binary chunks.
    Binary,
    /// `.gltf`: JSON, the buffer as a data URI.
    Json,
}

/// Writes `motion` to `path` (`.glb` or `.gltf`) and returns what was
/// changed on the way: the lengths scaled to metres (and why: the unit the
/// take's rest height reads as) and a turn to +Y up where the take stands
/// along another axis. Reading the file back ([`crate::read_gltf`]) undoes
/// both, from what the file records in its `extras`.
///
/// A take that glTF cannot hold is refused before anything is written:
/// no frames, no joints, values that are not finite. The file is written
/// atomically ([`AtomicFile`]): on an error, a file already at `path` is
/// left as it was.
pub fn write_gltf(path: &Path, motion: &Motion) -> Result<Vec<String>> {
    let container = container(path)?;
    check_expressible(path, motion)?;
    let mut notes = Vec::new();

    let units = take_units(motion.skeleton());
    notes.push(units.note());
    let factor = units.metres_per_unit();
    let scaled = (factor != 1.0).then(|| ops::scale(motion, factor));
    let motion = scaled.as_ref().unwrap_or(motion);

    let mut turned = None;
    let turned_motion = match turn_to_y_up(motion) {
        None => None,
        Some((up, turn)) => match ops::turn(motion, turn) {
            Ok(upright) => {
                notes.push(format!(
                    "turned Y-up: the take's up axis reads as {} (the head above the pelvis)",
                    axis_name(up)
                ));
                turned = Some(turn);
                Some(upright)
            }
            Err(e) => {
                notes.push(format!(
                    "not turned Y-up, though the take's up axis reads as {}: {e}",
                    axis_name(up)
                ));
                None
            }
        },
    };
    let motion = turned_motion.as_ref().unwrap_or(motion);

    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "take".to_string());
    let record = SkeletonRecord::new(motion.skeleton(), 1.0 / factor, turned);
    let height = units.rest_height * factor;
    let (mut root, bin) = build(motion, &record, height, &name);

    let mut file = AtomicFile::create(path)?;
    let written = match container {
        Container::Binary => {
            let json = json::serialize::to_vec(&root).map_err(|e| Error::io(path, e.into()))?;
            let glb = gltf::binary::Glb {
                header: gltf::binary::Header {
                    magic: *b"glTF",
                    version: 2,
                    // `to_writer` counts the length itself.
                    length: 0,
                },
                json: Cow::Owned(json),
                bin: Some(Cow::Owned(bin)),
            };
            glb.to_writer(&mut file)
                .map_err(|e| Error::io(path, std::io::Error::other(e.to_string())))
        }
        Container::Json => {
            let data = base64::engine::general_purpose::STANDARD.encode(&bin);
            root.buffers[0].uri = Some(format!("data:application/octet-stream;base64,{data}"));
            json::serialize::to_writer_pretty(&mut file, &root)
                .map_err(|e| Error::io(path, e.into()))
                .and_then(|()| file.write_all(b"\n").map_err(|e| Error::io(path, e)))
        }
    };
    written?;
    file.commit()?;
    Ok(notes)
}

fn container(path: &Path) -> Result<Container> {
    let extension = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    match extension.as_deref() {
        Some("glb") => Ok(Container::Binary),
        Some("gltf") => Ok(Container::Json),
        _ => Err(Error::Invalid(format!(
            "{}: a glTF file name ends in .glb (binary) or .gltf (JSON)",
            path.display()
        ))),
    }
}

/// Refuses, naming the file and the first fault, a take glTF cannot hold.
fn check_expressible(path: &Path, motion: &Motion) -> Result<()> {
    let refuse = |why: String| {
        Err(Error::Invalid(format!(
            "{}: cannot write this take as glTF: {why}",
            path.display()
        )))
    };
    let skeleton = motion.skeleton();
    if skeleton.joint_count() == 0 {
        return refuse("it has no joints".into());
    }
    if skeleton.joint_count() > usize::from(u16::MAX) {
        return refuse(format!(
            "it has {} joints; glTF's joint indices here are 16-bit (at most {})",
            skeleton.joint_count(),
            u16::MAX
        ));
    }
    if motion.frame_count() == 0 {
        return refuse("it has no frames (an animation needs at least one key)".into());
    }
    for joint in skeleton.joints() {
        let finite = |v: &Vec3| v.is_finite();
        if !finite(&joint.offset) || !joint.end_sites.iter().all(finite) {
            return refuse(format!(
                "joint {:?} has an offset or end site that is not a finite number",
                joint.name
            ));
        }
    }
    let per_frame = skeleton.channel_count();
    if let Some(at) = motion.values().iter().position(|v| !v.is_finite()) {
        let (frame, column) = (at / per_frame, at % per_frame);
        let joint = (0..skeleton.joint_count())
            .rev()
            .find(|&j| skeleton.channel_start(j) <= column)
            .expect("column 0 is the first joint's");
        let channel = skeleton.joint(joint).channels[column - skeleton.channel_start(joint)];
        return refuse(format!(
            "frame {frame}, joint {:?}, {} is {} (not a finite number)",
            skeleton.joint(joint).name,
            channel.name(),
            motion.values()[at]
        ));
    }
    // Key times, rotations and translations: 8 floats a joint a frame at
    // most; a GLB's length is a 32-bit number.
    let bytes = motion.frame_count() as u64 * (skeleton.joint_count() as u64 * 8 + 1) * 4;
    if bytes > u64::from(u32::MAX) {
        return refuse(format!(
            "its animation would take {bytes} bytes, more than glTF's 4 GiB; trim it (--frames)"
        ));
    }
    Ok(())
}

/// The glTF document and its one binary buffer.
fn build(
    motion: &Motion,
    record: &SkeletonRecord,
    height: f32,
    name: &str,
) -> (json::Root, Vec<u8>) {
    let skeleton = motion.skeleton();
    let mut doc = Document::default();
    doc.root.asset.generator = Some(format!("mocap-gltf {}", env!("CARGO_PKG_VERSION")));
    doc.root.asset.extras = to_extras(record);

    // Joint j is node j: the skin's order is the skeleton's.
    let mut rest = Vec::with_capacity(skeleton.joint_count());
    for (j, joint) in skeleton.joints().iter().enumerate() {
        rest.push(joint.parent.map_or(Vec3::ZERO, |p| rest[p]) + joint.offset);
        let children: Vec<json::Index<json::Node>> = skeleton
            .children(j)
            .map(|c| json::Index::new(c as u32))
            .collect();
        doc.root.push(json::Node {
            name: Some(joint.name.clone()),
            translation: (joint.offset != Vec3::ZERO).then(|| joint.offset.to_array()),
            children: (!children.is_empty()).then_some(children),
            ..Default::default()
        });
    }
    let roots: Vec<json::Index<json::Node>> = (0..skeleton.joint_count())
        .filter(|&j| skeleton.joint(j).parent.is_none())
        .map(|j| json::Index::new(j as u32))
        .collect();

    // The bind pose is the rest pose: each joint at its global rest
    // position with no rotation.
    let inverse_binds: Vec<f32> = rest
        .iter()
        .flat_map(|&at| Mat4::from_translation(-at).to_cols_array())
        .collect();
    let inverse_binds = doc.floats(&inverse_binds, json::accessor::Type::Mat4, None, false);
    let skin = doc.root.push(json::Skin {
        name: Some(name.to_string()),
        inverse_bind_matrices: Some(inverse_binds),
        joints: (0..skeleton.joint_count())
            .map(|j| json::Index::new(j as u32))
            .collect(),
        skeleton: roots.first().copied(),
        extensions: None,
        extras: None,
    });

    let mut scene_nodes = roots;
    let body = body_mesh(skeleton, &rest, &moving_joints(motion), height);
    if !body.indices.is_empty() {
        let mesh = doc.mesh(&body);
        scene_nodes.push(doc.root.push(json::Node {
            name: Some("body".to_string()),
            mesh: Some(mesh),
            skin: Some(skin),
            ..Default::default()
        }));
    }
    let scene = doc.root.push(json::Scene {
        name: Some(name.to_string()),
        nodes: scene_nodes,
        extensions: None,
        extras: None,
    });
    doc.root.scene = Some(scene);

    doc.animation(motion, name);
    doc.finish()
}

/// Whether each joint's position channels carry it away from its offset
/// during the take (by more than a tenth of the offset and a millimetre):
/// Bandai keys every joint's position, but only the hips move.
fn moving_joints(motion: &Motion) -> Vec<bool> {
    let skeleton = motion.skeleton();
    (0..skeleton.joint_count())
        .map(|j| {
            let offset = skeleton.joint(j).offset;
            let reach = 0.1 * offset.length() + 0.001;
            skeleton.joint(j).has_position_channels()
                && (0..motion.frame_count())
                    .any(|f| (motion.local_translation(f, j) - offset).length() > reach)
        })
        .collect()
}

/// The document being built and the bytes of its one buffer.
#[derive(Default)]
struct Document {
    root: json::Root,
    bin: Vec<u8>,
}

impl Document {
    /// A buffer view of `bytes`, aligned to 4 bytes as accessors of every
    /// component type need.
    fn view(
        &mut self,
        bytes: Vec<u8>,
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::buffer::View> {
        let offset = self.bin.len();
        let length = bytes.len();
        self.bin.extend(bytes);
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(length),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: None,
        })
    }

    fn accessor(
        &mut self,
        view: json::Index<json::buffer::View>,
        count: usize,
        component: json::accessor::ComponentType,
        type_: json::accessor::Type,
        bounds: Option<(Vec<f32>, Vec<f32>)>,
    ) -> json::Index<json::Accessor> {
        let (min, max) = bounds.map_or((None, None), |(min, max)| {
            (Some(json::Value::from(min)), Some(json::Value::from(max)))
        });
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(count),
            component_type: Valid(json::accessor::GenericComponentType(component)),
            type_: Valid(type_),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
            extensions: None,
            extras: None,
        })
    }

    /// An accessor of floats, `type_`'s number of components an element;
    /// with each component's bounds where `bounds` (POSITION and animation
    /// inputs must have them).
    fn floats(
        &mut self,
        data: &[f32],
        type_: json::accessor::Type,
        target: Option<json::buffer::Target>,
        bounds: bool,
    ) -> json::Index<json::Accessor> {
        let width = type_.multiplicity();
        let bounds = bounds.then(|| {
            let mut min = vec![f32::INFINITY; width];
            let mut max = vec![f32::NEG_INFINITY; width];
            for element in data.chunks_exact(width) {
                for (k, &v) in element.iter().enumerate() {
                    min[k] = min[k].min(v);
                    max[k] = max[k].max(v);
                }
            }
            (min, max)
        });
        let bytes = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(bytes, target);
        let component = json::accessor::ComponentType::F32;
        self.accessor(view, data.len() / width, component, type_, bounds)
    }

    /// The body: one primitive, skinned, with one grey material.
    fn mesh(&mut self, body: &BodyMesh) -> json::Index<json::Mesh> {
        use json::accessor::{ComponentType, Type};
        use json::buffer::Target::{ArrayBuffer, ElementArrayBuffer};
        use json::mesh::Semantic;
        let flat = |v: &[[f32; 3]]| v.iter().flatten().copied().collect::<Vec<f32>>();
        let positions = self.floats(&flat(&body.positions), Type::Vec3, Some(ArrayBuffer), true);
        let normals = self.floats(&flat(&body.normals), Type::Vec3, Some(ArrayBuffer), false);
        let weights: Vec<f32> = body.weights.iter().flatten().copied().collect();
        let weights = self.floats(&weights, Type::Vec4, Some(ArrayBuffer), false);
        let joints = body
            .joints
            .iter()
            .flatten()
            .flat_map(|j| j.to_le_bytes())
            .collect();
        let view = self.view(joints, Some(ArrayBuffer));
        let joints = self.accessor(
            view,
            body.joints.len(),
            ComponentType::U16,
            Type::Vec4,
            None,
        );
        let indices = body.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = self.view(indices, Some(ElementArrayBuffer));
        let indices = self.accessor(
            view,
            body.indices.len(),
            ComponentType::U32,
            Type::Scalar,
            None,
        );
        let material = self.root.push(json::Material {
            name: Some("body".to_string()),
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor([0.75, 0.72, 0.68, 1.0]),
                metallic_factor: json::material::StrengthFactor(0.0),
                roughness_factor: json::material::StrengthFactor(0.8),
                ..Default::default()
            },
            ..Default::default()
        });
        let attributes = BTreeMap::from([
            (Valid(Semantic::Positions), positions),
            (Valid(Semantic::Normals), normals),
            (Valid(Semantic::Joints(0)), joints),
            (Valid(Semantic::Weights(0)), weights),
        ]);
        self.root.push(json::Mesh {
            name: Some("body".to_string()),
            primitives: vec![json::mesh::Primitive {
                attributes,
                indices: Some(indices),
                material: Some(material),
                mode: Valid(json::mesh::Mode::Triangles),
                targets: None,
                extensions: None,
                extras: None,
            }],
            weights: None,
            extensions: None,
            extras: None,
        })
    }

    /// One animation with a key at every frame: a rotation channel for
    /// every joint with rotation channels, a translation channel for every
    /// joint with position channels, interpolated linearly.
    fn animation(&mut self, motion: &Motion, name: &str) {
        use json::accessor::Type;
        use json::animation::Property;
        let skeleton = motion.skeleton();
        let frames = motion.frame_count();
        let times: Vec<f32> = (0..frames)
            .map(|f| (f as f64 * motion.frame_time()) as f32)
            .collect();
        let input = self.floats(&times, Type::Scalar, None, true);
        let mut samplers = Vec::new();
        let mut channels = Vec::new();
        let mut add = |doc: &mut Document, joint: usize, property, values: &[f32], type_| {
            let output = doc.floats(values, type_, None, false);
            channels.push(json::animation::Channel {
                sampler: json::Index::new(samplers.len() as u32),
                target: json::animation::Target {
                    node: json::Index::new(joint as u32),
                    path: Valid(property),
                    extensions: None,
                    extras: None,
                },
                extensions: None,
                extras: None,
            });
            samplers.push(json::animation::Sampler {
                input,
                interpolation: Valid(json::animation::Interpolation::Linear),
                output,
                extensions: None,
                extras: None,
            });
        };
        for (j, joint) in skeleton.joints().iter().enumerate() {
            if joint.has_rotation_channels() {
                let mut values = Vec::with_capacity(frames * 4);
                let mut previous = Quat::IDENTITY;
                for f in 0..frames {
                    // q and -q are one rotation; linear interpolation
                    // between keys takes the short way only when
                    // neighbouring keys lie on the same side.
                    let mut q = motion.local_rotation(f, j).normalize();
                    if q.dot(previous) < 0.0 {
                        q = -q;
                    }
                    values.extend(q.to_array());
                    previous = q;
                }
                add(self, j, Property::Rotation, &values, Type::Vec4);
            }
            if joint.has_position_channels() {
                let values: Vec<f32> = (0..frames)
                    .flat_map(|f| motion.local_translation(f, j).to_array())
                    .collect();
                add(self, j, Property::Translation, &values, Type::Vec3);
            }
        }
        let record = AnimationRecord {
            frame_time: motion.frame_time(),
        };
        self.root.push(json::Animation {
            name: Some(name.to_string()),
            channels,
            samplers,
            extensions: None,
            extras: to_extras(&record),
        });
    }

    /// The document with its buffer declared.
    fn finish(mut self) -> (json::Root, Vec<u8>) {
        self.root.push(json::Buffer {
            byte_length: USize64::from(self.bin.len()),
            name: None,
            uri: None,
            extensions: None,
            extras: None,
        });
        (self.root, self.bin)
    }
}
