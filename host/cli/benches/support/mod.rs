//! What the benches that drive the `sweephold` binary share.

use std::process::Command;

/// Run `binary` with `args`; a failure stops the bench with the command and its stderr.
pub fn run_sweephold<S: AsRef<str>>(binary: &str, args: &[S]) {
    let args: Vec<&str> = args.iter().map(AsRef::as_ref).collect();
    let output = Command::new(binary)
        .args(&args)
        .output()
        .unwrap_or_else(|e| panic!("cannot run {binary}: {e}"));
    assert!(
        output.status.success(),
        "sweephold {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&output.stderr)
    );
}
