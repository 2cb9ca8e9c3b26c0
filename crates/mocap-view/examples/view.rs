//! Stand-in for `mocap view` and `mocap render` until the CLI wires them:
//!
//! ```text
//! cargo run -p mocap-view --example view -- view FILE... [--port P]
//! cargo run -p mocap-view --example view -- render FILE... -o out.gif|out.png [--frames A..B] [--every N] [--side]
//! ```

use std::path::PathBuf;
use std::process::ExitCode;

use mocap_view::render::{FrameRange, Layout, RenderOptions};
use mocap_view::{render, serve, Scene};

fn main() -> ExitCode {
    match run(std::env::args().skip(1).collect()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
    }
}

fn run(args: Vec<String>) -> Result<(), String> {
    let usage = "usage: view view FILE... [--port P] | view render FILE... -o OUT.png|OUT.gif [--frames A..B] [--every N] [--side]";
    let (command, rest) = args.split_first().ok_or(usage)?;
    let mut files = Vec::new();
    let mut port = 8080u16;
    let mut output = None;
    let mut frames = None;
    let mut every = None;
    let mut layout = Layout::Overlay;
    let mut it = rest.iter();
    while let Some(arg) = it.next() {
        let mut value = || it.next().ok_or(format!("{arg} needs a value"));
        match arg.as_str() {
            "--port" => port = value()?.parse().map_err(|_| "--port needs a number")?,
            "-o" | "--output" => output = Some(PathBuf::from(value()?)),
            "--frames" => frames = Some(value()?.parse::<FrameRange>().map_err(|e| e.to_string())?),
            "--every" => every = Some(value()?.parse().map_err(|_| "--every needs a number")?),
            "--side" => layout = Layout::SideBySide,
            s if s.starts_with('-') => return Err(format!("unknown option {s}\n{usage}")),
            s => files.push(PathBuf::from(s)),
        }
    }
    let scene = Scene::from_files(&files).map_err(|e| e.to_string())?;
    match command.as_str() {
        "view" => serve(&scene, port).map_err(|e| e.to_string()),
        "render" => {
            let output = output.ok_or("render needs -o OUT.png or -o OUT.gif")?;
            let options = RenderOptions {
                frames,
                every,
                layout,
                ..RenderOptions::default()
            };
            let summary = render(&scene, &output, &options).map_err(|e| e.to_string())?;
            println!(
                "wrote {} ({} x {}, {} frames)",
                summary.path.display(),
                summary.width,
                summary.height,
                summary.frames.len()
            );
            Ok(())
        }
        _ => Err(usage.to_string()),
    }
}
