//! Inputs found by fuzzing (`bench/fuzz.sh`): each once broke a reader or a
//! read -> write -> read round trip. They must now give a clear error or a
//! motion that writes back.

use std::path::Path;

use mocap_core::io::bvh::{read_bvh_from, write_bvh_to};
use mocap_core::Error;

fn fixture(name: &str) -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/fuzz")
        .join(name);
    std::fs::read(path).expect("fixture exists")
}

/// Reads BVH bytes; whatever is read must write and read back unchanged.
fn read_and_round_trip(bytes: &[u8]) -> Result<(), Error> {
    let motion = read_bvh_from(bytes, Path::new("fuzz.bvh"))?;
    let mut written = Vec::new();
    write_bvh_to(&mut written, &motion).expect("a motion that was read can be written");
    let again = read_bvh_from(written.as_slice(), Path::new("again.bvh")).unwrap();
    assert_eq!(again, motion);
    Ok(())
}

#[test]
fn control_characters_in_a_joint_name_are_refused_where_they_stand() {
    // Found by the `bvh` fuzz target: a JOINT name with NUL and CR bytes was
    // accepted by the reader but refused by the writer.
    let Err(Error::Parse(e)) = read_and_round_trip(&fixture("bvh-control-char-in-name.bvh")) else {
        panic!("expected a parse error");
    };
    assert_eq!(e.location.line, 6);
    assert!(e.message.contains("control character"), "{}", e.message);
}
