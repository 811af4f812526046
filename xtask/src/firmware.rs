//! `cargo xtask firmware`: builds the firmware variants, runs the emulated ones in QEMU with
//! `-icount shift=0`, checks every frame bit for bit against the same render on the host,
//! measures flash, RAM and instructions per frame, and writes `docs/firmware.md`.

use crate::elf::{demangled, Elf};
use anyhow::{bail, Context, Result};
use host_sim::load::read;
use host_sim::run::render_text;
use host_sim::uf2::Scenes;
use std::fmt::Write as _;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod spd;

/// One firmware build.
pub(crate) struct Variant {
    pub(crate) name: String,
    target: &'static str,
    /// Cargo profile: `release` (opt-level "s"), `speed` (opt-level 3) for the boards with flash
    /// to spare, or `small` (opt-level "z") for the parts with little.
    profile: &'static str,
    features: String,
    bin: &'static str,
    pub(crate) machine: Option<&'static str>,
    scenes: Option<&'static str>,
    scalar: &'static str,
    what: String,
    /// The `tiny` build: linked at its memory map's 16 KiB of flash (a bigger image fails to
    /// link, and the report with it), and built without the firmware's default features (the
    /// shapes beyond the chair's boxes and cylinders).
    tiny: bool,
}

/// The Pico 2 core's variant with the scenes baked, as the Pico 2 image has them.
const M33_BAKED: &str = "qemu-m33-f32-baked";
/// The Pico 2 core's variant rendering the Pico 2 image's own frame (the panels' frame:
/// `panel-frame`), its scenes baked.
const M33_PANEL: &str = "qemu-m33-f32-panel";

/// The firmware scalars: (name in reports, cargo feature).
pub const SCALARS: [(&str, &str); 4] = [
    ("f32", ""),
    ("fixed", "scalar-fixed"),
    ("f32-micromath", "scalar-micromath"),
    ("f32-micromath-newton", "scalar-micromath-newton"),
];

impl Variant {
    /// A build of the `qemu` binary in the `release` profile, for QEMU machine `machine`.
    fn qemu(
        name: impl Into<String>,
        (target, machine): (&'static str, &'static str),
        features: impl Into<String>,
        scalar: &'static str,
        what: impl Into<String>,
    ) -> Variant {
        Variant {
            name: name.into(),
            target,
            profile: "release",
            features: features.into(),
            bin: "qemu",
            machine: Some(machine),
            scenes: None,
            scalar,
            what: what.into(),
            tiny: false,
        }
    }
}

/// The Cortex-M0+ target and the QEMU board it runs on (a Cortex-M3 board: QEMU has no M0+ one).
const M0: (&str, &str) = ("thumbv6m-none-eabi", "mps2-an385");
/// The micro:bit: a Cortex-M0 with 16 KiB of RAM.
const MICROBIT: (&str, &str) = ("thumbv6m-none-eabi", "microbit");
/// The Pico 2's core (Cortex-M33) and QEMU's M33 board.
const M33: (&str, &str) = ("thumbv8m.main-none-eabihf", "mps2-an505");
/// The matte paper scenes: what the effect set saves is measured on them.
const MATTE: Option<&str> = Some("chair,desk,polyhedron");

/// A row of [`FIXED_M0`].
type FixedRow =
    (&'static str, (&'static str, &'static str), &'static str, Option<&'static str>, &'static str, &'static str);

/// The fixed-point Cortex-M0 variants, one row each: name, board, profile, scenes (`None`: all
/// five), features, what it is. What adaptive sampling, progressive frames and the effect set
/// cost; baked scenes (each scene and its lattice as tables in flash, nothing parsed or built);
/// the same built for size (the `small` profile, opt-level "z", and the `compact` feature: the
/// compiler's memory helpers as small loops) for parts with little flash; and the smallest
/// parts, the chair alone in 16 KiB of flash and 4 KiB of RAM (tiny/memory.x, linker-enforced).
#[rustfmt::skip]
const FIXED_M0: [FixedRow; 15] = [
    ("microbit-m0-fixed-chair", MICROBIT, "release", Some("chair"), "microbit,scalar-fixed", "BBC micro:bit (nRF51822, Cortex-M0, 16 KiB RAM, run on QEMU's microbit machine), fixed, only the chair embedded"),
    ("qemu-m0-fixed-exact", M0, "release", None, "qemu,scalar-fixed,exact-sampling", "Cortex-M0+, fixed, all five scenes, one eye ray per pixel (exact-sampling) instead of adaptive sub-sampling"),
    ("qemu-m0-fixed-progressive", M0, "release", None, "qemu,scalar-fixed,progressive", "Cortex-M0+, fixed, all five scenes, each frame in four progressive passes (8x8, 4x4, 2x2 blocks, then the frame; the last pass is the frame checked)"),
    ("qemu-m0-fixed-allfx", M0, "release", None, "qemu,scalar-fixed,effects-all", "Cortex-M0+, fixed, all five scenes, every effect compiled in and on"),
    ("qemu-m0-fixed-matte", M0, "release", MATTE, "qemu,scalar-fixed", "Cortex-M0+, fixed, the matte paper scenes, their effects only (shadows, composites)"),
    ("qemu-m0-fixed-matte-allfx", M0, "release", MATTE, "qemu,scalar-fixed,effects-all", "Cortex-M0+, fixed, the matte paper scenes, every effect compiled in"),
    ("qemu-m0-fixed-baked", M0, "release", None, "qemu,scalar-fixed,baked", "Cortex-M0+, fixed, all five scenes baked into flash (no parser, set-up or lattice build linked)"),
    ("qemu-m0-fixed-baked-allfx", M0, "release", None, "qemu,scalar-fixed,baked,effects-all", "Cortex-M0+, fixed, all five scenes baked, every effect compiled in and on"),
    ("qemu-m0-fixed-baked-chair", M0, "release", Some("chair"), "qemu,scalar-fixed,baked", "Cortex-M0+, fixed, only the chair, baked"),
    ("qemu-m0-fixed-baked-matte", M0, "release", MATTE, "qemu,scalar-fixed,baked", "Cortex-M0+, fixed, the matte paper scenes baked, their effects only (shadows, composites)"),
    ("microbit-m0-fixed-baked", MICROBIT, "release", None, "microbit,scalar-fixed,baked", "BBC micro:bit (nRF51822, Cortex-M0, 16 KiB RAM, QEMU's microbit machine), fixed, all five scenes baked"),
    ("qemu-m0-fixed-baked-small", M0, "small", None, "qemu,scalar-fixed,baked,compact", "Cortex-M0+, fixed, all five scenes baked, built for size (`small` profile: opt-level \"z\", `compact` feature)"),
    ("qemu-m0-fixed-baked-allfx-small", M0, "small", None, "qemu,scalar-fixed,baked,effects-all,compact", "Cortex-M0+, fixed, all five scenes baked, every effect compiled in and on, built for size"),
    ("qemu-m0-fixed-baked-matte-small", M0, "small", MATTE, "qemu,scalar-fixed,baked,compact", "Cortex-M0+, fixed, the matte paper scenes baked, their effects only, built for size"),
    (TINY, M0, "small", Some("chair"), "tiny,scalar-fixed,baked,compact", "the smallest Cortex-M0 parts' memory (tiny/memory.x: 16 KiB of flash and 4 KiB of RAM, linker-enforced, flip-link), fixed, only the chair, baked, built for size"),
];

/// Every firmware build the report makes, in its order.
fn variants() -> Vec<Variant> {
    let mut v = scalar_variants();
    v.extend(FIXED_M0.iter().map(|&(name, board, profile, scenes, features, what)| Variant {
        profile,
        scenes,
        tiny: name == TINY,
        ..Variant::qemu(name, board, features, "fixed", what)
    }));
    v.extend(pico_variants());
    v
}

/// Each core in each of its scalars with all five scenes; the Pico 2's core with its scenes
/// baked and in its own frame; the chair alone on a Cortex-M0+ in f32 and fixed point.
fn scalar_variants() -> Vec<Variant> {
    let mut v = Vec::new();
    for (board, target, core, scalars) in [
        ("m0", M0, "Cortex-M0+ (thumbv6m, run on QEMU's Cortex-M3 board)", &SCALARS[..]),
        ("m4f", ("thumbv7em-none-eabihf", "mps2-an386"), "Cortex-M4F (thumbv7em-none-eabihf)", &SCALARS[..]),
        // The Pico 2's core, in the Pico 2's scalar.
        ("m33", M33, "Cortex-M33 (thumbv8m.main-none-eabihf, the Pico 2's core)", &SCALARS[..1]),
    ] {
        for &(scalar, feature) in scalars {
            let features = ["qemu", feature].iter().filter(|f| !f.is_empty()).cloned().collect::<Vec<_>>().join(",");
            let what = format!("{core}, {scalar}, all five scenes");
            let variant = Variant::qemu(format!("qemu-{board}-{scalar}"), target, features, scalar, what);
            v.push(Variant { profile: if board == "m33" { "speed" } else { "release" }, ..variant });
        }
    }
    // The Pico 2's image bakes its scenes: its core's frame without parsing or set-up.
    let baked = "Cortex-M33 (the Pico 2's core), f32, all five scenes baked, as the Pico 2 image has them";
    v.push(Variant { profile: "speed", ..Variant::qemu(M33_BAKED, M33, "qemu,baked", "f32", baked) });
    // And the frame the Pico 2 image renders: the panels' (16x16 tiles, two-level sampling,
    // Floyd-Steinberg, silhouette lines), not the QEMU boards'.
    let panel = "Cortex-M33 (the Pico 2's core), f32, all five scenes baked, in the Pico 2 image's own frame (the panels': 16x16 tiles, two-level sampling, Floyd-Steinberg, lines)";
    v.push(Variant {
        profile: "speed",
        ..Variant::qemu(M33_PANEL, M33, "qemu-machine,panel-frame,baked", "f32", panel)
    });
    for (scalar, feature) in [SCALARS[0], SCALARS[1]] {
        let features = format!("qemu,{feature}").trim_end_matches(',').to_string();
        let what = format!("Cortex-M0+, {scalar}, only the chair embedded");
        v.push(Variant {
            scenes: Some("chair"),
            ..Variant::qemu(format!("qemu-m0-{scalar}-chair"), M0, features, scalar, what)
        });
    }
    v
}

/// The boards' own images: built and sized here; run on the emulated board by `cargo xtask
/// board` (the Pico), or only built (the Pico 2: no RP2350 emulator here).
fn pico_variants() -> [Variant; 2] {
    let pico = "Raspberry Pi Pico + SSD1306, fixed, all five scenes baked (run on an emulated board by `cargo xtask board`: docs/board.md)";
    let pico2 = "Raspberry Pi Pico 2 + SSD1306, f32, all five scenes baked (built only: no RP2350 emulator here; its core's code runs as qemu-m33-f32-baked)";
    [
        // The profiles of `cargo pico-build` and `cargo pico2-build`: the image kept as `pico` is
        // the one `cargo xtask board` runs, whichever command built it last.
        Variant { bin: "pico", machine: None, profile: "sram", ..Variant::qemu("pico", M0, "pico", "fixed", pico) },
        Variant { bin: "pico", machine: None, profile: "speed", ..Variant::qemu("pico2", M33, "pico2", "f32", pico2) },
    ]
}

/// Variant `name` of [`variants`] built with `scene` alone, kept apart from the report's image
/// (for `cargo xtask profile`).
pub(crate) fn profiled_variant(name: &str, scene: &str) -> Result<Variant> {
    let all = variants();
    let names: Vec<String> = all.iter().filter(|v| v.machine.is_some()).map(|v| v.name.clone()).collect();
    let Some(mut v) = all.into_iter().find(|v| v.name == name && v.machine.is_some()) else {
        bail!("no firmware variant `{name}` runs in QEMU; those that do: {}", names.join(", "));
    };
    v.name = format!("{name}-profile-{scene}");
    // A command-line value for the variant's `&'static` list of scenes: one per run.
    v.scenes = Some(Box::leak(scene.to_string().into_boxed_str()));
    Ok(v)
}

pub(crate) fn elf_path(root: &Path, v: &Variant) -> PathBuf {
    host_sim::uf2::kept_image(root, &v.name)
}

/// The cargo arguments that build variant `v`.
fn cargo_args(v: &Variant) -> Vec<&str> {
    let mut args = vec![
        "build",
        "--manifest-path",
        "firmware/Cargo.toml",
        "--profile",
        v.profile,
        "--features",
        &v.features,
        "--bin",
        v.bin,
        "--target",
        v.target,
    ];
    if v.tiny {
        args.push("--no-default-features");
    }
    args
}

pub(crate) fn build(root: &Path, v: &Variant) -> Result<()> {
    let args = cargo_args(v);
    let built = Path::new(v.target).join(v.profile).join(v.bin);
    let scenes = v.scenes.map_or(Scenes::Default, Scenes::Listed);
    host_sim::uf2::build_image(root, &v.name, &args, (scenes, &[]), &built)
        .with_context(|| format!("building firmware variant {} failed", v.name))?;
    Ok(())
}

/// Flash bytes (every allocated section with contents, `.data` counted at its load address)
/// and static RAM bytes (`.data`, `.bss`, `.uninit`).
pub fn elf_sizes(elf: &Path) -> Result<(u64, u64)> {
    Elf::read(elf)?.sizes()
}

/// What one QEMU run printed.
#[derive(Default)]
struct Run {
    /// Instructions per SysTick tick, from the firmware's calibration loop (`CALIBRATE`).
    per_tick: u64,
    scenes: Vec<SceneRun>,
    stack: u64,
    statics: u64,
    errors: Vec<String>,
}

struct SceneRun {
    name: String,
    ticks: u64,
    /// Ticks from the first tile to the last (both shares).
    tiles: u64,
    rays: u64,
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

/// QEMU running `elf` on `machine` as every run here does: no display, monitor or serial port,
/// semihosting for the harness's output, and `-icount shift=0` (one instruction per
/// nanosecond, the same counts on any host); `extra` options come before the image.
pub(crate) fn qemu(elf: &Path, machine: &str, extra: &[&str]) -> Command {
    let mut cmd = Command::new("qemu-system-arm");
    cmd.args(["-machine", machine, "-nographic", "-monitor", "none", "-serial", "none"])
        .args(["-semihosting-config", "enable=on,target=native", "-icount", "shift=0"])
        .args(extra)
        .arg("-kernel")
        .arg(elf)
        .stdin(Stdio::null());
    cmd
}

fn run_qemu(elf: &Path, machine: &str) -> Result<Run> {
    let mut child = qemu(elf, machine, &[])
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
                tiles: field(line, "tiles"),
                rays: field(line, "rays"),
                stack_so_far: field(line, "stack_so_far"),
                rows: Vec::new(),
            });
        } else if let Some(hex) = line.strip_prefix("ROW ") {
            if let Some(s) = run.scenes.last_mut() {
                let bytes = (0..hex.len() / 2).filter_map(|i| u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).ok());
                s.rows.extend(bytes);
            }
        } else if line.starts_with("CALIBRATE ") {
            let ticks = field(line, "ticks").max(1);
            run.per_tick = (field(line, "instructions") + ticks / 2) / ticks;
        } else if line.starts_with("RAM ") {
            run.stack = field(line, "stack_high_water");
            run.statics = field(line, "static");
        } else if line.starts_with("ERROR") || line.starts_with("PANIC") || line.starts_with("HARDFAULT") {
            run.errors.push(line.to_string());
        }
    }
    if run.per_tick == 0 && run.errors.is_empty() {
        run.errors.push("no CALIBRATE line: instructions per tick unknown".into());
    }
    if !status.success() && run.errors.is_empty() {
        run.errors.push(format!("QEMU exited with {status}"));
    }
    Ok(run)
}

/// The frame the boards render (the records crate the firmware compiles too).
pub use board_records::frame as board_frame;

/// The host's 1-bit frame of the scene file at `path` as `frame`, in scalar `R`.
fn host_frame_in<R: lattice_rt::Real>(path: &Path, frame: &lattice_rt::Frame) -> Result<Vec<u8>> {
    Ok(render_text::<R>(path, &read(path)?, frame, |_| {})?.bits)
}

/// The host's 1-bit frame of scene `name` (from the folder `scenes`) as the firmware `build`
/// renders it (`board_frame::rendered`), in a scalar named as in [`SCALARS`].
pub fn host_frame(scenes: &Path, name: &str, scalar: &str, build: board_frame::Build) -> Result<Vec<u8>> {
    host_frame_of(&scenes.join(format!("{name}.scene")), scalar, build)
}

/// [`host_frame`] of the scene or NFF file at `path`.
pub fn host_frame_of(path: &Path, scalar: &str, build: board_frame::Build) -> Result<Vec<u8>> {
    let frame = board_frame::rendered(build);
    match scalar {
        "fixed" => host_frame_in::<lattice_rt::Fx>(path, &frame),
        "f32-micromath" => host_frame_in::<lattice_rt::F32Micro>(path, &frame),
        "f32-micromath-newton" => host_frame_in::<lattice_rt::F32MicroNewton>(path, &frame),
        _ => host_frame_in::<f32>(path, &frame),
    }
}

/// The flash of an image by part: the tracer and renderer (the core), the scenes' tables and
/// constants (read-only data), the QEMU harness (its `main`, `core::fmt` and semihosting), the
/// compiler's built-ins (integer division, memcpy) and the rest (vector table, start-up).
fn flash_parts(elf: &Path) -> Result<Vec<(&'static str, u64)>> {
    use object::{Object as _, ObjectSection as _, ObjectSymbol as _, SectionKind};
    let image = Elf::read(elf)?;
    let file = image.file()?;
    let rodata: u64 =
        file.sections().filter(|s| s.name().is_ok_and(|n| n.starts_with(".rodata"))).map(|s| s.size()).sum();
    let (flash, _) = image.sizes()?;
    let mut parts: Vec<(&'static str, u64)> = vec![
        ("tracer and renderer (`lattice_rt`)", 0),
        ("the firmware's render loop (`firmware::app`)", 0),
        ("the QEMU harness's `main` (with the render loop inlined), `core::fmt`, semihosting", 0),
        ("compiler built-ins (integer division, memcpy)", 0),
        ("other code (start-up, panics)", 0),
    ];
    for sym in file.symbols() {
        let Some(section) = sym.section_index().and_then(|i| file.section_by_index(i).ok()) else { continue };
        if section.kind() != SectionKind::Text {
            continue;
        }
        let name = demangled(sym.name().unwrap_or(""));
        // The render loop is inlined into the harness's `main`, which counts it there.
        let part = if name.contains("fmt") || name.starts_with("qemu::") || name.contains("semihosting") {
            2
        } else if name.contains("lattice_rt::") {
            0
        } else if name.contains("firmware::") {
            1
        } else if name.contains("compiler_builtins") || name.starts_with("__") {
            3
        } else {
            4
        };
        parts[part].1 += sym.size();
    }
    let counted: u64 = parts.iter().map(|p| p.1).sum::<u64>() + rodata;
    parts.insert(2, ("tables (`.rodata`: the baked scenes and lattices, constants, strings)", rodata));
    parts.push(("vector table and alignment", flash.saturating_sub(counted)));
    Ok(parts)
}

/// Bytes of the baked scenes' `Baked` statics in an image (`firmware::app::baked::NAME`).
fn baked_static_bytes(elf: &Path) -> Result<u64> {
    Elf::read(elf)?.symbol_bytes("firmware::app::baked::")
}

/// The `tiny` build's variant: the chair in the smallest parts' memory map.
const TINY: &str = "tiny-m0-fixed-chair";

/// What the `tiny` build, which leaves out spheres and cones, says when it is built with a scene
/// of spheres: the reason it refuses it (`None` if it did not, and would draw it without them).
fn tiny_refuses_spheres(root: &Path, v: &Variant) -> Result<Option<String>> {
    let out = host_sim::uf2::firmware_cargo(root)
        .args(cargo_args(v))
        .env("FIRMWARE_SCENES", "spheres")
        .stdin(Stdio::null())
        .output()
        .context("cannot run cargo")?;
    let text = String::from_utf8_lossy(&out.stderr);
    let why = text
        .lines()
        .find_map(|l| Some(l.split_once("spheres.scene: ")?.1.trim().to_string()))
        .filter(|w| w.contains("which this build leaves out"));
    Ok(why.filter(|_| !out.status.success()))
}

/// The `tiny` build against its targets: the chair in 16 KiB of flash and 4 KiB of RAM.
fn tiny_section(
    md: &mut String,
    root: &Path,
    runs: &[(&Variant, Run)],
    identical: &std::collections::BTreeMap<(String, String), bool>,
    tally: &mut Tally,
) -> Result<()> {
    let Some((v, r)) = runs.iter().find(|(v, _)| v.name == TINY) else { return Ok(()) };
    let flash = elf_sizes(&elf_path(root, v))?.0;
    let ram = r.statics + r.stack;
    let same = r.scenes.iter().all(|s| identical.get(&(TINY.to_string(), s.name.clone())) == Some(&true));
    let refuses = tiny_refuses_spheres(root, v)?;
    if refuses.is_some() {
        tally.passed += 1;
    } else {
        tally.failed += 1;
        eprintln!("FAIL {TINY}: a scene with spheres was not refused when built");
    }
    // The run itself proves the 4 KiB: its memory map holds no more, and flip-link faults on an
    // overflow (a fault fails the run).
    if ram <= 4 << 10 && !r.scenes.is_empty() {
        tally.passed += 1;
    } else {
        tally.failed += 1;
        eprintln!("FAIL {TINY}: {ram} B of RAM in a 4096 B memory map, or no frame");
    }
    writeln!(md, "\n## The tiny build\n")?;
    writeln!(
        md,
        "`{TINY}` (the `tiny` and `compact` features, `small` profile): the chair alone in the memory of the smallest"
    )?;
    writeln!(
        md,
        "Cortex-M0 parts, `firmware/tiny/memory.x`: 16 KiB of flash and 4 KiB of RAM, enforced by the linker,"
    )?;
    writeln!(
        md,
        "with flip-link placing the stack below the statics so that an overflow faults. It is built without the"
    )?;
    writeln!(
        md,
        "firmware's default features, `spheres` and `cones`: the chair has boxes and cylinders only, and the"
    )?;
    writeln!(
        md,
        "other shapes' intersection code is left out (built with the spheres scene, it {}).",
        match &refuses {
            Some(why) => format!("is refused: *{why}*"),
            None => "**is not refused**".into(),
        }
    )?;
    writeln!(md, "The harness logs through a few bytes of its own (`Line` in `firmware/src/bin/qemu.rs`), and the")?;
    writeln!(md, "render path's index checks panic without formatting their numbers (`lattice_rt::bounds`), so no")?;
    writeln!(md, "`core::fmt` code is linked.\n")?;
    writeln!(md, "| target | measured | limit | met |\n|---|---:|---:|---|")?;
    writeln!(
        md,
        "| RAM (static + stack high-water, in the 4 KiB map) | {ram} B | 4096 B | {} |",
        if ram <= 4 << 10 { "yes" } else { "**no**" }
    )?;
    // The image was linked in that memory map: the flash row can only say yes.
    writeln!(md, "| flash | {flash} B | 16384 B | {} |", if flash <= 16 << 10 { "yes" } else { "**no**" })?;
    writeln!(
        md,
        "\nLinked at its memory map's 16 KiB (a bigger image fails to link, and this report with it), it has {} B to\nspare, and runs there: the chair's frame {} host-sim's, bit for bit.",
        (16 << 10) - flash as i64,
        if same { "equals" } else { "**differs from**" }
    )?;
    Ok(())
}

/// The baked builds against the memory targets (issue: flash at most 48 KiB with all five scenes
/// and every effect, 32 KiB for the matte paper scenes with their effects, which must be at least
/// 25 % smaller than the all-effects build; RAM at most 4 KiB for the chair, 6 KiB for all five).
fn baked_section(
    md: &mut String,
    root: &Path,
    runs: &[(&Variant, Run)],
    identical: &std::collections::BTreeMap<(String, String), bool>,
) -> Result<()> {
    let run = |name: &str| runs.iter().find(|(v, _)| v.name == name);
    let flash = |name: &str| run(name).and_then(|(v, _)| elf_sizes(&elf_path(root, v)).ok()).map(|f| f.0);
    let ram = |name: &str| run(name).map(|(_, r)| r.statics + r.stack);
    let (Some(all), Some(allfx), Some(chair), Some(matte)) = (
        flash("qemu-m0-fixed-baked"),
        flash("qemu-m0-fixed-baked-allfx"),
        flash("qemu-m0-fixed-baked-chair"),
        flash("qemu-m0-fixed-baked-matte"),
    ) else {
        return Ok(());
    };
    writeln!(md, "\n## Baked scenes\n\nWith the `baked` feature `firmware/build.rs` parses each embedded scene and builds its lattice on\nthe host, in the firmware's scalar, and writes both as static tables (`lattice_rt::bake`); the\nfirmware links no parser, no scene set-up (f64 maths) and no lattice build, and keeps neither\nobjects nor lattice in RAM. Every frame is checked bit for bit against host-sim like the others.\n")?;
    writeln!(md, "The flash targets are measured on the images built for size (`small` profile: opt-level \"z\", the\nchoice for a part with little flash, and the firmware's `compact` feature: memcpy and memset as\nloops of a few dozen bytes instead of compiler-builtins') and, beside them, on the release profile's (opt-level \"s\",\nwhat the other rows of this report run); the instructions each costs are in the table above\n(`m0-fixed-baked` against `m0-fixed-baked-small`).\n")?;
    writeln!(md, "| target | build | measured | limit | met |\n|---|---|---:|---:|---|")?;
    let mut row = |what: &str, build: &str, got: u64, limit: u64| {
        writeln!(md, "| {what} | `{build}` | {got} B | {limit} B | {} |", if got <= limit { "yes" } else { "**no**" })
    };
    for (what, build, limit) in [
        ("flash, all five scenes, every effect", "qemu-m0-fixed-baked-allfx-small", 48 << 10),
        ("flash, all five scenes, every effect", "qemu-m0-fixed-baked-allfx", 48 << 10),
        ("flash, the matte paper scenes, their effects", "qemu-m0-fixed-baked-matte-small", 32 << 10),
        ("flash, the matte paper scenes, their effects", "qemu-m0-fixed-baked-matte", 32 << 10),
    ] {
        if let Some(got) = flash(build) {
            row(what, build, got, limit)?;
        }
    }
    row("RAM, the chair", "qemu-m0-fixed-baked-chair", ram("qemu-m0-fixed-baked-chair").unwrap_or(0), 4 << 10)?;
    row("RAM, all five scenes", "qemu-m0-fixed-baked", ram("qemu-m0-fixed-baked").unwrap_or(0), 6 << 10)?;
    let smaller = 1.0 - matte as f64 / allfx as f64;
    let small = flash("qemu-m0-fixed-baked-matte-small")
        .zip(flash("qemu-m0-fixed-baked-allfx-small"))
        .map(|(m, a)| 1.0 - m as f64 / a as f64);
    writeln!(
        md,
        "\nThe matte build is {:.1} % smaller than the all-effects build{} (target: at least 25 %); all five scenes\nwith their own effects take {all} B{}, the chair alone {chair} B.",
        smaller * 100.0,
        small.map_or(String::new(), |s| format!(" ({:.1} % built for size)", s * 100.0)),
        flash("qemu-m0-fixed-baked-small").map_or(String::new(), |f| format!(" ({f} B built for size)"))
    )?;
    if let Some(r) = (Table { root, runs, identical }).ratio("qemu-m0-fixed-baked-small", "qemu-m0-fixed-baked") {
        writeln!(md, "Built for size, the baked five-scene image needs {r:.3}x the instructions of the release build over all scenes.")?;
    }
    let parsed = flash("qemu-m0-fixed").zip(ram("qemu-m0-fixed"));
    if let Some((f, r)) = parsed {
        writeln!(md, "Parsed at run time the same five scenes take {f} B of flash and {r} B of RAM.")?;
    }
    if let Some((v, r)) = run("qemu-m0-fixed-baked-allfx") {
        baked_flash_parts(md, root, v, r, allfx)?;
    }
    let mb = "microbit-m0-fixed-baked";
    if let Some((_, r)) = run(mb) {
        let same = r.scenes.iter().all(|s| identical.get(&(mb.to_string(), s.name.clone())) == Some(&true));
        writeln!(
            md,
            "\nOn the smallest board, `{mb}` (16 KiB of RAM): {} scenes at 128x64, {}, static {} + stack {} = {} B of RAM.",
            r.scenes.len(),
            if same && r.errors.is_empty() { "every frame bit-identical to host-sim" } else { "**not all frames identical**" },
            r.statics,
            r.stack,
            r.statics + r.stack
        )?;
    }
    Ok(())
}

/// Where the flash of the baked all-effects image `v` (run `r`, `allfx` bytes) goes: its
/// parts by symbol, then the tables' objects, `Baked` statics and lists.
fn baked_flash_parts(md: &mut String, root: &Path, v: &Variant, r: &Run, allfx: u64) -> Result<()> {
    let parts = flash_parts(&elf_path(root, v))?;
    writeln!(md, "\nWhere the {allfx} B of `qemu-m0-fixed-baked-allfx` go (symbol sizes from its ELF):\n\n| part | bytes |\n|---|---:|")?;
    for (part, bytes) in parts.into_iter().filter(|p| p.1 > 0) {
        writeln!(md, "| {part} | {bytes} |")?;
    }
    // The tables' parts: the objects, each scene's header, and its composites, materials
    // and lights (exactly as many as it has).
    let (mut objects, mut lists) = (0, 0);
    for s in &r.scenes {
        let text = host_sim::load::read(&root.join("scenes").join(format!("{}.scene", s.name)))?;
        let mut storage = host_sim::load::object_storage::<lattice_rt::Fx>(&text)?;
        let scene = lattice_rt::parse::<lattice_rt::Fx>(&text, &mut storage.objects, &mut storage.parts)
            .map_err(|e| anyhow::anyhow!("{}: {e}", s.name))?;
        objects += scene.objects().len();
        lists += size_of_val(scene.composites()) + size_of_val(scene.materials()) + size_of_val(scene.lights());
    }
    // A `Baked` holds slices (pointers): its size is the target's, from the ELF's symbols.
    let baked = baked_static_bytes(&elf_path(root, v))? / r.scenes.len().max(1) as u64;
    let object = size_of::<lattice_rt::scene::Object<lattice_rt::Fx>>();
    writeln!(
        md,
        "\nOf the tables, the {objects} objects take {objects} x {object} = {} B, the {} scenes' `Baked` statics\n{} x {baked} = {} B (each scene's camera, world box and lattice header, and slices of its\ncomposites, materials and lights) and those lists {lists} B; the rest are the lattices (cells,\nreferences, coordinate lists) and constants.",
        objects * object,
        r.scenes.len(),
        r.scenes.len(),
        r.scenes.len() as u64 * baked
    )?;
    Ok(())
}

/// The command.
pub fn firmware_cmd(root: &Path, out: &Path, skip_build: bool, with_spd: bool) -> Result<()> {
    let mut md = String::new();
    writeln!(md, "# Firmware budgets\n\nWritten by `cargo xtask firmware` (also run by `.ci/run`; `--spd` adds the last section).\nFrames are 128x64, lattice, blue-noise dither, each scene's own effects and depth.\n")?;
    let variants = variants();
    let runs = build_and_run(root, &variants, skip_build, &mut md)?;
    let mut tally = Tally::default();
    let identical = check_frames(root, &runs, &mut tally)?;
    let table = Table { root, runs: &runs, identical: &identical };
    let csv = table.instructions(&variants, &mut md)?;
    table.ratios(&mut md)?;
    table.pico2(&mut md)?;
    baked_section(&mut md, root, &runs, &identical)?;
    tiny_section(&mut md, root, &runs, &identical, &mut tally)?;
    table.smallest(&mut md)?;
    float_audit_section(root, &variants, &mut md, &mut tally)?;
    if with_spd {
        spd::spd_section(root, &mut md, &mut tally)?;
    }
    std::fs::create_dir_all(out.parent().unwrap_or(Path::new(".")))?;
    std::fs::write(out, md).with_context(|| format!("cannot write {}", out.display()))?;
    let csv_path = out.with_extension("csv");
    std::fs::write(&csv_path, csv).with_context(|| format!("cannot write {}", csv_path.display()))?;
    println!("wrote {} and {}", out.display(), csv_path.display());
    let Tally { passed, failed } = tally;
    println!("firmware: {passed} passed, {failed} failed");
    if failed > 0 {
        bail!("{failed} firmware checks failed");
    }
    Ok(())
}

/// Checks passed and failed.
#[derive(Default)]
struct Tally {
    passed: usize,
    failed: usize,
}

/// QEMU runs at once while the variants build (this machine has two cores).
const QEMU_AT_ONCE: usize = 2;

/// A variant's QEMU run, waited for: its place in the list, the variant, its flash bytes and
/// its run.
type Finished<'v> = (usize, &'v Variant, u64, Option<Run>);

/// A started QEMU run once it has finished.
fn finished<'v>(
    (i, v, flash, handle): (usize, &'v Variant, u64, std::thread::ScopedJoinHandle<'_, Result<Run>>),
) -> Result<Finished<'v>> {
    let run = handle.join().map_err(|_| anyhow::anyhow!("{}: the QEMU thread panicked", v.name))??;
    Ok((i, v, flash, Some(run)))
}

/// Builds (unless `skip_build`) every variant, runs those with a machine in QEMU, and writes
/// the builds table (flash and RAM) to `md`.
fn build_and_run<'v>(
    root: &Path,
    variants: &'v [Variant],
    skip_build: bool,
    md: &mut String,
) -> Result<Vec<(&'v Variant, Run)>> {
    writeln!(md, "## Builds\n\n| variant | what | flash bytes | static RAM | stack high-water | RAM total |\n|---|---|---|---|---|---|")?;
    let bar = host_sim::progress::bar(variants.len(), "firmware variants");
    // Each variant runs in QEMU on a thread of its own while the next builds (builds take
    // turns; QEMU keeps one core busy, and its instruction counts do not depend on the wall
    // clock), at most [`QEMU_AT_ONCE`] at a time; the rows are written in order once all ran.
    let built = std::thread::scope(|scope| -> Result<Vec<_>> {
        let (mut done, mut running) = (Vec::new(), std::collections::VecDeque::new());
        for (i, v) in variants.iter().enumerate() {
            bar.set_message(v.name.clone());
            bar.inc(1);
            if !skip_build {
                host_sim::progress::log(&bar, format_args!("  building {} ({})", v.name, v.target));
                build(root, v)?;
            }
            let elf = elf_path(root, v);
            let (flash, _) = elf_sizes(&elf)?;
            let Some(m) = v.machine else {
                done.push((i, v, flash, None));
                continue;
            };
            if running.len() == QEMU_AT_ONCE {
                if let Some(oldest) = running.pop_front() {
                    done.push(finished(oldest)?);
                }
            }
            host_sim::progress::log(&bar, format_args!("  running {} on {m}", v.name));
            running.push_back((i, v, flash, scope.spawn(move || run_qemu(&elf, m))));
        }
        for started in running {
            done.push(finished(started)?);
        }
        // In the variants' order, as the table lists them.
        done.sort_by_key(|&(i, ..)| i);
        Ok(done)
    })?;
    let mut runs = Vec::new();
    for (_, v, flash, run) in built {
        match &run {
            Some(r) => writeln!(
                md,
                "| {} | {} | {flash} | {} | {} | {} |",
                v.name,
                v.what,
                r.statics,
                r.stack,
                r.statics + r.stack
            )?,
            None if v.name == "pico" => {
                writeln!(md, "| {} | {} | {flash} | (docs/board.md) | (docs/board.md) | |", v.name, v.what)?
            }
            None => writeln!(md, "| {} | {} | {flash} | (not run) | (not run) | |", v.name, v.what)?,
        }
        if let Some(r) = run {
            runs.push((v, r));
        }
    }
    writeln!(md, "\nRAM is measured, not estimated: cortex-m-rt paints the stack at reset (`paint-stack`) and the\nfirmware reports the deepest word that lost the paint. All scene storage lives on the stack,\nsized by `firmware/build.rs` to exactly what the embedded scenes need.\n")?;
    Ok(runs)
}

/// Every frame against the host's render in the same scalar, bit for bit: which were identical.
fn check_frames(
    root: &Path,
    runs: &[(&Variant, Run)],
    tally: &mut Tally,
) -> Result<std::collections::BTreeMap<(String, String), bool>> {
    let scenes_dir = root.join("scenes");
    let mut identical = std::collections::BTreeMap::new();
    for (v, r) in runs {
        for e in &r.errors {
            eprintln!("FAIL {}: {e}", v.name);
            tally.failed += 1;
        }
        for s in &r.scenes {
            let build = board_frame::Build::of(|f| v.features.split([',', ' ']).any(|g| g == f));
            let want = host_frame(&scenes_dir, &s.name, v.scalar, build)?;
            let same = want == s.rows;
            if same {
                tally.passed += 1;
            } else {
                tally.failed += 1;
                let differ = want.iter().zip(&s.rows).map(|(a, b)| (a ^ b).count_ones()).sum::<u32>();
                eprintln!("FAIL {} {}: frame differs from host-sim in {differ} pixels", v.name, s.name);
            }
            identical.insert((v.name.clone(), s.name.clone()), same);
        }
    }
    Ok(identical)
}

/// The runs' figures, looked up by variant and scene for the report's tables.
struct Table<'a> {
    root: &'a Path,
    runs: &'a [(&'a Variant, Run)],
    identical: &'a std::collections::BTreeMap<(String, String), bool>,
}

impl Table<'_> {
    /// The scene's run in `variant`.
    fn find(&self, variant: &str, scene: &str) -> Option<&SceneRun> {
        self.runs.iter().find(|(v, _)| v.name == variant).and_then(|(_, r)| r.scenes.iter().find(|s| s.name == scene))
    }
    /// Instructions per SysTick tick of `variant`'s run.
    fn per_tick(&self, variant: &str) -> u64 {
        self.runs.iter().find(|(v, _)| v.name == variant).map_or(0, |(_, r)| r.per_tick)
    }
    /// Instructions of `scene`'s frame in `variant` (SysTick ticks x that run's calibration).
    fn instructions_of(&self, variant: &str, scene: &str) -> Option<u64> {
        self.find(variant, scene).map(|s| s.ticks * self.per_tick(variant))
    }
    /// The scenes the runs showed, in order.
    fn names(&self) -> Vec<String> {
        self.runs.first().map(|(_, r)| r.scenes.iter().map(|s| s.name.clone()).collect()).unwrap_or_default()
    }

    /// The instructions table (one column per full-scene variant) into `md`; the CSV of every run.
    fn instructions(&self, variants: &[Variant], md: &mut String) -> Result<String> {
        writeln!(md, "## Instructions per frame (QEMU, `-icount shift=0`)\n\nSysTick ticks x instructions per tick (1 ns per instruction; the firmware times a loop of known\nlength: 40 on the an385/an386's 25 MHz SysTick, 50 on the an505's 20 MHz): deterministic, the same on\nany machine. Every frame below was checked bit for bit against host-sim in the same scalar.\n")?;
        let cols: Vec<&Variant> = variants
            .iter()
            .filter(|v| v.machine.is_some() && v.scenes.is_none() && !v.features.contains("effects-all"))
            .collect();
        let header: String = cols.iter().map(|v| format!(" {} |", v.name.trim_start_matches("qemu-"))).collect();
        writeln!(md, "| scene | rays |{header}\n|---|---|{}", "---|".repeat(cols.len()))?;
        let mut csv = String::from("scene,scalar,board,instructions,rays,variant,flash\n");
        for scene in &self.names() {
            let rays = cols.first().and_then(|c| self.find(&c.name, scene)).map_or(0, |s| s.rays);
            let mut row = format!("| {scene} | {rays} |");
            for (v, r) in self.runs {
                if let Some(s) = r.scenes.iter().find(|s| &s.name == scene) {
                    let board = v.name.trim_start_matches("qemu-").split('-').next().unwrap_or("");
                    let flash = elf_sizes(&elf_path(self.root, v)).map(|f| f.0).unwrap_or(0);
                    csv.push_str(&format!(
                        "{scene},{},{board},{},{},{},{flash}\n",
                        v.scalar,
                        s.ticks * r.per_tick,
                        s.rays,
                        v.name
                    ));
                }
            }
            for v in &cols {
                match self.instructions_of(&v.name, scene) {
                    Some(ins) => {
                        let ok = if self.identical.get(&(v.name.clone(), scene.clone())) == Some(&true) {
                            ""
                        } else {
                            " (frame differs!)"
                        };
                        row.push_str(&format!(" {:.1} M{ok} |", ins as f64 / 1e6));
                    }
                    None => row.push_str(" - |"),
                }
            }
            writeln!(md, "{row}")?;
        }
        Ok(csv)
    }

    /// Instructions of variant `a` over those of `b`, all scenes together.
    fn ratio(&self, a: &str, b: &str) -> Option<f64> {
        let (mut x, mut y) = (0u64, 0u64);
        for scene in &self.names() {
            x += self.instructions_of(a, scene)?;
            y += self.instructions_of(b, scene)?;
        }
        Some(x as f64 / y.max(1) as f64)
    }

    /// The ratios between scalars, cores and the progressive frame.
    fn ratios(&self, md: &mut String) -> Result<()> {
        if let Some(r) = self.ratio("qemu-m0-f32", "qemu-m0-fixed") {
            writeln!(md, "\nOn the M0 build, f32 soft-float needs {r:.2}x the instructions of fixed point over all scenes (target: 3x).")?;
        }
        if let Some(r) = self.ratio("qemu-m0-f32", "qemu-m4f-f32") {
            writeln!(
                md,
                "The M0 build needs {r:.2}x the instructions of the M4F build in f32 (no FPU against an FPU)."
            )?;
        }
        if let Some(r) = self.ratio("qemu-m33-f32", "qemu-m4f-f32") {
            writeln!(md, "The M33 build (the Pico 2's core, built with the `speed` profile: opt-level 3) needs {r:.2}x the instructions of the M4F build (opt-level \"s\") in f32.")?;
        }
        if let Some(r) = self.ratio("qemu-m0-fixed-progressive", "qemu-m0-fixed") {
            let each: Vec<String> = self
                .names()
                .iter()
                .filter_map(|scene| {
                    Some(format!(
                        "{scene} {:.3}x",
                        self.instructions_of("qemu-m0-fixed-progressive", scene)? as f64
                            / self.instructions_of("qemu-m0-fixed", scene)?.max(1) as f64
                    ))
                })
                .collect();
            writeln!(md, "A progressive frame (four passes, the display updated after each) needs {r:.3}x the instructions of the plain frame over all scenes ({}; target: at most 1.05x).", each.join(", "))?;
        }
        Ok(())
    }

    /// The Pico 2's targets: instructions per frame on one core, f32.
    fn pico2(&self, md: &mut String) -> Result<()> {
        let (m33, baked, panel) = ("qemu-m33-f32", M33_BAKED, M33_PANEL);
        if self.find(m33, "chair").is_none() || self.find(baked, "chair").is_none() {
            return Ok(());
        }
        writeln!(
            md,
            "\n### The Pico 2's core (`{panel}`, `{baked}` and `{m33}`: the Pico 2's code on QEMU's mps2-an505)\n"
        )?;
        writeln!(
            md,
            "Targets: the whole frame on one core, in instructions; on both cores each takes about half, so 5 M"
        )?;
        writeln!(
            md,
            "on one core is 2.5 M per core, 60 frames per second at 150 MHz. `{panel}` renders the frame the"
        )?;
        writeln!(
            md,
            "Pico 2 image renders (the panels': 16x16 tiles, two-level sampling, Floyd-Steinberg, lines; the"
        )?;
        writeln!(
            md,
            "`panel-frame` feature); the others the QEMU boards' frame (8x8 tiles, one level, blue noise).\n"
        )?;
        writeln!(md, "| scene | the Pico 2's frame, baked | whole frame, baked (the Pico 2 image's scenes) | tiles alone, baked | whole frame, parsed | target (whole frame) | met (the Pico 2's frame) | frames per second at 150 MHz, one core, one instruction per cycle (the Pico 2's frame) |\n|---|---|---|---|---|---|---|---|")?;
        let m = |n: Option<u64>| n.map_or("-".to_string(), |n| format!("{:.2} M", n as f64 / 1e6));
        for scene in &self.names() {
            let tiles = self.find(baked, scene).map(|s| s.tiles * self.per_tick(baked));
            let (Some(all), Some(tiles), Some(parsed)) =
                (self.instructions_of(baked, scene), tiles, self.instructions_of(m33, scene))
            else {
                continue;
            };
            let own = self.instructions_of(panel, scene);
            let target = match scene.as_str() {
                "chair" => Some(5e6),
                "whitted" => Some(25e6),
                _ => None,
            };
            let (target, met) = match (target, own) {
                (Some(t), Some(own)) => (format!("{:.0} M", t / 1e6), if own as f64 <= t { "yes" } else { "**no**" }),
                (Some(t), None) => (format!("{:.0} M", t / 1e6), "-"),
                (None, _) => (String::new(), ""),
            };
            let fps = own.map_or("-".to_string(), |own| format!("{:.1}", 150e6 / own.max(1) as f64));
            writeln!(
                md,
                "| {scene} | {} | {:.2} M | {:.2} M | {:.2} M | {target} | {met} | {fps} |",
                m(own),
                all as f64 / 1e6,
                tiles as f64 / 1e6,
                parsed as f64 / 1e6
            )?;
        }
        writeln!(md, "\nThe whole frame is what `render_scene` does per frame: parse the scene text and build the lattice\n(parsed only), trace the tiles and send them; tiles alone is the part from the first tile to the last.\n`cargo xtask profile {baked}` (or `{panel}`) lists where a frame's instructions go, per function.")?;
        Ok(())
    }

    /// The chair alone on the M0 builds and on the micro:bit: RAM against 16 KiB.
    fn smallest(&self, md: &mut String) -> Result<()> {
        let run_of = |name: &str| self.runs.iter().find(|(v, _)| v.name == name).map(|(_, r)| r);
        for scalar in ["f32", "fixed"] {
            let name = format!("qemu-m0-{scalar}-chair");
            if let (Some(chair), Some(r)) = (self.find(&name, "chair"), run_of(&name)) {
                writeln!(md, "\nChair at 128x64, M0 build with only the chair embedded, {scalar}: static {} + stack {} = {} bytes of RAM (budget 16384).", r.statics, chair.stack_so_far, r.statics + chair.stack_so_far)?;
            }
        }
        let mb = "microbit-m0-fixed-chair";
        if let (Some(chair), Some(r)) = (self.find(mb, "chair"), run_of(mb)) {
            writeln!(
                md,
                "\nThe smallest board, `{mb}` (QEMU's `microbit`: an nRF51822's Cortex-M0 with 16 KiB of RAM): the chair's frame, bit-identical to host-sim, in {:.1} M instructions with static {} + stack {} = {} bytes of RAM of 16384. Parsed at run time, more scenes overflow the 16 KiB (their storage is sized for the largest; flip-link puts the stack below RAM, so the overflow faults instead of corrupting data); baked, all five fit (below).",
                self.instructions_of(mb, "chair").unwrap_or(0) as f64 / 1e6,
                r.statics,
                chair.stack_so_far,
                r.statics + chair.stack_so_far
            )?;
        }
        Ok(())
    }
}

/// No floating point per ray in the fixed-point build: the disassembly's call graph.
fn float_audit_section(root: &Path, variants: &[Variant], md: &mut String, tally: &mut Tally) -> Result<()> {
    let Some(v) = variants.iter().find(|v| v.name == "qemu-m0-fixed") else { return Ok(()) };
    let (reached, setup) = float_audit(&elf_path(root, v))?;
    writeln!(md, "\n## Fixed point uses no floating point per ray\n\nChecked on the disassembly of `{}` (call graph from `llvm-objdump`): soft-float routines\nreachable from `lattice_rt::render::render_share`: {}.", v.name, if reached.is_empty() { "none".to_string() } else { reached.join(", ") })?;
    writeln!(md, "Functions that do call soft-float routines (scene set-up: parsing, transforms, lattice\nresolution, reports): {}.", setup.iter().map(|f| format!("`{f}`")).collect::<Vec<_>>().join(", "))?;
    if reached.is_empty() {
        tally.passed += 1;
    } else {
        tally.failed += 1;
        eprintln!("FAIL {}: soft float reachable from the renderer: {}", v.name, reached.join(", "));
    }
    Ok(())
}

/// Soft-float routines of the ARM EABI and compiler-builtins (single and double precision).
fn is_soft_float(name: &str) -> bool {
    const PREFIXES: [&str; 9] = [
        "__aeabi_f",
        "__aeabi_d",
        "__aeabi_i2f",
        "__aeabi_i2d",
        "__aeabi_ui2f",
        "__aeabi_ui2d",
        "__aeabi_l2f",
        "__aeabi_l2d",
        "__aeabi_ul2",
    ];
    PREFIXES.iter().any(|p| name.starts_with(p))
        || matches!(
            name,
            "__addsf3" | "__mulsf3" | "__divsf3" | "__adddf3" | "__muldf3" | "__divdf3" | "sqrtf" | "sqrt"
        )
}

/// Finds `llvm-objdump` (rustup's `llvm-tools` component) or a system one.
fn objdump() -> Option<PathBuf> {
    let sysroot = Command::new("rustc").args(["--print", "sysroot"]).output().ok()?;
    let root = PathBuf::from(String::from_utf8_lossy(&sysroot.stdout).trim());
    let found = std::fs::read_dir(root.join("lib/rustlib"))
        .ok()?
        .flatten()
        .map(|e| e.path().join("bin/llvm-objdump"))
        .find(|p| p.exists());
    found.or_else(|| Command::new("llvm-objdump").arg("--version").output().ok().map(|_| PathBuf::from("llvm-objdump")))
}

/// The call graph of an ELF from its disassembly: function -> functions it branches to.
fn call_graph(elf: &Path) -> Result<std::collections::HashMap<String, std::collections::BTreeSet<String>>> {
    let tool = objdump().context("llvm-objdump not found: `rustup component add llvm-tools`")?;
    let out = Command::new(tool).args(["-d", "--no-show-raw-insn"]).arg(elf).output()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let mut graph: std::collections::HashMap<String, std::collections::BTreeSet<String>> = Default::default();
    let mut current = String::new();
    for line in text.lines() {
        if line.ends_with(">:") {
            if let (Some(a), Some(b)) = (line.find('<'), line.rfind(">:")) {
                current = line[a + 1..b].to_string();
                graph.entry(current.clone()).or_default();
            }
        } else if line.contains("\tbl\t")
            || line.contains("\tb\t")
            || line.contains("\tblx\t")
            || line.contains("\tb.w\t")
        {
            if let (Some(a), Some(b)) = (line.find('<'), line.rfind('>')) {
                let target = line[a + 1..b].split('+').next().unwrap_or("").to_string();
                if target != current {
                    graph.entry(current.clone()).or_default().insert(target);
                }
            }
        }
    }
    Ok(graph)
}

/// Soft-float routines reachable from the renderer (`lattice_rt::render::render_share` and `render`), with the
/// path that reaches each, and all soft-float call sites outside it (set-up code).
pub fn float_audit(elf: &Path) -> Result<(Vec<String>, Vec<String>)> {
    let graph = call_graph(elf)?;
    let name = |m: &str| format!("{:#}", rustc_demangle::demangle(m));
    // Every render entry point and the tile loop, in whichever room of `render` it lives.
    let root = |n: &str| {
        n.strip_prefix("lattice_rt::render::")
            .is_some_and(|rest| rest.rsplit("::").next().is_some_and(|f| f.starts_with("render")))
    };
    let roots: Vec<&String> = graph.keys().filter(|k| root(&name(k))).collect();
    if roots.is_empty() {
        bail!("no lattice_rt::render::render in {}", elf.display());
    }
    let mut seen: std::collections::HashMap<String, String> = Default::default();
    let mut queue: std::collections::VecDeque<String> = roots.iter().map(|r| r.to_string()).collect();
    for r in &roots {
        seen.insert(r.to_string(), String::new());
    }
    let mut reached = Vec::new();
    while let Some(f) = queue.pop_front() {
        for g in graph.get(&f).into_iter().flatten() {
            if seen.contains_key(g) {
                continue;
            }
            seen.insert(g.clone(), f.clone());
            if is_soft_float(g) {
                reached.push(format!("{} (called from {})", name(g), name(&f)));
            } else {
                queue.push_back(g.clone());
            }
        }
    }
    let mut setup: Vec<String> = graph
        .iter()
        .filter(|(f, calls)| !is_soft_float(f) && calls.iter().any(|c| is_soft_float(c)))
        .map(|(f, _)| name(f))
        .collect();
    setup.sort();
    setup.dedup();
    Ok((reached, setup))
}
