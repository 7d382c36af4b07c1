//! Running the `sinew` binary from integration tests: the command, scratch folders, and the
//! bad-input contract (exit code 2, one line on stderr, no panic).
//!
//! Kept apart from `tests/common`, which benchmarks include too: `CARGO_BIN_EXE_sinew` exists
//! only when integration tests are compiled, and only with the `cli` feature (the binary's):
//! without it only the scratch folders are here.
#![allow(dead_code)]

use std::path::Path;
#[cfg(feature = "cli")]
use std::path::PathBuf;
#[cfg(feature = "cli")]
use std::process::{Command, Output};

/// The exit code of every bad-input failure.
pub const EXIT_BAD_INPUT: i32 = 2;

/// Runs the binary with `args`.
#[cfg(feature = "cli")]
pub fn sinew(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sinew"))
        .args(args)
        .output()
        .expect("run sinew")
}

/// Scratch folders removed when a test ends, shared with the library's unit tests (the
/// module's doc tells how to keep them: `SINEW_KEEP_TEST_DIRS=1`).
#[path = "../../src/test_scratch.rs"]
pub mod test_scratch;

/// An empty folder of its own for one test (named after the test file and `name`), removed
/// when the result drops: keep it alive while the `sinew` it runs may still write there.
pub fn scratch(name: &str) -> tempfile::TempDir {
    test_scratch::scratch(&format!("{}-{name}", module_path!().replace("::", "-")))
}

/// A path as a command-line argument.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `sinew rig IMAGES --handles DIR/handles.json -o DIR/rig.json EXTRA...` with `handles_json`
/// written to that handles file; asserts success. Returns the rig document and its path.
#[cfg(feature = "cli")]
pub fn rig_cli(
    dir: &Path,
    images: &[&Path],
    handles_json: &str,
    extra: &[&str],
) -> (serde_json::Value, PathBuf) {
    let handles = dir.join("handles.json");
    std::fs::write(&handles, handles_json).unwrap();
    let rig = dir.join("rig.json");
    let mut args = vec!["rig"];
    args.extend(images.iter().map(|p| s(p)));
    args.extend(["--handles", s(&handles), "-o", s(&rig)]);
    args.extend_from_slice(extra);
    let out = sinew(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc = serde_json::from_str(&std::fs::read_to_string(&rig).unwrap()).unwrap();
    (doc, rig)
}

/// Runs a command that must fail on bad input, checks the contract and that the message
/// mentions `expect_in_message`; returns stderr.
#[cfg(feature = "cli")]
pub fn assert_bad_input(args: &[&str], expect_in_message: &str) -> String {
    let out = sinew(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(
        out.status.code(),
        Some(EXIT_BAD_INPUT),
        "{args:?}: stderr {stderr}"
    );
    assert_eq!(
        stderr.trim_end().lines().count(),
        1,
        "{args:?}: not one line: {stderr}"
    );
    assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    assert!(
        stderr.contains(expect_in_message),
        "{args:?}: '{stderr}' lacks '{expect_in_message}'"
    );
    stderr
}
