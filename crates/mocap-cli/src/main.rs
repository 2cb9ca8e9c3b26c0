//! `mocap`: the command-line front end. It parses arguments and calls the
//! libraries; all the work happens in the `mocap-*` crates.
//!
//! Exit codes (scripts can rely on them):
//! - 0: success;
//! - 1: the input could not be used (a file missing, unreadable or malformed,
//!   a request that does not fit the data);
//! - 2: the command line itself is wrong (clap's usage errors).

mod commands;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Human motion capture toolkit: read, convert, fuse, clean, search and restyle motion.
#[derive(Parser)]
#[command(name = "mocap", version, about, long_about = None)]
struct Cli {
    /// Print nothing but results and errors (no progress bars, no notes).
    #[arg(long, short, global = true)]
    quiet: bool,
    /// A rig the built-in tables do not know: a TOML file naming its joints
    /// (`[parts] pelvis = "Becken"`...; format: docs/rigs.md). Used for
    /// every skeleton that has the joints it names; may be repeated.
    #[arg(long, global = true, value_name = "FILE")]
    rig: Vec<std::path::PathBuf>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Joints, channels, frames, frame rate, duration and bounding box of motion files.
    Info(commands::info::Args),
    /// Convert, trim, resample, mirror or rescale a motion and write it as BVH or glTF.
    Convert(commands::convert::Args),
    /// Global joint positions of every frame, as CSV or JSON.
    Positions(commands::positions::Args),
    /// Multi-sensor capture: simulate, calibrate, fuse (offline or as a UDP server), write BVH, evaluate.
    Fuse(commands::fuse::Args),
    /// Capture from calibrated RGB cameras: 2D keypoints triangulated by confidence, written as BVH.
    Cameras(commands::cameras::Args),
    /// Denoise a take (learned model or classical filter); train and evaluate denoisers.
    Clean(Box<commands::clean::Args>),
    /// Keep planted feet still and above the floor: contacts found, legs turned by two-bone IK.
    Feet(commands::feet::Args),
    /// Motion retrieval by example: index a labelled library, query it, evaluate.
    Search(commands::search::Args),
    /// Zero-shot style transfer from one example clip; train the autoencoder, evaluate.
    Style(commands::style::Args),
    /// Play motions in a local web viewer (127.0.0.1).
    View(commands::view::ViewArgs),
    /// Draw motions as a filmstrip PNG or an animated GIF.
    Render(commands::view::RenderArgs),
    /// Run the whole pipeline (fuse, clean, feet, search, restyle) on bundled data and write an HTML report.
    Demo(commands::demo::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let options = commands::GlobalOptions { quiet: cli.quiet };
    // Batch commands end quietly when what reads their output stops reading
    // (`mocap info x.bvh | head`), as Unix tools do, instead of panicking on
    // the broken pipe. Not the servers and senders (`view`, `fuse serve`,
    // `fuse send`): a peer that goes away must not stop them.
    #[cfg(unix)]
    if !matches!(&cli.command, Command::View(_))
        && !matches!(&cli.command, Command::Fuse(args) if args.is_network())
    {
        // SAFETY: called once at start-up, before any other thread exists.
        unsafe {
            libc::signal(libc::SIGPIPE, libc::SIG_DFL);
        }
    }
    #[cfg(unix)]
    remove_unfinished_files_on_signals(
        !matches!(&cli.command, Command::Fuse(args) if args.finishes_on_ctrl_c()),
    );
    // The libraries' own progress bars (training) obey --quiet too.
    mocap_nn::train::hide_progress(cli.quiet);
    for rig in &cli.rig {
        if let Err(error) = mocap_core::bodymap::register_rig_file(rig) {
            eprintln!("error: {error:#}");
            return ExitCode::from(1);
        }
    }
    // Sensor recordings (.skeleton, .jsonl) read as motions by every command.
    mocap_fuse::register_recording_readers();
    // glTF (.glb, .gltf) read by every command and written by `convert`.
    mocap_gltf::register_formats();
    let result = match cli.command {
        Command::Info(args) => commands::info::run(args, &options),
        Command::Convert(args) => commands::convert::run(args, &options),
        Command::Positions(args) => commands::positions::run(args, &options),
        Command::Fuse(args) => commands::fuse::run(args, &options),
        Command::Cameras(args) => commands::cameras::run(args, &options),
        Command::Clean(args) => commands::clean::run(*args, &options),
        Command::Feet(args) => commands::feet::run(args, &options),
        Command::Search(args) => commands::search::run(args, &options),
        Command::Style(args) => commands::style::run(args, &options),
        Command::View(args) => commands::view::view(args, &options),
        Command::Render(args) => commands::view::render(args, &options),
        Command::Demo(args) => commands::demo::run(args, &options),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            ExitCode::from(1)
        }
    }
}

/// On Ctrl-C (when `ctrl_c`), `kill` or a closed terminal, removes the
/// temporary files of the outputs being written, then ends the process with
/// 128 + the signal's number, as a shell reports it. The outputs themselves
/// are left as they were. `fuse serve` handles Ctrl-C itself: it finishes
/// and writes the take.
#[cfg(unix)]
fn remove_unfinished_files_on_signals(ctrl_c: bool) {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut wanted = vec![SIGTERM, SIGHUP];
    if ctrl_c {
        wanted.push(SIGINT);
    }
    let Ok(mut signals) = signal_hook::iterator::Signals::new(&wanted) else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            let removed = mocap_core::io::atomic::remove_unfinished_files();
            if removed > 0 {
                eprintln!(
                    "interrupted: removed {removed} unfinished output file{}",
                    if removed == 1 { "" } else { "s" }
                );
            }
            std::process::exit(128 + signal);
        }
    });
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    /// Argument groups flattened into two subcommands or more (`commands::args`
    /// and a capability's own, such as search's labels); their options are not
    /// a subcommand's own. Name a group here only when it is shared: the test
    /// checks that too.
    const SHARED_GROUPS: &[&str] = &[
        "DeviceArgs",
        "ReportArgs",
        "RestyleArgs",
        "SearchForestArgs",
        "SearchLabelArgs",
        "TrainLoopArgs",
    ];
    const MAX_OWN_OPTIONS: usize = 15;

    /// Every rule of `commands::args`, on every subcommand; the failure lists
    /// each breach with the command that breaks it.
    #[test]
    fn cli_language() {
        let mut breaches = Vec::new();
        let mut uses = vec![0; SHARED_GROUPS.len()];
        // Built, so that every option knows how many values it takes.
        let mut cli = super::Cli::command();
        cli.build();
        check(&cli, "mocap", &mut breaches, &mut uses);
        for (group, n) in SHARED_GROUPS.iter().zip(uses) {
            if n < 2 {
                breaches.push(format!("group {group} is in {n} subcommands, not shared"));
            }
        }
        assert!(breaches.is_empty(), "{}", breaches.join("\n"));
    }

    fn check(command: &clap::Command, path: &str, breaches: &mut Vec<String>, uses: &mut [usize]) {
        for sub in command.get_subcommands() {
            check(sub, &format!("{path} {}", sub.get_name()), breaches, uses);
        }
        if command.get_subcommands().next().is_some() {
            return;
        }
        let mut shared = Vec::new();
        for group in command.get_groups() {
            if let Some(i) = SHARED_GROUPS
                .iter()
                .position(|g| *g == group.get_id().as_str())
            {
                uses[i] += 1;
                shared.extend(group.get_args().map(|id| id.as_str().to_string()));
            }
        }
        let mut own = 0;
        for arg in command.get_arguments() {
            let id = arg.get_id().as_str();
            if arg.is_global_set() || arg.is_positional() || ["help", "version"].contains(&id) {
                continue;
            }
            let is_shared = shared.iter().any(|s| s == id);
            let long = arg.get_long().unwrap_or("");
            let takes_value = arg.get_num_args().is_some_and(|n| n.takes_values());
            if !is_shared {
                own += 1;
            }
            if arg.get_short() == Some('o') && long != "output" {
                breaches.push(format!("{path}: -o is --{long}, not --output"));
            }
            if ["out", "md", "output-dir", "out-dir"].contains(&long) {
                breaches.push(format!("{path}: --{long} (say --output or --markdown)"));
            }
            if long == "json" && takes_value {
                breaches.push(format!("{path}: --json takes a value (it is a switch)"));
            }
            if long == "markdown" && !takes_value {
                breaches.push(format!("{path}: --markdown takes no FILE"));
            }
            if long == "device" && !is_shared {
                breaches.push(format!(
                    "{path}: --device outside commands::args::DeviceArgs"
                ));
            }
        }
        if own > MAX_OWN_OPTIONS {
            breaches.push(format!(
                "{path}: {own} options of its own (at most {MAX_OWN_OPTIONS})"
            ));
        }
    }
}
