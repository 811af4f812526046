//! `host-sim firmware`: builds the firmware variants, runs the emulated ones in QEMU with
//! `-icount shift=0`, checks every frame bit for bit against the same render on the host,
//! measures flash, RAM and instructions per frame, and writes `docs/firmware.md`.

use crate::load::{object_storage, parse_scene, read};
use crate::run::render_with;
use anyhow::{bail, Context, Result};
use lattice_rt::{Frame, LatticeConfig, Tracer};
use object::{Object, ObjectSection, SectionFlags};
use std::fmt::Write as _;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// SysTick runs at the mps2 boards' 25 MHz; under `-icount shift=0` one instruction is 1 ns.
const INSTRUCTIONS_PER_TICK: u64 = 40;

/// One firmware build.
struct Variant {
    name: &'static str,
    target: &'static str,
    features: &'static str,
    bin: &'static str,
    machine: Option<&'static str>,
    scenes: Option<&'static str>,
    what: &'static str,
}

const VARIANTS: [Variant; 4] = [
    Variant { name: "qemu-m0", target: "thumbv6m-none-eabi", features: "qemu", bin: "qemu", machine: Some("mps2-an385"), scenes: None, what: "Cortex-M0+ build (runs on QEMU's Cortex-M3 board), all five scenes" },
    Variant { name: "qemu-m4f", target: "thumbv7em-none-eabihf", features: "qemu", bin: "qemu", machine: Some("mps2-an386"), scenes: None, what: "Cortex-M4F build, all five scenes" },
    Variant { name: "qemu-m0-chair", target: "thumbv6m-none-eabi", features: "qemu", bin: "qemu", machine: Some("mps2-an385"), scenes: Some("chair"), what: "Cortex-M0+ build with only the chair embedded" },
    Variant { name: "pico", target: "thumbv6m-none-eabi", features: "pico", bin: "pico", machine: None, scenes: None, what: "Raspberry Pi Pico + SSD1306 image (built with the default linker; `cargo pico` links the same code with flip-link)" },
];

fn target_dir(root: &Path, v: &Variant) -> PathBuf {
    root.join("firmware/target/variants").join(v.name)
}

fn elf_path(root: &Path, v: &Variant) -> PathBuf {
    target_dir(root, v).join(v.target).join("release").join(v.bin)
}

fn build(root: &Path, v: &Variant) -> Result<()> {
    eprintln!("  building {} ({})", v.name, v.target);
    let mut cmd = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    cmd.current_dir(root.join("firmware"))
        .args(["build", "--release", "--features", v.features, "--bin", v.bin, "--target", v.target, "--target-dir"])
        .arg(target_dir(root, v))
        .env_remove("RUSTFLAGS");
    match v.scenes {
        Some(s) => cmd.env("FIRMWARE_SCENES", s),
        None => cmd.env_remove("FIRMWARE_SCENES"),
    };
    let status = cmd.status().context("cannot run cargo")?;
    if !status.success() {
        bail!("building firmware variant {} failed", v.name);
    }
    Ok(())
}

/// Flash bytes (every allocated section with contents, `.data` counted at its load address)
/// and static RAM bytes (`.data`, `.bss`, `.uninit`).
fn sizes(elf: &Path) -> Result<(u64, u64)> {
    let data = std::fs::read(elf).with_context(|| format!("cannot read {}", elf.display()))?;
    let file = object::File::parse(&*data)?;
    let (mut flash, mut ram) = (0, 0);
    for s in file.sections() {
        let SectionFlags::Elf { sh_flags } = s.flags() else { continue };
        if sh_flags & object::elf::SHF_ALLOC as u64 == 0 || s.size() == 0 {
            continue;
        }
        let in_ram = (0x2000_0000..0x3000_0000).contains(&s.address());
        let has_bytes = s.file_range().is_some();
        if has_bytes {
            flash += s.size();
        }
        if in_ram {
            ram += s.size();
        }
    }
    Ok((flash, ram))
}

/// What one QEMU run printed.
#[derive(Default)]
struct Run {
    scenes: Vec<SceneRun>,
    stack: u64,
    statics: u64,
    errors: Vec<String>,
}

struct SceneRun {
    name: String,
    ticks: u64,
    rays: u64,
    tests: u64,
    stack_so_far: u64,
    rows: Vec<u8>,
}

fn field(line: &str, key: &str) -> u64 {
    let mut it = line.split_whitespace();
    while let Some(w) = it.next() {
        if w == key {
            return it.next().and_then(|v| v.parse().ok()).unwrap_or(0);
        }
    }
    0
}

fn run_qemu(elf: &Path, machine: &str) -> Result<Run> {
    let mut child = Command::new("qemu-system-arm")
        .args(["-machine", machine, "-nographic", "-monitor", "none", "-serial", "none"])
        .args(["-semihosting-config", "enable=on,target=native", "-icount", "shift=0", "-kernel"])
        .arg(elf)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .context("cannot start qemu-system-arm (Debian package qemu-system-arm)")?;
    let mut out = String::new();
    let mut stdout = child.stdout.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stdout.read_to_string(&mut s);
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(st) = child.try_wait()? {
            break st;
        }
        if start.elapsed() > Duration::from_secs(600) {
            let _ = child.kill();
            bail!("QEMU ran for more than 10 minutes on {}", elf.display());
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    out.push_str(&reader.join().unwrap_or_default());
    let mut run = Run::default();
    for line in out.lines() {
        if let Some(rest) = line.strip_prefix("SCENE ") {
            run.scenes.push(SceneRun {
                name: rest.split_whitespace().next().unwrap_or("").to_string(),
                ticks: field(line, "ticks"),
                rays: field(line, "rays"),
                tests: field(line, "tests"),
                stack_so_far: field(line, "stack_so_far"),
                rows: Vec::new(),
            });
        } else if let Some(hex) = line.strip_prefix("ROW ") {
            if let Some(s) = run.scenes.last_mut() {
                let bytes = (0..hex.len() / 2).filter_map(|i| u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).ok());
                s.rows.extend(bytes);
            }
        } else if line.starts_with("RAM ") {
            run.stack = field(line, "stack_high_water");
            run.statics = field(line, "static");
        } else if line.starts_with("ERROR") || line.starts_with("PANIC") || line.starts_with("HARDFAULT") {
            run.errors.push(line.to_string());
        }
    }
    if !status.success() && run.errors.is_empty() {
        run.errors.push(format!("QEMU exited with {status}"));
    }
    Ok(run)
}

/// The host's 1-bit frame of a scene in f32 with the firmware's settings.
fn host_frame(scenes: &Path, name: &str) -> Result<Vec<u8>> {
    let path = scenes.join(format!("{name}.scene"));
    let text = read(&path)?;
    let mut storage = object_storage::<f32>(&text);
    let scene = parse_scene::<f32>(&path, &text, &mut storage)?;
    let cfg = LatticeConfig::default();
    let mut bufs = crate::load::LatticeBufs::for_scene(&scene, &cfg);
    let lattice = bufs.build(&scene, &cfg)?;
    let frame = Frame::new(128, 64);
    Ok(render_with(&Tracer::new(&scene, &lattice), &frame, false)?.bits)
}

/// The command.
pub fn firmware_cmd(root: &Path, out: &Path, skip_build: bool) -> Result<()> {
    let (mut passed, mut failed) = (0, 0);
    let mut md = String::new();
    writeln!(md, "# Firmware budgets\n\nWritten by `cargo run --release -p host-sim -- firmware` (also run by `.ci/run`).\nFrames are 128x64, f32, lattice, Bayer dither, each scene's own effects and depth.\n")?;
    writeln!(md, "## Builds\n\n| variant | what | flash bytes | static RAM | stack high-water | RAM total |\n|---|---|---|---|---|---|")?;
    let mut runs = Vec::new();
    for v in &VARIANTS {
        if !skip_build {
            build(root, v)?;
        }
        let elf = elf_path(root, v);
        let (flash, _) = sizes(&elf)?;
        let run = match v.machine {
            Some(m) => {
                eprintln!("  running {} on {m}", v.name);
                Some(run_qemu(&elf, m)?)
            }
            None => None,
        };
        match &run {
            Some(r) => writeln!(md, "| {} | {} | {flash} | {} | {} | {} |", v.name, v.what, r.statics, r.stack, r.statics + r.stack)?,
            None => writeln!(md, "| {} | {} | {flash} | (needs a board) | (needs a board) | |", v.name, v.what)?,
        }
        if let Some(r) = run {
            runs.push((v, r));
        }
    }
    writeln!(md, "\nRAM is measured, not estimated: cortex-m-rt paints the stack at reset (`paint-stack`) and the\nfirmware reports the deepest word that lost the paint. All scene storage lives on the stack,\nsized by `firmware/build.rs` to exactly what the embedded scenes need.\n")?;
    writeln!(md, "## Instructions per frame (QEMU, `-icount shift=0`)\n\nSysTick ticks x {INSTRUCTIONS_PER_TICK} (25 MHz SysTick, 1 ns per instruction): deterministic.\n")?;
    writeln!(md, "| scene | rays | object tests | M0 instructions | M0 instr/ray | M4F instructions | M4F instr/ray | M0 / M4F | frames bit-identical to host-sim |\n|---|---|---|---|---|---|---|---|---|")?;
    let scenes_dir = root.join("scenes");
    let find = |name: &str, variant: &str| runs.iter().find(|(v, _)| v.name == variant).and_then(|(_, r)| r.scenes.iter().find(|s| s.name == name));
    for (v, r) in &runs {
        for e in &r.errors {
            eprintln!("FAIL {}: {e}", v.name);
            failed += 1;
        }
        for s in &r.scenes {
            let want = host_frame(&scenes_dir, &s.name)?;
            if want == s.rows {
                passed += 1;
            } else {
                failed += 1;
                let differ = want.iter().zip(&s.rows).map(|(a, b)| (a ^ b).count_ones()).sum::<u32>();
                eprintln!("FAIL {} {}: frame differs from host-sim in {differ} pixels", v.name, s.name);
            }
        }
    }
    if let Some((_, m0)) = runs.iter().find(|(v, _)| v.name == "qemu-m0") {
        for s in &m0.scenes {
            let m4 = find(&s.name, "qemu-m4f");
            let i0 = s.ticks * INSTRUCTIONS_PER_TICK;
            let (i4, r4) = m4.map_or((0, 0.0), |m| (m.ticks * INSTRUCTIONS_PER_TICK, (m.ticks * INSTRUCTIONS_PER_TICK) as f64 / m.rays.max(1) as f64));
            let same = ["qemu-m0", "qemu-m4f", "qemu-m0-chair"]
                .iter()
                .filter_map(|v| find(&s.name, v).map(|x| (v, x)))
                .map(|(v, x)| format!("{v}: {}", if host_frame(&scenes_dir, &s.name).map(|h| h == x.rows).unwrap_or(false) { "yes" } else { "NO" }))
                .collect::<Vec<_>>()
                .join(", ");
            writeln!(
                md,
                "| {} | {} | {} | {} | {:.0} | {} | {:.0} | {:.2} | {same} |",
                s.name, s.rays, s.tests, i0, i0 as f64 / s.rays.max(1) as f64, i4, r4, i0 as f64 / i4.max(1) as f64
            )?;
        }
        if let Some(chair) = find("chair", "qemu-m0-chair") {
            let statics = runs.iter().find(|(v, _)| v.name == "qemu-m0-chair").map_or(0, |(_, r)| r.statics);
            writeln!(md, "\nChair at 128x64 on the M0 build with only the chair embedded: static {statics} + stack {} = {} bytes of RAM (budget 16384).", chair.stack_so_far, statics + chair.stack_so_far)?;
        }
    }
    std::fs::create_dir_all(out.parent().unwrap_or(Path::new(".")))?;
    std::fs::write(out, md).with_context(|| format!("cannot write {}", out.display()))?;
    println!("wrote {}", out.display());
    println!("firmware: {passed} passed, {failed} failed");
    if failed > 0 {
        bail!("{failed} firmware checks failed");
    }
    Ok(())
}
