//! What a new user meets first, through the real binary: standard input and output, output
//! formats named by their extension, machine-readable statistics, the board's own frame, the
//! gallery a user can reproduce, the scene slot's file, export without a format flag.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn work(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("first-look").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn scene(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../scenes/{name}.scene")).display().to_string()
}

/// Runs host-sim with `args` in `dir`, `input` on its standard input.
fn run_in(dir: &Path, args: &[&str], input: &[u8]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run host-sim");
    child.stdin.take().unwrap().write_all(input).unwrap();
    child.wait_with_output().unwrap()
}

fn ok(out: &Output) -> (String, String) {
    let (o, e) = (String::from_utf8_lossy(&out.stdout).to_string(), String::from_utf8_lossy(&out.stderr).to_string());
    assert!(out.status.success(), "{:?}\n{e}", out.status);
    (o, e)
}

/// The PNG's width and height.
fn png_size(bytes: &[u8]) -> (u32, u32) {
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "not a PNG");
    let word = |at: usize| u32::from_be_bytes(bytes[at..at + 4].try_into().unwrap());
    (word(16), word(20))
}

#[test]
fn a_scene_from_standard_input_renders_to_standard_output() {
    let dir = work("stdio");
    let text = std::fs::read(scene("chair")).unwrap();
    let out = run_in(&dir, &["render", "-", "-o", "-", "--scale", "1"], &text);
    let (_, err) = ok(&out);
    assert_eq!(png_size(&out.stdout), (128, 64));
    assert!(err.contains("- f64 lattice"), "the statistics go to standard error: {err}");
}

#[test]
fn an_extension_names_the_format_and_a_wrong_one_is_refused_before_anything_is_written() {
    let dir = work("ext");
    let out = run_in(&dir, &["render", &scene("chair"), "-o", "a.png", "--gray", "g.txt"], b"");
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("--gray g.txt: writes the gray levels as .pgm or as a gray .png")
    );
    assert!(!dir.join("a.png").exists(), "nothing is written");
    let out = run_in(&dir, &["render", &scene("chair"), "-o", "a.png", "--pbm", "b.png"], b"");
    assert!(String::from_utf8_lossy(&out.stderr).contains("--pbm b.png: writes a PBM file"));
    ok(&run_in(&dir, &["render", &scene("chair"), "-o", "frame.pbm", "--gray", "gray.png"], b""));
    assert!(std::fs::read(dir.join("frame.pbm")).unwrap().starts_with(b"P4\n128 64\n"));
    assert_eq!(png_size(&std::fs::read(dir.join("gray.png")).unwrap()), (512, 256));
}

#[test]
fn render_json_counts_rays_and_hits_by_kind() {
    let dir = work("json");
    let (o, _) = ok(&run_in(&dir, &["render", &scene("whitted"), "-o", "w.png", "--json"], b""));
    let v: serde_json::Value = serde_json::from_str(&o).expect("JSON on standard output");
    let w = &v["work"];
    for kind in ["eye", "shadow", "reflection", "refraction"] {
        let (rays, hits) = (w["rays"][kind].as_u64().unwrap(), w["hits"][kind].as_u64().unwrap());
        assert!(hits <= rays, "{kind}: {hits} hits of {rays} rays");
    }
    assert!(w["hits"]["shadow"].as_u64().unwrap() > 0 && w["rays"]["refraction"].as_u64().unwrap() > 0);
    assert_eq!(v["width"], 128);
    assert!(v["lattice"]["bytes"].as_u64().unwrap() > 0);
}

#[test]
fn stats_say_what_each_method_did_per_eye_ray() {
    let dir = work("stats");
    let (o, _) = ok(&run_in(&dir, &["stats", &scene("chair"), "--runs", "1", "--json"], b""));
    let v: serde_json::Value = serde_json::from_str(&o).unwrap();
    let per: Vec<(String, f64)> = v["per_eye_ray"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| (m["method"].as_str().unwrap().to_string(), m["object_tests_per_eye_ray"].as_f64().unwrap()))
        .collect();
    // Brute force tests every object for every eye ray; the others test fewer, each its own way.
    assert_eq!(per[0], ("brute".to_string(), 8.0));
    assert!(per[1].1 < 8.0 && per[2].1 < per[1].1 && per[3].0 == "default", "{per:?}");
    assert!(v["per_eye_ray"][2]["cells_per_eye_ray"].as_f64().unwrap() > 0.0, "the lattice walks cells");
    let (text, _) = ok(&run_in(&dir, &["stats", &scene("chair"), "--runs", "1"], b""));
    assert!(text.contains("as in the paper's Table 1") && text.contains("window on the image"), "{text}");
    // A budget too small suggests what stats can do, not render's --accel.
    let out = run_in(&dir, &["stats", &scene("chair"), "--budget", "10"], b"");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no lattice fits --budget 10") && !err.contains("--accel"), "{err}");
}

#[test]
fn render_board_pico_is_the_picos_frame() {
    let dir = work("board");
    ok(&run_in(&dir, &["render", &scene("desk"), "--board", "pico", "-o", "a.pbm"], b""));
    ok(&run_in(
        &dir,
        &[
            "render",
            &scene("desk"),
            "--scalar",
            "fixed",
            "--sampling",
            "coarse",
            "--dither",
            "fs",
            "--tile",
            "16",
            "--cutoff",
            "7",
            "-o",
            "b.pbm",
        ],
        b"",
    ));
    assert_eq!(std::fs::read(dir.join("a.pbm")).unwrap(), std::fs::read(dir.join("b.pbm")).unwrap());
    let out = run_in(&dir, &["render", &scene("desk"), "--board", "pico", "--size", "64x64"], b"");
    assert_eq!(out.status.code(), Some(2), "--board fixes the frame: --size is refused with it");
}

#[test]
fn a_gallery_picture_is_what_its_printed_command_draws() {
    let dir = work("gallery");
    let scenes = dir.join("scenes");
    std::fs::create_dir_all(&scenes).unwrap();
    for name in ["chair", "whitted"] {
        std::fs::copy(scene(name), scenes.join(format!("{name}.scene"))).unwrap();
    }
    let (o, _) = ok(&run_in(&dir, &["gallery", "--scenes", "scenes", "--out", "g"], b""));
    let lines: Vec<&str> = o.lines().filter(|l| l.starts_with("host-sim render")).collect();
    assert_eq!(lines.len(), 4, "two scenes, two sizes, the Whitted scene among them:\n{o}");
    assert!(lines.iter().any(|l| l.contains("whitted.scene --size 160x100")));
    // The first command again, into another file: the same picture.
    let args: Vec<String> = lines[0]
        .split(' ')
        .skip(1)
        .map(|w| if w.ends_with(".png") && !w.ends_with("-gray.png") { "again.png".into() } else { w.into() })
        .collect();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&run_in(&dir, &args, b""));
    let first = lines[0].split(' ').find(|w| w.ends_with(".png") && !w.ends_with("-gray.png")).unwrap();
    assert_eq!(std::fs::read(dir.join(first)).unwrap(), std::fs::read(dir.join("again.png")).unwrap());
}

#[test]
fn export_writes_povray_without_a_format_flag() {
    let dir = work("export");
    ok(&run_in(&dir, &["export", &scene("chair"), "-o", "c.pov"], b""));
    assert!(std::fs::read_to_string(dir.join("c.pov")).unwrap().contains("camera {"));
}

#[test]
fn a_scene_for_the_slot_is_checked_and_the_image_must_be_there() {
    let dir = work("slot");
    std::fs::write(dir.join("bad.scene"), "sphere raduis 1\n").unwrap();
    let out = run_in(&dir, &["uf2", "--scene", "bad.scene", "--image", "none.uf2"], b"");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("cannot read the slot image none.uf2") && err.contains("--features slot"), "{err}");
    std::fs::write(dir.join("fake.uf2"), [0u8; 512]).unwrap();
    let out = run_in(&dir, &["uf2", "--scene", "bad.scene", "--image", "fake.uf2"], b"");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.scene: line 1, column 8 at `raduis`"), "{err}");
    std::fs::write(dir.join("good.scene"), "sphere\n").unwrap();
    let out = run_in(&dir, &["uf2", "--scene", "good.scene", "--image", "fake.uf2"], b"");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("fake.uf2: not a UF2 file"), "{err}");
    assert!(!dir.join("out").exists(), "nothing written");
}
