//! Picks the memory map of the board being built (the Pico's is the repository's root
//! `memory.x`; the emulated board's is `qemu/memory.x`), the linker scripts, and the scenes
//! embedded in the firmware.
//!
//! Scenes: `FIRMWARE_SCENES` (comma-separated names from `scenes/`), or the list in
//! `default-scenes.txt` (the paper's four and the Whitted showcase; `cargo xtask board` reads it
//! too, to know which frames the image shows). Each is parsed here with the core itself, in the firmware's
//! scalar, so a broken scene fails the build with its line and column, and the storage
//! capacities are the exact maximum the chosen scenes need (written to `capacities.rs`).
use lattice_rt::bake::Literal;
use lattice_rt::lattice::{LatticeConfig, LatticeStorage, SubLattice};
use lattice_rt::scene::Object;
use lattice_rt::Lattice;
use lattice_rt::{Real, Sizes};

use board_records::frame;
use std::fmt::Write as _;
use std::{env, fs, path::PathBuf};

/// [`refuse`] with `format!`'s arguments.
macro_rules! refuse {
    ($($arg:tt)*) => {
        refuse(&format!($($arg)*))
    };
}

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    link(&out);
    println!("cargo:rerun-if-changed=default-scenes.txt");
    let names = env::var("FIRMWARE_SCENES")
        .unwrap_or_else(|_| fs::read_to_string("default-scenes.txt").expect("default-scenes.txt"));
    let mut list = String::new();
    let mut sizes = Sizes { objects: 1, lattices: 1, coords: 1, words: 1, rows: 0 };
    let mut effects = 0u8;
    let baked = bakes();
    println!("cargo::rustc-check-cfg=cfg(baked_scenes)");
    if baked {
        println!("cargo:rustc-cfg=baked_scenes");
    }
    let mut tables = String::new();
    // Whether the windows answer every ray of every embedded scene (`EyeRays::serve_every_ray`):
    // then a baked build gives its tracer brute force in place of the lattice, which it never
    // asks (`windows_only`). The ladder's rungs walk the lattice on purpose.
    let mut windows_only = baked && !has("ladder");
    // The slot image embeds no scene: it reads one from flash at run time.
    let names = if has("slot") { String::new() } else { names };
    let scenes: Vec<(String, PathBuf, String)> = names
        .split(',')
        .map(str::trim)
        .filter(|n| !n.is_empty())
        .map(|entry| {
            let (name, path) = scene_file(entry);
            println!("cargo:rerun-if-changed={}", path.display());
            let text = fs::read_to_string(&path).unwrap_or_else(|e| refuse!("FIRMWARE_SCENES: {}: {e}", path.display()));
            if !baked && lattice_rt::scene::Format::of(&text) == lattice_rt::scene::Format::Nff {
                refuse!("FIRMWARE_SCENES: {}: an NFF scene is baked into the image only (this build parses its scenes on the board: leave out `parse` and `orbit`)", path.display());
            }
            (name, path, text)
        })
        .collect();
    for (i, (name, path, _)) in scenes.iter().enumerate() {
        if let Some((other, ..)) = scenes[..i].iter().find(|(n, ..)| table_name(n) == table_name(name)) {
            refuse!("FIRMWARE_SCENES: {} is named `{name}`, as `{other}` before it is (scenes are told apart by name: rename the file)", path.display());
        }
    }
    for (name, path, text) in &scenes {
        let (s, e, serves) = plan_in_scalar(path, text, None);
        effects |= e;
        windows_only &= serves;
        sizes = sizes.max(s);
        let abs = fs::canonicalize(path).unwrap();
        writeln!(list, "    ({name:?}, include_str!({:?})),", abs.display()).unwrap();
    }
    println!("cargo::rustc-check-cfg=cfg(windows_only)");
    if windows_only {
        println!("cargo:rustc-cfg=windows_only");
    }
    if baked {
        // Baked once it is known whether the tracer asks the lattices: where it never does,
        // they are left out of flash.
        tables = bake_scenes(&scenes, !windows_only, &mut sizes);
    }
    if has("effects-all") {
        effects = lattice_rt::Effects::ALL.bits();
    }
    if has("slot") {
        // Room for any scene within the slot's: its rows are the frame's (any scene's), every
        // effect compiled in (the tracer still simulates only those the scene calls for).
        let (any, ..) = plan_in_scalar(std::path::Path::new("slot"), "sphere\n", None);
        sizes = any.max(board_records::slot::ROOM);
        effects = lattice_rt::Effects::ALL.bits();
    }
    write_capacities(&out, &list, &sizes, effects);
    if baked {
        let names: Vec<String> = scenes.iter().map(|(n, ..)| format!("({n:?}, &{})", table_name(n))).collect();
        writeln!(
            tables,
            "/// The baked scenes, by name.\npub static BAKED: [(&str, &Baked<S>); {}] = [{}];",
            names.len(),
            names.join(", ")
        )
        .unwrap();
        fs::write(out.join("baked.rs"), tables).unwrap();
    }
}

/// `capacities.rs`: the embedded scenes (`list`, one `(name, text)` line each), the storage
/// capacities they need and the effects compiled in.
fn write_capacities(out: &std::path::Path, list: &str, sizes: &Sizes, effects: u8) {
    let count = list.lines().count();
    let code = format!(
        "/// The scenes embedded in this build (`FIRMWARE_SCENES`).\n\
         pub const SCENES: [(&str, &str); {count}] = [\n{list}];\n\
         /// Most primitives in an embedded scene.\npub const MAX_OBJECTS: usize = {};\n\
         /// Most lattices (world + composites).\npub const MAX_LATTICES: usize = {};\n\
         /// Coordinate-list entries.\npub const MAX_COORDS: usize = {};\n\
         /// Words: cells + 1, references and the mailbox.\npub const MAX_WORDS: usize = {};\n\
         /// Render rows (dither carries, edge ids).\npub const MAX_ROWS: usize = {};\n\
         /// Effects compiled in: those the embedded scenes call for (`Effects` bits).\npub const EFFECTS: u8 = {effects};\n",
        sizes.objects, sizes.lattices, sizes.coords, sizes.words, sizes.rows
    );
    fs::write(out.join("capacities.rs"), code).unwrap();
}

/// The memory map of the board being built, the linker scripts and the link-time settings: the
/// Pico's hot code in SRAM, defmt's log level, the core's name in reports.
fn link(out: &std::path::Path) {
    let (pico, pico2, microbit, tiny) = (has("pico"), has("pico2"), has("microbit"), has("tiny"));
    let target = env::var("TARGET").unwrap_or_default();
    let m33 = target.starts_with("thumbv8m");
    let src = match (pico, pico2, m33, microbit, tiny) {
        (true, ..) => "../memory.x",
        (_, true, ..) => "pico2/memory.x",
        (_, _, true, ..) => "qemu-an505/memory.x",
        (_, _, _, true, _) => "microbit/memory.x",
        (.., true) => "tiny/memory.x",
        _ => "qemu/memory.x",
    };
    let mut map = fs::read_to_string(src).expect("memory.x");
    println!("cargo:rerun-if-env-changed=FIRMWARE_FLASH_KIB");
    if let (true, Ok(kib)) = (tiny, env::var("FIRMWARE_FLASH_KIB")) {
        let kib: u32 =
            kib.trim().parse().unwrap_or_else(|_| refuse!("FIRMWARE_FLASH_KIB is not a number of KiB: {kib:?}"));
        map = map.replace("LENGTH = 16K", &format!("LENGTH = {kib}K"));
    }
    // The Pico's flash as this image divides it (`pico_flash_kib`, `pico_code_load_kib`).
    if pico {
        let (flash, load) = (pico_flash_kib(), pico_code_load_kib());
        map = replace_line(&map, "FLASH     :", &format!("FLASH     : ORIGIN = 0x10000100, LENGTH = {flash}K - 0x100"));
        let origin = 0x1000_0000 + (2048 - load) * 1024;
        map = replace_line(&map, "CODE_LOAD :", &format!("CODE_LOAD : ORIGIN = {origin:#X}, LENGTH = {load}K"));
    }
    fs::write(out.join("memory.x"), map).expect("memory.x");
    println!("cargo:rustc-link-search={}", out.display());
    for map in
        ["../memory.x", "pico2/memory.x", "qemu-an505/memory.x", "qemu/memory.x", "microbit/memory.x", "tiny/memory.x"]
    {
        println!("cargo:rerun-if-changed={map}");
    }
    // The core's name in the firmware's reports.
    let core = if m33 {
        "m33"
    } else if target.starts_with("thumbv7em") {
        "m4f"
    } else {
        "m0"
    };
    println!("cargo:rustc-env=FIRMWARE_CORE={core}");
    println!("cargo:rerun-if-env-changed=FIRMWARE_SCENES");
    // The Pico's hot code runs from SRAM (pico/ram-code.x), unless `code-in-flash` keeps it in
    // flash behind the XIP cache (to measure what that costs). Its script comes before link.x,
    // so that its sections claim their input sections before link.x's `.text` can.
    println!("cargo:rerun-if-changed=pico/ram-code.x");
    if pico && !has("code-in-flash") {
        fs::copy("pico/ram-code.x", out.join("ram-code.x")).expect("ram-code.x");
        println!("cargo:rustc-link-arg-bins=-Tram-code.x");
        println!("cargo:rustc-cfg=ram_code");
    }
    println!("cargo:rustc-link-arg-bins=-Tlink.x");
    println!("cargo::rustc-check-cfg=cfg(ram_code)");
    if pico || pico2 {
        println!("cargo:rustc-link-arg-bins=-Tdefmt.x");
    }
    // defmt drops everything below `error` unless DEFMT_LOG says otherwise; the repository's
    // `.cargo/config.toml` sets it, but only for builds started inside the repository. The
    // firmware's own log lines show at `info` however and wherever it is built.
    println!("cargo:rerun-if-env-changed=DEFMT_LOG");
    if env::var_os("DEFMT_LOG").is_none() {
        println!("cargo:rustc-env=DEFMT_LOG=info");
    }
}

/// `map` with its line that starts (after indentation) with `start` replaced by `line`.
fn replace_line(map: &str, start: &str, line: &str) -> String {
    assert!(map.lines().any(|l| l.trim_start().starts_with(start)), "memory.x has no line `{start}`");
    let lines: Vec<String> = map
        .lines()
        .map(|l| if l.trim_start().starts_with(start) { format!("    {line}") } else { l.to_string() })
        .collect();
    lines.join("\n") + "\n"
}

/// What baking a scene asks of [`plan`]: its name, whether its lattice goes into flash, the
/// source its tables are appended to and the list its footprint is added to.
struct Bake<'a> {
    name: &'a str,
    with_lattice: bool,
    /// Most bytes its lattice may take (the core's lattice budget), or none.
    budget: Option<usize>,
    out: &'a mut String,
    footprints: &'a mut Vec<Footprint>,
}

/// The tables of `scenes` (name, path, text), each with its lattice (`with_lattice`), and the
/// storage they need merged into `sizes`. Where they do not fit the board's flash but their
/// objects do, they are baked again with their lattices fitted to the flash the objects leave
/// (each a share in proportion to its lattice's bytes: the core's budget search, the lattice
/// of least estimated cost within it), and the build says so; what still does not fit is
/// refused ([`check_fits`]).
fn bake_scenes(scenes: &[(String, PathBuf, String)], with_lattice: bool, sizes: &mut Sizes) -> String {
    let (mut tables, mut footprints) = bake_with(scenes, with_lattice, &vec![None; scenes.len()], sizes);
    if let Some(fitted) = lattice_budgets(&footprints) {
        for (f, b) in footprints.iter().zip(&fitted) {
            let kib = |b: usize| b as f64 / 1024.0;
            println!(
                "cargo:warning={}: its lattice of {:.0} KiB does not fit the flash its objects leave: fitted to {:.0} KiB",
                f.scene,
                kib(f.lattice_bytes),
                kib(*b)
            );
        }
        let budgets: Vec<Option<usize>> = fitted.into_iter().map(Some).collect();
        (tables, footprints) = bake_with(scenes, with_lattice, &budgets, sizes);
    }
    check_fits(&footprints, sizes);
    tables
}

/// The tables of `scenes`, each lattice within its budget of `budgets` (none: as configured),
/// and their footprints; the storage they need merged into `sizes`.
fn bake_with(
    scenes: &[(String, PathBuf, String)],
    with_lattice: bool,
    budgets: &[Option<usize>],
    sizes: &mut Sizes,
) -> (String, Vec<Footprint>) {
    let (mut tables, mut footprints) = (String::new(), Vec::new());
    for ((name, path, text), &budget) in scenes.iter().zip(budgets) {
        let bake = Bake { name, with_lattice, budget, out: &mut tables, footprints: &mut footprints };
        let (s, ..) = plan_in_scalar(path, text, Some(bake));
        *sizes = sizes.max(s);
    }
    (tables, footprints)
}

/// Per scene of `footprints`, the bytes its lattice may take when the tables do not fit the
/// board's flash but the objects alone do: the flash left after the objects, shared in
/// proportion to the lattices' bytes. None when they fit, or cannot be made to.
fn lattice_budgets(footprints: &[Footprint]) -> Option<Vec<usize>> {
    let (flash, code, _) = board_memory()?;
    let objects: usize = footprints.iter().map(|f| f.objects * f.object_bytes).sum();
    let lattices: usize = footprints.iter().map(|f| f.lattice_bytes).sum();
    let left = (flash - code).checked_sub(objects)?;
    if lattices <= left || left == 0 {
        return None;
    }
    Some(footprints.iter().map(|f| (left as u128 * f.lattice_bytes as u128 / lattices as u128) as usize).collect())
}

/// The flash a baked scene's tables take: its objects (each a full record: shape, placement and
/// its inverse, bounds, where it can appear) and its lattice.
struct Footprint {
    scene: String,
    objects: usize,
    object_bytes: usize,
    lattice_bytes: usize,
}

/// Flash of the Pico image besides the baked scenes' tables, at most: its code in flash, the
/// other read-only data, the vector table (32 KiB in the SPD's images today: 20 KiB of code,
/// 10 KiB of other read-only data; its hot code runs from SRAM and is loaded from the top of
/// flash, outside the region: `pico_code_load_kib`). Should an image outgrow it, the linker
/// refuses the image instead.
const PICO_CODE_FLASH: usize = 40 * 1024;
/// The same for the Pico 2's image, all of whose code stays in flash (about 110 KiB today).
const PICO2_CODE_FLASH: usize = 128 * 1024;
/// RAM of the Pico image besides the mailboxes, at most: the code run from SRAM (about 62 KiB),
/// core 1's stack (32 KiB), the tile buffers, the panel's frame, and room for core 0's stack.
const PICO_OTHER_RAM: usize = 160 * 1024;

/// The flash the board's image has besides its code loaded into SRAM, the flash its other code
/// takes at most, and its RAM (bytes): the Pico's and the Pico 2's (whose core's image on
/// QEMU's Cortex-M33 board has the same memory, `qemu-an505/memory.x`, and so the same
/// budgets); none for other boards.
fn board_memory() -> Option<(usize, usize, usize)> {
    let m33 = env::var("TARGET").is_ok_and(|t| t.starts_with("thumbv8m"));
    match (has("pico"), has("pico2") || m33) {
        (true, _) => Some((pico_flash_kib() * 1024 - 0x100, PICO_CODE_FLASH, 256 * 1024)),
        (_, true) => Some((4096 * 1024, PICO2_CODE_FLASH, 512 * 1024)),
        _ => None,
    }
}

/// Refuses, with the figure needed and the figure available, baked scenes whose tables do not
/// fit the Pico's flash or whose mailboxes (a word per object and lattice, for each core) do not
/// fit its RAM, before the linker would say so less clearly. Other boards are left to their
/// linker scripts.
fn check_fits(footprints: &[Footprint], sizes: &Sizes) {
    let Some((flash, code, ram)) = board_memory() else { return };
    let kib = |b: usize| format!("{:.0} KiB", b as f64 / 1024.0);
    let tables: usize = footprints.iter().map(|f| f.objects * f.object_bytes + f.lattice_bytes).sum();
    if tables + code > flash {
        let each: Vec<String> = footprints
            .iter()
            .map(|f| {
                format!(
                    "{}: {} objects of {} bytes, a lattice of {}",
                    f.scene,
                    f.objects,
                    f.object_bytes,
                    kib(f.lattice_bytes)
                )
            })
            .collect();
        refuse!(
            "FIRMWARE_SCENES: the baked scenes' tables need {} of flash ({}), and the image has {} for them ({} of flash less {} for its code): bake fewer or smaller scenes",
            kib(tables),
            each.join("; "),
            kib(flash - code),
            kib(flash),
            kib(code)
        );
    }
    let mailboxes = 2 * 4 * (sizes.objects + sizes.lattices);
    if mailboxes + PICO_OTHER_RAM > ram {
        refuse!(
            "FIRMWARE_SCENES: the largest baked scene's mailboxes need {} of RAM (a word per object and lattice on each core: {} objects, {} lattices), and the image has {} for them ({} of RAM less {} for the rest)",
            kib(mailboxes),
            sizes.objects,
            sizes.lattices,
            kib(ram - PICO_OTHER_RAM),
            kib(ram),
            kib(PICO_OTHER_RAM)
        );
    }
}

/// A `FIRMWARE_SCENES` entry's name and file: a name from `scenes/` (`chair`), or a path to a
/// scene or NFF file (it has a `/` or an extension; relative to the firmware's folder), named
/// by its file's stem (`balls-3` for `/tmp/balls-3.nff`).
fn scene_file(entry: &str) -> (String, PathBuf) {
    if !entry.contains('/') && !entry.contains('.') {
        return (entry.to_string(), PathBuf::from(format!("../scenes/{entry}.scene")));
    }
    let path = PathBuf::from(entry);
    let stem = path.file_stem().and_then(|s| s.to_str()).filter(|s| !s.is_empty());
    let name = stem.unwrap_or_else(|| {
        refuse!("FIRMWARE_SCENES: {entry}: a path names its scene by its file's stem, and this one has none")
    });
    (name.to_string(), path)
}

/// Stops the build with `why` as cargo's own error (`cargo::error`, one line each), where a
/// scene or setting is one the image cannot take: the user's input, told without a panic's
/// location and backtrace. Cargo fails the build on it.
fn refuse(why: &str) -> ! {
    for line in why.lines() {
        println!("cargo::error={line}");
    }
    std::process::exit(0)
}

/// Whether the image bakes its scenes: asked for (`baked`), or the Raspberry Pi boards' default:
/// their frames are shown from the scenes' own cameras, so nothing needs parsing on the board,
/// unless the camera moves (`orbit`) or run-time parsing is asked for (`parse`).
fn bakes() -> bool {
    has("baked") || (has("rp") && !has("orbit") && !has("parse"))
}

/// The Pico's flash (KiB, after the 256-byte second-stage bootloader) that the image's code and
/// read-only data, baked scenes' tables included, may take: all of the 2 MiB but the region
/// its SRAM code is loaded from at the top (`pico_code_load_kib`), and for the slot image all
/// below the scene slot.
fn pico_flash_kib() -> usize {
    if has("slot") {
        (board_records::slot::ADDRESS - 0x1000_0000) as usize / 1024
    } else {
        2048 - pico_code_load_kib()
    }
}

/// The Pico's region (KiB, at the top of flash) the code that runs from SRAM is loaded from: as
/// much as the images that parse scenes and build lattices on the board need (180 KiB, `parse`;
/// 256 KiB, the SRAM's size), and 128 KiB for the images that bake their scenes (about 64 KiB
/// of code), whose tables take the flash this leaves.
fn pico_code_load_kib() -> usize {
    if bakes() {
        128
    } else {
        256
    }
}

/// Whether the firmware is built with Cargo feature `feature` (its name as in Cargo.toml).
fn has(feature: &str) -> bool {
    env::var_os(format!("CARGO_FEATURE_{}", feature.to_uppercase().replace('-', "_"))).is_some()
}

/// The static a baked scene's tables are named by.
fn table_name(scene: &str) -> String {
    let name: String =
        scene.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_uppercase() } else { '_' }).collect();
    // A file's stem may start with a digit, which no Rust name does.
    if name.starts_with(|c: char| c.is_ascii_digit()) {
        format!("_{name}")
    } else {
        name
    }
}

/// The lattice a scene is planned with, within `budget` bytes (none: as configured): on the
/// Pico and the Pico 2, whose baked lattices are read from flash, at
/// [`board_records::BAKED_DENSITY`] cells per object where that fits (no budget); elsewhere,
/// and fitted to a budget, the core's default. (The budget search scaled down from the finer
/// lattice chose worse: the sphereflake at size 4 took 660.3 M cycles, against 183.4 M.)
fn lattice_config(budget: Option<usize>) -> LatticeConfig {
    let mut cfg = LatticeConfig { budget, ..LatticeConfig::default() };
    if budget.is_none() && bakes() && board_memory().is_some() {
        let fine = lattice_rt::lattice::Resolution::Auto { density: board_records::BAKED_DENSITY };
        (cfg.top, cfg.sub) = (fine, fine);
    }
    cfg
}

/// [`plan`] in the scalar the firmware's features choose.
fn plan_in_scalar(path: &std::path::Path, text: &str, bake: Option<Bake<'_>>) -> (Sizes, u8, bool) {
    if has("scalar-fixed") {
        plan::<lattice_rt::Fx>(path, text, bake)
    } else if has("scalar-micromath") {
        plan::<lattice_rt::F32Micro>(path, text, bake)
    } else if has("scalar-micromath-newton") {
        plan::<lattice_rt::F32MicroNewton>(path, text, bake)
    } else {
        plan::<f32>(path, text, bake)
    }
}

/// Storage and effects of one scene in the firmware's scalar, and whether its windows serve
/// every ray; with `bake`, its tables too (the scene as parsed and, if asked for, its lattice
/// as built in that scalar, as the firmware would).
fn plan<R: Real + Literal>(path: &std::path::Path, text: &str, bake: Option<Bake<'_>>) -> (Sizes, u8, bool) {
    let mut storage = vec![Object::<R>::default(); lattice_rt::object_count(text).max(1)];
    let mut parts = lattice_rt::Parts::default();
    // The frame this build renders, from its features (as `app::RENDERED` has it): the view is
    // fitted to its shape (square pixels on any glass).
    let frame = frame::rendered(frame::Build::of(has));
    let scene = lattice_rt::scene::parse_with::<R>(text, &mut storage, &mut parts, |c| c.frame = frame.size())
        .unwrap_or_else(|e| refuse!("{}: {e}", path.display()));
    // build.rs's own lattice-rt has every shape: the firmware's may not.
    for (i, o) in scene.objects().iter().enumerate() {
        let Some(feature) = o.shape().feature() else { continue };
        if !has(feature) {
            let default = if feature == "triangles" { "" } else { ", a default one" };
            refuse!(
                "{}: object {i} is a {}, which this build leaves out (the firmware's feature `{feature}`{default})",
                path.display(),
                lattice_rt::shape::SHAPE_NAMES[o.shape().kind()]
            );
        }
    }
    let effects = lattice_rt::Effects::of(&scene).bits();
    let cfg = lattice_config(bake.as_ref().and_then(|b| b.budget));
    let sizes = Sizes::of(&scene, Some(&cfg), &frame);
    if let Some(Bake { name, with_lattice, out, footprints, .. }) = bake {
        let s = Lattice::plan(&scene, &cfg);
        let (mut lattices, mut coords, mut words) =
            (vec![SubLattice::EMPTY; s.lattices], vec![R::ZERO; s.coords], vec![0; s.words()]);
        let storage = LatticeStorage { lattices: &mut lattices, coords: &mut coords, words: &mut words };
        let lattice = Lattice::build(&scene, &cfg, storage).unwrap_or_else(|e| refuse!("{}: {e}", path.display()));
        out.push_str(&lattice_rt::bake::source(
            &table_name(name),
            "S",
            &scene,
            Some(&lattice).filter(|_| with_lattice),
        ));
        footprints.push(Footprint {
            scene: name.to_string(),
            objects: scene.objects().len(),
            // This script's core has the firmware's `lean-objects` too (cargo turns a feature's
            // `lattice-rt/...` on in every dependency of that name), so its objects are the size
            // the image's are.
            object_bytes: size_of::<Object<R>>(),
            lattice_bytes: if with_lattice { lattice.bytes() } else { 0 },
        });
    }
    (sizes, effects, lattice_rt::EyeRays::serve_every_ray(&scene))
}
