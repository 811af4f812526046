//! The Standard Procedural Databases on the Pico 2's core (`cargo xtask firmware --spd`): each
//! curve scene at its default size generated as NFF, baked into the image of the Pico 2's core
//! in the Pico 2 image's own frame (4 MiB of flash, f32), run in QEMU's Cortex-M33 board with
//! `-icount shift=0`, its frame checked bit for bit against host-sim's render of the same file.
//! There is no RP2350 emulator here, so the figures are instructions, not cycles.

use super::{board_frame, build, elf_path, elf_sizes, host_frame_of, run_qemu, Tally, Variant, M33};
use anyhow::{Context, Result};
use host_sim::spd::Generator;
use host_sim::uf2::refusal;
use std::fmt::Write as _;
use std::path::Path;

/// The scenes: the SPD's curve scenes at their default sizes (the published figures' size).
const SCENES: [Generator; 5] =
    [Generator::Balls, Generator::Rings, Generator::Tree, Generator::Lattice, Generator::Shells];

/// The features of the images: the Pico 2 image's frame on QEMU's M33 board, baked, with the
/// triangle test (NFF's polygons).
const FEATURES: &str = "qemu-machine,panel-frame,baked,triangles";

/// Writes the section: per scene its objects, the image's flash, instructions per frame and
/// whether the frame is host-sim's, or why the image was refused.
pub(super) fn spd_section(root: &Path, md: &mut String, tally: &mut Tally) -> Result<()> {
    let dir = root.join("target/firmware-spd");
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let dir = dir.canonicalize()?;
    writeln!(md, "\n## The Standard Procedural Databases on the Pico 2's core\n")?;
    writeln!(md, "Written by `cargo xtask firmware --spd`: each curve scene of the SPD at its default size, generated as NFF (`host-sim spd NAME`), baked into the image of the Pico 2's core in the Pico 2 image's frame (`FIRMWARE_SCENES=/path/NAME-N.nff`, features `{FEATURES}`, profile `speed`; 4 MiB of flash as the Pico 2 has) and run in QEMU's mps2-an505 (Cortex-M33) with `-icount shift=0`; its frame checked against `host-sim render FILE --board pico2`. Instructions, not cycles: there is no RP2350 emulator here. The Pico's own runs of these scenes are in docs/board.md.\n")?;
    writeln!(md, "| scene | objects | flash (image) | instructions per frame | bit-identical to host-sim |\n|---|---:|---:|---:|---|")?;
    let mut refused = Vec::new();
    let frame = board_frame::Build::of(|f| FEATURES.split(',').any(|g| g == f));
    for g in SCENES {
        let name = format!("{}-{}", g.name(), g.default_size());
        let nff = dir.join(format!("{name}.nff"));
        let text = g.nff(g.default_size())?;
        host_sim::output::write_atomic(&nff, text.as_bytes())?;
        let objects = lattice_rt::object_count(&text);
        let path = nff.to_str().context("the target folder's path is not UTF-8")?;
        let what = format!("Cortex-M33, f32, {name} baked, in the Pico 2 image's frame");
        let v = Variant {
            profile: "speed",
            scenes: Some(Box::leak(path.to_string().into_boxed_str())),
            ..Variant::qemu(format!("qemu-m33-f32-spd-{name}"), M33, FEATURES, "f32", what)
        };
        eprintln!("building the Pico 2 core's image with {name} ({objects} objects) baked");
        if build(root, &v).is_err() {
            refused.push(format!("- **{name}**: {}", refusal(root, &super::cargo_args(&v), path)));
            writeln!(md, "| {name} | {objects} | refused | - | - |")?;
            continue;
        }
        let elf = elf_path(root, &v);
        let (flash, _) = elf_sizes(&elf)?;
        let run = run_qemu(&elf, M33.1)?;
        let scene = run.scenes.first();
        let want = host_frame_of(&nff, "f32", frame)?;
        let same = run.errors.is_empty() && scene.is_some_and(|s| s.rows == want);
        if same {
            tally.passed += 1;
        } else {
            tally.failed += 1;
            eprintln!("FAIL {}: the frame is not host-sim's ({})", v.name, run.errors.join("; "));
        }
        let instructions = scene.map_or(0, |s| s.ticks * run.per_tick);
        writeln!(
            md,
            "| {name} | {objects} | {:.0} KiB | {:.1} M | {} |",
            flash as f64 / 1024.0,
            instructions as f64 / 1e6,
            if same { "yes" } else { "**no**" }
        )?;
    }
    if !refused.is_empty() {
        writeln!(md, "\nRefused by the build:\n\n{}", refused.join("\n"))?;
    }
    Ok(())
}
