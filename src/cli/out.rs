//! What a command prints besides its outputs, as loud as `-q` and `-v` ask: reports (what was
//! made, on stdout), details (`-v` only), notes and progress bars (on stderr). Warnings and
//! errors always print; so does data a command is asked for (`sinew schema`, `--events`).

use std::sync::atomic::{AtomicU8, Ordering};
use std::time::Duration;

/// How much a command says: 0 quiet (`-q`), 1 the default, 2 verbose (`-v`).
static LEVEL: AtomicU8 = AtomicU8::new(1);

/// Sets the level from the global flags (clap refuses `-q` with `-v`).
pub fn set(quiet: bool, verbose: bool) {
    let level = match (quiet, verbose) {
        (true, _) => 0,
        (false, true) => 2,
        (false, false) => 1,
    };
    LEVEL.store(level, Ordering::Relaxed);
}

/// Whether `-q` silenced reports, notes and progress.
pub fn quiet() -> bool {
    LEVEL.load(Ordering::Relaxed) == 0
}

/// Whether `-v` asked for details.
pub fn verbose() -> bool {
    LEVEL.load(Ordering::Relaxed) >= 2
}

/// A line of what the command made (stdout), unless `-q`.
macro_rules! report {
    ($($arg:tt)*) => {
        if !$crate::cli::out::quiet() {
            println!($($arg)*);
        }
    };
}
pub(crate) use report;

/// A line of detail (stdout), only with `-v`.
macro_rules! detail {
    ($($arg:tt)*) => {
        if $crate::cli::out::verbose() {
            println!($($arg)*);
        }
    };
}
pub(crate) use detail;

/// A note on stderr (`sinew: note: ...`), unless `-q`.
macro_rules! note {
    ($($arg:tt)*) => {
        if !$crate::cli::out::quiet() {
            eprintln!("sinew: note: {}", format_args!($($arg)*));
        }
    };
}
pub(crate) use note;

/// A progress bar on stderr counting `unit`s (parts, frames, jobs) toward a total set later
/// with `set_length`, with the rate's estimate of the time left. Hidden with `-q` and when
/// stderr is not a terminal (indicatif draws nothing there).
pub fn bar(what: &str, unit: &str) -> indicatif::ProgressBar {
    let bar = if quiet() {
        indicatif::ProgressBar::hidden()
    } else {
        indicatif::ProgressBar::no_length()
    };
    let template = format!("{what} {{bar:30}} {{pos}}/{{len}} {unit} {{msg}} (left: {{eta}})");
    if let Ok(style) = indicatif::ProgressStyle::with_template(&template) {
        bar.set_style(style);
    }
    bar.enable_steady_tick(Duration::from_millis(250));
    bar
}
