//! glTF as other tools write it: an armature node with a rotation and a
//! 0.01 scale above the joints (Mixamo, Blender), joints with rest
//! rotations, rotation-only animation with keys at other times on each
//! joint. The take read from it must put every joint where glTF's own
//! node transforms put it.

mod common;

use std::collections::HashMap;
use std::f32::consts::FRAC_PI_2;

use common::{Foreign, Mat4, NodeSpec, Quat, Vec3};
use gltf_json::animation::{Interpolation, Property};
use mocap_core::rotation::angle_between;
use mocap_core::{forward_kinematics, Channel};
use mocap_gltf::read_gltf;

/// Node indices of the rig below.
const ARMATURE: u32 = 0;
const HIPS: u32 = 1;
const SPINE: u32 = 2;
const HEAD: u32 = 3;
const LEG: u32 = 4;
const FOOT: u32 = 5;
const HEAD_END: u32 = 6;
const PROP: u32 = 7;

struct Rig {
    file: Foreign,
    /// Each node's parent node.
    parents: HashMap<u32, u32>,
    /// Rotation keys: node, times, rotations.
    keys: Vec<(u32, Vec<f32>, Vec<Quat>)>,
}

/// A Blender-style rig in centimetres under an armature that turns Z-up
/// into Y-up and scales by 0.01, as Mixamo's FBX through Blender comes out.
fn rig() -> Rig {
    let mut file = Foreign::default();
    let armature_turn = Quat::from_rotation_x(-FRAC_PI_2);
    file.node(NodeSpec {
        name: "Armature",
        translation: [0.5, 0.0, -0.25],
        rotation: armature_turn,
        scale: [0.01; 3],
        children: &[HIPS, PROP],
    });
    file.node(NodeSpec {
        name: "Hips",
        translation: [0.0, 3.0, 95.0],
        rotation: Quat::from_rotation_z(0.5),
        children: &[SPINE, LEG],
        ..Default::default()
    });
    file.node(NodeSpec {
        name: "Spine",
        translation: [0.0, 1.0, 20.0],
        rotation: Quat::from_rotation_x(0.2),
        children: &[HEAD],
        ..Default::default()
    });
    file.node(NodeSpec {
        name: "Head",
        translation: [0.0, -2.0, 50.0],
        children: &[HEAD_END],
        ..Default::default()
    });
    file.node(NodeSpec {
        name: "Leg",
        translation: [10.0, 0.0, -5.0],
        rotation: Quat::from_rotation_z(3.0),
        children: &[FOOT],
        ..Default::default()
    });
    file.node(NodeSpec {
        name: "Foot",
        translation: [0.0, 0.0, -88.0],
        rotation: Quat::from_rotation_x(0.7),
        ..Default::default()
    });
    file.node(NodeSpec {
        name: "Head_end",
        translation: [0.0, 0.0, 18.0],
        ..Default::default()
    });
    file.node(NodeSpec {
        name: "Prop",
        translation: [30.0, 0.0, 0.0],
        ..Default::default()
    });
    file.skin(&[HIPS, SPINE, HEAD, LEG, FOOT]);
    let keys = vec![
        (
            HIPS,
            vec![0.0, 1.0],
            vec![Quat::from_rotation_z(0.5), Quat::from_rotation_z(1.5)],
        ),
        (
            SPINE,
            vec![0.0, 0.5, 1.0],
            vec![
                Quat::from_rotation_x(0.2),
                Quat::from_rotation_y(0.9),
                Quat::from_rotation_x(-0.4),
            ],
        ),
        (
            LEG,
            vec![0.0, 0.25, 0.5, 0.75, 1.0],
            (0..5)
                .map(|k| {
                    Quat::from_euler(glam::EulerRot::XYZ, 0.15 * k as f32, -0.1 * k as f32, 3.0)
                })
                .collect(),
        ),
    ];
    let flat: Vec<(u32, Vec<f32>)> = keys
        .iter()
        .map(|(node, _, qs)| (*node, qs.iter().flat_map(|q| q.to_array()).collect()))
        .collect();
    let channels: Vec<(u32, Property, &[f32], &[f32])> = keys
        .iter()
        .zip(&flat)
        .map(|((node, times, _), (_, values))| (*node, Property::Rotation, &times[..], &values[..]))
        .collect();
    file.animation("Walk", &channels, Interpolation::Linear);
    let parents = HashMap::from([
        (HIPS, ARMATURE),
        (PROP, ARMATURE),
        (SPINE, HIPS),
        (LEG, HIPS),
        (HEAD, SPINE),
        (HEAD_END, HEAD),
        (FOOT, LEG),
    ]);
    Rig {
        file,
        parents,
        keys,
    }
}

impl Rig {
    /// The world matrix of `node` at time `t`, by glTF's own rule (each
    /// node's T * R * S under its parent's), with the rotation keys
    /// interpolated by slerp.
    fn world(&self, node: u32, t: f32) -> Mat4 {
        let spec = &self.file.root.nodes[node as usize];
        let mut rotation = Quat::from_array(spec.rotation.as_ref().unwrap().0);
        if let Some((_, times, values)) = self.keys.iter().find(|(n, _, _)| *n == node) {
            let i = times
                .iter()
                .rposition(|&k| k <= t)
                .unwrap()
                .min(times.len() - 2);
            let u = ((t - times[i]) / (times[i + 1] - times[i])).clamp(0.0, 1.0);
            rotation = values[i].slerp(values[i + 1], u);
        }
        let local = Mat4::from_scale_rotation_translation(
            Vec3::from_array(spec.scale.unwrap()),
            rotation,
            Vec3::from_array(spec.translation.unwrap()),
        );
        match self.parents.get(&node) {
            Some(&parent) => self.world(parent, t) * local,
            None => local,
        }
    }
}

#[test]
fn an_armature_with_rotation_and_scale_and_rest_rotations_reads_to_the_right_positions() {
    let rig = rig();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mixamo style.glb");
    rig.file.write_glb(&path);
    let take = read_gltf(&path, None).unwrap();

    let skeleton = take.skeleton();
    let names: Vec<&str> = skeleton.joints().iter().map(|j| j.name.as_str()).collect();
    assert_eq!(names, ["Hips", "Spine", "Head", "Leg", "Foot"]);
    assert_eq!(
        skeleton.parents(),
        [None, Some(0), Some(1), Some(0), Some(3)]
    );
    // The root moves and turns; the others turn, in the default layout.
    let root_channels = [
        Channel::Xposition,
        Channel::Yposition,
        Channel::Zposition,
        Channel::Zrotation,
        Channel::Xrotation,
        Channel::Yrotation,
    ];
    assert_eq!(skeleton.joint(0).channels, root_channels);
    for joint in &skeleton.joints()[1..] {
        assert_eq!(joint.channels, root_channels[3..], "{}", joint.name);
    }
    // The densest track has a key every 0.25 s: five frames.
    assert_eq!(take.frame_count(), 5);
    assert!((take.frame_time() - 0.25).abs() < 1e-9);

    let poses = forward_kinematics(&take);
    let nodes = [HIPS, SPINE, HEAD, LEG, FOOT];
    for f in 0..take.frame_count() {
        let t = f as f32 * 0.25;
        for (j, &node) in nodes.iter().enumerate() {
            let expected = rig.world(node, t).transform_point3(Vec3::ZERO);
            let got = poses.position(f, j);
            assert!(
                (got - expected).length() < 1e-5,
                "frame {f}, {}: {got} where glTF puts {expected}",
                names[j]
            );
        }
        // The leaf node under the head is its end site.
        let end = skeleton.joint(2).end_sites[0];
        let got = poses.position(f, 2) + poses.rotation(f, 2) * end;
        let expected = rig.world(HEAD_END, t).transform_point3(Vec3::ZERO);
        assert!(
            (got - expected).length() < 1e-5,
            "frame {f}: head end {got} vs {expected}"
        );
    }
    // In metres, standing along +Y: the head is about 1.6 m above the feet.
    let height = poses.position(0, 2).y - poses.position(0, 4).y;
    assert!((1.3..1.9).contains(&height), "{height}");
}

#[test]
fn a_gltf_with_its_buffer_in_a_file_beside_it_reads_the_same() {
    let rig = rig();
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("take.glb");
    rig.file.write_glb(&glb);
    let gltf = dir.path().join("take.gltf");
    // A space in the file name: the URI spells it %20.
    rig.file
        .write_gltf_with_bin(&gltf, "take%20data.bin", false);
    std::fs::write(dir.path().join("take data.bin"), &rig.file.bin).unwrap();
    assert_eq!(
        read_gltf(&gltf, None).unwrap(),
        read_gltf(&glb, None).unwrap()
    );
}

#[test]
fn a_named_animation_is_read_and_the_registered_reader_takes_the_first() {
    let mut rig = rig();
    let values: Vec<f32> = [Quat::from_rotation_z(0.5), Quat::from_rotation_z(-1.0)]
        .iter()
        .flat_map(|q| q.to_array())
        .collect();
    let times = [0.0, 0.1, 0.2];
    let three: Vec<f32> = values.iter().chain(&values[4..]).copied().collect();
    rig.file.animation(
        "Turn",
        &[(HIPS, Property::Rotation, &times, &three)],
        Interpolation::Step,
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("two.glb");
    rig.file.write_glb(&path);
    let turn = read_gltf(&path, Some("Turn")).unwrap();
    assert_eq!(turn.frame_count(), 3);
    assert!((turn.frame_time() - 0.1).abs() < 1e-6);
    // STEP: the second key holds until the third.
    let hips = |f| turn.local_rotation(f, 0);
    let armature = Quat::from_rotation_x(-FRAC_PI_2);
    for (f, angle) in [(0, 0.5), (1, -1.0), (2, -1.0)] {
        let expected = armature * Quat::from_rotation_z(angle);
        assert!(
            angle_between(hips(f), expected) < 1e-4,
            "frame {f}: {} where {expected} expected",
            hips(f)
        );
    }

    mocap_gltf::register_formats();
    let first = mocap_core::io::read_motion(&path).unwrap();
    assert_eq!(first.frame_count(), 5);
}
