//! The Python with python-control, NumPy and SciPy that the export tests run (`STIRLING_PYTHON`,
//! as `.ci/run` exports it; else `python3`). Missing, it fails the test: never skipped.

use std::process::Command;

/// How `.ci/run` sets the Python up, for the failure messages.
pub const SETUP: &str =
    "python3 -m venv target/pyenv && target/pyenv/bin/pip install -q control numpy scipy \
&& export STIRLING_PYTHON=$PWD/target/pyenv/bin/python (as .ci/run does)";

/// The Python that has python-control and SciPy, or a failure saying how to get one.
pub fn python() -> String {
    let (py, from_env) = match std::env::var("STIRLING_PYTHON") {
        Ok(p) if !p.is_empty() => (p, true),
        _ => ("python3".to_string(), false),
    };
    let probe = Command::new(&py)
        .args(["-c", "import control, scipy"])
        .output();
    match probe {
        Ok(o) if o.status.success() => py,
        Ok(o) => panic!(
            "python-control is not importable by {py}{}: {}\nset it up with: {SETUP}",
            if from_env {
                " (STIRLING_PYTHON)"
            } else {
                " (STIRLING_PYTHON is unset)"
            },
            String::from_utf8_lossy(&o.stderr).trim()
        ),
        Err(e) => panic!(
            "cannot run {py}{}: {e}\nset it up with: {SETUP}",
            if from_env {
                " (STIRLING_PYTHON)"
            } else {
                " (STIRLING_PYTHON is unset)"
            }
        ),
    }
}
