//! The Standard Procedural Databases on the board: each scene generated as NFF (`host-sim spd`),
//! baked into its own Pico image (`FIRMWARE_SCENES` takes the file's path; objects, lattice and
//! windows in flash, read through the XIP cache), run on the emulated board and checked bit for
//! bit against host-sim's frame of the same file. A scene whose tables do not fit the image is
//! built again with the firmware's `lean-objects` (40 bytes less per object); one that fits
//! neither way is refused by `firmware/build.rs` with the figures, and the report gives its
//! message.

use super::{elf_sizes, m3, reported_frame, run_emulator, save_frame, Session, MISS_LINES, PICO, PICO_SCALAR};
use crate::elf::Elf;
use crate::firmware::host_frame_of;
use anyhow::{Context, Result};
use host_sim::spd::Generator;
use host_sim::uf2::{build_image, kept_image, pico_built, refusal, write_uf2, Scenes};
use std::fmt::Write as _;
use std::path::Path;

/// The scenes run: the sphereflake at sizes 1 to 3 (3: 820 spheres and the floor, the target's),
/// the small jacks, and every curve scene at its default size (the published figures' size).
pub(super) const SCENES: [(Generator, Option<u32>); 9] = [
    (Generator::Balls, Some(1)),
    (Generator::Balls, Some(2)),
    (Generator::Balls, Some(3)),
    (Generator::Jacks, None),
    (Generator::Balls, None),
    (Generator::Rings, None),
    (Generator::Tree, None),
    (Generator::Lattice, None),
    (Generator::Shells, None),
];

/// Most objects of a scene `cargo xtask board --spd-small` runs.
pub(super) const SMALL: usize = 1000;

/// Cycles a frame of `balls` at size 3 may take: 2 frames per second at 125 MHz.
const BALLS_3_TARGET: u64 = 62_500_000;
/// Cycles a frame of an SPD scene at its default size may take: 2 seconds at 125 MHz.
const DEFAULT_TARGET: u64 = 250_000_000;

/// What one scene's image did.
pub(super) struct SpdRow {
    /// `NAME-SIZE`.
    name: String,
    objects: usize,
    /// The image's flash and static RAM (bytes), or why it was not built.
    built: Result<(u64, u64), String>,
    /// Bytes of one object's record in flash (less with `lean-objects`).
    record: u64,
    /// The frame, as run (none if the image was refused or the run showed none).
    frame: Option<SpdFrame>,
}

/// A frame of an SPD image.
struct SpdFrame {
    same: bool,
    cycles: u64,
    /// The board's clock (Hz).
    clk_hz: f64,
    xip_misses: u64,
    xip_stall: u64,
    /// Rays by kind (eye, shadow, reflection, refraction), object tests, bytes of lattice.
    rays: [u64; 4],
    object_tests: u64,
    lattice_bytes: u32,
    /// Where the frame's XIP misses came from.
    misses: MissParts,
}

/// A frame's XIP misses by the part of the image whose line missed (`run.mjs --miss-lines`).
#[derive(Default)]
struct MissParts {
    /// On the object records.
    records: u64,
    /// On code run from flash.
    code: u64,
    /// On the rest: the lattice and the scene's other tables.
    rest: u64,
}

impl MissParts {
    /// The misses counted in `lines` (JSON pairs [address, misses]) of image `elf`, whose
    /// baked scene holds `objects` records of `record` bytes: the records are the table the
    /// baked scene points to with `objects` entries.
    fn of(elf: &Path, lines: &Path, objects: usize, record: u64) -> Result<MissParts> {
        let text = std::fs::read_to_string(lines).with_context(|| format!("cannot read {}", lines.display()))?;
        let counted: Vec<(u64, u64)> = serde_json::from_str(&text)
            .with_context(|| format!("{}: not JSON pairs [address, misses]", lines.display()))?;
        let image = Elf::read(elf)?;
        let start = image
            .slices_in("firmware::app::baked::")?
            .into_iter()
            .find(|&(_, len)| len == objects as u64)
            .map(|(at, _)| at)
            .with_context(|| format!("{}: no baked table of {objects} objects", elf.display()))?;
        let records = start..start + objects as u64 * record;
        let code = image.flash_code()?;
        let mut parts = MissParts::default();
        for (at, n) in counted {
            if records.contains(&at) {
                parts.records += n;
            } else if code.iter().any(|c| c.contains(&at)) {
                parts.code += n;
            } else {
                parts.rest += n;
            }
        }
        Ok(parts)
    }

    /// All of them.
    fn total(&self) -> u64 {
        self.records + self.code + self.rest
    }
}

impl Session<'_> {
    /// Every scene of [`SCENES`] in its own image.
    pub(super) fn spd_runs(&mut self) -> Result<Vec<SpdRow>> {
        let dir = self.frames_dir.join("spd");
        std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let dir = dir.canonicalize()?;
        let mut rows = Vec::new();
        for (g, size) in SCENES {
            let size = size.unwrap_or_else(|| g.default_size());
            let text = g.nff(size)?;
            if self.spd_small && lattice_rt::object_count(&text) > SMALL {
                eprintln!("leaving out {}-{size} (--spd-small)", g.name());
                continue;
            }
            rows.push(self.spd_run(g, size, &text, &dir)?);
        }
        Ok(rows)
    }

    /// One scene: its NFF `text` (generated by `g` at `size`), its image (or the build's
    /// refusal), its frame against host-sim's.
    fn spd_run(&mut self, g: Generator, size: u32, text: &str, dir: &Path) -> Result<SpdRow> {
        let name = format!("{}-{size}", g.name());
        let nff = dir.join(format!("{name}.nff"));
        host_sim::output::write_atomic(&nff, text.as_bytes())?;
        let objects = lattice_rt::object_count(text);
        let image = format!("pico-spd-{name}");
        let scenes = nff.to_str().context("the frames folder's path is not UTF-8")?;
        let (mut elf, mut record) = (self.spd_image(&image, scenes, false), WHOLE_RECORD);
        // Kept images (`--no-build`) are looked for the same way: whole, then lean.
        if matches!(&elf, Err(why) if too_big(why) || self.no_build) {
            (elf, record) = (self.spd_image(&image, scenes, true), LEAN_RECORD);
        }
        let elf = match elf {
            Ok(elf) => elf,
            Err(why) => return Ok(SpdRow { name, objects, built: Err(why), record, frame: None }),
        };
        let built = Ok(elf_sizes(&elf)?);
        let uf2 = dir.join(format!("lattice-rt-{image}.uf2"));
        write_uf2(&elf, &uf2)?;
        let work = dir.join(&name);
        std::fs::create_dir_all(&work)?;
        let run = run_emulator(self.root, &elf, &uf2, &self.bootrom, 1, true, &work, &[])?;
        self.checks.check(run.ok, || format!("SPD {name}: the run did not finish: {}", run.reason));
        let want = host_frame_of(&nff, PICO_SCALAR, PICO)?;
        // Counted for the first frame: a run that showed none (it failed, or node itself died)
        // may have written no counts, and is reported as failed above.
        let misses = match run.frames.first() {
            Some(_) => Some(MissParts::of(&elf, &work.join(MISS_LINES), objects, record)?),
            None => None,
        };
        let frame = run.frames.first().zip(misses).map(|(f, misses)| {
            let reported = reported_frame(&run.records, 0);
            SpdFrame {
                same: f.error.is_none() && f.pixels == want,
                cycles: f.cycles,
                clk_hz: run.clk_sys_hz,
                xip_misses: f.xip_misses,
                xip_stall: f.xip_stall,
                rays: reported.map_or([0; 4], |r| r.rays),
                object_tests: reported.map_or(0, |r| r.object_tests),
                lattice_bytes: reported.map_or(0, |r| r.lattice_bytes),
                misses,
            }
        });
        if let Some(f) = run.frames.first() {
            save_frame(&f.pixels, &work.join(format!("{name}.png")))?;
        }
        self.checks.check(frame.as_ref().is_some_and(|f| f.same), || {
            format!("SPD {name}: the board's frame is not host-sim's (see {})", work.display())
        });
        Ok(SpdRow { name, objects, built, record, frame })
    }

    /// The Pico image `image` with the NFF file `scenes` baked (`lean`: with the firmware's
    /// `lean-objects`), built or (`--no-build`) kept; or why not: the build's refusal.
    fn spd_image(&self, image: &str, scenes: &str, lean: bool) -> Result<std::path::PathBuf, String> {
        let (features, image) =
            if lean { ("triangles,lean-objects", format!("{image}-lean")) } else { ("triangles", image.to_string()) };
        let args = ["pico-build", "--features", features];
        if self.no_build {
            let kept = kept_image(self.root, &image);
            return if kept.exists() {
                Ok(kept)
            } else {
                Err(format!("no image kept in {} (run without --no-build)", kept.display()))
            };
        }
        eprintln!("building the Pico image {image} (cargo {})", args.join(" "));
        build_image(self.root, &image, &args, (Scenes::Listed(scenes), &[]), &pico_built())
            .map_err(|_| refusal(self.root, &args, scenes))
    }
}

/// Bytes of an object's record in a Pico image's flash.
const WHOLE_RECORD: u64 = std::mem::size_of::<lattice_rt::scene::Object<lattice_rt::Fx>>() as u64;
/// The same with the firmware's `lean-objects`: without the eye and first light in the
/// object's space and the shadow window.
const LEAN_RECORD: u64 = WHOLE_RECORD
    - 2 * std::mem::size_of::<lattice_rt::Vec3<lattice_rt::Fx>>() as u64
    - std::mem::size_of::<lattice_rt::scene::ShadowWindow<lattice_rt::Fx>>() as u64;

/// The plot of the sphereflake's images (`balls` at each size run): flash and static RAM (KiB),
/// cycles per frame (millions) and XIP misses per ray against its objects, written as [`PLOT`]
/// into the folder `images` beside the report `out`.
pub(super) fn spd_plot(rows: &[SpdRow], out: &Path) -> Result<()> {
    let images = out.parent().unwrap_or(Path::new(".")).join("images");
    std::fs::create_dir_all(&images).with_context(|| format!("cannot create {}", images.display()))?;
    let names = ["flash of the image (KiB)", "static RAM (KiB)", "cycles per frame (M)", "XIP misses per ray"];
    let mut series: Vec<(String, Vec<(f64, f64)>)> = names.iter().map(|n| (n.to_string(), Vec::new())).collect();
    for r in rows.iter().filter(|r| r.name.starts_with("balls-")) {
        let (Ok((flash, ram)), Some(f)) = (&r.built, &r.frame) else { continue };
        let x = r.objects as f64;
        let rays = f.rays.iter().sum::<u64>().max(1) as f64;
        let ys = [*flash as f64 / 1024.0, *ram as f64 / 1024.0, f.cycles as f64 / 1e6, f.xip_misses as f64 / rays];
        for (s, y) in series.iter_mut().zip(ys) {
            s.1.push((x, y));
        }
    }
    crate::plot::loglog(
        &images.join(PLOT),
        "The sphereflake baked into the Pico's flash (emulated board)",
        &format!("objects (balls at sizes {})", balls_sizes(rows)),
        "KiB, M cycles, misses per ray",
        &series,
    )
}

/// The sizes of the sphereflake whose images ran (for the plot's labels), as `1, 2, 3`.
fn balls_sizes(rows: &[SpdRow]) -> String {
    let sizes: Vec<&str> =
        rows.iter().filter(|r| r.frame.is_some()).filter_map(|r| r.name.strip_prefix("balls-")).collect();
    sizes.join(", ")
}

/// What one object's record in flash is made of (bytes, in fixed point as the Pico bakes it):
/// every shape takes the same record.
fn record_parts() -> String {
    use lattice_rt::scene::{EyeHull, EyeWindow, Object, ShadowWindow};
    use lattice_rt::{Aabb, Affine, Fx, Linear, Vec3};
    use std::mem::size_of;
    let parts = [
        ("placement's inverse", size_of::<Linear<Fx>>()),
        ("placement", size_of::<Affine<Fx>>()),
        ("bounds", size_of::<Aabb<Fx>>()),
        ("eye and light in object space", 2 * size_of::<Vec3<Fx>>()),
        ("eye window", size_of::<EyeWindow>()),
        ("eye hull", size_of::<EyeHull>()),
        ("shadow window", size_of::<ShadowWindow<Fx>>()),
    ];
    let total = size_of::<Object<Fx>>();
    let named: usize = parts.iter().map(|p| p.1).sum();
    let each: Vec<String> = parts.iter().map(|(n, b)| format!("{n} {b}")).collect();
    format!(
        "Each object, whatever its shape, is one record of {total} bytes in flash: {}, and {} for its shape, scales, material and composite. A scene whose tables do not fit so is built again with the firmware's `lean-objects` (*lean* in the table): records of {LEAN_RECORD} bytes without the eye and light in object space, which an eye ray's or first-light shadow ray's test then transforms again, and without the shadow window, which culls only shadow rays towards a directional first light (the SPD's lights are points): the same answers. A baked lattice is planned finer than host-sim's default, at {} cells per object (`firmware/build.rs`); where the objects fit and that lattice does not, `firmware/build.rs` fits a lattice to the flash they leave, starting from host-sim's default density rather than the finer one (the core's lattice budget: the lattice of least estimated cost within it), and *lattice bytes* is the fitted lattice's",
        each.join(", "),
        total - named,
        board_records::BAKED_DENSITY,
    )
}

/// Whether the build's refusal `why` is for the flash the tables need (not, say, a scene that
/// fixed point cannot hold).
fn too_big(why: &str) -> bool {
    why.contains("of flash")
}

/// Whether an SPD scene at its default size met the targets (fits the Pico's flash, a frame in
/// at most [`DEFAULT_TARGET`] cycles, the XIP stall at most a quarter of it), as a phrase.
fn default_verdict(r: &SpdRow) -> String {
    match (&r.built, &r.frame) {
        (Err(why), _) if too_big(why) => "does not fit the Pico's flash (**missed**)".into(),
        (Err(_), _) => "refused by the build, as said above (**missed**)".into(),
        (Ok(_), None) => "fits, but showed no frame (**missed**)".into(),
        (Ok(_), Some(f)) => {
            let stall = f.xip_stall as f64 / f.cycles.max(1) as f64;
            let met = f.cycles <= DEFAULT_TARGET && stall <= 0.25;
            format!(
                "fits; {} cycles, XIP stall {:.1} % ({})",
                m3(f.cycles),
                100.0 * stall,
                if met { "met" } else { "**missed**" }
            )
        }
    }
}

/// The table of where each frame's XIP misses came from.
fn miss_table(rows: &[SpdRow], md: &mut String) -> Result<()> {
    writeln!(md, "\nWhere a frame's XIP misses come from: the flash line of each miss, counted by the emulated cache (`run.mjs --miss-lines`), by the part of the image it lies in (the object records: the baked table of that many objects the scene points to, found in the ELF; code run from flash; the rest, the lattice and the scene's other tables):\n")?;
    writeln!(md, "| scene | XIP misses | object records | lattice and other tables | code |")?;
    writeln!(md, "|---|---:|---:|---:|---:|")?;
    for (r, f) in rows.iter().filter_map(|r| Some((r, r.frame.as_ref()?))) {
        let m = &f.misses;
        let share = |n: u64| format!("{:.1} %", 100.0 * n as f64 / m.total().max(1) as f64);
        writeln!(md, "| {} | {} | {} | {} | {} |", r.name, m.total(), share(m.records), share(m.rest), share(m.code))?;
    }
    Ok(())
}

/// The picture [`spd_plot`] draws, in docs/images.
pub(super) const PLOT: &str = "board-spd-balls.svg";

/// The report's section on the SPD scenes.
pub(super) fn spd_report(rows: &[SpdRow]) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "\n## The Standard Procedural Databases from flash\n")?;
    writeln!(
        md,
        "Written by `cargo xtask board`: each scene of Eric Haines' SPD is generated as NFF (`host-sim spd NAME --size N`), baked into its own Pico image (`FIRMWARE_SCENES=/path/NAME-N.nff cargo pico-build --features triangles`: objects, lattice and windows as tables in flash, read through the 16 KiB XIP cache; RAM holds what a frame writes) and run on the emulated board, its frame checked against host-sim's render of the same file with the board's settings (`host-sim render FILE --board pico`). Object tests per ray and rays are the board's own counts. Target: balls at size 3 (820 spheres and the floor) in at most 62.5 M cycles; every curve scene at its default size fitting the Pico's flash and drawn in at most 250 M cycles, with the XIP stall at most a quarter of the frame.\n"
    )?;
    writeln!(md, "| scene | objects | flash (image) | object records | lattice bytes | RAM (static) | frame: cycles | fps at 125 MHz | XIP misses per ray | XIP stall | eye rays | all rays | object tests per ray | bit-identical to host-sim |")?;
    writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")?;
    let kib = |b: u64| format!("{:.0} KiB", b as f64 / 1024.0);
    let mut refused = Vec::new();
    for r in rows {
        let (flash, ram) = match &r.built {
            Ok((flash, ram)) => (kib(*flash), kib(*ram)),
            Err(why) => {
                refused.push(format!("- **{}**: {why}", r.name));
                let cell = if too_big(why) { "does not fit" } else { "refused" };
                (cell.into(), "-".into())
            }
        };
        let lean = if r.record == LEAN_RECORD { " (lean)" } else { "" };
        let records = format!("{}{lean}", kib(r.objects as u64 * r.record));
        let Some(f) = &r.frame else {
            writeln!(
                md,
                "| {} | {} | {flash} | {records} | - | {ram} | - | - | - | - | - | - | - | - |",
                r.name, r.objects
            )?;
            continue;
        };
        let rays: u64 = f.rays.iter().sum();
        let per_ray = |n: u64| format!("{:.2}", n as f64 / rays.max(1) as f64);
        writeln!(
            md,
            "| {} | {} | {flash} | {records} | {} | {ram} | {} | {:.2} | {} | {:.1} % | {} | {rays} | {} | {} |",
            r.name,
            r.objects,
            f.lattice_bytes,
            m3(f.cycles),
            f.clk_hz / f.cycles.max(1) as f64,
            per_ray(f.xip_misses),
            100.0 * f.xip_stall as f64 / f.cycles.max(1) as f64,
            f.rays[0],
            per_ray(f.object_tests),
            if f.same { "yes" } else { "**no**" }
        )?;
    }
    writeln!(md, "\n{}.", record_parts())?;
    miss_table(rows, &mut md)?;
    if !refused.is_empty() {
        writeln!(md, "\nRefused by `firmware/build.rs`:\n")?;
        for r in &refused {
            writeln!(md, "{r}")?;
        }
    }
    let sizes = balls_sizes(rows);
    writeln!(md, "\nThe sphereflake's images by size (`balls` at {sizes}):\n\n![flash, RAM, cycles and XIP misses per ray of balls at sizes {sizes}](images/{PLOT})")?;
    writeln!(md, "\nAt their default sizes (target: fits the Pico's 2 MiB, a frame in at most 250 M cycles, XIP stall at most a quarter):\n")?;
    for (r, (g, size)) in rows.iter().zip(SCENES) {
        if size.is_none() && g != Generator::Jacks {
            writeln!(md, "- {}: {}", r.name, default_verdict(r))?;
        }
    }
    if let Some(f) = rows.iter().find(|r| r.name == "balls-3").and_then(|r| r.frame.as_ref()) {
        let met = if f.cycles <= BALLS_3_TARGET { "met" } else { "**missed**" };
        writeln!(md, "\nballs at size 3: {} cycles against the target's 62.5 M: {met}.", m3(f.cycles))?;
    }
    Ok(md)
}
