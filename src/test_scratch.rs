//! Scratch folders for tests: every test that writes files gets an empty folder of its own,
//! `sinew-NAME-XXXXXX` (random suffix) in the system's temp folder, removed when the returned
//! [`TempDir`] is dropped: at the end of the test, pass or fail (a drop runs while a panic
//! unwinds). Keep the `TempDir` alive as long as anything still uses the folder (a background
//! thread, a child process): drop it after joining or waiting for them.
//!
//! To inspect a test's files, run it with `SINEW_KEEP_TEST_DIRS=1` in the environment: the
//! folders are then kept and each one's path is printed on stderr (libtest shows it for a
//! failing test, or for all with `--nocapture`). Remove them by hand afterwards.
//!
//! The library's unit tests use this module as `crate::test_scratch`; the integration tests
//! include the same file through `tests/command/mod.rs`.

use tempfile::TempDir;

/// The environment variable that keeps the scratch folders (any value but `0` or empty).
pub const KEEP_VAR: &str = "SINEW_KEEP_TEST_DIRS";

/// Whether [`KEEP_VAR`] asks to keep the scratch folders.
pub fn keep_requested() -> bool {
    std::env::var_os(KEEP_VAR).is_some_and(|v| !v.is_empty() && v != "0")
}

/// A fresh, empty folder `sinew-NAME-XXXXXX` in the system's temp folder, removed when the
/// result is dropped (kept with [`KEEP_VAR`], see the module's doc).
pub fn scratch(name: &str) -> TempDir {
    let prefix = format!("sinew-{name}-");
    let mut dir = tempfile::Builder::new()
        .prefix(&prefix)
        .tempdir()
        .expect("a scratch folder in the temp folder");
    if keep_requested() {
        dir.disable_cleanup(true);
        eprintln!("{KEEP_VAR}: keeping {}", dir.path().display());
    }
    dir
}
