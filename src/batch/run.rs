//! Running a planned batch: each job once its dependencies are done, skipped when unchanged
//! ([`super::record`]), on an [`Executor`] (this machine's cores, or a Ray cluster through
//! [`super::ray`]); a failing job fails the jobs that read what it writes, not the others.
//!
//! In: a [`Plan`], the state file's path, an executor, a callback per finished job. Out: a
//! [`Report`]. The state is rewritten (atomically) after each success.

use super::manifest::Job;
use super::plan::{absolute, Plan};
use super::record::{self, State, Success};
use super::BatchError;
use crate::jobs::{self, AutorigFiles, ColorizeFiles, RenderFiles, RigFiles};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// How a job ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Ran and wrote its outputs.
    Done,
    /// Unchanged since its last success: not run.
    Skipped,
    /// Failed (or a job it reads from failed): `error` says why.
    Failed,
}

/// One job's line of the report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct JobReport {
    pub name: String,
    pub kind: String,
    pub status: Status,
    /// One line, for a failed job.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Wall time of the job, s (0 for a skipped one; on Ray, the task's time as its worker
    /// measured it).
    pub seconds: f64,
}

/// The report `sinew batch` prints: one entry per job, in manifest order.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Report {
    pub jobs: Vec<JobReport>,
    pub done: usize,
    pub skipped: usize,
    pub failed: usize,
    /// Wall time of the whole batch, s.
    pub seconds: f64,
}

/// Runs one job of a manifest whose paths are relative to `root`: output folders are made,
/// then the job runs through the same library call as its command.
pub fn run_job(job: &Job, root: &Path) -> Result<(), BatchError> {
    let at = |p: &PathBuf| absolute(root, p);
    let at_opt = |p: &Option<PathBuf>| p.as_ref().map(at);
    for output in job.outputs() {
        // The folder a file is written into; an output folder is made by its job.
        if let Some(folder) = at(&output.path).parent() {
            std::fs::create_dir_all(folder).map_err(|source| BatchError::Write {
                path: folder.to_path_buf(),
                source,
            })?;
        }
    }
    match job {
        Job::Rig(j) => {
            let files = RigFiles {
                images: j.inputs.images.iter().map(at).collect(),
                handles: at_opt(&j.inputs.handles),
                attachments: j.options.attachments.clone(),
                output: at(&j.outputs.rig),
                preview: at_opt(&j.outputs.preview),
                layout: Default::default(),
            };
            jobs::rig_files(&files, &j.options.build, &mut |_, _, _| {})?;
        }
        Job::Autorig(j) => {
            let mut options = crate::autorig::AutorigOptions {
                cage_vertices: j.options.cage,
                point_count: j.options.points,
                ..Default::default()
            };
            options.skeleton.max_bones = j.options.bones;
            let files = AutorigFiles {
                images: j.inputs.images.iter().map(at).collect(),
                output: at(&j.outputs.handles),
                preview: at_opt(&j.outputs.preview),
            };
            jobs::autorig_files(&files, &options)?;
        }
        Job::Render(j) => {
            let settings = j.options.settings()?;
            let files = RenderFiles {
                rig: at(&j.inputs.rig),
                animation: j.options.animation.clone(),
                skins: j.options.skins.clone(),
                output: at(&j.outputs.output),
                // A job that names no runtime plays as the rig's target, as `sinew render` does.
                follow_target: settings.sampling.curves == crate::anim::CurveEvaluation::Exact
                    && settings.baked_runtime.is_none(),
            };
            jobs::render_files(&files, &settings, &|_| {})?;
        }
        Job::Export(j) => {
            jobs::export_spine_files(
                &at(&j.inputs.rig),
                &at(&j.outputs.folder),
                j.options.skeleton.as_deref(),
                &j.options.spine()?,
            )?;
        }
        Job::Colorize(j) => {
            let files = ColorizeFiles {
                lineart: at(&j.inputs.lineart),
                scribbles: at(&j.inputs.scribbles),
                output: at(&j.outputs.image),
                layers: at_opt(&j.outputs.layers),
            };
            jobs::colorize_files(&files, &j.options.colorize())?;
        }
    }
    Ok(())
}

/// What runs jobs: submit a job by index; collect finished ones.
pub trait Executor {
    /// Starts job `index` of the plan.
    fn submit(&mut self, index: usize) -> Result<(), BatchError>;
    /// Waits for a submitted job to finish: its index, its error as one line, its seconds.
    fn next(&mut self) -> Result<(usize, Result<(), String>, f64), BatchError>;
}

/// The one-line text of an error.
pub fn one_line(error: &dyn std::error::Error) -> String {
    let mut line = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        let text = cause.to_string();
        if !line.contains(&text) {
            line.push_str(": ");
            line.push_str(&text);
        }
        source = cause.source();
    }
    line.replace('\n', " ")
}

/// Runs the plan on `executor`: a job is submitted once every job it reads from is done or
/// skipped, or skipped itself when unchanged; it fails at once when one of those failed.
/// `on_job` is called as each job ends. Only an executor that breaks (a Ray driver that
/// exits) or a state file that cannot be written stops the batch.
pub fn run(
    plan: &Plan,
    state_path: &Path,
    executor: &mut dyn Executor,
    on_job: &mut dyn FnMut(&JobReport),
) -> Result<Report, BatchError> {
    let started = Instant::now();
    let count = plan.jobs.len();
    let mut state: State = record::load_state(state_path);
    let mut reports: Vec<Option<JobReport>> = vec![None; count];
    let mut keys: Vec<Option<String>> = vec![None; count];
    let mut submitted = vec![false; count];
    let mut running = 0usize;
    let report = |job: &Job, status, error, seconds| JobReport {
        name: job.name().to_string(),
        kind: job.kind().to_string(),
        status,
        error,
        seconds,
    };
    loop {
        // Resolve every job whose dependencies have all ended, until nothing changes.
        let mut progressed = true;
        while progressed {
            progressed = false;
            for i in 0..count {
                if submitted[i] {
                    continue;
                }
                let deps = &plan.dependencies[i];
                if deps.iter().any(|&d| reports[d].is_none()) {
                    continue;
                }
                submitted[i] = true;
                progressed = true;
                let job = &plan.jobs[i];
                if let Some(&d) = deps
                    .iter()
                    .find(|&&d| reports[d].as_ref().map(|r| r.status) == Some(Status::Failed))
                {
                    let r = report(
                        job,
                        Status::Failed,
                        Some(format!(
                            "not run: job '{}', which writes one of its inputs, failed",
                            plan.jobs[d].name()
                        )),
                        0.0,
                    );
                    on_job(&r);
                    reports[i] = Some(r);
                    continue;
                }
                let key = record::job_key(job, &plan.root);
                if let Some(key) = &key {
                    if record::is_current(&state, job, key, &plan.root) {
                        let r = report(job, Status::Skipped, None, 0.0);
                        on_job(&r);
                        reports[i] = Some(r);
                        continue;
                    }
                }
                keys[i] = key;
                // The previous success no longer holds.
                if state.jobs.remove(job.name()).is_some() {
                    record::save_state(state_path, &state)?;
                }
                executor.submit(i)?;
                running += 1;
            }
        }
        if running == 0 {
            break;
        }
        let (i, result, seconds) = executor.next()?;
        running -= 1;
        let job = &plan.jobs[i];
        let r = match result {
            Ok(()) => {
                let outputs = record::output_hashes(job, &plan.root);
                if let (Some(key), Some(outputs)) = (keys[i].take(), outputs) {
                    state
                        .jobs
                        .insert(job.name().to_string(), Success { key, outputs });
                    record::save_state(state_path, &state)?;
                }
                report(job, Status::Done, None, seconds)
            }
            Err(error) => report(job, Status::Failed, Some(error), seconds),
        };
        on_job(&r);
        reports[i] = Some(r);
    }
    let jobs: Vec<JobReport> = reports.into_iter().flatten().collect();
    let count_of = |s| jobs.iter().filter(|r| r.status == s).count();
    Ok(Report {
        done: count_of(Status::Done),
        skipped: count_of(Status::Skipped),
        failed: count_of(Status::Failed),
        jobs,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// Runs jobs on this machine: each on a pool of `threads` threads (the jobs' own parallel
/// stages share the pool), at most [`crate::budget::max_threads`]; the jobs running at once
/// share the memory budget ([`crate::budget`]) equally.
pub struct LocalExecutor<'a> {
    plan: &'a Plan,
    pool: rayon::ThreadPool,
    /// Each job's share of the memory budget.
    budget: crate::budget::MemoryBudget,
    sender: std::sync::mpsc::Sender<(usize, Result<(), String>, f64)>,
    receiver: std::sync::mpsc::Receiver<(usize, Result<(), String>, f64)>,
}

impl<'a> LocalExecutor<'a> {
    /// `threads`: 0 = one per core; more than [`crate::budget::max_threads`] run as that many.
    pub fn new(plan: &'a Plan, threads: usize) -> Result<Self, BatchError> {
        let (threads, _) = crate::budget::bounded_threads(threads);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| BatchError::Executor(e.to_string()))?;
        let at_once = pool.current_num_threads().min(plan.jobs.len());
        let budget = crate::budget::memory_budget().share(at_once);
        let (sender, receiver) = std::sync::mpsc::channel();
        Ok(LocalExecutor {
            plan,
            pool,
            budget,
            sender,
            receiver,
        })
    }
}

impl Executor for LocalExecutor<'_> {
    fn submit(&mut self, index: usize) -> Result<(), BatchError> {
        let job = self.plan.jobs[index].clone();
        let root = self.plan.root.clone();
        let sender = self.sender.clone();
        let budget = self.budget;
        self.pool.spawn(move || {
            let started = Instant::now();
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                crate::budget::with_memory_budget(budget, || run_job(&job, &root))
                    .map_err(|e| one_line(&e))
            }))
            .unwrap_or_else(|_| Err("the job panicked (a bug in sinew)".into()));
            let _ = sender.send((index, result, started.elapsed().as_secs_f64()));
        });
        Ok(())
    }

    fn next(&mut self) -> Result<(usize, Result<(), String>, f64), BatchError> {
        self.receiver
            .recv()
            .map_err(|e| BatchError::Executor(e.to_string()))
    }
}
