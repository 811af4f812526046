//! `cargo xtask playground`: builds the browser playground (`playground/`) into a folder a static
//! file server can serve: the core compiled to WebAssembly with wasm-bindgen's glue, the page,
//! the emulated board bundled by esbuild as a Web Worker, the Pico image as `host-sim uf2` writes
//! it, the RP2040 bootrom, and `cost.json` (instructions per ray and per object test on the Pico's
//! core, fitted to the firmware report). `--serve` serves it; `--check` opens it in headless Chromium
//! (`playground/test.mjs`) and requires the panel, the errors and the Pico image's first frame
//! to be what host-sim gives.

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The wasm-bindgen version the `playground` crate pins (its glue must come from the same CLI).
const WASM_BINDGEN: &str = "0.2.105";

/// What `cargo xtask playground` was asked.
pub struct PlaygroundArgs {
    /// Folder the page is built into.
    pub out: PathBuf,
    /// Serve the page at this address once built.
    pub serve: Option<String>,
    /// Run the browser test once built.
    pub check: bool,
    /// Where the browser test writes its screenshot.
    pub screenshot: Option<PathBuf>,
    /// Use the Pico image already built.
    pub no_build: bool,
}

fn run(cmd: &mut Command, what: &str) -> Result<()> {
    let status = cmd.status().with_context(|| format!("cannot run {what}"))?;
    if !status.success() {
        bail!("{what} failed ({status})");
    }
    Ok(())
}

fn copy(from: &Path, to: &Path) -> Result<()> {
    std::fs::copy(from, to).with_context(|| format!("cannot copy {} to {}", from.display(), to.display()))?;
    Ok(())
}

/// `cargo xtask playground`.
pub fn playground_cmd(root: &Path, a: &PlaygroundArgs) -> Result<()> {
    let out = root.join(&a.out);
    build(root, &out, a.no_build)?;
    println!("built the playground in {}", out.display());
    if a.check {
        let host_sim = root.join("target/release/host-sim");
        run(
            Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into())).current_dir(root).args([
                "build",
                "--release",
                "-p",
                "host-sim",
            ]),
            "cargo build -p host-sim",
        )?;
        let mut test = Command::new("node");
        test.current_dir(root).arg("playground/test.mjs").arg("--dist").arg(&out).arg("--host-sim").arg(&host_sim);
        if let Some(s) = &a.screenshot {
            test.arg("--screenshot").arg(root.join(s));
        }
        run(&mut test, "the browser test (node playground/test.mjs)")?;
    }
    if let Some(addr) = &a.serve {
        run(
            Command::new("node").current_dir(root).arg("playground/serve.mjs").arg(&out).arg(addr),
            "node playground/serve.mjs",
        )?;
    }
    Ok(())
}

/// Builds the page into `out`.
fn build(root: &Path, out: &Path, no_build: bool) -> Result<()> {
    let version = Command::new("wasm-bindgen")
        .arg("--version")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string());
    if version.as_deref() != Some(&format!("wasm-bindgen {WASM_BINDGEN}")) {
        bail!(
            "the page's glue needs wasm-bindgen {WASM_BINDGEN} (found: {}): cargo install --locked wasm-bindgen-cli --version {WASM_BINDGEN}; and rustup target add wasm32-unknown-unknown",
            version.as_deref().unwrap_or("none")
        );
    }
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    eprintln!("building the core for the page (wasm32-unknown-unknown)");
    run(
        Command::new(&cargo).current_dir(root).args([
            "build",
            "--release",
            "-p",
            "playground",
            "--target",
            "wasm32-unknown-unknown",
        ]),
        "cargo build -p playground --target wasm32-unknown-unknown",
    )?;
    // Built beside `out` and renamed into place: a failed build leaves no half-written page.
    let staging = out.with_extension("partial");
    if staging.exists() {
        std::fs::remove_dir_all(&staging).with_context(|| format!("cannot remove {}", staging.display()))?;
    }
    std::fs::create_dir_all(&staging).with_context(|| format!("cannot create {}", staging.display()))?;
    let wasm = root.join("target/wasm32-unknown-unknown/release/playground.wasm");
    run(
        Command::new("wasm-bindgen").arg("--target").arg("web").arg("--out-dir").arg(staging.join("pkg")).arg(&wasm),
        "wasm-bindgen",
    )?;
    let web = root.join("playground/web");
    for f in ["index.html", "app.js", "style.css"] {
        copy(&web.join(f), &staging.join(f))?;
    }
    board_files(root, &staging, no_build)?;
    let scenes: Vec<String> = host_sim::shared::default_scene_paths()
        .iter()
        .map(|p| p.file_stem().expect("scenes/<name>.scene").to_string_lossy().into_owned())
        .collect();
    let board = serde_json::json!({ "uf2": "pico.uf2", "slotUf2": "pico-slot.uf2", "bootrom": "bootrom-b1.bin", "scenes": scenes });
    std::fs::write(staging.join("board.json"), board.to_string()).context("cannot write board.json")?;
    let cost = cost_fit(root)?;
    std::fs::write(staging.join("cost.json"), cost.to_string()).context("cannot write cost.json")?;
    if out.exists() {
        std::fs::remove_dir_all(out).with_context(|| format!("cannot remove the old {}", out.display()))?;
    }
    std::fs::rename(&staging, out)
        .with_context(|| format!("cannot move {} to {}", staging.display(), out.display()))?;
    Ok(())
}

/// The emulated board's files in `staging`: its worker bundled by esbuild, the Pico image and
/// the slot image as UF2 files (built, or as the last build left them with `no_build`), and
/// the RP2040 bootrom.
fn board_files(root: &Path, staging: &Path, no_build: bool) -> Result<()> {
    let web = root.join("playground/web");
    let npm_dir = root.join("playground");
    if !npm_dir.join("node_modules/esbuild/package.json").exists() {
        eprintln!("installing esbuild and puppeteer-core (npm ci in playground)");
        run(
            Command::new("npm").current_dir(&npm_dir).args(["ci", "--no-audit", "--no-fund"]),
            "npm ci in playground (Node.js 18 or newer)",
        )?;
    }
    let bootrom = crate::board::prepare_emulator(root)?;
    run(
        Command::new(npm_dir.join("node_modules/.bin/esbuild"))
            .arg(web.join("board-worker.js"))
            .args(["--bundle", "--format=iife", "--log-level=warning"])
            .arg(format!("--outfile={}", staging.join("board-worker.js").display())),
        "esbuild (the board worker)",
    )?;
    let elf = if no_build { host_sim::uf2::pico_elf(root) } else { host_sim::uf2::build_pico(root)? };
    host_sim::uf2::write_uf2(&elf, &staging.join("pico.uf2"))?;
    // The slot image, which the page writes the editor's scene beside (`host-sim uf2 --scene`).
    let slot = if no_build {
        host_sim::uf2::kept_image(root, "pico-slot")
    } else {
        host_sim::uf2::build_board(root, host_sim::uf2::Board::Pico, Some("slot"))?
    };
    host_sim::uf2::write_uf2(&slot, &staging.join("pico-slot.uf2"))?;
    copy(&bootrom, &staging.join("bootrom-b1.bin"))?;
    Ok(())
}

/// Least squares for two unknowns: the `[a, b]` that minimise the sum over `rows` of
/// `((a x + b z) / y - 1)^2` (relative errors, so the large scene does not decide alone), from
/// the 2x2 normal equations; `None` when the two columns cannot be told apart.
fn fit(rows: &[([f64; 2], f64)]) -> Option<[f64; 2]> {
    let (mut xx, mut xz, mut zz, mut x1, mut z1) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for ([x, z], y) in rows {
        let (x, z) = (x / y, z / y);
        (xx, xz, zz, x1, z1) = (xx + x * x, xz + x * z, zz + z * z, x1 + x, z1 + z);
    }
    let det = xx * zz - xz * xz;
    if det.abs() <= 1e-12 * xx * zz {
        return None;
    }
    Some([(x1 * zz - z1 * xz) / det, (z1 * xx - x1 * xz) / det])
}

/// The board's cost model: instructions on the Pico's core per ray and per object test, the
/// least-squares fit (relative errors) of the firmware report's instruction counts of the
/// fixed-point Cortex-M0 build (docs/firmware.csv, `qemu-m0-fixed`) to the rays and object
/// tests host-sim counts for the same frames.
fn cost_fit(root: &Path) -> Result<serde_json::Value> {
    let csv_path = root.join("docs/firmware.csv");
    let csv = std::fs::read_to_string(&csv_path).with_context(|| format!("cannot read {}", csv_path.display()))?;
    let mut rows = Vec::new();
    let mut names = Vec::new();
    for (i, line) in csv.lines().enumerate().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() < 6 || f[5] != "qemu-m0-fixed" {
            continue;
        }
        let instr: f64 =
            f[3].parse().with_context(|| format!("{}:{}: instructions `{}`", csv_path.display(), i + 1, f[3]))?;
        let path = root.join(format!("scenes/{}.scene", f[0]));
        let text = host_sim::load::read(&path)?;
        let s = host_sim::run::render_text::<lattice_rt::Fx>(&path, &text, &board_records::frame::FRAME, |_| {})?.stats;
        rows.push(([s.total_rays() as f64, s.object_tests as f64], instr));
        names.push(f[0].to_string());
    }
    let coef = fit(&rows).with_context(|| {
        format!(
            "{}: the qemu-m0-fixed rows cannot tell rays from object tests apart (run cargo xtask firmware)",
            csv_path.display()
        )
    })?;
    let worst = rows.iter().map(|(x, y)| ((x[0] * coef[0] + x[1] * coef[1]) / y - 1.0).abs()).fold(0.0, f64::max);
    eprintln!(
        "board cost fit: {:.0} instructions per ray, {:.0} per object test; worst error {:.1} % ({})",
        coef[0],
        coef[1],
        worst * 100.0,
        names.join(", ")
    );
    Ok(serde_json::json!({
        "perRay": coef[0],
        "perTest": coef[1],
        "source": format!("fitted to the fixed-point Cortex-M0 runs of {} in docs/firmware.csv, worst error {:.0} %", names.join(", "), worst * 100.0),
    }))
}
