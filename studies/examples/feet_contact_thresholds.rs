//! How many contacts the feet stage finds, and how much sliding it leaves,
//! as the contact thresholds are loosened: on the takes given (e.g. the
//! bundled walk and the demo's cleaned fused take, `clean/cleaned.bvh` of
//! `mocap demo -o DIR`). Heights in leg lengths above the foot joint's
//! lowest, speeds in leg lengths per second, touch-down / lift-off.
//!
//! cargo run --release -p mocap-studies --example feet_contact_thresholds -- TAKE.bvh...

use mocap_core::bodymap::BodyMap;
use mocap_core::io::bvh::read_bvh;
use mocap_feet::plant_feet;
use mocap_studies::feet::{with_thresholds, CONTACT_THRESHOLDS};

type Error = Box<dyn std::error::Error>;

fn main() -> Result<(), Error> {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    if paths.is_empty() {
        return Err("TAKE.bvh...".into());
    }
    println!("| take | heights | speeds | contact frames (left + right) of | sliding before → after (cm/s) |");
    println!("| --- | --- | --- | --- | --- |");
    for path in &paths {
        let take = read_bvh(path.as_ref())?;
        let map = BodyMap::detect(take.skeleton())?;
        for thresholds in CONTACT_THRESHOLDS {
            let (enter_height, leave_height, enter_speed, leave_speed) = thresholds;
            let options = with_thresholds(thresholds);
            let (_, report) = plant_feet(&take, &map, &options)?;
            println!(
                "| {path} | {enter_height}/{leave_height} | {enter_speed}/{leave_speed} | {} + {} of {} | {:.1} → {:.1} |",
                report.feet[0].contact_frames,
                report.feet[1].contact_frames,
                report.frames,
                report.before.sliding,
                report.after.sliding
            );
        }
    }
    Ok(())
}
