//! No scene file and no flag makes host-sim use more than 1 GiB, panic or abort (issue 13,
//! classes 4, 5 and 9). Each case runs the real binary in a child process whose address space
//! is limited to 1 GiB (`ulimit -v`): an allocation past the limit would abort it. The peak
//! resident memory of the children is measured with `getrusage` and printed.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const LIMIT_KIB: u64 = 1 << 20;

fn work() -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("limits");
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs host-sim with `args` under the 1 GiB limit.
fn run(args: &[&str]) -> Output {
    Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {LIMIT_KIB} && exec \"$0\" \"$@\""))
        .arg(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .current_dir(work())
        .output()
        .expect("run host-sim")
}

/// Peak resident memory of the largest child so far, in bytes.
fn peak_child_rss() -> u64 {
    // SAFETY: an all-zero `rusage` is a valid value, and getrusage only writes into it.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    let ok = unsafe { libc::getrusage(libc::RUSAGE_CHILDREN, &mut u) } == 0;
    assert!(ok, "getrusage failed");
    u.ru_maxrss as u64 * 1024
}

/// Asserts a clean refusal: exit code 1 (an error) or 2 (a usage error), no panic or abort,
/// and a message containing every one of `words`.
fn refused(args: &[&str], words: &[&str]) {
    let out = run(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        matches!(out.status.code(), Some(1) | Some(2)),
        "{args:?}: {:?} (a signal means abort or kill)\n{err}",
        out.status
    );
    assert!(!err.contains("panicked") && !err.contains("memory allocation"), "{args:?}: {err}");
    for w in words {
        assert!(err.contains(w), "{args:?}: the message lacks `{w}`:\n{err}");
    }
}

fn write(name: &str, bytes: &[u8]) -> String {
    let p = work().join(name);
    std::fs::write(&p, bytes).unwrap();
    p.display().to_string()
}

fn chair() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/chair.scene").display().to_string()
}

#[test]
fn hostile_inputs_and_flags_are_refused_within_a_gibibyte() {
    let chair = chair();
    let blank = write("blank.scene", &vec![b'\n'; 10 << 20]);
    refused(&["render", &blank], &["blank.scene", "scene has no objects"]);
    refused(&["render", "/dev/zero"], &["/dev/zero", "larger than 32 MiB"]);
    let spheres = write("spheres.scene", "sphere\n".repeat(4 << 20).as_bytes());
    refused(&["render", &spheres], &["declares 4194304 objects", "limit"]);
    let latin1 = write("latin1.scene", b"sphere\n# caf\xe9\n");
    refused(&["render", &latin1], &["latin1.scene: line 2, column 6: not UTF-8 text (byte 0xe9)"]);
    refused(&["render", &chair, "--scale", "4294967295"], &["--scale"]);
    refused(&["render", &chair, "--scale", "1000"], &["--scale"]);
    refused(&["render", &chair, "--size", "1x1", "--scale", "65536"], &["--scale"]);
    refused(&["render", &chair, "--size", "4096x4096", "--scale", "64"], &["--scale", "--size"]);
    refused(&["render", &chair, "--size", "100000x10"], &["--size"]);
    refused(&["stats", &chair, "--cells", "1024x1024x1024"], &["--cells"]);
    refused(&["render", &chair, "--cells", "1024x1024x1024"], &["--cells"]);
    refused(&["render", &chair, "--cells", "0x1x1"], &["--cells"]);
    refused(&["render", &chair, "--tile", "255"], &["--tile"]);
    let peak = peak_child_rss();
    eprintln!("peak resident memory of host-sim over the hostile cases: {:.1} MiB", peak as f64 / (1 << 20) as f64);
    assert!(peak < 1 << 30);
}

#[test]
fn a_100000_object_scene_renders_well_under_a_gibibyte() {
    let mut text = String::from("camera eye 0 30 -120 look 0 0 0\nlight directional dir -1 -2 1\n");
    for i in 0..100_000 {
        let (x, y, z) = (i % 100, (i / 100) % 10, i / 1000);
        text.push_str(&format!("sphere center {} {} {} radius 0.3\n", x - 50, y, z - 50));
    }
    let scene = write("many.scene", text.as_bytes());
    let png = work().join("many.png");
    let _ = std::fs::remove_file(&png);
    let out = run(&["render", &scene, "-o", &png.display().to_string()]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(png.exists());
    let peak = peak_child_rss();
    eprintln!(
        "peak resident memory (largest child so far, 100,000 objects): {:.1} MiB",
        peak as f64 / (1 << 20) as f64
    );
    assert!(peak < 1 << 30);
}

#[test]
fn a_failed_command_leaves_no_output_and_names_the_path() {
    let chair = chair();
    let dir = work().join("half");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("a.png");
    // The PGM goes below a regular file (no one, not even root, can create it): nothing may be
    // left, not even the PNG.
    let file = write("a-file", b"not a folder");
    let pgm = format!("{file}/a.pgm");
    refused(&["render", &chair, "-o", &png.display().to_string(), "--gray", &pgm], &[&pgm]);
    let left: Vec<_> = std::fs::read_dir(&dir).unwrap().flatten().map(|e| e.path()).collect();
    assert!(left.is_empty(), "left behind: {left:?}");
    let pov = format!("{file}/chair.pov");
    refused(&["export", &chair, "--pov", "-o", &pov], &[&pov]);
}

#[test]
fn export_refuses_what_povray_cannot_represent_and_ids_go_past_254() {
    // A scene a billion times smaller than usual: f64 traces it, POV-Ray's matrices cannot hold it.
    let tiny = write("tiny.scene", b"camera eye 0 0 -1e-8\nlight directional dir 0 -1 0\nsphere radius 1e-10\n");
    let out = work().join("tiny.pov");
    let _ = std::fs::remove_file(&out);
    refused(
        &["export", &tiny, "--pov", "-o", &out.display().to_string()],
        &["tiny.scene: line 3, column 1: cannot export object 0: POV-Ray cannot represent"],
    );
    assert!(!out.exists());
    let mut text = String::from("camera eye 0 0 -60\n");
    for i in 0..300 {
        text.push_str(&format!("sphere center {} {} 0 radius 0.4\n", i % 20 - 10, i / 20 - 7));
    }
    let many = write("many-ids.scene", text.as_bytes());
    let pov = work().join("many-ids.pov");
    let res = run(&["export", &many, "--pov", "--ids", "-o", &pov.display().to_string()]);
    assert!(res.status.success(), "{}", String::from_utf8_lossy(&res.stderr));
    let written = std::fs::read_to_string(&pov).unwrap();
    let colours: HashSet<&str> = written.lines().filter_map(|l| l.split("pigment {").nth(1)).collect();
    assert_eq!(colours.len(), 300, "every object its own colour");
}
