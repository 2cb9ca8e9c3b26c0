//! The stage on files: what `mocap feet IN -o OUT` calls.

use std::path::{Path, PathBuf};

use mocap_core::bodymap::BodyMap;
use mocap_core::io::{read_motion, write_motion};
use mocap_core::{Error, Motion, Result};
use serde::{Deserialize, Serialize};

use crate::plant::{plant_feet, FeetOptions, FeetReport};

/// What [`plant_feet_file`] did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FeetFileReport {
    pub input: PathBuf,
    pub output: PathBuf,
    /// The rig the body parts were found with (`BodyMap::rig`).
    pub rig: String,
    #[serde(flatten)]
    pub report: FeetReport,
}

/// Reads `input` (BVH, or AMC with its ASF), finds its body parts
/// ([`BodyMap::detect`]: the built-in rigs, or a rig file registered with
/// `mocap_core::bodymap::register_rig_file`), runs [`plant_feet`] and
/// writes the result to `output` as BVH (atomically: nothing is written on
/// an error). Errors name the input.
pub fn plant_feet_file(
    input: &Path,
    output: &Path,
    options: &FeetOptions,
) -> Result<FeetFileReport> {
    let motion = read_motion(input)?;
    let named = |e: Error| match e {
        Error::Invalid(message) => Error::Invalid(format!("{}: {message}", input.display())),
        other => other,
    };
    let (planted, rig, report) = plant_feet_detected(&motion, options).map_err(named)?;
    write_motion(output, &planted)?;
    Ok(FeetFileReport {
        input: input.to_path_buf(),
        output: output.to_path_buf(),
        rig,
        report,
    })
}

/// [`plant_feet`] with the body parts found by [`BodyMap::detect`]; also
/// returns the rig they were found with.
pub fn plant_feet_detected(
    motion: &Motion,
    options: &FeetOptions,
) -> Result<(Motion, String, FeetReport)> {
    let map = BodyMap::detect(motion.skeleton())?;
    let (planted, report) = plant_feet(motion, &map, options)?;
    Ok((planted, map.rig().to_string(), report))
}

/// What another command's `--feet` runs on its output before writing it:
/// [`plant_feet_detected`] when `options` is given, else `motion` as it is.
pub fn plant_feet_if_asked(
    motion: Motion,
    options: Option<&FeetOptions>,
) -> Result<(Motion, Option<FeetReport>)> {
    match options {
        Some(options) => {
            let (planted, _, report) = plant_feet_detected(&motion, options)?;
            Ok((planted, Some(report)))
        }
        None => Ok((motion, None)),
    }
}
