//! `sinew batch MANIFEST.json [--jobs N] [--ray ADDRESS]`: argument parsing, the progress bar,
//! the report. The batch itself is the library's ([`sinew::batch`]).

use anyhow::{bail, Result};
use clap::Args;
use sinew::batch::{self, ray, JobReport, LocalExecutor, Status};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args, Debug)]
pub struct BatchArgs {
    /// The manifest: jobs with their inputs, options and outputs (see docs/formats.md, "Batch
    /// manifest"). Its state is kept beside it (NAME.state.json).
    pub manifest: PathBuf,
    /// Jobs run at once on this machine (0 = one per core; at most 4 per core, more run as
    /// that many). They share the memory budget (--memory-budget) equally.
    #[arg(long, value_name = "N", default_value_t = 0, conflicts_with = "ray")]
    pub jobs: usize,
    /// Run each job as a task on the Ray cluster at this address (HOST:PORT of its head),
    /// through sinew's built-in Ray driver (see docs/batch.md).
    #[arg(long, value_name = "ADDRESS")]
    pub ray: Option<String>,
    /// The Python that runs the Ray driver: one with the `ray` package, e.g. a virtual
    /// environment's bin/python (see docs/batch.md).
    #[arg(
        long,
        value_name = "PYTHON",
        env = "SINEW_RAY_PYTHON",
        default_value = "python3"
    )]
    pub ray_python: PathBuf,
    /// A Ray driver script to run instead of the built-in one (which sinew writes for each
    /// run into a folder of its own in the temporary folder, and removes after).
    #[arg(long, value_name = "PY")]
    pub ray_driver: Option<PathBuf>,
    /// How many times Ray reruns a task whose worker died.
    #[arg(long, value_name = "N", default_value_t = 3)]
    pub max_retries: u32,
    /// Run only this job, now, without the state (what a Ray task runs); prints one JSON line
    /// {"name", "ok", "error", "seconds"}.
    #[arg(long, value_name = "NAME", conflicts_with = "ray")]
    pub job: Option<String>,
}

pub fn run(args: &BatchArgs) -> Result<()> {
    // The whole manifest is checked before any work.
    let plan = batch::load(&args.manifest)?;
    if let Some(name) = &args.job {
        return run_one(&plan, name);
    }
    let manifest = std::path::absolute(&args.manifest)?;
    let state = batch::record::state_path(&manifest);
    let bar = super::out::bar("batch", "jobs");
    bar.set_length(plan.jobs.len() as u64);
    let mut on_job = |r: &JobReport| {
        bar.inc(1);
        if r.status == Status::Failed {
            bar.set_message(format!("(failed: {})", r.name));
        }
    };
    let report = match &args.ray {
        None => {
            let (jobs, lowered) = sinew::budget::bounded_threads(args.jobs);
            if lowered {
                super::out::note!(
                    "--jobs {}: this machine runs at most {jobs} threads ({} per \
                     core); running {jobs} jobs at once",
                    args.jobs,
                    sinew::budget::THREADS_PER_CORE
                );
            }
            let mut executor = LocalExecutor::new(&plan, jobs)?;
            batch::run(&plan, &state, &mut executor, &mut on_job)
        }
        Some(address) => {
            // The built-in driver lives until the executor (declared after it) is dropped.
            let built_in;
            let driver = match &args.ray_driver {
                Some(path) => path.clone(),
                None => {
                    built_in = ray::DriverFile::write_in(&std::env::temp_dir())?;
                    built_in.path().to_path_buf()
                }
            };
            let options = ray::RayOptions {
                address: address.clone(),
                python: args.ray_python.clone(),
                driver,
                sinew: std::env::current_exe()?,
                manifest,
                max_retries: args.max_retries,
            };
            let mut executor = ray::RayExecutor::start(&plan, &options)?;
            batch::run(&plan, &state, &mut executor, &mut on_job)
        }
    };
    bar.finish_and_clear();
    let report = report?;
    println!("{}", serde_json::to_string_pretty(&report)?);
    if report.failed > 0 {
        bail!(
            "{} of {} jobs failed (see the report)",
            report.failed,
            report.jobs.len()
        );
    }
    Ok(())
}

/// One job, as a Ray task runs it: the result as one JSON line on stdout.
fn run_one(plan: &batch::Plan, name: &str) -> Result<()> {
    let Some(job) = plan.jobs.iter().find(|j| j.name() == name) else {
        bail!("the manifest has no job '{name}'");
    };
    let started = Instant::now();
    let result = batch::run_job(job, &plan.root);
    let line = serde_json::json!({
        "name": name,
        "ok": result.is_ok(),
        "error": result.as_ref().err().map(|e| batch::run::one_line(e)),
        "seconds": started.elapsed().as_secs_f64(),
    });
    println!("{line}");
    Ok(result?)
}
