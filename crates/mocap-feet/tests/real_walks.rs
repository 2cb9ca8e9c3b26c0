//! The feet stage on real Bandai walks (held-out dataset-2 takes).

use mocap_core::bodymap::{BodyMap, BodyPart};
use mocap_core::io::read_motion;
use mocap_core::ops::trim;
use mocap_core::rotation::Vec3;
use mocap_core::{forward_kinematics, Motion};
use mocap_feet::{estimate_floor, measure_feet, plant_feet, ContactOptions, FeetOptions};

fn walk(name: &str) -> Option<Motion> {
    let path = mocap_testdata::shared("bandai/dataset-2")?.join(name);
    Some(read_motion(&path).unwrap())
}

/// `motion` with its root moved by `offset(seconds)`.
fn moved(motion: &Motion, offset: impl Fn(f32) -> Vec3) -> Motion {
    let mut out = motion.clone();
    let fps = motion.fps() as f32;
    for f in 0..out.frame_count() {
        let t = out.local_translation(f, 0);
        out.set_local_translation(f, 0, t + offset(f as f32 / fps));
    }
    out
}

#[test]
fn a_dragged_walk_stops_sliding() {
    let Some(real) = walk("dataset-2_walk_normal_022.bvh") else {
        return;
    };
    let map = BodyMap::detect(real.skeleton()).unwrap();
    let leg = map.leg_length(real.skeleton()).unwrap();
    // The root dragged sideways at half a leg per second (40 cm/s): the
    // planted feet slide with it.
    let dragged = moved(&real, |t| Vec3::new(0.5 * leg * t, 0.0, 0.0));
    let floor = estimate_floor(&real, &map, &ContactOptions::default(), None).unwrap();
    let real_sliding = measure_feet(&real, &map, &floor).unwrap().sliding;
    let (fixed, report) = plant_feet(&dragged, &map, &FeetOptions::default()).unwrap();
    assert!(
        report.before.sliding > 4.0 * real_sliding,
        "{real_sliding} -> {}",
        report.before.sliding
    );
    // 53.0 -> 10.2 % of the leg a second, against the real walk's 7.1.
    assert!(
        report.after.sliding < 1.6 * real_sliding,
        "real {real_sliding}: {} -> {}",
        report.before.sliding,
        report.after.sliding
    );
    assert!(report.feet[0].contacts >= 6 && report.feet[1].contacts >= 6);
    assert!(report.after.jitter < 1.1 * report.before.jitter);
    assert_eq!(report.after.below_floor.frames_below, 0);
    // The measures in the report are those of the output.
    let again = measure_feet(&fixed, &map, &report.floor).unwrap();
    assert!((again.sliding - report.after.sliding).abs() < 1e-6 * (1.0 + again.sliding));
    // Same skeleton, channels, frames; only the legs and the root change.
    assert_eq!(fixed.skeleton(), dragged.skeleton());
    assert_eq!(fixed.frame_count(), dragged.frame_count());
    assert_eq!(fixed.frame_time(), dragged.frame_time());
    let (before, after) = (forward_kinematics(&dragged), forward_kinematics(&fixed));
    let head = map.joint(BodyPart::Head).unwrap();
    let pelvis = map.joint(BodyPart::Pelvis).unwrap();
    for f in 0..fixed.frame_count() {
        let rel = |p: &mocap_core::GlobalPoses| p.position(f, head) - p.position(f, pelvis);
        assert!((rel(&before) - rel(&after)).length() < 1e-3);
        // The root only goes down, and not by much.
        let down = before.position(f, pelvis).y - after.position(f, pelvis).y;
        assert!((-1e-3..0.1 * leg).contains(&down), "frame {f}: {down}");
    }
    // The ankles keep their orientation.
    let ankle = map.joint(BodyPart::LeftAnkle).unwrap();
    for f in 0..fixed.frame_count() {
        let angle = before
            .rotation(f, ankle)
            .angle_between(after.rotation(f, ankle));
        assert!(angle < 1e-2, "frame {f}: the ankle turned {angle}");
    }
}

#[test]
fn a_clean_walk_is_left_almost_as_it_was() {
    for name in [
        "dataset-2_walk_normal_022.bvh",
        "dataset-2_walk-turn-left_masculine_028.bvh",
        "dataset-2_walk_elderly_016.bvh",
    ] {
        let Some(real) = walk(name) else {
            return;
        };
        let map = BodyMap::detect(real.skeleton()).unwrap();
        let leg = map.leg_length(real.skeleton()).unwrap();
        let (_, report) = plant_feet(&real, &map, &FeetOptions::default()).unwrap();
        // At most 2.2% of the leg (1.8 cm) on the held-out walks.
        assert!(
            report.largest_joint_move < 0.03 * leg,
            "{name}: a joint moved {}",
            report.largest_joint_move
        );
        assert!(report.after.jitter < 1.02 * report.before.jitter, "{name}");
        assert!(report.after.sliding < report.before.sliding + 0.01 * leg as f64);
        assert!(report.feet.iter().all(|f| f.contacts >= 4), "{name}");
    }
}

#[test]
fn a_body_sunk_into_the_floor_is_lifted_out() {
    let Some(real) = walk("dataset-2_walk_masculine_025.bvh") else {
        return;
    };
    let map = BodyMap::detect(real.skeleton()).unwrap();
    let leg = map.leg_length(real.skeleton()).unwrap();
    let floor = estimate_floor(&real, &map, &ContactOptions::default(), None).unwrap();
    // The whole body 6 cm down over the middle second, eased in and out.
    let sunk = moved(&real, |t| {
        let w = (std::f32::consts::PI * ((t - 3.0) / 2.0).clamp(0.0, 1.0)).sin();
        Vec3::new(0.0, -0.075 * leg * w, 0.0)
    });
    let options = FeetOptions {
        floor: Some(floor.height),
        ..FeetOptions::default()
    };
    let (_, report) = plant_feet(&sunk, &map, &options).unwrap();
    assert_eq!(report.floor.height, floor.height);
    assert!(!report.floor.estimated);
    assert!(
        report.before.below_floor.frames_below > 20 && report.before.below_floor.max_depth > 4.0,
        "{:?}",
        report.before.below_floor
    );
    assert_eq!(
        report.after.below_floor.frames_below, 0,
        "{:?}",
        report.after.below_floor
    );
}

#[test]
fn a_take_too_short_and_a_rig_without_feet_are_refused() {
    let Some(real) = walk("dataset-2_walk_normal_022.bvh") else {
        return;
    };
    let map = BodyMap::detect(real.skeleton()).unwrap();
    let short = trim(&real, 0..2).unwrap();
    let error = plant_feet(&short, &map, &FeetOptions::default())
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("feet stage") && error.contains("this take has 2"),
        "{error}"
    );
    let legless = BodyMap::from_joints(
        real.skeleton(),
        "no feet",
        map.parts().filter(|(p, _)| {
            !matches!(
                p,
                BodyPart::LeftAnkle | BodyPart::RightAnkle | BodyPart::RightKnee
            )
        }),
    )
    .unwrap();
    let error = plant_feet(&real, &legless, &FeetOptions::default())
        .unwrap_err()
        .to_string();
    for part in ["left_ankle", "right_knee", "right_ankle", "--rig"] {
        assert!(error.contains(part), "{error}");
    }
}

#[test]
fn a_take_that_starts_at_the_rest_pose_keeps_those_frames() {
    let Some(dir) = mocap_testdata::shared("other-rigs/cmu-daz/07") else {
        return;
    };
    // A CMU walk converted for Daz: frame 0 is the rest pose, frames 1-4
    // blend out of it.
    let take = read_motion(&dir.join("07_01.bvh")).unwrap();
    let map = BodyMap::detect(take.skeleton()).unwrap();
    let (planted, report) = plant_feet(&take, &map, &FeetOptions::default()).unwrap();
    assert_eq!(report.lead_in_frames, 5);
    assert_eq!(report.frames, take.frame_count());
    assert_eq!(planted.frame_count(), take.frame_count());
    for f in 0..5 {
        assert_eq!(planted.frame(f), take.frame(f), "frame {f}");
    }
    // The rest is planted and measured as the take without its lead-in.
    let motion = trim(&take, 5..take.frame_count()).unwrap();
    let (alone, alone_report) = plant_feet(&motion, &map, &FeetOptions::default()).unwrap();
    assert_eq!(alone_report.lead_in_frames, 0);
    assert_eq!(report.before, alone_report.before);
    assert_eq!(report.after, alone_report.after);
    for f in 0..alone.frame_count() {
        assert_eq!(planted.frame(f + 5), alone.frame(f), "frame {f}");
    }
}
