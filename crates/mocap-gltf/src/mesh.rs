//! A simple body for the skeleton, so that any glTF viewer shows a person
//! and not only an invisible set of joints: a low-poly capsule along every
//! bone (to every child joint and end site), each vertex bound with weight
//! 1 to the joint the bone hangs from, so the capsule moves rigidly with it.

use std::f32::consts::{FRAC_PI_2, TAU};

use mocap_core::rotation::{Quat, Vec3};
use mocap_core::Skeleton;

/// Vertices around a capsule.
const AROUND: usize = 8;
/// Rings in each hemispherical cap, the equator included.
const CAP_RINGS: usize = 2;
/// A capsule's radius as a share of the rest height: about 6 cm on a
/// 1.4 m ankle-to-head skeleton.
const RADIUS_OF_HEIGHT: f32 = 0.045;
/// ...and at most this share of its bone's length, so fingers stay thin.
const RADIUS_OF_BONE: f32 = 0.3;
/// Bones shorter than this share of the rest height get no capsule: joints
/// at the same place (Bandai's root under the hips) have no bone to show.
const SHORTEST_BONE_OF_HEIGHT: f32 = 0.005;

/// The body's triangles, in the skeleton's rest pose (the bind pose).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BodyMesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    /// The skin joint of each vertex (the first of four; the others unused).
    pub joints: Vec<[u16; 4]>,
    pub weights: Vec<[f32; 4]>,
    /// Three vertex indices per triangle, counter-clockwise seen from
    /// outside.
    pub indices: Vec<u32>,
}

/// Capsules along the bones of `skeleton` posed at `rest` (each joint's
/// global rest position), their radius in proportion to `height`. A joint
/// that is `moving` (its position channels carry it away from its offset,
/// as Bandai's hips leave the root on the floor) hangs from its parent by
/// no bone.
pub fn body_mesh(skeleton: &Skeleton, rest: &[Vec3], moving: &[bool], height: f32) -> BodyMesh {
    let mut mesh = BodyMesh::default();
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let children = skeleton
            .children(j)
            .filter(|&c| !moving[c])
            .map(|c| rest[c] - rest[j]);
        let ends = joint.end_sites.iter().copied();
        for bone in children.chain(ends) {
            let length = bone.length();
            if length < SHORTEST_BONE_OF_HEIGHT * height {
                continue;
            }
            let radius = (RADIUS_OF_HEIGHT * height).min(RADIUS_OF_BONE * length);
            let joint = u16::try_from(j).expect("the writer refuses more joints than u16 holds");
            add_capsule(&mut mesh, rest[j], bone, radius, joint);
        }
    }
    mesh
}

/// A capsule from `start` to `start + bone`, bound to `joint`.
fn add_capsule(mesh: &mut BodyMesh, start: Vec3, bone: Vec3, radius: f32, joint: u16) {
    let length = bone.length();
    let turn = Quat::from_rotation_arc(Vec3::Y, bone / length);
    let first = mesh.positions.len() as u32;
    let mut add = |normal: Vec3, height: f32| {
        let local = normal * radius + Vec3::Y * height;
        mesh.positions.push((start + turn * local).to_array());
        mesh.normals.push((turn * normal).to_array());
        mesh.joints.push([joint, 0, 0, 0]);
        mesh.weights.push([1.0, 0.0, 0.0, 0.0]);
    };
    // In the capsule's frame: the bone along +Y from 0 to `length`; the
    // bottom pole, rings from the bottom cap to the top cap, the top pole.
    add(-Vec3::Y, 0.0);
    let mut rings = 0;
    // Latitudes from just above the bottom pole up to the equator about
    // the bone's start, then from the equator about its end up to just
    // below the top pole.
    let bottom = (1..=CAP_RINGS).map(|k| (k as f32 / CAP_RINGS as f32 - 1.0, 0.0));
    let top = (0..CAP_RINGS).map(|k| (k as f32 / CAP_RINGS as f32, length));
    for (share, centre) in bottom.chain(top) {
        let latitude = FRAC_PI_2 * share;
        for a in 0..AROUND {
            let angle = TAU * a as f32 / AROUND as f32;
            let normal = Vec3::new(
                latitude.cos() * angle.cos(),
                latitude.sin(),
                latitude.cos() * angle.sin(),
            );
            add(normal, centre);
        }
        rings += 1;
    }
    add(Vec3::Y, length);
    let ring = |r: usize, a: usize| first + 1 + (r * AROUND + a % AROUND) as u32;
    let top = first + 1 + (rings * AROUND) as u32;
    for a in 0..AROUND {
        // Counter-clockwise seen from outside, with angles growing from +X
        // towards +Z.
        mesh.indices.extend([first, ring(0, a), ring(0, a + 1)]);
        for r in 0..rings - 1 {
            let (p, q) = (ring(r, a), ring(r, a + 1));
            let (s, t) = (ring(r + 1, a), ring(r + 1, a + 1));
            mesh.indices.extend([p, t, q, p, s, t]);
        }
        mesh.indices
            .extend([top, ring(rings - 1, a + 1), ring(rings - 1, a)]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mocap_core::Joint;

    fn two_bones() -> (Skeleton, Vec<Vec3>) {
        let mut hip = Joint::new("hip", None, Vec3::ZERO);
        hip.end_sites.push(Vec3::new(0.3, 0.0, 0.0));
        let knee = Joint::new("knee", Some(0), Vec3::new(0.0, -0.4, 0.0));
        // Moving: no bone from the hip to it.
        let prop = Joint::new("prop", Some(0), Vec3::new(0.0, 0.0, 0.5));
        let skeleton = Skeleton::new(vec![hip, knee, prop]).unwrap();
        let rest = vec![
            Vec3::ZERO,
            Vec3::new(0.0, -0.4, 0.0),
            Vec3::new(0.0, 0.0, 0.5),
        ];
        (skeleton, rest)
    }

    #[test]
    fn capsules_face_outwards_and_cover_their_bones() {
        let (skeleton, rest) = two_bones();
        let mesh = body_mesh(&skeleton, &rest, &[false, false, true], 1.4);
        let per_capsule = 2 + 2 * CAP_RINGS * AROUND;
        // hip -> knee and hip -> end site; the knee has no bone below it,
        // the prop none above it.
        assert_eq!(mesh.positions.len(), 2 * per_capsule);
        assert!(mesh.joints.iter().all(|j| j[0] == 0));
        assert!(mesh.weights.iter().all(|w| *w == [1.0, 0.0, 0.0, 0.0]));
        let position = |i: u32| Vec3::from_array(mesh.positions[i as usize]);
        for triangle in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [triangle[0], triangle[1], triangle[2]];
            let face = (position(b) - position(a)).cross(position(c) - position(a));
            let normal: Vec3 = [a, b, c]
                .iter()
                .map(|&i| Vec3::from_array(mesh.normals[i as usize]))
                .sum();
            assert!(
                face.dot(normal) > 0.0,
                "triangle {triangle:?} faces inwards"
            );
        }
        // Each vertex is its radius away from its bone's segment.
        let radius = (RADIUS_OF_HEIGHT * 1.4).min(RADIUS_OF_BONE * 0.3);
        for p in &mesh.positions[per_capsule..] {
            let p = Vec3::from_array(*p);
            let nearest = Vec3::new(p.x.clamp(0.0, 0.3), 0.0, 0.0);
            assert!(((p - nearest).length() - radius).abs() < 1e-5, "{p}");
        }
    }
}
