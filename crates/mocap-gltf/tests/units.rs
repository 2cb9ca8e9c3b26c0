//! The unit rule ([`mocap_gltf::take_units`]) on every rig we have: each
//! file's unit as its source documents it, or none where nothing says.

use std::path::Path;

use mocap_core::io::asf_amc::read_asf_amc;
use mocap_core::io::bvh::read_bvh_header;
use mocap_gltf::{take_units, NOMINAL_HEIGHT};

/// The unit's symbol the rule should find for the skeleton of `path`
/// (`None`: no known unit).
fn assert_unit(path: &Path, expected: Option<&str>) {
    let (skeleton, _, _) = read_bvh_header(path).unwrap();
    let units = take_units(&skeleton);
    assert_eq!(
        units.unit.map(|u| u.symbol),
        expected,
        "{}: {units:?}",
        path.display()
    );
    if units.unit.is_none() {
        let metres = units.rest_height * units.metres_per_unit();
        assert!((metres - NOMINAL_HEIGHT).abs() < 1e-4, "{}", path.display());
    }
}

#[test]
fn the_bundled_bandai_takes_are_in_centimetres() {
    for name in [
        "dataset-1_walk_normal_001.bvh",
        "dataset-1_walk_proud_001.bvh",
    ] {
        assert_unit(&mocap_testdata::sample(name), Some("cm"));
    }
    let (skeleton, _, _) = read_bvh_header(&mocap_testdata::sample_walk()).unwrap();
    let units = take_units(&skeleton);
    // Ankle to pelvis and pelvis to head joint, along Bandai's bones.
    assert!((units.rest_height - 134.46).abs() < 0.01, "{units:?}");
    assert!(units.measured_on_body);
    assert_eq!(
        units.note(),
        "lengths scaled by 0.01: the take's units read as centimetres (rest height 134.5 cm)"
    );
}

#[test]
fn every_rig_of_other_rigs_reads_as_its_source_says() {
    let Some(dir) = mocap_testdata::shared("other-rigs") else {
        return;
    };
    // CMU's conversions: Daz's in centimetres, the others in ASF units;
    // FAIR's rig is in a unit nothing documents.
    let folders = [
        ("cmu-daz", Some("cm")),
        ("xia", Some("ASF units")),
        ("cmu-max", Some("ASF units")),
        ("cmu-asf", Some("ASF units")),
        ("animated-drawings/cmu1", Some("ASF units")),
        ("animated-drawings/fair1", None),
    ];
    let mut checked = 0;
    for (folder, unit) in folders {
        let folder = dir.join(folder);
        let mut files = vec![];
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                files.extend(mocap_testdata::bvh_files(&path));
            } else if path.extension().is_some_and(|e| e == "bvh") {
                files.push(path);
            }
        }
        assert!(!files.is_empty(), "{}", folder.display());
        for file in files {
            assert_unit(&file, unit);
            checked += 1;
        }
    }
    assert_eq!(checked, 96, "the README lists 96 clips");
}

#[test]
fn parser_cases_and_hdm05_read_as_their_sources_say() {
    let Some(dir) = mocap_testdata::shared_data() else {
        return;
    };
    let cases = [
        ("bvhanim_test_mocapbank.bvh", Some("cm")),
        ("bvhpython_test_mocapbank.bvh", Some("cm")),
        // Mixamo exports centimetres.
        ("bvhpython_test_freebvh.bvh", Some("cm")),
        (
            "dme_example_crlf_leadingdot_frametime.bvh",
            Some("ASF units"),
        ),
        // Two joints, no body: a made-up test skeleton.
        ("bvhanim_test_simple.bvh", None),
    ];
    for (name, unit) in cases {
        assert_unit(&dir.join("parser-cases").join(name), unit);
    }
    // The core reads ASF/AMC in centimetres.
    let hdm = dir.join("hdm05-sample");
    let take = read_asf_amc(
        hdm.join("HDM_bd.asf"),
        hdm.join("HDM_bd_depositFloorR_001_120.amc"),
    )
    .unwrap();
    let units = take_units(take.skeleton());
    assert_eq!(units.unit.map(|u| u.symbol), Some("cm"), "{units:?}");
}
