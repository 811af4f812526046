//! Progress on long commands: an `indicatif` bar on stderr when it is a terminal, hidden
//! otherwise (as in CI), where the log lines the commands print still appear.

use indicatif::{ProgressBar, ProgressFinish, ProgressStyle};
use std::fmt::Display;

/// A bar over `len` steps of `what`.
pub fn bar(len: usize, what: &str) -> ProgressBar {
    // Cleared when dropped, so the report lines that follow stand alone.
    let b = ProgressBar::new(len as u64).with_finish(ProgressFinish::AndClear);
    let style = ProgressStyle::with_template("  {prefix} [{bar:30}] {pos}/{len} {msg} ({elapsed})")
        .expect("a valid template")
        .progress_chars("=> ");
    b.set_style(style);
    b.set_prefix(what.to_string());
    b
}

/// Prints a log line above the bar (plainly when the bar is hidden).
pub fn log(b: &ProgressBar, line: impl Display) {
    b.suspend(|| eprintln!("{line}"));
}
