//! `mocap feet IN -o OUT`: planted feet held still and above the floor
//! (mocap-feet).

use std::path::PathBuf;

use mocap_feet::{plant_feet_file, FeetOptions, FeetReport};

use super::GlobalOptions;

#[derive(clap::Args)]
#[command(
    after_help = "Body parts are found by joint name; a rig the built-in tables do not know needs \
`mocap --rig RIG.toml feet ...` (docs/rigs.md).\nExamples:\n  mocap feet restyled.bvh -o planted.bvh\n  mocap --rig studio.toml feet take.bvh -o take_feet.bvh --json"
)]
pub struct Args {
    /// The take (BVH, or AMC with its ASF beside it).
    input: PathBuf,
    /// The take with its feet fixed (BVH: same skeleton and channel layout).
    #[arg(long, short)]
    output: PathBuf,
    /// The floor's height along the up axis, where the lowest foot joints (the toes) rest, in the
    /// file's units (default: estimated from the take's contacts).
    #[arg(long, value_name = "HEIGHT")]
    floor: Option<f32>,
    /// Print the report as JSON on standard output.
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args, options: &GlobalOptions) -> anyhow::Result<()> {
    options.note_if_replacing_an_input(&[&args.input], &args.output);
    let feet = FeetOptions {
        floor: args.floor,
        ..FeetOptions::default()
    };
    let report = plant_feet_file(&args.input, &args.output, &feet)?;
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
        return Ok(());
    }
    if options.quiet {
        return Ok(());
    }
    let r = &report.report;
    let leg = r.before.leg_length as f64;
    let per_leg = |v: f64| 100.0 * v / leg;
    eprintln!(
        "wrote {} ({} frames, {} rig)",
        report.output.display(),
        r.frames,
        report.rig
    );
    if r.lead_in_frames > 0 {
        eprintln!(
            "frames 0..{} left as they are and not measured: the rest pose and the blend out of it",
            r.lead_in_frames
        );
    }
    for (side, foot) in ["left", "right"].iter().zip(&r.feet) {
        eprintln!(
            "{side} foot: {} contacts over {} frames; {} frames turned, {} lifted out of the floor, \
             largest shift {:.2}",
            foot.contacts, foot.contact_frames, foot.frames_changed, foot.frames_lifted, foot.max_shift
        );
    }
    eprintln!(
        "planted-foot sliding: {:.2} -> {:.2} units/s ({:.1} -> {:.1}% of the leg a second)",
        r.before.sliding,
        r.after.sliding,
        per_leg(r.before.sliding),
        per_leg(r.after.sliding)
    );
    eprintln!(
        "below the floor ({} {:.2}): {} -> {} frames, deepest {:.2} -> {:.2}",
        if r.floor.estimated {
            "estimated at"
        } else {
            "given at"
        },
        r.floor.height,
        r.before.below_floor.frames_below,
        r.after.below_floor.frames_below,
        r.before.below_floor.max_depth,
        r.after.below_floor.max_depth
    );
    eprintln!(
        "jitter: {:.4} -> {:.4} ({:+.1}%); root lowered on {} frames (at most {:.2}); {} frames \
         changed, no joint moved more than {:.2}",
        r.before.jitter,
        r.after.jitter,
        100.0 * (r.after.jitter / r.before.jitter - 1.0),
        r.root_lowered_frames,
        r.max_root_drop,
        r.frames_changed,
        r.largest_joint_move
    );
    if r.frames_out_of_reach > 0 {
        eprintln!(
            "note: on {} frames a foot could not be held where it was: the leg does not reach",
            r.frames_out_of_reach
        );
    }
    Ok(())
}

/// One line on what the feet stage did, for the commands with `--feet`.
pub fn summary(r: &FeetReport) -> String {
    let leg = r.before.leg_length as f64;
    format!(
        "feet: planted-foot sliding {:.1} -> {:.1}% of the leg a second; frames with a foot below \
         the floor {} -> {}; jitter {:+.1}%",
        100.0 * r.before.sliding / leg,
        100.0 * r.after.sliding / leg,
        r.before.below_floor.frames_below,
        r.after.below_floor.frames_below,
        100.0 * (r.after.jitter / r.before.jitter - 1.0)
    )
}
