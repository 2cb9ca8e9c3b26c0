//! Any bytes given to the ASF and AMC readers give a motion or an error,
//! never a panic. The input is split at the first `\0`: ASF text before it,
//! AMC text after it (the seed corpus is the HDM05 sample joined that way).
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use mocap_core::io::asf_amc::{parse_amc, parse_asf, AsfOptions};

fuzz_target!(|data: &[u8]| {
    let split = data.iter().position(|&b| b == 0).unwrap_or(data.len());
    let (asf, amc) = (&data[..split], data.get(split + 1..).unwrap_or(&[]));
    if let Ok(skeleton) = parse_asf(asf, Path::new("fuzz.asf")) {
        let _ = parse_amc(amc, Path::new("fuzz.amc"), &skeleton, &AsfOptions::default());
    }
});
