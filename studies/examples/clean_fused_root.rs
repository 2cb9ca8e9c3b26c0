//! Where the noise of a fused capture is: the demo's chain fuses each take
//! (3 simulated Kinect v2 sensors over UDP, retargeted onto the take's rig),
//! then Butterworth filters run on the local rotations alone (what
//! `mocap clean apply --filter` does) and on the rotations and the root's
//! translation together. Errors against the take itself.
//!
//! `cargo run --release -p mocap-studies --example clean_fused_root -- TAKE.bvh...`
//! (docs/research/clean.md, "Fused captures").

use mocap_clean::{filter_motion, filter_translations, Filter};
use mocap_core::io::bvh::read_bvh;
use mocap_core::metrics::{jitter, mean_joint_position_error};
use mocap_core::ops::trim;
use mocap_core::{forward_kinematics, Motion};
use mocap_demo::{run_demo, DemoOptions};

/// `motion` with `filter` on its local rotations, and on its translation
/// channels too when `translations`.
fn filtered(motion: &Motion, filter: &Filter, translations: bool) -> Motion {
    let out = filter_motion(motion, filter).expect("a valid filter");
    if translations {
        filter_translations(&out, filter).expect("a valid filter")
    } else {
        out
    }
}

/// Mean joint position error (mm, the takes are in cm) and jitter
/// (mm/frame³) of `motion` against `truth`.
fn errors(motion: &Motion, truth: &Motion) -> (f32, f32) {
    let (p, t) = (forward_kinematics(motion), forward_kinematics(truth));
    (
        10.0 * mean_joint_position_error(&p, &t, None).unwrap(),
        10.0 * jitter(&p, None).unwrap(),
    )
}

fn main() {
    let work = tempfile::tempdir().unwrap();
    let filters = ["butterworth-gcv:2", "butterworth:2:3", "butterworth:2:4"];
    println!(
        "| take | fused | {} |",
        filters
            .map(|f| format!("{f}: rotations | {f}: rotations and root"))
            .join(" | ")
    );
    println!("|{}", " --- |".repeat(2 + 2 * filters.len()));
    for path in std::env::args().skip(1) {
        let sample = read_bvh(path.as_ref()).unwrap();
        let out = work.path().join("demo");
        let options = DemoOptions {
            out: out.clone(),
            sample: path.clone().into(),
            pictures: false,
            ..DemoOptions::default()
        };
        run_demo(&options).unwrap();
        let fused = read_bvh(&out.join("fuse/fused-on-sample-rig.bvh")).unwrap();
        // The fused take starts at the server's first instant, a frame or
        // two into the take: aligned where it is closest to the take.
        let aligned = |offset: usize| {
            let n = fused.frame_count().min(sample.frame_count() - offset);
            (
                trim(&fused, 0..n).unwrap(),
                trim(&sample, offset..offset + n).unwrap(),
            )
        };
        let (fused, truth) = (0..4)
            .map(aligned)
            .min_by(|a, b| errors(&a.0, &a.1).0.total_cmp(&errors(&b.0, &b.1).0))
            .unwrap();
        let cell = |(e, j): (f32, f32)| format!("{e:.1} mm, {j:.1}");
        let mut row = vec![
            std::path::Path::new(&path)
                .file_stem()
                .unwrap()
                .to_string_lossy()
                .into_owned(),
            format!(
                "{} (take {:.1})",
                cell(errors(&fused, &truth)),
                errors(&truth, &truth).1
            ),
        ];
        for spec in filters {
            let filter: Filter = spec.parse().unwrap();
            for translations in [false, true] {
                row.push(cell(errors(
                    &filtered(&fused, &filter, translations),
                    &truth,
                )));
            }
        }
        println!("| {} |", row.join(" | "));
    }
}
