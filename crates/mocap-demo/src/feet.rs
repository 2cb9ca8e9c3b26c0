//! Stage 3: the cleaned take's planted feet held still and above the floor
//! (mocap-feet: contacts, two-bone IK within the legs' reach). The sliding
//! is compared with the sample's own, measured the same way.

use mocap_core::bodymap::BodyMap;
use mocap_core::io::bvh::{read_bvh, write_bvh};
use mocap_feet::{estimate_floor, measure_feet, plant_feet, FeetOptions};
use mocap_view::{render_files, RenderOptions};

use crate::chain::{errors_against_truth, ChainTake};
use crate::{units_per_metre, viewer_command, StageContext, StageReport, StageResult};

pub(crate) fn run(context: &StageContext, report: &mut StageReport) -> StageResult {
    let options = context.options;
    let take = context.take()?;
    let sample = read_bvh(&options.sample)?;
    let input = read_bvh(&take.path)?;
    let map = BodyMap::detect(input.skeleton())?;
    let feet_options = FeetOptions::default();
    let (planted, feet) = plant_feet(&input, &map, &feet_options)?;
    let path = context.path("feet", "planted.bvh")?;
    write_bvh(&path, &planted)?;
    report.output(
        StageContext::relative("feet", "planted.bvh"),
        "the take with its planted feet held still: what the next stages get",
    );
    report.viewer_command = Some(viewer_command(&[&options.sample, &take.path, &path]));
    report.fact("input", take.path.display().to_string());

    // The sample on its own floor, measured as the take is.
    let sample_map = BodyMap::detect(sample.skeleton())?;
    let sample_floor = estimate_floor(&sample, &sample_map, &feet_options.contacts, None)?;
    let sample_feet = measure_feet(&sample, &sample_map, &sample_floor)?;

    let cm = 100.0 / units_per_metre(&sample) as f64;
    report.number(
        "sliding_before_cm_s",
        "planted-foot sliding of the input (flat feet on the floor)",
        feet.before.sliding * cm,
        "cm/s",
    );
    report.number(
        "sliding_after_cm_s",
        "planted-foot sliding after the feet stage",
        feet.after.sliding * cm,
        "cm/s",
    );
    report.number(
        "sliding_sample_cm_s",
        "planted-foot sliding of the sample itself (a real optical capture)",
        sample_feet.sliding * cm,
        "cm/s",
    );
    report.number(
        "frames_below_floor_before",
        "frames with a foot joint below the floor, input",
        feet.before.below_floor.frames_below as f64,
        "",
    );
    report.number(
        "frames_below_floor_after",
        "frames with a foot joint below the floor, after",
        feet.after.below_floor.frames_below as f64,
        "",
    );
    let mm = 10.0 * cm;
    report.number(
        "jitter_before",
        "mean jerk of the input's joints (mm/frame³)",
        feet.before.jitter as f64 * mm,
        "mm/frame³",
    );
    report.number(
        "jitter_after",
        "mean jerk after the feet stage (mm/frame³)",
        feet.after.jitter as f64 * mm,
        "mm/frame³",
    );
    let before = errors_against_truth(&input, &sample, take.first_time)?;
    let after = errors_against_truth(&planted, &sample, take.first_time)?;
    report.number(
        "position_error_before_mm",
        "input vs sample, mean per-joint position error",
        before.position_mm,
        "mm",
    );
    report.number(
        "position_error_after_mm",
        "after the feet stage vs sample, mean per-joint position error",
        after.position_mm,
        "mm",
    );
    report.number(
        "contacts",
        "foot contacts found (both feet)",
        (feet.feet[0].contacts + feet.feet[1].contacts) as f64,
        "",
    );
    report.fact("from", format!("the take of the {} stage", take.stage));
    context.pass_on(ChainTake {
        path: path.clone(),
        stage: "feet",
        first_time: take.first_time,
    });

    if options.pictures {
        let strip = context.path("feet", "input_planted.png")?;
        render_files(
            &[take.path.clone(), path.clone()],
            &strip,
            &RenderOptions::default(),
        )?;
        report.picture(
            StageContext::relative("feet", "input_planted.png"),
            "the input and the take with planted feet, overlaid",
        );
    }
    Ok(())
}
