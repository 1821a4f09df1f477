//! Tools a test needs beyond the build (h5py, gmsh, shellcheck, a tmpfs mount, ...). In CI
//! (`CI=true`) a missing one fails the test: `.ci/install-native` installs them all, so a
//! missing one there is a broken set-up, not a reason to pass. Elsewhere the test is skipped,
//! saying so where the person running the tests sees it.

use std::io::Write;

/// True when the test may go on. `available` false: in CI a panic naming `what`; elsewhere a
/// `SKIPPED:` line on the real stderr (past the test harness's capture, which hides a passing
/// test's output) and false, so the test returns.
pub fn prerequisite(what: &str, available: bool) -> bool {
    if available {
        return true;
    }
    if in_ci() {
        panic!(
            "missing prerequisite: {what} (CI=true: .ci/install-native should have installed it)"
        );
    }
    let test = std::thread::current()
        .name()
        .unwrap_or("a test")
        .to_string();
    let _ = writeln!(
        std::io::stderr().lock(),
        "SKIPPED: {test}: missing prerequisite: {what} (.ci/install-native installs it; in CI \
         this fails)"
    );
    false
}

/// `CI=true` (or `1`), as GitHub Actions, GitLab CI and `.ci/run` set it.
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v == "true" || v == "1")
}

/// Whether `python3` can import `module`.
pub fn python_has(module: &str) -> bool {
    std::process::Command::new("python3")
        .args(["-c", &format!("import {module}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// Whether `program` runs (`program --version` exits 0).
pub fn tool_runs(program: &str) -> bool {
    std::process::Command::new(program)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}
