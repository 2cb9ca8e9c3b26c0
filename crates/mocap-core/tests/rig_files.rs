//! Rig files given to the whole process (`register_rig_file`, what `mocap
//! --rig FILE` does). In a test binary of its own: a registered rig stays
//! registered for every later test of the process.

use std::io::Cursor;
use std::path::Path;

use mocap_core::bodymap::{register_rig_file, BodyMap, BodyPart};
use mocap_core::io::bvh::{read_bvh, read_bvh_from};
use mocap_core::ops::mirror_auto;
use mocap_core::{forward_kinematics, Motion};
use mocap_testdata::{renamed_bandai_bvh, sample_walk, RENAMED_BANDAI_RIG};

fn renamed_walk() -> Motion {
    let text = renamed_bandai_bvh(&sample_walk());
    read_bvh_from(Cursor::new(text), Path::new("renamed.bvh")).unwrap()
}

#[test]
fn a_registered_rig_file_reaches_every_detect_for_the_skeletons_it_fits() {
    let walk = read_bvh(&sample_walk()).unwrap();
    let renamed = renamed_walk();
    let err = BodyMap::detect(renamed.skeleton()).unwrap_err().to_string();
    assert!(err.contains("--rig"), "{err}");

    let dir = tempfile::tempdir().unwrap();
    // Bad files are refused, naming the file, and register nothing.
    let typo = dir.path().join("typo.toml");
    std::fs::write(&typo, "[parts]\npelviss = \"Becken\"\n").unwrap();
    let err = register_rig_file(&typo).unwrap_err().to_string();
    assert!(
        err.contains("typo.toml") && err.contains("pelviss"),
        "{err}"
    );
    let empty = dir.path().join("empty.toml");
    std::fs::write(&empty, "name = \"nothing\"\n").unwrap();
    let err = register_rig_file(&empty).unwrap_err().to_string();
    assert!(
        err.contains("empty.toml") && err.contains("names no joint"),
        "{err}"
    );
    let err = register_rig_file(dir.path().join("absent.toml"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("absent.toml"), "{err}");
    assert!(BodyMap::detect(renamed.skeleton()).is_err());

    // A misspelt joint: the file is registered but fits no skeleton, and
    // the error says so instead of looking as if no file were given.
    let misspelt = dir.path().join("misspelt.toml");
    std::fs::write(
        &misspelt,
        RENAMED_BANDAI_RIG.replace("\"Becken\"", "\"Beckn\""),
    )
    .unwrap();
    register_rig_file(&misspelt).unwrap();
    let err = BodyMap::detect(renamed.skeleton()).unwrap_err().to_string();
    assert!(
        err.contains("misspelt.toml names \"Beckn\", which this skeleton lacks"),
        "{err}"
    );

    let rig = dir.path().join("studio.toml");
    std::fs::write(&rig, RENAMED_BANDAI_RIG).unwrap();
    register_rig_file(&rig).unwrap();
    let map = BodyMap::detect(renamed.skeleton()).unwrap();
    assert_eq!(map.rig(), "Studio (German names)");
    let bandai = BodyMap::detect(walk.skeleton()).unwrap();
    // Every part at the same joint as on the original rig.
    assert_eq!(
        map.parts().collect::<Vec<_>>(),
        bandai.parts().collect::<Vec<_>>()
    );
    assert_eq!(
        renamed
            .skeleton()
            .joint(map.require(BodyPart::Pelvis).unwrap())
            .name,
        "Becken"
    );
    // The rig the file does not fit is still found by the built-in tables.
    assert_eq!(bandai.rig(), "Bandai Namco");

    // What needs the body map now works on the renamed rig, and gives what
    // it gives on the original: its mirror image, joint by joint.
    let (a, b) = (
        forward_kinematics(&mirror_auto(&walk).unwrap()),
        forward_kinematics(&mirror_auto(&renamed).unwrap()),
    );
    for f in 0..walk.frame_count() {
        for j in 0..walk.skeleton().joint_count() {
            let d = a.position(f, j).distance(b.position(f, j));
            assert!(d < 1e-3, "frame {f}, joint {j}: {d} cm apart");
        }
    }
}
