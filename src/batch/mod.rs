//! Batch work (`sinew batch MANIFEST.json`): many jobs — rig, autorig, render, export,
//! colorize — listed in one manifest, run in parallel on this machine's cores or as tasks on a
//! Ray cluster, incrementally (a job unchanged since its last success is skipped).
//!
//! In: the manifest file. Out: the jobs' files, the state beside the manifest, a [`Report`].
//! [`manifest`] parses the JSON into typed jobs; [`plan`] checks the whole manifest before any
//! work; [`record`] hashes and remembers successes; [`run`] runs the plan on an executor
//! (local threads, or [`ray`]). Each job is the library call its command makes
//! ([`crate::jobs`]), so a batch writes the bytes the commands write.

pub mod manifest;
pub mod plan;
pub mod ray;
pub mod record;
pub mod run;

pub use manifest::{Job, Manifest};
pub use plan::Plan;
pub use run::{run, run_job, Executor, JobReport, LocalExecutor, Report, Status};

use std::path::{Path, PathBuf};

/// What is wrong with a batch; each displays on one line.
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    #[error("{}: cannot read: {source}", .path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: cannot write: {source}", .path.display())]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    /// The manifest is not a manifest (JSON, top-level fields).
    #[error("not a valid batch manifest: {0}")]
    Json(String),
    /// One job is wrong: the job (index or name), and why.
    #[error("{0}: {1}")]
    Job(String, String),
    #[error("{}: jobs '{first}' and '{second}' both write it", .path.display())]
    SameOutput {
        path: PathBuf,
        first: String,
        second: String,
    },
    /// Jobs writing, in turn, what the next reads, back to the first.
    #[error("jobs {0} form a cycle (each writes what the next reads)")]
    Cycle(String),
    #[error("{0}")]
    Options(String),
    /// A path the manifest names (or a rig document it reads names) that leaves the
    /// manifest's folder: the file it is written in, the job, the field as written.
    #[error("{}: job '{job}': {field}: {problem}", .file.display())]
    Confined {
        file: PathBuf,
        job: String,
        field: String,
        problem: crate::io::PathError,
    },
    /// What is wrong with the manifest at `path` (its JSON, a job's fields, the plan).
    #[error("{}: {source}", .path.display())]
    InManifest {
        path: PathBuf,
        source: Box<BatchError>,
    },
    /// The job itself failed.
    #[error(transparent)]
    Run(Box<crate::jobs::JobError>),
    /// The executor broke (threads, or the Ray driver).
    #[error("{0}")]
    Executor(String),
}

impl From<crate::jobs::JobError> for BatchError {
    fn from(error: crate::jobs::JobError) -> Self {
        BatchError::Run(Box::new(error))
    }
}

/// Reads and checks the manifest at `path` (made absolute, so the plan's paths are too).
pub fn load(path: &Path) -> Result<Plan, BatchError> {
    let path = std::path::absolute(path).map_err(|source| BatchError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    let text = std::fs::read_to_string(&path).map_err(|source| BatchError::Read {
        path: path.clone(),
        source,
    })?;
    // A refusal names the manifest, unless it names its file already.
    let in_manifest = |e: BatchError| match e {
        BatchError::Read { .. } | BatchError::Write { .. } | BatchError::Confined { .. } => e,
        e => BatchError::InManifest {
            path: path.clone(),
            source: Box::new(e),
        },
    };
    let manifest = manifest::parse(&text).map_err(in_manifest)?;
    // A path that leaves the manifest's folder is named with the manifest file.
    let plan =
        plan::plan(manifest, crate::io::outputs::parent_dir(&path)).map_err(|e| match e {
            BatchError::Confined {
                file,
                job,
                field,
                problem,
            } if file.as_path() == crate::io::outputs::parent_dir(&path) => BatchError::Confined {
                file: path.clone(),
                job,
                field,
                problem,
            },
            other => in_manifest(other),
        })?;
    // No job may write over the manifest or its state.
    let state = record::state_path(&path);
    for job in &plan.jobs {
        for output in job.outputs() {
            let output = plan::absolute(&plan.root, &output.path);
            if [&path, &state].iter().any(|p| p.starts_with(&output)) {
                return Err(in_manifest(BatchError::Job(
                    format!("job '{}'", job.name()),
                    format!(
                        "{}: the output would overwrite the manifest or its state",
                        output.display()
                    ),
                )));
            }
        }
    }
    Ok(plan)
}
