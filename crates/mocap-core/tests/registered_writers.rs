//! Writers of formats the core does not know, given to the whole process
//! (`register_writer`, what mocap-gltf does for glTF). In a test binary of
//! its own: a registered writer stays registered for every later test of
//! the process.

use std::path::Path;

use mocap_core::io::bvh::read_bvh;
use mocap_core::io::{register_writer, write_motion, write_motion_noted};
use mocap_core::{Error, Motion, Result};
use mocap_testdata::sample_walk;

/// A `.fake` file holds the frame count; the writer notes the joint count.
fn write_fake(path: &Path, motion: &Motion) -> Result<Vec<String>> {
    std::fs::write(path, format!("{}\n", motion.frame_count())).map_err(|e| Error::io(path, e))?;
    Ok(vec![format!(
        "wrote only the frame count of {} joints",
        motion.skeleton().joint_count()
    )])
}

fn refuse(path: &Path, _: &Motion) -> Result<Vec<String>> {
    Err(Error::Invalid(format!("{}: refused", path.display())))
}

#[test]
fn a_registered_writer_writes_its_extension_returns_its_notes_and_is_named_in_the_unknown_type_error(
) {
    let dir = tempfile::tempdir().unwrap();
    let walk = read_bvh(&sample_walk()).unwrap();
    let fake = dir.path().join("take.FAKE");

    // Before registration: an unknown type; the error says what can be written.
    let err = write_motion(&fake, &walk).unwrap_err().to_string();
    assert!(err.contains("take.FAKE: cannot write this type"), "{err}");
    assert!(err.contains("can write .bvh)"), "{err}");
    assert!(!fake.exists());

    register_writer(&["fake", "fake2"], "a test format", write_fake);

    // The writer runs for its extension in any case, and its notes come back.
    let notes = write_motion_noted(&fake, &walk).unwrap();
    assert_eq!(
        std::fs::read_to_string(&fake).unwrap().trim(),
        walk.frame_count().to_string()
    );
    assert_eq!(
        notes,
        [format!(
            "wrote only the frame count of {} joints",
            walk.skeleton().joint_count()
        )]
    );
    // write_motion keeps its signature and drops the notes.
    let fake2 = dir.path().join("take.fake2");
    write_motion(&fake2, &walk).unwrap();
    assert!(fake2.exists());

    // BVH is the core's, with no notes, and cannot be taken over.
    register_writer(&["bvh", "fake"], "a refusing format", refuse);
    let bvh = dir.path().join("take.bvh");
    assert!(write_motion_noted(&bvh, &walk).unwrap().is_empty());
    assert_eq!(read_bvh(&bvh).unwrap().frame_count(), walk.frame_count());

    // The latest registration of an extension wins.
    let err = write_motion(&fake, &walk).unwrap_err().to_string();
    assert!(err.contains("take.FAKE: refused"), "{err}");

    // The unknown-type error lists every registered writer.
    let err = write_motion(&dir.path().join("take.xyz"), &walk)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("can write .bvh, or .fake2 (a test format), or .fake (a refusing format))"),
        "{err}"
    );
}
