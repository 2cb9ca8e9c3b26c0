//! Takes written as glTF and read back: the same skeleton, channel layout,
//! frames and joint positions, on real takes of three rigs and units.

use std::path::{Path, PathBuf};

use mocap_core::io::asf_amc::read_asf_amc;
use mocap_core::io::bvh::read_bvh;
use mocap_core::io::write_motion;
use mocap_core::{forward_kinematics, Motion};
use mocap_gltf::{read_gltf, write_gltf};

/// Joint positions must agree within this many metres.
const TOLERANCE_M: f32 = 1e-4;

/// Writes `motion` as `.glb` and `.gltf`, reads each back and compares;
/// `metres_per_unit` converts the take's lengths for the tolerance. Returns
/// the notes of the `.glb` write.
fn round_trip(motion: &Motion, metres_per_unit: f32) -> Vec<String> {
    let dir = tempfile::tempdir().unwrap();
    let mut notes = Vec::new();
    for name in ["take.glb", "take.gltf"] {
        let path = dir.path().join(name);
        let written = write_gltf(&path, motion).unwrap();
        if notes.is_empty() {
            notes = written;
        }
        let back = read_gltf(&path, None).unwrap();
        compare(motion, &back, metres_per_unit, &path);
        // And through BVH, as `mocap convert take.glb take.bvh` does.
        let bvh = dir.path().join("back.bvh");
        write_motion(&bvh, &back).unwrap();
        compare(motion, &read_bvh(&bvh).unwrap(), metres_per_unit, &bvh);
    }
    notes
}

fn compare(original: &Motion, back: &Motion, metres_per_unit: f32, path: &Path) {
    let (a, b) = (original.skeleton(), back.skeleton());
    assert_eq!(b.joint_count(), a.joint_count(), "{}", path.display());
    for (x, y) in a.joints().iter().zip(b.joints()) {
        assert_eq!(y.name, x.name);
        assert_eq!(y.parent, x.parent, "parent of {}", x.name);
        assert_eq!(y.channels, x.channels, "channels of {}", x.name);
        assert_eq!(
            y.end_sites.len(),
            x.end_sites.len(),
            "end sites of {}",
            x.name
        );
        for (e, f) in x.end_sites.iter().zip(&y.end_sites) {
            assert!(
                (*e - *f).length() * metres_per_unit < TOLERANCE_M,
                "{}",
                x.name
            );
        }
    }
    assert_eq!(back.frame_count(), original.frame_count());
    assert_eq!(back.frame_time(), original.frame_time());
    let (pa, pb) = (forward_kinematics(original), forward_kinematics(back));
    let mut worst = 0.0f32;
    for (p, q) in pa.positions.iter().zip(&pb.positions) {
        worst = worst.max((*p - *q).length() * metres_per_unit);
    }
    assert!(
        worst < TOLERANCE_M,
        "{}: joints up to {:.3} mm apart",
        path.display(),
        worst * 1000.0
    );
}

#[test]
fn the_bundled_bandai_walk_comes_back_from_glb_and_gltf() {
    let walk = read_bvh(&mocap_testdata::sample_walk()).unwrap();
    let notes = round_trip(&walk, 0.01);
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(
        notes[0].starts_with(
            "lengths scaled by 0.01: the take's units read as centimetres (rest height 1"
        ),
        "{notes:?}"
    );
}

/// One take of each rig in other-rigs, with the unit the rule should find
/// (`None`: none fits, scaled to the nominal height) and whether it is
/// turned Y-up.
#[test]
fn takes_of_other_rigs_come_back_in_their_units() {
    let Some(dir) = mocap_testdata::shared("other-rigs") else {
        return;
    };
    let cases: [(&str, f32, bool); 3] = [
        ("cmu-daz/02/02_01.bvh", 0.01, false),
        ("xia/angry_13_000.bvh", 0.0254 / 0.45, false),
        // FAIR's rig stands along +Z in no known unit.
        ("animated-drawings/fair1/dab.bvh", 0.0, true),
    ];
    for (file, metres_per_unit, turned) in cases {
        let path: PathBuf = dir.join(file);
        let take = read_bvh(&path).unwrap();
        // The whole take for one, the first 200 frames of the others, to
        // keep the test quick.
        let take = if file.starts_with("xia") {
            take
        } else {
            mocap_core::ops::trim(&take, 0..200.min(take.frame_count())).unwrap()
        };
        let units = mocap_gltf::take_units(take.skeleton());
        let scale = units.metres_per_unit();
        if metres_per_unit > 0.0 {
            assert!((scale - metres_per_unit).abs() < 1e-7, "{file}: {units:?}");
        } else {
            assert!(units.unit.is_none(), "{file}: {units:?}");
        }
        let notes = round_trip(&take, scale);
        assert_eq!(notes.len(), 1 + usize::from(turned), "{file}: {notes:?}");
        if turned {
            assert!(notes[1].contains("up axis reads as +Z"), "{notes:?}");
        }
    }
}

#[test]
fn the_hdm05_asf_amc_take_comes_back() {
    let Some(dir) = mocap_testdata::shared("hdm05-sample") else {
        return;
    };
    let take = read_asf_amc(
        dir.join("HDM_bd.asf"),
        dir.join("HDM_bd_depositFloorR_001_120.amc"),
    )
    .unwrap();
    let notes = round_trip(&take, 0.01);
    assert!(notes[0].contains("read as centimetres"), "{notes:?}");
}
