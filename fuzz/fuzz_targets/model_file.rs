//! Any bytes given as a model file (`--model`) give a model or an error,
//! never a panic, a hang or an allocation the file does not justify.
//!
//! Each input is loaded twice: as it is, where the checksum refuses almost
//! every mutation, and sealed (its checksum recomputed, as if the damage had
//! been done before the file was written), so that the fuzzer reaches the
//! header, the configuration and the tensors behind the checksum. The seed
//! corpus is the shipped style model and Wiener filter (`bench/fuzz.sh`).
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use mocap_clean::{CleanModel, WienerFilter};
use mocap_nn::checkpoint::seal;
use mocap_nn::device::DeviceChoice;
use mocap_style::StyleModel;

fn load_every_way(bytes: &[u8]) {
    let origin = Path::new("fuzz.safetensors");
    let _ = CleanModel::from_bytes(bytes.to_vec(), origin, DeviceChoice::Cpu);
    let _ = WienerFilter::from_bytes(bytes.to_vec(), origin);
    let _ = StyleModel::from_bytes(bytes.to_vec(), origin, DeviceChoice::Cpu);
}

fuzz_target!(|data: &[u8]| {
    load_every_way(data);
    if let Ok(sealed) = seal(data) {
        load_every_way(&sealed);
    }
});
