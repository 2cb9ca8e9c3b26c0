//! Any bytes given to the NTU RGB+D `.skeleton` reader give its bodies or
//! an error naming the file, never a panic; the bodies read make a
//! recording of finite joints that the offline fusion takes.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use mocap_fuse::{ntu_sensor_frames, read_ntu_skeleton_from, SensorStreams};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new("S001C002P003R001A001.skeleton");
    let frames = match read_ntu_skeleton_from(text, path) {
        Ok(frames) => frames,
        Err(e) => {
            let message = e.to_string();
            assert!(
                message.starts_with("S001C002P003R001A001.skeleton:"),
                "{message}"
            );
            return;
        }
    };
    let recording = ntu_sensor_frames(&frames, 2, 30.0);
    assert!(recording.len() <= frames.len());
    for f in &recording {
        assert!(f.joints.iter().all(|j| j.position.is_finite()));
    }
    let streams = SensorStreams::new(recording);
    assert!(streams.streams.len() <= 1);
    streams
        .check_span(30.0)
        .expect("an NTU take is 30 fps from frame 0");
});
