use std::path::PathBuf;

use anyhow::bail;
use mocap_core::io::positions::{write_positions_csv, write_positions_json};
use mocap_core::io::MotionSource;

use super::{write_output, GlobalOptions};

#[derive(clap::Args)]
pub struct Args {
    /// A BVH file, or an ASF skeleton followed by one AMC motion.
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// Write CSV: a header `frame,time,<joint>.x,...`, then one row per frame (the default).
    #[arg(long, conflicts_with = "json")]
    csv: bool,
    /// Write one JSON object with joint names, parents and positions per frame.
    #[arg(long)]
    json: bool,
    /// Output file (written atomically); standard output if absent or `-`.
    #[arg(long, short)]
    output: Option<PathBuf>,
}

pub fn run(args: Args, _options: &GlobalOptions) -> anyhow::Result<()> {
    let sources = MotionSource::group(&args.files)?;
    let [source] = sources.as_slice() else {
        bail!("`mocap positions` takes one motion, got {}", sources.len());
    };
    let motion = source.read()?;
    write_output(args.output.as_deref(), |w| {
        if args.json {
            write_positions_json(w, &motion)
        } else {
            write_positions_csv(w, &motion)
        }
    })
}
