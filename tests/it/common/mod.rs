//! Helpers shared by the integration tests that drive the real `lbdem` binary.

use std::path::Path;
use std::process::Command;

/// Run `lbdem ARGS`; returns whether it succeeded and what it printed on stderr.
pub fn run(args: &[&str]) -> (bool, String) {
    let (code, err) = run_code(None, args);
    (code == Some(0), err)
}

/// Run `lbdem ARGS` (in `dir` when given); returns its exit code (`None` when a signal ended it,
/// so a test can tell a refusal, 1, from a panic, 101, or an abort) and its stderr.
pub fn run_code(dir: Option<&Path>, args: &[&str]) -> (Option<i32>, String) {
    let mut command = Command::new(env!("CARGO_BIN_EXE_lbdem"));
    command.args(args);
    if let Some(dir) = dir {
        command.current_dir(dir);
    }
    let o = command.output().unwrap();
    (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
}
