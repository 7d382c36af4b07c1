//! What a batch remembers of its jobs' last successes: for each job, a key (SHA-256 of the
//! sinew version, the job as the manifest states it, and the content of every file it reads)
//! and the content hash of every output. Kept beside the manifest (`NAME.state.json` for
//! `NAME.json`), rewritten atomically after each job, so a killed batch keeps what it finished.
//!
//! A job is skipped when its key is the recorded one and its outputs still hash as recorded.

use super::manifest::{Job, JobPath};
use super::plan::absolute;
use super::BatchError;
use crate::io::RigDocument;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The version of sinew keys are computed with: a new version reruns every job.
pub const SINEW_VERSION: &str = env!("CARGO_PKG_VERSION");

/// The state file's layout version.
const STATE_FORMAT: u32 = 1;

/// The recorded state of a batch.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct State {
    pub format: u32,
    /// Job name → its last success.
    pub jobs: BTreeMap<String, Success>,
}

/// A job's last success.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Success {
    /// Hex SHA-256 of the version, the job and its inputs' contents.
    pub key: String,
    /// Output path (as the manifest names it) → hex SHA-256 of its content (a folder: of its
    /// files' relative names and contents, in name order).
    pub outputs: BTreeMap<String, String>,
}

/// Where the state of the batch `manifest` is kept.
pub fn state_path(manifest: &Path) -> PathBuf {
    manifest.with_extension("state.json")
}

/// Reads the state; a missing or unreadable one is empty (every job runs).
pub fn load_state(path: &Path) -> State {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|text| serde_json::from_str::<State>(&text).ok())
        .filter(|s| s.format == STATE_FORMAT)
        .unwrap_or_default()
}

/// Writes the state atomically.
pub fn save_state(path: &Path, state: &State) -> Result<(), BatchError> {
    let state = State {
        format: STATE_FORMAT,
        jobs: state.jobs.clone(),
    };
    let text = serde_json::to_string_pretty(&state).map_err(|e| BatchError::Json(e.to_string()))?;
    crate::io::write_atomic(path, (text + "\n").as_bytes()).map_err(|source| BatchError::Write {
        path: path.to_path_buf(),
        source,
    })
}

fn hex(digest: &[u8]) -> String {
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// Hex SHA-256 of a file's content, or of a folder's files (relative names and contents, in
/// name order); `None` when it cannot be read.
pub fn content_hash(path: &Path) -> Option<String> {
    let mut hasher = Sha256::new();
    if path.is_dir() {
        let mut files = Vec::new();
        collect_files(path, &mut files).ok()?;
        files.sort();
        for file in files {
            let relative = file.strip_prefix(path).ok()?;
            hasher.update(relative.to_string_lossy().as_bytes());
            hasher.update([0]);
            hasher.update(std::fs::read(&file).ok()?);
            hasher.update([0]);
        }
    } else {
        hasher.update(std::fs::read(path).ok()?);
    }
    Some(hex(&hasher.finalize()))
}

fn collect_files(dir: &Path, files: &mut Vec<PathBuf>) -> std::io::Result<()> {
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        if path.is_dir() {
            collect_files(&path, files)?;
        } else {
            files.push(path);
        }
    }
    Ok(())
}

/// The files `job` reads, absolute: its inputs and, for a rig document, its parts' images.
pub fn read_files(job: &Job, root: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = job.inputs().iter().map(|p| absolute(root, p)).collect();
    if let Job::Render(_) | Job::Export(_) = job {
        if let Some(rig) = files.first().cloned() {
            if let Ok(doc) = RigDocument::load(&rig) {
                files.extend(crate::jobs::part_images(&rig, &doc));
            }
        }
    }
    files
}

/// The job's key, or `None` when an input cannot be read (the job then runs and reports why).
pub fn job_key(job: &Job, root: &Path) -> Option<String> {
    let mut hasher = Sha256::new();
    hasher.update(format!("sinew {SINEW_VERSION}\n").as_bytes());
    hasher.update(serde_json::to_string(job).ok()?.as_bytes());
    for file in read_files(job, root) {
        hasher.update([0]);
        // Relative names: a batch folder moved elsewhere keeps its keys.
        let name = file.strip_prefix(root).unwrap_or(&file);
        hasher.update(name.to_string_lossy().as_bytes());
        hasher.update([0]);
        hasher.update(content_hash(&file)?.as_bytes());
    }
    Some(hex(&hasher.finalize()))
}

/// Each output's content hash, keyed by its path as the manifest names it; `None` when one is
/// missing.
pub fn output_hashes(job: &Job, root: &Path) -> Option<BTreeMap<String, String>> {
    job.outputs()
        .iter()
        .map(|JobPath { path, .. }| {
            let hash = content_hash(&absolute(root, path))?;
            Some((path.to_string_lossy().into_owned(), hash))
        })
        .collect()
}

/// Whether `job`, whose key is `key`, is unchanged since its recorded success.
pub fn is_current(state: &State, job: &Job, key: &str, root: &Path) -> bool {
    match state.jobs.get(job.name()) {
        Some(success) if success.key == key => {
            output_hashes(job, root).as_ref() == Some(&success.outputs)
        }
        _ => false,
    }
}
