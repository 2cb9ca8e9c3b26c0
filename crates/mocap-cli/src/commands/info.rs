//! `mocap info`: what motion files hold (mocap-core).

use std::path::PathBuf;

use anyhow::Context;
use mocap_core::info::describe_files;

use super::GlobalOptions;

#[derive(clap::Args)]
pub struct Args {
    /// Motion files: BVH, an ASF skeleton followed by its AMC motions, or one sensor's recording (.skeleton, .jsonl).
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// Print one JSON array with an object per motion.
    #[arg(long)]
    json: bool,
}

pub fn run(args: Args, options: &GlobalOptions) -> anyhow::Result<()> {
    let progress = options.progress(0, "reading");
    let infos = describe_files(&args.files, &mut |done, total| {
        progress.set_length(total as u64);
        progress.set_position(done as u64);
    })?;
    progress.finish_and_clear();
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&infos).context("writing JSON")?
        );
    } else {
        for info in &infos {
            print!("{}", info.to_text());
        }
    }
    Ok(())
}
