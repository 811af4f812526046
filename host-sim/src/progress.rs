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

/// Scenes of at least this many objects show what loading them is doing ([`step`]).
pub const LARGE_SCENE: usize = 20_000;

/// A spinner that says what a long step is doing and for how long (ticking on its own while
/// the step runs on this thread); hidden, as [`bar`], when stderr is no terminal, and cleared
/// when dropped. `None` for a scene of fewer than [`LARGE_SCENE`] objects, which loads at once.
pub fn step(objects: usize, what: impl Display) -> Option<ProgressBar> {
    if objects < LARGE_SCENE {
        return None;
    }
    let b = ProgressBar::new_spinner().with_finish(ProgressFinish::AndClear);
    b.set_style(ProgressStyle::with_template("  {spinner} {msg} ({elapsed})").expect("a valid template"));
    b.set_message(what.to_string());
    b.enable_steady_tick(std::time::Duration::from_millis(100));
    Some(b)
}

/// Prints a log line above the bar (plainly when the bar is hidden).
pub fn log(b: &ProgressBar, line: impl Display) {
    b.suspend(|| eprintln!("{line}"));
}
