//! `mocap view` and `mocap render`: seeing motion (mocap-view).

use std::path::PathBuf;

use mocap_view::{render_files, FrameRange, Layout, RenderOptions, Scene, ViewerServer};
use serde_json::json;

use super::GlobalOptions;

#[derive(clap::Args)]
pub struct ViewArgs {
    /// Motions to play: BVH, ASF followed by AMC, fused or sensor captures (.jsonl).
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// Port on 127.0.0.1 (0 picks a free one).
    #[arg(long, default_value_t = 8080)]
    port: u16,
    /// Print the viewer's address as JSON (`{"url": ...}`) before serving.
    #[arg(long)]
    json: bool,
}

#[derive(clap::Args)]
pub struct RenderArgs {
    /// Motions to draw: BVH, ASF followed by AMC, fused or sensor captures (.jsonl).
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// Output: a filmstrip (.png) or an animation at the take's speed (.gif).
    #[arg(long, short)]
    output: PathBuf,
    /// Frames A..B (from 0, B excluded; `A..` and `..B` work too).
    #[arg(long, value_name = "A..B")]
    frames: Option<FrameRange>,
    /// Draw every Nth frame (default: about 8 panels for a PNG, every frame for a GIF).
    #[arg(long)]
    every: Option<usize>,
    /// Place the motions next to each other instead of on top of each other.
    #[arg(long)]
    side_by_side: bool,
    /// Print what was written as JSON.
    #[arg(long)]
    json: bool,
}

pub fn view(args: ViewArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    let scene = Scene::from_files(&args.files)?;
    let server = ViewerServer::start(&scene, args.port)?;
    if args.json {
        println!("{}", json!({ "url": server.url() }));
    } else if !options.quiet {
        eprintln!("Viewer at {}; press Ctrl-C to stop.", server.url());
    }
    server.wait();
    Ok(())
}

pub fn render(args: RenderArgs, options: &GlobalOptions) -> anyhow::Result<()> {
    let render_options = RenderOptions {
        frames: args.frames,
        every: args.every,
        layout: if args.side_by_side {
            Layout::SideBySide
        } else {
            Layout::Overlay
        },
        ..RenderOptions::default()
    };
    let summary = render_files(&args.files, &args.output, &render_options)?;
    if args.json {
        println!(
            "{}",
            json!({
                "path": summary.path,
                "frames": summary.frames,
                "width": summary.width,
                "height": summary.height,
            })
        );
    } else if !options.quiet {
        eprintln!(
            "wrote {} ({} frames, {}x{})",
            summary.path.display(),
            summary.frames.len(),
            summary.width,
            summary.height
        );
    }
    Ok(())
}
