//! Any bytes given to the BVH reader give a motion or an error, never a
//! panic; a motion that was read writes back and reads again to the same
//! motion.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use mocap_core::io::bvh::{read_bvh_from, write_bvh_to};

fuzz_target!(|data: &[u8]| {
    let path = Path::new("fuzz.bvh");
    let Ok(motion) = read_bvh_from(data, path) else {
        return;
    };
    let mut written = Vec::new();
    write_bvh_to(&mut written, &motion).expect("writing to memory cannot fail");
    let again = read_bvh_from(written.as_slice(), path).expect("our own output reads back");
    assert_eq!(again.skeleton(), motion.skeleton());
    assert_eq!(again.frame_count(), motion.frame_count());
    assert_eq!(again.frame_time(), motion.frame_time());
    // Bit-identical values (NaN-safe comparison).
    let same = again
        .values()
        .iter()
        .zip(motion.values())
        .all(|(a, b)| a.to_bits() == b.to_bits());
    assert!(same, "values changed in a write/read round trip");
});
