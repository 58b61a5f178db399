//! Helpers shared by the integration tests that drive the real `lbdem` binary.

use std::process::Command;

/// Run `lbdem ARGS`; returns whether it succeeded and what it printed on stderr.
pub fn run(args: &[&str]) -> (bool, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_lbdem"))
        .args(args)
        .output()
        .unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}
