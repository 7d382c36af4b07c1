//! The memory budget (`--memory-budget`, `SINEW_MEMORY_BUDGET`, `sinew::budget`) and bounded
//! thread counts, measured on the binary: work over the budget is refused up front — exit 2,
//! one line naming the flag, no output — with its peak resident memory measured (the child's
//! `ru_maxrss` from `wait4`) far below the budget, and under an address-space limit a little
//! above it, so an allocation past the budget would abort the run instead of passing; work that
//! fits a small budget draws fewer frames at once and writes the same bytes.

#![cfg(all(target_os = "linux", feature = "cli"))]

mod command;

use command::{s, scratch, EXIT_BAD_INPUT};
use std::io::Read;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::OnceLock;

const MIB: u64 = 1024 * 1024;
const GIB: u64 = 1024 * MIB;
/// sinew's default budget (`sinew::budget::DEFAULT_MEMORY_BUDGET_BYTES`).
const DEFAULT_BUDGET_BYTES: u64 = 2 * GIB;
/// Address space a run may map beyond its budget: the binary, the rig and its textures,
/// thread stacks and the allocator's per-thread arenas (reserved, mostly never touched).
const ADDRESS_SPACE_SLACK_BYTES: u64 = 1536 * MIB;

/// What a measured run did.
struct Run {
    /// The exit code; `None` when a signal ended it (an allocation that failed aborts).
    code: Option<i32>,
    stdout: String,
    stderr: String,
    /// Peak resident memory, bytes.
    peak_rss_bytes: u64,
}

/// Runs `sinew args` with `env` set, its address space limited to `address_space_bytes`, and
/// measures its peak resident memory.
fn run_measured(args: &[&str], env: &[(&str, &str)], address_space_bytes: u64) -> Run {
    let mut command = Command::new(env!("CARGO_BIN_EXE_sinew"));
    command
        .args(args)
        .envs(env.iter().copied())
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let limit = libc::rlimit {
        rlim_cur: address_space_bytes,
        rlim_max: address_space_bytes,
    };
    // SAFETY: only setrlimit, async-signal-safe, runs between fork and exec.
    unsafe {
        command.pre_exec(move || {
            if libc::setrlimit(libc::RLIMIT_AS, &limit) == 0 {
                Ok(())
            } else {
                Err(std::io::Error::last_os_error())
            }
        });
    }
    let mut child = command.spawn().expect("run sinew");
    let mut out = child.stdout.take().expect("stdout");
    let mut err = child.stderr.take().expect("stderr");
    let reader = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = out.read_to_string(&mut text);
        text
    });
    let mut stderr = String::new();
    let _ = err.read_to_string(&mut stderr);
    let stdout = reader.join().expect("stdout read");
    let mut status = 0;
    // SAFETY: a zeroed rusage is a valid value for wait4 to fill.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: the child is ours and not yet reaped (std's Child is never waited on here).
    let pid = unsafe { libc::wait4(child.id() as libc::pid_t, &mut status, 0, &mut usage) };
    assert_eq!(pid, child.id() as libc::pid_t, "wait4");
    let code = libc::WIFEXITED(status).then(|| libc::WEXITSTATUS(status));
    Run {
        code,
        stdout,
        stderr,
        // ru_maxrss is in KiB on Linux.
        peak_rss_bytes: usage.ru_maxrss as u64 * 1024,
    }
}

/// The bundled character rigged by `sinew demo`, once for the whole file.
fn demo_rig() -> &'static Path {
    static DEMO: OnceLock<(tempfile::TempDir, PathBuf)> = OnceLock::new();
    let (_, rig) = DEMO.get_or_init(|| {
        let tmp = scratch("demo");
        let out = command::sinew(&["demo", "-o", s(tmp.path())]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let rig = tmp.path().join("character.json");
        (tmp, rig)
    });
    rig
}

/// Asserts the bad-input contract on a measured run: exit 2, one line containing `expect`.
fn assert_refused(run: &Run, args: &[&str], expect: &str) {
    assert_eq!(
        run.code,
        Some(EXIT_BAD_INPUT),
        "{args:?}: {}",
        run.stderr.lines().next().unwrap_or_default()
    );
    assert_eq!(
        run.stderr.trim_end().lines().count(),
        1,
        "{args:?}: {}",
        run.stderr
    );
    assert!(run.stderr.contains(expect), "{args:?}: {}", run.stderr);
}

#[test]
fn frames_of_16384_px_are_refused_before_they_are_allocated() {
    let rig = demo_rig();
    let tmp = scratch("huge");
    let dir = tmp.path();
    for (extra, output) in [
        (&["--size", "16384x16384"][..], dir.join("frames")),
        (&["--size", "16384x16384"][..], dir.join("walk.gif")),
        (&["--size", "16384x16384"][..], dir.join("sheet.png")),
        // The 512 px canvas at scale 32: 16384 px frames too.
        (&["--scale", "32"][..], dir.join("scaled")),
    ] {
        let mut args = vec!["render", s(rig), "--anim", "walk", "-o", s(&output)];
        args.extend_from_slice(extra);
        let run = run_measured(&args, &[], DEFAULT_BUDGET_BYTES + ADDRESS_SPACE_SLACK_BYTES);
        assert_refused(&run, &args, "16384×16384 px frame");
        assert!(
            run.stderr.contains("over the memory budget of 2.0 GiB")
                && run.stderr.contains("--memory-budget"),
            "{}",
            run.stderr
        );
        assert!(!output.exists(), "{args:?} wrote {}", output.display());
        assert!(!output.with_extension("json").exists());
        // Nothing of a frame was allocated: the peak is the rig's, far below one frame (1 GiB).
        assert!(
            run.peak_rss_bytes < 256 * MIB,
            "{args:?}: peak {} MiB",
            run.peak_rss_bytes / MIB
        );
    }
}

#[test]
fn the_budget_is_set_by_the_flag_or_the_environment_and_checked() {
    let rig = demo_rig();
    let tmp = scratch("set");
    let out = tmp.path().join("walk.gif");
    let render = ["render", s(rig), "--anim", "walk", "-o", s(&out)];
    // 8192² frames fit the default budget a frame at a time, not 1 GiB.
    let mut args = render.to_vec();
    args.extend(["--size", "8192x8192", "--memory-budget", "1GiB"]);
    let run = run_measured(&args, &[], GIB + ADDRESS_SPACE_SLACK_BYTES);
    assert_refused(&run, &args, "over the memory budget of 1.0 GiB");
    // The environment variable, and the flag over it.
    let mut args = render.to_vec();
    args.extend(["--size", "4096x4096"]);
    let run = run_measured(&args, &[("SINEW_MEMORY_BUDGET", "256MiB")], 4 * GIB);
    assert_refused(&run, &args, "over the memory budget of 256.0 MiB");
    let run = run_measured(&args, &[("SINEW_MEMORY_BUDGET", "lots")], 4 * GIB);
    assert_refused(&run, &args, "SINEW_MEMORY_BUDGET: memory budget 'lots'");
    let mut flagged = args.clone();
    flagged.extend(["--memory-budget", "200MiB"]);
    let run = run_measured(&flagged, &[("SINEW_MEMORY_BUDGET", "256MiB")], 4 * GIB);
    assert_refused(&run, &flagged, "over the memory budget of 200.0 MiB");
    for bad in ["64", "12 parsecs", "0.5MiB"] {
        let mut args = render.to_vec();
        args.extend(["--memory-budget", bad]);
        let run = run_measured(&args, &[], 4 * GIB);
        assert_refused(&run, &args, "memory budget");
    }
    assert!(!out.exists());
}

#[test]
fn a_render_that_fits_a_small_budget_draws_fewer_frames_at_once_and_the_same_bytes() {
    let rig = demo_rig();
    let tmp = scratch("small");
    let dir = tmp.path();
    // Budgets that hold a few of the 512² frames at once rather than 16 (see sinew::budget:
    // frames 4 B/px, 9 B/px per drawing thread, the writers' own).
    // The folder in 8 MiB draws 1 frame at a time, the GIF in 32 MiB 1: the default's 16 would
    // take about 22 and 37 MiB over the rig's. A sheet's estimate holds its whole area, far
    // above what this one touches: see the library test below for the frames it draws.
    for (name, small) in [
        ("frames", "8MiB"),
        ("walk.gif", "32MiB"),
        ("walk.png", "96MiB"),
    ] {
        let reference = dir.join(format!("default-{name}"));
        let small_out = dir.join(format!("small-{name}"));
        let args = |out: &Path, budget: &str| {
            vec![
                "render".to_string(),
                s(rig).into(),
                "--anim".into(),
                "walk".into(),
                "-o".into(),
                s(out).into(),
                "--memory-budget".into(),
                budget.into(),
            ]
        };
        let run = |out: &Path, budget: &str| {
            let owned = args(out, budget);
            let borrowed: Vec<&str> = owned.iter().map(String::as_str).collect();
            run_measured(&borrowed, &[], 8 * GIB)
        };
        let default = run(&reference, "2GiB");
        assert_eq!(default.code, Some(0), "{}", default.stderr);
        let fitted = run(&small_out, small);
        assert_eq!(fitted.code, Some(0), "{name} in {small}: {}", fitted.stderr);
        assert_eq!(fitted.stdout, default.stdout.replace("default-", "small-"));
        assert_same_output(&reference, &small_out);
        // What the rig takes before any frame, measured: the same render refused at once.
        let refused = run(&dir.join(format!("refused-{name}")), "1MiB");
        assert_eq!(refused.code, Some(EXIT_BAD_INPUT), "{}", refused.stderr);
        let budget = budget_bytes(small);
        assert!(
            fitted.peak_rss_bytes <= refused.peak_rss_bytes + budget,
            "{name}: peak {} MiB, over the rig's {} MiB + the budget {small}",
            fitted.peak_rss_bytes / MIB,
            refused.peak_rss_bytes / MIB
        );
    }
}

/// `8MiB` in bytes (MiB only: what the test above uses).
fn budget_bytes(text: &str) -> u64 {
    text.trim_end_matches("MiB").parse::<u64>().expect("MiB") * MIB
}

/// The two outputs (a folder's files, a GIF, a sheet's PNG and JSON) hold the same bytes, the
/// sheet's JSON up to the image name it records.
fn assert_same_output(a: &Path, b: &Path) {
    if a.is_dir() {
        let names = |dir: &Path| {
            let mut names: Vec<_> = std::fs::read_dir(dir)
                .unwrap()
                .map(|e| e.unwrap().file_name())
                .collect();
            names.sort();
            names
        };
        assert_eq!(names(a), names(b));
        for name in names(a) {
            assert!(
                std::fs::read(a.join(&name)).unwrap() == std::fs::read(b.join(&name)).unwrap(),
                "{name:?} differs"
            );
        }
        return;
    }
    assert!(
        std::fs::read(a).unwrap() == std::fs::read(b).unwrap(),
        "{} and {} differ",
        a.display(),
        b.display()
    );
    let (ja, jb) = (a.with_extension("json"), b.with_extension("json"));
    if ja.exists() {
        let stem = |p: &Path| p.file_stem().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(&ja).unwrap();
        assert_eq!(
            text.replace(&stem(a), &stem(b)),
            std::fs::read_to_string(&jb).unwrap()
        );
    }
}

#[test]
fn thread_counts_are_bounded_by_the_machine() {
    let tmp = scratch("jobs");
    let manifest = tmp.path().join("game.json");
    std::fs::write(&manifest, r#"{"jobs": []}"#).unwrap();
    // A million threads would exhaust the process (or, under this limit, fail to start).
    let args = ["batch", s(&manifest), "--jobs", "1000000"];
    let run = run_measured(&args, &[], GIB);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(
        run.stderr
            .contains("--jobs 1000000: this machine runs at most"),
        "{}",
        run.stderr
    );
    assert!(run.stdout.contains("\"failed\": 0"), "{}", run.stdout);
    // The same for the pool every command draws on.
    let rig = demo_rig();
    let out = tmp.path().join("walk.gif");
    let args = ["render", s(rig), "--anim", "walk", "-o", s(&out)];
    let run = run_measured(&args, &[("RAYON_NUM_THREADS", "1000000")], 2 * GIB);
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    assert!(
        run.stderr.contains("RAYON_NUM_THREADS=1000000"),
        "{}",
        run.stderr
    );
    assert!(out.exists());
}

/// Frames drawn on demand, as a render draws them, counting the most asked for at once.
struct Counted {
    frames: Vec<image::RgbaImage>,
    largest_draw: std::sync::atomic::AtomicUsize,
}

impl sinew::io::sequence::FrameSource for Counted {
    fn frame_count(&self) -> usize {
        self.frames.len()
    }

    fn frame_size_px(&self) -> (u32, u32) {
        self.frames[0].dimensions()
    }

    fn draw_bytes_per_thread(&self) -> u64 {
        let (w, h) = self.frame_size_px();
        u64::from(w) * u64::from(h) * sinew::budget::DRAW_BYTES_PER_PX
    }

    fn draw(
        &self,
        range: std::ops::Range<usize>,
    ) -> Result<Vec<std::borrow::Cow<'_, image::RgbaImage>>, sinew::io::sequence::SequenceError>
    {
        self.largest_draw
            .fetch_max(range.len(), std::sync::atomic::Ordering::Relaxed);
        Ok(self.frames[range]
            .iter()
            .map(|f| std::borrow::Cow::Owned(f.clone()))
            .collect())
    }
}

/// 37 frames of 256² px: a gradient and a square that moves, half transparent around it.
fn moving_square() -> Vec<image::RgbaImage> {
    (0..37u32)
        .map(|f| {
            image::RgbaImage::from_fn(256, 256, |x, y| {
                let inside = (x + 256 - 4 * f) % 256 < 96 && (y + 3 * f) % 256 < 128;
                if inside {
                    image::Rgba([200, (x / 2) as u8, (y + f) as u8, 255])
                } else if x < 128 {
                    image::Rgba([(x + f) as u8, 40, (255 - y) as u8, 255])
                } else {
                    image::Rgba([0, 0, 0, 0])
                }
            })
        })
        .collect()
}

#[test]
fn the_writers_hold_as_many_frames_as_the_budget_allows_and_write_the_same_bytes() {
    use sinew::budget::{with_memory_budget, MemoryBudget, MIB};
    use sinew::io::sequence::{write_sequence, SequenceError, STREAM_CHUNK_FRAMES};
    use std::sync::atomic::Ordering::Relaxed;
    let tmp = scratch("writers");
    let dir = tmp.path();
    let source = Counted {
        frames: moving_square(),
        largest_draw: 0.into(),
    };
    // Two drawing threads, as on the reference machine, whatever this one has.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let options = Default::default();
    // Budgets for a few frames (256 KiB each; 800 KiB per drawing thread; the folder's PNGs
    // 256 KiB per thread, the sheet's 12 B/px of its frames' area): each below what 16 frames
    // take. (A GIF fills its budget with frames and then checks its growing histogram
    // against what is left: see the command-line test above for its frames.)
    for (target, small_bytes) in [("frames", 3 * MIB), ("walk.png", 32 * MIB)] {
        let write = |side: &str, bytes: u64| {
            let out = dir.join(side).join(target);
            std::fs::create_dir_all(dir.join(side)).unwrap();
            source.largest_draw.store(0, Relaxed);
            let result = pool.install(|| {
                with_memory_budget(MemoryBudget { bytes }, || {
                    write_sequence(&source, &[], 24.0, &out, &options)
                })
            });
            (out, result, source.largest_draw.load(Relaxed))
        };
        let (reference, result, held) = write("default", 2048 * MIB);
        result.unwrap();
        assert_eq!(held, STREAM_CHUNK_FRAMES, "{target}");
        let (small, result, held) = write("small", small_bytes);
        result.unwrap();
        assert!(
            (1..STREAM_CHUNK_FRAMES).contains(&held),
            "{target}: {held} frames at once in {} MiB",
            small_bytes / MIB
        );
        assert_same_output(&reference, &small);
        // Not one frame in 1 MiB: refused before drawing, nothing written.
        let (refused, result, held) = write("refused", MIB);
        assert!(
            matches!(result, Err(SequenceError::Budget(_))),
            "{target}: {result:?}"
        );
        assert_eq!(held, 0, "{target}");
        assert!(!refused.exists() && !refused.with_extension("json").exists());
    }
}
