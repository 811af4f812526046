//! `host-sim uf2`: the Pico (or Pico 2) image as a UF2 file, to drag onto the board's BOOTSEL
//! drive; and building that image with the repository's own alias, so it is the image `cargo
//! pico` flashes (`cargo xtask board` runs the same build on the emulated board).

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The copy of the last Pico image [`build_pico`] built.
pub fn pico_elf(root: &Path) -> PathBuf {
    kept_image(root, Board::Pico.name())
}

/// A Raspberry Pi board the firmware is built for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Board {
    /// Raspberry Pi Pico (RP2040, Cortex-M0+): fixed point.
    Pico,
    /// Raspberry Pi Pico 2 (RP2350, Cortex-M33 with an FPU): f32.
    Pico2,
}

impl Board {
    /// Its name in file names and its cargo feature (`pico`, `pico2`).
    pub fn name(self) -> &'static str {
        match self {
            Board::Pico => "pico",
            Board::Pico2 => "pico2",
        }
    }
    /// The Rust target its image is built for.
    fn target(self) -> &'static str {
        match self {
            Board::Pico => "thumbv6m-none-eabi",
            Board::Pico2 => "thumbv8m.main-none-eabihf",
        }
    }
    /// Where `cargo <board>-build` writes the image, inside `firmware/target`.
    fn built(self) -> PathBuf {
        // Both boards' images are built for speed: the Pico's within the SRAM its hot code
        // runs from (`sram`, opt-level 2), the Pico 2's with 4 MiB of flash (`speed`, 3).
        let profile = match self {
            Board::Pico => "sram",
            Board::Pico2 => "speed",
        };
        Path::new(self.target()).join(profile).join("pico")
    }
    /// The drive the board shows in BOOTSEL mode.
    fn drive(self) -> &'static str {
        match self {
            Board::Pico => "RPI-RP2",
            Board::Pico2 => "RP2350",
        }
    }
    /// Writes `elf` as a UF2 file for the board's family (via a temporary file, so a failed
    /// write leaves nothing behind).
    fn write_uf2(self, elf: &Path, out: &Path) -> Result<()> {
        let data = std::fs::read(elf).with_context(|| format!("cannot read {}", elf.display()))?;
        let mut bytes = Vec::new();
        let converted = match self {
            Board::Pico => {
                elf2flash_core::elf2uf2(&data, &mut bytes, &elf2flash_core::boards::RP2040, elf2flash_core::NoProgress)
            }
            Board::Pico2 => {
                elf2flash_core::elf2uf2(&data, &mut bytes, &elf2flash_core::boards::RP2350, elf2flash_core::NoProgress)
            }
        };
        converted.map_err(|e| anyhow::anyhow!("cannot convert {} to UF2: {e}", elf.display()))?;
        crate::output::write_atomic(out, &bytes)
    }
}

/// Builds the Pico image with the repository's own alias, so it is the image `cargo pico` flashes.
pub fn build_pico(root: &Path) -> Result<PathBuf> {
    build_board(root, Board::Pico, None)
}

/// Builds `board`'s image with the repository's own alias (`cargo pico-build`,
/// `cargo pico2-build`), so it is the image `cargo pico` / `cargo pico2` flashes; with
/// `features` (the firmware's, comma-separated) it is kept as `<board>-<features>`.
pub fn build_board(root: &Path, board: Board, features: Option<&str>) -> Result<PathBuf> {
    build_board_with(root, board, features, Scenes::Inherited)
}

/// [`build_board`] with `scenes` embedded.
pub fn build_board_with(root: &Path, board: Board, features: Option<&str>, scenes: Scenes) -> Result<PathBuf> {
    let owned = board_args(board, features);
    let args: Vec<&str> = owned.iter().map(String::as_str).collect();
    let name =
        features.map_or_else(|| board.name().to_string(), |f| format!("{}-{}", board.name(), f.replace(',', "-")));
    eprintln!("building the {} image (cargo {})", board.name(), args.join(" "));
    build_image(root, &name, &args, (scenes, &[]), &board.built())
        .with_context(|| format!("`cargo {}` failed (its own message is above; it links with flip-link: `cargo install flip-link`; the target: `rustup target add {}`)", args[0], board.target()))
}

/// The cargo arguments that build `board`'s image with `features`: its alias
/// (`pico-build`, `pico2-build`), then `--features` if any.
fn board_args(board: Board, features: Option<&str>) -> Vec<String> {
    let mut args = vec![format!("{}-build", board.name())];
    if let Some(f) = features {
        args.extend(["--features".to_string(), f.to_string()]);
    }
    args
}

/// The scenes an image embeds (the firmware's build script reads `FIRMWARE_SCENES`).
#[derive(Clone, Copy, Debug)]
pub enum Scenes<'a> {
    /// As the caller's environment says (the firmware's default list when it says nothing).
    Inherited,
    /// The firmware's default list (`firmware/default-scenes.txt`), whatever the environment says.
    Default,
    /// These, comma-separated: names from `scenes/`, or paths of scene or NFF files.
    Listed(&'a str),
}

/// Runs `cargo <args>` from the repository's root with `scenes` and the variables `env` and keeps
/// the image it wrote, `built` (a path inside `firmware/target`), as [`kept_image`]`(name)`;
/// returns that copy.
///
/// Every image builds in the firmware's one target folder, so a dependency compiles once per
/// target and feature set, not once per image (a folder per image took 14 GB for the project's
/// checks); the copy keeps an image from being overwritten by the next build of the same binary.
pub fn build_image(
    root: &Path,
    name: &str,
    args: &[&str],
    (scenes, env): (Scenes, &[(&str, &str)]),
    built: &Path,
) -> Result<PathBuf> {
    // One build at a time, to its copy: cargo writes every variant of a board's image to the
    // same `built` path, so two threads building (`cargo xtask board` runs sections side by
    // side), or two processes (CI runs the emulated board beside the QEMU firmware), could each
    // keep the other's image. The thread lock orders this process's threads; the file's lock
    // (`flock`) orders processes.
    static BUILDING: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _one_at_a_time = BUILDING.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let lock_path = root.join("firmware/target/image-build.lock");
    std::fs::create_dir_all(root.join("firmware/target")).context("cannot create firmware/target")?;
    let lock = std::fs::File::create(&lock_path).with_context(|| format!("cannot create {}", lock_path.display()))?;
    lock.lock().with_context(|| format!("cannot lock {}", lock_path.display()))?;
    let mut cmd = firmware_cargo(root);
    cmd.args(args);
    match scenes {
        Scenes::Inherited => {}
        Scenes::Default => {
            cmd.env_remove("FIRMWARE_SCENES");
        }
        Scenes::Listed(list) => {
            cmd.env("FIRMWARE_SCENES", list);
        }
    }
    cmd.envs(env.iter().copied());
    let status = cmd.status().context("cannot run cargo")?;
    if !status.success() {
        bail!("`cargo {}` failed", args.join(" "));
    }
    let kept = kept_image(root, name);
    let dir = kept.parent().expect("kept images live in a folder");
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let from = root.join("firmware/target").join(built);
    // Copied beside, then renamed: a run reading the kept image (another process's) sees the
    // old file or the new one whole, never one half written.
    let part = kept.with_extension("part");
    std::fs::copy(&from, &part).with_context(|| format!("cannot copy {} to {}", from.display(), part.display()))?;
    std::fs::rename(&part, &kept).with_context(|| format!("cannot rename {} to {}", part.display(), kept.display()))?;
    Ok(kept)
}

/// `cargo`, run from the repository's root, for a firmware build: the caller's `RUSTFLAGS` and
/// `FIRMWARE_FLASH_KIB` left out, and the source paths an image carries (the panic locations of
/// the core, a path dependency outside the firmware's workspace, and of registry crates)
/// written relative to the repository (`lattice-rt/`) and to cargo's home (`cargo/`). So an
/// image's size is the same wherever the repository is checked out (a clone in /tmp built a
/// default image 40 bytes larger than /work/main's before). Its layout still is not quite:
/// cargo's crate hashes include the path, and functions of one size may swap places, which
/// moves code that runs from flash behind the XIP cache (the slot image's frame by up to 3 %).
/// Every firmware build the project's commands run goes through here, so they share one set of
/// compiled dependencies.
pub fn firmware_cargo(root: &Path) -> Command {
    let mut cmd = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()));
    let home = std::env::var_os("CARGO_HOME")
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| Path::new(&h).join(".cargo")));
    let mut flags: Vec<String> = Vec::new();
    let mut remap = |from: &Path, to: &str| flags.push(format!("--remap-path-prefix={}={to}", from.display()));
    if let Some(home) = &home {
        remap(home, "cargo");
    }
    // The later of two matching prefixes wins: the repository's, should it live in cargo's home.
    remap(root, "lattice-rt");
    if let Ok(canonical) = root.canonicalize() {
        if canonical != root {
            remap(&canonical, "lattice-rt");
        }
    }
    cmd.current_dir(root)
        .env_remove("RUSTFLAGS")
        .env_remove("FIRMWARE_FLASH_KIB")
        .env("CARGO_ENCODED_RUSTFLAGS", flags.join("\x1f"));
    cmd
}

/// Where `cargo pico-build` (with any extra features) writes the Pico image, inside `firmware/target`.
pub fn pico_built() -> PathBuf {
    Board::Pico.built()
}

/// Where [`build_image`] keeps the image called `name`: `firmware/target/images/<name>`.
pub fn kept_image(root: &Path, name: &str) -> PathBuf {
    root.join("firmware/target/images").join(name)
}

/// Writes `elf` as a UF2 file for the RP2040's BOOTSEL drive.
pub fn write_uf2(elf: &Path, out: &Path) -> Result<()> {
    Board::Pico.write_uf2(elf, out)
}

/// The firmware's `features` with `panel`'s own added (the default panel has none).
pub fn with_panel(features: Option<&str>, panel: Option<board_records::frame::Panel>) -> Option<String> {
    let own = panel.and_then(board_records::frame::Panel::feature);
    match (features, own) {
        (Some(f), Some(p)) => Some(format!("{p},{f}")),
        (f, p) => f.or(p).map(str::to_string),
    }
}

/// The command `host-sim uf2`: the image with the firmware's `features` (comma-separated, such
/// as `spi`), if any; `out` defaults to `out/lattice-rt-<board>[-<features>].uf2`.
pub fn uf2_cmd(root: &Path, board: Board, features: Option<&str>, bake: &[PathBuf], out: Option<&Path>) -> Result<()> {
    // The firmware's build script reads the files from its own folder: their paths go absolute.
    let files = bake
        .iter()
        .map(|f| f.canonicalize().with_context(|| format!("cannot read the scene to bake {}", f.display())))
        .collect::<Result<Vec<_>>>()?;
    let list = files.iter().map(|f| f.display().to_string()).collect::<Vec<_>>().join(",");
    let elf = if files.is_empty() {
        build_board_with(root, board, features, Scenes::Inherited)?
    } else {
        build_baked(root, board, features, &files, &list)?
    };
    let stems: Vec<String> =
        files.iter().filter_map(|f| f.file_stem()).map(|s| s.to_string_lossy().to_string()).collect();
    let parts: Vec<String> = features.map(|f| f.replace(',', "-")).into_iter().chain(stems).collect();
    let named = if parts.is_empty() {
        format!("out/lattice-rt-{}.uf2", board.name())
    } else {
        format!("out/lattice-rt-{}-{}.uf2", board.name(), parts.join("-"))
    };
    let out = out.map_or_else(|| PathBuf::from(named), Path::to_path_buf);
    board.write_uf2(&elf, &out)?;
    crate::say!(
        "wrote {}: hold BOOTSEL while plugging the board in, then copy this file onto the {} drive",
        out.display(),
        board.drive()
    )?;
    Ok(())
}

/// What [`refusal`] says of a build that failed with neither the build script's message nor
/// the linker's.
const NOT_BUILT: &str = "the image did not build";

/// `board`'s image with the scene files `files` (`list`, comma-separated) baked, built with
/// what they need beyond `features`: the firmware's `triangles` when a scene has triangles (the
/// SPD's polygons), and, on the Pico, built again with `lean-objects` (records without the eye
/// and light in object space and the shadow window) when the scenes' tables do not fit its flash whole, as `cargo
/// xtask board` builds the SPD's largest scenes. A refusal is the build script's own message.
fn build_baked(root: &Path, board: Board, features: Option<&str>, files: &[PathBuf], list: &str) -> Result<PathBuf> {
    let mut wanted: Vec<String> =
        features.into_iter().flat_map(|f| f.split(',')).map(|f| f.trim().to_string()).collect();
    if !wanted.iter().any(|f| f == "triangles") && files.iter().any(|f| has_triangles(f)) {
        eprintln!("the scenes have triangles: building with the firmware's `triangles`");
        wanted.push("triangles".into());
    }
    let mut lean = wanted.iter().any(|f| f == "lean-objects");
    loop {
        let mut all = wanted.clone();
        if lean && !all.iter().any(|f| f == "lean-objects") {
            all.push("lean-objects".into());
        }
        let joined = all.join(",");
        let chosen = (!joined.is_empty()).then_some(joined.as_str());
        let failed = match build_board_with(root, board, chosen, Scenes::Listed(list)) {
            Ok(elf) => return Ok(elf),
            Err(e) => e,
        };
        let args = board_args(board, chosen);
        let why = refusal(root, &args.iter().map(String::as_str).collect::<Vec<_>>(), list);
        if why == NOT_BUILT {
            return Err(failed);
        }
        if why.contains("of flash") && board == Board::Pico && !lean {
            eprintln!("the scenes' tables do not fit whole: building again with the firmware's `lean-objects` (40 bytes less per object)");
            lean = true;
            continue;
        }
        bail!("the {} image with {} baked was not built: {why}", board.name(), list.replace(',', ", "));
    }
}

/// Whether the scene file `path` has a triangle (parsed in `f64`; a file that does not parse
/// has none here, and its build says where it fails).
fn has_triangles(path: &Path) -> bool {
    let Ok(text) = crate::load::read(path) else { return false };
    let Ok(mut store) = crate::load::object_storage::<f64>(&text) else { return false };
    let parsed = lattice_rt::scene::parse_with::<f64>(&text, &mut store.objects, &mut store.parts, |_| {});
    parsed.is_ok_and(|scene| scene.objects().iter().any(|o| o.shape().feature() == Some("triangles")))
}

/// The command `host-sim uf2 --scene FILE`: `image` (the slot image's UF2 file) with the scene
/// in its slot, written to `out` (default `out/lattice-rt-pico-<scene>.uf2`). The scene is
/// checked first as the Pico will read it; nothing is built.
pub fn scene_cmd(board: Board, scene: &Path, image: &Path, out: Option<&Path>) -> Result<()> {
    if board != Board::Pico {
        bail!("the scene slot is the Pico's (RP2040) for now: --board pico");
    }
    let text = crate::load::read(scene)?;
    let base = std::fs::read(image).with_context(|| {
        format!("cannot read the slot image {}: build it once with `host-sim uf2 --features slot` (needs the Rust toolchain), or download it from the playground's page", image.display())
    })?;
    board_records::slot::check_scene(&text).map_err(|e| anyhow::anyhow!("{}: {e}", scene.display()))?;
    let bytes =
        board_records::slot::with::scene(&base, &text).map_err(|e| anyhow::anyhow!("{}: {e}", image.display()))?;
    let stem = scene.file_stem().map_or_else(|| "scene".to_string(), |s| s.to_string_lossy().to_string());
    let out = out.map_or_else(|| PathBuf::from(format!("out/lattice-rt-pico-{stem}.uf2")), Path::to_path_buf);
    crate::output::write_atomic(&out, &bytes)?;
    crate::say!("wrote {}: the slot image with {} in its scene slot ({} bytes); hold BOOTSEL while plugging the Pico in, then copy this file onto the RPI-RP2 drive", out.display(), scene.display(), text.len())?;
    Ok(())
}

/// Why the image built by `cargo ARGS` with `scenes` baked was not built: `firmware/build.rs`'s
/// message (the build is run again to read it, its folder left out of the paths it names), the
/// linker's when a region overflowed, or the build's failure.
pub fn refusal(root: &Path, args: &[&str], scenes: &str) -> String {
    let out = firmware_cargo(root).args(args).env("FIRMWARE_SCENES", scenes).output();
    let text = out.map(|o| String::from_utf8_lossy(&o.stderr).into_owned()).unwrap_or_default();
    refusal_in(&text, scenes)
}

/// [`refusal`] read from the build's error output `text`.
fn refusal_in(text: &str, scenes: &str) -> String {
    // The build script's refusal is cargo's `error: firmware@VERSION: ...` line (its
    // `cargo::error`); without one, the linker's complaint about the first region the image
    // overflowed (cargo may set it after a `= note:`).
    let message = text
        .lines()
        .find_map(|l| l.trim().strip_prefix("error: firmware@")?.split_once(": ").map(|(_, why)| why.to_string()))
        .or_else(|| {
            text.lines().find(|l| l.contains("will not fit in region")).map(|l| {
                let what = l.split_once("error: ").map_or(l.trim(), |(_, what)| what);
                format!("the linker: {what}")
            })
        });
    let folder = Path::new(scenes).parent().map(|p| format!("{}/", p.display())).unwrap_or_default();
    message.map_or_else(|| NOT_BUILT.into(), |m| m.trim_start_matches("FIRMWARE_SCENES: ").replace(&folder, ""))
}

#[cfg(test)]
mod tests {
    use super::{has_triangles, refusal_in};

    #[test]
    fn a_refusal_gives_the_linker_line_without_its_prefixes() {
        let text = "error: linking with `flip-link` failed: exit status: 1\n  = note: rust-lld: error: section '.rodata' will not fit in region 'FLASH': overflowed by 2469876 bytes\n          rust-lld: error: section '.gnu.sgstubs' will not fit in region 'FLASH': overflowed by 2469888 bytes\n";
        assert_eq!(
            refusal_in(text, "/tmp/out/shells.nff"),
            "the linker: section '.rodata' will not fit in region 'FLASH': overflowed by 2469876 bytes"
        );
    }

    #[test]
    fn a_refusal_gives_the_build_scripts_message_without_the_scenes_folder() {
        let text = "   Compiling firmware v0.1.0 (/src/firmware)\nerror: firmware@0.1.0: FIRMWARE_SCENES: /tmp/out/tree.nff:3:1: too big for fixed point\nerror: build script logged errors\n";
        assert_eq!(refusal_in(text, "/tmp/out/tree.nff"), "tree.nff:3:1: too big for fixed point");
    }

    #[test]
    fn a_scene_needs_the_triangle_test_only_when_it_has_triangles() {
        // `uf2 --bake` adds the firmware's `triangles` for NFF's polygons, not for spheres, and
        // leaves a file that does not parse to the build, which says where it fails.
        let dir = std::env::temp_dir().join(format!("uf2-triangles-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let head = "v\nfrom 0 -5 2\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.1\nresolution 64 64\nl 5 -5 5\nf 1 1 1 0.8 0 0 0 1\n";
        let files = [
            ("spheres.nff", format!("{head}s 0 0 0 1\n"), false),
            ("floor.nff", format!("{head}s 0 0 0 1\np 3\n-4 -4 -1\n4 -4 -1\n0 4 -1\n"), true),
            ("broken.nff", format!("{head}p 3\n-4 -4\n"), false),
        ];
        for (name, text, want) in files {
            let path = dir.join(name);
            std::fs::write(&path, text).unwrap();
            assert_eq!(has_triangles(&path), want, "{name}");
        }
        assert!(!has_triangles(&dir.join("missing.nff")));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
