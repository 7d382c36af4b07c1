//! Running a batch's jobs as Ray tasks: an [`Executor`] over the project's Python driver
//! (`tools/ray/driver.py`, built in as [`DRIVER_SOURCE`] and written out for a run by
//! [`DriverFile`]), which connects to a running Ray cluster and runs each job as a task calling
//! `sinew batch MANIFEST --job NAME` on a worker (see docs/batch.md).
//!
//! The protocol is lines of text: this side writes a job's name to the driver's stdin to
//! submit it; the driver prints one JSON object per finished job on stdout:
//! `{"name", "ok", "error", "seconds"}`. Ray retries a task whose worker died
//! (`max_retries`); a job that fails on its own is not retried. Inputs and outputs travel
//! through a path every node sees (the manifest's folder): on one machine any path; on a
//! cluster, shared storage mounted at the same path.

use super::plan::Plan;
use super::run::Executor;
use super::BatchError;
use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};

/// How to reach the cluster.
#[derive(Clone, Debug)]
pub struct RayOptions {
    /// The cluster's address, `HOST:PORT` of its head (GCS).
    pub address: String,
    /// A Python with the `ray` package (`tools/ray/install.sh` makes a virtual environment
    /// with the pinned version).
    pub python: PathBuf,
    /// The driver script ([`DriverFile`] writes the built-in one).
    pub driver: PathBuf,
    /// The sinew binary the workers run (the same path on every node).
    pub sinew: PathBuf,
    /// The manifest, absolute (the same path on every node).
    pub manifest: PathBuf,
    /// How many times Ray reruns a task whose worker died. Default 3.
    pub max_retries: u32,
}

/// Runs jobs through the Ray driver; the driver lives as long as this executor.
pub struct RayExecutor<'a> {
    plan: &'a Plan,
    child: Child,
    /// The driver's last line on stderr (its error when it stops); its other lines (Ray's
    /// warnings) are not shown.
    last_error: std::sync::Arc<std::sync::Mutex<String>>,
    stdin: Option<ChildStdin>,
    stdout: BufReader<ChildStdout>,
}

/// One line of the driver's output.
#[derive(serde::Deserialize)]
struct Finished {
    name: String,
    ok: bool,
    #[serde(default)]
    error: Option<String>,
    seconds: f64,
}

impl<'a> RayExecutor<'a> {
    /// Starts the driver (it connects to the cluster before reading any job).
    pub fn start(plan: &'a Plan, options: &RayOptions) -> Result<Self, BatchError> {
        let mut child = Command::new(&options.python)
            .arg(&options.driver)
            .arg("--address")
            .arg(&options.address)
            .arg("--sinew")
            .arg(&options.sinew)
            .arg("--manifest")
            .arg(&options.manifest)
            .arg("--max-retries")
            .arg(options.max_retries.to_string())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| {
                BatchError::Executor(format!(
                    "{}: cannot start the Ray driver: {e} ({NEEDS_RAY})",
                    options.python.display()
                ))
            })?;
        let stdin = child.stdin.take();
        let stdout = child
            .stdout
            .take()
            .map(BufReader::new)
            .ok_or_else(|| BatchError::Executor("the Ray driver has no stdout".into()))?;
        let last_error = std::sync::Arc::new(std::sync::Mutex::new(String::new()));
        if let Some(stderr) = child.stderr.take() {
            let last = last_error.clone();
            std::thread::spawn(move || {
                for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                    if !line.trim().is_empty() {
                        if let Ok(mut last) = last.lock() {
                            *last = line.trim().to_string();
                        }
                    }
                }
            });
        }
        Ok(RayExecutor {
            plan,
            child,
            last_error,
            stdin,
            stdout,
        })
    }

    /// The driver's exit, as an error.
    fn driver_gone(&mut self) -> BatchError {
        let status = self
            .child
            .wait()
            .map(|s| s.to_string())
            .unwrap_or_else(|e| e.to_string());
        // The stderr reader has the driver's last words once the pipe closes.
        std::thread::sleep(std::time::Duration::from_millis(100));
        let last = self
            .last_error
            .lock()
            .map(|l| l.clone())
            .unwrap_or_default();
        let hint = if last.contains("No module named 'ray'") {
            format!(" ({NEEDS_RAY})")
        } else {
            String::new()
        };
        BatchError::Executor(format!("the Ray driver stopped ({status}): {last}{hint}"))
    }
}

/// What the driver needs, as the errors of a Python without it say.
const NEEDS_RAY: &str = "the driver needs a Python with the `ray` package: `pip install ray`, \
     then point --ray-python or SINEW_RAY_PYTHON at that Python (docs/batch.md)";

/// The Ray driver (`tools/ray/driver.py`), built in so that an installed sinew runs batches on
/// Ray without its source tree.
pub const DRIVER_SOURCE: &str = include_str!("../../tools/ray/driver.py");

/// [`DRIVER_SOURCE`] written to a file for one run, in a folder of its own (made for it, so
/// no other run or user shares or swaps it); both are removed when this is dropped.
#[derive(Debug)]
pub struct DriverFile {
    dir: PathBuf,
    path: PathBuf,
}

impl DriverFile {
    /// Writes the built-in driver into a new folder `sinew-ray-driver-*` under `parent` (the
    /// system's temporary folder, `std::env::temp_dir()`, for the command line).
    pub fn write_in(parent: &Path) -> Result<Self, BatchError> {
        let stamp = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_nanos())
            .unwrap_or(0);
        let mut attempt = 0u32;
        let dir = loop {
            let dir = parent.join(format!(
                "sinew-ray-driver-{}-{stamp}-{attempt}",
                std::process::id()
            ));
            let mut builder = std::fs::DirBuilder::new();
            #[cfg(unix)]
            std::os::unix::fs::DirBuilderExt::mode(&mut builder, 0o700);
            match builder.create(&dir) {
                Ok(()) => break dir,
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && attempt < 100 => {
                    attempt += 1
                }
                Err(source) => return Err(BatchError::Write { path: dir, source }),
            }
        };
        let path = dir.join("driver.py");
        let file = DriverFile { dir, path };
        std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&file.path)
            .and_then(|mut f| f.write_all(DRIVER_SOURCE.as_bytes()))
            .map_err(|source| BatchError::Write {
                path: file.path.clone(),
                source,
            })?;
        Ok(file)
    }

    /// The driver script.
    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for DriverFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

impl Executor for RayExecutor<'_> {
    fn submit(&mut self, index: usize) -> Result<(), BatchError> {
        let name = self.plan.jobs[index].name().to_string();
        let sent = match self.stdin.as_mut() {
            Some(stdin) => writeln!(stdin, "{name}").and_then(|_| stdin.flush()),
            None => Err(std::io::ErrorKind::BrokenPipe.into()),
        };
        sent.map_err(|_| self.driver_gone())
    }

    fn next(&mut self) -> Result<(usize, Result<(), String>, f64), BatchError> {
        let mut line = String::new();
        loop {
            line.clear();
            match self.stdout.read_line(&mut line) {
                Ok(0) | Err(_) => return Err(self.driver_gone()),
                Ok(_) => {}
            }
            // Lines that are not a result (Ray's own messages) are left out.
            let Ok(done) = serde_json::from_str::<Finished>(line.trim()) else {
                continue;
            };
            let index = self
                .plan
                .jobs
                .iter()
                .position(|j| j.name() == done.name)
                .ok_or_else(|| {
                    BatchError::Executor(format!("the Ray driver names no job '{}'", done.name))
                })?;
            let result = if done.ok {
                Ok(())
            } else {
                Err(done.error.unwrap_or_else(|| "failed on Ray".into()))
            };
            return Ok((index, result, done.seconds));
        }
    }
}

impl Drop for RayExecutor<'_> {
    fn drop(&mut self) {
        // Closing stdin tells the driver no more jobs come; it exits once its tasks end.
        self.stdin.take();
        let _ = self.child.wait();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_built_in_driver_is_written_to_a_folder_of_its_own_and_removed() {
        let tmp = crate::test_scratch::scratch("ray-driver");
        let first = DriverFile::write_in(tmp.path()).unwrap();
        let second = DriverFile::write_in(tmp.path()).unwrap();
        assert_ne!(first.path().parent(), second.path().parent());
        let written = std::fs::read_to_string(first.path()).unwrap();
        assert_eq!(written, DRIVER_SOURCE);
        assert!(written.contains("import ray"));
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let dir = first.path().parent().unwrap();
            let mode = std::fs::metadata(dir).unwrap().permissions().mode();
            assert_eq!(mode & 0o077, 0, "{mode:o}");
        }
        let dir = first.path().parent().unwrap().to_path_buf();
        drop(first);
        assert!(!dir.exists());
        assert!(second.path().exists());
        // A parent that cannot hold it: one error naming the folder.
        let missing = tmp.path().join("no/such/folder");
        let error = DriverFile::write_in(&missing).unwrap_err().to_string();
        assert!(error.contains("no/such/folder"), "{error}");
    }
}
