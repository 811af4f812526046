//! Standard output that cannot take the output: a reader that went away (`| head`) ends the
//! command quietly, and a full disk (`> /dev/full`) is an error message, never a panic, for
//! every command that writes to standard output.

use std::process::{Command, Stdio};

fn scenes() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

/// The commands that write to standard output, each with enough output to fill a pipe's
/// buffer or to be cut by `head -1`.
fn commands() -> Vec<Vec<String>> {
    let desk = scenes().join("desk.scene").display().to_string();
    let chair = scenes().join("chair.scene").display().to_string();
    [
        vec!["spd", "balls", "-s", "3", "-o", "-"],
        vec!["stats", &desk, "--json"],
        vec!["stats", &chair],
        vec!["render", &chair, "-o", "-"],
    ]
    .into_iter()
    .map(|v| v.into_iter().map(String::from).collect())
    .collect()
}

#[test]
fn a_closed_pipe_ends_the_command_quietly() {
    for args in commands() {
        // `sh -c 'host-sim ... | head -c 1'`: head leaves after one byte and the pipe closes.
        let line = format!("\"$0\" {} | head -c 1 > /dev/null; exit ${{PIPESTATUS[0]}}", args.join(" "));
        let out = Command::new("bash")
            .arg("-c")
            .arg(line)
            .arg(env!("CARGO_BIN_EXE_host-sim"))
            .stderr(Stdio::piped())
            .output()
            .expect("run host-sim");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_eq!(out.status.code(), Some(0), "{args:?}: {err}");
        assert!(err.is_empty() || !err.contains("error"), "{args:?}: {err}");
    }
}

#[test]
fn a_full_disk_is_an_error_message() {
    if !std::path::Path::new("/dev/full").exists() {
        return; // not a Linux machine: nothing to write to
    }
    for args in commands() {
        let full = std::fs::OpenOptions::new().write(true).open("/dev/full").expect("open /dev/full");
        let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
            .args(&args)
            .stdout(Stdio::from(full))
            .stderr(Stdio::piped())
            .output()
            .expect("run host-sim");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(err.contains("error: cannot write") && err.contains("No space left"), "{args:?}: {err}");
    }
}
