//! Readers of formats the core does not know, given to the whole process
//! (`register_reader`, what mocap-fuse does for sensor recordings). In a
//! test binary of its own: a registered reader stays registered for every
//! later test of the process.

use std::path::{Path, PathBuf};

use mocap_core::info::describe_files;
use mocap_core::io::{read_motion, read_motions, register_reader, MotionSource};
use mocap_core::{Error, Motion, Result};
use mocap_testdata::sample_walk;

/// A `.fake` file holds a frame count; its motion is the sample walk's
/// skeleton at rest for that many frames, at 40 fps.
fn read_fake(path: &Path) -> Result<Motion> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    let frames: usize = text
        .trim()
        .parse()
        .map_err(|_| Error::Invalid(format!("{}: not a frame count", path.display())))?;
    let walk = mocap_core::io::bvh::read_bvh(&sample_walk())?;
    Motion::rest(walk.skeleton().clone(), 1.0 / 40.0, frames)
}

#[test]
fn a_registered_reader_reads_its_extension_and_is_named_in_the_unknown_type_error() {
    let dir = tempfile::tempdir().unwrap();
    let fake = dir.path().join("take.FAKE");
    std::fs::write(&fake, "7\n").unwrap();
    let unknown = dir.path().join("take.xyz");
    std::fs::write(&unknown, "7\n").unwrap();

    // Before registration: an unknown type, and the error does not offer it.
    let err = read_motion(&fake).unwrap_err().to_string();
    assert!(err.contains("unknown motion file type"), "{err}");
    assert!(!err.contains(".fake"), "{err}");

    register_reader(&["fake", "fake2"], "a test recording", read_fake);

    // read_motion, in any case of the extension.
    let motion = read_motion(&fake).unwrap();
    assert_eq!(motion.frame_count(), 7);
    assert!((motion.frame_time() - 1.0 / 40.0).abs() < 1e-9);

    // Grouped among BVH files, in order; no length announced by a header.
    let walk = sample_walk();
    let paths: Vec<PathBuf> = vec![walk.clone(), fake.clone()];
    let sources = MotionSource::group(&paths).unwrap();
    assert_eq!(
        sources,
        [
            MotionSource::Bvh(walk.clone()),
            MotionSource::Registered(fake.clone())
        ]
    );
    assert_eq!(sources[1].announced_length().unwrap(), None);
    assert_eq!(sources[1].display_name(), fake.display().to_string());
    let motions = read_motions(&paths).unwrap();
    assert_eq!(motions.len(), 2);
    assert_eq!(motions[1].1.frame_count(), 7);

    // `mocap info`'s entry point reads it too.
    let infos = describe_files(std::slice::from_ref(&fake), &mut |_, _| {}).unwrap();
    assert_eq!(infos.len(), 1);

    // The reader's own errors come through.
    let bad = dir.path().join("bad.fake2");
    std::fs::write(&bad, "many\n").unwrap();
    let err = read_motion(&bad).unwrap_err().to_string();
    assert!(err.contains("bad.fake2: not a frame count"), "{err}");

    // The unknown-type error lists the registered extensions and what they are.
    let err = read_motion(&unknown).unwrap_err().to_string();
    assert!(err.contains("take.xyz: unknown motion file type"), "{err}");
    assert!(err.contains(".bvh"), "{err}");
    assert!(err.contains(".fake or .fake2 (a test recording)"), "{err}");

    // Registering an extension again hands it to the latest reader; the
    // built-in extensions keep theirs.
    fn refuse(path: &Path) -> Result<Motion> {
        Err(Error::Invalid(format!("{}: refused", path.display())))
    }
    register_reader(&["fake", "bvh"], "a refused recording", refuse);
    let err = read_motion(&fake).unwrap_err().to_string();
    assert!(err.contains("refused"), "{err}");
    assert!(read_motion(&walk).is_ok());
    let err = read_motion(&unknown).unwrap_err().to_string();
    assert!(
        err.contains(".fake2 (a test recording), or .fake (a refused recording)"),
        "{err}"
    );
}
