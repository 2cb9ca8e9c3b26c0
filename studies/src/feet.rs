//! Setup shared by the feet studies.

use mocap_feet::{ContactOptions, FeetOptions};

/// Contact thresholds tried: the stage's default (first), then from the
/// strictest to the loosest: enter and leave heights in leg lengths above the foot joint's
/// lowest, enter and leave speeds in leg lengths per second.
pub const CONTACT_THRESHOLDS: [(f32, f32, f32, f32); 6] = [
    (0.05, 0.08, 1.0, 1.4),
    (0.04, 0.07, 0.6, 1.0),
    (0.06, 0.09, 0.6, 1.0),
    (0.04, 0.07, 0.9, 1.3),
    (0.06, 0.09, 0.9, 1.3),
    (0.08, 0.11, 1.2, 1.6),
];

/// The stage's options with the contact thresholds `(enter height, leave
/// height, enter speed, leave speed)`.
pub fn with_thresholds(
    (enter_height, leave_height, enter_speed, leave_speed): (f32, f32, f32, f32),
) -> FeetOptions {
    FeetOptions {
        contacts: ContactOptions {
            enter_height,
            leave_height,
            enter_speed,
            leave_speed,
            ..Default::default()
        },
        ..Default::default()
    }
}
