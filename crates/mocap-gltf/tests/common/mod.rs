//! glTF files as other tools write them, built with gltf-json for the
//! tests: nodes, a skin, animations, one buffer.

// Each test file uses its own part of this module.
#![allow(dead_code, unused_imports)]

use std::borrow::Cow;
use std::path::Path;

use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;

pub use glam::{Mat4, Quat, Vec3};

/// A document being built and its buffer's bytes.
#[derive(Default)]
pub struct Foreign {
    pub root: json::Root,
    pub bin: Vec<u8>,
}

/// A node's name, rest transform and children.
pub struct NodeSpec<'a> {
    pub name: &'a str,
    pub translation: [f32; 3],
    pub rotation: Quat,
    pub scale: [f32; 3],
    pub children: &'a [u32],
}

impl Default for NodeSpec<'_> {
    fn default() -> Self {
        NodeSpec {
            name: "node",
            translation: [0.0; 3],
            rotation: Quat::IDENTITY,
            scale: [1.0; 3],
            children: &[],
        }
    }
}

impl Foreign {
    pub fn node(&mut self, spec: NodeSpec) -> u32 {
        let index = self.root.nodes.len() as u32;
        self.root.push(json::Node {
            name: Some(spec.name.to_string()),
            translation: Some(spec.translation),
            rotation: Some(json::scene::UnitQuaternion(spec.rotation.to_array())),
            scale: Some(spec.scale),
            children: (!spec.children.is_empty())
                .then(|| spec.children.iter().map(|&c| json::Index::new(c)).collect()),
            ..Default::default()
        });
        index
    }

    pub fn skin(&mut self, joints: &[u32]) {
        self.root.push(json::Skin {
            name: Some("Armature".into()),
            inverse_bind_matrices: None,
            joints: joints.iter().map(|&j| json::Index::new(j)).collect(),
            skeleton: None,
            extensions: None,
            extras: None,
        });
    }

    /// An accessor of floats (`width` a element), in the one buffer.
    pub fn floats(
        &mut self,
        data: &[f32],
        type_: json::accessor::Type,
        bounds: bool,
    ) -> json::Index<json::Accessor> {
        let offset = self.bin.len();
        self.bin.extend(data.iter().flat_map(|v| v.to_le_bytes()));
        let view = self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(data.len() * 4),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            name: None,
            target: None,
            extensions: None,
            extras: None,
        });
        let width = type_.multiplicity();
        let (min, max) = if bounds {
            let min = data.iter().copied().fold(f32::INFINITY, f32::min);
            let max = data.iter().copied().fold(f32::NEG_INFINITY, f32::max);
            (
                Some(json::Value::from(vec![min])),
                Some(json::Value::from(vec![max])),
            )
        } else {
            (None, None)
        };
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(data.len() / width),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::F32,
            )),
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

    /// An animation named `name` of `(node, property, times, values)`
    /// channels with `interpolation`.
    pub fn animation(
        &mut self,
        name: &str,
        channels: &[(u32, json::animation::Property, &[f32], &[f32])],
        interpolation: json::animation::Interpolation,
    ) {
        use json::accessor::Type;
        let mut samplers = Vec::new();
        let mut targets = Vec::new();
        for (k, &(node, property, times, values)) in channels.iter().enumerate() {
            let input = self.floats(times, Type::Scalar, true);
            let type_ = match property {
                json::animation::Property::Rotation => Type::Vec4,
                _ => Type::Vec3,
            };
            let output = self.floats(values, type_, false);
            samplers.push(json::animation::Sampler {
                input,
                output,
                interpolation: Valid(interpolation),
                extensions: None,
                extras: None,
            });
            targets.push(json::animation::Channel {
                sampler: json::Index::new(k as u32),
                target: json::animation::Target {
                    node: json::Index::new(node),
                    path: Valid(property),
                    extensions: None,
                    extras: None,
                },
                extensions: None,
                extras: None,
            });
        }
        self.root.push(json::Animation {
            name: Some(name.to_string()),
            channels: targets,
            samplers,
            extensions: None,
            extras: None,
        });
    }

    fn with_buffer(&self, uri: Option<String>) -> json::Root {
        let mut root = self.root.clone();
        root.buffers = vec![json::Buffer {
            byte_length: USize64::from(self.bin.len()),
            name: None,
            uri,
            extensions: None,
            extras: None,
        }];
        root
    }

    /// Writes a `.glb`.
    pub fn write_glb(&self, path: &Path) {
        let json = json::serialize::to_vec(&self.with_buffer(None)).unwrap();
        let glb = gltf::binary::Glb {
            header: gltf::binary::Header {
                magic: *b"glTF",
                version: 2,
                length: 0,
            },
            json: Cow::Owned(json),
            bin: Some(Cow::Borrowed(&self.bin)),
        };
        std::fs::write(path, glb.to_vec().unwrap()).unwrap();
    }

    /// Writes a `.gltf` whose buffer is the file `bin_name` beside it
    /// (written only when `write_bin`).
    pub fn write_gltf_with_bin(&self, path: &Path, bin_name: &str, write_bin: bool) {
        let root = self.with_buffer(Some(bin_name.to_string()));
        std::fs::write(path, json::serialize::to_vec_pretty(&root).unwrap()).unwrap();
        if write_bin {
            std::fs::write(path.with_file_name(bin_name), &self.bin).unwrap();
        }
    }
}
