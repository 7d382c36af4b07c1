//! One memory budget that every path consults before it allocates, and thread counts bounded
//! by the machine.
//!
//! In: a [`MemoryBudget`] (bytes; [`DEFAULT_MEMORY_BUDGET_BYTES`] unless the shell sets another,
//! `sinew --memory-budget 8GiB` or `SINEW_MEMORY_BUDGET=8GiB`) and a job's estimated peak
//! bytes. Out: how many frames a streaming writer may hold at once, or a [`BudgetError`] naming
//! what would not fit, by how much, and the flag that raises the budget — before the job
//! allocates it.
//!
//! The default is a fixed number, not a share of the machine's memory, so the same job is
//! refused or rendered the same way on every machine. The estimates are upper bounds on what
//! is allocated (not what is touched): the straight RGBA8 frames a writer holds (4 B/px), and
//! per drawing thread the premultiplied pixmap (4 B/px) and the rasterizer's coverage scratch,
//! which the thread keeps (5 B/px) — see [`DRAW_BYTES_PER_PX`]; each writer adds its own.
//!
//! The budget in force is the process's ([`set_memory_budget`], what the command line does
//! first), unless the calling thread runs inside [`with_memory_budget`] (a batch gives each of
//! the jobs it runs at once its share). The checks run on the thread that starts a job, before
//! it fans out.
//!
//! Threads: [`bounded_threads`] caps a requested thread count at [`THREADS_PER_CORE`] per core
//! (`std::thread::available_parallelism`): more threads than that only add stacks and
//! switching, and a count such as 1000000 would exhaust the process before any work.

use serde::{Deserialize, Serialize};
use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

/// Bytes in a KiB.
pub const KIB: u64 = 1024;
/// Bytes in a MiB.
pub const MIB: u64 = 1024 * KIB;
/// Bytes in a GiB.
pub const GIB: u64 = 1024 * MIB;

/// The budget when none is set, bytes: 2 GiB. Every render of HD and 4K frames fits (a 4K
/// folder render holds 16 frames in ~0.9 GiB), an 8192² one renders a few frames at a time,
/// and a single 16384² frame (3.3 GiB to draw) is refused rather than left to the allocator;
/// it is a fixed number so that refusals are the same on every machine.
pub const DEFAULT_MEMORY_BUDGET_BYTES: u64 = 2 * GIB;
/// The smallest budget that may be set, bytes: below, even a small sprite cannot be drawn and
/// the number is most likely a missing unit (`--memory-budget 64`).
pub const MIN_MEMORY_BUDGET_BYTES: u64 = MIB;
/// The command-line flag that sets the budget (named by every refusal).
pub const MEMORY_BUDGET_FLAG: &str = "--memory-budget";
/// The environment variable that sets the budget when the flag is not given.
pub const MEMORY_BUDGET_ENV: &str = "SINEW_MEMORY_BUDGET";

/// Bytes per px of one straight-alpha RGBA8 frame.
pub const FRAME_BYTES_PER_PX: u64 = 4;
/// Bytes per output px a thread allocates to draw a frame besides the frame it returns: the
/// premultiplied pixmap (4) and the coverage scratch of a part as large as the frame (`i32`
/// accumulation cells and `u8` coverage: 5), which the thread keeps for its next frame.
pub const DRAW_BYTES_PER_PX: u64 = 9;

/// Threads per core a thread count may ask for at most ([`bounded_threads`]).
pub const THREADS_PER_CORE: usize = 4;

/// How much memory a job may allocate at its peak, bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct MemoryBudget {
    pub bytes: u64,
}

impl Default for MemoryBudget {
    fn default() -> Self {
        MemoryBudget {
            bytes: DEFAULT_MEMORY_BUDGET_BYTES,
        }
    }
}

/// Why work was refused, or a budget or thread count could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum BudgetError {
    /// The job's estimated peak is over the budget.
    #[error(
        "{what} needs {}: over the memory budget of {} (raise it with {MEMORY_BUDGET_FLAG})",
        format_bytes(*need_bytes),
        format_bytes(*budget_bytes)
    )]
    OverBudget {
        what: String,
        need_bytes: u64,
        budget_bytes: u64,
    },
    /// A budget that is not a size.
    #[error("memory budget '{text}': {reason} (a size such as 512MiB, 8GiB or a number of bytes)")]
    Parse { text: String, reason: String },
}

impl MemoryBudget {
    /// A budget of `bytes`, at least [`MIN_MEMORY_BUDGET_BYTES`].
    pub fn new(bytes: u64) -> Result<Self, BudgetError> {
        if bytes < MIN_MEMORY_BUDGET_BYTES {
            return Err(BudgetError::Parse {
                text: format!("{bytes}"),
                reason: format!("at least {}", format_bytes(MIN_MEMORY_BUDGET_BYTES)),
            });
        }
        Ok(MemoryBudget { bytes })
    }

    /// Parses `512MiB`, `8GiB`, `1.5G`, `4096` (bytes), …: a number and an optional unit, B,
    /// K/KiB, M/MiB, G/GiB or T/TiB (all powers of 1024; `KB`, `MB`… read the same), any case.
    pub fn parse(text: &str) -> Result<Self, BudgetError> {
        let bad = |reason: &str| BudgetError::Parse {
            text: text.to_string(),
            reason: reason.to_string(),
        };
        let trimmed = text.trim();
        let split = trimmed
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .unwrap_or(trimmed.len());
        let (number, unit) = trimmed.split_at(split);
        let value: f64 = number.parse().map_err(|_| bad("not a number"))?;
        let unit = unit.trim().to_ascii_lowercase();
        let scale = match unit.trim_end_matches('b').trim_end_matches('i') {
            "" => 1,
            "k" => KIB,
            "m" => MIB,
            "g" => GIB,
            "t" => 1024 * GIB,
            _ => return Err(bad("unknown unit")),
        };
        let bytes = value * scale as f64;
        if !bytes.is_finite() || bytes >= u64::MAX as f64 {
            return Err(bad("too large"));
        }
        MemoryBudget::new(bytes as u64).map_err(|e| match e {
            BudgetError::Parse { reason, .. } => bad(&reason),
            other => other,
        })
    }

    /// This budget split between `parts` jobs running at once (at least one part).
    pub fn share(self, parts: usize) -> Self {
        MemoryBudget {
            bytes: self.bytes / parts.max(1) as u64,
        }
    }

    /// Fails when `need_bytes` is over the budget; `what` names the work ("a 16384×16384 px
    /// frame to draw and write"), made only on failure.
    pub fn check(&self, need_bytes: u64, what: impl FnOnce() -> String) -> Result<(), BudgetError> {
        if need_bytes > self.bytes {
            return Err(BudgetError::OverBudget {
                what: what(),
                need_bytes,
                budget_bytes: self.bytes,
            });
        }
        Ok(())
    }

    /// The most frames, up to `max_frames`, that fit at once: `fixed_bytes` + frames × their
    /// `per_frame_bytes` + min(frames, `threads`) × `per_thread_bytes` within the budget.
    /// Fails (naming `what`, with the cost of one frame) when not even one fits.
    pub fn frames_in_flight(
        &self,
        cost: &FrameCost,
        max_frames: usize,
        what: impl FnOnce() -> String,
    ) -> Result<usize, BudgetError> {
        let need = |frames: usize| cost.peak_bytes(frames);
        self.check(need(1), what)?;
        let mut frames = 1;
        while frames < max_frames && need(frames + 1) <= self.bytes {
            frames += 1;
        }
        Ok(frames)
    }
}

/// What a job holding frames costs: fixed, per frame held, per thread working on them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameCost {
    /// Held whatever the number of frames, bytes.
    pub fixed_bytes: u64,
    /// Held per frame in flight, bytes.
    pub per_frame_bytes: u64,
    /// Held per thread busy with a frame, bytes.
    pub per_thread_bytes: u64,
    /// Threads that work on the frames at once (the thread pool's size).
    pub threads: usize,
}

impl FrameCost {
    /// The peak with `frames` frames in flight, bytes.
    pub fn peak_bytes(&self, frames: usize) -> u64 {
        let busy = frames.min(self.threads.max(1)) as u64;
        self.fixed_bytes
            .saturating_add(self.per_frame_bytes.saturating_mul(frames as u64))
            .saturating_add(self.per_thread_bytes.saturating_mul(busy))
    }
}

/// Bytes of `px` pixels at `bytes_per_px` each.
pub fn px_bytes(size_px: (u32, u32), bytes_per_px: u64) -> u64 {
    u64::from(size_px.0)
        .saturating_mul(u64::from(size_px.1))
        .saturating_mul(bytes_per_px)
}

/// `bytes` for people: `512 B`, `64.0 MiB`, `2.0 GiB`.
pub fn format_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    if bytes < KIB {
        format!("{bytes} B")
    } else if bytes < MIB {
        format!("{:.1} KiB", b / KIB as f64)
    } else if bytes < GIB {
        format!("{:.1} MiB", b / MIB as f64)
    } else {
        format!("{:.1} GiB", b / GIB as f64)
    }
}

/// The process's budget, bytes (see the module doc).
static PROCESS_BUDGET_BYTES: AtomicU64 = AtomicU64::new(DEFAULT_MEMORY_BUDGET_BYTES);

thread_local! {
    /// A budget for the work this thread runs, set by [`with_memory_budget`].
    static SCOPED_BUDGET_BYTES: Cell<Option<u64>> = const { Cell::new(None) };
}

/// The budget in force on this thread: its [`with_memory_budget`] scope's, else the process's.
pub fn memory_budget() -> MemoryBudget {
    let bytes = SCOPED_BUDGET_BYTES
        .with(Cell::get)
        .unwrap_or_else(|| PROCESS_BUDGET_BYTES.load(Ordering::Relaxed));
    MemoryBudget { bytes }
}

/// Sets the process's budget (the shell does so once, from its flag or the environment).
pub fn set_memory_budget(budget: MemoryBudget) {
    PROCESS_BUDGET_BYTES.store(budget.bytes, Ordering::Relaxed);
}

/// Runs `work` on this thread with `budget` in force (restored after, scopes nest).
pub fn with_memory_budget<R>(budget: MemoryBudget, work: impl FnOnce() -> R) -> R {
    struct Restore(Option<u64>);
    impl Drop for Restore {
        fn drop(&mut self) {
            SCOPED_BUDGET_BYTES.with(|b| b.set(self.0));
        }
    }
    let _restore = Restore(SCOPED_BUDGET_BYTES.with(|b| b.replace(Some(budget.bytes))));
    work()
}

/// The most threads a thread count may ask for on this machine: [`THREADS_PER_CORE`] per core.
pub fn max_threads() -> usize {
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
    cores.saturating_mul(THREADS_PER_CORE)
}

/// `asked` threads bounded by the machine ([`max_threads`]); 0 stays 0 (one per core, the
/// pools' default). The second value tells whether the count was lowered.
pub fn bounded_threads(asked: usize) -> (usize, bool) {
    let max = max_threads();
    if asked > max {
        (max, true)
    } else {
        (asked, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_binary_units() {
        let p = |t: &str| MemoryBudget::parse(t).map(|b| b.bytes);
        assert_eq!(p("8GiB"), Ok(8 * GIB));
        assert_eq!(p("8G"), Ok(8 * GIB));
        assert_eq!(p("512 MiB"), Ok(512 * MIB));
        assert_eq!(p("1.5gb"), Ok(3 * GIB / 2));
        assert_eq!(p("2097152"), Ok(2 * MIB));
        for bad in ["", "GiB", "8 parsecs", "-1GiB", "1e400", "64", "1.2.3M"] {
            let err = MemoryBudget::parse(bad).unwrap_err();
            assert!(matches!(err, BudgetError::Parse { .. }), "{bad}: {err}");
        }
        assert_eq!(format_bytes(3 * GIB / 2), "1.5 GiB");
        assert_eq!(format_bytes(64 * MIB), "64.0 MiB");
        assert_eq!(format_bytes(12), "12 B");
    }

    #[test]
    fn frames_in_flight_fill_the_budget_and_refuse_when_one_does_not_fit() {
        let budget = MemoryBudget { bytes: 100 };
        let cost = FrameCost {
            fixed_bytes: 10,
            per_frame_bytes: 10,
            per_thread_bytes: 20,
            threads: 2,
        };
        // 10 + 10 n + 20 min(n, 2) ≤ 100: n = 5 (10 + 50 + 40).
        assert_eq!(budget.frames_in_flight(&cost, 16, String::new), Ok(5));
        assert_eq!(budget.frames_in_flight(&cost, 3, String::new), Ok(3));
        let err = MemoryBudget { bytes: 39 }
            .frames_in_flight(&cost, 16, || "a frame".into())
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "a frame needs 40 B: over the memory budget of 39 B (raise it with --memory-budget)"
        );
    }

    #[test]
    fn a_scoped_budget_holds_on_its_thread_only_and_is_restored() {
        let outer = memory_budget();
        let small = MemoryBudget { bytes: 5 * MIB };
        with_memory_budget(small, || {
            assert_eq!(memory_budget(), small);
            let tiny = MemoryBudget { bytes: 2 * MIB };
            with_memory_budget(tiny, || assert_eq!(memory_budget(), tiny));
            assert_eq!(memory_budget(), small);
            std::thread::spawn(move || assert_eq!(memory_budget(), outer))
                .join()
                .unwrap();
        });
        assert_eq!(memory_budget(), outer);
        assert_eq!(small.share(2).bytes, 5 * MIB / 2);
        assert_eq!(small.share(0), small);
    }

    #[test]
    fn thread_counts_are_bounded_by_the_machine() {
        assert_eq!(bounded_threads(0), (0, false));
        assert_eq!(bounded_threads(1), (1, false));
        let max = max_threads();
        assert!(max >= THREADS_PER_CORE);
        assert_eq!(bounded_threads(1_000_000), (max, true));
        assert_eq!(bounded_threads(max), (max, false));
    }
}
