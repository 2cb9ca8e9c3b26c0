//! # mocap-feet
//!
//! Feet that stay planted, as one stage any motion can go through: a
//! captured, fused, cleaned or restyled take whose feet slide on the ground
//! or sink through the floor comes out with its planted feet held still,
//! no foot below the floor and the root lowered only where a leg cannot
//! reach, on the same skeleton and channels.
//!
//! - contacts are found from the motion: the height and speed of each
//!   foot's ankle and toe, with hysteresis and a shortest contact
//!   ([`ContactOptions`]);
//! - the floor is estimated from the contacts, or given ([`Floor`]);
//! - planted feet are pinned by two-bone IK of hip and knee
//!   ([`mocap_core::kinematics::two_bone_ik`]) within the legs' reach, with
//!   smooth blends in and out, the ankle keeping its orientation
//!   ([`plant_feet`], [`FeetOptions`]);
//! - the result is measured before and after on the input's floor:
//!   planted-foot sliding, feet below the floor, jitter ([`FeetMeasures`],
//!   from [`mocap_core::metrics`]);
//! - [`plant_feet_file`]: the stage from file to file (`mocap feet`).
//!
//! ```no_run
//! use mocap_core::bodymap::BodyMap;
//! use mocap_core::io::{read_motion, write_motion};
//! use mocap_feet::{plant_feet, FeetOptions};
//!
//! let motion = read_motion("restyled.bvh".as_ref())?;
//! let map = BodyMap::detect(motion.skeleton())?;
//! let (planted, report) = plant_feet(&motion, &map, &FeetOptions::default())?;
//! println!("sliding {:.1} -> {:.1} units/s", report.before.sliding, report.after.sliding);
//! write_motion("planted.bvh".as_ref(), &planted)?;
//! # Ok::<(), mocap_core::Error>(())
//! ```

mod contacts;
mod file;
mod floor;
mod ground;
mod plant;

pub use contacts::{ContactOptions, FLOOR_QUANTILE};
pub use file::{plant_feet_detected, plant_feet_file, plant_feet_if_asked, FeetFileReport};
pub use floor::{
    estimate_floor, measure_feet, FeetMeasures, Floor, BELOW_FLOOR_TOLERANCE, MIN_FRAMES,
};
pub use plant::{plant_feet, FeetOptions, FeetReport, FootReport};
