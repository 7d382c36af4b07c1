//! The rules every shell follows before it writes: an output never names an input (a sprite
//! written over with rig JSON, say) nor another output, and lies in a folder that exists. The
//! CLI checks its outputs with these before any work; the editor's exports check theirs with
//! the same functions.

use std::path::{Path, PathBuf};

/// Why the outputs cannot be written; nothing was written.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum OutputError {
    #[error("{}: cannot write there: folder {} does not exist", .path.display(), .folder.display())]
    MissingFolder { path: PathBuf, folder: PathBuf },
    #[error("{}: the output would overwrite an input", .0.display())]
    OverwritesInput(PathBuf),
    #[error("{}: two outputs name the same file", .0.display())]
    SameOutput(PathBuf),
    /// An existing entry of the wrong kind (a named pipe or a device given as a file, a file
    /// given as a frame folder), or a link that cannot be followed.
    #[error("{}: cannot write: {reason}", .path.display())]
    WrongKind { path: PathBuf, reason: String },
}

/// Fails when `output` exists and is not of `kind` (symbolic links are followed, as writes go
/// through them). Returns the path a write replaces.
pub fn check_output_kind(
    output: &Path,
    kind: crate::io::atomic::OutputKind,
) -> Result<PathBuf, OutputError> {
    crate::io::atomic::resolve_output(output, kind).map_err(|e| OutputError::WrongKind {
        path: output.to_path_buf(),
        reason: e.to_string(),
    })
}

/// The file `path` names, resolved through links as far as it exists (its nearest existing
/// ancestor resolved, [`crate::io::document::resolved`]); as given when nothing resolves.
pub fn resolved(path: &Path) -> PathBuf {
    crate::io::document::resolved(path).unwrap_or_else(|| path.to_path_buf())
}

/// The folder `path` is in (`.` for a bare file name).
pub fn parent_dir(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Fails, before any work, when an output file names an input or another output, exists and
/// is not a regular file (after links), or lies in a folder that does not exist (the outputs written before it would be left behind). Absent
/// (`None`) outputs are skipped; output folders, which the commands make where missing, are
/// not passed here.
pub fn check_outputs<'a>(
    inputs: impl IntoIterator<Item = &'a Path>,
    outputs: impl IntoIterator<Item = Option<&'a Path>> + Clone,
) -> Result<(), OutputError> {
    for output in outputs.clone().into_iter().flatten() {
        let target = check_output_kind(output, crate::io::atomic::OutputKind::File)?;
        let folder = parent_dir(&target);
        if !folder.as_os_str().is_empty() && !folder.is_dir() {
            return Err(OutputError::MissingFolder {
                path: output.to_path_buf(),
                folder: folder.to_path_buf(),
            });
        }
    }
    check_not_overwriting(inputs, outputs)
}

/// Fails when an output file names an input or another output.
pub fn check_not_overwriting<'a>(
    inputs: impl IntoIterator<Item = &'a Path>,
    outputs: impl IntoIterator<Item = Option<&'a Path>>,
) -> Result<(), OutputError> {
    // Sets: a layered file's thousands of part images made this quadratic (5e7 comparisons).
    let inputs: std::collections::HashSet<PathBuf> = inputs.into_iter().map(resolved).collect();
    let mut seen = std::collections::HashSet::new();
    for output in outputs.into_iter().flatten() {
        let at = resolved(output);
        if inputs.contains(&at) {
            return Err(OutputError::OverwritesInput(output.to_path_buf()));
        }
        if !seen.insert(at) {
            return Err(OutputError::SameOutput(output.to_path_buf()));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_output_naming_an_input_or_another_output_is_refused() {
        let tmp = crate::test_scratch::scratch("outputs");
        let dir = tmp.path();
        let input = dir.join("in.png");
        std::fs::write(&input, b"x").unwrap();
        let other = dir.join("out.json");
        // The same file through another spelling is still the input.
        let spelled = dir.join(".").join("in.png");
        assert_eq!(
            check_outputs([input.as_path()], [Some(spelled.as_path())]),
            Err(OutputError::OverwritesInput(spelled.clone()))
        );
        assert_eq!(
            check_outputs(
                [input.as_path()],
                [Some(other.as_path()), Some(other.as_path())]
            ),
            Err(OutputError::SameOutput(other.clone()))
        );
        let missing = dir.join("nowhere/out.json");
        assert!(matches!(
            check_outputs([input.as_path()], [Some(missing.as_path())]),
            Err(OutputError::MissingFolder { .. })
        ));
        assert_eq!(
            check_outputs([input.as_path()], [Some(other.as_path()), None]),
            Ok(())
        );
    }
}
