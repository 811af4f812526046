//! Standard output as the commands write it: a write that fails is an error the command
//! returns (a full disk says so), never a panic; a reader that went away (`| head`) ends the
//! command quietly ([`is_closed_pipe`]).

use anyhow::{Context, Result};
use std::io::Write;

/// Writes a line to standard output, as `println!` would, returning the failure instead of
/// panicking on it.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => {
        $crate::stdout::line(format_args!($($arg)*))
    };
}

/// Writes `args` and a newline to standard output.
pub fn line(args: std::fmt::Arguments<'_>) -> Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_fmt(args).and_then(|()| out.write_all(b"\n")).context("cannot write to standard output")
}

/// Writes `bytes` to standard output and flushes it.
pub fn bytes(bytes: &[u8]) -> Result<()> {
    let mut out = std::io::stdout().lock();
    out.write_all(bytes).and_then(|()| out.flush()).context("cannot write to standard output")
}

/// Flushes standard output (what is left of the last lines).
pub fn flush() -> Result<()> {
    std::io::stdout().lock().flush().context("cannot write to standard output")
}

/// Whether `e` is standard output's reader having gone away (a closed pipe): the command's
/// output was not wanted further, which is no error.
pub fn is_closed_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| c.downcast_ref::<std::io::Error>().is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe))
}
