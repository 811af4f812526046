//! A view too narrow for the scalar at the frame asked for is refused where the scene gives it
//! (the `camera` statement, NFF's `v`), with its line and column, before anything is rendered.

use std::process::Command;

fn render(name: &str, text: &str, scalar: &str) -> (Option<i32>, String) {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("view");
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join(name);
    std::fs::write(&scene, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["render", scene.to_str().unwrap(), "--scalar", scalar, "-o"])
        .arg(dir.join(format!("{name}.png")))
        .output()
        .expect("run host-sim");
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn a_view_too_narrow_is_refused_at_the_camera() {
    let text = "# a telephoto\nmaterial m kd 0.5\ncamera eye 0 0 -4 fov 1e-9 1e-9\nlight directional dir -1 -1 1\nsphere radius 1\n";
    let nff = "v\nfrom 0 -5 0\nat 0 0 0\nup 0 0 1\nangle 1e-10\nl 0 -5 5\ns 0 0 0 1\n";
    for scalar in ["f32", "fixed"] {
        let (code, err) = render("narrow.scene", text, scalar);
        assert_eq!(code, Some(1), "{err}");
        assert!(err.contains("narrow.scene: line 3, column 1 at `camera`: the view is too narrow"), "{scalar}: {err}");
        let (code, err) = render("narrow.nff", nff, scalar);
        assert_eq!(code, Some(1), "{err}");
        assert!(err.contains("narrow.nff: line 1, column 1 at `v`: the view is too narrow"), "{scalar}: {err}");
    }
    // f64 resolves it: rendered.
    let (code, err) = render("narrow64.scene", text, "f64");
    assert_eq!(code, Some(0), "{err}");
}
