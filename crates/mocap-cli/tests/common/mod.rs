//! What the command-line tests share: running the built `mocap` binary.

use std::process::{Command, Output};

/// Runs `mocap` with `args` and returns what it printed and its status.
pub fn mocap(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_mocap"))
        .args(args)
        .output()
        .expect("the mocap binary runs")
}

/// A command's standard error, as text.
#[allow(dead_code)] // not every test file reads it
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}
