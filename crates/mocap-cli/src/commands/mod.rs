//! One module per subcommand: its arguments and a `run` that calls the
//! libraries.

pub mod args;
pub mod cameras;
pub mod clean;
pub mod convert;
pub mod demo;
pub mod feet;
pub mod fuse;
pub mod info;
pub mod positions;
pub mod search;
pub mod style;
pub mod view;

use std::io::Write;
use std::path::Path;

/// Options every subcommand sees.
pub struct GlobalOptions {
    pub quiet: bool,
}

impl GlobalOptions {
    /// A progress bar on standard error, hidden with `--quiet` (indicatif also
    /// hides it when standard error is not a terminal).
    pub fn progress(&self, len: usize, message: &'static str) -> indicatif::ProgressBar {
        if self.quiet {
            return indicatif::ProgressBar::hidden();
        }
        let bar = indicatif::ProgressBar::new(len as u64);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} {wide_msg}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar.set_message(message);
        bar
    }

    /// Says so when `output` is one of `inputs`: writing there is allowed (a
    /// take cleaned in place), but a mistyped path loses a take, so the user
    /// is told which input the output replaces.
    pub fn note_if_replacing_an_input(&self, inputs: &[&Path], output: &Path) {
        let Ok(out) = output.canonicalize() else {
            return; // the output does not exist yet: it replaces nothing
        };
        let replaced = inputs
            .iter()
            .any(|input| input.canonicalize().is_ok_and(|i| i == out));
        if replaced && !self.quiet {
            eprintln!(
                "note: the output {} is also an input: the input is replaced",
                output.display()
            );
        }
    }
}

/// Writes `text` to `path` atomically, or to standard output for `None` or `-`.
pub fn write_output(
    path: Option<&Path>,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> anyhow::Result<()> {
    match path {
        Some(p) if p != Path::new("-") => {
            mocap_core::io::atomic::write_atomically(p, write)?;
        }
        _ => {
            let stdout = std::io::stdout();
            let mut lock = std::io::BufWriter::new(stdout.lock());
            let result = write(&mut lock).and_then(|()| lock.flush());
            match result {
                // A reader that stops early (`| head`) is not an error.
                Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {}
                other => other?,
            }
        }
    }
    Ok(())
}
